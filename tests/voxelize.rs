//! Properties of the separating voxelizer beyond separability: accuracy (every voxel is
//! near the surface), nesting of 6 in 26, class counts, normals, and thread independence.
#![cfg(feature = "fixtures")]

use glam::DVec3;
use voxelkit::mesh::{Mesh, generate};
use voxelkit::voxelize::Separability;
use voxelkit::voxelize::separating::{SeparatingOptions, voxelize_mesh};

/// Distance from `p` to triangle `abc` (brute force: plane if the projection is inside,
/// else the nearest edge).
fn point_triangle_distance(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let n = (b - a).cross(c - a).normalize();
    let inside = [(a, b), (b, c), (c, a)]
        .iter()
        .all(|(u, v)| n.cross(*v - *u).dot(p - *u) >= 0.0);
    if inside {
        return n.dot(p - a).abs();
    }
    [(a, b), (b, c), (c, a)]
        .iter()
        .map(|(u, v)| {
            let d = *v - *u;
            let t = ((p - *u).dot(d) / d.length_squared()).clamp(0.0, 1.0);
            (p - (*u + d * t)).length()
        })
        .fold(f64::INFINITY, f64::min)
}

mod common;

fn run(mesh: &Mesh, res: u32, sep: Separability, normals: bool) -> voxelkit::grid::SparseGrid {
    let opts = SeparatingOptions {
        separability: sep,
        normals,
        ..Default::default()
    };
    common::voxelize_at(mesh, res, opts).0
}

#[test]
fn every_voxel_is_within_rc_of_the_surface() {
    let mesh = generate::random_closed(7);
    for sep in [Separability::Six, Separability::TwentySix] {
        let g = run(&mesh, 24, sep, false);
        let h = g.transform.voxel_size;
        let tris: Vec<[DVec3; 3]> = mesh
            .triangles()
            .map(|(_, t)| t.map(|i| mesh.p(i)))
            .collect();
        for c in g.voxels() {
            let p = g.transform.index_to_world(c);
            let d = tris
                .iter()
                .map(|t| point_triangle_distance(p, t[0], t[1], t[2]))
                .fold(f64::INFINITY, f64::min);
            assert!(
                d <= (sep.vertex_edge_radius() + 1e-6) * h,
                "{c:?} is {} voxels away",
                d / h
            );
        }
    }
}

#[test]
fn six_separating_surface_lies_inside_the_26_one() {
    let mesh = generate::g_shape();
    let six = run(&mesh, 64, Separability::Six, false);
    let mut rest = six.clone();
    rest.difference(&run(&mesh, 64, Separability::TwentySix, false));
    assert!(six.voxel_count() > 0);
    assert_eq!(rest.voxel_count(), 0);
}

#[test]
fn class_counts_of_a_box_on_voxel_centres_are_exact() {
    // Corners, edges and faces on voxel centres: 6-separating keeps exactly the 41^3 shell,
    // 8 vertex voxels, 12 x 39 edge voxels and 6 x 39^2 body voxels.
    let mesh = generate::cuboid(DVec3::ZERO, DVec3::splat(10.0));
    let t = voxelkit::grid::Transform::new(DVec3::ZERO, 0.25);
    let opts = SeparatingOptions {
        separability: Separability::Six,
        normals: false,
        ..Default::default()
    };
    let (g, stats) = voxelize_mesh(&mesh, t, &opts, &voxelkit::progress::Progress::none()).unwrap();
    assert_eq!((stats.vertices, stats.edges, stats.triangles), (8, 12, 12));
    assert_eq!(stats.vertex_voxels, 8);
    assert_eq!(stats.edge_voxels, 12 * 39);
    assert_eq!(stats.body_voxels, 6 * 39 * 39);
    assert_eq!(g.voxel_count(), 41u64.pow(3) - 39u64.pow(3));
    assert_eq!(stats.total_voxels(), g.voxel_count());
}

#[test]
fn normals_are_unit_and_follow_the_sphere() {
    let mesh = generate::icosphere(DVec3::new(0.3, -0.1, 0.2), 1.0, 4);
    let g = run(&mesh, 64, Separability::TwentySix, true);
    for leaf in g.leaves() {
        let normals = leaf.normal.as_ref().unwrap();
        for (n, c) in leaf.offsets().zip(leaf.coords()) {
            let normal = glam::Vec3::from(normals[n]).as_dvec3();
            let radial = (g.transform.index_to_world(c) - DVec3::new(0.3, -0.1, 0.2)).normalize();
            assert!((normal.length() - 1.0).abs() < 1e-5);
            assert!(normal.dot(radial) > 0.98, "{c:?}: {normal} vs {radial}");
        }
    }
}

#[test]
fn result_does_not_depend_on_the_thread_count() {
    let mesh = generate::trefoil(1.0, 0.4, 256, 16);
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let two = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    let a = one.install(|| run(&mesh, 96, Separability::TwentySix, true));
    let b = two.install(|| run(&mesh, 96, Separability::TwentySix, true));
    let mut va: Vec<_> = a.voxels().collect();
    let mut vb: Vec<_> = b.voxels().collect();
    va.sort();
    vb.sort();
    assert_eq!(va, vb);
}

/// Sorted voxels and class counts of `mesh` on `t`, with or without normals.
fn voxels_and_classes(
    mesh: &Mesh,
    t: voxelkit::grid::Transform,
    sep: Separability,
    normals: bool,
) -> (Vec<[i64; 3]>, [u64; 3]) {
    let opts = SeparatingOptions {
        separability: sep,
        normals,
        ..Default::default()
    };
    let (g, s) = voxelize_mesh(mesh, t, &opts, &voxelkit::progress::Progress::none()).unwrap();
    let mut v: Vec<_> = g.voxels().collect();
    v.sort();
    (v, [s.vertex_voxels, s.edge_voxels, s.body_voxels])
}

#[test]
fn small_primitives_marked_without_branches_match_the_row_scans() {
    // Without channels, edges and triangles whose boxes are small are tested voxel by voxel
    // without branches; with normals every primitive takes the row scans. Both must give the
    // same voxels in the same classes: on small and large triangles, at random, and on a box
    // and a sphere whose corners, edges and faces fall on voxel centres and half-way between.
    let meshes = [
        (generate::random_closed(3), 0.05),
        (generate::trefoil(1.0, 0.4, 256, 16), 0.02),
        (generate::icosphere(DVec3::ZERO, 1.0, 4), 0.01),
        (generate::icosphere(DVec3::ZERO, 4.0, 3), 0.5),
        (generate::cuboid(DVec3::ZERO, DVec3::splat(10.0)), 0.25),
        (
            generate::cuboid(DVec3::splat(-0.125), DVec3::splat(2.125)),
            0.25,
        ),
        (
            generate::cuboid(DVec3::ZERO, DVec3::new(1.0, 1.5, 0.75)),
            0.25,
        ),
    ];
    for (mesh, h) in &meshes {
        let t = voxelkit::grid::Transform::new(DVec3::ZERO, *h);
        for sep in [Separability::Six, Separability::TwentySix] {
            let plain = voxels_and_classes(mesh, t, sep, false);
            let scanned = voxels_and_classes(mesh, t, sep, true);
            assert!(!plain.0.is_empty());
            assert_eq!(plain.1, scanned.1, "classes at {h} ({sep:?})");
            assert!(plain.0 == scanned.0, "voxels differ at {h} ({sep:?})");
        }
    }
}

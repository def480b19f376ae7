//! Minimality (Huang et al. §3): the share of N-simple voxels (removable without opening an
//! N-hole, local 3x3x3 test). The paper's full spheres and cylinders leave some; the
//! clipped criterion must leave fewer, and few.
#![cfg(feature = "fixtures")]

mod common;

use glam::DVec3;
use voxelkit::grid::Transform;
use voxelkit::mesh::{Mesh, generate};
use voxelkit::ops::minimality::{simple_voxel_count, simple_voxels};
use voxelkit::ops::separability::check_mesh_separation;
use voxelkit::progress::Progress;
use voxelkit::random::SplitMix64;
use voxelkit::voxelize::Separability;
use voxelkit::voxelize::separating::{Criterion, SeparatingOptions};

fn simple_share(mesh: &Mesh, resolution: u32, sep: Separability, criterion: Criterion) -> f64 {
    let opts = SeparatingOptions {
        separability: sep,
        criterion,
        normals: false,
    };
    let (grid, _) = common::voxelize_at(mesh, resolution, opts);
    simple_voxel_count(&grid, sep.flood_adjacency()).unwrap() as f64 / grid.voxel_count() as f64
}

fn assert_clipped_is_nearly_minimal(mesh: &Mesh, resolution: u32, limit: f64) {
    for sep in [Separability::Six, Separability::TwentySix] {
        let huang = simple_share(mesh, resolution, sep, Criterion::Huang);
        let clipped = simple_share(mesh, resolution, sep, Criterion::Clipped);
        assert!(
            clipped < huang,
            "{}: clipped {clipped} vs huang {huang}",
            mesh.source.display()
        );
        assert!(
            clipped < limit,
            "{} {sep:?}: {:.2}% simple",
            mesh.source.display(),
            100.0 * clipped
        );
    }
}

#[test]
fn a_sphere_is_almost_minimal() {
    let mesh = generate::icosphere(glam::DVec3::new(0.1, 0.2, 0.3), 1.0, 5);
    assert_clipped_is_nearly_minimal(&mesh, 128, 0.02);
}

#[test]
fn closed_data_meshes_at_256_have_few_simple_voxels() {
    let Some(data) = common::data_dir() else {
        return;
    };
    for name in common::CLOSED_MESHES {
        let mesh = Mesh::load(&data.join("meshes").join(format!("{name}.obj"))).unwrap();
        assert_clipped_is_nearly_minimal(&mesh, 256, 0.12);
    }
}

/// A box whose faces fall half-way between voxel centres (the grid fit puts a bounding box's
/// minimum on a voxel boundary) keeps one row per face: the half-open slabs.
#[test]
fn a_unit_cube_is_one_voxel_thick() {
    let cube = generate::cuboid(DVec3::ZERO, DVec3::ONE);
    for (sep, limit) in [(Separability::Six, 1800), (Separability::TwentySix, 2000)] {
        for criterion in [Criterion::Huang, Criterion::Clipped] {
            let opts = SeparatingOptions {
                separability: sep,
                criterion,
                normals: false,
            };
            let (grid, _) = common::voxelize_at(&cube, 16, opts);
            let n = grid.voxel_count();
            assert!(n <= limit, "{sep:?} {criterion:?}: {n} voxels");
            let report = check_mesh_separation(&grid, &cube, sep.flood_adjacency()).unwrap();
            assert!(report.separates(), "{sep:?} {criterion:?}: {report:?}");
        }
    }
}

/// 0, 1, 2, 3 or 4.
fn small(rng: &mut SplitMix64) -> f64 {
    (rng.next_u64() % 5) as f64
}

/// Huang et al.'s Theorems 3-4: the slab of a plane is N-minimal. Planes with small integer
/// normals through points on the half-voxel lattice put centres exactly on the slab's faces,
/// where closed slabs keep two rows; no voxel away from the polygon's border may be simple.
#[test]
fn voxelized_planes_are_minimal() {
    let mut rng = SplitMix64(34);
    let unit = Transform::new(DVec3::ZERO, 1.0);
    for case in 0..60 {
        let n = loop {
            let v = DVec3::new(
                small(&mut rng) - 2.0,
                small(&mut rng) - 2.0,
                small(&mut rng) - 2.0,
            );
            if v != DVec3::ZERO {
                break v.normalize();
            }
        };
        let half = |r: &mut SplitMix64| 0.5 * (r.next_u64() % 4) as f64;
        let centre = DVec3::new(half(&mut rng), half(&mut rng), half(&mut rng));
        // A square of side 40 in the plane, as two triangles.
        let u = n.any_orthonormal_vector();
        let w = n.cross(u);
        let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
            .map(|(a, b)| centre + 20.0 * (a * u + b * w));
        let square =
            Mesh::from_polygons("plane", corners.to_vec(), &[vec![0, 1, 2], vec![0, 2, 3]]);
        for sep in [Separability::Six, Separability::TwentySix] {
            let opts = SeparatingOptions {
                separability: sep,
                criterion: Criterion::Clipped,
                normals: false,
            };
            let (grid, _) = voxelkit::voxelize::separating::voxelize_mesh(
                &square,
                unit,
                &opts,
                &Progress::none(),
            )
            .unwrap();
            let inner: Vec<_> = simple_voxels(&grid, sep.flood_adjacency())
                .unwrap()
                .into_iter()
                .filter(|c| {
                    let p = DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64) - centre;
                    p.dot(u).abs() < 16.0 && p.dot(w).abs() < 16.0
                })
                .collect();
            assert!(
                inner.is_empty(),
                "case {case}, n = {n}, through {centre}, {sep:?}: {} simple voxels, e.g. {:?}",
                inner.len(),
                inner.first()
            );
        }
    }
}

//! Projective voxelization (Jegathese et al.): lines and triangles are 26-connected (the
//! paper's Claim 4) on random input and on every real mesh, triangles cover their points,
//! colours are the exact linear interpolants at the voxel centres, and the beam solid holds
//! the mesh's volume.
#![cfg(feature = "fixtures")]

mod common;

use glam::{DVec3, Vec3};
use std::collections::{HashMap, HashSet};
use voxelkit::mesh::generate::{SplitMix64, icosphere, torus};
use voxelkit::mesh::{GridFit, Mesh, fit_transform};
use voxelkit::progress::Progress;
use voxelkit::solids::beam::{BeamFill, beam_solid};
use voxelkit::voxelize::projective::line::{dominant_axis, voxel_of, voxelize_segment};
use voxelkit::voxelize::projective::triangle::{is_degenerate, voxelize_triangle};
use voxelkit::voxelize::projective::{Coloring, LineSource, line_segments, voxelize_triangles};

type Voxel = [i64; 3];

/// Whether `set` is one 26-connected piece.
fn is_26_connected(set: &HashSet<Voxel>) -> bool {
    let Some(&start) = set.iter().next() else {
        return true;
    };
    let mut seen = HashSet::from([start]);
    let mut stack = vec![start];
    while let Some(v) = stack.pop() {
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let n = [v[0] + dx, v[1] + dy, v[2] + dz];
                    if set.contains(&n) && seen.insert(n) {
                        stack.push(n);
                    }
                }
            }
        }
    }
    seen.len() == set.len()
}

fn centre(v: Voxel) -> DVec3 {
    DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64)
}

fn random_point(rng: &mut SplitMix64, extent: f64) -> DVec3 {
    DVec3::new(
        rng.range(-extent, extent),
        rng.range(-extent, extent),
        rng.range(-extent, extent),
    )
}

fn random_color(rng: &mut SplitMix64) -> DVec3 {
    DVec3::new(
        rng.range(0.0, 1.0),
        rng.range(0.0, 1.0),
        rng.range(0.0, 1.0),
    )
}

/// A segment's voxels with their colours; asserts 26-connectivity, both endpoint voxels,
/// and that every colour is the segment's exact value where the voxel's centre plane across
/// the dominant axis cuts it (the endpoint colour at an endpoint's own voxel).
fn check_segment(a: DVec3, b: DVec3, ca: DVec3, cb: DVec3) -> HashSet<Voxel> {
    let mut set = HashSet::new();
    let axis = dominant_axis(b - a);
    voxelize_segment(a, b, ca, cb, |v, _, c| {
        set.insert(v);
        let t = if b[axis] == a[axis] {
            0.0
        } else {
            ((v[axis] as f64 - a[axis]) / (b[axis] - a[axis])).clamp(0.0, 1.0)
        };
        let exact = ca.lerp(cb, t);
        let at_end = (v == voxel_of(a) && c == ca) || (v == voxel_of(b) && c == cb);
        assert!(
            at_end || (c - exact).abs().max_element() < 1e-9,
            "segment {a}-{b}: voxel {v:?} has colour {c}, the exact value is {exact}"
        );
    });
    assert!(set.contains(&voxel_of(a)) && set.contains(&voxel_of(b)));
    assert!(
        is_26_connected(&set),
        "segment {a} - {b} is not 26-connected"
    );
    set
}

#[test]
fn random_segments_and_polylines_are_26_connected_with_exact_colours() {
    let mut rng = SplitMix64(7);
    for case in 0..20_000 {
        let extent = [0.3, 2.0, 20.0, 200.0][case % 4];
        let a = random_point(&mut rng, extent);
        let b = if case % 7 == 0 {
            // Axis-parallel and half-integer endpoints: the rounding ties.
            let mut b = a;
            b[case % 3] += rng.range(-extent, extent).round() + 0.5;
            b
        } else {
            random_point(&mut rng, extent)
        };
        check_segment(a, b, random_color(&mut rng), random_color(&mut rng));
    }
    // Polylines: the union of consecutive segments is one piece from end to end.
    for _ in 0..500 {
        let mut all = HashSet::new();
        let mut p = random_point(&mut rng, 30.0);
        for _ in 0..8 {
            let q = p + random_point(&mut rng, 10.0);
            all.extend(check_segment(p, q, DVec3::ZERO, DVec3::ONE));
            p = q;
        }
        assert!(is_26_connected(&all));
    }
}

/// The exact barycentric colour of the point of triangle `p` above the voxel centre `v`
/// along the dominant normal axis, held within the vertex colours' range.
fn barycentric_color(p: [DVec3; 3], c: [DVec3; 3], v: Voxel) -> DVec3 {
    let w = dominant_axis((p[1] - p[0]).cross(p[2] - p[0]));
    let (u, vv) = ((w + 1) % 3, (w + 2) % 3);
    let q = p.map(|x| glam::DVec2::new(x[u], x[vv]));
    let x = glam::DVec2::new(v[u] as f64, v[vv] as f64);
    let area = (q[1] - q[0]).perp_dot(q[2] - q[0]);
    let l1 = (x - q[0]).perp_dot(q[2] - q[0]) / area;
    let l2 = (q[1] - q[0]).perp_dot(x - q[0]) / area;
    let l0 = 1.0 - l1 - l2;
    let exact = c[0] * l0 + c[1] * l1 + c[2] * l2;
    exact.clamp(c[0].min(c[1]).min(c[2]), c[0].max(c[1]).max(c[2]))
}

/// A triangle's voxels; asserts 26-connectivity, that each voxel lies within the triangle's
/// box grown by one voxel, that every sampled point of the triangle has a voxel in its column
/// within 1.5 voxels along the dominant axis, and, with `colors`, the exact colours.
fn check_triangle(
    p: [DVec3; 3],
    colors: Option<[DVec3; 3]>,
    rng: &mut SplitMix64,
) -> HashSet<Voxel> {
    let mut set = HashSet::new();
    let c = colors.unwrap_or([DVec3::ZERO; 3]);
    let degenerate = is_degenerate(p);
    let lo = p[0].min(p[1]).min(p[2]) - 1.0;
    let hi = p[0].max(p[1]).max(p[2]) + 1.0;
    voxelize_triangle(p, c, |v, _, col| {
        assert!(
            centre(v).cmpge(lo).all() && centre(v).cmple(hi).all(),
            "triangle {p:?}: stray voxel {v:?}"
        );
        if colors.is_some() && !degenerate {
            let exact = barycentric_color(p, c, v);
            assert!(
                (col - exact).abs().max_element() < 1e-9,
                "triangle {p:?}: voxel {v:?} has colour {col}, barycentric {exact}"
            );
        }
        set.insert(v);
    });
    assert!(is_26_connected(&set), "triangle {p:?} is not 26-connected");
    if !degenerate {
        let w = dominant_axis((p[1] - p[0]).cross(p[2] - p[0]));
        for _ in 0..50 {
            let (mut s, mut t) = (rng.range(0.0, 1.0), rng.range(0.0, 1.0));
            if s + t > 1.0 {
                (s, t) = (1.0 - s, 1.0 - t);
            }
            let x = p[0] + (p[1] - p[0]) * s + (p[2] - p[0]) * t;
            let column = voxel_of(x);
            let covered = (-2..=2).any(|dk| {
                let mut v = column;
                v[w] += dk;
                set.contains(&v) && (v[w] as f64 - x[w]).abs() <= 1.5 + 1e-9
            });
            assert!(
                covered,
                "triangle {p:?}: point {x} has no voxel in its column"
            );
        }
    }
    set
}

#[test]
fn random_triangles_are_26_connected_cover_their_points_and_interpolate_colours() {
    let mut rng = SplitMix64(11);
    for case in 0..20_000 {
        let extent = [0.4, 3.0, 15.0, 60.0][case % 4];
        let a = random_point(&mut rng, extent);
        let p = match case % 5 {
            // A sliver: two corners close together, the third far away.
            0 => {
                let b = random_point(&mut rng, extent);
                [a, b, b + random_point(&mut rng, 0.05)]
            }
            // Collinear: no area.
            1 => {
                let d = random_point(&mut rng, extent);
                [a, a + d, a + d * rng.range(-1.0, 2.0)]
            }
            // Corners on voxel boundaries and centres: every rounding tie.
            2 => [
                a,
                random_point(&mut rng, extent),
                random_point(&mut rng, extent),
            ]
            .map(|x| (x * 2.0).round() / 2.0),
            _ => [
                a,
                random_point(&mut rng, extent),
                random_point(&mut rng, extent),
            ],
        };
        let colors = [0; 3].map(|_| random_color(&mut rng));
        check_triangle(p, Some(colors), &mut rng);
    }
}

#[test]
fn every_triangle_and_edge_of_the_real_meshes_is_26_connected() {
    let Some(data) = common::data_dir() else {
        return;
    };
    let mut rng = SplitMix64(3);
    let mut entries: Vec<_> = std::fs::read_dir(data.join("meshes"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for path in entries {
        let mesh = Mesh::load(&path).unwrap();
        for res in [64, 512] {
            let t = fit_transform(&mesh.bbox(), GridFit::Resolution(res)).unwrap();
            let pos: Vec<DVec3> = mesh
                .positions
                .iter()
                .map(|&p| t.world_to_index(p))
                .collect();
            for (_, tri) in mesh.triangles() {
                check_triangle(tri.map(|i| pos[i as usize]), None, &mut rng);
            }
            let edges = LineSource {
                polylines: false,
                edges: true,
            };
            for [a, b] in line_segments(&mesh, edges) {
                check_segment(pos[a as usize], pos[b as usize], DVec3::ZERO, DVec3::ONE);
            }
            eprintln!(
                "{} at {res}: {} triangles and their edges 26-connected",
                path.display(),
                mesh.triangle_count()
            );
        }
    }
}

#[test]
fn mesh_voxels_are_the_union_of_the_triangles_with_the_nearest_sample_colour() {
    let mut mesh = icosphere(DVec3::ZERO, 1.0, 3);
    mesh.colors = mesh
        .positions
        .iter()
        .map(|p| (p.as_vec3() + 1.0) * 0.5)
        .collect();
    let t = fit_transform(&mesh.bbox(), GridFit::Resolution(48)).unwrap();
    let (grid, stats) = voxelize_triangles(
        &mesh,
        t,
        Coloring::Vertex,
        &voxelkit::progress::Progress::none(),
    )
    .unwrap();
    assert_eq!(stats.triangles, mesh.triangle_count() as u64);
    // The nearest sample of every voxel, scanned triangle by triangle.
    let mut nearest: HashMap<Voxel, (f64, Vec3)> = HashMap::new();
    for (_, tri) in mesh.triangles() {
        let p = tri.map(|i| t.world_to_index(mesh.p(i)));
        let c = tri.map(|i| mesh.colors[i as usize].as_dvec3());
        voxelize_triangle(p, c, |v, d, col: DVec3| {
            let e = nearest.entry(v).or_insert((f64::INFINITY, col.as_vec3()));
            if d < e.0 {
                *e = (d, col.as_vec3());
            }
        });
    }
    assert_eq!(grid.voxel_count(), nearest.len() as u64);
    for leaf in grid.leaves() {
        let colors = leaf.color.as_ref().expect("a colour channel");
        for n in leaf.offsets() {
            let v = voxelkit::grid::offset_coord(leaf.origin, n);
            let (_, expected) = nearest[&v];
            assert!((Vec3::from(colors[n]) - expected).abs().max_element() < 1e-6);
        }
    }
}

#[test]
fn the_beam_solid_holds_the_exact_volume_of_spheres_tori_and_real_meshes() {
    let mut meshes = vec![
        icosphere(DVec3::new(0.1, -0.2, 0.3), 1.0, 4),
        torus(DVec3::ZERO, 1.0, 0.35, 64, 32),
    ];
    if let Some(data) = common::data_dir() {
        for name in ["bunny-closed", "horse", "skull", "rocker-arm"] {
            meshes.push(Mesh::load(&data.join("meshes").join(format!("{name}.obj"))).unwrap());
        }
    }
    for mesh in &meshes {
        let volume = mesh.signed_volume().abs();
        for res in [48, 128] {
            let t = fit_transform(&mesh.bbox(), GridFit::Resolution(res)).unwrap();
            let parity = beam_solid(mesh, t, BeamFill::Parity, &Progress::none()).unwrap();
            let m = parity.solid.measures;
            assert_eq!(m.surface_voxels, parity.surface.voxel_count());
            assert!(
                m.volume_inside <= volume && volume <= m.volume_with_surface,
                "{} at {res}: {} .. {} does not hold {volume}",
                mesh.source.display(),
                m.volume_inside,
                m.volume_with_surface
            );
            // The paper's fill, from the face voxels: the same surface, and beams that open and
            // close on it. On the sphere and the torus it is the parity solid; on real meshes,
            // where the face voxels of a column need not line up with the exact crossings
            // (thin parts, steep faces), it differs from it by little (measured at 48 and 128:
            // at most 1.0% outside it, rocker-arm at 48, and 5.4% of it missed, horse at 48).
            let paper = beam_solid(mesh, t, BeamFill::Paper, &Progress::none()).unwrap();
            let p = paper.solid.measures;
            assert_eq!(p.surface_voxels, m.surface_voxels);
            let outside = paper
                .solid
                .inside
                .voxels()
                .filter(|&c| !parity.solid.inside.contains(c))
                .count();
            let missed = m.inside_voxels - (p.inside_voxels - outside as u64);
            eprintln!(
                "{} at {res}: beam {:.6} .. {:.6}, mesh {volume:.6}; paper fill {} inside ({} outside the parity solid, {} of its voxels missed), {} unclosed",
                mesh.source.display(),
                m.volume_inside,
                m.volume_with_surface,
                p.inside_voxels,
                outside,
                missed,
                paper.unclosed_beams
            );
            if mesh.source.extension().is_none() {
                assert_eq!((outside, missed), (0, 0), "{}", mesh.source.display());
            }
            assert!(outside as u64 * 50 <= m.inside_voxels, "{outside} outside");
            assert!(
                missed * 10 <= m.inside_voxels,
                "{missed} of {}",
                m.inside_voxels
            );
        }
    }
}

#[test]
fn the_beam_refuses_an_open_mesh() {
    let Some(data) = common::data_dir() else {
        return;
    };
    let mesh = Mesh::load(&data.join("meshes/cube_no_bottom.obj")).unwrap();
    let t = fit_transform(&mesh.bbox(), GridFit::Resolution(32)).unwrap();
    let err = beam_solid(&mesh, t, BeamFill::Paper, &Progress::none())
        .err()
        .unwrap()
        .to_string();
    assert!(
        err.contains("cube_no_bottom.obj") && err.contains("boundary edge"),
        "{err}"
    );
}

/// Measured on every closed mesh: the projective surface (naive planes, one voxel thick along
/// each triangle's dominant axis) blocks every 6-connected path from outside, like the 6-separating
/// surface, and like it lets 26-connected paths through.
#[test]
fn the_projective_surface_separates_under_6_flooding_and_leaks_under_26() {
    let Some(data) = common::data_dir() else {
        return;
    };
    use voxelkit::grid::Adjacency;
    use voxelkit::ops::separability::check_mesh_separation;
    let real = common::CLOSED_MESHES
        .iter()
        .map(|name| Mesh::load(&data.join("meshes").join(format!("{name}.obj"))).unwrap());
    let random = (0..24).map(voxelkit::mesh::generate::random_closed);
    for mesh in real.chain(random) {
        let name = mesh.source.display().to_string();
        for res in [64, 128] {
            let t = fit_transform(&mesh.bbox(), GridFit::Resolution(res)).unwrap();
            let (surface, _) = voxelize_triangles(
                &mesh,
                t,
                Coloring::None,
                &voxelkit::progress::Progress::none(),
            )
            .unwrap();
            let six = check_mesh_separation(&surface, &mesh, Adjacency::Six).unwrap();
            let all = check_mesh_separation(&surface, &mesh, Adjacency::TwentySix).unwrap();
            eprintln!(
                "{name} at {res}: {} voxels, 6-flood leaks {}, 26-flood leaks {} of {} inside",
                surface.voxel_count(),
                six.leaked,
                all.leaked,
                all.inside_empty
            );
            assert!(six.separates(), "{name} at {res}: {six:?}");
            assert!(
                all.leaked > 0,
                "{name} at {res}: a naive surface should leak under 26"
            );
        }
    }
}

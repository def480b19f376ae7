//! Lai & Cheng's Catmull-Clark solids (§6-7) on the closed control meshes of the data folder:
//! the exact limit volume (Gauss quadrature, divergence theorem) against a fine tessellation;
//! the seeds-and-FloodingXYZ solid at 64, 128 and 256 against the exterior flood of the same
//! surface (identical) and against the limit volume (within area x h); inward-oriented control
//! meshes fill the same; open ones are refused; CSG trees over subdivision solids; and the
//! depth-layer solid (Passalis et al. on the parametric surface): its certified tessellation
//! closed and within its tolerance of the limit surface, its inside the centres a fine
//! tessellation's winding number puts inside.
#![cfg(all(feature = "vdb", feature = "fixtures"))]

mod common;

use std::path::Path;
use voxelkit::mesh::{GridFit, Mesh, fit_transform};
use voxelkit::progress::Progress;
use voxelkit::solids::exterior_flood::{FloodMethod, solid_from_surface};
use voxelkit::solids::subdivision::{
    Filled, SubdivisionSolid, TESSELLATION_TOLERANCE, subdivision_depth_layer_solid,
    subdivision_solid,
};
use voxelkit::subd::{ControlMesh, LimitSurface, limit_volume};

/// Every closed control mesh of the data folder.
const CLOSED_CONTROL_MESHES: [&str; 12] = [
    "spot_control_mesh",
    "fish_control_mesh",
    "penguin_control_mesh",
    "catmark_cube",
    "catmark_cube_creases1",
    "catmark_gregory_test8",
    "catmark_pyramid",
    "catmark_righthanded",
    "catmark_smoothtris0",
    "catmark_torus",
    "catmark_toroidal_tet",
    "beast",
];

fn load(data: &Path, name: &str) -> ControlMesh {
    ControlMesh::load(&data.join(format!("subd/{name}.obj"))).unwrap()
}

fn solid_at(control: &ControlMesh, resolution: u32) -> (SubdivisionSolid, f64) {
    let t = fit_transform(
        &control.polygon_mesh().bbox(),
        GridFit::Resolution(resolution),
    )
    .unwrap();
    let made =
        subdivision_solid(control, t, &Default::default(), 1 << 16, &Progress::none()).unwrap();
    (made, t.voxel_size)
}

/// The tessellations' volumes converge on the quadrature's at second order (the error falls
/// about fourfold per doubling of the segments per patch), creased ones included. Beast is left out: its 32k patches
/// take a minute to tessellate finely; its volume is checked against the voxels below.
#[test]
fn the_limit_volume_is_what_fine_tessellations_converge_to() {
    let Some(data) = common::data_dir() else {
        return;
    };
    for name in CLOSED_CONTROL_MESHES.iter().filter(|&&n| n != "beast") {
        let surface = LimitSurface::new(load(&data, name));
        let exact = limit_volume(&surface);
        let error = |n: usize| {
            let tessellated = surface.tessellate(|_| n).signed_volume();
            (exact - tessellated).abs() / exact.abs()
        };
        // Creases of sharpness 5 bend the surface within 2^-5 of a patch's edge: the
        // tessellations converge once their segments are finer than that.
        let n = if surface.control().tags.is_empty() {
            8
        } else {
            64
        };
        let errors = [error(n), error(2 * n), error(4 * n)];
        eprintln!("{name}: limit volume {exact:.9}; tessellation errors {errors:?}");
        assert!(errors[2] < 2e-3, "{name}: {errors:?}");
        assert!(
            errors[1] < errors[0] / 3.0 && errors[2] < errors[1] / 3.0,
            "{name}: {errors:?}"
        );
    }
}

#[test]
fn seeded_solids_hold_the_limit_volume_and_equal_the_exterior_flood() {
    let Some(data) = common::data_dir() else {
        return;
    };
    for name in CLOSED_CONTROL_MESHES {
        let control = load(&data, name);
        let area = voxelkit::subd::limit_area(&LimitSurface::new(control.clone()));
        for resolution in [64, 128, 256] {
            let (made, h) = solid_at(&control, resolution);
            let m = made.solid.measures;
            let exact = made.limit_volume;
            let Filled::Seeds {
                seeds,
                outside_seeds,
            } = made.filled
            else {
                panic!("a seeded solid");
            };
            eprintln!(
                "{name} {resolution}: limit volume {exact:.6} in {:.6} .. {:.6} (area x h {:.6}); \
                 {seeds} seeds, {outside_seeds} outside",
                m.volume_inside,
                m.volume_with_surface,
                area * h,
            );
            assert!(m.volume_inside <= exact && exact <= m.volume_with_surface);
            assert!(exact - m.volume_inside <= area * h, "{name} {resolution}");
            assert!(
                m.volume_with_surface - exact <= area * h,
                "{name} {resolution}"
            );
            let exterior =
                solid_from_surface(&made.surface.surface, FloodMethod::Spans, &Progress::none())
                    .unwrap();
            let unseeded =
                exterior.inside.voxel_count() as i64 - made.solid.inside.voxel_count() as i64;
            assert_eq!(unseeded, 0, "{name} {resolution}");
            assert!(
                made.solid
                    .inside
                    .voxels()
                    .all(|c| exterior.inside.contains(c)),
                "{name} {resolution}"
            );
        }
    }
}

#[test]
fn inward_control_meshes_fill_the_same_and_open_ones_are_refused() {
    let Some(data) = common::data_dir() else {
        return;
    };
    let control = load(&data, "catmark_torus");
    let mesh = control.polygon_mesh();
    let reversed: Vec<Vec<u32>> = (0..mesh.face_count())
        .map(|f| mesh.face(f).iter().rev().copied().collect())
        .collect();
    let inward = ControlMesh::from_mesh(&Mesh::from_polygons(
        "inward",
        mesh.positions.clone(),
        &reversed,
    ))
    .unwrap();
    let (a, _) = solid_at(&control, 96);
    let (b, _) = solid_at(&inward, 96);
    assert_eq!(a.solid.inside.voxel_count(), b.solid.inside.voxel_count());
    assert!((a.limit_volume - b.limit_volume).abs() < 1e-9 * a.limit_volume);
    let open = load(&data, "catmark_pawn");
    assert!(!open.is_closed());
    let t = fit_transform(&open.polygon_mesh().bbox(), GridFit::Resolution(32)).unwrap();
    let err = subdivision_solid(&open, t, &Default::default(), 1024, &Progress::none())
        .err()
        .unwrap()
        .to_string();
    assert!(
        err.contains("catmark_pawn") && err.contains("closed"),
        "{err}"
    );
}

/// Booleans of two subdivision solids on one grid: the difference holds |A| - |A ∩ B|, and A
/// alone holds its limit volume within area x h.
#[test]
fn csg_trees_take_subdivision_leaves() {
    let Some(data) = common::data_dir() else {
        return;
    };
    use voxelkit::pipeline::{CsgSource, Details, Job, Task};
    let dir = tempfile::tempdir().unwrap();
    let a = data.join("subd/catmark_torus.obj");
    let b = data.join("subd/catmark_cube.obj");
    let (a, b) = (a.display(), b.display());
    let volume = |tree: String| {
        let path = dir.path().join("tree.json");
        let text = format!(
            r#"{{"resolution": 96, "bounds": {{"min": [-2, -2, -2], "max": [2, 2, 2]}}, "tree": {tree}}}"#
        );
        std::fs::write(&path, text).unwrap();
        let task = Task::CsgTree(CsgSource::File(path));
        let outcome = Job::new(task, GridFit::Resolution(96))
            .run(&voxelkit::progress::Unobserved)
            .unwrap();
        let Details::Csg(c) = outcome.report.details else {
            panic!("a CSG report");
        };
        c.volume
    };
    let va = volume(format!(r#"{{"subdiv": "{a}"}}"#));
    let both = volume(format!(
        r#"{{"intersection": [{{"subdiv": "{a}"}}, {{"subdiv": "{b}"}}]}}"#
    ));
    let minus = volume(format!(
        r#"{{"difference": [{{"subdiv": "{a}"}}, {{"subdiv": "{b}"}}]}}"#
    ));
    eprintln!("|A| {va}, |A n B| {both}, |A - B| {minus}");
    assert!(both > 0.0 && both < va);
    assert!(
        (minus - (va - both)).abs() <= 1e-9 * va,
        "{minus} vs {va} - {both}"
    );
    let exact = limit_volume(&LimitSurface::new(
        ControlMesh::load(&data.join("subd/catmark_torus.obj")).unwrap(),
    ))
    .abs();
    let h = 4.0 / 96.0;
    let area = voxelkit::subd::limit_area(&LimitSurface::new(
        ControlMesh::load(&data.join("subd/catmark_torus.obj")).unwrap(),
    ));
    assert!((va - exact).abs() <= area * h, "{va} vs {exact}");
}

/// The certified tessellation depth layers run on: closed and consistently oriented (every
/// edge in two triangles, once each way), every limit point sampled at random within its
/// tolerance of it, and its volume within area x tolerance of the limit volume.
#[test]
fn certified_tessellations_are_closed_and_within_their_tolerance() {
    let Some(data) = common::data_dir() else {
        return;
    };
    use voxelkit::mesh::winding::WindingTree;
    use voxelkit::subd::certified_tessellation;
    for name in CLOSED_CONTROL_MESHES {
        let control = load(&data, name);
        let b = control.bbox();
        let tolerance = TESSELLATION_TOLERANCE * (b.max - b.min).max_element() / 128.0;
        let surface = LimitSurface::new(control);
        let t = certified_tessellation(&surface, tolerance, u64::MAX, &Progress::none()).unwrap();
        let mesh = &t.mesh;
        let mut edges = std::collections::HashMap::new();
        for (_, [a, b, c]) in mesh.triangles() {
            for (p, q) in [(a, b), (b, c), (c, a)] {
                *edges.entry((p, q)).or_insert(0u32) += 1;
            }
        }
        let unmatched = edges
            .iter()
            .filter(|&(&(p, q), &n)| n != 1 || edges.get(&(q, p)) != Some(&1))
            .count();
        assert_eq!(
            unmatched, 0,
            "{name}: {unmatched} edges not shared once each way"
        );
        let tree = WindingTree::new(mesh);
        let mut farthest = 0.0f64;
        for (face, u, v) in surface.random_parameters(64, 7) {
            let p = surface.evaluate(face, u, v).unwrap().position;
            farthest = farthest.max(tree.distance(p));
        }
        let exact = limit_volume(&surface);
        let area = voxelkit::subd::limit_area(&surface);
        let volume_error = (mesh.signed_volume() - exact).abs();
        eprintln!(
            "{name}: {} triangles, level {} at most; limit points within {:.3} of the \
             tolerance; volume off by {:.3} of area x tolerance",
            mesh.triangle_count(),
            t.deepest,
            farthest / tolerance,
            volume_error / (area * tolerance)
        );
        assert!(farthest < tolerance, "{name}: {farthest} > {tolerance}");
        assert!(volume_error < area * tolerance, "{name}");
    }
}

/// The depth-layer solid of every closed control mesh at 64 (some at 128) holds exactly the centres
/// off the enclosing surface that the winding number of a fine tessellation (not the
/// certified one) puts inside, plus the surface; the seeded flood's solid holds them too,
/// with at most pockets of outside centres the enclosing surface walls in.
#[test]
fn depth_layer_solids_are_the_centres_inside_the_limit_surface() {
    let Some(data) = common::data_dir() else {
        return;
    };
    use voxelkit::mesh::winding::WindingTree;
    for name in CLOSED_CONTROL_MESHES {
        let control = load(&data, name);
        let surface = LimitSurface::new(control.clone());
        let segments = (512.0 / (surface.patch_count() as f64).sqrt()).clamp(4.0, 64.0) as usize;
        let reference = WindingTree::new(&surface.tessellate(|_| segments));
        // 128 as well where creases and extraordinary corners crowd the tessellation.
        let resolutions: &[u32] = match name {
            "spot_control_mesh" | "catmark_cube_creases1" | "beast" => &[64, 128],
            _ => &[64],
        };
        for &resolution in resolutions {
            let t = fit_transform(
                &control.polygon_mesh().bbox(),
                GridFit::Resolution(resolution),
            )
            .unwrap();
            let made = subdivision_depth_layer_solid(
                &control,
                t,
                &Default::default(),
                u64::MAX,
                &Progress::none(),
            )
            .unwrap();
            let Filled::DepthLayers {
                triangles,
                by_winding_number,
                ..
            } = made.filled
            else {
                panic!("a depth-layer solid");
            };
            let shell = &made.surface.surface;
            let bbox = shell.bbox().unwrap();
            let mut expected = 0u64;
            let mut wrong = Vec::new();
            for x in bbox.min[0]..=bbox.max[0] {
                for y in bbox.min[1]..=bbox.max[1] {
                    for z in bbox.min[2]..=bbox.max[2] {
                        let c = [x, y, z];
                        if shell.contains(c) {
                            continue;
                        }
                        let w = reference.winding_number(t.index_to_world(c)).abs();
                        let inside = w >= 0.5;
                        expected += u64::from(inside);
                        if inside != made.solid.inside.contains(c) {
                            wrong.push((c, w));
                        }
                    }
                }
            }
            let (seeded, _) = solid_at(&control, resolution);
            let walled_in =
                seeded.solid.inside.voxel_count() as i64 - made.solid.inside.voxel_count() as i64;
            eprintln!(
                "{name} {resolution}: {} inside ({expected} by the winding number), {triangles} \
                 triangles, {by_winding_number} undecided by the layers; the seeded flood \
                 holds {walled_in} more",
                made.solid.inside.voxel_count()
            );
            assert!(
                wrong.is_empty(),
                "{name} {resolution}: {:?}",
                &wrong[..wrong.len().min(5)]
            );
            assert!(
                made.solid
                    .inside
                    .voxels()
                    .all(|c| seeded.solid.inside.contains(c)),
                "{name} {resolution}"
            );
            assert!(walled_in >= 0, "{name} {resolution}");
        }
    }
}

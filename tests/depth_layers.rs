//! Depth-layer solids (Passalis et al.) against the exact inside test, on the closed meshes of
//! the data folder and on generated fixtures: the G whose hollow no axis sees, spheres in a
//! hollow box (unclassifiable), and open meshes (reported, never filled or left hollow).
#![cfg(feature = "fixtures")]

mod common;

use glam::DVec3;
use voxelkit::grid::{CoordBox, DenseMask, SparseGrid, Transform};
use voxelkit::mesh::inside::inside_centres;
use voxelkit::mesh::{GridFit, Mesh, fit_transform, generate, index_box};
use voxelkit::solids::depth_layers::{
    DepthLayerOptions, DepthLayerSolid, DirectionSet, Layers, Unclassified, depth_layer_solid,
};
use voxelkit::voxelize::Separability;
use voxelkit::voxelize::separating::{SeparatingOptions, voxelize_mesh};

fn solid(mesh: &Mesh, t: &Transform, directions: usize, layers: Layers) -> DepthLayerSolid {
    solid_by(mesh, t, directions, layers, Unclassified::NoDirection)
}

fn solid_by(
    mesh: &Mesh,
    t: &Transform,
    directions: usize,
    layers: Layers,
    unclassified: Unclassified,
) -> DepthLayerSolid {
    let options = DepthLayerOptions {
        directions: DirectionSet::first(directions).unwrap(),
        layers,
        unclassified,
    };
    solid_in(mesh, t, index_box(&mesh.bbox(), t), &options)
}

fn solid_in(
    mesh: &Mesh,
    t: &Transform,
    bbox: CoordBox,
    options: &DepthLayerOptions,
) -> DepthLayerSolid {
    depth_layer_solid(
        mesh,
        t,
        bbox,
        options,
        &voxelkit::progress::Progress::none(),
    )
    .unwrap()
}

fn surface(mesh: &Mesh, t: Transform) -> SparseGrid {
    let options = SeparatingOptions {
        separability: Separability::TwentySix,
        ..Default::default()
    };
    voxelize_mesh(mesh, t, &options, &voxelkit::progress::Progress::none())
        .unwrap()
        .0
}

/// (classified voxels off the surface that disagree with the exact test, unclassified ones).
fn disagreement(mesh: &Mesh, t: &Transform, s: &DepthLayerSolid) -> (u64, u64) {
    let exact = inside_centres(mesh, t, s.inside.bbox).unwrap();
    let surface = DenseMask::from_grid(&surface(mesh, *t), s.inside.bbox).unwrap();
    let (mut wrong, mut unclassified) = (0, 0);
    for i in 0..exact.len() {
        if surface.get_index(i) {
            continue;
        }
        if s.unclassified.get_index(i) {
            unclassified += 1;
        } else if s.inside.get_index(i) != exact.get_index(i) {
            wrong += 1;
        }
    }
    (wrong, unclassified)
}

#[test]
fn closed_meshes_match_ray_parity_off_the_surface() {
    let Some(data) = common::data_dir() else {
        return;
    };
    for name in common::CLOSED_MESHES {
        let mesh = Mesh::load(&data.join(format!("meshes/{name}.obj"))).unwrap();
        for resolution in [64, 128, 256] {
            let t = fit_transform(&mesh.bbox(), GridFit::Resolution(resolution)).unwrap();
            for directions in [3, 16] {
                let s = solid(&mesh, &t, directions, Layers::Double);
                assert_eq!(s.stats.odd_rays(), 0, "{name}: closed, yet odd counts");
                let (wrong, unclassified) = disagreement(&mesh, &t, &s);
                eprintln!(
                    "{name} {resolution} {directions} directions: {} inside, {wrong} wrong, {unclassified} unclassified off the surface",
                    s.stats.inside_voxels
                );
                assert_eq!(
                    wrong, 0,
                    "{name} {resolution} {directions}: {wrong} disagree"
                );
                if directions == 16 {
                    assert_eq!(
                        unclassified, 0,
                        "{name} {resolution}: 16 directions leave some"
                    );
                }
            }
        }
    }
}

/// Voxels whose centre lies in the G's hollow.
fn hollow_voxels(s: &DepthLayerSolid, t: &Transform) -> Vec<usize> {
    let cells = generate::g_hollow_cells();
    (0..s.inside.len())
        .filter(|&i| {
            let p = t.index_to_world(s.inside.coord(i));
            cells
                .iter()
                .any(|(lo, hi)| p.cmpgt(*lo).all() && p.cmplt(*hi).all())
        })
        .collect()
}

#[test]
fn the_g_between_plates_is_wrong_with_six_buffers_and_right_with_double_layers() {
    let mesh = generate::g_between_plates();
    for resolution in [64, 128] {
        let t = fit_transform(&mesh.bbox(), GridFit::Resolution(resolution)).unwrap();
        let six = solid(&mesh, &t, 3, Layers::Single);
        let double = solid(&mesh, &t, 3, Layers::Double);
        let hollow = hollow_voxels(&six, &t);
        assert!(
            hollow.len() > 1000,
            "{resolution}: {} hollow voxels",
            hollow.len()
        );
        let filled = hollow.iter().filter(|&&i| six.inside.get_index(i)).count();
        let (wrong_six, _) = disagreement(&mesh, &t, &six);
        let (wrong_double, unclassified) = disagreement(&mesh, &t, &double);
        eprintln!(
            "G {resolution}: {} hollow voxels; six buffers fill {filled} ({wrong_six} wrong off the surface); double layers: {wrong_double} wrong, {unclassified} unclassified",
            hollow.len()
        );
        // Karabassi fills the part of the hollow no axis sees (below the G's bar).
        assert!(
            filled * 3 > hollow.len(),
            "{resolution}: six buffers filled only {filled}"
        );
        assert!(wrong_six as usize >= filled / 2);
        assert!(hollow.iter().all(|&i| !double.inside.get_index(i)));
        assert_eq!((wrong_double, unclassified), (0, 0));
    }
}

#[test]
fn spheres_in_a_hollow_box_are_unclassifiable_not_guessed() {
    let mesh = generate::spheres_in_box();
    let t = fit_transform(&mesh.bbox(), GridFit::Resolution(96)).unwrap();
    let exact = |s: &DepthLayerSolid| inside_centres(&mesh, &t, s.inside.bbox).unwrap();
    for directions in [3, 16] {
        let s = solid(&mesh, &t, directions, Layers::Double);
        let exact = exact(&s);
        let in_sphere = |i: usize| {
            let p = t.index_to_world(s.inside.coord(i));
            [DVec3::new(-0.35, -0.3, 0.0), DVec3::new(0.35, 0.3, 0.1)]
                .iter()
                .any(|c| p.distance(*c) < 0.29)
        };
        let (mut sphere, mut sphere_unclassified, mut wrong) = (0, 0, 0);
        for i in 0..exact.len() {
            if in_sphere(i) {
                sphere += 1;
                sphere_unclassified += s.unclassified.get_index(i) as u64;
            }
            if !s.unclassified.get_index(i) && s.inside.get_index(i) != exact.get_index(i) {
                wrong += 1;
            }
        }
        eprintln!(
            "spheres in a box, {directions} directions: {sphere_unclassified} of {sphere} sphere voxels unclassified, {} unclassified in all, {wrong} classified wrongly",
            s.stats.unclassified_voxels
        );
        assert!(sphere > 10_000);
        assert_eq!(sphere_unclassified, sphere, "a sphere voxel was guessed");
        assert_eq!(s.stats.odd_rays(), 0);
        assert!(s.stats.per_direction.iter().all(|c| c.more > 0));
    }
}

#[test]
fn open_meshes_are_reported_never_filled_or_left_hollow() {
    let Some(data) = common::data_dir() else {
        return;
    };
    for name in ["cube_no_bottom", "stanford-bunny", "teapot"] {
        let mesh = Mesh::load(&data.join(format!("meshes/{name}.obj"))).unwrap();
        let t = fit_transform(&mesh.bbox(), GridFit::Resolution(128)).unwrap();
        let s = solid(&mesh, &t, 16, Layers::Double);
        eprintln!(
            "{name}: {} odd rays, {} unclassified voxels ({} on odd rays), {} inside",
            s.stats.odd_rays(),
            s.stats.unclassified_voxels,
            s.stats.open_voxels,
            s.stats.inside_voxels
        );
        assert!(s.stats.odd_rays() > 0, "{name}: open, yet no odd count");
        assert!(s.stats.open_voxels > 0, "{name}: nothing reported");
    }
    // The open box: every voxel centre strictly inside it is unclassifiable.
    let mesh = Mesh::load(&data.join("meshes/cube_no_bottom.obj")).unwrap();
    let t = fit_transform(&mesh.bbox(), GridFit::Resolution(64)).unwrap();
    let s = solid(&mesh, &t, 16, Layers::Double);
    let mut interior = 0;
    for i in 0..s.inside.len() {
        let p = t.index_to_world(s.inside.coord(i));
        if p.abs().max_element() < 0.99 {
            interior += 1;
            assert!(
                s.unclassified.get_index(i),
                "{:?} decided",
                s.inside.coord(i)
            );
        }
    }
    assert!(interior > 200_000);
}

/// Passalis et al.'s rule (unclassified when any direction counts more than four crossings)
/// marks every voxel today's rule marks, and more: on the spheres in a hollow box, voxels of
/// the walls' gap whose z ray meets a sphere are decided by x or y today.
#[test]
fn the_papers_rule_marks_more_voxels_unclassified_never_fewer() {
    let mesh = generate::spheres_in_box();
    let t = fit_transform(&mesh.bbox(), GridFit::Resolution(96)).unwrap();
    for directions in [3, 16] {
        let today = solid_by(
            &mesh,
            &t,
            directions,
            Layers::Double,
            Unclassified::NoDirection,
        );
        let paper = solid_by(&mesh, &t, directions, Layers::Double, Unclassified::Paper);
        let exact = inside_centres(&mesh, &t, paper.inside.bbox).unwrap();
        for i in 0..paper.inside.len() {
            assert!(
                !today.unclassified.get_index(i) || paper.unclassified.get_index(i),
                "{directions}: {:?} unclassified today only",
                paper.inside.coord(i)
            );
            if !paper.unclassified.get_index(i) {
                assert_eq!(
                    paper.inside.get_index(i),
                    exact.get_index(i),
                    "{directions}"
                );
            }
        }
        eprintln!(
            "spheres in a box, {directions} directions: {} unclassified by the paper's rule, {} today",
            paper.stats.unclassified_voxels, today.stats.unclassified_voxels
        );
        assert!(paper.stats.unclassified_voxels > today.stats.unclassified_voxels);
    }
}

/// Single layers (Karabassi et al. generalised to N directions, §3.1): a voxel is inside when
/// it lies between the first and last crossing along every direction, so every direction
/// added can only remove voxels, and the true inside always stays. The trefoil's pockets the
/// axes miss are emptied by 8 directions; the G between plates keeps its hollow, which no
/// direction sees.
#[test]
fn single_layers_with_more_directions_shrink_towards_the_inside() {
    let fixtures = [
        ("g shape", generate::g_shape()),
        ("g between plates", generate::g_between_plates()),
        ("random", generate::random_closed(3)),
        ("trefoil", generate::trefoil(1.0, 0.3, 96, 16)),
    ];
    for (name, mesh) in &fixtures {
        let t = fit_transform(&mesh.bbox(), GridFit::Resolution(80)).unwrap();
        let by = |n| solid(mesh, &t, n, Layers::Single);
        let (three, eight, sixteen) = (by(3), by(8), by(16));
        let exact = inside_centres(mesh, &t, three.inside.bbox).unwrap();
        let shell = DenseMask::from_grid(&surface(mesh, t), three.inside.bbox).unwrap();
        for i in 0..exact.len() {
            let (a, b, c) = (
                three.inside.get_index(i),
                eight.inside.get_index(i),
                sixteen.inside.get_index(i),
            );
            assert!(!c || b, "{name}: 16 directions keep a voxel 8 drop");
            assert!(!b || a, "{name}: 8 directions keep a voxel 3 drop");
            if exact.get_index(i) && !shell.get_index(i) {
                assert!(c, "{name} {:?}: inside, dropped by 16", exact.coord(i));
            }
        }
        let counts = [&three, &eight, &sixteen].map(|s| s.stats.inside_voxels);
        eprintln!(
            "{name}: single layers fill {counts:?} with 3, 8, 16 directions, exact {}",
            exact.count()
        );
        if *name == "trefoil" {
            // The knot's loops hide pockets from the axes that the diagonals see.
            assert!(
                counts[1] < counts[0] && counts[2] == exact.count(),
                "{counts:?}"
            );
        }
    }
}

/// §3.1's arbitrary directions: the user's own integer directions classify exactly like the
/// built-in ones (every decided voxel off the surface agrees with the exact test), and
/// directions the rays cannot follow through voxel centres, or parallel ones, are refused.
#[test]
fn user_directions_classify_exactly_and_bad_ones_are_refused() {
    let mesh = generate::g_between_plates();
    let t = fit_transform(&mesh.bbox(), GridFit::Resolution(80)).unwrap();
    let bbox = index_box(&mesh.bbox(), &t);
    for list in [
        vec![[1, 2, 0], [0, 1, 3], [2, -3, 1]],
        vec![[0, 1, 0], [3, 1, 2]],
        vec![[1, 1, 1]],
    ] {
        for layers in [Layers::Double, Layers::Single] {
            let options = DepthLayerOptions {
                directions: DirectionSet::given(&list).unwrap(),
                layers,
                ..Default::default()
            };
            let s = solid_in(&mesh, &t, bbox, &options);
            assert_eq!(s.stats.per_direction.len(), list.len());
            let (wrong, unclassified) = disagreement(&mesh, &t, &s);
            eprintln!("{list:?} {layers:?}: {wrong} wrong, {unclassified} unclassified");
            if layers == Layers::Double {
                assert_eq!(wrong, 0, "{list:?}");
            } else {
                // Single layers fill what no direction sees, never empty the inside.
                let exact = inside_centres(&mesh, &t, bbox).unwrap();
                assert!((0..exact.len()).all(|i| !exact.get_index(i) || s.inside.get_index(i)));
            }
        }
    }
    for (bad, why) in [
        (vec![[2, 3, 5]], "component of 1 or -1"),
        (vec![[1, 2, 0], [-1, -2, 0]], "parallel"),
        (vec![[0, 0, 0]], "component of 1 or -1"),
        (vec![], "1 to 16"),
    ] {
        let e = DirectionSet::given(&bad).unwrap_err().to_string();
        assert!(e.contains(why), "{bad:?}: {e}");
    }
}

/// One tie rule (`mesh::crossings`): an L-shaped prism whose faces all lie on planes of voxel
/// centres (and, shifted half a voxel, none does). Single layers, double layers (along the
/// axes, and along all sixteen directions) and ray parity agree on every voxel, surface
/// voxels included, and on the exact count: a centre is inside where the point just off it,
/// `c + (e, e^2, e^3)`, is, so each cube of 8^3 voxels holds 512 centres however it is placed.
#[test]
fn single_layers_double_layers_and_parity_share_one_tie_rule() {
    let cells = [
        [0, 0, 0],
        [1, 0, 0],
        [2, 0, 0],
        [0, 0, 1],
        [0, 1, 0],
        [1, 1, 0],
        [2, 1, 0],
        [0, 1, 1],
    ];
    let mesh = generate::polycube("L-prism", &cells, 8.0);
    for offset in [0.0, 0.5] {
        let t = Transform::new(DVec3::splat(offset), 1.0);
        let bbox = voxelkit::ops::flood::padded(index_box(&mesh.bbox(), &t), 2);
        let run = |layers: Layers, directions: DirectionSet| {
            let options = DepthLayerOptions {
                directions,
                layers,
                unclassified: Unclassified::NoDirection,
            };
            let s = solid_in(&mesh, &t, bbox, &options);
            assert_eq!(s.stats.unclassified_voxels, 0, "{layers:?} at {offset}");
            s.inside
        };
        let axes = DirectionSet::first(3).unwrap();
        let parity = inside_centres(&mesh, &t, bbox).unwrap();
        let expected = cells.len() as u64 * 512;
        assert_eq!(parity.count(), expected, "parity at offset {offset}");
        for (name, inside) in [
            ("single layers, axes", run(Layers::Single, axes)),
            (
                "single layers, 16 directions",
                run(Layers::Single, DirectionSet::ALL),
            ),
            ("double layers, axes", run(Layers::Double, axes)),
            (
                "double layers, 16 directions",
                run(Layers::Double, DirectionSet::ALL),
            ),
        ] {
            let differing = (0..inside.len())
                .filter(|&i| inside.get_index(i) != parity.get_index(i))
                .count();
            assert_eq!(
                differing,
                0,
                "{name} at offset {offset}: {} inside, parity {}",
                inside.count(),
                parity.count()
            );
        }
    }
}

/// Depth layers on formula sources (`implicit --depth-layers`): every ray's crossings of
/// F = 0 isolated by interval arithmetic, so the solid is exactly the centres where F < 0
/// within the bounds, for Cartesian, spherical and cylindrical formulas, a genus-2 surface,
/// a solid the bounds cut, and a plane through a row of centres (F = 0 there: outside, by the
/// tie rule; the rays lying in it are left undecided, and the z rays decide).
#[test]
fn formula_depth_layers_are_the_centres_where_f_is_negative() {
    use voxelkit::implicit::{Formula, value_at};
    use voxelkit::pipeline::request::{ImplicitRequest, Request};
    use voxelkit::progress::Unobserved;
    let genus_two = "((x^2 + y^2)^2 - x^2 + y^2)^2 + z^2 - 0.01";
    let cases = [
        ("torus", "", 64, [-1.0, 1.0]),
        ("gear", "", 64, [-1.0, 1.0]),
        ("", genus_two, 64, [-1.2, 1.2]),
        ("", "x^2 + y^2 + z^2 - 1.2", 48, [-1.0, 1.0]),
        ("", "z - 0.015625", 64, [-1.0, 1.0]),
    ];
    for (example, text, resolution, [lo, hi]) in cases {
        let (text, coords) = match voxelkit::implicit::examples::EXAMPLES
            .iter()
            .find(|e| e.name == example)
        {
            Some(e) => (e.formula.to_string(), e.coordinates),
            None => (text.to_string(), voxelkit::implicit::Coordinates::Cartesian),
        };
        let request = ImplicitRequest {
            coords,
            bounds: voxelkit::pipeline::request::Bounds::Cube([lo, hi]),
            resolution,
            depth_layers: true,
            ..ImplicitRequest::default()
        };
        let job = request.job(text.clone(), &Default::default()).unwrap();
        let outcome = job.plan().unwrap().run(&Unobserved).unwrap();
        let t = outcome.grid.transform;
        let formula = Formula::parse_in(&text, coords, Default::default()).unwrap();
        let mut expected = Vec::new();
        for i in 0..resolution as i64 {
            for j in 0..resolution as i64 {
                for k in 0..resolution as i64 {
                    let p = t.index_to_world([i, j, k]);
                    if value_at(&formula, p.to_array(), false) < 0.0 {
                        expected.push([i, j, k]);
                    }
                }
            }
        }
        let mut got: Vec<[i64; 3]> = outcome.grid.voxels().collect();
        got.sort();
        expected.sort();
        assert_eq!(got.len(), expected.len(), "{text}");
        assert!(
            got == expected,
            "{text}: the solid differs from F < 0 at the centres"
        );
        let unclassified = outcome
            .extra
            .iter()
            .find(|(n, _)| n == "unclassified")
            .map_or(0, |(_, g)| g.voxel_count());
        assert_eq!(unclassified, 0, "{text}");
    }
}

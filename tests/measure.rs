//! Measuring solids: the exact volume of a closed mesh lies between the inside voxels and the
//! inside plus surface voxels, and the bracket closes as the resolution grows; genus from the
//! Euler characteristic of the voxel solid; volume and face-weighted area of exact solids
//! (formulas) converging to their known values.
#![cfg(feature = "fixtures")]

use glam::DVec3;
use voxelkit::grid::{Adjacency, DenseMask};
use voxelkit::implicit::reference::reference_solids;
use voxelkit::mesh::{GridFit, Mesh, fit_transform, generate};
use voxelkit::ops::flood::{flood_from_border, padded};
use voxelkit::ops::measure::SolidMeasures;
use voxelkit::ops::topology::{components, euler_characteristic};
use voxelkit::solids::csg_leaves::measure_formula_solid;
use voxelkit::voxelize::Separability;
use voxelkit::voxelize::separating::{SeparatingOptions, voxelize_mesh};

/// (inside, surface) of a 26-separating voxelization of `mesh`.
fn solid(mesh: &Mesh, resolution: u32) -> (DenseMask, DenseMask, f64) {
    let t = fit_transform(&mesh.bbox(), GridFit::Resolution(resolution)).unwrap();
    let options = SeparatingOptions {
        separability: Separability::TwentySix,
        ..Default::default()
    };
    let (grid, _) =
        voxelize_mesh(mesh, t, &options, &voxelkit::progress::Progress::none()).unwrap();
    let bbox = padded(grid.bbox().unwrap(), 2);
    let surface = DenseMask::from_grid(&grid, bbox).unwrap();
    let exterior = flood_from_border(&surface, Adjacency::TwentySix).unwrap();
    let mut inside = DenseMask::new(bbox).unwrap();
    for i in 0..inside.len() {
        if !surface.get_index(i) && !exterior.get_index(i) {
            inside.set_index(i);
        }
    }
    (inside, surface, t.voxel_size)
}

#[test]
fn volume_is_bracketed_and_converges() {
    let shapes = [
        ("sphere", generate::icosphere(DVec3::ZERO, 1.0, 5)),
        ("torus", generate::torus(DVec3::ZERO, 1.0, 0.35, 64, 32)),
        (
            "box",
            generate::cuboid(DVec3::new(-1.0, -0.5, -0.25), DVec3::new(1.0, 0.5, 0.25)),
        ),
    ];
    for (name, mesh) in shapes {
        let exact = mesh.signed_volume();
        let mut previous = f64::INFINITY;
        for resolution in [32, 64, 128] {
            let (inside, surface, h) = solid(&mesh, resolution);
            let m = SolidMeasures::of(inside.count(), surface.count(), h);
            eprintln!(
                "{name} {resolution}: {:.6} <= {exact:.6} <= {:.6}",
                m.volume_inside, m.volume_with_surface
            );
            assert!(
                m.volume_inside <= exact && exact <= m.volume_with_surface,
                "{name} {resolution}"
            );
            let gap = (m.volume_with_surface - m.volume_inside) / exact;
            assert!(
                gap < previous,
                "{name}: the bracket did not close at {resolution}"
            );
            previous = gap;
            let (low, high) = m.mass(2.0);
            assert_eq!(
                (low, high),
                (2.0 * m.volume_inside, 2.0 * m.volume_with_surface)
            );
        }
    }
}

#[test]
fn genus_of_voxel_solids() {
    for (name, mesh, genus) in [
        ("sphere", generate::icosphere(DVec3::ZERO, 1.0, 4), 0),
        ("torus", generate::torus(DVec3::ZERO, 1.0, 0.35, 48, 24), 1),
    ] {
        let (inside, surface, _) = solid(&mesh, 48);
        let mut all = inside.clone();
        for i in surface.ones() {
            all.set_index(i);
        }
        let g = components(&all, Adjacency::Six) as i64 - euler_characteristic(&all);
        assert_eq!(g, genus, "{name}");
    }
}

#[test]
fn volume_and_area_of_exact_solids_converge() {
    for shape in reference_solids() {
        for resolution in [64, 128, 256] {
            let (volume, area) =
                measure_formula_solid(&shape.formula, &shape.bounds, resolution).unwrap();
            let ev = (volume - shape.volume).abs() / shape.volume;
            let ea = (area - shape.area).abs() / shape.area;
            eprintln!(
                "{} {resolution}: volume {volume:.6} ({ev:.1e}), area {area:.6} ({ea:.1e})",
                shape.name
            );
            // Centre sampling is noisy but first order at worst (the cube's edges add about
            // h per unit of edge length to the area error): bound the errors by h.
            assert!(
                ev < 0.6 / resolution as f64,
                "{} {resolution}: volume",
                shape.name
            );
            assert!(
                ea < 1.0 / resolution as f64,
                "{} {resolution}: area",
                shape.name
            );
        }
    }
}

/// The definition, voxel by voxel: the lattice elements of every cube in hash sets.
fn euler_by_elements(set: &DenseMask) -> i64 {
    let mut elements: [std::collections::HashSet<[i64; 3]>; 4] = Default::default();
    for i in set.ones() {
        let at = set.coord(i);
        for d in 0..27 {
            let e = [2 * at[0] + d / 9, 2 * at[1] + d / 3 % 3, 2 * at[2] + d % 3];
            elements[e.iter().filter(|&&v| v % 2 != 0).count()].insert(e);
        }
    }
    elements[0].len() as i64 - elements[1].len() as i64 + elements[2].len() as i64
        - elements[3].len() as i64
}

/// The definition of components: a flood per component through the adjacency's offsets.
fn components_by_flood(set: &DenseMask, adjacency: Adjacency) -> u64 {
    let mut seen = DenseMask::new(set.bbox).unwrap();
    let mut count = 0;
    for start in set.ones() {
        if seen.get_index(start) {
            continue;
        }
        count += 1;
        seen.set_index(start);
        let mut stack = vec![set.coord(start)];
        while let Some(c) = stack.pop() {
            for d in adjacency.offsets() {
                let n = [c[0] + d[0], c[1] + d[1], c[2] + d[2]];
                if set.bbox.contains(n) && set.get(n) && !seen.get(n) {
                    seen.set(n);
                    stack.push(n);
                }
            }
        }
    }
    count
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(64))]
    /// The word-wise topology equals the definitions on random volumes, rows longer than a
    /// word included.
    #[test]
    fn topology_matches_its_definition(
        seed in 0u64..u64::MAX,
        density in 0.05f64..0.95,
        dims in (1i64..7, 1i64..7, 1i64..140),
    ) {
        let bbox = voxelkit::grid::CoordBox { min: [-3, 2, -70], max: [dims.0 - 4, dims.1 + 1, dims.2 - 71] };
        let mut set = DenseMask::new(bbox).unwrap();
        let mut state = seed | 1;
        for i in 0..set.len() {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            if (state % 1000) as f64 / 1000.0 < density {
                set.set_index(i);
            }
        }
        proptest::prop_assert_eq!(euler_characteristic(&set), euler_by_elements(&set));
        for adjacency in [Adjacency::Six, Adjacency::TwentySix] {
            proptest::prop_assert_eq!(components(&set, adjacency), components_by_flood(&set, adjacency));
        }
    }
}

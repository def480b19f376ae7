//! Lai & Cheng's volume flooding: FloodingXYZ with a bounded GRAYSTACK and its resume sweep,
//! their linear baseline, the fast span flood and the plain flood reach exactly the same
//! voxels; seeds chosen from normals land inside.
#![cfg(feature = "fixtures")]

mod common;

use voxelkit::grid::{Adjacency, CoordBox, DenseMask};
use voxelkit::mesh::generate::SplitMix64;
use voxelkit::mesh::{GridFit, fit_transform, generate};
use voxelkit::ops::flood::{flood, flood_from_border, padded};
use voxelkit::ops::flood_linear::flood_linear;
use voxelkit::ops::flood_spans::flood_spans;
use voxelkit::ops::flood_xyz::flood_xyz;
use voxelkit::ops::seed::seed_from_normals;
use voxelkit::subd::ControlMesh;
use voxelkit::voxelize::parametric::{ParametricOptions, voxelize_subdivision};

fn same(a: &DenseMask, b: &DenseMask) -> bool {
    a.count() == b.count() && a.and_count(b) == a.count()
}

#[test]
fn all_floods_agree_on_random_volumes() {
    let mut rng = SplitMix64(17);
    for round in 0..40 {
        let n = 6 + (round % 5) * 5;
        let bbox = CoordBox {
            min: [0, 0, 0],
            max: [n, n + 3, n - 2],
        };
        let mut blocked = DenseMask::new(bbox).unwrap();
        let density = rng.range(0.2, 0.65);
        for i in 0..blocked.len() {
            if rng.range(0.0, 1.0) < density {
                blocked.set_index(i);
            }
        }
        let seeds: Vec<[i64; 3]> = (0..3)
            .map(|_| [0, 1, 2].map(|a| (rng.range(0.0, 1.0) * bbox.dim()[a] as f64) as i64))
            .collect();
        let mut seed_mask = DenseMask::new(bbox).unwrap();
        for &s in &seeds {
            seed_mask.set(s);
        }
        // From the border, for every adjacency: spans against the plain flood.
        let mut border = DenseMask::new(bbox).unwrap();
        for i in 0..border.len() {
            let c = border.coord(i);
            if (0..3).any(|a| c[a] == bbox.min[a] || c[a] == bbox.max[a]) {
                border.set_index(i);
            }
        }
        for adjacency in [Adjacency::Six, Adjacency::Eighteen, Adjacency::TwentySix] {
            let plain = flood(&blocked, &border, adjacency).unwrap();
            let spans = flood_from_border(&blocked, adjacency).unwrap();
            assert!(
                same(&plain, &spans),
                "round {round}: {adjacency:?} border flood differs"
            );
        }
        let reference = flood(&blocked, &seed_mask, Adjacency::Six).unwrap();
        let spans = flood_spans(&blocked, &seeds, &voxelkit::progress::Progress::none()).unwrap();
        assert!(
            same(&reference, &spans),
            "round {round}: span flood differs"
        );
        let (linear, _) = flood_linear(&blocked, &seeds).unwrap();
        assert!(
            same(&reference, &linear),
            "round {round}: linear flood differs"
        );
        for capacity in [1, 7, 1 << 20] {
            let (xyz, stats) = flood_xyz(
                &blocked,
                &seeds,
                capacity,
                &voxelkit::progress::Progress::none(),
            )
            .unwrap();
            assert!(
                same(&reference, &xyz),
                "round {round}: FloodingXYZ with capacity {capacity} differs"
            );
            if capacity == 1 << 20 {
                assert_eq!(stats.overflows, 0);
            }
        }
    }
}

#[test]
fn a_tiny_stack_needs_sweeps_and_still_fills_everything() {
    let bbox = CoordBox {
        min: [0, 0, 0],
        max: [40, 40, 40],
    };
    let blocked = DenseMask::new(bbox).unwrap();
    let (filled, stats) = flood_xyz(
        &blocked,
        &[[20, 20, 20]],
        4,
        &voxelkit::progress::Progress::none(),
    )
    .unwrap();
    assert_eq!(filled.count(), 41 * 41 * 41);
    assert!(stats.overflows > 0 && stats.sweeps > 1, "{stats:?}");
}

#[test]
fn seeds_from_normals_fill_the_inside_of_a_voxelized_solid() {
    // A generated torus as a Catmull-Clark control mesh, and the shared spot when present.
    let mut controls = vec![
        ControlMesh::from_mesh(&generate::torus(glam::DVec3::ZERO, 1.0, 0.4, 24, 12)).unwrap(),
    ];
    if let Some(data) = common::data_dir() {
        controls.push(ControlMesh::load(&data.join("subd/spot_control_mesh.obj")).unwrap());
    }
    for control in controls {
        let t = fit_transform(&control.polygon_mesh().bbox(), GridFit::Resolution(96)).unwrap();
        let out = voxelize_subdivision(
            &control,
            t,
            &ParametricOptions::default(),
            &voxelkit::progress::Progress::none(),
        )
        .unwrap();
        let choice = seed_from_normals(&out.surface, &out.opposite, false).expect("a seed");
        let bbox = padded(out.surface.bbox().unwrap(), 2);
        let blocked = DenseMask::from_grid(&out.surface, bbox).unwrap();
        // Inside: what neither the surface nor the exterior flood holds.
        let exterior = flood_from_border(&blocked, Adjacency::Six).unwrap();
        let inside = blocked.len() as u64 - blocked.count() - exterior.count();
        assert!(
            !exterior.get(choice.seed),
            "the seed {:?} is outside",
            choice.seed
        );
        let (xyz, stats) = flood_xyz(
            &blocked,
            &[choice.seed],
            4096,
            &voxelkit::progress::Progress::none(),
        )
        .unwrap();
        let spans = flood_spans(
            &blocked,
            &[choice.seed],
            &voxelkit::progress::Progress::none(),
        )
        .unwrap();
        assert!(same(&xyz, &spans));
        assert_eq!(
            xyz.count(),
            inside,
            "{}: {stats:?}",
            control.source.display()
        );
        let outward =
            seed_from_normals(&out.surface, &out.opposite, true).expect("an outside seed");
        assert!(exterior.get(outward.seed));
    }
}

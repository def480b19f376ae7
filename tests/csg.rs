//! Booleans on real voxel grids: the identities hold, counts add up, resampling is exact on
//! aligned grids, and mismatched transforms are refused unless resampling is asked for.
#![cfg(feature = "fixtures")]

mod common;

use glam::DVec3;
use voxelkit::grid::{SparseGrid, Transform};
use voxelkit::mesh::{Aabb, GridFit, Mesh, fit_transform, generate};
use voxelkit::ops::csg::{BooleanOp, combine, resample};
use voxelkit::voxelize::separating::{SeparatingOptions, voxelize_mesh};

fn surfaces() -> Vec<Mesh> {
    let mut meshes = vec![
        generate::icosphere(DVec3::new(0.2, 0.0, 0.0), 0.9, 4),
        generate::torus(DVec3::ZERO, 0.8, 0.3, 48, 24),
    ];
    if let Some(data) = common::data_dir() {
        for name in ["bunny-closed", "spot_triangulated"] {
            meshes.push(Mesh::load(&data.join(format!("meshes/{name}.obj"))).unwrap());
        }
    }
    meshes
}

/// Every mesh voxelized on one grid fitted to all of them.
fn on_one_grid(meshes: &[Mesh], resolution: u32) -> (Vec<SparseGrid>, Transform) {
    let b = meshes.iter().map(|m| m.bbox()).fold(
        Aabb {
            min: DVec3::splat(f64::INFINITY),
            max: DVec3::splat(f64::NEG_INFINITY),
        },
        |a, b| Aabb {
            min: a.min.min(b.min),
            max: a.max.max(b.max),
        },
    );
    let t = fit_transform(&b, GridFit::Resolution(resolution)).unwrap();
    let grids = meshes
        .iter()
        .map(|m| {
            voxelize_mesh(
                m,
                t,
                &SeparatingOptions::default(),
                &voxelkit::progress::Progress::none(),
            )
            .unwrap()
            .0
        })
        .collect();
    (grids, t)
}

#[test]
fn boolean_identities_hold_on_real_grids() {
    let meshes = surfaces();
    let (grids, _) = on_one_grid(&meshes, 128);
    for (i, a) in grids.iter().enumerate() {
        for b in &grids[i + 1..] {
            let op = |x: &SparseGrid, y: &SparseGrid, o| combine(x, y, o, false).unwrap();
            let union = op(a, b, BooleanOp::Union);
            let inter = op(a, b, BooleanOp::Intersection);
            assert_eq!(
                union.voxel_count(),
                op(b, a, BooleanOp::Union).voxel_count()
            );
            assert_eq!(
                op(&union, &op(b, a, BooleanOp::Union), BooleanOp::Difference).voxel_count(),
                0
            );
            assert_eq!(
                union.voxel_count() + inter.voxel_count(),
                a.voxel_count() + b.voxel_count()
            );
            let a_minus_b = op(a, b, BooleanOp::Difference);
            let a_minus_ab = op(a, &inter, BooleanOp::Difference);
            assert_eq!(a_minus_b.voxel_count(), a_minus_ab.voxel_count());
            assert_eq!(
                op(&a_minus_b, &a_minus_ab, BooleanOp::Difference).voxel_count(),
                0
            );
            assert_eq!(
                a_minus_b.voxel_count() + inter.voxel_count(),
                a.voxel_count()
            );
        }
    }
}

#[test]
fn resampling_is_exact_on_aligned_grids_and_required_otherwise() {
    let meshes = surfaces();
    let (grids, t) = on_one_grid(&meshes[..1], 64);
    let a = &grids[0];
    // Half-size voxels, shifted so that no centre of either grid lies on a face of the other
    // (where rounding would decide): each coarse voxel holds eight fine centres.
    let fine = Transform::new(
        t.origin - DVec3::splat(t.voxel_size / 8.0),
        t.voxel_size / 2.0,
    );
    let up = resample(a, fine);
    assert_eq!(up.voxel_count(), 8 * a.voxel_count());
    let down = resample(&up, t);
    assert_eq!(down.voxel_count(), a.voxel_count());
    assert_eq!(
        combine(a, &down, BooleanOp::Difference, false)
            .unwrap()
            .voxel_count(),
        0
    );
    // Different transforms: refused unless resampling is allowed.
    let e = combine(a, &up, BooleanOp::Union, false)
        .unwrap_err()
        .to_string();
    assert!(e.contains("transforms differ"), "{e}");
    let u = combine(a, &up, BooleanOp::Union, true).unwrap();
    assert_eq!(u.voxel_count(), a.voxel_count());
}

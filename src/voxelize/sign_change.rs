//! The naive reference for implicit surfaces: evaluate F at every voxel corner of the grid and
//! keep the voxels whose eight corners do not all have the same sign. It examines every voxel
//! (time grows 8x per doubling) and misses surface pieces that enter a voxel and leave it
//! between corners; the interval octree is measured against it.

use crate::grid::{Channels, SparseGrid, Transform};
use crate::implicit::{Coordinates, Formula, value_at};
use glam::DVec3;
use rayon::prelude::*;

/// The voxels of the grid of `resolution` voxels along the longest side of `[min, max]` (the
/// same grid as the octree's) whose corners change sign; with `both_signs`, also for F written
/// with -r (spherical and cylindrical).
pub fn voxelize_sign_change(
    formula: &Formula,
    min: DVec3,
    max: DVec3,
    resolution: u32,
    both_signs: bool,
) -> SparseGrid {
    let h = (max - min).max_element() / resolution as f64;
    let cells = ((max - min) / h).ceil().as_i64vec3();
    let transform = Transform::new(min + DVec3::splat(h / 2.0), h);
    let signs = |k: i64, negative: bool| -> Vec<bool> {
        let mut out = Vec::with_capacity(((cells.x + 1) * (cells.y + 1)) as usize);
        for j in 0..=cells.y {
            for i in 0..=cells.x {
                let p = min + DVec3::new(i as f64, j as f64, k as f64) * h;
                out.push(value_at(formula, p.to_array(), negative) < 0.0);
            }
        }
        out
    };
    let passes: Vec<bool> = if both_signs && formula.coordinates != Coordinates::Cartesian {
        vec![false, true]
    } else {
        vec![false]
    };
    (0..cells.z)
        .into_par_iter()
        .fold(
            || SparseGrid::new(transform, Channels::NONE),
            |mut grid, k| {
                for &negative in &passes {
                    let (below, above) = (signs(k, negative), signs(k + 1, negative));
                    let at =
                        |layer: &[bool], i: i64, j: i64| layer[(j * (cells.x + 1) + i) as usize];
                    for j in 0..cells.y {
                        for i in 0..cells.x {
                            let first = at(&below, i, j);
                            let mixed = [(0, 0), (1, 0), (0, 1), (1, 1)].iter().any(|&(di, dj)| {
                                at(&below, i + di, j + dj) != first
                                    || at(&above, i + di, j + dj) != first
                            });
                            if mixed {
                                grid.insert([i, j, k]);
                            }
                        }
                    }
                }
                grid
            },
        )
        .reduce(
            || SparseGrid::new(transform, Channels::NONE),
            |mut a, b| {
                a.union(&b);
                a
            },
        )
}

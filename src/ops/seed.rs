//! Lai & Cheng's seed selection (§6.1): from a surface voxel, step one voxel along the axis
//! direction most opposed to its normal; if that voxel is not a surface voxel it lies inside
//! (or, stepping along the normal, outside). Voxels crossed by sheets with disagreeing normals
//! are never used as start voxels.

use crate::grid::{Coord, SparseGrid};

/// A start voxel on the surface and the seed found from it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SeedChoice {
    pub start: Coord,
    pub seed: Coord,
}

const AXES: [[i64; 3]; 6] = [
    [1, 0, 0],
    [-1, 0, 0],
    [0, 1, 0],
    [0, -1, 0],
    [0, 0, 1],
    [0, 0, -1],
];

/// The first seed the rule finds: inside (against the normal) or, with `outward`, outside.
/// `surface` must carry normals; `None` when no start voxel gives one.
pub fn seed_from_normals(
    surface: &SparseGrid,
    opposite: &SparseGrid,
    outward: bool,
) -> Option<SeedChoice> {
    for leaf in surface.leaves() {
        let normals = leaf.normal.as_ref()?;
        for n in leaf.offsets() {
            let normal = normals[n];
            if normal == [0.0; 3] {
                continue;
            }
            let start = crate::grid::offset_coord(leaf.origin, n);
            if opposite.contains(start) {
                continue;
            }
            let score = |d: &[i64; 3]| {
                let dot = normal[0] as f64 * d[0] as f64
                    + normal[1] as f64 * d[1] as f64
                    + normal[2] as f64 * d[2] as f64;
                if outward { -dot } else { dot }
            };
            let d = AXES
                .iter()
                .min_by(|a, b| score(a).total_cmp(&score(b)))
                .expect("six axes");
            let seed = [start[0] + d[0], start[1] + d[1], start[2] + d[2]];
            if !surface.contains(seed) {
                return Some(SeedChoice { start, seed });
            }
        }
    }
    None
}

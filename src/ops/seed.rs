//! Lai & Cheng's seed selection (§6.1): from a surface voxel, step one voxel along the axis
//! direction most opposed to its normal; if that voxel is not a surface voxel it lies inside
//! (or, stepping along the normal, outside). For whole solids every axis direction on the
//! inner side of the normal is tried, the most opposed first. Voxels crossed by sheets with disagreeing normals
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
    seeds_along(surface, opposite, outward, 1).next()
}

/// Every seed the rule finds: from each start voxel, the first empty voxel along each axis
/// direction on the inner side of its normal (or, with `outward`, the outer side), the most
/// opposed first, so that each pocket of a solid that the surface voxels cut apart gets its
/// own seeds.
pub fn seeds_from_normals<'a>(
    surface: &'a SparseGrid,
    opposite: &'a SparseGrid,
    outward: bool,
) -> impl Iterator<Item = SeedChoice> + 'a {
    seeds_along(surface, opposite, outward, 3)
}

/// Seeds from every start voxel along its `axes` most opposed axis directions (those on the
/// inner side of the normal only).
fn seeds_along<'a>(
    surface: &'a SparseGrid,
    opposite: &'a SparseGrid,
    outward: bool,
    axes: usize,
) -> impl Iterator<Item = SeedChoice> + 'a {
    surface.leaves().iter().flat_map(move |leaf| {
        let normals = leaf.normal.as_deref();
        leaf.offsets().flat_map(move |n| {
            let mut found = Vec::new();
            let Some(normal) = normals.map(|v| v[n]).filter(|v| *v != [0.0; 3]) else {
                return found;
            };
            let start = crate::grid::offset_coord(leaf.origin, n);
            if opposite.contains(start) {
                return found;
            }
            // Along the normal is outward: inward seeds lie where the dot is negative.
            let score = |d: &[i64; 3]| {
                let dot = normal[0] as f64 * d[0] as f64
                    + normal[1] as f64 * d[1] as f64
                    + normal[2] as f64 * d[2] as f64;
                if outward { -dot } else { dot }
            };
            let mut inner: Vec<&[i64; 3]> = AXES.iter().filter(|d| score(d) < 0.0).collect();
            inner.sort_by(|a, b| score(a).total_cmp(&score(b)));
            for d in inner.into_iter().take(axes) {
                let seed = [start[0] + d[0], start[1] + d[1], start[2] + d[2]];
                if !surface.contains(seed) {
                    found.push(SeedChoice { start, seed });
                }
            }
            found
        })
    })
}

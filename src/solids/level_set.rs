//! Level sets of meshes: the narrow band of exact distances (`voxelize::distance_band`)
//! signed by where each voxel centre lies, inside or outside, by the mesh's inside rule
//! (`inside_rule`): its winding number (`winding_inside`: any consistently oriented mesh, open
//! or not), or ray parity (`mesh::inside`: closed meshes, no consistent orientation needed).
//! Values are in world units, negative inside, as OpenVDB's level sets are.
//!
//! Beside the band, the level set keeps its interior: the inside centres of the band's leaves,
//! and every 8^3 block wholly inside as a tile (128^3 where whole). A block without band
//! voxels holds no surface (any surface in it lies within sqrt(3)/2 of a centre, inside the
//! band), so one centre decides it.

use super::column_inside::{interior, leaf_inside, winding_columns};
use super::inside_rule::{Inside, InsideChoice, InsideRule, choose_inside};
use super::winding_inside::{WindingInside, block_columns, winding_inside};
use crate::error::{Error, Result};
use crate::grid::{Channels, Coord, Leaf, SparseGrid, Transform};
use crate::mesh::inside::ColumnCrossings;
use crate::mesh::{Mesh, index_box};
use crate::ops::flood::padded;
use crate::progress::Progress;
use crate::voxelize::distance_band::distance_band;
use crate::voxelize::separating::work_items;
use rayon::prelude::*;

/// Why a signed distance by parity needs a closed mesh, for the error that refuses an open one.
pub const SIGN_NEEDS_CLOSED: &str = "ray parity needs a closed mesh to sign distances (option \
     `inside` winding signs them by the winding number; option `udf` writes unsigned distances)";

/// A narrow-band level set and the inside it bounds.
pub struct LevelSet {
    /// Signed distances (world units, negative inside) on the band's voxels.
    pub band: SparseGrid,
    /// The inside centres: the band leaves' as leaves, whole inside blocks as tiles.
    pub interior: SparseGrid,
    /// The centres whose winding number lies near 1/2 (none by parity).
    pub ambiguous: SparseGrid,
    /// The band's voxels whose centre is inside (its negative values).
    pub inside_band_voxels: u64,
}

/// Signed distances (world units, negative inside) on every voxel within `band` voxels of
/// `mesh`, signed by the inside rule `rule` comes to (`choose_inside`), and its interior; the
/// rule chosen with it. The rule is chosen beside the band, which does not depend on it:
/// grouping the mesh's edges for the choice then takes no time of its own.
pub fn level_set(
    mesh: &Mesh,
    transform: Transform,
    band: f64,
    rule: InsideRule,
    progress: &Progress,
) -> Result<(InsideChoice, LevelSet)> {
    // The inside covers the band's columns: the mesh's box widened by the band. It is found
    // beside the band, filling the threads in its serial steps.
    let reach = band.ceil() as i64;
    let columns_box = padded(index_box(&mesh.bbox(), &transform), reach);
    let columns = block_columns(columns_box).len() as u64;
    progress.stage("distances and inside", work_items(mesh) + columns);
    let (grid, inside) = rayon::join(
        || distance_band(mesh, transform, band, progress),
        || {
            let choice = choose_inside(rule, mesh, SIGN_NEEDS_CLOSED)?;
            let signs = match &choice.inside {
                // Parity's crossings, or on a closed and consistently oriented mesh the
                // winding number as the signed count of crossings: the band's leaves and
                // blocks read them.
                Inside::Parity => {
                    progress.advance(columns);
                    Signs::Columns(ColumnCrossings::new(mesh, &transform, columns_box))
                }
                Inside::Winding(caps) if caps.is_empty() => {
                    progress.advance(columns);
                    Signs::Columns(winding_columns(mesh, caps, &transform, columns_box))
                }
                Inside::Winding(caps) => Signs::Winding(winding_inside(
                    mesh,
                    caps,
                    transform,
                    columns_box,
                    progress,
                )?),
            };
            Ok::<_, Error>((choice, signs))
        },
    );
    let (choice, signs) = inside?;
    let grid = grid?;
    let set = match signs {
        Signs::Columns(columns) => signed_by_columns(grid, &columns, transform),
        Signs::Winding(inside) => signed_by_winding(grid, inside, transform),
    };
    Ok((choice, set))
}

/// How a level set's band is signed once it is known.
enum Signs {
    /// A closed mesh's columns, read in the band's leaves and at one centre of each block
    /// without band voxels, not in every block.
    Columns(ColumnCrossings),
    /// Every centre decided already by the winding number (an open mesh's).
    Winding(WindingInside),
}

/// The level set of `grid`'s unsigned distances signed by the winding number's `inside`.
fn signed_by_winding(
    mut grid: SparseGrid,
    inside: WindingInside,
    transform: Transform,
) -> LevelSet {
    // Band leaves stay leaves, even wholly inside: the level set writes its tiles.
    let (full_band, full_free): (Vec<Coord>, Vec<Coord>) = inside
        .full_blocks
        .into_iter()
        .partition(|&o| grid.leaf(o).is_some());
    let mut leaves = inside.leaves;
    leaves.extend(
        full_band
            .into_iter()
            .map(|o| Leaf::with_mask(o, [u64::MAX; 8])),
    );
    let mut interior = SparseGrid::from_distinct_leaves(transform, Channels::NONE, leaves);
    interior.fill_free_leaf_blocks(full_free);
    let h = transform.voxel_size as f32;
    let inside_band_voxels = grid
        .leaves_mut()
        .par_iter_mut()
        .map(|leaf| sign_leaf(leaf, &interior.block_mask(leaf.origin), h))
        .sum();
    LevelSet {
        band: grid,
        interior,
        ambiguous: inside.ambiguous,
        inside_band_voxels,
    }
}

/// The level set of `grid`'s unsigned distances signed by the inside `columns` give.
fn signed_by_columns(
    mut grid: SparseGrid,
    columns: &ColumnCrossings,
    transform: Transform,
) -> LevelSet {
    if grid.leaf_count() == 0 {
        return LevelSet {
            band: grid,
            interior: SparseGrid::new(transform, Channels::NONE),
            ambiguous: SparseGrid::new(transform, Channels::NONE),
            inside_band_voxels: 0,
        };
    }
    let h = transform.voxel_size as f32;
    let (inside, counts): (Vec<Option<Leaf>>, Vec<u64>) = grid
        .leaves_mut()
        .par_iter_mut()
        .map(|leaf| {
            let mask = leaf_inside(columns, leaf.origin);
            let count = sign_leaf(leaf, &mask, h);
            let inside = Leaf::with_mask(leaf.origin, mask);
            ((!inside.is_empty()).then_some(inside), count)
        })
        .unzip();
    // Band leaves stay leaves, even wholly inside: the level set writes its tiles.
    let interior = interior(columns, &grid, inside.into_iter().flatten(), transform);
    LevelSet {
        band: grid,
        interior,
        ambiguous: SparseGrid::new(transform, Channels::NONE),
        inside_band_voxels: counts.iter().sum(),
    }
}

/// Negates the distances of `leaf`'s voxels in `inside` and scales all to world units; how
/// many it negated. Four voxels at a time without a branch: each value scaled by `h`, then
/// its sign bit flipped where the voxel is active and inside (`v * -h` is `-(v * h)` to the
/// bit); inactive voxels hold 0 and keep it.
fn sign_leaf(leaf: &mut Leaf, inside: &[u64; 8], h: f32) -> u64 {
    let values = leaf.value.as_mut().expect("distances");
    let mut negated = 0;
    for (w, (&active, &inside)) in leaf.mask.iter().zip(inside).enumerate() {
        let negate = active & inside;
        negated += u64::from(negate.count_ones());
        for (q, four) in values[64 * w..64 * w + 64].chunks_exact_mut(4).enumerate() {
            let flips = &SIGN_FLIPS[(negate >> (4 * q) & 15) as usize];
            for (v, flip) in four.iter_mut().zip(flips) {
                *v = f32::from_bits((*v * h).to_bits() ^ flip);
            }
        }
    }
    negated
}

/// The sign bits to flip in four consecutive values, for each four bits of a mask word.
const SIGN_FLIPS: [[u32; 4]; 16] = {
    let mut flips = [[0; 4]; 16];
    let mut bits = 0;
    while bits < 16 {
        let mut lane = 0;
        while lane < 4 {
            flips[bits][lane] = ((bits >> lane & 1) as u32) << 31;
            lane += 1;
        }
        bits += 1;
    }
    flips
};

/// Unsigned distances (world units) on every voxel within `band` voxels of `mesh`, open or
/// closed.
pub fn unsigned_distance(
    mesh: &Mesh,
    transform: Transform,
    band: f64,
    progress: &Progress,
) -> Result<SparseGrid> {
    let mut grid = distance_band(mesh, transform, band, progress)?;
    let h = transform.voxel_size as f32;
    grid.map_values(|_, d| d * h);
    Ok(grid)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::LEAF_VOXELS;
    use crate::random::SplitMix64;

    /// The branch-free signing gives, bit for bit, what multiplying each active value by
    /// `-h` inside and `h` outside gives, and leaves inactive voxels at 0.
    #[test]
    fn signing_matches_voxel_by_voxel() {
        let mut random = SplitMix64(7);
        for _ in 0..50 {
            let mut leaf = Leaf::new(
                [0, 0, 0],
                Channels {
                    value: true,
                    ..Channels::NONE
                },
            );
            leaf.mask = std::array::from_fn(|_| random.next_u64());
            let inside: [u64; 8] = std::array::from_fn(|_| random.next_u64());
            let values = leaf.value.as_mut().unwrap();
            for n in crate::grid::bits::ones(&leaf.mask) {
                values[n] = random.range(0.0, 3.0) as f32;
            }
            let before = **values;
            let h = random.range(1e-4, 1.0) as f32;
            let negated = sign_leaf(&mut leaf, &inside, h);
            let after = leaf.value.as_ref().unwrap();
            let mut expected_negated = 0;
            for n in 0..LEAF_VOXELS {
                let active = leaf.mask[n / 64] >> (n % 64) & 1 == 1;
                let inside = inside[n / 64] >> (n % 64) & 1 == 1;
                let expected = match (active, inside) {
                    (false, _) => 0.0,
                    (true, true) => before[n] * -h,
                    (true, false) => before[n] * h,
                };
                expected_negated += u64::from(active && inside);
                assert_eq!(after[n].to_bits(), expected.to_bits(), "voxel {n}");
            }
            assert_eq!(negated, expected_negated);
        }
    }
}

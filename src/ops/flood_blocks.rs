//! The exterior flood block by block. An 8^3 block without surface voxels is 6-connected
//! inside, so it is flooded as one; only the blocks that hold surface voxels are flooded voxel
//! by voxel, 512 bits at a time (a leaf's mask words shifted along x, y and z). Reached
//! voxels cross a block face as a face of bits. What the flood cannot reach is the inside:
//! whole blocks become tiles and the others leaves, so the voxels of whole blocks are never
//! touched. Same 6-connected exterior as the voxel floods (a test compares them).

use crate::error::{Error, Result};
use crate::grid::{Block, Channels, Coord, CoordBox, SparseGrid};
use crate::progress::Progress;
use rayon::prelude::*;

const FULL: [u64; 8] = [u64::MAX; 8];
/// The bits of a mask word with z = 0, and with z = 7.
const Z0: u64 = 0x0101_0101_0101_0101;
const Z7: u64 = Z0 << 7;

/// The six face directions: axis and sign.
const FACES: [(usize, i64); 6] = [(0, 1), (0, -1), (1, 1), (1, -1), (2, 1), (2, -1)];

/// The voxels of `r`'s face towards `(axis, sign)`, moved onto the facing face of the
/// neighbouring block (as that block's offsets).
fn across(r: &[u64; 8], axis: usize, sign: i64) -> [u64; 8] {
    let mut out = [0; 8];
    match (axis, sign) {
        (0, 1) => out[0] = r[7],
        (0, _) => out[7] = r[0],
        (1, 1) => (0..8).for_each(|x| out[x] = r[x] >> 56),
        (1, _) => (0..8).for_each(|x| out[x] = (r[x] & 0xff) << 56),
        (_, 1) => (0..8).for_each(|x| out[x] = (r[x] & Z7) >> 7),
        _ => (0..8).for_each(|x| out[x] = (r[x] & Z0) << 7),
    }
    out
}

/// The empty voxels of a block 6-connected to `seeds` inside it (`free`: its empty voxels).
fn flood_in_block(seeds: [u64; 8], free: &[u64; 8]) -> [u64; 8] {
    let mut r: [u64; 8] = std::array::from_fn(|x| seeds[x] & free[x]);
    loop {
        let mut next = r;
        for x in 0..8 {
            let w = r[x];
            let mut grown = w | (w << 1 & !Z0) | (w >> 1 & !Z7) | w << 8 | w >> 8;
            if x > 0 {
                grown |= r[x - 1];
            }
            if x < 7 {
                grown |= r[x + 1];
            }
            next[x] = grown & free[x];
        }
        if next == r {
            return r;
        }
        r = next;
    }
}

/// The blocks of the flood: a box of 8^3 blocks one block wider than the surface on every
/// side, each either empty or holding surface voxels.
struct Blocks {
    min: Coord,
    dims: [usize; 3],
    /// Per block: 0 when empty, else 1 + its index in `free`.
    slot: Vec<u32>,
    /// Per surface block: its origin and empty voxels.
    origins: Vec<Coord>,
    free: Vec<[u64; 8]>,
}

impl Blocks {
    fn new(surface: &SparseGrid, bbox: CoordBox) -> Result<Blocks> {
        let min = bbox.min.map(|v| (v >> 3) - 1);
        let max = bbox.max.map(|v| (v >> 3) + 1);
        let dims = std::array::from_fn(|a| (max[a] - min[a] + 1) as usize);
        let count = dims[0]
            .checked_mul(dims[1])
            .and_then(|n| n.checked_mul(dims[2]))
            .filter(|&n| n < u32::MAX as usize)
            .ok_or_else(|| Error::TooLarge {
                estimated_mib: u64::MAX,
                available_mib: 0,
                detail: format!(
                    "a flood over {}x{}x{} blocks of 8^3",
                    dims[0], dims[1], dims[2]
                ),
            })?;
        let mut blocks = Blocks {
            min,
            dims,
            slot: vec![0; count],
            origins: Vec::new(),
            free: Vec::new(),
        };
        let leaves = surface.leaves().iter().filter(|l| !l.is_empty());
        let origins = leaves.map(|l| l.origin).chain(surface.tiles().blocks());
        for origin in origins {
            let free = match surface.block(origin) {
                Block::Partial(l) => l.mask.map(|w| !w),
                _ => [0; 8],
            };
            let i = blocks.index(origin.map(|v| v >> 3));
            blocks.origins.push(origin);
            blocks.free.push(free);
            blocks.slot[i] = blocks.free.len() as u32;
        }
        Ok(blocks)
    }

    /// Linear index of block coordinate `b` (origin / 8), which must lie in the box.
    fn index(&self, b: Coord) -> usize {
        let [x, y, z] = std::array::from_fn(|a| (b[a] - self.min[a]) as usize);
        (x * self.dims[1] + y) * self.dims[2] + z
    }

    /// Block coordinate of linear index `i`.
    fn coord(&self, i: usize) -> Coord {
        let z = i % self.dims[2];
        let y = i / self.dims[2] % self.dims[1];
        let x = i / (self.dims[1] * self.dims[2]);
        [
            self.min[0] + x as i64,
            self.min[1] + y as i64,
            self.min[2] + z as i64,
        ]
    }

    /// The neighbour of block `i` (at block coordinate `b`) towards `(axis, sign)`, if
    /// inside the box.
    fn neighbour(&self, i: usize, b: Coord, axis: usize, sign: i64) -> Option<usize> {
        let n = b[axis] + sign - self.min[axis];
        if n < 0 || n >= self.dims[axis] as i64 {
            return None;
        }
        let stride = match axis {
            0 => self.dims[1] * self.dims[2],
            1 => self.dims[2],
            _ => 1,
        };
        Some(if sign > 0 { i + stride } else { i - stride })
    }
}

/// The voxels enclosed by `surface` (not reached from outside through 6-connected empty
/// voxels, and not surface voxels), as tiles and leaves on its transform.
pub fn inside_by_blocks(surface: &SparseGrid, progress: &Progress) -> Result<SparseGrid> {
    let mut inside = SparseGrid::new(surface.transform, Channels::NONE);
    let Some(bbox) = surface.bbox() else {
        return Ok(inside);
    };
    let blocks = Blocks::new(surface, bbox)?;
    let total = blocks.slot.len() as u64;
    progress.stage("filling", total);
    // Blocks first reached, told in batches: the flood reaches most blocks once.
    let (mut reached_blocks, mut told) = (1u64, 0u64);
    // Empty blocks: reached or not; surface blocks: their reached voxels.
    let mut exterior = vec![false; blocks.slot.len()];
    let mut reached = vec![[0u64; 8]; blocks.free.len()];
    let mut queued = vec![false; blocks.free.len()];
    let mut stack = vec![0usize];
    exterior[0] = true; // a corner block, outside the surface's box
    let mut popped = 0u64;
    while let Some(i) = stack.pop() {
        popped += 1;
        if popped.is_multiple_of(4096) {
            progress.advance(reached_blocks - told);
            told = reached_blocks;
            if progress.stopped() {
                return Err(Error::Cancelled);
            }
        }
        let slot = blocks.slot[i] as usize;
        let from = if slot == 0 {
            FULL
        } else {
            let s = slot - 1;
            queued[s] = false;
            reached[s] = flood_in_block(reached[s], &blocks.free[s]);
            reached[s]
        };
        let b = blocks.coord(i);
        for &(axis, sign) in &FACES {
            let Some(j) = blocks.neighbour(i, b, axis, sign) else {
                continue;
            };
            let face = across(&from, axis, sign);
            match blocks.slot[j] as usize {
                0 => {
                    if !exterior[j] && face.iter().any(|&w| w != 0) {
                        exterior[j] = true;
                        reached_blocks += 1;
                        stack.push(j);
                    }
                }
                s => {
                    let s = s - 1;
                    let first = reached[s] == [0; 8];
                    let mut grew = false;
                    for x in 0..8 {
                        let new = face[x] & blocks.free[s][x] & !reached[s][x];
                        grew |= new != 0;
                        reached[s][x] |= new;
                    }
                    reached_blocks += u64::from(grew && first);
                    if grew && !queued[s] {
                        queued[s] = true;
                        stack.push(j);
                    }
                }
            }
        }
    }
    // The blocks never reached are inside: done too.
    progress.advance(total.saturating_sub(told));
    let whole: Vec<Coord> = (0..blocks.slot.len())
        .into_par_iter()
        .filter(|&i| blocks.slot[i] == 0 && !exterior[i])
        .map(|i| blocks.coord(i).map(|v| v * 8))
        .collect();
    inside.fill_leaf_blocks(whole);
    for (s, origin) in blocks.origins.iter().enumerate() {
        let mask: [u64; 8] = std::array::from_fn(|x| blocks.free[s][x] & !reached[s][x]);
        if mask != [0; 8] {
            inside.leaf_mut_or_insert(*origin).mask = mask;
        }
    }
    inside.compact();
    Ok(inside)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::{DenseMask, Transform};
    use crate::ops::flood::padded;
    use crate::ops::flood_spans::flood_spans;
    use crate::random::SplitMix64;

    /// The voxel flood's inside, for comparison.
    fn inside_by_voxels(surface: &SparseGrid) -> SparseGrid {
        let bbox = padded(surface.bbox().unwrap(), 2);
        let blocked = DenseMask::from_grid(surface, bbox).unwrap();
        let exterior = flood_spans(&blocked, &[bbox.min], &Progress::none()).unwrap();
        DenseMask::neither(&blocked, &exterior).to_grid(surface.transform)
    }

    fn same_voxels(a: &SparseGrid, b: &SparseGrid) -> bool {
        a.voxel_count() == b.voxel_count() && a.voxels().all(|c| b.contains(c))
    }

    #[test]
    fn nested_shells_with_holes_match_the_voxel_flood() {
        let mut rng = SplitMix64(17);
        for round in 0..20i64 {
            let mut surface = SparseGrid::new(Transform::default(), Channels::NONE);
            // Concentric cube shells of random sizes, some with a hole, around a random centre.
            let c: Coord = [0, 1, 2].map(|_| rng.range(-20.0, 20.0).floor() as i64);
            let mut r: i64 = 3 + round % 5;
            while r < 40 {
                let hole = rng.range(0.0, 1.0) < 0.4;
                for x in -r..=r {
                    for y in -r..=r {
                        for z in -r..=r {
                            let on_shell = [x, y, z].iter().any(|v| v.abs() == r);
                            if on_shell && !(hole && x == r && y.abs() < 2 && z.abs() < 2) {
                                surface.insert([c[0] + x, c[1] + y, c[2] + z]);
                            }
                        }
                    }
                }
                r += 2 + (rng.range(0.0, 12.0) as i64);
            }
            let blocks = inside_by_blocks(&surface, &Progress::none()).unwrap();
            let voxels = inside_by_voxels(&surface);
            assert!(same_voxels(&blocks, &voxels), "round {round}");
        }
    }

    #[test]
    fn a_large_box_is_held_as_tiles() {
        let mut surface = SparseGrid::new(Transform::default(), Channels::NONE);
        let n = 300;
        for a in 0..=n {
            for b in 0..=n {
                for (x, y, z) in [
                    (0, a, b),
                    (n, a, b),
                    (a, 0, b),
                    (a, n, b),
                    (a, b, 0),
                    (a, b, n),
                ] {
                    surface.insert([x, y, z]);
                }
            }
        }
        let inside = inside_by_blocks(&surface, &Progress::none()).unwrap();
        assert_eq!(inside.voxel_count(), (n as u64 - 1).pow(3));
        assert!(inside.tiles().node_tiles().count() >= 1);
        assert!(inside.leaf_count() < 6 * 38 * 38);
    }
}

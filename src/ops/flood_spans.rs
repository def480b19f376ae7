//! The fast flood: scanline spans along z. A popped voxel grows to the whole run of empty
//! voxels along its z row; the neighbouring rows are scanned along that run (6: the four side
//! rows; 18: the side rows one voxel further at both ends and the four diagonal rows; 26: all
//! eight rows one voxel further) and one voxel per empty run found there is pushed. Every
//! voxel is marked once and each row run is entered a bounded number of times, so the stack
//! stays small (no entry per voxel) and the work is close to one pass over the reached voxels.
//! 6-connected, it reaches exactly the voxels FloodingXYZ reaches.

use crate::error::Result;
use crate::grid::{Adjacency, Coord, DenseMask};
use crate::progress::Progress;

/// Empty voxels 6-connected to the empty voxels among `seeds`; stops with `Cancelled` when
/// `progress`'s observer asks (it is asked every few thousand runs).
pub fn flood_spans(blocked: &DenseMask, seeds: &[Coord], progress: &Progress) -> Result<DenseMask> {
    let mut reached = DenseMask::new(blocked.bbox)?;
    flood_spans_into(blocked, seeds, Adjacency::Six, &mut reached, progress);
    progress.check()?;
    Ok(reached)
}

/// Empty voxels reachable from the border of `blocked.bbox` through `adjacency`-paths of
/// empty voxels.
pub fn flood_spans_from_border(blocked: &DenseMask, adjacency: Adjacency) -> Result<DenseMask> {
    let mut reached = DenseMask::new(blocked.bbox)?;
    let [nx, ny, nz] = blocked.dims();
    let b = blocked.bbox;
    let mut seeds = Vec::new();
    // Every border row in full, and the first and last voxel of every inner row.
    for x in 0..nx as i64 {
        for y in 0..ny as i64 {
            let edge = x == 0 || y == 0 || x == nx as i64 - 1 || y == ny as i64 - 1;
            let zs: Vec<i64> = if edge {
                (0..nz as i64).collect()
            } else {
                vec![0, nz as i64 - 1]
            };
            for z in zs {
                let c = [b.min[0] + x, b.min[1] + y, b.min[2] + z];
                let i = blocked.index(c);
                if !blocked.get_index(i) && !reached.get_index(i) {
                    seeds.push(c);
                    flood_spans_into(blocked, &seeds, adjacency, &mut reached, &Progress::none());
                    seeds.clear();
                }
            }
        }
    }
    Ok(reached)
}

/// Floods from `seeds` into `reached` (voxels already reached are walls too).
fn flood_spans_into(
    blocked: &DenseMask,
    seeds: &[Coord],
    adjacency: Adjacency,
    reached: &mut DenseMask,
    progress: &Progress,
) {
    let [nx, ny, nz] = blocked.dims();
    // Side rows scanned one voxel beyond the run for 18 and 26; diagonal rows for 18 (along
    // the run) and 26 (one beyond).
    let (side_reach, diagonal) = match adjacency {
        Adjacency::Six => (0, None),
        Adjacency::Eighteen => (1, Some(0)),
        Adjacency::TwentySix => (1, Some(1)),
    };
    // Walls (blocked or already reached) of row (x, y), 64 voxels at a time from z.
    let walls = |reached: &DenseMask, x: i64, y: i64, z: usize, n: usize| {
        blocked.row_bits(x, y, z, n) | reached.row_bits(x, y, z, n)
    };
    let mut stack: Vec<usize> = seeds
        .iter()
        .filter(|&&s| blocked.bbox.contains(s))
        .map(|&s| blocked.index(s))
        .collect();
    let mut runs = 0u32;
    while let Some(i) = stack.pop() {
        if blocked.get_index(i) || reached.get_index(i) {
            continue;
        }
        runs = runs.wrapping_add(1);
        if runs.is_multiple_of(4096) {
            progress.advance(0);
            if progress.stopped() {
                return;
            }
        }
        let row = i - i % nz;
        let (x, y) = ((row / (ny * nz)) as i64, ((row / nz) % ny) as i64);
        // Grow to the run [first, last] along z, a word at a time.
        let mut last = i - row;
        while last + 1 < nz {
            let n = (nz - last - 1).min(64);
            let w = walls(reached, x, y, last + 1, n);
            if w != 0 {
                last += w.trailing_zeros() as usize;
                break;
            }
            last += n;
        }
        let mut first = i - row;
        while first > 0 {
            let n = first.min(64);
            let w = walls(reached, x, y, first - n, n);
            if w != 0 {
                first -= n - 1 - (63 - w.leading_zeros() as usize);
                break;
            }
            first -= n;
        }
        reached.set_index_range(row + first, row + last);
        for dx in -1i64..=1 {
            for dy in -1i64..=1 {
                let reach = match (dx != 0, dy != 0) {
                    (false, false) => continue,
                    (true, true) => match diagonal {
                        Some(r) => r,
                        None => continue,
                    },
                    _ => side_reach,
                };
                let (ox, oy) = (x + dx, y + dy);
                if ox < 0 || oy < 0 || ox >= nx as i64 || oy >= ny as i64 {
                    continue;
                }
                let other = (ox as usize * ny + oy as usize) * nz;
                // One push per run of free voxels beside [z0, z1]: the first voxel of each.
                let (z0, z1) = (first.saturating_sub(reach), (last + reach).min(nz - 1));
                let mut z = z0;
                let mut before_free = false;
                while z <= z1 {
                    let n = (z1 + 1 - z).min(64);
                    let mask = if n == 64 { u64::MAX } else { (1u64 << n) - 1 };
                    let free = !walls(reached, ox, oy, z, n) & mask;
                    let mut starts = free & !((free << 1) | u64::from(before_free));
                    while starts != 0 {
                        stack.push(other + z + starts.trailing_zeros() as usize);
                        starts &= starts - 1;
                    }
                    before_free = free >> (n - 1) & 1 == 1;
                    z += n;
                }
            }
        }
    }
}

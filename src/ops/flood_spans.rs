//! The fast flood: scanline spans along z. A popped voxel grows to the whole run of empty
//! voxels along its z row; the neighbouring rows are scanned along that run (6: the four side
//! rows; 18: the side rows one voxel further at both ends and the four diagonal rows; 26: all
//! eight rows one voxel further) and one voxel per empty run found there is pushed. Every
//! voxel is marked once and each row run is entered a bounded number of times, so the stack
//! stays small (no entry per voxel) and the work is close to one pass over the reached voxels.
//! 6-connected, it reaches exactly the voxels FloodingXYZ reaches.

use crate::error::Result;
use crate::grid::{Adjacency, Coord, DenseMask};

/// Empty voxels 6-connected to the empty voxels among `seeds`.
pub fn flood_spans(blocked: &DenseMask, seeds: &[Coord]) -> Result<DenseMask> {
    let mut reached = DenseMask::new(blocked.bbox)?;
    flood_spans_into(blocked, seeds, Adjacency::Six, &mut reached);
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
                    flood_spans_into(blocked, &seeds, adjacency, &mut reached);
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
) {
    let [nx, ny, nz] = blocked.dims();
    // Side rows scanned one voxel beyond the run for 18 and 26; diagonal rows for 18 (along
    // the run) and 26 (one beyond).
    let (side_reach, diagonal) = match adjacency {
        Adjacency::Six => (0, None),
        Adjacency::Eighteen => (1, Some(0)),
        Adjacency::TwentySix => (1, Some(1)),
    };
    let free = |reached: &DenseMask, i: usize| !blocked.get_index(i) && !reached.get_index(i);
    let mut stack: Vec<usize> = seeds
        .iter()
        .filter(|&&s| blocked.bbox.contains(s))
        .map(|&s| blocked.index(s))
        .collect();
    while let Some(i) = stack.pop() {
        if !free(reached, i) {
            continue;
        }
        // Grow to the run [first, last] along z.
        let row = i - i % nz;
        let (mut first, mut last) = (i, i);
        while first > row && free(reached, first - 1) {
            first -= 1;
        }
        while last + 1 < row + nz && free(reached, last + 1) {
            last += 1;
        }
        reached.set_index_range(first, last);
        let (x, y) = ((row / (ny * nz)) as i64, ((row / nz) % ny) as i64);
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
                let z0 = (first - row).saturating_sub(reach);
                let z1 = (last - row + reach).min(nz - 1);
                // One push per run of free voxels beside [z0, z1].
                let mut in_run = false;
                for z in z0..=z1 {
                    let j = other + z;
                    let f = free(reached, j);
                    if f && !in_run {
                        stack.push(j);
                    }
                    in_run = f;
                }
            }
        }
    }
}

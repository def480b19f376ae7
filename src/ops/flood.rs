//! Flooding the empty voxels of a box from its border: the exterior of a voxel surface.

use crate::error::Result;
use crate::grid::{Adjacency, CoordBox, DenseMask};

/// Empty voxels (not in `blocked`) reachable from the border of `blocked.bbox` through
/// `adjacency`-paths of empty voxels.
/// (By z-row spans: no stack entry per voxel.)
pub fn flood_from_border(blocked: &DenseMask, adjacency: Adjacency) -> Result<DenseMask> {
    super::flood_spans::flood_spans_from_border(blocked, adjacency)
}

/// Empty voxels reachable from the empty voxels of `seeds` through `adjacency`-paths of
/// empty voxels, without leaving the box.
pub fn flood(blocked: &DenseMask, seeds: &DenseMask, adjacency: Adjacency) -> Result<DenseMask> {
    let mut reached = DenseMask::new(blocked.bbox)?;
    let [nx, ny, nz] = blocked.dims();
    let deltas: Vec<[i64; 3]> = adjacency.offsets();
    let strides = [(ny * nz) as isize, nz as isize, 1isize];
    let linear: Vec<isize> = deltas
        .iter()
        .map(|d| {
            d[0] as isize * strides[0] + d[1] as isize * strides[1] + d[2] as isize * strides[2]
        })
        .collect();
    let mut stack: Vec<usize> = Vec::new();
    for i in seeds.ones() {
        if !blocked.get_index(i) && !reached.get_index(i) {
            reached.set_index(i);
            stack.push(i);
        }
    }
    while let Some(i) = stack.pop() {
        let (x, y, z) = (i / (ny * nz), (i / nz) % ny, i % nz);
        let interior = x > 0 && y > 0 && z > 0 && x + 1 < nx && y + 1 < ny && z + 1 < nz;
        for (d, &l) in deltas.iter().zip(&linear) {
            if !interior {
                // Next to the border: keep the neighbour inside the box.
                let (a, b, c) = (x as i64 + d[0], y as i64 + d[1], z as i64 + d[2]);
                if a < 0
                    || b < 0
                    || c < 0
                    || a as usize >= nx
                    || b as usize >= ny
                    || c as usize >= nz
                {
                    continue;
                }
            }
            let j = (i as isize + l) as usize;
            if !blocked.get_index(j) && !reached.get_index(j) {
                reached.set_index(j);
                stack.push(j);
            }
        }
    }
    Ok(reached)
}

/// `bbox` grown by `pad` voxels on every side.
pub fn padded(bbox: CoordBox, pad: i64) -> CoordBox {
    CoordBox {
        min: bbox.min.map(|v| v - pad),
        max: bbox.max.map(|v| v + pad),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A hollow cube shell of `blocked` voxels: the inside is reached only through the
    /// gaps the chosen adjacency can squeeze through.
    #[test]
    fn diagonal_gap_leaks_for_26_but_not_for_6() {
        let bbox = CoordBox {
            min: [0, 0, 0],
            max: [8, 8, 8],
        };
        let mut shell = DenseMask::new(bbox).unwrap();
        for x in 2..=6 {
            for y in 2..=6 {
                for z in 2..=6 {
                    if [x, y, z].iter().any(|&v| v == 2 || v == 6) {
                        shell.set([x, y, z]);
                    }
                }
            }
        }
        // Replace a face voxel by a corner-only connection: remove nothing, but open a
        // diagonal: clear two face voxels that touch only at an edge.
        let inside = [4, 4, 4];
        for adj in [Adjacency::Six, Adjacency::Eighteen, Adjacency::TwentySix] {
            assert!(!flood_from_border(&shell, adj).unwrap().get(inside));
        }
        let mut holed = shell.clone();
        // Clear the edge voxel (2,2,4): outside (1,1,4) and inside (3,3,4) become 18/26-adjacent to it.
        let i = holed.index([2, 2, 4]);
        holed.clear_index(i);
        assert!(
            !flood_from_border(&holed, Adjacency::Six)
                .unwrap()
                .get(inside)
        );
        assert!(
            flood_from_border(&holed, Adjacency::Eighteen)
                .unwrap()
                .get(inside)
        );
    }
}

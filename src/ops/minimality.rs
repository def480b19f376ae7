//! Minimality of a separating surface (Huang et al. §3): a surface voxel is N-simple when
//! removing it keeps the surface N-separating. Tested locally in its 3x3x3 neighbourhood:
//! the voxel is simple when its empty N-neighbours all belong to one N-component of the
//! empty voxels of the neighbourhood (centre excluded), so removing it joins nothing.

use super::flood::padded;
use crate::error::Result;
use crate::grid::{Adjacency, Coord, DenseMask, SparseGrid};
use rayon::prelude::*;

/// Position of offset `(dx,dy,dz)` (each in -1..=1) in a 27-bit neighbourhood mask.
fn bit(dx: i64, dy: i64, dz: i64) -> usize {
    ((dx + 1) * 9 + (dy + 1) * 3 + (dz + 1)) as usize
}

const CENTRE: usize = 13;

/// For each of the 27 cells, the mask of its `adjacency` neighbours inside the cube.
fn neighbour_masks(adjacency: Adjacency) -> [u32; 27] {
    let mut masks = [0u32; 27];
    for x in -1..=1i64 {
        for y in -1..=1i64 {
            for z in -1..=1i64 {
                for d in adjacency.offsets() {
                    let (a, b, c) = (x + d[0], y + d[1], z + d[2]);
                    if (-1..=1).contains(&a) && (-1..=1).contains(&b) && (-1..=1).contains(&c) {
                        masks[bit(x, y, z)] |= 1 << bit(a, b, c);
                    }
                }
            }
        }
    }
    masks
}

/// Whether the centre of the neighbourhood `occupied` (27-bit mask of surface voxels) is
/// N-simple.
fn is_simple(occupied: u32, masks: &[u32; 27]) -> bool {
    let empty = !occupied & ((1 << 27) - 1) & !(1 << CENTRE);
    let mut touching = masks[CENTRE] & empty;
    let mut components = 0;
    while touching != 0 {
        components += 1;
        if components > 1 {
            return false;
        }
        // Grow one component from the lowest touching cell.
        let mut comp = touching & touching.wrapping_neg();
        loop {
            let mut grown = comp;
            let mut b = comp;
            while b != 0 {
                grown |= masks[b.trailing_zeros() as usize] & empty;
                b &= b - 1;
            }
            if grown == comp {
                break;
            }
            comp = grown;
        }
        touching &= !comp;
    }
    true
}

/// The N-simple voxels of `surface` (N = `adjacency`), leaf by leaf.
pub fn simple_voxels(surface: &SparseGrid, adjacency: Adjacency) -> Result<Vec<Coord>> {
    let Some(bbox) = surface.bbox() else {
        return Ok(Vec::new());
    };
    let dense = DenseMask::from_grid(surface, padded(bbox, 1))?;
    let masks = neighbour_masks(adjacency);
    Ok(surface
        .leaves()
        .par_iter()
        .flat_map_iter(|leaf| {
            leaf.coords().filter(|c| {
                let mut occ = 0u32;
                for dx in -1..=1 {
                    for dy in -1..=1 {
                        for dz in -1..=1 {
                            if dense.get([c[0] + dx, c[1] + dy, c[2] + dz]) {
                                occ |= 1 << bit(dx, dy, dz);
                            }
                        }
                    }
                }
                is_simple(occ, &masks)
            })
        })
        .collect())
}

/// The number of N-simple voxels of `surface` (N = `adjacency`).
pub fn simple_voxel_count(surface: &SparseGrid, adjacency: Adjacency) -> Result<u64> {
    Ok(simple_voxels(surface, adjacency)?.len() as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane_layer() -> u32 {
        // The z = 0 layer of the neighbourhood occupied.
        let mut m = 0;
        for x in -1..=1 {
            for y in -1..=1 {
                m |= 1 << bit(x, y, 0);
            }
        }
        m
    }

    #[test]
    fn a_one_voxel_plane_is_minimal_and_a_doubled_one_is_not() {
        for adj in [Adjacency::Six, Adjacency::TwentySix] {
            let masks = neighbour_masks(adj);
            assert!(!is_simple(plane_layer(), &masks));
            // A second layer above: the centre is no longer needed.
            let mut thick = plane_layer();
            for x in -1..=1 {
                for y in -1..=1 {
                    thick |= 1 << bit(x, y, 1);
                }
            }
            assert!(is_simple(thick, &masks));
        }
    }
}

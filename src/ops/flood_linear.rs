//! Linear flooding, the baseline Lai & Cheng measure FloodingXYZ against (§6.2): sweep the
//! volume from the first voxel to the last, marking every empty voxel 6-adjacent to a marked
//! one, and repeat until a sweep marks nothing. No extra memory, but as many sweeps as the
//! flood needs to turn against the sweep order.

use crate::error::Result;
use crate::grid::{Coord, DenseMask};

/// Empty voxels 6-connected to the empty voxels among `seeds`, and the number of sweeps.
pub fn flood_linear(blocked: &DenseMask, seeds: &[Coord]) -> Result<(DenseMask, u64)> {
    let mut gray = DenseMask::new(blocked.bbox)?;
    for &s in seeds {
        if blocked.bbox.contains(s) && !blocked.get(s) {
            gray.set(s);
        }
    }
    let [nx, ny, nz] = blocked.dims();
    let mut sweeps = 0;
    loop {
        sweeps += 1;
        let mut changed = false;
        for i in 0..gray.len() {
            if blocked.get_index(i) || gray.get_index(i) {
                continue;
            }
            let (x, y, z) = (i / (ny * nz), (i / nz) % ny, i % nz);
            let touches = (x > 0 && gray.get_index(i - ny * nz))
                || (x + 1 < nx && gray.get_index(i + ny * nz))
                || (y > 0 && gray.get_index(i - nz))
                || (y + 1 < ny && gray.get_index(i + nz))
                || (z > 0 && gray.get_index(i - 1))
                || (z + 1 < nz && gray.get_index(i + 1));
            if touches {
                gray.set_index(i);
                changed = true;
            }
        }
        if !changed {
            return Ok((gray, sweeps));
        }
    }
}

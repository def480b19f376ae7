//! Lai & Cheng's volume flooding (§6.2, "dynamic programming"): FloodingXYZ marks the empty
//! voxels on the three axis lines through a voxel, up to the first blocked voxel each way, and
//! pushes them onto GRAYSTACK, whose capacity the user sets; popped voxels are flooded the same
//! way. When the stack runs dry, a sweep over the whole volume restarts FloodingXYZ at every
//! empty voxel 6-adjacent to a marked one (voxels the full stack could not take), until a sweep
//! finds none. The paper's pseudo-code sets `loop = 1` after the sweep unconditionally; here it
//! is set only when the sweep found a voxel, or the loop would never end; and the stack is
//! drained after each restart within a sweep, so that one sweep carries a restart as far as
//! it goes.

use crate::error::Result;
use crate::grid::{Coord, DenseMask};
use crate::progress::Progress;

/// GRAYSTACK entries unless the user asks otherwise.
pub const DEFAULT_GRAYSTACK: usize = 1 << 20;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FloodXyzStats {
    /// FloodingXYZ calls.
    pub line_floods: u64,
    /// Full sweeps over the volume (the last finds nothing).
    pub sweeps: u64,
    /// Voxels that could not be pushed because GRAYSTACK was full.
    pub overflows: u64,
}

/// Empty voxels 6-connected to the empty voxels among `seeds`, with a GRAYSTACK of
/// `capacity` entries (at least 1).
pub fn flood_xyz(
    blocked: &DenseMask,
    seeds: &[Coord],
    capacity: usize,
    progress: &Progress,
) -> Result<(DenseMask, FloodXyzStats)> {
    let mut run = Run {
        blocked,
        gray: DenseMask::new(blocked.bbox)?,
        stack: Vec::with_capacity(capacity.max(1)),
        capacity: capacity.max(1),
        dims: blocked.dims(),
        stats: FloodXyzStats::default(),
    };
    for &s in seeds {
        if blocked.bbox.contains(s) {
            let i = blocked.index(s);
            if !blocked.get_index(i) && !run.gray.get_index(i) {
                run.gray.set_index(i);
                run.line_flood(i);
            }
        }
    }
    loop {
        while let Some(i) = run.stack.pop() {
            run.line_flood(i);
            // Ask the observer now and then; stop when it says so.
            if run.stats.line_floods.is_multiple_of(4096) {
                progress.advance(0);
                progress.check()?;
            }
        }
        run.stats.sweeps += 1;
        if !run.sweep() {
            break;
        }
    }
    Ok((run.gray, run.stats))
}

struct Run<'a> {
    blocked: &'a DenseMask,
    gray: DenseMask,
    stack: Vec<usize>,
    capacity: usize,
    dims: [usize; 3],
    stats: FloodXyzStats,
}

impl Run<'_> {
    fn white(&self, i: usize) -> bool {
        !self.blocked.get_index(i) && !self.gray.get_index(i)
    }

    fn mark(&mut self, i: usize) {
        self.gray.set_index(i);
        if self.stack.len() < self.capacity {
            self.stack.push(i);
        } else {
            self.stats.overflows += 1;
        }
    }

    /// FloodingXYZ: the white voxels on the x, y and z lines through (gray) voxel `i`.
    fn line_flood(&mut self, i: usize) {
        self.stats.line_floods += 1;
        let [_, ny, nz] = self.dims;
        let at = [i / (ny * nz), (i / nz) % ny, i % nz];
        let strides = [ny * nz, nz, 1];
        for axis in 0..3 {
            let n = self.dims[axis];
            let stride = strides[axis];
            let mut j = i;
            for _ in at[axis] + 1..n {
                j += stride;
                if !self.white(j) {
                    break;
                }
                self.mark(j);
            }
            let mut j = i;
            for _ in 0..at[axis] {
                j -= stride;
                if !self.white(j) {
                    break;
                }
                self.mark(j);
            }
        }
    }

    /// Restarts FloodingXYZ at every white voxel 6-adjacent to a gray one; whether any was.
    fn sweep(&mut self) -> bool {
        let [nx, ny, nz] = self.dims;
        let mut found = false;
        for i in 0..self.gray.len() {
            if !self.white(i) {
                continue;
            }
            let (x, y, z) = (i / (ny * nz), (i / nz) % ny, i % nz);
            let touches = (x > 0 && self.gray.get_index(i - ny * nz))
                || (x + 1 < nx && self.gray.get_index(i + ny * nz))
                || (y > 0 && self.gray.get_index(i - nz))
                || (y + 1 < ny && self.gray.get_index(i + nz))
                || (z > 0 && self.gray.get_index(i - 1))
                || (z + 1 < nz && self.gray.get_index(i + 1));
            if touches {
                found = true;
                self.gray.set_index(i);
                self.line_flood(i);
                while let Some(j) = self.stack.pop() {
                    self.line_flood(j);
                }
            }
        }
        found
    }
}

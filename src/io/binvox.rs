//! The binvox format (Patrick Min's voxel files, read by trimesh, binvox-rw and many learning
//! pipelines): an ASCII header (`#binvox 1`, `dim D D D`, `translate`, `scale`, `data`), then
//! the D^3 cube as run-length pairs of bytes (value 0 or 1, count 1..255), x slowest, then z,
//! y fastest. A voxel (i, j, k) of the cube has its centre at
//! `translate + (i + 0.5, j + 0.5, k + 0.5) * scale / D`. The cube is the voxel set's bounding
//! box grown to a cube from its minimum corner. Written atomically.

use super::atomic::write_atomic;
use crate::error::{Error, Result};
use crate::grid::{DenseMask, SparseGrid};
use std::io::Write;
use std::path::Path;

/// The largest cube written (binvox readers hold the whole cube in memory).
pub const MAX_BINVOX_DIM: u64 = 4096;

/// Writes the voxels of `grid` to `path` as binvox.
pub fn write_binvox(path: &Path, grid: &SparseGrid) -> Result<()> {
    let Some(bbox) = grid.bbox() else {
        return Err(Error::InvalidArgument(format!(
            "{}: the voxel set is empty; binvox has no empty cube",
            path.display()
        )));
    };
    let dim = bbox.dim().into_iter().max().expect("three axes");
    if dim > MAX_BINVOX_DIM {
        return Err(Error::InvalidArgument(format!(
            "{}: the voxels span {dim} voxels, more than the {MAX_BINVOX_DIM}^3 cube voxelkit \
             writes as binvox; lower the resolution or write .vdb",
            path.display()
        )));
    }
    let mut cube = bbox;
    cube.max = bbox.min.map(|v| v + dim as i64 - 1);
    let mask = DenseMask::from_grid(grid, cube)?;
    let t = grid.transform;
    let corner = t.index_to_world(bbox.min) - glam::DVec3::splat(t.voxel_size / 2.0);
    write_atomic(path, |tmp| {
        let file = std::fs::File::create(tmp).map_err(|e| Error::io(path, e))?;
        let mut out = std::io::BufWriter::new(file);
        let io = |e| Error::io(path, e);
        write!(
            out,
            "#binvox 1\ndim {dim} {dim} {dim}\ntranslate {} {} {}\nscale {}\ndata\n",
            corner.x,
            corner.y,
            corner.z,
            t.voxel_size * dim as f64
        )
        .map_err(io)?;
        let d = dim as usize;
        let mut run: Option<(bool, u8)> = None;
        for x in 0..d {
            for z in 0..d {
                for y in 0..d {
                    let on = mask.get_index((x * d + y) * d + z);
                    run = match run {
                        Some((v, n)) if v == on && n < u8::MAX => Some((v, n + 1)),
                        Some((v, n)) => {
                            out.write_all(&[u8::from(v), n]).map_err(io)?;
                            Some((on, 1))
                        }
                        None => Some((on, 1)),
                    };
                }
            }
        }
        if let Some((v, n)) = run {
            out.write_all(&[u8::from(v), n]).map_err(io)?;
        }
        out.flush().map_err(io)
    })
}

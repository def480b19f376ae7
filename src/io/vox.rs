//! MagicaVoxel `.vox` output through `dot_vox` (the format's maintained Rust crate, which also
//! reads it back): one model holding the voxel set, placed from its bounding box's minimum,
//! at most 256 voxels along each axis (the format's model limit: larger sets are refused with
//! the reason). Colours come from the `Cd` channel, quantized to a palette of 6 x 6 x 6
//! levels; without colours every voxel takes one light grey. Written atomically.

use super::atomic::write_atomic;
use crate::error::{Error, Result};
use crate::grid::SparseGrid;
use dot_vox::{Color, DotVoxData, Model, Size, Voxel};
use std::path::Path;

/// The largest model `.vox` holds, voxels per axis.
pub const MAX_VOX_DIM: u64 = 256;

/// Palette index of a colour with channels in 0..1: 6 levels per channel.
fn palette_index(c: [f32; 3]) -> u8 {
    let level = |v: f32| (v.clamp(0.0, 1.0) * 5.0).round() as u8;
    level(c[0]) * 36 + level(c[1]) * 6 + level(c[2])
}

/// The palette: the 216 quantized colours, then light grey (index 216) for voxels without
/// colour, then padding to MagicaVoxel's 256 entries.
fn palette() -> Vec<Color> {
    let step = |l: u8| l * 51;
    let mut p: Vec<Color> = (0..216u8)
        .map(|i| Color {
            r: step(i / 36),
            g: step(i / 6 % 6),
            b: step(i % 6),
            a: 255,
        })
        .collect();
    p.resize(
        256,
        Color {
            r: 200,
            g: 200,
            b: 200,
            a: 255,
        },
    );
    p
}

const GREY: u8 = 216;

/// Writes the voxels of `grid` (with their `Cd` colours) to `path` as MagicaVoxel `.vox`.
pub fn write_vox(path: &Path, grid: &SparseGrid) -> Result<()> {
    let refuse = |why: String| Error::InvalidArgument(format!("{}: {why}", path.display()));
    let Some(bbox) = grid.bbox() else {
        return Err(refuse(
            "the voxel set is empty; .vox has no empty model".into(),
        ));
    };
    let dim = bbox.dim();
    if dim.iter().any(|&d| d > MAX_VOX_DIM) {
        return Err(refuse(format!(
            "the voxels span {}x{}x{}, past the {MAX_VOX_DIM}^3 model of .vox; lower the \
             resolution or write .vdb",
            dim[0], dim[1], dim[2]
        )));
    }
    let mut voxels = Vec::with_capacity(grid.voxel_count() as usize);
    let at = |v: i64, a: usize| (v - bbox.min[a]) as u8;
    for leaf in grid.leaves() {
        for n in leaf.offsets() {
            let c = crate::grid::offset_coord(leaf.origin, n);
            let i = leaf.color.as_ref().map_or(GREY, |cd| palette_index(cd[n]));
            voxels.push(Voxel {
                x: at(c[0], 0),
                y: at(c[1], 1),
                z: at(c[2], 2),
                i,
            });
        }
    }
    for o in grid.tiles().blocks() {
        for n in 0..crate::grid::LEAF_VOXELS {
            let c = crate::grid::offset_coord(o, n);
            voxels.push(Voxel {
                x: at(c[0], 0),
                y: at(c[1], 1),
                z: at(c[2], 2),
                i: GREY,
            });
        }
    }
    let data = DotVoxData {
        version: 150,
        index_map: Vec::new(),
        models: vec![Model {
            size: Size {
                x: dim[0] as u32,
                y: dim[1] as u32,
                z: dim[2] as u32,
            },
            voxels,
        }],
        palette: palette(),
        materials: Vec::new(),
        scenes: Vec::new(),
        layers: Vec::new(),
    };
    write_atomic(path, |tmp| {
        let file = std::fs::File::create(tmp).map_err(|e| Error::io(path, e))?;
        let mut out = std::io::BufWriter::new(file);
        data.write_vox(&mut out).map_err(|e| Error::io(path, e))?;
        std::io::Write::flush(&mut out).map_err(|e| Error::io(path, e))
    })
}

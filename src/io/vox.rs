//! MagicaVoxel `.vox` output through `dot_vox` (the format's maintained Rust crate, which also
//! reads it back): one model holding the voxel set, placed from its bounding box's minimum,
//! when it fits the format's 256^3 model; larger sets are split into one model per 256^3
//! block, placed by the scene graph, up to 2048 voxels per axis (refused past it with the
//! reason). Colours come from the `Cd` channel, quantized to a palette of 6 x 6 x 6
//! levels; without colours every voxel takes one light grey. Written atomically.

use super::atomic::write_atomic;
use crate::error::{Error, Result};
use crate::grid::SparseGrid;
use dot_vox::{Color, Dict, DotVoxData, Frame, Layer, Model, SceneNode, ShapeModel, Size, Voxel};
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

/// The widest voxel set written, voxels per axis: 8 models of 256 (MagicaVoxel's world).
pub const MAX_VOX_SPAN: u64 = 8 * MAX_VOX_DIM;

/// Writes the voxels of `grid` (with their `Cd` colours) to `path` as MagicaVoxel `.vox`:
/// one model when the set fits in 256^3, else one model per occupied 256^3 block of its
/// box, each placed by a transform node of the scene graph.
pub fn write_vox(path: &Path, grid: &SparseGrid) -> Result<()> {
    let refuse = |why: String| Error::InvalidArgument(format!("{}: {why}", path.display()));
    let Some(bbox) = grid.bbox() else {
        return Err(refuse(
            "the voxel set is empty; .vox has no empty model".into(),
        ));
    };
    let dim = bbox.dim();
    if dim.iter().any(|&d| d > MAX_VOX_SPAN) {
        return Err(refuse(format!(
            "the voxels span {}x{}x{}, past the {MAX_VOX_SPAN} voxels per axis of a .vox \
             scene ({MAX_VOX_DIM}^3 models); lower the resolution or write .vdb",
            dim[0], dim[1], dim[2]
        )));
    }
    // Voxels by model: the 256^3 block of the box they fall in.
    let blocks = dim.map(|d| d.div_ceil(MAX_VOX_DIM) as usize);
    let mut by_block: Vec<Vec<Voxel>> = vec![Vec::new(); blocks[0] * blocks[1] * blocks[2]];
    let mut add = |c: [i64; 3], i: u8| {
        let r = [0, 1, 2].map(|a| (c[a] - bbox.min[a]) as u64);
        let b = r.map(|v| (v / MAX_VOX_DIM) as usize);
        let at = r.map(|v| (v % MAX_VOX_DIM) as u8);
        by_block[(b[2] * blocks[1] + b[1]) * blocks[0] + b[0]].push(Voxel {
            x: at[0],
            y: at[1],
            z: at[2],
            i,
        });
    };
    for leaf in grid.leaves() {
        for n in leaf.offsets() {
            let i = leaf.color.as_ref().map_or(GREY, |cd| palette_index(cd[n]));
            add(crate::grid::offset_coord(leaf.origin, n), i);
        }
    }
    for o in grid.tiles().blocks() {
        for n in 0..crate::grid::LEAF_VOXELS {
            add(crate::grid::offset_coord(o, n), GREY);
        }
    }
    let mut models = Vec::new();
    let mut offsets = Vec::new();
    for (k, voxels) in by_block.into_iter().enumerate() {
        if voxels.is_empty() {
            continue;
        }
        let b = [
            k % blocks[0],
            k / blocks[0] % blocks[1],
            k / (blocks[0] * blocks[1]),
        ];
        let offset = [0, 1, 2].map(|a| b[a] as u64 * MAX_VOX_DIM);
        let size = [0, 1, 2].map(|a| (dim[a] - offset[a]).min(MAX_VOX_DIM) as u32);
        models.push(Model {
            size: Size {
                x: size[0],
                y: size[1],
                z: size[2],
            },
            voxels,
        });
        offsets.push(offset);
    }
    let (scenes, layers) = if models.len() > 1 {
        scene_graph(&models, &offsets)
    } else {
        (Vec::new(), Vec::new())
    };
    let data = DotVoxData {
        version: 150,
        index_map: Vec::new(),
        models,
        palette: palette(),
        materials: Vec::new(),
        scenes,
        layers,
    };
    write_atomic(path, |tmp| {
        let file = std::fs::File::create(tmp).map_err(|e| Error::io(path, e))?;
        let mut out = std::io::BufWriter::new(file);
        data.write_vox(&mut out).map_err(|e| Error::io(path, e))?;
        std::io::Write::flush(&mut out).map_err(|e| Error::io(path, e))
    })
}

/// MagicaVoxel's scene graph for several models: a root transform over a group of one
/// transform and shape per model. A model's `_t` is where its centre lies (its voxel
/// `size / 2`, rounded down), so `_t = offset + size / 2` puts its voxel 0 at `offset`.
fn scene_graph(models: &[Model], offsets: &[[u64; 3]]) -> (Vec<SceneNode>, Vec<Layer>) {
    let dict = |pairs: &[(&str, String)]| -> Dict {
        pairs
            .iter()
            .map(|(k, v)| (k.to_string(), v.clone()))
            .collect()
    };
    let mut nodes = vec![
        SceneNode::Transform {
            attributes: Dict::new(),
            frames: vec![Frame::new(Dict::new())],
            child: 1,
            layer_id: u32::MAX,
        },
        SceneNode::Group {
            attributes: Dict::new(),
            children: Vec::new(),
        },
    ];
    let mut children = Vec::new();
    for (id, (model, offset)) in models.iter().zip(offsets).enumerate() {
        let size = [model.size.x, model.size.y, model.size.z];
        let centre = [0, 1, 2].map(|a| offset[a] + u64::from(size[a] / 2));
        let transform = nodes.len() as u32;
        children.push(transform);
        nodes.push(SceneNode::Transform {
            attributes: dict(&[("_name", format!("block {id}"))]),
            frames: vec![Frame::new(dict(&[(
                "_t",
                format!("{} {} {}", centre[0], centre[1], centre[2]),
            )]))],
            child: transform + 1,
            layer_id: 0,
        });
        nodes.push(SceneNode::Shape {
            attributes: Dict::new(),
            models: vec![ShapeModel {
                model_id: id as u32,
                attributes: Dict::new(),
            }],
        });
    }
    nodes[1] = SceneNode::Group {
        attributes: Dict::new(),
        children,
    };
    let layer = Layer {
        attributes: dict(&[("_name", "voxelkit".to_string())]),
    };
    (nodes, vec![layer])
}

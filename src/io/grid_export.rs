//! The grids a write makes, as plain arrays for another library to build its own grids from
//! (the OpenVDB bridge, crate voxelkit-openvdb, builds OpenVDB grids of them in memory and
//! writes them with OpenVDB's own `io::File`): the same grids, values, tiles, classes and
//! metadata the `.vdb` writer writes.

use super::grid_out::{GridOut, ValueType, block_origin, tree};
use super::vdb_format::MetaValue;
use crate::error::Result;
use crate::grid::LEAF_VOXELS;
use std::path::Path;

/// One grid as arrays.
#[derive(Clone, Debug)]
pub struct ExportedGrid {
    pub name: String,
    /// OpenVDB's value type: `bool`, `float` or `vec3s`.
    pub value_type: &'static str,
    /// OpenVDB's grid class (`fog volume`, `level set`), when it has one.
    pub class: Option<&'static str>,
    /// OpenVDB's vector type of a vec3s grid (`covariant normalize`, `invariant`).
    pub vector_type: Option<&'static str>,
    /// The caller's metadata and `voxelkit_version`.
    pub metadata: Vec<(String, MetaValue)>,
    pub voxel_size: f64,
    /// World position of the centre of voxel (0,0,0).
    pub origin: [f64; 3],
    /// The value outside the tree.
    pub background: f32,
    /// Every leaf's origin (3 x i32), in OpenVDB's tree order.
    pub leaf_origins: Vec<i32>,
    /// Every leaf's active mask (8 x u64; bit `n` of word `n / 64` is voxel
    /// `n = 64 x + 8 y + z`, OpenVDB's order).
    pub masks: Vec<u64>,
    /// Every leaf's 512 values (3 x 512 for vectors, none for bool grids) in voxel order,
    /// inactive ones as a reader sees them: the background, or minus it inside a level set.
    pub values: Vec<f32>,
    /// Every tile's origin and edge (8 or 128): 4 x i32.
    pub tiles: Vec<i32>,
    /// Whether the tiles are active (a level set's interior tiles are not), and their value.
    pub tiles_active: bool,
    pub tile_value: f32,
}

/// The arrays of `g`; errors name `path`.
pub(super) fn export_grid(path: &Path, g: &GridOut) -> Result<ExportedGrid> {
    let tree = tree(path, g)?;
    let value_type = g.values.value_type();
    let components = match value_type {
        ValueType::Bool => 0,
        ValueType::Float => 1,
        ValueType::Vec3 => 3,
    };
    let leaves = tree.leaves.len();
    let tiles: usize = tree.nodes.iter().map(|n| n.tile_count()).sum();
    crate::system::check_fits(
        (leaves * (12 + 64 + 4 * components * LEAF_VOXELS) + tiles * 16) as u64,
        None,
        &format!("{}: grid `{}` as arrays", path.display(), g.name),
    )?;
    let t = g.grid.transform;
    let mut out = ExportedGrid {
        name: g.name.to_string(),
        value_type: match value_type {
            ValueType::Bool => "bool",
            ValueType::Float => "float",
            ValueType::Vec3 => "vec3s",
        },
        class: g.class,
        vector_type: g.vector_type,
        metadata: g.metadata.to_vec(),
        voxel_size: t.voxel_size,
        origin: t.origin.to_array(),
        background: g.values.background(),
        leaf_origins: Vec::with_capacity(3 * leaves),
        masks: Vec::with_capacity(8 * leaves),
        values: vec![0.0; components * LEAF_VOXELS * leaves],
        tiles: Vec::with_capacity(4 * tiles),
        tiles_active: g.values.active_tiles(),
        tile_value: if tiles > 0 {
            g.values.tile_value()
        } else {
            0.0
        },
    };
    let mut values = out
        .values
        .chunks_exact_mut((components * LEAF_VOXELS).max(1));
    for &(_, leaf) in &tree.leaves {
        out.leaf_origins
            .extend(leaf.origin.iter().map(|&v| v as i32));
        out.masks.extend_from_slice(&leaf.mask);
        if components > 0 {
            let dense = values.next().expect("values for every leaf");
            g.values.dense_values(leaf, dense);
        }
    }
    for node in &tree.nodes {
        let key = (node.root, node.slot, 0);
        if node.tile {
            out.tiles.extend(block_origin(&key, false));
            out.tiles.push(128);
        }
        for slot in crate::grid::bits::ones(&node.tiles[..]) {
            out.tiles
                .extend(block_origin(&(key.0, key.1, slot as u16), true));
            out.tiles.push(8);
        }
    }
    Ok(out)
}

//! A check of one grid's transform, tree topology and leaf buffers, byte by byte, before
//! OpenVDB reads them. OpenVDB 10 trusts the sizes stored in front of compressed chunks: a
//! negative ("stored raw") size is copied into the node's buffer before it is compared with
//! the buffer's size, and blosc trusts the sizes in its own chunk header. Every chunk is
//! checked here against what the node holds, and every node against the bytes of the grid.

use super::vdb_format::{
    BLOSC_PAD_BYTES, COMPRESS_ACTIVE_MASK, COMPRESS_BLOSC, COMPRESS_ZIP, HALF_SUFFIX,
    LEAF_MASK_BYTES, NODE_LOG2, value_type,
};
use super::vdb_structure::Reader;
use std::collections::HashSet;

type Check = std::result::Result<(), String>;

/// What a grid type name tells about its tree's stored values.
#[derive(Clone, Copy)]
pub(super) struct TreeFormat {
    /// Bytes of one value at full precision (root tiles, background, inactive values).
    pub(super) value: u64,
    /// Bytes of one value in node and leaf buffers (half precision where saved so).
    pub(super) stored: u64,
    /// Values stored at half precision.
    pub(super) half: bool,
    pub(super) leaf: LeafKind,
}

#[derive(Clone, Copy, PartialEq)]
pub(super) enum LeafKind {
    /// Compressed values after the voxel mask (float, double, integer and vector trees).
    Values,
    /// Voxel mask, origin, value mask: bool trees.
    Bool,
    /// Voxel mask and origin: mask trees.
    Mask,
}

impl TreeFormat {
    /// The format of a standard (5-4-3) tree of a registered type, or why it is not read.
    pub(super) fn of(type_name: &str) -> std::result::Result<Self, String> {
        let half = type_name.ends_with(HALF_SUFFIX);
        let value_type = value_type(type_name);
        // (bytes, floating point, leaf layout)
        let (value, real, leaf) = match value_type {
            "bool" => (1, false, LeafKind::Bool),
            "mask" => (1, false, LeafKind::Mask),
            "float" => (4, true, LeafKind::Values),
            "double" => (8, true, LeafKind::Values),
            "int32" => (4, false, LeafKind::Values),
            "int64" => (8, false, LeafKind::Values),
            "vec3i" => (12, false, LeafKind::Values),
            "vec3s" => (12, true, LeafKind::Values),
            "vec3d" => (24, true, LeafKind::Values),
            _ => {
                return Err(format!(
                    "a grid of type `{type_name}`: voxelkit reads the standard trees of bool, mask, \
                     float, double, int32, int64 and vec3 grids"
                ));
            }
        };
        let components = if value_type.starts_with("vec3") { 3 } else { 1 };
        let half = half && real;
        let stored = if half { 2 * components } else { value };
        Ok(TreeFormat {
            value,
            stored,
            half,
            leaf,
        })
    }
}

/// Skips a grid's transform: a map type name and the map's fixed-size data (a frustum holds
/// one linear map of its own).
pub(super) fn transform(r: &mut Reader, what: &str) -> Check {
    let name = r.short_string(what)?;
    if name == "NonlinearFrustumMap" {
        // Bounding box (2 x vec3d), taper, depth, then its linear part.
        r.skip(64, what)?;
        let inner = r.short_string(what)?;
        return linear_map(r, &inner, what);
    }
    linear_map(r, &name, what)
}

fn linear_map(r: &mut Reader, name: &str, what: &str) -> Check {
    // Each vec3d is 24 bytes: scale maps keep the scale and four derived vectors.
    let bytes = match name {
        "TranslationMap" => 24,
        "ScaleMap" | "UniformScaleMap" => 5 * 24,
        "ScaleTranslateMap" | "UniformScaleTranslateMap" => 6 * 24,
        "AffineMap" | "UnitaryMap" => 128,
        _ => return Err(format!("{what}: a transform of unknown kind `{name}`")),
    };
    r.skip(bytes, what)
}

/// The nodes of a tree, counted from its topology.
#[derive(Default)]
struct Nodes {
    /// Internal nodes by depth (0: the root's children, 32^3 slots; 1: 16^3 slots).
    internal: [u64; 2],
    /// Every leaf's active voxel count, in the order OpenVDB reads their buffers.
    leaves: Vec<u16>,
    /// Active tiles as voxelkit keeps them once read: the lowest internal nodes holding 8^3
    /// tiles, and the 128^3 tiles of the nodes above them.
    nodes_with_blocks: u64,
    node_tiles: u64,
}

/// Checks a tree's topology (ending by `block`), then its leaf buffers (ending by `end`).
/// Returns the bytes OpenVDB allocates for the tree as it reads it, and its tiles in
/// voxelkit's grid.
pub(super) fn tree(
    r: &mut Reader,
    format: TreeFormat,
    compression: u32,
    block: u64,
    end: u64,
    what: &str,
) -> std::result::Result<u64, String> {
    let file_len = std::mem::replace(&mut r.len, block);
    let nodes = topology(r, format, compression, what);
    r.len = file_len;
    let nodes = nodes?;
    r.seek(block);
    r.len = end;
    let buffers = nodes
        .leaves
        .iter()
        .try_for_each(|&active| leaf_buffer(r, format, compression, active, what));
    r.len = file_len;
    buffers?;
    let tiles = crate::grid::tile_bytes(nodes.nodes_with_blocks, nodes.node_tiles);
    Ok(tree_memory(format, nodes.internal, nodes.leaves.len() as u64).saturating_add(tiles))
}

/// OpenVDB's memory for a tree of `internal` nodes (by depth) and `leaves` leaves: a slot
/// (child pointer or value) per internal-node entry and two masks, a leaf's values (a bit
/// mask for bool and mask leaves) and its mask.
pub(super) fn tree_memory(format: TreeFormat, internal: [u64; 2], leaves: u64) -> u64 {
    let slot = format.value.max(8).next_multiple_of(8);
    let internal: u64 = NODE_LOG2
        .iter()
        .zip(internal)
        .map(|(&log2, count)| {
            let entries = 1u64 << (3 * log2);
            count.saturating_mul(entries * slot + entries / 4 + 64)
        })
        .sum();
    let leaf = match format.leaf {
        LeafKind::Values => 512 * format.value + LEAF_MASK_BYTES + 48,
        LeafKind::Bool => 2 * LEAF_MASK_BYTES + 48,
        LeafKind::Mask => LEAF_MASK_BYTES + 48,
    };
    internal.saturating_add(leaves.saturating_mul(leaf))
}

/// The root's tiles and children, each child's nodes down to the leaves' masks. Leaves are
/// listed in the order OpenVDB reads their buffers: root children by origin (x, then y,
/// then z), below them by position.
fn topology(
    r: &mut Reader,
    format: TreeFormat,
    compression: u32,
    what: &str,
) -> std::result::Result<Nodes, String> {
    let buffer_count = r.u32(what)?;
    if buffer_count != 1 {
        return Err(format!("{what}: a tree of {buffer_count} buffers"));
    }
    r.skip(format.value, what)?; // background
    let tiles = r.u32(what)?;
    let children = r.u32(what)?;
    let root_edge = 1i64 << (NODE_LOG2[0] + NODE_LOG2[1] + 3);
    let mut keys = HashSet::new();
    let mut key = |r: &mut Reader| -> std::result::Result<[i64; 3], String> {
        let mut c = [0i64; 3];
        for v in &mut c {
            *v = i32::from_le_bytes(r.bytes::<4>(what)?) as i64;
        }
        if c.iter().any(|v| v.rem_euclid(root_edge) != 0) {
            return Err(format!(
                "{what}: a root entry at {c:?}, off the {root_edge}-voxel lattice"
            ));
        }
        if !keys.insert(c) {
            return Err(format!("{what}: two root entries at {c:?}"));
        }
        Ok(c)
    };
    for _ in 0..tiles {
        key(r)?;
        r.skip(format.value + 1, what)?; // value, active flag
    }
    let mut nodes = Nodes::default();
    let mut subtrees = Vec::new();
    for _ in 0..children {
        let origin = key(r)?;
        let first = nodes.leaves.len();
        internal_node(r, format, compression, 0, &mut nodes, what)?;
        subtrees.push((origin, nodes.leaves.split_off(first)));
    }
    subtrees.sort_unstable_by_key(|(origin, _)| *origin);
    nodes.leaves = subtrees
        .into_iter()
        .flat_map(|(_, leaves)| leaves)
        .collect();
    Ok(nodes)
}

/// An internal node at `depth` (0: the root's children): child and value masks, its
/// compressed tile values, then its children, all counted in `nodes`.
fn internal_node(
    r: &mut Reader,
    format: TreeFormat,
    compression: u32,
    depth: usize,
    nodes: &mut Nodes,
    what: &str,
) -> Check {
    nodes.internal[depth] += 1;
    let mask_bytes = (1u64 << (3 * NODE_LOG2[depth])) / 8;
    let child_mask = r.vec(mask_bytes, what)?;
    let value_mask = r.vec(mask_bytes, what)?;
    let slots = 8 * mask_bytes;
    compressed_values(r, format, compression, slots, ones(&value_mask), what)?;
    let tiles = value_mask
        .iter()
        .zip(&child_mask)
        .map(|(v, c)| (v & !c).count_ones() as u64)
        .sum::<u64>();
    if depth + 1 == NODE_LOG2.len() {
        nodes.nodes_with_blocks += u64::from(tiles > 0);
    } else {
        nodes.node_tiles += tiles;
    }
    for _ in 0..ones(&child_mask) {
        if depth + 1 == NODE_LOG2.len() {
            nodes
                .leaves
                .push(ones(&r.bytes::<{ LEAF_MASK_BYTES as usize }>(what)?) as u16);
        } else {
            internal_node(r, format, compression, depth + 1, nodes, what)?;
        }
    }
    Ok(())
}

/// The words of a mask stored as little-endian bytes (whole words, as every node mask is).
pub(super) fn mask_words(mask: &[u8]) -> impl Iterator<Item = u64> + '_ {
    mask.chunks_exact(8)
        .map(|w| u64::from_le_bytes(w.try_into().expect("8 bytes")))
}

/// The bits set in a mask stored as bytes, counted a word at a time.
pub(super) fn ones(mask: &[u8]) -> u64 {
    mask_words(mask).map(|w| u64::from(w.count_ones())).sum()
}

/// One leaf's buffer record, laid out by the tree's leaf kind. A value leaf repeats its voxel
/// mask, which must agree with its topology: OpenVDB counts the stored values by one or the
/// other.
pub(super) fn leaf_buffer(
    r: &mut Reader,
    format: TreeFormat,
    compression: u32,
    active: u16,
    what: &str,
) -> Check {
    match format.leaf {
        LeafKind::Bool => r.skip(2 * LEAF_MASK_BYTES + 12, what),
        LeafKind::Mask => r.skip(LEAF_MASK_BYTES + 12, what),
        LeafKind::Values => {
            let at = r.pos;
            let mask = ones(&r.bytes::<{ LEAF_MASK_BYTES as usize }>(what)?);
            if mask != active as u64 {
                return Err(format!(
                    "{what}: the leaf at byte {at} has {mask} active voxels, its topology {active}"
                ));
            }
            compressed_values(r, format, compression, 8 * LEAF_MASK_BYTES, mask, what)
        }
    }
}

/// OpenVDB's values of a node of `slots` values, `active` of them active: a flag saying
/// what follows (up to two inactive values and a selection mask), then every value, or with
/// mask compression only the active ones.
pub(super) fn compressed_values(
    r: &mut Reader,
    format: TreeFormat,
    compression: u32,
    slots: u64,
    active: u64,
    what: &str,
) -> Check {
    let flag = r.bytes::<1>(what)?[0];
    let (inactive_values, selection_mask) = match flag {
        0 | 1 | 6 => (0, false),
        2 => (1, false),
        3 => (0, true),
        4 => (1, true),
        5 => (2, true),
        _ => return Err(format!("{what}: a node with compression flag {flag}")),
    };
    r.skip(inactive_values * format.value, what)?;
    if selection_mask {
        r.skip(slots / 8, what)?;
    }
    let count = if compression & COMPRESS_ACTIVE_MASK != 0 && flag != 6 {
        active
    } else {
        slots
    };
    if format.half && count == 0 {
        return Ok(()); // OpenVDB writes nothing for no values at half precision
    }
    chunk(r, compression, count * format.stored, what)
}

/// A chunk of `bytes` bytes as OpenVDB stores it: raw, or behind a signed 64-bit size when
/// compressed (negative: stored raw; positive: a zip stream or a blosc chunk).
fn chunk(r: &mut Reader, compression: u32, bytes: u64, what: &str) -> Check {
    if compression & (COMPRESS_BLOSC | COMPRESS_ZIP) == 0 {
        return r.skip(bytes, what);
    }
    let at = r.pos;
    let size = r.i64(what)?;
    if size <= 0 {
        if size.unsigned_abs() != bytes {
            return Err(format!(
                "{what}: a raw chunk at byte {at} of {} bytes where the node holds {bytes}",
                size.unsigned_abs()
            ));
        }
        return r.skip(bytes, what);
    }
    let size = size as u64;
    if compression & COMPRESS_BLOSC == 0 {
        return r.skip(size, what);
    }
    // A blosc chunk: a 16-byte header with the uncompressed and the compressed size.
    if size < 16 {
        return Err(format!(
            "{what}: a compressed chunk at byte {at} shorter than its header"
        ));
    }
    let header = r.bytes::<16>(what)?;
    let word = |i: usize| u32::from_le_bytes(header[i..i + 4].try_into().expect("4 bytes")) as u64;
    if word(4) > bytes.max(BLOSC_PAD_BYTES as u64) || word(12) != size {
        return Err(format!(
            "{what}: a compressed chunk at byte {at} whose sizes disagree with its node"
        ));
    }
    r.skip(size - 16, what)
}

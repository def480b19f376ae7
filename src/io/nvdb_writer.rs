//! Writes `.nvdb` files: NanoVDB's own in-memory layout (ABI 32.4, what NanoVDB 10.0 reads,
//! Debian's libnanovdb-dev), which GPU renderers and simulators load as one buffer. No GPU
//! and no NanoVDB library are needed: the layout is plain data.
//!
//! A file is a segment: a 16-byte header, one 176-byte description and the name of each grid,
//! then each grid's buffer, uncompressed (codec NONE: a GPU program maps it as it is). A
//! grid's buffer is breadth-first, every part 32-byte aligned: the grid (672 bytes: name,
//! transform, world box, class, type), the tree (64: offsets and counts of each level), the
//! root with one tile per 4096^3 child, then every 4096^3 node, every 128^3 node and every
//! leaf, each in the tree order `grid_out` gives. Child offsets are bytes from the parent;
//! leaves hold all 512 values (a level set's inactive voxels at plus or minus its
//! background), nodes their tiles' values. Each node carries the box of its active values
//! and, for float grids, their minimum and maximum. The grid's checksum is NanoVDB's full
//! one: a CRC-32 of the grid, tree and root, and one of every node's CRC-32.
//!
//! A grid is built whole in memory (counted by the memory plan first), its nodes filled in
//! parallel; grids are written one after another and the header last.

use super::direct_file::DirectFile;
use super::grid_out::{GridOut, GridValues, TreeNode, ValueType, block_origin, tree};
use super::vdb::WriteClocks;
use super::vdb_format::{FOG_VOLUME, LEVEL_SET};
use crate::error::{Error, Result};
use crate::grid::{LEAF_VOXELS, Leaf};
use rayon::prelude::*;
use std::path::Path;

/// "NanoVDB0", little-endian.
const MAGIC: u64 = 0x3042_4456_6f6e_614e;
/// Major 32, minor 4, patch 2 in 11, 11 and 10 bits: the NanoVDB of OpenVDB 10.0.
const VERSION: u32 = (32 << 21) | (4 << 10) | 2;
const ALIGN: usize = 32;
const GRID_BYTES: usize = 672;
const TREE_BYTES: usize = 64;
const ROOT_TILE_BYTES: usize = 32;
const GRID_NAME_BYTES: usize = 256;
const FILE_HEADER_BYTES: usize = 16;
const GRID_META_BYTES: usize = 176;

/// NanoVDB's grid flags.
const HAS_BBOX: u32 = 1 << 1;
const HAS_MIN_MAX: u32 = 1 << 2;
const IS_BREADTH_FIRST: u32 = 1 << 5;
/// A node's flags: nothing to draw in it; it has active values (and so a box).
const NODE_SKIP: u64 = 1;
const NODE_HAS_BBOX: u64 = 2;

/// The edge of a lower internal node, in voxels.
const LOWER_EDGE: i32 = 128;

/// NanoVDB's grid types and classes.
fn grid_type(v: ValueType) -> u32 {
    match v {
        ValueType::Float => 1,
        ValueType::Vec3 => 6,
        ValueType::Bool => 11,
    }
}

fn grid_class(class: Option<&str>) -> u32 {
    match class {
        Some(LEVEL_SET) => 1,
        Some(FOG_VOLUME) => 2,
        _ => 0,
    }
}

fn align(n: usize) -> usize {
    n.div_ceil(ALIGN) * ALIGN
}

/// The sizes of a grid's parts for its value type, as NanoVDB's structs lay them out.
#[derive(Clone, Copy)]
struct Sizes {
    value_type: ValueType,
    /// A value, and a node's average and deviation (float for vectors, bool for bools).
    value: usize,
    stats: usize,
    /// A slot of an internal node's table: a value or a child offset (8 bytes).
    slot: usize,
    root: usize,
    upper: usize,
    lower: usize,
    leaf: usize,
    /// Where a leaf's values begin.
    leaf_values: usize,
}

impl Sizes {
    fn of(value_type: ValueType) -> Sizes {
        let (value, stats): (usize, usize) = match value_type {
            ValueType::Float => (4, 4),
            ValueType::Vec3 => (12, 4),
            ValueType::Bool => (1, 1),
        };
        let slot = value.max(8).next_multiple_of(8);
        let internal = |log2: u32| {
            let slots = 1usize << (3 * log2);
            // box, flags, value mask, child mask, minimum, maximum, average, deviation
            let table = align(32 + 2 * slots / 8 + 2 * value + 2 * stats);
            align(table + slots * slot)
        };
        // origin, box extent, flags and the active mask take 80 bytes.
        let (leaf_values, leaf) = match value_type {
            ValueType::Bool => (80, 160),
            _ => {
                let start = align(80 + 2 * value + 2 * stats);
                (start, align(start + LEAF_VOXELS * value))
            }
        };
        Sizes {
            value_type,
            value,
            stats,
            slot,
            root: align(28 + 3 * value + 2 * stats),
            upper: internal(5),
            lower: internal(4),
            leaf,
            leaf_values,
        }
    }

    /// Offsets of an internal node's statistics and table.
    fn internal_offsets(self, log2: u32) -> (usize, usize) {
        let masks = 2 * (1usize << (3 * log2)) / 8;
        let stats = 32 + masks;
        (stats, align(stats + 2 * self.value + 2 * self.stats))
    }
}

/// What a node's active values span: their box and, for float grids, their range.
#[derive(Clone, Copy)]
struct Span {
    min: [i32; 3],
    max: [i32; 3],
    low: f32,
    high: f32,
}

impl Span {
    const EMPTY: Span = Span {
        min: [i32::MAX; 3],
        max: [i32::MIN; 3],
        low: f32::INFINITY,
        high: f32::NEG_INFINITY,
    };

    fn is_empty(&self) -> bool {
        self.min[0] > self.max[0]
    }

    fn add(mut self, other: &Span) -> Span {
        for a in 0..3 {
            self.min[a] = self.min[a].min(other.min[a]);
            self.max[a] = self.max[a].max(other.max[a]);
        }
        self.low = self.low.min(other.low);
        self.high = self.high.max(other.high);
        self
    }

    /// A whole block of `edge` voxels at `origin` holding `value`.
    fn block(origin: [i32; 3], edge: i32, value: f32) -> Span {
        Span {
            min: origin,
            max: origin.map(|v| v + edge - 1),
            low: value,
            high: value,
        }
    }

    /// The node's flags: a level set's node lying wholly beyond a voxel from its surface has
    /// nothing to draw (NanoVDB's own rule).
    fn flags(&self, level_set_delta: Option<f32>) -> u64 {
        if self.is_empty() {
            return NODE_SKIP;
        }
        let far = level_set_delta.is_some_and(|d| self.low > d || self.high < -d);
        NODE_HAS_BBOX | u64::from(far)
    }
}

fn put<const N: usize>(buf: &mut [u8], at: usize, bytes: [u8; N]) {
    buf[at..at + N].copy_from_slice(&bytes);
}

fn put_coord(buf: &mut [u8], at: usize, c: [i32; 3]) {
    for (a, v) in c.iter().enumerate() {
        put(buf, at + 4 * a, v.to_le_bytes());
    }
}

fn put_box(buf: &mut [u8], at: usize, span: &Span) {
    put_coord(buf, at, span.min);
    put_coord(buf, at + 12, span.max);
}

/// One value of the grid's type at `at`: a bool, a float, or a vector from `v[..3]`.
fn put_value(buf: &mut [u8], at: usize, value_type: ValueType, v: &[f32]) {
    match value_type {
        ValueType::Bool => buf[at] = u8::from(v[0] != 0.0),
        ValueType::Float => put(buf, at, v[0].to_le_bytes()),
        ValueType::Vec3 => (0..3).for_each(|c| put(buf, at + 4 * c, v[c].to_le_bytes())),
    }
}

/// A node's minimum and maximum (float grids only; other types leave them zero).
fn put_range(buf: &mut [u8], at: usize, sizes: Sizes, span: &Span) {
    if sizes.value_type == ValueType::Float && !span.is_empty() {
        put(buf, at, span.low.to_le_bytes());
        put(buf, at + 4, span.high.to_le_bytes());
    }
}

fn set_bit(mask: &mut [u8], at: usize, n: usize) {
    mask[at + n / 8] |= 1 << (n % 8);
}

/// Fills a leaf: its box, flags, mask, range and values. Returns what it spans.
fn fill_leaf(
    buf: &mut [u8],
    leaf: &Leaf,
    values: GridValues,
    sizes: Sizes,
    delta: Option<f32>,
) -> Span {
    let origin = leaf.origin.map(|v| v as i32);
    let mut span = Span::EMPTY;
    for n in leaf.offsets() {
        let c = [(n >> 6) as i32, ((n >> 3) & 7) as i32, (n & 7) as i32];
        for a in 0..3 {
            span.min[a] = span.min[a].min(origin[a] + c[a]);
            span.max[a] = span.max[a].max(origin[a] + c[a]);
        }
    }
    for (w, word) in leaf.mask.iter().enumerate() {
        put(buf, 16 + 8 * w, word.to_le_bytes());
    }
    match sizes.value_type {
        ValueType::Bool => {
            // Every active voxel is true.
            for (w, word) in leaf.mask.iter().enumerate() {
                put(buf, sizes.leaf_values + 8 * w, word.to_le_bytes());
            }
        }
        value_type => {
            let components = if value_type == ValueType::Vec3 { 3 } else { 1 };
            let mut dense = [0f32; 3 * LEAF_VOXELS];
            let dense = &mut dense[..components * LEAF_VOXELS];
            values.dense_values(leaf, dense);
            for (n, v) in dense.chunks_exact(components).enumerate() {
                put_value(buf, sizes.leaf_values + n * sizes.value, value_type, v);
            }
            if value_type == ValueType::Float {
                for n in leaf.offsets() {
                    span.low = span.low.min(dense[n]);
                    span.high = span.high.max(dense[n]);
                }
            }
        }
    }
    put_coord(buf, 0, span.min);
    for a in 0..3 {
        buf[12 + a] = (span.max[a] - span.min[a]) as u8;
    }
    buf[15] = span.flags(delta) as u8;
    put_range(buf, 80, sizes, &span);
    span
}

/// Fills an internal node (`upper`: a 4096^3 one, else a 128^3 one) from its slots in use,
/// ascending: each a tile (with its origin) or a child, whose byte offsets from this node and
/// spans `child_offsets` gives in order. Returns what it spans and its active tile count.
fn fill_internal(
    buf: &mut [u8],
    upper: bool,
    slots: impl Iterator<Item = (usize, Option<[i32; 3]>)>,
    child_offsets: &mut dyn Iterator<Item = (i64, Span)>,
    values: GridValues,
    sizes: Sizes,
    delta: Option<f32>,
) -> (Span, u32) {
    let (log2, child_edge) = if upper { (5, LOWER_EDGE) } else { (4, 8) };
    let table_slots = 1usize << (3 * log2);
    let (stats_at, table) = sizes.internal_offsets(log2);
    let value_mask = 32;
    let child_mask = 32 + table_slots / 8;
    let background = values.background();
    for n in 0..table_slots {
        put_value(
            buf,
            table + n * sizes.slot,
            sizes.value_type,
            &[background; 3],
        );
    }
    let mut span = Span::EMPTY;
    let mut active_tiles = 0;
    for (n, tile) in slots {
        match tile {
            Some(origin) => {
                let v = values.tile_value();
                put_value(buf, table + n * sizes.slot, sizes.value_type, &[v; 3]);
                if values.active_tiles() {
                    set_bit(buf, value_mask, n);
                    active_tiles += 1;
                    span = span.add(&Span::block(origin, child_edge, v));
                }
            }
            None => {
                let (offset, child) = child_offsets.next().expect("one child per child slot");
                set_bit(buf, child_mask, n);
                put(buf, table + n * sizes.slot, offset.to_le_bytes());
                span = span.add(&child);
            }
        }
    }
    put_box(buf, 0, &span);
    put(buf, 24, span.flags(delta).to_le_bytes());
    put_range(buf, stats_at, sizes, &span);
    (span, active_tiles)
}

/// A grid's buffer and what the file's description of it says.
struct GridBuffer {
    bytes: Vec<u8>,
    voxels: u64,
    span: Span,
    nodes: [u32; 3],
    active_tiles: [u32; 3],
    value_type: ValueType,
    class: u32,
}

fn build(path: &Path, g: &GridOut) -> Result<GridBuffer> {
    let sizes = Sizes::of(g.values.value_type());
    if g.name.len() >= GRID_NAME_BYTES {
        return Err(Error::Vdb {
            path: path.to_path_buf(),
            message: format!("grid name `{}` is longer than NanoVDB's 255 bytes", g.name),
        });
    }
    let tree = tree(path, g)?;
    let uppers: Vec<&[TreeNode]> = tree.nodes.chunk_by(|a, b| a.root == b.root).collect();
    let lowers: Vec<&TreeNode> = tree.nodes.iter().filter(|node| !node.tile).collect();
    let leaves: Vec<&Leaf> = tree.leaves.iter().map(|&(_, leaf)| leaf).collect();
    let root_at = GRID_BYTES + TREE_BYTES;
    let upper_at = root_at + sizes.root + uppers.len() * ROOT_TILE_BYTES;
    let lower_at = upper_at + uppers.len() * sizes.upper;
    let leaf_at = lower_at + lowers.len() * sizes.lower;
    let end = leaf_at + leaves.len() * sizes.leaf;
    crate::system::check_fits(
        end as u64,
        None,
        &format!("{}: NanoVDB grid `{}`", path.display(), g.name),
    )?;
    let mut bytes = vec![0u8; end];
    let class = grid_class(g.class);
    let delta = (class == 1).then_some(g.grid.transform.voxel_size as f32);

    let (head, nodes) = bytes.split_at_mut(upper_at);
    let (upper_bytes, rest) = nodes.split_at_mut(lower_at - upper_at);
    let (lower_bytes, leaf_bytes) = rest.split_at_mut(leaf_at - lower_at);
    let leaf_spans: Vec<Span> = leaf_bytes
        .par_chunks_mut(sizes.leaf)
        .zip(&leaves)
        .map(|(buf, leaf)| fill_leaf(buf, leaf, g.values, sizes, delta))
        .collect();
    // Each lower node filled, its leaves a range of the tree's.
    let lower_spans: Vec<(Span, u32)> = lower_bytes
        .par_chunks_mut(sizes.lower)
        .zip(lowers.par_iter())
        .enumerate()
        .map(|(i, (buf, node))| {
            let here = lower_at + i * sizes.lower;
            let mut children = node
                .leaves
                .clone()
                .map(|l| ((leaf_at + l * sizes.leaf - here) as i64, leaf_spans[l]));
            let slots = node.blocks(&tree).map(|(slot, leaf)| {
                let tile = || block_origin(&(node.root, node.slot, slot), true);
                (usize::from(slot), leaf.is_none().then(tile))
            });
            fill_internal(buf, false, slots, &mut children, g.values, sizes, delta)
        })
        .collect();
    let mut first_lower = 0;
    let mut upper_spans = Vec::with_capacity(uppers.len());
    for (i, (buf, nodes)) in upper_bytes.chunks_mut(sizes.upper).zip(&uppers).enumerate() {
        let here = upper_at + i * sizes.upper;
        let mut children =
            (first_lower..).map(|l| ((lower_at + l * sizes.lower - here) as i64, lower_spans[l].0));
        let slots = nodes.iter().map(|node| {
            let tile = || block_origin(&(node.root, node.slot, 0), false);
            (usize::from(node.slot), node.tile.then(tile))
        });
        upper_spans.push(fill_internal(
            buf,
            true,
            slots,
            &mut children,
            g.values,
            sizes,
            delta,
        ));
        first_lower += nodes.iter().filter(|node| !node.tile).count();
    }

    // The root: its box, table size, background and range, then one tile per child.
    let span = upper_spans.iter().fold(Span::EMPTY, |s, u| s.add(&u.0));
    let root = &mut head[root_at..];
    put_box(root, 0, &span);
    put(root, 24, (uppers.len() as u32).to_le_bytes());
    put_value(root, 28, sizes.value_type, &[g.values.background(); 3]);
    put_range(root, 28 + sizes.value, sizes, &span);
    for (i, node) in uppers.iter().enumerate() {
        let tile = sizes.root + i * ROOT_TILE_BYTES;
        let o = node[0].root.map(|v| u64::from(v as u32 >> 12));
        put(root, tile, (o[2] | o[1] << 21 | o[0] << 42).to_le_bytes());
        let child = (upper_at + i * sizes.upper - root_at) as i64;
        put(root, tile + 8, child.to_le_bytes());
        put_value(
            root,
            tile + 20,
            sizes.value_type,
            &[g.values.background(); 3],
        );
    }

    let lower_tiles: u32 = lower_spans.iter().map(|s| s.1).sum();
    let upper_tiles: u32 = upper_spans.iter().map(|s| s.1).sum();
    let voxels = leaves.iter().map(|l| u64::from(l.count())).sum::<u64>()
        + u64::from(lower_tiles) * 512
        + u64::from(upper_tiles) * (LOWER_EDGE as u64).pow(3);
    let nodes = [
        leaves.len() as u32,
        lowers.len() as u32,
        uppers.len() as u32,
    ];

    // The tree: offsets from it to the first leaf, lower, upper node and the root.
    let tree = &mut head[GRID_BYTES..];
    let offset = |at: usize, n: u32| if n > 0 { (at - GRID_BYTES) as u64 } else { 0 };
    put(tree, 0, offset(leaf_at, nodes[0]).to_le_bytes());
    put(tree, 8, offset(lower_at, nodes[1]).to_le_bytes());
    put(tree, 16, offset(upper_at, nodes[2]).to_le_bytes());
    put(tree, 24, ((root_at - GRID_BYTES) as u64).to_le_bytes());
    for (i, n) in nodes
        .iter()
        .chain(&[lower_tiles, upper_tiles, 0])
        .enumerate()
    {
        put(tree, 32 + 4 * i, n.to_le_bytes());
    }
    put(tree, 56, voxels.to_le_bytes());

    let t = g.grid.transform;
    let grid = &mut head[..GRID_BYTES];
    put(grid, 0, MAGIC.to_le_bytes());
    put(grid, 16, VERSION.to_le_bytes());
    let mut flags = IS_BREADTH_FIRST;
    if !span.is_empty() {
        flags |= HAS_BBOX;
    }
    if sizes.value_type == ValueType::Float {
        flags |= HAS_MIN_MAX;
    }
    put(grid, 20, flags.to_le_bytes());
    put(grid, 28, 1u32.to_le_bytes()); // one grid in this buffer, index 0
    put(grid, 32, (end as u64).to_le_bytes());
    grid[40..40 + g.name.len()].copy_from_slice(g.name.as_bytes());
    put_map(grid, 296, t.voxel_size, t.origin.to_array());
    let world = world_box(&span, t.voxel_size, t.origin.to_array());
    for (i, v) in world.iter().flatten().enumerate() {
        put(grid, 560 + 8 * i, v.to_le_bytes());
    }
    for a in 0..3 {
        put(grid, 608 + 8 * a, t.voxel_size.to_le_bytes());
    }
    put(grid, 632, class.to_le_bytes());
    put(grid, 636, grid_type(sizes.value_type).to_le_bytes());

    let checksum = checksum(&bytes, upper_at, sizes, nodes);
    put(&mut bytes, 8, checksum.to_le_bytes());
    Ok(GridBuffer {
        bytes,
        voxels,
        span,
        nodes,
        active_tiles: [lower_tiles, upper_tiles, 0],
        value_type: sizes.value_type,
        class,
    })
}

/// NanoVDB's map of a uniform scale `h` and translation `origin`: the matrix, its inverse and
/// the translation in single then double precision, each with a taper of 1.
fn put_map(buf: &mut [u8], at: usize, h: f64, origin: [f64; 3]) {
    let diagonal = |d: f64| -> [f64; 9] { [d, 0.0, 0.0, 0.0, d, 0.0, 0.0, 0.0, d] };
    let mut single = at;
    for v in diagonal(h)
        .iter()
        .chain(&diagonal(1.0 / h))
        .chain(&origin)
        .chain(&[1.0])
    {
        put(buf, single, (*v as f32).to_le_bytes());
        single += 4;
    }
    let mut double = at + 88;
    for v in diagonal(h)
        .iter()
        .chain(&diagonal(1.0 / h))
        .chain(&origin)
        .chain(&[1.0])
    {
        put(buf, double, v.to_le_bytes());
        double += 8;
    }
}

/// The world box NanoVDB records: from the first active voxel's index to one past the last,
/// mapped to world space (an empty grid's is inverted at the extremes).
fn world_box(span: &Span, h: f64, origin: [f64; 3]) -> [[f64; 3]; 2] {
    if span.is_empty() {
        return [[f64::MAX; 3], [-f64::MAX; 3]];
    }
    [
        [0, 1, 2].map(|a| origin[a] + h * f64::from(span.min[a])),
        [0, 1, 2].map(|a| origin[a] + h * (f64::from(span.max[a]) + 1.0)),
    ]
}

/// NanoVDB's full checksum: the CRC-32 of the grid, tree and root with its tiles (after the
/// magic number and the checksum itself, up to the nodes at `nodes_at`) in the low half; in
/// the high half the CRC-32 of every node's CRC-32 (upper, lower, then leaves) each held in
/// 8 bytes, NanoVDB's `uint_fast32_t` on 64-bit Linux.
fn checksum(bytes: &[u8], nodes_at: usize, sizes: Sizes, nodes: [u32; 3]) -> u64 {
    let head = crc32fast::hash(&bytes[16..nodes_at]);
    if nodes[2] == 0 {
        return u64::from(head) | (u64::from(u32::MAX) << 32);
    }
    let lower_at = nodes_at + nodes[2] as usize * sizes.upper;
    let leaf_at = lower_at + nodes[1] as usize * sizes.lower;
    let crcs = |region: &[u8], size: usize| -> Vec<u32> {
        region.par_chunks(size).map(crc32fast::hash).collect()
    };
    let mut all = crcs(&bytes[nodes_at..lower_at], sizes.upper);
    all.extend(crcs(&bytes[lower_at..leaf_at], sizes.lower));
    all.extend(crcs(&bytes[leaf_at..], sizes.leaf));
    let wide: Vec<u8> = all
        .iter()
        .flat_map(|c| u64::from(*c).to_le_bytes())
        .collect();
    u64::from(head) | (u64::from(crc32fast::hash(&wide)) << 32)
}

/// NanoVDB's hash of a grid name (its file index's `nameKey`).
fn name_key(name: &str) -> u64 {
    name.bytes().fold(0u64, |hash, b| {
        let overflow = hash >> 56;
        hash.wrapping_mul(67).wrapping_add(u64::from(b) + overflow)
    })
}

/// The file's description of one grid, then its name with a closing NUL.
fn grid_meta(name: &str, g: &GridBuffer, voxel_size: f64, origin: [f64; 3]) -> Vec<u8> {
    let mut m = vec![0u8; GRID_META_BYTES];
    let size = g.bytes.len() as u64;
    put(&mut m, 0, size.to_le_bytes());
    put(&mut m, 8, size.to_le_bytes()); // stored uncompressed
    put(&mut m, 16, name_key(name).to_le_bytes());
    put(&mut m, 24, g.voxels.to_le_bytes());
    put(&mut m, 32, grid_type(g.value_type).to_le_bytes());
    put(&mut m, 36, g.class.to_le_bytes());
    let world = world_box(&g.span, voxel_size, origin);
    for (i, v) in world.iter().flatten().enumerate() {
        put(&mut m, 40 + 8 * i, v.to_le_bytes());
    }
    put_box(&mut m, 88, &g.span);
    for a in 0..3 {
        put(&mut m, 112 + 8 * a, voxel_size.to_le_bytes());
    }
    put(&mut m, 136, (name.len() as u32 + 1).to_le_bytes());
    for (i, n) in g
        .nodes
        .iter()
        .chain(&[1])
        .chain(&g.active_tiles)
        .enumerate()
    {
        put(&mut m, 140 + 4 * i, n.to_le_bytes());
    }
    put(&mut m, 172, VERSION.to_le_bytes());
    m.extend_from_slice(name.as_bytes());
    m.push(0);
    m
}

/// Writes `grids` to the new file `file` as one NanoVDB segment; errors name `path`, the
/// output it becomes.
pub(super) fn write_nvdb_grids(
    file: &Path,
    path: &Path,
    grids: &[GridOut],
    clocks: &mut WriteClocks,
) -> Result<()> {
    let io_error = |e| Error::io(path, e);
    let mut out = DirectFile::create(file).map_err(io_error)?;
    let index_bytes = FILE_HEADER_BYTES
        + grids
            .iter()
            .map(|g| GRID_META_BYTES + g.name.len() + 1)
            .sum::<usize>();
    // Room for the index, written over it once the grids' sizes are known.
    out.write_all(&vec![0; index_bytes]).map_err(io_error)?;
    let mut index = Vec::with_capacity(index_bytes);
    index.extend_from_slice(&MAGIC.to_le_bytes());
    index.extend_from_slice(&VERSION.to_le_bytes());
    index.extend_from_slice(&(grids.len() as u16).to_le_bytes());
    index.extend_from_slice(&0u16.to_le_bytes()); // codec NONE
    for g in grids {
        let buffer = clocks.encode.time(|| build(path, g))?;
        clocks
            .write
            .time(|| out.write_all(&buffer.bytes))
            .map_err(io_error)?;
        let t = g.grid.transform;
        index.extend(grid_meta(
            &g.name,
            &buffer,
            t.voxel_size,
            t.origin.to_array(),
        ));
    }
    clocks
        .write
        .time(|| {
            use std::os::unix::fs::FileExt;
            out.finish()?.write_all_at(&index, 0)
        })
        .map_err(io_error)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sizes NanoVDB 10.0's headers give (`sizeof` of its leaf, lower, upper and root
    /// node structs for float, Vec3f and bool).
    #[test]
    fn part_sizes_are_nanovdbs() {
        let cases = [
            (ValueType::Float, [2144, 33856, 270400, 64]),
            (ValueType::Vec3, [6272, 66624, 532544, 96]),
            (ValueType::Bool, [160, 33856, 270400, 64]),
        ];
        for (v, want) in cases {
            let s = Sizes::of(v);
            assert_eq!([s.leaf, s.lower, s.upper, s.root], want);
        }
        assert_eq!(Sizes::of(ValueType::Vec3).leaf_values, 128);
        assert_eq!(
            Sizes::of(ValueType::Float).internal_offsets(4),
            (1056, 1088)
        );
    }

    #[test]
    fn names_hash_as_nanovdb_hashes_them() {
        // NanoVDB's stringHash: h = h * 67 + byte + (h >> 56), from 0.
        assert_eq!(name_key(""), 0);
        assert_eq!(name_key("a"), 97);
        assert_eq!(name_key("ab"), 97 * 67 + 98);
    }
}

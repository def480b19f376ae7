//! Writes `.vdb` files directly from sparse grids, in the layout OpenVDB 10 reads (file
//! format 224): leaves and tiles are encoded in parallel, each root child's topology and each
//! batch of leaf buffers on its own thread, and a writer thread writes each piece as soon as
//! those before it are written (`direct_file`: large files around the page cache). Building
//! OpenVDB's own tree first and letting it write serially took longer than voxelizing.
//!
//! A grid is laid out as OpenVDB lays out its standard 5-4-3 tree: the root's children (4096^3
//! blocks) in coordinate order, each with its 128^3 children and 128^3 tiles, those with
//! their leaves and 8^3 tiles; then every leaf's buffer in the same order.

use super::direct_file::DirectFile;
use super::grid_out::{GridOut, GridValues, Tree, TreeNode, ValueType, tree};
use super::vdb::WriteClocks;
use super::vdb_chunks::{compression_name, push_chunk};
use super::vdb_format::{
    COMPRESS_ACTIVE_MASK, FILE_VERSION, HALF_SUFFIX, LIBRARY_VERSION, MAGIC, NODE_LOG2, tree_type,
};
use super::vdb_tree_structure::{TreeFormat, tree_memory};
use crate::error::{Error, Result};
use crate::grid::{CoordBox, LEAF_VOXELS, Leaf, Transform};
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::OnceLock;

/// Leaves per parallel batch of leaf buffers.
const BATCH: usize = 2048;
/// Leaves whose lookups in other grids (a level set's inside, a fog's band) are made one after
/// another before their buffers: the lookups' memory misses then overlap, where each alone
/// would wait for its own between two leaves' compression.
const WARM_RUN: usize = 64;

/// The standard tree's type name of a grid.
pub(super) fn tree_type_of(values: GridValues) -> String {
    tree_type(match values.value_type() {
        ValueType::Bool => "bool",
        ValueType::Vec3 => "vec3s",
        ValueType::Float => "float",
    })
}

/// The value of an active tile, as stored (half precision when `half`).
fn push_tile_value(out: &mut Vec<u8>, values: GridValues, half: bool) {
    match values.value_type() {
        ValueType::Bool => out.push(1),
        _ => push_reals(out, std::iter::once(values.tile_value()), 1, half),
    }
}

/// The active values of `leaf`, in offset order, as stored.
fn push_leaf_values(out: &mut Vec<u8>, leaf: &Leaf, values: GridValues, half: bool) {
    if values.value_type() == ValueType::Float {
        let mut floats = [0.0; LEAF_VOXELS];
        let count = values.active_floats(leaf, &mut floats);
        push_reals(out, floats[..count].iter().copied(), count, half);
    } else {
        let components = 3 * leaf.count() as usize;
        push_reals(out, values.active_vectors(leaf).flatten(), components, half);
    }
}

/// The `count` `values` as stored, one after another, written in place into room made once
/// (a push per value costs more than the value).
fn push_reals(out: &mut Vec<u8>, values: impl Iterator<Item = f32>, count: usize, half: bool) {
    let width = if half { 2 } else { 4 };
    let start = out.len();
    out.resize(start + width * count, 0);
    let room = out[start..].chunks_exact_mut(width);
    if half {
        for (bytes, v) in room.zip(values) {
            bytes.copy_from_slice(&half::f16::from_f32(v).to_le_bytes());
        }
    } else {
        for (bytes, v) in room.zip(values) {
            bytes.copy_from_slice(&v.to_le_bytes());
        }
    }
}

/// How the file is written.
#[derive(Clone, Copy)]
pub(super) struct Encoding {
    /// OpenVDB's per-grid `COMPRESS_*` flags (active-value masks always on).
    pub compression: u32,
    /// Float and vector values at half precision.
    pub half: bool,
}

/// Writes `grids` to the new file `file` as a `.vdb` file (not a stream); errors name
/// `path`, the output it becomes.
pub(super) fn write_grids(
    file: &Path,
    path: &Path,
    grids: &[GridOut],
    encoding: Encoding,
    clocks: &mut WriteClocks,
) -> Result<()> {
    let out = DirectFile::create(file).map_err(|e| Error::io(path, e))?;
    encode_grids(out, path, grids, encoding, clocks)
}

/// Where a `.vdb`'s bytes go, front to back, then the grids' end offsets patched in.
pub(super) trait Output: Send {
    type Done;
    fn write_all(&mut self, bytes: &[u8]) -> std::io::Result<()>;
    /// Makes the bytes so far durable, where that means anything.
    fn sync_data(&mut self) -> std::io::Result<()>;
    /// Ends the writing with each `(at, value)` of `patches` written as 8 bytes at `at`.
    fn finish(self, patches: &[(u64, u64)]) -> std::io::Result<Self::Done>;
}

impl Output for DirectFile {
    type Done = ();

    fn write_all(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        DirectFile::write_all(self, bytes)
    }

    fn sync_data(&mut self) -> std::io::Result<()> {
        DirectFile::sync_data(self)
    }

    fn finish(self, patches: &[(u64, u64)]) -> std::io::Result<()> {
        use std::os::unix::fs::FileExt;
        let file = DirectFile::finish(self)?;
        patches
            .iter()
            .try_for_each(|&(at, end)| file.write_all_at(&(end as i64).to_le_bytes(), at))
    }
}

impl Output for Vec<u8> {
    type Done = Vec<u8>;

    fn write_all(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        self.extend_from_slice(bytes);
        Ok(())
    }

    fn sync_data(&mut self) -> std::io::Result<()> {
        Ok(())
    }

    fn finish(mut self, patches: &[(u64, u64)]) -> std::io::Result<Vec<u8>> {
        for &(at, end) in patches {
            self[at as usize..at as usize + 8].copy_from_slice(&(end as i64).to_le_bytes());
        }
        Ok(self)
    }
}

/// Encodes `grids` into `out` (a file, or memory: `Vec<u8>`); errors name `path`.
pub(super) fn encode_grids<O: Output>(
    out: O,
    path: &Path,
    grids: &[GridOut],
    encoding: Encoding,
    clocks: &mut WriteClocks,
) -> Result<O::Done> {
    let io_error = |e| Error::io(path, e);
    // Every piece goes to a writer thread as soon as it is encoded, numbered in file order;
    // a grid's end is known only once its last buffer is, so it is patched in afterwards.
    // The write clock counts only the time spent waiting for the writer at the end.
    let (send, pieces) = std::sync::mpsc::channel();
    let spent = SpentBuffers::default();
    let (out, done, patches) = std::thread::scope(|scope| {
        let writer = scope.spawn(|| write_in_order(out, pieces, &spent));
        let mut file_out = Pieces {
            send,
            next: 0,
            pos: 0,
        };
        file_out.push(file_header(grids.len()));
        let mut patches = Vec::new();
        // The grids' heads (their topologies: serial in good part each) are built side by
        // side before any leaf buffer.
        let mut heads = clocks.encode.time(|| {
            grids
                .par_iter()
                .map(|g| grid_head(path, g, encoding))
                .collect::<Vec<_>>()
                .into_iter()
        });
        let encoded = grids.iter().enumerate().try_for_each(|(n, g)| {
            let head = heads.next().expect("a head for each grid")?;
            let mut descriptor = descriptor_names(g, head.half);
            let grid_pos = file_out.pos + descriptor.len() as u64 + 24;
            let block_pos = grid_pos + head.head.len() as u64;
            for p in [grid_pos, block_pos, 0] {
                descriptor.extend_from_slice(&(p as i64).to_le_bytes());
            }
            file_out.push(descriptor);
            file_out.push(head.head);
            let first = file_out.next;
            file_out.next += head.leaves.len().div_ceil(BATCH);
            let send = &file_out.send;
            let size = clocks.encode.time(|| {
                stream_leaf_buffers(
                    &head.leaves,
                    g.values,
                    head.compression,
                    head.half,
                    &spent,
                    |k, b| send.send((first + k, Piece::Bytes(b))).is_ok(),
                )
            });
            file_out.pos += size;
            patches.push((grid_pos - 8, file_out.pos));
            // A large grid followed by others starts reaching the disk while they are
            // encoded, so that the final sync has less left to wait for.
            if n + 1 < grids.len() && file_out.pos - grid_pos >= EARLY_SYNC_BYTES {
                file_out.sync();
            }
            Ok(())
        });
        drop(file_out);
        let (out, written) = clocks
            .write
            .time(|| writer.join())
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        (out, encoded.and(written.map_err(io_error)), patches)
    });
    done?;
    clocks.write.time(|| out.finish(&patches)).map_err(io_error)
}

/// The numbered pieces of a file on their way to the writer thread, and the file's length
/// so far.
struct Pieces {
    send: std::sync::mpsc::Sender<(usize, Piece)>,
    next: usize,
    pos: u64,
}

impl Pieces {
    fn push(&mut self, bytes: Vec<u8>) {
        self.pos += bytes.len() as u64;
        self.send_next(Piece::Bytes(bytes));
    }

    fn sync(&mut self) {
        self.send_next(Piece::Sync);
    }

    fn send_next(&mut self, piece: Piece) {
        // A closed channel means the writer stopped at an error, which its join reports.
        let _ = self.send.send((self.next, piece));
        self.next += 1;
    }
}

/// What the writer thread is handed: bytes to append, or a point at which to sync the file.
enum Piece {
    Bytes(Vec<u8>),
    Sync,
}

/// Buffers the writer has written, for the encoders to fill again: fresh memory costs more
/// than encoding into it (the kernel zeroes and maps each page on first touch).
#[derive(Default)]
struct SpentBuffers(std::sync::Mutex<Vec<Vec<u8>>>);

impl SpentBuffers {
    /// The most kept: about as many as the encoders run ahead of the writer.
    const MOST: usize = 16;

    /// An empty buffer with room for at least `capacity` bytes.
    fn take(&self, capacity: usize) -> Vec<u8> {
        let spent = self.0.lock().map(|mut free| free.pop()).ok().flatten();
        let mut buffer = spent.unwrap_or_default();
        buffer.clear();
        buffer.reserve(capacity);
        buffer
    }

    fn give_back(&self, buffer: Vec<u8>) {
        if let Ok(mut free) = self.0.lock()
            && free.len() < Self::MOST
        {
            free.push(buffer);
        }
    }
}

/// Writes the numbered pieces to `out` in their order, whatever order they arrive in;
/// stops at the first error, closing the channel so that the encoders stop too.
fn write_in_order<O: Output>(
    mut out: O,
    pieces: std::sync::mpsc::Receiver<(usize, Piece)>,
    spent: &SpentBuffers,
) -> (O, std::io::Result<()>) {
    let mut waiting = BTreeMap::new();
    let mut next = 0;
    for (n, piece) in pieces {
        waiting.insert(n, piece);
        while let Some(piece) = waiting.remove(&next) {
            next += 1;
            let done = match piece {
                Piece::Bytes(bytes) => {
                    let written = out.write_all(&bytes);
                    spent.give_back(bytes);
                    written
                }
                Piece::Sync => out.sync_data(),
            };
            if let Err(e) = done {
                return (out, Err(e));
            }
        }
    }
    (out, Ok(()))
}

/// The size from which a grid that other grids follow is synced as soon as it is written.
const EARLY_SYNC_BYTES: u64 = 16 << 20;

/// The magic number, versions, a flag for grid offsets, a UUID, no file metadata, the grid
/// count.
pub(super) fn file_header(grids: usize) -> Vec<u8> {
    let mut out = Vec::new();
    out.extend_from_slice(&MAGIC.to_le_bytes());
    out.extend_from_slice(&FILE_VERSION.to_le_bytes());
    LIBRARY_VERSION
        .iter()
        .for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
    out.push(1); // grid offsets follow each descriptor
    out.extend_from_slice(uuid().as_bytes());
    out.extend_from_slice(&0u32.to_le_bytes());
    out.extend_from_slice(&(grids as u32).to_le_bytes());
    out
}

/// A random (version 4) UUID in its 36-character text form.
fn uuid() -> String {
    use std::hash::{BuildHasher, Hasher};
    let mut h = std::collections::hash_map::RandomState::new().build_hasher();
    h.write_u128(
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos()),
    );
    let mut rng = crate::random::SplitMix64(h.finish());
    let mut bytes = [0u8; 16];
    bytes[..8].copy_from_slice(&rng.next_u64().to_le_bytes());
    bytes[8..].copy_from_slice(&rng.next_u64().to_le_bytes());
    bytes[6] = bytes[6] & 0x0f | 0x40;
    bytes[8] = bytes[8] & 0x3f | 0x80;
    let hex: String = bytes.iter().map(|b| format!("{b:02x}")).collect();
    format!(
        "{}-{}-{}-{}-{}",
        &hex[..8],
        &hex[8..12],
        &hex[12..16],
        &hex[16..20],
        &hex[20..]
    )
}

pub(super) fn push_string(out: &mut Vec<u8>, s: &str) {
    out.extend_from_slice(&(s.len() as u32).to_le_bytes());
    out.extend_from_slice(s.as_bytes());
}

/// A grid descriptor's names: the grid's, its tree type's and the empty name of the grid it
/// would be an instance of; its three offsets follow.
pub(super) fn descriptor_names(g: &GridOut, half: bool) -> Vec<u8> {
    let mut out = Vec::new();
    push_string(&mut out, &g.name);
    let mut tree_type = tree_type_of(g.values);
    if half {
        tree_type.push_str(HALF_SUFFIX);
    }
    push_string(&mut out, &tree_type);
    push_string(&mut out, "");
    out
}

/// A grid's head, from its compression flags through its topology, and its leaves in the
/// order their buffers follow it.
struct GridHead<'g> {
    head: Vec<u8>,
    leaves: Vec<&'g Leaf>,
    compression: u32,
    half: bool,
}

fn grid_head<'g>(path: &Path, g: &GridOut<'g>, encoding: Encoding) -> Result<GridHead<'g>> {
    let tree = tree(path, g)?;
    let half = encoding.half && (g.values.value_type() != ValueType::Bool);
    let compression = encoding.compression | COMPRESS_ACTIVE_MASK;
    // Each root child's topology on its own thread.
    let roots: Vec<&[TreeNode]> = tree.nodes.chunk_by(|a, b| a.root == b.root).collect();
    let encoded: Vec<(Vec<u8>, [u64; 2])> = roots
        .par_iter()
        .map(|nodes| root_child_topology(&tree, nodes, g.values, compression, half))
        .collect();
    let leaves: Vec<&Leaf> = tree.leaves.iter().map(|&(_, leaf)| leaf).collect();
    let internal = encoded
        .iter()
        .fold([0u64; 2], |a, e| [a[0] + e.1[0], a[1] + e.1[1]]);
    let stats = TreeStats {
        bbox: g.grid.bbox(),
        voxels: g.grid.voxel_count(),
        internal,
        leaves: leaves.len() as u64,
    };
    let mut head = Vec::new();
    push_grid_head(
        &mut head,
        g,
        encoding,
        &stats,
        g.grid.transform,
        roots.len(),
    );
    for (bytes, _) in &encoded {
        head.extend_from_slice(bytes);
    }
    Ok(GridHead {
        head,
        leaves,
        compression,
        half,
    })
}

/// A grid's head up to its root children: its compression flags, metadata (with `stats`),
/// transform, buffer count and background, no root tiles, then the count of root children
/// that follow.
pub(super) fn push_grid_head(
    out: &mut Vec<u8>,
    g: &GridOut,
    encoding: Encoding,
    stats: &TreeStats,
    transform: Transform,
    root_children: usize,
) {
    out.extend_from_slice(&(encoding.compression | COMPRESS_ACTIVE_MASK).to_le_bytes());
    push_metadata(out, g, encoding, stats);
    push_transform(out, transform);
    out.extend_from_slice(&1u32.to_le_bytes()); // one buffer per leaf
    match g.values {
        GridValues::Bool => out.push(0),
        GridValues::Normals | GridValues::Colors => out.extend_from_slice(&[0; 12]),
        values => out.extend_from_slice(&values.background().to_le_bytes()),
    }
    out.extend_from_slice(&0u32.to_le_bytes()); // no root tiles
    out.extend_from_slice(&(root_children as u32).to_le_bytes());
}

/// A root child's own bytes: its origin, then its masks and tile values from its 128^3 slots
/// in order (each a slot number and whether it holds a tile rather than a node).
pub(super) fn push_root_child(
    out: &mut Vec<u8>,
    origin: [i32; 3],
    slots: impl Iterator<Item = (u16, bool)>,
    values: GridValues,
    compression: u32,
    half: bool,
) {
    origin
        .iter()
        .for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
    let words = (1usize << (3 * NODE_LOG2[0])) / 64;
    let (mut children, mut tiles) = (vec![0u64; words], vec![0u64; words]);
    for (slot, tile) in slots {
        let mask = if tile { &mut tiles } else { &mut children };
        mask[slot as usize / 64] |= 1 << (slot % 64);
    }
    push_internal_values(out, &children, &tiles, values, compression, half);
}

/// Encodes the buffers of `leaves` in batches of `BATCH` on all threads, taken in order so
/// that the first are ready first, handing each to `deliver` with its number; stops early
/// when `deliver` refuses one. Their total size.
fn stream_leaf_buffers(
    leaves: &[&Leaf],
    values: GridValues,
    compression: u32,
    half: bool,
    spent: &SpentBuffers,
    deliver: impl Fn(usize, Vec<u8>) -> bool + Sync,
) -> u64 {
    use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering::Relaxed};
    let constant_chunks: Vec<OnceLock<Vec<u8>>> =
        (0..=LEAF_VOXELS).map(|_| OnceLock::new()).collect();
    let batches: Vec<&[&Leaf]> = leaves.chunks(BATCH).collect();
    let (next, size, refused) = (
        AtomicUsize::new(0),
        AtomicU64::new(0),
        AtomicBool::new(false),
    );
    // Each task takes the next batch, whichever task it is: rayon would otherwise give
    // each thread a contiguous half, and the writer would wait for the second half's start.
    (0..batches.len()).into_par_iter().for_each(|_| {
        let k = next.fetch_add(1, Relaxed);
        if refused.load(Relaxed) {
            return;
        }
        let mut out = spent.take(batches[k].len() * 200);
        let mut scratch = Vec::new();
        for run in batches[k].chunks(WARM_RUN) {
            run.iter().for_each(|leaf| values.warm(leaf));
            for leaf in run {
                leaf_buffer(
                    &mut out,
                    &mut scratch,
                    leaf,
                    values,
                    &constant_chunks,
                    compression,
                    half,
                );
            }
        }
        size.fetch_add(out.len() as u64, Relaxed);
        if !deliver(k, out) {
            refused.store(true, Relaxed);
        }
    });
    size.into_inner()
}

/// One root child (a 4096^3 node, its slots `nodes` of `tree`): its origin, then its node
/// topology; its count of internal nodes at each depth.
fn root_child_topology(
    tree: &Tree,
    nodes: &[TreeNode],
    values: GridValues,
    compression: u32,
    half: bool,
) -> (Vec<u8>, [u64; 2]) {
    let mut out = Vec::new();
    let slots = nodes.iter().map(|node| (node.slot, node.tile));
    push_root_child(&mut out, nodes[0].root, slots, values, compression, half);
    let mut lower = 0;
    for node in nodes.iter().filter(|node| !node.tile) {
        lower += 1;
        let children = node.children(&tree.leaves);
        push_internal_values(&mut out, &children, node.tiles, values, compression, half);
        for (_, leaf) in &tree.leaves[node.leaves.clone()] {
            push_mask(&mut out, &leaf.mask);
        }
    }
    (out, [1, lower])
}

/// An internal node's child and value masks, then its tile values: every non-child slot
/// holds the background except the active tiles, so only those are stored.
fn push_internal_values(
    out: &mut Vec<u8>,
    children: &[u64],
    tiles: &[u64],
    values: GridValues,
    compression: u32,
    half: bool,
) {
    let none = vec![0u64; tiles.len()];
    let (active, inside) = if values.active_tiles() {
        (tiles, &none[..])
    } else {
        (&none[..], tiles)
    };
    for mask in [children, active] {
        push_mask(out, mask);
    }
    let outside: Vec<u64> = (0..tiles.len())
        .map(|w| !(children[w] | tiles[w]))
        .collect();
    push_inactive(out, inside, &outside);
    let count: u32 = active.iter().map(|w| w.count_ones()).sum();
    let mut data = Vec::new();
    (0..count).for_each(|_| push_tile_value(&mut data, values, half));
    push_values(out, &data, values, compression, half);
}

fn push_mask(out: &mut Vec<u8>, mask: &[u64]) {
    mask.iter()
        .for_each(|w| out.extend_from_slice(&w.to_le_bytes()));
}

/// What a node's inactive values are, as OpenVDB flags them: `-background` on the slots of
/// `inside`, the background on those of `outside` (a selection mask picks where both occur).
fn push_inactive(out: &mut Vec<u8>, inside: &[u64], outside: &[u64]) {
    let any = |m: &[u64]| m.iter().any(|&w| w != 0);
    match (any(inside), any(outside)) {
        (false, _) => out.push(0),    // all the background
        (true, false) => out.push(1), // all minus the background
        (true, true) => {
            out.push(3); // selected: the background; the others minus it
            push_mask(out, outside);
        }
    }
}

/// A leaf's buffer: its mask, then a bool leaf's origin and value bits, or another leaf's
/// active values.
fn leaf_buffer(
    out: &mut Vec<u8>,
    scratch: &mut Vec<u8>,
    leaf: &Leaf,
    values: GridValues,
    constant_chunks: &[OnceLock<Vec<u8>>],
    compression: u32,
    half: bool,
) {
    push_mask(out, &leaf.mask);
    if let GridValues::Bool = values {
        leaf.origin
            .iter()
            .for_each(|&v| out.extend_from_slice(&(v as i32).to_le_bytes()));
        push_mask(out, &leaf.mask); // every active voxel is true
        return;
    }
    let inside = values.inside(leaf.origin);
    let inactive_inside: [u64; 8] = std::array::from_fn(|w| inside[w] & !leaf.mask[w]);
    let inactive_outside: [u64; 8] = std::array::from_fn(|w| !(inside[w] | leaf.mask[w]));
    push_inactive(out, &inactive_inside, &inactive_outside);
    if let GridValues::Constant(_) = values {
        // A constant grid's chunk depends on the leaf's voxel count alone: each count is
        // compressed once.
        let chunk = constant_chunks[leaf.count() as usize].get_or_init(|| {
            let mut data = Vec::new();
            push_leaf_values(&mut data, leaf, values, half);
            let mut chunk = Vec::new();
            push_values(&mut chunk, &data, values, compression, half);
            chunk
        });
        out.extend_from_slice(chunk);
        return;
    }
    scratch.clear();
    push_leaf_values(scratch, leaf, values, half);
    push_values(out, scratch, values, compression, half);
}

/// Stored values as a chunk; at half precision no values are no bytes at all.
fn push_values(out: &mut Vec<u8>, data: &[u8], values: GridValues, compression: u32, half: bool) {
    if half && data.is_empty() {
        return;
    }
    let component = match values {
        GridValues::Bool => 1,
        _ if half => 2,
        _ => 4,
    };
    push_chunk(out, data, component, compression);
}

/// What a tree holds, as its metadata states it: its active voxels' box and count, its
/// internal nodes by depth and its leaves.
pub(super) struct TreeStats {
    pub bbox: Option<CoordBox>,
    pub voxels: u64,
    pub internal: [u64; 2],
    pub leaves: u64,
}

/// The grid's metadata map, sorted by name as OpenVDB keeps it: the caller's entries, then
/// the grid's name, class and vector type, and the statistics OpenVDB adds when it writes.
fn push_metadata(out: &mut Vec<u8>, g: &GridOut, encoding: Encoding, stats: &TreeStats) {
    use super::vdb_format::MetaValue;
    enum Meta {
        Str(String),
        Vec3i([i32; 3]),
        Int64(i64),
        Double(f64),
        Bool(bool),
    }
    let mut map: BTreeMap<&str, Meta> = g
        .metadata
        .iter()
        .map(|(k, v)| {
            let value = match v {
                MetaValue::Text(s) => Meta::Str(s.clone()),
                MetaValue::Int(n) => Meta::Int64(*n),
                MetaValue::Real(x) => Meta::Double(*x),
            };
            (k.as_str(), value)
        })
        .collect();
    map.insert("name", Meta::Str(g.name.to_string()));
    if let Some(class) = g.class {
        map.insert("class", Meta::Str(class.to_string()));
    }
    if let Some(kind) = g.vector_type {
        map.insert("vector_type", Meta::Str(kind.to_string()));
    }
    if let Some(b) = stats.bbox {
        map.insert("file_bbox_min", Meta::Vec3i(b.min.map(|v| v as i32)));
        map.insert("file_bbox_max", Meta::Vec3i(b.max.map(|v| v as i32)));
    }
    map.insert(
        "file_compression",
        Meta::Str(compression_name(encoding.compression).to_string()),
    );
    let format = TreeFormat::of(&tree_type_of(g.values)).expect("a standard tree");
    map.insert(
        "file_mem_bytes",
        Meta::Int64(tree_memory(format, stats.internal, stats.leaves) as i64),
    );
    map.insert("file_voxel_count", Meta::Int64(stats.voxels as i64));
    map.insert(
        "is_saved_as_half_float",
        Meta::Bool(encoding.half && (g.values.value_type() != ValueType::Bool)),
    );
    out.extend_from_slice(&(map.len() as u32).to_le_bytes());
    for (name, value) in map {
        push_string(out, name);
        let (type_name, bytes): (&str, Vec<u8>) = match value {
            Meta::Str(s) => ("string", s.into_bytes()),
            Meta::Vec3i(v) => ("vec3i", v.iter().flat_map(|c| c.to_le_bytes()).collect()),
            Meta::Int64(v) => ("int64", v.to_le_bytes().to_vec()),
            Meta::Double(v) => ("double", v.to_le_bytes().to_vec()),
            Meta::Bool(v) => ("bool", vec![v as u8]),
        };
        push_string(out, type_name);
        out.extend_from_slice(&(bytes.len() as u32).to_le_bytes());
        out.extend_from_slice(&bytes);
    }
}

/// A uniform scale and translation, as OpenVDB's `UniformScaleTranslateMap` stores it: the
/// translation, the scale, the voxel size and the scale's inverse, inverse square and
/// inverse double.
pub(super) fn push_transform(out: &mut Vec<u8>, t: Transform) {
    push_string(out, "UniformScaleTranslateMap");
    let s = t.voxel_size;
    let vectors = [
        t.origin.to_array(),
        [s; 3],
        [s; 3],
        [1.0 / s; 3],
        [1.0 / (s * s); 3],
        [0.5 / s; 3],
    ];
    for v in vectors {
        v.iter()
            .for_each(|c| out.extend_from_slice(&c.to_le_bytes()));
    }
}

//! A brick set merged into one `.vdb` without decoding a voxel. A brick whose edge is a
//! multiple of 128 voxels holds whole 128^3 nodes of OpenVDB's tree, and its file holds each
//! of them as the merged file does: the node's topology (masks, tile values, its leaves'
//! masks) and its leaves' compressed buffers, byte for byte. The merge walks each brick's
//! structure (masks and chunk sizes, never a value), sorts the nodes of all bricks into
//! OpenVDB's order and lays the file out (`Spliced`), building only the root's children
//! (4096^3 nodes: which of their slots hold a node or a tile) itself. Then either it copies
//! the bricks' bytes into place from their files (`splice_brick_set`), or the workers that
//! hold the bricks encoded in memory (`EncodedBrick`) write them into place themselves
//! (`Spliced::write_in_place`). It holds a few dozen bytes per 128^3 node and no voxel, so
//! its memory does not grow with the voxels merged.

use super::atomic::{check_output, write_atomic};
use super::brick_set::{BrickSet, brick_voxels};
use super::direct_file::{DirectFile, write_pieces_at};
use super::direct_read::{self, AlignedBlock};
use super::grid_out::{GridOut, block_origin, key};
use super::vdb::{
    Contents, MetaValue, WriteOptions, candidates, encoding as vdb_encoding, meta_entries,
};
use super::vdb_format::{COMPRESS_ACTIVE_MASK, LEAF_MASK_BYTES, NODE_LOG2, ROOT_TILE};
use super::vdb_structure::{Reader, grid_offsets, header, metadata};
use super::vdb_tree_structure::{TreeFormat, compressed_values, leaf_buffer, mask_words, ones};
use super::vdb_writer::{
    Encoding, TreeStats, descriptor_names, file_header, push_grid_head, push_root_child,
    push_string, push_transform, tree_type_of,
};
use crate::error::{Error, Result};
use crate::grid::{Channels, CoordBox, NODE_DIM, SparseGrid, Transform, bits, mask_box};
use crate::mapped_bytes::MappedBytes;
use glam::DVec3;
use rayon::prelude::*;
use std::collections::HashMap;
use std::fs::File;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// Where a 128^3 slot lies: its root child's origin and its slot there. Sorting by key gives
/// OpenVDB's order.
type NodeKey = ([i32; 3], u16);

/// The 128^3 slots of a root child (32^3).
const ROOT_SLOTS: u16 = 1 << (3 * NODE_LOG2[0]);

/// A byte range of a brick's file and where it goes in the merged file.
pub type Placement = (Range<u64>, u64);

/// A 128^3 node in one brick file: the bytes of its topology and of its leaves' buffers.
struct NodeBytes {
    brick: usize,
    topology: Range<u64>,
    buffers: Range<u64>,
    leaves: u64,
}

/// A 128^3 slot of the merged tree: a node copied from a brick file, or an active tile.
type Slot = (NodeKey, Option<NodeBytes>);

/// Whether bricks of `brick_size` voxels lie on OpenVDB's 128^3 nodes, as
/// `splice_brick_set` needs.
pub fn splices(brick_size: i64) -> bool {
    brick_size % NODE_DIM == 0
}

/// Merges the brick set of the index at `index` into the `.vdb` `output` (atomically), as
/// the voxel set voxelkit writes (`density`) with `metadata`, copying each brick's nodes
/// without decoding them. Refuses bricks that do not lie on 128^3 nodes (`splices`) and a
/// brick file not laid out as voxelkit writes a voxel set, naming it. Returns the voxels.
pub fn splice_brick_set(
    set: &BrickSet,
    index: &Path,
    output: &Path,
    metadata: &[(&str, MetaValue)],
) -> Result<u64> {
    if !splices(set.brick_size) {
        return Err(Error::InvalidArgument(format!(
            "{}: bricks of {} voxels do not lie on OpenVDB's {NODE_DIM}-voxel nodes; only \
             bricks of a multiple of {NODE_DIM} merge without reading their voxels",
            index.display(),
            set.brick_size
        )));
    }
    let files = set.files(index)?;
    let inputs: Vec<&Path> = std::iter::once(index)
        .chain(files.iter().map(PathBuf::as_path))
        .collect();
    check_output(output, &inputs)?;
    let layout = Layout::voxel_set()?;
    let bricks: Vec<BrickNodes> = files
        .par_iter()
        .enumerate()
        .map(|(n, file)| brick_nodes(file, n, &layout))
        .collect::<Result<_>>()?;
    let spliced = Spliced::new(set, index, output, metadata, bricks, &files)?;
    write_atomic(output, |tmp| spliced.copy_from_files(tmp, output, &files))?;
    Ok(spliced.voxels)
}

/// A brick's file encoded in memory, its nodes walked: what a worker keeps until it writes
/// the nodes into their places in the merged file (`Spliced::placements`), so that no brick
/// goes through the disk twice; in a mapping of its own (`MappedBytes`), so that the memory
/// goes back to the kernel when the brick is dropped.
pub struct EncodedBrick {
    bytes: MappedBytes,
    nodes: BrickNodes,
}

impl EncodedBrick {
    /// The brick file `bytes` (as voxelkit writes a voxel set), walked; errors name `what`.
    pub fn new(bytes: Vec<u8>, what: &Path) -> Result<EncodedBrick> {
        let mut r = Reader::from_bytes(bytes);
        let nodes = walk_brick(&mut r, 0, &Layout::voxel_set()?).map_err(|m| damaged(what, m))?;
        let bytes = r.into_bytes().expect("a reader of bytes");
        let bytes = MappedBytes::copy_of(&bytes).map_err(|e| Error::io(what, e))?;
        Ok(EncodedBrick { bytes, nodes })
    }

    /// The brick file's bytes.
    pub fn bytes(&self) -> &[u8] {
        &self.bytes
    }

    pub fn voxels(&self) -> u64 {
        self.nodes.voxels
    }

    /// What the merge needs to know of the brick (`Spliced::in_place`): its nodes, where its
    /// file holds them, the box and count of its voxels, and its transform.
    pub fn nodes(&self) -> Vec<u8> {
        self.nodes.to_bytes()
    }

    /// The brick file's byte ranges of `placements` with where each goes.
    fn pieces<'a>(&'a self, placements: &[Placement]) -> Result<Vec<(&'a [u8], u64)>> {
        let len = self.bytes.len() as u64;
        placements
            .iter()
            .map(|(range, at)| {
                if range.start > range.end || range.end > len {
                    return Err(Error::InvalidArgument(format!(
                        "bytes {range:?} of a brick of {len} bytes"
                    )));
                }
                Ok((&self.bytes[range.start as usize..range.end as usize], *at))
            })
            .collect()
    }
}

/// Writes the ranges of each brick of `bricks` (`(brick, placements)`: byte ranges of its file
/// and where each goes) into place in the existing file `file`, and syncs it once.
pub fn write_bricks_into(file: &Path, bricks: &[(&EncodedBrick, Vec<Placement>)]) -> Result<()> {
    let mut pieces = Vec::new();
    for (brick, placements) in bricks {
        pieces.extend(brick.pieces(placements)?);
    }
    write_pieces_at(file, &pieces).map_err(|e| Error::io(file, e))
}

/// The merged file laid out: the bytes it makes itself and the brick ranges it copies, in
/// file order, and its length and voxels.
pub struct Spliced {
    pieces: Vec<Piece>,
    len: u64,
    pub voxels: u64,
}

/// A piece of the merged file: bytes of its own, or a byte range of brick `.0`'s file.
enum Piece {
    Own(Vec<u8>),
    Brick(usize, Range<u64>),
}

/// Where each piece of a merged file goes: its own bytes at their offsets, and for each
/// brick the ranges of its file with their offsets.
struct Placements {
    own: Vec<(Vec<u8>, u64)>,
    bricks: Vec<Vec<Placement>>,
}

impl Spliced {
    /// The merged file of `set`'s brick nodes `bricks` (`bricks[n]` of `set.bricks[n]`, whose
    /// file or place errors name `names[n]`; the set's own errors name `what`) to be written
    /// at `output` with `metadata`.
    fn new(
        set: &BrickSet,
        what: &Path,
        output: &Path,
        metadata: &[(&str, MetaValue)],
        bricks: Vec<BrickNodes>,
        names: &[PathBuf],
    ) -> Result<Spliced> {
        for ((brick, nodes), name) in set.bricks.iter().zip(&bricks).zip(names) {
            set.check_part(brick, name, nodes.bbox, &nodes.transform)?;
        }
        // Every brick's transform is close to the set's (`check_part`); the merged file takes
        // the first brick's, and the others must be equal to it.
        let transform = bricks.first().map_or(set.transform(), |b| b.transform);
        if let Some((_, name)) = bricks
            .iter()
            .zip(names)
            .find(|(b, _)| b.transform != transform)
        {
            return Err(Error::Vdb {
                path: name.clone(),
                message: "its transform is not the first brick's".into(),
            });
        }
        let mut merged = Merged::default();
        for (n, b) in bricks.into_iter().enumerate() {
            let b = b.numbered(n);
            merged.add(b.slots, b.bbox, b.voxels);
        }
        for &b in &set.full_bricks {
            merged.add_full(brick_voxels(b, set.brick_size), output)?;
        }
        merged.slots.par_sort_unstable_by_key(|s| s.0);
        if let Some(w) = merged.slots.windows(2).find(|w| w[0].0 == w[1].0) {
            return Err(Error::Parse {
                path: what.to_path_buf(),
                line: 0,
                message: format!(
                    "two bricks hold the node at {:?}",
                    block_origin(&(w[0].0.0, w[0].0.1, 0), false)
                ),
            });
        }
        let meta = meta_entries(metadata);
        let empty = SparseGrid::new(set.transform(), Channels::NONE);
        let grid = voxel_set_grid(output, &empty, &meta)?;
        Ok(Spliced::lay_out(&grid, transform, &merged))
    }

    /// The merged file of in-memory bricks (`EncodedBrick::nodes` of `set.bricks[n]`), errors
    /// naming the brick, to be written at `output` with `metadata`.
    pub fn in_place(
        set: &BrickSet,
        nodes: &[Vec<u8>],
        output: &Path,
        metadata: &[(&str, MetaValue)],
    ) -> Result<Spliced> {
        let names: Vec<PathBuf> = set
            .bricks
            .iter()
            .map(|b| PathBuf::from(format!("brick {:?}", b.brick)))
            .collect();
        let bricks = nodes
            .iter()
            .zip(&names)
            .map(|(bytes, name)| BrickNodes::from_bytes(bytes).map_err(|m| damaged(name, m)))
            .collect::<Result<Vec<_>>>()?;
        if bricks.len() != set.bricks.len() {
            return Err(Error::InvalidArgument(format!(
                "{} bricks' nodes for {} bricks",
                bricks.len(),
                set.bricks.len()
            )));
        }
        Spliced::new(set, output, output, metadata, bricks, &names)
    }

    /// The pieces of the merged file in order: the file's and grid's heads, each root
    /// child's masks followed by its 128^3 nodes' topologies, then every node's leaf buffers;
    /// consecutive ranges of one brick joined.
    fn lay_out(grid: &GridOut, transform: Transform, merged: &Merged) -> Spliced {
        let encoding = encoding();
        let roots: Vec<&[Slot]> = merged.slots.chunk_by(|a, b| a.0.0 == b.0.0).collect();
        let compression = encoding.compression | COMPRESS_ACTIVE_MASK;
        let nodes = || merged.slots.iter().filter_map(|s| s.1.as_ref());
        let stats = TreeStats {
            bbox: merged.bbox,
            voxels: merged.voxels,
            internal: [roots.len() as u64, nodes().count() as u64],
            leaves: merged.leaves,
        };
        let mut head = Vec::new();
        push_grid_head(&mut head, grid, encoding, &stats, transform, roots.len());
        let uppers: Vec<Vec<u8>> = roots
            .iter()
            .map(|slots| {
                let mut out = Vec::new();
                let kinds = slots.iter().map(|(key, node)| (key.1, node.is_none()));
                push_root_child(
                    &mut out,
                    slots[0].0.0,
                    kinds,
                    grid.values,
                    compression,
                    false,
                );
                out
            })
            .collect();
        let length = |r: &Range<u64>| r.end - r.start;
        let topology: u64 = uppers.iter().map(|u| u.len() as u64).sum::<u64>()
            + nodes().map(|n| length(&n.topology)).sum::<u64>();
        let buffers: u64 = nodes().map(|n| length(&n.buffers)).sum();
        let mut out = file_header(1);
        out.extend_from_slice(&descriptor_names(grid, false));
        let grid_pos = out.len() as u64 + 24;
        let block_pos = grid_pos + head.len() as u64 + topology;
        let end = block_pos + buffers;
        for p in [grid_pos, block_pos, end] {
            out.extend_from_slice(&(p as i64).to_le_bytes());
        }
        out.extend_from_slice(&head);
        let mut pieces = vec![Piece::Own(out)];
        for (slots, upper) in roots.iter().zip(uppers) {
            pieces.push(Piece::Own(upper));
            let topology = slots.iter().filter_map(|s| s.1.as_ref());
            pieces.extend(runs(topology.map(|n| (n.brick, n.topology.clone()))));
        }
        pieces.extend(runs(nodes().map(|n| (n.brick, n.buffers.clone()))));
        Spliced {
            pieces,
            len: end,
            voxels: merged.voxels,
        }
    }

    /// Writes the merged file of in-memory bricks (`in_place`) to `output`, atomically: the
    /// file made at its length, its own pieces written, then `write_bricks` handed the
    /// temporary file and each of the `bricks` bricks' placements (the bricks' ranges and
    /// where they go) to write them where the bricks are held (`write_bricks_into`).
    pub fn write_in_place(
        self,
        output: &Path,
        bricks: usize,
        write_bricks: impl FnOnce(&Path, Vec<Vec<Placement>>) -> Result<()>,
    ) -> Result<()> {
        let len = self.len;
        let placed = self.placements(bricks);
        write_atomic(output, |tmp| {
            let io_error = |e| Error::io(output, e);
            File::create(tmp)
                .and_then(|f| allocate(&f, len))
                .map_err(io_error)?;
            let own: Vec<(&[u8], u64)> = placed.own.iter().map(|(b, at)| (&b[..], *at)).collect();
            write_pieces_at(tmp, &own).map_err(io_error)?;
            write_bricks(tmp, placed.bricks)
        })
    }

    /// Where every piece goes, for `bricks` bricks.
    fn placements(self, bricks: usize) -> Placements {
        let mut placed = Placements {
            own: Vec::new(),
            bricks: vec![Vec::new(); bricks],
        };
        let mut at = 0;
        for piece in self.pieces {
            match piece {
                Piece::Own(bytes) => {
                    let len = bytes.len() as u64;
                    placed.own.push((bytes, at));
                    at += len;
                }
                Piece::Brick(brick, range) => {
                    let len = range.end - range.start;
                    placed.bricks[brick].push((range, at));
                    at += len;
                }
            }
        }
        placed
    }

    /// Writes the merged file to `file` (errors name `output`), copying the bricks' ranges
    /// from their files `bricks`.
    fn copy_from_files(&self, file: &Path, output: &Path, bricks: &[PathBuf]) -> Result<()> {
        let io_error = |e| Error::io(output, e);
        let out_file = DirectFile::create(file).map_err(io_error)?;
        // One thread gathers the bytes in order into chunks, another writes them: the disk
        // works while the next chunk is read.
        let (send, chunks) = std::sync::mpsc::sync_channel::<Vec<u8>>(2);
        let (give_back, returned) = std::sync::mpsc::channel::<Vec<u8>>();
        let (copied, written) = std::thread::scope(|scope| {
            let writer = scope.spawn(move || {
                let mut out_file = out_file;
                for chunk in chunks {
                    out_file.write_all(&chunk)?;
                    let _ = give_back.send(chunk);
                }
                Ok::<_, std::io::Error>(out_file)
            });
            let mut copy = Copier {
                send,
                returned,
                chunk: Vec::with_capacity(CHUNK),
                bricks,
                open: HashMap::new(),
                block: AlignedBlock::new(CHUNK),
            };
            let copied = self.pieces.iter().try_for_each(|piece| match piece {
                Piece::Own(bytes) => {
                    copy.bytes(bytes);
                    Ok(())
                }
                Piece::Brick(brick, range) => copy.range(*brick, range),
            });
            if copied.is_ok() {
                copy.flush();
            }
            drop(copy);
            let written = writer
                .join()
                .unwrap_or_else(|p| std::panic::resume_unwind(p));
            (copied, written)
        });
        copied?;
        written.map_err(io_error)?.finish().map_err(io_error)?;
        Ok(())
    }
}

/// Makes `file` `len` bytes long, its blocks allocated where the file system can: direct
/// writes from several processes into a file with holes wait on each other's allocations
/// (two workers writing igea's 387 MB: 0.23-0.26 s into holes, 0.19-0.20 s allocated).
fn allocate(file: &File, len: u64) -> std::io::Result<()> {
    use std::os::unix::io::AsRawFd;
    let len_signed = libc::off_t::try_from(len).map_err(std::io::Error::other)?;
    // SAFETY: fallocate on a descriptor this file owns, with no pointers.
    if unsafe { libc::fallocate(file.as_raw_fd(), 0, 0, len_signed) } == 0 {
        return Ok(());
    }
    file.set_len(len)
}

/// Fixed-size fields read off the front of bytes.
struct Fields<'a>(&'a [u8]);

impl Fields<'_> {
    fn take<const N: usize>(&mut self) -> std::result::Result<[u8; N], String> {
        let Some((field, rest)) = self.0.split_first_chunk::<N>() else {
            return Err("its description of its nodes ends early".into());
        };
        self.0 = rest;
        Ok(*field)
    }
}

/// A brick whose nodes cannot be walked.
fn damaged(what: &Path, message: String) -> Error {
    Error::Vdb {
        path: what.to_path_buf(),
        message: format!(
            "cannot merge it: not a brick as voxelkit writes one, or a damaged or truncated one \
             ({message})"
        ),
    }
}

/// How the merged file and every brick file encode their values (voxelkit's defaults).
fn encoding() -> Encoding {
    vdb_encoding(&WriteOptions::default())
}

/// The voxel set's grid as voxelkit writes it, with `grid`'s transform and `meta`.
fn voxel_set_grid<'g>(
    output: &Path,
    grid: &'g SparseGrid,
    meta: &'g [(String, MetaValue)],
) -> Result<GridOut<'g>> {
    let contents = Contents::Voxels {
        grid,
        masks: Vec::new(),
        attributes: &[],
    };
    Ok(
        candidates(output, &contents, meta, &WriteOptions::default())?
            .into_iter()
            .next()
            .expect("a voxel set writes its fog volume"),
    )
}

/// What every brick file must hold to be copied into the merged file: the grid's name, tree
/// type, compression and background as the merge writes them.
struct Layout {
    name: String,
    tree_type: String,
    compression: u32,
    background: Vec<u8>,
    format: TreeFormat,
}

impl Layout {
    /// What `grid` holds as voxelkit encodes it.
    fn of(grid: &GridOut) -> Layout {
        let tree_type = tree_type_of(grid.values);
        Layout {
            name: grid.name.to_string(),
            format: TreeFormat::of(&tree_type).expect("a standard tree"),
            tree_type,
            compression: encoding().compression | COMPRESS_ACTIVE_MASK,
            background: grid.values.background().to_le_bytes().to_vec(),
        }
    }

    /// What a voxel set's grid holds, whatever its transform and metadata.
    fn voxel_set() -> Result<Layout> {
        let empty = SparseGrid::new(Transform::new(DVec3::ZERO, 1.0), Channels::NONE);
        Ok(Layout::of(&voxel_set_grid(
            Path::new("the bricks"),
            &empty,
            &[],
        )?))
    }
}

/// One brick file's 128^3 slots, the box and count of its active voxels, and its transform.
struct BrickNodes {
    slots: Vec<Slot>,
    bbox: Option<CoordBox>,
    voxels: u64,
    transform: Transform,
}

impl BrickNodes {
    /// The nodes as those of brick `brick` of the set.
    fn numbered(mut self, brick: usize) -> BrickNodes {
        for node in self.slots.iter_mut().filter_map(|s| s.1.as_mut()) {
            node.brick = brick;
        }
        self
    }

    /// The nodes as a worker hands them to the merge: the transform, the voxel count and
    /// box, then each slot (its root child, slot, and for a node its ranges and leaves),
    /// little-endian.
    fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(88 + 55 * self.slots.len());
        let t = self.transform;
        for v in [t.origin.x, t.origin.y, t.origin.z, t.voxel_size] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        out.extend_from_slice(&self.voxels.to_le_bytes());
        let b = self.bbox.unwrap_or(CoordBox {
            min: [1; 3],
            max: [0; 3],
        });
        for v in b.min.iter().chain(&b.max) {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for ((origin, slot), node) in &self.slots {
            origin
                .iter()
                .for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
            out.extend_from_slice(&slot.to_le_bytes());
            out.push(u8::from(node.is_some()));
            if let Some(n) = node {
                for v in [
                    n.topology.start,
                    n.topology.end,
                    n.buffers.start,
                    n.buffers.end,
                    n.leaves,
                ] {
                    out.extend_from_slice(&v.to_le_bytes());
                }
            }
        }
        out
    }

    /// The nodes `to_bytes` gave.
    fn from_bytes(bytes: &[u8]) -> std::result::Result<BrickNodes, String> {
        let mut r = Fields(bytes);
        let mut real = || r.take().map(f64::from_le_bytes);
        let (x, y, z, voxel_size) = (real()?, real()?, real()?, real()?);
        let voxels = u64::from_le_bytes(r.take()?);
        let mut corner = [0i64; 6];
        for v in &mut corner {
            *v = i64::from_le_bytes(r.take()?);
        }
        let b = CoordBox {
            min: [corner[0], corner[1], corner[2]],
            max: [corner[3], corner[4], corner[5]],
        };
        let mut slots = Vec::new();
        while !r.0.is_empty() {
            let mut origin = [0i32; 3];
            for v in &mut origin {
                *v = i32::from_le_bytes(r.take()?);
            }
            let slot = u16::from_le_bytes(r.take()?);
            if origin.iter().any(|v| v.rem_euclid(ROOT_TILE) != 0) || slot >= ROOT_SLOTS {
                return Err(format!(
                    "a node at {origin:?}, slot {slot}, off the lattice"
                ));
            }
            let node = match r.take::<1>()?[0] {
                0 => None,
                1 => {
                    let mut v = [0u64; 5];
                    for x in &mut v {
                        *x = u64::from_le_bytes(r.take()?);
                    }
                    if v[0] > v[1] || v[2] > v[3] {
                        return Err(format!("a node's ranges {v:?} run backwards"));
                    }
                    Some(NodeBytes {
                        brick: 0,
                        topology: v[0]..v[1],
                        buffers: v[2]..v[3],
                        leaves: v[4],
                    })
                }
                k => return Err(format!("a slot of kind {k}")),
            };
            slots.push(((origin, slot), node));
        }
        Ok(BrickNodes {
            slots,
            bbox: (b.min[0] <= b.max[0]).then_some(b),
            voxels,
            transform: Transform::new(DVec3::new(x, y, z), voxel_size),
        })
    }
}

/// Walks the brick file `file` (number `brick` of the set) against `layout`.
fn brick_nodes(file: &Path, brick: usize, layout: &Layout) -> Result<BrickNodes> {
    let mut r = Reader::open_direct(file)?;
    walk_brick(&mut r, brick, layout).map_err(|message| damaged(file, message))
}

fn walk_brick(
    r: &mut Reader,
    brick: usize,
    layout: &Layout,
) -> std::result::Result<BrickNodes, String> {
    if header(r)? == 0 {
        return Err("it holds no grid".into());
    }
    let what = "the first grid's descriptor";
    let name = r.short_string(what)?;
    let tree_type = r.short_string(what)?;
    let instance = r.short_string(what)?;
    if name != layout.name || tree_type != layout.tree_type || !instance.is_empty() {
        return Err(format!(
            "its first grid is `{name}` of type {tree_type}, not the voxel set `{}` of type {} \
             that bricks hold",
            layout.name, layout.tree_type
        ));
    }
    let (grid, block, end) = grid_offsets(r, "the grid", what)?;
    r.seek(grid as u64);
    let compression = r.u32("the grid's compression")?;
    if compression != layout.compression {
        return Err(format!(
            "compression flags {compression}, where the merge writes {}",
            layout.compression
        ));
    }
    let file_len = std::mem::replace(&mut r.len, block as u64);
    metadata(r, "the grid's metadata", (end - grid) as u64 / 64 + 1)?;
    let transform = brick_transform(r)?;
    let what = "the tree";
    if r.u32(what)? != 1 {
        return Err("a tree of more than one buffer".into());
    }
    if r.vec(layout.background.len() as u64, what)? != layout.background {
        return Err("a background other than the voxel set's".into());
    }
    if r.u32(what)? != 0 {
        return Err("tiles at the root".into());
    }
    let children = r.u32(what)?;
    let mut walk = Walk::default();
    let mut previous = None;
    for _ in 0..children {
        let mut origin = [0i32; 3];
        for v in &mut origin {
            *v = i32::from_le_bytes(r.bytes::<4>(what)?);
        }
        if origin.iter().any(|v| v.rem_euclid(ROOT_TILE) != 0) || previous >= Some(origin) {
            return Err(format!(
                "a root child at {origin:?}, off the lattice or out of order"
            ));
        }
        previous = Some(origin);
        walk.root_child(r, origin, brick, layout)?;
    }
    r.len = end as u64;
    r.seek(block as u64);
    let mut leaves = walk.leaves.iter();
    for (_, node) in &mut walk.slots {
        let Some(node) = node else { continue };
        let start = r.pos;
        for &active in leaves.by_ref().take(node.leaves as usize) {
            leaf_buffer(r, layout.format, compression, active, "a leaf buffer")?;
        }
        node.buffers = start..r.pos;
    }
    r.len = file_len;
    Ok(BrickNodes {
        slots: walk.slots,
        bbox: walk.bbox,
        voxels: walk.voxels,
        transform,
    })
}

/// The grid's transform, which must be laid out as voxelkit writes it (a uniform scale and
/// translation with its derived values).
fn brick_transform(r: &mut Reader) -> std::result::Result<Transform, String> {
    let what = "the transform";
    let name = r.short_string(what)?;
    let mut stored = Vec::new();
    push_string(&mut stored, &name);
    stored.extend_from_slice(&r.vec(6 * 24, what)?);
    let real = |at: usize| f64::from_le_bytes(stored[at..at + 8].try_into().expect("8 bytes"));
    let at = 4 + name.len();
    let transform = Transform::new(
        DVec3::new(real(at), real(at + 8), real(at + 16)),
        real(at + 24),
    );
    let mut expected = Vec::new();
    push_transform(&mut expected, transform);
    if stored != expected {
        return Err(format!(
            "a transform ({name}) not laid out as voxelkit writes one"
        ));
    }
    Ok(transform)
}

/// A brick file's slots as its tree is walked, its leaves' voxel counts in buffer order, and
/// the box and count of its voxels.
#[derive(Default)]
struct Walk {
    slots: Vec<Slot>,
    leaves: Vec<u16>,
    bbox: Option<CoordBox>,
    voxels: u64,
}

impl Walk {
    fn grow(&mut self, b: CoordBox, voxels: u64) {
        self.voxels += voxels;
        self.bbox = Some(self.bbox.map_or(b, |a| a.union(&b)));
    }

    /// A root child (4096^3): its masks and tile values, then each 128^3 child's topology.
    fn root_child(
        &mut self,
        r: &mut Reader,
        origin: [i32; 3],
        brick: usize,
        layout: &Layout,
    ) -> std::result::Result<(), String> {
        let what = "a root child";
        let (children, values) = node_masks(r, 0, layout, what)?;
        let edge = i64::from(NODE_DIM as i32);
        for slot in bits::ones(&values).filter(|&s| !bits::get(&children, s)) {
            let min = block_origin(&(origin, slot as u16, 0), false).map(i64::from);
            let max = min.map(|v| v + edge - 1);
            self.grow(CoordBox { min, max }, (edge as u64).pow(3));
            self.slots.push(((origin, slot as u16), None));
        }
        for slot in bits::ones(&children) {
            let start = r.pos;
            let leaves = self.lower_node(r, (origin, slot as u16), layout)?;
            self.slots.push((
                (origin, slot as u16),
                Some(NodeBytes {
                    brick,
                    topology: start..r.pos,
                    buffers: 0..0,
                    leaves,
                }),
            ));
        }
        Ok(())
    }

    /// A 128^3 node's masks, tile values and leaf masks; its leaf count.
    fn lower_node(
        &mut self,
        r: &mut Reader,
        key: NodeKey,
        layout: &Layout,
    ) -> std::result::Result<u64, String> {
        let (children, values) = node_masks(r, 1, layout, "a 128^3 node")?;
        let block = |slot: usize| block_origin(&(key.0, key.1, slot as u16), true).map(i64::from);
        for slot in bits::ones(&values).filter(|&s| !bits::get(&children, s)) {
            let min = block(slot);
            let max = min.map(|v| v + 7);
            self.grow(CoordBox { min, max }, 512);
        }
        let mut leaves = 0;
        for slot in bits::ones(&children) {
            let bytes = r.bytes::<{ LEAF_MASK_BYTES as usize }>("a leaf's mask")?;
            let mut words = mask_words(&bytes);
            let mask: [u64; 8] = std::array::from_fn(|_| words.next().expect("a leaf's 8 words"));
            let active = mask.iter().map(|w| u64::from(w.count_ones())).sum();
            self.leaves.push(active as u16);
            leaves += 1;
            if let Some(b) = mask_box(block(slot), &mask) {
                self.grow(b, active);
            }
        }
        Ok(leaves)
    }
}

/// An internal node's child and value masks (at `depth`: 0 for a root child) as words, its
/// tile values skipped.
fn node_masks(
    r: &mut Reader,
    depth: usize,
    layout: &Layout,
    what: &str,
) -> std::result::Result<(Vec<u64>, Vec<u64>), String> {
    let bytes = (1u64 << (3 * NODE_LOG2[depth])) / 8;
    let children = r.vec(bytes, what)?;
    let values = r.vec(bytes, what)?;
    let slots = 8 * bytes;
    compressed_values(
        r,
        layout.format,
        layout.compression,
        slots,
        ones(&values),
        what,
    )?;
    Ok((
        mask_words(&children).collect(),
        mask_words(&values).collect(),
    ))
}

/// The slots of all bricks and full bricks, and the box and count of their voxels.
#[derive(Default)]
struct Merged {
    slots: Vec<Slot>,
    bbox: Option<CoordBox>,
    voxels: u64,
    leaves: u64,
}

impl Merged {
    fn add(&mut self, slots: Vec<Slot>, bbox: Option<CoordBox>, voxels: u64) {
        self.leaves += slots
            .iter()
            .filter_map(|s| s.1.as_ref())
            .map(|n| n.leaves)
            .sum::<u64>();
        self.slots.extend(slots);
        self.voxels += voxels;
        if let Some(b) = bbox {
            self.bbox = Some(self.bbox.map_or(b, |a| a.union(&b)));
        }
    }

    /// A brick wholly inside: a tile on each of its 128^3 slots.
    fn add_full(&mut self, b: CoordBox, output: &Path) -> Result<()> {
        let mut slots = Vec::new();
        let step = NODE_DIM as usize;
        for x in (b.min[0]..=b.max[0]).step_by(step) {
            for y in (b.min[1]..=b.max[1]).step_by(step) {
                for z in (b.min[2]..=b.max[2]).step_by(step) {
                    let k = key(output, [x, y, z])?;
                    slots.push(((k.0, k.1), None));
                }
            }
        }
        let voxels = (0..3).map(|a| (b.max[a] - b.min[a] + 1) as u64).product();
        self.add(slots, Some(b), voxels);
        Ok(())
    }
}

/// Byte ranges of bricks in copy order, each run of ranges that follow one another in one
/// brick joined into one: a brick's nodes lie in the merged order as in its file, a few at a
/// time, and each piece costs a read around the page cache, or a write of its unaligned
/// ends through it.
fn runs(ranges: impl Iterator<Item = (usize, Range<u64>)>) -> impl Iterator<Item = Piece> {
    let mut ranges = ranges.peekable();
    std::iter::from_fn(move || {
        let (brick, mut run) = ranges.next()?;
        while let Some((_, next)) = ranges.next_if(|(b, r)| *b == brick && r.start == run.end) {
            run.end = next.end;
        }
        Some(Piece::Brick(brick, run))
    })
}

/// Bytes gathered before a chunk goes to the writer thread.
const CHUNK: usize = 4 << 20;

/// Gathers the merged file's bytes (its own and byte ranges of brick files) in order into
/// chunks for the writer thread, reusing the chunks it hands back; keeps a bounded number
/// of brick files open, and reads them around the page cache through `block`.
struct Copier<'a> {
    send: std::sync::mpsc::SyncSender<Vec<u8>>,
    returned: std::sync::mpsc::Receiver<Vec<u8>>,
    chunk: Vec<u8>,
    bricks: &'a [PathBuf],
    open: HashMap<usize, File>,
    block: AlignedBlock,
}

/// Brick files held open at once; more are closed and opened again as needed.
const OPEN_FILES: usize = 64;

impl Copier<'_> {
    fn bytes(&mut self, bytes: &[u8]) {
        self.chunk.extend_from_slice(bytes);
        if self.chunk.len() >= CHUNK {
            self.flush();
        }
    }

    /// Hands the chunk to the writer (a writer that stopped at an error reports it when
    /// joined) and takes a fresh one.
    fn flush(&mut self) {
        let next = self
            .returned
            .try_recv()
            .map(|mut c| {
                c.clear();
                c
            })
            .unwrap_or_else(|_| Vec::with_capacity(CHUNK));
        let full = std::mem::replace(&mut self.chunk, next);
        let _ = self.send.send(full);
    }

    fn range(&mut self, brick: usize, range: &Range<u64>) -> Result<()> {
        let path = &self.bricks[brick];
        if !self.open.contains_key(&brick) {
            if self.open.len() == OPEN_FILES {
                self.open.clear();
            }
            let f = direct_read::open(path, true).map_err(|e| Error::io(path, e))?;
            self.open.insert(brick, f);
        }
        let mut at = range.start;
        while at < range.end {
            let room = CHUNK.max(self.chunk.len() + 1) - self.chunk.len();
            let n = (range.end - at).min(room as u64);
            self.block
                .append(&self.open[&brick], &(at..at + n), &mut self.chunk)
                .map_err(|e| Error::io(path, e))?;
            at += n;
            if self.chunk.len() >= CHUNK {
                self.flush();
            }
        }
        Ok(())
    }
}

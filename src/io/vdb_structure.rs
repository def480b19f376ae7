//! A check of a `.vdb` file's structure before OpenVDB reads it: the header, the file's
//! metadata, the grid descriptors and each grid's tree (`vdb_tree_structure`), every length
//! and offset against the file's size. OpenVDB trusts these numbers, so a file cut short can
//! make it allocate gigabytes for one string, a damaged chunk size overruns a node's buffer,
//! and a header alone reads as a file without grids.

use super::direct_read::BlockReader;
use super::vdb_format::{DELAYED_LOAD, MAGIC, NODE_MASK_VERSION};
use super::vdb_tree_structure::{self, TreeFormat};
use crate::error::{Error, Result};
use std::path::Path;

pub(super) struct Reader {
    input: Input,
    pub(super) pos: u64,
    pub(super) len: u64,
}

/// What a `Reader` reads: a file, or a file's bytes in memory.
enum Input {
    File(BlockReader),
    Bytes(Vec<u8>),
}

impl Reader {
    /// The file at `path`, read through a large buffer: most skips (compressed chunks of a
    /// few hundred bytes) stay inside it.
    pub(super) fn open(path: &Path) -> Result<Reader> {
        Reader::open_block_wise(path, false)
    }

    /// The file at `path`, read around the page cache where the file system allows it: a
    /// file about to be copied and deleted.
    pub(super) fn open_direct(path: &Path) -> Result<Reader> {
        Reader::open_block_wise(path, true)
    }

    fn open_block_wise(path: &Path, direct: bool) -> Result<Reader> {
        let input = BlockReader::open(path, 1 << 20, direct).map_err(|e| Error::io(path, e))?;
        let len = input.len().map_err(|e| Error::io(path, e))?;
        Ok(Reader {
            input: Input::File(input),
            pos: 0,
            len,
        })
    }

    /// A file's `bytes`, handed back by `into_bytes`.
    pub(super) fn from_bytes(bytes: Vec<u8>) -> Reader {
        Reader {
            len: bytes.len() as u64,
            input: Input::Bytes(bytes),
            pos: 0,
        }
    }

    /// The bytes of a reader made `from_bytes`.
    pub(super) fn into_bytes(self) -> Option<Vec<u8>> {
        match self.input {
            Input::Bytes(bytes) => Some(bytes),
            Input::File(_) => None,
        }
    }

    fn read(&mut self, out: &mut [u8]) -> std::result::Result<(), String> {
        match &mut self.input {
            Input::File(file) => file
                .read_exact_at(self.pos, out)
                .map_err(|e| e.to_string())?,
            Input::Bytes(bytes) => {
                let at = usize::try_from(self.pos).unwrap_or(usize::MAX);
                let source = bytes
                    .get(at..at.saturating_add(out.len()))
                    .ok_or("it ends early")?;
                out.copy_from_slice(source);
            }
        }
        self.pos += out.len() as u64;
        Ok(())
    }

    pub(super) fn bytes<const N: usize>(
        &mut self,
        what: &str,
    ) -> std::result::Result<[u8; N], String> {
        if self.pos + N as u64 > self.len {
            return Err(format!("it ends inside {what} (byte {})", self.pos));
        }
        let mut b = [0u8; N];
        self.read(&mut b)?;
        Ok(b)
    }

    pub(super) fn u32(&mut self, what: &str) -> std::result::Result<u32, String> {
        self.bytes::<4>(what).map(u32::from_le_bytes)
    }

    pub(super) fn i64(&mut self, what: &str) -> std::result::Result<i64, String> {
        self.bytes::<8>(what).map(i64::from_le_bytes)
    }

    /// Skips `n` bytes that must lie inside the file.
    pub(super) fn skip(&mut self, n: u64, what: &str) -> std::result::Result<(), String> {
        if n > self.len - self.pos {
            return Err(format!(
                "{what} at byte {} claims {n} bytes, past its end at byte {}",
                self.pos, self.len
            ));
        }
        self.pos += n;
        Ok(())
    }

    /// `n` bytes that must lie inside the file.
    pub(super) fn vec(&mut self, n: u64, what: &str) -> std::result::Result<Vec<u8>, String> {
        if n > self.len - self.pos {
            return Err(format!("it ends inside {what} (byte {})", self.pos));
        }
        let mut v = vec![0u8; n as usize];
        self.read(&mut v)?;
        Ok(v)
    }

    /// A length-prefixed name of at most 256 bytes.
    pub(super) fn short_string(&mut self, what: &str) -> std::result::Result<String, String> {
        let n = self.u32(what)? as u64;
        if n > 256 {
            return Err(format!("{what}: a name of {n} bytes"));
        }
        Ok(String::from_utf8_lossy(&self.vec(n, what)?).into_owned())
    }

    /// A length-prefixed string, skipped.
    fn string(&mut self, what: &str) -> std::result::Result<(), String> {
        let n = self.u32(what)?;
        self.skip(n as u64, what)
    }

    pub(super) fn seek(&mut self, to: u64) {
        self.pos = to;
    }
}

/// Checks the structure of the `.vdb` at `path`; the error says where it breaks. Returns the
/// bytes OpenVDB allocates to read its trees.
pub fn check_structure(path: &Path) -> Result<u64> {
    let mut r = Reader::open(path)?;
    walk(&mut r).map_err(|message| Error::Vdb {
        path: path.to_path_buf(),
        message: format!(
            "cannot read it: not a .vdb file, or a damaged or truncated one ({message})"
        ),
    })
}

/// A metadata map: a count, then name, type and value of each entry. OpenVDB's per-leaf
/// delayed-load table sizes itself by a count of its own: it must fit `max_entries`.
pub(super) fn metadata(
    r: &mut Reader,
    what: &str,
    max_entries: u64,
) -> std::result::Result<(), String> {
    let entries = r.u32(what)?;
    for _ in 0..entries {
        r.string(what)?;
        let type_len = r.u32(what)? as u64;
        if type_len > 64 {
            r.skip(type_len, what)?;
            return Err(format!("{what}: a metadata type name of {type_len} bytes"));
        }
        let mut type_name = vec![0u8; type_len as usize];
        for b in &mut type_name {
            *b = r.bytes::<1>(what)?[0];
        }
        let value_len = r.u32(what)? as u64;
        if type_name == DELAYED_LOAD && value_len > 0 {
            delayed_load_table(r, value_len, max_entries, what)?;
            continue;
        }
        // OpenVDB reads a fixed-size value by its type, whatever length the file gives.
        if let Some(size) = fixed_size(&type_name).filter(|&size| size != value_len) {
            return Err(format!(
                "{what}: a {} value of {value_len} bytes instead of {size}",
                String::from_utf8_lossy(&type_name)
            ));
        }
        r.skip(value_len, what)?;
    }
    Ok(())
}

/// The size OpenVDB reads for a metadata value of a fixed-size type.
fn fixed_size(type_name: &[u8]) -> Option<u64> {
    Some(match type_name {
        b"bool" => 1,
        b"int32" | b"float" => 4,
        b"int64" | b"double" | b"vec2i" | b"vec2s" => 8,
        b"vec3i" | b"vec3s" => 12,
        b"vec2d" => 16,
        b"vec3d" => 24,
        b"mat4s" => 64,
        b"mat4d" => 128,
        _ => return None,
    })
}

/// OpenVDB's delayed-load table, `len` bytes: a leaf count, then the per-leaf masks (1 byte
/// each) and the per-leaf sizes (8 bytes each, or none), each block a byte count (0: raw)
/// and its bytes, blosc-compressed when counted. OpenVDB sizes its buffers by these counts
/// and skips what is left of the table: the counts must fit the table and the grid.
fn delayed_load_table(
    r: &mut Reader,
    len: u64,
    max_leaves: u64,
    what: &str,
) -> std::result::Result<(), String> {
    let end = r.pos + len;
    let table = |detail: String| format!("{what}: a delayed-load table of {len} bytes {detail}");
    let room = |r: &Reader, n: u64| r.pos + n <= end;
    if !room(r, 8) {
        return Err(table("cut short".into()));
    }
    let leaves = r.u32(what)? as u64;
    if leaves > max_leaves {
        return Err(table(format!(
            "claims {leaves} leaves, more than the grid can hold"
        )));
    }
    for (element, optional) in [(1u64, false), (8, true)] {
        if !room(r, 4) {
            return Err(table("cut short".into()));
        }
        let bytes = r.u32(what)?;
        if optional && bytes == u32::MAX {
            continue; // no sizes stored
        }
        let block = if bytes == 0 {
            leaves * element
        } else {
            bytes as u64
        };
        if !room(r, block) {
            return Err(table(format!("holds a block of {block} bytes")));
        }
        if bytes > 0 {
            // A blosc chunk: a 16-byte header whose sizes must match the block and count.
            if block < 16 {
                return Err(table(
                    "holds a compressed block too short for its header".into(),
                ));
            }
            let header = r.bytes::<16>(what)?;
            let word = |i: usize| u32::from_le_bytes(header[i..i + 4].try_into().expect("4"));
            // OpenVDB pads buffers under 128 bytes to 128 before compressing them.
            if word(4) as u64 > (leaves * element).max(128) || word(12) as u64 != block {
                return Err(table(
                    "holds a compressed block whose sizes disagree".into(),
                ));
            }
            r.skip(block - 16, what)?;
        } else {
            r.skip(block, what)?;
        }
    }
    r.skip(end - r.pos, what)
}

/// A file's header through its grid count: OpenVDB's magic number, a format version voxelkit
/// reads, the library version, grid offsets (a file, not a stream), the UUID and the file's
/// metadata. Returns the grid count.
pub(super) fn header(r: &mut Reader) -> std::result::Result<u32, String> {
    if r.i64("the header")? != MAGIC {
        return Err("it does not start with OpenVDB's magic number".into());
    }
    let version = r.u32("the header")?;
    if version < NODE_MASK_VERSION {
        return Err(format!(
            "file format version {version}: voxelkit reads versions {NODE_MASK_VERSION} and later"
        ));
    }
    r.skip(8, "the library version")?;
    let offsets = r.bytes::<1>("the header")?[0] != 0;
    r.skip(36, "the file's UUID")?;
    metadata(r, "the file's metadata", 0)?;
    if !offsets {
        // Written as a stream: without grid offsets the trees cannot be checked.
        return Err("it has no grid offsets (an OpenVDB stream, not a file)".into());
    }
    r.u32("the grid count")
}

/// A grid descriptor's three offsets (the grid, its block of leaf buffers, its end), each
/// inside the file and in that order; `grid` names the grid in errors.
pub(super) fn grid_offsets(
    r: &mut Reader,
    grid: &str,
    what: &str,
) -> std::result::Result<(i64, i64, i64), String> {
    let (start, block, end) = (r.i64(what)?, r.i64(what)?, r.i64(what)?);
    let inside = |p: i64| p >= 0 && (p as u64) <= r.len;
    if !(inside(start) && inside(block) && inside(end) && start <= block && block <= end) {
        return Err(format!(
            "{grid} claims bytes {start}..{end}, outside the file ({} bytes)",
            r.len
        ));
    }
    Ok((start, block, end))
}

fn walk(r: &mut Reader) -> std::result::Result<u64, String> {
    let grids = header(r)?;
    let mut memory = 0u64;
    for g in 0..grids {
        let what = format!("the descriptor of grid {g}");
        r.string(&what)?;
        let type_name = r.short_string(&what)?;
        let instance = !r.short_string(&what)?.is_empty();
        let format = TreeFormat::of(&type_name).map_err(|e| format!("grid {g} is {e}"))?;
        let (grid, block, end) = grid_offsets(r, &format!("grid {g}"), &what)?;
        if (end as u64) < r.pos {
            return Err(format!("grid {g} ends before its own descriptor"));
        }
        // The grid's compression flags, metadata, transform and topology end by its block
        // of leaf buffers.
        r.seek(grid as u64);
        let file_len = std::mem::replace(&mut r.len, block as u64);
        let compression = r.u32(&format!("the compression flags of grid {g}"))?;
        // A leaf takes at least its 64-byte mask in the file.
        let max_leaves = (end - grid) as u64 / 64 + 1;
        metadata(r, &format!("grid {g}'s metadata"), max_leaves)?;
        vdb_tree_structure::transform(r, &format!("grid {g}'s transform"))?;
        r.len = file_len;
        if !instance {
            let what = format!("grid {g}'s tree");
            let bytes =
                vdb_tree_structure::tree(r, format, compression, block as u64, end as u64, &what)?;
            memory = memory.saturating_add(bytes);
        }
        r.seek(end as u64);
    }
    Ok(memory)
}

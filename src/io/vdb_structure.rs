//! A check of a `.vdb` file's structure before OpenVDB reads it: the header, the file's
//! metadata and the grid descriptors, every length and offset against the file's size.
//! OpenVDB trusts these numbers, so a file cut short can make it allocate gigabytes for one
//! string, and a header alone reads as a file without grids.

use crate::error::{Error, Result};
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::Path;

/// OpenVDB's magic number, the file's first eight bytes.
const MAGIC: i64 = 0x5644_4220;
/// The first file version with a 36-character UUID in the header, the oldest read (a
/// layout older still is refused rather than read on trust).
const UUID_VERSION: u32 = 218;
/// The first file version whose grid descriptors name an instance parent.
const INSTANCING_VERSION: u32 = 216;
/// The type name of OpenVDB's per-leaf delayed-load table.
const DELAYED_LOAD: &[u8] = b"__delayedload";
/// The first file version with compression flags at the start of each grid.
const NODE_MASK_VERSION: u32 = 222;

struct Reader {
    input: BufReader<std::fs::File>,
    pos: u64,
    len: u64,
}

impl Reader {
    fn bytes<const N: usize>(&mut self, what: &str) -> std::result::Result<[u8; N], String> {
        if self.pos + N as u64 > self.len {
            return Err(format!("it ends inside {what} (byte {})", self.pos));
        }
        let mut b = [0u8; N];
        self.input.read_exact(&mut b).map_err(|e| e.to_string())?;
        self.pos += N as u64;
        Ok(b)
    }

    fn u32(&mut self, what: &str) -> std::result::Result<u32, String> {
        self.bytes::<4>(what).map(u32::from_le_bytes)
    }

    fn i64(&mut self, what: &str) -> std::result::Result<i64, String> {
        self.bytes::<8>(what).map(i64::from_le_bytes)
    }

    /// Skips `n` bytes that must lie inside the file.
    fn skip(&mut self, n: u64, what: &str) -> std::result::Result<(), String> {
        if n > self.len - self.pos {
            return Err(format!(
                "{what} at byte {} claims {n} bytes, past its end at byte {}",
                self.pos, self.len
            ));
        }
        self.input
            .seek_relative(n as i64)
            .map_err(|e| e.to_string())?;
        self.pos += n;
        Ok(())
    }

    /// A length-prefixed string, skipped.
    fn string(&mut self, what: &str) -> std::result::Result<(), String> {
        let n = self.u32(what)?;
        self.skip(n as u64, what)
    }

    fn seek(&mut self, to: u64) -> std::result::Result<(), String> {
        self.input
            .seek(SeekFrom::Start(to))
            .map_err(|e| e.to_string())?;
        self.pos = to;
        Ok(())
    }
}

/// Checks the structure of the `.vdb` at `path`; the error says where it breaks.
pub fn check_structure(path: &Path) -> Result<()> {
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let len = file.metadata().map_err(|e| Error::io(path, e))?.len();
    let mut r = Reader {
        input: BufReader::new(file),
        pos: 0,
        len,
    };
    walk(&mut r).map_err(|message| Error::Vdb {
        path: path.to_path_buf(),
        message: format!(
            "cannot read it: not a .vdb file, or a damaged or truncated one ({message})"
        ),
    })
}

/// A metadata map: a count, then name, type and value of each entry. OpenVDB's per-leaf
/// delayed-load table sizes itself by a count of its own: it must fit `max_entries`.
fn metadata(r: &mut Reader, what: &str, max_entries: u64) -> std::result::Result<(), String> {
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

fn walk(r: &mut Reader) -> std::result::Result<(), String> {
    if r.i64("the header")? != MAGIC {
        return Err("it does not start with OpenVDB's magic number".into());
    }
    let version = r.u32("the header")?;
    if version < UUID_VERSION {
        return Err(format!(
            "file format version {version}: voxelkit reads versions {UUID_VERSION} and later"
        ));
    }
    r.skip(8, "the library version")?;
    let offsets = r.bytes::<1>("the header")?[0] != 0;
    if (220..222).contains(&version) {
        r.skip(4, "the compression flags")?;
    }
    r.skip(36, "the file's UUID")?;
    metadata(r, "the file's metadata", 0)?;
    if !offsets {
        return Ok(()); // a stream without grid offsets: nothing to check them against
    }
    let grids = r.u32("the grid count")?;
    for g in 0..grids {
        let what = format!("the descriptor of grid {g}");
        r.string(&what)?;
        r.string(&what)?;
        if version >= INSTANCING_VERSION {
            r.string(&what)?;
        }
        let (grid, block, end) = (r.i64(&what)?, r.i64(&what)?, r.i64(&what)?);
        let inside = |p: i64| p >= 0 && (p as u64) <= r.len;
        if !(inside(grid) && inside(block) && inside(end) && grid <= block && block <= end) {
            return Err(format!(
                "grid {g} claims bytes {grid}..{end}, outside the file ({} bytes)",
                r.len
            ));
        }
        if (end as u64) < r.pos {
            return Err(format!("grid {g} ends before its own descriptor"));
        }
        // The grid's own metadata (after its compression flags) must end inside the grid.
        r.seek(grid as u64)?;
        let file_len = std::mem::replace(&mut r.len, block as u64);
        if version >= NODE_MASK_VERSION {
            r.skip(4, &format!("the compression flags of grid {g}"))?;
        }
        // A leaf takes at least its 64-byte mask in the file.
        let max_leaves = (end - grid) as u64 / 64 + 1;
        metadata(r, &format!("grid {g}'s metadata"), max_leaves)?;
        r.len = file_len;
        r.seek(end as u64)?;
    }
    Ok(())
}

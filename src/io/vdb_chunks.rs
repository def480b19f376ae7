//! How a `.vdb` stores a block of node values: raw, or as a chunk behind a signed 64-bit size
//! (blosc or zip; a negative size marks bytes stored raw because compressing did not help).
//! These are the layouts OpenVDB reads (`io/Compression.h`); `vdb_tree_structure` checks
//! the same rules on the way in.

use std::os::raw::{c_int, c_ulong, c_void};

use super::blosc_chunk::blosc_chunk;
use super::vdb_format::{BLOSC_PAD_BYTES, COMPRESS_BLOSC, COMPRESS_ZIP};

#[link(name = "z")]
unsafe extern "C" {
    fn compress2(
        dest: *mut u8,
        dest_len: *mut c_ulong,
        source: *const u8,
        source_len: c_ulong,
        level: c_int,
    ) -> c_int;
}

/// Appends `data` (values of `value_size` bytes each) to `out` as the grid's `compression`
/// flags store it. Compressed bytes are written in place, after room for their size.
pub(super) fn push_chunk(out: &mut Vec<u8>, data: &[u8], value_size: usize, compression: u32) {
    if compression & (COMPRESS_BLOSC | COMPRESS_ZIP) == 0 {
        out.extend_from_slice(data);
        return;
    }
    let at = out.len();
    if !data.is_empty() {
        // Room for a chunk shorter than the data: a longer one is not kept.
        out.resize(at + 8 + data.len(), 0);
        let room = &mut out[at + 8..];
        let written = if compression & COMPRESS_BLOSC != 0 {
            blosc_chunk(data, value_size, room)
        } else {
            zip(data, room)
        };
        if let Some(n) = written.filter(|&n| n < data.len()) {
            out.truncate(at + 8 + n);
            out[at..at + 8].copy_from_slice(&(n as i64).to_le_bytes());
            return;
        }
        out.truncate(at);
    }
    out.extend_from_slice(&(-(data.len() as i64)).to_le_bytes());
    out.extend_from_slice(data);
}

/// Compresses `data` into `out` as a zlib stream at zlib's default level; its length, or
/// `None` when it does not fit `out`.
fn zip(data: &[u8], out: &mut [u8]) -> Option<usize> {
    let mut len = out.len() as c_ulong;
    // SAFETY: compress2 writes at most `len` bytes to `out` and reads `data.len()` from `data`.
    let status = unsafe {
        compress2(
            out.as_mut_ptr(),
            &mut len,
            data.as_ptr(),
            data.len() as c_ulong,
            -1,
        )
    };
    (status == 0).then_some(len as usize)
}

/// OpenVDB's name of a compression setting (the `file_compression` metadata).
pub(super) fn compression_name(compression: u32) -> &'static str {
    match (
        compression & COMPRESS_BLOSC != 0,
        compression & COMPRESS_ZIP != 0,
    ) {
        (true, _) => "blosc + active values",
        (false, true) => "zip + active values",
        (false, false) => "active values",
    }
}

#[link(name = "blosc")]
unsafe extern "C" {
    fn blosc_decompress_ctx(
        src: *const c_void,
        dest: *mut c_void,
        destsize: usize,
        numinternalthreads: c_int,
    ) -> c_int;
}

#[link(name = "z")]
unsafe extern "C" {
    fn uncompress(
        dest: *mut u8,
        dest_len: *mut c_ulong,
        source: *const u8,
        source_len: c_ulong,
    ) -> c_int;
}

/// Reads a chunk of `bytes` bytes that `push_chunk` (or OpenVDB) stored with the grid's
/// `compression` flags from the start of `input`: the bytes and how much of `input` it took.
pub(super) fn read_chunk(
    input: &[u8],
    bytes: usize,
    compression: u32,
) -> std::result::Result<(Vec<u8>, usize), String> {
    let take = |n: usize, from: usize| {
        input
            .get(from..from + n)
            .ok_or_else(|| format!("a chunk of {n} bytes runs past its grid"))
    };
    if compression & (COMPRESS_BLOSC | COMPRESS_ZIP) == 0 {
        return Ok((take(bytes, 0)?.to_vec(), bytes));
    }
    let size = i64::from_le_bytes(take(8, 0)?.try_into().expect("8 bytes"));
    if size <= 0 {
        if size.unsigned_abs() != bytes as u64 {
            return Err(format!(
                "a raw chunk of {} bytes where its node holds {bytes}",
                size.unsigned_abs()
            ));
        }
        return Ok((take(bytes, 8)?.to_vec(), 8 + bytes));
    }
    let packed = take(usize::try_from(size).map_err(|e| e.to_string())?, 8)?;
    // Room for blosc's padding of short buffers: it never writes past `destsize`.
    let mut out = vec![0u8; bytes.max(BLOSC_PAD_BYTES)];
    let unpacked = if compression & COMPRESS_BLOSC != 0 {
        // SAFETY: blosc reads the chunk (its header's sizes were checked against `packed`'s
        // length by the structure check) and writes at most `out.len()` bytes.
        let n = unsafe {
            blosc_decompress_ctx(
                packed.as_ptr().cast(),
                out.as_mut_ptr().cast(),
                out.len(),
                1,
            )
        };
        usize::try_from(n).ok()
    } else {
        let mut len = out.len() as c_ulong;
        // SAFETY: uncompress reads `packed.len()` bytes and writes at most `len` to `out`.
        let status = unsafe {
            uncompress(
                out.as_mut_ptr(),
                &mut len,
                packed.as_ptr(),
                packed.len() as c_ulong,
            )
        };
        (status == 0).then_some(len as usize)
    };
    match unpacked {
        Some(n) if n == bytes || (bytes < BLOSC_PAD_BYTES && n == BLOSC_PAD_BYTES) => {
            out.truncate(bytes);
            Ok((out, 8 + packed.len()))
        }
        _ => Err(format!(
            "a compressed chunk that does not unpack to the {bytes} bytes of its node"
        )),
    }
}

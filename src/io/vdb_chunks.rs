//! How a `.vdb` stores a block of node values: raw, or as a chunk behind a signed 64-bit size
//! (blosc or zip; a negative size marks bytes stored raw because compressing did not help).
//! These are the layouts OpenVDB reads (`io/Compression.h`); `vdb_tree_structure` checks
//! the same rules on the way in.

use std::os::raw::{c_char, c_int, c_ulong, c_void};

/// Per-grid compression flags (OpenVDB's `COMPRESS_*`).
pub(super) const COMPRESS_ZIP: u32 = 0x1;
pub(super) const COMPRESS_ACTIVE_MASK: u32 = 0x2;
pub(super) const COMPRESS_BLOSC: u32 = 0x4;

/// Blosc's chunk header, in bytes: the most compressing can add.
const BLOSC_OVERHEAD: usize = 16;

#[link(name = "blosc")]
unsafe extern "C" {
    fn blosc_compress_ctx(
        clevel: c_int,
        doshuffle: c_int,
        typesize: usize,
        nbytes: usize,
        src: *const c_void,
        dest: *mut c_void,
        destsize: usize,
        compressor: *const c_char,
        blocksize: usize,
        numinternalthreads: c_int,
    ) -> c_int;
}

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
        out.resize(at + 8 + data.len() + BLOSC_OVERHEAD, 0);
        let room = &mut out[at + 8..];
        let written = if compression & COMPRESS_BLOSC != 0 {
            blosc(data, value_size, room)
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

/// Compresses `data` into `out` as a blosc chunk (LZ4 with byte shuffling by value,
/// OpenVDB's settings); its length, or `None` when blosc cannot compress it into `out`.
fn blosc(data: &[u8], value_size: usize, out: &mut [u8]) -> Option<usize> {
    // SAFETY: both buffers are valid for the lengths given; blosc writes at most `destsize`.
    let written = unsafe {
        blosc_compress_ctx(
            9,
            1,
            value_size,
            data.len(),
            data.as_ptr().cast(),
            out.as_mut_ptr().cast(),
            out.len(),
            c"lz4".as_ptr(),
            data.len(),
            1,
        )
    };
    (written > 0).then_some(written as usize)
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

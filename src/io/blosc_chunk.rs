//! Blosc chunks written directly around LZ4: what `blosc_compress_ctx` at OpenVDB's settings
//! (LZ4, byte shuffle by value, one block) writes, without its per-call costs.
//!
//! Blosc builds a context and allocates its buffers for every chunk, and LZ4 clears its 16 KB
//! table before each: for a leaf of 300 floats that is a third of the time spent compressing
//! it (742 ns through blosc, 491 ns here, in a C program). Here
//! each thread keeps one LZ4 stream, reset in LZ4's fast way between chunks. The chunks are
//! blosc's (format 2, LZ4 format 1: a 16-byte header, the block's start, the block as one LZ4
//! stream after its length), so blosc, OpenVDB among its readers, decompresses them.
//!
//! A block of 128 values or more may instead be one stream per byte plane (blosc's split
//! mode, which its reader knows from the header). That is how a chunk skips LZ4 where it
//! cannot help: the low mantissa bytes of computed distances look random, LZ4 finds nothing in
//! them and takes as long as on the bytes it shrinks. Such a plane is stored raw (a stream as
//! long as its plane, as blosc stores a stream that did not shrink), the others compressed.
//!
//! A fast reset leaves the previous chunks' entries in the table, but LZ4 takes no match
//! from them (each reset moves the stream 64 KiB further on, out of reach), so a chunk's bytes
//! depend on its values alone, whichever thread wrote what before. A stream's first chunk
//! would see an empty table instead (where LZ4 finds other matches), so each stream compresses
//! one chunk before its first; and LZ4 empties the table itself once the stream has moved
//! 1 GiB on (about 16,000 chunks), so a stream is made anew well before that.

use std::cell::RefCell;
use std::os::raw::{c_char, c_int};

/// Blosc's chunk header, in bytes.
const HEADER: usize = 16;
/// The header, the block's start and the block's stream length.
const FRAMING: usize = HEADER + 4 + 4;
/// Blosc stores buffers shorter than this uncompressed (`BLOSC_MIN_BUFFERSIZE`).
const MIN_BUFFER: usize = 128;
/// `BLOSC_VERSION_FORMAT` and `BLOSC_LZ4_VERSION_FORMAT`.
const BLOSC_FORMAT: u8 = 2;
const LZ4_FORMAT: u8 = 1;
/// LZ4's acceleration at blosc's level 9, OpenVDB's (blosc passes 10 - level).
const LZ4_ACCELERATION: c_int = 1;
/// Header flags: byte shuffle (`BLOSC_DOSHUFFLE`) and LZ4's compressor code (1) in the top
/// three bits; with `BLOSC_DONT_SPLIT`, one stream per block.
const SPLIT_FLAGS: u8 = 0x01 | (1 << 5);
const FLAGS: u8 = SPLIT_FLAGS | 0x10;
/// Blosc splits a block into planes for values of at most this many bytes (`MAX_SPLITS`).
const MOST_PLANES: usize = 16;
/// Bytes a plane's look at itself samples, and how many distinct ones mark it as random: LZ4
/// shrinks bytes by repeats of four, which a plane of a few distinct bytes holds and one whose
/// sample is nearly all distinct almost never does.
const SAMPLES: usize = 16;
const RANDOM_DISTINCT: u32 = 13;

#[repr(C)]
struct Lz4Stream {
    _opaque: [u8; 0],
}

#[link(name = "lz4")]
unsafe extern "C" {
    fn LZ4_createStream() -> *mut Lz4Stream;
    fn LZ4_freeStream(stream: *mut Lz4Stream) -> c_int;
    fn LZ4_resetStream_fast(stream: *mut Lz4Stream);
    fn LZ4_compress_fast_continue(
        stream: *mut Lz4Stream,
        src: *const c_char,
        dst: *mut c_char,
        src_size: c_int,
        dst_capacity: c_int,
        acceleration: c_int,
    ) -> c_int;
}

/// Chunks a stream compresses before it is made anew (see the module docs): each moves it
/// at most 64 KiB plus a leaf's bytes on, short of 1 GiB by half.
const CHUNKS_PER_STREAM: u32 = 8192;

/// A thread's LZ4 stream, the chunks it compressed and its buffer of shuffled bytes.
struct Compressor {
    stream: *mut Lz4Stream,
    chunks: u32,
    shuffled: Vec<u8>,
}

impl Compressor {
    /// A new stream, warmed up; none where LZ4 cannot allocate one.
    fn new() -> Option<Compressor> {
        // SAFETY: a new stream, freed on drop.
        let stream = unsafe { LZ4_createStream() };
        if stream.is_null() {
            return None;
        }
        let mut c = Compressor {
            stream,
            chunks: 0,
            shuffled: Vec::new(),
        };
        let mut out = [0u8; MIN_BUFFER];
        c.lz4(&[0; MIN_BUFFER], &mut out);
        Some(c)
    }

    /// `data` as one LZ4 block into `out`; its length, 0 when it does not fit.
    fn lz4(&mut self, data: &[u8], out: &mut [u8]) -> usize {
        self.chunks += 1;
        // SAFETY: the stream is this thread's; LZ4 reads `data` and writes at most `out.len()`
        // bytes (both lengths below 2^31, checked by the caller).
        let n = unsafe {
            LZ4_resetStream_fast(self.stream);
            LZ4_compress_fast_continue(
                self.stream,
                data.as_ptr().cast(),
                out.as_mut_ptr().cast(),
                data.len() as c_int,
                out.len() as c_int,
                LZ4_ACCELERATION,
            )
        };
        n.max(0) as usize
    }

    /// The shuffled block as one LZ4 stream after the header and the block's start in `out`
    /// (its room): the chunk's length, `None` when it does not fit.
    fn stream(&mut self, shuffled: &[u8], out: &mut [u8]) -> Option<usize> {
        let packed = self.lz4(shuffled, &mut out[FRAMING..]);
        if packed == 0 {
            return None;
        }
        out[FRAMING - 4..FRAMING].copy_from_slice(&(packed as u32).to_le_bytes());
        Some(FRAMING + packed)
    }

    /// The shuffled block as one stream per plane, each behind its length: compressed where
    /// the plane is not among the `random` ones (bit `j` for plane `j`) and LZ4 shrinks it, raw
    /// (its length the plane's) where not. The chunk's length, `None` when it does not fit
    /// `out`.
    fn planes(
        &mut self,
        shuffled: &[u8],
        value_size: usize,
        random: u16,
        out: &mut [u8],
    ) -> Option<usize> {
        let plane_len = shuffled.len() / value_size;
        let mut at = FRAMING - 4;
        for (j, plane) in shuffled.chunks_exact(plane_len).enumerate() {
            let room = out.len().checked_sub(at + 4)?;
            let stream = &mut out[at + 4..];
            // A compressed stream as long as its plane would read as raw: LZ4 gets one less.
            let packed = if random >> j & 1 == 1 {
                0
            } else {
                self.lz4(plane, &mut stream[..room.min(plane_len - 1)])
            };
            let len = if packed == 0 {
                stream.get_mut(..plane_len)?.copy_from_slice(plane);
                plane_len
            } else {
                packed
            };
            out[at..at + 4].copy_from_slice(&(len as u32).to_le_bytes());
            at += 4 + len;
        }
        Some(at)
    }
}

impl Drop for Compressor {
    fn drop(&mut self) {
        // SAFETY: the stream was made by LZ4_createStream and is not used again.
        unsafe { LZ4_freeStream(self.stream) };
    }
}

thread_local! {
    static COMPRESSOR: RefCell<Option<Compressor>> = const { RefCell::new(None) };
}

/// `data` (values of `value_size` bytes) as a blosc chunk into `out`, when the chunk is shorter
/// than `data`: its length. `None` where blosc would not compress it either (short buffers,
/// or bytes that LZ4 does not shrink enough to pay for the framing), or where LZ4 has no
/// memory for a stream: the caller stores the bytes raw.
pub(super) fn blosc_chunk(data: &[u8], value_size: usize, out: &mut [u8]) -> Option<usize> {
    if data.len() < MIN_BUFFER || data.len() > i32::MAX as usize || value_size > 255 {
        return None;
    }
    // LZ4's room: what keeps the whole chunk shorter than the data.
    let room = out.len().min(data.len() - 1).checked_sub(FRAMING)?;
    COMPRESSOR.with_borrow_mut(|c| {
        if c.as_ref().is_none_or(|c| c.chunks >= CHUNKS_PER_STREAM) {
            *c = Compressor::new();
        }
        let c = c.as_mut()?;
        let mut shuffled = std::mem::take(&mut c.shuffled);
        shuffle(data, value_size, &mut shuffled);
        // The planes that look random, each sampled once (at most `MOST_PLANES`: a bit each).
        let random = if splits(data.len(), value_size) {
            shuffled
                .chunks_exact(data.len() / value_size)
                .enumerate()
                .fold(0u16, |bits, (j, plane)| {
                    bits | u16::from(looks_random(plane)) << j
                })
        } else {
            0
        };
        let split = random != 0;
        let written = if split {
            c.planes(&shuffled, value_size, random, &mut out[..FRAMING + room])
        } else {
            c.stream(&shuffled, &mut out[..FRAMING + room])
        };
        c.shuffled = shuffled;
        let total = written?;
        let nbytes = data.len() as u32;
        let flags = if split { SPLIT_FLAGS } else { FLAGS };
        out[..4].copy_from_slice(&[BLOSC_FORMAT, LZ4_FORMAT, flags, value_size as u8]);
        out[4..8].copy_from_slice(&nbytes.to_le_bytes());
        out[8..12].copy_from_slice(&nbytes.to_le_bytes());
        out[12..16].copy_from_slice(&(total as u32).to_le_bytes());
        out[16..20].copy_from_slice(&(HEADER as u32 + 4).to_le_bytes());
        Some(total)
    })
}

/// Whether blosc's reader splits a one-block chunk of `len` bytes of `value_size`-byte values
/// into planes when its header allows (`blosc_d`), each plane whole.
fn splits(len: usize, value_size: usize) -> bool {
    value_size > 1
        && value_size <= MOST_PLANES
        && len.is_multiple_of(value_size)
        && len / value_size >= MIN_BUFFER
}

/// Whether a plane's sample is nearly all distinct bytes (see `RANDOM_DISTINCT`).
fn looks_random(plane: &[u8]) -> bool {
    let stride = plane.len() / SAMPLES;
    let mut seen = [0u64; 4];
    for i in 0..SAMPLES {
        let b = plane[i * stride];
        seen[usize::from(b >> 6)] |= 1 << (b & 63);
    }
    seen.iter().map(|w| w.count_ones()).sum::<u32>() >= RANDOM_DISTINCT
}

/// Blosc's byte shuffle: byte `j` of every value together, for each `j` in turn; the bytes
/// after the last whole value as they are.
fn shuffle(data: &[u8], value_size: usize, out: &mut Vec<u8>) {
    // Every byte is written below: only new room is zeroed, not the whole buffer each time.
    out.resize(data.len(), 0);
    let values = data.len() / value_size;
    let whole = values * value_size;
    match value_size {
        4 => shuffle_floats(&data[..whole], &mut out[..whole]),
        2 => shuffle_halves(&data[..whole], &mut out[..whole]),
        _ => shuffle_values(&data[..whole], value_size, &mut out[..whole], 0),
    }
    out[whole..].copy_from_slice(&data[whole..]);
}

/// `shuffle` of whole values from value `first` on, one value at a time.
fn shuffle_values(data: &[u8], value_size: usize, out: &mut [u8], first: usize) {
    let values = data.len() / value_size;
    for (i, value) in data.chunks_exact(value_size).enumerate().skip(first) {
        for (j, &b) in value.iter().enumerate() {
            out[j * values + i] = b;
        }
    }
}

/// `shuffle` for floats: sixteen at a time by SSE2 where there is SSE2 (every x86-64), the
/// rest one at a time.
fn shuffle_floats(data: &[u8], out: &mut [u8]) {
    let values = data.len() / 4;
    #[cfg(target_arch = "x86_64")]
    let done = {
        let blocks = values / 16;
        for block in 0..blocks {
            // SAFETY: SSE2 is part of x86-64; the loads read 64 bytes of `data` from
            // `block * 64` and the stores write 16 bytes of each plane from `block * 16`, all
            // in bounds (`block < values / 16`, planes `values` long).
            unsafe { shuffle_16_floats(data, out, values, block) };
        }
        blocks * 16
    };
    #[cfg(not(target_arch = "x86_64"))]
    let done = 0;
    shuffle_values(data, 4, out, done);
}

/// Floats `16 * block..16 * block + 16` of `data` into the four planes of `out` (each `values`
/// long): within each 16-byte register a 4x4 transpose of bytes (two rounds of interleaving
/// its halves), then across the four registers a 4x4 transpose of 32-bit lanes.
#[cfg(target_arch = "x86_64")]
#[inline]
unsafe fn shuffle_16_floats(data: &[u8], out: &mut [u8], values: usize, block: usize) {
    use std::arch::x86_64::*;
    // SAFETY: see the caller.
    unsafe {
        let src = data.as_ptr().add(block * 64);
        let by_plane = |k: usize| {
            let x = _mm_loadu_si128(src.add(16 * k).cast());
            let x = _mm_unpacklo_epi8(x, _mm_srli_si128::<8>(x));
            _mm_unpacklo_epi8(x, _mm_srli_si128::<8>(x))
        };
        let (y0, y1, y2, y3) = (by_plane(0), by_plane(1), by_plane(2), by_plane(3));
        let (t0, t1) = (_mm_unpacklo_epi32(y0, y1), _mm_unpackhi_epi32(y0, y1));
        let (t2, t3) = (_mm_unpacklo_epi32(y2, y3), _mm_unpackhi_epi32(y2, y3));
        let planes = [
            _mm_unpacklo_epi64(t0, t2),
            _mm_unpackhi_epi64(t0, t2),
            _mm_unpacklo_epi64(t1, t3),
            _mm_unpackhi_epi64(t1, t3),
        ];
        let dst = out.as_mut_ptr();
        for (j, plane) in planes.into_iter().enumerate() {
            _mm_storeu_si128(dst.add(j * values + block * 16).cast(), plane);
        }
    }
}

/// `shuffle` for halves, one pass storing to both planes side by side (a `--sdf --half` level
/// set's encode at 1 thread: 0.263 s through `shuffle_values`, 0.246 s here).
fn shuffle_halves(data: &[u8], out: &mut [u8]) {
    let (p0, p1) = out.split_at_mut(data.len() / 2);
    for (value, (b0, b1)) in data.chunks_exact(2).zip(p0.iter_mut().zip(p1)) {
        (*b0, *b1) = (value[0], value[1]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::SplitMix64;
    use std::os::raw::c_void;

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
        fn blosc_set_splitmode(splitmode: c_int);
    }

    /// The chunk read back as the `.vdb` reader reads it, through blosc.
    fn unpack(chunk: &[u8], len: usize) -> Vec<u8> {
        let mut stored = (chunk.len() as i64).to_le_bytes().to_vec();
        stored.extend_from_slice(chunk);
        let (bytes, taken) = super::super::vdb_chunks::read_chunk(
            &stored,
            len,
            super::super::vdb_format::COMPRESS_BLOSC,
        )
        .expect("blosc reads the chunk back");
        assert_eq!(taken, stored.len());
        bytes
    }

    /// Values like a leaf's: a level set's distances, a fog's ones, halves, normals' triples.
    fn samples() -> Vec<(Vec<u8>, usize)> {
        let mut random = SplitMix64(5);
        let mut samples = Vec::new();
        for count in [32, 100, 300, 512] {
            let distances: Vec<u8> = (0..count)
                .flat_map(|i| ((i % 7) as f32 * 0.0015 - 0.0045).to_le_bytes())
                .collect();
            let noise: Vec<u8> = (0..count)
                .flat_map(|_| ((random.next_u64() % 10_000) as f32 * 1e-6).to_le_bytes())
                .collect();
            let ones: Vec<u8> = (0..count).flat_map(|_| 1.0f32.to_le_bytes()).collect();
            let halves: Vec<u8> = (0..count)
                .flat_map(|i| (i as u16 % 9).to_le_bytes())
                .collect();
            samples.extend([(distances, 4), (noise, 4), (ones, 4), (halves, 2)]);
            samples.push(((0..count * 12).map(|i| (i % 5) as u8).collect(), 12));
            samples.push(((0..count).map(|i| (i % 3) as u8).collect(), 1));
        }
        samples
    }

    #[test]
    fn chunks_are_blosc_chunks_of_the_same_bytes() {
        let mut compressed = 0;
        let mut split = 0;
        for (data, value_size) in samples() {
            let mut out = vec![0u8; data.len() + 64];
            let Some(n) = blosc_chunk(&data, value_size, &mut out) else {
                continue;
            };
            compressed += 1;
            assert!(n < data.len(), "kept only when shorter");
            assert_eq!(
                unpack(&out[..n], data.len()),
                data,
                "{value_size}-byte values"
            );
            // Blosc's chunks to compare headers with: split into planes or not, as this is
            // (its modes: 1 always, 2 never).
            let planes = out[2] & 0x10 == 0;
            split += usize::from(planes);
            // SAFETY: sets a global that only this test's calls read.
            unsafe { blosc_set_splitmode(if planes { 1 } else { 2 }) };
            // Blosc's own chunk of the same values has the same header (its sizes aside).
            let mut theirs = vec![0u8; data.len() + 64];
            // SAFETY: blosc reads `data` and writes at most `theirs.len()` bytes.
            let m = unsafe {
                blosc_compress_ctx(
                    9,
                    1,
                    value_size,
                    data.len(),
                    data.as_ptr().cast(),
                    theirs.as_mut_ptr().cast(),
                    theirs.len(),
                    c"lz4".as_ptr(),
                    data.len(),
                    1,
                )
            };
            assert!(m > 0);
            // Unless blosc stored them raw (its memcpy flag).
            if theirs[2] & 0x02 == 0 {
                assert_eq!(out[..12], theirs[..12], "the header as blosc writes it");
            }
        }
        assert!(compressed >= 12, "most samples compress ({compressed})");
        // The noise of 300 and 512 values (whose low bytes look random) is split.
        assert!(split >= 2, "{split} chunks split into planes");
    }

    #[test]
    fn random_planes_are_stored_raw_and_the_rest_compressed() {
        // Distances of a leaf: a smooth exponent byte, random low bytes.
        let mut random = SplitMix64(3);
        let data: Vec<u8> = (0..400)
            .flat_map(|i| {
                (0.001 * (1.0 + i as f32 / 400.0) + random.range(0.0, 1e-5) as f32).to_le_bytes()
            })
            .collect();
        let mut out = vec![0u8; data.len()];
        let n = blosc_chunk(&data, 4, &mut out).expect("the exponent plane compresses");
        assert_eq!(out[2] & 0x10, 0, "split into planes");
        let mut at = FRAMING - 4;
        let mut lengths = Vec::new();
        for _ in 0..4 {
            let len = u32::from_le_bytes(out[at..at + 4].try_into().unwrap()) as usize;
            lengths.push(len);
            at += 4 + len;
        }
        assert_eq!(at, n, "four streams fill the chunk");
        assert_eq!(lengths[..2], [400, 400], "the low bytes raw");
        assert!(
            lengths[3] < 100,
            "the exponent bytes compressed: {lengths:?}"
        );
        assert_eq!(unpack(&out[..n], data.len()), data);
    }

    #[test]
    fn a_chunk_does_not_depend_on_what_its_thread_compressed_before() {
        let samples = samples();
        let alone: Vec<Option<Vec<u8>>> = std::thread::scope(|s| {
            samples
                .iter()
                .map(|(data, value_size)| {
                    s.spawn(|| {
                        let mut out = vec![0u8; data.len() + 64];
                        blosc_chunk(data, *value_size, &mut out).map(|n| out[..n].to_vec())
                    })
                    .join()
                    .unwrap()
                })
                .collect()
        });
        // One thread, every sample after the others: all in reverse order, then all in order.
        for (i, (data, value_size)) in samples
            .iter()
            .enumerate()
            .rev()
            .chain(samples.iter().enumerate())
        {
            let mut out = vec![0u8; data.len() + 64];
            let after = blosc_chunk(data, *value_size, &mut out).map(|n| out[..n].to_vec());
            assert_eq!(after, alone[i], "sample {i}");
        }
    }

    #[test]
    fn a_chunk_does_not_depend_on_how_many_its_thread_compressed_before() {
        // A fog leaf's values (1 inside, a ramp near the surface): from an empty table LZ4
        // finds a match that it does not find after a stream's warm-up.
        let data: Vec<u8> = (0..494)
            .flat_map(|i| {
                let v = if i * 37 % 11 < 7 {
                    1.0f32
                } else {
                    (i % 13) as f32 / 13.0
                };
                v.to_le_bytes()
            })
            .collect();
        let chunk = || {
            let mut out = vec![0u8; data.len() + 64];
            blosc_chunk(&data, 4, &mut out).map(|n| out[..n].to_vec())
        };
        let alone = std::thread::scope(|s| s.spawn(chunk).join().unwrap());
        assert!(alone.is_some());
        // Past LZ4's reset of a stream's table, once its offset passes 1 GiB: about 16,000
        // chunks, each fast reset moving it 64 KiB on, as a thread encoding a grid does.
        std::thread::scope(|s| {
            s.spawn(|| (0..40_000).for_each(|k| assert_eq!(chunk(), alone, "chunk {k}")))
                .join()
                .unwrap()
        });
    }

    #[test]
    fn shuffles_put_each_byte_of_a_value_in_its_plane() {
        for (len, value_size) in [
            (0, 4),
            (4, 4),
            (60, 4),
            (64, 4),
            (2048, 4),
            (2051, 4),
            (94, 2),
            (36, 12),
        ] {
            let data: Vec<u8> = (0..len).map(|i| (i * 7 + i / 5) as u8).collect();
            let mut out = Vec::new();
            shuffle(&data, value_size, &mut out);
            let values = len / value_size;
            for i in 0..values {
                for j in 0..value_size {
                    assert_eq!(out[j * values + i], data[i * value_size + j], "{len} bytes");
                }
            }
            assert_eq!(out[values * value_size..], data[values * value_size..]);
        }
    }

    #[test]
    fn short_or_incompressible_data_is_left_to_be_stored_raw() {
        assert_eq!(blosc_chunk(&[1u8; 64], 4, &mut [0; 256]), None);
        let mut random = SplitMix64(9);
        let noise: Vec<u8> = (0..2048).map(|_| random.next_u64() as u8).collect();
        assert_eq!(blosc_chunk(&noise, 4, &mut vec![0; 4096]), None);
    }
}

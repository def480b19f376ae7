//! Large outputs written around the page cache. Every file voxelkit writes is synced before
//! it is renamed into place (`atomic`), so its bytes must reach the disk before the run ends
//! anyway; copying them into the page cache first cost more CPU than compressing them on the
//! virtual machine measured (about 2 ms per megabyte of fresh page cache) and adds the file's
//! size to the memory the run touches. Whole aligned blocks go to the disk directly
//! (`O_DIRECT`) from one reused buffer, and so do the whole pages of the last partial block
//! (a file of a few megabytes, a brick's, never fills a block); its last partial page and
//! later patches go through the page cache as usual, and so does everything where the file
//! system refuses direct I/O (tmpfs, some network file systems).

use std::fs::File;
use std::io;
use std::os::unix::fs::FileExt;
use std::os::unix::io::AsRawFd;
use std::path::Path;

/// Bytes per direct write: large enough that the device's latency is small beside the
/// transfer, small enough to stay in the cache while it is filled.
const BLOCK: usize = 4 << 20;

/// The alignment direct I/O asks of buffers, lengths and offsets: a page, which every
/// device's logical block size divides.
pub(super) const ALIGN: usize = 4096;

/// `len` bytes (a multiple of `ALIGN`) at an aligned address, as direct I/O asks.
pub(super) struct AlignedBuffer {
    /// `len + ALIGN` bytes, of which the aligned `len` from `start` are the buffer.
    buffer: Vec<u8>,
    start: usize,
    len: usize,
}

impl AlignedBuffer {
    pub(super) fn new(len: usize) -> AlignedBuffer {
        let buffer = vec![0u8; len + ALIGN];
        let start = buffer.as_ptr().align_offset(ALIGN);
        AlignedBuffer { buffer, start, len }
    }

    pub(super) fn bytes(&self) -> &[u8] {
        &self.buffer[self.start..self.start + self.len]
    }

    pub(super) fn bytes_mut(&mut self) -> &mut [u8] {
        &mut self.buffer[self.start..self.start + self.len]
    }
}

/// A new file written front to back in blocks.
pub(super) struct DirectFile {
    file: File,
    block: AlignedBuffer,
    /// Bytes of the block filled.
    filled: usize,
    /// Bytes already handed to the file.
    written: u64,
    /// Whether whole blocks still go around the page cache (until the file system refuses).
    direct: bool,
}

impl DirectFile {
    pub(super) fn create(path: &Path) -> io::Result<Self> {
        Ok(DirectFile {
            file: File::create(path)?,
            block: AlignedBuffer::new(BLOCK),
            filled: 0,
            written: 0,
            direct: true,
        })
    }

    pub(super) fn write_all(&mut self, mut bytes: &[u8]) -> io::Result<()> {
        while !bytes.is_empty() {
            let n = (BLOCK - self.filled).min(bytes.len());
            self.block.bytes_mut()[self.filled..self.filled + n].copy_from_slice(&bytes[..n]);
            self.filled += n;
            bytes = &bytes[n..];
            if self.filled == BLOCK {
                self.write_block()?;
            }
        }
        Ok(())
    }

    /// Makes the bytes written so far durable where they went through the page cache (direct
    /// blocks are on the device already; the partial block is not written yet).
    pub(super) fn sync_data(&mut self) -> io::Result<()> {
        if self.direct {
            return Ok(());
        }
        self.file.sync_data()
    }

    /// Writes the partial block (its whole pages directly, so that a file smaller than a
    /// block goes around the page cache too) and hands back the file, its direct I/O turned
    /// off so that small writes (patches) may follow anywhere.
    pub(super) fn finish(mut self) -> io::Result<File> {
        let pages = self.filled / ALIGN * ALIGN;
        if pages > 0 {
            self.write_direct(pages)?;
        }
        if self.direct {
            set_direct(&self.file, false)?;
        }
        let rest = &self.block.bytes()[pages..self.filled];
        self.file.write_all_at(rest, self.written)?;
        Ok(self.file)
    }

    fn write_block(&mut self) -> io::Result<()> {
        self.write_direct(BLOCK)?;
        self.filled = 0;
        Ok(())
    }

    /// Writes the block's first `len` bytes (whole pages) at their aligned place: directly
    /// while the file system allows, else through the page cache.
    fn write_direct(&mut self, len: usize) -> io::Result<()> {
        let block = &self.block.bytes()[..len];
        if self.direct && self.written == 0 && set_direct(&self.file, true).is_err() {
            self.direct = false;
        }
        if self.direct {
            match self.file.write_all_at(block, self.written) {
                Err(e) if e.raw_os_error() == Some(libc::EINVAL) => {
                    // Accepted at open, refused on write: the rest goes through the cache.
                    self.direct = false;
                    set_direct(&self.file, false)?;
                    self.file.write_all_at(block, self.written)?;
                }
                done => done?,
            }
        } else {
            self.file.write_all_at(block, self.written)?;
        }
        self.written += len as u64;
        Ok(())
    }
}

/// Turns direct I/O on or off for `file`.
pub(super) fn set_direct(file: &File, on: bool) -> io::Result<()> {
    let fd = file.as_raw_fd();
    // SAFETY: fcntl on a descriptor this file owns; F_GETFL and F_SETFL take no pointers.
    let flags = unsafe { libc::fcntl(fd, libc::F_GETFL) };
    if flags < 0 {
        return Err(io::Error::last_os_error());
    }
    let flags = if on {
        flags | libc::O_DIRECT
    } else {
        flags & !libc::O_DIRECT
    };
    // SAFETY: as above.
    if unsafe { libc::fcntl(fd, libc::F_SETFL, flags) } < 0 {
        return Err(io::Error::last_os_error());
    }
    Ok(())
}

/// Writes each `(bytes, at)` of `pieces` at `at` in the existing file `path` and syncs it:
/// the whole pages inside a piece directly (through an aligned buffer, as direct I/O asks),
/// its ends through the page cache. Pieces of one file may be written so by several
/// processes at once: a page is written directly only when one piece covers it, and a page
/// shared by two pieces is written through the one page cache, where each piece's bytes land
/// beside the other's. `WRITERS` threads take every `WRITERS`th piece each: pieces of a
/// brick merged in place are 0.1-0.5 MB, and one direct write at a time leaves the device
/// waiting between them.
pub(super) fn write_pieces_at(path: &Path, pieces: &[(&[u8], u64)]) -> io::Result<()> {
    let file = std::fs::OpenOptions::new().write(true).open(path)?;
    let writers = WRITERS.min(pieces.len());
    std::thread::scope(|scope| {
        let threads: Vec<_> = (0..writers)
            .map(|k| {
                let file = &file;
                scope.spawn(move || {
                    let mut out = PieceWriter::new(path, file);
                    let written = pieces[k..]
                        .iter()
                        .step_by(writers)
                        .try_for_each(|&(bytes, at)| out.write(bytes, at));
                    if let Ok(mut spare) = SPARE_BLOCKS.lock() {
                        spare.push(out.block);
                    }
                    written
                })
            })
            .collect();
        threads
            .into_iter()
            .try_for_each(|t| t.join().unwrap_or_else(|p| std::panic::resume_unwind(p)))
    })?;
    file.sync_data()
}

/// Threads writing pieces at once (`write_pieces_at`).
const WRITERS: usize = 4;

/// The writers' aligned buffers between calls: a worker writes brick after brick, and fresh
/// pages cost more than the copy into them.
static SPARE_BLOCKS: std::sync::Mutex<Vec<AlignedBuffer>> = std::sync::Mutex::new(Vec::new());

/// Writes pieces at their offsets: `file` for the pages a piece shares, a descriptor of its
/// own for direct writes (while the file system takes them) through its aligned buffer.
struct PieceWriter<'f> {
    file: &'f File,
    direct: Option<File>,
    block: AlignedBuffer,
}

impl<'f> PieceWriter<'f> {
    fn new(path: &Path, file: &'f File) -> PieceWriter<'f> {
        let direct = std::fs::OpenOptions::new()
            .write(true)
            .open(path)
            .and_then(|f| set_direct(&f, true).map(|_| f))
            .ok();
        let spare = SPARE_BLOCKS.lock().ok().and_then(|mut b| b.pop());
        PieceWriter {
            file,
            direct,
            block: spare.unwrap_or_else(|| AlignedBuffer::new(BLOCK)),
        }
    }

    fn write(&mut self, bytes: &[u8], at: u64) -> io::Result<()> {
        let align = ALIGN as u64;
        let end = at + bytes.len() as u64;
        let (first, last) = (at.next_multiple_of(align), end / align * align);
        if self.direct.is_none() || first >= last {
            return self.file.write_all_at(bytes, at);
        }
        self.file
            .write_all_at(&bytes[..(first - at) as usize], at)?;
        let mut pos = first;
        while pos < last {
            let n = (last - pos).min(BLOCK as u64) as usize;
            let from = (pos - at) as usize;
            let aligned = &mut self.block.bytes_mut()[..n];
            aligned.copy_from_slice(&bytes[from..from + n]);
            let written = self.direct.as_ref().map(|d| d.write_all_at(aligned, pos));
            if let Some(Err(e)) = &written
                && e.raw_os_error() == Some(libc::EINVAL)
            {
                // Accepted at open, refused on write: the rest goes through the cache.
                self.direct = None;
                break;
            }
            written.transpose()?;
            pos += n as u64;
        }
        // The piece's last partial page, or all from a block the file system refused.
        self.file.write_all_at(&bytes[(pos - at) as usize..], pos)
    }
}

/// Where the direct I/O tests write: the temporary folder (direct where its file system
/// allows) and memory (tmpfs, which refuses it), where they exist.
#[cfg(test)]
pub(super) fn test_folders() -> Vec<std::path::PathBuf> {
    let folders = [std::env::temp_dir(), "/dev/shm".into()];
    folders.into_iter().filter(|f| f.is_dir()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Files of every size around the block and alignment boundaries, written in uneven
    /// pieces, read back byte for byte: in the temporary folder (direct where its file
    /// system allows) and in memory (tmpfs, where it may not).
    #[test]
    fn what_is_written_reads_back() {
        for folder in test_folders() {
            written_files_read_back(&folder);
        }
    }

    /// A file cut into pieces of every size (within a page, across pages, over a block),
    /// written out of order by two threads at once into the file made at its length, reads
    /// back byte for byte: in the temporary folder and in memory.
    #[test]
    fn pieces_written_in_place_by_two_writers_read_back() {
        for folder in test_folders() {
            let path = folder.join(format!("voxelkit-pieces-{}", std::process::id()));
            let mut random = crate::random::SplitMix64(9);
            let bytes: Vec<u8> = (0..BLOCK * 2 + 5 * ALIGN + 321)
                .map(|_| random.next_u64() as u8)
                .collect();
            let mut pieces = Vec::new();
            let mut at = 0;
            for size in [
                1,
                ALIGN - 7,
                13,
                2 * ALIGN + 5,
                ALIGN,
                BLOCK + 3,
                40,
                usize::MAX,
            ] {
                let n = size.min(bytes.len() - at);
                pieces.push((&bytes[at..at + n], at as u64));
                at += n;
            }
            std::fs::File::create(&path)
                .unwrap()
                .set_len(bytes.len() as u64)
                .unwrap();
            pieces.reverse();
            let odd: Vec<_> = pieces.iter().copied().skip(1).step_by(2).collect();
            let even: Vec<_> = pieces.iter().copied().step_by(2).collect();
            std::thread::scope(|scope| {
                scope.spawn(|| write_pieces_at(&path, &odd).unwrap());
                scope.spawn(|| write_pieces_at(&path, &even).unwrap());
            });
            assert!(
                std::fs::read(&path).unwrap() == bytes,
                "{}",
                folder.display()
            );
            std::fs::remove_file(&path).unwrap();
        }
    }

    fn written_files_read_back(folder: &Path) {
        let dir = folder.join(format!("voxelkit-direct-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut random = crate::random::SplitMix64(3);
        for size in [
            0,
            1,
            ALIGN - 1,
            ALIGN,
            3 * ALIGN + 1,
            BLOCK - 1,
            BLOCK,
            BLOCK + 1,
            2 * BLOCK + 12345,
        ] {
            let bytes: Vec<u8> = (0..size).map(|_| random.next_u64() as u8).collect();
            let path = dir.join(format!("{size}.bin"));
            let mut out = DirectFile::create(&path).unwrap();
            let mut rest = &bytes[..];
            while !rest.is_empty() {
                let n = (random.next_u64() as usize % 300_000 + 1).min(rest.len());
                out.write_all(&rest[..n]).unwrap();
                rest = &rest[n..];
            }
            out.sync_data().unwrap();
            let file = out.finish().unwrap();
            if size > 8 {
                file.write_all_at(b"patched!", 1).unwrap();
            }
            drop(file);
            let mut expected = bytes.clone();
            if size > 8 {
                expected[1..9].copy_from_slice(b"patched!");
            }
            assert!(std::fs::read(&path).unwrap() == expected, "size {size}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

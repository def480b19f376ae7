//! Files read in aligned blocks into one reused buffer, around the page cache where asked
//! (`O_DIRECT`). A brick file is read once or twice by a merge and then deleted: caching it
//! would only cost fresh page cache (see `direct_file`), and on the virtual machine measured a
//! file written around the cache read back through it cost 1.5-2 ms of CPU per megabyte,
//! against almost none read directly. Where the file system refuses direct I/O the same
//! blocks go through the page cache.

use super::direct_file::{ALIGN, AlignedBuffer, set_direct};
use std::fs::File;
use std::io;
use std::ops::Range;
use std::os::unix::fs::{FileExt, OpenOptionsExt};
use std::path::Path;

/// Opens `path` for reading, directly if `direct` and the file system allows it.
pub(super) fn open(path: &Path, direct: bool) -> io::Result<File> {
    let flags = if direct { libc::O_DIRECT } else { 0 };
    match std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(flags)
        .open(path)
    {
        Err(e) if direct && e.raw_os_error() == Some(libc::EINVAL) => File::open(path),
        opened => opened,
    }
}

/// An aligned block of bytes (a multiple of `ALIGN`) that file pages are read into.
pub(super) struct AlignedBlock(AlignedBuffer);

impl AlignedBlock {
    pub(super) fn new(block: usize) -> AlignedBlock {
        AlignedBlock(AlignedBuffer::new(block))
    }

    /// Reads `file`'s pages from `at` (a page boundary) up to `len` bytes (at most the block)
    /// or the file's end; returns the bytes read.
    fn read(&mut self, file: &File, at: u64, len: usize) -> io::Result<&[u8]> {
        let len = len.min(self.0.bytes().len());
        let block = &mut self.0.bytes_mut()[..len];
        let mut filled = 0;
        let mut fell_back = false;
        while filled < block.len() {
            let read = match file.read_at(&mut block[filled..], at + filled as u64) {
                Err(e) if e.raw_os_error() == Some(libc::EINVAL) && !fell_back => {
                    // Accepted at open, refused on read: the rest goes through the cache.
                    set_direct(file, false)?;
                    fell_back = true;
                    continue;
                }
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                read => read?,
            };
            if read == 0 {
                break;
            }
            filled += read;
            // A direct read ends short only at the end of the file.
            if filled % ALIGN != 0 {
                break;
            }
        }
        Ok(&block[..filled])
    }

    /// Appends `file`'s bytes in `range` to `out`, reading only the pages that hold them.
    pub(super) fn append(
        &mut self,
        file: &File,
        range: &Range<u64>,
        out: &mut Vec<u8>,
    ) -> io::Result<()> {
        let mut pos = range.start;
        while pos < range.end {
            let at = page_below(pos);
            let want = (range.end.next_multiple_of(ALIGN as u64) - at) as usize;
            let bytes = self.read(file, at, want)?;
            let from = (pos - at) as usize;
            let to = ((range.end - at) as usize).min(bytes.len());
            if from >= to {
                return Err(io::ErrorKind::UnexpectedEof.into());
            }
            out.extend_from_slice(&bytes[from..to]);
            pos = at + to as u64;
        }
        Ok(())
    }
}

fn page_below(pos: u64) -> u64 {
    pos / ALIGN as u64 * ALIGN as u64
}

/// A file read forwards (or from any position) a block at a time.
pub(super) struct BlockReader {
    file: File,
    block: AlignedBlock,
    /// The file offset of the block's first byte, and how many of its bytes are valid.
    at: u64,
    filled: usize,
}

impl BlockReader {
    /// `path` read `block` bytes (a multiple of `ALIGN`) at a time, directly if `direct` and
    /// the file system allows it.
    pub(super) fn open(path: &Path, block: usize, direct: bool) -> io::Result<BlockReader> {
        Ok(BlockReader {
            file: open(path, direct)?,
            block: AlignedBlock::new(block),
            at: 0,
            filled: 0,
        })
    }

    pub(super) fn len(&self) -> io::Result<u64> {
        Ok(self.file.metadata()?.len())
    }

    /// Fills `out` with the file's bytes from `pos` on, from the block when it holds them.
    pub(super) fn read_exact_at(&mut self, mut pos: u64, mut out: &mut [u8]) -> io::Result<()> {
        while !out.is_empty() {
            let offset = pos.wrapping_sub(self.at);
            if pos < self.at || offset >= self.filled as u64 {
                self.at = page_below(pos);
                self.filled = self.block.read(&self.file, self.at, usize::MAX)?.len();
                if pos - self.at >= self.filled as u64 {
                    return Err(io::ErrorKind::UnexpectedEof.into());
                }
                continue;
            }
            let offset = offset as usize;
            let n = (self.filled - offset).min(out.len());
            out[..n].copy_from_slice(&self.block.0.bytes()[offset..offset + n]);
            pos += n as u64;
            out = &mut out[n..];
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reads forwards, backwards and across block and page boundaries, in the temporary
    /// folder (direct where its file system allows) and in memory (tmpfs), give the file's
    /// bytes; a read past the end fails.
    #[test]
    fn blocks_read_back_the_file() {
        for folder in crate::io::direct_file::test_folders() {
            let path = folder.join(format!("voxelkit-direct-read-{}", std::process::id()));
            let mut random = crate::random::SplitMix64(5);
            let bytes: Vec<u8> = (0..3 * ALIGN * 5 + 77)
                .map(|_| random.next_u64() as u8)
                .collect();
            std::fs::write(&path, &bytes).unwrap();
            let mut reader = BlockReader::open(&path, 2 * ALIGN, true).unwrap();
            assert_eq!(reader.len().unwrap(), bytes.len() as u64);
            let file = open(&path, true).unwrap();
            let mut block = AlignedBlock::new(2 * ALIGN);
            for _ in 0..200 {
                let a = random.next_u64() as usize % bytes.len();
                let b = a + random.next_u64() as usize % (bytes.len() - a + 1);
                let mut out = vec![0u8; b - a];
                reader.read_exact_at(a as u64, &mut out).unwrap();
                assert!(out == bytes[a..b], "bytes {a}..{b} of {folder:?}");
                let mut out = vec![1u8];
                block
                    .append(&file, &(a as u64..b as u64), &mut out)
                    .unwrap();
                assert!(out[1..] == bytes[a..b], "bytes {a}..{b} of {folder:?}");
            }
            let last = bytes.len() as u64 - 1;
            assert!(reader.read_exact_at(last, &mut [0u8; 2]).is_err());
            let past = bytes.len() as u64 - 1..bytes.len() as u64 + 1;
            assert!(block.append(&file, &past, &mut Vec::new()).is_err());
            std::fs::remove_file(&path).unwrap();
        }
    }
}

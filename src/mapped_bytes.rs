//! Bytes held in an anonymous mapping of their own, handed back to the kernel when dropped.
//! A distributed worker holds its encoded bricks until the merge: in glibc's arenas, which
//! a worker keeps for its next brick (`system::keep_freed_memory`), they would stay with the
//! process after the run (skull's surface at 32768: 5.9 GB a worker).

use std::ops::Deref;
use std::ptr::NonNull;

pub struct MappedBytes {
    ptr: *mut u8,
    len: usize,
}

// SAFETY: the mapping is owned, never aliased mutably after it is filled, and freed once.
unsafe impl Send for MappedBytes {}
// SAFETY: as above; shared access only reads.
unsafe impl Sync for MappedBytes {}

impl MappedBytes {
    /// A copy of `bytes` in a mapping of its own.
    pub fn copy_of(bytes: &[u8]) -> std::io::Result<MappedBytes> {
        if bytes.is_empty() {
            return Ok(MappedBytes {
                ptr: std::ptr::NonNull::dangling().as_ptr(),
                len: 0,
            });
        }
        let ptr = map_anonymous(bytes.len(), 0)?.as_ptr();
        // SAFETY: the mapping is `bytes.len()` writable bytes and does not overlap `bytes`.
        unsafe { std::ptr::copy_nonoverlapping(bytes.as_ptr(), ptr, bytes.len()) };
        Ok(MappedBytes {
            ptr,
            len: bytes.len(),
        })
    }
}

/// A new private anonymous mapping of `len` (non-zero) readable and writable bytes, with
/// `flags` beside `MAP_PRIVATE | MAP_ANONYMOUS`; its pages are made when first used.
pub(crate) fn map_anonymous(len: usize, flags: libc::c_int) -> std::io::Result<NonNull<u8>> {
    // SAFETY: a new private anonymous mapping; no file, no fixed address.
    let ptr = unsafe {
        libc::mmap(
            std::ptr::null_mut(),
            len,
            libc::PROT_READ | libc::PROT_WRITE,
            libc::MAP_PRIVATE | libc::MAP_ANONYMOUS | flags,
            -1,
            0,
        )
    };
    if ptr == libc::MAP_FAILED {
        return Err(std::io::Error::last_os_error());
    }
    NonNull::new(ptr.cast()).ok_or_else(|| std::io::Error::other("mmap returned null"))
}

impl Deref for MappedBytes {
    type Target = [u8];

    fn deref(&self) -> &[u8] {
        // SAFETY: `len` initialised bytes at `ptr` (or none at a dangling, aligned pointer).
        unsafe { std::slice::from_raw_parts(self.ptr, self.len) }
    }
}

impl Drop for MappedBytes {
    fn drop(&mut self) {
        if self.len > 0 {
            // SAFETY: the mapping made in `copy_of`, unmapped once.
            unsafe { libc::munmap(self.ptr.cast(), self.len) };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_copy_holds_the_bytes() {
        let bytes: Vec<u8> = (0..100_000u32).map(|v| (v * 7) as u8).collect();
        assert_eq!(&*MappedBytes::copy_of(&bytes).unwrap(), &bytes[..]);
        assert!(MappedBytes::copy_of(&[]).unwrap().is_empty());
    }
}

//! Large vectors backed by transparent huge pages.
//!
//! A 1024^3 surface's primitives are about a hundred megabytes written once: in 4 KiB pages
//! that is tens of thousands of page faults, a tenth of the whole run. Where transparent huge
//! pages are enabled for `madvise` (Debian's default), the kernel is asked to back vectors
//! that are about to be filled whole with 2 MiB pages. Only for vectors written whole: a
//! sparsely touched block would become resident in full. Only a hint: where the kernel
//! declines, nothing changes.

/// Vectors of at least this many bytes are advised (a few huge pages, little waste at the
/// ends).
const HUGE_BLOCK: usize = 4 << 20;
/// The huge page size on x86-64 and aarch64 with 4 KiB base pages.
const HUGE_PAGE: usize = 2 << 20;

/// An empty vector with room for `capacity` elements, its whole huge pages advised to be
/// huge: for a vector about to be filled to about that length.
pub fn vec_to_fill<T>(capacity: usize) -> Vec<T> {
    let v = Vec::with_capacity(capacity);
    let bytes = v.capacity() * std::mem::size_of::<T>();
    #[cfg(target_os = "linux")]
    if bytes >= HUGE_BLOCK {
        let start = (v.as_ptr() as usize).next_multiple_of(HUGE_PAGE);
        let end = (v.as_ptr() as usize + bytes) & !(HUGE_PAGE - 1);
        if end > start {
            // SAFETY: the range lies inside the vector's own allocation; the advice changes
            // how its pages are backed, not their contents.
            unsafe {
                libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE);
            }
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = bytes;
    v
}

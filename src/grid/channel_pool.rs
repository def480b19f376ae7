//! A leaf's channel arrays (its 512 values, normals or colours), held in chunks whose pages
//! are made present together.
//!
//! A 1024^3 level set's band holds 78,000 value arrays, 159 MB. Allocated one by one, each
//! 4 KiB page of fresh memory costs a page fault when first written: 39,000 of them. A chunk
//! of 32 arrays has its pages made present in one call instead (bunny-closed's level set at
//! 1024, 1 thread: 0.74 -> 0.68 s). (Huge pages would need fewer faults still, but where
//! memory is fragmented the kernel stalls compacting it for them.)
//!
//! Chunks are cut from large reservations of address space, whose pages exist only once made
//! present. Taken from the heap, nearly every chunk grew a thread's arena, a `mprotect` that
//! waits for the process's memory map while another thread makes its chunk's pages present
//! (bunny-closed's level set at 1024, 2 threads: 440 such waits; its distances and inside
//! 0.262 -> 0.229 s without them). The pool cannot reuse what a job freed to the heap, so the
//! heap's free pages go back to the kernel before each new reservation (a CSG union of two
//! solids' files peaked at 393 MiB without that, 278 MiB with it, 284 MiB from the heap). A
//! dropped array's slot is kept for the next array of its kind; once none is in use, every
//! chunk but the first goes back to the kernel.

use std::ptr::NonNull;
use std::sync::Mutex;

/// A channel array kept in a pool: zeroed when made, owned like a `Box`.
pub struct ChannelBox<T: Channel>(NonNull<T>);

/// A type whose arrays come from a pool of their own.
///
/// # Safety
/// Every bit pattern of zero bytes must be a valid `T` (arrays are made from zeroed memory),
/// and `T` must need no drop.
pub unsafe trait Channel: Copy + Send + Sync + 'static {
    /// The pool of arrays of this type.
    fn pool() -> &'static Mutex<Pool>;
}

// SAFETY: f32 arrays are valid as zero bytes and need no drop.
unsafe impl Channel for [f32; super::LEAF_VOXELS] {
    fn pool() -> &'static Mutex<Pool> {
        static POOL: Mutex<Pool> = Mutex::new(Pool::new(size_of::<[f32; super::LEAF_VOXELS]>()));
        &POOL
    }
}

// SAFETY: as above.
unsafe impl Channel for [[f32; 3]; super::LEAF_VOXELS] {
    fn pool() -> &'static Mutex<Pool> {
        static POOL: Mutex<Pool> =
            Mutex::new(Pool::new(size_of::<[[f32; 3]; super::LEAF_VOXELS]>()));
        &POOL
    }
}

// SAFETY: a `ChannelBox` owns its array alone, as a `Box` does.
unsafe impl<T: Channel> Send for ChannelBox<T> {}
// SAFETY: shared references give only shared access to the array.
unsafe impl<T: Channel> Sync for ChannelBox<T> {}

impl<T: Channel> ChannelBox<T> {
    /// A zeroed array.
    pub fn zeroed() -> Self {
        let slot = take(T::pool()).cast::<T>();
        // SAFETY: the slot is the pool's for `T`, unused, sized and aligned for one `T`; zero
        // bytes are a valid `T` (`Channel`'s contract).
        unsafe { slot.as_ptr().write_bytes(0, 1) };
        ChannelBox(slot)
    }
}

/// An unused slot of `pool`. A new chunk's pages are made present outside the lock: that
/// takes a while.
fn take(pool: &Mutex<Pool>) -> NonNull<u8> {
    let (chunk, len) = {
        let mut pool = lock(pool);
        if let Some(slot) = pool.take() {
            return slot;
        }
        pool.cut_chunk()
    };
    make_present(chunk, len);
    let mut pool = lock(pool);
    pool.add_chunk(chunk, len);
    pool.take().expect("a slot in the chunk just added")
}

impl ChannelBox<[f32; super::LEAF_VOXELS]> {
    /// The values `value(n)` for `n` in `0..512`, each written once (no zeroing first).
    #[inline]
    pub fn from_fn(mut value: impl FnMut(usize) -> f32) -> Self {
        let slot = take(<[f32; super::LEAF_VOXELS]>::pool()).cast::<f32>();
        for n in 0..super::LEAF_VOXELS {
            // SAFETY: the slot is unused, sized and aligned for 512 floats; every one is
            // written before the box hands out a reference.
            unsafe { slot.as_ptr().add(n).write(value(n)) };
        }
        ChannelBox(slot.cast())
    }
}

impl<T: Channel> std::ops::Deref for ChannelBox<T> {
    type Target = T;

    #[inline]
    fn deref(&self) -> &T {
        // SAFETY: the slot holds a valid `T` owned by this box until it drops.
        unsafe { self.0.as_ref() }
    }
}

impl<T: Channel> std::ops::DerefMut for ChannelBox<T> {
    #[inline]
    fn deref_mut(&mut self) -> &mut T {
        // SAFETY: as in `deref`; `&mut self` makes the access unique.
        unsafe { self.0.as_mut() }
    }
}

impl<T: Channel> Clone for ChannelBox<T> {
    fn clone(&self) -> Self {
        let slot = take(T::pool()).cast::<T>();
        // SAFETY: the slot is unused and sized and aligned for one `T`.
        unsafe { slot.as_ptr().write(**self) };
        ChannelBox(slot)
    }
}

impl<T: Channel> Drop for ChannelBox<T> {
    fn drop(&mut self) {
        lock(T::pool()).give(self.0.cast());
    }
}

impl<T: Channel + std::fmt::Debug> std::fmt::Debug for ChannelBox<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        (**self).fmt(f)
    }
}

impl<T: Channel + PartialEq> PartialEq for ChannelBox<T> {
    fn eq(&self, other: &Self) -> bool {
        **self == **other
    }
}

/// The pool's lock; a panic while it was held left its lists whole (each step that changes
/// them cannot panic half-way), so a poisoned lock is taken as it is.
fn lock(pool: &Mutex<Pool>) -> std::sync::MutexGuard<'_, Pool> {
    pool.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Slots per chunk: a value array's chunk is 64 KiB (larger chunks hold the memory map
/// longer while their pages are made present: 2 MiB ones made the level sets slower).
const CHUNK_SLOTS: usize = 32;

/// Bytes of address space reserved at a time: a few reservations hold a 1024^3 band.
const RESERVATION: usize = 64 << 20;

/// Slots of one size: those dropped, to reuse, and the untouched rest of the newest chunk.
pub struct Pool {
    slot: usize,
    /// The reservations chunks are cut from, in order: each one's start and length.
    reservations: Vec<(NonNull<u8>, usize)>,
    /// Where the next chunk is cut from the newest reservation, and that reservation's end.
    uncut: usize,
    uncut_end: usize,
    /// Chunks cut and not yet added (their pages being made present outside the lock): the
    /// reservations stay while there are any.
    cutting: usize,
    dropped: Vec<NonNull<u8>>,
    /// The newest chunk's first slot never handed out, and its end.
    fresh: usize,
    fresh_end: usize,
    in_use: usize,
}

// SAFETY: the pool hands out raw slots under its lock; the pointers are not dereferenced here.
unsafe impl Send for Pool {}

impl Pool {
    const fn new(slot: usize) -> Self {
        Pool {
            slot,
            reservations: Vec::new(),
            uncut: 0,
            uncut_end: 0,
            cutting: 0,
            dropped: Vec::new(),
            fresh: 0,
            fresh_end: 0,
            in_use: 0,
        }
    }

    /// An unused slot; none when every chunk is in use.
    fn take(&mut self) -> Option<NonNull<u8>> {
        let slot = match self.dropped.pop() {
            Some(slot) => slot,
            None if self.fresh + self.slot <= self.fresh_end => {
                let slot = self.fresh;
                self.fresh += self.slot;
                // SAFETY: a place inside a chunk, not null.
                unsafe { NonNull::new_unchecked(slot as *mut u8) }
            }
            None => return None,
        };
        self.in_use += 1;
        Some(slot)
    }

    /// A new chunk, cut from the newest reservation or from a new one: its start and length.
    fn cut_chunk(&mut self) -> (NonNull<u8>, usize) {
        let len = self.slot * CHUNK_SLOTS;
        if self.uncut + len > self.uncut_end {
            // The pool cannot reuse what the job freed to the heap: that goes back to the
            // kernel before the pool takes more.
            #[cfg(all(target_os = "linux", target_env = "gnu"))]
            // SAFETY: glibc's own call; it frees only memory no allocation holds.
            unsafe {
                libc::malloc_trim(0);
            }
            let size = RESERVATION.max(len);
            let start = reserve(size);
            self.reservations.push((start, size));
            self.uncut = start.as_ptr() as usize;
            self.uncut_end = self.uncut + size;
        }
        // SAFETY: a place inside a reservation, not null.
        let chunk = unsafe { NonNull::new_unchecked(self.uncut as *mut u8) };
        self.uncut += len;
        self.cutting += 1;
        (chunk, len)
    }

    /// Takes a new chunk into use. Another thread may have added one meanwhile: what is left
    /// of that one is kept with the dropped slots.
    fn add_chunk(&mut self, chunk: NonNull<u8>, len: usize) {
        self.cutting -= 1;
        while self.fresh + self.slot <= self.fresh_end {
            // SAFETY: a place inside a chunk, not null.
            self.dropped
                .push(unsafe { NonNull::new_unchecked(self.fresh as *mut u8) });
            self.fresh += self.slot;
        }
        self.fresh = chunk.as_ptr() as usize;
        self.fresh_end = self.fresh + len;
    }

    fn give(&mut self, slot: NonNull<u8>) {
        self.in_use -= 1;
        self.dropped.push(slot);
        // Once none is in use, the first chunk stays, so that making and dropping one array
        // at a time does not map and unmap memory each time. Every slot of it has been handed
        // out (a later chunk is cut only then), so all are among those dropped.
        if self.in_use > 0 || self.cutting > 0 {
            return;
        }
        let Some(&(first, size)) = self.reservations.first() else {
            return;
        };
        let first = first.as_ptr() as usize;
        let kept = first..first + self.slot * CHUNK_SLOTS;
        // More than the first chunk was cut: a later reservation, or the first past its first.
        if self.reservations.len() > 1 || self.uncut > kept.end {
            for (start, size) in self.reservations.drain(1..) {
                // SAFETY: a reservation of this pool, none of it in use.
                unsafe { libc::munmap(start.as_ptr().cast(), size) };
            }
            // SAFETY: the first reservation past its first chunk, none of it in use: its pages
            // go back to the kernel and read as zeros when used again.
            unsafe {
                libc::madvise(
                    kept.end as *mut libc::c_void,
                    first + size - kept.end,
                    libc::MADV_DONTNEED,
                );
            }
            self.dropped
                .retain(|s| kept.contains(&(s.as_ptr() as usize)));
            self.dropped.shrink_to_fit();
            (self.uncut, self.uncut_end) = (kept.end, first + size);
            (self.fresh, self.fresh_end) = (0, 0);
        }
    }
}

/// Hands the memory of every pool back to the kernel on the current rayon pool's threads, for
/// a process about to end: the kernel frees a dying process's memory on one thread (a 1024^3
/// level set's band, 160 MB, took about 20 ms after the exit at 2 threads).
///
/// # Safety
/// No array of any pool may be used afterwards: the process ends with them leaked.
pub unsafe fn release_before_exit() {
    use rayon::prelude::*;
    // Pieces small enough to share among the threads: a few reservations hold a large band.
    const PIECE: usize = 8 << 20;
    let pieces: Vec<(usize, usize)> = [
        <[f32; super::LEAF_VOXELS]>::pool(),
        <[[f32; 3]; super::LEAF_VOXELS]>::pool(),
    ]
    .iter()
    .flat_map(|pool| lock(pool).reservations.clone())
    .flat_map(|(start, size)| {
        let start = start.as_ptr() as usize;
        (0..size.div_ceil(PIECE)).map(move |k| (start + k * PIECE, PIECE.min(size - k * PIECE)))
    })
    .collect();
    pieces.par_iter().with_max_len(1).for_each(|&(start, len)| {
        // SAFETY: a range of a pool's reservation, whose arrays the caller will not use again;
        // its pages read as zeros if touched.
        unsafe { libc::madvise(start as *mut libc::c_void, len, libc::MADV_DONTNEED) };
    });
}

/// `size` bytes of fresh address space, readable and writable, its pages made only when used.
fn reserve(size: usize) -> NonNull<u8> {
    crate::mapped_bytes::map_anonymous(size, libc::MAP_NORESERVE).unwrap_or_else(|_| {
        std::alloc::handle_alloc_error(
            std::alloc::Layout::from_size_align(size, 4096).expect("a reservation's layout"),
        )
    })
}

/// Makes a chunk's pages present in one call where the kernel can (Linux 5.14 on); elsewhere
/// they fault in as they are written.
fn make_present(chunk: NonNull<u8>, len: usize) {
    #[cfg(target_os = "linux")]
    // SAFETY: the range is a chunk of a reservation, page aligned; populating keeps its
    // contents.
    unsafe {
        libc::madvise(chunk.as_ptr().cast(), len, libc::MADV_POPULATE_WRITE);
    }
    #[cfg(not(target_os = "linux"))]
    let _ = (chunk, len);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::LEAF_VOXELS;

    #[test]
    fn arrays_are_zeroed_owned_and_reused() {
        let mut held: Vec<ChannelBox<[f32; LEAF_VOXELS]>> = Vec::new();
        // Enough for several chunks.
        for i in 0..CHUNK_SLOTS * 5 + 7 {
            let mut a = ChannelBox::<[f32; LEAF_VOXELS]>::zeroed();
            assert!(a.iter().all(|&v| v == 0.0), "array {i} made zeroed");
            a.fill(i as f32);
            held.push(a);
        }
        let copy = held[7].clone();
        // Dropped arrays' slots are reused, zeroed again.
        held.truncate(10);
        for _ in 0..CHUNK_SLOTS * 3 {
            let a = ChannelBox::<[f32; LEAF_VOXELS]>::zeroed();
            assert!(a.iter().all(|&v| v == 0.0), "a reused slot made zeroed");
            held.push(a);
        }
        for (i, a) in held.iter().take(10).enumerate() {
            assert!(
                a.iter().all(|&v| v == i as f32),
                "array {i} kept its values"
            );
        }
        assert!(copy.iter().all(|&v| v == 7.0));
        let mut normals = ChannelBox::<[[f32; 3]; LEAF_VOXELS]>::zeroed();
        normals[511] = [1.0, 2.0, 3.0];
        assert_eq!(normals.clone()[511], [1.0, 2.0, 3.0]);
    }

    /// Threads making and dropping arrays at once, each round's arrays all dropped before the
    /// next (so the pool empties, gives memory back and cuts chunks again while other threads
    /// are cutting theirs): every array keeps its own values until it is dropped.
    #[test]
    fn arrays_stay_their_own_across_threads() {
        std::thread::scope(|scope| {
            for t in 0..4u32 {
                scope.spawn(move || {
                    for round in 0..50u32 {
                        let value = |i: usize| (t * 1_000_000 + round * 1000 + i as u32) as f32;
                        let held: Vec<ChannelBox<[f32; LEAF_VOXELS]>> = (0..CHUNK_SLOTS * 3
                            + t as usize)
                            .map(|i| {
                                let mut a = ChannelBox::<[f32; LEAF_VOXELS]>::zeroed();
                                a.fill(value(i));
                                a
                            })
                            .collect();
                        for (i, a) in held.iter().enumerate() {
                            assert!(
                                a.iter().all(|&v| v == value(i)),
                                "thread {t}, round {round}: array {i} changed"
                            );
                        }
                    }
                });
            }
        });
    }
}

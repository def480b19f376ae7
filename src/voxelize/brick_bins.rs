//! Surface voxelization in 128^3 bricks. Primitives are binned by the bricks their candidate
//! boxes overlap; each brick is then voxelized on its own thread, clipped to the brick, into
//! dense bit sets (one per class of primitive) and, with channels, dense nearest distances and
//! normals, from which its leaves are cut. Bricks never
//! share a leaf, so there are no thread-local grids to merge and no hashing per voxel: the
//! grid-per-thread fold it replaces spent most of its time looking up and merging leaves.

use crate::error::{Error, Result};
use crate::grid::{
    ChannelBox, Channels, Coord, CoordBox, LEAF_VOXELS, Leaf, SparseGrid, Transform,
};
use crate::parallel_concat::concat;
use crate::progress::Progress;
use glam::DVec3;
use rayon::prelude::*;
use rustc_hash::FxHashMap;

/// Brick edge in voxels (a power of two, a multiple of the leaf's 8).
const BRICK_LOG2: u32 = 7;
const BRICK: i64 = 1 << BRICK_LOG2;
const _: () = assert!(BRICK <= 128, "a brick's column fits a u128 (`add_z_run`)");
/// Leaves per brick edge, and per brick.
const EDGE_LEAVES: usize = (BRICK / 8) as usize;
const BRICK_LEAVES: usize = EDGE_LEAVES * EDGE_LEAVES * EDGE_LEAVES;
/// Bin entries pack a primitive's class in the top bits of its number.
const CLASS_SHIFT: u32 = 30;

/// One brick's voxels as dense bit sets, one per class, in leaf order: leaf `l` holds words
/// `8l..8l+8`, laid out as a leaf's mask. With channels, the nearest primitive's distance
/// (and normal) per voxel, voxel `n` of leaf `l` at `512 slot_of[l] + n`.
pub(crate) struct BrickBits<const CLASSES: usize> {
    classes: [Box<[u64]>; CLASSES],
    /// The leaves any class touched.
    touched: [u64; BRICK_LEAVES / 64],
    /// Each leaf's place in the channels, `NO_SLOT` until it is first touched. A brick's
    /// leaves take the places in the order they are first touched, so that every brick
    /// reuses the same front of the channels, which stays in cache: addressed by leaf, a
    /// brick's few hundred leaves lie anywhere in 8 MiB, and a voxel's first touch missed the
    /// cache (the band's most-sampled load).
    slot_of: Box<[u16]>,
    /// Places taken. A place's distances are made infinite when it is taken, so the channels
    /// start untouched and a thread's scratch is as large in memory as its busiest brick
    /// needs, not 8 MiB.
    slots: u16,
    distance: Option<Box<[f32]>>,
    normal: Option<Box<[[f32; 3]]>>,
}

/// A leaf without a place in the channels.
const NO_SLOT: u16 = u16::MAX;
const _: () = assert!(
    BRICK_LEAVES < NO_SLOT as usize,
    "a slot per leaf fits a u16"
);

impl<const CLASSES: usize> BrickBits<CLASSES> {
    fn new(channels: Channels) -> Self {
        debug_assert!(
            channels.value || !channels.normal,
            "normals go with distances"
        );
        let voxels = BRICK_LEAVES * LEAF_VOXELS;
        BrickBits {
            classes: std::array::from_fn(|_| vec![0u64; BRICK_LEAVES * 8].into_boxed_slice()),
            touched: [0; BRICK_LEAVES / 64],
            slot_of: vec![NO_SLOT; BRICK_LEAVES].into_boxed_slice(),
            slots: 0,
            distance: channels.value.then(|| vec![0.0; voxels].into_boxed_slice()),
            normal: channels
                .normal
                .then(|| vec![[0.0; 3]; voxels].into_boxed_slice()),
        }
    }

    /// The touched leaves, ascending.
    fn touched_leaves(&self) -> impl Iterator<Item = usize> + '_ {
        crate::grid::bits::ones(&self.touched)
    }

    /// Sets voxel `i`'s bit in `class` (`BrickSink::index`) and, when the brick keeps
    /// distances and `distance()` is the nearest yet, keeps it and `normal`.
    #[inline]
    fn put(&mut self, class: usize, i: usize, distance: impl FnOnce() -> f64, normal: DVec3) {
        self.classes[class][i >> 6] |= 1 << (i & 63);
        self.touched[i >> 15] |= 1 << ((i >> 9) & 63);
        if let Some(d) = self.distance.as_deref_mut() {
            let i = place(&mut self.slot_of, &mut self.slots, d, i);
            let near = distance() as f32;
            match self.normal.as_deref_mut() {
                // Without normals the least distance is a select, not a branch on each voxel's
                // value (which primitive is nearer is not predictable); no distance is NaN, so
                // it is one `minss`, where `f32::min` also handles NaN.
                None => {
                    let kept = d[i];
                    d[i] = if near < kept { near } else { kept };
                }
                Some(normals) => {
                    if near < d[i] {
                        d[i] = near;
                        normals[i] = normal.as_vec3().into();
                    }
                }
            }
        }
    }
}

/// Voxel `i`'s place in the channels (`slot_of` and the `slots` taken, `BrickBits`), its leaf
/// given the next place, its `distance`s made infinite, if it has none.
#[inline]
fn place(slot_of: &mut [u16], slots: &mut u16, distance: &mut [f32], i: usize) -> usize {
    let slot = &mut slot_of[i / LEAF_VOXELS];
    if *slot == NO_SLOT {
        *slot = *slots;
        *slots += 1;
        let first = usize::from(*slot) * LEAF_VOXELS;
        distance[first..first + LEAF_VOXELS].fill(f32::INFINITY);
    }
    usize::from(*slot) * LEAF_VOXELS + i % LEAF_VOXELS
}

/// Where a primitive's voxels go: its class's bits in a brick, and with channels the nearest
/// primitive's distance and normal per voxel.
pub(crate) struct BrickSink<'b, const CLASSES: usize> {
    bits: &'b mut BrickBits<CLASSES>,
    class: usize,
    origin: Coord,
}

impl<const CLASSES: usize> BrickSink<'_, CLASSES> {
    /// Marks voxel `c` (inside the brick), `distance()` voxels from the primitive whose
    /// normal is `normal` (computed only when the brick keeps distances).
    #[inline]
    pub fn add(&mut self, c: Coord, distance: impl FnOnce() -> f64, normal: DVec3) {
        let i = self.index(c);
        self.bits.put(self.class, i, distance, normal);
    }

    /// Marks the voxels of `column` (a voxel's place with coordinate `axis` taken from `ks`;
    /// all inside the brick) that `kept(k)` accepts, voxel `k` `distance(kept(k))` voxels from
    /// the primitive whose normal is `normal`, as `add` would one by one. A voxel's place in the
    /// brick's channels is its bit's place in its class (`index`), and along an axis both step
    /// by one stride inside a leaf and by a leaf's stride less 7 from leaf to leaf: found once
    /// per column, not per voxel.
    #[inline]
    pub fn add_column<T>(
        &mut self,
        column: Coord,
        axis: usize,
        ks: std::ops::RangeInclusive<i64>,
        kept: impl Fn(i64) -> Option<T>,
        distance: impl Fn(T) -> f64,
        normal: DVec3,
    ) {
        let (first, last) = (*ks.start(), *ks.end());
        if first > last {
            return;
        }
        let mut c = column;
        c[axis] = first;
        let mut i = self.index(c);
        let step = [64, 8, 1][axis];
        let leaf_step = [EDGE_LEAVES * EDGE_LEAVES, EDGE_LEAVES, 1][axis] * LEAF_VOXELS - 7 * step;
        let mut in_leaf = (first - self.origin[axis]) & 7;
        for k in first..=last {
            if let Some(at) = kept(k) {
                self.bits.put(self.class, i, || distance(at), normal);
            }
            in_leaf += 1;
            i += if in_leaf == 8 {
                in_leaf = 0;
                leaf_step
            } else {
                step
            };
        }
    }

    /// Whether the brick keeps only voxel bits: then `add_z_run` may mark them.
    pub fn bits_only(&self) -> bool {
        self.bits.distance.is_none() && self.bits.normal.is_none()
    }

    /// Marks voxels `(x, y, z + i)` for the set bits `i` of `run` (all inside the brick; a
    /// brick is at most 128 voxels long, so a `u128` holds a column). Only for a brick that
    /// keeps voxel bits alone. Along z a leaf's voxels are consecutive bits of one word: a run
    /// costs a word per leaf it crosses, not a mark per voxel.
    #[inline]
    pub fn add_z_run(&mut self, x: i64, y: i64, z: i64, run: u64) {
        debug_assert!(self.bits_only());
        let (lx, ly, lz) = (x - self.origin[0], y - self.origin[1], z - self.origin[2]);
        debug_assert!(
            [lx, ly, lz].iter().all(|&v| (0..BRICK).contains(&v))
                && (run == 0 || lz + (64 - run.leading_zeros() as i64) <= BRICK),
            "clipped to the brick"
        );
        let column = u128::from(run) << lz;
        let row = ((lx >> 3) as usize * EDGE_LEAVES + (ly >> 3) as usize) * EDGE_LEAVES;
        let shift = (ly & 7) << 3;
        let mut groups = column;
        while groups != 0 {
            let g = groups.trailing_zeros() as usize / 8;
            let byte = ((column >> (8 * g)) & 0xff) as u64;
            groups &= !(0xff << (8 * g));
            let leaf = row + g;
            self.bits.classes[self.class][leaf * 8 + (lx & 7) as usize] |= byte << shift;
            self.bits.touched[leaf / 64] |= 1 << (leaf % 64);
        }
    }

    /// Voxel `c`'s index in the brick's channels: `512 leaf + 64 x + 8 y + z` in leaf and
    /// voxel coordinates, so that its bit is bit `i % 64` of its class's word `i / 64` and its
    /// leaf `i / 512`.
    #[inline]
    fn index(&self, c: Coord) -> usize {
        let l = [
            c[0] - self.origin[0],
            c[1] - self.origin[1],
            c[2] - self.origin[2],
        ];
        debug_assert!(
            l.iter().all(|&v| (0..BRICK).contains(&v)),
            "clipped to the brick"
        );
        let leaf = (((l[0] >> 3) as usize * EDGE_LEAVES) + (l[1] >> 3) as usize) * EDGE_LEAVES
            + (l[2] >> 3) as usize;
        leaf * LEAF_VOXELS + (l[0] & 7) as usize * 64 + (((l[1] & 7) << 3) | (l[2] & 7)) as usize
    }
}

/// Bytes of the dense scratch each worker thread keeps for its bricks (`BrickBits`) with
/// `channels` and `classes` classes of primitive: memory a job's plan counts per thread. The
/// channels' places are in memory only once taken, one per leaf a brick touches: half a
/// brick's leaves are counted (the busiest brick of the level sets, surfaces with normals and
/// unsigned bands measured on bunny-closed, igea, skull and armadillo touched at most a third:
/// skull's level set at 1024, 1,413 of 4,096).
pub(crate) fn scratch_bytes(channels: Channels, classes: usize) -> u64 {
    let voxels = (BRICK_LEAVES * LEAF_VOXELS) as u64;
    let place_voxels = voxels / 2;
    let per_voxel = 4 * u64::from(channels.value) + 12 * u64::from(channels.normal);
    let slot_table = (BRICK_LEAVES * std::mem::size_of::<u16>()) as u64;
    voxels / 8 * classes as u64 + place_voxels * per_voxel + slot_table
}

/// The bricks a box of voxels overlaps.
fn brick_range(b: &CoordBox) -> [std::ops::RangeInclusive<i64>; 3] {
    std::array::from_fn(|a| (b.min[a] >> BRICK_LOG2)..=(b.max[a] >> BRICK_LOG2))
}

/// Voxelizes `counts[k]` primitives of each class `k` in bricks. `candidates(k, i)` bounds
/// the voxels primitive `i` of class `k` can mark; `emit(k, i, clip, sink)` marks those in
/// `clip`. Returns the grid and, per class, its voxels in no earlier class.
pub(crate) fn voxelize_in_bricks<const CLASSES: usize>(
    counts: [usize; CLASSES],
    transform: Transform,
    channels: Channels,
    progress: &Progress,
    candidates: impl Fn(usize, usize) -> CoordBox + Sync,
    emit: impl Fn(usize, usize, &CoordBox, &mut BrickSink<CLASSES>) + Sync,
) -> Result<(SparseGrid, [u64; CLASSES])> {
    if counts.iter().any(|&n| n >= 1 << CLASS_SHIFT) {
        return Err(Error::InvalidArgument(format!(
            "a mesh of more than {} primitives of one kind",
            1u64 << CLASS_SHIFT
        )));
    }
    let bins = bin_primitives(counts, &candidates);
    let scratch: Vec<std::sync::Mutex<BrickBits<CLASSES>>> = (0..rayon::current_num_threads())
        .map(|_| std::sync::Mutex::new(BrickBits::new(channels)))
        .collect();
    // The busiest bricks first, so that the last bricks a thread takes are short ones and no
    // thread waits long for another's at the end; the leaves are joined in the bins' order.
    let mut busiest_first: Vec<usize> = (0..bins.len()).collect();
    busiest_first.sort_by_key(|&b| std::cmp::Reverse(bins[b].entries.len()));
    let work: Vec<(Vec<Leaf>, [u64; CLASSES])> = busiest_first
        .par_iter()
        // One brick per task: bricks differ in cost by orders of magnitude, and rayon's
        // default halving leaves a thread idle while the other works through a long run.
        .with_max_len(1)
        .map(|&b| {
            let bin = &bins[b];
            // Each worker keeps its own scratch (rayon may split the work into many more
            // tasks than workers, and a brick's scratch is 8 MiB with distances).
            let mut scratch = scratch[rayon::current_thread_index().unwrap_or(0)]
                .lock()
                .unwrap_or_else(|poisoned| poisoned.into_inner());
            let bits = &mut *scratch;
            if progress.stopped() {
                return (Vec::new(), [0; CLASSES]);
            }
            let origin = bin.brick.map(|v| v << BRICK_LOG2);
            let clip = CoordBox {
                min: origin,
                max: origin.map(|v| v + BRICK - 1),
            };
            for &entry in &bin.entries {
                let (class, i) = (
                    (entry >> CLASS_SHIFT) as usize,
                    (entry & ((1 << CLASS_SHIFT) - 1)) as usize,
                );
                let mut sink = BrickSink {
                    bits,
                    class,
                    origin,
                };
                emit(class, i, &clip, &mut sink);
            }
            progress.advance(bin.first_of);
            let leaves = cut_leaves(bits, origin, channels);
            let counts = class_counts(bits);
            clear(bits);
            (leaves, counts)
        })
        .collect();
    progress.check()?;
    let mut totals = [0u64; CLASSES];
    let mut in_bin_order: Vec<Vec<Leaf>> = (0..bins.len()).map(|_| Vec::new()).collect();
    for (&b, (brick_leaves, counts)) in busiest_first.iter().zip(work) {
        in_bin_order[b] = brick_leaves;
        (0..CLASSES).for_each(|k| totals[k] += counts[k]);
    }
    Ok((
        SparseGrid::from_distinct_leaves(transform, channels, concat(in_bin_order)),
        totals,
    ))
}

/// A brick in use and its primitives.
struct Bin {
    /// Brick coordinate (origin / 128).
    brick: Coord,
    /// The primitives overlapping it, packed with their class.
    entries: Vec<u32>,
    /// How many of them it is the first brick of (progress counts each primitive once).
    first_of: u64,
}

/// The bricks in use, each with its primitives in class and number order, bricks in the
/// order of their first primitive. Binned in parallel runs of primitives, then joined.
fn bin_primitives<const CLASSES: usize>(
    counts: [usize; CLASSES],
    candidates: &(impl Fn(usize, usize) -> CoordBox + Sync),
) -> Vec<Bin> {
    let total: usize = counts.iter().sum();
    let run = total
        .div_ceil(4 * rayon::current_num_threads())
        .max(1 << 14);
    let runs: Vec<Vec<Bin>> = (0..total.div_ceil(run))
        .into_par_iter()
        .map(|r| bin_run(counts, candidates, r * run..((r + 1) * run).min(total)))
        .collect();
    let mut index: FxHashMap<Coord, usize> = FxHashMap::default();
    let mut bins: Vec<Bin> = Vec::new();
    for bin in runs.into_iter().flatten() {
        match index.entry(bin.brick) {
            std::collections::hash_map::Entry::Occupied(at) => {
                let joined = &mut bins[*at.get()];
                joined.entries.extend_from_slice(&bin.entries);
                joined.first_of += bin.first_of;
            }
            std::collections::hash_map::Entry::Vacant(at) => {
                at.insert(bins.len());
                bins.push(bin);
            }
        }
    }
    bins
}

/// The bins of primitives `items`, numbered across the classes in order.
fn bin_run<const CLASSES: usize>(
    counts: [usize; CLASSES],
    candidates: &(impl Fn(usize, usize) -> CoordBox + Sync),
    items: std::ops::Range<usize>,
) -> Vec<Bin> {
    let mut index: FxHashMap<Coord, u32> = FxHashMap::default();
    let mut bins: Vec<Bin> = Vec::new();
    let mut last = ([i64::MIN; 3], 0usize);
    let mut class_start = 0;
    for (class, &count) in counts.iter().enumerate() {
        let numbers = items.start.max(class_start)..items.end.min(class_start + count);
        for i in numbers.start - class_start..numbers.end.max(numbers.start) - class_start {
            let entry = ((class as u32) << CLASS_SHIFT) | i as u32;
            let [xs, ys, zs] = brick_range(&candidates(class, i));
            let mut first = true;
            for x in xs {
                for y in ys.clone() {
                    for z in zs.clone() {
                        let b = [x, y, z];
                        // Consecutive primitives mostly share a brick: skip the lookup.
                        if b != last.0 {
                            let n = *index.entry(b).or_insert_with(|| {
                                bins.push(Bin {
                                    brick: b,
                                    entries: Vec::new(),
                                    first_of: 0,
                                });
                                (bins.len() - 1) as u32
                            });
                            last = (b, n as usize);
                        }
                        let bin = &mut bins[last.1];
                        bin.entries.push(entry);
                        bin.first_of += u64::from(std::mem::take(&mut first));
                    }
                }
            }
        }
        class_start += count;
    }
    bins
}

/// The brick's leaves: the union of its classes' bits, with the channels kept.
fn cut_leaves<const CLASSES: usize>(
    bits: &BrickBits<CLASSES>,
    origin: Coord,
    channels: Channels,
) -> Vec<Leaf> {
    bits.touched_leaves()
        .filter_map(|l| {
            let mut mask = [0u64; 8];
            for class in &bits.classes {
                (0..8).for_each(|w| mask[w] |= class[8 * l + w]);
            }
            if mask == [0; 8] {
                return None;
            }
            let at = [
                l / (EDGE_LEAVES * EDGE_LEAVES),
                l / EDGE_LEAVES % EDGE_LEAVES,
                l % EDGE_LEAVES,
            ];
            let mut leaf = Leaf::new(
                std::array::from_fn(|a| origin[a] + 8 * at[a] as i64),
                Channels {
                    value: false,
                    ..channels
                },
            );
            leaf.mask = mask;
            let first = usize::from(bits.slot_of[l]) * LEAF_VOXELS;
            // A voxel holds a finite distance exactly where a class marked it (`put`): the
            // values are read whole, inactive ones 0, with no pass over the mask's bits.
            leaf.value = bits.distance.as_deref().map(|d| {
                let d = &d[first..first + LEAF_VOXELS];
                ChannelBox::from_fn(|n| if d[n] < f32::INFINITY { d[n] } else { 0.0 })
            });
            if let (Some(d), Some(v)) = (bits.normal.as_deref(), leaf.normal.as_deref_mut()) {
                crate::grid::bits::ones(&mask).for_each(|n| v[n] = d[first + n]);
            }
            Some(leaf)
        })
        .collect()
}

/// Per class, its voxels in no earlier class.
fn class_counts<const CLASSES: usize>(bits: &BrickBits<CLASSES>) -> [u64; CLASSES] {
    let mut counts = [0u64; CLASSES];
    for l in bits.touched_leaves() {
        for w in 8 * l..8 * l + 8 {
            let mut earlier = 0u64;
            for (k, class) in bits.classes.iter().enumerate() {
                counts[k] += (class[w] & !earlier).count_ones() as u64;
                earlier |= class[w];
            }
        }
    }
    counts
}

/// Clears the touched leaves for the next brick.
fn clear<const CLASSES: usize>(bits: &mut BrickBits<CLASSES>) {
    let touched: Vec<usize> = bits.touched_leaves().collect();
    for class in &mut bits.classes {
        for &l in &touched {
            class[8 * l..8 * l + 8].fill(0);
        }
    }
    if bits.distance.is_some() {
        for &l in &touched {
            bits.slot_of[l] = NO_SLOT;
        }
    }
    bits.slots = 0;
    bits.touched = [0; BRICK_LEAVES / 64];
}

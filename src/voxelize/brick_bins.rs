//! Surface voxelization in 64^3 bricks. Primitives are binned by the bricks their candidate
//! boxes overlap; each brick is then voxelized on its own thread, clipped to the brick, into
//! dense bit sets (one per class of primitive) from which its leaves are cut. Bricks never
//! share a leaf, so there are no thread-local grids to merge and no hashing per voxel: the
//! grid-per-thread fold it replaces spent most of its time looking up and merging leaves.

use super::sink::Sink;
use crate::error::{Error, Result};
use crate::grid::{Channels, Coord, CoordBox, Leaf, SparseGrid, Transform};
use crate::progress::Progress;
use glam::DVec3;
use rayon::prelude::*;
use rustc_hash::FxHashMap;

/// Brick edge in voxels (a power of two, a multiple of the leaf's 8).
const BRICK_LOG2: u32 = 6;
const BRICK: i64 = 1 << BRICK_LOG2;
/// Leaves per brick edge, and per brick.
const EDGE_LEAVES: usize = (BRICK / 8) as usize;
const BRICK_LEAVES: usize = EDGE_LEAVES * EDGE_LEAVES * EDGE_LEAVES;
/// Bin entries pack a primitive's class in the top bits of its number.
const CLASS_SHIFT: u32 = 30;

/// One brick's voxels as dense bit sets, one per class, in leaf order: leaf `l` holds words
/// `8l..8l+8`, laid out as a leaf's mask.
pub(crate) struct BrickBits<const CLASSES: usize> {
    classes: [Box<[u64]>; CLASSES],
    /// The leaves any class touched.
    touched: [u64; BRICK_LEAVES / 64],
}

impl<const CLASSES: usize> BrickBits<CLASSES> {
    fn new() -> Self {
        BrickBits {
            classes: std::array::from_fn(|_| vec![0u64; BRICK_LEAVES * 8].into_boxed_slice()),
            touched: [0; BRICK_LEAVES / 64],
        }
    }

    /// The touched leaves, ascending.
    fn touched_leaves(&self) -> impl Iterator<Item = usize> + '_ {
        crate::grid::bits::ones(&self.touched)
    }
}

/// Where a primitive's voxels go: its class's bits in a brick, and with channels the nearest
/// primitive's distance and normal per voxel, in a grid of the brick's own.
pub(crate) struct BrickSink<'b, 'g, const CLASSES: usize> {
    bits: &'b mut BrickBits<CLASSES>,
    class: usize,
    origin: Coord,
    nearest: Option<&'b mut Sink<'g>>,
}

impl<const CLASSES: usize> BrickSink<'_, '_, CLASSES> {
    /// Marks voxel `c` (inside the brick), `distance` voxels from the primitive whose normal
    /// is `normal`.
    #[inline]
    pub fn add(&mut self, c: Coord, distance: f64, normal: DVec3) {
        self.mark(c);
        if let Some(sink) = self.nearest.as_deref_mut() {
            sink.add(c, distance, normal);
        }
    }

    #[inline]
    fn mark(&mut self, c: Coord) {
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
        let word = leaf * 8 + (l[0] & 7) as usize;
        self.bits.classes[self.class][word] |= 1 << (((l[1] & 7) << 3) | (l[2] & 7));
        self.bits.touched[leaf / 64] |= 1 << (leaf % 64);
    }

    /// Marks voxel `c` (inside the brick), keeping the smallest distance given for it.
    #[inline]
    pub fn add_distance(&mut self, c: Coord, distance: f64) {
        self.mark(c);
        if let Some(sink) = self.nearest.as_deref_mut() {
            sink.add_distance(c, distance);
        }
    }
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
    let (bricks, bins) = bin_primitives(counts, &candidates);
    let work: Vec<(Vec<Leaf>, [u64; CLASSES])> = bins
        .par_iter()
        .zip(&bricks)
        .map_init(BrickBits::<CLASSES>::new, |bits, (entries, &brick)| {
            if progress.stopped() {
                return (Vec::new(), [0; CLASSES]);
            }
            let origin = brick.map(|v| v << BRICK_LOG2);
            let clip = CoordBox {
                min: origin,
                max: origin.map(|v| v + BRICK - 1),
            };
            let mut local = channels.value.then(|| SparseGrid::new(transform, channels));
            let mut nearest = local.as_mut().map(Sink::new);
            let mut firsts = 0;
            for &entry in entries {
                let (class, i) = (
                    (entry >> CLASS_SHIFT) as usize,
                    (entry & ((1 << CLASS_SHIFT) - 1)) as usize,
                );
                let mut sink = BrickSink {
                    bits,
                    class,
                    origin,
                    nearest: nearest.as_mut(),
                };
                emit(class, i, &clip, &mut sink);
                // Each primitive counts once, in the first brick it overlaps.
                let first = brick_range(&candidates(class, i)).map(|r| *r.start());
                firsts += u64::from(first == brick);
            }
            progress.advance(firsts);
            drop(nearest);
            let leaves = cut_leaves(bits, origin, local);
            let counts = class_counts(bits);
            clear(bits);
            (leaves, counts)
        })
        .collect();
    progress.check()?;
    let mut totals = [0u64; CLASSES];
    let mut leaves = Vec::with_capacity(work.iter().map(|w| w.0.len()).sum());
    for (brick_leaves, counts) in work {
        leaves.extend(brick_leaves);
        (0..CLASSES).for_each(|k| totals[k] += counts[k]);
    }
    Ok((
        SparseGrid::from_distinct_leaves(transform, channels, leaves),
        totals,
    ))
}

/// Bricks in use (by brick coordinate) and the primitives of each, packed with their class.
fn bin_primitives<const CLASSES: usize>(
    counts: [usize; CLASSES],
    candidates: &(impl Fn(usize, usize) -> CoordBox + Sync),
) -> (Vec<Coord>, Vec<Vec<u32>>) {
    let mut index: FxHashMap<Coord, u32> = FxHashMap::default();
    let mut bricks: Vec<Coord> = Vec::new();
    let mut bins: Vec<Vec<u32>> = Vec::new();
    let mut last = ([i64::MIN; 3], 0usize);
    for (class, &count) in counts.iter().enumerate() {
        for i in 0..count {
            let entry = ((class as u32) << CLASS_SHIFT) | i as u32;
            let [xs, ys, zs] = brick_range(&candidates(class, i));
            for x in xs {
                for y in ys.clone() {
                    for z in zs.clone() {
                        let b = [x, y, z];
                        // Consecutive primitives mostly share a brick: skip the lookup.
                        if b != last.0 {
                            let n = *index.entry(b).or_insert_with(|| {
                                bricks.push(b);
                                bins.push(Vec::new());
                                (bricks.len() - 1) as u32
                            });
                            last = (b, n as usize);
                        }
                        bins[last.1].push(entry);
                    }
                }
            }
        }
    }
    (bricks, bins)
}

/// The brick's leaves: from its grid when it keeps channels, else from the union of its bits.
fn cut_leaves<const CLASSES: usize>(
    bits: &BrickBits<CLASSES>,
    origin: Coord,
    local: Option<SparseGrid>,
) -> Vec<Leaf> {
    if let Some(grid) = local {
        return grid.into_leaves();
    }
    bits.touched_leaves()
        .filter_map(|l| {
            let mut mask = [0u64; 8];
            for class in &bits.classes {
                (0..8).for_each(|w| mask[w] |= class[8 * l + w]);
            }
            let at = [
                l / (EDGE_LEAVES * EDGE_LEAVES),
                l / EDGE_LEAVES % EDGE_LEAVES,
                l % EDGE_LEAVES,
            ];
            let mut leaf = Leaf::new(
                std::array::from_fn(|a| origin[a] + 8 * at[a] as i64),
                Channels::NONE,
            );
            leaf.mask = mask;
            (!leaf.is_empty()).then_some(leaf)
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
    bits.touched = [0; BRICK_LEAVES / 64];
}

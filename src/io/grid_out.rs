//! A grid to write, as both writers see it (`.vdb` by `vdb_writer`, `.nvdb` by
//! `nvdb_writer`): what its voxels and tiles hold, and its leaves and tiles sorted into the
//! order of OpenVDB's standard 5-4-3 tree (root children of 4096^3, internal nodes of 128^3,
//! leaves of 8^3), which NanoVDB shares.

use super::vdb_format::{CHILD_LOG2, NODE_LOG2, ROOT_TILE};
use crate::error::{Error, Result};
use crate::grid::{LEAF_VOXELS, Leaf, SparseGrid};
use rayon::prelude::*;
use std::path::Path;

/// What a grid's voxels hold.
#[derive(Clone, Copy)]
pub(super) enum GridValues<'g> {
    /// A BoolGrid, true on every active voxel and tile.
    Bool,
    /// A FloatGrid holding this value on every active voxel and tile (a fog volume's 1).
    Constant(f32),
    /// A Vec3SGrid of every leaf's normals (tiles carry none).
    Normals,
    /// A Vec3SGrid of every leaf's colours.
    Colors,
    /// A FloatGrid of every leaf's values with `background` elsewhere (an unsigned band).
    Distances { background: f32 },
    /// A level set: every leaf's signed values; its inactive voxels and tiles `-background`
    /// where `interior` holds them (its tiles are written, inactive), `background` elsewhere.
    LevelSet {
        background: f32,
        interior: &'g SparseGrid,
    },
    /// The fog volume of a level set (written from its interior): 1 on whole blocks and
    /// inside voxels off the band, `-d / background` on the band's inside voxels.
    Fog {
        band: &'g SparseGrid,
        background: f32,
    },
}

/// The type of a grid's values.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum ValueType {
    Bool,
    Float,
    Vec3,
}

impl GridValues<'_> {
    pub(super) fn value_type(self) -> ValueType {
        match self {
            GridValues::Bool => ValueType::Bool,
            GridValues::Normals | GridValues::Colors => ValueType::Vec3,
            _ => ValueType::Float,
        }
    }

    /// The value of voxels and slots outside the tree.
    pub(super) fn background(self) -> f32 {
        match self {
            GridValues::Distances { background } | GridValues::LevelSet { background, .. } => {
                background
            }
            _ => 0.0,
        }
    }

    /// Whether the grid's tiles are active (a level set's interior tiles are not).
    pub(super) fn active_tiles(self) -> bool {
        !matches!(self, GridValues::LevelSet { .. })
    }

    /// The value of a tile: an active tile's (true is 1), or a level set's interior one.
    pub(super) fn tile_value(self) -> f32 {
        match self {
            GridValues::Bool | GridValues::Fog { .. } => 1.0,
            GridValues::Constant(v) => v,
            GridValues::LevelSet { background, .. } => -background,
            _ => unreachable!("only voxel sets, fog volumes and level sets have tiles"),
        }
    }

    /// Hands `put` the active values of `leaf` in offset order, a vector's three components
    /// one after another; a bool grid's leaves store no values.
    #[inline(always)]
    pub(super) fn for_each_active(self, leaf: &Leaf, mut put: impl FnMut(f32)) {
        match self.value_type() {
            ValueType::Bool => unreachable!("bool leaves store a mask"),
            ValueType::Float => {
                let mut values = [0.0; LEAF_VOXELS];
                let count = self.active_floats(leaf, &mut values);
                values[..count].iter().for_each(|&v| put(v));
            }
            ValueType::Vec3 => self.active_vectors(leaf).flatten().for_each(put),
        }
    }

    /// The active vectors of a vector grid's `leaf`, in offset order.
    pub(super) fn active_vectors<'l>(self, leaf: &'l Leaf) -> impl Iterator<Item = [f32; 3]> + 'l {
        let vectors = match self {
            GridValues::Normals => leaf.normal.as_deref(),
            _ => leaf.color.as_deref(),
        };
        let vectors = vectors.expect("a vector grid's leaves carry its channel");
        leaf.offsets().map(move |n| vectors[n])
    }

    /// The active values of a float grid's `leaf` in offset order, at the start of `out`; how
    /// many.
    #[inline]
    pub(super) fn active_floats(self, leaf: &Leaf, out: &mut [f32; LEAF_VOXELS]) -> usize {
        let constant = |out: &mut [f32; LEAF_VOXELS], v: f32| {
            let count = leaf.count() as usize;
            out[..count].fill(v);
            count
        };
        match self {
            GridValues::Constant(v) => constant(out, v),
            GridValues::Distances { .. } | GridValues::LevelSet { .. } => {
                let d = leaf
                    .value
                    .as_deref()
                    .expect("a distance grid's leaves carry values");
                gather(&leaf.mask, out, d)
            }
            GridValues::Fog { band, background } => match band.leaf(leaf.origin) {
                None => constant(out, 1.0),
                Some(b) => {
                    let d = b.value.as_deref().expect("distances");
                    // The fog of a word's band voxels computed whole (the division in vector
                    // lanes), then 1 at its other active voxels.
                    let mut fog = [1.0; LEAF_VOXELS];
                    for (w, (&active, &on)) in leaf.mask.iter().zip(&b.mask).enumerate() {
                        if active & on == 0 {
                            continue;
                        }
                        let word = &mut fog[64 * w..64 * w + 64];
                        for (f, &d) in word.iter_mut().zip(&d[64 * w..]) {
                            *f = (-d / background).clamp(0.0, 1.0);
                        }
                        let mut off = active & !on;
                        while off != 0 {
                            word[off.trailing_zeros() as usize] = 1.0;
                            off &= off - 1;
                        }
                    }
                    gather(&leaf.mask, out, &fog)
                }
            },
            _ => unreachable!("not a float grid"),
        }
    }

    /// Looks up what writing `leaf` reads from other grids, so that it is in the cache when
    /// written (see `WARM_RUN`).
    #[inline]
    pub(super) fn warm(self, leaf: &Leaf) {
        std::hint::black_box(self.inside(leaf.origin));
        if let GridValues::Fog { band, .. } = self {
            std::hint::black_box(band.leaf(leaf.origin).map(|b| b.mask[0]));
        }
    }

    /// The inside voxels of a level set's leaf at `origin` (the others are outside).
    pub(super) fn inside(self, origin: [i64; 3]) -> [u64; 8] {
        match self {
            GridValues::LevelSet { interior, .. } => interior.block_mask(origin),
            _ => [0; 8],
        }
    }

    /// Every value of `leaf` as a reader sees it, one float (or three for vectors) per voxel
    /// in offset order into `out`: the active values, and at inactive voxels the background
    /// (minus it inside a level set). Not for bool grids, whose leaves hold their mask alone.
    pub(super) fn dense_values(self, leaf: &Leaf, out: &mut [f32]) {
        let components = match self.value_type() {
            ValueType::Vec3 => 3,
            _ => 1,
        };
        let background = self.background();
        let inside = self.inside(leaf.origin);
        for (n, voxel) in out.chunks_exact_mut(components).enumerate() {
            let v = if inside[n / 64] >> (n % 64) & 1 == 1 {
                -background
            } else {
                background
            };
            voxel.fill(v);
        }
        let mut offsets = leaf.offsets();
        let mut at = 0;
        let mut component = components;
        self.for_each_active(leaf, |v| {
            if component == components {
                at = offsets.next().expect("one value per active voxel") * components;
                component = 0;
            }
            out[at + component] = v;
            component += 1;
        });
    }
}

/// The values of `values` at the set bits of `mask`, in offset order, at the start of `out`;
/// how many. Eight values at a time by AVX2 where the CPU has it (igea's level set band at
/// 1024: 25 -> 12 ms a pass over its leaves), else a mask word at a time.
#[inline(always)]
fn gather(mask: &[u64; 8], out: &mut [f32; LEAF_VOXELS], values: &[f32; LEAF_VOXELS]) -> usize {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has AVX2.
        return unsafe { gather_by_eights(mask, out, values) };
    }
    gather_by_words(mask, out, values)
}

/// `gather` a mask word at a time, a whole word as one copy.
#[inline(always)]
fn gather_by_words(
    mask: &[u64; 8],
    out: &mut [f32; LEAF_VOXELS],
    values: &[f32; LEAF_VOXELS],
) -> usize {
    let mut at = 0;
    for (w, &bits) in mask.iter().enumerate() {
        let word = &values[64 * w..64 * w + 64];
        if bits == u64::MAX {
            out[at..at + 64].copy_from_slice(word);
            at += 64;
            continue;
        }
        let mut b = bits;
        while b != 0 {
            out[at] = word[b.trailing_zeros() as usize];
            at += 1;
            b &= b - 1;
        }
    }
    at
}

/// For each byte mask, the lanes of its set bits in order (the rest 0): the permutation that
/// packs those of eight values to the front.
#[cfg(target_arch = "x86_64")]
const PACKED_LANES: [[u32; 8]; 256] = {
    let mut lanes = [[0; 8]; 256];
    let mut byte = 0;
    while byte < 256 {
        let (mut lane, mut at) = (0, 0);
        while lane < 8 {
            if byte >> lane & 1 == 1 {
                lanes[byte][at] = lane as u32;
                at += 1;
            }
            lane += 1;
        }
        byte += 1;
    }
    lanes
};

/// `gather` eight values at a time: each eight permuted by their mask byte's packing and
/// stored whole at the next place (the lanes past its count are overwritten by the next
/// store, or left past the count).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn gather_by_eights(
    mask: &[u64; 8],
    out: &mut [f32; LEAF_VOXELS],
    values: &[f32; LEAF_VOXELS],
) -> usize {
    use std::arch::x86_64::*;
    let bytes = mask.iter().flat_map(|word| word.to_le_bytes());
    let mut at = 0;
    for (first, byte) in (0..LEAF_VOXELS).step_by(8).zip(bytes) {
        // SAFETY: AVX2 is enabled. The load reads `values[first..first + 8]` (`first` at most
        // 504); the store writes `out[at..at + 8]`, in bounds as `at` (the values before
        // `first` that were kept) is at most `first`. The table's row is 8 u32s.
        unsafe {
            let eight = _mm256_loadu_ps(values.as_ptr().add(first));
            let lanes = _mm256_loadu_si256(PACKED_LANES[usize::from(byte)].as_ptr().cast());
            _mm256_storeu_ps(
                out.as_mut_ptr().add(at),
                _mm256_permutevar8x32_ps(eight, lanes),
            );
        }
        at += byte.count_ones() as usize;
    }
    at
}

/// The origin of the node or tile at `key`: its root child's, plus its 128^3 slot, plus (for
/// an 8^3 block, `leaf_level`) its 8^3 slot.
pub(super) fn block_origin(key: &Key, leaf_level: bool) -> [i32; 3] {
    let slot = |n: u16, log2: u32, shift: u32| {
        let side = 1u16 << log2;
        let c = [n >> (2 * log2), (n >> log2) & (side - 1), n & (side - 1)];
        c.map(|v| i32::from(v) << shift)
    };
    let upper = slot(key.1, NODE_LOG2[0], CHILD_LOG2[0]);
    let lower = if leaf_level {
        slot(key.2, NODE_LOG2[1], CHILD_LOG2[1])
    } else {
        [0; 3]
    };
    [0, 1, 2].map(|a| key.0[a] + upper[a] + lower[a])
}

/// One grid to write.
pub(super) struct GridOut<'g> {
    pub name: std::borrow::Cow<'g, str>,
    pub grid: &'g SparseGrid,
    pub values: GridValues<'g>,
    /// OpenVDB's grid class (`fog volume`), when it has one.
    pub class: Option<&'static str>,
    /// OpenVDB's vector type of a Vec3 grid (`covariant normalize`, `invariant`).
    pub vector_type: Option<&'static str>,
    pub metadata: &'g [(String, super::vdb_format::MetaValue)],
}

/// Something held by a 128^3 or an 8^3 slot of an internal node.
#[derive(Clone, Copy)]
pub(super) enum Entry<'g> {
    NodeTile,
    LeafTile,
    Leaf(&'g Leaf),
}

/// Where an entry sits: its root child's origin, its slot in that child (32^3 slots of
/// 128^3), its slot in the 128^3 node (16^3 slots of 8^3). Sorting by key gives OpenVDB's
/// order.
pub(super) type Key = ([i32; 3], u16, u16);

/// `key` as one number that sorts as the key does (a tuple compares field by field).
#[inline]
fn packed(key: &Key) -> u128 {
    let c = key.0.map(|v| u128::from(v as u32 ^ 0x8000_0000));
    (c[0] << 96) | (c[1] << 64) | (c[2] << 32) | (u128::from(key.1) << 16) | u128::from(key.2)
}

/// The key of the block at `origin`; errors name `path`.
pub(super) fn key(path: &Path, origin: [i64; 3]) -> Result<Key> {
    let mut c = [0i32; 3];
    for (o, &v) in c.iter_mut().zip(&origin) {
        *o = i32::try_from(v)
            .ok()
            .filter(|v| v.checked_add(127).is_some())
            .ok_or_else(|| Error::Vdb {
                path: path.to_path_buf(),
                message: format!("block {origin:?} is outside OpenVDB's 32-bit index range"),
            })?;
    }
    let slot = |shift: u32, bits: u32| {
        let mask = (1 << bits) - 1;
        c.iter()
            .fold(0u16, |s, &v| (s << bits) | ((v >> shift) & mask) as u16)
    };
    Ok((
        c.map(|v| v & !(ROOT_TILE - 1)),
        slot(CHILD_LOG2[0], NODE_LOG2[0]),
        slot(CHILD_LOG2[1], NODE_LOG2[1]),
    ))
}

/// The grid's non-empty leaves and its tiles (a level set's: its interior's) in tree order;
/// refuses vectors on tiles and a tile sharing its place with another node. Errors name
/// `path`.
pub(super) fn tree_entries<'g>(path: &Path, g: &GridOut<'g>) -> Result<Vec<(Key, Entry<'g>)>> {
    let mut leaves: Vec<(Key, Entry)> = g
        .grid
        .leaves()
        .par_iter()
        .filter(|l| !l.is_empty())
        .map(|l| Ok((key(path, l.origin)?, Entry::Leaf(l))))
        .collect::<Result<_>>()?;
    leaves.par_sort_unstable_by_key(|e| e.0);
    let tiles = sorted_tiles(path, g)?;
    if g.values.value_type() == ValueType::Vec3 && !tiles.is_empty() {
        return Err(Error::Vdb {
            path: path.to_path_buf(),
            message: format!("grid {}: tiles carry no vectors", g.name),
        });
    }
    let entries = merge_sorted(leaves, tiles);
    // A block is a leaf or a tile, and a 128^3 tile holds nothing else.
    let clash = entries.windows(2).find(|w| {
        w[0].0 == w[1].0
            || (w[0].0.0 == w[1].0.0 && w[0].0.1 == w[1].0.1 && matches!(w[0].1, Entry::NodeTile))
    });
    if let Some(w) = clash {
        return Err(Error::Vdb {
            path: path.to_path_buf(),
            message: format!(
                "grid {}: a tile and another node in one place (root child {:?}, slot {})",
                g.name, w[0].0.0, w[0].0.1
            ),
        });
    }
    Ok(entries)
}

/// The grid's tiles (a level set's: its interior's) in tree order: only their nodes are
/// sorted, as a node lists its 8^3 tiles in its slots' order already.
fn sorted_tiles<'g>(path: &Path, g: &GridOut<'g>) -> Result<Vec<(Key, Entry<'g>)>> {
    let tiles = match g.values {
        GridValues::LevelSet { interior, .. } => interior,
        _ => g.grid,
    }
    .tiles();
    let mut nodes: Vec<(Key, Option<Vec<usize>>)> = tiles
        .node_tiles()
        .map(|o| Ok((key(path, o)?, None)))
        .chain(
            tiles
                .leaf_tiles_by_node()
                .map(|(node, slots)| Ok((key(path, node)?, Some(slots.collect())))),
        )
        .collect::<Result<_>>()?;
    nodes.sort_unstable_by_key(|n| n.0);
    let mut sorted = Vec::with_capacity(tiles.count() as usize);
    for (node_key, blocks) in nodes {
        match blocks {
            None => sorted.push((node_key, Entry::NodeTile)),
            // A block's slot in its node is the key's last part.
            Some(slots) => sorted.extend(
                slots
                    .into_iter()
                    .map(|s| ((node_key.0, node_key.1, s as u16), Entry::LeafTile)),
            ),
        }
    }
    Ok(sorted)
}

/// The entries of two sorted lists in one sorted list.
fn merge_sorted<'g>(a: Vec<(Key, Entry<'g>)>, b: Vec<(Key, Entry<'g>)>) -> Vec<(Key, Entry<'g>)> {
    let mut merged = Vec::with_capacity(a.len() + b.len());
    let (mut a, mut b) = (a.into_iter().peekable(), b.into_iter().peekable());
    while let (Some(x), Some(y)) = (a.peek(), b.peek()) {
        let next = if packed(&x.0) <= packed(&y.0) {
            a.next()
        } else {
            b.next()
        };
        merged.extend(next);
    }
    merged.extend(a);
    merged.extend(b);
    merged
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::SplitMix64;

    /// Both ways of gathering against the values picked bit by bit, on masks empty, full,
    /// with whole words and at random densities.
    #[test]
    fn gathers_pick_the_active_values_in_order() {
        let values: [f32; LEAF_VOXELS] = std::array::from_fn(|n| n as f32 * 0.5 - 7.0);
        let mut random = SplitMix64(3);
        let mut masks = vec![[0u64; 8], [u64::MAX; 8]];
        for density in [1, 2, 4, 8] {
            for _ in 0..50 {
                masks.push(std::array::from_fn(|_| {
                    (0..density).fold(u64::MAX, |m, _| m & random.next_u64())
                }));
            }
        }
        masks.push([u64::MAX, 0, 1 << 63, u64::MAX, 5, u64::MAX, 0, u64::MAX]);
        for mask in masks {
            let expected: Vec<f32> = (0..LEAF_VOXELS)
                .filter(|&n| mask[n / 64] >> (n % 64) & 1 == 1)
                .map(|n| values[n])
                .collect();
            let mut out = [f32::NAN; LEAF_VOXELS];
            let n = gather(&mask, &mut out, &values);
            assert_eq!(&out[..n], &expected[..], "mask {mask:x?}");
            let mut out = [f32::NAN; LEAF_VOXELS];
            let n = gather_by_words(&mask, &mut out, &values);
            assert_eq!(&out[..n], &expected[..], "mask {mask:x?} by words");
        }
    }
}

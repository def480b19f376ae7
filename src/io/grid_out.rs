//! A grid to write, as both writers see it (`.vdb` by `vdb_writer`, `.nvdb` by
//! `nvdb_writer`): what its voxels and tiles hold, and its leaves and tiles sorted into the
//! order of OpenVDB's standard 5-4-3 tree (root children of 4096^3, internal nodes of 128^3,
//! leaves of 8^3), which NanoVDB shares.

use super::vdb_format::{CHILD_LOG2, NODE_LOG2, ROOT_TILE};
use crate::error::{Error, Result};
use crate::grid::{LEAF_VOXELS, Leaf, NODE_LEAVES, SparseGrid};
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

/// Where a block sits: its root child's origin, its slot in that child (32^3 slots of
/// 128^3), its slot in the 128^3 node (16^3 slots of 8^3).
pub(super) type Key = ([i32; 3], u16, u16);

/// The words of a 128^3 node's mask of 8^3 slots.
const NODE_WORDS: usize = NODE_LEAVES / 64;

/// No 8^3 tiles in a node.
const NO_TILES: [u64; NODE_WORDS] = [0; NODE_WORDS];

/// A grid's tree in OpenVDB's order (root children, then their 128^3 slots, then 8^3 slots,
/// each ascending), node by node: 8^3 tiles are a node's mask, not one entry each (a solid
/// has hundreds of thousands of them in a few hundred nodes).
pub(super) struct Tree<'g> {
    /// The non-empty leaves in tree order, each with its slot in its node.
    pub leaves: Vec<(u16, &'g Leaf)>,
    /// The 128^3 nodes and tiles in tree order.
    pub nodes: Vec<TreeNode<'g>>,
}

/// A 128^3 slot of a root child: a tile, or a node of 8^3 tiles and leaves.
pub(super) struct TreeNode<'g> {
    /// Its root child's origin.
    pub root: [i32; 3],
    /// Its slot in the root child.
    pub slot: u16,
    /// Whether the slot holds a 128^3 tile (then nothing else).
    pub tile: bool,
    /// Its 8^3 tiles, a bit per slot.
    pub tiles: &'g [u64; NODE_WORDS],
    /// Its leaves: a range of the tree's.
    pub leaves: std::ops::Range<usize>,
}

impl<'g> TreeNode<'g> {
    /// The node at `origin` (its key's first parts), with nothing in it yet.
    fn at(path: &Path, origin: [i64; 3]) -> Result<Self> {
        let (root, slot, _) = key(path, origin)?;
        Ok(TreeNode {
            root,
            slot,
            tile: false,
            tiles: &NO_TILES,
            leaves: 0..0,
        })
    }

    /// Its tiles: the 128^3 one, or its 8^3 ones.
    pub fn tile_count(&self) -> usize {
        let leaf_tiles: u32 = self.tiles.iter().map(|w| w.count_ones()).sum();
        usize::from(self.tile) + leaf_tiles as usize
    }

    /// Its leaves' slots as a mask (`leaves`: the tree's).
    pub fn children(&self, leaves: &[(u16, &Leaf)]) -> [u64; NODE_WORDS] {
        let mut mask = [0u64; NODE_WORDS];
        for &(slot, _) in &leaves[self.leaves.clone()] {
            mask[usize::from(slot) / 64] |= 1 << (slot % 64);
        }
        mask
    }

    /// Its 8^3 slots in use, ascending: each a leaf, or a tile (`None`).
    pub fn blocks<'t>(
        &'t self,
        tree: &'t Tree<'g>,
    ) -> impl Iterator<Item = (u16, Option<&'g Leaf>)> + 't {
        let mut leaves = tree.leaves[self.leaves.clone()].iter().peekable();
        let mut tiles = crate::grid::bits::ones(&self.tiles[..]).peekable();
        std::iter::from_fn(move || {
            let tile = tiles.peek().map(|&t| t as u16);
            match (leaves.peek(), tile) {
                (Some(&&(slot, leaf)), t) if t.is_none_or(|t| slot < t) => {
                    leaves.next();
                    Some((slot, Some(leaf)))
                }
                (_, Some(t)) => {
                    tiles.next();
                    Some((t, None))
                }
                _ => None,
            }
        })
    }
}

/// A root child's origin and a 128^3 slot as one number that sorts as the pair does.
#[inline]
fn node_order(root: [i32; 3], slot: u16) -> u128 {
    let c = root.map(|v| u128::from(v as u32 ^ 0x8000_0000));
    (c[0] << 96) | (c[1] << 64) | (c[2] << 32) | (u128::from(slot) << 16)
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

/// The grid's tree: its non-empty leaves and its tiles (a level set's: its interior's);
/// refuses vectors on tiles and a tile sharing its place with another node. Errors name
/// `path`.
pub(super) fn tree<'g>(path: &Path, g: &GridOut<'g>) -> Result<Tree<'g>> {
    let mut keyed: Vec<(u128, u16, &Leaf)> = g
        .grid
        .leaves()
        .par_iter()
        .filter(|l| !l.is_empty())
        .map(|l| {
            let (root, node, slot) = key(path, l.origin)?;
            Ok((node_order(root, node) | u128::from(slot), slot, l))
        })
        .collect::<Result<_>>()?;
    keyed.par_sort_unstable_by_key(|e| e.0);
    let tiles = match g.values {
        GridValues::LevelSet { interior, .. } => interior,
        _ => g.grid,
    }
    .tiles();
    if g.values.value_type() == ValueType::Vec3 && !tiles.is_empty() {
        return Err(Error::Vdb {
            path: path.to_path_buf(),
            message: format!("grid {}: tiles carry no vectors", g.name),
        });
    }
    // The nodes holding leaves, then those holding tiles, in one list sorted by place: a
    // stable sort keeps a node's leaves before its tiles, which then join them.
    let mut nodes: Vec<TreeNode> = Vec::new();
    for (n, &(order, _, leaf)) in keyed.iter().enumerate() {
        match nodes.last_mut() {
            Some(node) if node_order(node.root, node.slot) == order & !0xffff => {
                node.leaves.end = n + 1
            }
            _ => nodes.push(TreeNode {
                leaves: n..n + 1,
                ..TreeNode::at(path, leaf.origin)?
            }),
        }
    }
    let leaves: Vec<(u16, &Leaf)> = keyed
        .into_iter()
        .map(|(_, slot, leaf)| (slot, leaf))
        .collect();
    for (origin, mask) in tiles.leaf_tile_masks() {
        nodes.push(TreeNode {
            tiles: mask,
            ..TreeNode::at(path, origin)?
        });
    }
    for origin in tiles.node_tiles() {
        nodes.push(TreeNode {
            tile: true,
            ..TreeNode::at(path, origin)?
        });
    }
    let order = |n: &TreeNode| node_order(n.root, n.slot);
    nodes.sort_by_key(order);
    let mut joined: Vec<TreeNode> = Vec::with_capacity(nodes.len());
    for next in nodes {
        match joined.last_mut() {
            // Anything more in a place than a node's leaves and its 8^3 tiles is a clash.
            Some(last) if order(last) == order(&next) => {
                let overlap =
                    |c: [u64; NODE_WORDS]| c.iter().zip(next.tiles).any(|(c, t)| c & t != 0);
                if last.tile
                    || next.tile
                    || last.tile_count() > 0
                    || overlap(last.children(&leaves))
                {
                    return Err(Error::Vdb {
                        path: path.to_path_buf(),
                        message: format!(
                            "grid {}: a tile and another node in one place (root child {:?}, \
                             slot {})",
                            g.name, last.root, last.slot
                        ),
                    });
                }
                last.tiles = next.tiles;
            }
            _ => joined.push(next),
        }
    }
    Ok(Tree {
        leaves,
        nodes: joined,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::SplitMix64;

    fn voxels_grid() -> SparseGrid {
        SparseGrid::new(
            crate::grid::Transform::default(),
            crate::grid::Channels::NONE,
        )
    }

    /// Leaves and tiles across two root children and several nodes come out in OpenVDB's
    /// order: nodes by root child and slot, a node's leaves and 8^3 tiles by slot between.
    #[test]
    fn the_tree_is_in_order_node_by_node() {
        let mut grid = voxels_grid();
        // Leaves in two nodes of the root child at 0 and one of the child at -4096, given
        // out of order; 8^3 tiles between the first node's leaves; a 128^3 tile.
        for c in [[136, 0, 0], [16, 8, 0], [-8, 0, 0], [0, 0, 8], [0, 0, 0]] {
            grid.insert(c);
        }
        for o in [[0, 0, 16], [8, 0, 0], [0, 8, 0]] {
            grid.fill_leaf_block(o);
        }
        grid.fill_node_block([0, 128, 0]);
        let out = GridOut {
            name: "g".into(),
            grid: &grid,
            values: GridValues::Bool,
            class: None,
            vector_type: None,
            metadata: &[],
        };
        let tree = tree(Path::new("t.vdb"), &out).expect("a tree");
        let order: Vec<([i32; 3], u16, bool)> = tree
            .nodes
            .iter()
            .map(|n| (n.root, n.slot, n.tile))
            .collect();
        assert_eq!(
            order,
            [
                ([-4096, 0, 0], 31 << 10, false),
                ([0, 0, 0], 0, false),
                ([0, 0, 0], 1 << 5, true),
                ([0, 0, 0], 1 << 10, false),
            ]
        );
        let first = &tree.nodes[1];
        let blocks: Vec<(u16, bool)> = first
            .blocks(&tree)
            .map(|(slot, leaf)| (slot, leaf.is_some()))
            .collect();
        // Slots x << 8 | y << 4 | z of the 8^3 blocks: (0,0,0) and (0,0,1) leaves, (0,0,2),
        // (0,1,0) and (1,0,0) tiles, (2,1,0) a leaf.
        assert_eq!(
            blocks,
            [
                (0, true),
                (1, true),
                (2, false),
                (16, false),
                (256, false),
                (528, true)
            ]
        );
        assert_eq!(first.tile_count(), 3);
        let leaves: Vec<[i64; 3]> = tree.leaves.iter().map(|(_, l)| l.origin).collect();
        assert_eq!(
            leaves,
            [[-8, 0, 0], [0, 0, 0], [0, 0, 8], [16, 8, 0], [136, 0, 0]]
        );
        for node in &tree.nodes {
            for &(slot, leaf) in &tree.leaves[node.leaves.clone()] {
                let origin = block_origin(&(node.root, node.slot, slot), true);
                assert_eq!(
                    leaf.origin,
                    origin.map(i64::from),
                    "a leaf in its node's range"
                );
            }
        }
    }

    /// A level set whose interior holds a tile where the band holds a leaf, 8^3 or 128^3, is
    /// refused.
    #[test]
    fn a_tile_on_a_leaf_is_refused() {
        let mut band = voxels_grid();
        band.insert([3, 3, 3]);
        let (mut block, mut node) = (voxels_grid(), voxels_grid());
        block.fill_leaf_block([0, 0, 0]);
        node.fill_node_block([0, 0, 0]);
        for interior in [&block, &node] {
            let out = GridOut {
                name: "surface".into(),
                grid: &band,
                values: GridValues::LevelSet {
                    background: 3.0,
                    interior,
                },
                class: None,
                vector_type: None,
                metadata: &[],
            };
            let Err(e) = tree(Path::new("t.vdb"), &out) else {
                panic!("a clash refused");
            };
            assert!(
                e.to_string()
                    .contains("a tile and another node in one place"),
                "{e}"
            );
        }
    }

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

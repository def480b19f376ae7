//! The sparse voxel grid: leaves in a vector (cheap iteration, bulk transfer to OpenVDB)
//! indexed by origin through a hash map, and tiles for whole 8^3 and 128^3 blocks. A block
//! is either a tile or a leaf, never both; tiles carry no channels.

use super::coord::{Coord, CoordBox, leaf_offset, leaf_origin, offset_coord};
use super::leaf::{Channels, Leaf, mask_box};
use super::tiles::{NODE_DIM, NodeMask, Tiles, node_leaf_origins, node_origin};
use super::transform::Transform;
use rayon::prelude::*;
use rustc_hash::{FxHashMap, FxHashSet};

#[derive(Clone, Debug, Default)]
pub struct SparseGrid {
    pub transform: Transform,
    channels: Channels,
    leaves: Vec<Leaf>,
    index: FxHashMap<Coord, u32>,
    tiles: Tiles,
}

/// What a grid holds in one 8^3 block.
pub enum Block<'g> {
    Empty,
    Whole,
    Partial(&'g Leaf),
}

const FULL: [u64; 8] = [u64::MAX; 8];

impl SparseGrid {
    pub fn new(transform: Transform, channels: Channels) -> Self {
        SparseGrid {
            transform,
            channels,
            leaves: Vec::new(),
            index: FxHashMap::default(),
            tiles: Tiles::default(),
        }
    }

    pub fn channels(&self) -> Channels {
        self.channels
    }

    /// Builds a grid from leaves; leaves with the same origin are OR-ed together.
    pub fn from_leaves(transform: Transform, channels: Channels, leaves: Vec<Leaf>) -> Self {
        let mut g = SparseGrid::new(transform, channels);
        for leaf in leaves {
            g.merge_leaf(leaf, union_leaf);
        }
        g
    }

    /// Builds a grid from leaves of distinct origins, without tiles.
    pub fn from_distinct_leaves(
        transform: Transform,
        channels: Channels,
        leaves: Vec<Leaf>,
    ) -> Self {
        let mut index = FxHashMap::default();
        index.reserve(leaves.len());
        for (i, leaf) in leaves.iter().enumerate() {
            let before = index.insert(leaf.origin, i as u32);
            debug_assert!(before.is_none(), "leaf origins are distinct");
        }
        SparseGrid {
            transform,
            channels,
            leaves,
            index,
            tiles: Tiles::default(),
        }
    }

    /// The leaves, for a grid without tiles.
    pub fn into_leaves(self) -> Vec<Leaf> {
        debug_assert!(self.tiles.is_empty(), "a grid without tiles");
        self.leaves
    }

    /// The leaves (blocks held voxel by voxel); whole blocks are in `tiles`.
    pub fn leaves(&self) -> &[Leaf] {
        &self.leaves
    }

    /// The leaves, to change their voxels and channels (not their origins).
    pub fn leaves_mut(&mut self) -> &mut [Leaf] {
        &mut self.leaves
    }

    /// The whole 8^3 and 128^3 blocks.
    pub fn tiles(&self) -> &Tiles {
        &self.tiles
    }

    /// Makes the 8^3 block at `origin` (a multiple of 8) whole.
    pub fn fill_leaf_block(&mut self, origin: Coord) {
        if self.leaf_block_to_tile(origin) {
            self.tiles.insert_leaf(origin);
        }
    }

    /// Readies the 8^3 block at `origin` to be made whole: a leaf there is kept, whole, where
    /// channels live in leaves, and emptied otherwise. Whether the block is to become a tile
    /// (one already a tile is left as it is).
    fn leaf_block_to_tile(&mut self, origin: Coord) -> bool {
        match self.index.get(&origin) {
            None => true,
            Some(_) if self.tiles.covers(origin) => false,
            Some(&i) if self.channels != Channels::NONE => {
                self.leaves[i as usize].mask = FULL;
                false
            }
            Some(&i) => {
                self.leaves[i as usize].mask = [0; 8];
                true
            }
        }
    }

    /// `fill_free_leaf_blocks` for the blocks of each 128^3 node given as its mask.
    pub fn fill_free_node_masks(&mut self, masks: &[NodeMask]) {
        for mask in masks {
            self.tiles.insert_node_mask(mask);
        }
        self.tiles.promote();
    }

    /// Makes the 8^3 blocks at `origins` whole, as `fill_leaf_block` does one by one, and
    /// each 128^3 node whole in 8^3 tiles a node tile.
    pub fn fill_leaf_blocks(&mut self, origins: Vec<Coord>) {
        let free: Vec<Coord> = origins
            .into_iter()
            .filter(|&o| self.leaf_block_to_tile(o))
            .collect();
        self.fill_free_leaf_blocks(free);
    }

    /// `fill_leaf_blocks` for blocks where the grid holds no leaf: none is looked up.
    pub fn fill_free_leaf_blocks(&mut self, origins: Vec<Coord>) {
        debug_assert!(origins.iter().all(|o| !self.index.contains_key(o)));
        // Blocks given in runs within one 128^3 node (a column's are) share the node's
        // lookups: a solid's inside is hundreds of thousands of blocks.
        for run in origins.chunk_by(|a, b| node_origin(*a) == node_origin(*b)) {
            self.tiles
                .insert_leaves_of_node(node_origin(run[0]), run.iter().copied());
        }
        self.tiles.promote();
    }

    /// Makes the 128^3 block at `origin` (a multiple of 128) whole.
    pub fn fill_node_block(&mut self, origin: Coord) {
        let leaves_under = || node_leaf_origins(origin).any(|o| self.index.contains_key(&o));
        if self.index.is_empty() || !leaves_under() {
            self.tiles.insert_node(origin);
            return;
        }
        if self.channels != Channels::NONE {
            // Channels live in leaves: keep those, whole.
            node_leaf_origins(origin).for_each(|o| self.fill_leaf_block(o));
            return;
        }
        self.tiles.insert_node(origin);
        for leaf in &mut self.leaves {
            if node_origin(leaf.origin) == origin {
                leaf.mask = [0; 8];
            }
        }
        self.prune();
    }

    /// What the grid holds in the 8^3 block at `origin`.
    pub fn block(&self, origin: Coord) -> Block<'_> {
        if self.tiles.covers(origin) {
            Block::Whole
        } else {
            self.leaf(origin).map_or(Block::Empty, Block::Partial)
        }
    }

    /// The voxels the grid holds in the 8^3 block at `origin`, as a leaf's mask words.
    pub fn block_mask(&self, origin: Coord) -> [u64; 8] {
        match self.block(origin) {
            Block::Whole => FULL,
            Block::Partial(leaf) => leaf.mask,
            Block::Empty => [0; 8],
        }
    }

    /// Replaces the value of every active voxel by `f(voxel, value)`, leaves in parallel.
    pub fn map_values(&mut self, f: impl Fn(Coord, f32) -> f32 + Sync) {
        use rayon::prelude::*;
        self.leaves.par_iter_mut().for_each(|leaf| {
            let origin = leaf.origin;
            let on: Vec<usize> = leaf.offsets().collect();
            if let Some(values) = leaf.value.as_mut() {
                for n in on {
                    values[n] = f(offset_coord(origin, n), values[n]);
                }
            }
        });
    }

    pub fn leaf(&self, origin: Coord) -> Option<&Leaf> {
        self.index.get(&origin).map(|&i| &self.leaves[i as usize])
    }

    /// Index of the leaf at `origin`, created when missing (whole when the block was a
    /// tile, which it replaces).
    fn leaf_index_or_insert(&mut self, origin: Coord) -> usize {
        if let Some(&i) = self.index.get(&origin) {
            return i as usize;
        }
        let i = self.leaves.len();
        let mut leaf = Leaf::new(origin, self.channels);
        if !self.tiles.is_empty() && self.tiles.remove_leaf(origin) {
            leaf.mask = FULL;
        }
        self.leaves.push(leaf);
        self.index.insert(origin, i as u32);
        i
    }

    pub fn leaf_mut_or_insert(&mut self, origin: Coord) -> &mut Leaf {
        let i = self.leaf_index_or_insert(origin);
        &mut self.leaves[i]
    }

    pub fn insert(&mut self, c: Coord) {
        if self.tiles.covers(leaf_origin(c)) {
            return;
        }
        self.leaf_mut_or_insert(leaf_origin(c))
            .set_on(leaf_offset(c));
    }

    pub fn contains(&self, c: Coord) -> bool {
        match self.block(leaf_origin(c)) {
            Block::Empty => false,
            Block::Whole => true,
            Block::Partial(l) => l.is_on(leaf_offset(c)),
        }
    }

    /// A write accessor that remembers the last leaf it touched.
    pub fn accessor(&mut self) -> Accessor<'_> {
        Accessor {
            grid: self,
            cached_origin: [i64::MIN; 3],
            cached_index: 0,
        }
    }

    pub fn voxel_count(&self) -> u64 {
        // Counted on all threads, as `bbox` is: reports ask while nothing else runs.
        let leaves: u64 = self.leaves.par_iter().map(|l| l.count() as u64).sum();
        leaves + self.tiles.voxel_count()
    }

    /// Number of leaves holding at least one active voxel.
    pub fn leaf_count(&self) -> usize {
        self.leaves.par_iter().filter(|l| !l.is_empty()).count()
    }

    pub fn is_empty(&self) -> bool {
        self.tiles.is_empty() && self.leaves.iter().all(|l| l.is_empty())
    }

    /// Bounding box of the active voxels, `None` for an empty grid.
    pub fn bbox(&self) -> Option<CoordBox> {
        // On all threads: the writers and reports ask for it while nothing else runs.
        let leaves = self
            .leaves
            .par_iter()
            .filter_map(|leaf| mask_box(leaf.origin, &leaf.mask))
            .reduce_with(|a, b| a.union(&b));
        leaves
            .into_iter()
            .chain(self.tiles.bbox())
            .reduce(|a, b| a.union(&b))
    }

    /// Every active voxel (leaves first, then tiles).
    pub fn voxels(&self) -> impl Iterator<Item = Coord> + '_ {
        let tiled: Vec<Coord> = self.tiles.blocks().collect();
        let n = self.leaves.len();
        // One flat_map over leaves and whole blocks by index (a chain of the two confuses
        // valgrind's definedness tracking).
        (0..n + tiled.len()).flat_map(move |i| {
            let (origin, mask) = match self.leaves.get(i) {
                Some(l) => (l.origin, l.mask),
                None => (tiled[i - n], FULL),
            };
            (0..8).flat_map(move |w| {
                let mut bits = mask[w];
                std::iter::from_fn(move || {
                    (bits != 0).then(|| {
                        let n = w * 64 + bits.trailing_zeros() as usize;
                        bits &= bits - 1;
                        offset_coord(origin, n)
                    })
                })
            })
        })
    }

    /// Merges `leaf` into the leaf of the same origin with `combine(existing, incoming)`
    /// (a whole block stays whole).
    pub fn merge_leaf(&mut self, leaf: Leaf, combine: impl FnOnce(&mut Leaf, &Leaf)) {
        if self.tiles.covers(leaf.origin) {
            return;
        }
        match self.index.get(&leaf.origin) {
            Some(&i) => combine(&mut self.leaves[i as usize], &leaf),
            None => {
                self.index.insert(leaf.origin, self.leaves.len() as u32);
                self.leaves.push(leaf);
            }
        }
    }

    /// Merges every leaf of `other` into `self` with `combine(existing, incoming)`, and
    /// `other`'s tiles as whole blocks.
    pub fn merge_with(&mut self, other: SparseGrid, mut combine: impl FnMut(&mut Leaf, &Leaf)) {
        self.fill_tiles_of(&other);
        for leaf in other.leaves {
            self.merge_leaf(leaf, &mut combine);
        }
    }

    /// Makes every block that is whole in `other` whole in `self`.
    fn fill_tiles_of(&mut self, other: &SparseGrid) {
        other
            .tiles
            .leaf_tiles()
            .for_each(|o| self.fill_leaf_block(o));
        other
            .tiles
            .node_tiles()
            .for_each(|o| self.fill_node_block(o));
    }

    /// Voxels active in `self` or `other`; where both are, `self`'s channels are kept.
    pub fn union(&mut self, other: &SparseGrid) {
        self.fill_tiles_of(other);
        for leaf in &other.leaves {
            if self.tiles.covers(leaf.origin) {
                continue;
            }
            let i = self.leaf_index_or_insert(leaf.origin);
            union_leaf(&mut self.leaves[i], leaf);
        }
        self.compact();
    }

    /// Voxels active in both grids.
    pub fn intersection(&mut self, other: &SparseGrid) {
        for leaf in &mut self.leaves {
            match other.block(leaf.origin) {
                Block::Whole => {}
                Block::Partial(o) => (0..8).for_each(|w| leaf.mask[w] &= o.mask[w]),
                Block::Empty => leaf.mask = [0; 8],
            }
        }
        // A whole block of `self` becomes what `other` holds there.
        let mut blocks: Vec<Coord> = self.tiles.leaf_tiles().collect();
        for node in self.tiles.node_tiles().collect::<Vec<_>>() {
            if !other.tiles.has_node(node) {
                self.tiles.remove_node(node);
                blocks.extend(other.blocks_in_node(node));
            }
        }
        for o in blocks {
            match other.block(o) {
                Block::Whole => self.tiles.insert_leaf(o),
                Block::Partial(l) => {
                    self.tiles.remove_leaf(o);
                    self.leaf_mut_or_insert(o).mask = l.mask;
                }
                Block::Empty => {
                    self.tiles.remove_leaf(o);
                }
            }
        }
        self.prune();
        self.compact();
    }

    /// Voxels active in `self` and not in `other`.
    pub fn difference(&mut self, other: &SparseGrid) {
        for leaf in &mut self.leaves {
            match other.block(leaf.origin) {
                Block::Whole => leaf.mask = [0; 8],
                Block::Partial(o) => (0..8).for_each(|w| leaf.mask[w] &= !o.mask[w]),
                Block::Empty => {}
            }
        }
        // Whole blocks of `self` lose what `other` holds there; node tiles split only where
        // `other` reaches into them.
        let touched: FxHashSet<Coord> = other
            .leaves
            .iter()
            .map(|l| l.origin)
            .chain(other.tiles.leaf_tiles())
            .map(node_origin)
            .collect();
        let mut blocks: Vec<Coord> = self.tiles.leaf_tiles().collect();
        for node in self.tiles.node_tiles().collect::<Vec<_>>() {
            if other.tiles.has_node(node) {
                self.tiles.remove_node(node);
            } else if touched.contains(&node) {
                self.tiles.remove_node(node);
                blocks.extend(node_leaf_origins(node));
            }
        }
        for o in blocks {
            match other.block(o) {
                Block::Whole => {
                    self.tiles.remove_leaf(o);
                }
                Block::Partial(l) => {
                    self.tiles.remove_leaf(o);
                    self.leaf_mut_or_insert(o).mask = l.mask.map(|w| !w);
                }
                Block::Empty => self.tiles.insert_leaf(o),
            }
        }
        self.prune();
        self.compact();
    }

    /// Keeps only the voxels inside `keep`; tiles it cuts become leaves.
    pub fn clip(&mut self, keep: CoordBox) {
        for leaf in &mut self.leaves {
            let inside = block_mask(leaf.origin, &keep);
            (0..8).for_each(|w| leaf.mask[w] &= inside[w]);
        }
        let mut blocks: Vec<Coord> = self.tiles.leaf_tiles().collect();
        for node in self.tiles.node_tiles().collect::<Vec<_>>() {
            let last = node.map(|v| v + NODE_DIM - 1);
            if !(keep.contains(node) && keep.contains(last)) {
                self.tiles.remove_node(node);
                blocks.extend(node_leaf_origins(node));
            }
        }
        for o in blocks {
            match block_mask(o, &keep) {
                FULL => self.tiles.insert_leaf(o),
                [0, 0, 0, 0, 0, 0, 0, 0] => {
                    self.tiles.remove_leaf(o);
                }
                inside => {
                    self.tiles.remove_leaf(o);
                    self.leaf_mut_or_insert(o).mask = inside;
                }
            }
        }
        self.prune();
        self.compact();
    }

    /// Origins of the blocks `self` holds anything in, inside the 128^3 node at `node`.
    fn blocks_in_node(&self, node: Coord) -> Vec<Coord> {
        self.leaves
            .iter()
            .map(|l| l.origin)
            .chain(self.tiles.leaf_tiles())
            .filter(|&o| node_origin(o) == node)
            .collect()
    }

    /// Keeps the leaves whose origin `keep` accepts (a grid without tiles: a surface).
    pub fn retain_leaves(&mut self, keep: impl Fn(Coord) -> bool) {
        debug_assert!(self.tiles.is_empty(), "only leaves are filtered");
        self.leaves.retain(|l| keep(l.origin));
        self.reindex();
    }

    /// Drops empty leaves.
    pub fn prune(&mut self) {
        self.leaves.retain(|l| !l.is_empty());
        self.reindex();
    }

    fn reindex(&mut self) {
        self.index = self
            .leaves
            .iter()
            .enumerate()
            .map(|(i, l)| (l.origin, i as u32))
            .collect();
    }

    /// Complete 128^3 groups of 8^3 tiles become node tiles (leaves are left as they are).
    pub fn promote_tiles(&mut self) {
        self.tiles.promote();
    }

    /// Whole leaves become tiles (when the grid has no channels) and complete 128^3 groups
    /// of tiles become node tiles.
    pub fn compact(&mut self) {
        if self.channels != Channels::NONE {
            return;
        }
        let whole = self.leaves.iter().filter(|l| l.mask == FULL).count();
        if whole > 0 {
            for leaf in self.leaves.iter().filter(|l| l.mask == FULL) {
                self.tiles.insert_leaf(leaf.origin);
            }
            self.leaves.retain(|l| l.mask != FULL);
            self.reindex();
        }
        self.tiles.promote();
    }
}

/// The voxels of the 8^3 block at `origin` that lie in `keep`, as a leaf mask.
fn block_mask(origin: Coord, keep: &CoordBox) -> [u64; 8] {
    let range = |a: usize| {
        [
            (keep.min[a] - origin[a]).max(0),
            (keep.max[a] - origin[a]).min(7),
        ]
    };
    let ([x0, x1], [y0, y1], [z0, z1]) = (range(0), range(1), range(2));
    let mut mask = [0u64; 8];
    if x0 > x1 || y0 > y1 || z0 > z1 {
        return mask;
    }
    let row = ((1u64 << (z1 - z0 + 1)) - 1) << z0;
    let word = (y0..=y1).fold(0u64, |w, y| w | row << (y * 8));
    for x in x0..=x1 {
        mask[x as usize] = word;
    }
    mask
}

/// ORs `src` into `dst`, taking `src`'s channels only where `dst` was empty.
fn union_leaf(dst: &mut Leaf, src: &Leaf) {
    for w in 0..8 {
        let new = src.mask[w] & !dst.mask[w];
        let mut b = new;
        while b != 0 {
            let n = w * 64 + b.trailing_zeros() as usize;
            dst.copy_channels_from(src, n);
            b &= b - 1;
        }
        dst.mask[w] |= src.mask[w];
    }
}

/// Write access with a one-leaf cache: consecutive writes into the same leaf skip the hash.
pub struct Accessor<'g> {
    grid: &'g mut SparseGrid,
    cached_origin: Coord,
    cached_index: usize,
}

impl Accessor<'_> {
    /// The leaf holding `c` (created when missing) and the offset of `c` in it.
    #[inline]
    pub fn leaf_mut(&mut self, c: Coord) -> (&mut Leaf, usize) {
        let origin = leaf_origin(c);
        if origin != self.cached_origin {
            self.cached_index = self.grid.leaf_index_or_insert(origin);
            self.cached_origin = origin;
        }
        (&mut self.grid.leaves[self.cached_index], leaf_offset(c))
    }

    #[inline]
    pub fn insert(&mut self, c: Coord) {
        let (leaf, n) = self.leaf_mut(c);
        leaf.set_on(n);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(coords: &[Coord]) -> SparseGrid {
        let mut g = SparseGrid::default();
        let mut acc = g.accessor();
        coords.iter().for_each(|&c| acc.insert(c));
        g
    }

    #[test]
    fn counts_bbox_and_membership() {
        let g = grid(&[[0, 0, 0], [9, -3, 2], [9, -3, 2], [-100, 5, 3000]]);
        assert_eq!(g.voxel_count(), 3);
        assert_eq!(g.leaf_count(), 3);
        assert!(g.contains([9, -3, 2]) && !g.contains([9, -3, 3]));
        let b = g.bbox().unwrap();
        assert_eq!(b.min, [-100, -3, 0]);
        assert_eq!(b.max, [9, 5, 3000]);
        let mut all: Vec<_> = g.voxels().collect();
        all.sort();
        assert_eq!(all, vec![[-100, 5, 3000], [0, 0, 0], [9, -3, 2]]);
    }

    #[test]
    fn bbox_from_masks_equals_the_voxels_box() {
        let mut rng = crate::random::SplitMix64(3);
        for round in 0..50 {
            let n = 1 + round % 9;
            let pts: Vec<Coord> = (0..n)
                .map(|_| [0, 1, 2].map(|_| rng.range(-40.0, 40.0).floor() as i64))
                .collect();
            let g = grid(&pts);
            let mut expected = CoordBox::point(pts[0]);
            for &p in &pts {
                expected.expand(p);
            }
            assert_eq!(g.bbox(), Some(expected), "{pts:?}");
        }
    }

    #[test]
    fn clip_keeps_exactly_the_voxels_in_the_box() {
        // A whole 128^3 node, a whole 8^3 block and scattered voxels, cut by boxes.
        let mut rng = crate::random::SplitMix64(11);
        let scattered: Vec<Coord> = (0..300)
            .map(|_| [0, 1, 2].map(|_| rng.range(-20.0, 150.0).floor() as i64))
            .collect();
        let mut g = grid(&scattered);
        g.fill_node_block([0, 0, 0]);
        g.fill_leaf_block([-16, 0, 8]);
        g.compact();
        let all: Vec<Coord> = g.voxels().collect();
        for keep in [
            CoordBox {
                min: [3, -5, 10],
                max: [60, 130, 127],
            },
            CoordBox {
                min: [-20, -20, -20],
                max: [200, 200, 200],
            },
            CoordBox {
                min: [-13, 2, 9],
                max: [-9, 6, 14],
            },
            CoordBox {
                min: [500, 0, 0],
                max: [501, 1, 1],
            },
        ] {
            let mut clipped = g.clone();
            clipped.clip(keep);
            let expected = all.iter().filter(|&&c| keep.contains(c)).count() as u64;
            assert_eq!(clipped.voxel_count(), expected, "{keep:?}");
            assert!(clipped.voxels().all(|c| keep.contains(c)), "{keep:?}");
        }
    }

    #[test]
    fn boolean_operations_match_set_algebra() {
        let a_pts: Vec<Coord> = (0..40).map(|i| [i, i % 7, -i]).collect();
        let b_pts: Vec<Coord> = (20..60).map(|i| [i, i % 7, -i]).collect();
        let (a, b) = (grid(&a_pts), grid(&b_pts));
        let mut u = a.clone();
        u.union(&b);
        let mut i = a.clone();
        i.intersection(&b);
        let mut d = a.clone();
        d.difference(&b);
        assert_eq!(u.voxel_count(), 60);
        assert_eq!(i.voxel_count(), 20);
        assert_eq!(d.voxel_count(), 20);
        assert!(i.voxels().all(|c| c[0] >= 20 && c[0] < 40));
        assert!(d.voxels().all(|c| c[0] < 20));
    }

    /// A grid of scattered voxels, whole 8^3 blocks and whole 128^3 blocks, and its voxels.
    fn tiled(rng: &mut crate::random::SplitMix64) -> (SparseGrid, FxHashSet<Coord>) {
        let mut g = SparseGrid::default();
        let mut set = FxHashSet::default();
        let mut pick = |lo: f64, hi: f64| rng.range(lo, hi).floor() as i64;
        for _ in 0..300 {
            let c = [pick(-140.0, 140.0), pick(-140.0, 140.0), pick(-20.0, 20.0)];
            g.insert(c);
            set.insert(c);
        }
        let mut blocks: Vec<(Coord, i64)> = Vec::new();
        for _ in 0..12 {
            blocks.push((
                [
                    pick(-16.0, 16.0) * 8,
                    pick(-16.0, 16.0) * 8,
                    pick(-3.0, 3.0) * 8,
                ],
                8,
            ));
        }
        blocks.push(([pick(-1.0, 1.0) * 128, 0, -128], 128));
        for (o, d) in blocks {
            if d == 8 {
                g.fill_leaf_block(o);
            } else {
                g.fill_node_block(o);
            }
            for x in 0..d {
                for y in 0..d {
                    for z in 0..d {
                        set.insert([o[0] + x, o[1] + y, o[2] + z]);
                    }
                }
            }
        }
        g.compact();
        (g, set)
    }

    fn voxel_set(g: &SparseGrid) -> FxHashSet<Coord> {
        let set: FxHashSet<Coord> = g.voxels().collect();
        assert_eq!(set.len() as u64, g.voxel_count(), "a voxel listed twice");
        set
    }

    #[test]
    fn booleans_with_tiles_match_set_algebra() {
        let mut rng = crate::random::SplitMix64(11);
        for round in 0..3 {
            let (a, sa) = tiled(&mut rng);
            let (b, sb) = tiled(&mut rng);
            assert_eq!(voxel_set(&a), sa);
            assert!(a.tiles().node_tiles().count() == 1, "round {round}");
            let mut u = a.clone();
            u.union(&b);
            assert_eq!(voxel_set(&u), &sa | &sb, "union, round {round}");
            let mut i = a.clone();
            i.intersection(&b);
            assert_eq!(voxel_set(&i), &sa & &sb, "intersection, round {round}");
            let mut d = a.clone();
            d.difference(&b);
            assert_eq!(voxel_set(&d), &sa - &sb, "difference, round {round}");
            for c in sa.iter().take(500) {
                assert!(a.contains(*c));
            }
            let bbox = a.bbox().unwrap();
            for c in &sa {
                assert!(bbox.contains(*c));
            }
        }
    }

    #[test]
    fn coordinates_beyond_2048_cubed_do_not_overflow() {
        let big = 1i64 << 33;
        let g = grid(&[[big, -big, big + 7], [-big, big, 0]]);
        assert!(g.contains([big, -big, big + 7]));
        assert_eq!(g.bbox().unwrap().max[0], big);
    }
}

//! Constant active regions of a sparse grid, held as origins without per-voxel storage:
//! whole 8^3 blocks (OpenVDB's tiles in a level-1 internal node) and whole 128^3 blocks
//! (tiles in a level-2 node). A solid's inside is mostly such blocks, so it costs a bit per
//! block under its 128^3 node instead of hundreds of thousands of leaves.

use super::bits;
use super::coord::{Coord, CoordBox};
use rustc_hash::{FxHashMap, FxHashSet};

/// Edge of a node tile in voxels (16 leaves of 8).
pub const NODE_DIM: i64 = 128;
/// The 8^3 blocks of a node tile.
pub const NODE_LEAVES: usize = 4096;

/// Origin of the 128^3 node holding `c`: each coordinate rounded down to a multiple of 128.
#[inline]
pub fn node_origin(c: Coord) -> Coord {
    c.map(|v| v & !(NODE_DIM - 1))
}

/// The origins of the 4096 leaves of the node at `origin`.
pub fn node_leaf_origins(origin: Coord) -> impl Iterator<Item = Coord> {
    (0..16i64).flat_map(move |x| {
        (0..16i64).flat_map(move |y| {
            (0..16i64).map(move |z| [origin[0] + 8 * x, origin[1] + 8 * y, origin[2] + 8 * z])
        })
    })
}

/// The 8^3 blocks of one 128^3 node that are whole: a bit per block, in
/// `node_leaf_origins` order.
#[derive(Clone, Debug)]
struct NodeBlocks {
    bits: Box<[u64; NODE_LEAVES / 64]>,
    count: u32,
}

impl Default for NodeBlocks {
    fn default() -> Self {
        NodeBlocks {
            bits: Box::new([0; NODE_LEAVES / 64]),
            count: 0,
        }
    }
}

// Counted by branches: the branchless form (`count -= u32::from(was)`) came out of rustc
// 1.95's release build leaving the count unchanged when inlined into `Tiles::remove_leaf`
// (the unit test below caught it).
impl NodeBlocks {
    /// Sets block `slot`; whether it was not set before.
    fn insert(&mut self, slot: usize) -> bool {
        let new = !bits::get(&self.bits[..], slot);
        if new {
            bits::set(&mut self.bits[..], slot);
            self.count += 1;
        }
        new
    }

    /// Clears block `slot`; whether it was set.
    fn remove(&mut self, slot: usize) -> bool {
        let was = bits::get(&self.bits[..], slot);
        if was {
            bits::clear(&mut self.bits[..], slot);
            self.count -= 1;
        }
        was
    }
}

/// The slot of the 8^3 block at `leaf_origin` in its node, in `node_leaf_origins` order.
#[inline]
fn block_slot(leaf_origin: Coord) -> usize {
    let at = leaf_origin.map(|v| ((v & (NODE_DIM - 1)) >> 3) as usize);
    (at[0] << 8) | (at[1] << 4) | at[2]
}

/// Where block `slot` sits in its node, in blocks along x, y and z.
#[inline]
fn slot_position(slot: usize) -> [usize; 3] {
    [slot >> 8, (slot >> 4) & 15, slot & 15]
}

/// The origin of block `slot` of the node at `node`.
fn slot_origin(node: Coord, slot: usize) -> Coord {
    let at = slot_position(slot);
    std::array::from_fn(|a| node[a] + 8 * at[a] as i64)
}

/// Some 8^3 blocks of one 128^3 node, a bit per block as `Tiles` keeps them: made apart (on
/// any thread) and then made whole together (`Tiles::insert_node_mask`).
pub struct NodeMask {
    node: Coord,
    bits: [u64; NODE_LEAVES / 64],
}

impl NodeMask {
    /// No block of the node at `node` (a multiple of 128).
    pub fn new(node: Coord) -> Self {
        debug_assert_eq!(node_origin(node), node, "a node's origin");
        NodeMask {
            node,
            bits: [0; NODE_LEAVES / 64],
        }
    }

    pub fn node(&self) -> Coord {
        self.node
    }

    /// Adds the 8^3 block at `leaf_origin`, which must lie in the node.
    #[inline]
    pub fn insert(&mut self, leaf_origin: Coord) {
        debug_assert_eq!(node_origin(leaf_origin), self.node, "a block of the node");
        bits::set(&mut self.bits[..], block_slot(leaf_origin));
    }
}

/// Whole 8^3 blocks are kept as a bit per block under their 128^3 node (a solid's inside has
/// hundreds of thousands of them in a few hundred nodes: setting, testing and copying bits is
/// what keeps making and combining solids cheap), whole 128^3 blocks by their origin.
#[derive(Clone, Debug, Default)]
pub struct Tiles {
    /// Whole 8^3 blocks by the node holding them, none in a node tile; no node without one.
    leaves: FxHashMap<Coord, NodeBlocks>,
    /// How many 8^3 blocks `leaves` holds.
    leaf_count: usize,
    /// Origins of whole 128^3 blocks.
    nodes: FxHashSet<Coord>,
}

/// Bytes the tiles of a grid take at the peak: a node's 8^3 blocks (their bits and the map's
/// entry, at the map's load after growing) and a node tile's set entry, each with its copy
/// while a grid is read or combined.
const NODE_BLOCKS_BYTES: u64 = 1280;
const NODE_TILE_BYTES: u64 = 64;

impl Tiles {
    /// The tiles, 8^3 and 128^3.
    pub fn count(&self) -> u64 {
        (self.leaf_count + self.nodes.len()) as u64
    }

    pub fn is_empty(&self) -> bool {
        self.leaf_count == 0 && self.nodes.is_empty()
    }

    /// Bytes the tiles take at the peak (`NODE_BLOCKS_BYTES`).
    pub fn bytes(&self) -> u64 {
        tile_bytes(self.leaves.len() as u64, self.nodes.len() as u64)
    }

    /// Whether the 8^3 block at `leaf_origin` is whole.
    #[inline]
    pub fn covers(&self, leaf_origin: Coord) -> bool {
        if self.is_empty() {
            return false;
        }
        let node = node_origin(leaf_origin);
        self.leaves
            .get(&node)
            .is_some_and(|b| bits::get(&b.bits[..], block_slot(leaf_origin)))
            || self.nodes.contains(&node)
    }

    pub fn voxel_count(&self) -> u64 {
        self.leaf_count as u64 * 512 + self.nodes.len() as u64 * (NODE_DIM as u64).pow(3)
    }

    /// Origins of the 8^3 tiles.
    pub fn leaf_tiles(&self) -> impl Iterator<Item = Coord> + '_ {
        self.leaf_tile_masks()
            .flat_map(|(node, mask)| bits::ones(&mask[..]).map(move |s| slot_origin(node, s)))
    }

    /// The nodes holding 8^3 tiles, each with its tiles as a bit per slot: a slot numbers the
    /// blocks in `node_leaf_origins` order, OpenVDB's order of a 128^3 node's children (x,
    /// then y, then z, 16 each).
    pub fn leaf_tile_masks(&self) -> impl Iterator<Item = (Coord, &[u64; NODE_LEAVES / 64])> + '_ {
        self.leaves.iter().map(|(&node, b)| (node, &*b.bits))
    }

    /// Origins of the 128^3 tiles.
    pub fn node_tiles(&self) -> impl Iterator<Item = Coord> + '_ {
        self.nodes.iter().copied()
    }

    pub fn has_node(&self, origin: Coord) -> bool {
        self.nodes.contains(&origin)
    }

    /// The origin of every whole 8^3 block, node tiles' included.
    pub fn blocks(&self) -> impl Iterator<Item = Coord> + '_ {
        self.leaf_tiles()
            .chain(self.node_tiles().flat_map(node_leaf_origins))
    }

    /// Every tile as its origin and edge (8 or 128): leaf tiles first.
    pub fn with_edges(&self) -> impl Iterator<Item = (Coord, i64)> + '_ {
        self.leaf_tiles()
            .map(|o| (o, 8))
            .chain(self.node_tiles().map(|o| (o, NODE_DIM)))
    }

    /// Every tile as its box of voxels.
    pub fn boxes(&self) -> impl Iterator<Item = CoordBox> + '_ {
        self.with_edges().map(|(o, d)| CoordBox {
            min: o,
            max: o.map(|v| v + d - 1),
        })
    }

    /// The box of the tiles' voxels, `None` without tiles: a node's 8^3 tiles bounded by their
    /// slots, not box by box.
    pub fn bbox(&self) -> Option<CoordBox> {
        let leaf_boxes = self.leaf_tile_masks().map(|(node, mask)| {
            let (mut lo, mut hi) = ([usize::MAX; 3], [0; 3]);
            for s in bits::ones(&mask[..]) {
                let at = slot_position(s);
                lo = std::array::from_fn(|a| lo[a].min(at[a]));
                hi = std::array::from_fn(|a| hi[a].max(at[a]));
            }
            CoordBox {
                min: std::array::from_fn(|a| node[a] + 8 * lo[a] as i64),
                max: std::array::from_fn(|a| node[a] + 8 * hi[a] as i64 + 7),
            }
        });
        let node_boxes = self.node_tiles().map(|o| CoordBox {
            min: o,
            max: o.map(|v| v + NODE_DIM - 1),
        });
        leaf_boxes.chain(node_boxes).reduce(|a, b| a.union(&b))
    }

    /// Makes the 8^3 block at `origin` whole.
    pub fn insert_leaf(&mut self, origin: Coord) {
        self.insert_leaves_of_node(node_origin(origin), [origin]);
    }

    /// Makes the 8^3 blocks at `origins`, all in the 128^3 node at `node`, whole, as
    /// `insert_leaf` does one by one: the node is looked up once.
    pub fn insert_leaves_of_node(&mut self, node: Coord, origins: impl IntoIterator<Item = Coord>) {
        if !self.nodes.contains(&node) {
            let blocks = self.leaves.entry(node).or_default();
            for origin in origins {
                debug_assert_eq!(node_origin(origin), node, "a block of the node");
                self.leaf_count += usize::from(blocks.insert(block_slot(origin)));
            }
        }
    }

    /// Makes the 8^3 blocks of `mask` whole, as `insert_leaves_of_node` does.
    pub fn insert_node_mask(&mut self, mask: &NodeMask) {
        if !self.nodes.contains(&mask.node) {
            let blocks = self.leaves.entry(mask.node).or_default();
            let mut added = 0;
            for (word, &new) in blocks.bits.iter_mut().zip(&mask.bits) {
                added += (new & !*word).count_ones();
                *word |= new;
            }
            blocks.count += added;
            self.leaf_count += added as usize;
        }
    }

    /// Makes the 128^3 block at `origin` whole, absorbing its 8^3 tiles.
    pub fn insert_node(&mut self, origin: Coord) {
        if self.nodes.insert(origin)
            && let Some(blocks) = self.leaves.remove(&origin)
        {
            self.leaf_count -= blocks.count as usize;
        }
    }

    /// Takes the 8^3 block at `origin` out of the tiles (splitting its node tile); returns
    /// whether it was whole.
    pub fn remove_leaf(&mut self, origin: Coord) -> bool {
        let node = node_origin(origin);
        if let Some(blocks) = self.leaves.get_mut(&node) {
            if !blocks.remove(block_slot(origin)) {
                return false;
            }
            self.leaf_count -= 1;
            if blocks.count == 0 {
                self.leaves.remove(&node);
            }
            return true;
        }
        if !self.nodes.remove(&node) {
            return false;
        }
        let mut blocks = NodeBlocks {
            bits: Box::new([u64::MAX; NODE_LEAVES / 64]),
            count: NODE_LEAVES as u32,
        };
        blocks.remove(block_slot(origin));
        self.leaf_count += NODE_LEAVES - 1;
        self.leaves.insert(node, blocks);
        true
    }

    /// Drops the node tile at `origin` and returns whether it was there (its leaves are not
    /// kept as tiles).
    pub fn remove_node(&mut self, origin: Coord) -> bool {
        self.nodes.remove(&origin)
    }

    /// Replaces every complete group of 4096 leaf tiles by its node tile.
    pub fn promote(&mut self) {
        let whole: Vec<Coord> = self
            .leaves
            .iter()
            .filter(|(_, b)| b.count as usize == NODE_LEAVES)
            .map(|(&node, _)| node)
            .collect();
        whole.into_iter().for_each(|node| self.insert_node(node));
    }

    /// Removes every tile.
    pub fn clear(&mut self) {
        self.leaves.clear();
        self.leaf_count = 0;
        self.nodes.clear();
    }
}

/// Bytes at the peak of the tiles of `nodes_with_blocks` nodes holding 8^3 tiles and
/// `node_tiles` 128^3 tiles.
pub fn tile_bytes(nodes_with_blocks: u64, node_tiles: u64) -> u64 {
    nodes_with_blocks
        .saturating_mul(NODE_BLOCKS_BYTES)
        .saturating_add(node_tiles.saturating_mul(NODE_TILE_BYTES))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn leaf_tiles_promote_to_a_node_tile_and_split_back() {
        let mut t = Tiles::default();
        for o in node_leaf_origins([128, -128, 0]) {
            t.insert_leaf(o);
        }
        assert_eq!(t.voxel_count(), 128 * 128 * 128);
        t.promote();
        assert_eq!(t.node_tiles().count(), 1);
        assert_eq!(t.leaf_tiles().count(), 0);
        assert!(t.covers([128 + 120, -8, 64]));
        assert!(!t.covers([0, 0, 0]));
        assert!(t.remove_leaf([136, -128, 8]));
        assert_eq!(t.node_tiles().count(), 0);
        assert_eq!(t.leaf_tiles().count(), 4095);
        assert!(!t.covers([136, -128, 8]));
        assert_eq!(node_origin([-1, 127, 128]), [-128, 0, 128]);
    }

    #[test]
    fn leaf_tiles_are_kept_per_node_and_counted_once() {
        let mut t = Tiles::default();
        let origins = [
            [0, 0, 0],
            [120, 8, 64],
            [-8, 0, 0],
            [-128, -8, 120],
            [0, 0, 0],
        ];
        origins.iter().for_each(|&o| t.insert_leaf(o));
        assert_eq!(t.count(), 4);
        assert_eq!(t.bytes(), tile_bytes(3, 0));
        let mut listed: Vec<Coord> = t.leaf_tiles().collect();
        listed.sort_unstable();
        let mut expected = origins[..4].to_vec();
        expected.sort_unstable();
        assert_eq!(listed, expected);
        assert!(origins.iter().all(|&o| t.covers(o)));
        assert!(!t.covers([8, 0, 0]) && !t.remove_leaf([8, 0, 0]));
        assert!(t.remove_leaf([-8, 0, 0]));
        assert!(!t.covers([-8, 0, 0]));
        assert_eq!((t.count(), t.bytes()), (3, tile_bytes(2, 0)));
        let boxes = t.boxes().reduce(|a, b| a.union(&b));
        assert_eq!(t.bbox(), boxes);
        assert_eq!(t.bbox().unwrap().min, [-128, -8, 0]);
        t.insert_node([0, 0, 0]);
        assert_eq!((t.count(), t.voxel_count()), (2, 512 + 128 * 128 * 128));
        assert_eq!(t.bbox().unwrap().max, [127, 127, 127]);
    }
}

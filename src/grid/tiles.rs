//! Constant active regions of a sparse grid, held as origins without per-voxel storage:
//! whole 8^3 blocks (OpenVDB's tiles in a level-1 internal node) and whole 128^3 blocks
//! (tiles in a level-2 node). A solid's inside is mostly such blocks, so it costs a few
//! hash entries instead of hundreds of thousands of leaves.

use super::coord::{Coord, CoordBox};
use rustc_hash::FxHashSet;

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

#[derive(Clone, Debug, Default)]
pub struct Tiles {
    /// Origins of whole 8^3 blocks, none inside a node tile.
    leaves: FxHashSet<Coord>,
    /// Origins of whole 128^3 blocks.
    nodes: FxHashSet<Coord>,
}

/// Bytes a tile takes in a grid at the peak: its hash-set entry (an origin, its control byte)
/// at the set's load after growing, and its copy while a grid is read or combined.
pub const TILE_BYTES: u64 = 64;

impl Tiles {
    /// The tiles, 8^3 and 128^3.
    pub fn count(&self) -> u64 {
        (self.leaves.len() + self.nodes.len()) as u64
    }

    pub fn is_empty(&self) -> bool {
        self.leaves.is_empty() && self.nodes.is_empty()
    }

    /// Whether the 8^3 block at `leaf_origin` is whole.
    #[inline]
    pub fn covers(&self, leaf_origin: Coord) -> bool {
        !self.is_empty()
            && (self.leaves.contains(&leaf_origin)
                || self.nodes.contains(&node_origin(leaf_origin)))
    }

    pub fn voxel_count(&self) -> u64 {
        self.leaves.len() as u64 * 512 + self.nodes.len() as u64 * (NODE_DIM as u64).pow(3)
    }

    /// Origins of the 8^3 tiles.
    pub fn leaf_tiles(&self) -> impl Iterator<Item = Coord> + '_ {
        self.leaves.iter().copied()
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

    /// Makes the 8^3 block at `origin` whole.
    pub fn insert_leaf(&mut self, origin: Coord) {
        if !self.nodes.contains(&node_origin(origin)) {
            self.leaves.insert(origin);
        }
    }

    /// Room for `n` more 8^3 tiles.
    pub fn reserve_leaves(&mut self, n: usize) {
        self.leaves.reserve(n);
    }

    /// Makes the 8^3 blocks at `origins` whole, where no node tile holds any of them.
    pub fn insert_leaves_off_nodes(&mut self, origins: &[Coord]) {
        debug_assert!(
            origins
                .iter()
                .all(|&o| !self.nodes.contains(&node_origin(o)))
        );
        self.leaves.extend(origins.iter().copied());
    }

    /// Makes the 128^3 block at `origin` whole, absorbing its 8^3 tiles.
    pub fn insert_node(&mut self, origin: Coord) {
        if self.nodes.insert(origin) {
            if self.leaves.len() < NODE_LEAVES {
                self.leaves.retain(|&o| node_origin(o) != origin);
            } else {
                for o in node_leaf_origins(origin) {
                    self.leaves.remove(&o);
                }
            }
        }
    }

    /// Takes the 8^3 block at `origin` out of the tiles (splitting its node tile); returns
    /// whether it was whole.
    pub fn remove_leaf(&mut self, origin: Coord) -> bool {
        if self.leaves.remove(&origin) {
            return true;
        }
        let node = node_origin(origin);
        if !self.nodes.remove(&node) {
            return false;
        }
        self.leaves
            .extend(node_leaf_origins(node).filter(|&o| o != origin));
        true
    }

    /// Drops the node tile at `origin` and returns whether it was there (its leaves are not
    /// kept as tiles).
    pub fn remove_node(&mut self, origin: Coord) -> bool {
        self.nodes.remove(&origin)
    }

    /// Replaces every complete group of 4096 leaf tiles by its node tile.
    pub fn promote(&mut self) {
        let mut per_node: rustc_hash::FxHashMap<Coord, u32> = Default::default();
        for &o in &self.leaves {
            *per_node.entry(node_origin(o)).or_default() += 1;
        }
        for (node, n) in per_node {
            if n as usize == NODE_LEAVES {
                self.insert_node(node);
            }
        }
    }

    /// Removes every tile.
    pub fn clear(&mut self) {
        self.leaves.clear();
        self.nodes.clear();
    }
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
}

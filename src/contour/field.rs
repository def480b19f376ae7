//! What a grid means as a scalar field to contour: a value at every voxel centre, negative
//! inside. A level set's values less the iso value (inside its negative tiles, outside
//! elsewhere beyond its leaves); a fog volume's iso value less its density (tiles hold the
//! density 1, empty space 0); a voxel set's -1/2 on its voxels and tiles, +1/2 elsewhere, so
//! that its surface passes half way between a voxel and an empty neighbour.

use crate::grid::{Block, Channels, Coord, Leaf, SparseGrid, offset_coord};
use rayon::prelude::*;
use std::borrow::Cow;

/// How a grid's contents are read as values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Meaning {
    /// Signed distances, negative inside; beyond the leaves `outside` (and `-outside` in the
    /// negative tiles).
    LevelSet { outside: f32 },
    /// A density: inside where it exceeds the iso value; tiles are taken as density 1.
    Fog,
    /// A voxel set (no values): inside on its voxels and tiles.
    Voxels,
}

/// The signs of a block's values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlockSign {
    Inside,
    Outside,
    Both,
}

impl BlockSign {
    fn of(value: f32) -> BlockSign {
        if value < 0.0 {
            BlockSign::Inside
        } else {
            BlockSign::Outside
        }
    }
}

/// A grid read as a field, with the iso value of the surface wanted.
pub struct ScalarField<'g> {
    pub grid: Cow<'g, SparseGrid>,
    pub meaning: Meaning,
    pub iso: f32,
}

impl<'g> ScalarField<'g> {
    /// The field of a level set grid (leaves holding every voxel's value, tiles only where
    /// negative), or none when `iso` lies beyond its band: beyond the leaves its values are the
    /// largest magnitude they hold, the band's edge, signed by the tiles.
    pub fn level_set(grid: SparseGrid, iso: f32) -> Option<ScalarField<'g>> {
        let outside = grid
            .leaves()
            .iter()
            .filter_map(|l| l.value.as_ref())
            .flat_map(|v| v.iter())
            .fold(0f32, |m, v| m.max(v.abs()));
        (iso.abs() < outside).then_some(ScalarField {
            grid: Cow::Owned(grid),
            meaning: Meaning::LevelSet { outside },
            iso,
        })
    }

    /// The field of a distance band held in memory: distances on `band`'s voxels, elsewhere
    /// `-background` in `interior` (a level set's inside) and `background` beyond it (an
    /// unsigned band has no interior); none when `iso` lies beyond the band.
    pub fn from_band(
        band: &SparseGrid,
        background: f32,
        interior: Option<&SparseGrid>,
        iso: f32,
    ) -> Option<ScalarField<'g>> {
        if iso.abs() >= background {
            return None;
        }
        let inside = |c: Coord| interior.is_some_and(|g| g.contains(c));
        let sign = |c: Coord| if inside(c) { -background } else { background };
        let mut leaves: Vec<Leaf> = band
            .leaves()
            .par_iter()
            .map(|l| {
                let mut leaf = Leaf::new(l.origin, Channels::VALUE);
                leaf.mask = l.mask;
                let values = leaf.value.as_mut().expect("a value leaf");
                for (n, v) in values.iter_mut().enumerate() {
                    *v = match &l.value {
                        Some(d) if l.is_on(n) => d[n],
                        _ => sign(offset_coord(l.origin, n)),
                    };
                }
                leaf
            })
            .collect();
        if let Some(interior) = interior {
            leaves.extend(
                interior
                    .leaves()
                    .iter()
                    .filter(|l| band.leaf(l.origin).is_none())
                    .map(|l| {
                        let mut leaf = Leaf::new(l.origin, Channels::VALUE);
                        let values = leaf.value.as_mut().expect("a value leaf");
                        for (n, v) in values.iter_mut().enumerate() {
                            *v = if l.is_on(n) { -background } else { background };
                        }
                        leaf
                    }),
            );
        }
        let mut grid = SparseGrid::from_distinct_leaves(band.transform, Channels::VALUE, leaves);
        if let Some(interior) = interior {
            // Band leaves inside a tile keep their distances (a block with a leaf is not whole).
            interior
                .tiles()
                .leaf_tiles()
                .for_each(|o| grid.fill_leaf_block(o));
            interior
                .tiles()
                .node_tiles()
                .for_each(|o| grid.fill_node_block(o));
        }
        Some(ScalarField {
            grid: Cow::Owned(grid),
            meaning: Meaning::LevelSet {
                outside: background,
            },
            iso,
        })
    }

    /// Whether the voxels' values steer the vertices (level sets and fog), or only the
    /// crossings do (voxel sets, whose values are steps).
    pub fn has_gradients(&self) -> bool {
        self.meaning != Meaning::Voxels
    }

    fn whole(&self) -> f32 {
        match self.meaning {
            Meaning::LevelSet { outside } => -outside - self.iso,
            Meaning::Fog => self.iso - 1.0,
            Meaning::Voxels => -0.5,
        }
    }

    fn empty(&self) -> f32 {
        match self.meaning {
            Meaning::LevelSet { outside } => outside - self.iso,
            Meaning::Fog => self.iso,
            Meaning::Voxels => 0.5,
        }
    }

    fn in_leaf(&self, leaf: &Leaf, n: usize) -> f32 {
        match (self.meaning, leaf.value.as_ref()) {
            (Meaning::LevelSet { .. }, Some(v)) => v[n] - self.iso,
            (Meaning::Fog, Some(v)) if leaf.is_on(n) => self.iso - v[n],
            (Meaning::Fog, _) => self.iso,
            _ => {
                if leaf.is_on(n) {
                    -0.5
                } else {
                    0.5
                }
            }
        }
    }

    /// The signs of the values in the 8^3 block `block` holds (tiles and empty space are of
    /// one sign).
    pub fn block_sign(&self, block: Block) -> BlockSign {
        match block {
            Block::Empty => BlockSign::of(self.empty()),
            Block::Whole => BlockSign::of(self.whole()),
            Block::Partial(leaf) => {
                let first = BlockSign::of(self.in_leaf(leaf, 0));
                if (1..512).all(|n| BlockSign::of(self.in_leaf(leaf, n)) == first) {
                    first
                } else {
                    BlockSign::Both
                }
            }
        }
    }

    /// The values of the `edge`^3 voxels from `low` on, x slowest, into `out`.
    pub fn gather(&self, low: Coord, edge: usize, out: &mut Vec<f32>) {
        out.clear();
        out.resize(edge * edge * edge, 0.0);
        let (whole, empty) = (self.whole(), self.empty());
        let e = edge as i64;
        // The 8^3 blocks the box touches, each looked up once.
        let first = low.map(|v| v.div_euclid(8) * 8);
        let last = low.map(|v| (v + e - 1).div_euclid(8) * 8);
        let mut bx = first[0];
        while bx <= last[0] {
            let mut by = first[1];
            while by <= last[1] {
                let mut bz = first[2];
                while bz <= last[2] {
                    let origin = [bx, by, bz];
                    let block = self.grid.block(origin);
                    let lo = [0, 1, 2].map(|a| origin[a].max(low[a]));
                    let hi = [0, 1, 2].map(|a| (origin[a] + 8).min(low[a] + e));
                    for x in lo[0]..hi[0] {
                        for y in lo[1]..hi[1] {
                            let row = ((x - low[0]) * e + (y - low[1])) * e;
                            for z in lo[2]..hi[2] {
                                out[(row + z - low[2]) as usize] = match block {
                                    Block::Empty => empty,
                                    Block::Whole => whole,
                                    Block::Partial(leaf) => {
                                        let n = ((x - bx) << 6 | (y - by) << 3 | (z - bz)) as usize;
                                        self.in_leaf(leaf, n)
                                    }
                                };
                            }
                        }
                    }
                    bz += 8;
                }
                by += 8;
            }
            bx += 8;
        }
    }
}

//! A dense bit volume over a box of voxel indices, for whole-volume passes (flooding,
//! inside classification, neighbourhood tests) where hashing per voxel would dominate.

use super::bits;
use super::coord::{Coord, CoordBox};
use super::sparse::SparseGrid;
use crate::error::{Error, Result};

#[derive(Clone, Debug)]
pub struct DenseMask {
    pub bbox: CoordBox,
    dims: [usize; 3],
    bits: Vec<u64>,
}

/// The most voxels a dense volume holds (2 GiB of bits).
pub const MAX_DENSE_VOXELS: u64 = 1 << 34;

impl DenseMask {
    /// An all-clear volume over `bbox`; refuses boxes over `MAX_DENSE_VOXELS`.
    pub fn new(bbox: CoordBox) -> Result<Self> {
        let d = bbox.dim();
        let total = d[0].checked_mul(d[1]).and_then(|v| v.checked_mul(d[2]));
        match total {
            Some(n) if n <= MAX_DENSE_VOXELS => Ok(DenseMask {
                bbox,
                dims: d.map(|v| v as usize),
                bits: vec![0; (n as usize).div_ceil(64)],
            }),
            _ => Err(Error::TooLarge {
                estimated_mib: total.map_or(u64::MAX, |n| n / 8 / (1 << 20)),
                available_mib: 2048,
                detail: format!("a dense volume of {}x{}x{} voxels", d[0], d[1], d[2]),
            }),
        }
    }

    /// The active voxels of `grid` inside `bbox`, copied 8 voxels (a leaf row along z) at
    /// a time, tiles a whole row at a time.
    pub fn from_grid(grid: &SparseGrid, bbox: CoordBox) -> Result<Self> {
        let mut m = DenseMask::new(bbox)?;
        for leaf in grid.leaves() {
            let o = leaf.origin;
            // The part of the leaf's z row inside the box, as a bit range of the row.
            let z0 = (bbox.min[2] - o[2]).clamp(0, 8);
            let z1 = (bbox.max[2] - o[2] + 1).clamp(0, 8);
            if z0 >= z1 {
                continue;
            }
            let keep = (0xffu64 >> (8 - (z1 - z0))) << z0;
            for dx in 0..8 {
                let x = o[0] + dx;
                if x < bbox.min[0] || x > bbox.max[0] {
                    continue;
                }
                for dy in 0..8 {
                    let y = o[1] + dy;
                    let row = (leaf.mask[dx as usize] >> (dy * 8)) & keep;
                    if row != 0 && y >= bbox.min[1] && y <= bbox.max[1] {
                        let start = m.index([x, y, o[2] + z0]);
                        bits::or_bits(&mut m.bits, start, row >> z0);
                    }
                }
            }
        }
        for tile in grid.tiles().boxes() {
            m.set_box(tile);
        }
        Ok(m)
    }

    /// Sets the voxels of `b` that lie in the box, a z row at a time.
    pub fn set_box(&mut self, b: CoordBox) {
        let lo: Coord = std::array::from_fn(|a| b.min[a].max(self.bbox.min[a]));
        let hi: Coord = std::array::from_fn(|a| b.max[a].min(self.bbox.max[a]));
        if (0..3).any(|a| lo[a] > hi[a]) {
            return;
        }
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                let first = self.index([x, y, lo[2]]);
                self.set_index_range(first, first + (hi[2] - lo[2]) as usize);
            }
        }
    }

    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    pub fn len(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Linear index of `c`, which must lie in the box.
    #[inline]
    pub fn index(&self, c: Coord) -> usize {
        let x = (c[0] - self.bbox.min[0]) as usize;
        let y = (c[1] - self.bbox.min[1]) as usize;
        let z = (c[2] - self.bbox.min[2]) as usize;
        (x * self.dims[1] + y) * self.dims[2] + z
    }

    /// The coordinate of linear index `i`.
    pub fn coord(&self, i: usize) -> Coord {
        let z = i % self.dims[2];
        let y = (i / self.dims[2]) % self.dims[1];
        let x = i / (self.dims[1] * self.dims[2]);
        [
            self.bbox.min[0] + x as i64,
            self.bbox.min[1] + y as i64,
            self.bbox.min[2] + z as i64,
        ]
    }

    #[inline]
    pub fn get_index(&self, i: usize) -> bool {
        bits::get(&self.bits, i)
    }

    #[inline]
    pub fn set_index(&mut self, i: usize) {
        bits::set(&mut self.bits, i);
    }

    #[inline]
    pub fn clear_index(&mut self, i: usize) {
        bits::clear(&mut self.bits, i);
    }

    /// False outside the box.
    pub fn get(&self, c: Coord) -> bool {
        self.bbox.contains(c) && self.get_index(self.index(c))
    }

    pub fn set(&mut self, c: Coord) {
        let i = self.index(c);
        self.set_index(i);
    }

    /// Sets the voxels of linear indices `first..=last`.
    pub fn set_index_range(&mut self, first: usize, last: usize) {
        bits::set_range(&mut self.bits, first, last);
    }

    /// The voxels set in neither `a` nor `b` (same box).
    pub fn neither(a: &DenseMask, b: &DenseMask) -> DenseMask {
        assert_eq!(a.bbox, b.bbox, "masks over different boxes");
        let mut out = a.clone();
        for (o, w) in out.bits.iter_mut().zip(&b.bits) {
            *o = !(*o | w);
        }
        let tail = out.len() % 64;
        if tail != 0 {
            let last = out.bits.len() - 1;
            out.bits[last] &= (1u64 << tail) - 1;
        }
        out
    }

    /// The set voxels as a sparse grid on `transform`, built leaf by leaf from 8-voxel rows;
    /// whole blocks become tiles.
    pub fn to_grid(&self, transform: super::Transform) -> SparseGrid {
        let mut grid = SparseGrid::new(transform, super::Channels::NONE);
        let lo = super::coord::leaf_origin(self.bbox.min);
        let hi = self.bbox.max;
        let mut origin = lo;
        while origin[0] <= hi[0] {
            origin[1] = lo[1];
            while origin[1] <= hi[1] {
                origin[2] = lo[2];
                while origin[2] <= hi[2] {
                    let mut leaf = super::Leaf::new(origin, super::Channels::NONE);
                    let z0 = origin[2].max(self.bbox.min[2]);
                    let z1 = (origin[2] + 7).min(hi[2]);
                    for dx in 0..8 {
                        let x = origin[0] + dx;
                        if x < self.bbox.min[0] || x > hi[0] {
                            continue;
                        }
                        for dy in 0..8 {
                            let y = origin[1] + dy;
                            if y < self.bbox.min[1] || y > hi[1] {
                                continue;
                            }
                            let row = bits::range(
                                &self.bits,
                                self.index([x, y, z0]),
                                (z1 - z0 + 1) as usize,
                            );
                            leaf.mask[dx as usize] |= row << (dy * 8 + (z0 - origin[2]));
                        }
                    }
                    if leaf.mask == [u64::MAX; 8] {
                        grid.fill_leaf_block(origin);
                    } else if !leaf.is_empty() {
                        grid.merge_leaf(leaf, |_, _| {});
                    }
                    origin[2] += 8;
                }
                origin[1] += 8;
            }
            origin[0] += 8;
        }
        grid.compact();
        grid
    }

    /// The set voxels with a face neighbour that is clear (or outside the box).
    pub fn boundary(&self) -> DenseMask {
        let mut out = DenseMask {
            bbox: self.bbox,
            dims: self.dims,
            bits: vec![0; self.bits.len()],
        };
        for i in self.ones() {
            let c = self.coord(i);
            let exposed = (0..3).any(|a| {
                [-1, 1].iter().any(|&s| {
                    let mut n = c;
                    n[a] += s;
                    !self.get(n)
                })
            });
            if exposed {
                out.set_index(i);
            }
        }
        out
    }

    /// Combines `other` into `self` word by word with `f` (same box); `f` must map clear
    /// bits to clear bits (union, intersection, difference do).
    pub fn combine_words(&mut self, other: &DenseMask, f: impl Fn(u64, u64) -> u64) {
        assert_eq!(self.bbox, other.bbox, "masks over different boxes");
        for (o, w) in self.bits.iter_mut().zip(&other.bits) {
            *o = f(*o, *w);
        }
    }

    /// Up to 64 voxels of row `(x, y)` (offsets in the box) from `z` on, as the low bits of
    /// a word; clear for rows outside the box.
    pub fn row_bits(&self, x: i64, y: i64, z: usize, n: usize) -> u64 {
        let [nx, ny, nz] = self.dims;
        if x < 0 || y < 0 || x as usize >= nx || y as usize >= ny {
            return 0;
        }
        bits::range(&self.bits, (x as usize * ny + y as usize) * nz + z, n)
    }

    /// The voxels set in `self` but not in `other` (same box).
    pub fn minus(&self, other: &DenseMask) -> DenseMask {
        let mut out = self.clone();
        out.combine_words(other, |a, b| a & !b);
        out
    }

    pub fn count(&self) -> u64 {
        self.bits.iter().map(|w| w.count_ones() as u64).sum()
    }

    /// Linear indices of the set voxels.
    pub fn ones(&self) -> impl Iterator<Item = usize> + '_ {
        bits::ones(&self.bits)
    }

    /// Voxels set in both.
    pub fn and_count(&self, other: &DenseMask) -> u64 {
        assert_eq!(self.bbox, other.bbox, "masks over different boxes");
        self.bits
            .iter()
            .zip(&other.bits)
            .map(|(a, b)| (a & b).count_ones() as u64)
            .sum()
    }

    /// First voxel set in both.
    pub fn first_common(&self, other: &DenseMask) -> Option<Coord> {
        assert_eq!(self.bbox, other.bbox, "masks over different boxes");
        self.bits
            .iter()
            .zip(&other.bits)
            .position(|(a, b)| a & b != 0)
            .map(|w| {
                let bit = (self.bits[w] & other.bits[w]).trailing_zeros() as usize;
                self.coord(w * 64 + bit)
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::{Channels, Transform};
    use crate::random::SplitMix64;

    #[test]
    fn from_grid_copies_exactly_the_voxels_inside_the_box() {
        let mut rng = SplitMix64(9);
        let mut grid = SparseGrid::new(Transform::default(), Channels::NONE);
        let mut voxels = Vec::new();
        for _ in 0..4000 {
            let c = [0, 1, 2].map(|_| rng.range(-30.0, 30.0).floor() as i64);
            grid.insert(c);
            voxels.push(c);
        }
        // Boxes cutting leaves at every offset, and one holding everything.
        for (lo, hi) in [(-30, 29), (-13, 5), (-7, -5), (3, 21), (-31, 40)] {
            let bbox = CoordBox {
                min: [lo, lo + 1, lo - 2],
                max: [hi, hi - 1, hi + 3],
            };
            let mask = DenseMask::from_grid(&grid, bbox).unwrap();
            let mut expected = DenseMask::new(bbox).unwrap();
            for &c in voxels.iter().filter(|&&c| bbox.contains(c)) {
                expected.set(c);
            }
            assert_eq!(mask.bits, expected.bits, "box {bbox:?}");
        }
    }
}

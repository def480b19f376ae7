//! Integer voxel coordinates and their split into leaf origin and in-leaf offset.
//!
//! Coordinates are `i64` so grids of 2048^3 and far beyond never overflow; the `.vdb`
//! writer checks the `i32` range OpenVDB needs before it writes.

/// A voxel index `(i, j, k)`; voxel `(i,j,k)` is the unit cube centred on that integer point.
pub type Coord = [i64; 3];

/// Voxels per leaf.
pub const LEAF_VOXELS: usize = 512;

/// Origin of the leaf holding `c`: each coordinate rounded down to a multiple of 8.
#[inline]
pub fn leaf_origin(c: Coord) -> Coord {
    [c[0] & !7, c[1] & !7, c[2] & !7]
}

/// Offset of `c` inside its leaf, in OpenVDB's order `x * 64 + y * 8 + z`.
#[inline]
pub fn leaf_offset(c: Coord) -> usize {
    (((c[0] & 7) << 6) | ((c[1] & 7) << 3) | (c[2] & 7)) as usize
}

/// The coordinate of in-leaf offset `n` of the leaf at `origin`.
#[inline]
pub fn offset_coord(origin: Coord, n: usize) -> Coord {
    let n = n as i64;
    [
        origin[0] + (n >> 6),
        origin[1] + ((n >> 3) & 7),
        origin[2] + (n & 7),
    ]
}

/// An axis-aligned box of voxel indices, both corners inclusive.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CoordBox {
    pub min: Coord,
    pub max: Coord,
}

impl CoordBox {
    /// The box holding the single voxel `c`.
    pub fn point(c: Coord) -> Self {
        CoordBox { min: c, max: c }
    }

    /// Grows the box to hold `c`.
    pub fn expand(&mut self, c: Coord) {
        self.min = std::array::from_fn(|a| self.min[a].min(c[a]));
        self.max = std::array::from_fn(|a| self.max[a].max(c[a]));
    }

    /// The smallest box holding both.
    pub fn union(&self, other: &CoordBox) -> CoordBox {
        let mut b = *self;
        b.expand(other.min);
        b.expand(other.max);
        b
    }

    /// Number of voxels along each axis.
    pub fn dim(&self) -> [u64; 3] {
        [0, 1, 2].map(|a| (self.max[a] - self.min[a] + 1) as u64)
    }

    /// The voxels in both, or none.
    pub fn intersection(&self, other: &CoordBox) -> Option<CoordBox> {
        let b = CoordBox {
            min: std::array::from_fn(|a| self.min[a].max(other.min[a])),
            max: std::array::from_fn(|a| self.max[a].min(other.max[a])),
        };
        (0..3).all(|a| b.min[a] <= b.max[a]).then_some(b)
    }

    pub fn contains(&self, c: Coord) -> bool {
        (0..3).all(|a| c[a] >= self.min[a] && c[a] <= self.max[a])
    }
}

/// `floor(x)` as an integer, by truncation plus a fix-up (see `ceil_int`), for `x` within
/// i64's range: a planned grid's coordinates (the plan refuses grids it cannot index).
#[inline]
pub fn floor_int(x: f64) -> i64 {
    let h = x as i64;
    if (h as f64) > x { h - 1 } else { h }
}

/// `ceil(x)` as an integer, by truncation plus a fix-up: `f64::ceil` and `floor` are libm
/// calls without SSE4.1, which the x86-64 baseline lacks.
#[inline]
pub fn ceil_int(x: f64) -> i64 {
    let l = x as i64;
    if (l as f64) < x { l + 1 } else { l }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offsets_round_trip_for_negative_and_huge_coordinates() {
        for c in [
            [0, 0, 0],
            [-1, -8, -9],
            [7, 8, 15],
            [1 << 40, -(1 << 40) - 3, 5],
        ] {
            let o = leaf_origin(c);
            assert!(o.iter().all(|v| v % 8 == 0));
            assert_eq!(offset_coord(o, leaf_offset(c)), c);
        }
        assert_eq!(leaf_origin([-1, -8, -9]), [-8, -8, -16]);
    }
}

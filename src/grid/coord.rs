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

/// 1.5 * 2^52: a value of magnitude below 2^51 added to it is rounded to the nearest integer
/// (the sum's last place is 1), which the sum's low bits then hold.
const ROUNDING_BIAS: f64 = 6_755_399_441_055_744.0;
/// 2^51: the magnitudes `ROUNDING_BIAS` rounds exactly.
const BIASED_BELOW: f64 = 2_251_799_813_685_248.0;

/// `x` rounded to the nearest integer (ties to even), as a float and as an integer, for
/// `|x| < BIASED_BELOW`: two additions and a subtraction of bits, where a conversion to i64
/// also checks its range, and the fix-up converts back (the two took an eighth of the time
/// of the band's triangle prisms, and of its edges' wedges).
#[inline]
fn nearest(x: f64) -> (f64, i64) {
    let biased = x + ROUNDING_BIAS;
    (
        biased - ROUNDING_BIAS,
        biased.to_bits() as i64 - ROUNDING_BIAS.to_bits() as i64,
    )
}

/// `floor(x)` as an integer, for `x` within i64's range: a planned grid's coordinates (the plan
/// refuses grids it cannot index). Beyond 2^51 (and for NaN) by truncation plus a fix-up,
/// saturating as `as` does. `f64::floor` and `ceil` are libm calls without SSE4.1, which the
/// x86-64 baseline lacks.
#[inline]
pub fn floor_int(x: f64) -> i64 {
    if x.abs() < BIASED_BELOW {
        let (rounded, n) = nearest(x);
        n - i64::from(rounded > x)
    } else {
        let h = x as i64;
        if (h as f64) > x { h - 1 } else { h }
    }
}

/// `ceil(x)` as an integer, as `floor_int` finds it.
#[inline]
pub fn ceil_int(x: f64) -> i64 {
    if x.abs() < BIASED_BELOW {
        let (rounded, n) = nearest(x);
        n + i64::from(rounded < x)
    } else {
        let l = x as i64;
        if (l as f64) < x { l + 1 } else { l }
    }
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

    /// The rounding by `ROUNDING_BIAS` gives what truncation plus a fix-up gives (itself
    /// `f64::floor` and `ceil` where they fit i64), on integers, halves, values a few last
    /// places from them, values near 2^51 and beyond, infinities and NaN.
    #[test]
    fn biased_rounding_matches_truncation() {
        let by_truncation = |x: f64| {
            let t = x as i64;
            (
                if (t as f64) > x { t - 1 } else { t },
                if (t as f64) < x { t + 1 } else { t },
            )
        };
        let mut values = vec![
            0.0,
            -0.0,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
            5e-324,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            1e300,
            -1e300,
            9.3e18,
            -9.3e18,
        ];
        let mut random = crate::random::SplitMix64(11);
        for scale in [1.0, 1e3, 1e9, 1e15, BIASED_BELOW] {
            for _ in 0..20_000 {
                values.push(random.range(-scale, scale));
            }
        }
        for base in [
            0.0,
            1.0,
            2.5,
            -2.5,
            1e6,
            -7.5e9,
            BIASED_BELOW,
            -BIASED_BELOW,
        ] {
            for k in -3i64..=3 {
                let at = (base + k as f64).abs();
                for step in -4i64..=4 {
                    let near = f64::from_bits((at.to_bits() as i64 + step) as u64);
                    values.extend([near, -near, near + 0.5, -near - 0.5]);
                }
            }
        }
        for x in values {
            let (floor, ceil) = by_truncation(x);
            assert_eq!(floor_int(x), floor, "floor of {x:e}");
            assert_eq!(ceil_int(x), ceil, "ceil of {x:e}");
            if x.is_finite() && x.abs() < 9e18 {
                assert_eq!(floor_int(x), x.floor() as i64, "floor of {x:e}");
                assert_eq!(ceil_int(x), x.ceil() as i64, "ceil of {x:e}");
            }
        }
    }
}

//! What the projective scan carries besides position: nothing, or a colour, interpolated by
//! the same increments as the coordinates.

use glam::DVec3;

/// A value interpolated linearly along lines and across triangles.
pub trait Attribute: Copy + Send + Sync {
    /// Whether values are carried: which of several samples of a voxel is kept then matters.
    const CARRIED: bool = true;
    fn add(self, d: Self) -> Self;
    fn sub(self, o: Self) -> Self;
    fn scale(self, s: f64) -> Self;
    /// Component-wise `lo.min(hi) <= self <= lo.max(hi)` clamp: interpolation stops at the
    /// values of the primitive's vertices where a voxel centre lies just beyond it.
    fn clamp_between(self, lo: Self, hi: Self) -> Self;
    fn min(self, o: Self) -> Self;
    fn max(self, o: Self) -> Self;
}

/// No attribute: the scan compiles down to coordinates only.
impl Attribute for () {
    const CARRIED: bool = false;
    #[inline]
    fn add(self, _: Self) -> Self {}
    #[inline]
    fn sub(self, _: Self) -> Self {}
    #[inline]
    fn scale(self, _: f64) -> Self {}
    #[inline]
    fn clamp_between(self, _: Self, _: Self) -> Self {}
    #[inline]
    fn min(self, _: Self) -> Self {}
    #[inline]
    fn max(self, _: Self) -> Self {}
}

/// An RGB colour, carried in double precision: a sliver's gradient is the difference of two
/// large terms, and long spans add many increments.
impl Attribute for DVec3 {
    #[inline]
    fn add(self, d: Self) -> Self {
        self + d
    }
    #[inline]
    fn sub(self, o: Self) -> Self {
        self - o
    }
    #[inline]
    fn scale(self, s: f64) -> Self {
        self * s
    }
    #[inline]
    fn clamp_between(self, lo: Self, hi: Self) -> Self {
        self.clamp(lo.min(hi), lo.max(hi))
    }
    #[inline]
    fn min(self, o: Self) -> Self {
        DVec3::min(self, o)
    }
    #[inline]
    fn max(self, o: Self) -> Self {
        DVec3::max(self, o)
    }
}

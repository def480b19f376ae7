//! Hermite data from the source itself (dual contouring's edge crossings and normals, Ju et
//! al. 2002): where a solid known exactly crosses a lattice edge, found on the segment to
//! within a millionth of a voxel, and its outward normal there. The grid's samples say only
//! roughly where a surface passes; with the source's own crossings and normals, the vertices
//! of the cells a sharp edge or corner passes through land on it.

use super::field::ScalarField;
use crate::grid::SparseGrid;
use glam::DVec3;

/// A solid known exactly: where its surface crosses a segment, and its outward normal there.
pub trait ExactSurface: Send + Sync {
    /// The source as the segments within the world box `[lo, hi]` meet it (a block's edges
    /// ask it together: what lies near the block is found once).
    fn near(&self, lo: DVec3, hi: DVec3) -> Box<dyn SegmentCrossings + '_>;

    /// The solid's own values on the lattice around `grid` (the result's voxels), where the
    /// result holds none its surface can be drawn from (a formula's enveloping shell); none:
    /// the result's grid is contoured as it is.
    fn field_around(&self, _grid: &SparseGrid) -> Option<ScalarField<'static>> {
        None
    }
}

/// Where a source's surface crosses segments.
pub trait SegmentCrossings {
    /// Where the surface crosses the segment from `a` (inside, as the grid says, when
    /// `a_inside`) to `b` (world units): the fraction along it, nearest `guess` (the grid's
    /// own) where it crosses more than once, and the unit normal there, pointing out of the
    /// solid. None where the source cannot say (a leaf known only by its voxels, a clip it does
    /// not see, a sheet spanning a hole): the grid's crossing stands there.
    fn crossing(&self, a: DVec3, b: DVec3, a_inside: bool, guess: f64) -> Option<(f64, DVec3)>;
}

/// Where on the segment the crossing is sought to: a millionth of it.
const TOLERANCE: f64 = 1e-6;
/// Enough halvings for any segment to reach the tolerance.
const MOST_STEPS: usize = 64;

/// The crossing of a solid given by its values (`sample`: negative inside, positive outside,
/// zero on the surface, with the unit outward normal of the part of the surface the value
/// measures), as `ExactSurface::crossing` answers it: by regula falsi on the segment; none
/// where the values' signs at the ends are not the grid's.
pub fn crossing_of_values(
    mut sample: impl FnMut(DVec3) -> (f64, DVec3),
    a: DVec3,
    b: DVec3,
    a_inside: bool,
) -> Option<(f64, DVec3)> {
    // Inside as the grid counts it: a point on the surface belongs to the solid.
    let mut value = |t: f64| sample(a + (b - a) * t).0;
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    let (mut f_lo, mut f_hi) = (value(lo), value(hi));
    if (f_lo <= 0.0) != a_inside || (f_hi <= 0.0) == a_inside {
        return None;
    }
    // Regula falsi with the Illinois rule, which keeps it from stalling on one end, and a
    // halving where the interpolation lands outside the bracket.
    let mut side = 0i8;
    for _ in 0..MOST_STEPS {
        if hi - lo <= TOLERANCE {
            break;
        }
        let mut t = lo + (hi - lo) * f_lo / (f_lo - f_hi);
        if !(t > lo && t < hi) {
            t = 0.5 * (lo + hi);
        }
        let f = value(t);
        if f == 0.0 {
            (lo, hi) = (t, t);
            break;
        }
        if (f <= 0.0) == (f_lo <= 0.0) {
            (lo, f_lo) = (t, f);
            if side == -1 {
                f_hi *= 0.5;
            }
            side = -1;
        } else {
            (hi, f_hi) = (t, f);
            if side == 1 {
                f_lo *= 0.5;
            }
            side = 1;
        }
    }
    let t = 0.5 * (lo + hi);
    let normal = sample(a + (b - a) * t).1.try_normalize()?;
    Some((t, normal))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ball(p: DVec3) -> (f64, DVec3) {
        (p.length() - 1.0, p.normalize_or_zero())
    }

    #[test]
    fn a_ball_is_crossed_at_its_radius_with_its_normal() {
        let a = DVec3::new(0.2, 0.3, 0.1);
        let b = DVec3::new(1.5, 0.9, 0.4);
        let (t, n) = crossing_of_values(ball, a, b, true).unwrap();
        let p = a + (b - a) * t;
        assert!((p.length() - 1.0).abs() < 1e-6, "{p}");
        assert!((n - p.normalize()).length() < 1e-9);
        // Ends of one sign, or signs the grid does not share: no crossing.
        assert!(crossing_of_values(ball, a, a * 0.5, true).is_none());
        assert!(crossing_of_values(ball, a, b, false).is_none());
    }
}

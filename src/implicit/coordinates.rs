//! From Cartesian points and boxes to the coordinates a formula is written in, and the test
//! whether a box may hold a point of the surface F = 0 (Stolte & Kaufman §3).
//!
//! Boxes: r = sqrt(x² + y² + z²) (or sqrt(x² + z²) for cylinders) in interval arithmetic is
//! exactly [nearest, farthest distance] up to rounding. θ in (-π, π] is atan2(z, x); θ in the
//! paper's [0, 2π) is π - atan2(z, -x), the same angle with the cut turned onto the positive
//! x axis. Either is extreme at the box's corners unless the box meets the cut, where it is
//! split into the two pieces on either side of it (the paper's nine θ cases reduce to this),
//! or contains the y axis (the paper's case 4), where θ can be anything: `Undecided` asks the
//! caller to subdivide further. φ = atan2(y, sqrt(x² + z²)) lies in [-π/2, π/2].
//!
//! F = G - r with r nowhere else in G (the paper's examples): the box may hold a point of the
//! surface when G (taken non-negative, as r >= 0; or whole, under the paper's substitution
//! [G]² - r² = 0) and r overlap, compared as squares: r² is x² + y² + z² (or x² + z²) in
//! interval arithmetic, with no square root.
//!
//! Negative r: a point with coordinates (r, θ, φ) also has (-r, θ + π, -φ) (cylinders:
//! (-r, θ + π, y)). With `both_signs`, a box is kept when F contains 0 on either; the second
//! set sees θ + π unreduced.

use super::interval::Interval;
use super::split::Enclosure;
use super::tape::Number;
use super::{Coordinates, Formula, ThetaRange};
use std::f64::consts::PI;

/// Coordinates of a Cartesian point, over any number type, with θ in `range`.
pub fn to_coordinates<N: Number>(c: Coordinates, range: ThetaRange, [x, y, z]: [N; 3]) -> [N; 3] {
    let theta = match range {
        ThetaRange::Symmetric => z.atan2(x),
        ThetaRange::Positive => N::constant(PI).sub(z.atan2(x.neg())),
    };
    match c {
        Coordinates::Cartesian => [x, y, z],
        Coordinates::Spherical => {
            let horizontal = x.powi(2).add(z.powi(2));
            [
                horizontal.add(y.powi(2)).sqrt(),
                theta,
                y.atan2(horizontal.sqrt()),
            ]
        }
        Coordinates::Cylindrical => [x.powi(2).add(z.powi(2)).sqrt(), theta, y],
    }
}

/// F at a Cartesian point; with `negative`, at the same point written with -r:
/// `(-r, θ + π, -φ)` in spherical, `(-r, θ + π, y)` in cylindrical coordinates. Under the
/// paper's substitution (F = G - r, `squared`) the value is G² - r².
pub fn value_at(f: &Formula, p: [f64; 3], negative: bool) -> f64 {
    let c = f.coordinates;
    let [r, theta, third] = f.coordinates_of(p);
    let (r, theta, third) = match c {
        Coordinates::Cartesian => return f.tape.eval([r, theta, third]),
        _ if !negative => (r, theta, third),
        Coordinates::Spherical => (-r, theta + PI, -third),
        Coordinates::Cylindrical => (-r, theta + PI, third),
    };
    let value = f.tape.eval([r, theta, third]);
    if f.squared && f.tape.isolated(0).is_some() {
        let g = value + r;
        g * g - r * r
    } else {
        value
    }
}

/// What interval evaluation says about a box.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BoxTest {
    /// F excludes 0 on the box: no surface.
    Empty,
    /// F may be 0 somewhere in the box.
    MayContain,
    /// The box contains the axis, where θ is unbounded: subdivide further.
    Undecided,
}

/// Intervals of atan2(z, x) over the box (one or two), or `None` if the box contains the
/// y axis.
fn atan2_pieces(x: Interval, z: Interval) -> Option<([Interval; 2], usize)> {
    if x.contains_zero() && z.contains_zero() {
        return None;
    }
    if x.hi < 0.0 && z.contains_zero() {
        // Across the cut at ±π: above it θ falls from π, below it rises from -π.
        let upper = Interval::new(z.hi.atan2(x.hi), PI).widened();
        let lower = Interval::new(-PI, z.lo.atan2(x.hi)).widened();
        return Some(([upper, lower], 2));
    }
    let theta = z.atan2(x);
    Some(([theta, theta], 1))
}

/// Intervals of θ in `range` over the box (one or two), or `None` if the box contains the
/// y axis.
fn theta_pieces(x: Interval, z: Interval, range: ThetaRange) -> Option<([Interval; 2], usize)> {
    match range {
        ThetaRange::Symmetric => atan2_pieces(x, z),
        ThetaRange::Positive => {
            let (pieces, n) = atan2_pieces(x.neg(), z)?;
            let turned = pieces.map(|p| Interval::new(PI - p.hi, PI - p.lo).widened());
            Some((turned, n))
        }
    }
}

/// Whether the Cartesian box `b` may hold a point where the formula is zero; `slots` is
/// scratch space. With `whole_axis`, a box on the axis is bounded with θ over its whole
/// range instead of being `Undecided` (for boxes too small to subdivide further).
pub fn test_box<N: Enclosure>(
    f: &Formula,
    b: [Interval; 3],
    both_signs: bool,
    whole_axis: bool,
    slots: &mut Vec<N>,
) -> BoxTest {
    let (tape, c) = (&f.tape, f.coordinates);
    let [x, _, z] = b;
    let contains = |v: [Interval; 3], slots: &mut Vec<N>| {
        tape.eval_with(v.map(N::from), slots).contains_zero()
    };
    if c == Coordinates::Cartesian {
        return if contains(b, slots) {
            BoxTest::MayContain
        } else {
            BoxTest::Empty
        };
    }
    // On the axis, θ in [-π, π] still rules many boxes out; the others are undecided.
    let whole_turn = match f.theta_range {
        ThetaRange::Symmetric => Interval::new(-PI, PI),
        ThetaRange::Positive => Interval::new(0.0, 2.0 * PI),
    };
    let (thetas, count, on_axis) = match theta_pieces(x, z, f.theta_range) {
        Some((t, n)) => (t, n, false),
        None => ([whole_turn.widened(); 2], 1, !whole_axis),
    };
    let [r, _, third] = f.coordinates_of(b);
    let isolated = tape.isolated(0);
    let r_squared = match (isolated, c) {
        (None, _) => Interval::point(0.0),
        (Some(_), Coordinates::Spherical) => x.powi(2).add(b[1].powi(2)).add(z.powi(2)),
        (Some(_), _) => x.powi(2).add(z.powi(2)),
    };
    // G = r >= 0 (or, for the point written with -r, G = -r <= 0; under the paper's
    // substitution, G² = r² whatever G's sign): compare squares.
    let meets_r = |g: Interval, negative: bool| {
        let non_negative = |g: Interval| Interval::new(g.lo.max(0.0), g.hi);
        let g = match (f.squared, negative) {
            (true, _) => g,
            (false, false) => non_negative(g),
            (false, true) => non_negative(g.neg()),
        };
        !g.is_empty() && g.lo <= g.hi && g.powi(2).overlaps(r_squared)
    };
    let third = match c {
        Coordinates::Spherical => {
            third.clamp_to(-std::f64::consts::FRAC_PI_2, std::f64::consts::FRAC_PI_2)
        }
        _ => third,
    };
    let half_turn = Interval::point(PI).widened();
    let may_contain = if on_axis {
        BoxTest::Undecided
    } else {
        BoxTest::MayContain
    };
    let holds = |v: [Interval; 3], negative: bool, slots: &mut Vec<N>| match isolated {
        Some(g) => {
            tape.eval_with(v.map(N::from), slots);
            slots[g as usize]
                .pieces()
                .iter()
                .any(|&piece| meets_r(piece, negative))
        }
        None => contains(v, slots),
    };
    for &theta in &thetas[..count] {
        if holds([r, theta, third], false, slots) {
            return may_contain;
        }
        if both_signs {
            let flipped = match c {
                Coordinates::Spherical => third.neg(),
                _ => third,
            };
            if holds([r.neg(), theta.add(half_turn), flipped], true, slots) {
                return may_contain;
            }
        }
    }
    BoxTest::Empty
}

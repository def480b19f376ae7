//! Interval arithmetic with a guaranteed enclosure: the interval an operation returns holds
//! every value the operation takes on its argument intervals.
//!
//! Error model. `+ - * /` and `sqrt` are correctly rounded in IEEE 754 (within half an ulp of
//! the exact result), so each computed bound is moved one ulp outwards (`next_down` /
//! `next_up`). `powi` is repeated multiplication: |n| + 1 roundings, so its bounds are widened
//! by that many ulps (relative). The libm functions (`sin cos tan exp ln atan2`) are not
//! correctly rounded; glibc documents at most a few ulps for them, and their bounds are
//! widened by 8 ulps (relative, plus one ulp absolute). Range reductions (where sin reaches ±1,
//! where tan has a pole) are decided with a margin that only ever widens the result.
//!
//! An empty interval (a function undefined on the whole argument, such as `sqrt` of negative
//! numbers) is `[NaN, NaN]`; it propagates, and `contains_zero` is false for it, so a cell on
//! which the formula is nowhere defined holds no surface.

use super::tape::Number;
use std::f64::consts::{FRAC_PI_2, PI, TAU};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    pub lo: f64,
    pub hi: f64,
}

const EMPTY: Interval = Interval {
    lo: f64::NAN,
    hi: f64::NAN,
};
const ENTIRE: Interval = Interval {
    lo: f64::NEG_INFINITY,
    hi: f64::INFINITY,
};

/// Moves bounds out by `ulps` relative units of 2^-52, plus one ulp.
fn widen(lo: f64, hi: f64, ulps: f64) -> Interval {
    let rel = ulps * f64::EPSILON;
    Interval {
        lo: (lo - lo.abs() * rel).next_down(),
        hi: (hi + hi.abs() * rel).next_up(),
    }
}

/// Correctly rounded result: one ulp out on each side.
fn rounded(lo: f64, hi: f64) -> Interval {
    Interval {
        lo: lo.next_down(),
        hi: hi.next_up(),
    }
}

const LIBM_ULPS: f64 = 8.0;

impl Interval {
    pub fn new(lo: f64, hi: f64) -> Self {
        Interval { lo, hi }
    }

    pub fn point(x: f64) -> Self {
        Interval { lo: x, hi: x }
    }

    pub fn is_empty(&self) -> bool {
        self.lo.is_nan() || self.hi.is_nan()
    }

    pub fn contains(&self, x: f64) -> bool {
        self.lo <= x && x <= self.hi
    }

    /// Whether the two intervals share a point (false if either is empty).
    pub fn overlaps(&self, o: Interval) -> bool {
        self.lo <= o.hi && o.lo <= self.hi
    }

    pub fn contains_zero(&self) -> bool {
        self.contains(0.0)
    }

    /// Moved out by the libm margin (for bounds computed with libm or from rounded constants).
    pub fn widened(self) -> Self {
        widen(self.lo, self.hi, LIBM_ULPS)
    }

    /// Intersection with `[lo, hi]` moved out one ulp (`lo`, `hi` rounded constants).
    pub fn clamp_to(self, lo: f64, hi: f64) -> Self {
        Interval {
            lo: self.lo.max(lo.next_down()),
            hi: self.hi.min(hi.next_up()),
        }
    }

    pub fn width(&self) -> f64 {
        self.hi - self.lo
    }

    /// Whether some `offset + k * period` lies in the interval (with a margin that may say
    /// yes when the answer is barely no, which only widens results).
    fn reaches(&self, offset: f64, period: f64) -> bool {
        let margin = 1e-9;
        let first = ((self.lo - offset) / period - margin).ceil();
        let last = ((self.hi - offset) / period + margin).floor();
        first <= last
    }

    /// Range of sin or cos (`f`), which reach -1 at `min_at + 2kπ` and 1 at `max_at + 2kπ`
    /// and are monotone in between.
    fn periodic(self, f: fn(f64) -> f64, min_at: f64, max_at: f64) -> Self {
        if self.is_empty() {
            return EMPTY;
        }
        if !self.width().is_finite() || self.width() >= TAU {
            return Interval::new(-1.0, 1.0);
        }
        let (a, b) = (f(self.lo), f(self.hi));
        let w = widen(a.min(b), a.max(b), LIBM_ULPS);
        let lo = if self.reaches(min_at, TAU) {
            -1.0
        } else {
            w.lo.max(-1.0)
        };
        let hi = if self.reaches(max_at, TAU) {
            1.0
        } else {
            w.hi.min(1.0)
        };
        Interval { lo, hi }
    }

    /// Widened libm result of a function monotone on the interval.
    fn monotone(self, f: fn(f64) -> f64, increasing: bool) -> Self {
        let (a, b) = (f(self.lo), f(self.hi));
        let (lo, hi) = if increasing { (a, b) } else { (b, a) };
        widen(lo, hi, LIBM_ULPS)
    }
}

impl Number for Interval {
    fn constant(c: f64) -> Self {
        Interval::point(c)
    }

    fn neg(self) -> Self {
        Interval {
            lo: -self.hi,
            hi: -self.lo,
        }
    }

    fn add(self, o: Self) -> Self {
        rounded(self.lo + o.lo, self.hi + o.hi)
    }

    fn sub(self, o: Self) -> Self {
        rounded(self.lo - o.hi, self.hi - o.lo)
    }

    fn mul(self, o: Self) -> Self {
        if self.is_empty() || o.is_empty() {
            return EMPTY;
        }
        // 0 * inf stands for a bound of 0 times an unbounded side: the product bound is 0.
        let p = |a: f64, b: f64| {
            let v = a * b;
            if v.is_nan() { 0.0 } else { v }
        };
        let c = [
            p(self.lo, o.lo),
            p(self.lo, o.hi),
            p(self.hi, o.lo),
            p(self.hi, o.hi),
        ];
        rounded(
            c.iter().copied().fold(f64::INFINITY, f64::min),
            c.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        )
    }

    fn div(self, o: Self) -> Self {
        if self.is_empty() || o.is_empty() || (o.lo == 0.0 && o.hi == 0.0) {
            return EMPTY;
        }
        if o.contains_zero() {
            return ENTIRE;
        }
        self.mul(rounded(1.0 / o.hi, 1.0 / o.lo))
    }

    fn powi(self, n: i32) -> Self {
        if self.is_empty() {
            return EMPTY;
        }
        if n == 0 {
            return Interval::point(1.0);
        }
        if n < 0 {
            return Interval::point(1.0).div(self.powi(-n));
        }
        let ulps = n as f64 + 1.0;
        if n % 2 == 1 {
            return widen(self.lo.powi(n), self.hi.powi(n), ulps);
        }
        let (a, b) = (self.lo.abs(), self.hi.abs());
        if self.contains_zero() {
            Interval {
                lo: 0.0,
                hi: widen(0.0, a.max(b).powi(n), ulps).hi,
            }
        } else {
            let lo = widen(a.min(b).powi(n), 0.0, ulps).lo.max(0.0);
            Interval {
                lo,
                hi: widen(0.0, a.max(b).powi(n), ulps).hi,
            }
        }
    }

    fn sqrt(self) -> Self {
        if self.is_empty() || self.hi < 0.0 {
            return EMPTY;
        }
        let lo = if self.lo <= 0.0 {
            0.0
        } else {
            self.lo.sqrt().next_down().max(0.0)
        };
        Interval {
            lo,
            hi: self.hi.sqrt().next_up(),
        }
    }

    fn abs(self) -> Self {
        if self.is_empty() {
            EMPTY
        } else if self.lo >= 0.0 {
            self
        } else if self.hi <= 0.0 {
            self.neg()
        } else {
            Interval {
                lo: 0.0,
                hi: (-self.lo).max(self.hi),
            }
        }
    }

    fn sin(self) -> Self {
        self.periodic(f64::sin, -FRAC_PI_2, FRAC_PI_2)
    }

    fn cos(self) -> Self {
        self.periodic(f64::cos, PI, 0.0)
    }

    fn tan(self) -> Self {
        if self.is_empty() {
            return EMPTY;
        }
        if !self.width().is_finite() || self.width() >= PI || self.reaches(FRAC_PI_2, PI) {
            return ENTIRE;
        }
        self.monotone(f64::tan, true)
    }

    fn exp(self) -> Self {
        if self.is_empty() {
            return EMPTY;
        }
        let w = self.monotone(f64::exp, true);
        Interval {
            lo: w.lo.max(0.0),
            hi: w.hi,
        }
    }

    fn ln(self) -> Self {
        if self.is_empty() || self.hi <= 0.0 {
            return EMPTY;
        }
        let w = self.monotone(f64::ln, true);
        Interval {
            lo: if self.lo <= 0.0 {
                f64::NEG_INFINITY
            } else {
                w.lo
            },
            hi: w.hi,
        }
    }

    fn atan2(self, x: Self) -> Self {
        let y = self;
        if y.is_empty() || x.is_empty() {
            return EMPTY;
        }
        // The angle of a box that meets the origin or the cut along the negative x axis
        // can be anything. Otherwise x and y keep their signs on the box wherever the angle's
        // partial derivatives (x / r², -y / r²) would change theirs, so the angle is extreme
        // at two corners that the signs alone pick.
        if x.lo <= 0.0 && y.contains_zero() {
            return Interval::new(-PI, PI);
        }
        let y_near_axis = if y.lo > 0.0 { y.lo } else { y.hi };
        let (x_max, y_max, x_min, y_min) = (
            if y.hi < 0.0 { x.hi } else { x.lo },
            if x.lo > 0.0 {
                y.hi
            } else if x.hi < 0.0 {
                y.lo
            } else {
                y_near_axis
            },
            if y.lo > 0.0 { x.hi } else { x.lo },
            if x.lo > 0.0 {
                y.lo
            } else if x.hi < 0.0 {
                y.hi
            } else {
                y_near_axis
            },
        );
        let w = widen(y_min.atan2(x_min), y_max.atan2(x_max), LIBM_ULPS);
        Interval {
            lo: w.lo.max(-PI.next_up()),
            hi: w.hi.min(PI.next_up()),
        }
    }

    fn min(self, o: Self) -> Self {
        if self.is_empty() || o.is_empty() {
            return EMPTY;
        }
        Interval {
            lo: self.lo.min(o.lo),
            hi: self.hi.min(o.hi),
        }
    }

    fn max(self, o: Self) -> Self {
        if self.is_empty() || o.is_empty() {
            return EMPTY;
        }
        Interval {
            lo: self.lo.max(o.lo),
            hi: self.hi.max(o.hi),
        }
    }
}

//! Interval arithmetic over unions of at most two intervals, so that dividing by an interval
//! that holds zero splits at the pole instead of covering every number: `1/x` over a box
//! across x = 0 is (-inf, 1/lo] ∪ [1/hi, inf), which excludes 0, so a pole is never taken for
//! a root. Each operation runs on every piece (or pair of pieces) with `Interval`'s enclosures
//! and joins the results, filling the narrowest gaps when more than two pieces remain, so
//! every result still encloses every value.

use super::interval::Interval;
use super::tape::Number;

/// What the box test needs of an interval type: made from an interval, seen as pieces.
pub trait Enclosure: Number + From<Interval> {
    /// The disjoint pieces, ascending (none when empty).
    fn pieces(&self) -> &[Interval];

    fn contains_zero(&self) -> bool {
        self.pieces().iter().any(Interval::contains_zero)
    }
}

impl Enclosure for Interval {
    fn pieces(&self) -> &[Interval] {
        std::slice::from_ref(self)
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Split {
    pieces: [Interval; 2],
    count: usize,
}

impl From<Interval> for Split {
    fn from(i: Interval) -> Split {
        Split {
            pieces: [i, i],
            count: usize::from(!i.is_empty()),
        }
    }
}

impl Enclosure for Split {
    fn pieces(&self) -> &[Interval] {
        &self.pieces[..self.count]
    }
}

impl Split {
    /// The union of `parts` (at most 8; empty ones dropped), merged down to two pieces.
    fn join(parts: &[Interval]) -> Split {
        let mut v = [Interval::point(0.0); 8];
        let mut n = 0;
        for p in parts.iter().filter(|p| !p.is_empty()) {
            v[n] = *p;
            n += 1;
        }
        let v = &mut v[..n];
        v.sort_unstable_by(|a, b| a.lo.total_cmp(&b.lo));
        // Merge overlapping pieces in place: v[..m] are the disjoint ones so far.
        let mut m = 0;
        for i in 0..v.len() {
            if m > 0 && v[i].lo <= v[m - 1].hi {
                v[m - 1].hi = v[m - 1].hi.max(v[i].hi);
            } else {
                v[m] = v[i];
                m += 1;
            }
        }
        // Fill the narrowest gaps until two pieces remain.
        while m > 2 {
            let gap = |k: usize| v[k + 1].lo - v[k].hi;
            let narrowest = (0..m - 1)
                .min_by(|&i, &j| gap(i).total_cmp(&gap(j)))
                .expect("three pieces or more");
            v[narrowest].hi = v[narrowest + 1].hi;
            v.copy_within(narrowest + 2..m, narrowest + 1);
            m -= 1;
        }
        match m {
            0 => Split::from(Interval::new(f64::NAN, f64::NAN)),
            1 => Split::from(v[0]),
            _ => Split {
                pieces: [v[0], v[1]],
                count: 2,
            },
        }
    }

    fn lift1(self, f: impl Fn(Interval) -> Interval) -> Split {
        if self.count == 1 {
            return Split::from(f(self.pieces[0]));
        }
        let parts = [f(self.pieces[0]), f(self.pieces[1])];
        Split::join(&parts[..self.count])
    }

    fn lift2(self, o: Split, f: impl Fn(Interval, Interval) -> Interval) -> Split {
        if self.count == 1 && o.count == 1 {
            return Split::from(f(self.pieces[0], o.pieces[0]));
        }
        let mut parts = [Interval::point(0.0); 4];
        let mut n = 0;
        for &a in self.pieces() {
            for &b in o.pieces() {
                parts[n] = f(a, b);
                n += 1;
            }
        }
        Split::join(&parts[..n])
    }
}

/// The pieces of 1/d (at most two, the count second): two across a pole, one beside it,
/// none at 0 alone (undefined).
fn reciprocal(d: Interval) -> ([Interval; 2], usize) {
    let up = |v: f64| v.next_up();
    let down = |v: f64| v.next_down();
    let below = |lo: f64| Interval::new(f64::NEG_INFINITY, up(1.0 / lo));
    let above = |hi: f64| Interval::new(down(1.0 / hi), f64::INFINITY);
    if d.is_empty() || (d.lo == 0.0 && d.hi == 0.0) {
        return ([d, d], 0);
    }
    match (d.lo < 0.0, d.hi > 0.0) {
        (true, true) => ([below(d.lo), above(d.hi)], 2),
        (false, true) if d.lo == 0.0 => ([above(d.hi), d], 1),
        (true, false) if d.hi == 0.0 => ([below(d.lo), d], 1),
        _ => ([Number::div(Interval::point(1.0), d), d], 1),
    }
}

impl Number for Split {
    fn constant(c: f64) -> Self {
        Split::from(Interval::point(c))
    }
    fn neg(self) -> Self {
        self.lift1(Number::neg)
    }
    fn add(self, o: Self) -> Self {
        self.lift2(o, Number::add)
    }
    fn sub(self, o: Self) -> Self {
        self.lift2(o, Number::sub)
    }
    fn mul(self, o: Self) -> Self {
        self.lift2(o, Number::mul)
    }
    fn div(self, o: Self) -> Self {
        let mut parts = [Interval::point(0.0); 8];
        let mut n = 0;
        for &d in o.pieces() {
            let (r, count) = reciprocal(d);
            for &r in &r[..count] {
                for &a in self.pieces() {
                    parts[n] = Number::mul(a, r);
                    n += 1;
                }
            }
        }
        Split::join(&parts[..n])
    }
    fn powi(self, n: i32) -> Self {
        if n < 0 {
            return Split::constant(1.0).div(self.powi(n.saturating_neg()));
        }
        self.lift1(|p| p.powi(n))
    }
    fn sqrt(self) -> Self {
        self.lift1(Number::sqrt)
    }
    fn abs(self) -> Self {
        self.lift1(Number::abs)
    }
    fn sin(self) -> Self {
        self.lift1(Number::sin)
    }
    fn cos(self) -> Self {
        self.lift1(Number::cos)
    }
    fn tan(self) -> Self {
        self.lift1(Number::tan)
    }
    fn exp(self) -> Self {
        self.lift1(Number::exp)
    }
    fn ln(self) -> Self {
        self.lift1(Number::ln)
    }
    fn atan2(self, x: Self) -> Self {
        self.lift2(x, Number::atan2)
    }
    fn min(self, o: Self) -> Self {
        self.lift2(o, Number::min)
    }
    fn max(self, o: Self) -> Self {
        self.lift2(o, Number::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::implicit::Enclosure;

    fn split(lo: f64, hi: f64) -> Split {
        Split::from(Interval::new(lo, hi))
    }

    #[test]
    fn division_across_zero_leaves_a_gap_around_zero() {
        let r = Split::constant(1.0).div(split(-1.0, 2.0));
        assert_eq!(r.pieces().len(), 2);
        assert!(!r.contains_zero());
        assert!(r.pieces()[0].hi >= -1.0 && r.pieces()[0].hi < -0.99);
        assert!(r.pieces()[1].lo <= 0.5 && r.pieces()[1].lo > 0.49);
        // x^-1 - 2 over [-1, 2] holds 0 (at x = 0.5); over [-1, 0.4] it does not.
        assert!(
            split(-1.0, 2.0)
                .powi(-1)
                .sub(Split::constant(2.0))
                .contains_zero()
        );
        assert!(
            !split(-1.0, 0.4)
                .powi(-1)
                .sub(Split::constant(2.0))
                .contains_zero()
        );
        // 1/(x - x) is nowhere 0.
        let x = split(-3.0, 5.0);
        assert!(!Split::constant(1.0).div(x.sub(x)).contains_zero());
        // Division by exactly zero is undefined: empty.
        assert!(
            Split::constant(1.0)
                .div(split(0.0, 0.0))
                .pieces()
                .is_empty()
        );
    }

    #[test]
    fn every_sampled_value_is_enclosed() {
        let mut rng = crate::random::SplitMix64(5);
        for _ in 0..2000 {
            let (a, b) = (rng.range(-3.0, 3.0), rng.range(-3.0, 3.0));
            let (c, d) = (rng.range(-3.0, 3.0), rng.range(-3.0, 3.0));
            let x = split(a.min(b), a.max(b));
            let y = split(c.min(d), c.max(d));
            let f = |x: Split, y: Split| x.div(y).sub(y.powi(-2)).mul(x);
            let result = f(x, y);
            for k in 0..=8 {
                let xv = a.min(b) + (a - b).abs() * k as f64 / 8.0;
                let yv = c.min(d) + (c - d).abs() * (8 - k) as f64 / 8.0;
                let v = (xv / yv - 1.0 / (yv * yv)) * xv;
                if v.is_finite() {
                    assert!(
                        result.pieces().iter().any(|p| p.contains(v)),
                        "{v} not in {result:?} for x={xv} y={yv}"
                    );
                }
            }
        }
    }
}

//! Huang et al.'s criterion on a surface typed as a formula, F = 0 (§7: the method "works even
//! when there is no analytical solution" of the Lagrange condition): the nearest point of the
//! surface to each voxel centre is found numerically, and interval arithmetic (Stolte &
//! Kaufman's, `implicit`) certifies what is left out.
//!
//! The foot point: from the centre p, Newton steps along the gradient put a point q on F = 0;
//! p's foot on q's tangent plane starts the next projection; the two alternate until they meet,
//! where p - q is parallel to the gradient at q (the Lagrange condition). On a sphere the first
//! projection is the foot. The normal is the unit gradient at q (towards F > 0), the curvature
//! the largest principal curvature there, from the Hessian (central differences of the exact
//! gradient) on the tangent plane: on a sphere 1/R, as `shape sphere` takes it.
//!
//! Certified: a centre is left out without a search only where interval arithmetic proves
//! F != 0 over the cube of half edge `reach` around it (a fortiori over the ball); the blocks
//! of the scan likewise. Where the search fails (a vanishing gradient at a cone's apex or a
//! crease of `min`/`max`, no convergence), the distance is a certified lower bound instead, the
//! widest cube around the centre proven free of the surface, ruled by `Rc` as an edge is: `Rc`
//! separates whatever the surface. A foot point that is nearest only locally can still leave a
//! step open: `step_certificate` closes every step between two centres left out that interval
//! arithmetic cannot prove free of the surface, so the voxels separate by construction.

use super::separating_analytic::{AnalyticSurface, Nearest};
use crate::implicit::{BoxTest, Dual, Formula, Interval, Split, test_box};
use crate::mesh::Aabb;
use glam::DVec3;

/// Newton steps onto the surface, and alternations of projection and tangent foot, at most.
const MOST_STEPS: usize = 64;

/// Halvings of the reach tried for a certified lower bound of the distance.
const LOWER_BOUND_HALVINGS: i32 = 10;

thread_local! {
    /// Scratch slots of the interval tape evaluations.
    static BOX_SLOTS: std::cell::RefCell<(Vec<Interval>, Vec<Split>)> =
        const { std::cell::RefCell::new((Vec::new(), Vec::new())) };
}

/// The surface F = 0 of a formula inside a box.
#[derive(Clone, Debug)]
pub struct FormulaSurface {
    formula: Formula,
    bounds: Aabb,
}

impl FormulaSurface {
    /// F = 0 inside `bounds` (world units); F's sign tells the two sides apart.
    pub fn new(formula: Formula, bounds: Aabb) -> FormulaSurface {
        FormulaSurface { formula, bounds }
    }

    pub fn formula(&self) -> &Formula {
        &self.formula
    }

    fn value_and_gradient(&self, x: DVec3, slots: &mut Vec<Dual>) -> (f64, DVec3) {
        self.formula.value_and_gradient_at(x.to_array(), slots)
    }

    /// F at `x`.
    pub fn value(&self, x: DVec3) -> f64 {
        crate::implicit::value_at(&self.formula, x.to_array(), false)
    }

    /// Whether interval arithmetic proves F != 0 over the box `[lo, hi]`.
    pub fn box_is_empty(&self, lo: DVec3, hi: DVec3) -> bool {
        let b = [0, 1, 2].map(|a| Interval::new(lo[a], hi[a]));
        // Asked once a voxel and once a step piece: the tape's slots are kept per thread.
        BOX_SLOTS.with_borrow_mut(|(intervals, splits)| {
            let test = if self.formula.tape.divides() {
                test_box::<Split>(&self.formula, b, false, true, splits)
            } else {
                test_box::<Interval>(&self.formula, b, false, true, intervals)
            };
            test == BoxTest::Empty
        })
    }

    /// The point of F = 0 that Newton steps along the gradient reach from `x`, with the
    /// gradient there; none where the gradient vanishes or the steps do not settle within `tol`.
    fn project(&self, mut x: DVec3, tol: f64, slots: &mut Vec<Dual>) -> Option<(DVec3, DVec3)> {
        for _ in 0..MOST_STEPS {
            let (f, g) = self.value_and_gradient(x, slots);
            let g2 = g.length_squared();
            if !(g2 > 0.0 && g2.is_finite() && f.is_finite()) {
                return None;
            }
            let step = g * (f / g2);
            x -= step;
            if step.length() <= tol {
                return Some((x, self.value_and_gradient(x, slots).1));
            }
        }
        None
    }

    /// The foot point of `p` (where p - q is parallel to the gradient at q) and the gradient
    /// there.
    fn foot(&self, p: DVec3, tol: f64, slots: &mut Vec<Dual>) -> Option<(DVec3, DVec3)> {
        let mut start = p;
        for _ in 0..MOST_STEPS {
            let (q, g) = self.project(start, tol, slots)?;
            let n = g.try_normalize()?;
            let tangent_foot = p - n * n.dot(p - q);
            if tangent_foot.distance(q) <= tol {
                return Some((q, g));
            }
            start = tangent_foot;
        }
        None
    }

    /// The largest principal curvature (absolute) of F = 0 at `q`, gradient `g`, from the
    /// Hessian by central differences of step `step` on the tangent plane.
    fn curvature(&self, q: DVec3, g: DVec3, step: f64, slots: &mut Vec<Dual>) -> f64 {
        let length = g.length();
        let n = g / length;
        let (u, v) = n.any_orthonormal_pair();
        // The Hessian applied to a direction: the gradient's change along it.
        let along = |d: DVec3, slots: &mut Vec<Dual>| {
            let plus = self.value_and_gradient(q + d * step, slots).1;
            let minus = self.value_and_gradient(q - d * step, slots).1;
            (plus - minus) / (2.0 * step)
        };
        let (hu, hv) = (along(u, slots), along(v, slots));
        let (a, b, d) = (
            u.dot(hu) / length,
            0.5 * (v.dot(hu) + u.dot(hv)) / length,
            v.dot(hv) / length,
        );
        let (mean, spread) = (0.5 * (a + d), (0.25 * (a - d).powi(2) + b * b).sqrt());
        (mean.abs() + spread).max(0.0)
    }

    /// A certified lower bound of the distance from `p` to the surface, at most `reach`: the
    /// widest cube around `p` of half edge `reach / 2^k` that interval arithmetic proves free
    /// of the surface (0 where none is).
    fn free_radius(&self, p: DVec3, reach: f64) -> f64 {
        (0..=LOWER_BOUND_HALVINGS)
            .map(|k| reach * 0.5f64.powi(k))
            .find(|&r| self.box_is_empty(p - r, p + r))
            .unwrap_or(0.0)
    }
}

impl AnalyticSurface for FormulaSurface {
    fn bbox(&self) -> Aabb {
        self.bounds
    }

    fn nearest(&self, p: DVec3, reach: f64) -> Nearest {
        if self.box_is_empty(p - reach, p + reach) {
            return Nearest {
                distance: reach,
                normal: DVec3::Z,
                on_edge: true,
                curvature: 0.0,
            };
        }
        let mut slots = Vec::new();
        let tol = reach * 1e-13;
        if let Some((q, g)) = self.foot(p, tol, &mut slots) {
            let normal = g.normalize();
            return Nearest {
                distance: p.distance(q),
                normal,
                on_edge: false,
                curvature: self.curvature(q, g, reach * 1e-4, &mut slots),
            };
        }
        let (_, g) = self.value_and_gradient(p, &mut slots);
        Nearest {
            distance: self.free_radius(p, reach),
            normal: g.try_normalize().unwrap_or(DVec3::Z),
            on_edge: true,
            curvature: 0.0,
        }
    }

    fn side(&self, p: DVec3) -> f64 {
        self.value(p)
    }

    fn may_come_within(&self, lo: DVec3, hi: DVec3, reach: f64) -> bool {
        !self.box_is_empty(lo - reach, hi + reach)
    }
}

//! A formula's solid, F < 0 within its bounds, as the depth buffers see it (Passalis et al. on
//! a surface that is not a mesh): each ray's crossings of F = 0 are isolated by interval
//! arithmetic. A piece of the ray whose box `test_box` proves free of F = 0 holds none; other
//! pieces are halved until they are shorter than `CLOSE` voxels, and such a piece holds a
//! crossing where F's sign differs at its ends (a touching zero, same sign at both ends, is
//! none: the solid does not change there). Where the ray enters or leaves the bounds inside
//! the solid, the bounds' face is a crossing, so a solid the bounds cut is closed by them.
//!
//! The tie rule is F's own sign at the centres: a centre where F = 0 lies outside (F < 0 is
//! inside), so every direction, and sampling F at the centres, agree on it. A ray whose search
//! would exceed `BUDGET` boxes (F = 0 along a stretch of it) cannot be decided: it reports six
//! crossings, which no direction takes as a verdict.

use super::depth_layers::RaySurface;
use crate::grid::Transform;
use crate::implicit::{BoxTest, Formula, Interval, test_box, value_at};
use crate::mesh::Aabb;
use crate::mesh::crossings::{RayCrossing, RayFrame, RayWindow};
use crate::progress::Progress;
use glam::DVec3;
use rayon::prelude::*;

/// Pieces of a ray shorter than this (voxels) are not halved further.
const CLOSE: f64 = 1e-6;
/// Boxes tested per ray at most.
const BUDGET: usize = 50_000;
/// Crossings reported for a ray that cannot be decided (more than four: no verdict).
const UNDECIDED_CROSSINGS: usize = 6;

/// F < 0 within `bounds`, on the grid `transform`, for the volume whose first voxel is
/// `first`; once `progress` is stopped, the remaining rays are skipped (the caller checks).
pub struct FormulaRays<'f, 'p> {
    pub formula: &'f Formula,
    pub transform: Transform,
    pub first: [i64; 3],
    pub bounds: Aabb,
    pub progress: &'f Progress<'p>,
}

impl RaySurface for FormulaRays<'_, '_> {
    fn crossings(&self, frame: &RayFrame, window: &RayWindow, cross: &mut dyn FnMut(RayCrossing)) {
        let per_ray: Vec<Vec<RayCrossing>> = (0..window.len())
            .into_par_iter()
            .map_init(Vec::new, |slots, ray| {
                if self.progress.stopped() {
                    return Vec::new();
                }
                let (a, b) = (
                    window.a0 + (ray / window.height) as i64,
                    window.b0 + (ray % window.height) as i64,
                );
                self.ray_crossings(frame, ray, [a, b], slots)
            })
            .collect();
        per_ray.into_iter().flatten().for_each(cross);
    }
}

impl FormulaRays<'_, '_> {
    /// The world point at `t` along ray `ab`.
    fn world(&self, frame: &RayFrame, ab: [i64; 2], t: f64) -> DVec3 {
        let p = frame.from_ray(DVec3::new(ab[0] as f64, ab[1] as f64, t));
        self.transform.origin
            + (p + DVec3::from_array(self.first.map(|v| v as f64))) * self.transform.voxel_size
    }

    /// Whether the world point `p` lies in the solid.
    fn inside(&self, p: DVec3) -> bool {
        value_at(self.formula, p.to_array(), false) < 0.0
    }

    /// The part of ray `ab` within the bounds, as `t`, if any.
    fn clipped(&self, frame: &RayFrame, ab: [i64; 2]) -> Option<(f64, f64)> {
        let start = self.world(frame, ab, 0.0);
        let step = self.world(frame, ab, 1.0) - start;
        let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
        for axis in 0..3 {
            let (lo, hi) = (self.bounds.min[axis], self.bounds.max[axis]);
            if step[axis] == 0.0 {
                if start[axis] < lo || start[axis] > hi {
                    return None;
                }
                continue;
            }
            let (a, b) = (
                (lo - start[axis]) / step[axis],
                (hi - start[axis]) / step[axis],
            );
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
        (t0 < t1).then_some((t0, t1))
    }

    fn ray_crossings(
        &self,
        frame: &RayFrame,
        ray: usize,
        ab: [i64; 2],
        slots: &mut Vec<Interval>,
    ) -> Vec<RayCrossing> {
        let Some((t_in, t_out)) = self.clipped(frame, ab) else {
            return Vec::new();
        };
        let inside_at = |t: f64| self.inside(self.world(frame, ab, t));
        let mut crossings = Vec::new();
        let crossing = |t: f64, after: i64, rising: bool| RayCrossing {
            ray,
            t,
            after,
            rising,
        };
        let (s_in, s_out) = (inside_at(t_in), inside_at(t_out));
        if s_in {
            crossings.push(crossing(t_in, t_in.ceil() as i64, false));
        }
        let mut stack = vec![(t_in, t_out, s_in, s_out)];
        let mut tested = 0;
        while let Some((t0, t1, s0, s1)) = stack.pop() {
            tested += 1;
            if tested > BUDGET {
                return vec![crossing(t_in, t_in.ceil() as i64, false); UNDECIDED_CROSSINGS];
            }
            let (p0, p1) = (self.world(frame, ab, t0), self.world(frame, ab, t1));
            let (lo, hi) = (p0.min(p1), p0.max(p1));
            let b = [0, 1, 2].map(|a| Interval::new(lo[a], hi[a]).widened());
            if test_box(self.formula, b, false, true, slots) == BoxTest::Empty {
                continue;
            }
            if t1 - t0 < CLOSE {
                if s0 != s1 {
                    // The first centre on the far side: F's sign at a centre inside the
                    // piece decides it.
                    let n = t1.floor();
                    let after = if n > t0 && inside_at(n) == s1 {
                        n as i64
                    } else {
                        t1.floor() as i64 + 1
                    };
                    crossings.push(crossing(0.5 * (t0 + t1), after, s0));
                }
                continue;
            }
            let middle = 0.5 * (t0 + t1);
            let s = inside_at(middle);
            // The nearer half last, so crossings come out in order.
            stack.push((middle, t1, s, s1));
            stack.push((t0, middle, s0, s));
        }
        if s_out {
            crossings.push(crossing(t_out, t_out.floor() as i64 + 1, true));
        }
        crossings
    }
}

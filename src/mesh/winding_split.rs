//! The winding number of a set of triangles (a mesh's caps) within one small ball, split so
//! that many queries there are cheap: the triangles that come near the ball are summed exactly,
//! and the far ones, whose number is smooth over the ball, by a second-order Taylor model
//! around its middle. The model's gradient and Hessian come from the far triangles' boundary
//! (`boundary_derivatives`): the whole rim less the near triangles' own boundary. Its remainder
//! is bounded by that boundary's third derivatives (`RimBound::third_derivative`'s bound),
//! small because every far triangle lies at least the split's gap beyond the ball.

use super::triangle_distance::triangle_distance;
use super::winding::{
    RimBound, WindingBounds, boundary_derivatives, segments_power_sum, winding_number_of,
};
use glam::{DMat3, DVec3};
use std::f64::consts::PI;

/// The winding number of a `Splitter`'s triangles within the ball it was split for.
pub struct SplitWinding {
    /// The triangles within the ball's radius plus the gap of its middle, with their bounding
    /// balls.
    near: Vec<[DVec3; 3]>,
    near_balls: Vec<(DVec3, f64)>,
    /// The near triangles' boundary (their rim segments and the edges they share with far
    /// triangles), directed as they face.
    near_boundary: Vec<[DVec3; 2]>,
    middle: DVec3,
    /// The far triangles' number at the middle, its gradient and half its Hessian there.
    far_value: f64,
    far_gradient: DVec3,
    far_half_hessian: DMat3,
    /// The model's remainder at distance d from the middle is at most this times d^3.
    far_third: f64,
}

/// A second-order model of the winding number around a point, valid within its ball where no
/// triangle passes (or continued smoothly across them): the value, gradient and half Hessian
/// there, and the remainder's bound.
pub struct LocalModel {
    value: f64,
    gradient: DVec3,
    half_hessian: DMat3,
    near_third: f64,
    far_third: f64,
    at: DVec3,
    middle: DVec3,
}

impl LocalModel {
    /// The model's value at `p`.
    #[cfg(test)]
    pub fn value_at(&self, p: DVec3) -> f64 {
        let (c0, c1, c2) = self.along_z(p.x, p.y);
        let t = p.z - self.at.z;
        c0 + t * (c1 + t * c2)
    }

    /// The model along the line through (x, y) parallel to z, as coefficients (c0, c1, c2):
    /// its value at z is c0 + c1 t + c2 t^2 with t = z minus the model point's z.
    pub fn along_z(&self, x: f64, y: f64) -> (f64, f64, f64) {
        let (dx, dy) = (x - self.at.x, y - self.at.y);
        let (g, h) = (self.gradient, self.half_hessian);
        let c0 = self.value
            + g.x * dx
            + g.y * dy
            + h.x_axis.x * dx * dx
            + h.y_axis.y * dy * dy
            + (h.y_axis.x + h.x_axis.y) * dx * dy;
        let c1 = g.z + (h.z_axis.x + h.x_axis.z) * dx + (h.z_axis.y + h.y_axis.z) * dy;
        (c0, c1, h.z_axis.z)
    }

    /// The most the true number may differ from the model at `p`.
    pub fn error_at(&self, p: DVec3) -> f64 {
        let (d, e) = (p.distance(self.at), p.distance(self.middle));
        self.near_third * d * d * d + self.far_third * e * e * e
    }

    /// The most the true number may differ from the model anywhere within `reach` of its
    /// point.
    pub fn most_error(&self, reach: f64) -> f64 {
        let e = self.at.distance(self.middle) + reach;
        self.near_third * reach.powi(3) + self.far_third * e * e * e
    }
}

/// Triangles closed off by their rim (each triangle (c, a, b) has its rim segment a to b),
/// ready to be split around many balls.
pub struct Splitter<'a> {
    triangles: &'a [[DVec3; 3]],
    balls: Vec<(DVec3, f64)>,
    rim: &'a RimBound,
}

impl<'a> Splitter<'a> {
    pub fn new(triangles: &'a [[DVec3; 3]], rim: &'a RimBound) -> Splitter<'a> {
        let balls = triangles.iter().map(|&t| bounding_ball(t)).collect();
        Splitter {
            triangles,
            balls,
            rim,
        }
    }

    /// The exact sum over every triangle at `p`.
    pub fn winding_number(&self, p: DVec3) -> f64 {
        winding_number_of(self.triangles, p)
    }

    /// The split for queries within `reach` of `middle`: the triangles within `reach + gap`
    /// of it are near.
    pub fn around(&self, middle: DVec3, reach: f64, gap: f64) -> SplitWinding {
        let mut near = Vec::new();
        let mut near_balls = Vec::new();
        let mut far_boundary = Vec::with_capacity(self.triangles.len());
        for (&t, &(c, r)) in self.triangles.iter().zip(&self.balls) {
            let far =
                c.distance(middle) - r > reach + gap || triangle_distance(middle, t) > reach + gap;
            if far {
                far_boundary.push([t[1], t[2]]);
            } else {
                near.push(t);
                near_balls.push((c, r));
            }
        }
        // The edges the near triangles share with far ones (those of their other edges that no
        // near triangle runs the other way) bound both: the far ones reversed.
        let interface = uncancelled(near.iter().flat_map(|&[c, a, b]| [[c, a], [b, c]]));
        far_boundary.extend(interface.iter().map(|&[a, b]| [b, a]));
        let mut near_boundary: Vec<[DVec3; 2]> = near.iter().map(|&[_, a, b]| [a, b]).collect();
        near_boundary.extend(interface);
        let far_value = self.winding_number(middle) - winding_number_of(&near, middle);
        let (rim_gradient, rim_hessian) = self.rim.winding_derivatives(middle);
        let (near_gradient, near_hessian) = boundary_derivatives(&near_boundary, middle);
        let far_third = third_coefficient(&far_boundary, middle, reach);
        SplitWinding {
            near,
            near_balls,
            near_boundary,
            middle,
            far_value,
            far_gradient: rim_gradient - near_gradient,
            far_half_hessian: (rim_hessian - near_hessian) * 0.5,
            far_third,
        }
    }
}

impl SplitWinding {
    /// The far triangles' number at `p` by the model, and its error bound there.
    fn far_at(&self, p: DVec3) -> (f64, f64) {
        let d = p - self.middle;
        let value = self.far_value + self.far_gradient.dot(d) + d.dot(self.far_half_hessian * d);
        let e = d.length();
        (value, self.far_third * e * e * e)
    }

    /// The winding number at `p` (within the ball) and how far the true one may be from it.
    pub fn bounds(&self, p: DVec3) -> WindingBounds {
        let (far, spread) = self.far_at(p);
        WindingBounds {
            value: winding_number_of(&self.near, p) + far,
            spread,
        }
    }

    /// Whether a triangle comes within `reach` of `p` (a ball inside the split's).
    pub fn comes_within(&self, p: DVec3, reach: f64) -> bool {
        self.near
            .iter()
            .zip(&self.near_balls)
            .any(|(&t, &(c, r))| c.distance(p) <= r + reach && triangle_distance(p, t) <= reach)
    }

    /// The range of the winding number over the ball of radius `reach` around `centre` (inside
    /// the split's ball): none where a triangle comes within it (the number jumps across one).
    pub fn range(&self, centre: DVec3, reach: f64) -> Option<WindingBounds> {
        if self.comes_within(centre, reach) {
            return None;
        }
        let near_change =
            reach * segments_power_sum(&self.near_boundary, centre, reach, 2) / (4.0 * PI);
        let d = centre - self.middle;
        let (far, _) = self.far_at(centre);
        let far_slope = self.far_gradient + 2.0 * (self.far_half_hessian * d);
        let far_change = far_slope.length() * reach
            + frobenius(self.far_half_hessian) * reach * reach
            + self.far_third * (d.length() + reach).powi(3);
        let spread = near_change + far_change;
        spread.is_finite().then(|| WindingBounds {
            value: winding_number_of(&self.near, centre) + far,
            spread,
        })
    }

    /// The second-order model around `q` for the ball of radius `reach` there (inside the
    /// split's ball), or none where the near boundary comes within it. Where a near triangle
    /// passes through the ball, the model continues the number smoothly across it (the number
    /// itself jumps by one there).
    pub fn model(&self, q: DVec3, reach: f64) -> Option<LocalModel> {
        let near_third = third_coefficient(&self.near_boundary, q, reach);
        if !near_third.is_finite() {
            return None;
        }
        let (near_gradient, near_hessian) = boundary_derivatives(&self.near_boundary, q);
        let (far, _) = self.far_at(q);
        let e = q - self.middle;
        Some(LocalModel {
            value: winding_number_of(&self.near, q) + far,
            gradient: near_gradient + self.far_gradient + 2.0 * (self.far_half_hessian * e),
            half_hessian: near_hessian * 0.5 + self.far_half_hessian,
            near_third,
            far_third: self.far_third,
            at: q,
            middle: self.middle,
        })
    }
}

/// The coefficient of d^3 in the bound on a second-order model's remainder at distance d
/// within the ball of radius `reach` around `p`, of the number of a surface bounded by
/// `segments`: a sixth of `RimBound::third_derivative`'s bound.
fn third_coefficient(segments: &[[DVec3; 2]], p: DVec3, reach: f64) -> f64 {
    segments_power_sum(segments, p, reach, 4) / (4.0 * PI)
}

/// The directed `edges` less those cancelled by an edge running the other way between the
/// same points.
fn uncancelled(edges: impl Iterator<Item = [DVec3; 2]>) -> Vec<[DVec3; 2]> {
    let bits = |p: DVec3| p.to_array().map(f64::to_bits);
    let mut keyed: Vec<([[u64; 3]; 2], i32)> = edges
        .map(|[a, b]| {
            let (ka, kb) = (bits(a), bits(b));
            if ka < kb {
                ([ka, kb], 1)
            } else {
                ([kb, ka], -1)
            }
        })
        .collect();
    keyed.sort_unstable_by_key(|e| e.0);
    let point = |k: [u64; 3]| DVec3::from_array(k.map(f64::from_bits));
    let mut out = Vec::new();
    for run in keyed.chunk_by(|x, y| x.0 == y.0) {
        let count: i32 = run.iter().map(|e| e.1).sum();
        let [lo, hi] = run[0].0.map(point);
        let edge = if count > 0 { [lo, hi] } else { [hi, lo] };
        out.extend(std::iter::repeat_n(edge, count.unsigned_abs() as usize));
    }
    out
}

fn bounding_ball([a, b, c]: [DVec3; 3]) -> (DVec3, f64) {
    let centre = (a + b + c) / 3.0;
    let radius = centre
        .distance(a)
        .max(centre.distance(b))
        .max(centre.distance(c));
    (centre, radius)
}

fn frobenius(m: DMat3) -> f64 {
    (m.x_axis.length_squared() + m.y_axis.length_squared() + m.z_axis.length_squared()).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{Mesh, boundary_caps::boundary_caps, generate};

    /// The caps of a torus with every fifth face removed (many small holes), as corners.
    fn holed_torus_caps() -> Vec<[DVec3; 3]> {
        let torus = generate::torus(DVec3::ZERO, 1.0, 0.35, 64, 32);
        let open: Vec<Vec<u32>> = (0..torus.face_count())
            .filter(|&f| f % 5 != 0)
            .map(|f| torus.face(f).to_vec())
            .collect();
        let holed = Mesh::from_polygons("holed", torus.positions.clone(), &open);
        let caps = boundary_caps(&holed);
        let mut points = holed.positions.clone();
        points.extend_from_slice(&caps.points);
        caps.triangles
            .iter()
            .map(|t| t.map(|v| points[v as usize]))
            .collect()
    }

    fn random_in_ball(rng: &mut crate::random::SplitMix64, centre: DVec3, reach: f64) -> DVec3 {
        loop {
            let d = DVec3::new(
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
                rng.range(-1.0, 1.0),
            );
            if d.length() <= 1.0 {
                return centre + d * reach;
            }
        }
    }

    /// Around many balls by the caps' holes, the split's bounds, ranges and models hold the
    /// exact sum over every triangle: the bounds and ranges everywhere they answer, the models
    /// where no cap passes through their ball, and across a cap up to the whole turn the
    /// number jumps by there.
    #[test]
    fn the_split_holds_the_exact_number_in_its_ball() {
        let caps = holed_torus_caps();
        let rim = RimBound::new(caps.iter().map(|&[_, a, b]| [a, b]).collect());
        let splitter = Splitter::new(&caps, &rim);
        let mut rng = crate::random::SplitMix64(21);
        let (reach, gap) = (0.06, 0.2);
        let (mut ranged, mut modelled, mut across) = (0, 0, 0);
        for round in 0..80 {
            // Middles near a rim vertex, where the number changes fastest, or near a cap's
            // middle, where it jumps across the cap.
            let [c, a, _] = caps[(rng.next_u64() % caps.len() as u64) as usize];
            let middle = if round % 2 == 0 {
                random_in_ball(&mut rng, a, 0.1)
            } else {
                random_in_ball(&mut rng, c, 0.01)
            };
            let split = splitter.around(middle, reach, gap);
            for _ in 0..40 {
                let p = random_in_ball(&mut rng, middle, reach);
                let exact = winding_number_of(&caps, p);
                let b = split.bounds(p);
                assert!(
                    (exact - b.value).abs() <= b.spread + 1e-12,
                    "{exact} outside {b:?} at {p}"
                );
            }
            let small = reach / 3.0;
            let centre = random_in_ball(&mut rng, middle, reach - small);
            if let Some(b) = split.range(centre, small) {
                ranged += 1;
                for _ in 0..20 {
                    let p = random_in_ball(&mut rng, centre, small);
                    let exact = winding_number_of(&caps, p);
                    assert!(b.low() - 1e-12 <= exact && exact <= b.high() + 1e-12);
                }
            }
            if let Some(model) = split.model(centre, small) {
                let smooth = !split.comes_within(centre, small);
                let at_centre = winding_number_of(&caps, centre);
                for _ in 0..20 {
                    let p = random_in_ball(&mut rng, centre, small);
                    let off = winding_number_of(&caps, p) - model.value_at(p);
                    // Across a cap the number jumps by a whole turn; the model continues it.
                    let jump = if smooth { 0.0 } else { off.round() };
                    across += usize::from(jump != 0.0);
                    assert!(
                        (off - jump).abs() <= model.error_at(p) + 1e-12,
                        "model off by {off} where {} is allowed",
                        model.error_at(p)
                    );
                    assert!(model.error_at(p) <= model.most_error(small) + 1e-12);
                }
                assert!(
                    (model.value_at(centre) - at_centre).abs() <= model.error_at(centre) + 1e-12
                );
                modelled += 1;
            }
        }
        assert!(
            ranged > 10 && modelled > 10,
            "{ranged} ranges, {modelled} models"
        );
        assert!(across > 0, "no model was tried across a cap");
    }

    /// Opposite edges cancel; the rest keep their direction and multiplicity.
    #[test]
    fn edges_cancel_with_their_reverses_only() {
        let (a, b, c) = (DVec3::X, DVec3::Y, DVec3::Z);
        let out = uncancelled([[a, b], [b, a], [b, c], [b, c], [c, a]].into_iter());
        assert_eq!(out.len(), 3);
        assert_eq!(out.iter().filter(|&&e| e == [b, c]).count(), 2);
        assert!(out.contains(&[c, a]));
    }
}

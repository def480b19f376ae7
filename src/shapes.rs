//! The primitive shapes, one vocabulary for every method: the analytic surfaces of Huang et
//! al. §7 (their exact distances live in `voxelize::separating_analytic`) and the solid
//! leaves of CSG trees (`solids::csg_leaves`). All in world units.

use crate::mesh::Aabb;
use glam::DVec3;

/// A ball, or its sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    pub center: DVec3,
    pub radius: f64,
}

/// A closed cylinder: side, two caps and two sharp rims.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cylinder {
    /// Centre of the axis segment.
    pub center: DVec3,
    /// Unit axis direction.
    pub axis: DVec3,
    pub radius: f64,
    pub height: f64,
}

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cuboid {
    pub min: DVec3,
    pub max: DVec3,
}

/// The parabolic cylinder `x^2 + k y + k z = 0` (Huang et al. §7), clipped to a cube of
/// half edge `half_extent` around the origin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quadric {
    pub k: f64,
    pub half_extent: f64,
}

impl Sphere {
    pub fn area(&self) -> f64 {
        4.0 * std::f64::consts::PI * self.radius * self.radius
    }

    pub fn bounds(&self) -> Aabb {
        Aabb {
            min: self.center - self.radius,
            max: self.center + self.radius,
        }
    }

    pub fn contains(&self, p: DVec3) -> bool {
        p.distance_squared(self.center) <= self.radius * self.radius
    }
}

impl Cylinder {
    /// Side and both caps.
    pub fn area(&self) -> f64 {
        let r = self.radius;
        2.0 * std::f64::consts::PI * r * (self.height + r)
    }

    /// The cylinder from `base` along the unit `axis` for `height`.
    pub fn from_base(base: DVec3, axis: DVec3, radius: f64, height: f64) -> Cylinder {
        Cylinder {
            center: base + 0.5 * height * axis,
            axis,
            radius,
            height,
        }
    }

    /// The centres of the two caps.
    pub fn ends(&self) -> [DVec3; 2] {
        let half = 0.5 * self.height * self.axis;
        [self.center - half, self.center + half]
    }

    pub fn bounds(&self) -> Aabb {
        let [a, b] = self.ends();
        // Per axis, a disc of radius r perpendicular to `axis` reaches r * sqrt(1 - a_i^2).
        let reach = (DVec3::ONE - self.axis * self.axis)
            .max(DVec3::ZERO)
            .powf(0.5)
            * self.radius;
        Aabb {
            min: a.min(b) - reach,
            max: a.max(b) + reach,
        }
    }

    pub fn contains(&self, p: DVec3) -> bool {
        let d = p - self.center;
        let along = d.dot(self.axis);
        along.abs() <= 0.5 * self.height
            && (d - along * self.axis).length_squared() <= self.radius * self.radius
    }
}

impl Cuboid {
    pub fn bounds(&self) -> Aabb {
        Aabb {
            min: self.min,
            max: self.max,
        }
    }

    pub fn contains(&self, p: DVec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    /// The signed distance from `p` to the box's surface (negative inside) and its gradient,
    /// the unit outward normal of the nearest face, edge or corner.
    pub fn signed_distance(&self, p: DVec3) -> (f64, DVec3) {
        let centre = 0.5 * (self.min + self.max);
        let d = p - centre;
        let q = d.abs() - 0.5 * (self.max - self.min);
        let outside = q.max(DVec3::ZERO);
        let length = outside.length();
        let sign = DVec3::select(d.cmpge(DVec3::ZERO), DVec3::ONE, DVec3::NEG_ONE);
        if length > 0.0 {
            (length, sign * outside / length)
        } else {
            let axis = q.max_position();
            let mut n = DVec3::ZERO;
            n[axis] = sign[axis];
            (q[axis], n)
        }
    }
}

impl Quadric {
    pub fn bounds(&self) -> Aabb {
        Aabb {
            min: DVec3::splat(-self.half_extent),
            max: DVec3::splat(self.half_extent),
        }
    }

    /// The area inside the cube, by the midpoint rule over (x, y) on a 256 x 256 grid: the
    /// surface is z = -(x^2 + k y) / k, with area element sqrt(2 + (2x / k)^2), kept where z
    /// lies in the cube (for planning; within a percent or so).
    pub fn area(&self) -> f64 {
        const N: usize = 256;
        let e = self.half_extent;
        let step = 2.0 * e / N as f64;
        let mut sum = 0.0;
        for i in 0..N {
            let x = -e + (i as f64 + 0.5) * step;
            for j in 0..N {
                let y = -e + (j as f64 + 0.5) * step;
                let z = -(x * x + self.k * y) / self.k;
                if z.abs() <= e {
                    sum += (2.0 + (2.0 * x / self.k).powi(2)).sqrt();
                }
            }
        }
        sum * step * step
    }
}

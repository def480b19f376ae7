//! Solids with known volume and area, written as formulas (solid where F < 0), for measuring
//! how voxel volumes and areas converge: a sphere, a torus and a cube turned off the axes.

use super::{Coordinates, Formula};
use crate::mesh::Aabb;
use glam::{DMat3, DVec3};
use std::f64::consts::PI;

pub struct ReferenceSolid {
    pub name: &'static str,
    pub formula: Formula,
    pub bounds: Aabb,
    pub volume: f64,
    pub area: f64,
}

fn cube_bounds(half: f64) -> Aabb {
    Aabb {
        min: DVec3::splat(-half),
        max: DVec3::splat(half),
    }
}

pub fn reference_solids() -> Vec<ReferenceSolid> {
    let parse = |text: &str| Formula::parse(text, Coordinates::Cartesian).expect("a valid formula");
    let (big_r, r) = (1.0, 0.35);
    let half = 0.8;
    // The cube's axes: turned 30 degrees about z, then 20 degrees about x.
    let m = DMat3::from_rotation_x(20f64.to_radians()) * DMat3::from_rotation_z(30f64.to_radians());
    let row = |k: usize| {
        let v = m.row(k);
        format!("abs({:.17} * x + {:.17} * y + {:.17} * z)", v.x, v.y, v.z)
    };
    vec![
        ReferenceSolid {
            name: "sphere",
            formula: parse("x^2 + y^2 + z^2 - 1"),
            bounds: cube_bounds(1.05),
            volume: 4.0 / 3.0 * PI,
            area: 4.0 * PI,
        },
        ReferenceSolid {
            name: "torus",
            formula: parse(&format!("(sqrt(x^2 + y^2) - {big_r})^2 + z^2 - {}", r * r)),
            bounds: Aabb {
                min: DVec3::new(-1.4, -1.4, -0.4),
                max: DVec3::new(1.4, 1.4, 0.4),
            },
            volume: 2.0 * PI * PI * big_r * r * r,
            area: 4.0 * PI * PI * big_r * r,
        },
        ReferenceSolid {
            name: "turned cube",
            formula: parse(&format!(
                "max(max({}, {}), {}) - {half}",
                row(0),
                row(1),
                row(2)
            )),
            bounds: cube_bounds(half * 3f64.sqrt() + 0.05),
            volume: (2.0 * half).powi(3),
            area: 6.0 * (2.0 * half).powi(2),
        },
    ]
}

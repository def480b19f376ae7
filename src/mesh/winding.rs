//! The winding number of a mesh at a point: the signed solid angle its triangles subtend,
//! over 4π (Van Oosterom and Strackee's formula for a triangle's solid angle). For a closed,
//! consistently oriented mesh it is the signed count of shells around the point: 1 inside an
//! outward shell, -1 inside an inward one, 0 outside or in a cavity; for an open mesh it is
//! the generalized winding number, a fraction near its holes.

use super::Mesh;
use glam::DVec3;
use rayon::prelude::*;

/// The solid angle of triangle `abc` seen from the origin, signed by its orientation.
fn solid_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let numerator = a.dot(b.cross(c));
    let denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    2.0 * numerator.atan2(denominator)
}

/// The winding number of `mesh` at `p`.
pub fn winding_number(mesh: &Mesh, p: DVec3) -> f64 {
    let triangles: Vec<[u32; 3]> = mesh.triangles().map(|(_, t)| t).collect();
    let total: f64 = triangles
        .par_iter()
        .map(|t| solid_angle(mesh.p(t[0]) - p, mesh.p(t[1]) - p, mesh.p(t[2]) - p))
        .sum();
    total / (4.0 * std::f64::consts::PI)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate;

    #[test]
    fn a_cube_winds_once_around_its_inside_and_never_outside() {
        let cube = generate::cuboid(DVec3::ZERO, DVec3::ONE);
        assert!((winding_number(&cube, DVec3::splat(0.5)) - 1.0).abs() < 1e-12);
        assert!((winding_number(&cube, DVec3::new(0.1, 0.9, 0.3)) - 1.0).abs() < 1e-12);
        assert!(winding_number(&cube, DVec3::new(1.5, 0.5, 0.5)).abs() < 1e-12);
        assert!(winding_number(&cube, DVec3::splat(-3.0)).abs() < 1e-12);
    }

    #[test]
    fn an_open_box_winds_by_the_share_of_the_sky_it_covers() {
        // Without its top face, a cube seen from its centre covers five sixths of the sky.
        let mut cube = generate::cuboid(DVec3::ZERO, DVec3::ONE);
        let keep: Vec<Vec<u32>> = (0..cube.face_count())
            .filter(|&f| cube.face(f).iter().any(|&v| cube.p(v).z < 0.5))
            .map(|f| cube.face(f).to_vec())
            .collect();
        cube = Mesh::from_polygons(cube.source.clone(), cube.positions.clone(), &keep);
        let w = winding_number(&cube, DVec3::splat(0.5));
        assert!((w - 5.0 / 6.0).abs() < 1e-12, "{w}");
    }
}

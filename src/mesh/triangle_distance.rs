//! The distance from a point to a triangle: to its plane where the point projects inside it,
//! else to the nearest of its edges. Squared, so that comparisons need no square root.

use glam::DVec3;

/// The squared distance from `p` to the segment `ab`.
pub fn segment_distance_squared(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let d = b - a;
    let t = if d.length_squared() > 0.0 {
        ((p - a).dot(d) / d.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + d * t).distance_squared(p)
}

/// The distance from `p` to the segment `ab`.
pub fn segment_distance(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    segment_distance_squared(p, a, b).sqrt()
}

/// The squared distance from `p` to the triangle `abc` (a degenerate one: to its edges).
pub fn triangle_distance_squared(p: DVec3, [a, b, c]: [DVec3; 3]) -> f64 {
    let n = (b - a).cross(c - a);
    let n2 = n.length_squared();
    let inside = n2 > 0.0
        && [(a, b), (b, c), (c, a)]
            .iter()
            .all(|&(u, v)| (v - u).cross(p - u).dot(n) >= 0.0);
    if inside {
        let h = (p - a).dot(n);
        return h * h / n2;
    }
    segment_distance_squared(p, a, b)
        .min(segment_distance_squared(p, b, c))
        .min(segment_distance_squared(p, c, a))
}

/// The distance from `p` to the triangle `abc`.
pub fn triangle_distance(p: DVec3, t: [DVec3; 3]) -> f64 {
    triangle_distance_squared(p, t).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distances_to_the_face_its_edges_and_corners() {
        let t = [DVec3::ZERO, DVec3::X, DVec3::Y];
        assert!((triangle_distance(DVec3::new(0.2, 0.2, 3.0), t) - 3.0).abs() < 1e-12);
        assert!((triangle_distance(DVec3::new(0.5, -2.0, 0.0), t) - 2.0).abs() < 1e-12);
        assert!((triangle_distance(DVec3::new(-3.0, -4.0, 0.0), t) - 5.0).abs() < 1e-12);
        let hypotenuse = triangle_distance(DVec3::new(1.0, 1.0, 0.0), t);
        assert!((hypotenuse - 0.5f64.sqrt()).abs() < 1e-12);
        let flat = [DVec3::ZERO, DVec3::X, DVec3::X * 2.0];
        assert!((triangle_distance(DVec3::new(1.0, 1.0, 0.0), flat) - 1.0).abs() < 1e-12);
    }
}

//! The distance from a point to a triangle: to its plane where the point projects inside it,
//! else to the nearest of its edges. Squared, so that comparisons need no square root.

use glam::DVec3;

/// The point of segment `ab` nearest to `p`, as its parameter `t` in [0, 1] from `a`, and
/// its squared distance to `p`.
#[inline]
pub fn nearest_on_segment(p: DVec3, a: DVec3, b: DVec3) -> (f64, f64) {
    let d = b - a;
    let t = if d.length_squared() > 0.0 {
        ((p - a).dot(d) / d.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (t, (a + d * t).distance_squared(p))
}

/// The squared distance from `p` to the segment `ab`.
#[inline]
pub fn segment_distance_squared(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    nearest_on_segment(p, a, b).1
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

/// The point of triangle `abc` nearest to `p`, as barycentric weights of `a`, `b` and `c`:
/// the foot on its plane where `p` projects inside it, else the nearest point of the
/// nearest edge (as `triangle_distance_squared` measures).
pub fn nearest_on_triangle(p: DVec3, [a, b, c]: [DVec3; 3]) -> DVec3 {
    let n = (b - a).cross(c - a);
    let n2 = n.length_squared();
    let areas = [(b, c), (c, a), (a, b)].map(|(u, v)| (v - u).cross(p - u).dot(n));
    if n2 > 0.0 && areas.iter().all(|&w| w >= 0.0) {
        return DVec3::from_array(areas) / n2;
    }
    let mut best = (f64::INFINITY, DVec3::ZERO);
    for (i, j, u, v) in [(0, 1, a, b), (1, 2, b, c), (2, 0, c, a)] {
        let (t, d2) = nearest_on_segment(p, u, v);
        if d2 < best.0 {
            let mut w = DVec3::ZERO;
            w[i] = 1.0 - t;
            w[j] = t;
            best = (d2, w);
        }
    }
    best.1
}

/// The distance from `p` to the triangle `abc`.
pub fn triangle_distance(p: DVec3, t: [DVec3; 3]) -> f64 {
    triangle_distance_squared(p, t).sqrt()
}

#[cfg(test)]
mod tests {
    #[test]
    fn nearest_points_lie_at_the_distance() {
        use super::*;
        let mut random = crate::random::SplitMix64(7);
        for _ in 0..2000 {
            let mut point = || {
                DVec3::new(
                    random.range(-1.0, 1.0),
                    random.range(-1.0, 1.0),
                    random.range(-1.0, 1.0),
                )
            };
            let t = [point(), point(), point()];
            let p = point() * 2.0;
            let w = nearest_on_triangle(p, t);
            assert!((w.element_sum() - 1.0).abs() < 1e-12 && w.min_element() >= -1e-12);
            let q = w.x * t[0] + w.y * t[1] + w.z * t[2];
            let d = triangle_distance(p, t);
            assert!((q.distance(p) - d).abs() < 1e-9 * (1.0 + d), "{p} {t:?}");
        }
    }

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

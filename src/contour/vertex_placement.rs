//! Where a cycle's own vertex goes: the point that best fits the tangent planes at its
//! crossings (the quadratic error function of dual contouring, Ju et al. 2002), pulled
//! lightly towards the crossings' mean so that it is defined on flat and curved pieces alike,
//! kept strictly inside its cell, and given up for the mean when it would fold the fan.

use glam::DVec3;

/// The pull towards the mean, against a tangent plane's weight of 1 (index units).
const PULL: f64 = 0.01;
/// How far inside its cell's faces a vertex stays, in voxels: no fan triangle is flat.
pub const INSET: f64 = 0.01;

/// The vertex of a cycle whose crossings are `points` (in order) with unit `normals` (zero
/// where unknown), inside the cell `[low, low + 1]^3`.
pub fn cycle_vertex(points: &[DVec3], normals: &[DVec3], low: DVec3) -> DVec3 {
    let mean = points.iter().copied().sum::<DVec3>() / points.len() as f64;
    if normals.iter().all(|n| *n == DVec3::ZERO) {
        return mean;
    }
    // Normal equations of sum (n.(x - p))^2 + PULL |x - mean|^2, in coordinates about the mean.
    let mut a = [[0.0f64; 3]; 3];
    let mut b = DVec3::ZERO;
    for (p, n) in points.iter().zip(normals) {
        let d = n.dot(*p - mean);
        for i in 0..3 {
            for j in 0..3 {
                a[i][j] += n[i] * n[j];
            }
        }
        b += *n * d;
    }
    for (i, row) in a.iter_mut().enumerate() {
        row[i] += PULL;
    }
    let Some(x) = solve_symmetric(a, b) else {
        return mean;
    };
    let x = (mean + x).clamp(low + INSET, low + 1.0 - INSET);
    if folds(points, x) { mean } else { x }
}

/// How far off a triangle's plane its fan's centre must lie for the fan to stand clear of it.
const OFF_PLANE: f64 = 1e-6;

/// Whether the fan from `centre` over the cycle may cross itself: whether it turns any
/// triangle against the cycle's own orientation. A triangle's fan is three faces of a
/// tetrahedron, which meet only along their edges, wherever the centre lies off its plane:
/// a corner of a solid (three planes) lands where it is, however the tetrahedron leans.
fn folds(points: &[DVec3], centre: DVec3) -> bool {
    let n = points.len();
    let mean = points.iter().copied().sum::<DVec3>() / n as f64;
    let area: DVec3 = (0..n)
        .map(|i| (points[i] - mean).cross(points[(i + 1) % n] - mean))
        .sum();
    if n == 3
        && let Some(normal) = area.try_normalize()
        && normal.dot(centre - mean).abs() > OFF_PLANE
    {
        return false;
    }
    (0..n).any(|i| {
        (points[i] - centre)
            .cross(points[(i + 1) % n] - centre)
            .dot(area)
            <= 0.0
    })
}

/// `a x = b` for a symmetric positive definite `a` (Cholesky), or none when it is not.
fn solve_symmetric(a: [[f64; 3]; 3], b: DVec3) -> Option<DVec3> {
    let mut l = [[0.0f64; 3]; 3];
    for i in 0..3 {
        for j in 0..=i {
            let s: f64 = a[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
            if i == j {
                if s <= 0.0 {
                    return None;
                }
                l[i][i] = s.sqrt();
            } else {
                l[i][j] = s / l[j][j];
            }
        }
    }
    let mut y = [0.0f64; 3];
    for i in 0..3 {
        y[i] = (b[i] - (0..i).map(|k| l[i][k] * y[k]).sum::<f64>()) / l[i][i];
    }
    let mut x = [0.0f64; 3];
    for i in (0..3).rev() {
        x[i] = (y[i] - (i + 1..3).map(|k| l[k][i] * x[k]).sum::<f64>()) / l[i][i];
    }
    Some(DVec3::from_array(x))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Three planes meeting at a corner inside the cell: the vertex lands on the corner.
    #[test]
    fn three_planes_give_their_corner() {
        let corner = DVec3::new(0.3, 0.6, 0.4);
        let points = [
            DVec3::new(0.3, 0.0, 0.0),
            DVec3::new(0.0, 0.6, 1.0),
            DVec3::new(1.0, 1.0, 0.4),
        ];
        let normals = [DVec3::X, DVec3::Y, DVec3::Z];
        let v = cycle_vertex(&points, &normals, DVec3::ZERO);
        // The pull moves it by well under a hundredth of a voxel.
        assert!((v - corner).length() < 0.05, "{v}");
    }
}

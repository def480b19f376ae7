//! Comparing the evaluator with expected limit points (reference files, or OpenSubdiv live).

use super::points_file::SurfacePoint;
use super::surface::LimitSurface;
use crate::error::Result;
use glam::DVec3;
use rayon::prelude::*;

/// The worst disagreement over a set of points.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Comparison {
    pub points: usize,
    /// Largest position distance, absolute and divided by the bbox diagonal of the expected
    /// positions.
    pub max_position_error: f64,
    pub max_relative_position_error: f64,
    /// Largest angle between normals, in radians.
    pub max_normal_angle: f64,
    /// The point where the normal angle was largest.
    pub worst_normal_at: Option<(usize, f64, f64)>,
}

/// Angle between two unit vectors, accurate for tiny angles too.
pub fn angle_between(a: DVec3, b: DVec3) -> f64 {
    a.cross(b).length().atan2(a.dot(b))
}

/// Evaluates every point that carries an expected value and reports the worst errors.
pub fn compare_points(surface: &LimitSurface, points: &[SurfacePoint]) -> Result<Comparison> {
    let with_expected: Vec<(&SurfacePoint, DVec3, DVec3)> = points
        .iter()
        .filter_map(|p| p.expected.map(|(x, n)| (p, x, n)))
        .collect();
    let errors: Vec<(f64, f64, &SurfacePoint)> = with_expected
        .par_iter()
        .map(|&(p, x, n)| {
            let s = surface.evaluate(p.face, p.u, p.v)?;
            Ok((
                (s.position - x).length(),
                angle_between(s.normal, n.normalize()),
                p,
            ))
        })
        .collect::<Result<_>>()?;
    let (lo, hi) = with_expected.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), &(_, x, _)| (lo.min(x), hi.max(x)),
    );
    let diagonal = (hi - lo).length();
    let mut c = Comparison {
        points: errors.len(),
        ..Default::default()
    };
    for (dp, dn, p) in errors {
        c.max_position_error = c.max_position_error.max(dp);
        if dn > c.max_normal_angle || c.worst_normal_at.is_none() {
            c.max_normal_angle = c.max_normal_angle.max(dn);
            c.worst_normal_at = Some((p.face, p.u, p.v));
        }
    }
    c.max_relative_position_error = if diagonal > 0.0 {
        c.max_position_error / diagonal
    } else {
        c.max_position_error
    };
    Ok(c)
}

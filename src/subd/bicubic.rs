//! The uniform bicubic B-spline patch: the exact Catmull-Clark limit surface of a regular
//! face, and the Bezier form of any sub-rectangle (whose control points bound the piece).

use glam::DVec3;

/// 16 control points `p[i][j]`, `i` along u and `j` along v; the face itself is the middle
/// cell (`p[1][1]` is corner 0 of the face, `p[2][1]` corner 1, `p[2][2]` corner 2).
#[derive(Clone, Debug)]
pub(crate) struct Bicubic {
    pub p: [[DVec3; 4]; 4],
}

/// Cubic B-spline basis functions and their first derivatives at `t`.
#[inline]
fn basis(t: f64) -> ([f64; 4], [f64; 4]) {
    let s = 1.0 - t;
    let t2 = t * t;
    let t3 = t2 * t;
    let b = [
        s * s * s / 6.0,
        (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0,
        (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0,
        t3 / 6.0,
    ];
    let d = [
        -s * s / 2.0,
        (3.0 * t2 - 4.0 * t) / 2.0,
        (-3.0 * t2 + 2.0 * t + 1.0) / 2.0,
        t2 / 2.0,
    ];
    (b, d)
}

/// Power-basis coefficients of the uniform cubic B-spline: `f(t) = [1 t t² t³] M P`.
const POWER: [[f64; 4]; 4] = [
    [1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0, 0.0],
    [-0.5, 0.0, 0.5, 0.0],
    [0.5, -1.0, 0.5, 0.0],
    [-1.0 / 6.0, 0.5, -0.5, 1.0 / 6.0],
];

/// Rows map the 4 B-spline control points of one direction to the 4 Bezier control points
/// of the curve restricted to `[a, b]`: Bezier point `k` is the blossom at
/// `(a^(3-k), b^k)`, and the blossom of `c0 + c1 t + c2 t² + c3 t³` at `(x, y, z)` is
/// `c0 + c1 (x+y+z)/3 + c2 (xy+yz+zx)/3 + c3 xyz`.
fn restriction(a: f64, b: f64) -> [[f64; 4]; 4] {
    let mut out = [[0.0; 4]; 4];
    for (k, row) in out.iter_mut().enumerate() {
        let mut args = [a; 3];
        for arg in args.iter_mut().take(k) {
            *arg = b;
        }
        let [x, y, z] = args;
        let w = [
            1.0,
            (x + y + z) / 3.0,
            (x * y + y * z + z * x) / 3.0,
            x * y * z,
        ];
        for (i, r) in row.iter_mut().enumerate() {
            *r = (0..4).map(|p| w[p] * POWER[p][i]).sum();
        }
    }
    out
}

impl Bicubic {
    /// Position and both first derivatives at `(u, v)` in `[0,1]²`.
    #[inline]
    pub fn eval(&self, u: f64, v: f64) -> (DVec3, DVec3, DVec3) {
        let (bu, du) = basis(u);
        let (bv, dv) = basis(v);
        let mut p = DVec3::ZERO;
        let mut pu = DVec3::ZERO;
        let mut pv = DVec3::ZERO;
        for i in 0..4 {
            let mut row_b = DVec3::ZERO;
            let mut row_d = DVec3::ZERO;
            for j in 0..4 {
                row_b += bv[j] * self.p[i][j];
                row_d += dv[j] * self.p[i][j];
            }
            p += bu[i] * row_b;
            pu += du[i] * row_b;
            pv += bu[i] * row_d;
        }
        (p, pu, pv)
    }

    /// A bound on `|S_uu| + 2 |S_uv| + |S_vv|` over the patch: each second derivative is a
    /// convex combination (B-spline weights) of the net's second differences, so its length is
    /// at most theirs.
    pub fn second_derivative_bound(&self) -> f64 {
        let p = &self.p;
        let mut along_u = 0.0f64;
        let mut along_v = 0.0f64;
        let mut mixed = 0.0f64;
        for (a, row) in p.iter().enumerate() {
            for b in 0..2 {
                along_u = along_u.max((p[b][a] - 2.0 * p[b + 1][a] + p[b + 2][a]).length());
                along_v = along_v.max((row[b] - 2.0 * row[b + 1] + row[b + 2]).length());
            }
        }
        for i in 0..3 {
            for j in 0..3 {
                let twist = p[i + 1][j + 1] - p[i + 1][j] - p[i][j + 1] + p[i][j];
                mixed = mixed.max(twist.length());
            }
        }
        along_u + 2.0 * mixed + along_v
    }

    /// Bounding box of the piece over `[u0,u1] x [v0,v1]`: the box of its 16 Bezier control
    /// points, which contain the piece (convex hull property).
    pub fn bound(&self, u0: f64, u1: f64, v0: f64, v1: f64) -> (DVec3, DVec3) {
        let tu = restriction(u0, u1);
        let tv = restriction(v0, v1);
        let mut along_u = [[DVec3::ZERO; 4]; 4];
        for (k, row) in along_u.iter_mut().enumerate() {
            for (j, out) in row.iter_mut().enumerate() {
                *out = (0..4).map(|i| tu[k][i] * self.p[i][j]).sum();
            }
        }
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for row in &along_u {
            for weights in &tv {
                let q: DVec3 = (0..4).map(|j| weights[j] * row[j]).sum();
                lo = lo.min(q);
                hi = hi.max(q);
            }
        }
        (lo, hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample_patch() -> Bicubic {
        let mut p = [[DVec3::ZERO; 4]; 4];
        for (i, row) in p.iter_mut().enumerate() {
            for (j, q) in row.iter_mut().enumerate() {
                let (x, y) = (i as f64, j as f64);
                *q = DVec3::new(
                    x + 0.3 * y * y,
                    y - 0.2 * x * y,
                    (x * 1.7).sin() + y * y * 0.1,
                );
            }
        }
        Bicubic { p }
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let b = sample_patch();
        let h = 1e-6;
        for &(u, v) in &[(0.2, 0.7), (0.0, 1.0), (0.5, 0.5)] {
            let (_, pu, pv) = b.eval(u, v);
            let fu = (b.eval(u + h, v).0 - b.eval(u - h, v).0) / (2.0 * h);
            let fv = (b.eval(u, v + h).0 - b.eval(u, v - h).0) / (2.0 * h);
            assert!((pu - fu).length() < 1e-8 && (pv - fv).length() < 1e-8);
        }
    }

    #[test]
    fn second_derivatives_stay_within_the_bound() {
        let b = sample_patch();
        let bound = b.second_derivative_bound();
        let h = 1e-4;
        let mut largest = 0.0f64;
        for a in 0..=10 {
            for c in 0..=10 {
                let (u, v) = (0.05 + 0.09 * a as f64, 0.05 + 0.09 * c as f64);
                let f = |du: f64, dv: f64| b.eval(u + du, v + dv).0;
                let uu = (f(h, 0.0) - 2.0 * f(0.0, 0.0) + f(-h, 0.0)) / (h * h);
                let vv = (f(0.0, h) - 2.0 * f(0.0, 0.0) + f(0.0, -h)) / (h * h);
                let uv = (f(h, h) - f(h, -h) - f(-h, h) + f(-h, -h)) / (4.0 * h * h);
                largest = largest.max(uu.length() + 2.0 * uv.length() + vv.length());
            }
        }
        assert!(largest <= bound * (1.0 + 1e-6), "{largest} > {bound}");
        assert!(
            largest > 0.3 * bound,
            "the bound is loose: {largest} against {bound}"
        );
    }

    #[test]
    fn bezier_bound_contains_dense_samples_and_is_tight_at_corners() {
        let b = sample_patch();
        let (u0, u1, v0, v1) = (0.3, 0.55, 0.1, 0.9);
        let (lo, hi) = b.bound(u0, u1, v0, v1);
        for a in 0..=40 {
            for c in 0..=40 {
                let u = u0 + (u1 - u0) * a as f64 / 40.0;
                let v = v0 + (v1 - v0) * c as f64 / 40.0;
                let p = b.eval(u, v).0;
                assert!(p.cmpge(lo - 1e-12).all() && p.cmple(hi + 1e-12).all());
            }
        }
        // The corner control points of the Bezier form are the patch's corner points.
        let corner = b.eval(u0, v0).0;
        assert!(corner.cmpge(lo).all() && corner.cmple(hi).all());
    }
}

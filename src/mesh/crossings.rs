//! Exact crossings of triangles with a lattice of parallel rays: the rays are the lines
//! `(a, b) = const` for integer `a, b`, running along the third coordinate `t` of the points
//! given. Each triangle whose `(a, b)` projection contains a ray's point crosses it once, at
//! the `t` of its plane there.
//!
//! One tie rule for every ray direction and every use (ray parity, depth layers single and
//! double): every voxel centre is perturbed symbolically by the same vector
//! `(e, e^2, e^3)` in index space (Edelsbrunner & Mücke's simulation of simplicity), seen in
//! each direction's `(a, b, t)` through its change of coordinates (`RayFrame`). A ray through a
//! projected edge or vertex is then decided by the perturbed `(a, b)`, with every edge function
//! evaluated from its lower-numbered vertex, so both triangles at an edge see the same answer
//! and a closed mesh is crossed an exact, even number of times along every ray; triangles seen
//! edge-on are missed. A centre exactly on a crossing lies on the side its perturbed `t` falls
//! (`RayCrossing::after`): a centre on a face lies inside or outside as a point just off it, in the
//! same place whichever direction looks at it, so the methods agree on surface voxels too.

use crate::grid::{ceil_int, floor_int};
use glam::{DVec2, DVec3};

/// The rays `a0 ..= a0 + width - 1` by `b0 ..= b0 + height - 1`, numbered
/// `(a - a0) * height + (b - b0)`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RayWindow {
    pub a0: i64,
    pub b0: i64,
    pub width: usize,
    pub height: usize,
}

impl RayWindow {
    pub fn len(&self) -> usize {
        self.width * self.height
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The number of ray `(a, b)`, which must lie in the window.
    #[inline]
    pub fn ray(&self, a: i64, b: i64) -> usize {
        (a - self.a0) as usize * self.height + (b - self.b0) as usize
    }
}

/// Rays along an integer direction `d` with a component of ±1 (the `k`th; `i`, `j` the others):
/// the coordinates `(a, b, t) = (p_i - t d_i, p_j - t d_j, p_k d_k)`, a unimodular change of
/// lattice coordinates, so the rays through voxel centres are the integer `(a, b)` and centres
/// sit at integer `t`; with the perturbation `(e, e^2, e^3)` of index space in these
/// coordinates, `(a, b, t) + sum_m e^m (alpha_m, beta_m, tau_m)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayFrame {
    pub d: [i64; 3],
    k: usize,
    i: usize,
    j: usize,
    alpha: [f64; 3],
    beta: [f64; 3],
    tau: [f64; 3],
}

impl RayFrame {
    /// Rays along `d`, which must have a component of ±1 (the last such is `k`).
    pub fn along(d: [i64; 3]) -> RayFrame {
        let k = (0..3)
            .rev()
            .find(|&a| d[a].abs() == 1)
            .expect("a ±1 component");
        let (i, j) = match k {
            0 => (1, 2),
            1 => (0, 2),
            _ => (0, 1),
        };
        // The images of the unit axes: the perturbation's coefficient of e^(m+1) is axis m's.
        let image = |m: usize| {
            let t = if m == k { d[k] } else { 0 };
            let a = i64::from(m == i) - t * d[i];
            let b = i64::from(m == j) - t * d[j];
            (a as f64, b as f64, t as f64)
        };
        let (mut alpha, mut beta, mut tau) = ([0.0; 3], [0.0; 3], [0.0; 3]);
        for m in 0..3 {
            (alpha[m], beta[m], tau[m]) = image(m);
        }
        RayFrame {
            d,
            k,
            i,
            j,
            alpha,
            beta,
            tau,
        }
    }

    /// `(a, b, t)` of an index-space point.
    #[inline]
    pub fn to_ray(&self, p: DVec3) -> DVec3 {
        let t = p[self.k] * self.d[self.k] as f64;
        DVec3::new(
            p[self.i] - t * self.d[self.i] as f64,
            p[self.j] - t * self.d[self.j] as f64,
            t,
        )
    }

    /// The index-space point of `(a, b, t)`.
    #[inline]
    pub fn from_ray(&self, r: DVec3) -> DVec3 {
        let mut p = DVec3::ZERO;
        p[self.k] = r.z * self.d[self.k] as f64;
        p[self.i] = r.x + r.z * self.d[self.i] as f64;
        p[self.j] = r.y + r.z * self.d[self.j] as f64;
        p
    }

    /// Ray `(a, b)` and `t` of an integer index-space point.
    #[inline]
    pub fn lattice_ray(&self, p: [i64; 3]) -> ([i64; 2], i64) {
        let t = p[self.k] * self.d[self.k];
        (
            [
                p[self.i] - t * self.d[self.i],
                p[self.j] - t * self.d[self.j],
            ],
            t,
        )
    }

    /// Sign of the edge function of `a -> b` at the perturbed `p`: +1 left of the edge, -1
    /// right.
    fn edge_side(&self, ia: u32, a: DVec2, ib: u32, b: DVec2, p: DVec2) -> f64 {
        let (flip, a, b) = if ia < ib { (1.0, a, b) } else { (-1.0, b, a) };
        let d = b - a;
        let e = d.x * (p.y - a.y) - d.y * (p.x - a.x);
        let s = if e != 0.0 {
            e.signum()
        } else {
            // e(p + sum e^m (alpha_m, beta_m)): the first power with a coefficient decides
            // (the coefficients span the plane, so one does for any edge).
            (0..3)
                .map(|m| d.x * self.beta[m] - d.y * self.alpha[m])
                .find(|&c| c != 0.0)
                .map_or(0.0, f64::signum)
        };
        flip * s
    }

    /// Whether a centre at `t` exactly on a crossing of the plane with normal `n` (in `(a, b,
    /// t)`) lies beyond it: its perturbed `t` against the plane's perturbed depth there.
    fn beyond(&self, n: DVec3) -> bool {
        // t + sum e^m tau_m - (t - sum e^m (n_a alpha_m + n_b beta_m) / n_t), times n_t.
        let c = (0..3)
            .map(|m| self.tau[m] * n.z + n.x * self.alpha[m] + n.y * self.beta[m])
            .find(|&c| c != 0.0)
            .unwrap_or(0.0);
        c * n.z > 0.0
    }
}

/// A crossing of a ray: its depth `t` and the first lattice `t` beyond it by the tie rule.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayCrossing {
    pub ray: usize,
    pub t: f64,
    /// The first centre beyond the crossing: centres `t' < after` lie before it.
    pub after: i64,
    /// The triangle's normal points along +t.
    pub rising: bool,
}

/// Calls `cross` for every crossing of a triangle of `points` (given as `(a, b, t)` of
/// `frame`) with a ray of `window`.
pub fn for_each_crossing(
    points: &[DVec3],
    triangles: impl Iterator<Item = [u32; 3]>,
    frame: &RayFrame,
    window: &RayWindow,
    mut cross: impl FnMut(RayCrossing),
) {
    if window.is_empty() {
        return;
    }
    let (a_last, b_last) = (
        window.a0 + window.width as i64 - 1,
        window.b0 + window.height as i64 - 1,
    );
    for t in triangles {
        let p = t.map(|i| points[i as usize]);
        let q = p.map(|v| v.truncate());
        let area = (q[1] - q[0]).perp_dot(q[2] - q[0]);
        if area == 0.0 {
            continue;
        }
        let orient = area.signum();
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        let lo = q[0].min(q[1]).min(q[2]);
        let hi = q[0].max(q[1]).max(q[2]);
        let a0 = ceil_int(lo.x).max(window.a0);
        let a1 = floor_int(hi.x).min(a_last);
        let b0 = ceil_int(lo.y).max(window.b0);
        let b1 = floor_int(hi.y).min(b_last);
        let beyond = frame.beyond(n);
        for a in a0..=a1 {
            for b in b0..=b1 {
                let c = DVec2::new(a as f64, b as f64);
                let inside = (0..3).all(|k| {
                    let (u, v) = (k, (k + 1) % 3);
                    frame.edge_side(t[u], q[u], t[v], q[v], c) == orient
                });
                if inside {
                    // The plane through p[0] with normal n, solved for t at (a, b).
                    let depth = p[0].z - (n.x * (c.x - p[0].x) + n.y * (c.y - p[0].y)) / n.z;
                    let up = ceil_int(depth);
                    let after = if up as f64 == depth && !beyond {
                        depth as i64 + 1
                    } else {
                        up
                    };
                    cross(RayCrossing {
                        ray: window.ray(a, b),
                        t: depth,
                        after,
                        rising: orient > 0.0,
                    });
                }
            }
        }
    }
}

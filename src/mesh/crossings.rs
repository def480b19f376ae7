//! Exact crossings of triangles with a lattice of parallel rays: the rays are the lines
//! `(a, b) = const` for integer `a, b`, running along the third coordinate `t` of the points
//! given. Each triangle whose `(a, b)` projection contains a ray's point crosses it once, at
//! the `t` of its plane there.
//!
//! Points exactly on a projected edge or vertex are decided by a symbolic perturbation of the
//! query point, `(a + e, b + e^2)`, with every edge function evaluated from its lower-numbered
//! vertex: both triangles at an edge then see the same answer, so a closed mesh is crossed an
//! exact, even number of times along every ray. Triangles seen edge-on are missed by the
//! perturbed ray.

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

/// Sign of the edge function of `a -> b` at the perturbed `p`: +1 left of the edge, -1 right.
fn edge_side(ia: u32, a: DVec2, ib: u32, b: DVec2, p: DVec2) -> f64 {
    let (flip, a, b) = if ia < ib { (1.0, a, b) } else { (-1.0, b, a) };
    let d = b - a;
    let e = d.x * (p.y - a.y) - d.y * (p.x - a.x);
    let s = if e != 0.0 {
        e.signum()
    } else if d.y != 0.0 {
        // e(p + (eps, eps^2)) = d.x eps^2 - d.y eps: the eps term decides.
        -d.y.signum()
    } else {
        d.x.signum()
    };
    flip * s
}

/// Calls `cross(ray, t, rising)` for every crossing of a triangle of `points` (given as
/// `(a, b, t)`) with a ray of `window`; `rising` when the triangle's normal points along +t.
pub fn for_each_crossing(
    points: &[DVec3],
    triangles: impl Iterator<Item = [u32; 3]>,
    window: &RayWindow,
    mut cross: impl FnMut(usize, f64, bool),
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
        let a0 = (lo.x.ceil() as i64).max(window.a0);
        let a1 = (hi.x.floor() as i64).min(a_last);
        let b0 = (lo.y.ceil() as i64).max(window.b0);
        let b1 = (hi.y.floor() as i64).min(b_last);
        for a in a0..=a1 {
            for b in b0..=b1 {
                let c = DVec2::new(a as f64, b as f64);
                let inside = (0..3).all(|k| {
                    let (u, v) = (k, (k + 1) % 3);
                    edge_side(t[u], q[u], t[v], q[v], c) == orient
                });
                if inside {
                    // The plane through p[0] with normal n, solved for t at (a, b).
                    let depth = p[0].z - (n.x * (c.x - p[0].x) + n.y * (c.y - p[0].y)) / n.z;
                    cross(window.ray(a, b), depth, orient > 0.0);
                }
            }
        }
    }
}

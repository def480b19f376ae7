//! Triangle voxelization by projection onto the plane of the dominant normal component
//! (Jegathese et al. §4.2, Fig. 4): the edges are scanned into left and right buffers, one
//! entry per scan-line, and each scan-line's span is filled by incremental interpolation of
//! the third coordinate and the attribute.
//!
//! Decided here where the paper is silent:
//! - The buffers hold, per scan-line `v = j`, the triangle's extent over the whole band
//!   `[j - 1/2, j + 1/2]` rather than at the line `v = j` alone. Bands of neighbouring lines
//!   share their boundary, so neighbouring spans overlap and thin, steep triangles leave no
//!   gap between scan-lines (the paper's per-line extents do).
//! - The span runs over the voxel centres `round(left) ..= round(right)`, and the third
//!   coordinate, interpolated at those centres, is held within the triangle's own range before
//!   it is rounded. With the dominant component chosen, the third coordinate changes by at most
//!   one per step along a span or across lines, so the voxels of a triangle are 26-connected
//!   (the paper's Claim 4).
//! - Edge ownership: every triangle covers its own edges, so two triangles sharing an edge may
//!   both emit its voxels (the grid keeps one, with the attribute of the nearer sample). Nothing
//!   between them is left uncovered.
//! - The attribute is the triangle's affine interpolant at the voxel's projection onto the
//!   plane along the dominant axis, held within the range of the vertex values. Where several
//!   triangles reach a voxel, the grid keeps the sample nearest the voxel's centre: how far the
//!   plane lies along the dominant axis (before it is held within the triangle's range), plus
//!   how far the projection lies outside the triangle, so that a triangle's own value beats a
//!   neighbour's extrapolated one.
//! - A triangle without area (the sine of an angle below 1e-9) is voxelized as its longest edge.

use super::attribute::Attribute;
use super::line::{dominant_axis, round, voxelize_segment};
use glam::DVec3;

/// Calls `emit(voxel, distance, attribute)` for the voxels of triangle `p` (index space) with
/// vertex attributes `c`, `distance` being how far the plane lies from the voxel centre along
/// the dominant axis. Voxels may repeat. Returns whether the triangle was degenerate (and
/// voxelized as its longest edge).
#[inline]
pub fn voxelize_triangle<A: Attribute>(
    p: [DVec3; 3],
    c: [A; 3],
    emit: impl FnMut([i64; 3], f64, A),
) -> bool {
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let n = e1.cross(e2);
    if too_thin(n, e1, e2) {
        let (a, b) = longest_edge(p);
        voxelize_segment(p[a], p[b], c[a], c[b], emit);
        return true;
    }
    // One copy of the scan per dominant axis, so every coordinate access is a constant.
    match dominant_axis(n) {
        0 => scan::<0, A>(p, c, n, emit),
        1 => scan::<1, A>(p, c, n, emit),
        _ => scan::<2, A>(p, c, n, emit),
    }
    false
}

/// The scan-lines of a triangle with dominant normal axis `W`, scanning along
/// `u = (W + 1) % 3` in lines of constant `v = (W + 2) % 3`.
#[inline(always)]
fn scan<const W: usize, A: Attribute>(
    p: [DVec3; 3],
    c: [A; 3],
    n: DVec3,
    mut emit: impl FnMut([i64; 3], f64, A),
) {
    let (u, v) = ((W + 1) % 3, (W + 2) % 3);
    let inv_nw = 1.0 / n[W];
    let dw_du = -n[u] * inv_nw;
    let dw_dv = -n[v] * inv_nw;
    let w_lo = p[0][W].min(p[1][W]).min(p[2][W]);
    let w_hi = p[0][W].max(p[1][W]).max(p[2][W]);
    let gradient = attribute_gradient(p, c, u, v);
    let (c_lo, c_hi) = (c[0].min(c[1]).min(c[2]), c[0].max(c[1]).max(c[2]));
    let q = p.map(|x| [x[u], x[v]]);
    let outside = A::CARRIED.then(|| Outside::new(q));
    let (j0, j1) = (
        round(q[0][1].min(q[1][1]).min(q[2][1])),
        round(q[0][1].max(q[1][1]).max(q[2][1])),
    );
    // One scan-line (most triangles of a fine mesh) spans all three corners; more need the
    // sides.
    let sides = (j1 > j0).then(|| Sides::new(q));
    for j in j0..=j1 {
        let (left, right) = match &sides {
            Some(sides) => sides.band(j),
            None => (
                q[0][0].min(q[1][0]).min(q[2][0]),
                q[0][0].max(q[1][0]).max(q[2][0]),
            ),
        };
        let (i0, i1) = (round(left), round(right));
        let du0 = i0 as f64 - q[0][0];
        let dv0 = j as f64 - q[0][1];
        let mut depth = p[0][W] + dw_du * du0 + dw_dv * dv0;
        let mut attr = affine_at(c[0], gradient, du0, dv0);
        for i in i0..=i1 {
            let held = depth.clamp(w_lo, w_hi);
            let k = round(held);
            let mut voxel = [0; 3];
            voxel[u] = i;
            voxel[v] = j;
            voxel[W] = k;
            let beyond = outside.as_ref().map_or(0.0, |o| o.at(i as f64, j as f64));
            emit(
                voxel,
                (depth - k as f64).abs() + beyond,
                attr.clamp_between(c_lo, c_hi),
            );
            depth += dw_du;
            attr = attr.add(gradient.0);
        }
    }
}

/// The projected triangle as its two sides between the lowest and highest vertex along the
/// scan axis `v`: the long edge `q0-q2`, and the short edges `q0-q1-q2`.
struct Sides {
    /// `(u, v)` corners sorted by `v`.
    q: [[f64; 2]; 3],
    /// `du/dv` along `q0-q2`, `q0-q1` and `q1-q2` (0 where an edge has no extent in `v`).
    slope: [f64; 3],
}

impl Sides {
    #[inline]
    fn new(mut q: [[f64; 2]; 3]) -> Self {
        if q[0][1] > q[1][1] {
            q.swap(0, 1);
        }
        if q[1][1] > q[2][1] {
            q.swap(1, 2);
        }
        if q[0][1] > q[1][1] {
            q.swap(0, 1);
        }
        let slope = |a: [f64; 2], b: [f64; 2]| {
            let dv = b[1] - a[1];
            if dv > 0.0 { (b[0] - a[0]) / dv } else { 0.0 }
        };
        Sides {
            q,
            slope: [slope(q[0], q[2]), slope(q[0], q[1]), slope(q[1], q[2])],
        }
    }

    /// The ends of the cross-section at `v = y`, for `y` in the triangle's range.
    #[inline]
    fn section(&self, y: f64) -> (f64, f64) {
        let [a, m, _] = self.q;
        let long = a[0] + self.slope[0] * (y - a[1]);
        let short = if y < m[1] {
            a[0] + self.slope[1] * (y - a[1])
        } else {
            m[0] + self.slope[2] * (y - m[1])
        };
        (long.min(short), long.max(short))
    }

    /// The left and right ends of the triangle over the band `[j - 1/2, j + 1/2]`: the
    /// cross-sections where the band's edges cut it, and the middle corner when it lies in the
    /// band.
    #[inline]
    fn band(&self, j: i64) -> (f64, f64) {
        let [a, m, b] = self.q;
        let y0 = (j as f64 - 0.5).max(a[1]);
        let y1 = (j as f64 + 0.5).min(b[1]);
        let (l0, r0) = self.section(y0);
        let (l1, r1) = self.section(y1);
        let (mut left, mut right) = (l0.min(l1), r0.max(r1));
        if y0 <= m[1] && m[1] <= y1 {
            left = left.min(m[0]);
            right = right.max(m[0]);
        }
        (left, right)
    }
}

/// How far a point of the projection plane lies outside the projected triangle: the largest
/// distance beyond one of its edges' lines (0 inside).
struct Outside {
    /// Per edge: its inward unit normal `(nu, nv)` and offset, `nu * u + nv * v + offset`
    /// being the signed distance inside.
    edges: [[f64; 3]; 3],
}

impl Outside {
    #[inline]
    fn new(q: [[f64; 2]; 3]) -> Self {
        let area =
            (q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - (q[1][1] - q[0][1]) * (q[2][0] - q[0][0]);
        let sign = area.signum();
        let edges = [(0, 1), (1, 2), (2, 0)].map(|(a, b)| {
            let (du, dv) = (q[b][0] - q[a][0], q[b][1] - q[a][1]);
            let length = du.hypot(dv).max(f64::MIN_POSITIVE);
            let (nu, nv) = (-dv * sign / length, du * sign / length);
            [nu, nv, -(nu * q[a][0] + nv * q[a][1])]
        });
        Outside { edges }
    }

    #[inline]
    fn at(&self, u: f64, v: f64) -> f64 {
        self.edges
            .iter()
            .map(|[nu, nv, c]| -(nu * u + nv * v + c))
            .fold(0.0, f64::max)
    }
}

/// The gradient of the affine interpolant of `c` in the `(u, v)` projection plane (Cramer's
/// rule on the two edges from vertex 0).
#[inline]
fn attribute_gradient<A: Attribute>(p: [DVec3; 3], c: [A; 3], u: usize, v: usize) -> (A, A) {
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let det = e1[u] * e2[v] - e1[v] * e2[u];
    let (c1, c2) = (c[1].sub(c[0]), c[2].sub(c[0]));
    let da_du = c1.scale(e2[v] / det).sub(c2.scale(e1[v] / det));
    let da_dv = c2.scale(e1[u] / det).sub(c1.scale(e2[u] / det));
    (da_du, da_dv)
}

/// The affine interpolant with value `c0` at vertex 0 and gradient `(da_du, da_dv)`, at
/// `(du0, dv0)` from vertex 0 in the projection plane.
#[inline]
fn affine_at<A: Attribute>(c0: A, (da_du, da_dv): (A, A), du0: f64, dv0: f64) -> A {
    c0.add(da_du.scale(du0)).add(da_dv.scale(dv0))
}

/// Whether triangle `p` has too little area for a plane: the sine of its angle at `p[0]` is
/// below 1e-9 (its width across the longest edge is then far below a voxel, and the plane's
/// normal is rounding noise).
#[inline]
pub fn is_degenerate(p: [DVec3; 3]) -> bool {
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    too_thin(e1.cross(e2), e1, e2)
}

/// `is_degenerate` for edges `e1`, `e2` from `p[0]` and their cross product `n`.
#[inline]
fn too_thin(n: DVec3, e1: DVec3, e2: DVec3) -> bool {
    let nn = n.length_squared();
    !nn.is_finite() || nn <= 1e-18 * e1.length_squared() * e2.length_squared()
}

/// The two vertices farthest apart.
fn longest_edge(p: [DVec3; 3]) -> (usize, usize) {
    [(0, 1), (1, 2), (2, 0)]
        .into_iter()
        .max_by(|&(a, b), &(c, d)| {
            p[a].distance_squared(p[b])
                .total_cmp(&p[c].distance_squared(p[d]))
        })
        .unwrap_or((0, 1))
}

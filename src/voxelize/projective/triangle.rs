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
//!   plane along the dominant axis, held within the range of the vertex values.
//! - A triangle without area is voxelized as its longest edge.

use super::attribute::Attribute;
use super::line::{round, voxelize_segment};
use glam::DVec3;

/// Scan-lines kept on the stack; larger triangles take a heap buffer.
const STACK_LINES: usize = 32;

/// Calls `emit(voxel, distance, attribute)` for the voxels of triangle `p` (index space) with
/// vertex attributes `c`, `distance` being how far the plane lies from the voxel centre along
/// the dominant axis. Voxels may repeat.
#[inline]
pub fn voxelize_triangle<A: Attribute>(
    p: [DVec3; 3],
    c: [A; 3],
    mut emit: impl FnMut([i64; 3], f64, A),
) {
    let n = (p[1] - p[0]).cross(p[2] - p[0]);
    let an = n.abs();
    // The paper's choice: z unless x or y is strictly larger.
    let w = if an.x > an.y && an.x > an.z {
        0
    } else if an.y > an.x && an.y > an.z {
        1
    } else {
        2
    };
    if an[w] == 0.0 || !an[w].is_finite() {
        let (a, b) = longest_edge(p);
        return voxelize_segment(p[a], p[b], c[a], c[b], emit);
    }
    let (u, v) = ((w + 1) % 3, (w + 2) % 3);
    let dw_du = -n[u] / n[w];
    let dw_dv = -n[v] / n[w];
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    // The attribute's gradient in the projection plane (Cramer's rule on the two edges).
    let det = e1[u] * e2[v] - e1[v] * e2[u];
    let (c1, c2) = (c[1].sub(c[0]), c[2].sub(c[0]));
    let da_du = c1.scale(e2[v] / det).sub(c2.scale(e1[v] / det));
    let da_dv = c2.scale(e1[u] / det).sub(c1.scale(e2[u] / det));
    let (c_lo, c_hi) = (c[0].min(c[1]).min(c[2]), c[0].max(c[1]).max(c[2]));
    let w_lo = p[0][w].min(p[1][w]).min(p[2][w]);
    let w_hi = p[0][w].max(p[1][w]).max(p[2][w]);

    let v_lo = p[0][v].min(p[1][v]).min(p[2][v]);
    let v_hi = p[0][v].max(p[1][v]).max(p[2][v]);
    let (j0, j1) = (round(v_lo), round(v_hi));
    let lines = (j1 - j0 + 1) as usize;
    let mut stack = [(f64::INFINITY, f64::NEG_INFINITY); STACK_LINES];
    let mut heap = Vec::new();
    let spans: &mut [(f64, f64)] = if lines <= STACK_LINES {
        &mut stack[..lines]
    } else {
        heap.resize(lines, (f64::INFINITY, f64::NEG_INFINITY));
        &mut heap
    };
    for (a, b) in [(0, 1), (1, 2), (2, 0)] {
        let (a, b) = if p[a][v] <= p[b][v] {
            (p[a], p[b])
        } else {
            (p[b], p[a])
        };
        scan_edge([a[u], a[v]], [b[u], b[v]], j0, spans);
    }
    for (line, &(left, right)) in spans.iter().enumerate() {
        let j = j0 + line as i64;
        let (i0, i1) = (round(left), round(right));
        let du0 = i0 as f64 - p[0][u];
        let dv0 = j as f64 - p[0][v];
        let mut depth = p[0][w] + dw_du * du0 + dw_dv * dv0;
        let mut attr = c[0].add(da_du.scale(du0)).add(da_dv.scale(dv0));
        for i in i0..=i1 {
            let held = depth.clamp(w_lo, w_hi);
            let k = round(held);
            let mut voxel = [0; 3];
            voxel[u] = i;
            voxel[v] = j;
            voxel[w] = k;
            emit(
                voxel,
                (held - k as f64).abs(),
                attr.clamp_between(c_lo, c_hi),
            );
            depth += dw_du;
            attr = attr.add(da_du);
        }
    }
}

/// Widens the span of every scan-line band `[j - 1/2, j + 1/2]` the edge `a`-`b` (given as
/// `(u, v)` with `a.v <= b.v`) passes through by the edge's extent within the band.
#[inline]
fn scan_edge(a: [f64; 2], b: [f64; 2], j0: i64, spans: &mut [(f64, f64)]) {
    let widen = |span: &mut (f64, f64), x0: f64, x1: f64| {
        span.0 = span.0.min(x0.min(x1));
        span.1 = span.1.max(x0.max(x1));
    };
    let (ja, jb) = (round(a[1]), round(b[1]));
    if ja == jb {
        return widen(&mut spans[(ja - j0) as usize], a[0], b[0]);
    }
    let du_dv = (b[0] - a[0]) / (b[1] - a[1]);
    // u where the edge leaves each band, stepped from band to band.
    let mut exit = a[0] + du_dv * (ja as f64 + 0.5 - a[1]);
    widen(&mut spans[(ja - j0) as usize], a[0], exit);
    for j in ja + 1..jb {
        let enter = exit;
        exit += du_dv;
        widen(&mut spans[(j - j0) as usize], enter, exit);
    }
    widen(&mut spans[(jb - j0) as usize], exit, b[0]);
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

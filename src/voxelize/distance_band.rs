//! The narrow band of exact distances to a mesh: every voxel whose centre lies within `band`
//! voxels of a triangle, with the distance to the nearest point of the nearest triangle,
//! computed in f64 (closest point on a triangle by its Voronoi regions) and kept as f32 in
//! voxel units. The sign (inside or outside) is not decided here: see `solids::level_set`.

use super::Progress;
use super::brick_bins::{BrickSink, voxelize_in_bricks};
use crate::error::{Error, Result};
use crate::grid::{Channels, CoordBox, SparseGrid, Transform};
use crate::mesh::Mesh;
use glam::DVec3;

/// The closest point of triangle `abc` to `p` (Ericson, Real-Time Collision Detection §5.1.5).
pub fn closest_point_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

/// Unsigned distances in voxels (value channel) on every voxel within `band` voxels of a
/// triangle of `mesh`, computed in 64^3 bricks on all threads; `progress` counts triangles.
pub fn distance_band(
    mesh: &Mesh,
    transform: Transform,
    band: f64,
    progress: &Progress,
) -> Result<SparseGrid> {
    mesh.validate()?;
    if !(band.is_finite() && band >= 1.0) {
        return Err(Error::InvalidArgument(format!(
            "the band must be at least one voxel wide, got {band}"
        )));
    }
    let pos: Vec<DVec3> = mesh
        .positions
        .iter()
        .map(|&p| transform.world_to_index(p))
        .collect();
    let triangles: Vec<[DVec3; 3]> = mesh
        .triangles()
        .map(|(_, t)| t.map(|i| pos[i as usize]))
        .collect();
    let channels = Channels {
        value: true,
        ..Channels::NONE
    };
    let candidates = |_, i: usize| {
        let [a, b, c] = triangles[i];
        CoordBox {
            min: (a.min(b).min(c) - band).ceil().as_i64vec3().to_array(),
            max: (a.max(b).max(c) + band).floor().as_i64vec3().to_array(),
        }
    };
    let (grid, _) = voxelize_in_bricks(
        [triangles.len()],
        transform,
        channels,
        progress,
        candidates,
        |_, i, clip, sink| triangle_band(triangles[i], band, clip, sink),
    )?;
    Ok(grid)
}

/// The voxels in `clip` within `band` of triangle `abc` (index space), with their distances.
/// Columns run along the normal's largest axis, each limited to the slab within `band` of
/// the triangle's plane and to the prism within `band` of its edges. Along a column the
/// plane distance and the edge functions are linear: where all edge functions are
/// non-negative the nearest point is the centre's projection and the distance the plane
/// distance; elsewhere the closest point is computed.
fn triangle_band([a, b, c]: [DVec3; 3], band: f64, clip: &CoordBox, sink: &mut BrickSink<1>) {
    let lo = (a.min(b).min(c) - band).ceil().as_i64vec3().to_array();
    let hi = (a.max(b).max(c) + band).floor().as_i64vec3().to_array();
    let range = |axis: usize| lo[axis].max(clip.min[axis])..=hi[axis].min(clip.max[axis]);
    let band2 = band * band;
    let Some(n) = (b - a).cross(c - a).try_normalize() else {
        // No plane: every centre of the box is tried.
        for x in range(0) {
            for y in range(1) {
                for z in range(2) {
                    let p = DVec3::new(x as f64, y as f64, z as f64);
                    let d2 = p.distance_squared(closest_point_on_triangle(p, a, b, c));
                    if d2 <= band2 {
                        sink.add_distance([x, y, z], d2.sqrt());
                    }
                }
            }
        }
        return;
    };
    let w = n.abs().max_position();
    let (u, v) = ((w + 1) % 3, (w + 2) % 3);
    // Linear functions f(p) = g·p + h: the plane distance, and the edge functions (in-plane
    // inward normals of length |edge|, positive inside).
    let plane = (n, -n.dot(a));
    let edges = [(a, b), (b, c), (c, a)].map(|(p, q)| {
        let m = n.cross(q - p);
        (m, -m.dot(p), m.length())
    });
    for iu in range(u) {
        for iv in range(v) {
            // Each function along the column: f(k) = f0 + k g_w.
            let at = |(g, h): (DVec3, f64)| g[u] * iu as f64 + g[v] * iv as f64 + h;
            let s0 = at(plane);
            // The slab |s| <= band and the prism e_i >= -band |m_i|, widened so rounding
            // drops no voxel (the exact test below decides).
            let (mut k0, mut k1) = {
                let (x0, x1) = ((-band - s0) / n[w], (band - s0) / n[w]);
                (x0.min(x1), x0.max(x1))
            };
            let mut empty = false;
            for &(m, h, len) in &edges {
                let e0 = at((m, h)) + band * len;
                if m[w] > 0.0 {
                    k0 = k0.max(-e0 / m[w]);
                } else if m[w] < 0.0 {
                    k1 = k1.min(-e0 / m[w]);
                } else if e0 < 0.0 {
                    empty = true;
                }
            }
            if empty || k0 > k1 {
                continue;
            }
            let slack = 1e-9 * (1.0 + k0.abs().max(k1.abs()));
            let first = (k0 - slack).ceil().max(*range(w).start() as f64) as i64;
            let last = (k1 + slack).floor().min(*range(w).end() as f64) as i64;
            for k in first..=last {
                let mut p = DVec3::ZERO;
                p[u] = iu as f64;
                p[v] = iv as f64;
                p[w] = k as f64;
                let projected_inside = edges.iter().all(|&(m, h, _)| m.dot(p) + h >= 0.0);
                let d2 = if projected_inside {
                    let s = n.dot(p) + plane.1;
                    s * s
                } else {
                    p.distance_squared(closest_point_on_triangle(p, a, b, c))
                };
                if d2 <= band2 {
                    let mut coord = [0i64; 3];
                    coord[u] = iu;
                    coord[v] = iv;
                    coord[w] = k;
                    sink.add_distance(coord, d2.sqrt());
                }
            }
        }
    }
}

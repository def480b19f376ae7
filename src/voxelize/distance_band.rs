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
    TriangleQuery::new(a, b, c).closest_point(p)
}

/// A triangle prepared for many distance queries: its corners, edges and their dot products.
struct TriangleQuery {
    a: DVec3,
    b: DVec3,
    c: DVec3,
    ab: DVec3,
    ac: DVec3,
    /// The edges' dot products: ab·ab, ab·ac, ac·ac.
    ab_ab: f64,
    ab_ac: f64,
    ac_ac: f64,
}

impl TriangleQuery {
    fn new(a: DVec3, b: DVec3, c: DVec3) -> Self {
        let (ab, ac) = (b - a, c - a);
        TriangleQuery {
            a,
            b,
            c,
            ab,
            ac,
            ab_ab: ab.dot(ab),
            ab_ac: ab.dot(ac),
            ac_ac: ac.dot(ac),
        }
    }

    /// The closest point of the triangle to `p`, by its Voronoi regions (vertices, edges,
    /// face), tested with the dot products of `p - a` with the two edges from `a`: those of
    /// `p - b` and `p - c` differ from them by the edges' own dot products.
    #[inline]
    fn closest_point(&self, p: DVec3) -> DVec3 {
        let ap = p - self.a;
        let (d1, d2) = (self.ab.dot(ap), self.ac.dot(ap));
        if d1 <= 0.0 && d2 <= 0.0 {
            return self.a;
        }
        let (d3, d4) = (d1 - self.ab_ab, d2 - self.ab_ac);
        if d3 >= 0.0 && d4 <= d3 {
            return self.b;
        }
        let vc = d1 * d4 - d3 * d2;
        if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
            return self.a + self.ab * (d1 / (d1 - d3));
        }
        let (d5, d6) = (d1 - self.ab_ac, d2 - self.ac_ac);
        if d6 >= 0.0 && d5 <= d6 {
            return self.c;
        }
        let vb = d5 * d2 - d1 * d6;
        if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
            return self.a + self.ac * (d2 / (d2 - d6));
        }
        let va = d3 * d6 - d5 * d4;
        if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
            return self.b + (self.c - self.b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
        }
        let denom = 1.0 / (va + vb + vc);
        self.a + self.ab * (vb * denom) + self.ac * (vc * denom)
    }

    #[inline]
    fn distance_squared(&self, p: DVec3) -> f64 {
        p.distance_squared(self.closest_point(p))
    }
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
    let query = TriangleQuery::new(a, b, c);
    // Every point of the triangle lies within `radius` of its centroid: a centre farther than
    // band + radius from it is out of the band.
    let centroid = (a + b + c) / 3.0;
    let radius = centroid
        .distance_squared(a)
        .max(centroid.distance_squared(b))
        .max(centroid.distance_squared(c))
        .sqrt();
    let reach2 = (band + radius) * (band + radius) * (1.0 + 1e-12);
    let Some(n) = (b - a).cross(c - a).try_normalize() else {
        // No plane: every centre of the box is tried.
        for x in range(0) {
            for y in range(1) {
                for z in range(2) {
                    let p = DVec3::new(x as f64, y as f64, z as f64);
                    let d2 = query.distance_squared(p);
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
                } else if p.distance_squared(centroid) > reach2 {
                    continue;
                } else {
                    query.distance_squared(p)
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

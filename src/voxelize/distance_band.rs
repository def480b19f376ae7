//! The narrow band of exact distances to a mesh: every voxel whose centre lies within `band`
//! voxels of a triangle, with the distance to the nearest point of the nearest triangle,
//! computed in f64 (closest point on a triangle by its Voronoi regions) and kept as f32 in
//! voxel units. The sign (inside or outside) is not decided here: see `solids::level_set`.

use super::Progress;
use super::sink::{Sink, voxelize_indexed};
use crate::error::{Error, Result};
use crate::grid::{Channels, SparseGrid, Transform};
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
/// triangle of `mesh`; `progress` counts faces.
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
    let channels = Channels {
        value: true,
        ..Channels::NONE
    };
    let grid = voxelize_indexed(
        mesh.face_count(),
        transform,
        channels,
        progress,
        |f, sink| {
            for t in mesh.fan(f) {
                let [a, b, c] = t.map(|i| pos[i as usize]);
                triangle_band(a, b, c, band, sink);
            }
        },
    );
    progress.check()?;
    Ok(grid)
}

/// The voxels within `band` of triangle `abc` (index space), with their distances.
fn triangle_band(a: DVec3, b: DVec3, c: DVec3, band: f64, sink: &mut Sink) {
    let lo = (a.min(b).min(c) - band).ceil().as_i64vec3();
    let hi = (a.max(b).max(c) + band).floor().as_i64vec3();
    let unit = (b - a).cross(c - a).try_normalize();
    // Every point of the triangle lies within `radius` of its centroid: a voxel farther than
    // band + radius from the centroid, or than the band from its plane, is out of the band.
    let centroid = (a + b + c) / 3.0;
    let radius = centroid
        .distance_squared(a)
        .max(centroid.distance_squared(b))
        .max(centroid.distance_squared(c))
        .sqrt();
    let reach = (band + radius) * (band + radius);
    let band2 = band * band;
    for x in lo.x..=hi.x {
        for y in lo.y..=hi.y {
            for z in lo.z..=hi.z {
                let p = DVec3::new(x as f64, y as f64, z as f64);
                if p.distance_squared(centroid) > reach
                    || unit.is_some_and(|n| (p - a).dot(n).abs() > band)
                {
                    continue;
                }
                let d2 = p.distance_squared(closest_point_on_triangle(p, a, b, c));
                if d2 <= band2 {
                    sink.add_distance([x, y, z], d2.sqrt());
                }
            }
        }
    }
}

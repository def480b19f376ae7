//! Which voxel centres lie inside a closed mesh, by ray parity along z.
//!
//! Every column of centres `(i, j)` casts one ray along +z; each triangle whose xy
//! projection contains the column adds a crossing. A centre is inside when an odd number of
//! crossings lies below it. Points exactly on a projected edge or vertex are decided by a
//! symbolic perturbation of the query point, `(x + e, y + e^2)`, with every edge function
//! evaluated from its lower-numbered vertex: both triangles at an edge then see the same
//! answer, so a closed mesh is crossed an exact, consistent number of times.

use crate::error::Result;
use crate::grid::{CoordBox, DenseMask, Transform};
use crate::mesh::Mesh;
use glam::{DVec2, DVec3};

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

/// Voxel centres inside the closed `mesh` (world units) over `bbox`, with `transform`.
pub fn inside_centres(mesh: &Mesh, transform: &Transform, bbox: CoordBox) -> Result<DenseMask> {
    let mut inside = DenseMask::new(bbox)?;
    let pos: Vec<DVec3> = mesh
        .positions
        .iter()
        .map(|&p| transform.world_to_index(p))
        .collect();
    let [nx, ny, _] = inside.dims();
    let mut crossings: Vec<(u32, f64)> = Vec::new();
    for (_, t) in mesh.triangles() {
        let p = t.map(|i| pos[i as usize]);
        let q = p.map(|v| v.truncate());
        let area = (q[1] - q[0]).perp_dot(q[2] - q[0]);
        if area == 0.0 {
            continue; // seen edge-on: the perturbed ray misses it
        }
        let orient = area.signum();
        let n = (p[1] - p[0]).cross(p[2] - p[0]);
        let lo = q[0].min(q[1]).min(q[2]);
        let hi = q[0].max(q[1]).max(q[2]);
        let x0 = (lo.x.ceil() as i64).max(bbox.min[0]);
        let x1 = (hi.x.floor() as i64).min(bbox.max[0]);
        let y0 = (lo.y.ceil() as i64).max(bbox.min[1]);
        let y1 = (hi.y.floor() as i64).min(bbox.max[1]);
        for x in x0..=x1 {
            for y in y0..=y1 {
                let c = DVec2::new(x as f64, y as f64);
                let inside_tri = (0..3).all(|k| {
                    let (a, b) = (k, (k + 1) % 3);
                    edge_side(t[a], q[a], t[b], q[b], c) == orient
                });
                if inside_tri {
                    // Plane through p[0] with normal n, solved for z at (x, y).
                    let z = p[0].z - (n.x * (c.x - p[0].x) + n.y * (c.y - p[0].y)) / n.z;
                    let column = (x - bbox.min[0]) as usize * ny + (y - bbox.min[1]) as usize;
                    crossings.push((column as u32, z));
                }
            }
        }
    }
    crossings.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut i = 0;
    while i < crossings.len() {
        let column = crossings[i].0 as usize;
        let mut j = i;
        while j < crossings.len() && crossings[j].0 as usize == column {
            j += 1;
        }
        let (x, y) = (column / ny, column % ny);
        debug_assert!(x < nx);
        // Between crossing 2m and 2m+1 (sorted) the ray is inside.
        for pair in crossings[i..j].chunks_exact(2) {
            let z0 = (pair[0].1.ceil() as i64).max(bbox.min[2]);
            let z1 = (pair[1].1.floor() as i64).min(bbox.max[2]);
            for z in z0..=z1 {
                inside.set([bbox.min[0] + x as i64, bbox.min[1] + y as i64, z]);
            }
        }
        i = j;
    }
    Ok(inside)
}

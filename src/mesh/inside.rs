//! Which voxel centres lie inside a closed mesh, by ray parity along z: every column of
//! centres `(i, j)` casts one ray along +z (exact crossings, see `crossings`), and a centre is
//! inside when an odd number of crossings lies below it.

use super::crossings::{RayWindow, for_each_crossing};
use crate::error::Result;
use crate::grid::{CoordBox, DenseMask, Transform};
use crate::mesh::Mesh;
use glam::DVec3;

/// Voxel centres inside the closed `mesh` (world units) over `bbox`, with `transform`.
pub fn inside_centres(mesh: &Mesh, transform: &Transform, bbox: CoordBox) -> Result<DenseMask> {
    let mut inside = DenseMask::new(bbox)?;
    let pos: Vec<DVec3> = mesh
        .positions
        .iter()
        .map(|&p| transform.world_to_index(p))
        .collect();
    let [nx, ny, _] = inside.dims();
    let window = RayWindow {
        a0: bbox.min[0],
        b0: bbox.min[1],
        width: nx,
        height: ny,
    };
    let mut crossings: Vec<(u32, f64)> = Vec::new();
    for_each_crossing(&pos, mesh.triangles().map(|(_, t)| t), &window, |ray, z| {
        crossings.push((ray as u32, z))
    });
    crossings.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    for column in crossings.chunk_by(|a, b| a.0 == b.0) {
        let ray = column[0].0 as usize;
        let (x, y) = (ray / ny, ray % ny);
        // Between crossing 2m and 2m+1 (sorted) the ray is inside.
        for pair in column.chunks_exact(2) {
            let z0 = (pair[0].1.ceil() as i64).max(bbox.min[2]);
            let z1 = (pair[1].1.floor() as i64).min(bbox.max[2]);
            if z0 <= z1 {
                let column = [bbox.min[0] + x as i64, bbox.min[1] + y as i64];
                let first = inside.index([column[0], column[1], z0]);
                inside.set_index_range(first, first + (z1 - z0) as usize);
            }
        }
    }
    Ok(inside)
}

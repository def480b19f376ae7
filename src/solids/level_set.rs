//! Level sets of closed meshes: the narrow band of exact distances (`voxelize::distance_band`)
//! signed by where each voxel centre lies, inside or outside, by ray parity
//! (`mesh::inside`), which needs no consistent orientation: inward-facing or mixed normals
//! give the same level set. Values are in world units, negative inside, as OpenVDB's level
//! sets are.

use crate::error::Result;
use crate::grid::{SparseGrid, Transform};
use crate::mesh::Mesh;
use crate::mesh::inside::inside_centres;
use crate::progress::Progress;
use crate::voxelize::distance_band::distance_band;

/// Why a signed distance needs a closed mesh, for the error that refuses an open one.
const SIGN_NEEDS_CLOSED: &str = "a signed distance needs an inside, which an open surface does \
     not have (--udf writes unsigned distances)";

/// Signed distances (world units, negative inside) on every voxel within `band` voxels of
/// the closed `mesh`.
pub fn level_set(
    mesh: &Mesh,
    transform: Transform,
    band: f64,
    progress: &Progress,
) -> Result<SparseGrid> {
    mesh.require_closed(SIGN_NEEDS_CLOSED)?;
    let mut grid = distance_band(mesh, transform, band, progress)?;
    let Some(bbox) = grid.bbox() else {
        return Ok(grid);
    };
    let inside = inside_centres(mesh, &transform, bbox)?;
    let h = transform.voxel_size as f32;
    grid.map_values(|c, d| if inside.get(c) { -d * h } else { d * h });
    Ok(grid)
}

/// Unsigned distances (world units) on every voxel within `band` voxels of `mesh`, open or
/// closed.
pub fn unsigned_distance(
    mesh: &Mesh,
    transform: Transform,
    band: f64,
    progress: &Progress,
) -> Result<SparseGrid> {
    let mut grid = distance_band(mesh, transform, band, progress)?;
    let h = transform.voxel_size as f32;
    grid.map_values(|_, d| d * h);
    Ok(grid)
}

//! Polyhedron voxelization as a beam of voxels (Jegathese et al. §4.3): the front and back
//! faces are voxelized by projection (`triangle`), and the voxels between them along each
//! column fill the interior.
//!
//! Decided here where the paper is silent:
//! - The beam runs along z through voxel centres. Front and back faces are told apart by their
//!   order along the column (the exact crossings of `ops::crossings`, paired first with
//!   second, third with fourth), not by their orientation, so inward-facing meshes fill the
//!   same and a column crossing several parts of a non-convex solid holds several beams.
//! - Only closed meshes are accepted: an open one would pair a front face with the wrong back
//!   face and fill outside.

use crate::error::Result;
use crate::grid::DenseMask;
use crate::grid::{SparseGrid, Transform};
use crate::mesh::inside::inside_centres;
use crate::mesh::{Mesh, index_box};
use crate::ops::flood::padded;
use crate::ops::measure::SolidMeasures;
use crate::solids::exterior_flood::Solid;
use crate::voxelize::Progress;
use crate::voxelize::projective::{Coloring, ProjectiveStats, voxelize_triangles};

/// Why the beam needs a closed mesh, for the error that refuses an open one.
const BEAM_NEEDS_CLOSED: &str = "a column through an open surface can enter without leaving, and its beam would fill the outside";

/// The projective surface of the closed `mesh` and the solid it bounds: `inside` holds the
/// beam voxels that are not surface voxels. `progress` counts triangles.
pub fn beam_solid(
    mesh: &Mesh,
    transform: Transform,
    progress: &Progress,
) -> Result<(SparseGrid, Solid, ProjectiveStats)> {
    mesh.require_closed(BEAM_NEEDS_CLOSED)?;
    let (surface, stats) = voxelize_triangles(mesh, transform, Coloring::None, progress)?;
    let mut bbox = index_box(&mesh.bbox(), &transform);
    if let Some(b) = surface.bbox() {
        bbox = bbox.union(&b);
    }
    let bbox = padded(bbox, 1);
    let blocked = DenseMask::from_grid(&surface, bbox)?;
    let beams = inside_centres(mesh, &transform, bbox)?;
    let inside = beams.minus(&blocked);
    let measures = SolidMeasures::of(inside.count(), blocked.count(), transform.voxel_size);
    let solid = Solid {
        inside: inside.to_grid(transform),
        measures,
        xyz_stats: None,
    };
    Ok((surface, solid, stats))
}

//! Checking that a voxel surface separates the inside of a closed mesh from the outside:
//! flood the empty voxels from outside and look for an inside centre the flood reached.

use super::flood::{flood, flood_from_border, padded};
use crate::error::Result;
use crate::grid::{Adjacency, CoordBox, DenseMask, SparseGrid};
use crate::mesh::Mesh;
use crate::mesh::inside::inside_centres;

/// What the exterior flood found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SeparationReport {
    pub adjacency: Adjacency,
    /// Voxels whose centre lies inside the mesh.
    pub inside_centres: u64,
    /// Inside centres that are not surface voxels (the flood must not reach any of them).
    pub inside_empty: u64,
    /// Empty voxels reached from outside.
    pub exterior: u64,
    /// Inside centres reached from outside: zero for a separating surface.
    pub leaked: u64,
    /// One leaked voxel, for diagnosis.
    pub first_leak: Option<[i64; 3]>,
}

impl SeparationReport {
    pub fn separates(&self) -> bool {
        self.leaked == 0
    }
}

/// Floods the complement of `surface` with `adjacency` from the border of a box two voxels
/// larger than surface and mesh, and counts the inside centres (of `mesh`) it reaches.
pub fn check_mesh_separation(
    surface: &SparseGrid,
    mesh: &Mesh,
    adjacency: Adjacency,
) -> Result<SeparationReport> {
    let t = surface.transform;
    let b = mesh.bbox();
    let mut bbox = CoordBox {
        min: t.world_to_voxel(b.min),
        max: t.world_to_voxel(b.max),
    };
    if let Some(sb) = surface.bbox() {
        bbox = bbox.union(&sb);
    }
    let bbox = padded(bbox, 2);
    let blocked = DenseMask::from_grid(surface, bbox)?;
    let inside = inside_centres(mesh, &t, bbox)?;
    let reached = flood_from_border(&blocked, adjacency)?;
    Ok(report(adjacency, &blocked, &inside, &reached))
}

/// Floods the complement of `surface` inside `bbox` from the voxels `side` puts on the
/// positive side, and counts the voxels of the negative side it reaches: for surfaces that
/// cross the box (an open analytic surface) as well as closed ones.
pub fn check_side_separation(
    surface: &SparseGrid,
    bbox: CoordBox,
    side: impl Fn([i64; 3]) -> f64,
    adjacency: Adjacency,
) -> Result<SeparationReport> {
    let blocked = DenseMask::from_grid(surface, bbox)?;
    let mut inside = DenseMask::new(bbox)?;
    let mut outside = DenseMask::new(bbox)?;
    for i in 0..blocked.len() {
        let s = side(blocked.coord(i));
        if s < 0.0 {
            inside.set_index(i);
        } else if s > 0.0 {
            outside.set_index(i);
        }
    }
    let reached = flood(&blocked, &outside, adjacency)?;
    Ok(report(adjacency, &blocked, &inside, &reached))
}

fn report(
    adjacency: Adjacency,
    blocked: &DenseMask,
    inside: &DenseMask,
    reached: &DenseMask,
) -> SeparationReport {
    SeparationReport {
        adjacency,
        inside_centres: inside.count(),
        inside_empty: inside.count() - inside.and_count(blocked),
        exterior: reached.count(),
        leaked: reached.and_count(inside),
        first_leak: reached.first_common(inside),
    }
}

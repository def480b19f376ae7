//! The input mesh's vertex attributes on a job's voxels: interpolated by the projective scan,
//! or taken from the mesh's nearest point (separating surfaces, distance bands), each written
//! as a grid of its own name, renamed `vertex_NAME` where that name is one of the job's own.
//! Vertex colours travel as the attribute `Cd` where the job does not write them itself.

use super::{Outcome, SurfaceMethod};
use crate::error::Result;
use crate::io::vdb::{
    COLOR_GRID, DENSITY_GRID, DISTANCE_GRID, LEVEL_SET_GRID, NORMAL_GRID, VOXELS_GRID,
};
use crate::mesh::Mesh;
use crate::mesh::attributes::{AttributeChoice, AttributeKind, VertexAttribute};
use crate::mesh::nearest_attributes::carry_nearest;
use crate::progress::Progress;
use crate::voxelize::projective::interpolate_attributes;

/// How attribute values reach the voxels.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Carry {
    /// Across each triangle by the projective scan.
    Interpolated,
    /// From the point of the mesh nearest each voxel's centre.
    Nearest,
}

impl Carry {
    /// How `method` carries attributes.
    pub(super) fn of(method: &SurfaceMethod) -> Carry {
        match method {
            SurfaceMethod::Separating(_) => Carry::Nearest,
            SurfaceMethod::Projective(_) => Carry::Interpolated,
        }
    }

    /// Whether vertex colours travel as an attribute (`Cd`): the projective method writes them
    /// as its own colour grid instead.
    pub(super) fn carries_colours(self) -> bool {
        self == Carry::Nearest
    }
}

/// Grid names a job writes of its own.
const OWN_GRIDS: [&str; 6] = [
    DENSITY_GRID,
    VOXELS_GRID,
    NORMAL_GRID,
    COLOR_GRID,
    LEVEL_SET_GRID,
    DISTANCE_GRID,
];

/// Adds the attributes of `mesh` that `chosen` names to `outcome`, on its voxels.
pub(super) fn add_attributes(
    outcome: &mut Outcome,
    mesh: &Mesh,
    chosen: &AttributeChoice,
    carry: Carry,
    progress: &Progress,
) -> Result<()> {
    let attributes = chosen.select(mesh, carry.carries_colours())?;
    if attributes.is_empty() {
        return Ok(());
    }
    let attributes: Vec<&VertexAttribute> = attributes.iter().map(|a| &**a).collect();
    // A stage of its own: the interpolation scans the faces once per attribute, the nearest
    // point is found once per leaf of the result.
    let grids = match carry {
        Carry::Interpolated => {
            let faces = (mesh.face_count() * attributes.len()) as u64;
            progress.stage("attributes", faces);
            interpolate_attributes(mesh, outcome.grid.transform, &attributes, progress)?
        }
        Carry::Nearest => {
            progress.stage("attributes", outcome.grid.leaf_count() as u64);
            carry_nearest(mesh, &outcome.grid, &attributes, progress)?
        }
    };
    let how = match carry {
        Carry::Interpolated => "interpolated across triangles",
        Carry::Nearest => "from the nearest point",
    };
    for mut grid in grids {
        let own = grid.kind != AttributeKind::Color && OWN_GRIDS.contains(&grid.name.as_str());
        if own {
            grid.name = format!("vertex_{}", grid.name);
        }
        outcome.report.attributes.push(format!(
            "{} ({how}, {} voxels)",
            grid.name,
            grid.grid.voxel_count()
        ));
        outcome.attributes.push(grid);
    }
    Ok(())
}

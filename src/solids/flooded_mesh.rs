//! A mesh's solid as Lai & Cheng compose it: the mesh's 26-separating surface (Huang et al.)
//! and the voxels inside it, by the mesh's inside rule (`inside_rule`): every voxel the
//! exterior flood cannot reach through the surface but its cavities (parity, closed meshes),
//! or every centre whose winding number is at least 1/2 (winding, any mesh); and the measures
//! of the whole solid's shape, its components and genus.

use super::cavities::remove_cavities;
use super::column_inside::{interior_near, winding_columns};
use super::exterior_flood::{FloodMethod, Solid, solid_from_surface};
use super::inside_rule::{Inside, InsideChoice, InsideRule, choose_inside};
use super::winding_inside::{block_columns, winding_inside};
use crate::error::{Error, Result};
use crate::grid::{Adjacency, Channels, DenseMask, SparseGrid, Transform};
use crate::mesh::inside::ColumnCrossings;
use crate::mesh::{Mesh, index_box};
use crate::ops::flood::padded;
use crate::ops::measure::SolidMeasures;
use crate::ops::topology::{components, euler_characteristic};
use crate::progress::Progress;
use crate::voxelize::Separability;
use crate::voxelize::separating::{SeparatingOptions, voxelize_mesh, work_items};

/// Why the flood needs a closed mesh, for the error that refuses an open one.
pub const FLOOD_NEEDS_CLOSED: &str = "the exterior flood would leak through it and leave the solid hollow \
     (option `inside` winding fills it by the winding number)";

/// A surface, the solid inside it, and the two together.
pub struct SurfaceAndInside {
    pub surface: SparseGrid,
    pub solid: Solid,
    /// Surface and inside: the whole solid.
    pub whole: SparseGrid,
    /// The centres whose winding number lies near 1/2, where the winding number decided.
    pub ambiguous: Option<SparseGrid>,
}

impl SurfaceAndInside {
    pub fn of(surface: SparseGrid, solid: Solid) -> SurfaceAndInside {
        // The inside is mostly tiles: start from it and add the surface's leaves.
        let mut whole = solid.inside.clone();
        whole.union(&surface);
        SurfaceAndInside {
            surface,
            solid,
            whole,
            ambiguous: None,
        }
    }

    /// The surface and the centres inside it, the surface's voxels not counted twice.
    fn with_inside(surface: SparseGrid, mut inside: SparseGrid) -> SurfaceAndInside {
        // (inside less surface) with surface is inside with surface: both are made at once.
        let mut whole = inside.clone();
        rayon::join(|| whole.union(&surface), || inside.difference(&surface));
        let measures = SolidMeasures::of(
            inside.voxel_count(),
            surface.voxel_count(),
            surface.transform.voxel_size,
        );
        let solid = Solid {
            inside,
            measures,
            xyz_stats: None,
        };
        SurfaceAndInside {
            surface,
            solid,
            whole,
            ambiguous: None,
        }
    }

    /// The closed `surface` and what `flood` cannot reach from outside.
    pub fn flooded(surface: SparseGrid, flood: FloodMethod, progress: &Progress) -> Result<Self> {
        let solid = solid_from_surface(&surface, flood, progress)?;
        Ok(SurfaceAndInside::of(surface, solid))
    }
}

/// The 26-separating surface of a mesh, the surface a solid is filled in.
pub fn flood_surface(mesh: &Mesh, t: Transform, progress: &Progress) -> Result<SparseGrid> {
    let options = SeparatingOptions {
        separability: Separability::TwentySix,
        ..Default::default()
    };
    Ok(voxelize_mesh(mesh, t, &options, progress)?.0)
}

/// A mesh's solid: its 26-separating surface and, by winding number, the centres inside it;
/// by parity, the surface of the closed mesh flooded by `flood`, less the enclosed regions its
/// winding number says are cavities. The rule is chosen from `rule` (`choose_inside`) while
/// the surface, which either rule needs, is voxelized: grouping the mesh's edges for the
/// choice then takes no time of its own. Returns the choice with the parts.
pub fn flooded_mesh(
    mesh: &Mesh,
    t: Transform,
    flood: FloodMethod,
    rule: InsideRule,
    progress: &Progress,
) -> Result<(InsideChoice, SurfaceAndInside)> {
    if rule == InsideRule::Parity {
        let choice = choose_inside(rule, mesh, FLOOD_NEEDS_CLOSED)?;
        let surface = flood_surface(mesh, t, progress)?;
        return Ok((choice, flooded_by_parity(mesh, surface, flood, progress)?));
    }
    let region = index_box(&mesh.bbox(), &t);
    let columns = block_columns(region).len() as u64;
    progress.stage("surface and inside", work_items(mesh) + columns);
    // The inside's grids (or a closed mesh's columns) are made on its side, while the surface
    // may still be running.
    let (surface, inside) = rayon::join(
        || flood_surface(mesh, t, progress),
        || {
            let choice = choose_inside(rule, mesh, FLOOD_NEEDS_CLOSED)?;
            let centres = match &choice.inside {
                Inside::Winding(caps) if caps.is_empty() => {
                    let crossings = winding_columns(mesh, caps, &t, region);
                    progress.advance(columns);
                    Centres::Columns(crossings)
                }
                Inside::Winding(caps) => Centres::Grids(Box::new(
                    winding_inside(mesh, caps, t, region, progress)?.into_grids(t),
                )),
                // Orientations disagree on a closed mesh: the flood fills it (below).
                Inside::Parity => {
                    progress.advance(columns);
                    Centres::Flood
                }
            };
            Ok::<_, Error>((choice, centres))
        },
    );
    let (choice, centres) = inside?;
    let surface = surface?;
    let (centres, ambiguous) = match centres {
        // Every voxel the mesh passes through belongs to its 26-separating surface (the
        // slabs reach a voxel's extent along the normal, Huang's full spheres and cylinders
        // its half diagonal), as `column_inside` needs: the columns are read at the surface's
        // leaves and at one centre of each other block.
        Centres::Columns(columns) => (
            interior_near(&columns, &surface),
            SparseGrid::new(t, Channels::NONE),
        ),
        Centres::Grids(grids) => *grids,
        Centres::Flood => {
            return Ok((choice, flooded_by_parity(mesh, surface, flood, progress)?));
        }
    };
    let parts = SurfaceAndInside {
        ambiguous: Some(ambiguous),
        ..SurfaceAndInside::with_inside(surface, centres)
    };
    Ok((choice, parts))
}

/// How a solid's inside centres are found once its surface is known.
enum Centres {
    /// A closed, consistently oriented mesh's columns, to read near the surface.
    Columns(ColumnCrossings),
    /// Every centre decided already (inside, and ambiguous).
    Grids(Box<(SparseGrid, SparseGrid)>),
    /// The surface flooded from outside.
    Flood,
}

/// The closed mesh's `surface` flooded by `flood`, less the cavities.
fn flooded_by_parity(
    mesh: &Mesh,
    surface: SparseGrid,
    flood: FloodMethod,
    progress: &Progress,
) -> Result<SurfaceAndInside> {
    let mut solid = solid_from_surface(&surface, flood, progress)?;
    if remove_cavities(mesh, &mut solid.inside)? > 0 {
        let inside = solid.inside.voxel_count();
        solid.measures =
            SolidMeasures::of(inside, surface.voxel_count(), surface.transform.voxel_size);
    }
    Ok(SurfaceAndInside::of(surface, solid))
}

/// Components (26-connected) and genus (components - Euler characteristic) of a solid.
pub fn topology(whole: &SparseGrid) -> Result<(u64, i64)> {
    let Some(bbox) = whole.bbox() else {
        return Ok((0, 0));
    };
    let all = DenseMask::from_grid(whole, padded(bbox, 1))?;
    let parts = components(&all, Adjacency::TwentySix);
    Ok((parts, parts as i64 - euler_characteristic(&all)))
}

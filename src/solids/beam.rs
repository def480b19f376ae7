//! Polyhedron voxelization as a beam of voxels (Jegathese et al. §4.3): the front and back
//! faces are voxelized by projection (`triangle`), and the voxels between them along each
//! column fill the interior.
//!
//! Two fills (`BeamFill`):
//! - `Parity` (decided here where the paper is silent): the beam runs along z through voxel
//!   centres; front and back faces are told apart by their order along the column (the exact
//!   crossings of `ops::crossings`, paired first with second, third with fourth), not by their
//!   orientation, so inward-facing meshes fill the same and a column crossing several parts
//!   of a non-convex solid holds several beams.
//! - `Paper`: the paper's own rule, from the face voxels. Faces are back facing (normal toward
//!   -z, once the mesh is turned to face outward) or front facing (toward +z), and each is
//!   voxelized on its own; up each column, a back-face voxel opens a beam and the next
//!   front-face voxel closes it, and the voxels between are filled. Where the face voxels of
//!   neighbouring columns do not line up, a beam can open without closing before the column
//!   ends: it is left empty and counted.
//!
//! Only closed meshes are accepted: an open one would pair a front face with the wrong back
//! face and fill outside.

use crate::error::Result;
use crate::grid::{CoordBox, DenseMask};
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

/// How the voxels between front and back faces are found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BeamFill {
    /// Voxel centres between exact crossings 1-2, 3-4, ... along z.
    #[default]
    Parity,
    /// Jegathese et al.'s rule: from a back-face voxel up to the next front-face voxel.
    Paper,
}

crate::named_choices! {
    BeamFill, "the beam fill":
    "parity" => Parity,
    "paper" => Paper,
}

/// The beam solid and what its fill met.
pub struct Beam {
    pub surface: SparseGrid,
    pub solid: Solid,
    pub stats: ProjectiveStats,
    /// `Paper`: beams opened by a back face that no front face closed (left empty).
    pub unclosed_beams: u64,
}

/// The projective surface of the closed `mesh` and the solid it bounds: `inside` holds the
/// beam voxels that are not surface voxels. `progress` counts triangles.
pub fn beam_solid(
    mesh: &Mesh,
    transform: Transform,
    fill: BeamFill,
    progress: &Progress,
) -> Result<Beam> {
    mesh.require_closed(BEAM_NEEDS_CLOSED)?;
    let (surface, stats) = voxelize_triangles(mesh, transform, Coloring::None, progress)?;
    let mut bbox = index_box(&mesh.bbox(), &transform);
    if let Some(b) = surface.bbox() {
        bbox = bbox.union(&b);
    }
    let bbox = padded(bbox, 1);
    let blocked = DenseMask::from_grid(&surface, bbox)?;
    let (beams, unclosed_beams) = match fill {
        BeamFill::Parity => (inside_centres(mesh, &transform, bbox)?, 0),
        BeamFill::Paper => beams_from_face_voxels(mesh, transform, bbox)?,
    };
    let inside = beams.minus(&blocked);
    let measures = SolidMeasures::of(inside.count(), blocked.count(), transform.voxel_size);
    let solid = Solid {
        inside: inside.to_grid(transform),
        measures,
        xyz_stats: None,
    };
    Ok(Beam {
        surface,
        solid,
        stats,
        unclosed_beams,
    })
}

/// The paper's beams: the voxels from each back-face voxel up to the next front-face voxel
/// of its column, and the count of beams no front face closed.
fn beams_from_face_voxels(
    mesh: &Mesh,
    transform: Transform,
    bbox: CoordBox,
) -> Result<(DenseMask, u64)> {
    // Faces facing -z (back) or +z (front) once the mesh faces outward.
    let outward = if mesh.signed_volume() >= 0.0 {
        1.0
    } else {
        -1.0
    };
    let (mut back, mut front) = (Vec::new(), Vec::new());
    for f in 0..mesh.face_count() {
        let normal_z: f64 = mesh
            .fan(f)
            .map(|[a, b, c]| (mesh.p(b) - mesh.p(a)).cross(mesh.p(c) - mesh.p(a)).z)
            .sum::<f64>()
            * outward;
        let face = mesh.face(f).to_vec();
        if normal_z < 0.0 {
            back.push(face);
        } else if normal_z > 0.0 {
            front.push(face);
        }
    }
    let voxels = |faces: &[Vec<u32>]| -> Result<DenseMask> {
        let part = Mesh::from_polygons(&mesh.source, mesh.positions.clone(), faces);
        let (grid, _) = voxelize_triangles(&part, transform, Coloring::None, &Progress::none())?;
        DenseMask::from_grid(&grid, bbox)
    };
    let (back, front) = (voxels(&back)?, voxels(&front)?);
    // Up every column (z is the fastest index): events in order, a back voxel before a
    // front one in the same voxel.
    let column = back.dims()[2];
    let mut beams = DenseMask::new(bbox)?;
    let mut unclosed = 0u64;
    // The first voxel after the opening back voxel, and the column.
    let mut opened: Option<(usize, usize)> = None;
    let mut backs = back.ones().peekable();
    let mut fronts = front.ones().peekable();
    loop {
        let (i, is_back) = match (backs.peek(), fronts.peek()) {
            (Some(&b), Some(&f)) if b <= f => (b, true),
            (_, Some(&f)) => (f, false),
            (Some(&b), None) => (b, true),
            (None, None) => break,
        };
        if is_back {
            backs.next();
        } else {
            fronts.next();
        }
        if opened.is_some_and(|(_, col)| col != i / column) {
            opened = None;
            unclosed += 1;
        }
        match (is_back, opened) {
            (true, None) => opened = Some((i + 1, i / column)),
            (false, Some((start, _))) => {
                if i > start {
                    beams.set_index_range(start, i - 1);
                }
                opened = None;
            }
            _ => {}
        }
    }
    unclosed += u64::from(opened.is_some());
    Ok((beams, unclosed))
}

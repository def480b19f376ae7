//! OpenSubdiv's own limit points (feature `osd`), for checking the evaluator live: exact ones
//! at dyadic (u, v) through `Far::PrimvarRefiner::Limit`, and at any (u, v) through
//! `Bfr::Surface`.

use super::compare::{Comparison, compare_points};
use super::control_mesh::ControlMesh;
use super::points_file::SurfacePoint;
use super::surface::LimitSurface;
use crate::error::{Error, Result};
use crate::ffi::osd::bridge;
use glam::DVec3;

/// `Bfr::Surface` refines irregular regions this many times before approximating them; 10
/// is its most accurate setting (differences from the exact limit stay near 1e-15 there).
pub const BFR_APPROX_LEVEL: i32 = 10;

/// The control mesh, its creases and its corners as OpenSubdiv takes them (boundaries are
/// OpenSubdiv's own rule, not tags).
fn cage(control: &ControlMesh) -> bridge::ControlCage {
    let mesh = &control.mesh;
    let mut cage = bridge::ControlCage {
        positions: mesh.points.iter().flat_map(|p| p.to_array()).collect(),
        face_sizes: (0..mesh.face_count())
            .map(|f| mesh.face_len(f) as i32)
            .collect(),
        face_verts: mesh.verts.iter().map(|&v| v as i32).collect(),
        crease_verts: Vec::new(),
        crease_weights: Vec::new(),
        corner_verts: Vec::new(),
        corner_weights: Vec::new(),
    };
    for h in 0..mesh.verts.len() as u32 {
        let s = mesh.sharpness[h as usize];
        if s > 0.0 && mesh.twin(h).is_some_and(|t| t > h) {
            cage.crease_verts
                .extend([mesh.from(h) as i32, mesh.to(h) as i32]);
            cage.crease_weights.push(s);
        }
    }
    for (v, &s) in mesh.vertex_sharpness.iter().enumerate() {
        if s > 0.0 {
            cage.corner_verts.push(v as i32);
            cage.corner_weights.push(s);
        }
    }
    cage
}

fn to_points(out: bridge::LimitPoints) -> Vec<SurfacePoint> {
    (0..out.face.len())
        .map(|i| SurfacePoint {
            face: out.face[i] as usize,
            u: out.uv[2 * i],
            v: out.uv[2 * i + 1],
            expected: Some((
                DVec3::from_slice(&out.position[3 * i..3 * i + 3]),
                DVec3::from_slice(&out.normal[3 * i..3 * i + 3]),
            )),
        })
        .collect()
}

fn osd_error(control: &ControlMesh, e: cxx::Exception) -> Error {
    Error::Unsupported(format!(
        "{}: OpenSubdiv: {}",
        control.source.display(),
        e.what()
    ))
}

/// Every corner of every face after `level` uniform refinements, with OpenSubdiv's exact limit
/// position and normal. Left out: interior valence-2 vertices (OpenSubdiv's `Limit()` gives them
/// the corner mask) and boundary vertices with 3 or more faces (its normal there changes with
/// `level`: on catmark_helmet by 1.3e-3 rad from level 1 to 6, converging slowly to the
/// tangent plane voxelkit computes from the subdivision matrix's eigenvectors), and vertices on
/// tagged creases (one normal for both sides; the smooth masks at a dart). Semi-sharp
/// creases are refined away first (`Limit()` treats a semi-sharp edge as sharp): `None` where
/// that takes more than [`MOST_REFINED_FACES`] faces.
pub fn dyadic_limit_points(control: &ControlMesh, level: u32) -> Result<Option<Vec<SurfacePoint>>> {
    let softening = control
        .mesh
        .sharpness
        .iter()
        .chain(&control.mesh.vertex_sharpness)
        .filter(|&&s| s < super::crease::INFINITE)
        .fold(0.0f32, |a, &s| a.max(s));
    let refine = level.max(softening.ceil() as u32);
    let faces = control.face_count() as u64;
    if refine > level && faces << (2 * refine) > MOST_REFINED_FACES {
        return Ok(None);
    }
    let out = bridge::limit_at_dyadic(&cage(control), refine as i32, level as i32)
        .map_err(|e| osd_error(control, e))?;
    Ok(Some(to_points(out)))
}

/// Uniform refinement multiplies the faces by 4 per level; refining deeper than asked stops
/// at this many faces (a few hundred faces at 8 levels would need gigabytes).
pub const MOST_REFINED_FACES: u64 = 8 << 20;

/// OpenSubdiv's limit position and normal at each `(face, u, v)`.
pub fn limit_points(
    control: &ControlMesh,
    queries: &[(usize, f64, f64)],
) -> Result<Vec<SurfacePoint>> {
    let faces: Vec<u32> = queries.iter().map(|q| q.0 as u32).collect();
    let uv: Vec<f64> = queries.iter().flat_map(|q| [q.1, q.2]).collect();
    let out = bridge::limit_at(&cage(control), &faces, &uv, BFR_APPROX_LEVEL)
        .map_err(|e| osd_error(control, e))?;
    Ok(to_points(out))
}

/// How far voxelkit's evaluator is from OpenSubdiv on one control mesh.
#[derive(Clone, Copy, Debug)]
pub struct LiveCheck {
    /// At every corner of the level-3 refinement (exact on both sides); `None` where
    /// semi-sharp creases would need more than [`MOST_REFINED_FACES`] faces.
    pub dyadic: Option<Comparison>,
    /// At random (u, v) on every patch, against `Bfr::Surface`.
    pub random: Comparison,
}

/// Compares `surface` with OpenSubdiv at the level-3 dyadic points and at `per_patch` random
/// points on every patch.
pub fn check_against_opensubdiv(
    surface: &LimitSurface,
    per_patch: usize,
    seed: u64,
) -> Result<LiveCheck> {
    let control = surface.control();
    let dyadic = match dyadic_limit_points(control, 3)? {
        Some(points) => Some(compare_points(surface, &points)?),
        None => None,
    };
    let queries = surface.random_parameters(per_patch, seed);
    let random = compare_points(surface, &limit_points(control, &queries)?)?;
    Ok(LiveCheck { dyadic, random })
}

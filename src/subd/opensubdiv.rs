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

struct FlatMesh {
    positions: Vec<f64>,
    face_sizes: Vec<i32>,
    face_verts: Vec<i32>,
}

fn flatten(control: &ControlMesh) -> FlatMesh {
    let mesh = &control.mesh;
    FlatMesh {
        positions: mesh.points.iter().flat_map(|p| p.to_array()).collect(),
        face_sizes: (0..mesh.face_count())
            .map(|f| mesh.face_len(f) as i32)
            .collect(),
        face_verts: mesh.verts.iter().map(|&v| v as i32).collect(),
    }
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
/// tangent plane voxelkit computes from the subdivision matrix's eigenvectors).
pub fn dyadic_limit_points(control: &ControlMesh, level: u32) -> Result<Vec<SurfacePoint>> {
    let flat = flatten(control);
    let out = bridge::limit_at_dyadic(
        &flat.positions,
        &flat.face_sizes,
        &flat.face_verts,
        level as i32,
    )
    .map_err(|e| osd_error(control, e))?;
    Ok(to_points(out))
}

/// OpenSubdiv's limit position and normal at each `(face, u, v)`.
pub fn limit_points(
    control: &ControlMesh,
    queries: &[(usize, f64, f64)],
) -> Result<Vec<SurfacePoint>> {
    let flat = flatten(control);
    let faces: Vec<u32> = queries.iter().map(|q| q.0 as u32).collect();
    let uv: Vec<f64> = queries.iter().flat_map(|q| [q.1, q.2]).collect();
    let out = bridge::limit_at(
        &flat.positions,
        &flat.face_sizes,
        &flat.face_verts,
        &faces,
        &uv,
        BFR_APPROX_LEVEL,
    )
    .map_err(|e| osd_error(control, e))?;
    Ok(to_points(out))
}

/// How far voxelkit's evaluator is from OpenSubdiv on one control mesh.
#[derive(Clone, Copy, Debug)]
pub struct LiveCheck {
    /// At every corner of the level-3 refinement (exact on both sides).
    pub dyadic: Comparison,
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
    let dyadic = compare_points(surface, &dyadic_limit_points(control, 3)?)?;
    let queries = surface.random_parameters(per_patch, seed);
    let random = compare_points(surface, &limit_points(control, &queries)?)?;
    Ok(LiveCheck { dyadic, random })
}

//! Meshes from Python: a path to any file the CLI reads, or a `(vertices, faces)` pair of
//! array-likes (faces: an (m, k) integer array, or a list of polygons of any sizes).

use crate::mesh::Mesh;
use crate::pipeline::MeshSource;
use glam::DVec3;
use numpy::{AllowTypeChange, PyArrayLike2};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use std::path::PathBuf;

/// What the arrays are called in messages.
const ARRAYS: &str = "the (vertices, faces) arrays";

/// The mesh `source` names; arrays are copied only once the copy's memory fits in `limit`
/// bytes (none: the memory available).
pub fn mesh_source(source: &Bound<'_, PyAny>, limit: Option<u64>) -> PyResult<MeshSource> {
    if let Ok(path) = source.extract::<PathBuf>() {
        return Ok(MeshSource::File(path));
    }
    let Ok((vertices, faces)) = source.extract::<(Bound<PyAny>, Bound<PyAny>)>() else {
        return Err(PyTypeError::new_err(
            "a mesh is a path or a (vertices, faces) pair of arrays",
        ));
    };
    Ok(MeshSource::Mesh(mesh_from_arrays(
        &vertices, &faces, limit,
    )?))
}

/// Bytes a mesh of `vertices` and `corners` takes while it is built from arrays: the rows
/// copied, the polygons, and the mesh's own vectors.
const VERTEX_COPY_BYTES: u64 = 3 * 24;
const CORNER_COPY_BYTES: u64 = 3 * 8 + 16;

/// Refuses, with MemoryError, arrays whose copy does not fit.
fn check_copy_fits(vertices: usize, corners: usize, limit: Option<u64>) -> PyResult<()> {
    let bytes = (vertices as u64)
        .saturating_mul(VERTEX_COPY_BYTES)
        .saturating_add((corners as u64).saturating_mul(CORNER_COPY_BYTES));
    let what = format!("{ARRAYS} ({vertices} vertices, {corners} face corners)");
    crate::system::check_fits(bytes, limit, &what).map_err(super::to_py_err)
}

fn mesh_from_arrays(
    vertices: &Bound<'_, PyAny>,
    faces: &Bound<'_, PyAny>,
    limit: Option<u64>,
) -> PyResult<Mesh> {
    let vertices: PyArrayLike2<f64, AllowTypeChange> = vertices
        .extract()
        .map_err(|e| PyValueError::new_err(format!("vertices: an (n, 3) float array ({e})")))?;
    let v = vertices.as_array();
    if v.ncols() != 3 {
        return Err(PyValueError::new_err(format!(
            "vertices: expected shape (n, 3), got {:?}",
            v.shape()
        )));
    }
    // The faces are counted first, so that one check covers every copy before any is made.
    let polygons = polygons(faces, |corners| check_copy_fits(v.nrows(), corners, limit))?;
    let positions: Vec<DVec3> = v
        .rows()
        .into_iter()
        .map(|r| DVec3::new(r[0], r[1], r[2]))
        .collect();
    let mut polys = Vec::with_capacity(polygons.len());
    for (f, polygon) in polygons.into_iter().enumerate() {
        let p = polygon
            .into_iter()
            .map(|i| {
                u32::try_from(i).map_err(|_| {
                    PyValueError::new_err(format!("{ARRAYS}: face {f}: vertex index {i}"))
                })
            })
            .collect::<PyResult<Vec<u32>>>()?;
        polys.push(p);
    }
    let mut mesh = Mesh::from_polygons(ARRAYS, positions, &polys);
    mesh.numbered_from_zero = true;
    Ok(mesh)
}

/// Faces as polygons: from a rectangular integer array, else from a sequence of sequences;
/// `fits(corners)` refuses what would not fit before it is copied.
fn polygons(
    faces: &Bound<'_, PyAny>,
    fits: impl Fn(usize) -> PyResult<()>,
) -> PyResult<Vec<Vec<i64>>> {
    if let Ok(array) = faces.extract::<PyArrayLike2<i64, AllowTypeChange>>() {
        fits(array.as_array().len())?;
        return Ok(array
            .as_array()
            .rows()
            .into_iter()
            .map(|r| r.to_vec())
            .collect());
    }
    fits(faces.len().unwrap_or(0).saturating_mul(3))?;
    faces.extract::<Vec<Vec<i64>>>().map_err(|e| {
        PyValueError::new_err(format!(
            "faces: an (m, 3) integer array or a list of polygons ({e})"
        ))
    })
}

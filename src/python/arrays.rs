//! Meshes from Python: a path to any file the CLI reads, a `(vertices, faces)` pair of
//! array-likes (faces: an (m, k) integer array, or a list of polygons of any sizes), or a mesh
//! object with `vertices` and `faces` (trimesh's `Trimesh`) or `vertices` and `triangles`
//! (Open3D's `TriangleMesh`). Faces must hold whole numbers: a float array is taken only where
//! every value is one.

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
    let (vertices, faces) = if let Ok(pair) = source.extract::<(Bound<PyAny>, Bound<PyAny>)>() {
        pair
    } else if let Some(arrays) = mesh_object_arrays(source)? {
        arrays
    } else {
        return Err(PyTypeError::new_err(format!(
            "a mesh is a path, a (vertices, faces) pair of arrays, or an object with `vertices` \
             and `faces` (trimesh) or `triangles` (Open3D); got {}",
            source.get_type().name()?
        )));
    };
    Ok(MeshSource::Mesh(mesh_from_arrays(
        &vertices, &faces, limit,
    )?))
}

/// The arrays of a mesh object: `vertices` with `faces` (trimesh) or `triangles` (Open3D,
/// whose vectors numpy reads in place); none when `source` has no such attributes.
fn mesh_object_arrays<'py>(
    source: &Bound<'py, PyAny>,
) -> PyResult<Option<(Bound<'py, PyAny>, Bound<'py, PyAny>)>> {
    if !source.hasattr("vertices")? {
        return Ok(None);
    }
    for faces in ["faces", "triangles"] {
        if source.hasattr(faces)? {
            return Ok(Some((source.getattr("vertices")?, source.getattr(faces)?)));
        }
    }
    Ok(None)
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

/// `array` as rows of three numbers (an (n, 3) array-like of floats), named `what` in errors.
pub fn xyz_rows<'py>(
    array: &Bound<'py, PyAny>,
    what: &str,
) -> PyResult<PyArrayLike2<'py, f64, AllowTypeChange>> {
    let rows: PyArrayLike2<f64, AllowTypeChange> = array
        .extract()
        .map_err(|e| PyValueError::new_err(format!("{what}: an (n, 3) float array ({e})")))?;
    if rows.as_array().ncols() != 3 {
        return Err(PyValueError::new_err(format!(
            "{what}: expected shape (n, 3), got {:?}",
            rows.as_array().shape()
        )));
    }
    Ok(rows)
}

/// The rows of an (n, 3) array as points.
pub fn points_of(rows: &PyArrayLike2<'_, f64, AllowTypeChange>) -> Vec<DVec3> {
    rows.as_array()
        .rows()
        .into_iter()
        .map(|r| DVec3::new(r[0], r[1], r[2]))
        .collect()
}

fn mesh_from_arrays(
    vertices: &Bound<'_, PyAny>,
    faces: &Bound<'_, PyAny>,
    limit: Option<u64>,
) -> PyResult<Mesh> {
    let vertices = xyz_rows(vertices, "vertices")?;
    let count = vertices.as_array().nrows();
    // The faces are counted first, so that one check covers every copy before any is made.
    let polygons = polygons(faces, |corners| check_copy_fits(count, corners, limit))?;
    let positions = points_of(&vertices);
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

/// Faces as polygons: from a rectangular array (floats only where every value is a whole
/// number), else from a sequence of sequences of integers; `fits(corners)` refuses what would
/// not fit before it is copied.
fn polygons(
    faces: &Bound<'_, PyAny>,
    fits: impl Fn(usize) -> PyResult<()>,
) -> PyResult<Vec<Vec<i64>>> {
    let Some(array) = rectangular(faces)? else {
        fits(faces.len().unwrap_or(0).saturating_mul(3))?;
        return faces.extract::<Vec<Vec<i64>>>().map_err(|e| {
            PyValueError::new_err(format!(
                "faces: an (m, 3) integer array or a list of polygons ({e})"
            ))
        });
    };
    let kind: String = array.getattr("dtype")?.getattr("kind")?.extract()?;
    if kind != "f" {
        let array: PyArrayLike2<i64, AllowTypeChange> = array
            .extract()
            .map_err(|e| PyValueError::new_err(format!("faces: an (m, k) integer array ({e})")))?;
        fits(array.as_array().len())?;
        return Ok(array
            .as_array()
            .rows()
            .into_iter()
            .map(|r| r.to_vec())
            .collect());
    }
    let array: PyArrayLike2<f64, AllowTypeChange> = array
        .extract()
        .map_err(|e| PyValueError::new_err(format!("faces: an (m, k) array ({e})")))?;
    fits(array.as_array().len())?;
    let mut out = Vec::with_capacity(array.as_array().nrows());
    for (f, row) in array.as_array().rows().into_iter().enumerate() {
        let mut polygon = Vec::with_capacity(row.len());
        for &i in row {
            if i.fract() != 0.0 || !i.is_finite() {
                return Err(PyValueError::new_err(format!(
                    "faces: face {f} holds {i}, not a vertex index: faces are whole numbers (an \
                     integer array)"
                )));
            }
            polygon.push(i as i64);
        }
        out.push(polygon);
    }
    Ok(out)
}

/// `faces` as a two-dimensional numpy array: itself when it is an array, else as numpy reads
/// it (a list of equal-length lists, Open3D's vectors); none for ragged polygons.
fn rectangular<'py>(faces: &Bound<'py, PyAny>) -> PyResult<Option<Bound<'py, PyAny>>> {
    let array = if faces.hasattr("dtype")? {
        faces.clone()
    } else {
        match faces
            .py()
            .import("numpy")?
            .call_method1("asarray", (faces,))
        {
            Ok(array) => array,
            Err(_) => return Ok(None),
        }
    };
    let dimensions: usize = array.getattr("ndim")?.extract()?;
    Ok((dimensions == 2).then_some(array))
}

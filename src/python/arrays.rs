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

pub fn mesh_source(source: &Bound<'_, PyAny>) -> PyResult<MeshSource> {
    if let Ok(path) = source.extract::<PathBuf>() {
        return Ok(MeshSource::File(path));
    }
    let Ok((vertices, faces)) = source.extract::<(Bound<PyAny>, Bound<PyAny>)>() else {
        return Err(PyTypeError::new_err(
            "a mesh is a path or a (vertices, faces) pair of arrays",
        ));
    };
    Ok(MeshSource::Mesh(mesh_from_arrays(&vertices, &faces)?))
}

fn mesh_from_arrays(vertices: &Bound<'_, PyAny>, faces: &Bound<'_, PyAny>) -> PyResult<Mesh> {
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
    let positions: Vec<DVec3> = v
        .rows()
        .into_iter()
        .map(|r| DVec3::new(r[0], r[1], r[2]))
        .collect();
    let polygons = polygons(faces)?;
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

/// Faces as polygons: from a rectangular integer array, else from a sequence of sequences.
fn polygons(faces: &Bound<'_, PyAny>) -> PyResult<Vec<Vec<i64>>> {
    if let Ok(array) = faces.extract::<PyArrayLike2<i64, AllowTypeChange>>() {
        return Ok(array
            .as_array()
            .rows()
            .into_iter()
            .map(|r| r.to_vec())
            .collect());
    }
    faces.extract::<Vec<Vec<i64>>>().map_err(|e| {
        PyValueError::new_err(format!(
            "faces: an (m, 3) integer array or a list of polygons ({e})"
        ))
    })
}

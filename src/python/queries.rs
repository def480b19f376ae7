//! Point queries from Python: `signed_distance(mesh, points)` and `contains(mesh, points)`
//! (see `solids::point_queries`), over an (n, 3) array of points on every thread, the GIL
//! released.

use super::arrays::{mesh_source, points_of, xyz_rows};
use super::keywords::Keywords;
use super::to_py_err;
use crate::mesh::UpAxis;
use crate::pipeline::on_threads;
use crate::pipeline::request::QueryRequest;
use crate::solids::inside_rule::choose_inside;
use crate::solids::level_set::SIGN_NEEDS_CLOSED;
use crate::solids::point_queries::PointQueries;
use glam::DVec3;
use numpy::{IntoPyArray, PyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;

/// `f` of every point of `points` (an (n, 3) array-like), for the mesh `source`.
fn over_points<'py, T: numpy::Element + Send>(
    py: Python<'py>,
    source: &Bound<'py, PyAny>,
    points: &Bound<'py, PyAny>,
    options: Option<&Bound<'py, PyDict>>,
    f: impl Fn(&PointQueries, DVec3) -> T + Sync,
) -> PyResult<Bound<'py, PyArray1<T>>> {
    let call = Keywords::<QueryRequest>::new(options)?;
    let limits = call.limits.limits();
    let source = mesh_source(source, limits.max_memory)?;
    let points = xyz_rows(points, "points")?;
    let count = points.as_array().nrows() as u64;
    // Each point copied, and its answer.
    let bytes = count.saturating_mul(24 + std::mem::size_of::<T>() as u64);
    crate::system::check_fits(bytes, limits.max_memory, &format!("{count} points"))
        .map_err(to_py_err)?;
    let p = points_of(&points);
    let rule = call.request.inside;
    let values = py
        .detach(|| {
            on_threads(limits.threads, || {
                let mesh = source.load(false, UpAxis::default())?;
                let choice = choose_inside(rule, &mesh, SIGN_NEEDS_CLOSED)?;
                let queries = PointQueries::new(&mesh, &choice.inside);
                Ok(p.par_iter().map(|&q| f(&queries, q)).collect::<Vec<T>>())
            })
        })
        .map_err(to_py_err)?;
    Ok(values.into_pyarray(py))
}

/// The exact distance from each point to the mesh, negative inside (by the option `inside`).
#[pyfunction]
#[pyo3(signature = (mesh, points, **options))]
pub fn signed_distance<'py>(
    py: Python<'py>,
    mesh: &Bound<'py, PyAny>,
    points: &Bound<'py, PyAny>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    over_points(py, mesh, points, options, PointQueries::signed_distance)
}

/// Whether each point lies inside the mesh (by the option `inside`).
#[pyfunction]
#[pyo3(signature = (mesh, points, **options))]
pub fn contains<'py>(
    py: Python<'py>,
    mesh: &Bound<'py, PyAny>,
    points: &Bound<'py, PyAny>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyArray1<bool>>> {
    over_points(py, mesh, points, options, PointQueries::contains)
}

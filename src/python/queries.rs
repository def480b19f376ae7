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
    // Each point copied, its place in the Morton order, and its answer (twice: by place, then
    // in the points' order).
    let bytes = count.saturating_mul(24 + 8 + 16 + std::mem::size_of::<T>() as u64);
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
                // Points taken in Morton order walk the tree through the same clusters in turn.
                let order = morton_order(&p);
                let mut answers: Vec<(usize, T)> =
                    order.par_iter().map(|&i| (i, f(&queries, p[i]))).collect();
                answers.par_sort_unstable_by_key(|a| a.0);
                Ok(answers.into_iter().map(|a| a.1).collect::<Vec<T>>())
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

/// The indices of `points` sorted along a Morton curve over their box (10 bits an axis).
fn morton_order(points: &[DVec3]) -> Vec<usize> {
    let (lo, hi) = points.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let scale = 1023.0 / (hi - lo).max(DVec3::splat(f64::MIN_POSITIVE));
    let spread = |v: u64| {
        let mut x = v & 0x3ff;
        x = (x | x << 16) & 0x0300_00ff;
        x = (x | x << 8) & 0x0300_f00f;
        x = (x | x << 4) & 0x030c_30c3;
        (x | x << 2) & 0x0924_9249
    };
    let key = |p: DVec3| {
        let q = ((p - lo) * scale).max(DVec3::ZERO);
        spread(q.x as u64) | spread(q.y as u64) << 1 | spread(q.z as u64) << 2
    };
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.par_sort_unstable_by_key(|&i| {
        if points[i].is_finite() {
            key(points[i])
        } else {
            u64::MAX
        }
    });
    order
}

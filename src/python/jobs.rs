//! The module's functions: each fills the request of `pipeline::request` from its keyword
//! arguments (see `keywords`), turns it into the job every front end runs (see `watch`) and
//! returns a `Grid`. The package wraps them with the schema's
//! signatures and docs (`python/voxelkit/__init__.py`).

use super::arrays::mesh_source;
use super::grid::Grid;
use super::keywords::Keywords;
use super::to_py_err;
use super::watch::run_job;
use crate::mesh::GridFit;
use crate::pipeline::request::{
    CombineRequest, ImplicitRequest, LimitsRequest, LinesRequest, MeasureRequest, MeshRequest,
    Request, SolidRequest, SubdivRequest,
};
use crate::pipeline::{CsgSource, GridSource, Job, MeasureSource, MeshSource, Outcome, Task};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// Runs the job of `call`'s request on `input` under its limits and progress function.
fn run<R: Request>(py: Python<'_>, call: Keywords<R>, input: R::Input) -> PyResult<Grid> {
    let job = call.request.job(input, &call.limits).map_err(to_py_err)?;
    let inputs = job.task.input_files();
    let outcome = run_job(py, job, call.progress)?;
    Ok(Grid::new(outcome, inputs))
}

/// The schema of every request (JSON): what `voxelkit.OPTIONS` and the package's signatures,
/// the Blender add-on and the Dask front end are made from.
#[pyfunction]
pub fn options() -> String {
    crate::pipeline::request::schema().to_string()
}

/// The job of request `R` on a mesh (a path or a `(vertices, faces)` pair).
fn on_mesh<R: Request<Input = MeshSource>>(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Grid> {
    let call = Keywords::<R>::new(options)?;
    let mesh = mesh_source(source, call.limits.limits().max_memory)?;
    run(py, call, mesh)
}

#[pyfunction]
#[pyo3(signature = (source, **options))]
pub fn mesh(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Grid> {
    on_mesh::<MeshRequest>(py, source, options)
}

#[pyfunction]
#[pyo3(signature = (source, **options))]
pub fn solid(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Grid> {
    on_mesh::<SolidRequest>(py, source, options)
}

#[pyfunction]
#[pyo3(signature = (source, **options))]
pub fn subdiv(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Grid> {
    on_mesh::<SubdivRequest>(py, source, options)
}

#[pyfunction]
#[pyo3(signature = (source, **options))]
pub fn lines(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Grid> {
    on_mesh::<LinesRequest>(py, source, options)
}

#[pyfunction]
#[pyo3(signature = (formula, **options))]
pub fn implicit(
    py: Python<'_>,
    formula: String,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Grid> {
    run(py, Keywords::<ImplicitRequest>::new(options)?, formula)
}

/// A CSG tree (the CLI's `csg --tree` JSON): a path to the JSON file, or the tree as a dict
/// (its file names are then found from the current directory).
#[pyfunction]
#[pyo3(signature = (tree, **options))]
pub fn csg(
    py: Python<'_>,
    tree: &Bound<'_, PyAny>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Grid> {
    let source = if tree.is_instance_of::<PyDict>() {
        let text: String = py
            .import("json")?
            .call_method1("dumps", (tree,))?
            .extract()?;
        CsgSource::Json {
            text,
            folder: PathBuf::from("."),
        }
    } else {
        CsgSource::File(tree.extract::<PathBuf>()?)
    };
    // A tree's options are in the tree: its only keywords are the limits.
    let call = Keywords::<LimitsRequest>::new(options)?;
    let job = Job {
        limits: call.request.limits(),
        ..Job::new(Task::CsgTree(source), GridFit::from_options(None, None))
    };
    let inputs = job.task.input_files();
    Ok(Grid::new(run_job(py, job, call.progress)?, inputs))
}

#[pyfunction]
#[pyo3(signature = (source, **options))]
pub fn measure(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Grid> {
    let call = Keywords::<MeasureRequest>::new(options)?;
    let source = if let Ok(grid) = source.cast::<Grid>() {
        MeasureSource::Grid(grid.borrow().outcome().grid.clone())
    } else if let Ok(path) = source.extract::<PathBuf>()
        && path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("vdb"))
    {
        MeasureSource::Vdb(path)
    } else {
        MeasureSource::Mesh(mesh_source(source, call.limits.limits().max_memory)?)
    };
    run(py, call, source)
}

/// `a` and `b` are Grids, or `.vdb` paths whose grid `grid` or voxel set is read.
#[pyfunction]
#[pyo3(signature = (a, b, **options))]
pub fn combine(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Grid> {
    let source = |g: &Bound<'_, PyAny>| -> PyResult<GridSource> {
        match g.cast::<Grid>() {
            Ok(grid) => Ok(GridSource::Grid(grid.borrow().outcome().solid_voxels())),
            Err(_) => Ok(GridSource::File(g.extract::<PathBuf>()?)),
        }
    };
    let call = Keywords::<CombineRequest>::new(options)?;
    run(py, call, (source(a)?, source(b)?))
}

/// Where the grid of a mesh job lies, as the job would place it: its voxel size and the
/// world position of voxel (0, 0, 0), from the mesh options' placement (`resolution`,
/// `voxel_size`, `origin`, `bounds`, `up_axis`). Several meshes given as one share it.
#[pyfunction]
#[pyo3(signature = (source, **options))]
pub fn placement(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<(f64, [f64; 3])> {
    let call = Keywords::<MeshRequest>::new(options)?;
    let source = mesh_source(source, call.limits.limits().max_memory)?;
    let fit = call.request.fit().map_err(to_py_err)?;
    let up = call.request.up_axis();
    py.detach(|| {
        let mesh = source.load(false, up)?;
        crate::mesh::fit_transform(&mesh.bbox(), fit)
    })
    .map(|t| (t.voxel_size, t.origin.to_array()))
    .map_err(to_py_err)
}

/// A grid of a `.vdb` file: the one named `grid`, else the voxel set voxelkit writes
/// (`voxels`, else `density`), else the first bool, mask or float grid.
#[pyfunction]
#[pyo3(signature = (path, grid = None))]
pub fn read_vdb(py: Python<'_>, path: PathBuf, grid: Option<String>) -> PyResult<Grid> {
    let outcome = py
        .detach(|| Outcome::read_vdb(&path, grid.as_deref()))
        .map_err(super::to_py_err)?;
    Ok(Grid::new(outcome, vec![path]))
}

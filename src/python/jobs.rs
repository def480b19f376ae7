//! The module's functions: each fills the request of `pipeline::request` from its keyword
//! arguments (by name, as the schema declares them), turns it into the job every front end
//! runs (see `watch`) and returns a `Grid`. The package wraps them with the schema's
//! signatures and docs (`python/voxelkit/__init__.py`).

use super::arrays::mesh_source;
use super::grid::Grid;
use super::to_py_err;
use super::watch::run_job;
use crate::mesh::GridFit;
use crate::pipeline::request::{
    CombineRequest, ImplicitRequest, LimitsRequest, LinesRequest, MeasureRequest, MeshRequest,
    Request, Schema, SolidRequest, SubdivRequest,
};
use crate::pipeline::{CsgSource, GridSource, Job, MeasureSource, MeshSource, Outcome, Task};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyString};
use serde_json::{Map, Value};
use std::path::PathBuf;

/// The keyword that takes the progress function (not an option of the request).
const PROGRESS: &str = "progress";

/// A keyword's value as JSON: booleans, integers (numpy's too), finite floats, strings and
/// sequences of these. `None` is left to the caller (it means the default).
fn to_json(v: &Bound<'_, PyAny>) -> Result<Value, String> {
    if v.is_instance_of::<PyBool>() {
        return Ok(Value::Bool(v.extract::<bool>().unwrap_or_default()));
    }
    if v.is_instance_of::<PyString>() {
        return v
            .extract::<String>()
            .map(Value::String)
            .map_err(|e| e.to_string());
    }
    if let Ok(n) = v.extract::<i64>() {
        return Ok(Value::from(n));
    }
    if let Ok(x) = v.extract::<f64>() {
        return serde_json::Number::from_f64(x)
            .map(Value::Number)
            .ok_or_else(|| format!("must be a finite number, not {x}"));
    }
    if let Ok(b) = v.extract::<bool>() {
        return Ok(Value::Bool(b));
    }
    if let Ok(items) = v.try_iter() {
        return items
            .map(|item| item.map_err(|e| e.to_string()).and_then(|i| to_json(&i)))
            .collect::<Result<Vec<_>, _>>()
            .map(Value::Array);
    }
    Err(format!(
        "cannot take a {}",
        v.get_type()
            .name()
            .map_or("value".into(), |n| n.to_string())
    ))
}

/// One call's request, limits and progress function, from its keyword arguments.
pub(super) struct Call<R> {
    pub(super) request: R,
    limits: LimitsRequest,
    progress: Option<Py<PyAny>>,
}

impl<R: Schema> Call<R> {
    pub(super) fn new(options: Option<&Bound<'_, PyDict>>) -> PyResult<Call<R>> {
        let own: Vec<&str> = R::fields().iter().map(|f| f.name).collect();
        let limits: Vec<&str> = LimitsRequest::fields().iter().map(|f| f.name).collect();
        let (mut fields, mut limit_fields) = (Map::new(), Map::new());
        let mut progress = None;
        for (key, value) in options.into_iter().flatten() {
            let key: String = key.extract()?;
            let into = if key == PROGRESS {
                progress = (!value.is_none()).then(|| value.unbind());
                continue;
            } else if own.contains(&key.as_str()) {
                &mut fields
            } else if limits.contains(&key.as_str()) {
                &mut limit_fields
            } else {
                return Err(PyTypeError::new_err(format!(
                    "{}() got an unexpected keyword argument '{key}' (it takes {})",
                    R::NAME,
                    [own.as_slice(), limits.as_slice(), &[PROGRESS]]
                        .concat()
                        .join(", ")
                )));
            };
            if value.is_none() {
                continue;
            }
            let json = to_json(&value).map_err(|e| PyValueError::new_err(format!("{key}: {e}")))?;
            into.insert(key, json);
        }
        Ok(Call {
            request: R::from_json(Value::Object(fields)).map_err(to_py_err)?,
            limits: LimitsRequest::from_json(Value::Object(limit_fields)).map_err(to_py_err)?,
            progress,
        })
    }

    fn run(self, py: Python<'_>, input: R::Input) -> PyResult<Grid>
    where
        R: Request,
    {
        let job = self.request.job(input, &self.limits).map_err(to_py_err)?;
        let inputs = job.task.input_files();
        let outcome = run_job(py, job, self.progress)?;
        Ok(Grid::new(outcome, inputs))
    }
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
    let call = Call::<R>::new(options)?;
    let mesh = mesh_source(source, call.limits.limits().max_memory)?;
    call.run(py, mesh)
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
    Call::<ImplicitRequest>::new(options)?.run(py, formula)
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
    let call = Call::<LimitsRequest>::new(options)?;
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
    let call = Call::<MeasureRequest>::new(options)?;
    let source = if let Ok(grid) = source.cast::<Grid>() {
        MeasureSource::Grid(grid.borrow().sparse().clone())
    } else if let Ok(path) = source.extract::<PathBuf>()
        && path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("vdb"))
    {
        MeasureSource::Vdb(path)
    } else {
        MeasureSource::Mesh(mesh_source(source, call.limits.limits().max_memory)?)
    };
    call.run(py, source)
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
            Ok(grid) => Ok(GridSource::Grid(grid.borrow().sparse().clone())),
            Err(_) => Ok(GridSource::File(g.extract::<PathBuf>()?)),
        }
    };
    Call::<CombineRequest>::new(options)?.run(py, (source(a)?, source(b)?))
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

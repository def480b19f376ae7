//! The brick functions behind `voxelkit.distributed` (see `pipeline::bricks`): planning on
//! the client, one brick's surface, outside labels or solid on a worker, and the merge.
//! Brick meshes travel as three arrays: positions (k, 3), the faces' vertex indices back to
//! back, and where each face starts (m + 1 entries).

use super::arrays::mesh_source;
use super::keywords::Keywords;
use super::to_py_err;
use crate::choice::Choice;
use crate::error::Result;
use crate::grid::Transform;
use crate::io::brick_set::BrickSet;
use crate::io::brick_splice::Spliced;
use crate::io::vdb::WriteOptions;
use crate::mesh::GridFit;
use crate::mesh::Mesh;
use crate::pipeline::brick_exterior::{FaceRuns, exterior_labels};
use crate::pipeline::brick_merge::{brick_metadata, merge_brick_set};
use crate::pipeline::bricks::{BrickIndex, BrickRun, sub_mesh};
use crate::pipeline::request::{BricksRequest, mib_limit};
use crate::pipeline::{BrickStage, BrickTask, Details, Job, Limits, Outcome, Task, merged_bytes};
use crate::progress::Unobserved;
use crate::voxelize::Separability;
use glam::DVec3;
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyType};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A brick index as Python sees it: a tuple, so that it can key a dict.
type PyBrick = (i64, i64, i64);

fn to_py(b: BrickIndex) -> PyBrick {
    (b[0], b[1], b[2])
}

fn from_py(b: PyBrick) -> BrickIndex {
    [b.0, b.1, b.2]
}

/// A mesh placed on its grid and cut into bricks, with the faces each brick receives, and the
/// run's options.
#[pyclass(module = "voxelkit")]
pub struct BrickPlan(BrickRun, BricksRequest);

#[pymethods]
impl BrickPlan {
    /// World position of the centre of voxel (0, 0, 0).
    #[getter]
    fn origin(&self) -> [f64; 3] {
        self.0.layout.transform.origin.to_array()
    }

    #[getter]
    fn voxel_size(&self) -> f64 {
        self.0.layout.transform.voxel_size
    }

    /// Voxels along a brick's edge.
    #[getter]
    fn size(&self) -> i64 {
        self.0.layout.size
    }

    /// The first and last brick along each axis.
    #[getter]
    fn extent(&self) -> (PyBrick, PyBrick) {
        (to_py(self.0.layout.min), to_py(self.0.layout.max))
    }

    /// The separability of a surface run.
    #[getter]
    fn separability(&self) -> u32 {
        self.1.separability.adjacency()
    }

    /// Each brick's memory limit in MiB (none: the memory available).
    #[getter]
    fn max_memory_mib(&self) -> Option<u64> {
        mib_limit(self.1.max_memory_mib).map(|bytes| bytes >> 20)
    }

    /// The bricks that receive faces.
    #[getter]
    fn bricks(&self) -> Vec<PyBrick> {
        self.0.bins.keys().copied().map(to_py).collect()
    }

    #[getter]
    fn face_count(&self) -> usize {
        self.0.mesh.face_count()
    }

    /// The faces brick `b` receives, as (positions, indices, starts).
    fn faces_of<'py>(&self, py: Python<'py>, b: PyBrick) -> PyMeshArrays<'py> {
        let faces = self.0.bins.get(&from_py(b)).map_or(&[][..], Vec::as_slice);
        to_arrays(py, sub_mesh(&self.0.mesh, faces))
    }

    /// The whole mesh, as (positions, indices, starts): what each brick of a winding solid
    /// receives besides its faces.
    fn mesh_arrays<'py>(&self, py: Python<'py>) -> PyMeshArrays<'py> {
        to_arrays(py, self.0.mesh.clone())
    }

    /// Whether a solid's inside is the winding number (else the exterior flood).
    #[getter]
    fn winding(&self) -> bool {
        self.0.winding
    }

    /// Which inside rule a solid takes, and why.
    #[getter]
    fn inside_reason(&self) -> Option<String> {
        self.0.inside_reason.clone()
    }

    /// The bytes a brick wholly inside takes in a merge (its tiles).
    #[getter]
    fn full_brick_bytes(&self) -> u64 {
        let layout = &self.0.layout;
        let mut full = crate::grid::SparseGrid::new(layout.transform, Default::default());
        crate::io::brick_set::fill_box(&mut full, layout.voxels(layout.min));
        merged_bytes(&full)
    }

    /// Whether the bricks lie on OpenVDB's 128^3 nodes, so that their merge copies each
    /// brick's nodes without reading a voxel, in memory that does not grow with them.
    #[getter]
    fn splices(&self) -> bool {
        crate::io::brick_splice::splices(self.0.layout.size)
    }

    /// The bricks a winding solid runs (with faces, or within the mesh's box).
    #[getter]
    fn winding_bricks(&self) -> Vec<PyBrick> {
        self.0.winding_bricks().into_iter().map(to_py).collect()
    }

    /// Cuts the grid into bricks sized for `threads` worker threads when the run gave no
    /// brick size (see `BricksRequest`'s `brick`); the size.
    fn fit_to_threads(&mut self, py: Python<'_>, threads: usize) -> PyResult<i64> {
        let BrickPlan(run, request) = self;
        py.detach(|| run.fit_to_threads(request, threads))
            .map_err(to_py_err)
    }
}

/// A mesh as Python holds it: positions (k, 3), the faces' vertex indices back to back, and
/// where each face starts (m + 1 entries).
type PyMeshArrays<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray1<u32>>,
    Bound<'py, PyArray1<u32>>,
);

fn to_arrays(py: Python<'_>, mesh: Mesh) -> PyMeshArrays<'_> {
    let flat: Vec<f64> = mesh.positions.iter().flat_map(|p| p.to_array()).collect();
    (
        Array2::from_shape_vec((mesh.positions.len(), 3), flat)
            .expect("three coordinates per vertex")
            .into_pyarray(py),
        Array1::from_vec(mesh.indices).into_pyarray(py),
        Array1::from_vec(mesh.face_starts).into_pyarray(py),
    )
}

/// The mesh of arrays Python hands in (see `PyMeshArrays`), named `source` in errors.
fn from_arrays((positions, indices, starts): BrickArrays, source: &str) -> Mesh {
    Mesh {
        positions: positions
            .as_array()
            .rows()
            .into_iter()
            .map(|r| DVec3::new(r[0], r[1], r[2]))
            .collect(),
        indices: indices.as_array().to_vec(),
        face_starts: starts.as_array().to_vec(),
        source: source.into(),
        numbered_from_zero: true,
        ..Default::default()
    }
}

/// The plan of a distributed run (`BricksRequest`'s options as keywords): the mesh read,
/// fitted and cut into bricks by the pipeline; `solid`: its inside rule chosen as a single
/// run chooses it.
#[pyfunction]
#[pyo3(signature = (source, solid = false, output = None, **options))]
pub fn brick_plan(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    solid: bool,
    output: Option<PathBuf>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<BrickPlan> {
    let keywords: Keywords<BricksRequest> = Keywords::new(options)?;
    if keywords.limits.threads.is_some() {
        return Err(PyTypeError::new_err(
            "a distributed run takes no threads: each worker runs its bricks on its own threads",
        ));
    }
    let request = keywords.request;
    let source = mesh_source(source, mib_limit(request.max_memory_mib))?;
    let named = output.unwrap_or_else(|| PathBuf::from("the bricks"));
    py.detach(|| BrickRun::plan(&source, &request, solid, &named))
        .map(|run| BrickPlan(run, request))
        .map_err(to_py_err)
}

/// Where a brick lies: the run's grid (origin, voxel size), the brick and its edge, and its
/// memory limit in MiB.
type BrickAt = ([f64; 3], f64, PyBrick, i64, Option<u64>);

/// Runs one brick's job from its arrays (positions (k, 3), the faces' vertex indices back to
/// back, where each face starts) on the run's grid, under its memory limit.
fn run_brick(
    py: Python<'_>,
    arrays: BrickArrays,
    stage: BrickStage,
    (origin, voxel_size, brick, size, max_memory_mib): BrickAt,
) -> PyResult<Outcome> {
    let faces = from_arrays(arrays, "a brick's faces");
    let task = Task::Brick(BrickTask {
        faces,
        brick: from_py(brick),
        size,
        stage,
    });
    let placed = GridFit::Placed(Transform::new(DVec3::from_array(origin), voxel_size));
    let job = Job {
        limits: Limits {
            max_memory: mib_limit(max_memory_mib),
            ..Limits::default()
        },
        ..Job::new(task, placed)
    };
    py.detach(|| job.run(&Unobserved)).map_err(to_py_err)
}

/// A brick's faces as Python hands them in.
type BrickArrays<'py> = (
    PyReadonlyArray2<'py, f64>,
    PyReadonlyArray1<'py, u32>,
    PyReadonlyArray1<'py, u32>,
);

/// A brick's grid written to `path` (atomically): its voxel count and the bytes it takes in
/// a merge that reads it (`merged_bytes`); without a path, kept encoded in memory for a merge
/// in place (an `EncodedBrick`).
fn finish_brick(
    py: Python<'_>,
    mut outcome: Outcome,
    path: Option<PathBuf>,
    brick: PyBrick,
) -> PyResult<Py<PyAny>> {
    let options = WriteOptions::default();
    let Some(path) = path else {
        let what = PathBuf::from(format!("brick {brick:?}"));
        let encoded = py
            .detach(|| {
                let bytes = outcome.encode_vdb(&what, &options)?;
                crate::io::brick_splice::EncodedBrick::new(bytes, &what)
            })
            .map_err(to_py_err)?;
        return Ok(Py::new(py, EncodedBrick(encoded))?.into_any());
    };
    py.detach(|| outcome.write(&path, &[], &options))
        .map_err(to_py_err)?;
    let counts = (outcome.grid.voxel_count(), merged_bytes(&outcome.grid));
    Ok(counts.into_pyobject(py)?.into_any().unbind())
}

/// A brick's file encoded in memory on the worker that made it, until its nodes are written
/// into the merged file (`brick_splice_in_place`); pickled as the file's bytes.
#[pyclass(module = "voxelkit._voxelkit", frozen)]
pub struct EncodedBrick(crate::io::brick_splice::EncodedBrick);

#[pymethods]
impl EncodedBrick {
    /// The brick file `bytes`, walked.
    #[new]
    fn new(py: Python<'_>, bytes: Vec<u8>) -> PyResult<Self> {
        let what = Path::new("an encoded brick");
        py.detach(|| crate::io::brick_splice::EncodedBrick::new(bytes, what))
            .map(EncodedBrick)
            .map_err(to_py_err)
    }

    #[getter]
    fn voxels(&self) -> u64 {
        self.0.voxels()
    }

    /// The memory it holds, by which Dask counts a worker's results and spills them to its
    /// disk beyond the worker's memory limit.
    fn __sizeof__(&self) -> usize {
        std::mem::size_of::<Self>() + self.0.bytes().len()
    }

    /// What the merge needs to know of the brick's nodes (`brick_splice_in_place`).
    fn nodes<'py>(&self, py: Python<'py>) -> Bound<'py, PyBytes> {
        PyBytes::new(py, &self.0.nodes())
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> (Bound<'py, PyType>, (Bound<'py, PyBytes>,)) {
        let bytes = PyBytes::new(slf.py(), slf.get().0.bytes());
        (slf.get_type(), (bytes,))
    }
}

/// A brick's part of the separating surface, written to `path` or kept (`finish_brick`).
#[pyfunction]
#[pyo3(signature = (positions, indices, starts, origin, voxel_size, brick, size, path,
    separability, max_memory_mib = None))]
#[allow(clippy::too_many_arguments)]
pub fn brick_surface_file(
    py: Python<'_>,
    positions: PyReadonlyArray2<f64>,
    indices: PyReadonlyArray1<u32>,
    starts: PyReadonlyArray1<u32>,
    origin: [f64; 3],
    voxel_size: f64,
    brick: PyBrick,
    size: i64,
    path: Option<PathBuf>,
    separability: u32,
    max_memory_mib: Option<u64>,
) -> PyResult<Py<PyAny>> {
    let separability =
        Separability::from_number(i64::from(separability)).map_err(PyValueError::new_err)?;
    let arrays = (positions, indices, starts);
    let stage = BrickStage::Surface(separability);
    let outcome = run_brick(
        py,
        arrays,
        stage,
        (origin, voxel_size, brick, size, max_memory_mib),
    )?;
    finish_brick(py, outcome, path, brick)
}

/// The labels of a brick's outside components on its six faces (-x, +x, -y, +y, -z, +z),
/// each a uint32 array of runs in cell order (label, count, label, count, ...); 0 marks the
/// surface.
#[pyfunction]
#[pyo3(signature = (positions, indices, starts, origin, voxel_size, brick, size,
    max_memory_mib = None))]
#[allow(clippy::too_many_arguments)]
pub fn brick_faces<'py>(
    py: Python<'py>,
    positions: PyReadonlyArray2<f64>,
    indices: PyReadonlyArray1<u32>,
    starts: PyReadonlyArray1<u32>,
    origin: [f64; 3],
    voxel_size: f64,
    brick: PyBrick,
    size: i64,
    max_memory_mib: Option<u64>,
) -> PyResult<Vec<Bound<'py, PyArray1<u32>>>> {
    let arrays = (positions, indices, starts);
    let stage = BrickStage::FaceLabels;
    let outcome = run_brick(
        py,
        arrays,
        stage,
        (origin, voxel_size, brick, size, max_memory_mib),
    )?;
    let Details::BrickFaces(faces) = outcome.report.details else {
        return Err(PyValueError::new_err(
            "a brick's labels job returned no labels",
        ));
    };
    Ok(faces
        .labels
        .into_iter()
        .map(|runs| {
            let flat: Vec<u32> = runs.into_iter().flat_map(|(l, n)| [l, n]).collect();
            Array1::from_vec(flat).into_pyarray(py)
        })
        .collect())
}

/// A brick of the solid (its surface and the components not in `exterior`), written to
/// `path` or kept (`finish_brick`).
#[pyfunction]
#[pyo3(signature = (positions, indices, starts, origin, voxel_size, brick, size, exterior,
    path, max_memory_mib = None))]
#[allow(clippy::too_many_arguments)]
pub fn brick_solid_file(
    py: Python<'_>,
    positions: PyReadonlyArray2<f64>,
    indices: PyReadonlyArray1<u32>,
    starts: PyReadonlyArray1<u32>,
    origin: [f64; 3],
    voxel_size: f64,
    brick: PyBrick,
    size: i64,
    exterior: Vec<u32>,
    path: Option<PathBuf>,
    max_memory_mib: Option<u64>,
) -> PyResult<Py<PyAny>> {
    let arrays = (positions, indices, starts);
    let stage = BrickStage::Solid { exterior };
    let outcome = run_brick(
        py,
        arrays,
        stage,
        (origin, voxel_size, brick, size, max_memory_mib),
    )?;
    finish_brick(py, outcome, path, brick)
}

/// A brick of a solid whose inside is the winding number of the whole mesh (`mesh_*`, as
/// `BrickPlan.mesh_arrays` gives it): its surface and the centres inside, written to `path`
/// or kept (`finish_brick`).
#[pyfunction]
#[pyo3(signature = (positions, indices, starts, mesh_positions, mesh_indices, mesh_starts,
    origin, voxel_size, brick, size, path, max_memory_mib = None))]
#[allow(clippy::too_many_arguments)]
pub fn brick_winding_file(
    py: Python<'_>,
    positions: PyReadonlyArray2<f64>,
    indices: PyReadonlyArray1<u32>,
    starts: PyReadonlyArray1<u32>,
    mesh_positions: PyReadonlyArray2<f64>,
    mesh_indices: PyReadonlyArray1<u32>,
    mesh_starts: PyReadonlyArray1<u32>,
    origin: [f64; 3],
    voxel_size: f64,
    brick: PyBrick,
    size: i64,
    path: Option<PathBuf>,
    max_memory_mib: Option<u64>,
) -> PyResult<Py<PyAny>> {
    let mesh = from_arrays(
        (mesh_positions, mesh_indices, mesh_starts),
        "the run's mesh",
    );
    let stage = BrickStage::Winding { mesh };
    let arrays = (positions, indices, starts);
    let outcome = run_brick(
        py,
        arrays,
        stage,
        (origin, voxel_size, brick, size, max_memory_mib),
    )?;
    finish_brick(py, outcome, path, brick)
}

/// The exterior labels of every brick of `plan`, from the face labels of the bricks that
/// hold surface (`{brick: [six arrays]}`); bricks without surface have the one label 1.
#[pyfunction]
pub fn brick_exterior(
    py: Python<'_>,
    plan: &BrickPlan,
    faces: BTreeMap<PyBrick, Vec<PyReadonlyArray1<u32>>>,
) -> PyResult<BTreeMap<PyBrick, Vec<u32>>> {
    let mut runs: BTreeMap<BrickIndex, Vec<FaceRuns>> = BTreeMap::new();
    for (b, f) in faces {
        let face = |a: &PyReadonlyArray1<u32>| -> PyResult<FaceRuns> {
            let flat: Vec<u32> = a.as_array().iter().copied().collect();
            if !flat.len().is_multiple_of(2) {
                return Err(PyValueError::new_err(format!(
                    "brick {b:?}: a face's runs come in (label, count) pairs"
                )));
            }
            Ok(flat.chunks_exact(2).map(|p| (p[0], p[1])).collect())
        };
        runs.insert(from_py(b), f.iter().map(face).collect::<PyResult<_>>()?);
    }
    let layout = plan.0.layout;
    let exterior = py
        .detach(|| exterior_labels(&layout, &runs))
        .map_err(to_py_err)?;
    Ok(exterior.into_iter().map(|(b, l)| (to_py(b), l)).collect())
}

/// Writes the brick-set index `index` (brick files named relative to it); with `merged`, also
/// merges the bricks into that one `.vdb` (see `pipeline::brick_merge`) and returns how
/// (`"splicing"` or `"reading"`).
#[pyfunction]
#[pyo3(signature = (plan, files, full_bricks, index, merged = None))]
pub fn brick_finish(
    py: Python<'_>,
    plan: &BrickPlan,
    files: BTreeMap<PyBrick, String>,
    full_bricks: Vec<PyBrick>,
    index: PathBuf,
    merged: Option<PathBuf>,
) -> PyResult<Option<&'static str>> {
    let set = brick_set(plan, files, full_bricks);
    let source = plan.0.mesh.source.display().to_string();
    py.detach(|| -> Result<Option<&'static str>> {
        set.write(&index)?;
        let Some(out) = merged else {
            return Ok(None);
        };
        let (by, _) = merge_brick_set(&index, &out, &source)?;
        Ok(Some(by.name()))
    })
    .map_err(to_py_err)
}

/// Bytes start..end of a brick's file and where they go in the merged file: (start, end, at).
type PyPlacement = (u64, u64, u64);

/// Writes the ranges of each brick of `bricks` ((brick, placements): (start, end, at) for
/// bytes start..end of its file at `at`) into the existing file `path`, and syncs it.
#[pyfunction]
pub fn write_bricks_into(
    py: Python<'_>,
    path: PathBuf,
    bricks: Vec<(PyRef<'_, EncodedBrick>, Vec<PyPlacement>)>,
) -> PyResult<()> {
    let bricks: Vec<_> = bricks
        .iter()
        .map(|(brick, placements)| {
            let ranges = placements.iter().map(|&(a, b, at)| (a..b, at)).collect();
            (&brick.0, ranges)
        })
        .collect();
    py.detach(|| crate::io::brick_splice::write_bricks_into(&path, &bricks))
        .map_err(to_py_err)
}

/// The brick set of `plan`'s run: its bricks (in files named `files`, or kept) and the bricks
/// wholly inside.
fn brick_set(
    plan: &BrickPlan,
    files: BTreeMap<PyBrick, String>,
    full_bricks: Vec<PyBrick>,
) -> BrickSet {
    BrickSet {
        format: crate::io::brick_set::BRICK_SET_FORMAT.into(),
        voxel_size: plan.0.layout.transform.voxel_size,
        origin: plan.0.layout.transform.origin.to_array(),
        brick_size: plan.0.layout.size,
        bricks: files
            .into_iter()
            .map(|(brick, file)| crate::io::brick_set::BrickFile {
                brick: from_py(brick),
                file,
            })
            .collect(),
        full_bricks: full_bricks.into_iter().map(from_py).collect(),
    }
}

/// Merges bricks kept in the workers' memory into the one `.vdb` `output`, atomically: from
/// each brick's `nodes` (`EncodedBrick.nodes`) it lays the file out, writes its own bytes
/// (the heads and the 4096^3 nodes' masks), and calls `write_bricks(temporary, placements)`
/// to have every brick write its ranges into place (`placements`: {brick: [(start, end,
/// at)]}; `write_bricks_into`), then syncs and renames the file. Returns the voxels.
#[pyfunction]
pub fn brick_splice_in_place(
    py: Python<'_>,
    plan: &BrickPlan,
    nodes: BTreeMap<PyBrick, Vec<u8>>,
    full_bricks: Vec<PyBrick>,
    output: PathBuf,
    write_bricks: Py<PyAny>,
) -> PyResult<u64> {
    let bricks: Vec<PyBrick> = nodes.keys().copied().collect();
    let named = bricks.iter().map(|&b| (b, String::new())).collect();
    let set = brick_set(plan, named, full_bricks);
    let source = plan.0.mesh.source.display().to_string();
    let nodes: Vec<Vec<u8>> = nodes.into_values().collect();
    // A Python error from `write_bricks` (a brick that failed for good, a signal) is raised
    // again as it was.
    let mut raised = None;
    let merged = py.detach(|| {
        let spliced = Spliced::in_place(&set, &nodes, &output, &brick_metadata(&source))?;
        let voxels = spliced.voxels;
        spliced.write_in_place(&output, bricks.len(), |tmp, placements| {
            Python::attach(|py| {
                let by_brick = PyDict::new(py);
                for (b, ranges) in bricks.iter().zip(placements) {
                    let ranges: Vec<PyPlacement> = ranges
                        .into_iter()
                        .map(|(r, at)| (r.start, r.end, at))
                        .collect();
                    by_brick.set_item(b, ranges)?;
                }
                write_bricks.call1(py, (tmp, by_brick)).map(|_| ())
            })
            .map_err(|e| {
                let message = e.to_string();
                raised = Some(e);
                crate::error::Error::InvalidArgument(message)
            })
        })?;
        Ok(voxels)
    });
    match (merged, raised) {
        (_, Some(e)) => Err(e),
        (merged, None) => merged.map_err(to_py_err),
    }
}

/// Merges the brick set of the index at `index` into the one `.vdb` `output` (see
/// `pipeline::brick_merge`); returns how (`"splicing"` or `"reading"`) and its voxels.
#[pyfunction]
pub fn brick_merge(
    py: Python<'_>,
    index: PathBuf,
    output: PathBuf,
) -> PyResult<(&'static str, u64)> {
    let source = index.display().to_string();
    py.detach(|| merge_brick_set(&index, &output, &source))
        .map(|(by, voxels)| (by.name(), voxels))
        .map_err(to_py_err)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<BrickPlan>()?;
    m.add_class::<EncodedBrick>()?;
    m.add_function(wrap_pyfunction!(brick_plan, m)?)?;
    m.add_function(wrap_pyfunction!(brick_surface_file, m)?)?;
    m.add_function(wrap_pyfunction!(brick_faces, m)?)?;
    m.add_function(wrap_pyfunction!(brick_solid_file, m)?)?;
    m.add_function(wrap_pyfunction!(brick_winding_file, m)?)?;
    m.add_function(wrap_pyfunction!(brick_exterior, m)?)?;
    m.add_function(wrap_pyfunction!(brick_finish, m)?)?;
    m.add_function(wrap_pyfunction!(brick_merge, m)?)?;
    m.add_function(wrap_pyfunction!(brick_splice_in_place, m)?)?;
    m.add_function(wrap_pyfunction!(write_bricks_into, m)?)?;
    Ok(())
}

//! The brick functions behind `voxelkit.distributed` (see `pipeline::bricks`): planning on
//! the client, one brick's surface, outside labels or solid on a worker, and the merge.
//! Brick meshes travel as three arrays: positions (k, 3), the faces' vertex indices back to
//! back, and where each face starts (m + 1 entries).

use super::arrays::mesh_source;
use super::grid::Grid;
use super::to_py_err;
use crate::error::Result;
use crate::grid::{CoordBox, Transform};
use crate::io::brick_set::{BrickSet, brick_voxels};
use crate::io::vdb::{WriteOptions, check_voxel_size, write_vdb_as};
use crate::mesh::{GridFit, Mesh, UpAxis};
use crate::pipeline::Outcome;
use crate::pipeline::brick_exterior::exterior_labels;
use crate::pipeline::bricks::{
    BrickIndex, BrickLayout, BrickOutside, FACES, brick_surface, check_brick_fits, sub_mesh,
};
use crate::progress::Progress;
use crate::voxelize::Separability;
use crate::voxelize::separating::SeparatingOptions;
use glam::DVec3;
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
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

/// A mesh placed on its grid and cut into bricks, with the faces each brick receives.
#[pyclass(module = "voxelkit")]
pub struct BrickPlan {
    mesh: Mesh,
    layout: BrickLayout,
    bins: BTreeMap<BrickIndex, Vec<u32>>,
}

#[pymethods]
impl BrickPlan {
    /// World position of the centre of voxel (0, 0, 0).
    #[getter]
    fn origin(&self) -> [f64; 3] {
        self.layout.transform.origin.to_array()
    }

    #[getter]
    fn voxel_size(&self) -> f64 {
        self.layout.transform.voxel_size
    }

    /// Voxels along a brick's edge.
    #[getter]
    fn size(&self) -> i64 {
        self.layout.size
    }

    /// The first and last brick along each axis.
    #[getter]
    fn extent(&self) -> (PyBrick, PyBrick) {
        (to_py(self.layout.min), to_py(self.layout.max))
    }

    /// The bricks that receive faces.
    #[getter]
    fn bricks(&self) -> Vec<PyBrick> {
        self.bins.keys().copied().map(to_py).collect()
    }

    #[getter]
    fn face_count(&self) -> usize {
        self.mesh.face_count()
    }

    /// The faces brick `b` receives, as (positions, indices, starts).
    #[allow(clippy::type_complexity)]
    fn faces_of<'py>(
        &self,
        py: Python<'py>,
        b: PyBrick,
    ) -> (
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray1<u32>>,
        Bound<'py, PyArray1<u32>>,
    ) {
        let faces = self.bins.get(&from_py(b)).map_or(&[][..], Vec::as_slice);
        let sub = sub_mesh(&self.mesh, faces);
        let flat: Vec<f64> = sub.positions.iter().flat_map(|p| p.to_array()).collect();
        (
            Array2::from_shape_vec((sub.positions.len(), 3), flat)
                .expect("three coordinates per vertex")
                .into_pyarray(py),
            Array1::from_vec(sub.indices).into_pyarray(py),
            Array1::from_vec(sub.face_starts).into_pyarray(py),
        )
    }
}

/// Reads the mesh (as the CLI does), places it on the grid a single run would use, and cuts
/// it into bricks of `brick` voxels; `solid`: the mesh must be closed.
#[pyfunction]
#[pyo3(signature = (source, brick, resolution = None, voxel_size = None, solid = false,
    up_axis = "z", output = None))]
#[allow(clippy::too_many_arguments)]
pub fn brick_plan(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    brick: u32,
    resolution: Option<u32>,
    voxel_size: Option<f64>,
    solid: bool,
    up_axis: &str,
    output: Option<PathBuf>,
) -> PyResult<BrickPlan> {
    let source = mesh_source(source)?;
    let up: UpAxis = up_axis.parse().map_err(PyValueError::new_err)?;
    let fit = GridFit::from_options(resolution, voxel_size);
    py.detach(|| -> Result<BrickPlan> {
        let mesh = source.load(false, up)?;
        if solid {
            mesh.require_closed(crate::pipeline::FLOOD_NEEDS_CLOSED)?;
        }
        let layout = BrickLayout::new(&mesh, fit, brick)?;
        let named = output.unwrap_or_else(|| PathBuf::from("the bricks"));
        check_voxel_size(&named, layout.transform.voxel_size)?;
        let bins = layout.bin_faces(&mesh);
        Ok(BrickPlan { mesh, layout, bins })
    })
    .map_err(to_py_err)
}

/// One brick's work: its faces, grid and voxels.
struct BrickJob {
    faces: Mesh,
    transform: Transform,
    voxels: CoordBox,
}

impl BrickJob {
    fn new(
        positions: PyReadonlyArray2<f64>,
        indices: PyReadonlyArray1<u32>,
        starts: PyReadonlyArray1<u32>,
        origin: [f64; 3],
        voxel_size: f64,
        brick: BrickIndex,
        size: i64,
    ) -> PyResult<BrickJob> {
        let p = positions.as_array();
        let faces = Mesh {
            positions: p
                .rows()
                .into_iter()
                .map(|r| DVec3::new(r[0], r[1], r[2]))
                .collect(),
            indices: indices.as_array().to_vec(),
            face_starts: starts.as_array().to_vec(),
            source: "a brick's faces".into(),
            numbered_from_zero: true,
            ..Default::default()
        };
        faces.validate().map_err(to_py_err)?;
        Ok(BrickJob {
            faces,
            transform: Transform::new(DVec3::from_array(origin), voxel_size),
            voxels: brick_voxels(brick, size),
        })
    }

    fn surface(
        &self,
        separability: Separability,
        solid: bool,
        max_memory_mib: Option<u64>,
    ) -> Result<crate::grid::SparseGrid> {
        let limit = max_memory_mib.map(|m| m.saturating_mul(1 << 20));
        check_brick_fits(&self.faces, &self.transform, self.voxels, solid, limit)?;
        let options = SeparatingOptions {
            separability,
            ..Default::default()
        };
        brick_surface(
            &self.faces,
            self.transform,
            self.voxels,
            &options,
            &Progress::none(),
        )
    }
}

/// Writes `grid` to `path` (atomically) and returns its voxel count.
fn write_brick(grid: &crate::grid::SparseGrid, path: &Path) -> Result<u64> {
    let meta = [("method", "voxelkit brick".into())];
    write_vdb_as(path, grid, &[], &meta, &WriteOptions::default())?;
    Ok(grid.voxel_count())
}

/// A brick's part of the separating surface, written to `path`; returns its voxel count.
#[pyfunction]
#[pyo3(signature = (positions, indices, starts, origin, voxel_size, brick, size, path,
    separability = 26, max_memory_mib = None))]
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
    path: PathBuf,
    separability: u32,
    max_memory_mib: Option<u64>,
) -> PyResult<u64> {
    let job = BrickJob::new(
        positions,
        indices,
        starts,
        origin,
        voxel_size,
        from_py(brick),
        size,
    )?;
    let separability: Separability = separability
        .to_string()
        .parse()
        .map_err(PyValueError::new_err)?;
    py.detach(|| write_brick(&job.surface(separability, false, max_memory_mib)?, &path))
        .map_err(to_py_err)
}

/// The labels of a brick's outside components on its six faces (-x, +x, -y, +y, -z, +z),
/// each a (size * size) uint32 array; 0 marks the surface.
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
    let job = BrickJob::new(
        positions,
        indices,
        starts,
        origin,
        voxel_size,
        from_py(brick),
        size,
    )?;
    let faces = py
        .detach(|| -> Result<Vec<Vec<u32>>> {
            let surface = job.surface(Separability::TwentySix, true, max_memory_mib)?;
            let outside = BrickOutside::label(&surface, job.voxels)?;
            Ok((0..FACES).map(|f| outside.face(f)).collect())
        })
        .map_err(to_py_err)?;
    Ok(faces
        .into_iter()
        .map(|f| Array1::from_vec(f).into_pyarray(py))
        .collect())
}

/// A brick of the solid (its surface and the components not in `exterior`), written to
/// `path`; returns its voxel count.
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
    mut exterior: Vec<u32>,
    path: PathBuf,
    max_memory_mib: Option<u64>,
) -> PyResult<u64> {
    let job = BrickJob::new(
        positions,
        indices,
        starts,
        origin,
        voxel_size,
        from_py(brick),
        size,
    )?;
    exterior.sort_unstable();
    py.detach(|| {
        let surface = job.surface(Separability::TwentySix, true, max_memory_mib)?;
        let outside = BrickOutside::label(&surface, job.voxels)?;
        write_brick(&outside.solid(&surface, &exterior), &path)
    })
    .map_err(to_py_err)
}

/// The exterior labels of every brick of `plan`, from the face labels of the bricks that
/// hold surface (`{brick: [six arrays]}`); bricks without surface have the one label 1.
#[pyfunction]
pub fn brick_exterior(
    py: Python<'_>,
    plan: &BrickPlan,
    faces: BTreeMap<PyBrick, Vec<PyReadonlyArray1<u32>>>,
) -> PyResult<BTreeMap<PyBrick, Vec<u32>>> {
    let faces: BTreeMap<BrickIndex, Vec<Vec<u32>>> = faces
        .into_iter()
        .map(|(b, f)| {
            (
                from_py(b),
                f.iter().map(|a| a.as_array().to_vec()).collect(),
            )
        })
        .collect();
    let layout = plan.layout;
    let exterior = py
        .detach(|| exterior_labels(&layout, &faces))
        .map_err(to_py_err)?;
    Ok(exterior.into_iter().map(|(b, l)| (to_py(b), l)).collect())
}

/// Writes the brick-set index `index` (brick files named relative to it); with `merged`, also
/// merges the bricks into that one `.vdb` and returns it as a Grid.
#[pyfunction]
#[pyo3(signature = (plan, files, full_bricks, index, merged = None))]
pub fn brick_finish(
    py: Python<'_>,
    plan: &BrickPlan,
    files: BTreeMap<PyBrick, String>,
    full_bricks: Vec<PyBrick>,
    index: PathBuf,
    merged: Option<PathBuf>,
) -> PyResult<Option<Grid>> {
    let set = BrickSet {
        format: crate::io::brick_set::BRICK_SET_FORMAT.into(),
        voxel_size: plan.layout.transform.voxel_size,
        origin: plan.layout.transform.origin.to_array(),
        brick_size: plan.layout.size,
        bricks: files
            .into_iter()
            .map(|(brick, file)| crate::io::brick_set::BrickFile {
                brick: from_py(brick),
                file,
            })
            .collect(),
        full_bricks: full_bricks.into_iter().map(from_py).collect(),
    };
    py.detach(|| -> Result<Option<Grid>> {
        set.write(&index)?;
        let Some(out) = merged else {
            return Ok(None);
        };
        let mut outcome = Outcome::read_vdb(&index, None)?;
        outcome.write(&out, &[index.as_path()], &WriteOptions::default())?;
        Ok(Some(Grid::new(outcome, vec![index.clone()])))
    })
    .map_err(to_py_err)
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<BrickPlan>()?;
    m.add_function(wrap_pyfunction!(brick_plan, m)?)?;
    m.add_function(wrap_pyfunction!(brick_surface_file, m)?)?;
    m.add_function(wrap_pyfunction!(brick_faces, m)?)?;
    m.add_function(wrap_pyfunction!(brick_solid_file, m)?)?;
    m.add_function(wrap_pyfunction!(brick_exterior, m)?)?;
    m.add_function(wrap_pyfunction!(brick_finish, m)?)?;
    Ok(())
}

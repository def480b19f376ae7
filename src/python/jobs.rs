//! The module's functions: each builds the CLI's `Job` from keyword arguments and runs it
//! (see `watch`), returning a `Grid`.

use super::arrays::mesh_source;
use super::grid::Grid;
use super::watch::run_job;
use crate::grid::Adjacency;
use crate::implicit::Coordinates;
use crate::mesh::{GridFit, UpAxis};
use crate::ops::csg::BooleanOp;
use crate::pipeline::{
    ColorChoice, CsgSource, Fill, GridSource, Job, Limits, MeasureSource, Outcome, SubdivisionFill,
    SurfaceMethod, Task,
};
use crate::solids::beam::BeamFill;
use crate::solids::depth_layers::{DepthLayerOptions, DirectionSet, Layers, Unclassified};
use crate::solids::exterior_flood::FloodMethod;
use crate::voxelize::Separability;
use crate::voxelize::parametric::ParametricOptions;
use crate::voxelize::separating::{Criterion, SeparatingOptions};
use glam::{DVec3, Vec3};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::str::FromStr;

/// A keyword's text value parsed as the CLI parses it; its error becomes a ValueError.
fn parse<T: FromStr<Err = String>>(s: &str) -> PyResult<T> {
    s.parse().map_err(PyValueError::new_err)
}

fn fit(resolution: Option<u32>, voxel_size: Option<f64>) -> PyResult<GridFit> {
    if resolution.is_some() && voxel_size.is_some() {
        return Err(PyValueError::new_err(
            "give resolution or voxel_size, not both",
        ));
    }
    Ok(GridFit::from_options(resolution, voxel_size))
}

/// The keywords every function takes besides its own.
struct Common {
    threads: Option<usize>,
    max_memory_mib: Option<u64>,
    up_axis: UpAxis,
    progress: Option<Py<PyAny>>,
}

impl Common {
    fn new(
        threads: Option<usize>,
        max_memory_mib: Option<u64>,
        up_axis: &str,
        progress: Option<Py<PyAny>>,
    ) -> PyResult<Common> {
        Ok(Common {
            threads,
            max_memory_mib,
            up_axis: parse(up_axis)?,
            progress,
        })
    }

    fn run(self, py: Python<'_>, task: Task, fit: GridFit) -> PyResult<Grid> {
        let job = Job {
            limits: Limits {
                threads: self.threads,
                max_memory: self.max_memory_mib.map(|m| m.saturating_mul(1 << 20)),
            },
            up_axis: self.up_axis,
            ..Job::new(task, fit)
        };
        let inputs = job.task.input_files();
        let outcome = run_job(py, job, self.progress)?;
        Ok(Grid::new(outcome, inputs))
    }
}

fn separability(s: u32) -> PyResult<Separability> {
    parse(&s.to_string())
}

fn flood_method(flood: &str, graystack: usize) -> PyResult<FloodMethod> {
    match flood {
        "blocks" => Ok(FloodMethod::Blocks),
        "spans" => Ok(FloodMethod::Spans),
        "xyz" => Ok(FloodMethod::Xyz {
            capacity: graystack.max(1),
        }),
        _ => Err(PyValueError::new_err(format!(
            "flood must be blocks, spans or xyz, not `{flood}`"
        ))),
    }
}

/// `directions`: a count of the built-in directions (default all 16, as the CLI), or a list
/// of integer (x, y, z) triples.
fn direction_set(directions: Option<&Bound<'_, PyAny>>) -> PyResult<DirectionSet> {
    let Some(directions) = directions else {
        return Ok(DirectionSet::ALL);
    };
    let set = match directions.extract::<usize>() {
        Ok(n) => DirectionSet::first(n),
        Err(_) => DirectionSet::given(&directions.extract::<Vec<[i64; 3]>>().map_err(|_| {
            PyValueError::new_err("directions: a count, or a list of (x, y, z) integer triples")
        })?),
    };
    set.map_err(super::to_py_err)
}

fn color_choice(color: Option<[f32; 3]>, from_mesh: bool) -> ColorChoice {
    match (color, from_mesh) {
        (Some(c), _) => ColorChoice::Constant(Vec3::from_array(c)),
        (None, true) => ColorChoice::FromMesh,
        (None, false) => ColorChoice::None,
    }
}

/// A polygon mesh's surface: 6- or 26-separating (Huang et al.) or projective (Jegathese
/// et al.); with `sdf` or `udf`, exact distances within `band` voxels instead.
///
/// `source` is a path (.obj, .stl, .ply, .off, .gltf, .glb) or a `(vertices, faces)` pair.
#[pyfunction]
#[pyo3(signature = (source, resolution = None, voxel_size = None, separability = 26,
    method = "separating", criterion = "huang", normals = false, colors = true, color = None,
    sdf = false, udf = false, band = 3.0, threads = None, max_memory_mib = None,
    up_axis = "z", progress = None))]
#[allow(clippy::too_many_arguments)]
pub fn mesh(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    resolution: Option<u32>,
    voxel_size: Option<f64>,
    separability: u32,
    method: &str,
    criterion: &str,
    normals: bool,
    colors: bool,
    color: Option<[f32; 3]>,
    sdf: bool,
    udf: bool,
    band: f64,
    threads: Option<usize>,
    max_memory_mib: Option<u64>,
    up_axis: &str,
    progress: Option<Py<PyAny>>,
) -> PyResult<Grid> {
    let mesh = mesh_source(source)?;
    let task = if sdf || udf {
        if sdf && udf {
            return Err(PyValueError::new_err("sdf and udf exclude each other"));
        }
        Task::DistanceBand {
            mesh,
            band,
            signed: sdf,
        }
    } else {
        let method = match method {
            "separating" => SurfaceMethod::Separating(SeparatingOptions {
                separability: self::separability(separability)?,
                criterion: parse::<Criterion>(criterion)?,
                normals,
            }),
            "projective" => SurfaceMethod::Projective(color_choice(color, colors)),
            _ => {
                return Err(PyValueError::new_err(format!(
                    "method must be separating or projective, not `{method}`"
                )));
            }
        };
        Task::MeshSurface { mesh, method }
    };
    Common::new(threads, max_memory_mib, up_axis, progress)?.run(
        py,
        task,
        fit(resolution, voxel_size)?,
    )
}

/// A closed mesh's solid: `method="flood"` (the 26-separating surface and everything the
/// exterior flood cannot reach), `"depth-layers"` (Passalis et al.) or `"beam"` (Jegathese
/// et al.); with `sdf`, its level set. The report holds the volume, mass and area.
///
/// Depth layers: `directions` is a count of the 16 built-in directions (default all) or a
/// list of integer (x, y, z) triples, each with a component of ±1; `layers` single or double;
/// `unclassified` "no-direction" (a voxel no direction decides) or "paper" (a voxel on a ray
/// of any direction crossing more than four times). Beam: `fill` "parity" (centres between
/// exact crossings) or "paper" (from each back-face voxel up to the next front-face voxel).
#[pyfunction]
#[pyo3(signature = (source, resolution = None, voxel_size = None, method = "flood",
    flood = "blocks", graystack = 1 << 20, directions = None, layers = "double",
    unclassified = "no-direction", fill = "parity", density = 1.0,
    topology = false, sdf = false, band = 3.0, threads = None, max_memory_mib = None,
    up_axis = "z", progress = None))]
#[allow(clippy::too_many_arguments)]
pub fn solid(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    resolution: Option<u32>,
    voxel_size: Option<f64>,
    method: &str,
    flood: &str,
    graystack: usize,
    directions: Option<&Bound<'_, PyAny>>,
    layers: &str,
    unclassified: &str,
    fill: &str,
    density: f64,
    topology: bool,
    sdf: bool,
    band: f64,
    threads: Option<usize>,
    max_memory_mib: Option<u64>,
    up_axis: &str,
    progress: Option<Py<PyAny>>,
) -> PyResult<Grid> {
    let mesh = mesh_source(source)?;
    let task = if sdf {
        Task::DistanceBand {
            mesh,
            band,
            signed: true,
        }
    } else {
        let fill = match method {
            "flood" => Fill::Flood(flood_method(flood, graystack)?),
            "depth-layers" => Fill::DepthLayers(DepthLayerOptions {
                directions: direction_set(directions)?,
                layers: match layers {
                    "single" => Layers::Single,
                    "double" => Layers::Double,
                    _ => {
                        return Err(PyValueError::new_err(format!(
                            "layers must be single or double, not `{layers}`"
                        )));
                    }
                },
                unclassified: match unclassified {
                    "no-direction" => Unclassified::NoDirection,
                    "paper" => Unclassified::Paper,
                    _ => {
                        return Err(PyValueError::new_err(format!(
                            "unclassified must be no-direction or paper, not `{unclassified}`"
                        )));
                    }
                },
            }),
            "beam" => Fill::Beam(parse::<BeamFill>(fill)?),
            _ => {
                return Err(PyValueError::new_err(format!(
                    "method must be flood, depth-layers or beam, not `{method}`"
                )));
            }
        };
        Task::Solid {
            mesh,
            fill,
            density,
            topology,
        }
    };
    Common::new(threads, max_memory_mib, up_axis, progress)?.run(
        py,
        task,
        fit(resolution, voxel_size)?,
    )
}

/// A Catmull-Clark limit surface from its control mesh (Lai & Cheng): every voxel meets the
/// `adjacency` (6, 18 or 26) between the corners of its sub-patches; `enclose`: every voxel
/// the surface touches. `solid`: the solid of the closed limit surface, its inside flooded
/// from seeds against the limit normals by FloodingXYZ (`graystack` entries), with its volume
/// and mass (`density`) beside the exact limit volume in the report.
#[pyfunction]
#[pyo3(signature = (source, resolution = None, voxel_size = None, adjacency = 26,
    enclose = false, presplit = 8, solid = false, graystack = 1 << 20, density = 1.0,
    topology = false, threads = None, max_memory_mib = None, up_axis = "z", progress = None))]
#[allow(clippy::too_many_arguments)]
pub fn subdiv(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    resolution: Option<u32>,
    voxel_size: Option<f64>,
    adjacency: u32,
    enclose: bool,
    presplit: u32,
    solid: bool,
    graystack: usize,
    density: f64,
    topology: bool,
    threads: Option<usize>,
    max_memory_mib: Option<u64>,
    up_axis: &str,
    progress: Option<Py<PyAny>>,
) -> PyResult<Grid> {
    let adjacency = match adjacency {
        6 => Adjacency::Six,
        18 => Adjacency::Eighteen,
        26 => Adjacency::TwentySix,
        _ => {
            return Err(PyValueError::new_err(format!(
                "adjacency must be 6, 18 or 26, not {adjacency}"
            )));
        }
    };
    let task = Task::Subdivision {
        mesh: mesh_source(source)?,
        options: ParametricOptions {
            adjacency,
            presplit,
            enclose,
        },
        solid: solid.then_some(SubdivisionFill {
            graystack,
            density,
            topology,
        }),
    };
    Common::new(threads, max_memory_mib, up_axis, progress)?.run(
        py,
        task,
        fit(resolution, voxel_size)?,
    )
}

/// The surface F = 0 of a formula (Stolte & Kaufman's interval octree): `coords` is
/// cartesian (x, y, z), spherical (r, theta, phi) or cylindrical (r, theta, z); `bounds`
/// is `(lo, hi)` for a cube or `((x0, y0, z0), (x1, y1, z1))`; `theta_range` "positive"
/// (the paper's [0, 2pi)) or "symmetric" ((-pi, pi]); `squared`: the paper's [G]^2 - r^2 = 0
/// for F = G - r (the surface r = |G|).
#[pyfunction]
#[pyo3(signature = (formula, coords = "cartesian", bounds = None, resolution = 256,
    levels = false, negative_r = false, theta_range = "positive", squared = false,
    threads = None, max_memory_mib = None, progress = None))]
#[allow(clippy::too_many_arguments)]
pub fn implicit(
    py: Python<'_>,
    formula: String,
    coords: &str,
    bounds: Option<&Bound<'_, PyAny>>,
    resolution: u32,
    levels: bool,
    negative_r: bool,
    theta_range: &str,
    squared: bool,
    threads: Option<usize>,
    max_memory_mib: Option<u64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Grid> {
    let (min, max) = match bounds {
        None => (DVec3::splat(-1.0), DVec3::splat(1.0)),
        Some(b) => {
            if let Ok((lo, hi)) = b.extract::<(f64, f64)>() {
                (DVec3::splat(lo), DVec3::splat(hi))
            } else {
                let (lo, hi) = b.extract::<([f64; 3], [f64; 3])>().map_err(|_| {
                    PyValueError::new_err("bounds: (lo, hi) or ((x0, y0, z0), (x1, y1, z1))")
                })?;
                (DVec3::from_array(lo), DVec3::from_array(hi))
            }
        }
    };
    let task = Task::Implicit {
        formula,
        coordinates: parse::<Coordinates>(coords)?,
        min,
        max,
        levels,
        negative_r,
        theta_range: parse::<crate::implicit::ThetaRange>(theta_range)?,
        squared,
    };
    Common::new(threads, max_memory_mib, "z", progress)?.run(
        py,
        task,
        GridFit::Resolution(resolution),
    )
}

/// 3D lines (Jegathese et al.): the polylines (OBJ `l`) of a file, and with `edges` (or
/// when there are none) the faces' edges; colours from the mesh, or `color`.
#[pyfunction]
#[pyo3(signature = (source, resolution = None, voxel_size = None, edges = false,
    colors = true, color = None, threads = None, max_memory_mib = None, up_axis = "z",
    progress = None))]
#[allow(clippy::too_many_arguments)]
pub fn lines(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    resolution: Option<u32>,
    voxel_size: Option<f64>,
    edges: bool,
    colors: bool,
    color: Option<[f32; 3]>,
    threads: Option<usize>,
    max_memory_mib: Option<u64>,
    up_axis: &str,
    progress: Option<Py<PyAny>>,
) -> PyResult<Grid> {
    let task = Task::Lines {
        mesh: mesh_source(source)?,
        edges,
        color: color_choice(color, colors),
    };
    Common::new(threads, max_memory_mib, up_axis, progress)?.run(
        py,
        task,
        fit(resolution, voxel_size)?,
    )
}

/// A CSG tree (the CLI's `csg --tree` JSON): a path to the JSON file, or the tree as a dict
/// (its file names are then found from the current directory).
#[pyfunction]
#[pyo3(signature = (tree, threads = None, max_memory_mib = None, progress = None))]
pub fn csg(
    py: Python<'_>,
    tree: &Bound<'_, PyAny>,
    threads: Option<usize>,
    max_memory_mib: Option<u64>,
    progress: Option<Py<PyAny>>,
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
    Common::new(threads, max_memory_mib, "z", progress)?.run(
        py,
        Task::CsgTree(source),
        GridFit::Resolution(256),
    )
}

/// Volume, mass, area, components and genus of a closed mesh (its flooded 26-separating
/// surface), of a `.vdb` surface (a solid's `shell`, else its voxels) or of a Grid holding a
/// surface. Returns the solid; the measures are in its `report`.
#[pyfunction]
#[pyo3(signature = (source, resolution = None, voxel_size = None, flood = "blocks",
    graystack = 1 << 20, density = 1.0, threads = None, max_memory_mib = None,
    up_axis = "z", progress = None))]
#[allow(clippy::too_many_arguments)]
pub fn measure(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    resolution: Option<u32>,
    voxel_size: Option<f64>,
    flood: &str,
    graystack: usize,
    density: f64,
    threads: Option<usize>,
    max_memory_mib: Option<u64>,
    up_axis: &str,
    progress: Option<Py<PyAny>>,
) -> PyResult<Grid> {
    let source = if let Ok(grid) = source.cast::<Grid>() {
        MeasureSource::Grid(grid.borrow().sparse().clone())
    } else if let Ok(path) = source.extract::<PathBuf>()
        && path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("vdb"))
    {
        MeasureSource::Vdb(path)
    } else {
        MeasureSource::Mesh(mesh_source(source)?)
    };
    let task = Task::Measure {
        source,
        flood: flood_method(flood, graystack)?,
        density,
    };
    Common::new(threads, max_memory_mib, up_axis, progress)?.run(
        py,
        task,
        fit(resolution, voxel_size)?,
    )
}

/// A Boolean of two grids (Grids, or `.vdb` paths whose grid `grid` or voxel set is read):
/// `op` is union, intersection or difference; `resample` puts b on a's grid when their
/// voxel sizes differ.
#[pyfunction]
#[pyo3(signature = (a, b, op = "union", grid = None, resample = false, threads = None,
    progress = None))]
#[allow(clippy::too_many_arguments)]
pub fn combine(
    py: Python<'_>,
    a: &Bound<'_, PyAny>,
    b: &Bound<'_, PyAny>,
    op: &str,
    grid: Option<String>,
    resample: bool,
    threads: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Grid> {
    let source = |g: &Bound<'_, PyAny>| -> PyResult<GridSource> {
        match g.cast::<Grid>() {
            Ok(grid) => Ok(GridSource::Grid(grid.borrow().sparse().clone())),
            Err(_) => Ok(GridSource::File(g.extract::<PathBuf>()?)),
        }
    };
    let task = Task::Combine {
        a: source(a)?,
        b: source(b)?,
        grid,
        op: parse::<BooleanOp>(op)?,
        resample,
        curve: false,
    };
    Common::new(threads, None, "z", progress)?.run(py, task, GridFit::Resolution(256))
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

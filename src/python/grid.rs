//! `voxelkit.Grid`: what every Python call returns — the voxels as numpy arrays, the
//! channels, the transform, the report, the extra grids, and writing.

use super::keywords::Keywords;
use super::to_py_err;
use crate::grid::Transform;
use crate::io::preview::{Scene, View, check_picture_output, render, write_png};
use crate::io::vdb::{COLOR_GRID, DISTANCE_GRID, LEVEL_SET_GRID, NORMAL_GRID};

use crate::io::mesh_out::MeshFormat;
use crate::mesh::UpAxis;
use crate::mesh::attributes::{AttributeGrid, AttributeKind};
use crate::pipeline::Outcome;
use crate::pipeline::request::{ToMeshRequest, WriteRequest};
use crate::pipeline::to_mesh::check_mesh_output;
use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{AllowTypeChange, IntoPyArray, PyArray2, PyArrayLike2};
use pyo3::exceptions::{PyKeyError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// A sparse voxel grid with the report of the job that made it.
///
/// `ijk` lists the active voxels (leaves first, then whole tiles); `values(name)` gives a
/// channel in the same order; `index_to_world` maps indices to world positions of voxel
/// centres.
#[pyclass(name = "Grid", module = "voxelkit")]
pub struct Grid {
    outcome: Outcome,
    /// Files the job read: writing refuses to replace them.
    inputs: Vec<PathBuf>,
}

impl Grid {
    pub fn new(outcome: Outcome, inputs: Vec<PathBuf>) -> Grid {
        Grid { outcome, inputs }
    }

    pub fn outcome(&self) -> &Outcome {
        &self.outcome
    }

    fn transform(&self) -> Transform {
        self.outcome.grid.transform
    }

    /// Refuses, with MemoryError, an array of `bytes_per_voxel` per active voxel that does
    /// not fit in the memory available (built once, then copied into numpy: twice over).
    fn check_per_voxel(&self, bytes_per_voxel: u64, what: &str) -> PyResult<()> {
        let voxels = self.outcome.grid.voxel_count();
        let bytes = voxels.saturating_mul(bytes_per_voxel).saturating_mul(2);
        crate::system::check_fits(bytes, None, &format!("{what} of {voxels} voxels"))
            .map_err(super::to_py_err)
    }

    /// The value channel's name, as the file names its grid: `surface` for a level set,
    /// `distance` for unsigned distances and the separating voxelizer's distances.
    fn value_name(&self) -> &'static str {
        let level_set = self
            .outcome
            .distances
            .as_ref()
            .is_some_and(|d| d.interior.is_some());
        if level_set {
            LEVEL_SET_GRID
        } else {
            DISTANCE_GRID
        }
    }

    /// The width of channel `name` (1 or 3), none when the grid has no such channel.
    fn channel_width(&self, name: &str) -> PyResult<usize> {
        if !self.channel_names().contains(&name) {
            return Err(PyKeyError::new_err(format!(
                "no channel `{name}`: this grid has {:?}",
                self.channel_names()
            )));
        }
        let scalar = |a: &AttributeGrid| a.name == name && a.kind == AttributeKind::Scalar;
        let one = name == self.value_name() || self.outcome.attributes.iter().any(scalar);
        Ok(if one { 1 } else { 3 })
    }

    /// Channel `name` of the voxel at leaf `leaf`, offset `n` (width floats).
    fn channel_at<'a>(
        &'a self,
        name: &str,
        leaf: &'a crate::grid::Leaf,
        n: usize,
    ) -> Option<&'a [f32]> {
        if let Some(a) = self.outcome.attributes.iter().find(|a| a.name == name) {
            let at = a.grid.leaf(leaf.origin).filter(|l| l.is_on(n))?;
            return if a.kind == AttributeKind::Scalar {
                at.value.as_ref().map(|v| &v[n..n + 1])
            } else {
                at.color.as_ref().map(|v| &v[n][..])
            };
        }
        if name == self.value_name() {
            leaf.value.as_ref().map(|v| &v[n..n + 1])
        } else if name == NORMAL_GRID {
            leaf.normal.as_ref().map(|v| &v[n][..])
        } else {
            leaf.color.as_ref().map(|v| &v[n][..])
        }
    }

    /// A channel per active voxel, `width` floats each, NaN on whole tiles (which carry
    /// no channels).
    fn channel<'a>(
        &'a self,
        width: usize,
        get: impl Fn(&'a crate::grid::Leaf, usize) -> Option<&'a [f32]>,
    ) -> Vec<f32> {
        let grid = &self.outcome.grid;
        let mut out = Vec::with_capacity(grid.voxel_count() as usize * width);
        for leaf in grid.leaves() {
            for n in leaf.offsets() {
                match get(leaf, n) {
                    Some(v) => out.extend_from_slice(v),
                    None => out.extend(std::iter::repeat_n(f32::NAN, width)),
                }
            }
        }
        let tiled = grid.voxel_count() as usize - out.len() / width;
        out.extend(std::iter::repeat_n(f32::NAN, tiled * width));
        out
    }

    /// The names `values` accepts for this grid: its channels, then the mesh attributes
    /// carried onto its voxels.
    fn channel_names(&self) -> Vec<&str> {
        let c = self.outcome.grid.channels();
        [
            (c.value, self.value_name()),
            (c.normal, NORMAL_GRID),
            (c.color, COLOR_GRID),
        ]
        .into_iter()
        .filter_map(|(on, name)| on.then_some(name))
        .chain(self.outcome.attributes.iter().map(|a| a.name.as_str()))
        .collect()
    }
}

#[pymethods]
impl Grid {
    /// The active voxels as an (N, 3) int64 array of indices.
    #[getter]
    fn ijk<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        self.check_per_voxel(24, "the indices")?;
        let flat: Vec<i64> = self.outcome.grid.voxels().flatten().collect();
        let n = flat.len() / 3;
        Ok(Array2::from_shape_vec((n, 3), flat)
            .expect("three indices per voxel")
            .into_pyarray(py))
    }

    /// A channel in the order of `ijk`, named as the file names its grid: `"surface"` (N,) for
    /// a level set (`sdf`), `"distance"` (N,) for unsigned distances (`udf`, world units) and
    /// the separating voxelizer's `normals=True` (voxels); `"normal"` and `"Cd"` (N, 3); a
    /// mesh attribute (`attributes=`): `"uv"`, `"vertex_normal"` (N, 3), a PLY scalar (N,).
    /// Whole tiles give NaN.
    fn values<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
        let width = self.channel_width(name)?;
        self.check_per_voxel(4 * width as u64, &format!("the values `{name}`"))?;
        let data = self.channel(width, |l, n| self.channel_at(name, l, n));
        if width == 1 {
            Ok(Array1::from_vec(data).into_pyarray(py).into_any())
        } else {
            let n = data.len() / width;
            Ok(Array2::from_shape_vec((n, width), data)
                .expect("width floats per voxel")
                .into_pyarray(py)
                .into_any())
        }
    }

    /// The voxels as a dense array over their box (the bounds' voxels, for a job given
    /// bounds: the same shape whatever the mesh), and the index of its element [0, 0, 0]:
    /// `dense[i - ox, j - oy, k - oz]` is voxel (i, j, k). Without `channel`, booleans (the
    /// voxel set); with one of `values`' names, float32: a level set's `surface` holds minus
    /// its background inside and plus it outside away from the band (as OpenVDB reads the
    /// file), unsigned `distance` the background, other channels NaN (`normal` and `Cd`:
    /// shape (X, Y, Z, 3)). Refused with MemoryError when the array would not fit.
    #[pyo3(signature = (channel = None))]
    fn to_dense<'py>(
        &self,
        py: Python<'py>,
        channel: Option<&str>,
    ) -> PyResult<(Bound<'py, PyAny>, [i64; 3])> {
        let grid = &self.outcome.grid;
        let width = channel.map(|c| self.channel_width(c)).transpose()?;
        let bounds = (self.outcome.report.bounds_voxels)
            .map(|[min, max]| crate::grid::CoordBox { min, max });
        let Some(b) = bounds.or_else(|| grid.bbox()) else {
            let empty = match width {
                None => Array3::from_elem((0, 0, 0), false)
                    .into_pyarray(py)
                    .into_any(),
                Some(_) => Array3::from_elem((0, 0, 0), 0f32)
                    .into_pyarray(py)
                    .into_any(),
            };
            return Ok((empty, [0; 3]));
        };
        let dims = [0, 1, 2].map(|a| (b.max[a] - b.min[a] + 1).max(0) as u64);
        let cells = dims.iter().try_fold(1u64, |acc, &d| acc.checked_mul(d));
        let per_cell = width.map_or(1, |w| 4 * w as u64);
        let bytes = cells.map_or(u64::MAX, |c| c.saturating_mul(per_cell));
        crate::system::check_fits(bytes, None, &format!("a dense array of {dims:?} voxels"))
            .map_err(to_py_err)?;
        let at = |v: crate::grid::Coord| [0, 1, 2].map(|a| (v[a] - b.min[a]) as usize);
        let [x, y, z] = dims.map(|d| d as usize);
        let (Some(name), Some(width)) = (channel, width) else {
            let mut dense = Array3::from_elem((x, y, z), false);
            for v in grid.voxels() {
                dense[at(v)] = true;
            }
            return Ok((dense.into_pyarray(py).into_any(), b.min));
        };
        let mut dense = numpy::ndarray::Array4::from_elem((x, y, z, width), f32::NAN);
        if name == self.value_name()
            && let Some(d) = &self.outcome.distances
        {
            dense.fill(d.background);
            if let Some(interior) = &d.interior {
                for v in interior.voxels() {
                    if (0..3).all(|a| b.min[a] <= v[a] && v[a] <= b.max[a]) {
                        dense[[at(v)[0], at(v)[1], at(v)[2], 0]] = -d.background;
                    }
                }
            }
        }
        for leaf in grid.leaves() {
            for n in leaf.offsets() {
                if let Some(values) = self.channel_at(name, leaf, n) {
                    let [i, j, k] = at(crate::grid::offset_coord(leaf.origin, n));
                    for (c, &value) in values.iter().enumerate() {
                        dense[[i, j, k, c]] = value;
                    }
                }
            }
        }
        let dense = if width == 1 {
            dense
                .into_shape_with_order((x, y, z))
                .expect("one value per voxel")
                .into_pyarray(py)
                .into_any()
        } else {
            dense.into_pyarray(py).into_any()
        };
        Ok((dense, b.min))
    }

    /// The grid's value at each of an (n, 3) array of world points, trilinear between voxel
    /// centres, as OpenVDB's box sampler reads the file: a level set's band values, minus its
    /// background inside and plus it outside the band; unsigned distances with the background
    /// beyond; a voxel set 1 on its voxels and 0 elsewhere.
    fn sample<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, numpy::PyArray1<f64>>> {
        let rows = super::arrays::xyz_rows(points, "points")?;
        let count = rows.as_array().nrows() as u64;
        crate::system::check_fits(count.saturating_mul(32), None, &format!("{count} points"))
            .map_err(to_py_err)?;
        let points = super::arrays::points_of(&rows);
        let grid = &self.outcome.grid;
        let distances = self.outcome.distances.as_ref();
        let value = |c: crate::grid::Coord| -> f64 {
            let n = crate::grid::leaf_offset(c);
            let band = grid
                .leaf(crate::grid::leaf_origin(c))
                .filter(|l| l.is_on(n))
                .and_then(|l| l.value.as_ref().map(|v| f64::from(v[n])));
            match (distances, band) {
                (Some(_), Some(v)) => v,
                (Some(d), None) => {
                    let inside = d.interior.as_ref().is_some_and(|i| i.contains(c));
                    f64::from(if inside { -d.background } else { d.background })
                }
                (None, _) => f64::from(u8::from(grid.contains(c))),
            }
        };
        let transform = self.transform();
        let values: Vec<f64> = py.detach(|| {
            use rayon::prelude::*;
            points
                .par_iter()
                .map(|&p| {
                    if !p.is_finite() {
                        return f64::NAN;
                    }
                    let q = transform.world_to_index(p);
                    let base = q.floor();
                    let t = q - base;
                    let b = [base.x as i64, base.y as i64, base.z as i64];
                    let mut sum = 0.0;
                    for corner in 0..8 {
                        let d = [0, 1, 2].map(|a| (corner >> a) & 1);
                        let weight = [0, 1, 2]
                            .map(|a| if d[a] == 1 { t[a] } else { 1.0 - t[a] })
                            .iter()
                            .product::<f64>();
                        if weight > 0.0 {
                            sum += weight * value([0, 1, 2].map(|a| b[a] + d[a] as i64));
                        }
                    }
                    sum
                })
                .collect()
        });
        Ok(values.into_pyarray(py))
    }

    /// Edge length of a voxel in world units.
    #[getter]
    fn voxel_size(&self) -> f64 {
        self.transform().voxel_size
    }

    /// World position of the centre of voxel (0, 0, 0).
    #[getter]
    fn origin(&self) -> [f64; 3] {
        self.transform().origin.to_array()
    }

    /// World positions of voxel centres for an (N, 3) array of indices (integers, or any
    /// fractional index).
    fn index_to_world<'py>(
        &self,
        py: Python<'py>,
        ijk: PyArrayLike2<'py, f64, AllowTypeChange>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let a = ijk.as_array();
        if a.ncols() != 3 {
            return Err(PyValueError::new_err(format!(
                "expected an (N, 3) array, got shape {:?}",
                a.shape()
            )));
        }
        let t = self.transform();
        let o = t.origin.to_array();
        Ok(
            Array2::from_shape_fn(a.dim(), |(i, c)| o[c] + t.voxel_size * a[[i, c]])
                .into_pyarray(py),
        )
    }

    /// The smallest and largest voxel index, or None when there are no voxels.
    #[getter]
    fn bbox(&self) -> Option<([i64; 3], [i64; 3])> {
        self.outcome.grid.bbox().map(|b| (b.min, b.max))
    }

    /// The job's report (the CLI's `--json`): counts, measures, timings, warnings.
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py.import("json")?
            .call_method1("loads", (self.outcome.report.to_json(),))
    }

    /// The grids beside the main one (a solid's `shell` and `interior`, `unclassified`, ...).
    #[getter]
    fn extras(&self) -> Vec<String> {
        self.outcome.extra.iter().map(|(n, _)| n.clone()).collect()
    }

    /// One of `extras` as a Grid of its own.
    fn extra(&self, name: &str) -> PyResult<Grid> {
        let (_, grid) = self
            .outcome
            .extra
            .iter()
            .find(|(n, _)| n == name)
            .ok_or_else(|| {
                PyKeyError::new_err(format!("no grid `{name}`: there are {:?}", self.extras()))
            })?;
        let outcome = Outcome::from_grid(grid.clone(), &self.outcome);
        Ok(Grid::new(outcome, self.inputs.clone()))
    }

    /// Writes the grid as the CLI does, by extension: `.vdb` (all grids, or those `grids`
    /// names: `density`, `voxels`, `normal`, `Cd`, `shell`, ...), `.nvdb` (the same grids
    /// for NanoVDB), `.binvox` or `.vox`; or its surface as a mesh (`to_mesh`'s): `.obj`,
    /// `.ply`, `.stl` or `.glb`; atomically, never over an input of the job. The keywords are `OPTIONS["write"]`'s:
    /// `grids`, `compression` (blosc, zip or none) and `half`; for a mesh, `adaptivity`.
    #[pyo3(signature = (path, **options))]
    fn write(
        &mut self,
        py: Python<'_>,
        path: PathBuf,
        options: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<()> {
        let inputs: Vec<&std::path::Path> = self.inputs.iter().map(PathBuf::as_path).collect();
        let outcome = &mut self.outcome;
        if MeshFormat::of(&path).is_ok() {
            let request = Keywords::<ToMeshRequest>::new(options)?.request;
            let adaptivity = request.result_adaptivity().map_err(to_py_err)?;
            return py
                .detach(|| {
                    check_mesh_output(&path, &inputs)?;
                    outcome.write_mesh(&path, adaptivity)
                })
                .map_err(to_py_err);
        }
        let options = Keywords::<WriteRequest>::new(options)?.request.options();
        py.detach(|| outcome.write(&path, &inputs, &options))
            .map_err(to_py_err)
    }

    /// The surface as a closed, manifold triangle mesh, counter-clockwise seen from outside:
    /// `(vertices, triangles)`, an (n, 3) float64 array of world positions and an (m, 3)
    /// int64 array of vertex rows. A level set's zero set (sdf), a formula's F < 0 within its
    /// bounds, a solid's or a voxel surface's boundary, half way between its voxels and empty
    /// ones. `adaptivity` (voxels, `OPTIONS["to_mesh"]`'s) merges flat regions, moving the surface
    /// by at most about that much: every vertex stays within half of it of the plane of each
    /// triangle it replaces.
    #[allow(clippy::type_complexity)]
    #[pyo3(signature = (adaptivity = None))]
    fn to_mesh<'py>(
        &self,
        py: Python<'py>,
        adaptivity: Option<f64>,
    ) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<i64>>)> {
        let outcome = &self.outcome;
        let adaptivity = adaptivity.unwrap_or(ToMeshRequest::default().adaptivity);
        let mesh = py
            .detach(|| outcome.surface_mesh(adaptivity))
            .map_err(to_py_err)?;
        let vertices: Vec<f64> = mesh.positions.iter().flat_map(|p| p.to_array()).collect();
        let triangles: Vec<i64> = mesh
            .triangles
            .iter()
            .flat_map(|t| t.map(i64::from))
            .collect();
        let vertices = Array2::from_shape_vec((mesh.positions.len(), 3), vertices)
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        let triangles = Array2::from_shape_vec((mesh.triangles.len(), 3), triangles)
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        Ok((vertices.into_pyarray(py), triangles.into_pyarray(py)))
    }

    /// Draws the voxels into a PNG at `path`, as `voxelkit render` does: each voxel a cube,
    /// lit by the grid's normals when it has them, coloured by its colours; `view` "iso", "x",
    /// "y" or "z" (Z up); `size` (width, height). Written atomically, never over an input.
    #[pyo3(signature = (path, view = "iso", size = (800, 600)))]
    fn render(&self, py: Python<'_>, path: PathBuf, view: &str, size: (u32, u32)) -> PyResult<()> {
        let view = view.parse::<View>().map_err(PyValueError::new_err)?;
        let inputs: Vec<&std::path::Path> = self.inputs.iter().map(PathBuf::as_path).collect();
        let grid = &self.outcome.grid;
        py.detach(|| {
            check_picture_output(&path, &inputs)?;
            let picture = render(&Scene::of(grid), view, UpAxis::Z, size.0, size.1, None)?;
            write_png(&path, &picture)
        })
        .map_err(to_py_err)
    }

    /// `write` for a `.vdb` path.
    #[pyo3(signature = (path, **options))]
    fn write_vdb(
        &mut self,
        py: Python<'_>,
        path: PathBuf,
        options: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<()> {
        self.write(py, path, options)
    }

    /// Whether `other` holds exactly the same voxel indices (compared block by block, never
    /// voxel by voxel where both hold whole tiles).
    fn same_voxels(&self, py: Python<'_>, other: PyRef<'_, Grid>) -> bool {
        let (a, b) = (&self.outcome.grid, &other.outcome.grid);
        py.detach(|| {
            if a.voxel_count() != b.voxel_count() {
                return false;
            }
            let mut rest = a.clone();
            rest.difference(b);
            rest.voxel_count() == 0
        })
    }

    fn __len__(&self) -> usize {
        self.outcome.grid.voxel_count() as usize
    }

    fn __repr__(&self) -> String {
        let r = &self.outcome.report;
        format!(
            "<voxelkit.Grid {} voxels, voxel size {}, {}>",
            self.outcome.grid.voxel_count(),
            self.transform().voxel_size,
            if r.method.is_empty() {
                &r.input
            } else {
                &r.method
            }
        )
    }
}

//! What a job returns: the main grid, the grids written beside it, the `.vdb` metadata and
//! the report; and the surface tasks that make them.

use super::attribute_grids::{Carry, add_attributes};
use super::report::{
    Details, ImplicitDetails, ProjectiveDetails, Report, SeparatingClasses, SeparationCheckDetails,
    SubdivisionDetails, TagSummary,
};
use super::{Shape, ShapeTask, SurfaceMethod, on_threads};
use crate::contour::ExactSurface;
use crate::error::{Error, Result};
use crate::grid::{Adjacency, Channels, CoordBox, Leaf, SparseGrid, Transform};
use crate::implicit::Formula;
use crate::implicit::formula_solid::FormulaSolid;
use crate::io::atomic::check_output;
use crate::io::binvox::write_binvox;
use crate::io::brick_set::{BrickSet, is_brick_set};
use crate::io::grid_export::ExportedGrid;
use crate::io::preview::Scene;
use crate::io::vdb::{
    Contents, MetaValue, NORMAL_GRID, SHELL_GRID, WriteOptions, content_grid_count,
    encode_contents, export_contents, is_nvdb, read_vdb_grid, write_contents_timed,
};
use crate::io::vox::write_vox;
use crate::mesh::attributes::{AttributeChoice, AttributeGrid};
use crate::mesh::{GridFit, Mesh};
use crate::ops::csg::{BooleanOp, combine as combine_grids, same_transform};
use crate::ops::csg_normals::boolean_normals;
use crate::ops::measure::SolidMeasures;
use crate::ops::minimality::simple_voxel_count;
use crate::ops::separability::check_mesh_separation;
use crate::progress::{Progress, StageTime};
use crate::shapes::Cuboid;
use crate::subd::{ControlMesh, LimitSurface};
use crate::voxelize::interval_octree::{OctreeOptions, voxelize_implicit};
use crate::voxelize::parametric::{ParametricOptions, voxelize_subdivision};
use crate::voxelize::projective::{self, Coloring, LineSource};
use crate::voxelize::separating::{Criterion, SeparatingOptions, voxelize_mesh};
use crate::voxelize::separating_analytic::{scan_region, voxelize_surface};
use crate::voxelize::step_certificate::close_unproven_steps;
use glam::DVec3;
use std::borrow::Cow;
use std::path::Path;
use std::time::Instant;

/// The result of a job.
pub struct Outcome {
    /// The voxel set: a surface (with its normal or colour channel) or a whole solid.
    pub grid: SparseGrid,
    /// Bool grids written beside it (`shell`, `interior`, `unclassified`,
    /// `opposite_normals`, `level_0` ..), by name.
    pub extra: Vec<(String, SparseGrid)>,
    /// The input mesh's attributes on the voxels (`uv`, `vertex_normal`, PLY scalars).
    pub attributes: Vec<AttributeGrid>,
    /// The metadata every written grid carries (`method`, `source_file`, ...).
    pub metadata: Vec<(String, MetaValue)>,
    pub report: Report,
    /// Set when `grid` holds distances (world units) to write as a narrow band, instead of a
    /// voxel set.
    pub distances: Option<Distances>,
    /// The threads the job ran on (all when `None`): writing encodes on them too.
    pub threads: Option<usize>,
    /// The source known exactly (a CSG tree of shapes and formulas; the mesh of a level set):
    /// the meshes of the result take their crossings and normals from it.
    pub exact: Option<std::sync::Arc<dyn ExactSurface>>,
}

/// How a distance band is written: its background, and for a level set the interior it
/// bounds (its inactive voxels and tiles there are -background).
pub struct Distances {
    pub background: f32,
    pub interior: Option<SparseGrid>,
}

/// What errors of an export name.
fn exported() -> &'static Path {
    Path::new("the exported grids")
}

/// Output formats by extension; `-` is standard output (as `.vdb`).
const FORMATS: &str = ".vdb (or - for standard output), .nvdb (NanoVDB), .binvox and .vox";

/// The voxel-set formats besides `.vdb`, by extension.
#[derive(Clone, Copy, PartialEq, Eq)]
enum VoxelFile {
    Binvox,
    Vox,
}

fn voxel_file(path: &Path) -> Option<VoxelFile> {
    let ext = path.extension()?.to_str()?.to_ascii_lowercase();
    match ext.as_str() {
        "binvox" => Some(VoxelFile::Binvox),
        "vox" => Some(VoxelFile::Vox),
        _ => None,
    }
}

/// Refuses an output voxelkit cannot write, or one that is an input, before any work.
pub fn check_output_path(path: &Path, inputs: &[&Path]) -> Result<()> {
    if path == Path::new("-") {
        return Ok(());
    }
    check_output(path, inputs)?;
    let vdb = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("vdb"));
    if !vdb && !is_nvdb(path) && voxel_file(path).is_none() {
        return Err(Error::InvalidArgument(format!(
            "{}: voxelkit cannot write this format; it writes {FORMATS}",
            path.display()
        )));
    }
    Ok(())
}

impl Outcome {
    /// Ends the outcome with the process, which must end next: its memory is left to the
    /// kernel, sooner than freeing every leaf one by one (a level set at 1024 holds hundreds of
    /// thousands), and its leaves' arrays are handed back first, on as many threads as the job
    /// ran on.
    ///
    /// # Safety
    /// No other grid's leaf arrays may be used afterwards either (`release_before_exit`).
    pub unsafe fn end_with_process(self) {
        let threads = self.threads;
        std::mem::forget(self);
        let _ = on_threads(threads, || {
            // SAFETY: the caller's promise.
            unsafe { crate::grid::release_before_exit() };
            Ok(())
        });
    }

    pub(super) fn new(
        grid: SparseGrid,
        metadata: Vec<(&str, MetaValue)>,
        details: Details,
    ) -> Outcome {
        let method = metadata
            .iter()
            .find(|(k, _)| *k == "method")
            .map(|(_, v)| v.to_string())
            .unwrap_or_default();
        let report = Report {
            method,
            voxels: grid.voxel_count(),
            leaves: grid.leaf_count() as u64,
            voxel_size: grid.transform.voxel_size,
            origin: grid.transform.origin.to_array(),
            details,
            ..Default::default()
        };
        Outcome {
            grid,
            extra: Vec::new(),
            attributes: Vec::new(),
            metadata: metadata
                .into_iter()
                .map(|(k, v)| (k.to_string(), v))
                .collect(),
            report,
            distances: None,
            threads: None,
            exact: None,
        }
    }

    /// Keeps the voxels inside `keep` in every grid (a fit within bounds); the report counts
    /// what is kept: the voxels, and a solid's or a band's measures.
    pub(super) fn clip(&mut self, keep: CoordBox) -> Result<()> {
        let before = self.grid.voxel_count();
        self.grid.clip(keep);
        self.extra.iter_mut().for_each(|(_, g)| g.clip(keep));
        self.attributes.iter_mut().for_each(|a| a.grid.clip(keep));
        if let Some(interior) = self.distances.as_mut().and_then(|d| d.interior.as_mut()) {
            interior.clip(keep);
        }
        let count = |name: &str| {
            self.extra
                .iter()
                .find(|(n, _)| n == name)
                .map(|(_, g)| g.voxel_count())
        };
        let h = self.grid.transform.voxel_size;
        let cell = h.powi(3);
        match &mut self.report.details {
            Details::Solid(d) => {
                let m = SolidMeasures::of(
                    count("interior").unwrap_or(0),
                    count(SHELL_GRID).unwrap_or(0),
                    h,
                );
                (d.mass_inside, d.mass_with_surface) = m.mass(d.density);
                (d.inside_voxels, d.surface_voxels) = (m.inside_voxels, m.surface_voxels);
                (d.volume_inside, d.volume_with_surface) = (m.volume_inside, m.volume_with_surface);
                d.ambiguous_voxels = d.ambiguous_voxels.map(|_| count("ambiguous").unwrap_or(0));
                if d.components.is_some() {
                    let (components, genus) = crate::solids::flooded_mesh::topology(&self.grid)?;
                    (d.components, d.genus) = (Some(components), Some(genus));
                }
            }
            Details::DepthLayers(d) => {
                d.inside_voxels = self.grid.voxel_count();
                d.unclassified_voxels = count("unclassified").unwrap_or(0);
                d.volume = d.inside_voxels as f64 * cell;
                d.volume_with_unclassified =
                    (d.inside_voxels + d.unclassified_voxels) as f64 * cell;
                d.mass = d.volume * d.density;
            }
            Details::DistanceBand(d) => {
                d.inside_band_voxels = super::solid::inside_band_voxels(&self.grid);
                d.ambiguous_voxels = d.ambiguous_voxels.map(|_| count("ambiguous").unwrap_or(0));
            }
            _ => {}
        }
        self.report.voxels = self.grid.voxel_count();
        self.report.leaves = self.grid.leaf_count() as u64;
        self.report.bounds_voxels = Some([keep.min, keep.max]);
        self.report.voxels_outside_bounds = Some(before - self.report.voxels);
        Ok(())
    }

    /// A grid of a `.vdb` file (its grid `name`, else the voxel set voxelkit writes), as an
    /// outcome that can be examined and written again.
    /// A brick-set index (`.json`, see `io::brick_set`) reads as its bricks merged.
    pub fn read_vdb(path: &Path, name: Option<&str>) -> Result<Outcome> {
        let start = Instant::now();
        let source = path.display().to_string();
        let (grid, method) = if is_brick_set(path) {
            (BrickSet::read(path)?.merge(path)?, "voxelkit bricks")
        } else {
            (read_vdb_grid(path, name)?, "read")
        };
        let metadata = vec![
            ("method", method.into()),
            ("source_file", source.as_str().into()),
        ];
        let mut outcome = Outcome::new(grid, metadata, Details::None);
        outcome.report.input = source;
        outcome.report.finish(start);
        Ok(outcome)
    }

    /// A voxel set made elsewhere (read from a file, built from a caller's leaves) as an
    /// outcome: `source` says where it came from.
    pub fn from_voxels(grid: SparseGrid, source: &str) -> Outcome {
        let mut outcome = Outcome::new(grid, Vec::new(), Details::None);
        outcome.report.input = source.to_string();
        outcome
    }

    /// One of `parent`'s grids as an outcome of its own, with `parent`'s metadata.
    pub fn from_grid(grid: SparseGrid, parent: &Outcome) -> Outcome {
        let mut report = parent.report.clone();
        report.voxels = grid.voxel_count();
        report.leaves = grid.leaf_count() as u64;
        report.output = None;
        Outcome {
            grid,
            extra: Vec::new(),
            attributes: Vec::new(),
            metadata: parent.metadata.clone(),
            report,
            distances: None,
            threads: parent.threads,
            exact: None,
        }
    }

    /// Adds a bool grid written beside the main one.
    pub(super) fn with(mut self, name: &str, grid: SparseGrid) -> Outcome {
        self.extra.push((name.to_string(), grid));
        self
    }

    /// The result as a picture shows it: its voxels, lit by their normals (the grid's own, or
    /// a solid's on its shell) and coloured by their colours.
    pub fn scene(&self) -> Scene<'_> {
        let mut scene = Scene::of(&self.grid);
        if let Some((_, shell_normals)) = self
            .extra
            .iter()
            .find(|(name, g)| name == NORMAL_GRID && g.channels().normal)
        {
            scene.normals = Some(shell_normals);
        }
        scene
    }

    pub(super) fn timed(mut self, start: Instant) -> Outcome {
        self.report.voxelize_seconds = start.elapsed().as_secs_f64();
        self
    }

    /// What the outcome stands for as an operand of a Boolean or a measure: a level set's
    /// inside (its negative band voxels and its interior), any other grid's voxels.
    pub fn solid_voxels(&self) -> SparseGrid {
        let Some(interior) = self.distances.as_ref().and_then(|d| d.interior.as_ref()) else {
            return self.grid.clone();
        };
        let negative = self
            .grid
            .leaves()
            .iter()
            .map(|l| {
                let values = l.value.as_ref().expect("distances");
                let mut leaf = Leaf::new(l.origin, Channels::NONE);
                l.offsets()
                    .filter(|&n| values[n] < 0.0)
                    .for_each(|n| leaf.set_on(n));
                leaf
            })
            .filter(|l| !l.is_empty())
            .collect();
        let mut inside =
            SparseGrid::from_distinct_leaves(self.grid.transform, Channels::NONE, negative);
        inside.union(interior);
        inside
    }

    /// Writes the grids to `path` (`.vdb` or `.nvdb`; `-` for standard output, as `.vdb`) as
    /// `options` say, or the voxel set alone to a `.binvox` or `.vox`, atomically, refusing to
    /// replace any of `inputs`; records the output in the report.
    pub fn write(&mut self, path: &Path, inputs: &[&Path], options: &WriteOptions) -> Result<()> {
        let stages = self.write_timed(path, inputs, options)?;
        self.report.stages.extend(stages);
        self.report.output = Some(path.display().to_string());
        Ok(())
    }

    /// `write` without recording the output: the files alone.
    pub fn write_files(&self, path: &Path, inputs: &[&Path], options: &WriteOptions) -> Result<()> {
        self.write_timed(path, inputs, options).map(|_| ())
    }

    /// The `.vdb` file `write` would write with `options`, in memory; errors name `what`.
    pub fn encode_vdb(&self, what: &Path, options: &WriteOptions) -> Result<Vec<u8>> {
        let meta = self.metadata_entries();
        on_threads(self.threads, || {
            encode_contents(what, &self.contents(), &meta, options)
        })
    }

    /// `write_files`, returning where the time went: encoding, writing and syncing a `.vdb`
    /// or `.nvdb` (a `.binvox` or `.vox`: its writing alone).
    fn write_timed(
        &self,
        path: &Path,
        inputs: &[&Path],
        options: &WriteOptions,
    ) -> Result<Vec<StageTime>> {
        check_output_path(path, inputs)?;
        if let Some(format) = voxel_file(path) {
            if self.distances.is_some() {
                return Err(Error::InvalidArgument(format!(
                    "{}: .binvox and .vox hold voxel sets, not distances; write the level set \
                     as .vdb or .nvdb",
                    path.display()
                )));
            }
            let begun = StageTime::now();
            match format {
                VoxelFile::Binvox => write_binvox(path, &self.grid)?,
                VoxelFile::Vox => write_vox(path, &self.grid)?,
            }
            return Ok(vec![StageTime::since("write", begun)]);
        }
        let meta = self.metadata_entries();
        let write = |file: &Path| write_contents_timed(file, &self.contents(), &meta, options);
        // The writer encodes in parallel: on the job's threads, as the work was.
        let stages = on_threads(self.threads, || {
            if path == Path::new("-") {
                write_to_stdout(write)
            } else {
                write(path)
            }
        })?;
        Ok(stages.into())
    }
}

impl Outcome {
    /// What the outcome writes: its voxel set and the bool grids beside it, or its distances.
    pub fn contents(&self) -> Contents<'_> {
        match &self.distances {
            Some(d) => Contents::Distances {
                grid: &self.grid,
                background: d.background,
                interior: d.interior.as_ref(),
                attributes: &self.attributes,
            },
            None => Contents::Voxels {
                grid: &self.grid,
                masks: self.extra.iter().map(|(n, g)| (n.as_str(), g)).collect(),
                attributes: &self.attributes,
            },
        }
    }

    fn metadata_entries(&self) -> Vec<(&str, MetaValue)> {
        self.metadata
            .iter()
            .map(|(k, v)| (k.as_str(), v.clone()))
            .collect()
    }

    /// The grids `write` puts in a `.vdb` (as `options` choose them; only the one at index
    /// `which` when given), as plain arrays for another library to build its own grids from
    /// (the OpenVDB bridge, voxelkit-openvdb; the C interface's `vk_grid_export_*`).
    pub fn export_grids(
        &self,
        options: &WriteOptions,
        which: Option<usize>,
    ) -> Result<Vec<ExportedGrid>> {
        let meta = self.metadata_entries();
        on_threads(self.threads, || {
            export_contents(exported(), &self.contents(), &meta, options, which)
        })
    }

    /// How many grids `export_grids` gives.
    pub fn export_grid_count(&self, options: &WriteOptions) -> Result<usize> {
        content_grid_count(exported(), &self.contents(), options)
    }
}

/// `.vdb` files are written whole, then renamed into place: `write` a private temporary
/// file, then copy it to stdout.
fn write_to_stdout<T>(write: impl FnOnce(&Path) -> Result<T>) -> Result<T> {
    let dir = std::env::temp_dir().join(format!("voxelkit-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
    let file = dir.join("stdout.vdb");
    let result = write(&file).and_then(|written| {
        let mut bytes = std::fs::File::open(&file).map_err(|e| Error::io(&file, e))?;
        let mut out = std::io::stdout().lock();
        std::io::copy(&mut bytes, &mut out)
            .and_then(|_| std::io::Write::flush(&mut out))
            .map_err(|e| Error::io("standard output", e))
            .map(|_| written)
    });
    let _ = std::fs::remove_dir_all(&dir);
    result
}

/// A control mesh's crease and corner counts in a grid's metadata.
pub(super) fn tag_metadata(meta: &mut Vec<(&'static str, MetaValue)>, tags: &Option<TagSummary>) {
    if let Some(t) = tags {
        meta.push(("creases", t.creases.into()));
        meta.push(("corners", t.corners.into()));
    }
}

/// `method`, `source_file` and the grid's fit, the metadata every output carries.
pub(super) fn provenance(
    method: &str,
    source: &str,
    fit: GridFit,
) -> Vec<(&'static str, MetaValue)> {
    let mut meta = vec![("method", method.into()), ("source_file", source.into())];
    meta.extend(fit_metadata(fit));
    meta
}

/// How the grid was fitted, typed: `resolution` (an int) or `voxel_size` (a double), and
/// `grid_placement` `given` for a grid placed beforehand (shared by several meshes, or a voxel
/// size and origin given), or the bounds it was clipped to.
fn fit_metadata(fit: GridFit) -> Vec<(&'static str, MetaValue)> {
    match fit {
        GridFit::Resolution(r) | GridFit::ResolutionAt(r, _) => vec![("resolution", r.into())],
        GridFit::VoxelSize(h) => vec![("voxel_size", h.into())],
        GridFit::Placed(t) => vec![
            ("voxel_size", t.voxel_size.into()),
            ("grid_placement", "given".into()),
        ],
        GridFit::Within(t, b) => vec![
            ("voxel_size", t.voxel_size.into()),
            (
                "grid_placement",
                format!("within bounds {},{}", b.min, b.max).into(),
            ),
        ],
    }
}

fn describe(coloring: Coloring) -> String {
    match coloring {
        Coloring::None => "none".into(),
        Coloring::Vertex => "vertex colours interpolated".into(),
        Coloring::Constant(c) => format!("constant {},{},{}", c.x, c.y, c.z),
    }
}

/// A projective surface or line set, with its colouring in the metadata and the report.
fn projective_outcome(
    grid: SparseGrid,
    mut meta: Vec<(&str, MetaValue)>,
    s: &projective::ProjectiveStats,
    coloring: Coloring,
) -> Outcome {
    meta.push(("color", describe(coloring).into()));
    let details = ProjectiveDetails {
        triangles: s.triangles,
        degenerate_triangles: s.degenerate_triangles,
        segments: s.segments,
        color: describe(coloring),
    };
    Outcome::new(grid, meta, Details::Projective(details))
}

/// `mesh`'s surface by `method`, with the attributes `chosen` on its voxels.
pub(super) fn mesh_surface(
    mesh: &Mesh,
    t: Transform,
    method: SurfaceMethod,
    chosen: &AttributeChoice,
    fit: GridFit,
    progress: &Progress,
) -> Result<Outcome> {
    let start = Instant::now();
    let mut outcome = bare_mesh_surface(mesh, t, method, fit, progress)?;
    add_attributes(&mut outcome, mesh, chosen, Carry::of(&method), progress)?;
    Ok(outcome.timed(start))
}

fn bare_mesh_surface(
    mesh: &Mesh,
    t: Transform,
    method: SurfaceMethod,
    fit: GridFit,
    progress: &Progress,
) -> Result<Outcome> {
    let source = mesh.source.display().to_string();
    match method {
        SurfaceMethod::Separating(options) => {
            let (grid, s) = voxelize_mesh(mesh, t, &options, progress)?;
            let method = match options.criterion {
                Criterion::Huang => "huang-separating",
                Criterion::Clipped => "huang-separating-clipped",
            };
            let sep = options.separability.adjacency();
            let mut meta = provenance(method, &source, fit);
            meta.insert(1, ("separability", sep.into()));
            let classes = SeparatingClasses {
                vertex_voxels: s.vertex_voxels,
                edge_voxels: s.edge_voxels,
                body_voxels: s.body_voxels,
                triangles: s.triangles as u64,
                edges: s.edges as u64,
                vertices: s.vertices as u64,
                degenerate_faces: s.degenerate_faces as u64,
            };
            let mut out = Outcome::new(
                grid,
                meta,
                Details::Separating {
                    separability: sep,
                    classes,
                },
            );
            if s.degenerate_faces > 0 {
                out.report.warnings.push(format!(
                    "{source}: {} degenerate faces (zero area or repeated vertex) voxelized by their edges only",
                    s.degenerate_faces
                ));
            }
            Ok(out)
        }
        SurfaceMethod::Projective(color) => {
            let coloring = color.coloring(mesh);
            let (grid, s) = projective::voxelize_triangles(mesh, t, coloring, progress)?;
            let meta = provenance("projective-triangles", &source, fit);
            Ok(projective_outcome(grid, meta, &s, coloring))
        }
    }
}

/// Why a separation check refuses an open surface.
const CHECK_NEEDS_CLOSED: &str = "a separation check needs a closed surface: it tells inside \
     from outside by ray parity";

pub(super) fn separation_check(
    mesh: &Mesh,
    t: Transform,
    options: SeparatingOptions,
    fit: GridFit,
    progress: &Progress,
) -> Result<Outcome> {
    mesh.require_closed(CHECK_NEEDS_CLOSED)?;
    let method = SurfaceMethod::Separating(options);
    let none = AttributeChoice::None;
    let mut outcome = mesh_surface(mesh, t, method, &none, fit, progress)?;
    let adjacency = options.separability.flood_adjacency();
    check_against(&mut outcome, mesh, adjacency, fit)?;
    Ok(outcome)
}

/// Floods `outcome`'s surface against the closed `mesh` (`adjacency`-connected) and counts its
/// simple voxels, into the report.
fn check_against(
    outcome: &mut Outcome,
    mesh: &Mesh,
    adjacency: Adjacency,
    fit: GridFit,
) -> Result<()> {
    let found = check_mesh_separation(&outcome.grid, mesh, adjacency)?;
    let simple = simple_voxel_count(&outcome.grid, adjacency)?;
    outcome.report.details = Details::SeparationCheck(SeparationCheckDetails {
        separability: adjacency.number(),
        inside_centres: found.inside_centres,
        exterior_voxels: found.exterior,
        leaked: found.leaked,
        first_leak: found.first_leak,
        simple_voxels: simple,
        simple_share: simple as f64 / outcome.grid.voxel_count().max(1) as f64,
        resolution: fit.describe(),
    });
    Ok(())
}

pub(super) fn lines(
    mesh: &Mesh,
    t: Transform,
    source: LineSource,
    coloring: Coloring,
    fit: GridFit,
    progress: &Progress,
) -> Result<Outcome> {
    let start = Instant::now();
    let (grid, s) = projective::voxelize_lines(mesh, t, source, coloring, progress)?;
    let method = if source.edges && !mesh.polylines.is_empty() {
        "projective-lines+edges"
    } else if source.edges {
        "projective-edges"
    } else {
        "projective-lines"
    };
    let meta = provenance(method, &mesh.source.display().to_string(), fit);
    Ok(projective_outcome(grid, meta, &s, coloring).timed(start))
}

pub(super) fn shape(
    task: &ShapeTask,
    t: Transform,
    fit: GridFit,
    progress: &Progress,
) -> Result<Outcome> {
    let &ShapeTask {
        ref shape,
        separability,
        normals,
        curvature_margin,
    } = task;
    let start = Instant::now();
    let mut grid = voxelize_surface(
        shape.surface(),
        t,
        separability,
        normals,
        curvature_margin,
        progress,
    )?;
    let certificate_voxels = match shape {
        Shape::Formula(f) => {
            let region = scan_region(f, &t);
            Some(close_unproven_steps(
                f,
                &mut grid,
                region,
                separability,
                progress,
            )?)
        }
        _ => None,
    };
    let name = shape.describe();
    let sep = separability.adjacency();
    let method = if curvature_margin {
        "huang-separating-analytic"
    } else {
        "huang-separating-analytic-plain"
    };
    let mut meta = provenance(method, &name, fit);
    meta.insert(1, ("separability", sep.into()));
    if let Some(added) = certificate_voxels {
        meta.push(("certificate_voxels", added.into()));
    }
    let details = Details::Shape {
        shape: name,
        separability: sep,
        curvature_margin,
        certificate_voxels,
    };
    Ok(Outcome::new(grid, meta, details).timed(start))
}

pub(super) fn subdivision(
    control: &ControlMesh,
    t: Transform,
    options: &ParametricOptions,
    fit: GridFit,
    progress: &Progress,
) -> Result<Outcome> {
    let start = Instant::now();
    let out = voxelize_subdivision(control, t, options, progress)?;
    let s = out.stats;
    let method = if options.enclose {
        "lai-cheng-parametric-enclosed"
    } else {
        "lai-cheng-parametric"
    };
    let adjacency = options.adjacency.number();
    let mut meta = provenance(method, &control.source.display().to_string(), fit);
    meta.insert(1, ("adjacency", adjacency.into()));
    meta.push(("presplit", options.presplit.into()));
    meta.push(("surface_area", s.area.into()));
    let tags = TagSummary::of(&control.tags);
    tag_metadata(&mut meta, &tags);
    let details = SubdivisionDetails {
        adjacency,
        opposite_normal_voxels: s.opposite_voxels,
        patches: s.patches,
        evaluations: s.evaluations,
        uniform_evaluations: s.uniform_evaluations,
        subpatches: s.subpatches,
        depth_guard_stops: s.depth_guard_stops,
        enclose_splits: s.enclose_splits,
        tolerance_voxels: s.guard_voxels,
        area: s.area,
        tags,
    };
    Ok(
        Outcome::new(out.surface, meta, Details::Subdivision(details))
            .with("opposite_normals", out.opposite)
            .timed(start),
    )
}

/// The limit surface's voxels, checked as `separation_check` checks a mesh's: the exterior
/// flood against a tessellation far finer than a voxel (inside by its ray parity), 6-connected
/// for the paper's surface (what §5 proves), 26-connected for the enclosed one.
pub(super) fn subdivision_check(
    control: &ControlMesh,
    t: Transform,
    options: &ParametricOptions,
    fit: GridFit,
    progress: &Progress,
) -> Result<Outcome> {
    control.polygon_mesh().require_closed(CHECK_NEEDS_CLOSED)?;
    let mut outcome = subdivision(control, t, options, fit, progress)?;
    let segments = check_segments(control, &t);
    let polygons = LimitSurface::new(control.clone()).tessellate(|_| segments);
    let adjacency = if options.enclose {
        Adjacency::TwentySix
    } else {
        Adjacency::Six
    };
    check_against(&mut outcome, &polygons, adjacency, fit)?;
    Ok(outcome)
}

/// Tessellation segments per voxel of a patch's side (a patch spans extent / sqrt(patches)
/// voxels), and the most per patch side: the polygons stay far finer than a voxel.
const TESSELLATION_PER_VOXEL: f64 = 4.0;
const MOST_TESSELLATION_SEGMENTS: f64 = 32.0;

/// The segments per patch side of the tessellation `subdivision_check` floods against.
pub(super) fn check_segments(control: &ControlMesh, t: &Transform) -> usize {
    let extent = (control.bbox().max - control.bbox().min).max_element() / t.voxel_size;
    (TESSELLATION_PER_VOXEL * extent / (control.patch_count() as f64).sqrt())
        .ceil()
        .clamp(2.0, MOST_TESSELLATION_SEGMENTS) as usize
}

pub(super) fn implicit(
    formula: &Formula,
    text: &str,
    min: DVec3,
    max: DVec3,
    options: &OctreeOptions,
    progress: &Progress,
) -> Result<Outcome> {
    let start = Instant::now();
    let out = voxelize_implicit(formula, min, max, options, progress)?;
    let s = out.stats;
    let coordinates = format!("{:?}", formula.coordinates).to_lowercase();
    let meta = vec![
        ("method", "stolte-kaufman-interval-octree".into()),
        ("formula", text.into()),
        ("coordinates", coordinates.as_str().into()),
        ("resolution", options.resolution.into()),
    ];
    let details = ImplicitDetails {
        formula: text.to_string(),
        coordinates,
        cells_tested: s.cells_tested,
        axis_cells: s.axis_cells,
        levels: out.levels.len() as u64,
        depth: s.depth,
    };
    let mut outcome = Outcome::new(out.surface, meta, Details::Implicit(details));
    let bounds = Cuboid { min, max };
    if let Some(solid) = FormulaSolid::new(formula, bounds, options.both_signs) {
        outcome.exact = Some(std::sync::Arc::new(solid));
    }
    for (l, level) in out.levels.into_iter().enumerate() {
        outcome = outcome.with(&format!("level_{l}"), level);
    }
    Ok(outcome.timed(start))
}

pub(super) fn combine(
    operands: &[SparseGrid],
    normals: &[Option<SparseGrid>],
    op: BooleanOp,
    resample: bool,
    curve: bool,
    source: &str,
) -> Result<Outcome> {
    let start = Instant::now();
    let named = |e| match e {
        Error::InvalidArgument(m) => Error::InvalidArgument(format!("{source}: {m}")),
        other => other,
    };
    let (first, later) = operands
        .split_first()
        .ok_or_else(|| Error::InvalidArgument("a Boolean needs grids".into()))?;
    // Normals follow the Boolean on one grid (resampled operands leave theirs behind).
    let on_one_grid = later
        .iter()
        .all(|b| same_transform(&first.transform, &b.transform));
    let mut grid = first.clone();
    let mut carried = normals
        .first()
        .and_then(Option::as_ref)
        .filter(|_| on_one_grid)
        .map(Cow::Borrowed);
    for (b, b_normals) in later.iter().zip(normals.iter().skip(1)) {
        grid = combine_grids(&grid, b, op, resample).map_err(named)?;
        if on_one_grid {
            carried =
                boolean_normals(&grid, carried.as_deref(), b_normals.as_ref(), op).map(Cow::Owned);
        }
    }
    let method = if curve {
        "intersection-curve".to_string()
    } else {
        format!("{op:?}").to_lowercase()
    };
    let meta = vec![("method", method.into()), ("source_file", source.into())];
    let outcome = Outcome::new(grid, meta, Details::None);
    Ok(match carried {
        Some(normals) if !normals.is_empty() => outcome.with(NORMAL_GRID, normals.into_owned()),
        _ => outcome,
    }
    .timed(start))
}

//! The one way to run any method, behind every front end (the CLI, the C API, the Python
//! module): a `Job` says what to make from what; `Job::plan` reads the inputs, places the
//! grid and estimates memory and work, refusing what does not fit before anything big is
//! allocated; `PlannedJob::run` does the work under an `Observer` (progress, cancellation)
//! and returns an `Outcome`: the grids, their `.vdb` metadata and the report.

mod attribute_grids;
pub mod batch;
pub mod brick_exterior;
pub mod brick_merge;
pub mod bricks;
mod estimate;
mod load;
mod outcome;
mod report;
pub mod request;
mod solid;
pub mod to_mesh;

pub use crate::solids::flooded_mesh::FLOOD_NEEDS_CLOSED;
pub use estimate::{BASE_BYTES, merged_bytes};
pub use outcome::{Outcome, check_output_path};
pub use report::*;

use crate::error::{Error, Result};
use crate::grid::{SparseGrid, Transform};
use crate::implicit::{Coordinates, ThetaRange};
use crate::mesh::attributes::AttributeChoice;
use crate::mesh::{GridFit, Mesh, UpAxis};
use crate::ops::csg::BooleanOp;
use crate::progress::{Observer, Progress, StageTime};
use crate::shapes::{Cylinder, Quadric, Sphere};
use crate::solids::beam::BeamFill;
use crate::solids::depth_layers::DepthLayerOptions;
use crate::solids::exterior_flood::FloodMethod;
use crate::solids::inside_rule::InsideRule;
use crate::voxelize::Separability;
use crate::voxelize::parametric::ParametricOptions;
use crate::voxelize::projective::{Coloring, LineSource};
use crate::voxelize::separating::SeparatingOptions;
use crate::voxelize::separating_analytic::AnalyticSurface;
use crate::voxelize::separating_formula::FormulaSurface;
use glam::{DVec3, Vec3};
use load::Work;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Most worker threads a job starts; more are clamped with a warning.
pub const MAX_THREADS: usize = 256;

/// A mesh given as a file or already in memory (arrays from C or Python).
#[derive(Clone, Debug)]
pub enum MeshSource {
    File(PathBuf),
    Mesh(Mesh),
}

/// Where the voxels' colours come from (projective methods).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum ColorChoice {
    /// The mesh's vertex colours when it has them.
    #[default]
    FromMesh,
    /// One colour for everything.
    Constant(Vec3),
    /// No `Cd` grid.
    None,
}

/// How a polygon mesh becomes a surface.
#[derive(Clone, Copy, Debug)]
pub enum SurfaceMethod {
    /// Huang et al.'s 6/26-separating surface.
    Separating(SeparatingOptions),
    /// Jegathese et al.'s scan-lines in each triangle's dominant plane.
    Projective(ColorChoice),
}

/// An analytic surface of Huang et al. §7.
#[derive(Clone, Debug)]
pub enum Shape {
    Sphere(Sphere),
    Cylinder(Cylinder),
    Quadric(Quadric),
    /// F = 0 of a formula, its nearest points found numerically.
    Formula(FormulaSurface),
}

/// How a mesh's solid is found.
#[derive(Clone, Copy, Debug)]
pub enum Fill {
    /// The 26-separating surface plus what the exterior flood cannot reach.
    Flood(FloodMethod),
    /// Passalis et al.'s depth layers with a stencil count.
    DepthLayers(DepthLayerOptions),
    /// The projective surface plus beams between front and back faces along z.
    Beam(BeamFill),
}

/// What `measure` measures: a mesh (its flooded 26-separating surface), a `.vdb` surface (a
/// solid's `shell`, else its voxel set) or a surface in memory.
#[derive(Clone, Debug)]
pub enum MeasureSource {
    Mesh(MeshSource),
    Vdb(PathBuf),
    Grid(SparseGrid),
}

/// A CSG tree: a JSON file, or JSON text whose file names are found in `folder`.
#[derive(Clone, Debug)]
pub enum CsgSource {
    File(PathBuf),
    Json { text: String, folder: PathBuf },
}

/// A voxel grid: a grid of a `.vdb` file (named by the task), or one in memory.
#[derive(Clone, Debug)]
pub enum GridSource {
    File(PathBuf),
    Grid(SparseGrid),
}

/// What to make.
#[derive(Clone, Debug)]
pub enum Task {
    MeshSurface {
        mesh: MeshSource,
        method: SurfaceMethod,
        /// The mesh's vertex attributes written beside the voxels.
        attributes: AttributeChoice,
    },
    /// The separating surface of a closed mesh, checked: the inside centres an exterior flood
    /// reaches through it (none when it separates) and its simple (removable) voxels.
    SeparationCheck {
        mesh: MeshSource,
        options: SeparatingOptions,
    },
    /// Polylines (OBJ `l`) and, with `edges` or when there are none, the faces' edges.
    Lines {
        mesh: MeshSource,
        edges: bool,
        color: ColorChoice,
    },
    Shape(ShapeTask),
    /// A Catmull-Clark limit surface from its control mesh, the solid it bounds (seeds from
    /// the limit normals, FloodingXYZ from them) or the surface's separation checked.
    Subdivision {
        mesh: MeshSource,
        options: ParametricOptions,
        output: SubdivisionOutput,
    },
    /// F = 0 inside `[min, max]`, by interval octree.
    Implicit {
        formula: String,
        coordinates: Coordinates,
        min: DVec3,
        max: DVec3,
        levels: bool,
        negative_r: bool,
        /// Where θ lies: the paper's [0, 2π) by default.
        theta_range: ThetaRange,
        /// The paper's substitution [G]² - r² = 0 for F = G - r (r = |G|).
        squared: bool,
        /// The solid F < 0 by depth layers instead of the surface.
        depth_layers: bool,
    },
    Solid {
        mesh: MeshSource,
        fill: Fill,
        density: f64,
        /// Also count components and genus (a pass over the whole solid; `Measure` always
        /// does).
        topology: bool,
        /// How a flood solid's inside is decided.
        inside: InsideRule,
    },
    Measure {
        source: MeasureSource,
        flood: FloodMethod,
        density: f64,
        /// How a mesh's inside is decided.
        inside: InsideRule,
    },
    /// Exact distances to a mesh on every voxel within `band` voxels: signed (a level set,
    /// signed by `inside`) or unsigned.
    DistanceBand {
        mesh: MeshSource,
        band: f64,
        signed: bool,
        inside: InsideRule,
        /// The mesh's vertex attributes written on the band's voxels.
        attributes: AttributeChoice,
    },
    /// A CSG tree in JSON (see `ops::csg_tree`); the tree sets the grid.
    CsgTree(CsgSource),
    /// One brick of a distributed run, on the run's grid (`GridFit::Placed`).
    Brick(BrickTask),
    /// A Boolean of two or more grids, folded from the left (from files: their grid `grid`,
    /// or the voxel set voxelkit writes); `curve`: the intersection of surfaces.
    Combine {
        operands: Vec<GridSource>,
        grid: Option<String>,
        op: BooleanOp,
        resample: bool,
        curve: bool,
    },
}

/// An analytic surface and how it is voxelized.
#[derive(Clone, Debug)]
pub struct ShapeTask {
    pub shape: Shape,
    pub separability: Separability,
    pub normals: bool,
    /// Widen the slabs by the curvature margin (false: the paper's plain rule).
    pub curvature_margin: bool,
}

/// One brick of a distributed run (see `bricks`): the faces it received and what to make of
/// them.
#[derive(Clone, Debug)]
pub struct BrickTask {
    pub faces: Mesh,
    pub brick: bricks::BrickIndex,
    /// Voxels along the brick's edge.
    pub size: i64,
    pub stage: BrickStage,
}

/// What a brick's job makes.
#[derive(Clone, Debug)]
pub enum BrickStage {
    /// Its part of the separating surface.
    Surface(Separability),
    /// Its 26-separating surface, with the labels of its outside components on its six faces
    /// in the report (`Details::BrickFaces`) for the client to join.
    FaceLabels,
    /// Its part of the solid: the surface and the components not in `exterior` (labels of
    /// the face-label stage).
    Solid { exterior: Vec<u32> },
    /// Its part of a solid whose inside is the winding number of `mesh`, the whole mesh (the
    /// brick's own faces give its surface).
    Winding { mesh: Mesh },
}

/// What a Catmull-Clark run makes of its limit surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SubdivisionOutput {
    /// The surface's voxels.
    Surface,
    /// The solid the closed surface bounds.
    Solid(SubdivisionFill),
    /// The surface's voxels, checked by flooding against a tessellation far finer than a
    /// voxel (6-paths for the paper's surface, 26-paths for the enclosed one) with the share
    /// of simple voxels, as `check` does for meshes.
    SeparationCheck,
}

/// How a Catmull-Clark solid is filled and weighed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SubdivisionFill {
    /// By depth layers on a certified tessellation instead of seeds and FloodingXYZ.
    pub depth_layers: bool,
    /// GRAYSTACK capacity for FloodingXYZ (entries).
    pub graystack: usize,
    /// Mass per unit volume.
    pub density: f64,
    /// Also count components and genus.
    pub topology: bool,
}

/// Limits the work must respect.
#[derive(Clone, Copy, Debug, Default)]
pub struct Limits {
    /// Worker threads (default: all cores; at most `MAX_THREADS`).
    pub threads: Option<usize>,
    /// Refuse work estimated above this many bytes (default: the memory available).
    pub max_memory: Option<u64>,
}

/// One job: a task, how the grid is fitted and the limits.
#[derive(Clone, Debug)]
pub struct Job {
    pub task: Task,
    pub fit: GridFit,
    pub limits: Limits,
    /// Which axis of the mesh files points up (files only; meshes in memory are kept).
    pub up_axis: UpAxis,
}

/// What planning found: where the grid lies and what the work will cost.
#[derive(Clone, Copy, Debug)]
pub struct Plan {
    pub transform: Transform,
    /// Voxels along x, y and z of the region the work covers.
    pub extent: [f64; 3],
    pub estimated_bytes: u64,
    /// Work items the observer will hear about (an estimate for some methods).
    pub work_items: u64,
}

impl Plan {
    /// The region in voxels, `1024x1013x789`, in scientific notation when huge.
    pub fn describe_extent(&self) -> String {
        let v: Vec<String> = self
            .extent
            .iter()
            .map(|&e| {
                if e < 1e9 {
                    format!("{e:.0}")
                } else {
                    format!("{e:.3e}")
                }
            })
            .collect();
        v.join("x")
    }
}

/// A job whose inputs are read and whose plan fits.
pub struct PlannedJob {
    job: Job,
    work: Work,
    plan: Plan,
    warnings: Vec<String>,
    start: Instant,
    /// Reading the inputs, then planning, timed.
    planning: [StageTime; 2],
}

impl GridFit {
    /// The fit in words, for reports: `256`, or `voxel size 0.1`.
    pub fn describe(&self) -> String {
        match self {
            GridFit::Resolution(r) => r.to_string(),
            GridFit::ResolutionAt(r, o) => format!("{r}, origin {:?},{:?},{:?}", o.x, o.y, o.z),
            GridFit::VoxelSize(h) => format!("voxel size {h:?}"),
            GridFit::Placed(t) => format!(
                "voxel size {:?}, origin {:?},{:?},{:?} (placed beforehand)",
                t.voxel_size, t.origin.x, t.origin.y, t.origin.z
            ),
            GridFit::Within(t, b) => format!(
                "voxel size {:?} within bounds {},{}",
                t.voxel_size, b.min, b.max
            ),
        }
    }
}

impl MeshSource {
    /// The mesh (polygons, or with `lines` also polylines), turned `up` when read from a file.
    pub fn load(&self, lines: bool, up: UpAxis) -> Result<Mesh> {
        match self {
            MeshSource::File(path) if lines => Ok(Mesh::load_lines(path)?.with_up_axis(up)),
            MeshSource::File(path) => Ok(Mesh::load(path)?.with_up_axis(up)),
            MeshSource::Mesh(mesh) => {
                if !lines {
                    mesh.validate()?;
                }
                Ok(mesh.clone())
            }
        }
    }

    /// The file, when it is one.
    fn path(&self) -> Option<&Path> {
        match self {
            MeshSource::File(p) => Some(p),
            MeshSource::Mesh(_) => None,
        }
    }
}

impl ColorChoice {
    fn coloring(self, mesh: &Mesh) -> Coloring {
        match self {
            ColorChoice::FromMesh => Coloring::of(mesh),
            ColorChoice::Constant(c) => Coloring::Constant(c),
            ColorChoice::None => Coloring::None,
        }
    }
}

impl Shape {
    pub fn surface(&self) -> &dyn AnalyticSurface {
        match self {
            Shape::Sphere(s) => s,
            Shape::Cylinder(c) => c,
            Shape::Quadric(q) => q,
            Shape::Formula(f) => f,
        }
    }

    /// The shape's area in world units (for planning).
    pub fn area(&self) -> f64 {
        match self {
            Shape::Sphere(s) => s.area(),
            Shape::Cylinder(c) => c.area(),
            Shape::Quadric(q) => q.area(),
            // Planned from the formula's octree instead (`estimate`).
            Shape::Formula(_) => 0.0,
        }
    }

    /// The shape in words, for the report and the `source_file` metadata.
    pub fn describe(&self) -> String {
        match self {
            Shape::Sphere(s) => format!("sphere r={} c={}", s.radius, s.center),
            Shape::Cylinder(c) => format!(
                "cylinder r={} h={} c={} axis={}",
                c.radius, c.height, c.center, c.axis
            ),
            Shape::Quadric(q) => format!(
                "x^2 + {k} y + {k} z = 0 in [-{e},{e}]^3",
                k = q.k,
                e = q.half_extent
            ),
            Shape::Formula(f) => format!("{} = 0", f.formula().text),
        }
    }
}

impl Task {
    /// The mesh a mesh-based task reads.
    fn mesh(&self) -> Option<&MeshSource> {
        match self {
            Task::MeshSurface { mesh, .. }
            | Task::SeparationCheck { mesh, .. }
            | Task::DistanceBand { mesh, .. }
            | Task::Lines { mesh, .. }
            | Task::Subdivision { mesh, .. }
            | Task::Solid { mesh, .. }
            | Task::Measure {
                source: MeasureSource::Mesh(mesh),
                ..
            } => Some(mesh),
            _ => None,
        }
    }

    /// The files the task reads (an output must not be one of them).
    pub fn input_files(&self) -> Vec<PathBuf> {
        if let Some(mesh) = self.mesh() {
            return mesh.path().map(Path::to_path_buf).into_iter().collect();
        }
        match self {
            Task::Measure {
                source: MeasureSource::Vdb(p),
                ..
            }
            | Task::CsgTree(CsgSource::File(p)) => vec![p.clone()],
            Task::Combine { operands, .. } => operands
                .iter()
                .filter_map(|g| match g {
                    GridSource::File(p) => Some(p.clone()),
                    GridSource::Grid(_) => None,
                })
                .collect(),
            _ => vec![],
        }
    }
}

impl Job {
    pub fn new(task: Task, fit: GridFit) -> Job {
        Job {
            task,
            fit,
            limits: Limits::default(),
            up_axis: UpAxis::default(),
        }
    }

    /// Reads the inputs, places the grid, estimates memory and work; refuses work that does
    /// not fit in `limits.max_memory` (or the memory available) with the estimate.
    pub fn plan(self) -> Result<PlannedJob> {
        let begun = StageTime::now();
        let start = begun.0;
        let mut warnings = Vec::new();
        if let Some(n) = self.limits.threads {
            if n == 0 {
                return Err(Error::InvalidArgument(
                    "the thread count must be at least 1".into(),
                ));
            }
            if n > MAX_THREADS {
                warnings.push(format!("{n} threads asked for; using {MAX_THREADS}"));
            }
        }
        let work = load::load(&self.task, self.up_axis)?;
        warnings.extend(work.unwritten_attributes());
        let reading = StageTime::since("read", begun);
        let planning_begun = StageTime::now();
        let mut plan = estimate::price(&work, self.fit, &self.describe_input())?;
        let threads = worker_count(self.limits.threads).unwrap_or_else(rayon::current_num_threads);
        plan.estimated_bytes = plan
            .estimated_bytes
            .saturating_add(threads as u64 * estimate::thread_bytes(&work));
        let limit = self.limits.max_memory;
        crate::system::check_fits(
            plan.estimated_bytes,
            limit,
            &format!(
                "{} at {} voxels; {}",
                self.describe_input(),
                plan.describe_extent(),
                match self.task {
                    Task::Brick(_) => "use smaller bricks or raise the memory limit",
                    _ => "lower the resolution or raise the memory limit",
                }
            ),
        )?;
        Ok(PlannedJob {
            job: self,
            work,
            plan,
            warnings,
            start,
            planning: [reading, StageTime::since("plan", planning_begun)],
        })
    }

    /// Plans and runs.
    pub fn run(self, observer: &dyn Observer) -> Result<Outcome> {
        self.plan()?.run(observer)
    }

    /// The input in words: the file, or what the task makes.
    fn describe_input(&self) -> String {
        const IN_MEMORY: &str = "a grid in memory";
        let grid = |g: &GridSource| match g {
            GridSource::File(p) => p.display().to_string(),
            GridSource::Grid(_) => IN_MEMORY.to_string(),
        };
        match (&self.task, self.task.mesh()) {
            (_, Some(MeshSource::File(p))) => p.display().to_string(),
            (_, Some(MeshSource::Mesh(m))) => m.source.display().to_string(),
            (Task::Shape(s), _) => s.shape.describe(),
            (Task::Implicit { formula, .. }, _) => formula.clone(),
            (Task::Brick(b), _) => format!(
                "the brick of {}^3 voxels at {:?} with {} faces",
                b.size,
                crate::io::brick_set::brick_voxels(b.brick, b.size).min,
                b.faces.face_count()
            ),
            (Task::Combine { operands, .. }, _) => {
                operands.iter().map(grid).collect::<Vec<_>>().join(" ")
            }
            (
                Task::Measure {
                    source: MeasureSource::Grid(_),
                    ..
                },
                _,
            ) => IN_MEMORY.to_string(),
            (other, _) => other
                .input_files()
                .first()
                .map(|p| p.display().to_string())
                .unwrap_or_default(),
        }
    }
}

/// The workers a job asking for `threads` runs on: 1 to `MAX_THREADS`, or the global pool's
/// (all cores) when it asks for none.
fn worker_count(threads: Option<usize>) -> Option<usize> {
    threads.map(|n| n.clamp(1, MAX_THREADS))
}

/// Runs `work` on a pool of `threads` workers (1 to `MAX_THREADS`), or without one on the
/// global pool (all cores).
pub fn on_threads<T: Send>(
    threads: Option<usize>,
    work: impl FnOnce() -> Result<T> + Send,
) -> Result<T> {
    match worker_count(threads) {
        None => work(),
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map_err(|e| Error::InvalidArgument(format!("cannot start {n} threads: {e}")))?
            .install(work),
    }
}

impl PlannedJob {
    pub fn plan(&self) -> &Plan {
        &self.plan
    }

    pub fn job(&self) -> &Job {
        &self.job
    }

    /// Every file the job reads, those a CSG tree names included.
    pub fn input_files(&self) -> Vec<PathBuf> {
        match &self.work {
            Work::CsgTree(tree) => tree.input_files(),
            _ => self.job.task.input_files(),
        }
    }

    /// Does the work on the job's threads; the observer's `Break` ends it with
    /// `Error::Cancelled`.
    pub fn run(self, observer: &dyn Observer) -> Result<Outcome> {
        let progress = Progress::new(observer);
        progress.stage(self.stage_name(), self.plan.work_items);
        let mut outcome = on_threads(self.job.limits.threads, || self.run_here(&progress))?;
        progress.check()?;
        if let Some(keep) = self.job.fit.kept_voxels() {
            on_threads(self.job.limits.threads, || outcome.clip(keep))?;
        }
        outcome.report.stages = self
            .planning
            .into_iter()
            .chain(progress.profile())
            .collect();
        outcome.threads = self.job.limits.threads;
        outcome.report.warnings.splice(0..0, self.warnings);
        outcome.report.input = self.job.describe_input();
        outcome.report.estimated_mib = self.plan.estimated_bytes as f64 / (1 << 20) as f64;
        outcome.report.finish(self.start);
        Ok(outcome)
    }

    fn stage_name(&self) -> &'static str {
        match &self.job.task {
            Task::MeshSurface { .. }
            | Task::SeparationCheck { .. }
            | Task::Shape(_)
            | Task::Subdivision { .. } => "voxelizing",
            Task::Lines { .. } => "lines",
            Task::DistanceBand { .. } => "distances",
            Task::Implicit { .. } => "octree",
            Task::Solid { .. } | Task::Measure { .. } => "surface",
            Task::CsgTree(_) | Task::Combine { .. } => "combining",
            Task::Brick(_) => "brick",
        }
    }

    fn run_here(&self, progress: &Progress) -> Result<Outcome> {
        let t = self.plan.transform;
        let fit = self.job.fit;
        let source = self.job.describe_input();
        match &self.work {
            Work::MeshSurface {
                mesh,
                method,
                attributes,
            } => outcome::mesh_surface(mesh, t, *method, attributes, fit, progress),
            Work::SeparationCheck { mesh, options } => {
                outcome::separation_check(mesh, t, *options, fit, progress)
            }
            Work::Lines {
                mesh,
                source,
                coloring,
            } => outcome::lines(mesh, t, *source, *coloring, fit, progress),
            Work::Shape(s) => outcome::shape(s, t, fit, progress),
            Work::Subdivision {
                control,
                options,
                output: SubdivisionOutput::Surface,
            } => outcome::subdivision(control, t, options, fit, progress),
            Work::Subdivision {
                control,
                options,
                output: SubdivisionOutput::SeparationCheck,
            } => outcome::subdivision_check(control, t, options, fit, progress),
            Work::Subdivision {
                control,
                options,
                output: SubdivisionOutput::Solid(fill),
            } => {
                let memory = estimate::memory_budget(self.job.limits.max_memory);
                solid::subdivision_solid(control, t, options, *fill, fit, memory, progress)
            }
            Work::Implicit {
                formula,
                text,
                min,
                max,
                depth_layers: true,
                ..
            } => {
                let bounds = crate::mesh::Aabb {
                    min: *min,
                    max: *max,
                };
                solid::formula_depth_layers(formula, text, bounds, t, progress)
            }
            Work::Implicit {
                formula,
                text,
                min,
                max,
                levels,
                negative_r,
                ..
            } => {
                let options = crate::voxelize::interval_octree::OctreeOptions {
                    resolution: estimate::octree_resolution(fit, *min, *max)?,
                    both_signs: *negative_r,
                    levels: *levels,
                    max_leaves: Some(estimate::leaf_budget(self.job.limits.max_memory, 1)),
                };
                outcome::implicit(formula, text, *min, *max, &options, progress)
            }
            Work::DistanceBand {
                mesh,
                band,
                signed,
                inside,
                attributes,
            } => {
                let band = solid::BandAsked {
                    band: *band,
                    signed: *signed,
                    inside: *inside,
                    attributes,
                };
                solid::distance_band(mesh, t, band, fit, progress)
            }
            Work::Solid {
                mesh,
                fill,
                density,
                topology,
                inside,
            } => {
                let asked = solid::SolidAsked {
                    fill: *fill,
                    density: *density,
                    topology: *topology,
                    inside: *inside,
                };
                solid::mesh_solid(mesh, t, asked, fit, progress)
            }
            Work::MeasureMesh {
                mesh,
                flood,
                density,
                inside,
            } => solid::measure_mesh(mesh, t, *flood, *density, *inside, progress),
            Work::MeasureSurface {
                surface,
                flood,
                density,
            } => solid::measure_surface(surface, &source, *flood, *density, progress),
            Work::CsgTree(tree) => solid::csg_tree(tree, progress),
            Work::Combine {
                operands,
                normals,
                op,
                resample,
                curve,
            } => outcome::combine(operands, normals, *op, *resample, *curve, &source),
            Work::Brick(brick) => bricks::run_brick(brick, t, progress),
        }
    }
}

/// The segments `lines` voxelizes: the polylines, and the edges when asked or when there are
/// no polylines.
fn lines_source(mesh: &Mesh, edges: bool) -> LineSource {
    LineSource {
        polylines: true,
        edges: edges || mesh.polylines.is_empty(),
    }
}

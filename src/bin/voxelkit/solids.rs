//! Solids and their uses: `voxelkit solid`, `csg`, `intersect` and `measure`.

use crate::FitArgs;
use crate::run::{Global, run_and_report, run_job};
use clap::Args;
use std::path::PathBuf;
use voxelkit::implicit::{Coordinates, Formula, ThetaRange};
use voxelkit::io::vdb::read_vdb_grid;
use voxelkit::mesh::GridFit;
use voxelkit::mesh::attributes::AttributeChoice;
use voxelkit::mesh::fit_transform;
use voxelkit::ops::csg::BooleanOp;
use voxelkit::pipeline::batch::shared_placement;
use voxelkit::pipeline::request::ImplicitRequest;
use voxelkit::pipeline::request::{FillKind, FloodKind, MeasureRequest, Request, SolidRequest};
use voxelkit::pipeline::{
    CsgSource, GridSource, Job, MeasureSource, MeshSource, Shape, ShapeTask, SubdivisionOutput,
    SurfaceMethod, Task,
};
use voxelkit::solids::beam::BeamFill;
use voxelkit::solids::inside_rule::InsideRule;
use voxelkit::voxelize::parametric::ParametricOptions;
use voxelkit::voxelize::separating_formula::FormulaSurface;
use voxelkit::{Error, Result};

/// How the exterior is flooded.
#[derive(Args, Clone, Copy)]
pub struct FloodArgs {
    /// The exterior flood of --inside parity: blocks (whole empty 8^3 blocks at once,
    /// fastest), spans (scanlines over a dense bit volume) or xyz (Lai & Cheng's FloodingXYZ
    /// with a GRAYSTACK).
    #[arg(long, default_value_t = SolidRequest::default().flood, value_parser = parse_flood)]
    flood: FloodKind,
    /// GRAYSTACK capacity for --flood xyz (entries; when full, sweeps resume the flood).
    #[arg(long, default_value_t = SolidRequest::default().graystack)]
    graystack: usize,
}

/// Which inside a mesh gets.
#[derive(Args, Clone, Copy)]
pub struct InsideArgs {
    /// How the inside is decided: auto (the generalized winding number wherever the mesh's
    /// orientation is consistent: open, overlapping, nested and hollow meshes too; ray parity
    /// where it is not), winding (inside where the winding number is at least 1/2), or parity
    /// (ray parity and the exterior flood: closed meshes only).
    #[arg(long, default_value_t = InsideRule::default(), value_parser = parse_inside, value_name = "RULE")]
    pub inside: InsideRule,
}

fn parse_inside(s: &str) -> std::result::Result<InsideRule, String> {
    s.parse()
}

fn parse_flood(s: &str) -> std::result::Result<FloodKind, String> {
    s.parse()
}

fn parse_fill_kind(s: &str) -> std::result::Result<FillKind, String> {
    s.parse()
}

/// Grid, flood and density: what filling and measuring take.
#[derive(Args, Clone, Copy)]
pub struct FillArgs {
    #[command(flatten)]
    pub fit: FitArgs,
    #[command(flatten)]
    flood: FloodArgs,
    /// Density (mass per unit volume) for the mass.
    #[arg(long, default_value_t = SolidRequest::default().density)]
    pub density: f64,
    #[command(flatten)]
    pub inside: InsideArgs,
}

fn parse_beam_fill(s: &str) -> std::result::Result<BeamFill, String> {
    s.parse()
}

#[derive(Args)]
pub struct SolidArgs {
    /// Input meshes (.obj, .stl, .ply, .off, .gltf or .glb; several with --out-dir, or one
    /// pattern with --frames): open, overlapping or hollow ones too (see --inside). With
    /// --method depth-layers their undecidable voxels are reported.
    #[arg(required = true, num_args = 1..)]
    pub inputs: Vec<PathBuf>,
    /// flood: the 26-separating surface plus its inside (--inside: the centres of winding
    /// number at least 1/2, or what the exterior flood cannot reach, Lai & Cheng); depth-layers: depth buffers with a stencil count (Passalis et al.), exact at
    /// voxel centres, voxels no direction can decide reported as unclassifiable; beam: the
    /// projective surface plus the beams of voxels between front and back faces along z
    /// (Jegathese et al.), closed meshes only.
    #[arg(long, default_value_t = SolidRequest::default().method, value_parser = parse_fill_kind)]
    pub method: FillKind,
    /// --method beam: `parity` fills voxel centres between exact crossings 1-2, 3-4, ... of
    /// each column; `paper` fills Jegathese et al.'s way, from each back-face voxel up to the
    /// next front-face voxel.
    #[arg(
        long = "fill",
        value_parser = parse_beam_fill,
        default_value_t = SolidRequest::default().fill,
        value_name = "RULE"
    )]
    pub beam_fill: BeamFill,
    #[command(flatten)]
    pub fill: FillArgs,
    /// Also count the solid's components (26-connected) and genus, as `measure` does (a
    /// pass over every voxel of the solid).
    #[arg(long)]
    pub topology: bool,
    #[command(flatten)]
    pub depth: crate::solid_depth::DepthArgs,
    /// Write the solid as a level set instead (as `mesh --sdf`): exact signed distances
    /// within --band, class LEVEL_SET, named `surface`, after its fog volume `density`.
    #[arg(long)]
    pub sdf: bool,
    /// Half width of the --sdf band, in voxels.
    #[arg(long, default_value_t = SolidRequest::default().band, value_name = "W")]
    pub band: f64,
    /// Output: a .binvox or .vox (the whole solid), or a .vdb: `density` (1 on the whole
    /// solid, whole blocks as tiles), `shell` (its outer voxels) and `interior`; depth layers
    /// add `unclassified`; `voxels` (the whole solid as booleans) when --grids names it. With
    /// --sdf: `density` and the level set `surface`. A .nvdb holds the same grids for NanoVDB.
    #[command(flatten)]
    pub out: crate::batch::OutputArgs,
    #[command(flatten)]
    pub write: crate::WriteArgs,
    #[command(flatten)]
    pub up: crate::UpAxisArgs,
}

#[derive(Args)]
pub struct CsgArgs {
    /// union, intersection or difference (of A and B); or give --tree instead.
    #[arg(value_parser = parse_op, required_unless_present = "tree")]
    operation: Option<BooleanOp>,
    /// First .vdb (its transform is the result's).
    #[arg(required_unless_present = "tree")]
    a: Option<PathBuf>,
    /// Second .vdb.
    #[arg(required_unless_present = "tree")]
    b: Option<PathBuf>,
    /// A CSG tree in JSON: union / intersection / difference over box, cylinder, sphere,
    /// formula (solid where F < 0), mesh (closed .obj/.stl/.ply/.off) and vdb leaves, with a resolution
    /// or voxel_size (see examples/csg/).
    #[arg(long, conflicts_with_all = ["operation", "a", "b"])]
    tree: Option<PathBuf>,
    /// The grid read from both files [default: `voxels`, else `density`, else the first
    /// bool, mask or float grid].
    #[arg(long)]
    grid: Option<String>,
    /// Resample the second grid onto the first's transform when they differ.
    #[arg(long)]
    resample: bool,
    /// Output .vdb holding the result (`density`; `voxels` with --grids), with `normal` where
    /// the operands carry normals on one grid (a difference's cut takes the subtracted
    /// operand's, turned); a tree also writes `shell` and `interior`, and when its leaves are
    /// shapes and formulas, `normal` on the shell (the exact normal of the leaf surface each
    /// voxel lies on).
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    pub write: crate::WriteArgs,
}

#[derive(Args)]
pub struct IntersectArgs {
    /// Surfaces (two or more with the --formula ones): .vdb grids made on one grid
    /// (`--shared-grid`, or resampled onto the first's with --resample), and meshes (.obj,
    /// .stl, .ply, .off, .gltf, .glb), voxelized here as separating surfaces (-s) on the first
    /// grid's placement, or without a grid on one fitted to the union of their boxes (-r).
    /// Catmull-Clark surfaces made with --enclose hold every voxel the surface touches, so that
    /// their curve is not broken where the paper's adjacency test skips a voxel.
    #[arg(num_args = 0..)]
    inputs: Vec<PathBuf>,
    /// Read the .obj inputs as Catmull-Clark control meshes (with their crease tags), their
    /// limit surfaces voxelized here enclosed (every voxel the surface touches).
    #[arg(long)]
    subdiv: bool,
    /// A formula surface F = 0 (x y z, r theta phi blended; see `implicit`), voxelized here
    /// by Huang's criterion (-s) within --bounds [default: -1,1] on the same grid; repeat for
    /// several.
    #[arg(long = "formula", value_name = "F", allow_hyphen_values = true)]
    formulas: Vec<String>,
    #[command(flatten)]
    fit: FitArgs,
    #[command(flatten)]
    surface: crate::SurfaceArgs,
    /// Resample the later grids onto the first's transform where they differ.
    #[arg(long)]
    resample: bool,
    /// Output .vdb holding the voxels common to both surfaces.
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    pub write: crate::WriteArgs,
}

#[derive(Args)]
pub struct MeasureArgs {
    /// A mesh (.obj, .stl, ...; voxelized and filled by --inside first) or a .vdb whose
    /// `surface` grid is closed.
    input: PathBuf,
    #[command(flatten)]
    fill: FillArgs,
    #[command(flatten)]
    pub up: crate::UpAxisArgs,
}

fn parse_op(s: &str) -> std::result::Result<BooleanOp, String> {
    s.parse()
}

pub fn solid(args: &SolidArgs, global: &Global) -> Result<()> {
    let request = SolidRequest {
        method: args.method,
        flood: args.fill.flood.flood,
        graystack: args.fill.flood.graystack,
        directions: args.depth.directions.clone(),
        layers: args.depth.layers,
        unclassified: args.depth.unclassified,
        fill: args.beam_fill,
        density: args.fill.density,
        topology: args.topology,
        sdf: args.sdf,
        band: args.band,
        inside: args.fill.inside.inside,
        ..SolidRequest::default()
    };
    crate::batch::run(
        &args.inputs,
        &args.out,
        args.fill.fit.grid_fit()?,
        global,
        |mesh| request.task(mesh),
    )
}

pub fn measure(args: &MeasureArgs, global: &Global) -> Result<()> {
    let is_vdb = args
        .input
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("vdb"));
    let source = if is_vdb {
        MeasureSource::Vdb(args.input.clone())
    } else {
        MeasureSource::Mesh(MeshSource::File(args.input.clone()))
    };
    let request = MeasureRequest {
        flood: args.fill.flood.flood,
        graystack: args.fill.flood.graystack,
        density: args.fill.density,
        inside: args.fill.inside.inside,
        ..MeasureRequest::default()
    };
    let task = request.task(source)?;
    let outcome = run_job(Job::new(task, args.fill.fit.grid_fit()?), None, global)?;
    if global.json {
        println!("{}", outcome.report.to_json());
    } else {
        println!("{}", crate::run::with_flags(&outcome.report.summary()));
    }
    Ok(())
}

pub fn csg(args: &CsgArgs, global: &Global) -> Result<()> {
    let task = match (args.operation, &args.a, &args.b, &args.tree) {
        (Some(op), Some(a), Some(b), None) => Task::Combine {
            operands: vec![GridSource::File(a.clone()), GridSource::File(b.clone())],
            grid: args.grid.clone(),
            op,
            resample: args.resample,
            curve: false,
        },
        (_, _, _, Some(tree)) => Task::CsgTree(CsgSource::File(tree.clone())),
        _ => unreachable!("clap requires --tree or A and B"),
    };
    // The grid comes from the inputs (the first grid, or the tree's resolution).
    let job = Job::new(task, voxelkit::mesh::GridFit::from_options(None, None));
    run_and_report(job, &args.output, global)
}

pub fn intersect(args: &IntersectArgs, global: &Global) -> Result<()> {
    if args.inputs.len() + args.formulas.len() < 2 {
        return Err(Error::InvalidArgument(
            "intersect needs two or more surfaces: files and --formula ones".into(),
        ));
    }
    let is_grid = |p: &PathBuf| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("vdb"));
    let meshes: Vec<PathBuf> = args
        .inputs
        .iter()
        .filter(|p| !is_grid(p))
        .cloned()
        .collect();
    let bounds = args.fit.bounds.unwrap_or(ImplicitRequest::default().bounds);
    // Surfaces made here take the first grid's placement, or share one fitted to all the
    // meshes (a control mesh's box holds its limit surface), or to the formulas' bounds.
    let placement = match args.inputs.iter().find(|p| is_grid(p)) {
        _ if meshes.is_empty() && args.formulas.is_empty() => None,
        Some(first) => Some(GridFit::Placed(read_vdb_grid(first, None)?.transform)),
        None if meshes.is_empty() => Some(GridFit::Placed(fit_transform(
            &bounds.aabb(),
            args.fit.grid_fit()?,
        )?)),
        None => Some(shared_placement(
            &meshes,
            args.fit.grid_fit()?,
            global.up_axis,
        )?),
    };
    let made_here = |task: Task, fit: GridFit| -> Result<GridSource> {
        Ok(GridSource::Grid(
            run_job(Job::new(task, fit), None, global)?.grid,
        ))
    };
    let operand = |p: &PathBuf| -> Result<GridSource> {
        let Some(fit) = placement.filter(|_| !is_grid(p)) else {
            return Ok(GridSource::File(p.clone()));
        };
        let mesh = MeshSource::File(p.clone());
        let task = if args.subdiv {
            Task::Subdivision {
                mesh,
                options: ParametricOptions {
                    enclose: true,
                    ..ParametricOptions::default()
                },
                output: SubdivisionOutput::Surface,
            }
        } else {
            Task::MeshSurface {
                mesh,
                method: SurfaceMethod::Separating(args.surface.separating()),
                attributes: AttributeChoice::None,
            }
        };
        made_here(task, fit)
    };
    let formula = |text: &String| -> Result<GridSource> {
        let parsed = Formula::parse_in(text, Coordinates::Cartesian, ThetaRange::default())?;
        let task = Task::Shape(ShapeTask {
            shape: Shape::Formula(FormulaSurface::new(parsed, bounds.aabb())),
            separability: args.surface.separating().separability,
            normals: false,
            curvature_margin: true,
        });
        made_here(task, placement.expect("formulas are placed"))
    };
    let operands = args
        .inputs
        .iter()
        .map(operand)
        .chain(args.formulas.iter().map(formula))
        .collect::<Result<_>>()?;
    let task = Task::Combine {
        operands,
        grid: None,
        op: BooleanOp::Intersection,
        resample: args.resample,
        curve: true,
    };
    let job = Job::new(task, voxelkit::mesh::GridFit::from_options(None, None));
    run_and_report(job, &args.output, global)
}

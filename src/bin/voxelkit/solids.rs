//! Solids and their uses: `voxelkit solid`, `csg`, `intersect` and `measure`.

use crate::FitArgs;
use crate::report::{Json, peak_mib, progress_bar};
use clap::Args;
use std::path::{Path, PathBuf};
use std::time::Instant;
use voxelkit::grid::{Adjacency, DenseMask, SparseGrid};
use voxelkit::io::vdb::{read_vdb_grid, write_vdb_with_masks};
use voxelkit::mesh::{Mesh, fit_transform};
use voxelkit::ops::csg::{BooleanOp, combine};
use voxelkit::ops::flood::padded;
use voxelkit::ops::measure::{components, euler_characteristic};
use voxelkit::ops::solid::{FloodMethod, Solid, solid_from_surface};
use voxelkit::voxelize::Separability;
use voxelkit::voxelize::separating::{SeparatingOptions, voxelize_mesh, work_items};
use voxelkit::{Error, Result};

/// The floods to choose from.
#[derive(clap::ValueEnum, Clone, Copy)]
enum FloodKind {
    /// The fast scanline flood.
    Spans,
    /// Lai & Cheng's FloodingXYZ with a GRAYSTACK.
    Xyz,
}

/// How the exterior is flooded.
#[derive(Args, Clone, Copy)]
pub struct FloodArgs {
    #[arg(long, value_enum, default_value = "spans")]
    flood: FloodKind,
    /// GRAYSTACK capacity for --flood xyz (entries; when full, sweeps resume the flood).
    #[arg(long, default_value_t = 1 << 20)]
    graystack: usize,
}

impl FloodArgs {
    fn method(&self) -> FloodMethod {
        match self.flood {
            FloodKind::Xyz => FloodMethod::Xyz {
                capacity: self.graystack.max(1),
            },
            FloodKind::Spans => FloodMethod::Spans,
        }
    }
}

/// Grid, flood and density: what filling and measuring take.
#[derive(Args, Clone, Copy)]
pub struct FillArgs {
    #[command(flatten)]
    pub fit: FitArgs,
    #[command(flatten)]
    flood: FloodArgs,
    /// Density (mass per unit volume) for the mass.
    #[arg(long, default_value_t = 1.0)]
    pub density: f64,
}

/// How a solid is found.
#[derive(clap::ValueEnum, Clone, Copy, PartialEq, Eq)]
pub enum SolidMethod {
    /// The 26-separating surface plus everything the exterior flood cannot reach (Lai & Cheng).
    Flood,
    /// Depth buffers with a stencil count (Passalis et al.): exact at voxel centres, and
    /// voxels no direction can decide are reported as unclassifiable.
    DepthLayers,
    /// The projective surface plus the beams of voxels between front and back faces along z
    /// (Jegathese et al.); closed meshes only.
    Beam,
}

#[derive(Args)]
pub struct SolidArgs {
    /// Closed input mesh (.obj or .stl); its orientation does not matter. With
    /// --method depth-layers open meshes are accepted and their undecidable voxels reported.
    pub input: PathBuf,
    #[arg(long, value_enum, default_value = "flood")]
    pub method: SolidMethod,
    #[command(flatten)]
    pub fill: FillArgs,
    #[command(flatten)]
    pub depth: crate::solid_depth::DepthArgs,
    /// Output .vdb: `surface` and `density` (1 on the whole solid), `boundary` (its outer
    /// voxels) and `interior`; depth layers add `unclassified`.
    #[arg(short, long)]
    pub output: PathBuf,
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
    /// formula (solid where F < 0), mesh (closed .obj/.stl) and vdb leaves, with a resolution
    /// or voxel_size (see examples/csg/).
    #[arg(long, conflicts_with_all = ["operation", "a", "b"])]
    tree: Option<PathBuf>,
    /// The grid read from both files.
    #[arg(long, default_value = "surface")]
    grid: String,
    /// Resample the second grid onto the first's transform when they differ.
    #[arg(long)]
    resample: bool,
    #[arg(short, long)]
    output: PathBuf,
}

#[derive(Args)]
pub struct IntersectArgs {
    /// First surface (.vdb).
    a: PathBuf,
    /// Second surface (.vdb).
    b: PathBuf,
    /// Resample the second grid onto the first's transform when they differ.
    #[arg(long)]
    resample: bool,
    /// Output .vdb holding the voxels common to both surfaces.
    #[arg(short, long)]
    output: PathBuf,
}

#[derive(Args)]
pub struct MeasureArgs {
    /// A closed mesh (.obj, .stl; voxelized first) or a .vdb whose `surface` grid is closed.
    input: PathBuf,
    #[command(flatten)]
    fill: FillArgs,
}

fn parse_op(s: &str) -> std::result::Result<BooleanOp, String> {
    s.parse()
}

/// A 26-separating surface of a mesh, with a progress bar.
fn mesh_surface(mesh: &Mesh, fit: FitArgs, quiet: bool) -> Result<SparseGrid> {
    let t = fit_transform(&mesh.bbox(), fit.grid_fit())?;
    let options = SeparatingOptions {
        separability: Separability::TwentySix,
        ..Default::default()
    };
    let bar = progress_bar(work_items(mesh), "surface", quiet);
    let (grid, _) = voxelize_mesh(mesh, t, &options, &|n| bar.inc(n))?;
    bar.finish_and_clear();
    Ok(grid)
}

/// Components and genus of surface plus inside (26-connected components; genus of the
/// boundary for solids without cavities).
/// `None` above `TOPOLOGY_LIMIT` voxels, where the Euler characteristic (a hash set of cube
/// faces, edges and vertices) would cost more than everything else together.
fn topology(surface: &SparseGrid, solid: &Solid) -> Result<Option<(u64, i64)>> {
    const TOPOLOGY_LIMIT: u64 = 20_000_000;
    let m = solid.measures;
    if m.inside_voxels + m.surface_voxels > TOPOLOGY_LIMIT {
        return Ok(None);
    }
    let Some(bbox) = surface.bbox() else {
        return Ok(Some((0, 0)));
    };
    let mut all = DenseMask::from_grid(surface, padded(bbox, 1))?;
    for c in solid.inside.voxels() {
        all.set(c);
    }
    let parts = components(&all, Adjacency::TwentySix);
    Ok(Some((parts, parts as i64 - euler_characteristic(&all))))
}

/// How the flood decides what is inside, for the summary.
const FLOOD_RULE: &str =
    "inside = what the exterior flood (from the box corner, no normals needed) cannot reach";

#[allow(clippy::too_many_arguments)]
fn report(
    what: &str,
    surface: &SparseGrid,
    solid: &Solid,
    rule: &str,
    density: f64,
    extra: Json,
    start: Instant,
    json: bool,
) -> Result<()> {
    let seconds = start.elapsed().as_secs_f64();
    let m = solid.measures;
    let topo = topology(surface, solid)?;
    let topo_text = match topo {
        Some((parts, genus)) => format!("{parts} component(s), genus {genus}"),
        None => "components and genus skipped (over 20M voxels)".to_string(),
    };
    let (mass_low, mass_high) = m.mass(density);
    if json {
        let mut j = extra
            .int("inside_voxels", m.inside_voxels)
            .int("surface_voxels", m.surface_voxels)
            .num("volume_inside", m.volume_inside)
            .num("volume_with_surface", m.volume_with_surface)
            .num("mass_inside", mass_low)
            .num("mass_with_surface", mass_high)
            .num("components", topo.map_or(f64::NAN, |t| t.0 as f64))
            .num("genus", topo.map_or(f64::NAN, |t| t.1 as f64))
            .str("inside_rule", rule)
            .num("seconds", seconds)
            .num("peak_mib", peak_mib());
        if let Some(s) = solid.xyz_stats {
            j = j
                .int("line_floods", s.line_floods)
                .int("sweeps", s.sweeps)
                .int("graystack_overflows", s.overflows);
        }
        println!("{}", j.render());
    } else {
        println!(
            "{what}: {} inside + {} surface voxels; volume {:.6} (inside) .. {:.6} (with surface); mass {:.6} .. {:.6} at density {density}; \
             {topo_text}; {rule}{}; {:.2} s, peak {:.0} MiB",
            m.inside_voxels,
            m.surface_voxels,
            m.volume_inside,
            m.volume_with_surface,
            mass_low,
            mass_high,
            solid.xyz_stats.map_or(String::new(), |s| format!(
                " (FloodingXYZ: {} line floods, {} sweeps, {} stack overflows)",
                s.line_floods, s.sweeps, s.overflows
            )),
            seconds,
            peak_mib()
        );
    }
    Ok(())
}

/// Writes a solid classified at voxel centres: `surface` and `density` on the whole solid,
/// `boundary` (voxels with a face towards the outside), `interior`, then `extra` grids.
/// Returns the solid's voxel count.
pub fn write_centre_solid(
    path: &Path,
    solid: &DenseMask,
    transform: voxelkit::grid::Transform,
    extra: &[(&str, &SparseGrid)],
    meta: &[(&str, String)],
) -> Result<u64> {
    let outer = solid.boundary();
    let interior = solid.minus(&outer).to_grid(transform);
    let boundary = outer.to_grid(transform);
    let grid = solid.to_grid(transform);
    let mut masks = vec![("boundary", &boundary), ("interior", &interior)];
    masks.extend_from_slice(extra);
    write_vdb_with_masks(path, &grid, &masks, meta)?;
    Ok(grid.voxel_count())
}

/// Why the flood needs a closed mesh, for the error that refuses an open one.
const FLOOD_NEEDS_CLOSED: &str = "the exterior flood would leak through it and leave the solid hollow \
     (--method depth-layers reports which voxels an open mesh leaves undecidable)";

pub fn solid(args: &SolidArgs, json: bool) -> Result<()> {
    match args.method {
        SolidMethod::DepthLayers => return crate::solid_depth::run(args, json),
        SolidMethod::Beam => return crate::projective::beam(args, json),
        SolidMethod::Flood => {}
    }
    let start = Instant::now();
    let mesh = Mesh::load(&args.input)?;
    mesh.require_closed(FLOOD_NEEDS_CLOSED)?;
    let surface = mesh_surface(&mesh, args.fill.fit, json)?;
    let solid = solid_from_surface(&surface, args.fill.flood.method())?;
    let meta = vec![
        (
            "method",
            "huang-26-separating-surface+exterior-flood".to_string(),
        ),
        ("source_file", args.input.display().to_string()),
        ("resolution", args.fill.fit.describe()),
    ];
    write_and_report(
        args, &mesh, &surface, &solid, &meta, FLOOD_RULE, start, json,
    )
}

/// Writes a solid made of a surface and the voxels inside it (`surface` and `density` on
/// both, `boundary` and `interior` apart) and prints its summary, `rule` saying what inside
/// means.
#[allow(clippy::too_many_arguments)]
pub fn write_and_report(
    args: &SolidArgs,
    mesh: &Mesh,
    surface: &SparseGrid,
    solid: &Solid,
    meta: &[(&str, String)],
    rule: &str,
    start: Instant,
    json: bool,
) -> Result<()> {
    let mut whole = SparseGrid::new(surface.transform, voxelkit::grid::Channels::NONE);
    whole.union(surface);
    whole.union(&solid.inside);
    write_vdb_with_masks(
        &args.output,
        &whole,
        &[("boundary", surface), ("interior", &solid.inside)],
        meta,
    )?;
    let extra = Json::default()
        .str("output", args.output.display().to_string())
        .num("mesh_signed_volume", mesh.signed_volume());
    let what = format!(
        "{} (mesh signed volume {:.6})",
        args.output.display(),
        mesh.signed_volume()
    );
    report(
        &what,
        surface,
        solid,
        rule,
        args.fill.density,
        extra,
        start,
        json,
    )
}

pub fn measure(args: &MeasureArgs, json: bool) -> Result<()> {
    let start = Instant::now();
    let is_vdb = args
        .input
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("vdb"));
    let (surface, extra, what) = if is_vdb {
        // A solid written by `voxelkit solid` keeps its surface voxels as `boundary`.
        let grid = read_vdb_grid(&args.input, Some("boundary"))
            .or_else(|_| read_vdb_grid(&args.input, Some("surface")))?;
        (
            grid,
            Json::default().str("input", args.input.display().to_string()),
            args.input.display().to_string(),
        )
    } else {
        let mesh = Mesh::load(&args.input)?;
        mesh.require_closed(FLOOD_NEEDS_CLOSED)?;
        let extra = Json::default()
            .str("input", args.input.display().to_string())
            .num("mesh_area", mesh.area())
            .num("mesh_signed_volume", mesh.signed_volume());
        let what = format!(
            "{} (faces: area {:.6}, signed volume {:.6})",
            args.input.display(),
            mesh.area(),
            mesh.signed_volume()
        );
        (mesh_surface(&mesh, args.fill.fit, json)?, extra, what)
    };
    let solid = solid_from_surface(&surface, args.fill.flood.method())?;
    report(
        &what,
        &surface,
        &solid,
        FLOOD_RULE,
        args.fill.density,
        extra,
        start,
        json,
    )
}

/// An error about a pair of inputs, naming both files.
fn both_files(a: &Path, b: &Path, e: Error) -> Error {
    let message = match e {
        Error::InvalidArgument(m) => m,
        other => other.to_string(),
    };
    Error::InvalidArgument(format!("{} and {}: {message}", a.display(), b.display()))
}

fn read_surface(path: &Path, grid: &str) -> Result<SparseGrid> {
    read_vdb_grid(path, Some(grid))
}

fn write_result(
    path: &Path,
    grid: &SparseGrid,
    method: &str,
    inputs: [&Path; 2],
    json: bool,
    seconds: f64,
) -> Result<()> {
    let meta = vec![
        ("method", method.to_string()),
        (
            "source_file",
            format!("{} {}", inputs[0].display(), inputs[1].display()),
        ),
    ];
    write_vdb_with_masks(path, grid, &[], &meta)?;
    if json {
        let j = Json::default()
            .str("output", path.display().to_string())
            .int("voxels", grid.voxel_count())
            .num("seconds", seconds);
        println!("{}", j.render());
    } else {
        println!(
            "{}: {} voxels ({method}) in {:.2} s",
            path.display(),
            grid.voxel_count(),
            seconds
        );
    }
    Ok(())
}

pub fn csg(args: &CsgArgs, json: bool) -> Result<()> {
    let start = Instant::now();
    let (Some(operation), Some(a_path), Some(b_path)) = (args.operation, &args.a, &args.b) else {
        let tree = args
            .tree
            .as_deref()
            .expect("clap requires --tree or A and B");
        return crate::csg_tree::run(tree, &args.output, json);
    };
    let a = read_surface(a_path, &args.grid)?;
    let b = read_surface(b_path, &args.grid)?;
    let out =
        combine(&a, &b, operation, args.resample).map_err(|e| both_files(a_path, b_path, e))?;
    let method = format!("{operation:?}").to_lowercase();
    write_result(
        &args.output,
        &out,
        &method,
        [a_path, b_path],
        json,
        start.elapsed().as_secs_f64(),
    )
}

pub fn intersect(args: &IntersectArgs, json: bool) -> Result<()> {
    let start = Instant::now();
    let a = read_surface(&args.a, "surface")?;
    let b = read_surface(&args.b, "surface")?;
    let curve = combine(&a, &b, BooleanOp::Intersection, args.resample)
        .map_err(|e| both_files(&args.a, &args.b, e))?;
    write_result(
        &args.output,
        &curve,
        "intersection-curve",
        [&args.a, &args.b],
        json,
        start.elapsed().as_secs_f64(),
    )
}

//! `voxelkit subdiv`: Catmull-Clark control meshes voxelized from their exact limit surface,
//! and the evaluator checked against OpenSubdiv.

use crate::FitArgs;
use crate::run::Global;
use clap::{Args, Subcommand};
use std::path::{Path, PathBuf};
use voxelkit::grid::Adjacency;
use voxelkit::pipeline::request::Request;
use voxelkit::pipeline::request::SubdivRequest;
use voxelkit::subd::{ControlMesh, LimitSurface, compare_points, limit_area, read_points};
use voxelkit::{Error, Result};

#[derive(Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct SubdivArgs {
    #[command(subcommand)]
    action: Option<SubdivAction>,
    /// Catmull-Clark control meshes (.obj; quads, triangles, n-gons; closed or open), with
    /// their crease tags (`t` lines, or NAME.tags beside NAME.obj); several with --out-dir,
    /// on one grid with --shared-grid.
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    #[command(flatten)]
    pub voxelize: SubdivVoxelizeArgs,
}

/// How the limit surface is voxelized: what `subdiv` and `check --subdiv` take.
#[derive(Args, Clone, Copy)]
pub struct SubdivSurfaceArgs {
    /// The adjacency the corner voxels of every final sub-patch must have: 6 gives the
    /// thickest surface, 26 the thinnest; all three block 6-paths (the paper's guarantee,
    /// checked by flooding). Use --enclose to block 26-paths as well.
    #[arg(short, long, default_value_t = SubdivRequest::default().adjacency, value_parser = parse_adjacency)]
    adjacency: Adjacency,
    /// Pre-split every patch k x k before the recursive subdivision.
    #[arg(long, default_value_t = SubdivRequest::default().presplit, value_name = "K")]
    presplit: u32,
    /// Output every voxel the limit surface touches: refine past the paper's adjacency test
    /// until each sub-patch provably lies in its corner voxels (thicker and slower; the
    /// paper's test alone misses voxels the surface passes through).
    #[arg(long)]
    enclose: bool,
}

impl SubdivSurfaceArgs {
    /// The request these flags fill; the library checks and completes it.
    pub fn request(&self) -> SubdivRequest {
        SubdivRequest {
            adjacency: self.adjacency,
            presplit: self.presplit,
            enclose: self.enclose,
            ..SubdivRequest::default()
        }
    }
}

#[derive(Args)]
pub struct SubdivVoxelizeArgs {
    #[command(flatten)]
    surface: SubdivSurfaceArgs,
    #[command(flatten)]
    fit: FitArgs,
    /// Fill the closed limit surface (Lai & Cheng §6): seeds one voxel against the limit
    /// normals, the inside flooded from them by FloodingXYZ; written like `voxelkit solid`'s
    /// (`density` on the whole solid, `shell`, `interior`), with its volume and mass beside
    /// the exact limit volume (Gauss quadrature). The surface is always refined as --enclose
    /// refines it, so that no gap lets the inside flood out.
    #[arg(long)]
    solid: bool,
    /// --solid: fill by Passalis et al.'s double depth layers along z, x and y, run on a
    /// tessellation certified within 0.45 voxel of the limit surface and united with the
    /// enclosing surface, instead of seeds and FloodingXYZ: no seeds to miss a pocket.
    #[arg(long, requires = "solid")]
    depth_layers: bool,
    /// --solid: GRAYSTACK capacity of FloodingXYZ (entries; when full, sweeps resume the
    /// flood).
    #[arg(long, default_value_t = SubdivRequest::default().graystack, requires = "solid")]
    graystack: usize,
    /// --solid: density (mass per unit volume) for the mass.
    #[arg(long, default_value_t = SubdivRequest::default().density, requires = "solid")]
    density: f64,
    /// --solid: also count the solid's components (26-connected) and genus.
    #[arg(long, requires = "solid")]
    topology: bool,
    /// Output: a .vdb (`density`, `normal` and `opposite_normals` grids; with --solid,
    /// `density`, `shell`, `interior` and `opposite_normals`), a .nvdb (the same grids for
    /// NanoVDB), or a .binvox or .vox.
    #[command(flatten)]
    out: crate::batch::OutputArgs,
    #[command(flatten)]
    pub write: crate::WriteArgs,
    #[command(flatten)]
    pub up: crate::UpAxisArgs,
}

#[derive(Subcommand)]
enum SubdivAction {
    /// Compare the limit-surface evaluator with OpenSubdiv: at every corner of the level-3
    /// refinement (Far::PrimvarRefiner::Limit) and at random (u, v) (Bfr::Surface); also
    /// prints the limit surface's area by Gauss quadrature.
    Check {
        /// Control mesh (.obj).
        input: PathBuf,
        /// Random points per patch.
        #[arg(long, default_value_t = 16)]
        per_patch: usize,
        /// Also compare with a reference file of `face u v x y z nx ny nz` lines.
        #[arg(long)]
        reference: Option<PathBuf>,
    },
    /// Evaluate the limit surface at the `face u v` lines of a file; prints
    /// `face u v x y z nx ny nz` (OpenSubdiv's parametrization: quads in [0,1]^2, n-gons as
    /// half-size sub-face tiles).
    Eval {
        /// Control mesh (.obj).
        input: PathBuf,
        /// Text file, one `face u v` per line (`#` comments; extra columns must be 6 numbers).
        #[arg(long)]
        points: PathBuf,
    },
}

fn parse_adjacency(s: &str) -> std::result::Result<Adjacency, String> {
    s.parse()
}

pub fn run(args: &SubdivArgs, global: &Global) -> Result<()> {
    let json = global.json;
    match &args.action {
        Some(SubdivAction::Check {
            input,
            per_patch,
            reference,
        }) => check(input, *per_patch, reference.as_deref(), json),
        Some(SubdivAction::Eval { input, points }) => eval(input, points),
        None => voxelize(&args.inputs, &args.voxelize, global),
    }
}

fn voxelize(inputs: &[PathBuf], args: &SubdivVoxelizeArgs, global: &Global) -> Result<()> {
    let request = SubdivRequest {
        solid: args.solid,
        depth_layers: args.depth_layers,
        graystack: args.graystack,
        density: args.density,
        topology: args.topology,
        ..args.surface.request()
    };
    crate::batch::run(inputs, &args.out, args.fit.grid_fit()?, global, |mesh| {
        request.task(mesh)
    })
}

#[cfg(feature = "osd")]
fn check(input: &Path, per_patch: usize, reference: Option<&Path>, json: bool) -> Result<()> {
    use voxelkit::subd::opensubdiv::check_against_opensubdiv;
    let control = ControlMesh::load(input)?;
    let stats = control.stats();
    let surface = LimitSurface::new(control);
    let live = check_against_opensubdiv(&surface, per_patch, 1)?;
    let area = limit_area(&surface);
    let reference = match reference {
        Some(path) => Some(compare_points(&surface, &read_points(path)?)?),
        None => None,
    };
    let rows = [
        ("OpenSubdiv Limit() at level-3 corners", live.dyadic),
        (
            "OpenSubdiv Bfr::Surface at random (u, v)",
            Some(live.random),
        ),
        ("reference file", reference),
    ];
    if json {
        let comparison = |c: Option<voxelkit::subd::Comparison>| {
            c.map(|c| {
                serde_json::json!({
                    "points": c.points,
                    "max_position_error": c.max_position_error,
                    "max_relative_position_error": c.max_relative_position_error,
                    "max_normal_angle_rad": c.max_normal_angle,
                })
            })
        };
        let j = serde_json::json!({
            "input": input.display().to_string(),
            "faces": stats.faces,
            "patches": surface.patch_count(),
            "limit_area": area,
            "dyadic": comparison(live.dyadic),
            "random": comparison(Some(live.random)),
            "reference": comparison(reference),
        });
        println!("{j}");
        return Ok(());
    }
    println!(
        "{}: {} vertices, {} faces ({} quads, {} triangles, {} other), {} extraordinary, {} on the boundary, {} patches; limit surface area {area:.10} (Gauss quadrature)",
        input.display(),
        stats.vertices,
        stats.faces,
        stats.quads,
        stats.triangles,
        stats.other,
        stats.extraordinary,
        stats.boundary_vertices,
        surface.patch_count()
    );
    for (what, c) in rows {
        if let Some(c) = c {
            println!(
                "  {what}: {} points, max position error {:.3e} ({:.3e} of the bbox diagonal), max normal error {:.3e} rad",
                c.points, c.max_position_error, c.max_relative_position_error, c.max_normal_angle
            );
        }
    }
    Ok(())
}

#[cfg(not(feature = "osd"))]
fn check(_: &Path, _: usize, _: Option<&Path>, _: bool) -> Result<()> {
    Err(Error::Unsupported(
        "`subdiv check` needs OpenSubdiv: build with the `osd` feature".into(),
    ))
}

fn eval(input: &Path, points: &Path) -> Result<()> {
    use std::io::Write as _;
    let surface = LimitSurface::new(ControlMesh::load(input)?);
    let queries = read_points(points)?;
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    let io_error = |source| Error::Io {
        path: "<stdout>".into(),
        source,
    };
    writeln!(
        out,
        "# face u v x y z nx ny nz (limit surface of {})",
        input.display()
    )
    .map_err(io_error)?;
    for q in queries {
        let s = surface.evaluate(q.face, q.u, q.v)?;
        let (p, n) = (s.position, s.normal);
        writeln!(
            out,
            "{} {} {} {:.17e} {:.17e} {:.17e} {:.17e} {:.17e} {:.17e}",
            q.face, q.u, q.v, p.x, p.y, p.z, n.x, n.y, n.z
        )
        .map_err(io_error)?;
    }
    out.flush().map_err(io_error)
}

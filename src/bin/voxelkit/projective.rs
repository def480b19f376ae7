//! The projective voxelizer (Jegathese et al.) on the command line: `voxelkit lines`,
//! `voxelkit mesh --method projective` and `voxelkit solid --method beam`.

use crate::FitArgs;
use crate::report::{Json, peak_mib, progress_bar};
use clap::Args;
use glam::Vec3;
use std::path::{Path, PathBuf};
use std::time::Instant;
use voxelkit::Result;
use voxelkit::grid::{SparseGrid, Transform};
use voxelkit::io::vdb::write_vdb;
use voxelkit::mesh::{Mesh, fit_transform};
use voxelkit::voxelize::projective::{
    Coloring, LineSource, ProjectiveStats, beam::beam_solid, estimate_bytes, line_segments,
    voxelize_lines, voxelize_triangles,
};

fn parse_color(s: &str) -> std::result::Result<Vec3, String> {
    let v: Vec<f32> = s
        .split(',')
        .map(|p| p.trim().parse::<f32>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| format!("expected a colour r,g,b, got `{s}`"))?;
    match v[..] {
        [r, g, b] if v.iter().all(|c| c.is_finite()) => Ok(Vec3::new(r, g, b)),
        _ => Err(format!("expected three finite numbers r,g,b, got `{s}`")),
    }
}

/// Where the `Cd` grid's colours come from.
#[derive(Args, Clone, Copy)]
pub struct ColorArgs {
    /// One colour r,g,b for every voxel, instead of the vertex colours (`v x y z r g b`)
    /// that are otherwise interpolated into a `Cd` grid.
    #[arg(long, value_parser = parse_color, allow_hyphen_values = true)]
    color: Option<Vec3>,
    /// Write no `Cd` grid, even when the vertices carry colours.
    #[arg(long, conflicts_with = "color")]
    no_color: bool,
}

impl ColorArgs {
    /// Whether any colour option was given (only the projective methods use them).
    pub fn given(&self) -> bool {
        self.color.is_some() || self.no_color
    }

    fn coloring(&self, mesh: &Mesh) -> Coloring {
        match (self.color, self.no_color) {
            (Some(c), _) => Coloring::Constant(c),
            (None, true) => Coloring::None,
            (None, false) => Coloring::of(mesh),
        }
    }
}

fn describe(coloring: Coloring) -> String {
    match coloring {
        Coloring::None => "none".into(),
        Coloring::Vertex => "vertex colours interpolated".into(),
        Coloring::Constant(c) => format!("constant {},{},{}", c.x, c.y, c.z),
    }
}

#[derive(Args)]
pub struct LinesArgs {
    /// Input .obj: its `l` polylines, or, when it has none, the edges of its faces.
    input: PathBuf,
    /// Voxelize the edges of the faces (the wireframe) as well as the `l` polylines.
    #[arg(long)]
    edges: bool,
    #[command(flatten)]
    fit: FitArgs,
    #[command(flatten)]
    color: ColorArgs,
    /// Refuse work whose estimated memory exceeds this many MiB [default: available memory].
    #[arg(long, value_name = "MIB")]
    max_memory: Option<u64>,
    /// Output .vdb: `surface`, `density` and, with colours, `Cd`.
    #[arg(short, long)]
    output: PathBuf,
}

/// The grid transform, refused when the estimate does not fit in memory.
fn fitted(
    mesh: &Mesh,
    fit: FitArgs,
    coloring: Coloring,
    lines: Option<LineSource>,
    max_memory: Option<u64>,
) -> Result<Transform> {
    let transform = fit_transform(&mesh.bbox(), fit.grid_fit())?;
    crate::commands::check_memory(
        mesh,
        &transform,
        estimate_bytes(mesh, &transform, coloring, lines),
        max_memory,
    )?;
    Ok(transform)
}

fn metadata(
    method: &str,
    input: &Path,
    fit: FitArgs,
    coloring: Coloring,
) -> Vec<(&'static str, String)> {
    vec![
        ("method", method.to_string()),
        ("source_file", input.display().to_string()),
        ("resolution", fit.describe()),
        ("color", describe(coloring)),
    ]
}

/// The summary of a surface or line voxelization.
fn summarize(
    output: &Path,
    grid: &SparseGrid,
    stats: &ProjectiveStats,
    coloring: Coloring,
    (voxelize_s, total_s): (f64, f64),
    json: bool,
) {
    let per_second = |n: u64| n as f64 / voxelize_s.max(1e-9);
    if json {
        let j = Json::default()
            .str("output", output.display().to_string())
            .int("voxels", grid.voxel_count())
            .int("leaves", grid.leaf_count() as u64)
            .num("voxel_size", grid.transform.voxel_size)
            .int("triangles", stats.triangles)
            .int("degenerate_triangles", stats.degenerate_triangles)
            .int("segments", stats.segments)
            .str("color", describe(coloring))
            .timings(voxelize_s, total_s);
        println!("{}", j.render());
        return;
    }
    let primitives = if stats.segments > 0 {
        format!(
            "{} segments ({:.2}M lines/s)",
            stats.segments,
            per_second(stats.segments) / 1e6
        )
    } else {
        format!(
            "{} triangles ({} without area, voxelized as their longest edge; {:.2}M triangles/s)",
            stats.triangles,
            stats.degenerate_triangles,
            per_second(stats.triangles) / 1e6
        )
    };
    println!(
        "{}: {} voxels in {} leaves from {primitives}, colour {}, voxel size {:.6}, {:.2} s (voxelize {:.2} s), peak {:.0} MiB",
        output.display(),
        grid.voxel_count(),
        grid.leaf_count(),
        describe(coloring),
        grid.transform.voxel_size,
        total_s,
        voxelize_s,
        peak_mib()
    );
}

pub fn lines(args: &LinesArgs, json: bool) -> Result<()> {
    let start = Instant::now();
    let mesh = Mesh::load_lines(&args.input)?;
    let source = LineSource {
        polylines: true,
        edges: args.edges || mesh.polylines.is_empty(),
    };
    let coloring = args.color.coloring(&mesh);
    let transform = fitted(&mesh, args.fit, coloring, Some(source), args.max_memory)?;
    let count = line_segments(&mesh, source).len() as u64;
    let bar = progress_bar(count, "lines", json);
    let scan = Instant::now();
    let (grid, stats) = voxelize_lines(&mesh, transform, source, coloring, &|n| bar.inc(n))?;
    let voxelize_s = scan.elapsed().as_secs_f64();
    bar.finish_and_clear();
    let method = if source.edges && !mesh.polylines.is_empty() {
        "projective-lines+edges"
    } else if source.edges {
        "projective-edges"
    } else {
        "projective-lines"
    };
    write_vdb(
        &args.output,
        &grid,
        &metadata(method, &args.input, args.fit, coloring),
    )?;
    let total_s = start.elapsed().as_secs_f64();
    summarize(
        &args.output,
        &grid,
        &stats,
        coloring,
        (voxelize_s, total_s),
        json,
    );
    Ok(())
}

/// `voxelkit mesh --method projective`.
pub fn mesh(
    input: &Path,
    fit: FitArgs,
    color: &ColorArgs,
    max_memory: Option<u64>,
    output: &Path,
    json: bool,
) -> Result<()> {
    let start = Instant::now();
    let mesh = Mesh::load(input)?;
    let coloring = color.coloring(&mesh);
    let transform = fitted(&mesh, fit, coloring, None, max_memory)?;
    let bar = progress_bar(mesh.face_count() as u64, "faces", json);
    let scan = Instant::now();
    let (grid, stats) = voxelize_triangles(&mesh, transform, coloring, &|n| bar.inc(n))?;
    let voxelize_s = scan.elapsed().as_secs_f64();
    bar.finish_and_clear();
    write_vdb(
        output,
        &grid,
        &metadata("projective-triangles", input, fit, coloring),
    )?;
    let total_s = start.elapsed().as_secs_f64();
    summarize(output, &grid, &stats, coloring, (voxelize_s, total_s), json);
    Ok(())
}

/// `voxelkit solid --method beam`.
pub fn beam(args: &crate::solids::SolidArgs, json: bool) -> Result<()> {
    let start = Instant::now();
    let mesh = Mesh::load(&args.input)?;
    let fit = args.fill.fit;
    let transform = fitted(&mesh, fit, Coloring::None, None, None)?;
    let bar = progress_bar(mesh.face_count() as u64, "faces", json);
    let (surface, solid, _) = beam_solid(&mesh, transform, &|n| bar.inc(n))?;
    bar.finish_and_clear();
    crate::solids::write_and_report(
        args,
        &mesh,
        &surface,
        &solid,
        &metadata("projective-beam", &args.input, fit, Coloring::None),
        "inside = the beams between front and back faces along z (centres between crossings 1-2, 3-4, ...)",
        start,
        json,
    )
}

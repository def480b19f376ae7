//! The subcommands other than `bench`.

use crate::report::{Json, peak_mib, progress_bar};
use crate::{FitArgs, SurfaceArgs};
use clap::{Args, Subcommand};
use glam::DVec3;
use std::path::{Path, PathBuf};
use std::time::Instant;
use voxelkit::grid::{SparseGrid, Transform};
use voxelkit::io::vdb::{read_vdb_info, write_vdb};
use voxelkit::mesh::{Aabb, GridFit, Mesh, fit_transform, generate};
use voxelkit::ops::minimality::simple_voxel_count;
use voxelkit::ops::separability::check_mesh_separation;
use voxelkit::voxelize::Separability;
use voxelkit::voxelize::separating::{
    Criterion, SeparatingOptions, SeparatingStats, estimate_bytes, voxelize_mesh, work_items,
};
use voxelkit::voxelize::separating_analytic::{
    AnalyticSurface, Cylinder, Quadric, Sphere, voxelize_surface,
};
use voxelkit::{Error, Result};

impl FitArgs {
    pub fn grid_fit(&self) -> GridFit {
        match (self.resolution, self.voxel_size) {
            (_, Some(h)) => GridFit::VoxelSize(h),
            (Some(r), None) => GridFit::Resolution(r),
            (None, None) => GridFit::Resolution(256),
        }
    }
    pub fn describe(&self) -> String {
        match self.grid_fit() {
            GridFit::Resolution(r) => r.to_string(),
            GridFit::VoxelSize(h) => format!("voxel size {h}"),
        }
    }
}

fn parse_vec3(s: &str) -> std::result::Result<DVec3, String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|p| {
            p.trim()
                .parse::<f64>()
                .map_err(|_| format!("`{p}` is not a number"))
        })
        .collect::<std::result::Result<_, _>>()?;
    match v[..] {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(DVec3::new(x, y, z)),
        _ => Err(format!("expected three finite numbers x,y,z, got `{s}`")),
    }
}

/// Grid fit, surface options and output file: what every voxelizing command takes.
#[derive(Args, Clone)]
pub struct VoxelizeArgs {
    #[command(flatten)]
    pub fit: FitArgs,
    #[command(flatten)]
    pub surface: SurfaceArgs,
    /// Output .vdb file.
    #[arg(short, long)]
    pub output: PathBuf,
}

#[derive(Subcommand, Clone)]
pub enum ShapeKind {
    /// A sphere.
    Sphere {
        #[arg(long, default_value_t = 1.0)]
        radius: f64,
        #[arg(long, value_parser = parse_vec3, default_value = "0,0,0", allow_hyphen_values = true)]
        center: DVec3,
        #[command(flatten)]
        common: VoxelizeArgs,
    },
    /// A closed cylinder (side, caps and sharp rims).
    Cylinder {
        #[arg(long, default_value_t = 1.0)]
        radius: f64,
        #[arg(long, default_value_t = 2.0)]
        height: f64,
        #[arg(long, value_parser = parse_vec3, default_value = "0,0,0", allow_hyphen_values = true)]
        center: DVec3,
        /// Axis direction (normalized for you).
        #[arg(long, value_parser = parse_vec3, default_value = "0,0,1", allow_hyphen_values = true)]
        axis: DVec3,
        #[command(flatten)]
        common: VoxelizeArgs,
    },
    /// The surface x^2 + k y + k z = 0, clipped to the cube [-extent, extent]^3.
    Quadric {
        #[arg(long, default_value_t = 10.0)]
        k: f64,
        #[arg(long, default_value_t = 100.0)]
        extent: f64,
        #[command(flatten)]
        common: VoxelizeArgs,
    },
}

/// The `method` metadata of a mesh voxelization.
fn criterion_method(c: Criterion) -> &'static str {
    match c {
        Criterion::Huang => "huang-separating",
        Criterion::Clipped => "huang-separating-clipped",
    }
}

/// Metadata every output carries.
fn metadata(
    method: &str,
    sep: Separability,
    source: &str,
    resolution: &str,
) -> Vec<(&'static str, String)> {
    vec![
        ("method", method.to_string()),
        ("separability", sep.adjacency().to_string()),
        ("source_file", source.to_string()),
        ("resolution", resolution.to_string()),
    ]
}

fn stats_json(s: &SeparatingStats) -> Json {
    Json::default()
        .int("vertex_voxels", s.vertex_voxels)
        .int("edge_voxels", s.edge_voxels)
        .int("body_voxels", s.body_voxels)
        .int("triangles", s.triangles as u64)
        .int("edges", s.edges as u64)
        .int("vertices", s.vertices as u64)
        .int("degenerate_faces", s.degenerate_faces as u64)
}

/// Refuses voxelizing `mesh` on `transform` when `estimate` bytes exceed `max_memory_mib`
/// (default: the available memory), naming the mesh and the grid size.
pub fn check_memory(
    mesh: &Mesh,
    transform: &Transform,
    estimate: u64,
    max_memory_mib: Option<u64>,
) -> Result<()> {
    let extent = mesh.bbox().extent() / transform.voxel_size;
    voxelkit::system::check_fits(
        estimate,
        max_memory_mib.map(|m| m << 20),
        &format!(
            "{} at {:.0}x{:.0}x{:.0} voxels; lower --resolution or raise --max-memory",
            mesh.source.display(),
            extent.x,
            extent.y,
            extent.z
        ),
    )
}

/// Loads, fits, checks memory and voxelizes a mesh with a progress bar.
fn voxelize_file(
    mesh: &Mesh,
    fit: FitArgs,
    surface: SurfaceArgs,
    quiet: bool,
) -> Result<(SparseGrid, SeparatingStats, f64)> {
    let transform = fit_transform(&mesh.bbox(), fit.grid_fit())?;
    let opts = SeparatingOptions {
        separability: surface.separability,
        criterion: surface.criterion,
        normals: surface.normals,
    };
    let estimate = estimate_bytes(mesh, &transform, &opts);
    check_memory(mesh, &transform, estimate, surface.max_memory)?;
    let bar = progress_bar(work_items(mesh), "voxelizing", quiet);
    let start = Instant::now();
    let (grid, stats) = voxelize_mesh(mesh, transform, &opts, &|n| bar.inc(n))?;
    bar.finish_and_clear();
    Ok((grid, stats, start.elapsed().as_secs_f64()))
}

pub fn mesh(input: &Path, args: &VoxelizeArgs, json: bool) -> Result<()> {
    let (fit, surface, output) = (args.fit, args.surface, args.output.as_path());
    let start = Instant::now();
    let mesh = Mesh::load(input)?;
    let load_s = start.elapsed().as_secs_f64();
    let (grid, stats, voxelize_s) = voxelize_file(&mesh, fit, surface, json)?;
    let meta = metadata(
        criterion_method(surface.criterion),
        surface.separability,
        &input.display().to_string(),
        &fit.describe(),
    );
    write_vdb(output, &grid, &meta)?;
    let total_s = start.elapsed().as_secs_f64();
    if json {
        let j = Json::default()
            .str("output", output.display().to_string())
            .int("voxels", grid.voxel_count())
            .int("leaves", grid.leaf_count() as u64)
            .num("voxel_size", grid.transform.voxel_size)
            .int("separability", surface.separability.adjacency() as u64)
            .obj("classes", stats_json(&stats))
            .num("load_seconds", load_s)
            .timings(voxelize_s, total_s);
        println!("{}", j.render());
    } else {
        if stats.degenerate_faces > 0 {
            eprintln!(
                "warning: {}: {} degenerate faces (zero area or repeated vertex) voxelized by their edges only",
                input.display(),
                stats.degenerate_faces
            );
        }
        println!(
            "{}: {} voxels ({} vertex, {} edge, {} body) in {} leaves, {}-separating, voxel size {:.6}, {:.2} s (voxelize {:.2} s), peak {:.0} MiB",
            output.display(),
            grid.voxel_count(),
            stats.vertex_voxels,
            stats.edge_voxels,
            stats.body_voxels,
            grid.leaf_count(),
            surface.separability.adjacency(),
            grid.transform.voxel_size,
            total_s,
            voxelize_s,
            peak_mib()
        );
    }
    Ok(())
}

pub fn shape(kind: &ShapeKind, json: bool) -> Result<()> {
    let positive = |name: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(Error::InvalidArgument(format!(
                "--{name} must be a positive number, got {v}"
            )))
        }
    };
    let (surface_obj, name, common): (Box<dyn AnalyticSurface>, String, &VoxelizeArgs) = match kind
    {
        ShapeKind::Sphere {
            radius,
            center,
            common,
        } => {
            positive("radius", *radius)?;
            (
                Box::new(Sphere {
                    center: *center,
                    radius: *radius,
                }),
                format!("sphere r={radius} c={center}"),
                common,
            )
        }
        ShapeKind::Cylinder {
            radius,
            height,
            center,
            axis,
            common,
        } => {
            positive("radius", *radius)?;
            positive("height", *height)?;
            let axis = axis
                .try_normalize()
                .ok_or_else(|| Error::InvalidArgument("--axis must not be zero".into()))?;
            let c = Cylinder {
                center: *center,
                axis,
                radius: *radius,
                height: *height,
            };
            (
                Box::new(c),
                format!("cylinder r={radius} h={height} c={center} axis={axis}"),
                common,
            )
        }
        ShapeKind::Quadric { k, extent, common } => {
            positive("extent", *extent)?;
            if !(k.is_finite() && *k != 0.0) {
                return Err(Error::InvalidArgument(format!(
                    "--k must be a non-zero number, got {k}"
                )));
            }
            (
                Box::new(Quadric {
                    k: *k,
                    half_extent: *extent,
                }),
                format!("x^2 + {k} y + {k} z = 0 in [-{extent},{extent}]^3"),
                common,
            )
        }
    };
    let bbox: Aabb = surface_obj.bbox();
    let transform: Transform = fit_transform(&bbox, common.fit.grid_fit())?;
    let sep = common.surface.separability;
    let cells = (bbox.extent() / transform.voxel_size + 2.0)
        .to_array()
        .iter()
        .product::<f64>();
    // The scan touches every block once; the result is a surface of ~ (cells)^(2/3) * 2 voxels.
    let estimate =
        (cells.powf(2.0 / 3.0) * 2.0 * if common.surface.normals { 40.0 } else { 8.0 }) as u64;
    voxelkit::system::check_fits(estimate, common.surface.max_memory.map(|m| m << 20), &name)?;
    let blocks = (cells / 512.0).ceil() as u64;
    let bar = progress_bar(blocks, "voxelizing", json);
    let start = Instant::now();
    let grid = voxelize_surface(
        surface_obj.as_ref(),
        transform,
        sep,
        common.surface.normals,
        &|n| bar.inc(n),
    );
    bar.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64();
    write_vdb(
        &common.output,
        &grid,
        &metadata(
            "huang-separating-analytic",
            sep,
            &name,
            &common.fit.describe(),
        ),
    )?;
    if json {
        let j = Json::default()
            .str("output", common.output.display().to_string())
            .str("shape", name)
            .int("voxels", grid.voxel_count())
            .int("leaves", grid.leaf_count() as u64)
            .num("voxel_size", transform.voxel_size)
            .num("seconds", seconds)
            .num("peak_mib", peak_mib());
        println!("{}", j.render());
    } else {
        println!(
            "{}: {name}: {} voxels in {} leaves, {}-separating, voxel size {:.6}, {:.2} s, peak {:.0} MiB",
            common.output.display(),
            grid.voxel_count(),
            grid.leaf_count(),
            sep.adjacency(),
            transform.voxel_size,
            seconds,
            peak_mib()
        );
    }
    Ok(())
}

pub fn info(file: &Path, json: bool) -> Result<()> {
    let grids = read_vdb_info(file)?;
    if json {
        let items = grids
            .iter()
            .map(|g| {
                let meta = g
                    .metadata
                    .iter()
                    .fold(Json::default(), |j, m| j.str(&m.key, m.value.clone()));
                Json::default()
                    .str("name", g.name.clone())
                    .str("type", g.value_type.clone())
                    .str("class", g.grid_class.clone())
                    .int("active_voxels", g.active_voxels)
                    .int("leaves", g.leaf_count)
                    .num("voxel_size", g.voxel_size[0])
                    .str("origin", format!("{:?}", g.origin))
                    .str("bbox", format!("{:?}..{:?}", g.bbox_min, g.bbox_max))
                    .obj("metadata", meta)
            })
            .collect();
        println!(
            "{}",
            Json::default()
                .str("file", file.display().to_string())
                .arr("grids", items)
                .render()
        );
        return Ok(());
    }
    println!("{}: {} grid(s)", file.display(), grids.len());
    for g in &grids {
        println!(
            "  {} ({}, class {}): {} active voxels in {} leaves, index bbox {:?}..{:?}",
            g.name,
            g.value_type,
            g.grid_class,
            g.active_voxels,
            g.leaf_count,
            g.bbox_min,
            g.bbox_max
        );
        println!(
            "    transform: voxel size {:?}, voxel (0,0,0) at {:?}{}",
            g.voxel_size,
            g.origin,
            if g.uniform_linear {
                ""
            } else {
                " (not a uniform linear map)"
            }
        );
        for m in &g.metadata {
            println!("    {} = {}", m.key, m.value);
        }
    }
    Ok(())
}

pub fn check(input: &Path, fit: FitArgs, surface: SurfaceArgs, json: bool) -> Result<()> {
    let mesh = Mesh::load(input)?;
    let (grid, stats, seconds) = voxelize_file(&mesh, fit, surface, json)?;
    let adjacency = surface.separability.flood_adjacency();
    let report = check_mesh_separation(&grid, &mesh, adjacency)?;
    let simple = simple_voxel_count(&grid, adjacency)?;
    let share = simple as f64 / grid.voxel_count().max(1) as f64;
    if json {
        let j = Json::default()
            .str("input", input.display().to_string())
            .int("separability", surface.separability.adjacency() as u64)
            .int("voxels", grid.voxel_count())
            .obj("classes", stats_json(&stats))
            .int("inside_centres", report.inside_centres)
            .int("exterior_voxels", report.exterior)
            .int("leaked", report.leaked)
            .int("simple_voxels", simple)
            .num("simple_share", share)
            .num("voxelize_seconds", seconds);
        println!("{}", j.render());
    } else {
        println!(
            "{} at {}: {} voxels, {}-separating: exterior flood ({}-connected) reached {} inside voxels of {} ({}); {} simple voxels ({:.2}%)",
            input.display(),
            fit.describe(),
            grid.voxel_count(),
            surface.separability.adjacency(),
            adjacency.number(),
            report.leaked,
            report.inside_centres,
            if report.separates() {
                "separating"
            } else {
                "NOT separating"
            },
            simple,
            100.0 * share
        );
    }
    if report.separates() {
        Ok(())
    } else {
        Err(Error::Unsupported(format!(
            "{}: the surface leaks at voxel {:?}",
            input.display(),
            report.first_leak
        )))
    }
}

pub fn demo(folder: &Path, resolution: u32, json: bool) -> Result<()> {
    std::fs::create_dir_all(folder).map_err(|e| Error::Io {
        path: folder.to_path_buf(),
        source: e,
    })?;
    let mut mesh = generate::trefoil(1.0, 0.45, 384, 32);
    let obj = folder.join("trefoil.obj");
    mesh.write_obj(&obj)?;
    mesh.source = obj.clone();
    let mut results = Vec::new();
    for sep in [Separability::Six, Separability::TwentySix] {
        let fit = FitArgs {
            resolution: Some(resolution),
            voxel_size: None,
        };
        let surface = SurfaceArgs {
            separability: sep,
            criterion: Criterion::Huang,
            normals: true,
            max_memory: None,
        };
        let (grid, stats, seconds) = voxelize_file(&mesh, fit, surface, json)?;
        let out = folder.join(format!("trefoil-{}.vdb", sep.adjacency()));
        write_vdb(
            &out,
            &grid,
            &metadata(
                "huang-separating",
                sep,
                &obj.display().to_string(),
                &resolution.to_string(),
            ),
        )?;
        let adjacency = sep.flood_adjacency();
        let report = check_mesh_separation(&grid, &mesh, adjacency)?;
        if !json {
            println!(
                "{}: {} voxels ({} vertex, {} edge, {} body), {:.2} s; flood check: {}",
                out.display(),
                grid.voxel_count(),
                stats.vertex_voxels,
                stats.edge_voxels,
                stats.body_voxels,
                seconds,
                if report.separates() {
                    format!("{}-separating", sep.adjacency())
                } else {
                    "LEAKS".into()
                }
            );
        }
        results.push(
            Json::default()
                .str("output", out.display().to_string())
                .int("voxels", grid.voxel_count())
                .num("seconds", seconds)
                .str(
                    "flood_check",
                    if report.separates() {
                        "separating"
                    } else {
                        "leaks"
                    },
                ),
        );
    }
    if json {
        println!(
            "{}",
            Json::default()
                .str("mesh", obj.display().to_string())
                .arr("outputs", results)
                .render()
        );
    } else {
        println!(
            "open the .vdb files in Blender (File > Import > OpenVDB) or inspect them with `voxelkit info`"
        );
    }
    Ok(())
}

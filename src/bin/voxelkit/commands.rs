//! The subcommands other than `bench`: each is arguments -> `Job` -> report.

use crate::batch::{self, OutputArgs};
use crate::run::{Global, run_and_report, run_job};
use crate::{FitArgs, SurfaceArgs};
use clap::{Args, Subcommand};
use glam::DVec3;
use serde::Serialize;
use std::path::{Path, PathBuf};
use voxelkit::grid::{CoordBox, Transform};
use voxelkit::implicit::Formula;
use voxelkit::io::brick_set::{BrickSet, is_brick_set};
use voxelkit::io::vdb::{DENSITY_GRID, VOXELS_GRID, read_vdb_info};
use voxelkit::mesh::attributes::AttributeChoice;
use voxelkit::mesh::{GridFit, generate};
use voxelkit::ops::separability::check_mesh_separation;
use voxelkit::pipeline::request::ImplicitRequest;
use voxelkit::pipeline::request::{Bounds, MeshRequest, Request, SurfaceKind};
use voxelkit::pipeline::{
    Details, Job, MeshSource, Shape, ShapeTask, SubdivisionOutput, SurfaceMethod, Task,
};
use voxelkit::shapes::{Cylinder, Quadric, Sphere};
use voxelkit::voxelize::Separability;
use voxelkit::voxelize::parametric::ParametricOptions;
use voxelkit::voxelize::separating::{Criterion, SeparatingOptions};
use voxelkit::voxelize::separating_formula::FormulaSurface;
use voxelkit::{Error, Result};

impl FitArgs {
    pub fn grid_fit(&self) -> Result<GridFit> {
        GridFit::from_options(self.resolution, self.voxel_size)
            .with_origin(self.origin)
            .within(self.bounds.as_ref().map(Bounds::aabb))
    }
}

pub fn parse_vec3(s: &str) -> std::result::Result<DVec3, String> {
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
    /// Output: a .vdb (`density`, `normal` with --normals; `voxels` with --grids), a .nvdb
    /// (the same grids for NanoVDB), or a .binvox or .vox (the voxel set alone).
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub write: crate::WriteArgs,
}

#[derive(Subcommand, Clone)]
pub enum ShapeKind {
    /// A sphere.
    Sphere {
        /// Radius, in world units.
        #[arg(long, default_value_t = 1.0)]
        radius: f64,
        /// Centre, `x,y,z` in world units.
        #[arg(long, value_parser = parse_vec3, default_value = "0,0,0", allow_hyphen_values = true)]
        center: DVec3,
        #[command(flatten)]
        common: VoxelizeArgs,
    },
    /// A closed cylinder (side, caps and sharp rims).
    Cylinder {
        /// Radius, in world units.
        #[arg(long, default_value_t = 1.0)]
        radius: f64,
        /// Length along the axis, cap to cap, in world units.
        #[arg(long, default_value_t = 2.0)]
        height: f64,
        /// Centre (midway between the caps), `x,y,z` in world units.
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
        /// The coefficient k of x^2 + k y + k z = 0.
        #[arg(long, default_value_t = 10.0)]
        k: f64,
        /// Half the edge of the cube the surface is clipped to, in world units.
        #[arg(long, default_value_t = 100.0)]
        extent: f64,
        #[command(flatten)]
        common: VoxelizeArgs,
    },
    /// Any surface F = 0 typed as a formula, inside --bounds [default: -1,1]: Huang's
    /// criterion with each voxel's nearest surface point found numerically; interval arithmetic
    /// proves every step between two centres left out free of the surface (where it cannot,
    /// the nearer end is added), so the voxels separate as the closed-form shapes' do.
    Formula {
        #[command(flatten)]
        formula: crate::implicit::FormulaArgs,
        #[command(flatten)]
        common: VoxelizeArgs,
    },
}

impl ShapeKind {
    pub fn common(&self) -> &VoxelizeArgs {
        match self {
            ShapeKind::Sphere { common, .. }
            | ShapeKind::Cylinder { common, .. }
            | ShapeKind::Quadric { common, .. }
            | ShapeKind::Formula { common, .. } => common,
        }
    }
}

/// A narrow band of exact distances instead of a voxel set.
#[derive(Args, Clone, Copy)]
pub struct DistanceArgs {
    /// Write a level set instead: exact signed distances (world units, negative inside) on
    /// every voxel within --band of the mesh, as a FloatGrid of class LEVEL_SET named
    /// `surface` (Houdini's name) after its fog volume `density`, signed by --inside.
    #[arg(long)]
    pub sdf: bool,
    /// Write unsigned distances within --band (a FloatGrid `distance`); open meshes too.
    #[arg(long, conflicts_with = "sdf")]
    pub udf: bool,
    /// Half width of the distance band, in voxels (the background is band x voxel size).
    #[arg(long, default_value_t = voxelkit::pipeline::request::MeshRequest::default().band, value_name = "W")]
    pub band: f64,
    #[command(flatten)]
    pub inside: crate::solids::InsideArgs,
}

impl SurfaceArgs {
    /// The mesh request of these flags (every other option at its default).
    pub fn request(&self) -> MeshRequest {
        MeshRequest {
            separability: self.separability,
            criterion: self.criterion,
            normals: self.normals,
            ..MeshRequest::default()
        }
    }

    pub fn separating(&self) -> SeparatingOptions {
        self.request().separating()
    }
}

/// The separating surface of a mesh.
fn surface_job(mesh: MeshSource, fit: FitArgs, surface: SurfaceArgs) -> Result<Job> {
    Ok(Job::new(
        Task::MeshSurface {
            mesh,
            method: SurfaceMethod::Separating(surface.separating()),
            attributes: AttributeChoice::None,
        },
        fit.grid_fit()?,
    ))
}

/// `voxelkit mesh`: a separating or projective surface, or a distance band, of each input.
#[allow(clippy::too_many_arguments)]
pub fn mesh(
    inputs: &[PathBuf],
    projective: bool,
    color: &crate::projective::ColorArgs,
    attributes: Option<Vec<String>>,
    distance: &DistanceArgs,
    fit: FitArgs,
    surface: SurfaceArgs,
    out: &OutputArgs,
    global: &Global,
) -> Result<()> {
    if !projective && color.given() {
        return Err(Error::InvalidArgument(
            "--color and --no-color need --method projective (the separating surface carries no colour)".into(),
        ));
    }
    let (colors, color) = color.request();
    let request = MeshRequest {
        method: if projective {
            SurfaceKind::Projective
        } else {
            SurfaceKind::Separating
        },
        colors,
        color,
        attributes,
        sdf: distance.sdf,
        udf: distance.udf,
        band: distance.band,
        inside: distance.inside.inside,
        ..surface.request()
    };
    batch::run(inputs, out, fit.grid_fit()?, global, |mesh| {
        request.task(mesh)
    })
}

/// The library's check of a positive, finite number, naming the flag.
fn positive(name: &str, v: f64) -> Result<()> {
    voxelkit::pipeline::request::positive(&format!("--{name}"), v)
}

pub fn shape(kind: &ShapeKind, global: &Global) -> Result<()> {
    let (shape, common) = match kind {
        ShapeKind::Sphere {
            radius,
            center,
            common,
        } => {
            positive("radius", *radius)?;
            let s = Sphere {
                center: *center,
                radius: *radius,
            };
            (Shape::Sphere(s), common)
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
            (Shape::Cylinder(c), common)
        }
        ShapeKind::Quadric { k, extent, common } => {
            positive("extent", *extent)?;
            if !(k.is_finite() && *k != 0.0) {
                return Err(Error::InvalidArgument(format!(
                    "--k must be a non-zero number, got {k}"
                )));
            }
            let q = Quadric {
                k: *k,
                half_extent: *extent,
            };
            (Shape::Quadric(q), common)
        }
        ShapeKind::Formula { formula, common } => {
            let (text, coordinates) = formula.text_and_coordinates()?;
            let parsed = Formula::parse_in(&text, coordinates, formula.theta_range)?;
            let bounds = common
                .fit
                .bounds
                .unwrap_or(ImplicitRequest::default().bounds);
            (
                Shape::Formula(FormulaSurface::new(parsed, bounds.aabb())),
                common,
            )
        }
    };
    let task = Task::Shape(ShapeTask {
        shape,
        separability: common.surface.separability,
        normals: common.surface.normals,
        curvature_margin: !common.surface.no_curvature_margin,
    });
    run_and_report(
        Job::new(task, common.fit.grid_fit()?),
        &common.output,
        global,
    )
}

/// One grid of `voxelkit info --json`.
#[derive(Serialize)]
struct GridSummary {
    name: String,
    #[serde(rename = "type")]
    value_type: String,
    class: String,
    active_voxels: u64,
    leaves: u64,
    voxel_size: [f64; 3],
    origin: [f64; 3],
    uniform_linear: bool,
    bbox_min: [i32; 3],
    bbox_max: [i32; 3],
    metadata: std::collections::BTreeMap<String, serde_json::Value>,
}

/// A metadata value as JSON of its OpenVDB type: numbers and booleans as such.
fn typed(m: &voxelkit::io::vdb::MetaEntry) -> serde_json::Value {
    let parsed = match m.type_name.as_str() {
        "int32" | "int64" => m.value.parse::<i64>().ok().map(serde_json::Value::from),
        "float" | "double" => m.value.parse::<f64>().ok().map(serde_json::Value::from),
        "bool" => m.value.parse::<bool>().ok().map(serde_json::Value::from),
        _ => None,
    };
    parsed.unwrap_or_else(|| serde_json::Value::from(m.value.clone()))
}

/// `info` on a brick set's index: the bricks, and the voxels of their main grids.
fn brick_set_info(index: &Path, global: &Global) -> Result<()> {
    let set = BrickSet::read(index)?;
    let mut voxels = (set.full_bricks.len() as u64) * (set.brick_size as u64).pow(3);
    let mut rows = Vec::new();
    for (brick, file) in set.bricks.iter().zip(set.files(index)?) {
        let grids = read_vdb_info(&file)?;
        let main = grids
            .iter()
            .find(|g| g.name == VOXELS_GRID)
            .or_else(|| grids.iter().find(|g| g.name == DENSITY_GRID))
            .or(grids.first());
        if let Some(g) = main {
            let bbox = (g.active_voxels > 0).then(|| CoordBox {
                min: g.bbox_min.map(i64::from),
                max: g.bbox_max.map(i64::from),
            });
            let transform = Transform::new(DVec3::from_array(g.origin), g.voxel_size[0]);
            set.check_part(brick, &file, bbox, &transform)?;
        }
        let count = main.map_or(0, |g| g.active_voxels);
        voxels += count;
        rows.push(serde_json::json!({
            "brick": brick.brick,
            "file": file.display().to_string(),
            "active_voxels": count,
        }));
    }
    if global.json {
        let j = serde_json::json!({
            "file": index.display().to_string(),
            "brick_size": set.brick_size,
            "voxel_size": set.voxel_size,
            "origin": set.origin,
            "active_voxels": voxels,
            "bricks": rows,
            "full_bricks": set.full_bricks,
        });
        println!("{j}");
        return Ok(());
    }
    println!(
        "{}: brick set of {} bricks in files and {} whole bricks of {}^3 voxels: {} active voxels",
        index.display(),
        set.bricks.len(),
        set.full_bricks.len(),
        set.brick_size,
        voxels
    );
    println!(
        "    transform: voxel size {:?}, voxel (0,0,0) at {:?}",
        set.voxel_size, set.origin
    );
    for r in &rows {
        println!(
            "  brick {} {}: {} active voxels",
            r["brick"], r["file"], r["active_voxels"]
        );
    }
    Ok(())
}

pub fn info(file: &Path, global: &Global) -> Result<()> {
    if is_brick_set(file) {
        return brick_set_info(file, global);
    }
    let grids = read_vdb_info(file)?;
    if global.json {
        let items: Vec<GridSummary> = grids
            .iter()
            .map(|g| GridSummary {
                name: g.name.clone(),
                value_type: g.value_type.clone(),
                class: g.grid_class.clone(),
                active_voxels: g.active_voxels,
                leaves: g.leaf_count,
                voxel_size: g.voxel_size,
                origin: g.origin,
                uniform_linear: g.uniform_linear,
                bbox_min: g.bbox_min,
                bbox_max: g.bbox_max,
                metadata: g
                    .metadata
                    .iter()
                    .map(|m| (m.key.clone(), typed(m)))
                    .collect(),
            })
            .collect();
        let j = serde_json::json!({ "file": file.display().to_string(), "grids": items });
        println!("{j}");
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

/// Checks the separation of a mesh's surface, or with `subdiv` of a Catmull-Clark limit
/// surface's voxels, and fails when the surface leaks.
pub fn check(
    input: &Path,
    fit: FitArgs,
    surface: SurfaceArgs,
    subdiv: Option<ParametricOptions>,
    global: &Global,
) -> Result<()> {
    let mesh = MeshSource::File(input.to_path_buf());
    let task = match subdiv {
        Some(options) => Task::Subdivision {
            mesh,
            options,
            output: SubdivisionOutput::SeparationCheck,
        },
        None => Task::SeparationCheck {
            mesh,
            options: surface.separating(),
        },
    };
    let outcome = run_job(Job::new(task, fit.grid_fit()?), None, global)?;
    let report = &outcome.report;
    println!(
        "{}",
        if global.json {
            report.to_json()
        } else {
            report.summary()
        }
    );
    match &report.details {
        Details::SeparationCheck(c) if c.leaked > 0 => {
            let v = c.first_leak.unwrap_or_default();
            Err(Error::Unsupported(format!(
                "{}: the surface leaks: the exterior flood reaches the inside voxel ({}, {}, {})",
                input.display(),
                v[0],
                v[1],
                v[2]
            )))
        }
        _ => Ok(()),
    }
}

pub fn demo(folder: &Path, resolution: u32, global: &Global) -> Result<()> {
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
        let surface = SurfaceArgs {
            separability: sep,
            criterion: Criterion::Huang,
            normals: true,
            no_curvature_margin: false,
        };
        let fit = FitArgs {
            resolution: Some(resolution),
            voxel_size: None,
            origin: None,
            bounds: None,
        };
        let out = folder.join(format!("trefoil-{}.vdb", sep.adjacency()));
        let job = surface_job(MeshSource::Mesh(mesh.clone()), fit, surface)?;
        let outcome = run_job(job, Some(&out), global)?;
        let found = check_mesh_separation(&outcome.grid, &mesh, sep.flood_adjacency())?;
        let verdict = if found.separates() {
            format!("{}-separating", sep.adjacency())
        } else {
            "LEAKS".to_string()
        };
        if !global.json {
            println!("{}; flood check: {verdict}", outcome.report.summary());
        }
        results.push(serde_json::json!({
            "report": outcome.report,
            "flood_check": verdict,
        }));
    }
    if global.json {
        println!(
            "{}",
            serde_json::json!({ "mesh": obj.display().to_string(), "outputs": results })
        );
    } else {
        println!(
            "open the .vdb files in Blender (File > Import > OpenVDB) or inspect them with `voxelkit info`"
        );
    }
    Ok(())
}

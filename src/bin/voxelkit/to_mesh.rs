//! `voxelkit to-mesh`: the surface of a grid in a .vdb file as a triangle mesh; `voxelkit
//! remesh`: any mesh remade closed and manifold through its level set.

use crate::run::{Global, run_job, with_flags};
use clap::Args;
use std::path::PathBuf;
use voxelkit::Result;
use voxelkit::pipeline::request::{MeshRequest, Request, ToMeshRequest};
use voxelkit::pipeline::to_mesh::{check_adaptivity, check_mesh_output, vdb_to_mesh};
use voxelkit::pipeline::{Job, MeshSource};

#[derive(Args)]
pub struct ToMeshArgs {
    /// The .vdb file: its level set (`surface`) when it has one, else its voxel set or fog.
    pub input: PathBuf,
    /// The mesh written: .obj, .ply (binary), .stl (binary) or .glb, by the extension.
    #[arg(short, long)]
    pub output: PathBuf,
    /// The grid to draw, by name [default: `surface` when the file has that level set, else
    /// `voxels`, else `density`, else the first bool, mask or float grid].
    #[arg(long, value_name = "NAME")]
    pub grid: Option<String>,
    /// The value the surface passes through [default: 0 for a level set, 0.5 for a fog
    /// volume; a voxel set's surface lies half way between its voxels and empty ones].
    #[arg(long, allow_hyphen_values = true, value_name = "V")]
    pub iso: Option<f64>,
    #[command(flatten)]
    pub adaptivity: AdaptivityArgs,
}

/// How far merging flat regions may move a mesh written: an option of every command that
/// writes one.
#[derive(Args, Clone, Copy)]
pub struct AdaptivityArgs {
    /// Merge the triangles of flat regions, moving the surface by at most about this many
    /// voxels: every vertex stays within half of it of the plane of each triangle it replaces
    /// (0: every cell keeps its vertex; 0.25 leaves about a third of a smooth mesh's triangles).
    #[arg(long, default_value_t = ToMeshRequest::default().adaptivity, value_name = "VOXELS")]
    pub adaptivity: f64,
}

pub fn run(args: &ToMeshArgs, global: &Global) -> Result<()> {
    let request = ToMeshRequest {
        grid: args.grid.clone(),
        iso: args.iso,
        adaptivity: args.adaptivity.adaptivity,
    };
    let report = vdb_to_mesh(&args.input, &args.output, &request, &global.limits())?;
    if global.json {
        println!("{}", serde_json::to_string(&report).unwrap_or_default());
    } else {
        println!("{}", report.summary());
    }
    Ok(())
}

#[derive(Args)]
pub struct RemeshArgs {
    /// Any mesh (.obj, .stl, .ply, .off, .gltf or .glb): open, overlapping and
    /// self-intersecting ones take their inside from --inside.
    pub input: PathBuf,
    /// The closed, manifold mesh written: .obj, .ply, .stl or .glb.
    #[arg(short, long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub fit: crate::FitArgs,
    #[command(flatten)]
    pub inside: crate::solids::InsideArgs,
    #[command(flatten)]
    pub up: crate::UpAxisArgs,
    #[command(flatten)]
    pub adaptivity: AdaptivityArgs,
}

/// The mesh's level set on the grid, signed by the inside rule, drawn as a mesh, and its
/// distance to the input measured.
pub fn remesh(args: &RemeshArgs, global: &Global) -> Result<()> {
    let source = MeshSource::File(args.input.clone());
    let request = MeshRequest {
        sdf: true,
        inside: args.inside.inside,
        ..MeshRequest::default()
    };
    check_mesh_output(&args.output, &[&args.input])?;
    check_adaptivity(args.adaptivity.adaptivity)?;
    let mesh = source.load(false, global.up_axis)?;
    let job = Job::new(request.task(source)?, args.fit.grid_fit()?);
    let mut outcome = run_job(job, None, global)?;
    outcome.write_remesh(&args.output, args.adaptivity.adaptivity, &mesh)?;
    println!(
        "{}",
        if global.json {
            outcome.report.to_json()
        } else {
            with_flags(&outcome.report.summary())
        }
    );
    Ok(())
}

//! `voxelkit to-mesh`: the surface of a grid in a .vdb file as a triangle mesh.

use crate::run::Global;
use clap::Args;
use std::path::PathBuf;
use voxelkit::Result;
use voxelkit::pipeline::request::ToMeshRequest;
use voxelkit::pipeline::to_mesh::vdb_to_mesh;

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
}

pub fn run(args: &ToMeshArgs, global: &Global) -> Result<()> {
    let request = ToMeshRequest {
        grid: args.grid.clone(),
        iso: args.iso,
    };
    let report = vdb_to_mesh(&args.input, &args.output, &request, &global.limits())?;
    if global.json {
        println!("{}", serde_json::to_string(&report).unwrap_or_default());
    } else {
        println!("{}", report.summary());
    }
    Ok(())
}

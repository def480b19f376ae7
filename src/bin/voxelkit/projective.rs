//! The projective voxelizer (Jegathese et al.) on the command line: `voxelkit lines`, and the
//! colour options of `voxelkit mesh --method projective` (`solid --method beam` is with the
//! solids).

use crate::FitArgs;
use crate::run::{Global, run_and_report};
use clap::Args;
use glam::Vec3;
use std::path::PathBuf;
use voxelkit::Result;
use voxelkit::pipeline::request::{LinesRequest, Request};
use voxelkit::pipeline::{Job, MeshSource};

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

    /// The requests' `colors` and `color`.
    pub fn request(&self) -> (bool, Option<[f32; 3]>) {
        (!self.no_color, self.color.map(|c| c.to_array()))
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
    /// Output: a .vdb (`density` and, with colours, `Cd`), a .nvdb (the same grids for
    /// NanoVDB), or a .binvox or .vox (the voxels alone).
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    pub write: crate::WriteArgs,
    #[command(flatten)]
    pub up: crate::UpAxisArgs,
}

pub fn lines(args: &LinesArgs, global: &Global) -> Result<()> {
    let (colors, color) = args.color.request();
    let request = LinesRequest {
        edges: args.edges,
        colors,
        color,
        ..LinesRequest::default()
    };
    let task = request.task(MeshSource::File(args.input.clone()))?;
    run_and_report(Job::new(task, args.fit.grid_fit()?), &args.output, global)
}

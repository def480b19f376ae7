//! `voxelkit implicit`: a typed formula voxelized by interval octree (Stolte & Kaufman).

use crate::run::{Global, run_and_report};
use clap::Args;
use std::path::PathBuf;
use voxelkit::Result;
use voxelkit::implicit::examples::example;
use voxelkit::implicit::{Coordinates, ThetaRange};
use voxelkit::mesh::GridFit;
use voxelkit::pipeline::Job;
use voxelkit::pipeline::request::Request;
use voxelkit::pipeline::request::{Bounds, ImplicitRequest};

/// A formula and the variables it is written in: what `implicit` and `shape formula` take.
#[derive(Args, Clone)]
pub struct FormulaArgs {
    /// The formula F; the surface is F = 0. Variables: x y z (cartesian), r theta phi
    /// (spherical: theta in the XZ plane from +X, phi from the XZ plane), r theta y
    /// (cylindrical). Operators + - * / ^ (integer powers), functions sqrt abs sin cos tan
    /// exp log atan2 min max, `pi`, and `name = expr;` sub-expressions.
    #[arg(
        required_unless_present = "example",
        conflicts_with = "example",
        allow_hyphen_values = true
    )]
    formula: Option<String>,
    /// A named example instead of a formula: sphere, torus, sinsin, gear, crankshaft.
    #[arg(long)]
    example: Option<String>,
    /// The formula's variables: cartesian (x y z), spherical (r theta phi) or cylindrical
    /// (r theta y).
    #[arg(long, default_value_t = ImplicitRequest::default().coords, value_parser = parse_coords)]
    coords: Coordinates,
    /// Spherical and cylindrical: the values theta takes, `positive` (the paper's
    /// [0, 2pi), cut along +x) or `symmetric` ((-pi, pi], cut along -x).
    #[arg(long, default_value_t = ImplicitRequest::default().theta_range, value_parser = parse_theta_range)]
    pub theta_range: ThetaRange,
}

impl FormulaArgs {
    /// The formula's text and coordinates: as typed, or the named example's.
    pub fn text_and_coordinates(&self) -> Result<(String, Coordinates)> {
        match &self.example {
            Some(name) => {
                let e = example(name)?;
                Ok((e.formula.to_string(), e.coordinates))
            }
            None => Ok((
                self.formula.clone().expect("clap requires a formula"),
                self.coords,
            )),
        }
    }
}

#[derive(Args)]
pub struct ImplicitArgs {
    #[command(flatten)]
    formula: FormulaArgs,
    /// The box searched: `lo,hi` (a cube) or `x0,y0,z0,x1,y1,z1`. Formulas run with the same
    /// bounds and resolution share one grid (their voxels align, as --shared-grid aligns
    /// meshes'), so their outputs combine voxel for voxel (`voxelkit intersect`, `csg`).
    #[arg(long, default_value_t = ImplicitRequest::default().bounds, value_parser = parse_bounds, allow_hyphen_values = true, value_name = "LO,HI")]
    bounds: Bounds,
    /// Voxels along the longest side of the bounds.
    #[arg(short, long, default_value_t = ImplicitRequest::default().resolution)]
    resolution: u32,
    /// Also write every level of the octree as `level_0` .. `level_n` (each envelops the
    /// surface).
    #[arg(long)]
    levels: bool,
    /// Spherical and cylindrical only: also look for the surface at negative r, i.e. where
    /// F(-r, theta + pi, -phi) = 0 (cylindrical: F(-r, theta + pi, y) = 0).
    #[arg(long)]
    negative_r: bool,
    /// For F = G - r: Stolte & Kaufman's substitution [G]^2 - r^2 = 0, the surface r = |G|
    /// (lobes where G < 0 included) instead of r = G as typed.
    #[arg(long)]
    squared: bool,
    /// Write the solid F < 0 within the bounds instead of the surface: Passalis et al.'s
    /// double depth layers along z, x and y, each ray's crossings of F = 0 isolated by
    /// interval arithmetic (`density`, `shell`, `interior`, `unclassified`).
    #[arg(long)]
    depth_layers: bool,
    /// Output: a .vdb (`density`, `normal`, and the levels), a .nvdb (the same grids for
    /// NanoVDB), or a .binvox or .vox (the voxels alone).
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    pub write: crate::WriteArgs,
}

fn parse_theta_range(s: &str) -> std::result::Result<ThetaRange, String> {
    s.parse()
}

fn parse_coords(s: &str) -> std::result::Result<Coordinates, String> {
    s.parse()
}

/// `--bounds` as the request takes it.
pub fn parse_bounds(s: &str) -> std::result::Result<Bounds, String> {
    s.parse()
}

pub fn run(args: &ImplicitArgs, global: &Global) -> Result<()> {
    let (text, coordinates) = args.formula.text_and_coordinates()?;
    let request = ImplicitRequest {
        coords: coordinates,
        bounds: args.bounds,
        resolution: args.resolution,
        levels: args.levels,
        negative_r: args.negative_r,
        theta_range: args.formula.theta_range,
        squared: args.squared,
        depth_layers: args.depth_layers,
    };
    let job = Job::new(request.task(text)?, GridFit::Resolution(args.resolution));
    run_and_report(job, &args.output, global)
}

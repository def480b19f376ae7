//! `voxelkit bench subdiv`: the parametric Catmull-Clark voxelizer per mesh, resolution and
//! adjacency — seconds, evaluations, evaluations per second, and the evaluations a uniform
//! grid at the same finest spacing would need (the paper's case for adaptivity). The reference
//! in the same process: OpenVDB's meshToUnsignedDistanceField (one-voxel band) on a tessellation of the same
//! limit surface with about one voxel between samples, on the same thread count (tessellating
//! is not timed).

use crate::bench::{best_of, data_folder};
use crate::json::Json;
use crate::openvdb_reference;
use clap::Args;
use std::path::PathBuf;
use voxelkit::grid::Adjacency;
use voxelkit::mesh::{GridFit, fit_transform};
use voxelkit::subd::{ControlMesh, LimitSurface};
use voxelkit::voxelize::parametric::{ParametricOptions, voxelize_subdivision};
use voxelkit::{Error, Result};
use voxelkit_openvdb::Reference as OpenVdbReference;

#[derive(Args)]
pub struct SubdivBenchArgs {
    /// Control meshes: names in DATA/subd (without .obj) or paths to .obj files.
    #[arg(long, value_delimiter = ',', default_value = "spot_control_mesh,beast")]
    meshes: Vec<String>,
    /// Data folder holding subd/ [default: $VOXELKIT_DATA or ../shared/data].
    #[arg(long)]
    data: Option<PathBuf>,
    #[arg(long, value_delimiter = ',', default_value = "256,512,1024")]
    resolutions: Vec<u32>,
    #[arg(long, value_delimiter = ',', default_value = "6,18,26")]
    adjacency: Vec<u32>,
    /// Also run the enclosed variant (every voxel the surface touches).
    #[arg(long)]
    enclose: bool,
    /// Worker threads for both sides.
    #[arg(long, default_value_t = 2)]
    threads: usize,
    /// Runs per measurement; the fastest is reported.
    #[arg(long, default_value_t = 3)]
    repeat: usize,
    /// Skip the OpenVDB reference.
    #[arg(long)]
    no_reference: bool,
}

fn adjacency(n: u32) -> Result<Adjacency> {
    match n {
        6 => Ok(Adjacency::Six),
        18 => Ok(Adjacency::Eighteen),
        26 => Ok(Adjacency::TwentySix),
        _ => Err(Error::InvalidArgument(format!(
            "adjacency must be 6, 18 or 26, not {n}"
        ))),
    }
}

pub fn run(args: &SubdivBenchArgs, json: bool) -> Result<()> {
    let data = data_folder(&args.data);
    let pool = crate::bench::thread_pool(args.threads)?;
    let mut variants = Vec::new();
    for &n in &args.adjacency {
        variants.push((adjacency(n)?, false));
    }
    if args.enclose {
        variants.push((Adjacency::TwentySix, true));
    }
    let mut rows = Vec::new();
    if !json {
        println!(
            "{:<18} {:>5} {:>4} {:>8} {:>10} {:>12} {:>10} {:>13} {:>9} {:>10} {:>9}",
            "mesh",
            "res",
            "N",
            "seconds",
            "voxels",
            "evaluations",
            "evals/s",
            "uniform evals",
            "uniform/x",
            "openvdb s",
            "speedup"
        );
    }
    for name in &args.meshes {
        let path = crate::bench::resolve(name, &data, "subd");
        let control = ControlMesh::load(&path)?;
        let bbox = control.polygon_mesh().bbox();
        let limit = LimitSurface::new(control.clone());
        for &res in &args.resolutions {
            let transform = fit_transform(&bbox, GridFit::Resolution(res))?;
            let reference = if args.no_reference {
                None
            } else {
                Some(reference_seconds(&limit, transform, args, &pool)?)
            };
            for &(adj, enclose) in &variants {
                let options = ParametricOptions {
                    adjacency: adj,
                    enclose,
                    ..Default::default()
                };
                let (seconds, out) = pool.install(|| {
                    best_of(args.repeat, || {
                        voxelize_subdivision(
                            &control,
                            transform,
                            &options,
                            &voxelkit::progress::Progress::none(),
                        )
                    })
                })?;
                let s = out.stats;
                let rate = s.evaluations as f64 / seconds;
                let uniform_ratio = s.uniform_evaluations as f64 / s.evaluations as f64;
                let label = format!("{}{}", adj.number(), if enclose { "e" } else { "" });
                let speedup = reference.map(|r| r / seconds);
                if json {
                    let mut j = Json::default()
                        .str("mesh", name.clone())
                        .int("resolution", res as u64)
                        .int("adjacency", adj.number() as u64)
                        .str("mode", if enclose { "enclosed" } else { "paper" })
                        .int("threads", args.threads as u64)
                        .num("seconds", seconds)
                        .int("voxels", s.voxels)
                        .int("evaluations", s.evaluations)
                        .num("evaluations_per_second", rate)
                        .int("uniform_evaluations", s.uniform_evaluations);
                    if let (Some(r), Some(x)) = (reference, speedup) {
                        j = j.num("openvdb_seconds", r).num("speedup", x);
                    }
                    rows.push(j);
                } else {
                    println!(
                        "{:<18} {:>5} {:>4} {:>8.3} {:>10} {:>12} {:>10.3e} {:>13} {:>8.1}x {:>10} {:>9}",
                        name,
                        res,
                        label,
                        seconds,
                        s.voxels,
                        s.evaluations,
                        rate,
                        s.uniform_evaluations,
                        uniform_ratio,
                        reference.map_or("-".into(), |r| format!("{r:.3}")),
                        speedup.map_or("-".into(), |x| format!("{x:.2}x"))
                    );
                }
            }
        }
    }
    if json {
        println!("{}", Json::default().arr("runs", rows).render());
    }
    Ok(())
}

/// OpenVDB's meshToUnsignedDistanceField on a tessellation with about one voxel between samples.
fn reference_seconds(
    limit: &LimitSurface,
    transform: voxelkit::grid::Transform,
    args: &SubdivBenchArgs,
    pool: &rayon::ThreadPool,
) -> Result<f64> {
    let mesh = pool.install(|| {
        limit.tessellate(|pid| {
            // The patch's extent from a coarse sample grid (its control bound can be loose).
            let (mut lo, mut hi) = (
                glam::DVec3::splat(f64::INFINITY),
                glam::DVec3::splat(f64::NEG_INFINITY),
            );
            for j in 0..=4 {
                for i in 0..=4 {
                    let p = limit
                        .eval_patch(pid, i as f64 / 4.0, j as f64 / 4.0)
                        .position;
                    lo = lo.min(p);
                    hi = hi.max(p);
                }
            }
            ((hi - lo).max_element() / transform.voxel_size)
                .ceil()
                .clamp(1.0, 256.0) as usize
        })
    });
    let (points, tris) = crate::bench::openvdb_mesh(&mesh, &transform);
    let (seconds, _) = best_of(args.repeat, || {
        openvdb_reference(
            OpenVdbReference::Unsigned,
            &points,
            &tris,
            transform.voxel_size,
            1.0,
            args.threads,
        )
    })?;
    Ok(seconds)
}

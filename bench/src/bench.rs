//! `voxelkit bench`: our separating voxelizer against OpenVDB's
//! `tools::meshToUnsignedDistanceField` with a one-voxel band, on the same mesh, voxel size and
//! thread count, in the same process.

use crate::json::Json;
use crate::openvdb_reference;
use clap::Args;
use std::path::PathBuf;
use std::time::Instant;
use voxelkit::choice::Choice;
use voxelkit::mesh::{GridFit, Mesh, fit_transform};
use voxelkit::voxelize::Separability;
use voxelkit::voxelize::separating::{Criterion, SeparatingOptions, voxelize_mesh};
use voxelkit::{Error, Result};
use voxelkit_openvdb::Reference as OpenVdbReference;

#[derive(Args)]
#[command(args_conflicts_with_subcommands = true)]
pub struct BenchArgs {
    #[command(subcommand)]
    kind: Option<BenchKind>,
    /// Meshes to run: names in DATA/meshes (without .obj) or paths to .obj/.stl files.
    #[arg(long, value_delimiter = ',', default_value = "igea,skull,bunny-closed")]
    meshes: Vec<String>,
    /// Data folder holding meshes/ [default: $VOXELKIT_DATA or ../shared/data].
    #[arg(long)]
    data: Option<PathBuf>,
    #[arg(long, value_delimiter = ',', default_value = "256,512,1024")]
    resolutions: Vec<u32>,
    #[arg(long, value_delimiter = ',', default_value = "6,26")]
    separability: Vec<String>,
    /// Criteria to run (huang, clipped).
    #[arg(long, value_delimiter = ',', default_value = "huang,clipped", value_parser = crate::parse_criterion)]
    criterion: Vec<Criterion>,
    /// Thread counts to compare.
    #[arg(long = "thread-counts", value_delimiter = ',', default_value = "1,2")]
    thread_counts: Vec<usize>,
    /// Runs per measurement; the fastest is reported.
    #[arg(long, default_value_t = 3)]
    repeat: usize,
}

#[derive(clap::Subcommand)]
enum BenchKind {
    /// The Catmull-Clark voxelizer: evaluations against uniform sampling, and time against
    /// OpenVDB's meshToUnsignedDistanceField on a tessellation of the same limit surface.
    Subdiv(crate::bench_subdiv::SubdivBenchArgs),
    /// Implicit surfaces: the paper's Fig. 5 by interval octree, against naive corner signs.
    Implicit(crate::bench_implicit::ImplicitBenchArgs),
    /// Solids: surface plus flood against OpenVDB's meshToLevelSet plus sdfInteriorMask.
    Solid(crate::bench_solid::SolidBenchArgs),
    /// Volume and area convergence on exact solids; depth-layer volumes of real meshes.
    Measure(crate::bench_measure::MeasureBenchArgs),
    /// The projective voxelizer in triangles/s and lines/s against the separating one;
    /// with --leaks, voxel counts and flood leaks of both.
    Projective(crate::bench_projective::ProjectiveBenchArgs),
    /// The whole `voxelkit` process (`mesh`, `solid` or `mesh --sdf`) against the cheapest
    /// OpenVDB call with the same output, with file sizes and both processes' peaks.
    Whole(crate::bench_whole::WholeBenchArgs),
    /// Planning's memory estimates against whole runs' peaks, family by family, with the
    /// factor that refits each family's constants.
    Calibrate(crate::calibrate::CalibrateArgs),
    /// Huang et al.'s Tables 1–3 on the shared meshes: set-up, and for 6- and 26-separation
    /// voxels, time, voxels per ms and voxels by class, beside the paper's rows.
    Huang(crate::bench_huang::HuangBenchArgs),
    /// One OpenVDB reference run, in a process of its own (used by `whole`).
    #[command(hide = true)]
    Openvdb(crate::bench_whole::OpenVdbRunArgs),
}

/// `mesh` as OpenVDB's mesher takes it: points in the index space of `t` and triangle
/// corners (made before any timing starts).
pub fn openvdb_mesh(mesh: &Mesh, t: &voxelkit::grid::Transform) -> (Vec<f32>, Vec<u32>) {
    let points = mesh
        .positions
        .iter()
        .flat_map(|&p| t.world_to_index(p).as_vec3().to_array())
        .collect();
    (points, mesh.triangles().flat_map(|(_, t)| t).collect())
}

/// A pool of `threads` workers for one side of a comparison.
pub fn thread_pool(threads: usize) -> Result<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::InvalidArgument(format!("cannot start {threads} threads: {e}")))
}

/// The data folder: `--data`, else `$VOXELKIT_DATA`, else `../shared/data`.
pub fn data_folder(explicit: &Option<PathBuf>) -> PathBuf {
    explicit
        .clone()
        .or_else(|| std::env::var_os("VOXELKIT_DATA").map(PathBuf::from))
        .unwrap_or_else(|| PathBuf::from("../shared/data"))
}

/// A path as given (it has an extension), or `DATA/folder/NAME.obj` for a bare name.
pub fn resolve(name: &str, data: &std::path::Path, folder: &str) -> PathBuf {
    let p = PathBuf::from(name);
    if p.extension().is_some() {
        p
    } else {
        data.join(folder).join(format!("{name}.obj"))
    }
}

/// Fastest of `repeat` runs of `f`, in seconds, with its last result.
pub fn best_of<T>(repeat: usize, mut f: impl FnMut() -> Result<T>) -> Result<(f64, T)> {
    let mut best = f64::INFINITY;
    let mut last = None;
    for _ in 0..repeat.max(1) {
        let start = Instant::now();
        let r = f()?;
        best = best.min(start.elapsed().as_secs_f64());
        last = Some(r);
    }
    Ok((best, last.expect("at least one run")))
}

pub fn run(args: &BenchArgs, json: bool) -> Result<()> {
    match &args.kind {
        Some(BenchKind::Subdiv(sub)) => return crate::bench_subdiv::run(sub, json),
        Some(BenchKind::Calibrate(c)) => return crate::calibrate::run(c, json),
        Some(BenchKind::Implicit(imp)) => return crate::bench_implicit::run(imp, json),
        Some(BenchKind::Solid(solid)) => return crate::bench_solid::run(solid, json),
        Some(BenchKind::Measure(m)) => return crate::bench_measure::run(m, json),
        Some(BenchKind::Projective(p)) => return crate::bench_projective::run(p, json),
        Some(BenchKind::Whole(w)) => return crate::bench_whole::run(w, json),
        Some(BenchKind::Huang(h)) => return crate::bench_huang::run(h, json),
        Some(BenchKind::Openvdb(o)) => return crate::bench_whole::run_openvdb(o),
        None => {}
    }
    let data = data_folder(&args.data);
    let seps: Vec<Separability> = args
        .separability
        .iter()
        .map(|s| s.parse().map_err(Error::InvalidArgument))
        .collect::<Result<_>>()?;
    let mut rows = Vec::new();
    if !json {
        println!(
            "{:<14} {:>5} {:>3} {:>8} {:>3} {:>10} {:>11} {:>12} {:>11} {:>8}",
            "mesh",
            "res",
            "sep",
            "criterion",
            "thr",
            "ours s",
            "ours voxels",
            "openvdb s",
            "vdb voxels",
            "compute x"
        );
    }
    for name in &args.meshes {
        let path = resolve(name, &data, "meshes");
        let mesh = Mesh::load(&path)?;
        for &res in &args.resolutions {
            let transform = fit_transform(&mesh.bbox(), GridFit::Resolution(res))?;
            let (index_points, tris) = openvdb_mesh(&mesh, &transform);
            for &threads in &args.thread_counts {
                let pool = thread_pool(threads)?;
                let (vdb_s, vdb_voxels) = best_of(args.repeat, || {
                    openvdb_reference(
                        OpenVdbReference::Unsigned,
                        &index_points,
                        &tris,
                        transform.voxel_size,
                        1.0,
                        threads,
                    )
                })?;
                for (&sep, &criterion) in seps
                    .iter()
                    .flat_map(|s| args.criterion.iter().map(move |c| (s, c)))
                {
                    let opts = SeparatingOptions {
                        separability: sep,
                        criterion,
                        normals: false,
                    };
                    let (ours_s, voxels) = pool.install(|| {
                        best_of(args.repeat, || {
                            voxelize_mesh(
                                &mesh,
                                transform,
                                &opts,
                                &voxelkit::progress::Progress::none(),
                            )
                            .map(|(g, _)| g.voxel_count())
                        })
                    })?;
                    let speedup = vdb_s / ours_s;
                    if json {
                        rows.push(
                            Json::default()
                                .str("mesh", name.clone())
                                .int("resolution", res as u64)
                                .int("separability", sep.adjacency() as u64)
                                .str("criterion", criterion.name())
                                .int("threads", threads as u64)
                                .num("ours_seconds", ours_s)
                                .int("ours_voxels", voxels)
                                .num("openvdb_seconds", vdb_s)
                                .int("openvdb_voxels", vdb_voxels)
                                .num("speedup", speedup),
                        );
                    } else {
                        println!(
                            "{:<14} {:>5} {:>3} {:>8} {:>3} {:>10.4} {:>11} {:>12.4} {:>11} {:>7.2}x",
                            name,
                            res,
                            sep.adjacency(),
                            criterion.name(),
                            threads,
                            ours_s,
                            voxels,
                            vdb_s,
                            vdb_voxels,
                            speedup
                        );
                    }
                }
            }
        }
    }
    if json {
        println!("{}", Json::default().arr("runs", rows).render());
    } else {
        println!(
            "compute x: OpenVDB's compute over ours, both in this process (the separating voxelizer alone); the ratio a \
             user meets, file in and file on disk, is `voxelkit-bench whole`"
        );
    }
    Ok(())
}

//! `voxelkit-bench whole`: voxelkit as a user meets it — the whole `voxelkit` process, mesh
//! file in, `.vdb` on disk — against the cheapest OpenVDB call that gives the same output,
//! timed on its compute alone (the mesh already in memory) in a process of its own so that
//! both peaks are measured alike:
//! - `mesh`: the surface against `meshToUnsignedDistanceField` with a one-voxel band;
//! - `solid`: the solid against `meshToLevelSet` (half width 3) plus `sdfInteriorMask`;
//! - `sdf`: `mesh --sdf` against `meshToLevelSet` with the same band;
//! - `to-mesh`: `to-mesh` of the mesh's level set (made once beforehand by `mesh --sdf`), its
//!   `.vdb` in and a PLY on disk, against `volumeToMesh` (adaptivity 0) on the same grid
//!   already read; counts are triangles (OpenVDB's quads as two).

use crate::bench::data_folder;
use crate::json::{Json, Value};
use crate::openvdb_reference;
use clap::{Args, ValueEnum};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;
use voxelkit::mesh::{GridFit, Mesh, fit_transform};
use voxelkit::{Error, Result};
use voxelkit_openvdb::Reference as OpenVdbReference;

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum WholeTask {
    Mesh,
    Solid,
    Sdf,
    ToMesh,
}

impl WholeTask {
    /// The OpenVDB call that gives the same output, and its band in voxels.
    fn reference(self, band: f32) -> (OpenVdbReference, f32) {
        match self {
            WholeTask::Mesh => (OpenVdbReference::Unsigned, 1.0),
            WholeTask::Solid => (OpenVdbReference::Solid, 3.0),
            WholeTask::Sdf | WholeTask::ToMesh => (OpenVdbReference::LevelSet, band),
        }
    }

    /// The `voxelkit` arguments before the mesh, and after it.
    fn arguments(self, band: f32) -> (Vec<String>, Vec<String>) {
        match self {
            WholeTask::Mesh => (vec!["mesh".into()], vec![]),
            WholeTask::Solid => (vec!["solid".into()], vec![]),
            WholeTask::Sdf => (
                vec!["mesh".into()],
                vec!["--sdf".into(), "--band".into(), band.to_string()],
            ),
            WholeTask::ToMesh => (vec!["to-mesh".into()], vec![]),
        }
    }

    /// What the counts count.
    fn counted(self) -> &'static str {
        match self {
            WholeTask::ToMesh => "triangles",
            _ => "voxels",
        }
    }
}

#[derive(Args)]
pub struct WholeBenchArgs {
    /// What to compare.
    #[arg(long, value_enum, default_value = "solid")]
    task: WholeTask,
    /// Meshes: names in DATA/meshes (without .obj) or paths.
    #[arg(long, value_delimiter = ',', default_value = "bunny-closed,igea")]
    meshes: Vec<String>,
    /// Data folder holding meshes/ [default: $VOXELKIT_DATA or ../shared/data].
    #[arg(long)]
    data: Option<PathBuf>,
    #[arg(long, value_delimiter = ',', default_value = "256,1024")]
    resolutions: Vec<u32>,
    #[arg(long = "thread-counts", value_delimiter = ',', default_value = "1,2")]
    thread_counts: Vec<usize>,
    /// Half width of the level set's band in voxels (`--task sdf`).
    #[arg(long, default_value_t = 3.0)]
    band: f32,
    #[arg(long, default_value_t = 1)]
    repeat: usize,
}

/// `voxelkit-bench openvdb`: one OpenVDB reference in this process, for `whole` to time
/// and measure; prints `{"seconds", "voxels", "peak_mib"}` (`voxels`: triangles for
/// `to-mesh`).
#[derive(Args)]
pub struct OpenVdbRunArgs {
    #[arg(long, value_enum)]
    task: WholeTask,
    /// The mesh, or for `to-mesh` the level set's `.vdb` (its grid `surface`).
    #[arg(long)]
    mesh: PathBuf,
    #[arg(long)]
    resolution: u32,
    #[arg(long)]
    threads: usize,
    #[arg(long, default_value_t = 3.0)]
    band: f32,
}

pub fn run_openvdb(args: &OpenVdbRunArgs) -> Result<()> {
    let (seconds, voxels) = if args.task == WholeTask::ToMesh {
        let path = args.mesh.display().to_string();
        let failed = |message: String| Error::Vdb {
            path: args.mesh.clone(),
            message,
        };
        let grids = voxelkit_openvdb::OpenVdbGrids::read(&path).map_err(failed)?;
        let made = grids
            .volume_to_mesh("surface", 0.0, 0.0, args.threads)
            .map_err(failed)?;
        (made.seconds, made.triangles + 2 * made.quads)
    } else {
        let mesh = Mesh::load(&args.mesh)?;
        let t = fit_transform(&mesh.bbox(), GridFit::Resolution(args.resolution))?;
        let (points, tris) = crate::bench::openvdb_mesh(&mesh, &t);
        let (kind, band) = args.task.reference(args.band);
        let start = Instant::now();
        let voxels = openvdb_reference(kind, &points, &tris, t.voxel_size, band, args.threads)?;
        (start.elapsed().as_secs_f64(), voxels)
    };
    let peak = voxelkit::system::peak_memory_mib();
    println!(
        "{}",
        Json::default()
            .num("seconds", seconds)
            .int("voxels", voxels)
            .num("peak_mib", peak)
            .render()
    );
    Ok(())
}

/// Runs `exe` with `args`; its stdout as JSON, or an error with its stderr.
fn json_of(exe: &Path, args: &[String]) -> Result<serde_json::Value> {
    let run = Command::new(exe)
        .args(args)
        .output()
        .map_err(|e| Error::io(exe, e))?;
    if !run.status.success() {
        return Err(Error::Unsupported(format!(
            "{} {}: {}",
            exe.display(),
            args.join(" "),
            String::from_utf8_lossy(&run.stderr)
        )));
    }
    serde_json::from_slice(&run.stdout)
        .map_err(|e| Error::Unsupported(format!("{}'s report: {e}", exe.display())))
}

/// One `voxelkit` run in its own process: its wall-clock seconds, and its report plus
/// `file_bytes`.
fn ours(
    task: WholeTask,
    mesh: &Path,
    res: u32,
    threads: usize,
    band: f32,
) -> Result<(f64, serde_json::Value)> {
    let this = std::env::current_exe().map_err(|e| Error::io("voxelkit-bench", e))?;
    let extension = if task == WholeTask::ToMesh {
        "ply"
    } else {
        "vdb"
    };
    let out =
        std::env::temp_dir().join(format!("voxelkit-bench-{}.{extension}", std::process::id()));
    let (before, after) = task.arguments(band);
    let mut args: Vec<String> = vec!["--json".into(), "--threads".into(), threads.to_string()];
    args.extend(before);
    args.push(mesh.display().to_string());
    args.extend(after);
    if task != WholeTask::ToMesh {
        args.extend(["-r".into(), res.to_string()]);
    }
    args.extend(["-o".into(), out.display().to_string()]);
    let start = std::time::Instant::now();
    let mut report = json_of(&this.with_file_name("voxelkit"), &args)?;
    let seconds = start.elapsed().as_secs_f64();
    report["file_bytes"] = std::fs::metadata(&out).map(|m| m.len()).unwrap_or(0).into();
    // Removed outside the timed run: deleting the output is no part of making it.
    let _ = std::fs::remove_file(&out);
    Ok((seconds, report))
}

/// A run's stage profile from its report, as one line: each stage's seconds and threads
/// busy (stages under a millisecond left out).
fn stage_profile(stages: &serde_json::Value) -> String {
    let stages: Vec<String> = stages
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|stage| {
            let seconds = stage["seconds"].as_f64()?;
            (seconds >= 0.001).then(|| {
                format!(
                    "{} {seconds:.3} s ({:.1})",
                    stage["stage"].as_str().unwrap_or("?"),
                    stage["threads_busy"].as_f64().unwrap_or(f64::NAN)
                )
            })
        })
        .collect();
    format!("stages (seconds, threads busy): {}", stages.join(", "))
}

/// The level set of `mesh` at `res` by `voxelkit mesh --sdf`, for `to-mesh` to start from.
fn level_set(mesh: &Path, res: u32, band: f32) -> Result<PathBuf> {
    let this = std::env::current_exe().map_err(|e| Error::io("voxelkit-bench", e))?;
    let out = std::env::temp_dir().join(format!(
        "voxelkit-bench-level-set-{}.vdb",
        std::process::id()
    ));
    let (before, after) = WholeTask::Sdf.arguments(band);
    let mut args: Vec<String> = vec!["--json".into()];
    args.extend(before);
    args.push(mesh.display().to_string());
    args.extend(after);
    args.extend([
        "-r".into(),
        res.to_string(),
        "-o".into(),
        out.display().to_string(),
    ]);
    json_of(&this.with_file_name("voxelkit"), &args)?;
    Ok(out)
}

/// The OpenVDB reference in its own process: (compute seconds, voxels, peak MiB).
fn openvdb(
    task: WholeTask,
    mesh: &Path,
    res: u32,
    threads: usize,
    band: f32,
) -> Result<(f64, u64, f64)> {
    let this = std::env::current_exe().map_err(|e| Error::io("voxelkit-bench", e))?;
    let task_name = task
        .to_possible_value()
        .map(|v| v.get_name().to_string())
        .unwrap_or_default();
    let args: Vec<String> = [
        "openvdb",
        "--task",
        &task_name,
        "--mesh",
        &mesh.display().to_string(),
        "--resolution",
        &res.to_string(),
        "--threads",
        &threads.to_string(),
        "--band",
        &band.to_string(),
    ]
    .map(String::from)
    .to_vec();
    let j = json_of(&this, &args)?;
    Ok((
        j["seconds"].as_f64().unwrap_or(f64::NAN),
        j["voxels"].as_u64().unwrap_or(0),
        j["peak_mib"].as_f64().unwrap_or(0.0),
    ))
}

pub fn run(args: &WholeBenchArgs, json: bool) -> Result<()> {
    let data = data_folder(&args.data);
    let mut rows = Vec::new();
    if !json {
        println!(
            "{:<14} {:>5} {:>3} {:>8} {:>10} {:>7} {:>11} {:>11} {:>8} {:>9} {:>9}",
            "mesh",
            "res",
            "thr",
            "ours s",
            "openvdb s",
            "ratio",
            "ours vox",
            "vdb vox",
            "file MB",
            "peak MiB",
            "vdb MiB"
        );
    }
    for name in &args.meshes {
        let mesh = crate::bench::resolve(name, &data, "meshes");
        for &res in &args.resolutions {
            // `to-mesh` starts from the level set, made once and not timed.
            let level_set = (args.task == WholeTask::ToMesh)
                .then(|| level_set(&mesh, res, args.band))
                .transpose()?;
            let path = level_set.as_ref().unwrap_or(&mesh);
            for &threads in &args.thread_counts {
                let mut runs = (0..args.repeat.max(1))
                    .map(|_| ours(args.task, path, res, threads, args.band))
                    .collect::<Result<Vec<_>>>()?;
                runs.sort_by(|a, b| a.0.total_cmp(&b.0));
                let (ours_s, report) = runs.swap_remove(0);
                let mut reference = openvdb(args.task, path, res, threads, args.band)?;
                for _ in 1..args.repeat {
                    let again = openvdb(args.task, path, res, threads, args.band)?;
                    if again.0 < reference.0 {
                        reference = again;
                    }
                }
                let (vdb_s, vdb_voxels, vdb_peak) = reference;
                let voxels = report[args.task.counted()].as_u64().unwrap_or(0);
                let file_mb = report["file_bytes"].as_f64().unwrap_or(0.0) / 1e6;
                let peak = report["peak_mib"].as_f64().unwrap_or(0.0);
                if json {
                    rows.push(
                        Json::default()
                            .str(
                                "task",
                                args.task
                                    .to_possible_value()
                                    .map(|v| v.get_name().to_string())
                                    .unwrap_or_default(),
                            )
                            .str("mesh", name.clone())
                            .int("resolution", res as u64)
                            .int("threads", threads as u64)
                            .num("ours_seconds", ours_s)
                            .num("openvdb_seconds", vdb_s)
                            .num("ratio", vdb_s / ours_s)
                            .int("voxels", voxels)
                            .int("openvdb_voxels", vdb_voxels)
                            .num("file_mb", file_mb)
                            .num("peak_mib", peak)
                            .num("openvdb_peak_mib", vdb_peak)
                            .put("stages", Value::Raw(report["stages"].to_string())),
                    );
                } else {
                    println!(
                        "{name:<14} {res:>5} {threads:>3} {ours_s:>8.3} {vdb_s:>10.3} {:>6.2}x {voxels:>11} {vdb_voxels:>11} {file_mb:>8.1} {peak:>9.0} {vdb_peak:>9.0}",
                        vdb_s / ours_s
                    );
                    println!("  {}", stage_profile(&report["stages"]));
                }
            }
            if let Some(made) = &level_set {
                let _ = std::fs::remove_file(made);
            }
        }
    }
    if json {
        println!("{}", Json::default().arr("runs", rows).render());
    } else {
        let reference = match args.task {
            WholeTask::ToMesh => {
                "volumeToMesh (adaptivity 0) compute only, the grid already read; \
                                  counts: triangles"
                    .to_string()
            }
            task => format!(
                "{:?} compute only, the mesh already in memory",
                task.reference(args.band).0
            ),
        };
        println!(
            "ours: the whole voxelkit process (read, compute, write its output); openvdb: \
             {reference}; peaks: each process's maximum resident set; under each row, the stage \
             profile of our best run"
        );
    }
    Ok(())
}

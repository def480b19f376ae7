//! `voxelkit-bench levelset`: `voxelkit mesh --sdf` as a user meets it (the whole process,
//! OBJ in, `.vdb` on disk) against OpenVDB's `meshToLevelSet` with the same band, voxel size
//! and threads (its compute only: the mesh is already in memory), and the peak memory and
//! file size of ours.

use crate::bench::{best_of, data_folder};
use crate::json::Json;
use clap::Args;
use std::path::PathBuf;
use std::process::Command;
use voxelkit::io::vdb::openvdb_mesh_to_volume;
use voxelkit::mesh::{GridFit, Mesh, fit_transform};
use voxelkit::{Error, Result};

#[derive(Args)]
pub struct LevelSetBenchArgs {
    /// Meshes: names in DATA/meshes (without .obj) or paths.
    #[arg(long, value_delimiter = ',', default_value = "bunny-closed,igea")]
    meshes: Vec<String>,
    /// Data folder holding meshes/ [default: $VOXELKIT_DATA or ../shared/data].
    #[arg(long)]
    data: Option<PathBuf>,
    #[arg(long, value_delimiter = ',', default_value = "256,512,1024")]
    resolutions: Vec<u32>,
    #[arg(long = "thread-counts", value_delimiter = ',', default_value = "1,2")]
    thread_counts: Vec<usize>,
    /// Half width of the band in voxels.
    #[arg(long, default_value_t = 3.0)]
    band: f32,
    #[arg(long, default_value_t = 1)]
    repeat: usize,
}

/// `voxelkit mesh --sdf` in its own process: (seconds, its JSON report).
fn ours(mesh: &std::path::Path, res: u32, threads: usize, band: f32) -> Result<serde_json::Value> {
    let exe = std::env::current_exe()
        .map_err(|e| Error::io("voxelkit-bench", e))?
        .with_file_name("voxelkit");
    let out = std::env::temp_dir().join(format!("voxelkit-bench-{}.vdb", std::process::id()));
    let run = Command::new(&exe)
        .args(["--json", "--threads", &threads.to_string(), "mesh"])
        .arg(mesh)
        .args([
            "--sdf",
            "--band",
            &band.to_string(),
            "-r",
            &res.to_string(),
            "-o",
        ])
        .arg(&out)
        .output()
        .map_err(|e| Error::io(&exe, e))?;
    if !run.status.success() {
        return Err(Error::Unsupported(
            String::from_utf8_lossy(&run.stderr).into(),
        ));
    }
    let mut report: serde_json::Value = serde_json::from_slice(&run.stdout)
        .map_err(|e| Error::Unsupported(format!("voxelkit's report: {e}")))?;
    let size = std::fs::metadata(&out).map(|m| m.len()).unwrap_or(0);
    report["file_bytes"] = size.into();
    let _ = std::fs::remove_file(&out);
    Ok(report)
}

pub fn run(args: &LevelSetBenchArgs, json: bool) -> Result<()> {
    let data = data_folder(&args.data);
    let mut rows = Vec::new();
    if !json {
        println!(
            "{:<14} {:>5} {:>3} {:>10} {:>11} {:>8} {:>10} {:>9} {:>8}",
            "mesh", "res", "thr", "ours s", "openvdb s", "ratio", "voxels", "file MB", "peak MB"
        );
    }
    for name in &args.meshes {
        let path = crate::bench::resolve(name, &data, "meshes");
        let mesh = Mesh::load(&path)?;
        for &res in &args.resolutions {
            let t = fit_transform(&mesh.bbox(), GridFit::Resolution(res))?;
            let (points, tris) = crate::bench::openvdb_mesh(&mesh, &t);
            for &threads in &args.thread_counts {
                let (ours_s, report) =
                    best_of(args.repeat, || ours(&path, res, threads, args.band))?;
                let (vdb_s, vdb_voxels) = best_of(args.repeat, || {
                    openvdb_mesh_to_volume(
                        &points,
                        &tris,
                        t.voxel_size,
                        args.band,
                        args.band,
                        threads,
                    )
                })?;
                let voxels = report["voxels"].as_u64().unwrap_or(0);
                let file_mb = report["file_bytes"].as_f64().unwrap_or(0.0) / 1e6;
                let peak = report["peak_mib"].as_f64().unwrap_or(0.0);
                if json {
                    rows.push(
                        Json::default()
                            .str("mesh", name.clone())
                            .int("resolution", res as u64)
                            .int("threads", threads as u64)
                            .num("ours_seconds", ours_s)
                            .num("openvdb_seconds", vdb_s)
                            .num("ratio", vdb_s / ours_s)
                            .int("voxels", voxels)
                            .int("openvdb_voxels", vdb_voxels)
                            .num("file_mb", file_mb)
                            .num("peak_mib", peak),
                    );
                } else {
                    println!(
                        "{name:<14} {res:>5} {threads:>3} {ours_s:>10.3} {vdb_s:>11.3} {:>7.2}x {voxels:>10} {file_mb:>9.1} {peak:>8.0}",
                        vdb_s / ours_s
                    );
                }
            }
        }
    }
    if json {
        println!("{}", Json::default().arr("runs", rows).render());
    } else {
        println!(
            "ours: the whole `voxelkit mesh --sdf` process (read, distances, signs, write); \
             openvdb: meshToVolume with the same band outside and inside (meshToLevelSet), compute only"
        );
    }
    Ok(())
}

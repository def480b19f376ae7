//! `voxelkit-bench calibrate`: planning's memory estimates against the measured peaks of whole
//! `voxelkit` runs, family by family, with the factor each family's constants in
//! `src/pipeline/estimate.rs` need: the least-squares fit of the peaks above the process's
//! base (`pipeline::BASE_BYTES`) to the estimates above it. On the meshes the constants were
//! fitted on (the default) it refits them; on others (`--meshes scorpion,fandisk`) it checks
//! them.

use crate::bench::{data_folder, resolve};
use clap::Args;
use serde_json::{Value, json};
use std::path::{Path, PathBuf};
use std::process::Command;
use voxelkit::{Error, Result};

#[derive(Args)]
pub struct CalibrateArgs {
    /// Meshes: names in DATA/meshes (without .obj) or paths.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "bunny-closed,igea,horse,armadillo,skull"
    )]
    meshes: Vec<String>,
    /// Data folder holding meshes/ [default: $VOXELKIT_DATA or ../shared/data].
    #[arg(long)]
    data: Option<PathBuf>,
    #[arg(short, long, default_value_t = 1024)]
    resolution: u32,
    /// Families to run (default: all): surface, normals, solid, spans, beam, depth-layers,
    /// sdf, udf, check, measure, lines.
    #[arg(long, value_delimiter = ',')]
    families: Vec<String>,
}

/// A family of runs priced by the same constants: its name, the `voxelkit` arguments before
/// the mesh and the byte costs the fitted factor scales.
struct Family {
    name: &'static str,
    command: &'static [&'static str],
    constants: &'static str,
}

const FAMILIES: [Family; 11] = [
    Family {
        name: "surface",
        command: &["mesh"],
        constants: "MESH_LEAF_BYTES, TRIANGLE_BYTES",
    },
    Family {
        name: "normals",
        command: &["mesh", "--normals"],
        constants: "MESH_VECTOR_LEAF_BYTES",
    },
    Family {
        name: "solid",
        command: &["solid"],
        constants: "BLOCK_FLOOD_COST, FILLED_TRIANGLE_BYTES",
    },
    Family {
        name: "spans",
        command: &["solid", "--flood", "spans"],
        constants: "DENSE_FLOOD_COST",
    },
    Family {
        name: "beam",
        command: &["solid", "--method", "beam"],
        constants: "BEAM_COST",
    },
    Family {
        name: "depth-layers",
        command: &["solid", "--method", "depth-layers"],
        constants: "DEPTH_LAYERS_COST",
    },
    Family {
        name: "sdf",
        command: &["mesh", "--sdf"],
        constants: "SIGNED_BAND_LEAF_BYTES, BAND_TRIANGLE_BYTES",
    },
    Family {
        name: "udf",
        command: &["mesh", "--udf"],
        constants: "UNSIGNED_BAND_LEAF_BYTES, BAND_TRIANGLE_BYTES",
    },
    Family {
        name: "check",
        command: &["check"],
        constants: "CHECK_VOLUMES, CHECK_LEAF_BYTES",
    },
    Family {
        name: "measure",
        command: &["measure"],
        constants: "MEASURE_COST",
    },
    Family {
        name: "lines",
        command: &["lines"],
        constants: "LINE_TRIANGLE_BYTES (divide LINE_LENGTH_PER_LEAF)",
    },
];

/// (estimated, peak) MiB of one `voxelkit --json` run, each in its own process so that the
/// peak is the run's alone.
fn measure(family: &Family, mesh: &Path, resolution: u32, out: &Path) -> Result<(f64, f64)> {
    let exe = std::env::current_exe()
        .map_err(|e| Error::io("voxelkit-bench", e))?
        .with_file_name("voxelkit");
    let mut command = Command::new(&exe);
    command.arg("--json").args(family.command).arg(mesh);
    command.args(["-r", &resolution.to_string()]);
    if !matches!(family.command[0], "check" | "measure") {
        command.arg("-o").arg(out);
    }
    let run = command.output().map_err(|e| Error::io(&exe, e))?;
    let report: Value = serde_json::from_slice(&run.stdout).unwrap_or(Value::Null);
    if !run.status.success() {
        let why = report["error"].as_str().map_or_else(
            || String::from_utf8_lossy(&run.stderr).trim().to_string(),
            str::to_string,
        );
        return Err(Error::InvalidArgument(why));
    }
    let mib = |key: &str| {
        report[key]
            .as_f64()
            .ok_or_else(|| Error::InvalidArgument(format!("the report has no {key}")))
    };
    Ok((mib("estimated_mib")?, mib("peak_mib")?))
}

/// The factor on the estimates above `base` that best fits the peaks above it.
fn fitted_factor(pairs: &[(f64, f64)], base: f64) -> f64 {
    let (mut cross, mut square) = (0.0, 0.0);
    for &(estimated, peak) in pairs {
        cross += (peak - base) * (estimated - base);
        square += (estimated - base).powi(2);
    }
    if square > 0.0 { cross / square } else { 1.0 }
}

pub fn run(args: &CalibrateArgs, json_out: bool) -> Result<()> {
    let data = data_folder(&args.data);
    let base = voxelkit::pipeline::BASE_BYTES / f64::from(1u32 << 20);
    let chosen: Vec<&Family> = FAMILIES
        .iter()
        .filter(|f| args.families.is_empty() || args.families.iter().any(|n| n == f.name))
        .collect();
    if chosen.is_empty() {
        let names: Vec<&str> = FAMILIES.iter().map(|f| f.name).collect();
        return Err(Error::InvalidArgument(format!(
            "no such family; the families are {}",
            names.join(", ")
        )));
    }
    let out = std::env::temp_dir().join(format!("voxelkit-calibrate-{}.vdb", std::process::id()));
    let mut families = Vec::new();
    for family in chosen {
        let mut runs = Vec::new();
        let mut pairs = Vec::new();
        for name in &args.meshes {
            let mesh = resolve(name, &data, "meshes");
            eprint!("{} {name}: ", family.name);
            match measure(family, &mesh, args.resolution, &out) {
                Ok((estimated, peak)) => {
                    eprintln!("estimated {estimated:.0} MiB, peak {peak:.0} MiB");
                    pairs.push((estimated, peak));
                    runs.push(json!({"mesh": name, "estimated_mib": estimated,
                        "peak_mib": peak, "ratio": estimated / peak}));
                }
                Err(e) => {
                    eprintln!("not measured: {e}");
                    runs.push(json!({"mesh": name, "error": e.to_string()}));
                }
            }
        }
        let ratios: Vec<f64> = pairs.iter().map(|(e, p)| e / p).collect();
        let (lo, hi) = ratios.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &r| {
            (lo.min(r), hi.max(r))
        });
        families.push(json!({
            "family": family.name,
            "constants": family.constants,
            "runs": runs,
            "ratio_min": (!ratios.is_empty()).then_some(lo),
            "ratio_max": (!ratios.is_empty()).then_some(hi),
            "factor": (!pairs.is_empty()).then(|| fitted_factor(&pairs, base)),
        }));
    }
    let _ = std::fs::remove_file(&out);
    if json_out {
        println!(
            "{}",
            json!({"resolution": args.resolution, "families": families})
        );
        return Ok(());
    }
    println!(
        "estimate / peak at {}^3 over {} (factor: scale the family's byte costs by it)",
        args.resolution,
        args.meshes.join(", ")
    );
    println!(
        "{:<13} {:>11} {:>8}  constants",
        "family", "ratio", "factor"
    );
    for f in &families {
        let range = match (f["ratio_min"].as_f64(), f["ratio_max"].as_f64()) {
            (Some(lo), Some(hi)) => format!("{lo:.2}-{hi:.2}"),
            _ => "-".into(),
        };
        let factor = f["factor"]
            .as_f64()
            .map_or_else(|| "-".into(), |x| format!("{x:.3}"));
        println!(
            "{:<13} {range:>11} {factor:>8}  {}",
            f["family"].as_str().unwrap_or(""),
            f["constants"].as_str().unwrap_or("")
        );
    }
    Ok(())
}

//! `voxelkit-bench huang`: Huang et al.'s Tables 1–3 on the shared meshes. Table 1 describes each
//! mesh at the resolution (facets, average triangle area in world units and in voxel faces, the
//! size in voxels); Tables 2 and 3 give, for 6- and 26-separation, the voxels, the time, voxels
//! per millisecond and the voxels by class (vertex spheres, edge cylinders, face bodies, each
//! voxel counted in the first class that holds it, as the paper classifies). The paper's own
//! rows (512^3, a 195 MHz R10000, its four mechanical parts) are printed below for comparison.

use crate::bench::{best_of, data_folder, resolve, thread_pool};
use crate::json::Json;
use clap::Args;
use std::path::PathBuf;
use voxelkit::Result;
use voxelkit::mesh::{GridFit, Mesh, fit_transform, index_box};
use voxelkit::progress::Progress;
use voxelkit::voxelize::Separability;
use voxelkit::voxelize::separating::{Criterion, SeparatingOptions, voxelize_mesh};

#[derive(Args)]
pub struct HuangBenchArgs {
    /// Meshes (names in DATA/meshes or paths): two mechanical parts and two scans by default.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "fandisk,rocker-arm,bunny-closed,igea"
    )]
    meshes: Vec<String>,
    /// Data folder holding meshes/ [default: $VOXELKIT_DATA or ../shared/data].
    #[arg(long)]
    data: Option<PathBuf>,
    /// Voxels along each mesh's longest side (the paper's volume is 512^3).
    #[arg(long, default_value_t = 512)]
    resolution: u32,
    /// Threads (the paper ran on one processor).
    #[arg(long, default_value_t = 1)]
    threads: usize,
    /// Runs per measurement; the fastest is reported.
    #[arg(long, default_value_t = 3)]
    repeat: usize,
}

/// The paper's Table 1: part, facets, average triangle area, the same in voxel faces, size in
/// voxels.
const PAPER_SETUP: [(&str, u64, f64, f64, [u64; 3]); 4] = [
    ("Connector", 242, 0.4, 1371.6, [406, 118, 171]),
    ("Brevi", 1812, 3.7, 102.4, [200, 183, 503]),
    ("Bowl", 328, 21.0, 199.4, [512, 250, 490]),
    ("Pump", 3030, 7.7, 72.9, [506, 368, 435]),
];

/// The paper's Tables 2 (6-separation) and 3 (26-separation): part, voxels (1000s), seconds,
/// voxels per ms, vertex voxels, edge and body voxels (1000s).
type PaperRow = (&'static str, f64, f64, f64, f64, f64, f64);
const PAPER_RESULTS: [(u32, [PaperRow; 4]); 2] = [
    (
        6,
        [
            ("Connector", 220.0, 4.7, 46.4, 63.0, 16.0, 204.0),
            ("Brevi", 466.0, 12.7, 36.7, 524.0, 75.0, 391.0),
            ("Bowl", 839.0, 33.3, 25.1, 112.0, 46.0, 794.0),
            ("Pump", 1483.0, 67.8, 21.8, 983.0, 163.0, 1320.0),
        ],
    ),
    (
        26,
        [
            ("Connector", 270.0, 6.5, 41.1, 309.0, 44.0, 226.0),
            ("Brevi", 636.0, 18.2, 35.0, 2290.0, 187.0, 447.0),
            ("Bowl", 1115.0, 44.7, 24.9, 407.0, 119.0, 995.0),
            ("Pump", 2019.0, 95.4, 21.2, 3729.0, 418.0, 1597.0),
        ],
    ),
];

/// One mesh's row of Table 1.
struct Setup {
    name: String,
    mesh: Mesh,
    transform: voxelkit::grid::Transform,
    mean_area: f64,
    size: [u64; 3],
}

pub fn run(args: &HuangBenchArgs, json: bool) -> Result<()> {
    let data = data_folder(&args.data);
    let pool = thread_pool(args.threads)?;
    let setups: Vec<Setup> = args
        .meshes
        .iter()
        .map(|name| {
            let mesh = Mesh::load(&resolve(name, &data, "meshes"))?;
            let transform = fit_transform(&mesh.bbox(), GridFit::Resolution(args.resolution))?;
            let mean_area = mesh.area() / mesh.triangle_count().max(1) as f64;
            let size = index_box(&mesh.bbox(), &transform).dim();
            Ok(Setup {
                name: name.clone(),
                mesh,
                transform,
                mean_area,
                size,
            })
        })
        .collect::<Result<_>>()?;
    let mut rows = Vec::new();
    if !json {
        println!(
            "Table 1: experiment set-up at {}^3 (ours)\n{:<14} {:>9} {:>12} {:>16} {:>18}",
            args.resolution, "mesh", "facets", "avg tri area", "avg tri in VS", "size (x, y, z)"
        );
        for s in &setups {
            let in_voxels = s.mean_area / s.transform.voxel_size.powi(2);
            println!(
                "{:<14} {:>9} {:>12.3e} {:>16.2} {:>18}",
                s.name,
                s.mesh.triangle_count(),
                s.mean_area,
                in_voxels,
                format!("{}, {}, {}", s.size[0], s.size[1], s.size[2])
            );
        }
    }
    for (table, sep) in [(2, Separability::Six), (3, Separability::TwentySix)] {
        if !json {
            println!(
                "\nTable {table}: {}-separation, {} thread(s), best of {}\n{:<14} {:>14} {:>10} {:>14} {:>10} {:>14} {:>14}",
                sep.adjacency(),
                args.threads,
                args.repeat,
                "mesh",
                "voxels (1000s)",
                "seconds",
                "voxels per ms",
                "S_v",
                "S_e (1000s)",
                "S_b (1000s)"
            );
        }
        for s in &setups {
            let options = SeparatingOptions {
                separability: sep,
                criterion: Criterion::Huang,
                normals: false,
            };
            let (seconds, stats) = pool.install(|| {
                best_of(args.repeat, || {
                    voxelize_mesh(&s.mesh, s.transform, &options, &Progress::none())
                        .map(|(_, stats)| stats)
                })
            })?;
            let voxels = stats.total_voxels();
            let per_ms = voxels as f64 / (seconds * 1e3);
            if json {
                rows.push(
                    Json::default()
                        .str("mesh", s.name.as_str())
                        .int("resolution", args.resolution as u64)
                        .int("facets", s.mesh.triangle_count() as u64)
                        .num("mean_triangle_area", s.mean_area)
                        .num(
                            "mean_triangle_voxel_faces",
                            s.mean_area / s.transform.voxel_size.powi(2),
                        )
                        .int("separability", sep.adjacency() as u64)
                        .int("threads", args.threads as u64)
                        .int("voxels", voxels)
                        .num("seconds", seconds)
                        .num("voxels_per_ms", per_ms)
                        .int("vertex_voxels", stats.vertex_voxels)
                        .int("edge_voxels", stats.edge_voxels)
                        .int("body_voxels", stats.body_voxels),
                );
            } else {
                println!(
                    "{:<14} {:>14.0} {:>10.3} {:>14.0} {:>10} {:>14.0} {:>14.0}",
                    s.name,
                    voxels as f64 / 1e3,
                    seconds,
                    per_ms,
                    stats.vertex_voxels,
                    stats.edge_voxels as f64 / 1e3,
                    stats.body_voxels as f64 / 1e3
                );
            }
        }
    }
    if json {
        println!("{}", Json::default().arr("rows", rows).render());
    } else {
        print_paper();
    }
    Ok(())
}

/// The paper's tables, as printed in it, for comparison.
fn print_paper() {
    println!("\nThe paper's Table 1 (512^3):");
    for (part, facets, area, in_voxels, size) in PAPER_SETUP {
        println!(
            "{part:<14} {facets:>9} {area:>12} {in_voxels:>16} {:>18}",
            format!("{}, {}, {}", size[0], size[1], size[2])
        );
    }
    for (sep, rows) in PAPER_RESULTS {
        println!(
            "The paper's Table {} ({sep}-separation, 195 MHz R10000):",
            if sep == 6 { 2 } else { 3 }
        );
        for (part, voxels, seconds, per_ms, sv, se, sb) in rows {
            println!(
                "{part:<14} {voxels:>14} {seconds:>10} {per_ms:>14} {sv:>10} {se:>14} {sb:>14}"
            );
        }
    }
    println!("S_v counts voxels, S_e and S_b thousands of voxels, as in the paper");
}

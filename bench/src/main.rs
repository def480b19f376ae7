//! `voxelkit-bench`: voxelkit against OpenVDB (and the papers' figures) on the same meshes,
//! voxel sizes and thread counts, in the same process. Kept out of the `voxelkit` binary so
//! that the command line stays a thin front end.

mod bench;
mod bench_huang;
mod bench_implicit;
mod bench_measure;
mod bench_projective;
mod bench_solid;
mod bench_subdiv;
mod bench_whole;
mod calibrate;
mod json;

use clap::Parser;
use std::process::ExitCode;
use voxelkit::voxelize::separating::Criterion;

#[derive(Parser)]
#[command(
    name = "voxelkit-bench",
    version,
    about = "Benchmark voxelkit against OpenVDB's meshToUnsignedDistanceField with a one-voxel band, \
             in the same run (`whole`: the whole voxelkit process against OpenVDB; `subdiv`: the \
             Catmull-Clark voxelizer; `implicit`: the interval octree; `solid`: filled solids; \
             `measure`: volume convergence; `projective`: triangles/s; `calibrate`: memory estimates \
             against peaks; `huang`: the paper's Tables 1-3)"
)]
struct Cli {
    /// Print one JSON object instead of the tables.
    #[arg(long, global = true)]
    json: bool,
    #[command(flatten)]
    args: bench::BenchArgs,
}

pub fn parse_criterion(s: &str) -> Result<Criterion, String> {
    s.parse()
}

/// OpenVDB's conversion `kind` of a mesh in index space (`voxelkit_openvdb::reference`), its
/// errors as voxelkit's.
pub fn openvdb_reference(
    kind: voxelkit_openvdb::Reference,
    index_points: &[f32],
    triangles: &[u32],
    voxel_size: f64,
    band: f32,
    threads: usize,
) -> voxelkit::Result<u64> {
    voxelkit_openvdb::reference(kind, index_points, triangles, voxel_size, band, threads).map_err(
        |message| voxelkit::Error::Vdb {
            path: "<OpenVDB>".into(),
            message,
        },
    )
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match bench::run(&cli.args, cli.json) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

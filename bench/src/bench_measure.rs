//! `voxelkit bench measure`: how voxel volumes and areas converge on solids with known values
//! (a sphere, a torus and a turned cube, as formulas), and depth-layer volumes of closed real
//! meshes against each mesh's own signed volume.

use crate::bench::{data_folder, resolve, thread_pool};
use crate::json::Json;
use clap::Args;
use std::path::PathBuf;
use std::time::Instant;
use voxelkit::Result;
use voxelkit::implicit::reference::reference_solids;
use voxelkit::mesh::{GridFit, Mesh, fit_transform, index_box};
use voxelkit::solids::csg_leaves::measure_formula_solid;
use voxelkit::solids::depth_layers::{DepthLayerOptions, DirectionSet, depth_layer_solid};

#[derive(Args)]
pub struct MeasureBenchArgs {
    #[arg(long, value_delimiter = ',', default_value = "64,128,256,512,1024")]
    resolutions: Vec<u32>,
    /// Closed meshes for the signed-volume rows (names in DATA/meshes or paths).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "bunny-closed,armadillo,skull,horse"
    )]
    meshes: Vec<String>,
    /// Resolutions for the mesh rows.
    #[arg(long, value_delimiter = ',', default_value = "128,256,512")]
    mesh_resolutions: Vec<u32>,
    /// Data folder holding meshes/ [default: $VOXELKIT_DATA or ../shared/data].
    #[arg(long)]
    data: Option<PathBuf>,
    #[arg(long, default_value_t = 2)]
    threads: usize,
}

pub fn run(args: &MeasureBenchArgs, json: bool) -> Result<()> {
    let pool = thread_pool(args.threads)?;
    let mut rows = Vec::new();
    if !json {
        println!(
            "{:<12} {:>5} {:>12} {:>12} {:>9} {:>12} {:>12} {:>9} {:>8}",
            "solid", "res", "volume", "exact", "error", "area", "exact", "error", "s"
        );
    }
    for shape in reference_solids() {
        for &resolution in &args.resolutions {
            let start = Instant::now();
            let (volume, area) =
                pool.install(|| measure_formula_solid(&shape.formula, &shape.bounds, resolution))?;
            let seconds = start.elapsed().as_secs_f64();
            let ev = (volume - shape.volume) / shape.volume;
            let ea = (area - shape.area) / shape.area;
            if json {
                rows.push(
                    Json::default()
                        .str("solid", shape.name)
                        .int("resolution", resolution as u64)
                        .num("volume", volume)
                        .num("exact_volume", shape.volume)
                        .num("area", area)
                        .num("exact_area", shape.area)
                        .num("seconds", seconds),
                );
            } else {
                println!(
                    "{:<12} {resolution:>5} {volume:>12.6} {:>12.6} {ev:>9.1e} {area:>12.6} {:>12.6} {ea:>9.1e} {seconds:>8.2}",
                    shape.name, shape.volume, shape.area
                );
            }
        }
    }
    let data = data_folder(&args.data);
    if !json {
        println!(
            "\n{:<14} {:>5} {:>14} {:>14} {:>9}   (depth layers, 16 directions)",
            "mesh", "res", "volume", "signed volume", "error"
        );
    }
    for name in &args.meshes {
        let mesh = Mesh::load(&resolve(name, &data, "meshes"))?;
        let exact = mesh.signed_volume().abs();
        for &resolution in &args.mesh_resolutions {
            let t = fit_transform(&mesh.bbox(), GridFit::Resolution(resolution))?;
            let options = DepthLayerOptions {
                directions: DirectionSet::ALL,
                ..Default::default()
            };
            let s = pool.install(|| {
                depth_layer_solid(
                    &mesh,
                    &t,
                    index_box(&mesh.bbox(), &t),
                    &options,
                    &voxelkit::progress::Progress::none(),
                )
            })?;
            let volume = s.stats.inside_voxels as f64 * t.voxel_size.powi(3);
            let error = (volume - exact) / exact;
            if json {
                rows.push(
                    Json::default()
                        .str("mesh", name.as_str())
                        .int("resolution", resolution as u64)
                        .num("volume", volume)
                        .num("signed_volume", exact)
                        .int("unclassified", s.stats.unclassified_voxels),
                );
            } else {
                println!("{name:<14} {resolution:>5} {volume:>14.8} {exact:>14.8} {error:>9.1e}");
            }
        }
    }
    if json {
        println!("{}", Json::default().arr("rows", rows).render());
    }
    Ok(())
}

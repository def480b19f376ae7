//! `voxelkit bench solid`: solids at 512^3 and 1024^3 — our surface plus exterior flood (span
//! flood, and Lai & Cheng's FloodingXYZ), the paper's linear flooding on small sizes, and
//! OpenVDB's own solid (meshToLevelSet with its default half width of 3, then
//! sdfInteriorMask) on the same mesh, voxel size and thread count, in the same process.

use crate::bench::{best_of, data_folder};
use crate::json::Json;
use crate::openvdb_reference;
use clap::Args;
use std::path::PathBuf;
use voxelkit::Result;
use voxelkit::grid::DenseMask;
use voxelkit::mesh::{GridFit, Mesh, fit_transform};
use voxelkit::ops::flood::padded;
use voxelkit::ops::flood_linear::flood_linear;
use voxelkit::solids::exterior_flood::{FloodMethod, solid_from_surface};
use voxelkit::voxelize::Separability;
use voxelkit::voxelize::separating::{SeparatingOptions, voxelize_mesh};
use voxelkit_openvdb::Reference as OpenVdbReference;

#[derive(Args)]
pub struct SolidBenchArgs {
    /// Meshes: names in DATA/meshes (without .obj) or paths.
    #[arg(long, value_delimiter = ',', default_value = "bunny-closed")]
    meshes: Vec<String>,
    /// Data folder holding meshes/ [default: $VOXELKIT_DATA or ../shared/data].
    #[arg(long)]
    data: Option<PathBuf>,
    #[arg(long, value_delimiter = ',', default_value = "128,512,1024")]
    resolutions: Vec<u32>,
    /// Largest resolution at which the linear flooding baseline runs (it is slow).
    #[arg(long, default_value_t = 128)]
    linear_up_to: u32,
    /// GRAYSTACK capacity for FloodingXYZ.
    #[arg(long, default_value_t = 1 << 20)]
    graystack: usize,
    #[arg(long, default_value_t = 2)]
    threads: usize,
    #[arg(long, default_value_t = 1)]
    repeat: usize,
}

pub fn run(args: &SolidBenchArgs, json: bool) -> Result<()> {
    let data = data_folder(&args.data);
    let pool = crate::bench::thread_pool(args.threads)?;
    let mut rows = Vec::new();
    if !json {
        println!(
            "{:<14} {:>5} {:>10} {:>9} {:>9} {:>9} {:>10} {:>10} {:>12} {:>8}",
            "mesh",
            "res",
            "surface s",
            "spans s",
            "xyz s",
            "linear s",
            "ours s",
            "openvdb s",
            "solid voxels",
            "compute x"
        );
    }
    for name in &args.meshes {
        let path = crate::bench::resolve(name, &data, "meshes");
        let mesh = Mesh::load(&path)?;
        for &res in &args.resolutions {
            let t = fit_transform(&mesh.bbox(), GridFit::Resolution(res))?;
            let options = SeparatingOptions {
                separability: Separability::TwentySix,
                ..Default::default()
            };
            let (surface_s, surface) = pool.install(|| {
                best_of(args.repeat, || {
                    voxelize_mesh(&mesh, t, &options, &voxelkit::progress::Progress::none())
                        .map(|r| r.0)
                })
            })?;
            let (spans_s, solid) = best_of(args.repeat, || {
                solid_from_surface(
                    &surface,
                    FloodMethod::Spans,
                    &voxelkit::progress::Progress::none(),
                )
            })?;
            let (xyz_s, _) = best_of(args.repeat, || {
                solid_from_surface(
                    &surface,
                    FloodMethod::Xyz {
                        capacity: args.graystack,
                    },
                    &voxelkit::progress::Progress::none(),
                )
            })?;
            let linear_s = if res <= args.linear_up_to {
                let bbox = padded(surface.bbox().expect("a surface"), 2);
                let blocked = DenseMask::from_grid(&surface, bbox)?;
                Some(best_of(args.repeat, || flood_linear(&blocked, &[bbox.min]))?.0)
            } else {
                None
            };
            let (points, tris) = crate::bench::openvdb_mesh(&mesh, &t);
            let (vdb_s, vdb_voxels) = best_of(args.repeat, || {
                openvdb_reference(
                    OpenVdbReference::Solid,
                    &points,
                    &tris,
                    t.voxel_size,
                    3.0,
                    args.threads,
                )
            })?;
            let ours = surface_s + spans_s;
            let voxels = solid.measures.inside_voxels + solid.measures.surface_voxels;
            if json {
                let mut j = Json::default()
                    .str("mesh", name.clone())
                    .int("resolution", res as u64)
                    .num("surface_seconds", surface_s)
                    .num("span_flood_seconds", spans_s)
                    .num("xyz_flood_seconds", xyz_s)
                    .num("ours_seconds", ours)
                    .num("openvdb_seconds", vdb_s)
                    .int("solid_voxels", voxels)
                    .int("openvdb_voxels", vdb_voxels)
                    .num("speedup", vdb_s / ours);
                if let Some(l) = linear_s {
                    j = j.num("linear_flood_seconds", l);
                }
                rows.push(j);
            } else {
                println!(
                    "{:<14} {:>5} {:>10.3} {:>9.3} {:>9.3} {:>9} {:>10.3} {:>10.3} {:>12} {:>7.2}x",
                    name,
                    res,
                    surface_s,
                    spans_s,
                    xyz_s,
                    linear_s.map_or("-".into(), |l| format!("{l:.3}")),
                    ours,
                    vdb_s,
                    voxels,
                    vdb_s / ours
                );
            }
        }
    }
    if json {
        println!("{}", Json::default().arr("runs", rows).render());
    } else {
        println!(
            "compute x: OpenVDB's compute over ours, both in this process (surface plus flood alone); the ratio a \
             user meets, file in and file on disk, is `voxelkit-bench whole`"
        );
    }
    Ok(())
}

//! The parametric voxelizer (Lai & Cheng §4) on the closed control meshes of the data folder:
//! separability by flooding, accuracy (eqs. 3-4) by dense sampling, area against Gauss
//! quadrature, and the opposite-normal marking of §6.1.

mod common;

use glam::DVec3;
use std::path::Path;
use voxelkit::grid::{Adjacency, Transform};
use voxelkit::mesh::{GridFit, fit_transform, generate};
use voxelkit::ops::separability::check_mesh_separation;
use voxelkit::subd::{ControlMesh, LimitSurface, limit_area};
use voxelkit::voxelize::parametric::{ParametricOptions, ParametricOutput, voxelize_subdivision};

const CLOSED_CONTROL_MESHES: [&str; 7] = [
    "spot_control_mesh",
    "fish_control_mesh",
    "penguin_control_mesh",
    "catmark_cube",
    "catmark_torus",
    "catmark_toroidal_tet",
    "beast",
];

fn load(data: &Path, name: &str) -> ControlMesh {
    ControlMesh::load(&data.join(format!("subd/{name}.obj"))).unwrap()
}

fn voxelize(
    control: &ControlMesh,
    resolution: u32,
    adjacency: Adjacency,
    enclose: bool,
) -> (ParametricOutput, Transform) {
    let t = fit_transform(
        &control.polygon_mesh().bbox(),
        GridFit::Resolution(resolution),
    )
    .unwrap();
    let options = ParametricOptions {
        adjacency,
        enclose,
        ..Default::default()
    };
    (
        voxelize_subdivision(control, t, &options, &|_| {}).unwrap(),
        t,
    )
}

#[test]
fn closed_surfaces_separate_at_every_adjacency() {
    let Some(data) = common::data_dir() else {
        return;
    };
    for name in CLOSED_CONTROL_MESHES {
        let control = load(&data, name);
        let surface = LimitSurface::new(control.clone());
        for resolution in [64, 128, 256] {
            // A polygon approximation far finer than a voxel decides inside and outside.
            let segments =
                (4.0 * resolution as f64 / (surface.patch_count() as f64).sqrt()).ceil() as usize;
            let polygons = surface.tessellate(segments.clamp(2, 32));
            // The paper proves 6-separability for every N (§5): a sheet can clip the corner of a
            // voxel that no sample lands in, so 26-paths may pass. The enclosed output holds
            // every voxel the surface touches and blocks 26-paths too.
            let runs = [
                (Adjacency::Six, false, Adjacency::Six),
                (Adjacency::Eighteen, false, Adjacency::Six),
                (Adjacency::TwentySix, false, Adjacency::Six),
                (Adjacency::TwentySix, true, Adjacency::TwentySix),
            ];
            for (adjacency, enclose, flood) in runs {
                let (out, _) = voxelize(&control, resolution, adjacency, enclose);
                let report = check_mesh_separation(&out.surface, &polygons, flood).unwrap();
                eprintln!(
                    "{name} {resolution} N={}{}: {} voxels, flood {}: {} leaked of {} inside centres",
                    adjacency.number(),
                    if enclose { " enclosed" } else { "" },
                    out.stats.voxels,
                    flood.number(),
                    report.leaked,
                    report.inside_centres
                );
                assert!(
                    report.inside_empty > 0,
                    "{name}: nothing inside to leak into"
                );
                assert!(
                    report.separates(),
                    "{name} {resolution} N={}: leaked at {:?}",
                    adjacency.number(),
                    report.first_leak
                );
            }
        }
    }
}

//! Separability by flooding (Huang et al.): for every closed mesh of the shared data and for
//! random closed meshes, the exterior flood through empty voxels — 6-connected for the
//! 6-separating surface, 26-connected for the 26-separating one — reaches no voxel whose
//! centre lies inside the mesh.
#![cfg(feature = "fixtures")]

mod common;

use proptest::prelude::*;
use voxelkit::mesh::{Mesh, generate};
use voxelkit::ops::separability::check_mesh_separation;
use voxelkit::voxelize::Separability;
use voxelkit::voxelize::separating::{Criterion, SeparatingOptions};

/// Voxelizes and floods; panics with a diagnosis when the flood leaks.
fn assert_separates(mesh: &Mesh, resolution: u32, sep: Separability) {
    for criterion in [Criterion::Huang, Criterion::Clipped] {
        assert_separates_with(mesh, resolution, sep, criterion);
    }
}

fn assert_separates_with(mesh: &Mesh, resolution: u32, sep: Separability, criterion: Criterion) {
    let opts = SeparatingOptions {
        separability: sep,
        criterion,
        normals: false,
    };
    let (grid, stats) = common::voxelize_at(mesh, resolution, opts);
    let report = check_mesh_separation(&grid, mesh, sep.flood_adjacency()).unwrap();
    assert!(
        report.inside_empty > 0,
        "{}: no empty inside voxel at {resolution}: vacuous test",
        mesh.source.display()
    );
    assert!(report.exterior > 0);
    assert!(
        report.separates(),
        "{} at {resolution}, {}-separating ({criterion:?}): flood leaked into {} inside voxels, e.g. {:?} ({} voxels, {:?})",
        mesh.source.display(),
        sep.adjacency(),
        report.leaked,
        report.first_leak,
        grid.voxel_count(),
        stats
    );
    assert_eq!(stats.total_voxels(), grid.voxel_count());
}

#[test]
fn closed_data_meshes_are_separated_at_64_128_256() {
    let Some(data) = common::data_dir() else {
        return;
    };
    for name in common::CLOSED_MESHES {
        let mesh = Mesh::load(&data.join("meshes").join(format!("{name}.obj"))).unwrap();
        for resolution in [64, 128, 256] {
            for sep in [Separability::Six, Separability::TwentySix] {
                assert_separates(&mesh, resolution, sep);
            }
        }
    }
}

#[test]
fn generated_fixtures_are_separated() {
    let fixtures = [
        generate::icosphere(glam::DVec3::ZERO, 1.0, 3),
        generate::torus(glam::DVec3::ZERO, 1.0, 0.3, 48, 16),
        generate::cuboid(glam::DVec3::ZERO, glam::DVec3::new(1.0, 0.7, 0.3)),
        generate::g_shape(),
        generate::trefoil(1.0, 0.45, 192, 16),
    ];
    for mesh in &fixtures {
        for resolution in [16, 37, 80] {
            for sep in [Separability::Six, Separability::TwentySix] {
                assert_separates(mesh, resolution, sep);
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    #[test]
    fn random_closed_meshes_are_separated(seed in any::<u64>(), resolution in 12u32..96, six in any::<bool>()) {
        let mesh = generate::random_closed(seed);
        let sep = if six { Separability::Six } else { Separability::TwentySix };
        assert_separates(&mesh, resolution, sep);
    }
}

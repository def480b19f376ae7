//! Minimality (Huang et al. §3): the share of N-simple voxels (removable without opening an
//! N-hole, local 3x3x3 test). The paper's full spheres and cylinders leave some; the
//! clipped criterion must leave fewer, and few.
#![cfg(feature = "fixtures")]

mod common;

use voxelkit::mesh::{Mesh, generate};
use voxelkit::ops::minimality::simple_voxel_count;
use voxelkit::voxelize::Separability;
use voxelkit::voxelize::separating::{Criterion, SeparatingOptions};

fn simple_share(mesh: &Mesh, resolution: u32, sep: Separability, criterion: Criterion) -> f64 {
    let opts = SeparatingOptions {
        separability: sep,
        criterion,
        normals: false,
    };
    let (grid, _) = common::voxelize_at(mesh, resolution, opts);
    simple_voxel_count(&grid, sep.flood_adjacency()).unwrap() as f64 / grid.voxel_count() as f64
}

fn assert_clipped_is_nearly_minimal(mesh: &Mesh, resolution: u32, limit: f64) {
    for sep in [Separability::Six, Separability::TwentySix] {
        let huang = simple_share(mesh, resolution, sep, Criterion::Huang);
        let clipped = simple_share(mesh, resolution, sep, Criterion::Clipped);
        assert!(
            clipped < huang,
            "{}: clipped {clipped} vs huang {huang}",
            mesh.source.display()
        );
        assert!(
            clipped < limit,
            "{} {sep:?}: {:.2}% simple",
            mesh.source.display(),
            100.0 * clipped
        );
    }
}

#[test]
fn a_sphere_is_almost_minimal() {
    let mesh = generate::icosphere(glam::DVec3::new(0.1, 0.2, 0.3), 1.0, 5);
    assert_clipped_is_nearly_minimal(&mesh, 128, 0.02);
}

#[test]
fn closed_data_meshes_at_256_have_few_simple_voxels() {
    let Some(data) = common::data_dir() else {
        return;
    };
    for name in common::CLOSED_MESHES {
        let mesh = Mesh::load(&data.join("meshes").join(format!("{name}.obj"))).unwrap();
        assert_clipped_is_nearly_minimal(&mesh, 256, 0.12);
    }
}

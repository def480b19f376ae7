//! Mesh formats beside OBJ: every mesh of the shared data, converted to OFF by the test, reads
//! back to the same positions and faces and voxelizes to exactly the OBJ's voxel set.
#![cfg(feature = "fixtures")]

mod common;

use voxelkit::mesh::Mesh;
use voxelkit::voxelize::separating::SeparatingOptions;

#[test]
fn off_conversions_of_the_shared_meshes_voxelize_like_their_obj() {
    let Some(data) = common::data_dir() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let names = common::shared_meshes(&data);
    assert!(names.len() >= 10);
    for obj in names {
        let mesh = Mesh::load(&obj).unwrap();
        let off = dir
            .path()
            .join(obj.file_stem().unwrap())
            .with_extension("off");
        mesh.write_off(&off).unwrap();
        let back = Mesh::load(&off).unwrap();
        assert_eq!(back.positions, mesh.positions, "{}", obj.display());
        assert_eq!(back.indices, mesh.indices, "{}", obj.display());
        assert_eq!(back.face_starts, mesh.face_starts, "{}", obj.display());
        let (a, _) = common::voxelize_at(&mesh, 64, SeparatingOptions::default());
        let (b, _) = common::voxelize_at(&back, 64, SeparatingOptions::default());
        assert_eq!(a.voxel_count(), b.voxel_count(), "{}", obj.display());
        assert!(a.voxels().all(|c| b.contains(c)), "{}", obj.display());
    }
}

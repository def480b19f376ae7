//! Mesh formats beside OBJ: every mesh of the shared data, converted by the test to OFF and to
//! PLY (ASCII and binary), reads back to the same positions and faces and voxelizes to
//! exactly the OBJ's voxel set.
#![cfg(feature = "fixtures")]

mod common;

use voxelkit::mesh::Mesh;
use voxelkit::voxelize::separating::SeparatingOptions;

#[test]
fn off_and_ply_conversions_of_the_shared_meshes_voxelize_like_their_obj() {
    let Some(data) = common::data_dir() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let names = common::shared_meshes(&data);
    assert!(names.len() >= 10);
    for obj in names {
        let mesh = Mesh::load(&obj).unwrap();
        let (a, _) = common::voxelize_at(&mesh, 64, SeparatingOptions::default());
        let stem = dir.path().join(obj.file_stem().unwrap());
        let (off, ascii, binary) = (
            stem.with_extension("off"),
            stem.with_extension("ascii.ply"),
            stem.with_extension("ply"),
        );
        mesh.write_off(&off).unwrap();
        mesh.write_ply(&ascii, false).unwrap();
        mesh.write_ply(&binary, true).unwrap();
        for converted in [off, ascii, binary] {
            let what = converted.display();
            let back = Mesh::load(&converted).unwrap();
            assert_eq!(back.positions, mesh.positions, "{what}");
            assert_eq!(back.indices, mesh.indices, "{what}");
            assert_eq!(back.face_starts, mesh.face_starts, "{what}");
            let (b, _) = common::voxelize_at(&back, 64, SeparatingOptions::default());
            assert_eq!(a.voxel_count(), b.voxel_count(), "{what}");
            assert!(a.voxels().all(|c| b.contains(c)), "{what}");
        }
    }
}

/// A PLY file's vertex colours arrive as the mesh's colours; damaged PLY files are refused
/// naming the file.
#[test]
fn ply_colours_are_read_and_damaged_files_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut mesh = voxelkit::mesh::generate::icosphere(glam::DVec3::ZERO, 1.0, 1);
    mesh.colors = (0..mesh.positions.len())
        .map(|i| glam::Vec3::new(i as f32 / 64.0, 0.5, 1.0))
        .collect();
    let path = dir.path().join("c.ply");
    mesh.write_ply(&path, true).unwrap();
    let back = Mesh::load(&path).unwrap();
    for (a, b) in back.colors.iter().zip(&mesh.colors) {
        assert!(
            (*a - *b).abs().max_element() <= 0.5 / 255.0 + 1e-6,
            "{a} vs {b}"
        );
    }
    let bytes = std::fs::read(&path).unwrap();
    for (name, cut) in [
        ("cut.ply", bytes.len() - 7),
        ("head.ply", 40),
        ("empty.ply", 0),
    ] {
        let damaged = dir.path().join(name);
        std::fs::write(&damaged, &bytes[..cut]).unwrap();
        let err = Mesh::load(&damaged).unwrap_err().to_string();
        assert!(err.contains(name), "{err}");
    }
    let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
                end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n";
    let bad = dir.path().join("bad.ply");
    std::fs::write(&bad, text).unwrap();
    let err = Mesh::load(&bad).unwrap_err().to_string();
    assert!(
        err.contains("bad.ply") && err.contains("face 0 uses vertex 7"),
        "{err}"
    );
}

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

/// The voxel sets of two meshes at 64 differ in this many voxels (either way).
fn voxel_difference(a: &Mesh, b: &Mesh) -> usize {
    let (a, _) = common::voxelize_at(a, 64, SeparatingOptions::default());
    let (b, _) = common::voxelize_at(b, 64, SeparatingOptions::default());
    a.voxels().filter(|&c| !b.contains(c)).count() + b.voxels().filter(|&c| !a.contains(c)).count()
}

/// glTF stores positions as 32-bit floats: every shared mesh written as `.glb`, as `.gltf`
/// with an embedded buffer and as `.gltf` with a `.bin` beside it reads back to the OBJ's
/// triangles at the OBJ's positions rounded to floats, and voxelizes to exactly the OBJ's
/// voxel set.
#[test]
fn gltf_conversions_of_the_shared_meshes_voxelize_like_their_obj() {
    use voxelkit::mesh::GltfLayout;
    let Some(data) = common::data_dir() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    for obj in common::shared_meshes(&data) {
        let mesh = Mesh::load(&obj).unwrap();
        let stem = dir.path().join(obj.file_stem().unwrap());
        for (layout, name) in [
            (GltfLayout::Binary, stem.with_extension("glb")),
            (GltfLayout::Embedded, stem.with_extension("embedded.gltf")),
            (GltfLayout::SeparateBuffer, stem.with_extension("gltf")),
        ] {
            mesh.write_gltf(&name, layout, &[]).unwrap();
            let back = Mesh::load(&name).unwrap();
            let what = name.display();
            assert_eq!(back.triangle_count(), mesh.triangle_count(), "{what}");
            for (f, (_, t)) in mesh.triangles().enumerate() {
                let corners = back.face(f);
                for (k, &i) in t.iter().enumerate() {
                    let rounded = mesh.p(i).as_vec3().as_dvec3();
                    assert_eq!(back.p(corners[k]), rounded, "{what}: triangle {f}");
                }
            }
            assert_eq!(voxel_difference(&mesh, &back), 0, "{what}");
        }
    }
}

/// Node transforms are composed down the tree (parent first) and applied, a mirroring one
/// turns the faces so that they still face outward, split vertices are joined (a closed mesh
/// stays closed) and `COLOR_0` arrives as the vertex colours.
#[test]
fn gltf_nodes_place_the_mesh_and_colours_survive() {
    use glam::{DMat4, DQuat, DVec3, Vec3};
    use voxelkit::mesh::{GltfLayout, generate};
    let dir = tempfile::tempdir().unwrap();
    let mut torus = generate::torus(DVec3::ZERO, 1.0, 0.3, 24, 12);
    torus.colors = (0..torus.positions.len())
        .map(|i| Vec3::new((i % 7) as f32 / 7.0, 0.25, 1.0))
        .collect();
    let placement = [
        DMat4::from_translation(DVec3::new(1.0, 2.0, 3.0)),
        DMat4::from_quat(DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2)),
        DMat4::from_scale(DVec3::new(2.0, -2.0, 2.0)),
    ];
    let path = dir.path().join("placed.glb");
    torus
        .write_gltf(&path, GltfLayout::Binary, &placement)
        .unwrap();
    let back = Mesh::load(&path).unwrap();
    let world = placement[0] * placement[1] * placement[2];
    assert_eq!(back.positions.len(), torus.positions.len());
    for (i, p) in torus.positions.iter().enumerate() {
        let expected = world.transform_point3(p.as_vec3().as_dvec3());
        assert!(
            (back.positions[i] - expected).length() < 1e-12,
            "vertex {i}"
        );
        assert!((back.colors[i] - torus.colors[i]).abs().max_element() < 1e-6);
    }
    // Mirrored by the scale, yet facing outward: the same positive volume, 8 times it.
    let v = back.signed_volume();
    assert!((v - 8.0 * torus.signed_volume()).abs() < 1e-6 * v, "{v}");
    assert!(back.edge_counts().is_closed());
    // The same torus with every triangle on its own three vertices, as exporters split them.
    let mut soup_positions = Vec::new();
    let mut soup_faces = Vec::new();
    for (_, t) in torus.triangles() {
        soup_faces.push((0..3).map(|k| (soup_positions.len() + k) as u32).collect());
        soup_positions.extend(t.map(|i| torus.p(i)));
    }
    let soup = Mesh::from_polygons("soup", soup_positions, &soup_faces);
    assert!(!soup.edge_counts().is_closed());
    let path = dir.path().join("soup.gltf");
    soup.write_gltf(&path, GltfLayout::SeparateBuffer, &[])
        .unwrap();
    let back = Mesh::load(&path).unwrap();
    assert_eq!(back.positions.len(), torus.positions.len());
    assert!(back.edge_counts().is_closed());
}

/// Damaged glTF files are refused naming the file and the place, without a panic.
#[test]
fn damaged_gltf_files_are_refused() {
    use voxelkit::mesh::{GltfLayout, generate};
    let dir = tempfile::tempdir().unwrap();
    let mesh = generate::icosphere(glam::DVec3::ZERO, 1.0, 1);
    let glb = dir.path().join("m.glb");
    mesh.write_gltf(&glb, GltfLayout::Binary, &[]).unwrap();
    let bytes = std::fs::read(&glb).unwrap();
    for (name, cut) in [
        ("cut.glb", bytes.len() - 9),
        ("head.glb", 30),
        ("empty.glb", 0),
    ] {
        let damaged = dir.path().join(name);
        std::fs::write(&damaged, &bytes[..cut]).unwrap();
        let err = Mesh::load(&damaged).unwrap_err().to_string();
        assert!(err.contains(name), "{err}");
    }
    let gltf = dir.path().join("m.gltf");
    mesh.write_gltf(&gltf, GltfLayout::Embedded, &[]).unwrap();
    let text = std::fs::read_to_string(&gltf).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    let edit = |name: &str, change: &dyn Fn(&mut serde_json::Value), expect: &str| {
        let mut j = json.clone();
        change(&mut j);
        let path = dir.path().join(name);
        std::fs::write(&path, j.to_string()).unwrap();
        let err = Mesh::load(&path).unwrap_err().to_string();
        assert!(err.contains(name) && err.contains(expect), "{err}");
    };
    edit(
        "long_view.gltf",
        &|j| j["bufferViews"][0]["byteLength"] = 1_000_000.into(),
        "reaches past the end of buffer 0",
    );
    edit(
        "far_accessor.gltf",
        &|j| j["accessors"][1]["byteOffset"] = 4_000_000_000u64.into(),
        "runs past the end of buffer view 1",
    );
    edit(
        "bad_index.gltf",
        &|j| j["accessors"][0]["count"] = 3.into(),
        "mesh 0, primitive 0: index",
    );
    edit(
        "missing.gltf",
        &|j| j["buffers"][0]["uri"] = "nowhere.bin".into(),
        "nowhere.bin",
    );
    edit(
        "bad_base64.gltf",
        &|j| j["buffers"][0]["uri"] = "data:application/octet-stream;base64,@@@@".into(),
        "bad base64",
    );
    edit(
        "cycle.gltf",
        &|j| j["nodes"] = serde_json::json!([{"children": [1]}, {"mesh": 0, "children": [0]}]),
        "m",
    );
    edit(
        "bytes.gltf",
        &|j| j["accessors"][0]["componentType"] = 5121.into(),
        "POSITION accessor 0 holds U8",
    );
}

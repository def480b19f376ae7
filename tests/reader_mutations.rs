//! Every reader of untrusted input survives mutated input: valid OBJ, OFF, PLY, glTF (`.glb` and
//! `.gltf`) and STL (ASCII and binary),
//! formula, CSG-tree and `.vdb` files with random bytes changed, inserted, deleted or cut off
//! are either read or refused with an error naming the file (and meshes that read are
//! voxelized or refused); never a panic, never a crash, never a hang.
#![cfg(all(feature = "vdb", feature = "fixtures"))]

use glam::DVec3;
use proptest::prelude::*;
use std::path::Path;
use voxelkit::implicit::{Coordinates, Formula};
use voxelkit::mesh::attributes::AttributeChoice;
use voxelkit::mesh::{GridFit, Mesh, generate};
use voxelkit::pipeline::{Fill, Job, MeshSource, SurfaceMethod, Task};
use voxelkit::progress::Unobserved;
use voxelkit::solids::csg_tree::read_csg_tree;

/// One edit of a byte string.
#[derive(Clone, Debug)]
enum Edit {
    Set(usize, u8),
    Insert(usize, u8),
    Delete(usize),
    Cut(usize),
}

fn edits() -> impl Strategy<Value = Vec<Edit>> {
    let edit = prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Edit::Set(i, b)),
        (
            any::<usize>(),
            prop::sample::select(b"0123456789.-+eE /\n#vfl\0".to_vec())
        )
            .prop_map(|(i, b)| Edit::Insert(i, b)),
        any::<usize>().prop_map(Edit::Delete),
        any::<usize>().prop_map(Edit::Cut),
    ];
    prop::collection::vec(edit, 1..6)
}

fn apply(mut bytes: Vec<u8>, edits: &[Edit]) -> Vec<u8> {
    for e in edits {
        let n = bytes.len().max(1);
        match *e {
            Edit::Set(i, b) if !bytes.is_empty() => bytes[i % n] = b,
            Edit::Insert(i, b) => bytes.insert(i % (bytes.len() + 1), b),
            Edit::Delete(i) if !bytes.is_empty() => {
                bytes.remove(i % n);
            }
            Edit::Cut(i) => bytes.truncate(i % (bytes.len() + 1)),
            _ => {}
        }
    }
    bytes
}

/// The reader gives a mesh or an error naming the file; a mesh that reads is voxelized and
/// filled or refused, without a panic.
fn read_mesh(dir: &Path, name: &str, bytes: &[u8]) -> Result<(), TestCaseError> {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    match Mesh::load(&path) {
        Err(e) => prop_assert!(e.to_string().contains(name), "{e}"),
        Ok(_) => {
            let mesh = MeshSource::File(path.clone());
            for task in [
                Task::MeshSurface {
                    mesh: mesh.clone(),
                    method: SurfaceMethod::Separating(Default::default()),
                    attributes: AttributeChoice::None,
                },
                Task::Solid {
                    mesh,
                    fill: Fill::DepthLayers(Default::default()),
                    density: 1.0,
                    topology: true,
                    inside: Default::default(),
                },
            ] {
                let _ = Job::new(task, GridFit::Resolution(12)).run(&Unobserved);
            }
        }
    }
    Ok(())
}

fn obj_text() -> Vec<u8> {
    let mut text = String::new();
    let m = generate::icosphere(DVec3::ZERO, 1.0, 1);
    for p in &m.positions {
        text.push_str(&format!("v {} {} {}\n", p.x, p.y, p.z));
    }
    for f in 0..m.face_count() {
        let face: Vec<String> = m.face(f).iter().map(|i| (i + 1).to_string()).collect();
        text.push_str(&format!("f {}\n", face.join(" ")));
    }
    text.push_str("l 1 2 3\n");
    text.into_bytes()
}

fn off_text() -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.off");
    generate::icosphere(DVec3::ZERO, 1.0, 1)
        .write_off(&path)
        .unwrap();
    std::fs::read(&path).unwrap()
}

fn ply_bytes(binary: bool) -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.ply");
    generate::icosphere(DVec3::ZERO, 1.0, 1)
        .write_ply(&path, binary)
        .unwrap();
    std::fs::read(&path).unwrap()
}

fn gltf_bytes(layout: voxelkit::mesh::GltfLayout, name: &str) -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    generate::icosphere(DVec3::ZERO, 1.0, 1)
        .write_gltf(&path, layout, &[glam::DMat4::from_scale(DVec3::splat(2.0))])
        .unwrap();
    std::fs::read(&path).unwrap()
}

fn stl_ascii() -> Vec<u8> {
    let m = generate::icosphere(DVec3::ZERO, 1.0, 0);
    let mut s = String::from("solid s\n");
    for (_, t) in m.triangles() {
        s.push_str("facet normal 0 0 1\nouter loop\n");
        for i in t {
            let p = m.p(i);
            s.push_str(&format!("vertex {} {} {}\n", p.x, p.y, p.z));
        }
        s.push_str("endloop\nendfacet\n");
    }
    s.push_str("endsolid s\n");
    s.into_bytes()
}

fn stl_binary() -> Vec<u8> {
    let m = generate::icosphere(DVec3::ZERO, 1.0, 0);
    let tris: Vec<[u32; 3]> = m.triangles().map(|(_, t)| t).collect();
    let mut b = vec![0u8; 80];
    b.extend_from_slice(&(tris.len() as u32).to_le_bytes());
    for t in tris {
        b.extend_from_slice(&[0u8; 12]);
        for i in t {
            for c in m.p(i).to_array() {
                b.extend_from_slice(&(c as f32).to_le_bytes());
            }
        }
        b.extend_from_slice(&[0u8; 2]);
    }
    b
}

const TREE: &str = r#"{ "resolution": 16, "bounds": {"min": [-1, -1, -1], "max": [1, 1, 1]},
  "tree": { "difference": [ { "box": { "min": [-1, -1, -1], "max": [1, 1, 1] } },
    { "union": [ { "sphere": { "center": [0, 0, 0], "radius": 0.5 } },
      { "cylinder": { "base": [0, 0, -1], "axis": [0, 0, 1], "radius": 0.2, "height": 2 } },
      { "formula": { "text": "x^2 + y^2 - 0.1", "coordinates": "cartesian" } } ] } ] } }"#;

/// A small `.vdb` with leaves and tiles in a float and a bool grid.
/// A `.vdb` with a float grid (values, inactive background) and a bool grid, leaves and a
/// tile, in each compression (blosc, zip, none) and, for blosc, at half precision.
fn vdb_bytes(variant: usize) -> &'static [u8] {
    use voxelkit::io::vdb::Compression;
    static BYTES: std::sync::OnceLock<Vec<Vec<u8>>> = std::sync::OnceLock::new();
    &BYTES.get_or_init(|| {
        let mut grid = voxelkit::grid::SparseGrid::default();
        grid.fill_leaf_block([8, 0, 0]);
        for k in 0..40 {
            grid.insert([k, k % 5, -k]);
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("base.vdb");
        let variants = [
            (Compression::Blosc, false),
            (Compression::Blosc, true),
            (Compression::Zip, false),
            (Compression::None, false),
        ];
        variants
            .into_iter()
            .map(|(compression, half)| {
                let options = voxelkit::io::vdb::WriteOptions {
                    grids: vec!["density".into(), "voxels".into()],
                    compression,
                    half,
                };
                voxelkit::io::vdb::write_vdb_as(&path, &grid, &[], &[], &options).unwrap();
                std::fs::read(&path).unwrap()
            })
            .collect()
    })[variant % 4]
}

const FORMULA: &str = "a = x^2 + z^2; max(sqrt(a) - 0.5, abs(y) - 0.2) + sin(3*x)*exp(-y)/(1 + a)";

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]

    #[test]
    fn mutated_obj_files_are_read_or_refused(e in edits()) {
        let dir = tempfile::tempdir().unwrap();
        read_mesh(dir.path(), "m.obj", &apply(obj_text(), &e))?;
    }

    #[test]
    fn mutated_off_files_are_read_or_refused(e in edits()) {
        let dir = tempfile::tempdir().unwrap();
        read_mesh(dir.path(), "m.off", &apply(off_text(), &e))?;
    }

    #[test]
    fn mutated_ply_files_are_read_or_refused(e in edits(), binary in any::<bool>()) {
        let dir = tempfile::tempdir().unwrap();
        read_mesh(dir.path(), "m.ply", &apply(ply_bytes(binary), &e))?;
    }

    #[test]
    fn mutated_gltf_files_are_read_or_refused(e in edits(), binary in any::<bool>()) {
        use voxelkit::mesh::GltfLayout;
        let dir = tempfile::tempdir().unwrap();
        let (layout, name) = if binary {
            (GltfLayout::Binary, "m.glb")
        } else {
            (GltfLayout::Embedded, "m.gltf")
        };
        read_mesh(dir.path(), name, &apply(gltf_bytes(layout, name), &e))?;
    }

    #[test]
    fn mutated_stl_files_are_read_or_refused(e in edits(), binary in any::<bool>()) {
        let dir = tempfile::tempdir().unwrap();
        let base = if binary { stl_binary() } else { stl_ascii() };
        read_mesh(dir.path(), "m.stl", &apply(base, &e))?;
    }

    #[test]
    fn mutated_formulas_are_parsed_or_refused_at_a_column(e in edits()) {
        let bytes = apply(FORMULA.as_bytes().to_vec(), &e);
        let text = String::from_utf8_lossy(&bytes);
        for coordinates in [Coordinates::Cartesian, Coordinates::Spherical] {
            if let Err(err) = Formula::parse(&text, coordinates) {
                prop_assert!(err.to_string().contains("column"), "{err}");
            }
        }
    }

    /// Edits anywhere (header, metadata, transform, topology, compressed node data) and cuts,
    /// in blosc, half-precision, zip and uncompressed files.
    #[test]
    fn mutated_vdb_files_are_read_or_refused_naming_the_file(e in edits(), variant in 0..4usize) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("g.vdb");
        std::fs::write(&path, apply(vdb_bytes(variant).to_vec(), &e)).unwrap();
        if let Err(err) = voxelkit::io::vdb::read_vdb_info(&path) {
            prop_assert!(err.to_string().contains("g.vdb"), "{err}");
        }
        for name in [None, Some("voxels")] {
            if let Err(err) = voxelkit::io::vdb::read_vdb_grid(&path, name) {
                prop_assert!(err.to_string().contains("g.vdb"), "{err}");
            }
        }
    }

    #[test]
    fn mutated_csg_trees_are_read_or_refused_naming_the_file(e in edits()) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.json");
        std::fs::write(&path, apply(TREE.as_bytes().to_vec(), &e)).unwrap();
        match read_csg_tree(&path) {
            Ok(tree) => {
                // A tree that reads must evaluate or refuse, too.
                if let Err(err) = tree.transform() {
                    prop_assert!(err.to_string().contains("t.json"), "{err}");
                }
            }
            Err(err) => prop_assert!(err.to_string().contains("t.json"), "{err}"),
        }
    }
}

//! Mesh input on the real data (counts and volumes against the data README) and STL written
//! here in both encodings.
#![cfg(feature = "fixtures")]

mod common;

use voxelkit::mesh::{Mesh, generate};

#[test]
fn data_meshes_load_with_their_published_counts_and_volumes() {
    let Some(data) = common::data_dir() else {
        return;
    };
    // (file, faces, signed volume) from the data README.
    let expected = [
        ("bunny-closed", 6598, 0.749334),
        ("horse", 96966, -0.000263418),
        ("igea", 268686, 0.000278524),
        ("skull", 100002, 563.42),
        ("spot_quadrangulated", 2928, 0.717887),
        ("torus", 4608, 1.21878),
        ("cube_no_bottom", 40, 6.66667),
    ];
    for (name, faces, volume) in expected {
        let m = Mesh::load(&data.join("meshes").join(format!("{name}.obj"))).unwrap();
        assert_eq!(m.face_count(), faces, "{name}");
        assert!(
            (m.signed_volume() / volume - 1.0).abs() < 1e-4,
            "{name}: {}",
            m.signed_volume()
        );
    }
    // Quads stay quads.
    let quads = Mesh::load(&data.join("meshes/spot_quadrangulated.obj")).unwrap();
    assert!((0..quads.face_count()).all(|f| quads.face(f).len() == 4));
    // Every mesh of the folder loads, open and messy ones included.
    for entry in std::fs::read_dir(data.join("meshes")).unwrap() {
        let path = entry.unwrap().path();
        Mesh::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    }
}

fn stl_binary(m: &Mesh) -> Vec<u8> {
    let tris: Vec<[u32; 3]> = m.triangles().map(|(_, t)| t).collect();
    let mut out = vec![0u8; 80];
    out.extend((tris.len() as u32).to_le_bytes());
    for t in tris {
        out.extend([0f32; 3].iter().flat_map(|v| v.to_le_bytes()));
        for i in t {
            out.extend(
                m.p(i)
                    .as_vec3()
                    .to_array()
                    .iter()
                    .flat_map(|v| v.to_le_bytes()),
            );
        }
        out.extend([0u8; 2]);
    }
    out
}

fn stl_ascii(m: &Mesh) -> String {
    let mut s = String::from("solid test\n");
    for (_, t) in m.triangles() {
        s.push_str("  facet normal 0 0 0\n    outer loop\n");
        for i in t {
            let p = m.p(i);
            s.push_str(&format!("      vertex {} {} {}\n", p.x, p.y, p.z));
        }
        s.push_str("    endloop\n  endfacet\n");
    }
    s.push_str("endsolid test\n");
    s
}

#[test]
fn stl_in_both_encodings_welds_back_to_the_same_mesh() {
    let mut m = generate::torus(glam::DVec3::ZERO, 1.0, 0.3, 32, 12);
    // Round positions to f32 so binary STL holds them exactly.
    for p in &mut m.positions {
        *p = p.as_vec3().as_dvec3();
    }
    let dir = tempfile::tempdir().unwrap();
    let bin = dir.path().join("t.stl");
    std::fs::write(&bin, stl_binary(&m)).unwrap();
    let asc = dir.path().join("a.stl");
    std::fs::write(&asc, stl_ascii(&m)).unwrap();
    for path in [bin, asc] {
        let back = Mesh::load(&path).unwrap();
        assert_eq!(back.face_count(), m.triangles().count());
        assert_eq!(
            back.positions.len(),
            m.positions.len(),
            "{}: welding",
            path.display()
        );
        assert!((back.signed_volume() / m.signed_volume() - 1.0).abs() < 1e-9);
    }
}

//! Mesh input on the real data (counts and volumes against the data README), STL written
//! here in both encodings, and the attributes readers read past, named in the jobs' warnings.
#![cfg(feature = "fixtures")]

mod cli_support;
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

/// What a reader reads is named, and what it reads past, so that a job can say what it does
/// not write: OBJ texture coordinates and normals that not every face corner names, PLY list
/// properties. A job warns about them, about attributes it does not write, and about vertex
/// colours unless it colours its voxels with them.
#[test]
fn attributes_read_past_are_named_and_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    let tetrahedron = "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";
    let obj = dir.path().join("t.obj");
    std::fs::write(
        &obj,
        format!(
            "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nv 0 0 1 1 1 1\nvt 0 0\nvn 0 0 1\n{tetrahedron}"
        ),
    )
    .unwrap();
    let m = Mesh::load(&obj).unwrap();
    assert_eq!(
        m.unread,
        [
            "texture coordinates (vt) (line 7: a face corner names none)",
            "normals (vn) (line 7: a face corner names none)"
        ]
    );
    assert!(m.attributes.is_empty());
    let cornered = dir.path().join("c.obj");
    std::fs::write(
        &cornered,
        "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nv 0 0 1 1 1 1\nvt 0 0\nvn 0 0 1\n\
         f 1/1/1 3/1/1 2/1/1\nf 1/1/1 2/1/1 4/1/1\nf 2/1/1 3/1/1 4/1/1\nf 3/1/1 1/1/1 4/1/1\n",
    )
    .unwrap();
    let m = Mesh::load(&cornered).unwrap();
    let names: Vec<&str> = m.attributes.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["uv", "vertex_normal"]);
    assert!(m.unread.is_empty());
    let plain = dir.path().join("plain.obj");
    std::fs::write(
        &plain,
        format!("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n{tetrahedron}"),
    )
    .unwrap();
    assert!(Mesh::load(&plain).unwrap().unread.is_empty());
    let ply = dir.path().join("t.ply");
    std::fs::write(
        &ply,
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
         property float z\nproperty float nx\nproperty float quality\nelement face 4\n\
         property list uchar int vertex_indices\nend_header\n0 0 0 1 5\n1 0 0 1 5\n0 1 0 1 5\n\
         0 0 1 1 5\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n",
    )
    .unwrap();
    let m = Mesh::load(&ply).unwrap();
    let names: Vec<&str> = m.attributes.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["nx", "quality"], "a lone `nx` is a scalar");
    assert!(m.unread.is_empty());

    // The job's warning: everything on the separating surface, all but the colours on the
    // projective one (which writes them as `Cd`).
    let warnings = |obj: &std::path::Path, method: &str| {
        let o = cli_support::voxelkit(&[
            "--json",
            "mesh",
            obj.to_str().unwrap(),
            "--method",
            method,
            "-r",
            "16",
            "-o",
            dir.path().join(format!("{method}.vdb")).to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", cli_support::text(&o));
        let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        report["warnings"].to_string()
    };
    let separating = warnings(&cornered, "separating");
    assert!(
        separating.contains("vertex colours, `uv`, `vertex_normal` are not written"),
        "{separating}"
    );
    assert_eq!(
        warnings(&cornered, "projective"),
        "null",
        "projective writes them all"
    );
    let projective = warnings(&obj, "projective");
    assert!(
        projective.contains("texture coordinates (vt) (line 7")
            && !projective.contains("vertex colours"),
        "{projective}"
    );
    // Normals come from the separating method only: the projective one refuses them.
    let o = cli_support::voxelkit(&[
        "mesh",
        obj.to_str().unwrap(),
        "--method",
        "projective",
        "--normals",
        "-r",
        "16",
        "-o",
        dir.path().join("n.vdb").to_str().unwrap(),
    ]);
    assert!(!o.status.success() && cli_support::text(&o).contains("separating method"));
    assert!(!dir.path().join("n.vdb").exists());
}

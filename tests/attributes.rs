//! Vertex attributes written as grids: the projective method's interpolated values against
//! the barycentric value at each voxel's projection; the separating surface's and the level
//! set's values against the mesh's nearest point found by brute force; OBJ corner values
//! across seams and PLY properties read from files, through the command line, and their
//! grids as OpenVDB reads them; the warning for attributes left out.

mod cli_support;
mod common;

use glam::{DVec3, Vec3};
use voxelkit::grid::{SparseGrid, Transform};
use voxelkit::mesh::attributes::{AttributeKind, VertexAttribute};
use voxelkit::mesh::triangle_distance::triangle_distance;
use voxelkit::mesh::{Mesh, generate};
use voxelkit::pipeline::request::{MeshRequest, Request, SolidRequest};
use voxelkit::pipeline::{MeshSource, Outcome};
use voxelkit::progress::Unobserved;
use voxelkit::random::SplitMix64;

fn run(request: impl Request<Input = MeshSource>, mesh: MeshSource) -> voxelkit::Result<Outcome> {
    let job = request.job(mesh, &Default::default())?;
    job.plan()?.run(&Unobserved)
}

/// The grid written for attribute `name`.
fn attribute<'o>(outcome: &'o Outcome, name: &str) -> &'o SparseGrid {
    &outcome
        .attributes
        .iter()
        .find(|a| a.name == name)
        .unwrap_or_else(|| panic!("no `{name}` grid"))
        .grid
}

/// Every active voxel of `grid`: its centre (world), value and vector.
fn voxels(grid: &SparseGrid) -> Vec<(DVec3, f32, Vec3)> {
    let t: Transform = grid.transform;
    grid.leaves()
        .iter()
        .flat_map(|leaf| {
            leaf.offsets().zip(leaf.coords()).map(move |(n, c)| {
                (
                    t.index_to_world(c),
                    leaf.value.as_ref().unwrap()[n],
                    Vec3::from_array(leaf.color.as_ref().unwrap()[n]),
                )
            })
        })
        .collect()
}

/// A tilted plane z = 0.3x + 0.2y + 0.1 over [0, 1]^2 of `n` x `n` jittered vertices, each
/// with a random scalar `quality`, and `patch`: per-corner values that jump across every
/// edge (each face's corners its own).
fn tilted_plane(n: usize) -> Mesh {
    let mut random = SplitMix64(11);
    let h = 1.0 / (n - 1) as f64;
    let mut positions = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let border = i == 0 || j == 0 || i == n - 1 || j == n - 1;
            let jitter = if border { 0.0 } else { 0.3 * h };
            let x = i as f64 * h + random.range(-jitter, jitter);
            let y = j as f64 * h + random.range(-jitter, jitter);
            positions.push(DVec3::new(x, y, 0.3 * x + 0.2 * y + 0.1));
        }
    }
    let mut polygons = Vec::new();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let v = |a: usize, b: usize| ((j + b) * n + i + a) as u32;
            polygons.push(vec![v(0, 0), v(1, 0), v(1, 1)]);
            polygons.push(vec![v(0, 0), v(1, 1), v(0, 1)]);
        }
    }
    let mut mesh = Mesh::from_polygons("tilted plane", positions, &polygons);
    let quality = (0..mesh.positions.len())
        .map(|_| Vec3::new(random.range(-5.0, 5.0) as f32, 0.0, 0.0))
        .collect();
    let patch: Vec<Vec3> = (0..mesh.indices.len())
        .map(|_| {
            Vec3::new(
                random.range(0.0, 1.0) as f32,
                random.range(0.0, 1.0) as f32,
                0.0,
            )
        })
        .collect();
    mesh.attributes = vec![
        VertexAttribute {
            name: "quality".into(),
            kind: AttributeKind::Scalar,
            values: quality,
            corners: Vec::new(),
        },
        VertexAttribute {
            name: "patch".into(),
            kind: AttributeKind::TextureCoordinates,
            corners: (0..patch.len() as u32).collect(),
            values: patch,
        },
    ];
    mesh
}

/// The barycentric weights of `p` in the triangle `t`, in the plane's (x, y).
fn barycentric_xy(p: DVec3, t: [DVec3; 3]) -> [f64; 3] {
    let cross =
        |a: DVec3, b: DVec3, c: DVec3| (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    let area = cross(t[0], t[1], t[2]);
    [
        cross(p, t[1], t[2]) / area,
        cross(t[0], p, t[2]) / area,
        cross(t[0], t[1], p) / area,
    ]
}

#[test]
fn projective_values_are_the_barycentric_values_at_voxel_projections() {
    let mesh = tilted_plane(12);
    let request = MeshRequest {
        method: voxelkit::pipeline::request::SurfaceKind::Projective,
        resolution: Some(96),
        ..MeshRequest::default()
    };
    let outcome = run(request, MeshSource::Mesh(mesh.clone())).unwrap();
    let triangles: Vec<(usize, [usize; 3])> = (0..mesh.face_count())
        .flat_map(|f| mesh.fan_corners(f).map(move |s| (f, s)))
        .collect();
    let corner = |s: usize| mesh.positions[mesh.indices[s] as usize];
    for name in ["quality", "patch"] {
        let grid = attribute(&outcome, name);
        assert_eq!(grid.voxel_count(), outcome.grid.voxel_count(), "{name}");
        let a = mesh.attributes.iter().find(|a| a.name == name).unwrap();
        let mut checked = 0;
        for (centre, value, vector) in voxels(grid) {
            // Voxels of the plane's digital surface (those the scan of a neighbouring triangle
            // adds above or below it hold that triangle's value, within its range), whose
            // projection along z (the dominant axis) lies strictly inside a triangle.
            let t = grid.transform;
            let on_plane = DVec3::new(centre.x, centre.y, 0.3 * centre.x + 0.2 * centre.y + 0.1);
            if t.world_to_index(on_plane).z.round() != t.world_to_index(centre).z.round() {
                continue;
            }
            let inside = triangles.iter().find_map(|&(_, s)| {
                let w = barycentric_xy(centre, s.map(corner));
                (w.iter().all(|&w| w > 1e-9)).then_some((s, w))
            });
            let Some((slots, w)) = inside else {
                continue;
            };
            let values = mesh.attribute_corners(a, slots);
            let expected = w[0] * values[0] + w[1] * values[1] + w[2] * values[2];
            let got = if name == "quality" {
                assert_eq!(value, vector.x);
                DVec3::new(value as f64, 0.0, 0.0)
            } else {
                vector.as_dvec3()
            };
            assert!(
                got.distance(expected) < 1e-5,
                "{name} at {centre}: {got} against the barycentric {expected}"
            );
            checked += 1;
        }
        assert!(checked > 5000, "{name}: {checked} voxels checked");
    }
}

#[test]
fn nearest_point_values_match_a_brute_force_nearest_point() {
    // The attribute is each vertex's position: its value anywhere on the mesh is that point,
    // so a voxel's value is the nearest point the transfer found.
    let mut mesh = generate::torus(DVec3::new(0.1, -0.2, 0.3), 1.0, 0.35, 40, 20);
    let positions: Vec<Vec3> = mesh.positions.iter().map(|p| p.as_vec3()).collect();
    mesh.attributes = vec![VertexAttribute {
        name: "rest".into(),
        kind: AttributeKind::TextureCoordinates,
        values: positions,
        corners: Vec::new(),
    }];
    let triangles: Vec<[DVec3; 3]> = mesh
        .triangles()
        .map(|(_, t)| t.map(|v| mesh.positions[v as usize]))
        .collect();
    let nearest = |p: DVec3| {
        triangles
            .iter()
            .map(|&t| triangle_distance(p, t))
            .fold(f64::INFINITY, f64::min)
    };
    let all = || Some(vec!["all".to_string()]);
    let surface = MeshRequest {
        resolution: Some(64),
        attributes: all(),
        ..MeshRequest::default()
    };
    let level_set = MeshRequest {
        resolution: Some(64),
        sdf: true,
        attributes: all(),
        ..MeshRequest::default()
    };
    for (what, request) in [("surface", surface), ("level set", level_set)] {
        let outcome = run(request, MeshSource::Mesh(mesh.clone())).unwrap();
        let grid = attribute(&outcome, "rest");
        assert_eq!(grid.voxel_count(), outcome.grid.voxel_count(), "{what}");
        let h = grid.transform.voxel_size;
        for (centre, _, q) in voxels(grid) {
            let q = q.as_dvec3();
            let tolerance = 2e-6 * (1.0 + centre.length());
            assert!(nearest(q) < tolerance, "{what}: {q} lies off the mesh");
            assert!(
                (q.distance(centre) - nearest(centre)).abs() < tolerance + 1e-6 * h,
                "{what}: at {centre}, {q} is not a nearest point"
            );
        }
    }
}

#[test]
fn files_attributes_reach_their_grids_and_openvdb_reads_them() {
    let dir = tempfile::tempdir().unwrap();
    // Two quads sharing an edge along which the texture coordinates jump (a seam), and a
    // per-vertex normal.
    let obj = dir.path().join("seam.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0.2\nv 1 1 0.2\nv 2 1 0.2\n\
         vt 0 0\nvt 0.5 0\nvt 0 1\nvt 0.5 1\nvt 0.6 0\nvt 1 0\nvt 0.6 1\nvt 1 1\n\
         vn 0 -0.2 1\n\
         f 1/1/1 2/2/1 5/4/1 4/3/1\nf 2/5/1 3/6/1 6/8/1 5/7/1\n",
    )
    .unwrap();
    let ply = dir.path().join("tetra.ply");
    std::fs::write(
        &ply,
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
         property float z\nproperty float quality\nproperty float nx\nproperty float ny\n\
         property float nz\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n\
         0 0 0 1 -1 -1 -1\n1 0 0 2 1 0 0\n0 1 0 3 0 1 0\n0 0 1 4 0 0 1\n\
         3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",
    )
    .unwrap();
    let written = |input: &std::path::Path, out: &str, extra: &[&str]| {
        let output = dir.path().join(out);
        let mut args = vec!["mesh", input.to_str().unwrap(), "-r", "48", "-o"];
        args.push(output.to_str().unwrap());
        args.extend(extra);
        let o = cli_support::voxelkit(&args);
        assert!(o.status.success(), "{}", cli_support::text(&o));
        (
            output.clone(),
            String::from_utf8_lossy(&o.stdout).to_string(),
        )
    };
    let (seam, summary) = written(&obj, "seam.vdb", &["--method", "projective"]);
    assert!(
        summary.contains("attributes: uv (interpolated"),
        "{summary}"
    );
    let uv = voxelkit::io::vdb::read_vdb_grid(&seam, Some("uv")).unwrap();
    let normals = voxelkit::io::vdb::read_vdb_grid(&seam, Some("vertex_normal")).unwrap();
    let density = voxelkit::io::vdb::read_vdb_grid(&seam, Some("density")).unwrap();
    assert_eq!(uv.voxel_count(), density.voxel_count());
    // Left of the seam u stays within [0, 0.5], right of it within [0.6, 1]: no value blends
    // the two sides.
    for leaf in uv.leaves() {
        for (n, c) in leaf.offsets().zip(leaf.coords()) {
            let u = leaf.color.as_ref().unwrap()[n][0];
            let x = uv.transform.index_to_world(c).x;
            if x < 0.95 {
                assert!((-1e-6..=0.5 + 1e-6).contains(&u), "u {u} at x {x}");
            } else if x > 1.05 {
                assert!((0.6 - 1e-6..=1.0 + 1e-6).contains(&u), "u {u} at x {x}");
            }
        }
    }
    let expected = DVec3::new(0.0, -0.2, 1.0).normalize();
    for leaf in normals.leaves() {
        for n in leaf.offsets() {
            let v = Vec3::from_array(leaf.color.as_ref().unwrap()[n]).as_dvec3();
            assert!(v.distance(expected) < 1e-6, "{v}");
        }
    }
    let (tetra, summary) = written(
        &ply,
        "tetra.vdb",
        &["--attributes", "quality,vertex_normal"],
    );
    assert!(
        summary.contains("quality (from the nearest point"),
        "{summary}"
    );
    let quality = voxelkit::io::vdb::read_vdb_grid(&tetra, Some("quality")).unwrap();
    let values: Vec<f32> = quality
        .leaves()
        .iter()
        .flat_map(|l| l.offsets().map(|n| l.value.as_ref().unwrap()[n]))
        .collect();
    assert!(values.iter().all(|v| (1.0..=4.0).contains(v)));
    assert!(values.iter().any(|&v| v < 1.5) && values.iter().any(|&v| v > 3.5));
    // Vertex colours travel to the separating surface as `Cd`, from the nearest point.
    let coloured = dir.path().join("coloured.obj");
    std::fs::write(
        &coloured,
        "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nv 0 0 1 1 1 1\n\
         f 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n",
    )
    .unwrap();
    let (colours, summary) = written(&coloured, "coloured.vdb", &["--attributes", "Cd"]);
    assert!(
        summary.contains("Cd (from the nearest point") && !summary.contains("warning"),
        "{summary}"
    );
    let cd = voxelkit::io::vdb::read_vdb_grid(&colours, Some("Cd")).unwrap();
    assert!(cd.voxel_count() > 1000);
    assert!(cd.leaves().iter().all(|l| l.offsets().all(|n| {
        let c = l.color.as_ref().unwrap()[n];
        c.iter().all(|v| (0.0..=1.0).contains(v)) && c.iter().sum::<f32>() >= 1.0 - 1e-5
    })));
    #[cfg(feature = "vdb")]
    for (file, grid) in [
        (&seam, "uv"),
        (&seam, "vertex_normal"),
        (&tetra, "quality"),
        (&tetra, "vertex_normal"),
    ] {
        common::assert_read_as_openvdb_reads(file, grid);
    }
}

#[test]
fn shared_meshes_carry_their_texture_coordinates_and_normals() {
    let Some(data) = common::data_dir() else {
        return;
    };
    let meshes = data.join("meshes");
    // spot's texture coordinates have seams (one vertex, several `vt`).
    let spot = MeshRequest {
        method: voxelkit::pipeline::request::SurfaceKind::Projective,
        resolution: Some(128),
        ..MeshRequest::default()
    };
    let file = |name: &str| MeshSource::File(meshes.join(name));
    let outcome = run(spot, file("spot_triangulated.obj")).unwrap();
    let uv = attribute(&outcome, "uv");
    assert_eq!(uv.voxel_count(), outcome.grid.voxel_count());
    assert!(
        outcome.report.warnings.is_empty(),
        "{:?}",
        outcome.report.warnings
    );
    // bunny-closed's vertex normals, carried to its separating surface, against the exact
    // nearest face, edge or vertex normal of the same voxels.
    let bunny = MeshRequest {
        resolution: Some(128),
        normals: true,
        attributes: Some(vec!["vertex_normal".into()]),
        ..MeshRequest::default()
    };
    let outcome = run(bunny, file("bunny-closed.obj")).unwrap();
    let vertex = attribute(&outcome, "vertex_normal");
    let mut agree = 0;
    let mut total = 0;
    for leaf in vertex.leaves() {
        let exact = outcome.grid.leaf(leaf.origin).unwrap();
        for n in leaf.offsets() {
            let a = Vec3::from_array(leaf.color.as_ref().unwrap()[n]);
            let b = Vec3::from_array(exact.normal.as_ref().unwrap()[n]);
            assert!((a.length() - 1.0).abs() < 1e-5);
            agree += usize::from(a.dot(b) > 0.8);
            total += 1;
        }
    }
    assert!(agree as f64 > 0.95 * total as f64, "{agree} of {total}");
    // A job that writes no attributes says which it leaves out; an unknown name is refused.
    let solid = SolidRequest {
        resolution: Some(48),
        ..SolidRequest::default()
    };
    let outcome = run(solid, file("bunny-closed.obj")).unwrap();
    assert!(
        outcome
            .report
            .warnings
            .iter()
            .any(|w| w.contains("`vertex_normal`")),
        "{:?}",
        outcome.report.warnings
    );
    let unknown = MeshRequest {
        attributes: Some(vec!["uv".into()]),
        ..MeshRequest::default()
    };
    let error = run(unknown, file("bunny-closed.obj"))
        .err()
        .unwrap()
        .to_string();
    assert!(
        error.contains("bunny-closed.obj") && error.contains("no attribute `uv`"),
        "{error}"
    );
}

/// glTF `NORMAL` (turned with the node) and `TEXCOORD_0` reach the mesh per triangle corner:
/// two primitives share an edge's positions (joined into one vertex) with different texture
/// coordinates, which stay apart.
#[test]
fn gltf_normals_and_texture_coordinates_are_read_per_corner() {
    let dir = tempfile::tempdir().unwrap();
    let mut bin: Vec<u8> = Vec::new();
    let mut floats = |v: &[f32]| {
        let at = bin.len();
        bin.extend(v.iter().flat_map(|f| f.to_le_bytes()));
        at
    };
    // Two unit squares side by side in z = 0: [0,1]x[0,1] and [1,2]x[0,1].
    let left = floats(&[0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.]);
    let right = floats(&[1., 0., 0., 2., 0., 0., 2., 1., 0., 1., 1., 0.]);
    let normals = floats(&[0., 0., 1., 0., 0., 1., 0., 0., 1., 0., 0., 1.]);
    let uv_left = floats(&[0., 0., 0.5, 0., 0.5, 1., 0., 1.]);
    let uv_right = floats(&[0.6, 0., 1., 0., 1., 1., 0.6, 1.]);
    let indices = bin.len();
    bin.extend([0u16, 1, 2, 0, 2, 3].iter().flat_map(|i| i.to_le_bytes()));
    std::fs::write(dir.path().join("squares.bin"), &bin).unwrap();
    let view = |offset: usize, length: usize| serde_json::json!({"buffer": 0, "byteOffset": offset, "byteLength": length});
    let accessor = |view: usize, kind: &str, count: usize, component: u32| serde_json::json!({"bufferView": view, "componentType": component, "count": count, "type": kind});
    let mut position = accessor(0, "VEC3", 4, 5126);
    position["min"] = serde_json::json!([0, 0, 0]);
    position["max"] = serde_json::json!([1, 1, 0]);
    let mut position_right = accessor(1, "VEC3", 4, 5126);
    position_right["min"] = serde_json::json!([1, 0, 0]);
    position_right["max"] = serde_json::json!([2, 1, 0]);
    let half = std::f32::consts::FRAC_1_SQRT_2;
    let gltf = serde_json::json!({
        "asset": {"version": "2.0"},
        "buffers": [{"uri": "squares.bin", "byteLength": bin.len()}],
        "bufferViews": [view(left, 48), view(right, 48), view(normals, 48), view(uv_left, 32), view(uv_right, 32), view(indices, 12)],
        "accessors": [position, position_right, accessor(2, "VEC3", 4, 5126), accessor(3, "VEC2", 4, 5126), accessor(4, "VEC2", 4, 5126), accessor(5, "SCALAR", 6, 5123)],
        "meshes": [{"primitives": [
            {"attributes": {"POSITION": 0, "NORMAL": 2, "TEXCOORD_0": 3}, "indices": 5},
            {"attributes": {"POSITION": 1, "NORMAL": 2, "TEXCOORD_0": 4}, "indices": 5}
        ]}],
        // A quarter turn about x: z = 0 becomes y = 0, the normal +z becomes -y.
        "nodes": [{"mesh": 0, "rotation": [half, 0.0, 0.0, half]}],
        "scenes": [{"nodes": [0]}],
        "scene": 0
    });
    let path = dir.path().join("squares.gltf");
    std::fs::write(&path, gltf.to_string()).unwrap();
    let mesh = Mesh::load(&path).unwrap();
    assert_eq!(
        mesh.positions.len(),
        6,
        "the shared edge's positions are joined"
    );
    assert!(mesh.unread.is_empty(), "{:?}", mesh.unread);
    let uv = mesh.attributes.iter().find(|a| a.name == "uv").unwrap();
    let normal = mesh
        .attributes
        .iter()
        .find(|a| a.name == "vertex_normal")
        .unwrap();
    for v in &normal.values {
        assert!(v.distance(Vec3::new(0.0, -1.0, 0.0)) < 1e-6, "{v}");
    }
    // The corners at x = 1 take u = 0.5 in the left square's faces and 0.6 in the right's.
    let mut seen = std::collections::BTreeSet::new();
    for f in 0..mesh.face_count() {
        for slots in mesh.fan_corners(f) {
            for s in slots {
                let p = mesh.positions[mesh.indices[s] as usize];
                if (p.x - 1.0).abs() < 1e-9 {
                    let u = uv.at_corner(&mesh.indices, s).x;
                    let left_face = mesh
                        .face(f)
                        .iter()
                        .any(|&v| mesh.positions[v as usize].x < 0.5);
                    assert!(
                        (u - if left_face { 0.5 } else { 0.6 }).abs() < 1e-6,
                        "u {u}"
                    );
                    seen.insert(left_face);
                }
            }
        }
    }
    assert_eq!(seen.len(), 2);
}

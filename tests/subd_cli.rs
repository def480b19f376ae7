//! `voxelkit subdiv` end to end on control meshes the tests write: the .vdb it writes read
//! back by OpenVDB, `subdiv eval` against the library, and bad control meshes refused with an
//! error naming the vertex, face or line, a non-zero exit and no output file.
#![cfg(feature = "vdb")]

use std::path::Path;
mod cli_support;
mod common;

use cli_support::{json_field, text, voxelkit};
use voxelkit::io::vdb::read_vdb_info;
use voxelkit::subd::{ControlMesh, LimitSurface};

use common::CUBE_OBJ as CUBE;

fn write(dir: &Path, name: &str, content: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, content).unwrap();
    p.to_str().unwrap().to_string()
}

#[test]
fn subdiv_writes_a_vdb_that_openvdb_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    let input = write(dir.path(), "cube.obj", CUBE);
    let output = dir.path().join("cube.vdb");
    let o = voxelkit(&[
        "subdiv",
        &input,
        "-a",
        "6",
        "-r",
        "64",
        "-o",
        output.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let summary = text(&o);
    for word in ["voxels", "evaluations", "area", "6-adjacent"] {
        assert!(summary.contains(word), "`{word}` missing from: {summary}");
    }
    let grids = read_vdb_info(&output).unwrap();
    let grid = |name: &str| grids.iter().find(|g| g.name == name).unwrap();
    assert_eq!(grids.len(), 3);
    let surface = grid("density");
    assert!(surface.active_voxels > 1000);
    assert_eq!(grid("normal").active_voxels, surface.active_voxels);
    assert_eq!(grid("opposite_normals").active_voxels, 0);
    let meta = |key: &str| {
        surface
            .metadata
            .iter()
            .find(|m| m.key == key)
            .map(|m| m.value.clone())
    };
    assert_eq!(meta("adjacency").as_deref(), Some("6"));
    assert_eq!(meta("method").as_deref(), Some("lai-cheng-parametric"));
}

#[test]
fn subdiv_eval_prints_the_limit_surface() {
    let dir = tempfile::tempdir().unwrap();
    let input = write(dir.path(), "cube.obj", CUBE);
    let points = write(
        dir.path(),
        "uv.txt",
        "# face u v\n0 0 0\n3 0.25 0.75\n5 1 1\n",
    );
    let o = voxelkit(&["subdiv", "eval", &input, "--points", &points]);
    assert!(o.status.success(), "{}", text(&o));
    let surface = LimitSurface::new(ControlMesh::load(Path::new(&input)).unwrap());
    let lines: Vec<String> = String::from_utf8_lossy(&o.stdout)
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(String::from)
        .collect();
    assert_eq!(lines.len(), 3);
    for line in lines {
        let f: Vec<f64> = line
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        let s = surface.evaluate(f[0] as usize, f[1], f[2]).unwrap();
        assert!((s.position - glam::DVec3::new(f[3], f[4], f[5])).length() < 1e-15);
        assert!((s.normal - glam::DVec3::new(f[6], f[7], f[8])).length() < 1e-15);
    }
    // At the valence-3 corner (-1,-1,-1): (n² v + 4 Σe + Σf) / (n (n + 5)) per axis is
    // (9·(-1) + 4·(-1) + 1) / 24 = -1/2.
    let corner = surface.evaluate(0, 0.0, 0.0).unwrap().position;
    assert!(
        (corner - glam::DVec3::splat(-0.5)).length() < 1e-14,
        "{corner:?}"
    );
}

/// Runs `voxelkit` with `args` (`IN` and `OUT` replaced by the written input and an output
/// path) and checks the failure: non-zero exit, every piece of `expect`, nothing written.
fn assert_fails(content: &str, args: &[&str], expect: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let input = write(dir.path(), "in.obj", content);
    let output = dir.path().join("out.vdb");
    let args: Vec<&str> = args
        .iter()
        .map(|&a| match a {
            "IN" => input.as_str(),
            "OUT" => output.to_str().unwrap(),
            a => a,
        })
        .collect();
    let o = voxelkit(&args);
    let msg = text(&o);
    assert!(!o.status.success(), "expected failure, got: {msg}");
    for e in expect {
        assert!(msg.contains(e), "`{e}` missing from: {msg}");
    }
    assert!(!msg.contains("panicked"), "{msg}");
    assert!(!output.exists(), "output left behind");
}

#[test]
fn bad_control_meshes_are_refused_by_name() {
    let voxelize = ["subdiv", "IN", "-r", "32", "-o", "OUT"];
    // Three quads on one edge (vertices 1 and 2).
    let fin = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 1 0 1\nv 0 0 1\nv 1 -1 0\nv 0 -1 0\n\
f 1 2 3 4\nf 2 1 6 5\nf 1 2 7 8\n";
    assert_fails(
        fin,
        &voxelize,
        &[
            "in.obj",
            "vertices 1 and 2",
            "non-manifold",
            "faces 0, 1, 2",
        ],
    );
    // Vertex 9 is used by no face.
    assert_fails(
        &format!("{CUBE}v 5 5 5\n"),
        &voxelize,
        &["in.obj", "vertex 9", "isolated"],
    );
    // Face 1 is flipped: its edges run the same way as face 0's.
    let flipped = CUBE.replace("f 5 6 7 8", "f 8 7 6 5");
    assert_fails(&flipped, &voxelize, &["in.obj", "inconsistently"]);
    // Two pyramids touching at their apex (vertex 5): one vertex, two fans.
    let bowtie = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\nv 0 0 2\nv 1 0 2\nv 1 1 2\nv 0 1 2\n\
f 1 4 3 2\nf 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\nf 6 7 8 9\nf 7 6 5\nf 8 7 5\nf 9 8 5\nf 6 9 5\n";
    assert_fails(
        bowtie,
        &voxelize,
        &["in.obj", "vertex 5", "more than one fan"],
    );
    // A face that repeats a vertex.
    assert_fails(
        &CUBE.replace("f 5 6 7 8", "f 5 6 6 8"),
        &voxelize,
        &["in.obj", "face 1", "twice"],
    );
    // Unreadable coordinates, with the line.
    assert_fails(
        &CUBE.replace("v 1 1 1", "v 1 nan 1"),
        &voxelize,
        &["in.obj:7", "non-finite"],
    );
    // An empty mesh.
    assert_fails("# nothing\n", &voxelize, &["in.obj", "empty"]);
    // An output folder that does not exist.
    assert_fails(
        CUBE,
        &[
            "subdiv",
            "IN",
            "-r",
            "32",
            "-o",
            "/nonexistent-folder/x.vdb",
        ],
        &["nonexistent-folder"],
    );
    // A resolution whose memory estimate exceeds the limit.
    assert_fails(
        CUBE,
        &[
            "subdiv",
            "IN",
            "-r",
            "100000",
            "--max-memory",
            "64",
            "-o",
            "OUT",
        ],
        &["resolution too large"],
    );
}

#[test]
fn bad_points_are_refused_with_their_line() {
    let dir = tempfile::tempdir().unwrap();
    let input = write(dir.path(), "cube.obj", CUBE);
    for (points, expect) in [
        ("0 0.5 0.5\n0 0.5\n", "uv.txt:2"),
        ("0 0.5 x\n", "not a finite number"),
        ("7 0.5 0.5\n", "face 7 does not exist"),
        ("0 1.5 0.5\n", "outside face 0"),
    ] {
        let file = write(dir.path(), "uv.txt", points);
        let o = voxelkit(&["subdiv", "eval", &input, "--points", &file]);
        let msg = text(&o);
        assert!(
            !o.status.success() && msg.contains(expect),
            "`{expect}` missing from: {msg}"
        );
    }
}

/// `subdiv --solid`: the solid written like `voxelkit solid`'s (`density` on the whole solid,
/// `shell` and `interior`), the exact limit volume in the report between the voxel volumes;
/// an open control mesh refused with no output.
#[test]
fn subdiv_solid_writes_the_filled_limit_surface() {
    let dir = tempfile::tempdir().unwrap();
    let input = write(dir.path(), "cube.obj", CUBE);
    let output = dir.path().join("solid.vdb");
    let o = voxelkit(&[
        "--json",
        "subdiv",
        &input,
        "--solid",
        "-r",
        "48",
        "-o",
        output.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let number = |k: &str| report[k].as_f64().unwrap();
    assert!(number("volume_inside") <= number("limit_volume"));
    assert!(number("limit_volume") <= number("volume_with_surface"));
    assert!(number("line_floods") > 0.0);
    let grids = read_vdb_info(&output).unwrap();
    let count = |name: &str| grids.iter().find(|g| g.name == name).unwrap().active_voxels;
    assert_eq!(grids[0].name, "density");
    assert_eq!(count("density"), count("shell") + count("interior"));
    // Depth layers on the certified tessellation fill the same voxels (no pocket walls an
    // outside centre in on the cube) and say how.
    let layered = dir.path().join("layered.vdb");
    let o = voxelkit(&[
        "subdiv",
        &input,
        "--solid",
        "--depth-layers",
        "-r",
        "48",
        "-o",
        layered.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(
        text(&o).contains("tessellation within 0.45 voxel"),
        "{}",
        text(&o)
    );
    let layered_grids = read_vdb_info(&layered).unwrap();
    let density = &layered_grids[0];
    assert_eq!(density.active_voxels, count("density"));
    let meta = |key: &str| {
        density
            .metadata
            .iter()
            .find(|m| m.key == key)
            .map(|m| m.value.clone())
    };
    assert_eq!(
        meta("method").as_deref(),
        Some("lai-cheng-parametric-enclosed+depth-layers-on-certified-tessellation")
    );
    assert_eq!(meta("odd_rays").as_deref(), Some("0"));
    assert!(
        meta("tessellation_triangles")
            .unwrap()
            .parse::<u64>()
            .unwrap()
            > 100
    );
    let o = voxelkit(&[
        "subdiv",
        &input,
        "--depth-layers",
        "-o",
        layered.to_str().unwrap(),
    ]);
    assert!(
        !o.status.success() && text(&o).contains("--solid"),
        "{}",
        text(&o)
    );
    // One face fewer: an open control mesh.
    let open = CUBE.rsplit_once("f 4 1 5 8\n").unwrap().0;
    let open = write(dir.path(), "open.obj", open);
    let refused = dir.path().join("open.vdb");
    let o = voxelkit(&["subdiv", &open, "--solid", "-o", refused.to_str().unwrap()]);
    assert!(
        !o.status.success() && text(&o).contains("closed"),
        "{}",
        text(&o)
    );
    assert!(!refused.exists());
}

/// `--up-axis y` turns a control mesh as it turns a polygon mesh: (x, y, z) -> (x, -z, y).
#[test]
fn the_up_axis_turns_the_control_mesh() {
    let Some(data) = common::data_dir() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let input = data.join("subd/catmark_car.obj");
    let extent = |up: &str| {
        let out = dir.path().join(format!("car-{up}.vdb"));
        let args = [
            "subdiv",
            input.to_str().unwrap(),
            "-r",
            "32",
            "--up-axis",
            up,
            "-o",
        ];
        let o = voxelkit(&[&args[..], &[out.to_str().unwrap()]].concat());
        assert!(o.status.success(), "{}", text(&o));
        let b = voxelkit::io::vdb::read_vdb_grid(&out, None)
            .unwrap()
            .bbox()
            .unwrap();
        [0, 1, 2].map(|a| b.max[a] - b.min[a])
    };
    let (kept, turned) = (extent("z"), extent("y"));
    assert_eq!([kept[0], kept[2], kept[1]], turned);
}

/// Lai & Cheng §7.3: intersection curves from the common voxels of surfaces on one grid
/// (`subdiv A B --shared-grid`, then `intersect`). The enclosed surfaces (every voxel the limit
/// surface touches) give whole curves: one 26-component per loop of the intersection of fine
/// tessellations of the two limit surfaces (catmark_torus's tube crosses catmark_cube's limit
/// surface in two loops, and catmark_toroidal_tet's in two as well); the paper's adjacency
/// test alone leaves gaps (torus and cube: 12 pieces at 128, 20 at 256).
#[test]
fn catmull_clark_surfaces_on_one_grid_meet_in_whole_curves() {
    let Some(data) = common::data_dir() else {
        return;
    };
    use voxelkit::grid::{Adjacency, DenseMask};
    use voxelkit::io::vdb::read_vdb_grid;
    let dir = tempfile::tempdir().unwrap();
    let subd = |name: &str| data.join(format!("subd/{name}.obj"));
    let components = |a: &str, b: &str, extra: &[&str]| {
        let out = dir.path().join(format!("{a}-{b}-{}", extra.len()));
        let mut args = vec![
            "subdiv".to_string(),
            subd(a).display().to_string(),
            subd(b).display().to_string(),
            "--shared-grid".into(),
            "-r".into(),
            "128".into(),
            "--out-dir".into(),
            out.display().to_string(),
        ];
        args.extend(extra.iter().map(|s| s.to_string()));
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = voxelkit(&refs);
        assert!(o.status.success(), "{}", text(&o));
        let curve = out.join("curve.vdb");
        let o = voxelkit(&[
            "intersect",
            out.join(format!("{a}.vdb")).to_str().unwrap(),
            out.join(format!("{b}.vdb")).to_str().unwrap(),
            "-o",
            curve.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", text(&o));
        let grid = read_vdb_grid(&curve, None).unwrap();
        let mask = DenseMask::from_grid(&grid, grid.bbox().unwrap()).unwrap();
        (
            grid.voxel_count(),
            voxelkit::ops::topology::components(&mask, Adjacency::TwentySix),
        )
    };
    let tessellation = |name: &str| {
        let control = voxelkit::subd::ControlMesh::load(&subd(name)).unwrap();
        voxelkit::subd::LimitSurface::new(control).tessellate(|_| 24)
    };
    for (a, b) in [
        ("catmark_torus", "catmark_cube"),
        ("catmark_torus", "catmark_toroidal_tet"),
    ] {
        let loops = intersection_loops(&tessellation(a), &tessellation(b));
        let (voxels, pieces) = components(a, b, &["--enclose"]);
        eprintln!("{a} x {b}: {loops} loops; enclosed: {voxels} voxels in {pieces} pieces");
        assert!(loops >= 2);
        assert_eq!(pieces, loops as u64, "{a} x {b}: {voxels} voxels");
    }
    // `intersect --subdiv` makes the enclosed surfaces on one grid itself: the same curve.
    let direct = dir.path().join("direct.vdb");
    let o = voxelkit(&[
        "intersect",
        "--subdiv",
        subd("catmark_torus").to_str().unwrap(),
        subd("catmark_cube").to_str().unwrap(),
        "-r",
        "128",
        "-o",
        direct.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let two_steps = dir.path().join("catmark_torus-catmark_cube-1/curve.vdb");
    let coords = |p: &std::path::Path| {
        let g = read_vdb_grid(p, None).unwrap();
        let mut c: Vec<[i64; 3]> = g.leaves().iter().flat_map(|l| l.coords()).collect();
        c.sort();
        c
    };
    assert_eq!(coords(&direct), coords(&two_steps));
    let (default_voxels, default_pieces) = components("catmark_torus", "catmark_cube", &[]);
    eprintln!("torus x cube, default: {default_voxels} voxels in {default_pieces} pieces");
    assert!(default_pieces > 2);
}

/// The number of closed loops in which two triangle meshes meet: the segments of every pair
/// of crossing triangles, joined where they share an end. An end is where an edge of one mesh
/// pierces a triangle of the other, named by that edge and triangle, so the segments of
/// neighbouring pairs join exactly (meshes in general position).
fn intersection_loops(a: &voxelkit::mesh::Mesh, b: &voxelkit::mesh::Mesh) -> usize {
    use glam::DVec3;
    use std::collections::HashMap;
    type End = (u8, u32, u32, usize);
    let tris =
        |m: &voxelkit::mesh::Mesh| -> Vec<[u32; 3]> { m.triangles().map(|(_, t)| t).collect() };
    let (ta, tb) = (tris(a), tris(b));
    // Triangles of b by the cells of a coarse lattice their boxes meet.
    let cell = 0.05;
    let key = |p: DVec3| (p / cell).floor().as_i64vec3().to_array();
    let mut cells: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    for (n, t) in tb.iter().enumerate() {
        let p = t.map(|i| b.positions[i as usize]);
        let (lo, hi) = (key(p[0].min(p[1]).min(p[2])), key(p[0].max(p[1]).max(p[2])));
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    cells.entry([x, y, z]).or_default().push(n);
                }
            }
        }
    }
    let mut parent: HashMap<End, End> = HashMap::new();
    fn root(parent: &mut HashMap<End, End>, e: End) -> End {
        let p = *parent.entry(e).or_insert(e);
        if p == e {
            return e;
        }
        let r = root(parent, p);
        parent.insert(e, r);
        r
    }
    for (na, &t) in ta.iter().enumerate() {
        let p = t.map(|i| a.positions[i as usize]);
        let (lo, hi) = (key(p[0].min(p[1]).min(p[2])), key(p[0].max(p[1]).max(p[2])));
        let mut candidates = Vec::new();
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    candidates.extend(cells.get(&[x, y, z]).into_iter().flatten().copied());
                }
            }
        }
        candidates.sort_unstable();
        candidates.dedup();
        for nb in candidates {
            let s = tb[nb];
            let q = s.map(|i| b.positions[i as usize]);
            // The points where edges of one triangle pierce the other, named by edge and
            // triangle.
            let mut ends: Vec<End> = Vec::new();
            for (side, (edges_of, verts, over, tri)) in
                [(t, p, q, nb), (s, q, p, na)].into_iter().enumerate()
            {
                let n = (over[1] - over[0]).cross(over[2] - over[0]);
                for k in 0..3 {
                    let (u, v) = (verts[k], verts[(k + 1) % 3]);
                    let (du, dv) = (n.dot(u - over[0]), n.dot(v - over[0]));
                    if du * dv >= 0.0 {
                        continue;
                    }
                    let x = u + (v - u) * (du / (du - dv));
                    let inside = (0..3).all(|m| {
                        let (o0, o1) = (over[m], over[(m + 1) % 3]);
                        (o1 - o0).cross(x - o0).dot(n) >= 0.0
                    });
                    if inside {
                        let (i, j) = (edges_of[k], edges_of[(k + 1) % 3]);
                        ends.push((side as u8, i.min(j), i.max(j), tri));
                    }
                }
            }
            if ends.len() == 2 {
                let (r0, r1) = (root(&mut parent, ends[0]), root(&mut parent, ends[1]));
                parent.insert(r0, r1);
            }
        }
    }
    let keys: Vec<End> = parent.keys().copied().collect();
    let mut roots: Vec<End> = keys.into_iter().map(|e| root(&mut parent, e)).collect();
    roots.sort_unstable();
    roots.dedup();
    roots.len()
}

/// `check --subdiv`: a Catmull-Clark limit surface's voxels checked by flooding against a fine
/// tessellation, as `check` checks a mesh's: the paper's surface blocks 6-paths, the enclosed
/// one 26-paths; an open control mesh is refused, naming its boundary.
#[test]
fn check_floods_catmull_clark_surfaces() {
    let Some(data) = common::data_dir() else {
        return;
    };
    let spot = data.join("subd/spot_control_mesh.obj");
    for (extra, separability) in [(None, 6.0), (Some("--enclose"), 26.0)] {
        let mut args = vec![
            "--json",
            "check",
            "--subdiv",
            spot.to_str().unwrap(),
            "-r",
            "96",
        ];
        args.extend(extra);
        let o = voxelkit(&args);
        assert!(o.status.success(), "{}", text(&o));
        let out = String::from_utf8_lossy(&o.stdout).to_string();
        assert_eq!(json_field(&out, "separability"), separability, "{out}");
        assert_eq!(json_field(&out, "leaked"), 0.0, "{out}");
        assert!(json_field(&out, "inside_centres") > 10_000.0, "{out}");
    }
    let pawn = data.join("subd/catmark_pawn.obj");
    let o = voxelkit(&["check", "--subdiv", pawn.to_str().unwrap(), "-r", "64"]);
    assert!(!o.status.success());
    assert!(text(&o).contains("24 boundary edge(s)"), "{}", text(&o));
}

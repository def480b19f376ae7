//! `voxelkit lines`, `mesh --method projective` and `solid --method beam` end to end: the
//! `Cd` grid read back by pyopenvdb (an independent reader) holds exactly the library's
//! colours, the beam's volume holds the exact one, and bad input is refused by name.
#![cfg(all(feature = "vdb", feature = "fixtures"))]

mod cli_support;

use cli_support::{json_field, run_pyopenvdb, text, voxelkit};
use glam::{DVec3, Vec3};
use std::collections::HashMap;
use std::path::Path;
use voxelkit::grid::{SparseGrid, offset_coord};
use voxelkit::mesh::{GridFit, Mesh, fit_transform, generate};
use voxelkit::voxelize::projective::{Coloring, LineSource, voxelize_lines, voxelize_triangles};

/// Every active voxel of the `Cd` grid and the `density` count, through pyopenvdb; `None`
/// (loudly) when pyopenvdb is missing.
fn read_cd(path: &Path) -> Option<(HashMap<[i64; 3], Vec3>, u64)> {
    let script = r#"
import sys, pyopenvdb as vdb
print(vdb.read(sys.argv[1], "density").activeVoxelCount())
g = vdb.read(sys.argv[1], "Cd")
for item in g.citerOnValues():
    lo, hi, c = item["min"], item["max"], item["value"]
    for x in range(lo[0], hi[0] + 1):
        for y in range(lo[1], hi[1] + 1):
            for z in range(lo[2], hi[2] + 1):
                print(x, y, z, repr(c[0]), repr(c[1]), repr(c[2]))
"#;
    let text = run_pyopenvdb(script, path, "the Cd read-back")?;
    let mut lines = text.lines();
    let surface = lines.next().unwrap().parse().unwrap();
    let cd = lines
        .map(|l| {
            let w: Vec<&str> = l.split_whitespace().collect();
            let i = |k: usize| w[k].parse::<i64>().unwrap();
            let f = |k: usize| w[k].parse::<f32>().unwrap();
            ([i(0), i(1), i(2)], Vec3::new(f(3), f(4), f(5)))
        })
        .collect();
    Some((cd, surface))
}

/// Asserts that the file's `Cd` grid holds exactly `grid`'s voxels and colours.
fn assert_same_colours(path: &Path, grid: &SparseGrid) {
    let Some((cd, surface)) = read_cd(path) else {
        return;
    };
    assert_eq!(surface, grid.voxel_count());
    assert_eq!(cd.len() as u64, grid.voxel_count());
    for leaf in grid.leaves() {
        let colors = leaf.color.as_ref().unwrap();
        for n in leaf.offsets() {
            let v = offset_coord(leaf.origin, n);
            assert_eq!(cd[&v], Vec3::from(colors[n]), "voxel {v:?}");
        }
    }
}

/// A coloured helix as one polyline, and two loose segments.
fn helix() -> Mesh {
    let n = 400;
    let mut mesh = Mesh::default();
    for k in 0..n {
        let t = k as f64 / (n - 1) as f64;
        let a = t * 6.0 * std::f64::consts::PI;
        mesh.positions
            .push(DVec3::new(a.cos(), a.sin(), 2.0 * t - 1.0));
        mesh.colors.push(Vec3::new(t as f32, 1.0 - t as f32, 0.5));
    }
    mesh.polylines.push((0..n as u32).collect());
    mesh.polylines.push(vec![0, n as u32 / 2, n as u32 - 1]);
    mesh.face_starts = vec![0];
    mesh
}

#[test]
fn lines_and_projective_meshes_write_the_library_colours() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    helix().write_obj(&p("helix.obj")).unwrap();
    let o = voxelkit(&[
        "--json",
        "lines",
        p("helix.obj").to_str().unwrap(),
        "-r",
        "64",
        "-o",
        p("helix.vdb").to_str().unwrap(),
    ]);
    let out = text(&o);
    assert!(o.status.success(), "{out}");
    assert_eq!(json_field(&out, "segments"), 401.0);
    let mesh = Mesh::load_lines(&p("helix.obj")).unwrap();
    let t = fit_transform(&mesh.bbox(), GridFit::Resolution(64)).unwrap();
    let source = LineSource {
        polylines: true,
        edges: false,
    };
    let (grid, _) = voxelize_lines(
        &mesh,
        t,
        source,
        Coloring::Vertex,
        &voxelkit::progress::Progress::none(),
    )
    .unwrap();
    assert_eq!(json_field(&out, "voxels"), grid.voxel_count() as f64);
    assert_same_colours(&p("helix.vdb"), &grid);

    // A sphere coloured by position, through `mesh --method projective`.
    let mut ball = generate::icosphere(DVec3::ZERO, 1.0, 4);
    ball.colors = ball
        .positions
        .iter()
        .map(|q| (q.as_vec3() + 1.0) * 0.5)
        .collect();
    ball.write_obj(&p("ball.obj")).unwrap();
    let o = voxelkit(&[
        "mesh",
        p("ball.obj").to_str().unwrap(),
        "--method",
        "projective",
        "-r",
        "80",
        "-o",
        p("ball.vdb").to_str().unwrap(),
    ]);
    let out = text(&o);
    assert!(o.status.success(), "{out}");
    assert!(out.contains("vertex colours interpolated"), "{out}");
    let mesh = Mesh::load(&p("ball.obj")).unwrap();
    let t = fit_transform(&mesh.bbox(), GridFit::Resolution(80)).unwrap();
    let (grid, _) = voxelize_triangles(
        &mesh,
        t,
        Coloring::Vertex,
        &voxelkit::progress::Progress::none(),
    )
    .unwrap();
    assert_same_colours(&p("ball.vdb"), &grid);

    // A constant colour on every voxel; the edges of the same sphere as lines.
    let o = voxelkit(&[
        "lines",
        p("ball.obj").to_str().unwrap(),
        "--color",
        "0.25,0.5,1",
        "-r",
        "40",
        "-o",
        p("edges.vdb").to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    if let Some((cd, surface)) = read_cd(&p("edges.vdb")) {
        assert_eq!(cd.len() as u64, surface);
        assert!(cd.values().all(|&c| c == Vec3::new(0.25, 0.5, 1.0)));
    }
}

#[test]
fn the_beam_solid_from_the_command_line_holds_the_exact_volume() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("torus.obj");
    let torus = generate::torus(DVec3::ZERO, 1.0, 0.35, 64, 32);
    torus.write_obj(&path).unwrap();
    let out_path = dir.path().join("torus.vdb");
    let o = voxelkit(&[
        "--json",
        "solid",
        path.to_str().unwrap(),
        "--method",
        "beam",
        "--topology",
        "-r",
        "96",
        "-o",
        out_path.to_str().unwrap(),
    ]);
    let out = text(&o);
    assert!(o.status.success(), "{out}");
    let exact = torus.signed_volume();
    assert!(json_field(&out, "volume_inside") < exact, "{out}");
    assert!(json_field(&out, "volume_with_surface") > exact, "{out}");
    assert_eq!(json_field(&out, "genus"), 1.0, "{out}");
    let info = voxelkit::io::vdb::read_vdb_info(&out_path).unwrap();
    let mut names: Vec<&str> = info.iter().map(|g| g.name.as_str()).collect();
    names.sort();
    assert_eq!(names, ["density", "interior", "shell"]);
}

#[test]
fn bad_input_is_refused_by_file_and_line_and_leaves_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    let run = |args: &[&str]| {
        let o = voxelkit(args);
        assert!(!o.status.success(), "{args:?} should fail");
        text(&o)
    };
    std::fs::write(p("mixed.obj"), "v 0 0 0 1 0 0\nv 1 0 0\nl 1 2\n").unwrap();
    let err = run(&["lines", &p("mixed.obj"), "-o", &p("a.vdb")]);
    assert!(err.contains("mixed.obj") && err.contains("line 2"), "{err}");
    std::fs::write(p("points.obj"), "v 0 0 0\nv 1 0 0\n").unwrap();
    let err = run(&["lines", &p("points.obj"), "-o", &p("a.vdb")]);
    assert!(
        err.contains("points.obj") && err.contains("0 lines"),
        "{err}"
    );
    std::fs::write(p("nan.obj"), "v 0 0 0\nv nan 0 0\nl 1 2\n").unwrap();
    let err = run(&["lines", &p("nan.obj"), "-o", &p("a.vdb")]);
    assert!(err.contains("nan.obj:2:"), "{err}");
    std::fs::write(p("plain.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let err = run(&[
        "mesh",
        &p("plain.obj"),
        "--method",
        "projective",
        "--color",
        "1,x,0",
        "-o",
        &p("a.vdb"),
    ]);
    assert!(err.contains("r,g,b"), "{err}");
    let err = run(&[
        "mesh",
        &p("plain.obj"),
        "--color",
        "1,0,0",
        "-o",
        &p("a.vdb"),
    ]);
    assert!(err.contains("--method projective"), "{err}");
    let err = run(&[
        "solid",
        &p("plain.obj"),
        "--method",
        "beam",
        "-o",
        &p("a.vdb"),
    ]);
    assert!(
        err.contains("plain.obj") && err.contains("boundary edge"),
        "{err}"
    );
    assert!(!Path::new(&p("a.vdb")).exists());
}

//! The command line as a front end of the pipeline: every command refuses an impossible grid
//! at once with the estimate and writes nothing; `--json` reports are typed JSON and errors
//! are one JSON object; outputs are `.vdb` files or standard output, nothing else.
#![cfg(all(feature = "vdb", feature = "fixtures"))]

use std::path::Path;
use std::time::{Duration, Instant};
mod cli_support;

use cli_support::{text, voxelkit};

const TETRA: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn every_command_refuses_an_impossible_grid_at_once_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("tetra.obj");
    std::fs::write(&obj, TETRA).unwrap();
    let cube = dir.path().join("cube.obj");
    // A quad cube: a Catmull-Clark control mesh.
    voxelkit::mesh::generate::cuboid(glam::DVec3::splat(-1.0), glam::DVec3::ONE)
        .write_obj(&cube)
        .unwrap();
    let tree = dir.path().join("tree.json");
    std::fs::write(
        &tree,
        r#"{"resolution": 500000, "tree": {"sphere": {"center": [0, 0, 0], "radius": 1}}}"#,
    )
    .unwrap();
    let out = dir.path().join("out.vdb");
    let (o, c, t, v) = (s(&obj), s(&cube), s(&tree), s(&out));
    let cases: Vec<Vec<&str>> = vec![
        vec!["mesh", o, "-r", "1000000", "-o", v],
        vec!["mesh", o, "--voxel-size", "1e-30", "-o", v],
        vec![
            "mesh",
            o,
            "--method",
            "projective",
            "-r",
            "1000000",
            "-o",
            v,
        ],
        vec!["lines", o, "-r", "100000000", "-o", v],
        vec!["shape", "sphere", "-r", "1000000", "-o", v],
        vec!["subdiv", c, "-r", "1000000", "-o", v],
        vec!["implicit", "x^2 + y^2 + z^2 - 0.5", "-r", "65536", "-o", v],
        vec!["solid", o, "-r", "60000", "-o", v],
        vec!["solid", o, "--voxel-size", "1e-30", "-o", v],
        vec![
            "solid",
            o,
            "--method",
            "depth-layers",
            "-r",
            "60000",
            "-o",
            v,
        ],
        vec!["solid", o, "--method", "beam", "-r", "60000", "-o", v],
        vec!["measure", o, "-r", "60000"],
        vec!["check", o, "-r", "1000000"],
        vec!["csg", "--tree", t, "-o", v],
        vec!["mesh", o, "-r", "64", "--max-memory", "1", "-o", v],
    ];
    // An address-space limit (`ulimit -v`, as a cgroup limit) is what is available.
    let limited = std::process::Command::new("bash")
        .arg("-c")
        .arg(format!(
            "ulimit -v 400000; exec {} shape sphere --normals -r 1024 -o {v}",
            env!("CARGO_BIN_EXE_voxelkit")
        ))
        .output()
        .unwrap();
    let msg = text(&limited);
    assert!(
        !limited.status.success() && msg.contains("an estimated"),
        "{msg}"
    );
    assert!(!out.exists());
    // OpenVDB cannot store a voxel this small: refused before the work, not after it.
    let tiny = voxelkit(&["lines", o, "--voxel-size", "1e-6", "-o", v]);
    let msg = text(&tiny);
    assert!(
        !tiny.status.success() && msg.contains("OpenVDB cannot store"),
        "{msg}"
    );
    for args in cases {
        let start = Instant::now();
        let result = voxelkit(&args);
        let elapsed = start.elapsed();
        let msg = text(&result);
        assert!(!result.status.success(), "{args:?} succeeded: {msg}");
        assert!(
            msg.contains("an estimated") && msg.contains("MiB"),
            "{args:?}: no estimate in: {msg}"
        );
        assert!(
            elapsed < Duration::from_secs(1),
            "{args:?}: refusing took {elapsed:?}"
        );
        assert!(!out.exists(), "{args:?} wrote a file");
    }
}

#[test]
fn json_reports_are_typed_and_errors_are_json_objects() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("tetra.obj");
    std::fs::write(&obj, TETRA).unwrap();
    let out = dir.path().join("out.vdb");
    let run = voxelkit(&["--json", "mesh", s(&obj), "-r", "16", "-o", s(&out)]);
    assert!(run.status.success(), "{}", text(&run));
    let report: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
    assert!(report["voxels"].as_u64().unwrap() > 0);
    assert!(report["seconds"].as_f64().unwrap() >= report["voxelize_seconds"].as_f64().unwrap());
    assert_eq!(report["origin"].as_array().unwrap().len(), 3);
    assert_eq!(report["method"], "huang-separating");

    let info = voxelkit(&["--json", "info", s(&out)]);
    let info: serde_json::Value = serde_json::from_slice(&info.stdout).unwrap();
    let grid = &info["grids"][0];
    assert!(
        grid["origin"]
            .as_array()
            .unwrap()
            .iter()
            .all(|v| v.is_f64())
    );
    assert!(
        grid["bbox_min"]
            .as_array()
            .unwrap()
            .iter()
            .all(|v| v.is_i64())
    );
    assert_eq!(grid["metadata"]["method"], "huang-separating");

    let bad = dir.path().join("bad.obj");
    std::fs::write(&bad, "v 0 0 0\nv 1 0 zero\n").unwrap();
    let failed = voxelkit(&["--json", "mesh", s(&bad), "-o", s(&out)]);
    assert!(!failed.status.success());
    assert!(failed.stdout.is_empty());
    let error: serde_json::Value = serde_json::from_slice(&failed.stderr)
        .unwrap_or_else(|_| panic!("not JSON: {}", text(&failed)));
    assert_eq!(error["line"], 2);
    assert!(error["file"].as_str().unwrap().ends_with("bad.obj"));
    assert!(error["error"].as_str().unwrap().contains("bad.obj:2"));
}

#[test]
fn outputs_are_vdb_binvox_or_vox_files_or_standard_output() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("tetra.obj");
    std::fs::write(&obj, TETRA).unwrap();
    for name in ["out.npy", "out.npz", "out"] {
        let out = dir.path().join(name);
        let refused = voxelkit(&["mesh", s(&obj), "-r", "16", "-o", s(&out)]);
        let msg = text(&refused);
        assert!(!refused.status.success(), "{name}: {msg}");
        assert!(
            msg.contains(".vdb") && msg.contains("standard output") && msg.contains(".vox"),
            "{msg}"
        );
        assert!(!out.exists());
    }
    let piped = voxelkit(&["mesh", s(&obj), "-r", "16", "-o", "-"]);
    assert!(piped.status.success(), "{}", text(&piped));
    assert!(!dir.path().join("-").exists());
    let copy = dir.path().join("copy.vdb");
    std::fs::write(&copy, &piped.stdout).unwrap();
    let grids = voxelkit::io::vdb::read_vdb_info(&copy).unwrap();
    assert!(
        grids
            .iter()
            .any(|g| g.name == "density" && g.active_voxels > 0)
    );
    // The summary went to stderr, leaving stdout to the file.
    assert!(String::from_utf8_lossy(&piped.stderr).contains("voxels"));
}

#[test]
fn an_absurd_thread_count_is_clamped_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("tetra.obj");
    std::fs::write(&obj, TETRA).unwrap();
    let out = dir.path().join("out.vdb");
    let o = voxelkit(&[
        "--threads",
        "1000000",
        "mesh",
        s(&obj),
        "-r",
        "8",
        "-o",
        s(&out),
    ]);
    let msg = text(&o);
    assert!(o.status.success(), "{msg}");
    assert!(
        msg.contains("1000000 threads asked for; using 256"),
        "{msg}"
    );
}

#[test]
fn grids_compression_and_half_precision_are_chosen_when_writing() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("torus.obj");
    voxelkit::mesh::generate::torus(glam::DVec3::ZERO, 1.0, 0.35, 48, 24)
        .write_obj(&obj)
        .unwrap();
    let o = s(&obj);
    let write = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let mut args = vec!["mesh", o, "-r", "96", "-o", out.to_str().unwrap()];
        args.extend_from_slice(extra);
        let run = voxelkit(&args);
        (run, out)
    };
    let (run, only) = write("only.vdb", &["--grids", "density"]);
    assert!(run.status.success(), "{}", text(&run));
    let grids = voxelkit::io::vdb::read_vdb_info(&only).unwrap();
    assert_eq!(
        grids.iter().map(|g| g.name.as_str()).collect::<Vec<_>>(),
        ["density"]
    );

    let (run, missing) = write("missing.vdb", &["--grids", "density,nope"]);
    let msg = text(&run);
    assert!(
        !run.status.success() && msg.contains("nope") && msg.contains("density"),
        "{msg}"
    );
    assert!(!missing.exists());

    let (_, blosc) = write("blosc.vdb", &[]);
    let (run, plain) = write("plain.vdb", &["--compression", "none"]);
    assert!(run.status.success(), "{}", text(&run));
    let size = |p: &Path| std::fs::metadata(p).unwrap().len();
    assert!(
        size(&plain) > size(&blosc),
        "{} vs {}",
        size(&plain),
        size(&blosc)
    );

    let (run, half) = write("half.vdb", &["--sdf", "--half"]);
    assert!(run.status.success(), "{}", text(&run));
    let (_, full) = write("full.vdb", &["--sdf"]);
    let a = voxelkit::io::vdb::read_vdb_grid(&half, Some("surface")).unwrap();
    let b = voxelkit::io::vdb::read_vdb_grid(&full, Some("surface")).unwrap();
    assert_eq!(a.voxel_count(), b.voxel_count());
    let h = b.transform.voxel_size as f32;
    for (la, lb) in a.leaves().iter().zip(b.leaves()) {
        let (va, vb) = (la.value.as_ref().unwrap(), lb.value.as_ref().unwrap());
        for n in lb.offsets() {
            assert!(
                (va[n] - vb[n]).abs() <= 1e-3 * 3.0 * h,
                "{} vs {}",
                va[n],
                vb[n]
            );
        }
    }
}

/// `--up-axis y` turns a Y-up file to Z-up as Blender's OBJ importer does: a torus centred at
/// y = 2 comes out centred at z = 2, with the same voxel count as when it is read Z-up.
#[test]
fn a_y_up_mesh_is_turned_z_up_on_request() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("torus.obj");
    voxelkit::mesh::generate::torus(glam::DVec3::new(0.0, 2.0, 0.0), 1.0, 0.3, 32, 8)
        .write_obj(&obj)
        .unwrap();
    let centre_and_count = |up: &str| {
        let out = dir.path().join(format!("{up}.vdb"));
        let o = voxelkit(&["mesh", "--up-axis", up, s(&obj), "-r", "32", "-o", s(&out)]);
        assert!(o.status.success(), "{}", text(&o));
        let grid = voxelkit::io::vdb::read_vdb_grid(&out, None).unwrap();
        let b = grid.bbox().unwrap();
        let t = grid.transform;
        let centre = (t.index_to_world(b.min) + t.index_to_world(b.max)) / 2.0;
        (centre, grid.voxel_count())
    };
    let (kept, n_kept) = centre_and_count("z");
    let (turned, n_turned) = centre_and_count("y");
    assert!((kept.y - 2.0).abs() < 0.1 && kept.z.abs() < 0.1, "{kept}");
    assert!(
        (turned.z - 2.0).abs() < 0.1 && turned.y.abs() < 0.1,
        "{turned}"
    );
    assert_eq!(n_kept, n_turned);
}

#[test]
fn bounds_place_the_grid_and_leave_out_every_voxel_beyond_them() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("torus.obj");
    voxelkit::mesh::generate::torus(glam::DVec3::ZERO, 1.0, 0.3, 48, 16)
        .write_obj(&obj)
        .unwrap();
    let (lo, hi) = (
        glam::DVec3::new(-1.5, -1.5, -0.2),
        glam::DVec3::new(0.0, 1.5, 0.4),
    );
    for command in ["mesh", "solid"] {
        let out = dir.path().join(format!("{command}.vdb"));
        let bounds = "-1.5,-1.5,-0.2,0,1.5,0.4";
        let o = voxelkit(&[
            command,
            s(&obj),
            "-r",
            "60",
            "--bounds",
            bounds,
            "-o",
            s(&out),
        ]);
        assert!(o.status.success(), "{}", text(&o));
        assert!(text(&o).contains("outside left out"), "{}", text(&o));
        let grid = voxelkit::io::vdb::read_vdb_grid(&out, None).unwrap();
        let t = grid.transform;
        // 60 voxels along the bounds' longest side (y, 3 units), the first centre half a
        // voxel inside their low corner.
        assert!((t.voxel_size - 0.05).abs() < 1e-12, "{}", t.voxel_size);
        assert!((t.origin - (lo + 0.025)).length() < 1e-12, "{}", t.origin);
        assert!(grid.voxel_count() > 500);
        for v in grid.voxels() {
            let c = t.index_to_world(v);
            assert!(
                c.cmpge(lo).all() && c.cmple(hi).all(),
                "{command}: {v:?} at {c}"
            );
        }
    }
    let out = dir.path().join("bad.vdb");
    let o = voxelkit(&["mesh", s(&obj), "--bounds", "1,0,0,0,1,1", "-o", s(&out)]);
    assert!(
        !o.status.success() && text(&o).contains("bounds"),
        "{}",
        text(&o)
    );
    assert!(!out.exists());
}

/// A file's bytes past its UUID do not depend on the thread count: leaves are encoded in
/// parallel, each chunk from its values alone, even on a thread that compresses tens of
/// thousands of them (about 37,000 each here).
#[test]
fn a_level_set_is_the_same_bytes_on_one_thread_and_on_two() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("sphere.obj");
    voxelkit::mesh::generate::icosphere(glam::DVec3::ZERO, 1.0, 4)
        .write_obj(&obj)
        .unwrap();
    let written = |threads: &str| {
        let out = dir.path().join(format!("{threads}.vdb"));
        let o = voxelkit(&[
            "--threads",
            threads,
            "mesh",
            s(&obj),
            "--sdf",
            "-r",
            "640",
            "-o",
            s(&out),
        ]);
        assert!(o.status.success(), "{}", text(&o));
        let mut bytes = std::fs::read(&out).unwrap();
        // Magic, versions and the offsets flag, then the file's own UUID.
        bytes.drain(21..57);
        bytes
    };
    let (one, two) = (written("1"), written("2"));
    assert_eq!(one.len(), two.len());
    let first = one.iter().zip(&two).position(|(a, b)| a != b);
    assert_eq!(first, None, "the files differ from this byte on");
}

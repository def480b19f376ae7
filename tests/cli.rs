//! The CLI end to end: real files in and out, and every kind of bad input answered with a
//! clear error naming the file and place, a non-zero exit and no output file.
#![cfg(all(feature = "vdb", feature = "fixtures"))]

use std::path::{Path, PathBuf};
mod cli_support;

use cli_support::{text, voxelkit};

/// Files in `dir` other than `keep`.
fn extra_files(dir: &Path, keep: &[&Path]) -> Vec<PathBuf> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| !keep.contains(&p.as_path()))
        .collect()
}

const TETRA: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

/// Runs `voxelkit mesh` on `content` and checks the failure: non-zero exit, a message
/// containing every piece of `expect`, and nothing written.
fn assert_mesh_fails(file_name: &str, content: &[u8], extra_args: &[&str], expect: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join(file_name);
    std::fs::write(&input, content).unwrap();
    let output = dir.path().join("out.vdb");
    let mut args = vec![
        "mesh",
        input.to_str().unwrap(),
        "-o",
        output.to_str().unwrap(),
    ];
    args.extend_from_slice(extra_args);
    let o = voxelkit(&args);
    let msg = text(&o);
    assert!(
        !o.status.success(),
        "{file_name}: expected failure, got: {msg}"
    );
    for e in expect {
        assert!(msg.contains(e), "{file_name}: `{e}` missing from: {msg}");
    }
    assert!(!msg.contains("panicked"), "{msg}");
    assert!(
        extra_files(dir.path(), &[&input]).is_empty(),
        "{file_name}: output left behind"
    );
}

#[test]
fn malformed_obj_names_file_and_line() {
    assert_mesh_fails(
        "bad.obj",
        b"v 0 0 0\nv 1 0 zero\nv 0 1 0\nf 1 2 3\n",
        &[],
        &["bad.obj:2:"],
    );
}

#[test]
fn nan_and_inf_coordinates_name_the_line() {
    assert_mesh_fails(
        "nan.obj",
        b"v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n",
        &[],
        &["nan.obj:3:", "non-finite"],
    );
    assert_mesh_fails(
        "inf.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n",
        &[],
        &["inf.obj:3:", "non-finite"],
    );
}

#[test]
fn out_of_range_face_index_names_the_line() {
    assert_mesh_fails(
        "range.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 9\n",
        &[],
        &["range.obj:5:", "out of range"],
    );
    assert_mesh_fails(
        "zero.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n",
        &[],
        &["zero.obj:4:"],
    );
}

#[test]
fn empty_mesh_is_refused() {
    assert_mesh_fails(
        "empty.obj",
        b"# nothing here\nv 0 0 0\n",
        &[],
        &["empty.obj", "empty"],
    );
    assert_mesh_fails(
        "empty.stl",
        b"solid x\nendsolid x\n",
        &[],
        &["empty.stl", "empty"],
    );
}

#[test]
fn broken_stl_names_the_triangle_or_line() {
    // Binary: 1 triangle with a NaN corner.
    let mut bin = vec![0u8; 84];
    bin[80] = 1;
    let mut tri = vec![0u8; 50];
    tri[12..16].copy_from_slice(&f32::NAN.to_le_bytes());
    bin.extend(tri);
    assert_mesh_fails("nan.stl", &bin, &[], &["nan.stl", "face 0", "non-finite"]);
    // Binary: announced 2 triangles, holds one.
    let mut short = bin.clone();
    short[80] = 2;
    assert_mesh_fails(
        "short.stl",
        &short,
        &[],
        &["short.stl", "announces 2 triangles"],
    );
    let ascii = b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 x\nendloop\nendfacet\nendsolid t\n";
    assert_mesh_fails("bad.stl", ascii, &[], &["bad.stl:6:"]);
}

#[test]
fn unsupported_extension_and_missing_file() {
    assert_mesh_fails("mesh.3ds", b"MM", &[], &["mesh.3ds", "unsupported"]);
    assert_mesh_fails("mesh.glb", b"glTF", &[], &["mesh.glb", "glTF"]);
    assert_mesh_fails("mesh.ply", b"ply\n", &[], &["mesh.ply", "PLY"]);
    let o = voxelkit(&["mesh", "does-not-exist.obj", "-o", "never.vdb"]);
    assert!(!o.status.success() && text(&o).contains("does-not-exist.obj"));
    assert!(!Path::new("never.vdb").exists());
}

#[test]
fn resolution_that_cannot_fit_is_refused_before_allocating() {
    assert_mesh_fails(
        "tetra.obj",
        TETRA.as_bytes(),
        &["-r", "2000000"],
        &["resolution too large", "MiB", "tetra.obj"],
    );
    assert_mesh_fails(
        "tetra.obj",
        TETRA.as_bytes(),
        &["-r", "512", "--max-memory", "1"],
        &["resolution too large"],
    );
}

#[test]
fn unwritable_output_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("tetra.obj");
    std::fs::write(&input, TETRA).unwrap();
    let missing_dir = dir.path().join("no-such-dir").join("out.vdb");
    let o = voxelkit(&[
        "mesh",
        input.to_str().unwrap(),
        "-r",
        "16",
        "-o",
        missing_dir.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(text(&o).contains("no-such-dir/out.vdb"), "{}", text(&o));
    // The output path is an existing directory: the rename fails, the temporary goes away.
    let as_dir = dir.path().join("taken.vdb");
    std::fs::create_dir(&as_dir).unwrap();
    let o = voxelkit(&[
        "mesh",
        input.to_str().unwrap(),
        "-r",
        "16",
        "-o",
        as_dir.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(text(&o).contains("taken.vdb"));
    assert!(extra_files(dir.path(), &[&input, &as_dir]).is_empty());
    assert_eq!(std::fs::read_dir(&as_dir).unwrap().count(), 0);
}

#[test]
fn degenerate_and_non_manifold_faces_are_reported_not_fatal() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("odd.obj");
    // A tetrahedron plus a zero-area face, a repeated-vertex face and a fin sharing edge 1-2.
    let content = format!("{TETRA}v 2 0 0\nv 0 0 -1\nf 1 2 5\nf 1 1 2\nf 1 2 6\n");
    std::fs::write(&input, content).unwrap();
    let output = dir.path().join("odd.vdb");
    let o = voxelkit(&[
        "mesh",
        input.to_str().unwrap(),
        "-r",
        "32",
        "-o",
        output.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("\"degenerate_faces\":2"),
        "{}",
        text(&o)
    );
    assert!(output.exists());
}

#[test]
fn bad_shape_parameters_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("s.vdb");
    let o = voxelkit(&[
        "shape",
        "sphere",
        "--radius=-1",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success() && text(&o).contains("--radius"));
    let o = voxelkit(&[
        "shape",
        "cylinder",
        "--axis",
        "0,0,0",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success() && text(&o).contains("--axis"));
    assert!(!out.exists());
}

#[test]
fn info_on_a_file_that_is_not_vdb_fails_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("fake.vdb");
    std::fs::write(&f, b"not a vdb").unwrap();
    let o = voxelkit(&["info", f.to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(
        text(&o).contains("fake.vdb") && !text(&o).contains("panicked"),
        "{}",
        text(&o)
    );
}

#[test]
fn mesh_shape_info_and_demo_produce_real_files() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("tetra.obj");
    std::fs::write(&obj, TETRA).unwrap();
    let vdb = dir.path().join("tetra.vdb");
    let o = voxelkit(&[
        "mesh",
        obj.to_str().unwrap(),
        "-r",
        "40",
        "-s",
        "6",
        "--normals",
        "-o",
        vdb.to_str().unwrap(),
        "--json",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let json = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(
        json.starts_with('{')
            && json.contains("\"separability\":6")
            && json.contains("\"peak_mib\""),
        "{json}"
    );
    let o = voxelkit(&["info", vdb.to_str().unwrap()]);
    let t = text(&o);
    assert!(o.status.success());
    for s in [
        "density",
        "normal",
        "method = huang-separating",
        "separability = 6",
        "resolution = 40",
        "tetra.obj",
    ] {
        assert!(t.contains(s), "`{s}` missing from info: {t}");
    }
    let sphere = dir.path().join("sphere.vdb");
    let plain = dir.path().join("plain.vdb");
    let ball = ["shape", "sphere", "--radius", "2", "-r", "32", "-o"];
    let o = voxelkit(&[&ball[..], &[sphere.to_str().unwrap()]].concat());
    assert!(o.status.success() && sphere.exists(), "{}", text(&o));
    assert!(text(&o).contains(", 26-separating,"), "{}", text(&o));
    // The paper's plain slabs are said to be unguaranteed, in the summary and the JSON.
    let args = [
        &ball[..],
        &[plain.to_str().unwrap(), "--no-curvature-margin"],
    ]
    .concat();
    let o = voxelkit(&args);
    assert!(
        o.status.success() && text(&o).contains("separation not guaranteed"),
        "{}",
        text(&o)
    );
    let o = voxelkit(&[&["--json"][..], &args].concat());
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(report["curvature_margin"], false, "{report}");
    let demo = dir.path().join("demo");
    let o = voxelkit(&["demo", "-o", demo.to_str().unwrap(), "-r", "64"]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(
        text(&o).contains("26-separating") && text(&o).contains("6-separating"),
        "{}",
        text(&o)
    );
    for f in ["trefoil.obj", "trefoil-6.vdb", "trefoil-26.vdb"] {
        assert!(demo.join(f).exists(), "{f}");
    }
    // The grids the README says the demo writes: the surface as `density`, and `normal`.
    let info = text(&voxelkit(&[
        "info",
        demo.join("trefoil-26.vdb").to_str().unwrap(),
    ]));
    let grids: Vec<&str> = info
        .lines()
        .filter_map(|l| l.strip_prefix("  ")?.split(' ').next())
        .filter(|name| !name.is_empty())
        .collect();
    assert_eq!(grids, ["density", "normal"], "{info}");
}

/// The subcommands `-h` lists for `path` (none for a leaf command).
fn subcommands(path: &[&str]) -> Vec<String> {
    let mut args = path.to_vec();
    args.push("-h");
    let help = text(&voxelkit(&args));
    help.lines()
        .skip_while(|l| *l != "Commands:")
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next().map(str::to_string))
        .filter(|name| name != "help")
        .collect()
}

#[test]
fn every_option_and_argument_has_a_short_help() {
    let mut commands: Vec<Vec<String>> = vec![vec![]];
    let mut undescribed = Vec::new();
    let mut seen = 0;
    while let Some(path) = commands.pop() {
        let path_str: Vec<&str> = path.iter().map(String::as_str).collect();
        for sub in subcommands(&path_str) {
            let mut child = path.clone();
            child.push(sub);
            commands.push(child);
        }
        let mut args = path_str.clone();
        args.push("-h");
        let help = text(&voxelkit(&args));
        for line in help.lines() {
            // `  -o, --output <OUTPUT>  Text` or `  <INPUT>  Text`: a name, two spaces, its help.
            let trimmed = line.trim_start();
            let is_entry =
                line.starts_with("  ") && (trimmed.starts_with('-') || trimmed.starts_with('<'));
            if !is_entry || path.is_empty() && trimmed.starts_with("-V") {
                continue;
            }
            seen += 1;
            let described = trimmed
                .split_once("  ")
                .map(|(_, rest)| rest.trim())
                .is_some_and(|rest| !rest.is_empty() && !rest.starts_with("[default"));
            if !described {
                undescribed.push(format!("voxelkit {} : {trimmed}", path.join(" ")));
            }
        }
    }
    assert!(seen > 100, "only {seen} options found");
    assert!(undescribed.is_empty(), "{}", undescribed.join("\n"));
}

/// Write options (`--grids`, `--compression`, `--half`, `--preview`) belong to the commands
/// that write a .vdb, `--up-axis` to those that read meshes (and `render`, where it names the
/// grid's up axis): elsewhere they are refused, not ignored, and not listed.
#[test]
fn options_are_taken_only_where_they_act() {
    let dir = tempfile::tempdir().unwrap();
    let vdb = dir.path().join("s.vdb");
    let v = vdb.to_str().unwrap();
    let o = voxelkit(&["shape", "sphere", "-r", "16", "--half", "-o", v]);
    assert!(o.status.success(), "{}", text(&o));
    let png = dir.path().join("s.png");
    let p = png.to_str().unwrap();
    let refused: [(&[&str], &[&str]); 6] = [
        (&["info", v], &["--up-axis", "y"]),
        (&["info", v], &["--half"]),
        (&["render", v, "-o", p], &["--grids", "density"]),
        (&["render", v, "-o", p], &["--preview"]),
        (&["measure", v], &["--compression", "none"]),
        (&["csg", "union", v, v, "-o", p], &["--up-axis", "y"]),
    ];
    for (command, option) in refused {
        let args = [command, option].concat();
        let o = voxelkit(&args);
        assert!(
            !o.status.success() && text(&o).contains("unexpected argument"),
            "{args:?}: {}",
            text(&o)
        );
        let help = text(&voxelkit(&[command[0], "-h"]));
        assert!(
            !help.contains(option[0]),
            "{} -h lists {}",
            command[0],
            option[0]
        );
    }
    let o = voxelkit(&["render", v, "--up-axis", "y", "-o", p]);
    assert!(o.status.success() && png.exists(), "{}", text(&o));
}

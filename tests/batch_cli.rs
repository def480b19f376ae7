//! Several inputs in one call: frame sequences share one grid (voxel size and origin, from
//! the union of the frames' boxes), lists of files go into `--out-dir` named after their
//! inputs, a failing input is reported while the others are written (non-zero exit), and
//! calls that cannot be told apart are refused before any work. glTF inputs run through the
//! same commands.
#![cfg(all(feature = "vdb", feature = "fixtures"))]

mod cli_support;

use cli_support::{text, voxelkit};
use glam::DVec3;
use std::path::Path;
use voxelkit::io::vdb::read_vdb_info;
use voxelkit::mesh::generate;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Frames 1..=3 of a torus moving along x by `step` per frame.
fn write_frames(dir: &Path, step: f64) {
    for f in 1..=3 {
        let center = DVec3::new(step * f as f64, 0.0, 0.0);
        generate::torus(center, 1.0, 0.3, 24, 12)
            .write_obj(&dir.join(format!("f_{f:04}.obj")))
            .unwrap();
    }
}

#[test]
fn a_frame_sequence_shares_one_voxel_size_and_origin() {
    let dir = tempfile::tempdir().unwrap();
    write_frames(dir.path(), 0.5);
    let input = dir.path().join("f_####.obj");
    let output = dir.path().join("out/v_####.vdb");
    let o = voxelkit(&[
        "mesh",
        s(&input),
        "--frames",
        "1-3",
        "-r",
        "64",
        "-o",
        s(&output),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(
        text(&o).contains("3 of 3 inputs written on one grid"),
        "{}",
        text(&o)
    );
    // The union of the boxes: x from 0.5 - 1.3 to 1.5 + 1.3, the longest axis.
    let h = (1.5 + 1.3 - (0.5 - 1.3)) / 64.0;
    let mut counts = Vec::new();
    for f in 1..=3 {
        let info = read_vdb_info(&dir.path().join(format!("out/v_{f:04}.vdb"))).unwrap();
        let density = &info[0];
        assert!(
            (density.voxel_size[0] - h).abs() < 1e-12,
            "{}",
            density.voxel_size[0]
        );
        let expected = [0.5 - 1.3 + 0.5 * h, -1.3 + 0.5 * h, -0.3 + 0.5 * h];
        for (got, want) in density.origin.iter().zip(expected) {
            assert!((got - want).abs() < 1e-9, "frame {f}");
        }
        counts.push(density.active_voxels);
    }
    // The same torus on the same grid: its voxel count barely changes between frames.
    let (lo, hi) = (counts.iter().min().unwrap(), counts.iter().max().unwrap());
    assert!((hi - lo) * 50 < *lo, "{counts:?}");
}

#[test]
fn a_failing_frame_is_reported_and_the_others_written() {
    let dir = tempfile::tempdir().unwrap();
    write_frames(dir.path(), 0.5);
    std::fs::write(dir.path().join("f_0002.obj"), "v 0 0 0\nf 1 2 3\n").unwrap();
    let input = dir.path().join("f_####.obj");
    let o = voxelkit(&[
        "solid",
        s(&input),
        "--frames",
        "1-4",
        "-r",
        "32",
        "--out-dir",
        s(&dir.path().join("solids")),
    ]);
    let t = text(&o);
    assert!(!o.status.success(), "{t}");
    assert!(t.contains("f_0002.obj") && t.contains("f_0004.obj"), "{t}");
    assert!(t.contains("2 of 4 inputs failed"), "{t}");
    for (f, written) in [(1, true), (2, false), (3, true), (4, false)] {
        let out = dir.path().join(format!("solids/f_{f:04}.vdb"));
        assert_eq!(out.exists(), written, "frame {f}: {t}");
    }
}

#[test]
fn lists_of_inputs_go_into_the_output_folder() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("ball.obj");
    generate::icosphere(DVec3::ZERO, 1.0, 2)
        .write_obj(&a)
        .unwrap();
    // The second input as glTF: every format runs through the same commands.
    let glb = dir.path().join("ring.glb");
    generate::torus(DVec3::ZERO, 1.0, 0.3, 24, 12)
        .write_gltf(&glb, voxelkit::mesh::GltfLayout::Binary, &[])
        .unwrap();
    let out = dir.path().join("vox");
    let o = voxelkit(&[
        "--json",
        "mesh",
        s(&a),
        s(&glb),
        "-r",
        "32",
        "--out-dir",
        s(&out),
        "--format",
        "binvox",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(report["written"], 2);
    assert_eq!(report["inputs"].as_array().unwrap().len(), 2);
    assert!(out.join("ball.binvox").exists() && out.join("ring.binvox").exists());
    // -o with two inputs, and two inputs with one name, are refused before any work.
    let single = dir.path().join("one.vdb");
    let o = voxelkit(&["mesh", s(&a), s(&glb), "-o", s(&single)]);
    assert!(
        !o.status.success() && text(&o).contains("--out-dir"),
        "{}",
        text(&o)
    );
    assert!(!single.exists());
    let other = dir.path().join("sub");
    std::fs::create_dir(&other).unwrap();
    std::fs::copy(&a, other.join("ball.obj")).unwrap();
    let o = voxelkit(&[
        "mesh",
        s(&a),
        s(&other.join("ball.obj")),
        "--out-dir",
        s(&dir.path().join("clash")),
    ]);
    assert!(
        !o.status.success() && text(&o).contains("both be written"),
        "{}",
        text(&o)
    );
    assert!(!dir.path().join("clash").exists());
}

#[test]
fn frame_options_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    write_frames(dir.path(), 0.5);
    let input = dir.path().join("f_####.obj");
    let plain = dir.path().join("f_0001.obj");
    let out = dir.path().join("o.vdb");
    for (args, expected) in [
        (vec!["mesh", s(&input), "-o", s(&out)], "give --frames"),
        (
            vec!["mesh", s(&plain), "--frames", "1-3", "-o", s(&out)],
            "needs `#` in the input",
        ),
        (
            vec!["mesh", s(&input), "--frames", "1-3", "-o", s(&out)],
            "-o needs `#`",
        ),
        (
            vec!["mesh", s(&input), "--frames", "3-1", "-o", s(&out)],
            "must not come before",
        ),
    ] {
        let o = voxelkit(&args);
        assert!(
            !o.status.success() && text(&o).contains(expected),
            "{args:?}: {}",
            text(&o)
        );
        assert!(!out.exists());
    }
}

//! `voxelkit implicit` end to end: named examples and typed formulas written as .vdb files
//! that OpenVDB reads back, the octree levels, and errors that point at the formula's column.
#![cfg(feature = "vdb")]

mod cli_support;

use cli_support::{text, voxelkit};
use voxelkit::io::vdb::read_vdb_info;

#[test]
fn examples_write_vdb_files() {
    let dir = tempfile::tempdir().unwrap();
    for example in ["sphere", "torus", "sinsin", "gear", "crankshaft"] {
        let out = dir.path().join(format!("{example}.vdb"));
        let o = voxelkit(&[
            "implicit",
            "--example",
            example,
            "-r",
            "64",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{example}: {}", text(&o));
        let grids = read_vdb_info(&out).unwrap();
        let surface = grids.iter().find(|g| g.name == "density").unwrap();
        assert!(
            surface.active_voxels > 1000,
            "{example}: {} voxels",
            surface.active_voxels
        );
        assert!(grids.iter().any(|g| g.name == "normal"));
        assert!(surface.metadata.iter().any(|m| m.key == "formula"));
    }
    // A formula may start with a minus sign.
    let out = dir.path().join("ball.vdb");
    let o = voxelkit(&[
        "implicit",
        "-x^2 - y^2 - z^2 + 0.25",
        "-r",
        "32",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
}

/// `--theta-range` (the paper's [0, 2π) by default) and `--squared` reach the octree: the
/// cylindrical spiral θ - r makes its full turn only in [0, 2π), and the squared Fig. 5
/// surface holds every lobe, twice the typed one's voxels.
#[test]
fn theta_range_and_the_squared_substitution_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("s.vdb");
    let voxels = |extra: &[&str], formula: &str, coords: &str, bounds: &str| {
        let mut args = vec![
            "--json",
            "implicit",
            formula,
            "--coords",
            coords,
            "--bounds",
            bounds,
            "-r",
            "64",
            "-o",
            out.to_str().unwrap(),
        ];
        args.extend(extra);
        let o = voxelkit(&args);
        assert!(o.status.success(), "{}", text(&o));
        cli_support::json_field(&String::from_utf8_lossy(&o.stdout), "voxels")
    };
    let spiral = "theta - r + 0*y";
    let full = voxels(&[], spiral, "cylindrical", "-7,7");
    let paper = voxels(
        &["--theta-range", "positive"],
        spiral,
        "cylindrical",
        "-7,7",
    );
    let half = voxels(
        &["--theta-range", "symmetric"],
        spiral,
        "cylindrical",
        "-7,7",
    );
    assert_eq!(full, paper);
    assert!(full > 2.5 * half, "{full} vs {half}");
    let fig5 = "sin(3*theta)*sin(4*phi) - r";
    let typed = voxels(&[], fig5, "spherical", "-1,1");
    let squared = voxels(&["--squared"], fig5, "spherical", "-1,1");
    assert!(
        (1.8..2.2).contains(&(squared / typed)),
        "{squared} vs {typed}"
    );
    let o = voxelkit(&[
        "implicit",
        spiral,
        "--theta-range",
        "degrees",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(
        !o.status.success() && text(&o).contains("positive"),
        "{}",
        text(&o)
    );
}

#[test]
fn levels_are_written_with_their_own_voxel_size() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("levels.vdb");
    let o = voxelkit(&[
        "implicit",
        "sin(3*theta)*sin(4*phi) - r",
        "--coords",
        "spherical",
        "--bounds",
        "-1,1",
        "-r",
        "32",
        "--levels",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let grids = read_vdb_info(&out).unwrap();
    let level = |l: usize| {
        grids
            .iter()
            .find(|g| g.name == format!("level_{l}"))
            .unwrap()
    };
    assert_eq!(level(0).active_voxels, 1);
    assert_eq!(level(0).voxel_size[0], 2.0);
    assert_eq!(level(5).voxel_size[0], 2.0 / 32.0);
    let surface = grids.iter().find(|g| g.name == "density").unwrap();
    assert_eq!(level(5).active_voxels, surface.active_voxels);
    for l in 1..=5 {
        assert!(level(l).active_voxels >= level(l - 1).active_voxels);
        // Each level's normals beside it, on the same voxels.
        let normals = grids
            .iter()
            .find(|g| g.name == format!("level_{l}_normal"))
            .unwrap();
        assert_eq!(normals.active_voxels, level(l).active_voxels);
        assert_eq!(normals.value_type, "vec3s");
    }
}

#[test]
fn bad_formulas_and_arguments_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.vdb");
    let o = out.to_str().unwrap();
    for (args, expect) in [
        (
            vec!["implicit", "x^2 + * y", "-o", o],
            vec!["column 7", "x^2 + * y\n        ^"],
        ),
        (
            vec!["implicit", "x^2 + y^^2 + z^2 - 1", "-o", o],
            vec![
                "column 9",
                "a stray `^` where the power after `^` should be",
            ],
        ),
        (
            vec!["implicit", "q - 1", "-o", o],
            vec!["unknown name `q`", "x y z r theta phi"],
        ),
        (
            vec!["implicit", "x - 1", "--bounds", "1,1", "-o", o],
            vec!["positive size"],
        ),
        (
            vec!["implicit", "x - 1", "--bounds", "a,b", "-o", o],
            vec!["--bounds"],
        ),
        (
            vec!["implicit", "--example", "teapot", "-o", o],
            vec!["no example `teapot`", "gear"],
        ),
        (
            vec!["implicit", "x - 1", "--coords", "polar", "-o", o],
            vec!["cartesian, spherical or cylindrical"],
        ),
        (
            vec!["implicit", "x - 1", "-o", "/nonexistent-folder/x.vdb"],
            vec!["nonexistent-folder"],
        ),
    ] {
        let r = voxelkit(&args);
        let msg = text(&r);
        assert!(!r.status.success(), "{args:?}: {msg}");
        for e in expect {
            assert!(msg.contains(e), "`{e}` missing from: {msg}");
        }
        assert!(!msg.contains("panicked"), "{msg}");
        assert!(!out.exists());
    }
}

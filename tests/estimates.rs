//! Planning's memory estimates against the measured peak of the whole process (`voxelkit
//! --json` reports both), each within 30% of its peak: mesh surfaces (with and without
//! normals) and block-flood solids on five shared meshes, every other fill (span flood,
//! FloodingXYZ, beam, depth layers), lines, `check`, `measure` of a mesh and of a file, CSG
//! trees and Booleans of two grids, the §7 shapes, Catmull-Clark surfaces and solids,
//! distance bands and implicit surfaces (a formula zero everywhere included); and surfaces,
//! solids and level sets of meshes the constants were not fitted on (`voxelkit-bench calibrate`
//! refits them). Every run is its own process, so that each peak is the run's alone.
#![cfg(all(feature = "vdb", feature = "fixtures"))]

mod cli_support;
mod common;

use cli_support::{text, voxelkit};

const MESHES: [&str; 5] = ["bunny-closed", "igea", "horse", "armadillo", "skull"];

/// The estimate over the peak of `voxelkit --json ARGS -o OUT`.
fn ratio(args: &[&str], out: &std::path::Path) -> f64 {
    let mut all = vec!["--json"];
    all.extend(args);
    // `check` and `measure` write nothing.
    if !matches!(args[0], "check" | "measure") {
        all.extend(["-o", out.to_str().unwrap()]);
    }
    let o = voxelkit(&all);
    assert!(o.status.success(), "{args:?}: {}", text(&o));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let (estimated, peak) = (
        report["estimated_mib"].as_f64().unwrap(),
        report["peak_mib"].as_f64().unwrap(),
    );
    eprintln!("{args:?}: estimated {estimated:.0} MiB, peak {peak:.0} MiB");
    estimated / peak
}

/// One test's runs at a time: a run sharing the cores with another's threads peaks lower
/// than it does alone (the halves of its joins no longer overlap).
static ALONE: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Runs every case (so that one failure shows all that are out of bounds) and asserts each
/// estimate within 30% of its peak.
fn all_within_30_percent(cases: &[Vec<String>], out: &std::path::Path) {
    let _alone = ALONE.lock().unwrap_or_else(|e| e.into_inner());
    let outside: Vec<String> = cases
        .iter()
        .filter_map(|case| {
            let args: Vec<&str> = case.iter().map(String::as_str).collect();
            let r = ratio(&args, out);
            (!(0.7..=1.3).contains(&r)).then(|| format!("{args:?}: estimate / peak = {r:.2}"))
        })
        .collect();
    assert!(outside.is_empty(), "{}", outside.join("\n"));
}

#[test]
fn estimates_are_within_30_percent_of_the_peak() {
    let Some(data) = common::data_dir() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.vdb");
    let mut cases: Vec<Vec<String>> = Vec::new();
    for name in MESHES {
        let mesh = data
            .join(format!("meshes/{name}.obj"))
            .display()
            .to_string();
        for command in ["mesh", "solid"] {
            cases.push(vec![
                command.into(),
                mesh.clone(),
                "-r".into(),
                "1024".into(),
            ]);
        }
    }
    let bunny = data.join("meshes/bunny-closed.obj").display().to_string();
    cases.push(vec![
        "mesh".into(),
        bunny,
        "-r".into(),
        "512".into(),
        "--normals".into(),
    ]);
    let subd = |name: &str| data.join(format!("subd/{name}.obj")).display().to_string();
    for shape in ["sphere", "cylinder", "quadric"] {
        cases.push(vec![
            "shape".into(),
            shape.into(),
            "-r".into(),
            "1024".into(),
        ]);
    }
    for name in ["spot_control_mesh", "catmark_torus"] {
        cases.push(vec![
            "subdiv".into(),
            subd(name),
            "-r".into(),
            "1024".into(),
        ]);
    }
    for (name, kind) in [("bunny-closed", "--sdf"), ("igea", "--udf")] {
        let mesh = data
            .join(format!("meshes/{name}.obj"))
            .display()
            .to_string();
        cases.push(vec![
            "mesh".into(),
            mesh,
            kind.into(),
            "-r".into(),
            "1024".into(),
        ]);
    }
    for formula in ["x^2 + y^2 + z^2 - 0.5", "0*x"] {
        cases.push(vec![
            "implicit".into(),
            formula.into(),
            "-r".into(),
            "256".into(),
        ]);
    }
    for example in ["gear", "sinsin"] {
        cases.push(vec![
            "implicit".into(),
            "--example".into(),
            example.into(),
            "-r".into(),
            "1024".into(),
        ]);
    }
    // Every other way to fill, check, measure or trace a mesh, and Catmull-Clark solids.
    let meshes = |name: &str| {
        data.join(format!("meshes/{name}.obj"))
            .display()
            .to_string()
    };
    for (command, name, resolution, extra) in [
        (
            "solid",
            "bunny-closed",
            "1024",
            &["--inside", "parity", "--flood", "spans"][..],
        ),
        (
            "solid",
            "armadillo",
            "512",
            &["--inside", "parity", "--flood", "xyz"][..],
        ),
        ("solid", "igea", "1024", &["--method", "beam"][..]),
        ("solid", "horse", "1024", &["--method", "depth-layers"][..]),
        ("lines", "cow", "2048", &[][..]),
        ("lines", "igea", "512", &[][..]),
        ("check", "armadillo", "1024", &[][..]),
        ("measure", "igea", "1024", &[][..]),
    ] {
        let mut case = vec![command.into(), meshes(name), "-r".into(), resolution.into()];
        case.extend(extra.iter().map(|s| s.to_string()));
        cases.push(case);
    }
    for (name, resolution) in [("catmark_cube", "512"), ("spot_control_mesh", "256")] {
        cases.push(vec![
            "subdiv".into(),
            subd(name),
            "-r".into(),
            resolution.into(),
            "--solid".into(),
        ]);
    }
    // CSG: a tree of shapes and a formula (the flange at 1024), and two solids on one grid
    // combined; `measure` of a solid's file.
    let flange = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/csg/flange.json"),
    )
    .unwrap()
    .replace("\"resolution\": 256", "\"resolution\": 1024");
    let tree = dir.path().join("flange.json");
    std::fs::write(&tree, flange).unwrap();
    cases.push(vec![
        "csg".into(),
        "--tree".into(),
        tree.display().to_string(),
    ]);
    let solids = dir.path().join("solids");
    let made = voxelkit(&[
        "solid",
        &meshes("bunny-closed"),
        &meshes("armadillo"),
        "--shared-grid",
        "-r",
        "1024",
        "--out-dir",
        solids.to_str().unwrap(),
    ]);
    assert!(made.status.success(), "{}", text(&made));
    let solid = |name: &str| solids.join(format!("{name}.vdb")).display().to_string();
    cases.push(vec![
        "csg".into(),
        "union".into(),
        solid("bunny-closed"),
        solid("armadillo"),
    ]);
    cases.push(vec!["measure".into(), solid("bunny-closed")]);
    all_within_30_percent(&cases, &out);
}

/// The constants hold on closed meshes they were not fitted on (thin claws, a CAD part, a
/// mechanical part, a quadrangulated character), on an open one's surface, and on a creased
/// Catmull-Clark surface.
#[test]
fn estimates_hold_on_meshes_they_were_not_fitted_on() {
    let Some(data) = common::data_dir() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.vdb");
    let mut cases: Vec<Vec<String>> = Vec::new();
    for name in ["scorpion", "fandisk", "rocker-arm", "spot_triangulated"] {
        let mesh = data
            .join(format!("meshes/{name}.obj"))
            .display()
            .to_string();
        for command in [&["mesh"][..], &["solid"], &["mesh", "--sdf"]] {
            // rocker-arm's surface at 1024 peaks at 23-24 MiB, mostly the process itself, where
            // a MiB of noise moves the ratio by 4%: at 2048 the surface is what is measured.
            let resolution = if name == "rocker-arm" && command == ["mesh"] {
                "2048"
            } else {
                "1024"
            };
            let mut case: Vec<String> = command.iter().map(|s| s.to_string()).collect();
            case.extend([mesh.clone(), "-r".into(), resolution.into()]);
            cases.push(case);
        }
    }
    let ogre = data.join("meshes/ogre.obj").display().to_string();
    cases.push(vec!["mesh".into(), ogre, "-r".into(), "1024".into()]);
    // Semi-sharp creases: 280 edges of sharpness 7.9, whose quadtrees are most of the peak.
    let rook = data.join("subd/catmark_rook.obj").display().to_string();
    for resolution in ["256", "1024"] {
        cases.push(vec![
            "subdiv".into(),
            rook.clone(),
            "-r".into(),
            resolution.into(),
        ]);
    }
    all_within_30_percent(&cases, &out);
}

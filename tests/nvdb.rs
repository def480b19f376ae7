//! NanoVDB output checked by NanoVDB itself: `.nvdb` files the CLI writes for the shared
//! meshes (a surface with normals and booleans, a solid with tiles, a level set with interior
//! tiles, negative indices) pass `nanovdb_validate` (checksums included), list in
//! `nanovdb_print` with the `.vdb`'s grids and voxel counts, and hold, read by NanoVDB's
//! headers (`tests/nvdb/same_grids.cpp`), the same voxels, values and tiles as
//! `nanovdb_convert` makes from the `.vdb` of the same run.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

fn voxelkit() -> Command {
    Command::new(env!("CARGO_BIN_EXE_voxelkit"))
}

fn have(tool: &str) -> bool {
    Command::new("sh")
        .args(["-c", &format!("command -v {tool}")])
        .output()
        .is_ok_and(|o| o.status.success())
}

/// NanoVDB's tools and headers and a C++ compiler, or a skip (a failure in CI).
fn nanovdb_ready() -> bool {
    let tools = [
        "nanovdb_validate",
        "nanovdb_print",
        "nanovdb_convert",
        "c++",
    ];
    if let Some(missing) = tools.iter().find(|t| !have(t)) {
        common::skip_or_fail(&format!(
            "{missing} is missing (libnanovdb-tools, libnanovdb-dev, g++): the NanoVDB checks"
        ));
        return false;
    }
    if !Path::new("/usr/include/nanovdb/NanoVDB.h").exists() {
        common::skip_or_fail("NanoVDB's headers are missing (libnanovdb-dev): the NanoVDB checks");
        return false;
    }
    true
}

/// `tests/nvdb/same_grids.cpp`, compiled once.
fn same_grids() -> &'static Path {
    static PROGRAM: OnceLock<PathBuf> = OnceLock::new();
    PROGRAM.get_or_init(|| {
        let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("nvdb");
        std::fs::create_dir_all(&dir).unwrap();
        let program = dir.join("same_grids");
        let source = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/nvdb/same_grids.cpp");
        let out = Command::new("c++")
            .args(["-std=c++17", "-O2", "-Wall", "-Wextra", "-Werror", "-o"])
            .arg(&program)
            .arg(&source)
            .arg("-pthread")
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        program
    })
}

fn run(cmd: &mut Command) -> String {
    let out = cmd.output().unwrap();
    assert!(
        out.status.success(),
        "{cmd:?}: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Runs `args` once to `.vdb` and once to `.nvdb` in `dir`, then checks the `.nvdb` by
/// NanoVDB's tools and against NanoVDB's conversion of the `.vdb`; returns the grid lines.
fn check_run(dir: &Path, name: &str, args: &[&str]) -> String {
    let vdb = dir.join(format!("{name}.vdb"));
    let nvdb = dir.join(format!("{name}.nvdb"));
    for out in [&vdb, &nvdb] {
        run(voxelkit().args(args).arg("-o").arg(out));
    }
    let infos = voxelkit::io::vdb::read_vdb_info(&vdb).unwrap();
    let validated = run(Command::new("nanovdb_validate").arg("-v").arg(&nvdb));
    let printed = run(Command::new("nanovdb_print").arg(&nvdb));
    for info in &infos {
        assert!(
            validated.contains(&format!("Grid named \"{}\": passed", info.name)),
            "{name}: {validated}"
        );
        let row = printed
            .lines()
            .find(|l| l.split_whitespace().nth(1) == Some(info.name.as_str()))
            .unwrap_or_else(|| panic!("{name}: no grid {} in {printed}", info.name));
        assert!(
            row.split_whitespace()
                .any(|w| w == info.active_voxels.to_string()),
            "{name}: {} has {} voxels: {row}",
            info.name,
            info.active_voxels
        );
    }
    let converted = dir.join(format!("{name}.converted.nvdb"));
    run(Command::new("nanovdb_convert").arg(&vdb).arg(&converted));
    let same = run(Command::new(same_grids()).arg(&nvdb).arg(&converted));
    assert_eq!(same.lines().count(), infos.len(), "{name}: {same}");
    same
}

#[test]
fn nvdb_files_hold_what_nanovdb_makes_of_the_vdb() {
    let Some(data) = common::data_dir() else {
        return;
    };
    if !nanovdb_ready() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let mesh = |m: &str| {
        data.join("meshes")
            .join(format!("{m}.obj"))
            .to_string_lossy()
            .into_owned()
    };
    let armadillo = mesh("armadillo");
    let bunny = mesh("bunny-closed");
    let sphere = mesh("sphere");
    let runs: [(&str, Vec<&str>, &[&str]); 4] = [
        (
            "surface",
            vec![
                "mesh",
                &armadillo,
                "-r",
                "160",
                "--normals",
                "--grids",
                "density,voxels,normal",
            ],
            &["density float", "voxels bool", "normal Vec3f"],
        ),
        (
            "solid",
            vec!["solid", &bunny, "-r", "200"],
            &["density float", "shell bool", "interior bool"],
        ),
        // Whole 128^3 blocks inside: tiles of the upper nodes, active in the fog volume and
        // inactive at minus the background in the level set.
        (
            "level-set",
            vec!["mesh", &sphere, "-r", "400", "--sdf"],
            &["density float", "surface float"],
        ),
        // The grid's (0,0,0) voxel inside the mesh: negative indices.
        (
            "negative",
            vec!["solid", &sphere, "-r", "150", "--origin", "0.3,0.2,0.1"],
            &["density float", "shell bool", "interior bool"],
        ),
    ];
    for (name, args, grids) in runs {
        let same = check_run(dir.path(), name, &args);
        for g in grids {
            assert!(same.contains(g), "{name}: {g} missing from {same}");
        }
    }
    // The level set has upper-node tiles (its interior), so the tile walk was exercised.
    let info = voxelkit::io::vdb::read_vdb_info(&dir.path().join("level-set.vdb")).unwrap();
    assert!(info.iter().any(|g| g.name == "density" && g.tile_count > 0));
}

#[test]
fn nvdb_refuses_half_precision_and_batches_write_it() {
    let Some(data) = common::data_dir() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let torus = data.join("meshes/torus.obj");
    let out = dir.path().join("torus.nvdb");
    let refused = voxelkit()
        .arg("mesh")
        .arg(&torus)
        .args(["-r", "32", "--half", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(!refused.status.success());
    let message = String::from_utf8_lossy(&refused.stderr);
    assert!(
        message.contains("torus.nvdb") && message.contains("half"),
        "{message}"
    );
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        0,
        "nothing is left"
    );

    let folder = dir.path().join("out");
    run(voxelkit()
        .arg("mesh")
        .arg(&torus)
        .arg(data.join("meshes/sphere.obj"))
        .args(["-r", "32", "--format", "nvdb", "--out-dir"])
        .arg(&folder));
    for name in ["torus.nvdb", "sphere.nvdb"] {
        let bytes = std::fs::read(folder.join(name)).unwrap();
        assert_eq!(&bytes[..8], b"NanoVDB0", "{name}");
    }
    if nanovdb_ready() {
        run(Command::new("nanovdb_validate").arg(folder.join("torus.nvdb")));
    }
}

//! The C interface as a C or C++ user meets it: `scripts/install.sh` into a fresh prefix,
//! the C++ example built by CMake with `-Wall -Wextra -Werror` against the static and the
//! shared library and checked against the Rust API, and the C smoke test (every capability,
//! every misuse) built through pkg-config and run under valgrind.
#![cfg(feature = "vdb")]

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;
use voxelkit::io::vdb::read_vdb_grid;
use voxelkit::mesh::{GridFit, Mesh, fit_transform, generate};
use voxelkit::voxelize::separating::{SeparatingOptions, voxelize_mesh};

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn run(cmd: &mut Command) -> Output {
    let out = cmd.output().unwrap_or_else(|e| panic!("{cmd:?}: {e}"));
    assert!(
        out.status.success(),
        "{cmd:?} failed:\n{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn have(tool: &str) -> bool {
    Command::new(tool)
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
}

/// One installation for all tests of this file.
fn prefix() -> &'static Path {
    static PREFIX: OnceLock<tempfile::TempDir> = OnceLock::new();
    PREFIX
        .get_or_init(|| {
            let dir = tempfile::tempdir().unwrap();
            run(Command::new(repo().join("scripts/install.sh")).arg(dir.path()));
            dir
        })
        .path()
}

/// A closed mesh from the shared data, or a generated one in a clean clone.
fn test_mesh(dir: &Path) -> PathBuf {
    match common::data_dir() {
        Some(data) => data.join("meshes/bunny-closed.obj"),
        None => {
            let path = dir.join("torus.obj");
            generate::torus(glam::DVec3::ZERO, 1.0, 0.35, 64, 32)
                .write_obj(&path)
                .unwrap();
            path
        }
    }
}

fn field(text: &str, key: &str) -> u64 {
    text.lines()
        .find_map(|l| l.strip_prefix(key)?.trim().parse().ok())
        .unwrap_or_else(|| panic!("{key} missing from {text}"))
}

#[test]
fn the_cpp_example_builds_with_werror_static_and_shared_and_matches_the_rust_api() {
    if !have("cmake") {
        return common::skip_or_fail("cmake is not installed: the C++ example test");
    }
    let work = tempfile::tempdir().unwrap();
    let mesh_path = test_mesh(work.path());
    let resolution = 128;
    let mesh = Mesh::load(&mesh_path).unwrap();
    let t = fit_transform(&mesh.bbox(), GridFit::Resolution(resolution)).unwrap();
    let expected = voxelize_mesh(
        &mesh,
        t,
        &SeparatingOptions::default(),
        &voxelkit::progress::Progress::none(),
    )
    .unwrap()
    .0
    .voxel_count();
    for (static_link, name) in [(false, "shared"), (true, "static")] {
        let build = work.path().join(name);
        run(Command::new("cmake")
            .arg("-S")
            .arg(repo().join("examples/cpp"))
            .arg("-B")
            .arg(&build)
            .arg(format!("-DCMAKE_PREFIX_PATH={}", prefix().display()))
            .arg(format!(
                "-DVOXELKIT_STATIC={}",
                if static_link { "ON" } else { "OFF" }
            ))
            .arg("-DCMAKE_CXX_FLAGS=-Wall -Wextra -Werror"));
        run(Command::new("cmake").arg("--build").arg(&build));
        let exe = build.join("voxelize_to_openvdb");
        let deps = String::from_utf8_lossy(&run(Command::new("ldd").arg(&exe)).stdout).to_string();
        assert_eq!(
            deps.contains("libvoxelkit.so"),
            !static_link,
            "{name}: {deps}"
        );
        let vdb = work.path().join(format!("{name}.vdb"));
        let out = run(Command::new(&exe)
            .arg(&mesh_path)
            .arg(resolution.to_string())
            .arg(&vdb));
        let text = String::from_utf8_lossy(&out.stdout);
        assert_eq!(field(&text, "voxelkit_voxels"), expected, "{name}: {text}");
        assert_eq!(field(&text, "openvdb_voxels"), expected, "{name}: {text}");
        assert!(field(&text, "mesh_quads") > 0, "{name}: {text}");
        let written = read_vdb_grid(&vdb, Some("density")).unwrap();
        assert_eq!(written.voxel_count(), expected);
        assert_eq!(written.transform, t);
        eprintln!("C++ example ({name}): {expected} voxels, as the Rust API; {text}");
    }
}

#[test]
fn the_c_smoke_test_passes_static_and_shared_and_runs_clean_under_valgrind() {
    if !have("pkg-config") || !have("gcc") {
        return common::skip_or_fail("gcc or pkg-config is missing: the C smoke test");
    }
    let work = tempfile::tempdir().unwrap();
    let mesh_path = test_mesh(work.path());
    let pkg_config_path = prefix().join("lib/pkgconfig");
    let valgrind = have("valgrind");
    if !valgrind {
        common::skip_or_fail("valgrind is not installed: the leak and invalid-read check");
    }
    for package in ["voxelkit", "voxelkit-static"] {
        let flags = run(Command::new("pkg-config")
            .env("PKG_CONFIG_PATH", &pkg_config_path)
            .args(["--cflags", "--libs", package]));
        let flags = String::from_utf8_lossy(&flags.stdout).to_string();
        let exe = work.path().join(package);
        run(Command::new("gcc")
            .args(["-std=c11", "-Wall", "-Wextra", "-Werror", "-pedantic"])
            .arg(repo().join("tests/c/smoke.c"))
            .args(flags.split_whitespace())
            .arg("-o")
            .arg(&exe));
        let vdb = work.path().join(format!("{package}.vdb"));
        let out = run(Command::new(&exe)
            .arg(&mesh_path)
            .arg(&vdb)
            .env("RUST_BACKTRACE", "0"));
        assert_eq!(String::from_utf8_lossy(&out.stdout).trim(), "ok");
        if valgrind {
            let out = run(Command::new("valgrind")
                .args([
                    "--leak-check=full",
                    "--show-leak-kinds=definite",
                    "--errors-for-leak-kinds=definite",
                    "--error-exitcode=99",
                ])
                .arg(&exe)
                .arg(&mesh_path)
                .arg(&vdb)
                .env("RUST_BACKTRACE", "0"));
            let report = String::from_utf8_lossy(&out.stderr);
            assert!(report.contains("ERROR SUMMARY: 0 errors"), "{report}");
            assert!(report.contains("definitely lost: 0 bytes"), "{report}");
            eprintln!("{package} under valgrind: 0 errors, 0 bytes definitely lost");
        }
    }
}

//! The C interface as a C or C++ user meets it: `scripts/install.sh` into a fresh prefix,
//! the C++ example built by CMake with `-Wall -Wextra -Werror` against the static and the
//! shared library and checked against the Rust API, and the C smoke test (every capability,
//! every misuse) built through pkg-config and run under valgrind.
#![cfg(all(feature = "vdb", feature = "fixtures"))]

mod cli_support;
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

/// `tests/c/NAME.c` built strictly (C11, every warning an error) against the installed
/// static library, into `dir`.
fn static_c_program(name: &str, dir: &Path) -> PathBuf {
    let flags = run(Command::new("pkg-config")
        .env("PKG_CONFIG_PATH", prefix().join("lib/pkgconfig"))
        .args(["--cflags", "--libs", "voxelkit-static"]));
    let exe = dir.join(name);
    run(Command::new("gcc")
        .args(["-std=c11", "-Wall", "-Wextra", "-Werror", "-pedantic"])
        .arg(repo().join(format!("tests/c/{name}.c")))
        .args(String::from_utf8_lossy(&flags.stdout).split_whitespace())
        .arg("-o")
        .arg(&exe));
    exe
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

/// The number after `key` on a line of a program's output.
fn field<T: std::str::FromStr>(text: &str, key: &str) -> T {
    text.lines()
        .find_map(|l| l.strip_prefix(&format!("{key} "))?.trim().parse().ok())
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
        assert_eq!(
            field::<u64>(&text, "voxelkit_voxels"),
            expected,
            "{name}: {text}"
        );
        assert_eq!(
            field::<u64>(&text, "openvdb_voxels"),
            expected,
            "{name}: {text}"
        );
        assert!(field::<u64>(&text, "mesh_quads") > 0, "{name}: {text}");
        let written = read_vdb_grid(&vdb, Some("density")).unwrap();
        assert_eq!(written.voxel_count(), expected);
        assert_eq!(written.transform, t);
        // vk::to_openvdb gives the grid the metadata and class the CLI's file gives it.
        let cli = work.path().join(format!("{name}-cli.vdb"));
        run(Command::new(env!("CARGO_BIN_EXE_voxelkit"))
            .arg("mesh")
            .arg(&mesh_path)
            .args(["-r", &resolution.to_string(), "-o"])
            .arg(&cli));
        let density = |path: &Path| {
            let infos = voxelkit::io::vdb::read_vdb_info(path).unwrap();
            let info = infos.into_iter().find(|i| i.name == "density").unwrap();
            // Less the writer's bookkeeping, which OpenVDB writes only when set.
            let items: Vec<String> = info
                .metadata
                .iter()
                .filter(|m| m.key != "is_saved_as_half_float")
                .map(|m| format!("{m:?}"))
                .collect();
            (info.grid_class, items)
        };
        assert_eq!(density(&vdb), density(&cli), "{name}");
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

/// The voxels and the metadata of grid `density` in a `.vdb` file.
fn surface_of(path: &Path) -> (Vec<[i64; 3]>, std::collections::BTreeMap<String, String>) {
    let mut voxels: Vec<[i64; 3]> = read_vdb_grid(path, Some("density"))
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .voxels()
        .collect();
    voxels.sort_unstable();
    let info = voxelkit::io::vdb::read_vdb_info(path).unwrap();
    let surface = info.iter().find(|g| g.name == "density").unwrap();
    let meta = surface
        .metadata
        .iter()
        .map(|m| (m.key.clone(), m.value.clone()))
        .collect();
    (voxels, meta)
}

#[test]
fn the_c_interface_and_the_command_line_give_the_same_voxels_and_metadata() {
    if !have("pkg-config") || !have("gcc") {
        return common::skip_or_fail("gcc or pkg-config is missing: the C/CLI equality test");
    }
    let work = tempfile::tempdir().unwrap();
    let dir = work.path();
    let mesh = dir.join("torus.obj");
    generate::torus(glam::DVec3::ZERO, 1.0, 0.35, 48, 24)
        .write_obj(&mesh)
        .unwrap();
    let control = dir.join("cube.obj");
    // A quad cube: a Catmull-Clark control mesh.
    generate::cuboid(glam::DVec3::splat(-1.0), glam::DVec3::ONE)
        .write_obj(&control)
        .unwrap();
    let exe = static_c_program("equality", dir);
    let from_c = dir.join("c");
    std::fs::create_dir(&from_c).unwrap();
    run(Command::new(&exe).arg(&mesh).arg(&control).arg(&from_c));

    let cli = |args: &[&str], name: &str| -> PathBuf {
        let out = dir.join(format!("cli-{name}.vdb"));
        run(Command::new(env!("CARGO_BIN_EXE_voxelkit"))
            .args(args)
            .args(["-r", "64", "-o"])
            .arg(&out));
        out
    };
    let (m, c) = (mesh.to_str().unwrap(), control.to_str().unwrap());
    let c_mesh = from_c.join("mesh.vdb");
    let c_lines = from_c.join("lines.vdb");
    let pairs = [
        ("mesh", cli(&["mesh", m], "mesh")),
        (
            "projective",
            cli(&["mesh", m, "--method", "projective"], "projective"),
        ),
        ("lines", cli(&["lines", m], "lines")),
        ("solid", cli(&["solid", m], "solid")),
        ("subdiv", cli(&["subdiv", c], "subdiv")),
        (
            "implicit",
            cli(&["implicit", "x^2 + y^2 + z^2 - 0.5"], "implicit"),
        ),
    ];
    for (name, from_cli) in &pairs {
        let (c_voxels, c_meta) = surface_of(&from_c.join(format!("{name}.vdb")));
        let (cli_voxels, cli_meta) = surface_of(from_cli);
        assert!(!c_voxels.is_empty(), "{name}");
        assert_eq!(c_voxels, cli_voxels, "{name}: the voxels differ");
        assert_eq!(c_meta, cli_meta, "{name}: the metadata differs");
        assert!(
            c_meta.contains_key("method") && c_meta.contains_key("resolution"),
            "{name}"
        );
    }
    // CSG: the CLI combines the C interface's own files, the C interface the grids in memory.
    let out = dir.join("cli-csg.vdb");
    run(Command::new(env!("CARGO_BIN_EXE_voxelkit"))
        .args(["csg", "union"])
        .arg(&c_mesh)
        .arg(&c_lines)
        .arg("-o")
        .arg(&out));
    let (c_voxels, c_meta) = surface_of(&from_c.join("csg.vdb"));
    let (cli_voxels, cli_meta) = surface_of(&out);
    assert_eq!(c_voxels, cli_voxels, "csg: the voxels differ");
    assert_eq!(
        c_meta["method"], cli_meta["method"],
        "csg: the method differs"
    );
}

#[test]
fn handles_survive_racing_frees_and_are_never_reused() {
    if !have("pkg-config") || !have("gcc") {
        return common::skip_or_fail("gcc or pkg-config is missing: the handle race test");
    }
    let work = tempfile::tempdir().unwrap();
    let mesh = work.path().join("torus.obj");
    generate::torus(glam::DVec3::ZERO, 1.0, 0.35, 24, 12)
        .write_obj(&mesh)
        .unwrap();
    let flags = run(Command::new("pkg-config")
        .env("PKG_CONFIG_PATH", prefix().join("lib/pkgconfig"))
        .args(["--cflags", "--libs", "voxelkit"]));
    let exe = work.path().join("race");
    run(Command::new("gcc")
        .args(["-std=c11", "-Wall", "-Wextra", "-Werror", "-pthread"])
        .arg(repo().join("tests/c/race.c"))
        .args(String::from_utf8_lossy(&flags.stdout).split_whitespace())
        .arg("-o")
        .arg(&exe));
    let out = run(Command::new(&exe).arg(&mesh));
    assert_eq!(String::from_utf8_lossy(&out.stdout).trim(), "ok");
    if !have("valgrind") {
        return common::skip_or_fail("valgrind is not installed: the handle race under valgrind");
    }
    let out = run(Command::new("valgrind")
        .args([
            "--error-exitcode=99",
            "--leak-check=full",
            "--errors-for-leak-kinds=definite",
        ])
        .arg(&exe)
        .arg(&mesh));
    let report = String::from_utf8_lossy(&out.stderr);
    assert!(report.contains("ERROR SUMMARY: 0 errors"), "{report}");
}

/// Python's error for `value` as field `field` of request `request`: what the C setter must
/// say too.
fn schema_error(request: &str, field: &str, value: &serde_json::Value) -> String {
    use voxelkit::pipeline::request::*;
    let values = serde_json::json!({ field: value });
    let refused = match request {
        "mesh" => MeshRequest::from_json(values).err(),
        "solid" => SolidRequest::from_json(values).err(),
        "subdiv" => SubdivRequest::from_json(values).err(),
        "lines" => LinesRequest::from_json(values).err(),
        "limits" => LimitsRequest::from_json(values).err(),
        "write" => WriteRequest::from_json(values).err(),
        other => panic!("the C options hold no {other}"),
    };
    refused
        .unwrap_or_else(|| panic!("{request}.{field} took {value}"))
        .to_string()
}

#[test]
fn every_field_of_the_c_options_is_settable_by_name_with_pythons_checks() {
    if !have("pkg-config") || !have("gcc") {
        return common::skip_or_fail("gcc or pkg-config is missing: the C options test");
    }
    let work = tempfile::tempdir().unwrap();
    let flags = run(Command::new("pkg-config")
        .env("PKG_CONFIG_PATH", prefix().join("lib/pkgconfig"))
        .args(["--cflags", "--libs", "voxelkit"]));
    let exe = work.path().join("set_options");
    run(Command::new("gcc")
        .args(["-std=c11", "-Wall", "-Wextra", "-Werror"])
        .arg(repo().join("tests/c/set_options.c"))
        .args(String::from_utf8_lossy(&flags.stdout).split_whitespace())
        .arg("-o")
        .arg(&exe));
    // Every field at its default, then a value of the wrong kind; then the write options and
    // a small grid for the file, 0 MiB meaning the memory available.
    let schema = voxelkit::pipeline::request::schema();
    let bad = serde_json::json!("nonsense");
    let (mut lines, mut expected) = (String::new(), Vec::new());
    for request in ["mesh", "solid", "subdiv", "lines", "limits", "write"] {
        for field in schema[request]["fields"].as_array().unwrap() {
            let name = field["name"].as_str().unwrap();
            lines.push_str(&format!("{request}\t{name}\t{}\n", field["default"]));
            expected.push("ok".to_string());
            lines.push_str(&format!("{request}\t{name}\t{bad}\n"));
            expected.push(format!("error: {}", schema_error(request, name, &bad)));
        }
    }
    for (request, field, value) in [
        ("mesh", "resolution", "16"),
        // Another field of the request keeps the grid; another request's placement changes it.
        ("mesh", "band", "2.0"),
        ("solid", "origin", "[0, 0, 0]"),
        ("mesh", "bounds", "[[0, 0, 0], [0.5, 1, 1]]"),
        ("limits", "max_memory_mib", "0"),
        ("limits", "threads", "0"),
        ("write", "grids", r#"["voxels"]"#),
        ("write", "compression", r#""zip""#),
    ] {
        lines.push_str(&format!("{request}\t{field}\t{value}\n"));
        expected.push("ok".to_string());
    }
    lines.push_str("mesh\tno_such_field\t1\n");
    expected.push(format!(
        "error: {}",
        schema_error("mesh", "no_such_field", &serde_json::json!(1))
    ));
    let out = work.path().join("cube.vdb");
    let mut child = Command::new(&exe)
        .arg(&out)
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    use std::io::Write;
    child
        .stdin
        .take()
        .unwrap()
        .write_all(lines.as_bytes())
        .unwrap();
    let done = child.wait_with_output().unwrap();
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    let said: Vec<String> = String::from_utf8_lossy(&done.stdout)
        .lines()
        .map(str::to_string)
        .collect();
    let sent: Vec<&str> = lines.lines().collect();
    assert!(expected.len() > 50, "only {} settings", expected.len());
    for ((line, want), got) in sent.iter().zip(&expected).zip(&said) {
        assert_eq!(got, want, "{line}");
    }
    assert_eq!(said.len(), expected.len());
    // The write options reached the file: only `voxels`, at 16 voxels across the bounds'
    // longest side, centres on multiples of the voxel size, none beyond x = 0.5.
    let voxels = read_vdb_grid(&out, Some("voxels")).unwrap();
    assert!(voxels.voxel_count() > 0);
    assert!(read_vdb_grid(&out, Some("density")).is_err());
    let t = voxels.transform;
    assert!((t.voxel_size - 1.0 / 16.0).abs() < 1e-9, "{}", t.voxel_size);
    assert_eq!(t.origin, glam::DVec3::ZERO);
    let b = voxels.bbox().unwrap();
    assert!(b.min[0] >= 0 && b.max[0] == 8, "{b:?}");
}

/// A level set OpenVDB wrote (pyopenvdb's level-set sphere), read through `vk_grid_read_vdb`
/// and subtracted from a solid box with `vk_grid_combine`, removes every voxel OpenVDB holds
/// negative, its interior tiles included.
#[test]
fn a_level_set_read_through_c_stands_for_its_inside() {
    if !have("pkg-config") || !have("gcc") {
        return common::skip_or_fail("gcc or pkg-config is missing: the C level-set operand test");
    }
    let work = tempfile::tempdir().unwrap();
    let dir = work.path();
    let sphere = dir.join("sphere.vdb");
    let Some(out) =
        cli_support::run_pyopenvdb(cli_support::OPENVDB_SPHERE, &sphere, "an OpenVDB level set")
    else {
        return;
    };
    let mut words = out.split_whitespace();
    let negative: u64 = words.next().unwrap().parse().unwrap();
    let h: f64 = words.next().unwrap().parse().unwrap();
    let half = 50.5 * h;
    generate::cuboid(glam::DVec3::splat(-half), glam::DVec3::splat(half))
        .write_obj(&dir.join("box.obj"))
        .unwrap();
    let boxed = dir.join("box.vdb");
    run(Command::new(env!("CARGO_BIN_EXE_voxelkit"))
        .arg("solid")
        .arg(dir.join("box.obj"))
        .args(["--voxel-size", &format!("{h:?}"), "-o"])
        .arg(&boxed));
    let exe = static_c_program("level_set_operand", dir);
    let printed = run(Command::new(&exe).arg(&boxed).arg(&sphere));
    let text = String::from_utf8_lossy(&printed.stdout);
    let counts: Vec<u64> = text
        .split_whitespace()
        .map(|w| w.parse().unwrap())
        .collect();
    assert_eq!(counts[0] - counts[1], negative, "{text}");
}

/// A level set made and read in memory through C (values against the exact distance of a
/// box, measures, a Boolean operand, its surface mesh) and a grid rebuilt from its leaves:
/// `in_memory.c`, under valgrind; its level set file holds what the CLI's `--sdf` file holds,
/// its mesh file the CLI's `--mesh-out`, and its `.nvdb` passes NanoVDB's validation.
#[test]
fn a_level_set_in_memory_through_c_is_the_clis_and_grids_rebuild_from_leaves() {
    if !have("pkg-config") || !have("gcc") {
        return common::skip_or_fail("gcc or pkg-config is missing: the C in-memory test");
    }
    let work = tempfile::tempdir().unwrap();
    let dir = work.path();
    let flags = run(Command::new("pkg-config")
        .env("PKG_CONFIG_PATH", prefix().join("lib/pkgconfig"))
        .args(["--cflags", "--libs", "voxelkit"]));
    let exe = dir.join("in_memory");
    run(Command::new("gcc")
        .args(["-std=c11", "-Wall", "-Wextra", "-Werror", "-pedantic"])
        .arg(repo().join("tests/c/in_memory.c"))
        .args(String::from_utf8_lossy(&flags.stdout).split_whitespace())
        .arg("-lm")
        .arg("-o")
        .arg(&exe));
    let from_c = dir.join("c.vdb");
    let nvdb = dir.join("c.nvdb");
    let out = run(Command::new(&exe).arg(&from_c).arg(&nvdb));
    assert_eq!(String::from_utf8_lossy(&out.stdout).trim(), "ok");
    // The same level set for NanoVDB, by extension.
    assert_eq!(&std::fs::read(&nvdb).unwrap()[..8], b"NanoVDB0");
    if have("nanovdb_validate") {
        let out = run(Command::new("nanovdb_validate").arg("-v").arg(&nvdb));
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(text.contains("Grid named \"surface\": passed"), "{text}");
    } else {
        common::skip_or_fail("nanovdb_validate is missing (libnanovdb-tools): the C .nvdb check");
    }
    if have("valgrind") {
        let out = run(Command::new("valgrind")
            .args(["--leak-check=full", "--errors-for-leak-kinds=definite"])
            .args(["--show-leak-kinds=definite", "--error-exitcode=99"])
            .arg(&exe)
            .arg(dir.join("valgrind.vdb")));
        let report = String::from_utf8_lossy(&out.stderr);
        assert!(report.contains("ERROR SUMMARY: 0 errors"), "{report}");
    } else {
        common::skip_or_fail("valgrind is not installed: the leak and invalid-read check");
    }
    // The same box through the CLI.
    let obj = dir.join("box.obj");
    generate::cuboid(glam::DVec3::ZERO, glam::DVec3::new(1.0, 1.0, 2.0))
        .write_obj(&obj)
        .unwrap();
    let from_cli = dir.join("cli.vdb");
    run(Command::new(env!("CARGO_BIN_EXE_voxelkit"))
        .args(["mesh", "--sdf", "-r", "40", "-o"])
        .arg(&from_cli)
        .arg("--mesh-out")
        .arg(dir.join("cli.ply"))
        .arg(&obj));
    // The surface mesh C wrote is the CLI's --mesh-out.
    let (c_mesh, cli_mesh) = (
        Mesh::load(&dir.join("c.vdb.ply")).unwrap(),
        Mesh::load(&dir.join("cli.ply")).unwrap(),
    );
    assert_eq!(c_mesh.positions, cli_mesh.positions);
    assert_eq!(c_mesh.indices, cli_mesh.indices);
    let (c, cli) = (
        read_vdb_grid(&from_c, Some("surface")).unwrap(),
        read_vdb_grid(&from_cli, Some("surface")).unwrap(),
    );
    assert_eq!(c.transform, cli.transform);
    assert_eq!(c.voxel_count(), cli.voxel_count());
    for leaf in cli.leaves() {
        let other = c.leaf(leaf.origin).expect("the same leaves");
        assert_eq!(other.mask, leaf.mask);
        let (a, b) = (other.value.as_ref().unwrap(), leaf.value.as_ref().unwrap());
        assert!(leaf.offsets().all(|n| a[n] == b[n]), "{:?}", leaf.origin);
    }
    let (c_inside, cli_inside) = (
        voxelkit::io::vdb::read_vdb_solid(&from_c, Some("surface")).unwrap(),
        voxelkit::io::vdb::read_vdb_solid(&from_cli, Some("surface")).unwrap(),
    );
    assert!(c_inside.voxel_count() > 0 && c_inside.voxel_count() == cli_inside.voxel_count());
}

/// The installed shared library exports the header's functions and nothing else, without
/// debug information (kept beside it).
#[test]
fn the_installed_library_exports_exactly_the_headers_functions_stripped() {
    if !have("nm") {
        return common::skip_or_fail("nm is missing: the exported-symbol check");
    }
    let lib = prefix().join("lib/libvoxelkit.so");
    let out = run(Command::new("nm").args(["-D", "--defined-only"]).arg(&lib));
    let mut exported: Vec<String> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| l.split_whitespace().nth(2).map(str::to_string))
        .collect();
    exported.sort();
    let header = std::fs::read_to_string(repo().join("include/voxelkit.h")).unwrap();
    let mut declared: Vec<String> = header
        .split(|c: char| !(c.is_alphanumeric() || c == '_'))
        .filter(|w| w.starts_with("vk_"))
        .filter(|w| header.contains(&format!("{w}(")))
        .map(str::to_string)
        .collect();
    declared.sort();
    declared.dedup();
    assert_eq!(exported, declared);
    let size = std::fs::metadata(&lib).unwrap().len();
    assert!(prefix().join("lib/libvoxelkit.so.debug").is_file());
    let sections = run(Command::new("objdump").arg("-h").arg(&lib));
    assert!(!String::from_utf8_lossy(&sections.stdout).contains(".debug_info"));
    eprintln!(
        "libvoxelkit.so: {size} bytes, {} exported symbols",
        exported.len()
    );
}

/// The C++ bridge (`voxelkit/openvdb.hpp`) as a user builds it with CMake against the
/// installed package: a mesh's level set handed to OpenVDB measures the mesh's volume and
/// meshes; an OpenVDB sphere taken into voxelkit removes its whole inside from a box. Both
/// valgrind-clean.
#[test]
fn the_openvdb_bridge_hands_level_sets_over_both_ways() {
    if !have("cmake") {
        return common::skip_or_fail("cmake is not installed: the OpenVDB bridge test");
    }
    let work = tempfile::tempdir().unwrap();
    let build = work.path().join("build");
    run(Command::new("cmake")
        .arg("-S")
        .arg(repo().join("tests/cpp"))
        .arg("-B")
        .arg(&build)
        .arg(format!("-DCMAKE_PREFIX_PATH={}", prefix().display())));
    run(Command::new("cmake").arg("--build").arg(&build));
    let mesh_path = test_mesh(work.path());
    let exact = Mesh::load(&mesh_path).unwrap().signed_volume();
    let volume_exe = build.join("level_set_volume");
    let out = run(Command::new(&volume_exe).arg(&mesh_path).arg("256"));
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    let number = |key: &str| -> f64 { field(&text, key) };
    let volume = number("volume");
    assert!(
        (volume - exact).abs() <= 1e-3 * exact,
        "OpenVDB measured {volume}, the mesh holds {exact}"
    );
    assert!(number("quads") > 1000.0, "{text}");
    let sphere_exe = build.join("openvdb_sphere_difference");
    let out = run(&mut Command::new(&sphere_exe));
    let text = String::from_utf8_lossy(&out.stdout).to_string();
    let number = |key: &str| -> f64 { field(&text, key) };
    assert_eq!(number("left_inside"), 0.0, "{text}");
    assert!(
        (number("sphere_voxels") / number("sphere_expected") - 1.0).abs() < 0.01,
        "{text}"
    );
    assert!(number("carved_voxels") < number("box_voxels"), "{text}");
    eprintln!("OpenVDB levelSetVolume {volume} of a mesh holding {exact}; sphere: {text}");
    if !have("valgrind") {
        return common::skip_or_fail("valgrind is not installed: the bridge's leak check");
    }
    for args in [
        vec![
            volume_exe.clone().into_os_string(),
            mesh_path.clone().into_os_string(),
            "64".into(),
        ],
        vec![sphere_exe.into_os_string()],
    ] {
        let out = run(Command::new("valgrind")
            .args(["--leak-check=full", "--errors-for-leak-kinds=definite"])
            .args(["--show-leak-kinds=definite", "--error-exitcode=99"])
            .args(&args));
        let report = String::from_utf8_lossy(&out.stderr);
        assert!(report.contains("ERROR SUMMARY: 0 errors"), "{report}");
        assert!(report.contains("definitely lost: 0 bytes"), "{report}");
    }
}

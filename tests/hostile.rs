//! Hostile input, each case a reproduction of a failure once seen: deep formulas that
//! overflowed the stack, numbers that silently became infinite, a byte-order mark that ate
//! the first OBJ line, STL files read wrongly, volumes lost to cancellation far from the
//! origin, voxel sizes whose cube overflows. Every one is now a clear error or a right answer.
#![cfg(all(feature = "vdb", feature = "fixtures"))]

use std::path::Path;
use std::process::Command;
mod cli_support;

use cli_support::{json_field, text, voxelkit};
use voxelkit::Error;
use voxelkit::implicit::{Coordinates, Formula};
use voxelkit::mesh::Mesh;

const TETRA: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

fn formula_error(text: &str) -> String {
    match Formula::parse(text, Coordinates::Cartesian) {
        Err(e @ Error::Formula { .. }) => e.to_string(),
        Err(e) => panic!("not a formula error: {e}"),
        Ok(_) => panic!("accepted: {}", &text[..text.len().min(40)]),
    }
}

#[test]
fn deep_formulas_are_refused_on_a_small_stack() {
    // Run where a host thread of the C interface would: a 256 KiB stack.
    let worker = std::thread::Builder::new()
        .stack_size(256 << 10)
        .spawn(|| {
            for deep in [
                format!("{}x{}", "(".repeat(15_000), ")".repeat(15_000)),
                format!("{}x", "-".repeat(50_000)),
                format!("{}x{}", "sqrt(".repeat(10_000), ")".repeat(10_000)),
                format!("{}x{}", "(".repeat(500), ")".repeat(500)),
            ] {
                assert!(formula_error(&deep).contains("nests more than"));
            }
            // Deep but reasonable formulas still parse.
            let fine = format!("{}x{}", "(".repeat(60), ")".repeat(60));
            Formula::parse(&fine, Coordinates::Cartesian).unwrap();
        })
        .unwrap();
    worker
        .join()
        .expect("the parser overflowed a 256 KiB stack");
}

#[test]
fn numbers_beyond_double_precision_are_refused() {
    let e = formula_error("x - 1e400");
    assert!(e.contains("1e400") && e.contains("too large"), "{e}");
}

#[test]
fn a_byte_order_mark_is_not_part_of_the_first_line() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("bom.obj");
    std::fs::write(&obj, format!("\u{feff}{TETRA}")).unwrap();
    let mesh = Mesh::load(&obj).unwrap();
    assert_eq!(mesh.positions.len(), 4);
    assert!((mesh.signed_volume().abs() - 1.0 / 6.0).abs() < 1e-12);
}

/// An ASCII STL of the unit tetrahedron, keywords in `case`.
fn ascii_stl(upper: bool, end: bool) -> String {
    let p = [[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]];
    let faces = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    let mut s = String::from("solid t\n");
    for f in faces {
        s.push_str("facet normal 0 0 0\nouter loop\n");
        for v in f {
            s.push_str(&format!("vertex {} {} {}\n", p[v][0], p[v][1], p[v][2]));
        }
        s.push_str("endloop\nendfacet\n");
    }
    if end {
        s.push_str("endsolid t\n");
    }
    if upper { s.to_uppercase() } else { s }
}

#[test]
fn stl_in_any_case_with_a_mark_is_read_and_a_cut_one_refused() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, body: &[u8]| {
        let p = dir.path().join(name);
        std::fs::write(&p, body).unwrap();
        p
    };
    for (name, body) in [
        ("upper.stl", ascii_stl(true, true).into_bytes()),
        (
            "bom.stl",
            [
                b"\xEF\xBB\xBF".as_slice(),
                ascii_stl(false, true).as_bytes(),
            ]
            .concat(),
        ),
    ] {
        let mesh = Mesh::load(&write(name, &body)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(mesh.face_count(), 4, "{name}");
        assert!(
            (mesh.signed_volume().abs() - 1.0 / 6.0).abs() < 1e-12,
            "{name}"
        );
    }
    // Cut at a facet boundary: no `endsolid`.
    let cut = write("cut.stl", ascii_stl(false, false).as_bytes());
    let e = Mesh::load(&cut).unwrap_err().to_string();
    assert!(e.contains("cut.stl") && e.contains("endsolid"), "{e}");
}

fn tetra_at(dir: &Path, offset: f64) -> std::path::PathBuf {
    let p = dir.join(format!("tetra{offset}.obj"));
    let mut s = String::new();
    for v in [[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.]] {
        s.push_str(&format!(
            "v {} {} {}\n",
            v[0] + offset,
            v[1] + offset,
            v[2] + offset
        ));
    }
    s.push_str("f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
    std::fs::write(&p, s).unwrap();
    p
}

#[test]
fn far_from_the_origin_the_volume_holds_or_the_grid_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let shifted = tetra_at(dir.path(), 1e8);
    let o = voxelkit(&["--json", "measure", shifted.to_str().unwrap(), "-r", "32"]);
    assert!(o.status.success(), "{}", text(&o));
    let v = json_field(&String::from_utf8_lossy(&o.stdout), "mesh_signed_volume");
    assert!((v.abs() - 1.0 / 6.0).abs() < 1e-6, "signed volume {v}");
    // At 1e14 no double places a 1/64 voxel: refused, not wrong.
    let far = tetra_at(dir.path(), 1e14);
    let o = voxelkit(&["measure", far.to_str().unwrap(), "-r", "64"]);
    let msg = text(&o);
    assert!(
        !o.status.success() && msg.contains("double precision"),
        "{msg}"
    );
}

#[test]
fn a_voxel_size_whose_cube_overflows_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("tetra.obj");
    std::fs::write(&obj, TETRA).unwrap();
    let o = voxelkit(&["measure", obj.to_str().unwrap(), "--voxel-size", "1e308"]);
    let msg = text(&o);
    assert!(!o.status.success(), "{msg}");
    assert!(
        msg.contains("cube is finite") && !msg.contains("NaN"),
        "{msg}"
    );
}

#[test]
fn damaged_vdb_files_are_refused_plainly_and_huge_tiles_before_allocating() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("sphere.vdb");
    let made = voxelkit(&["shape", "sphere", "-r", "48", "-o", good.to_str().unwrap()]);
    assert!(made.status.success(), "{}", text(&made));
    let bytes = std::fs::read(&good).unwrap();
    for (name, cut) in [
        ("half.vdb", bytes.len() / 2),
        ("head.vdb", 200),
        // The header alone (magic, versions, flags, UUID): not a file without grids.
        ("header.vdb", 57),
        ("empty.vdb", 0),
    ] {
        let damaged = dir.path().join(name);
        std::fs::write(&damaged, &bytes[..cut]).unwrap();
        for args in [vec!["info"], vec!["measure"]] {
            let mut args = args.clone();
            args.push(damaged.to_str().unwrap());
            let o = voxelkit(&args);
            let msg = text(&o);
            assert!(!o.status.success(), "{name} {args:?}: {msg}");
            assert!(msg.contains(name) && msg.len() < 1000, "{name}: {msg}");
            assert!(!msg.contains("panicked"), "{msg}");
        }
    }
    // One active tile of 4096^3 voxels in a 545-byte file: read as tiles, then refused by
    // the measure's memory plan before anything large is allocated.
    let tile = dir.path().join("tile.vdb");
    let script = "import sys, pyopenvdb as vdb\n\
                  g = vdb.BoolGrid()\n\
                  g.fill((0, 0, 0), (4095, 4095, 4095), True, True)\n\
                  g.name = 'surface'\n\
                  vdb.write(sys.argv[1], grids=[g])\n";
    if cli_support::run_pyopenvdb(script, &tile, "the huge-tile file").is_none() {
        return;
    }
    let start = std::time::Instant::now();
    let o = voxelkit(&["measure", tile.to_str().unwrap()]);
    let msg = text(&o);
    assert!(
        !o.status.success() && msg.contains("tile.vdb") && msg.contains("4095x4095x4095"),
        "{msg}"
    );
    assert!(start.elapsed() < std::time::Duration::from_secs(2), "{msg}");
}

/// Where a compressed chunk of node values starts: its signed 64-bit size, then a blosc
/// header (version 2) repeating that size as its compressed length. Returns the last one.
fn last_blosc_chunk(bytes: &[u8]) -> usize {
    let at = |i: usize, n: usize| bytes[i..i + n].to_vec();
    (0..bytes.len() - 24)
        .rev()
        .find(|&i| {
            let size = i64::from_le_bytes(at(i, 8).try_into().unwrap());
            let cbytes = u32::from_le_bytes(at(i + 20, 4).try_into().unwrap());
            (17..1 << 20).contains(&size) && bytes[i + 8] == 2 && cbytes as i64 == size
        })
        .expect("a blosc chunk")
}

#[test]
fn damaged_chunk_sizes_of_compressed_vdb_files_are_refused_before_openvdb_reads_them() {
    // OpenVDB 10.0.1 copies a chunk stored raw (negative size) into the node's buffer before
    // comparing the sizes (heap corruption, SIGABRT), and blosc reads as far as its own
    // header says (past the chunk).
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("sphere.vdb");
    let made = voxelkit(&["shape", "sphere", "-r", "48", "-o", good.to_str().unwrap()]);
    assert!(made.status.success(), "{}", text(&made));
    let bytes = std::fs::read(&good).unwrap();
    let chunk = last_blosc_chunk(&bytes);
    let size = i64::from_le_bytes(bytes[chunk..chunk + 8].try_into().unwrap());
    let edit = |name: &str, offset: usize, value: &[u8]| {
        let mut b = bytes.clone();
        b[chunk + offset..chunk + offset + value.len()].copy_from_slice(value);
        let path = dir.path().join(name);
        std::fs::write(&path, b).unwrap();
        path
    };
    for damaged in [
        edit("raw.vdb", 0, &(-200_000i64).to_le_bytes()),
        edit("long.vdb", 20, &(size as u32 + 5000).to_le_bytes()),
        edit("wide.vdb", 12, &(1u32 << 20).to_le_bytes()),
    ] {
        let name = damaged.file_name().unwrap().to_str().unwrap();
        for command in ["info", "measure"] {
            let o = voxelkit(&[command, damaged.to_str().unwrap()]);
            let msg = text(&o);
            assert!(o.status.code() == Some(1), "{name} {command}: {msg}");
            assert!(msg.contains(name) && msg.contains("chunk at byte"), "{msg}");
        }
    }
    let o = voxelkit(&["info", good.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o));
}

#[test]
fn reading_trees_that_cannot_fit_is_refused_before_openvdb_allocates() {
    // A 10 MB file whose trees take about 400 MB once read (float and vector leaves, blosc):
    // under a 300 MB address-space cap, OpenVDB's reader ran out of memory inside its trees.
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("tetra.obj");
    std::fs::write(&mesh, TETRA).unwrap();
    let file = dir.path().join("normals.vdb");
    let made = voxelkit(&[
        "mesh",
        mesh.to_str().unwrap(),
        "-r",
        "1024",
        "--normals",
        "-o",
        file.to_str().unwrap(),
    ]);
    assert!(made.status.success(), "{}", text(&made));
    let capped = |mib: u64| {
        let mut command = std::process::Command::new(env!("CARGO_BIN_EXE_voxelkit"));
        command.args(["info", file.to_str().unwrap()]);
        let limit = libc::rlimit {
            rlim_cur: mib << 20,
            rlim_max: mib << 20,
        };
        // SAFETY: setrlimit is async-signal-safe; the child only sets its own limit.
        unsafe {
            use std::os::unix::process::CommandExt;
            command.pre_exec(move || {
                if libc::setrlimit(libc::RLIMIT_AS, &limit) == 0 {
                    Ok(())
                } else {
                    Err(std::io::Error::last_os_error())
                }
            });
        }
        command.output().unwrap()
    };
    let o = capped(300);
    let msg = text(&o);
    assert_eq!(o.status.code(), Some(1), "{msg}");
    assert!(
        msg.contains("normals.vdb: reading its trees") && msg.contains("MiB"),
        "{msg}"
    );
    let o = capped(2048);
    assert!(o.status.success(), "{}", text(&o));
}

#[test]
fn huge_faces_and_valences_of_control_meshes_are_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let ngon = dir.path().join("ngon.obj");
    let mut s = String::new();
    for k in 0..3000 {
        let a = std::f64::consts::TAU * k as f64 / 3000.0;
        s.push_str(&format!("v {} {} 0\n", a.cos(), a.sin()));
    }
    s.push_str(&format!(
        "f {}\n",
        (1..=3000)
            .map(|k| k.to_string())
            .collect::<Vec<_>>()
            .join(" ")
    ));
    std::fs::write(&ngon, s).unwrap();
    let repeated = dir.path().join("repeated.obj");
    let corners: Vec<String> = (0..1_000_000).map(|k| (k % 4 + 1).to_string()).collect();
    std::fs::write(
        &repeated,
        format!(
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf {}\n",
            corners.join(" ")
        ),
    )
    .unwrap();
    let out = dir.path().join("out.vdb");
    for args in [
        vec![
            "subdiv",
            ngon.to_str().unwrap(),
            "-r",
            "64",
            "-o",
            out.to_str().unwrap(),
        ],
        vec!["subdiv", "check", repeated.to_str().unwrap()],
    ] {
        let start = std::time::Instant::now();
        let o = voxelkit(&args);
        let msg = text(&o);
        assert!(!o.status.success() && msg.contains("corners"), "{msg}");
        assert!(
            start.elapsed() < std::time::Duration::from_secs(3),
            "{args:?}"
        );
    }
    assert!(!out.exists());
}

#[test]
fn a_formula_zero_everywhere_stops_at_the_memory_limit() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("zero.vdb");
    let o = voxelkit(&[
        "implicit",
        "0*x",
        "-r",
        "256",
        "--max-memory",
        "200",
        "-o",
        out.to_str().unwrap(),
    ]);
    // Planning's coarse pass sees it fill its box and refuses it at once (the octree's leaf
    // budget stops what planning lets through).
    let msg = text(&o);
    assert!(
        !o.status.success() && msg.contains("0*x") && msg.contains("estimated"),
        "{msg}"
    );
    assert!(!out.exists());
    // A real surface at the same settings fits.
    let sphere = voxelkit(&[
        "implicit",
        "x^2 + y^2 + z^2 - 0.5",
        "-r",
        "256",
        "--max-memory",
        "200",
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(sphere.status.success(), "{}", text(&sphere));
}

/// Voxels of `voxelkit implicit FORMULA -r RESOLUTION` over [-1, 1]^3.
fn implicit_voxels(formula: &str, resolution: u32) -> f64 {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("f.vdb");
    let r = resolution.to_string();
    let o = voxelkit(&[
        "--json",
        "implicit",
        formula,
        "-r",
        &r,
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{formula}: {}", text(&o));
    json_field(&String::from_utf8_lossy(&o.stdout), "voxels")
}

#[test]
fn a_pole_is_not_taken_for_a_root() {
    // 1/x and 1/(x - x) have no zero; x^-1 - 2 is zero on the plane x = 1/2 only.
    assert_eq!(implicit_voxels("1/x", 64), 0.0);
    assert_eq!(implicit_voxels("1/(x-x)", 64), 0.0);
    assert_eq!(
        implicit_voxels("x^-1 - 2", 64),
        implicit_voxels("x - 0.5", 64)
    );
}

#[test]
fn a_formula_at_resolution_one_is_one_voxel() {
    assert_eq!(implicit_voxels("x^2 + y^2 + z^2 - 0.5", 1), 1.0);
}

#[test]
fn tiny_and_huge_numbers_are_printed_short() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("tetra.obj");
    std::fs::write(&obj, TETRA).unwrap();
    let out = dir.path().join("out.vdb");
    for size in ["1e-300", "-1e-300"] {
        let o = voxelkit(&[
            "mesh",
            obj.to_str().unwrap(),
            "--voxel-size",
            size,
            "-o",
            out.to_str().unwrap(),
        ]);
        let msg = text(&o);
        assert!(!o.status.success(), "{msg}");
        assert!(msg.len() < 400 && !msg.contains("00000000"), "{msg}");
    }
}

#[test]
fn resampling_onto_a_far_finer_grid_is_planned() {
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    for (radius, res, name) in [("1", "64", "small.vdb"), ("1000", "16", "big.vdb")] {
        let o = voxelkit(&[
            "shape",
            "sphere",
            "--radius",
            radius,
            "-r",
            res,
            "-o",
            &p(name),
        ]);
        assert!(o.status.success(), "{}", text(&o));
    }
    let start = std::time::Instant::now();
    let o = voxelkit(&[
        "csg",
        "union",
        &p("small.vdb"),
        &p("big.vdb"),
        "--resample",
        "-o",
        &p("u.vdb"),
    ]);
    let msg = text(&o);
    assert!(!o.status.success() && msg.contains("an estimated"), "{msg}");
    assert!(start.elapsed() < std::time::Duration::from_secs(2));
    assert!(!dir.path().join("u.vdb").exists());
}

#[test]
fn a_mirrored_grid_is_refused_saying_what_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let mirror = dir.path().join("mirror.vdb");
    let script = "import sys, pyopenvdb as vdb\n\
                  g = vdb.BoolGrid()\n\
                  g.fill((0, 0, 0), (3, 3, 3), True, True)\n\
                  g.name = 'surface'\n\
                  g.transform = vdb.createLinearTransform([[-1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])\n\
                  vdb.write(sys.argv[1], grids=[g])\n";
    if cli_support::run_pyopenvdb(script, &mirror, "the mirrored-grid file").is_none() {
        return;
    }
    let o = voxelkit(&["measure", mirror.to_str().unwrap()]);
    let msg = text(&o);
    assert!(!o.status.success() && msg.contains("mirroring"), "{msg}");
}

/// A tetrahedron as `model/m.gltf` with its buffer in `model/m.bin`, and the buffer's URI
/// replaced by `uri` (none: kept).
fn gltf_naming(dir: &Path, uri: Option<&str>) -> std::path::PathBuf {
    let folder = dir.join("model");
    std::fs::create_dir_all(&folder).unwrap();
    let obj = dir.join("t.obj");
    std::fs::write(&obj, TETRA).unwrap();
    let gltf = folder.join("m.gltf");
    Mesh::load(&obj)
        .unwrap()
        .write_gltf(&gltf, voxelkit::mesh::GltfLayout::SeparateBuffer, &[])
        .unwrap();
    if let Some(uri) = uri {
        let mut json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(&gltf).unwrap()).unwrap();
        json["buffers"][0]["uri"] = uri.into();
        std::fs::write(&gltf, json.to_string()).unwrap();
    }
    gltf
}

#[test]
fn a_gltf_buffer_is_read_from_the_models_folder_only_and_no_further_than_declared() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let fine = gltf_naming(d, None);
    assert_eq!(Mesh::load(&fine).unwrap().face_count(), 4);
    // The same buffer outside the folder, behind a link, a FIFO, a device, a folder.
    std::fs::copy(d.join("model/m.bin"), d.join("outside.bin")).unwrap();
    std::os::unix::fs::symlink("../outside.bin", d.join("model/link.bin")).unwrap();
    let fifo = d.join("model/fifo.bin");
    assert!(
        Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    std::fs::create_dir_all(d.join("model/sub")).unwrap();
    std::fs::write(d.join("model/short.bin"), [0u8; 8]).unwrap();
    let passwd = "root:x:0:0:secret-of-the-machine";
    std::fs::write(d.join("passwd"), passwd).unwrap();
    let absolute = d.join("passwd").display().to_string();
    for (uri, why) in [
        (absolute.as_str(), "an absolute path"),
        ("/dev/zero", "an absolute path"),
        ("/dev/urandom", "an absolute path"),
        ("../outside.bin", "outside the model's folder"),
        ("..%2Foutside.bin", "outside the model's folder"),
        ("link.bin", "outside the model's folder"),
        ("fifo.bin", "not a regular file"),
        ("sub", "not a regular file"),
        ("short.bin", "holds 8 bytes, but the model declares"),
    ] {
        let gltf = gltf_naming(d, Some(uri));
        let started = std::time::Instant::now();
        let e = Mesh::load(&gltf).expect_err(uri).to_string();
        assert!(e.contains(why) && e.contains("m.gltf"), "{uri}: {e}");
        assert!(
            !e.contains("secret"),
            "{uri}: the error shows the file's bytes: {e}"
        );
        assert!(
            started.elapsed() < std::time::Duration::from_secs(5),
            "{uri}"
        );
        // The command line says the same, and writes nothing.
        let out = d.join("out.vdb");
        let o = voxelkit(&[
            "mesh",
            gltf.to_str().unwrap(),
            "-r",
            "8",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert!(
            !o.status.success() && text(&o).contains(why),
            "{uri}: {}",
            text(&o)
        );
        assert!(!out.exists(), "{uri}");
    }
}

/// A brick set of one real brick (`b.vdb`) in `set/`, its index edited by `edit`.
fn brick_index(dir: &Path, edit: impl Fn(&mut serde_json::Value)) -> std::path::PathBuf {
    let set = dir.join("set");
    std::fs::create_dir_all(&set).unwrap();
    let mut grid = voxelkit::pipeline::Outcome::read_vdb(&sphere_vdb(dir), None)
        .unwrap()
        .grid;
    // The part of the sphere in brick (0, 0, 0).
    grid.retain_leaves(|origin| origin.iter().all(|v| (0..64).contains(v)));
    voxelkit::io::vdb::write_vdb(&set.join("b.vdb"), &grid, &[]).unwrap();
    let mut index = serde_json::json!({
        "format": "voxelkit-bricks", "voxel_size": grid.transform.voxel_size,
        "origin": grid.transform.origin.to_array(), "brick_size": 64,
        "bricks": [{"brick": [0, 0, 0], "file": "b.vdb"}], "full_bricks": [],
    });
    edit(&mut index);
    let path = set.join("index.json");
    std::fs::write(&path, index.to_string()).unwrap();
    path
}

fn sphere_vdb(dir: &Path) -> std::path::PathBuf {
    let path = dir.join("sphere.vdb");
    if !path.exists() {
        let o = voxelkit(&[
            "shape",
            "sphere",
            "--radius",
            "0.5",
            "--center",
            "0.5,0.5,0.5",
            "--voxel-size",
            "0.05",
            "-o",
            path.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", text(&o));
    }
    path
}

#[test]
fn a_tampered_brick_index_is_refused_alike_by_info_and_read_vdb() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let fine = brick_index(d, |_| {});
    let o = voxelkit(&["--json", "info", fine.to_str().unwrap()]);
    assert!(o.status.success(), "{}", text(&o));
    // Both count the voxels the merged grid holds.
    let merged = voxelkit::pipeline::Outcome::read_vdb(&fine, None)
        .unwrap()
        .grid;
    assert_eq!(
        json_field(&text(&o), "active_voxels") as u64,
        merged.voxel_count()
    );
    std::fs::copy(sphere_vdb(d), d.join("outside.vdb")).unwrap();
    assert!(
        Command::new("mkfifo")
            .arg(d.join("set/fifo.vdb"))
            .status()
            .unwrap()
            .success()
    );
    type Edit = Box<dyn Fn(&mut serde_json::Value)>;
    let cases: Vec<(&str, Edit, &str)> = vec![
        (
            "outside",
            Box::new(|j| j["bricks"][0]["file"] = "../outside.vdb".into()),
            "outside the model's folder",
        ),
        (
            "absolute",
            Box::new(|j| j["bricks"][0]["file"] = "/etc/passwd".into()),
            "an absolute path",
        ),
        (
            "fifo",
            Box::new(|j| j["bricks"][0]["file"] = "fifo.vdb".into()),
            "not a regular file",
        ),
        (
            "brick twice",
            Box::new(|j| {
                j["bricks"]
                    .as_array_mut()
                    .unwrap()
                    .push(serde_json::json!({"brick": [0, 0, 0], "file": "c.vdb"}))
            }),
            "listed twice",
        ),
        (
            "file twice",
            Box::new(|j| {
                j["bricks"]
                    .as_array_mut()
                    .unwrap()
                    .push(serde_json::json!({"brick": [1, 0, 0], "file": "b.vdb"}))
            }),
            "named for two bricks",
        ),
        (
            "far brick",
            Box::new(|j| j["bricks"][0]["brick"] = serde_json::json!([1i64 << 62, 0, 0])),
            "32-bit",
        ),
        (
            "brick size",
            Box::new(|j| j["brick_size"] = 12.into()),
            "multiple of 8",
        ),
        (
            "huge brick",
            Box::new(|j| j["brick_size"] = (1i64 << 40).into()),
            "multiple of 8",
        ),
        (
            "voxel size",
            Box::new(|j| j["voxel_size"] = (-1.0).into()),
            "voxel_size -1",
        ),
        (
            "moved brick",
            Box::new(|j| j["bricks"][0]["brick"] = serde_json::json!([1, 0, 0])),
            "voxels outside its brick",
        ),
        (
            "other grid",
            Box::new(|j| j["voxel_size"] = 0.1.into()),
            "is not the brick set's",
        ),
    ];
    for (name, edit, why) in cases {
        let index = brick_index(d, edit);
        let started = std::time::Instant::now();
        let o = voxelkit(&["info", index.to_str().unwrap()]);
        assert!(
            !o.status.success() && text(&o).contains(why),
            "{name}: info: {}",
            text(&o)
        );
        let Err(e) = voxelkit::pipeline::Outcome::read_vdb(&index, None) else {
            panic!("{name}: read_vdb accepted it");
        };
        let e = e.to_string();
        assert!(e.contains(why), "{name}: read_vdb: {e}");
        assert!(
            started.elapsed() < std::time::Duration::from_secs(5),
            "{name}"
        );
    }
}

#[test]
fn a_ply_declaring_a_property_or_an_element_twice_is_refused_at_its_line() {
    let dir = tempfile::tempdir().unwrap();
    let body = "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
    for (header, why, line) in [
        (
            "element vertex 4\nproperty float x\nproperty float x\nproperty float y\nproperty float z\n",
            "the property `x` of element `vertex` is declared twice",
            5,
        ),
        (
            "element vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 4\nproperty list uchar int vertex_indices\nelement face 4\nproperty list uchar int vertex_indices\n",
            "the element `face` is declared twice",
            9,
        ),
    ] {
        let ply = dir.path().join("twice.ply");
        std::fs::write(
            &ply,
            format!("ply\nformat ascii 1.0\n{header}end_header\n{body}"),
        )
        .unwrap();
        let e = Mesh::load(&ply).expect_err(why);
        assert!(e.to_string().contains(why), "{e}");
        assert_eq!(e.location().1, Some(line), "{e}");
    }
}

/// A closed box of side `side` centred at the origin, as an OBJ (the project's fixture).
fn cube_obj(dir: &Path, side: f64) -> std::path::PathBuf {
    let h = glam::DVec3::splat(side / 2.0);
    let path = dir.join("cube.obj");
    voxelkit::mesh::generate::cuboid(-h, h)
        .write_obj(&path)
        .unwrap();
    path
}

#[test]
fn distances_beyond_half_precision_are_refused_not_written_as_infinities() {
    let dir = tempfile::tempdir().unwrap();
    let cube = cube_obj(dir.path(), 4e6);
    let out = dir.path().join("big.vdb");
    let (c, o) = (cube.to_str().unwrap(), out.to_str().unwrap());
    let refused = voxelkit(&["mesh", "--half", c, "--sdf", "-r", "32", "-o", o]);
    assert!(!refused.status.success(), "{}", text(&refused));
    assert!(
        text(&refused).contains("exceed half precision's range (65504)"),
        "{}",
        text(&refused)
    );
    assert!(!out.exists());
    let full = voxelkit(&["mesh", c, "--sdf", "-r", "32", "-o", o]);
    assert!(full.status.success(), "{}", text(&full));
}

#[test]
fn a_band_that_is_not_a_positive_finite_number_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let cube = cube_obj(dir.path(), 1.0);
    let out = dir.path().join("b.vdb");
    for band in ["nan", "inf", "-1", "0"] {
        for command in ["mesh", "solid"] {
            let o = voxelkit(&[
                command,
                cube.to_str().unwrap(),
                "--sdf",
                &format!("--band={band}"),
                "-o",
                out.to_str().unwrap(),
            ]);
            assert!(!o.status.success(), "{command} --band {band}");
            assert!(
                text(&o).contains("band must be a positive number"),
                "{command} --band {band}: {}",
                text(&o)
            );
        }
    }
    assert!(!out.exists());
}

#[test]
fn one_input_with_an_out_dir_that_does_not_exist_makes_it() {
    let dir = tempfile::tempdir().unwrap();
    let cube = cube_obj(dir.path(), 1.0);
    let folder = dir.path().join("new/deeper");
    let o = voxelkit(&[
        "mesh",
        cube.to_str().unwrap(),
        "-r",
        "16",
        "--out-dir",
        folder.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(folder.join("cube.vdb").exists());
}

#[test]
fn a_picture_beyond_the_memory_limit_is_refused_before_it_is_drawn() {
    let dir = tempfile::tempdir().unwrap();
    let vdb = sphere_vdb(dir.path());
    let png = dir.path().join("p.png");
    let o = voxelkit(&[
        "--max-memory",
        "64",
        "render",
        vdb.to_str().unwrap(),
        "--size",
        "16384x16384",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(!o.status.success(), "{}", text(&o));
    assert!(
        text(&o).contains("16384x16384") && text(&o).contains("MiB"),
        "{}",
        text(&o)
    );
    assert!(!png.exists());
    let small = voxelkit(&[
        "--max-memory",
        "64",
        "render",
        vdb.to_str().unwrap(),
        "--size",
        "64x48",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(small.status.success(), "{}", text(&small));
}

/// A solid with a void (an outward cube around an inward one, the void's wall facing into
/// it): the flood cannot reach the void, but its winding number is 0, so it is not inside.
/// The volume bracket of `solid` and `measure` holds the exact volume, 1 - 0.4^3, for every
/// flood; the void's shell alone, or a cube nested the same way but outward, keeps it.
#[test]
fn an_inward_shell_leaves_a_void_that_the_volume_bracket_excludes() {
    use glam::DVec3;
    use voxelkit::mesh::generate;
    let dir = tempfile::tempdir().unwrap();
    let mut void = generate::cuboid(DVec3::splat(0.3), DVec3::splat(0.7));
    generate::reverse_faces(&mut void);
    let hollow = generate::combine(
        "hollow cube",
        &[generate::cuboid(DVec3::ZERO, DVec3::ONE), void],
    );
    let exact = 1.0 - 0.4f64.powi(3);
    assert!((hollow.signed_volume() - exact).abs() < 1e-12);
    let path = dir.path().join("hollow.obj");
    hollow.write_obj(&path).unwrap();
    let out = dir.path().join("hollow.vdb");
    for args in [
        vec!["solid"],
        vec!["solid", "--flood", "spans"],
        vec!["solid", "--flood", "xyz"],
        vec!["measure"],
    ] {
        let mut all = vec!["--json"];
        all.extend(&args);
        all.extend([path.to_str().unwrap(), "-r", "100"]);
        if args[0] == "solid" {
            all.extend(["-o", out.to_str().unwrap()]);
        }
        let o = voxelkit(&all);
        assert!(o.status.success(), "{args:?}: {}", text(&o));
        let report = text(&o);
        let (lo, hi) = (
            json_field(&report, "volume_inside"),
            json_field(&report, "volume_with_surface"),
        );
        assert!(
            lo <= exact && exact <= hi,
            "{args:?}: [{lo}, {hi}] excludes {exact}"
        );
    }
    // Nested outward cubes enclose no void: the inner one's region winds twice.
    let nested = generate::combine(
        "nested cubes",
        &[
            generate::cuboid(DVec3::ZERO, DVec3::ONE),
            generate::cuboid(DVec3::splat(0.3), DVec3::splat(0.7)),
        ],
    );
    let path = dir.path().join("nested.obj");
    nested.write_obj(&path).unwrap();
    let o = voxelkit(&["--json", "measure", path.to_str().unwrap(), "-r", "100"]);
    assert!(o.status.success(), "{}", text(&o));
    let hi = json_field(&text(&o), "volume_with_surface");
    assert!(hi >= 1.0, "the nested cube's inside was taken out: {hi}");
}

/// A million 8^3 tiles in a checkerboard (no 128^3 node whole), as a `.vdb`.
fn tile_checkerboard(path: &Path) {
    use voxelkit::grid::{Channels, SparseGrid, Transform};
    let mut grid = SparseGrid::new(Transform::new(glam::DVec3::ZERO, 0.01), Channels::NONE);
    let mut origins = Vec::new();
    for x in 0..126i64 {
        for y in 0..126i64 {
            for z in 0..126i64 {
                if (x + y + z) % 2 == 0 {
                    origins.push([8 * x, 8 * y, 8 * z]);
                }
            }
        }
    }
    grid.fill_leaf_blocks(origins);
    assert_eq!(grid.tiles().count(), 1_000_188);
    voxelkit::io::vdb::write_vdb(path, &grid, &[]).unwrap();
}

/// Tiles expand where they are combined, measured or drawn: each of those is planned against
/// `--max-memory` (drawing included) and refused under it; read, they stay a bit per block,
/// so `info` runs under the smallest limit; and a resample of grids on one transform costs
/// what the Boolean without it does.
#[test]
fn tiles_are_planned_against_the_memory_limit_given() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.vdb"), dir.path().join("b.vdb"));
    tile_checkerboard(&a);
    std::fs::copy(&a, &b).unwrap();
    let p = |f: &Path| f.to_str().unwrap().to_string();
    let out = p(&dir.path().join("u.vdb"));
    let png = p(&dir.path().join("u.png"));
    let cases: [(Vec<String>, &str); 4] = [
        (
            vec![
                "csg".into(),
                "union".into(),
                p(&a),
                p(&b),
                "-o".into(),
                out.clone(),
            ],
            "50",
        ),
        (
            vec![
                "csg".into(),
                "union".into(),
                "--resample".into(),
                p(&a),
                p(&b),
                "-o".into(),
                out.clone(),
            ],
            "50",
        ),
        (vec!["measure".into(), p(&a)], "50"),
        (vec!["render".into(), p(&a), "-o".into(), png.clone()], "20"),
    ];
    for (args, limit) in &cases {
        let mut all: Vec<&str> = vec!["--max-memory", limit];
        all.extend(args.iter().map(String::as_str));
        let o = voxelkit(&all);
        let said = text(&o);
        assert_eq!(
            o.status.code(),
            Some(1),
            "{args:?} under {limit} MiB: {said}"
        );
        assert!(
            said.contains(&format!("only {limit} MiB")),
            "{args:?}: {said}"
        );
    }
    let read = voxelkit(&["--max-memory", "20", "info", &p(&a)]);
    assert!(read.status.success(), "{}", text(&read));
    assert!(
        text(&read).contains("512096256 active voxels"),
        "{}",
        text(&read)
    );
    // With room, the resample of one transform runs as the plain Boolean does.
    for resample in [false, true] {
        let mut all = vec!["--json", "--max-memory", "2000", "csg", "union"];
        if resample {
            all.push("--resample");
        }
        let (a, b) = (p(&a), p(&b));
        all.extend([a.as_str(), b.as_str(), "-o", out.as_str()]);
        let o = voxelkit(&all);
        assert!(o.status.success(), "resample {resample}: {}", text(&o));
    }
}

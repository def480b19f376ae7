//! Blender opens what voxelkit writes: a headless Blender imports the .vdb as a volume
//! object and loads the `density`, `voxels` and `normal` grids at the right place, the
//! `density` and level-set `surface` of `--sdf`, and a solid's tiles; `density` comes first.
//! Skipped (loudly) where Blender is not installed, outside CI; CI installs it.
#![cfg(all(feature = "vdb", feature = "fixtures"))]

use std::process::Command;
use voxelkit::io::vdb::{WriteOptions, write_vdb_as};
use voxelkit::mesh::generate;
use voxelkit::voxelize::Separability;
use voxelkit::voxelize::separating::SeparatingOptions;

mod common;

#[test]
fn blender_imports_the_volume() {
    if Command::new("blender").arg("--version").output().is_err() {
        return common::skip_or_fail("blender is not installed: the Blender import test");
    }
    let mesh = generate::torus(glam::DVec3::new(2.0, -1.0, 0.5), 1.0, 0.3, 64, 16);
    let opts = SeparatingOptions {
        separability: Separability::TwentySix,
        normals: true,
        ..Default::default()
    };
    let (grid, _) = common::voxelize_at(&mesh, 64, opts);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("torus.vdb");
    let options = WriteOptions {
        grids: vec!["density".into(), "voxels".into(), "normal".into()],
        ..Default::default()
    };
    write_vdb_as(&path, &grid, &[], &[], &options).unwrap();
    let text = blender_grids(&path);
    for g in [
        "GRID density FLOAT True",
        "GRID voxels BOOLEAN True",
        "GRID normal VECTOR_FLOAT True",
    ] {
        assert!(text.contains(g), "`{g}` missing: {text}");
    }
    assert_first_grid_is_density(&text);
    // BOUNDS (x0, y0, z0) (x1, y1, z1): Blender bounds a volume by the voxel centres of whole
    // 8^3 leaves, so the box holds the active centres and reaches at most a leaf beyond.
    let line = text
        .lines()
        .find(|l| l.starts_with("BOUNDS"))
        .expect("bounds line");
    let nums: Vec<f64> = line
        .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
        .filter_map(|w| w.parse().ok())
        .collect();
    let b = grid.bbox().unwrap();
    let lo = grid.transform.index_to_world(b.min);
    let hi = grid.transform.index_to_world(b.max);
    let h = grid.transform.voxel_size;
    for a in 0..3 {
        assert!(
            nums[a] <= lo[a] + 1e-3 && nums[a] >= lo[a] - 8.0 * h,
            "{line} vs {lo}"
        );
        assert!(
            nums[3 + a] >= hi[a] - 1e-3 && nums[3 + a] <= hi[a] + 8.0 * h,
            "{line} vs {hi}"
        );
    }
}

#[test]
fn blender_imports_the_level_set() {
    if Command::new("blender").arg("--version").output().is_err() {
        return common::skip_or_fail("blender is not installed: the Blender level-set test");
    }
    let dir = tempfile::tempdir().unwrap();
    let path = voxelkit_on_a_torus(dir.path(), &["mesh", "--sdf", "-r", "64"]);
    let text = blender_grids(&path);
    for g in ["GRID density FLOAT True", "GRID surface FLOAT True"] {
        assert!(text.contains(g), "`{g}` missing: {text}");
    }
    assert_first_grid_is_density(&text);
}

#[test]
fn blender_imports_a_solid_with_tiles() {
    if Command::new("blender").arg("--version").output().is_err() {
        return common::skip_or_fail("blender is not installed: the Blender solid test");
    }
    let dir = tempfile::tempdir().unwrap();
    let path = voxelkit_on_a_torus(dir.path(), &["solid", "-r", "200"]);
    let info = voxelkit::io::vdb::read_vdb_info(&path).unwrap();
    let density = info.iter().find(|g| g.name == "density").unwrap();
    assert!(
        density.tile_count > 0,
        "the solid's inside has whole blocks"
    );
    let text = blender_grids(&path);
    for g in [
        "GRID density FLOAT True",
        "GRID shell BOOLEAN True",
        "GRID interior BOOLEAN True",
    ] {
        assert!(text.contains(g), "`{g}` missing: {text}");
    }
    assert_first_grid_is_density(&text);
}

/// Runs `voxelkit COMMAND torus.obj OPTIONS -o out.vdb` (`args` = command then options) on a
/// generated torus in `dir`; returns the output.
fn voxelkit_on_a_torus(dir: &std::path::Path, args: &[&str]) -> std::path::PathBuf {
    let obj = dir.join("torus.obj");
    generate::torus(glam::DVec3::ZERO, 1.0, 0.3, 64, 16)
        .write_obj(&obj)
        .unwrap();
    let path = dir.join("torus.vdb");
    let made = Command::new(env!("CARGO_BIN_EXE_voxelkit"))
        .arg(args[0])
        .arg(&obj)
        .args(&args[1..])
        .arg("-o")
        .arg(&path)
        .output()
        .unwrap();
    assert!(
        made.status.success(),
        "{}",
        String::from_utf8_lossy(&made.stderr)
    );
    path
}

/// What headless Blender prints after importing `path` as a volume object.
fn blender_grids(path: &std::path::Path) -> String {
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/blender/inspect_volume.py"
    );
    let out = Command::new("blender")
        .args(["-b", "--factory-startup", "--python", script, "--"])
        .arg(path)
        .output()
        .unwrap();
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Blender's volume object shows the first grid: it must be `density`.
fn assert_first_grid_is_density(text: &str) {
    let first = text.lines().find(|l| l.starts_with("GRID")).unwrap_or("");
    assert!(first.starts_with("GRID density "), "{text}");
}

/// Blender imports the meshes voxelkit writes (OBJ by its own importer, binary glTF) with every
/// vertex and triangle, every edge joining two faces and the volume of the mesh written.
#[test]
fn blender_imports_the_meshes() {
    if Command::new("blender").arg("--version").output().is_err() {
        return common::skip_or_fail("blender is not installed: the Blender mesh import test");
    }
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("torus.obj");
    generate::torus(glam::DVec3::new(2.0, -1.0, 0.5), 1.0, 0.3, 64, 16)
        .write_obj(&obj)
        .unwrap();
    let mut counts = Vec::new();
    for ext in ["obj", "glb"] {
        let out = dir.path().join(format!("out.{ext}"));
        let status = Command::new(env!("CARGO_BIN_EXE_voxelkit"))
            .args(["mesh", "--sdf", "-r", "64", "-o"])
            .arg(dir.path().join("torus.vdb"))
            .arg("--mesh-out")
            .arg(&out)
            .arg(&obj)
            .output()
            .unwrap();
        assert!(status.status.success(), "{status:?}");
        let written = voxelkit::mesh::Mesh::load(&out).unwrap();
        let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/blender/inspect_mesh.py");
        let o = Command::new("blender")
            .args(["-b", "--factory-startup", "--python", script, "--"])
            .arg(&out)
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&o.stdout).into_owned();
        let line = text
            .lines()
            .find(|l| l.starts_with("MESH "))
            .unwrap_or_else(|| panic!("{ext}: {text}"));
        let fields: Vec<&str> = line.split(' ').collect();
        assert_eq!(
            fields[1].parse::<usize>().unwrap(),
            written.positions.len(),
            "{ext}: {line}"
        );
        assert_eq!(
            fields[2].parse::<usize>().unwrap(),
            written.face_count(),
            "{ext}: {line}"
        );
        assert_eq!(fields[3], "True", "{ext}: not manifold in Blender: {line}");
        let volume: f64 = fields[4].parse().unwrap();
        // The torus's volume, 2 pi^2 R r^2, less what its 16-sided tube cuts off.
        assert!((volume - 1.72).abs() < 0.03, "{ext}: volume {volume}");
        counts.push(fields[2].to_string());
    }
    assert_eq!(counts[0], counts[1]);
}

//! Blender opens what voxelkit writes: a headless Blender imports the .vdb as a volume
//! object and loads the `density`, `surface` and `normal` grids at the right place, and the
//! `density` and level-set `surface` of `--sdf`.
//! Skipped (loudly) where Blender is not installed, outside CI; CI installs it.
#![cfg(all(feature = "vdb", feature = "fixtures"))]

use std::process::Command;
use voxelkit::io::vdb::write_vdb;
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
    write_vdb(&path, &grid, &[]).unwrap();
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/blender/inspect_volume.py"
    );
    let out = Command::new("blender")
        .args([
            "-b",
            "--factory-startup",
            "--python",
            script,
            "--",
            path.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    for g in [
        "GRID density FLOAT True",
        "GRID surface BOOLEAN True",
        "GRID normal VECTOR_FLOAT True",
    ] {
        assert!(text.contains(g), "`{g}` missing: {text}");
    }
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
    let obj = dir.path().join("torus.obj");
    generate::torus(glam::DVec3::ZERO, 1.0, 0.3, 64, 16)
        .write_obj(&obj)
        .unwrap();
    let path = dir.path().join("torus-sdf.vdb");
    let made = Command::new(env!("CARGO_BIN_EXE_voxelkit"))
        .args(["mesh", obj.to_str().unwrap(), "--sdf", "-r", "64", "-o"])
        .arg(&path)
        .output()
        .unwrap();
    assert!(
        made.status.success(),
        "{}",
        String::from_utf8_lossy(&made.stderr)
    );
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/blender/inspect_volume.py"
    );
    let out = Command::new("blender")
        .args(["-b", "--factory-startup", "--python", script, "--"])
        .arg(&path)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    for g in ["GRID density FLOAT True", "GRID surface FLOAT True"] {
        assert!(text.contains(g), "`{g}` missing: {text}");
    }
}

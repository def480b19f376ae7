//! Running the `voxelkit` binary from the CLI tests (only built with feature `vdb`).
#![allow(dead_code)]

use std::process::{Command, Output};

// Tests that use both helpers get two copies of this small module; that is harmless.
#[allow(clippy::duplicate_mod)]
#[path = "../common/skip.rs"]
mod skip;
pub use skip::skip_or_fail;

pub fn voxelkit(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_voxelkit"))
        .args(args)
        .output()
        .unwrap()
}

/// stdout and stderr together.
pub fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// A numeric field of a `--json` object.
pub fn json_field(out: &str, key: &str) -> f64 {
    let start = out
        .find(&format!("\"{key}\":"))
        .unwrap_or_else(|| panic!("{key} missing from {out}"))
        + key.len()
        + 3;
    out[start..]
        .split([',', '}'])
        .next()
        .unwrap()
        .trim()
        .parse()
        .unwrap()
}

/// Runs a Python `script` with pyopenvdb on `path` and returns its stdout; `None`, with a loud
/// warning naming `what` is skipped, when pyopenvdb is not installed.
pub fn run_pyopenvdb(script: &str, path: &std::path::Path, what: &str) -> Option<String> {
    let python = "/usr/bin/python3";
    let probe = Command::new(python)
        .args(["-c", "import pyopenvdb"])
        .output();
    if !probe.map(|o| o.status.success()).unwrap_or(false) {
        skip_or_fail(&format!(
            "python3-openvdb (pyopenvdb) is not installed: {what}"
        ));
        return None;
    }
    let out = Command::new(python)
        .args(["-c", script, path.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    Some(String::from_utf8(out.stdout).unwrap())
}

/// Writes OpenVDB's level-set sphere (radius 0.5, voxel size 0.02, half width 3) to the file
/// given and prints its voxels of negative value, counted over every value, tiles included.
pub const OPENVDB_SPHERE: &str = r#"import sys, pyopenvdb as vdb
g = vdb.createLevelSetSphere(radius=0.5, center=(0, 0, 0), voxelSize=0.02, halfWidth=3.0)
g.name = 'sphere'
vdb.write(sys.argv[1], grids=[g])
n = 0
for it in g.citerAllValues():
    if it.value < 0:
        (x0, y0, z0), (x1, y1, z1) = it.min, it.max
        n += (x1 - x0 + 1) * (y1 - y0 + 1) * (z1 - z0 + 1)
print(n, g.transform.voxelSize()[0])
"#;

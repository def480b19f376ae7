//! Running the `voxelkit` binary from the CLI tests (only built with feature `vdb`).
#![allow(dead_code)]

use std::process::{Command, Output};

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

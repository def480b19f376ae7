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

//! Compiles cpp/vdb_bridge.cc against OpenVDB (C++17, TBB, Imath). Without OpenVDB's headers
//! the crate builds empty, with a warning: only voxelkit's tests and benchmarks use it, and
//! they need the `vdb` feature, which installs OpenVDB with them.

use std::path::Path;
use std::process::Command;

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo::rustc-check-cfg=cfg(openvdb)");
    let headers = [
        "openvdb/openvdb.h",
        "boost/version.hpp",
        "tbb/tbb.h",
        "Imath/ImathVec.h",
    ];
    let found = headers.iter().all(|h| {
        ["/usr/include", "/usr/local/include"]
            .iter()
            .any(|d| Path::new(d).join(h).exists())
    });
    if !found {
        println!(
            "cargo:warning=OpenVDB is missing: voxelkit-openvdb builds empty (install libopenvdb-dev libboost-dev libtbb-dev pkg-config)"
        );
        return;
    }
    println!("cargo:rustc-cfg=openvdb");
    let mut build = cxx_build::bridge("src/bridge.rs");
    build
        .file("cpp/vdb_bridge.cc")
        .include("../cpp")
        .include("../include")
        .std("c++17")
        .flag_if_supported("-Wno-deprecated-declarations")
        .opt_level(2);
    for flag in pkg_config(&["--cflags", "tbb", "Imath"]) {
        build.flag(&flag);
    }
    build.compile("voxelkit_openvdb_bridge");
    for flag in pkg_config(&["--libs", "tbb", "Imath"]) {
        if let Some(lib) = flag.strip_prefix("-l") {
            println!("cargo:rustc-link-lib={lib}");
        } else if let Some(dir) = flag.strip_prefix("-L") {
            println!("cargo:rustc-link-search=native={dir}");
        }
    }
    println!("cargo:rustc-link-lib=openvdb");
    println!("cargo:rustc-link-lib=tbb");
    for f in [
        "cpp/vdb_bridge.cc",
        "cpp/vdb_bridge.h",
        "../cpp/trycatch.h",
        "../include/voxelkit/openvdb.hpp",
        "../include/voxelkit.h",
        "src/bridge.rs",
    ] {
        println!("cargo:rerun-if-changed={f}");
    }
}

/// `pkg-config` output split into words (empty when pkg-config or the package is missing).
fn pkg_config(args: &[&str]) -> Vec<String> {
    Command::new("pkg-config")
        .args(args)
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| {
            String::from_utf8_lossy(&o.stdout)
                .split_whitespace()
                .map(String::from)
                .collect()
        })
        .unwrap_or_default()
}

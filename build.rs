//! Builds the C++ side of the OpenSubdiv bridge (feature `osd`) and checks for the C
//! libraries the `.vdb` writer and reader call (feature `vdb`: blosc, LZ4 and zlib). When a library
//! is missing the build stops with one line naming the Debian packages to install. OpenVDB
//! itself is not linked: its own tools, for tests and benchmarks, live in `openvdb/`.

use std::path::Path;
use std::process::Command;

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    // The shared library behind include/voxelkit.h, found at run time by this name.
    println!("cargo:rustc-cdylib-link-arg=-Wl,-soname,libvoxelkit.so");
    let vdb = std::env::var_os("CARGO_FEATURE_VDB").is_some();
    let osd = std::env::var_os("CARGO_FEATURE_OSD").is_some();
    if vdb {
        require(
            &[],
            &["blosc", "lz4", "z"],
            "blosc, LZ4 or zlib is missing: install them with `apt-get install libblosc-dev liblz4-dev zlib1g-dev`, or build with --no-default-features",
        );
    }
    if osd {
        require(
            &["opensubdiv/version.h"],
            &["osdCPU"],
            "OpenSubdiv is missing: install it with `apt-get install libosd-dev`, or build with --no-default-features",
        );
        build_osd_bridge();
    }
}

/// Stops the build with `message` unless every header and library is found.
fn require(headers: &[&str], libs: &[&str], message: &str) {
    let include_dirs = ["/usr/include", "/usr/local/include"];
    let lib_dirs = lib_search_dirs();
    let header_ok = headers
        .iter()
        .all(|h| include_dirs.iter().any(|d| Path::new(d).join(h).exists()));
    let lib_ok = libs.iter().all(|l| {
        lib_dirs
            .iter()
            .any(|d| Path::new(d).join(format!("lib{l}.so")).exists())
    });
    if !(header_ok && lib_ok) {
        eprintln!("voxelkit: {message}");
        std::process::exit(1);
    }
}

fn lib_search_dirs() -> Vec<String> {
    let mut dirs: Vec<String> = ["/usr/lib", "/usr/local/lib", "/usr/lib64"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    if let Ok(out) = Command::new("gcc").arg("-print-multiarch").output() {
        let triple = String::from_utf8_lossy(&out.stdout).trim().to_string();
        if !triple.is_empty() {
            dirs.push(format!("/usr/lib/{triple}"));
        }
    }
    dirs
}

fn build_osd_bridge() {
    cxx_build::bridge("src/ffi/osd.rs")
        .file("cpp/osd_bridge.cc")
        .std("c++17")
        .opt_level(2)
        .compile("voxelkit_osd_bridge");
    println!("cargo:rustc-link-lib=osdCPU");
    for path in [
        "cpp/osd_bridge.cc",
        "cpp/osd_bridge.h",
        "cpp/trycatch.h",
        "src/ffi/osd.rs",
    ] {
        println!("cargo:rerun-if-changed={path}");
    }
}

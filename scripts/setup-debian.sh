#!/usr/bin/env bash
# Installs what voxelkit needs on Debian 12, saying what it does as it goes:
# - Debian packages: a C/C++ tool chain and pkg-config; blosc, LZ4 and zlib (build.rs links them for
#   .vdb files); OpenVDB, Boost headers, TBB and OpenSubdiv (the C++ side, the tests'
#   independent reader and the benchmarks' reference); pyopenvdb; NanoVDB's headers and tools
#   (the .nvdb files are checked by them); CMake and valgrind (the C and C++ interface
#   tests); Blender (opens the .vdb files headless in a test); Python's venv
#   and pip (scripts/test-all.sh builds the Python module into a virtual environment); EGL
#   (Open3D, which the Python tests compare against, loads it).
#   On a fresh Debian 12 that is about 410 packages with their dependencies: 430 MB to
#   download, 1.8 GB installed, a few minutes.
# - Rust, when cargo is missing or older than Cargo.toml's rust-version (Debian 12's own cargo
#   is): rustup's stable toolchain in ~/.cargo (from static.rust-lang.org). Run cargo with
#   ~/.cargo/bin first on PATH, as the README's commands do.
set -euo pipefail
cd "$(dirname "$0")/.."

say() { printf '\n==> %s\n' "$*"; }
fail() { printf '\nsetup-debian.sh: %s\n' "$*" >&2; exit 1; }

packages=(
    build-essential pkg-config cmake valgrind curl ca-certificates
    libblosc-dev liblz4-dev zlib1g-dev
    libopenvdb-dev libboost-dev libtbb-dev libosd-dev python3-openvdb
    libnanovdb-dev libnanovdb-tools
    blender
    python3-venv python3-pip python3-numpy
    libegl1
)

command -v apt-get >/dev/null && command -v dpkg-query >/dev/null ||
    fail "apt-get is missing: this script is for Debian 12. Elsewhere install the equivalents of: ${packages[*]}; and Rust (https://rustup.rs)"
if [ -r /etc/os-release ] && ! grep -q '^VERSION_ID="12"' /etc/os-release; then
    say "warning: this is not Debian 12 ($(. /etc/os-release; echo "${PRETTY_NAME:-unknown}")); the package names may differ"
fi

missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
    say "Debian packages: all ${#packages[@]} installed"
else
    SUDO=""
    if [ "$(id -u)" -ne 0 ]; then
        command -v sudo >/dev/null || fail "run as root or install sudo: ${#missing[@]} packages are missing: ${missing[*]}"
        SUDO="sudo"
    fi
    export DEBIAN_FRONTEND=noninteractive
    say "Debian packages: updating the package lists"
    $SUDO apt-get update -q
    say "Debian packages: installing ${#missing[@]} (with their dependencies; minutes on a fresh machine): ${missing[*]}"
    $SUDO apt-get install -y -q --no-install-recommends -o Dpkg::Progress-Fancy=0 "${missing[@]}" ||
        fail "apt-get could not install: ${missing[*]}"
fi

# The oldest Rust that builds voxelkit, from Cargo.toml.
needed=$(sed -n 's/^rust-version = "\(.*\)"/\1/p' Cargo.toml | head -1)
export PATH="$HOME/.cargo/bin:$PATH"
version_of_cargo() { cargo --version 2>/dev/null | awk '{print $2}'; }
new_enough() { [ -n "$1" ] && [ "$(printf '%s\n%s\n' "$needed" "$1" | sort -V | head -1)" = "$needed" ]; }
have=$(version_of_cargo || true)
if new_enough "$have"; then
    say "Rust: cargo $have (at least $needed)"
else
    if [ -z "$have" ]; then
        say "Rust: cargo is missing; installing rustup's stable toolchain into ~/.cargo"
    else
        say "Rust: cargo $have is older than the $needed voxelkit needs; installing rustup's stable toolchain into ~/.cargo"
    fi
    if command -v rustup >/dev/null; then
        rustup toolchain install stable --profile minimal && rustup default stable
    else
        curl -sSf https://sh.rustup.rs | sh -s -- -y --profile minimal ||
            fail "rustup could not be installed from https://sh.rustup.rs (is the network reachable?)"
    fi
    have=$(version_of_cargo || true)
    new_enough "$have" || fail "cargo ${have:-is still missing} after installing rustup: $needed or newer is needed"
    say "Rust: cargo $have in ~/.cargo/bin (put it first on PATH: export PATH=\"\$HOME/.cargo/bin:\$PATH\")"
fi
say "Set up. Building voxelkit takes about 2.5 minutes on 2 cores; its tests add about 4 more (target/ grows to about 3.6 GB)"

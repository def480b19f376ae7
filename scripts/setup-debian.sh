#!/usr/bin/env bash
# Installs what voxelkit needs on Debian 12: OpenVDB, Boost headers, TBB, OpenSubdiv,
# pyopenvdb (an independent .vdb reader for the tests), CMake and valgrind (the C and C++
# interface tests), Blender (opens the .vdb files headless in a test), Python's venv and pip
# (the Python module is built into a virtual environment by scripts/test-all.sh), blosc and
# zlib (build.rs links them for .vdb files) and, when
# cargo is missing, Rust.
set -euo pipefail
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends \
    build-essential pkg-config cmake valgrind curl ca-certificates \
    libopenvdb-dev libboost-dev libtbb-dev libosd-dev libblosc-dev zlib1g-dev python3-openvdb blender \
    python3-venv python3-pip python3-numpy >/dev/null
if ! command -v cargo >/dev/null 2>&1; then
    curl -sSf https://sh.rustup.rs | sh -s -- -y --profile minimal
    echo "Rust installed: run 'source \$HOME/.cargo/env' in new shells"
fi

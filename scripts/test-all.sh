#!/usr/bin/env bash
# Every test suite: cargo (the library, the CLI, and the C and C++ interfaces through their
# integration tests), then the Python module built from this checkout into a virtual
# environment (target/python-venv) and tested with pytest (the module, the Blender add-on
# in headless Blender, Dask scale-out). Every suite runs even when one fails; the last line
# counts passed, failed and skipped tests and what the skipped ones needed.
#
# The environment is made from Debian's Python (PYTHON, default /usr/bin/python3) with its
# site packages, so that pyopenvdb (python3-openvdb) and Blender's Python match the module.
# Building it installs maturin, and the module's extras for the tests (pytest, Dask, trimesh,
# Open3D: about 1.3 GB), from PyPI.
set -uo pipefail
cd "$(dirname "$0")/.."
# rustup's cargo, where scripts/setup-debian.sh installed it, before an older system one.
export PATH="$HOME/.cargo/bin:$PATH"
python="${PYTHON:-/usr/bin/python3}"
# The tests build without the release profile's whole-program optimisation (Cargo.toml), which
# would take minutes for each test program, and into their own folder, so that target/release
# keeps the optimised build of the README's first command.
export CARGO_TARGET_DIR="$PWD/target/tests" CARGO_PROFILE_RELEASE_LTO=false \
    CARGO_PROFILE_RELEASE_CODEGEN_UNITS=16
export VOXELKIT_CLI="$CARGO_TARGET_DIR/release/voxelkit"
logs=target/test-logs
mkdir -p "$logs"
cargo test --release --no-fail-fast 2>&1 | tee "$logs/cargo.log"
cargo_status=${PIPESTATUS[0]}
venv=target/python-venv
{
    if [ ! -x "$venv/bin/python" ]; then
        "$python" -m venv --system-site-packages "$venv"
    fi &&
        "$venv/bin/python" -m pip install --quiet ".[distributed,test]" &&
        "$venv/bin/python" -m pytest -q -rs python/tests
} 2>&1 | tee "$logs/pytest.log"
pytest_status=${PIPESTATUS[0]}
"$python" scripts/test_summary.py "$logs/cargo.log" "$cargo_status" "$logs/pytest.log" "$pytest_status"
[ "$cargo_status" -eq 0 ] && [ "$pytest_status" -eq 0 ]

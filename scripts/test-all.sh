#!/usr/bin/env bash
# Every test suite: cargo (the library, the CLI, and the C and C++ interfaces through their
# integration tests), then the Python module built from this checkout into a virtual
# environment (target/python-venv) and tested with pytest (the module, the Blender add-on
# in headless Blender, Dask scale-out).
#
# The environment is made from Debian's Python (PYTHON, default /usr/bin/python3) with its
# site packages, so that pyopenvdb (python3-openvdb) and Blender's Python match the module.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --release
python="${PYTHON:-/usr/bin/python3}"
venv=target/python-venv
if [ ! -x "$venv/bin/python" ]; then
    "$python" -m venv --system-site-packages "$venv"
fi
"$venv/bin/python" -m pip install --quiet ".[distributed,test]"
"$venv/bin/python" -m pytest -q python/tests

"""Shared fixtures: the shared test data, the CLI built by cargo, and pyopenvdb.

The shared data folder is `$VOXELKIT_DATA` (default: ../shared/data beside the repository).
Where it, the CLI, pyopenvdb or Blender is missing, tests fail under CI (`CI=true`) and are
skipped with a loud warning elsewhere.
"""

import importlib
import os
import subprocess
import warnings
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


def missing(need, detail):
    """Fails in CI, skips loudly elsewhere: `need` names what is missing (the test summary
    counts skips by it), `detail` what it is wanted for."""
    message = f"MISSING {need}: {detail}"
    if os.environ.get("CI") == "true":
        pytest.fail(message)
    warnings.warn(message)
    pytest.skip(message)


@pytest.fixture(scope="session")
def data():
    folder = Path(os.environ.get("VOXELKIT_DATA", REPO.parent / "shared" / "data"))
    if not (folder / "meshes").is_dir():
        missing("the shared test data (VOXELKIT_DATA)", f"not at {folder}")
    return folder


@pytest.fixture(scope="session")
def cli():
    """The `voxelkit` command line tool of this checkout (`cargo build --release`)."""
    path = Path(os.environ.get("VOXELKIT_CLI", REPO / "target" / "release" / "voxelkit"))
    if not path.is_file():
        missing("the voxelkit CLI (cargo build --release)", f"not at {path}")

    def run(*args):
        done = subprocess.run([str(path), *map(str, args)], capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        return done

    return run


def imported(module, need, detail):
    """The module named, or `missing(need, detail)` where it is not installed."""
    try:
        return importlib.import_module(module)
    except ImportError:
        missing(need, detail)


@pytest.fixture(scope="session")
def pyopenvdb():
    return imported("pyopenvdb", "pyopenvdb (python3-openvdb)", "the independent .vdb reader")


@pytest.fixture(scope="session")
def trimesh():
    return imported("trimesh", 'trimesh (pip install ".[test]")', "meshes as trimesh users hold them")


@pytest.fixture(scope="session")
def open3d():
    return imported("open3d", 'Open3D (pip install ".[test]")', "meshes and voxel grids as Open3D users hold them")


def closed_meshes(data):
    """The shared meshes the exterior flood can fill (inside="parity": it refuses open ones)."""
    import voxelkit

    closed = []
    for path in sorted((data / "meshes").glob("*.obj")):
        try:
            voxelkit.solid(path, resolution=8, inside="parity")
        except ValueError as e:
            assert "open" in str(e) or "boundary" in str(e), e
            continue
        closed.append(path)
    return closed


def voxel_set(ijk):
    """Voxel indices as a set of tuples, for comparisons that name the differences."""
    return set(map(tuple, ijk.tolist()))

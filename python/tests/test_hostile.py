"""Hostile input through Python: OpenVDB-made grids voxelkit must read, and writes it must
refuse rather than get wrong."""

import numpy as np
import pytest

import voxelkit


def _grid_with_scale(pyopenvdb, path, diagonal, translation):
    matrix = [[diagonal[0], 0, 0, 0], [0, diagonal[1], 0, 0], [0, 0, diagonal[2], 0], [*translation, 1]]
    grid = pyopenvdb.BoolGrid()
    grid.transform = pyopenvdb.createLinearTransform(matrix)
    grid.getAccessor().setValueOn((1, 2, 3), True)
    grid.name = "voxels"
    pyopenvdb.write(str(path), [grid])


def test_a_uniform_scale_rounded_beside_a_large_translation_is_read(tmp_path, pyopenvdb):
    path = tmp_path / "far.vdb"
    _grid_with_scale(pyopenvdb, path, (0.01, 0.0099999998, 0.010000000009), (5e5, 5e6, 100))
    grid = voxelkit.read_vdb(path)
    assert len(grid) == 1 and grid.voxel_size == pytest.approx(0.01, rel=1e-6)
    skewed = tmp_path / "skewed.vdb"
    _grid_with_scale(pyopenvdb, skewed, (0.01, 0.02, 0.01), (0, 0, 0))
    with pytest.raises(OSError, match="different scale per axis"):
        voxelkit.read_vdb(skewed)


def test_half_precision_is_refused_for_distances_beyond_its_range(tmp_path):
    half = 2e6
    corners = [[x, y, z] for x in (-half, half) for y in (-half, half) for z in (-half, half)]
    quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
    faces = [[q[0], q[1], q[2]] for q in quads] + [[q[0], q[2], q[3]] for q in quads]
    grid = voxelkit.mesh((corners, faces), resolution=32, sdf=True)
    with pytest.raises(ValueError, match="exceed half precision's range"):
        grid.write(tmp_path / "big.vdb", half=True)
    assert not (tmp_path / "big.vdb").exists()
    grid.write(tmp_path / "big.vdb")


def test_huge_arrays_and_tile_grids_are_memory_errors_not_aborts(tmp_path, pyopenvdb):
    # 2^31 vertices as a strided view of three numbers: no memory until copied.
    vertices = np.lib.stride_tricks.as_strided(np.zeros(3), shape=(2**31, 3), strides=(0, 8))
    with pytest.raises(MemoryError):
        voxelkit.mesh((vertices, [[0, 1, 2]]), max_memory_mib=500)
    faces = np.lib.stride_tricks.as_strided(np.zeros(3, dtype=np.int64), shape=(2**31, 3), strides=(0, 8))
    with pytest.raises(MemoryError):
        voxelkit.mesh(([[0, 0, 0], [1, 0, 0], [0, 1, 0]], faces), max_memory_mib=500)
    # One root tile of 4096^3 voxels: 6.9e10 indices do not fit.
    grid = pyopenvdb.BoolGrid()
    grid.fill((0, 0, 0), (4095, 4095, 4095), True)
    grid.name = "voxels"
    pyopenvdb.write(str(tmp_path / "tile.vdb"), [grid])
    tiles = voxelkit.read_vdb(tmp_path / "tile.vdb")
    assert len(tiles) == 4096**3
    with pytest.raises(MemoryError):
        tiles.ijk
    with pytest.raises(MemoryError):
        tiles.to_dense()

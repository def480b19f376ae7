"""Hostile input through Python: OpenVDB-made grids voxelkit must read, and writes it must
refuse rather than get wrong."""

import pytest

import voxelkit


def _grid_with_scale(pyopenvdb, path, diagonal, translation):
    matrix = [[diagonal[0], 0, 0, 0], [0, diagonal[1], 0, 0], [0, 0, diagonal[2], 0], [*translation, 1]]
    grid = pyopenvdb.BoolGrid()
    grid.transform = pyopenvdb.createLinearTransform(matrix)
    grid.getAccessor().setValueOn((1, 2, 3), True)
    grid.name = "voxels"
    pyopenvdb.write(str(path), [grid])


def test_a_uniform_scale_rounded_beside_a_large_translation_is_read(tmp_path):
    pyopenvdb = pytest.importorskip("pyopenvdb")
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

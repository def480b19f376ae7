"""voxelkit as trimesh and Open3D users reach for it: their mesh objects as inputs, and arrays
whose meaning is checked rather than guessed."""

import numpy as np
import pytest

import voxelkit
from conftest import voxel_set


def test_a_trimesh_mesh_voxelizes_as_its_arrays(trimesh):
    mesh = trimesh.creation.torus(major_radius=1.0, minor_radius=0.3)
    from_object = voxelkit.mesh(mesh, resolution=64)
    from_arrays = voxelkit.mesh((mesh.vertices, mesh.faces), resolution=64)
    assert len(from_object) > 1000
    assert voxel_set(from_object.ijk) == voxel_set(from_arrays.ijk)
    report = voxelkit.solid(mesh, resolution=64).report
    assert report["volume_inside"] <= mesh.volume <= report["volume_with_surface"]


def test_an_open3d_mesh_voxelizes_as_its_arrays(open3d):
    mesh = open3d.geometry.TriangleMesh.create_torus(torus_radius=1.0, tube_radius=0.3)
    vertices, triangles = np.asarray(mesh.vertices), np.asarray(mesh.triangles)
    from_object = voxelkit.mesh(mesh, resolution=64)
    assert len(from_object) > 1000
    assert voxel_set(from_object.ijk) == voxel_set(voxelkit.mesh((vertices, triangles), resolution=64).ijk)


def test_faces_must_be_whole_numbers():
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    faces = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    exact = voxelkit.mesh((vertices, faces), resolution=16)
    # Whole numbers stored as floats are the same faces.
    assert voxel_set(voxelkit.mesh((vertices, faces.astype(float)), resolution=16).ijk) == voxel_set(exact.ijk)
    with pytest.raises(ValueError, match="face 0 holds 0.7, not a vertex index"):
        voxelkit.mesh((vertices, faces + 0.7), resolution=16)
    with pytest.raises(ValueError, match="face 1 holds 2.5"):
        voxelkit.mesh((vertices, [[0, 2, 1], [0, 2.5, 3]]), resolution=16)
    with pytest.raises(TypeError, match="trimesh"):
        voxelkit.mesh(object(), resolution=16)

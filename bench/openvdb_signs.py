"""How often OpenVDB's meshToLevelSet signs a level set's band differently from voxelkit.

    voxelkit mesh MESH.obj --sdf -r 512 -o ours.vdb
    /usr/bin/python3 bench/openvdb_signs.py MESH.obj ours.vdb

OpenVDB (pyopenvdb's createLevelSetFromPolygons) converts the same OBJ on the same transform
and band; every band voxel of voxelkit's `surface` grid is compared by the sign of the value
OpenVDB holds there. voxelkit's signs follow the mesh's winding number (checked against the
exact sum in tests/winding_inside.rs), so the share is where OpenVDB departs from it.
"""

import sys

import numpy as np
import pyopenvdb as vdb


def read_obj(path):
    points, triangles = [], []
    with open(path) as f:
        for line in f:
            words = line.split()
            if words and words[0] == "v":
                points.append([float(x) for x in words[1:4]])
            elif words and words[0] == "f":
                corners = [int(w.split("/")[0]) for w in words[1:]]
                corners = [c - 1 if c > 0 else len(points) + c for c in corners]
                triangles += [[corners[0], a, b] for a, b in zip(corners[1:], corners[2:])]
    return np.array(points), np.array(triangles, dtype=np.uint32)


def main(mesh_path, ours_path):
    ours = vdb.read(ours_path, "surface")
    band = ours.background / ours.transform.voxelSize()[0]
    points, triangles = read_obj(mesh_path)
    theirs = vdb.FloatGrid.createLevelSetFromPolygons(
        points, triangles=triangles, transform=ours.transform, halfWidth=band
    )
    at = theirs.getConstAccessor()
    total = differ = 0
    for item in ours.citerOnValues():
        if item.count == 1:
            total += 1
            differ += (item.value < 0) != (at.getValue(item.min) < 0)
    print(f"{mesh_path}: {total} band voxels; OpenVDB signs {differ} of them differently "
          f"({100.0 * differ / max(total, 1):.2f}%)")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])

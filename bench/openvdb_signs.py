"""How often OpenVDB's meshToLevelSet signs a level set's band differently from voxelkit.

    voxelkit mesh MESH.obj --sdf -r 512 -o ours.vdb
    /usr/bin/python3 bench/openvdb_signs.py MESH.obj ours.vdb

OpenVDB (pyopenvdb's createLevelSetFromPolygons) converts the same OBJ on the same transform
and band; every band voxel of voxelkit's `surface` grid is compared by the sign of the value
OpenVDB holds there. voxelkit's signs follow the mesh's winding number (checked against the
exact sum in tests/winding_inside.rs), so the share is where OpenVDB departs from it.
"""

import sys

import pyopenvdb as vdb

from obj_arrays import read_obj


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

"""voxelkit: voxelization with guaranteed topology.

Polygon meshes, Catmull-Clark subdivision surfaces, formulas and 3D lines become sparse voxel
grids whose topology is guaranteed (6- or 26-separating surfaces, solids by flooding, exact
level sets), written as OpenVDB ``.vdb`` files. The same pipeline as the ``voxelkit`` command
line tool, with the same options and messages::

    import voxelkit
    grid = voxelkit.mesh("bunny.obj", resolution=512, separability=26)
    grid.ijk            # (N, 3) int64 voxel indices
    grid.report         # the CLI's JSON report as a dict
    grid.write("bunny.vdb")

A mesh is a path (.obj, .stl, .ply, .off, .gltf, .glb) or a ``(vertices, faces)`` pair of arrays. Every
call releases the GIL while it works; Ctrl-C cancels it, and ``progress=f`` calls
``f(stage, done, total)`` a few times a second (raising in ``f`` cancels too). Errors are
``ValueError`` (bad input), ``MemoryError`` (work that does not fit), ``OSError`` (files).

``voxelkit.blender`` is a Blender add-on; ``voxelkit.distributed`` spreads one job over Dask
workers in bricks.
"""

from ._voxelkit import (
    Grid,
    __version__,
    combine,
    csg,
    implicit,
    lines,
    measure,
    mesh,
    read_vdb,
    solid,
    subdiv,
)

__all__ = [
    "Grid",
    "__version__",
    "combine",
    "csg",
    "implicit",
    "lines",
    "measure",
    "mesh",
    "read_vdb",
    "solid",
    "subdiv",
]

# Blender installs this package as an add-on from these (see voxelkit.blender).
bl_info = {
    "name": "voxelkit",
    "author": "voxelkit",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Properties > Object > voxelkit",
    "description": "Voxelize meshes with guaranteed topology into OpenVDB volumes",
    "category": "Object",
}


def register():
    """Registers the Blender add-on (inside Blender only)."""
    from . import blender

    blender.register()


def unregister():
    """Unregisters the Blender add-on."""
    from . import blender

    blender.unregister()

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

A mesh is a path (.obj, .stl, .ply, .off, .gltf, .glb), a ``(vertices, faces)`` pair of arrays
(faces: whole numbers), or a trimesh ``Trimesh`` or Open3D ``TriangleMesh`` as it is.
``signed_distance(mesh, points)`` and ``contains(mesh, points)`` answer for any points,
exactly. Every
call releases the GIL while it works; Ctrl-C cancels it, and ``progress=f`` calls
``f(stage, done, total)`` a few times a second (raising in ``f`` cancels too). Errors are
``ValueError`` (bad input), ``MemoryError`` (work that does not fit), ``OSError`` (files).

``voxelkit.blender`` is a Blender add-on; ``voxelkit.distributed`` spreads one job over Dask
workers in bricks.
"""

import inspect as _inspect
import json as _json

from . import _voxelkit
from ._voxelkit import DEFAULT_RESOLUTION, Grid, __version__, read_vdb

#: Every function's options: ``OPTIONS[name]["fields"]`` lists each option's ``name``,
#: ``doc``, ``default`` and ``choices``; ``OPTIONS["limits"]`` the keywords every job takes.
#: The functions below, the Blender add-on and ``voxelkit.distributed`` are made from it.
OPTIONS = _json.loads(_voxelkit.options())

_PROGRESS_DOC = "progress: f(stage, done, total), called a few times a second (raising cancels)"


def _default(value):
    return tuple(value) if isinstance(value, list) else value


def _option_parameters(fields, kind):
    """The signature parameters of the table's ``fields``, with their defaults."""
    return [_inspect.Parameter(f["name"], kind, default=_default(f["default"])) for f in fields]


def _option_lines(fields):
    """A docstring line per field of the table: name = default (choices): doc."""
    lines = []
    for f in fields:
        choices = f" (one of {', '.join(map(str, f['choices']))})" if f["choices"] else ""
        lines.append(f"{f['name']} = {f['default']!r}{choices}: {f['doc']}")
    return lines


#: Each function made from the table: its positional inputs with their types (annotations
#: for the generated stubs), the table entry of its options, what it returns, and what it
#: takes. ``python -m voxelkit._stubs`` writes ``__init__.pyi`` from these and the table.
_FUNCTIONS = {
    "mesh": (
        {"source": "MeshSource"}, "mesh", "Grid",
        "source: a path (.obj, .stl, .ply, .off, .gltf, .glb), a (vertices, faces) pair, or a trimesh or Open3D mesh.",
    ),
    "solid": (
        {"source": "MeshSource"}, "solid", "Grid",
        "source: a mesh, as for mesh() (open ones too: see inside); the report holds the volume, mass and area.",
    ),
    "subdiv": (
        {"source": "MeshSource"}, "subdiv", "Grid",
        "source: a Catmull-Clark control mesh (a path or a (vertices, faces) pair).",
    ),
    "implicit": (
        {"formula": "str"}, "implicit", "Grid",
        "formula: F in the coordinates' variables; the surface is F = 0.",
    ),
    "lines": (
        {"source": "MeshSource"}, "lines", "Grid",
        "source: a mesh with polylines (OBJ `l`) or faces.",
    ),
    "measure": (
        {"source": "Union[MeshSource, Grid]"}, "measure", "Grid",
        "source: a closed mesh, a .vdb path or a Grid holding a surface; the measures are in the returned solid's report.",
    ),
    "combine": (
        {"a": "Union[Grid, Path]", "b": "Union[Grid, Path]"}, "combine", "Grid",
        "a, b: Grids, or .vdb paths whose grid `grid` (or voxel set) is read; the result has a's transform.",
    ),
    "signed_distance": (
        {"mesh": "MeshSource", "points": "npt.ArrayLike"}, "query", "npt.NDArray[np.float64]",
        "mesh: as for mesh(); points: an (n, 3) array. Returns the exact distance (f64) from each point to the nearest triangle, negative inside by the option inside; computed on every thread, the GIL released.",
    ),
    "contains": (
        {"mesh": "MeshSource", "points": "npt.ArrayLike"}, "query", "npt.NDArray[np.bool_]",
        "mesh: as for mesh(); points: an (n, 3) array. Returns whether each point lies inside the mesh (bool), by the option inside: its winding number (at least 1/2, exact where near 1/2) or ray parity.",
    ),
    "csg": (
        {"tree": "Union[Path, Dict[str, Any]]"}, None, "Grid",
        "A CSG tree (the CLI's `csg --tree` JSON): a path to the JSON file, or the tree as a dict (its file names are then found from the current directory).",
    ),
}


def _option_fields(request):
    """The table's fields of a function's options: its request's, then the limits."""
    return (OPTIONS[request]["fields"] if request else []) + OPTIONS["limits"]["fields"]


def _from_schema(name):
    """``_voxelkit.<name>`` with the table's signature and docs: positional inputs, then
    the request's options, the limits and ``progress``."""
    inputs, request, _, summary = _FUNCTIONS[name]
    native = getattr(_voxelkit, name)
    fields = _option_fields(request)
    kind = _inspect.Parameter.POSITIONAL_OR_KEYWORD
    params = [_inspect.Parameter(i, kind) for i in inputs]
    params += _option_parameters(fields, kind)
    params.append(_inspect.Parameter("progress", kind, default=None))
    signature = _inspect.Signature(params)

    def call(*args, **kwargs):
        bound = signature.bind(*args, **kwargs)
        given = dict(bound.arguments)
        positional = [given.pop(i) for i in inputs]
        return native(*positional, **given)

    paragraphs = ([OPTIONS[request]["doc"]] if request else []) + [summary]
    options = _option_lines(fields) + [_PROGRESS_DOC]
    call.__name__ = call.__qualname__ = name
    call.__module__ = __name__
    call.__signature__ = signature
    call.__doc__ = "\n\n".join(paragraphs + ["\n".join(options)])
    return call


mesh = _from_schema("mesh")
solid = _from_schema("solid")
subdiv = _from_schema("subdiv")
implicit = _from_schema("implicit")
lines = _from_schema("lines")
measure = _from_schema("measure")
combine = _from_schema("combine")
signed_distance = _from_schema("signed_distance")
contains = _from_schema("contains")
csg = _from_schema("csg")

__all__ = [
    "DEFAULT_RESOLUTION",
    "Grid",
    "OPTIONS",
    "__version__",
    "combine",
    "contains",
    "csg",
    "implicit",
    "lines",
    "measure",
    "mesh",
    "read_vdb",
    "signed_distance",
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

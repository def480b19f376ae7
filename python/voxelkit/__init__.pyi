"""Type stubs of voxelkit, written by ``python -m voxelkit._stubs`` from the table of
options (voxelkit.OPTIONS): edit the table, not this file."""

from os import PathLike
from typing import Any, Callable, Dict, Literal, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from ._voxelkit import DEFAULT_RESOLUTION as DEFAULT_RESOLUTION
from ._voxelkit import Grid as Grid
from ._voxelkit import __version__ as __version__
from ._voxelkit import read_vdb as read_vdb

Path = Union[str, PathLike]
#: A path, a (vertices, faces) pair of arrays, or an object with them (trimesh, Open3D).
MeshSource = Union[Path, Tuple[npt.ArrayLike, npt.ArrayLike], Any]
Progress = Callable[[str, int, int], Any]

#: Every function's options (see the package docstring).
OPTIONS: Dict[str, Dict[str, Any]]
bl_info: Dict[str, Any]

def register() -> None:
    """Registers the Blender add-on (inside Blender only)."""

def unregister() -> None:
    """Unregisters the Blender add-on."""

def mesh(
    source: MeshSource,
    resolution: Optional[int] = None,
    voxel_size: Optional[float] = None,
    origin: Optional[Sequence[float]] = None,
    bounds: Optional[Union[Sequence[float], Sequence[Sequence[float]]]] = None,
    separability: Literal[6, 26] = 26,
    method: Literal["separating", "projective"] = 'separating',
    criterion: Literal["huang", "clipped"] = 'huang',
    normals: bool = False,
    colors: bool = True,
    attributes: Optional[Sequence[str]] = None,
    color: Optional[Sequence[float]] = None,
    sdf: bool = False,
    udf: bool = False,
    band: float = 3.0,
    inside: Literal["auto", "winding", "parity"] = 'auto',
    up_axis: Literal["y", "z"] = 'z',
    threads: Optional[int] = None,
    max_memory_mib: Optional[int] = None,
    progress: Optional[Progress] = None,
) -> Grid:
    """A polygon mesh's surface: 6- or 26-separating (Huang et al.) or projective (Jegathese et al.); with `sdf` or `udf`, exact distances within `band` voxels instead.

    source: a path (.obj, .stl, .ply, .off, .gltf, .glb), a (vertices, faces) pair, or a trimesh or Open3D mesh.

    resolution = None: Voxels along the longest bounding-box axis (none: the default resolution, unless voxel_size is given).
    voxel_size = None: Voxel edge length in world units (instead of resolution).
    origin = None: The world position of the centre of voxel (0, 0, 0) (none: half a voxel inside the low corner of the mesh's box): [0, 0, 0] puts every centre on a multiple of the voxel size, as trimesh does; the mesh's low corner gives Open3D's VoxelGrid centres.
    bounds = None: The world box the grid covers, `[lo, hi]` (a cube) or `[[x0, y0, z0], [x1, y1, z1]]` (none: the mesh's box): resolution counts voxels along its longest side and, unless origin is given, the first centre lies half a voxel inside its low corner (Open3D's within_bounds grid); only voxels whose centres lie in it are kept, and dense arrays span it.
    separability = 26 (one of 6, 26): 6: thin surface blocking face-connected paths; 26: blocks every path.
    method = 'separating' (one of separating, projective): separating: Huang et al.'s surface; projective: Jegathese et al.'s scan-lines (colours, no separability guarantee where triangles meet).
    criterion = 'huang' (one of huang, clipped): huang: the paper's full vertex spheres and edge cylinders; clipped: the same clipped to the face slabs (still separating, far fewer redundant voxels).
    normals = False: Also keep a `normal` grid (nearest face, edge or vertex normal per voxel).
    colors = True: Projective: carry the mesh's vertex colours into a `Cd` grid.
    attributes = None: The mesh's vertex attributes to write, each as a grid of its name (`uv`, `vertex_normal`, a PLY property's name, `Cd` for vertex colours where the method does not colour its voxels itself): `["all"]`, `["none"]` or names (none: all with the projective method, none otherwise). The projective method interpolates them across each triangle; separating surfaces and distance bands take each voxel's value at the mesh's nearest point.
    color = None: Projective: one (r, g, b) colour for every voxel instead.
    sdf = False: Exact signed distances (a level set) within `band`, signed by `inside`.
    udf = False: Exact unsigned distances within `band` (open meshes too).
    band = 3.0: Half width of the distance band, in voxels.
    inside = 'auto' (one of auto, winding, parity): How the inside is decided: auto (the winding number where the orientation is consistent, ray parity where not), winding (inside where the generalized winding number is at least 1/2: open, overlapping and hollow meshes too) or parity (ray parity and the exterior flood: closed meshes).
    up_axis = 'z' (one of y, z): The up axis of a mesh file: y turns a Y-up file to Z-up as Blender's importer does.
    threads = None: Worker threads (none or 0: every core; at most 256).
    max_memory_mib = None: Refuse work estimated above this many MiB before it starts (none or 0: the memory available).
    progress: f(stage, done, total), called a few times a second (raising cancels)"""

def solid(
    source: MeshSource,
    resolution: Optional[int] = None,
    voxel_size: Optional[float] = None,
    origin: Optional[Sequence[float]] = None,
    bounds: Optional[Union[Sequence[float], Sequence[Sequence[float]]]] = None,
    method: Literal["flood", "depth-layers", "beam"] = 'flood',
    flood: Literal["blocks", "spans", "xyz"] = 'blocks',
    graystack: int = 1048576,
    directions: Union[int, Sequence[Sequence[int]]] = 16,
    layers: Literal["double", "single"] = 'double',
    unclassified: Literal["no-direction", "paper"] = 'no-direction',
    fill: Literal["parity", "paper"] = 'parity',
    density: float = 1.0,
    topology: bool = False,
    sdf: bool = False,
    band: float = 3.0,
    inside: Literal["auto", "winding", "parity"] = 'auto',
    up_axis: Literal["y", "z"] = 'z',
    threads: Optional[int] = None,
    max_memory_mib: Optional[int] = None,
    progress: Optional[Progress] = None,
) -> Grid:
    """A closed mesh's solid: flood (the 26-separating surface and everything the exterior flood cannot reach), depth-layers (Passalis et al.) or beam (Jegathese et al.); with `sdf`, its level set.

    source: a mesh, as for mesh() (open ones too: see inside); the report holds the volume, mass and area.

    resolution = None: Voxels along the longest bounding-box axis (none: the default resolution, unless voxel_size is given).
    voxel_size = None: Voxel edge length in world units (instead of resolution).
    origin = None: The world position of the centre of voxel (0, 0, 0) (none: half a voxel inside the low corner of the mesh's box): [0, 0, 0] puts every centre on a multiple of the voxel size, as trimesh does; the mesh's low corner gives Open3D's VoxelGrid centres.
    bounds = None: The world box the grid covers, `[lo, hi]` (a cube) or `[[x0, y0, z0], [x1, y1, z1]]` (none: the mesh's box): resolution counts voxels along its longest side and, unless origin is given, the first centre lies half a voxel inside its low corner (Open3D's within_bounds grid); only voxels whose centres lie in it are kept, and dense arrays span it.
    method = 'flood' (one of flood, depth-layers, beam): flood, depth-layers or beam.
    flood = 'blocks' (one of blocks, spans, xyz): The exterior flood of inside parity: blocks (fastest), spans, or xyz (Lai & Cheng's FloodingXYZ).
    graystack = 1048576: GRAYSTACK capacity of the xyz flood (entries; when full, sweeps resume the flood).
    directions = 16: Depth layers: a count of the 16 built-in directions, or integer (x, y, z) triples, each with a component of 1 or -1, none parallel.
    layers = 'double' (one of double, single): Depth layers: double (a stencil count, Passalis et al.) or single (Karabassi et al.).
    unclassified = 'no-direction' (one of no-direction, paper): Depth layers: no-direction (a voxel no direction decides) or paper (a voxel on a ray of any direction crossing more than four times).
    fill = 'parity' (one of parity, paper): Beam: parity (centres between exact crossings) or paper (from each back-face voxel up to the next front-face voxel).
    density = 1.0: Mass per unit volume.
    topology = False: Also count components (26-connected) and genus.
    sdf = False: Write the solid's level set instead: exact signed distances within `band`.
    band = 3.0: Half width of the distance band, in voxels.
    inside = 'auto' (one of auto, winding, parity): How the inside is decided: auto (the winding number where the orientation is consistent, ray parity where not), winding (inside where the generalized winding number is at least 1/2: open, overlapping and hollow meshes too) or parity (ray parity and the exterior flood: closed meshes).
    up_axis = 'z' (one of y, z): The up axis of a mesh file: y turns a Y-up file to Z-up as Blender's importer does.
    threads = None: Worker threads (none or 0: every core; at most 256).
    max_memory_mib = None: Refuse work estimated above this many MiB before it starts (none or 0: the memory available).
    progress: f(stage, done, total), called a few times a second (raising cancels)"""

def subdiv(
    source: MeshSource,
    resolution: Optional[int] = None,
    voxel_size: Optional[float] = None,
    origin: Optional[Sequence[float]] = None,
    bounds: Optional[Union[Sequence[float], Sequence[Sequence[float]]]] = None,
    adjacency: Literal[6, 18, 26] = 26,
    enclose: bool = False,
    presplit: int = 8,
    solid: bool = False,
    depth_layers: bool = False,
    graystack: int = 1048576,
    density: float = 1.0,
    topology: bool = False,
    up_axis: Literal["y", "z"] = 'z',
    threads: Optional[int] = None,
    max_memory_mib: Optional[int] = None,
    progress: Optional[Progress] = None,
) -> Grid:
    """A Catmull-Clark limit surface from its control mesh (Lai & Cheng); with `solid`, the solid it bounds, flooded from seeds against the limit normals by FloodingXYZ.

    source: a Catmull-Clark control mesh (a path or a (vertices, faces) pair).

    resolution = None: Voxels along the longest bounding-box axis (none: the default resolution, unless voxel_size is given).
    voxel_size = None: Voxel edge length in world units (instead of resolution).
    origin = None: The world position of the centre of voxel (0, 0, 0) (none: half a voxel inside the low corner of the mesh's box): [0, 0, 0] puts every centre on a multiple of the voxel size, as trimesh does; the mesh's low corner gives Open3D's VoxelGrid centres.
    bounds = None: The world box the grid covers, `[lo, hi]` (a cube) or `[[x0, y0, z0], [x1, y1, z1]]` (none: the mesh's box): resolution counts voxels along its longest side and, unless origin is given, the first centre lies half a voxel inside its low corner (Open3D's within_bounds grid); only voxels whose centres lie in it are kept, and dense arrays span it.
    adjacency = 26 (one of 6, 18, 26): The adjacency (6, 18 or 26) every voxel meets between its sub-patches' corners.
    enclose = False: Every voxel the surface touches (an enveloping voxelization).
    presplit = 8: Each face's patch split K x K before the adaptive subdivision.
    solid = False: The solid of the closed limit surface, with its volume and mass.
    depth_layers = False: With `solid`: fill by Passalis et al.'s double depth layers along z, x and y on a tessellation certified within 0.45 voxel of the limit surface, united with the enclosing surface, instead of seeds and FloodingXYZ (every pocket filled).
    graystack = 1048576: GRAYSTACK capacity of FloodingXYZ (entries).
    density = 1.0: Mass per unit volume.
    topology = False: Also count components and genus.
    up_axis = 'z' (one of y, z): The up axis of a mesh file: y turns a Y-up file to Z-up as Blender's importer does.
    threads = None: Worker threads (none or 0: every core; at most 256).
    max_memory_mib = None: Refuse work estimated above this many MiB before it starts (none or 0: the memory available).
    progress: f(stage, done, total), called a few times a second (raising cancels)"""

def implicit(
    formula: str,
    coords: Literal["cartesian", "spherical", "cylindrical"] = 'cartesian',
    bounds: Union[Sequence[float], Sequence[Sequence[float]]] = (-1.0, 1.0),
    resolution: int = 256,
    levels: bool = False,
    negative_r: bool = False,
    theta_range: Literal["positive", "symmetric"] = 'positive',
    squared: bool = False,
    depth_layers: bool = False,
    threads: Optional[int] = None,
    max_memory_mib: Optional[int] = None,
    progress: Optional[Progress] = None,
) -> Grid:
    """The surface F = 0 of a formula, by interval octree (Stolte & Kaufman).

    formula: F in the coordinates' variables; the surface is F = 0.

    coords = 'cartesian' (one of cartesian, spherical, cylindrical): cartesian (x, y, z), spherical (r, theta, phi) or cylindrical (r, theta, y: r and theta in the XZ plane, y along the axis).
    bounds = [-1.0, 1.0]: The box: [lo, hi] for a cube, or [[x0, y0, z0], [x1, y1, z1]].
    resolution = 256: Voxels along the box's longest side.
    levels = False: Also keep every level of the octree (each envelops the surface).
    negative_r = False: Spherical and cylindrical: the surface where r < 0 too.
    theta_range = 'positive' (one of positive, symmetric): positive (the paper's [0, 2pi)) or symmetric ((-pi, pi]).
    squared = False: The paper's [G]^2 - r^2 = 0 for F = G - r (the surface r = |G|).
    depth_layers = False: The solid F < 0 within the bounds instead of the surface, by Passalis et al.'s double depth layers along z, x and y, each ray's crossings of F = 0 isolated by interval arithmetic.
    threads = None: Worker threads (none or 0: every core; at most 256).
    max_memory_mib = None: Refuse work estimated above this many MiB before it starts (none or 0: the memory available).
    progress: f(stage, done, total), called a few times a second (raising cancels)"""

def lines(
    source: MeshSource,
    resolution: Optional[int] = None,
    voxel_size: Optional[float] = None,
    origin: Optional[Sequence[float]] = None,
    bounds: Optional[Union[Sequence[float], Sequence[Sequence[float]]]] = None,
    edges: bool = False,
    colors: bool = True,
    color: Optional[Sequence[float]] = None,
    up_axis: Literal["y", "z"] = 'z',
    threads: Optional[int] = None,
    max_memory_mib: Optional[int] = None,
    progress: Optional[Progress] = None,
) -> Grid:
    """3D lines (Jegathese et al.): the polylines (OBJ `l`) of a mesh, and with `edges` (or when there are none) the faces' edges.

    source: a mesh with polylines (OBJ `l`) or faces.

    resolution = None: Voxels along the longest bounding-box axis (none: the default resolution, unless voxel_size is given).
    voxel_size = None: Voxel edge length in world units (instead of resolution).
    origin = None: The world position of the centre of voxel (0, 0, 0) (none: half a voxel inside the low corner of the mesh's box): [0, 0, 0] puts every centre on a multiple of the voxel size, as trimesh does; the mesh's low corner gives Open3D's VoxelGrid centres.
    bounds = None: The world box the grid covers, `[lo, hi]` (a cube) or `[[x0, y0, z0], [x1, y1, z1]]` (none: the mesh's box): resolution counts voxels along its longest side and, unless origin is given, the first centre lies half a voxel inside its low corner (Open3D's within_bounds grid); only voxels whose centres lie in it are kept, and dense arrays span it.
    edges = False: Also the faces' edges.
    colors = True: Carry the mesh's vertex colours into a `Cd` grid.
    color = None: One (r, g, b) colour for every voxel instead.
    up_axis = 'z' (one of y, z): The up axis of a mesh file: y turns a Y-up file to Z-up as Blender's importer does.
    threads = None: Worker threads (none or 0: every core; at most 256).
    max_memory_mib = None: Refuse work estimated above this many MiB before it starts (none or 0: the memory available).
    progress: f(stage, done, total), called a few times a second (raising cancels)"""

def measure(
    source: Union[MeshSource, Grid],
    resolution: Optional[int] = None,
    voxel_size: Optional[float] = None,
    origin: Optional[Sequence[float]] = None,
    bounds: Optional[Union[Sequence[float], Sequence[Sequence[float]]]] = None,
    flood: Literal["blocks", "spans", "xyz"] = 'blocks',
    graystack: int = 1048576,
    density: float = 1.0,
    inside: Literal["auto", "winding", "parity"] = 'auto',
    up_axis: Literal["y", "z"] = 'z',
    threads: Optional[int] = None,
    max_memory_mib: Optional[int] = None,
    progress: Optional[Progress] = None,
) -> Grid:
    """Volume, mass, area, components and genus of a closed mesh (its flooded 26-separating surface) or of a closed voxel surface.

    source: a closed mesh, a .vdb path or a Grid holding a surface; the measures are in the returned solid's report.

    resolution = None: Voxels along the longest bounding-box axis (none: the default resolution, unless voxel_size is given).
    voxel_size = None: Voxel edge length in world units (instead of resolution).
    origin = None: The world position of the centre of voxel (0, 0, 0) (none: half a voxel inside the low corner of the mesh's box): [0, 0, 0] puts every centre on a multiple of the voxel size, as trimesh does; the mesh's low corner gives Open3D's VoxelGrid centres.
    bounds = None: The world box the grid covers, `[lo, hi]` (a cube) or `[[x0, y0, z0], [x1, y1, z1]]` (none: the mesh's box): resolution counts voxels along its longest side and, unless origin is given, the first centre lies half a voxel inside its low corner (Open3D's within_bounds grid); only voxels whose centres lie in it are kept, and dense arrays span it.
    flood = 'blocks' (one of blocks, spans, xyz): The exterior flood of inside parity: blocks (fastest), spans, or xyz (Lai & Cheng's FloodingXYZ).
    graystack = 1048576: GRAYSTACK capacity of the xyz flood (entries; when full, sweeps resume the flood).
    density = 1.0: Mass per unit volume.
    inside = 'auto' (one of auto, winding, parity): How the inside is decided: auto (the winding number where the orientation is consistent, ray parity where not), winding (inside where the generalized winding number is at least 1/2: open, overlapping and hollow meshes too) or parity (ray parity and the exterior flood: closed meshes).
    up_axis = 'z' (one of y, z): The up axis of a mesh file: y turns a Y-up file to Z-up as Blender's importer does.
    threads = None: Worker threads (none or 0: every core; at most 256).
    max_memory_mib = None: Refuse work estimated above this many MiB before it starts (none or 0: the memory available).
    progress: f(stage, done, total), called a few times a second (raising cancels)"""

def combine(
    a: Union[Grid, Path],
    b: Union[Grid, Path],
    op: Literal["union", "intersection", "difference"] = 'union',
    grid: Optional[str] = None,
    resample: bool = False,
    threads: Optional[int] = None,
    max_memory_mib: Optional[int] = None,
    progress: Optional[Progress] = None,
) -> Grid:
    """A Boolean of two grids.

    a, b: Grids, or .vdb paths whose grid `grid` (or voxel set) is read; the result has a's transform.

    op = 'union' (one of union, intersection, difference): union, intersection or difference.
    grid = None: The grid read from files (none: `voxels`, else `density`, else the first bool, mask or float grid).
    resample = False: Resample the second grid onto the first's transform when they differ.
    threads = None: Worker threads (none or 0: every core; at most 256).
    max_memory_mib = None: Refuse work estimated above this many MiB before it starts (none or 0: the memory available).
    progress: f(stage, done, total), called a few times a second (raising cancels)"""

def signed_distance(
    mesh: MeshSource,
    points: npt.ArrayLike,
    inside: Literal["auto", "winding", "parity"] = 'auto',
    threads: Optional[int] = None,
    max_memory_mib: Optional[int] = None,
    progress: Optional[Progress] = None,
) -> npt.NDArray[np.float64]:
    """Exact distances from points to a mesh, and whether each point lies inside it.

    mesh: as for mesh(); points: an (n, 3) array. Returns the exact distance (f64) from each point to the nearest triangle, negative inside by the option inside; computed on every thread, the GIL released.

    inside = 'auto' (one of auto, winding, parity): How the inside is decided: auto (the winding number where the orientation is consistent, ray parity where not), winding (inside where the generalized winding number is at least 1/2: open, overlapping and hollow meshes too) or parity (ray parity and the exterior flood: closed meshes).
    threads = None: Worker threads (none or 0: every core; at most 256).
    max_memory_mib = None: Refuse work estimated above this many MiB before it starts (none or 0: the memory available).
    progress: f(stage, done, total), called a few times a second (raising cancels)"""

def contains(
    mesh: MeshSource,
    points: npt.ArrayLike,
    inside: Literal["auto", "winding", "parity"] = 'auto',
    threads: Optional[int] = None,
    max_memory_mib: Optional[int] = None,
    progress: Optional[Progress] = None,
) -> npt.NDArray[np.bool_]:
    """Exact distances from points to a mesh, and whether each point lies inside it.

    mesh: as for mesh(); points: an (n, 3) array. Returns whether each point lies inside the mesh (bool), by the option inside: its winding number (at least 1/2, exact where near 1/2) or ray parity.

    inside = 'auto' (one of auto, winding, parity): How the inside is decided: auto (the winding number where the orientation is consistent, ray parity where not), winding (inside where the generalized winding number is at least 1/2: open, overlapping and hollow meshes too) or parity (ray parity and the exterior flood: closed meshes).
    threads = None: Worker threads (none or 0: every core; at most 256).
    max_memory_mib = None: Refuse work estimated above this many MiB before it starts (none or 0: the memory available).
    progress: f(stage, done, total), called a few times a second (raising cancels)"""

def csg(
    tree: Union[Path, Dict[str, Any]],
    threads: Optional[int] = None,
    max_memory_mib: Optional[int] = None,
    progress: Optional[Progress] = None,
) -> Grid:
    """A CSG tree (the CLI's `csg --tree` JSON): a path to the JSON file, or the tree as a dict (its file names are then found from the current directory).

    threads = None: Worker threads (none or 0: every core; at most 256).
    max_memory_mib = None: Refuse work estimated above this many MiB before it starts (none or 0: the memory available).
    progress: f(stage, done, total), called a few times a second (raising cancels)"""

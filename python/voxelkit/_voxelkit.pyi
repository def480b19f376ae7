"""Type stubs of the extension module (see the package docstring)."""

from os import PathLike
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str
DEFAULT_RESOLUTION: int

def options() -> str:
    """The schema of every function's options, as JSON (see voxelkit.OPTIONS)."""

Path = Union[str, PathLike]
MeshSource = Union[Path, Tuple[npt.ArrayLike, Union[npt.ArrayLike, Sequence[Sequence[int]]]]]
Progress = Callable[[str, int, int], Any]
#: What comes back as three numbers: a list.
Vec3 = List[float]
#: A brick's index (a dict key): a tuple.
Index = Tuple[int, int, int]

class Grid:
    """A sparse voxel grid with the report of the job that made it."""

    @property
    def ijk(self) -> npt.NDArray[np.int64]:
        """The active voxels, (N, 3): leaves first, then whole tiles."""
    def values(self, name: str) -> npt.NDArray[np.float32]:
        """A channel in the order of `ijk`, named as the file names its grid: `surface` (N,)
        for a level set, `distance` (N,) for unsigned distances, `normal` or `Cd` (N, 3); NaN
        on tiles."""
    def to_dense(
        self, channel: Optional[str] = None
    ) -> Tuple[Union[npt.NDArray[np.bool_], npt.NDArray[np.float32]], List[int]]:
        """A dense array over the voxels' box (the bounds' voxels, given bounds) and the index of its element [0, 0, 0]:
        booleans, or with `channel` (a name of `values`) float32 (a level set's `surface`
        minus its background inside and plus it outside the band, as OpenVDB reads it)."""
    def sample(self, points: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """The value at each world point, trilinear between voxel centres as OpenVDB's box
        sampler reads the file (a level set: minus the background inside, plus it outside)."""
    @property
    def voxel_size(self) -> float: ...
    @property
    def origin(self) -> Vec3:
        """World position of the centre of voxel (0, 0, 0)."""
    def index_to_world(self, ijk: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
    @property
    def bbox(self) -> Optional[Tuple[List[int], List[int]]]:
        """The active voxels' index box, both corners inclusive (None when empty)."""
    @property
    def report(self) -> Dict[str, Any]:
        """The CLI's JSON report."""
    @property
    def extras(self) -> List[str]:
        """Grids beside the main one (`shell`, `interior`, ...)."""
    def extra(self, name: str) -> "Grid": ...
    def write(
        self,
        path: Path,
        grids: Optional[Sequence[str]] = None,
        compression: str = "blosc",
        half: bool = False,
    ) -> None:
        """Writes .vdb, .nvdb (NanoVDB), .binvox or .vox by extension, or the surface as a mesh
        (to_mesh's) to .obj, .ply, .stl or .glb; atomically, never over an input."""
    def to_mesh(self) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]:
        """The surface as a closed, manifold triangle mesh: (vertices (n, 3) world positions,
        triangles (m, 3) vertex rows, counter-clockwise seen from outside). A level set's zero
        set (sdf=True), a formula's F < 0 within its bounds, a solid's or a voxel surface's
        boundary."""
    def render(
        self, path: Path, view: str = "iso", size: Tuple[int, int] = (800, 600)
    ) -> None:
        """Draws the voxels into a PNG (each voxel a cube, lit by normals, coloured by Cd)."""
    def write_vdb(
        self,
        path: Path,
        grids: Optional[Sequence[str]] = None,
        compression: str = "blosc",
        half: bool = False,
    ) -> None: ...
    def same_voxels(self, other: "Grid") -> bool:
        """Whether both hold exactly the same voxel indices."""
    def __len__(self) -> int: ...

# The jobs (mesh, solid, ...) take their options by keyword; their typed signatures are in
# the package's stubs, written from the table of options.
def mesh(source: Any, **options: Any) -> Grid: ...
def solid(source: Any, **options: Any) -> Grid: ...
def subdiv(source: Any, **options: Any) -> Grid: ...
def implicit(formula: str, **options: Any) -> Grid: ...
def lines(source: Any, **options: Any) -> Grid: ...
def measure(source: Any, **options: Any) -> Grid: ...
def combine(a: Any, b: Any, **options: Any) -> Grid: ...
def signed_distance(mesh: Any, points: npt.ArrayLike, **options: Any) -> npt.NDArray[np.float64]: ...
def contains(mesh: Any, points: npt.ArrayLike, **options: Any) -> npt.NDArray[np.bool_]: ...
def csg(tree: Any, **options: Any) -> Grid: ...
def placement(source: Any, **options: Any) -> Tuple[float, List[float]]:
    """The voxel size and origin a mesh job with these placement options would use."""
def read_vdb(path: Path, grid: Optional[str] = None) -> Grid:
    """A .vdb grid, or a brick set's index (.json) merged."""

class BrickPlan:
    @property
    def origin(self) -> Vec3: ...
    @property
    def voxel_size(self) -> float: ...
    @property
    def size(self) -> int: ...
    @property
    def extent(self) -> Tuple[Index, Index]: ...
    @property
    def bricks(self) -> List[Index]: ...
    @property
    def face_count(self) -> int: ...
    def faces_of(
        self, b: Index
    ) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.uint32], npt.NDArray[np.uint32]]: ...
    def mesh_arrays(
        self,
    ) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.uint32], npt.NDArray[np.uint32]]: ...
    @property
    def winding(self) -> bool: ...
    @property
    def inside_reason(self) -> Optional[str]: ...
    @property
    def winding_bricks(self) -> List[Index]: ...
    @property
    def full_brick_bytes(self) -> int: ...
    @property
    def splices(self) -> bool: ...
    def fit_to_threads(self, threads: int) -> int: ...

def brick_plan(
    source: MeshSource,
    solid: bool = False,
    output: Optional[Path] = None,
    brick: Optional[int] = None,
    resolution: Optional[int] = None,
    voxel_size: Optional[float] = None,
    origin: Optional[Sequence[float]] = None,
    up_axis: str = "z",
    separability: int = 26,
    max_memory_mib: Optional[int] = None,
    inside: str = "auto",
) -> BrickPlan:
    """The plan of a distributed run; the keywords are OPTIONS["distributed"]'s."""
def brick_surface_file(
    positions: npt.NDArray[np.float64],
    indices: npt.NDArray[np.uint32],
    starts: npt.NDArray[np.uint32],
    origin: Sequence[float],
    voxel_size: float,
    brick: Index,
    size: int,
    path: Optional[Path],
    separability: int,
    max_memory_mib: Optional[int] = None,
) -> Union[Tuple[int, int], EncodedBrick]: ...
def brick_faces(
    positions: npt.NDArray[np.float64],
    indices: npt.NDArray[np.uint32],
    starts: npt.NDArray[np.uint32],
    origin: Sequence[float],
    voxel_size: float,
    brick: Index,
    size: int,
    max_memory_mib: Optional[int] = None,
) -> List[npt.NDArray[np.uint32]]: ...
def brick_solid_file(
    positions: npt.NDArray[np.float64],
    indices: npt.NDArray[np.uint32],
    starts: npt.NDArray[np.uint32],
    origin: Sequence[float],
    voxel_size: float,
    brick: Index,
    size: int,
    exterior: Sequence[int],
    path: Optional[Path],
    max_memory_mib: Optional[int] = None,
) -> Union[Tuple[int, int], EncodedBrick]: ...
def brick_winding_file(
    positions: npt.NDArray[np.float64],
    indices: npt.NDArray[np.uint32],
    starts: npt.NDArray[np.uint32],
    mesh_positions: npt.NDArray[np.float64],
    mesh_indices: npt.NDArray[np.uint32],
    mesh_starts: npt.NDArray[np.uint32],
    origin: Sequence[float],
    voxel_size: float,
    brick: Index,
    size: int,
    path: Optional[Path],
    max_memory_mib: Optional[int] = None,
) -> Union[Tuple[int, int], EncodedBrick]: ...
def brick_exterior(
    plan: BrickPlan, faces: Dict[Index, Sequence[npt.NDArray[np.uint32]]]
) -> Dict[Index, List[int]]: ...
class EncodedBrick:
    """A brick's file encoded in memory on its worker (the brick functions without a path)."""
    def __init__(self, bytes: bytes) -> None: ...
    @property
    def voxels(self) -> int: ...
    def nodes(self) -> bytes: ...

def brick_finish(
    plan: BrickPlan,
    files: Dict[Index, str],
    full_bricks: Sequence[Index],
    index: Path,
    merged: Optional[Path] = None,
) -> Optional[str]: ...
def write_bricks_into(
    path: Path, bricks: Sequence[Tuple[EncodedBrick, Sequence[Tuple[int, int, int]]]]
) -> None: ...
def brick_splice_in_place(
    plan: BrickPlan,
    nodes: Dict[Index, bytes],
    full_bricks: Sequence[Index],
    output: Path,
    write_bricks: Callable[[Path, Dict[Index, List[Tuple[int, int, int]]]], None],
) -> int: ...
def brick_merge(index: Path, output: Path) -> Tuple[str, int]: ...

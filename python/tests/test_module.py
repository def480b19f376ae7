"""The Python module against the CLI: the same voxels for every kind of job on the shared
data, arrays in memory like files, the Grid's arrays and transform, writing read back by
OpenVDB, errors as Python exceptions, cancellation and the GIL."""

import os
import signal
import threading
import time

import numpy as np
import pytest

import voxelkit
from conftest import voxel_set


def cli_voxels(cli, tmp_path, *args):
    """The voxel set the CLI writes for `voxelkit ARGS -o out.vdb --grids voxels`."""
    out = tmp_path / "cli.vdb"
    cli(*args, "-o", out, "--grids", "voxels")
    return voxel_set(voxelkit.read_vdb(out, grid="voxels").ijk)


@pytest.mark.parametrize("name", ["bunny-closed.obj", "fandisk.obj", "cube_no_bottom.obj"])
@pytest.mark.parametrize("separability", [6, 26])
def test_mesh_equals_cli(data, cli, tmp_path, name, separability):
    path = data / "meshes" / name
    grid = voxelkit.mesh(path, resolution=96, separability=separability)
    expected = cli_voxels(cli, tmp_path, "mesh", path, "-r", 96, "-s", separability)
    assert voxel_set(grid.ijk) == expected
    assert grid.report["voxels"] == len(expected)


@pytest.mark.parametrize("name", ["bunny-closed.obj", "torus.obj", "spot_triangulated.obj"])
def test_solid_equals_cli(data, cli, tmp_path, name):
    path = data / "meshes" / name
    grid = voxelkit.solid(path, resolution=96)
    assert voxel_set(grid.ijk) == cli_voxels(cli, tmp_path, "solid", path, "-r", 96)
    report = grid.report
    assert report["volume_inside"] > 0 and sorted(grid.extras) == ["interior", "shell"]
    # The solid holds its shell, and inside and shell make the whole.
    shell, interior = voxel_set(grid.extra("shell").ijk), voxel_set(grid.extra("interior").ijk)
    assert shell | interior == voxel_set(grid.ijk) and not shell & interior


def test_projective_and_lines_equal_cli(data, cli, tmp_path):
    path = data / "meshes" / "cow.obj"
    grid = voxelkit.mesh(path, resolution=80, method="projective")
    assert voxel_set(grid.ijk) == cli_voxels(cli, tmp_path, "mesh", path, "-r", 80, "--method", "projective")
    lines = voxelkit.lines(path, resolution=80, edges=True)
    assert voxel_set(lines.ijk) == cli_voxels(cli, tmp_path, "lines", path, "-r", 80, "--edges")


@pytest.mark.parametrize("name", ["spot_control_mesh.obj", "catmark_torus.obj"])
def test_subdiv_equals_cli(data, cli, tmp_path, name):
    path = data / "subd" / name
    grid = voxelkit.subdiv(path, resolution=64, adjacency=6)
    assert voxel_set(grid.ijk) == cli_voxels(cli, tmp_path, "subdiv", path, "-r", 64, "-a", 6)


def test_subdiv_solid_equals_cli(data, cli, tmp_path):
    """A Catmull-Clark solid (seeds, FloodingXYZ) is the CLI's, and its voxel volume brackets
    the exact limit volume."""
    path = data / "subd" / "catmark_torus.obj"
    grid = voxelkit.subdiv(path, resolution=64, solid=True)
    expected = cli_voxels(cli, tmp_path, "subdiv", path, "-r", 64, "--solid")
    assert voxel_set(grid.ijk) == expected
    r = grid.report
    assert r["volume_inside"] <= r["limit_volume"] <= r["volume_with_surface"]
    assert set(grid.extras) >= {"shell", "interior"}
    # Depth layers on the certified tessellation: the CLI's voxels, and the flood's here.
    layered = voxelkit.subdiv(path, resolution=64, solid=True, depth_layers=True)
    assert voxel_set(layered.ijk) == expected
    assert "depth layers" in layered.report["inside_rule"]


def test_implicit_equals_cli(cli, tmp_path):
    formula = "sin(3*theta)*sin(4*phi) - r"
    grid = voxelkit.implicit(formula, coords="spherical", bounds=(-1, 1), resolution=64)
    expected = cli_voxels(
        cli, tmp_path, "implicit", formula, "--coords", "spherical", "--bounds", "-1,1", "-r", 64
    )
    assert voxel_set(grid.ijk) == expected and len(expected) > 1000
    squared = voxelkit.implicit(
        formula, coords="spherical", bounds=(-1, 1), resolution=64, squared=True,
        theta_range="symmetric",
    )
    expected = cli_voxels(
        cli, tmp_path, "implicit", formula, "--coords", "spherical", "--bounds", "-1,1", "-r", 64,
        "--squared", "--theta-range", "symmetric",
    )
    assert voxel_set(squared.ijk) == expected and len(expected) > 1.8 * len(grid.ijk)


def test_arrays_equal_the_file(data):
    """A mesh in numpy arrays voxelizes like the same mesh read from its file."""
    path = data / "meshes" / "torus.obj"
    vertices, faces = [], []
    for line in open(path):
        parts = line.split()
        if parts and parts[0] == "v":
            vertices.append([float(p) for p in parts[1:4]])
        elif parts and parts[0] == "f":
            faces.append([int(p.split("/")[0]) - 1 for p in parts[1:]])
    from_file = voxelkit.mesh(path, resolution=100)
    from_arrays = voxelkit.mesh((np.array(vertices), faces), resolution=100)
    assert voxel_set(from_file.ijk) == voxel_set(from_arrays.ijk)
    assert from_file.voxel_size == pytest.approx(from_arrays.voxel_size)
    # Float32 vertices and int32 faces are accepted.
    if all(len(f) == 3 for f in faces):
        small = voxelkit.mesh((np.array(vertices, np.float32), np.array(faces, np.int32)), resolution=100)
        assert len(small) > 0


def tetrahedron():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    return v, f


def test_grid_arrays_and_transform():
    grid = voxelkit.mesh(tetrahedron(), resolution=40, normals=True)
    ijk = grid.ijk
    assert ijk.dtype == np.int64 and ijk.shape == (len(grid), 3)
    normals = grid.values("normal")
    assert normals.shape == (len(grid), 3)
    assert np.allclose(np.linalg.norm(normals, axis=1), 1, atol=1e-4)
    distances = grid.values("distance")
    # The separating voxelizer keeps each voxel's distance to the surface in voxels, within
    # the 26-separating threshold sqrt(3)/2.
    assert distances.shape == (len(grid),) and (np.abs(distances) <= 0.8661).all()
    with pytest.raises(KeyError):
        grid.values("Cd")
    dense, offset = grid.to_dense()
    assert dense.sum() == len(grid)
    assert dense[tuple((ijk - offset).T)].all()
    lo, hi = grid.bbox
    assert list(lo) == list(ijk.min(axis=0)) and list(hi) == list(ijk.max(axis=0))
    # Voxel centres lie within a voxel's half diagonal of the tetrahedron's box.
    world = grid.index_to_world(ijk)
    h = grid.voxel_size
    assert world.min() >= -h and world.max() <= 1 + h
    assert np.allclose(grid.index_to_world([[0, 0, 0]])[0], grid.origin)
    assert grid.report["method"].startswith("huang")


def test_write_is_read_by_openvdb(tmp_path, pyopenvdb):
    grid = voxelkit.solid(tetrahedron(), resolution=48)
    out = tmp_path / "tet.vdb"
    grid.write(out, grids=["density", "voxels"])
    assert grid.report["output"] == str(out)
    density = pyopenvdb.read(str(out), "density")
    assert density.activeVoxelCount() == len(grid)
    lo, hi = density.evalActiveVoxelBoundingBox()
    assert (tuple(lo), tuple(hi)) == tuple(map(tuple, grid.bbox))
    back = voxelkit.read_vdb(out)
    assert voxel_set(back.ijk) == voxel_set(grid.ijk)
    # binvox and vox by extension, like the CLI.
    grid.write(tmp_path / "tet.binvox")
    assert (tmp_path / "tet.binvox").stat().st_size > 0


def test_write_nvdb_is_read_by_nanovdb(tmp_path):
    import shutil
    import subprocess

    from conftest import missing

    tools = ["nanovdb_validate", "nanovdb_print"]
    if not all(shutil.which(t) for t in tools):
        missing("NanoVDB's tools (libnanovdb-tools)", "reading the .nvdb back")
    grid = voxelkit.solid(tetrahedron(), resolution=48)
    out = tmp_path / "tet.nvdb"
    grid.write(out)
    assert grid.report["output"] == str(out)
    validated = subprocess.run(["nanovdb_validate", "-v", str(out)], capture_output=True, text=True)
    assert validated.returncode == 0 and 'Grid named "density": passed' in validated.stdout
    printed = subprocess.run(["nanovdb_print", str(out)], capture_output=True, text=True).stdout
    rows = {line.split()[1]: line.split() for line in printed.splitlines() if line[:1].isdigit()}
    assert sorted(rows) == ["density", "interior", "shell"]
    assert str(len(grid)) in rows["density"]
    with pytest.raises(ValueError, match="half"):
        grid.write(tmp_path / "half.nvdb", half=True)
    assert not (tmp_path / "half.nvdb").exists()


def ball(radius):
    return {"sphere": {"radius": radius, "center": [0, 0, 0]}}


def test_csg_from_a_dict_and_combine(tmp_path):
    tree = {
        "resolution": 64,
        "tree": {"difference": [ball(1.0), ball(0.5)]},
    }
    shell = voxelkit.csg(tree)
    full = voxelkit.csg({"resolution": 64, "tree": ball(1.0)})
    assert 0 < len(shell) < len(full)
    a = voxelkit.mesh(tetrahedron(), resolution=32)
    both = voxelkit.combine(a, a, op="intersection")
    assert voxel_set(both.ijk) == voxel_set(a.ijk)
    measured = voxelkit.measure(tetrahedron(), resolution=64)
    r = measured.report
    assert r["volume_inside"] < 1 / 6 < r["volume_with_surface"]


def test_an_openvdb_level_set_operand_means_its_inside(tmp_path, pyopenvdb):
    """A level set OpenVDB wrote, subtracted from a solid, removes its whole inside: every
    voxel OpenVDB holds negative, its interior tiles included."""
    sphere = pyopenvdb.createLevelSetSphere(radius=0.5, center=(0, 0, 0), voxelSize=0.02, halfWidth=3.0)
    path = tmp_path / "sphere.vdb"
    pyopenvdb.write(str(path), grids=[sphere])
    negative = sum(
        (it.max[0] - it.min[0] + 1) * (it.max[1] - it.min[1] + 1) * (it.max[2] - it.min[2] + 1)
        for it in sphere.citerAllValues()
        if it.value < 0
    )
    h = sphere.transform.voxelSize()[0]
    box = voxelkit.csg({"voxel_size": h, "tree": {"box": {"min": [-50.5 * h] * 3, "max": [50.5 * h] * 3}}})
    cut = voxelkit.combine(box, path, op="difference", resample=True)
    assert len(box) - len(cut) == negative


def test_open_meshes_are_filled_by_their_winding_number(data):
    scan = voxelkit.solid(data / "meshes" / "stanford-bunny.obj", resolution=64)
    assert "winding" in scan.report["inside_rule"]
    with pytest.raises(ValueError, match="open"):
        voxelkit.solid(data / "meshes" / "stanford-bunny.obj", resolution=64, inside="parity")


def test_errors_are_python_exceptions(tmp_path):
    v, f = tetrahedron()
    with pytest.raises(FileNotFoundError, match="nothing.obj"):
        voxelkit.mesh(tmp_path / "nothing.obj")
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nf 1 2 7\n")
    with pytest.raises(ValueError, match=r"bad.obj:3"):
        voxelkit.mesh(bad)
    with pytest.raises(ValueError, match="face 1"):
        voxelkit.mesh((v, [[0, 1, 2], [0, 1, -1]]))
    with pytest.raises(ValueError, match="face 0"):
        voxelkit.mesh((v, [[0, 1, 9]]))
    with pytest.raises(ValueError, match="NaN|finite"):
        voxelkit.mesh((np.array([[0, 0, 0], [1, 0, 0], [np.nan, 1, 0]]), [[0, 1, 2]]))
    with pytest.raises(MemoryError, match="resolution too large"):
        voxelkit.solid((v, f), resolution=200000, max_memory_mib=64)
    with pytest.raises(ValueError, match="separability"):
        voxelkit.mesh((v, f), separability=7)
    with pytest.raises(ValueError, match="open"):
        voxelkit.solid((v, f[:3]), inside="parity")
    with pytest.raises(ValueError, match="not both"):
        voxelkit.mesh((v, f), resolution=8, voxel_size=0.1)
    source = tmp_path / "in.obj"
    source.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    grid = voxelkit.mesh(source, resolution=8)
    with pytest.raises(OSError, match="replace the input"):
        grid.write(source)
    with pytest.raises(OSError):
        grid.write(tmp_path / "missing-folder" / "out.vdb")
    assert not (tmp_path / "missing-folder").exists()


def test_progress_reports_and_its_exception_cancels():
    seen = []
    voxelkit.solid(tetrahedron(), resolution=64, progress=lambda *a: seen.append(a))
    stage, done, total = seen[-1]
    assert stage and done == total

    class Stop(Exception):
        pass

    def stop(stage, done, total):
        raise Stop()

    start = time.perf_counter()
    with pytest.raises(Stop):
        voxelkit.implicit("sin(9*x)*sin(9*y)*sin(9*z) - 0.1*x", resolution=2048, progress=stop)
    assert time.perf_counter() - start < 10


def test_ctrl_c_cancels_a_long_call():
    # A process started in the background inherits SIGINT ignored: give it Python's handler.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    start = time.perf_counter()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            # About 20 s when not cancelled.
            voxelkit.implicit("sin(9*x)*sin(9*y)*sin(9*z) - 0.1*x", resolution=2048)
        assert time.perf_counter() - start < 10
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, previous)


def ticks_during(call):
    """How long `call` took and how often another Python thread ticked meanwhile."""
    ticks = []
    done = threading.Event()

    def tick():
        while not done.is_set():
            ticks.append(1)
            time.sleep(0.001)

    t = threading.Thread(target=tick)
    t.start()
    start = time.perf_counter()
    try:
        call()
    finally:
        elapsed = time.perf_counter() - start
        done.set()
        t.join()
    return elapsed, len(ticks)


def test_the_gil_is_released():
    # Work long enough to count ticks over, on a fast machine too: finer grids until it is.
    for resolution in (900, 1200, 1500):
        elapsed, ticks = ticks_during(lambda: voxelkit.solid(tetrahedron(), resolution=resolution, flood="spans"))
        if elapsed > 0.2:
            break
    # The other thread ran all along: at least a tick per 10 ms of the call.
    assert elapsed > 0.2 and ticks > 100 * elapsed, (resolution, elapsed, ticks)


def test_depth_layers_take_the_papers_unclassified_rule(data):
    path = data / "meshes" / "armadillo.obj"
    today = voxelkit.solid(path, resolution=96, method="depth-layers")
    paper = voxelkit.solid(path, resolution=96, method="depth-layers", unclassified="paper")
    assert paper.report["unclassified_voxels"] > today.report["unclassified_voxels"]
    assert "unclassified" in paper.extras
    with pytest.raises(ValueError, match="no-direction or paper"):
        voxelkit.solid(path, resolution=16, method="depth-layers", unclassified="never")
    own = voxelkit.solid(path, resolution=48, method="depth-layers", directions=[(0, 0, 1), (1, 1, 0), (2, 1, -1)])
    assert own.report["directions"][2]["direction"] == [2, 1, -1]
    with pytest.raises(ValueError, match="component of 1 or -1"):
        voxelkit.solid(path, resolution=16, method="depth-layers", directions=[(2, 3, 5)])


def test_a_grid_draws_a_png(data, tmp_path):
    """Grid.render writes a PNG of the asked size, as `voxelkit render` does; bad views and
    names are refused."""
    import struct

    grid = voxelkit.mesh(data / "meshes" / "torus.obj", resolution=64, normals=True)
    picture = tmp_path / "torus.png"
    grid.render(picture, view="z", size=(320, 200))
    head = picture.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    assert struct.unpack(">II", head[16:24]) == (320, 200)
    with pytest.raises(ValueError, match="iso, x, y or z"):
        grid.render(tmp_path / "a.png", view="up")
    with pytest.raises(ValueError, match=".png"):
        grid.render(tmp_path / "a.jpg")
    assert not (tmp_path / "a.png").exists()


def test_vertex_attributes_as_arrays(data, tmp_path):
    """A mesh's texture coordinates and normals are arrays in the order of ``ijk``: spot's
    ``uv`` interpolated by the projective method, bunny-closed's ``vertex_normal`` taken from
    the nearest point of the separating surface, close to the exact nearest-feature normal."""
    spot = voxelkit.mesh(data / "meshes" / "spot_triangulated.obj", resolution=64, method="projective")
    uv = spot.values("uv")
    assert uv.shape == (len(spot), 3) and not np.isnan(uv).any()
    assert uv[:, :2].min() > -0.06 and uv[:, :2].max() < 1.01 and (uv[:, 2] == 0).all()
    bunny = voxelkit.mesh(
        data / "meshes" / "bunny-closed.obj", resolution=64, normals=True, attributes=["vertex_normal"]
    )
    vertex = bunny.values("vertex_normal")
    assert np.allclose(np.linalg.norm(vertex, axis=1), 1, atol=1e-5)
    agree = (np.sum(vertex * bunny.values("normal"), axis=1) > 0.8).mean()
    assert agree > 0.95
    with pytest.raises(KeyError):
        bunny.values("uv")
    with pytest.raises(ValueError, match="no attribute `uv`"):
        voxelkit.mesh(data / "meshes" / "bunny-closed.obj", resolution=32, attributes=["uv"])


def test_names_given_as_one_string(data, tmp_path):
    """Options that take names take one comma-separated string too, as the command line does."""
    bunny = voxelkit.mesh(data / "meshes" / "bunny-closed.obj", resolution=32, attributes="all")
    assert bunny.values("vertex_normal").shape == (len(bunny), 3)
    out = tmp_path / "b.vdb"
    bunny.write(out, grids="density,vertex_normal")
    assert voxelkit.read_vdb(out, grid="vertex_normal") is not None

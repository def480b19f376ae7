"""Dask scale-out: a brick run gives exactly the single-process voxels, for surfaces and
solids, on every closed mesh of the shared data and, by the winding number, on the open ones; it succeeds where the single run does not fit
the memory limit; kept brick sets read back as one grid."""

import os
import signal
import struct
import subprocess
import sys
import time

import pytest

import voxelkit
import voxelkit.distributed as vd
from conftest import closed_meshes, imported, voxel_set


@pytest.fixture(scope="module")
def dask():
    return imported("dask.distributed", 'Dask (pip install ".[distributed]")', "scale-out")


@pytest.fixture(scope="module")
def client(dask):
    from dask.distributed import Client, LocalCluster

    cluster = LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0",
        env={"RAYON_NUM_THREADS": "1"},
    )
    client = Client(cluster)
    yield client
    client.close()
    cluster.close()


@pytest.fixture(scope="module")
def meshes(data):
    found = closed_meshes(data)
    assert len(found) >= 10, found
    return found


def tree_bytes(path):
    """A .vdb's first grid from its tree on (topology and leaf buffers), without its metadata."""
    b = path.read_bytes()

    def string(p):
        n = struct.unpack_from("<I", b, p)[0]
        return p + 4 + n

    p = 8 + 4 + 8 + 1 + 36 + 4 + 4  # magic, versions, offsets flag, UUID, no metadata, count
    for _ in range(3):  # grid name, tree type, instance parent
        p = string(p)
    grid, _, end = struct.unpack_from("<qqq", b, p)
    (entries,) = struct.unpack_from("<I", b, grid + 4)
    p = grid + 8
    for _ in range(3 * entries):  # name, type, value
        p = string(p)
    return b[string(p) + 6 * 24:end]  # after the transform's map name and its six vectors


@pytest.mark.parametrize("solid", [False, True], ids=["surface", "solid"])
def test_bricks_equal_the_single_run(meshes, client, tmp_path, pyopenvdb, solid):
    for path in meshes:
        out = tmp_path / f"{path.stem}-{solid}.vdb"
        result = vd.run(path, out, solid=solid, resolution=512, brick=128, client=client)
        single = voxelkit.solid(path, resolution=512) if solid else voxelkit.mesh(path, resolution=512)
        assert result["voxels"] == len(single) and result["bricks"] > 8
        assert result["output"] == str(out) and voxelkit.read_vdb(out).same_voxels(single), path.name
        # Spliced from the bricks' nodes, the tree is the single run's byte for byte.
        assert result["merged_by"] == "splicing"
        single.write(tmp_path / "single.vdb")
        assert tree_bytes(out) == tree_bytes(tmp_path / "single.vdb"), path.name
        assert pyopenvdb.read(str(out), "density").activeVoxelCount() == len(single)
    assert not list(tmp_path.glob("*.bricks")), "the bricks of a merged run go"


def test_bricks_fit_where_the_single_run_does_not(data, client, tmp_path):
    path = data / "meshes" / "bunny-closed.obj"
    estimate = voxelkit.solid(path, resolution=64, inside="parity").report["estimated_mib"]
    single = voxelkit.solid(path, resolution=768, inside="parity")
    # Half-way between a small run (the process itself, mostly) and the single run.
    limit = int((single.report["estimated_mib"] + estimate) / 2)
    assert single.report["estimated_mib"] > limit > estimate
    with pytest.raises(MemoryError):
        voxelkit.solid(path, resolution=768, max_memory_mib=limit)
    # The exterior flood across bricks (the winding number's bricks are all tasks).
    result = vd.solid(path, tmp_path / "b.vdb", resolution=768, brick=128, max_memory_mib=limit, client=client,
                      inside="parity")
    assert voxelkit.read_vdb(tmp_path / "b.vdb").same_voxels(single)
    assert result["full_bricks"] > 0, "bricks wholly inside are written as tiles"
    # A brick that cannot fit is refused with the reason.
    with pytest.raises(MemoryError, match="brick"):
        vd.solid(path, tmp_path / "c.vdb", resolution=768, brick=1024, max_memory_mib=limit, client=client,
                 inside="parity")


@pytest.mark.parametrize("name", ["stanford-bunny", "teapot", "cube_no_bottom", "ogre"])
def test_bricks_of_open_meshes_give_the_single_runs_winding_solid(data, client, tmp_path, name):
    path = data / "meshes" / f"{name}.obj"
    result = vd.solid(path, tmp_path / f"{name}.vdb", resolution=160, brick=32, client=client)
    single = voxelkit.solid(path, resolution=160)
    assert result["inside_rule"].startswith("winding") and "open" in result["inside_rule"]
    assert result["bricks"] > 8
    # Bricks of 32 voxels share OpenVDB's 128^3 nodes: merged through one grid.
    assert result["merged_by"] == "reading"
    assert voxelkit.read_vdb(tmp_path / f"{name}.vdb").same_voxels(single), name


def test_kept_bricks_read_as_one_grid(data, client, cli, tmp_path):
    path = data / "meshes" / "torus.obj"
    # 0 MiB is the memory available, as in every front end.
    result = vd.mesh(path, tmp_path / "t.vdb", resolution=300, brick=64, keep_bricks=True, client=client,
                     max_memory_mib=0)
    index = tmp_path / "t.bricks" / "index.json"
    assert result["output"] == str(index) and result["merged_by"] is None
    assert not (tmp_path / "t.vdb").exists()
    merged = voxelkit.read_vdb(index)
    assert voxel_set(merged.ijk) == voxel_set(voxelkit.mesh(path, resolution=300).ijk)
    info = cli("info", index).stdout
    assert "bricks" in info and str(result["voxels"]) in info


def test_a_kept_brick_set_merges_later_and_refuses_foreign_bricks(data, client, tmp_path):
    path = data / "meshes" / "torus.obj"
    vd.mesh(path, tmp_path / "t.vdb", resolution=400, brick=128, keep_bricks=True, client=client)
    index = tmp_path / "t.bricks" / "index.json"
    single = voxelkit.mesh(path, resolution=400)
    single.write(tmp_path / "single.vdb")
    out = tmp_path / "merged.vdb"
    done = subprocess.run(
        [sys.executable, "-m", "voxelkit.distributed", "merge", str(index), "-o", str(out)],
        capture_output=True, text=True, timeout=300,
    )
    assert done.returncode == 0, done.stderr
    assert f"{len(single)} voxels merged by splicing" in done.stdout
    assert tree_bytes(out) == tree_bytes(tmp_path / "single.vdb")
    out.unlink()
    bricks = sorted((tmp_path / "t.bricks").glob("brick_*.vdb"))
    # Every refusal names the file and leaves no output behind.
    with pytest.raises(OSError, match="brick_"):
        vd.merge(index, bricks[0])
    victim = bricks[len(bricks) // 2]
    whole = victim.read_bytes()
    victim.write_bytes(whole[: len(whole) // 2])
    with pytest.raises(OSError, match=victim.name):
        vd.merge(index, out)
    # A voxel set on another grid.
    voxelkit.mesh(path, resolution=40).write(victim)
    with pytest.raises(ValueError, match=victim.name):
        vd.merge(index, out)
    # The same voxels written with half-precision values: not the layout the merge copies.
    victim.write_bytes(whole)
    voxelkit.read_vdb(victim).write(tmp_path / "half.vdb", half=True)
    os.replace(tmp_path / "half.vdb", victim)
    with pytest.raises(OSError, match=victim.name):
        vd.merge(index, out)
    assert not out.exists() and not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


def test_a_failing_brick_in_a_shared_task_is_named():
    def fails():
        return 1 / 0

    with pytest.raises(RuntimeError, match=r"brick \(1, 2, 3\): ZeroDivisionError"):
        vd._in_turn([((0, 0, 0), int, ()), ((1, 2, 3), fails, ())])
    assert vd._in_turn([((0, 0, 0), int, ("7",))]) == [((0, 0, 0), 7)]


def test_the_command_line_starts_its_own_cluster(data, dask, tmp_path):
    path = data / "meshes" / "cow.obj"
    out = tmp_path / "cow.vdb"
    done = subprocess.run(
        [sys.executable, "-m", "voxelkit.distributed", "mesh", str(path), "-r", "256",
         "--brick", "64", "--workers", "2", "-o", str(out)],
        capture_output=True, text=True, timeout=300,
    )
    assert done.returncode == 0, done.stderr
    assert "voxels from" in done.stdout and "worker peak memory" in done.stdout
    assert voxel_set(voxelkit.read_vdb(out).ijk) == voxel_set(voxelkit.mesh(path, resolution=256).ijk)
    bad = subprocess.run(
        [sys.executable, "-m", "voxelkit.distributed", "mesh", str(tmp_path / "none.obj"), "-o", str(out)],
        capture_output=True, text=True, timeout=300,
    )
    assert bad.returncode == 1 and "none.obj" in bad.stderr


def test_a_voxel_size_openvdb_cannot_store_is_refused_before_any_work(data, tmp_path):
    out = tmp_path / "tiny.vdb"
    with pytest.raises(OSError, match="cannot store voxel size"):
        vd.mesh(data / "meshes" / "igea.obj", out, resolution=8192, brick=1024)
    assert not list(tmp_path.iterdir()), "nothing is left behind"


def _descendants(pid):
    """The process ids below `pid`, from /proc."""
    children = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as f:
                    parent = int(f.read().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
            children.setdefault(parent, []).append(int(entry))
    found, todo = [], [pid]
    while todo:
        for c in children.get(todo.pop(), []):
            found.append(c)
            todo.append(c)
    return found


def _start(path, out, *extra):
    return subprocess.Popen(
        [sys.executable, "-m", "voxelkit.distributed", "mesh", str(path), "-r", "1024",
         "--brick", "64", "--workers", "2", "-o", str(out), *extra],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )


def _wait_for_bricks(run, folder, timeout=120):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and run.poll() is None:
        if folder.is_dir() and any(folder.glob("brick_*.vdb")):
            return True
        time.sleep(0.05)
    return False


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_a_signal_during_a_run_leaves_no_partial_folder_and_a_rerun_works(data, dask, tmp_path, signum):
    path = data / "meshes" / "igea.obj"
    out = tmp_path / "igea.vdb"
    folder = tmp_path / "igea.bricks"
    run = _start(path, out)
    assert _wait_for_bricks(run, folder), "no brick was written"
    run.send_signal(signum)
    _, err = run.communicate(timeout=120)
    assert run.returncode != 0, "the run completed despite the signal"
    assert "stopped by signal" in err and "Traceback" not in err, err
    assert not folder.exists() and not out.exists()
    again = subprocess.run(
        [sys.executable, "-m", "voxelkit.distributed", "mesh", str(path), "-r", "128",
         "--brick", "64", "--workers", "1", "-o", str(out)],
        capture_output=True, text=True, timeout=300,
    )
    assert again.returncode == 0, again.stderr


def test_a_killed_worker_is_retried_and_the_result_is_whole(data, dask, tmp_path):
    path = data / "meshes" / "igea.obj"
    out = tmp_path / "igea.vdb"
    run = _start(path, out)
    assert _wait_for_bricks(run, tmp_path / "igea.bricks"), "no brick was written"
    workers = [p for p in _descendants(run.pid) if b"spawn_main" in open(f"/proc/{p}/cmdline", "rb").read()]
    assert workers, "no worker process found"
    os.kill(workers[-1], signal.SIGKILL)
    _, err = run.communicate(timeout=600)
    assert run.returncode == 0, err
    assert "Traceback" not in err, err
    assert voxel_set(voxelkit.read_vdb(out).ijk) == voxel_set(voxelkit.mesh(path, resolution=1024).ijk)


@pytest.mark.parametrize("when", ["bricks", "merge"])
def test_a_worker_killed_holding_bricks_in_memory_is_made_good(data, dask, tmp_path, monkeypatch, when):
    """Bricks on OpenVDB's nodes stay in their workers' memory until they are written into the
    merged file: a worker killed (SIGKILL) while the bricks run, or after they all ran and
    before the merge, takes bricks with it, which Dask runs again; the file is the single
    run's and nothing is left behind."""
    from dask.distributed import Client, LocalCluster

    path = data / "meshes" / "igea.obj"
    out = tmp_path / "igea.vdb"
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0",
                           env={"RAYON_NUM_THREADS": "1"})
    client = Client(cluster)
    killed = []

    def kill_a_worker():
        if not killed:
            pid = next(iter(client.run(os.getpid).values()))
            os.kill(pid, signal.SIGKILL)
            killed.append(pid)

    if when == "bricks":
        results = []
        original = vd._result

        def result(future, group, stage):
            results.append(group)
            if len(results) == 3:
                kill_a_worker()
            return original(future, group, stage)

        monkeypatch.setattr(vd, "_result", result)
    else:
        original = vd._merge_in_place

        def merge(*args):
            kill_a_worker()
            return original(*args)

        monkeypatch.setattr(vd, "_merge_in_place", merge)
    try:
        result = vd.run(path, out, resolution=1024, brick=128, client=client)
    finally:
        client.close()
        cluster.close()
    assert killed, "no worker was killed"
    assert result["merged_by"] == "splicing" and result["bricks"] > 50
    single = voxelkit.mesh(path, resolution=1024)
    single.write(tmp_path / "single.vdb")
    assert tree_bytes(out) == tree_bytes(tmp_path / "single.vdb")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["igea.vdb", "single.vdb"]


def test_a_scheduler_that_never_answers_is_an_error_within_seconds(data, dask, tmp_path):
    import socket

    silent = socket.socket()
    silent.bind(("127.0.0.1", 0))
    silent.listen(4)
    port = silent.getsockname()[1]
    started = time.monotonic()
    try:
        with pytest.raises(OSError, match="did not answer"):
            vd.mesh(data / "meshes" / "cow.obj", tmp_path / "cow.vdb", resolution=64, brick=64,
                    scheduler=f"tcp://127.0.0.1:{port}")
    finally:
        silent.close()
    assert time.monotonic() - started < 60
    assert not list(tmp_path.iterdir()), "nothing is left behind"


def _free_port():
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_a_cluster_of_separate_scheduler_and_worker_processes(data, dask, tmp_path):
    """As a cluster is run: `dask scheduler` and two `dask worker` processes started on their
    own, on loopback, the output folder shared; the command line sends them an open mesh's
    solid, which comes back as the single run's."""
    dask_cli = os.path.join(os.path.dirname(sys.executable), "dask")
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    env = dict(os.environ, RAYON_NUM_THREADS="1")
    quiet = dict(stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env, cwd=tmp_path)
    started = [subprocess.Popen([dask_cli, "scheduler", "--host", "127.0.0.1", "--port", str(port),
                                 "--no-dashboard"], **quiet)]
    try:
        started += [
            subprocess.Popen([dask_cli, "worker", address, "--nthreads", "1", "--no-dashboard",
                              "--local-directory", str(tmp_path / f"worker-{n}")], **quiet)
            for n in range(2)
        ]
        path = data / "meshes" / "stanford-bunny.obj"
        out = tmp_path / "shared" / "bunny.vdb"
        out.parent.mkdir()
        done = subprocess.run(
            [sys.executable, "-m", "voxelkit.distributed", "solid", str(path), "-r", "200",
             "--brick", "64", "--scheduler", address, "-o", str(out)],
            capture_output=True, text=True, timeout=300,
        )
        assert done.returncode == 0, done.stderr
        assert "inside: winding" in done.stdout, done.stdout
        assert voxelkit.read_vdb(out).same_voxels(voxelkit.solid(path, resolution=200))
        assert [p.name for p in out.parent.iterdir()] == ["bunny.vdb"], "the bricks went after the merge"
    finally:
        for p in reversed(started):
            p.terminate()
        for p in started:
            p.wait(timeout=60)


def test_two_runs_to_one_output_are_refused_while_the_first_runs(data, dask, tmp_path):
    path = data / "meshes" / "igea.obj"
    out = tmp_path / "igea.vdb"
    first = _start(path, out)
    assert _wait_for_bricks(first, tmp_path / "igea.bricks"), "no brick was written"
    with pytest.raises(OSError, match="already exists"):
        vd.mesh(path, out, resolution=64, brick=64, workers=1)
    _, err = first.communicate(timeout=600)
    assert first.returncode == 0, err
    assert voxel_set(voxelkit.read_vdb(out).ijk) == voxel_set(voxelkit.mesh(path, resolution=1024).ijk)


def _cube_frames(folder, count):
    """An animation: a box that moves and grows, one OBJ per frame (f_0001.obj, ...)."""
    corners = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
    faces = [(1, 3, 4, 2), (5, 6, 8, 7), (1, 2, 6, 5), (3, 7, 8, 4), (1, 5, 7, 3), (2, 4, 8, 6)]
    for f in range(1, count + 1):
        scale, shift = 1.0 + 0.2 * f, 0.7 * f
        lines = [f"v {shift + scale * x} {0.5 * shift + 0.8 * scale * y} {0.6 * scale * z}"
                 for x, y, z in corners]
        lines += ["f " + " ".join(map(str, q)) for q in faces]
        (folder / f"f_{f:04d}.obj").write_text("\n".join(lines) + "\n")


@pytest.mark.parametrize("solid", [False, True], ids=["surface", "solid"])
def test_frames_on_the_cluster_equal_the_command_lines_frames(client, cli, tmp_path, solid):
    """A frame farm: each frame whole on a worker, all on the grid the command line's --frames
    fits to the union of their boxes: the same voxels, frame by frame."""
    _cube_frames(tmp_path, 4)
    command = "solid" if solid else "mesh"
    result = vd.frames(tmp_path / "f_####.obj", tmp_path / "farm" / "v_####.vdb", "1-4", solid=solid,
                       resolution=48, client=client)
    cli(command, tmp_path / "f_####.obj", "--frames", "1-4", "-r", "48", "-o", tmp_path / "cli" / "v_####.vdb")
    assert result["frames"] == 4 and len(result["outputs"]) == 4
    for f in range(1, 5):
        farm = voxelkit.read_vdb(tmp_path / "farm" / f"v_{f:04d}.vdb")
        single = voxelkit.read_vdb(tmp_path / "cli" / f"v_{f:04d}.vdb")
        assert farm.same_voxels(single), f
        assert len(farm) == result["voxels"][f - 1] > 0
    assert result["voxels"][3] > result["voxels"][0], "the box grows"
    with pytest.raises(ValueError, match="needs `#` for the frame number"):
        vd.frames(tmp_path / "f_0001.obj", tmp_path / "x_####.vdb", "1-2", client=client)
    with pytest.raises(ValueError, match="the last frame must not come before the first"):
        vd.frames(tmp_path / "f_####.obj", tmp_path / "x_####.vdb", "4-1", client=client)


def test_the_command_line_farms_frames(dask, tmp_path):
    _cube_frames(tmp_path, 3)
    done = subprocess.run(
        [sys.executable, "-m", "voxelkit.distributed", "mesh", str(tmp_path / "f_####.obj"), "--frames", "1-3:2",
         "-r", "32", "--workers", "2", "-o", str(tmp_path / "out" / "f_####.vdb")],
        capture_output=True, text=True, timeout=300,
    )
    assert done.returncode == 0, done.stderr
    assert "2 frames" in done.stdout and "worker peak memory" in done.stdout
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["f_0001.vdb", "f_0003.vdb"]

"""Scale-out on Dask: one voxelization spread over worker processes or machines in bricks.

    python -m voxelkit.distributed mesh IN -r 16384 --workers 4 -o OUT.vdb
    python -m voxelkit.distributed solid IN -r 4096 --brick 512 --scheduler tcp://host:8786 -o OUT.vdb
    python -m voxelkit.distributed mesh 'f_####.obj' --frames 1-240 -r 512 -o 'out/f_####.vdb'
    python -m voxelkit.distributed merge OUT.bricks/index.json -o OUT.vdb

The grid is placed as a single run would place it and cut into cubic bricks of ``--brick``
voxels, or without it of the size chosen for the cluster's worker threads (``--brick``'s help
says how; a few bricks each keep every thread busy to the end, and larger bricks cost less to
merge). The client reads the mesh once and bins its faces: each
brick receives only the faces whose box, grown by one voxel, reaches it (the separating
criterion is local, so this halo is all a brick needs), voxelizes them and writes its part as
a ``.vdb``.

Solids take the inside rule a single run takes (option ``inside``). By the winding number
(``auto`` on a consistently oriented mesh, open or not, or ``winding``) every brick within the
mesh's box also receives the whole mesh (sent to each worker once) and writes its surface and
the centres whose winding number is at least 1/2: one round, no brick waits for another. By
parity (``parity``, or ``auto`` where orientations disagree; closed meshes) they take two
rounds: each brick labels its outside components and returns the labels on its faces; the
client joins them across bricks and finds the exterior (what reaches the grid's border); each
brick then writes its surface and the components that are not exterior, and bricks without
faces are wholly outside or wholly inside (written as tiles, no task).

The bricks are merged into ``OUT.vdb``. Bricks of a multiple of 128 voxels (every size chosen)
lie on OpenVDB's 128^3 nodes and each brick holds its nodes as the merged file does, so they
never go through the disk twice: each worker keeps its bricks encoded in memory and tells the
client where its nodes lie; the client lays the merged file out in OpenVDB's order, writes only
the 4096^3 nodes' masks and the heads itself, and each worker writes its bricks' nodes into
place (a worker lost before that is made good by Dask running its bricks again). The client
never holds a voxel: its memory does not grow with the voxels. Bricks of other sizes are
written as files, read into one grid, and merged only when it fits in the client's memory
(each brick reports the bytes its leaves and tiles take). With ``--keep-bricks`` (or when that
does not fit) the brick files stay as ``OUT.bricks/`` with an index ``OUT.bricks/index.json``
that ``voxelkit info`` and ``voxelkit.read_vdb`` read as one grid, and ``merge`` merges later.
Workers write into the output's folder (brick files, or the merged file in place), so with
``--scheduler`` it must be on a file system every worker sees. While a run lasts it holds the
folder ``OUT.bricks/``, and a second run to the same output is refused.

With ``--frames`` the input and output are frame patterns and each frame runs whole on one
worker, every frame on the grid fitted to the union of their boxes (see ``frames``).

Without ``--scheduler`` a local cluster of ``--workers`` processes is started, each running
its bricks on (cores / workers) threads; the worker processes are spawned, so a script that
calls ``run`` must do so under ``if __name__ == "__main__":``. ``--max-memory`` (MiB) bounds each brick's work.
"""

import argparse
import contextlib
import inspect
import logging
import os
import shutil
import signal
import sys
import threading
import time

from . import OPTIONS, _option_lines, _option_parameters
from . import _voxelkit as vk

#: The options of a distributed run, their defaults, choices and docs: the library's table.
_FIELDS = OPTIONS["distributed"]["fields"]



def _surface_brick(arrays, origin, voxel_size, brick, size, path, separability, max_memory_mib):
    positions, indices, starts = arrays
    return vk.brick_surface_file(
        positions, indices, starts, origin, voxel_size, brick, size, path,
        separability=separability, max_memory_mib=max_memory_mib,
    )


def _brick_faces(arrays, origin, voxel_size, brick, size, max_memory_mib):
    positions, indices, starts = arrays
    return vk.brick_faces(
        positions, indices, starts, origin, voxel_size, brick, size,
        max_memory_mib=max_memory_mib,
    )


def _solid_brick(arrays, origin, voxel_size, brick, size, exterior, path, max_memory_mib):
    positions, indices, starts = arrays
    return vk.brick_solid_file(
        positions, indices, starts, origin, voxel_size, brick, size, exterior, path,
        max_memory_mib=max_memory_mib,
    )


def _winding_brick(arrays, mesh, origin, voxel_size, brick, size, path, max_memory_mib):
    positions, indices, starts = arrays
    return vk.brick_winding_file(
        positions, indices, starts, *mesh, origin, voxel_size, brick, size, path,
        max_memory_mib=max_memory_mib,
    )


def _frame(input, output, solid, voxel_size, origin, options):
    """One frame voxelized whole on a worker on the shared grid and written (atomically:
    a retried frame writes the same file again); returns its voxel count."""
    from . import mesh as surface, solid as filled

    os.makedirs(os.path.dirname(os.path.abspath(output)), exist_ok=True)
    grid = (filled if solid else surface)(input, voxel_size=voxel_size, origin=origin, **options)
    grid.write(output)
    return len(grid)


def _peak_rss_mib():
    """This process's peak resident memory: VmHWM, which starts afresh in a spawned worker
    (ru_maxrss would carry over the memory of the process that spawned it)."""
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def _available_bytes():
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return None


class _Progress:
    """One line on stderr: what is running and how many bricks are done."""

    def __init__(self, enabled):
        self.enabled = enabled and sys.stderr.isatty()

    def show(self, stage, done, total):
        if self.enabled:
            sys.stderr.write(f"\r{stage}: {done}/{total} bricks")
            sys.stderr.flush()
            if done == total:
                sys.stderr.write("\n")


#: Seconds a scheduler has to answer before the run gives up on it.
_SCHEDULER_TIMEOUT = 10


def _connect(client_class, scheduler):
    """A client of `scheduler`, or OSError when it does not answer in time. Dask's own timeout
    does not bound a server that accepts the connection and never answers, so the client is
    made on a thread of its own, waited for no longer than the timeout."""
    made = {}

    def connect():
        try:
            made["client"] = client_class(scheduler, timeout=_SCHEDULER_TIMEOUT)
        except Exception as e:
            made["error"] = e

    thread = threading.Thread(target=connect, daemon=True, name="voxelkit-connect")
    thread.start()
    thread.join(_SCHEDULER_TIMEOUT + 1)
    if "client" in made:
        return made["client"]
    reason = f" ({made['error']})" if "error" in made else ""
    raise OSError(f"the scheduler at {scheduler} did not answer within {_SCHEDULER_TIMEOUT} s{reason}")


def _client(scheduler, workers, threads):
    from dask.distributed import Client, LocalCluster

    if scheduler:
        return _connect(Client, scheduler), None
    # The scheduler's HTTP server starts even without a dashboard: on a free port, so that a
    # taken 8787 prints no warning. Workers log nothing below critical: a brick's failure comes
    # back to the client with its name, and a run stopped by a signal ends with one line, not
    # the heartbeat tracebacks of workers whose scheduler went first.
    cluster = LocalCluster(
        n_workers=workers,
        threads_per_worker=1,
        processes=True,
        dashboard_address=":0",
        env={"RAYON_NUM_THREADS": str(threads), "DASK_LOGGING__DISTRIBUTED": "critical"},
    )
    return Client(cluster), cluster


@contextlib.contextmanager
def _using(client, scheduler, workers):
    """`client`, else a client of the scheduler at `scheduler`, else of a local cluster of
    `workers` processes (each on cores / workers threads) started for the call and closed
    after it."""
    if client is not None:
        yield client
        return
    threads = max(1, (os.cpu_count() or 1) // max(1, workers))
    client, cluster = _client(scheduler, workers, threads)
    try:
        yield client
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


#: How often a brick whose worker died is run again on another worker.
_RETRIES = 2


class _Stopped(KeyboardInterrupt):
    """SIGTERM or SIGINT during a run: raised in the main thread, and again at the next
    stage should Dask's own waiting have swallowed it."""


@contextlib.contextmanager
def _stopped_by_signals():
    """SIGTERM and SIGINT end the run (its bricks removed) instead of killing the process
    with its partial bricks left, or being lost inside Dask's waiting."""
    if threading.current_thread() is not threading.main_thread():
        yield lambda: None
        return
    caught = []

    def stop(signum, _frame):
        caught.append(signum)
        # The cluster is torn down mid-work: Dask's own logs of the closing would bury the
        # one line that says why the run ended.
        for name in ["distributed", *logging.root.manager.loggerDict]:
            if name.split(".")[0] == "distributed":
                logging.getLogger(name).disabled = True
        raise _Stopped(f"stopped by signal {signal.Signals(signum).name}")

    previous = {s: signal.signal(s, stop) for s in (signal.SIGTERM, signal.SIGINT)}
    previous_hook = sys.unraisablehook

    def unraisable(info):
        # A stop raised where it cannot propagate (a garbage-collector callback of Dask's)
        # would print a traceback; `check` raises it again at the next stage.
        if not isinstance(info.exc_value, _Stopped):
            previous_hook(info)

    sys.unraisablehook = unraisable

    def check():
        if caught:
            raise _Stopped(f"stopped by signal {signal.Signals(caught[0]).name}")

    try:
        yield check
    finally:
        sys.unraisablehook = previous_hook
        for s, handler in previous.items():
            signal.signal(s, handler)


#: Tasks per worker thread when bricks are grouped: enough to balance uneven bricks, few
#: enough that a task's fixed cost (its trips through the scheduler) is not paid per brick.
_TASKS_PER_THREAD = 16


def _in_turn(calls):
    """A task's bricks run one after another on its worker: [(brick, result)]. An error that
    does not name its brick is raised again naming it."""
    results = []
    for b, f, args in calls:
        try:
            results.append((b, f(*args)))
        except (ValueError, MemoryError, OSError):
            raise
        except Exception as e:
            raise RuntimeError(f"brick {b}: {type(e).__name__}: {e}") from None
    return results


def _run(client, calls, stage, progress, check, grouped=True, keep=False):
    """Submits `calls` ({brick: (function, args)}) and gathers {brick: result}. Consecutive
    bricks share a task (`grouped`; frames do not). A task's arguments travel with it (not
    scattered to one worker), so that a task whose worker dies runs again elsewhere; a brick
    that still fails ends the run with an error that names it. With `keep`, the results (the
    bricks, encoded) stay on their workers: {brick: (voxels, nodes)} comes back, with the
    tasks that hold them ([(future, bricks)]), which Dask runs again should a worker holding
    one die before the merge."""
    from dask.distributed import as_completed

    keys = list(calls)
    threads = sum(client.nthreads().values()) if grouped else 0
    size = max(1, -(-len(keys) // (_TASKS_PER_THREAD * threads))) if threads else 1
    futures, held = {}, []
    for i in range(0, len(keys), size):
        group = keys[i:i + size]
        work = [(b, *calls[b]) for b in group]
        future = client.submit(_in_turn, work, pure=False, retries=_RETRIES)
        if keep:
            held.append((future, group))
            future = client.submit(_nodes_of, future, pure=False, retries=_RETRIES)
        futures[future] = group
    results = {}
    progress.show(stage, 0, len(keys))
    for future in as_completed(futures):
        check()
        results.update(_result(future, futures[future], stage))
        progress.show(stage, len(results), len(keys))
    check()
    return (results, held) if keep else results


def _result(future, group, stage):
    """A task's result; its failure as an error that names its bricks."""
    try:
        return future.result()
    except (ValueError, MemoryError, OSError):
        raise
    except Exception as e:
        named = f"brick {group[0]}" if len(group) == 1 else f"bricks {group[0]} to {group[-1]}"
        raise RuntimeError(
            f"{named} ({stage}) failed on its worker after {_RETRIES} retries: "
            f"{type(e).__name__}: {e}"
        ) from None


def _nodes_of(results):
    """What the merge needs of a task's encoded bricks: [(brick, (voxels, nodes))]."""
    return [(b, (encoded.voxels, encoded.nodes())) for b, encoded in results]


def _write_into(results, path, placements):
    """A task's encoded bricks written into the merged file at `path`."""
    vk.write_bricks_into(path, [(encoded, placements[b]) for b, encoded in results])


def _merge_in_place(client, plan, held, nodes, full_bricks, output, progress, check):
    """The bricks kept on the workers merged into `output`: the client lays the file out and
    writes its own bytes, each task's worker writes its bricks' nodes into place."""
    from dask.distributed import as_completed

    def write_bricks(path, placements):
        tasks = {
            client.submit(_write_into, future, path, {b: placements[b] for b in group},
                          pure=False, retries=_RETRIES): group
            for future, group in held
        }
        done = 0
        progress.show("merge", done, len(nodes))
        for task in as_completed(tasks):
            check()
            _result(task, tasks[task], "merge")
            done += len(tasks[task])
            progress.show("merge", done, len(nodes))

    return vk.brick_splice_in_place(
        plan, {b: n for b, (_, n) in nodes.items()}, full_bricks, output, write_bricks
    )


def _brick_file(b):
    return "brick_{}_{}_{}.vdb".format(*b)


def run(source, output, solid=False, scheduler=None, workers=2, keep_bricks=False,
        progress=False, client=None, **options):
    start = time.perf_counter()
    output = os.fspath(output)
    # The library checks every option (the table's names, values and messages) before any work.
    plan = vk.brick_plan(source, solid=solid, output=output, **options)
    folder = os.path.splitext(output)[0] + ".bricks"
    if os.path.exists(folder):
        raise OSError(f"{folder}: already exists; remove it or choose another output")
    with _stopped_by_signals() as check:
        os.makedirs(folder)
        try:
            return _run_in(plan, folder, output, solid, scheduler, workers, keep_bricks,
                           progress, client, start, check)
        except BaseException:
            # No half-written output: the bricks of a failed or interrupted run go.
            shutil.rmtree(folder, ignore_errors=True)
            raise


def _run_in(plan, folder, output, solid, scheduler, workers, keep_bricks, progress, client,
            start, check):
    separability, max_memory_mib = plan.separability, plan.max_memory_mib
    show = _Progress(progress)
    # Bricks on OpenVDB's nodes merged into one file stay in their workers' memory, encoded,
    # and are written into place from there; the others go through brick files.
    in_place = plan.splices and not keep_bricks
    with _using(client, scheduler, workers) as client:
        size = plan.fit_to_threads(sum(client.nthreads().values()))
        origin, h = plan.origin, plan.voxel_size
        bricks = plan.winding_bricks if solid and plan.winding else plan.bricks
        arrays = {b: plan.faces_of(b) for b in bricks}
        # Submitted most faces first, so that the bricks left running when the others are done
        # are short ones, not the one worker's whole last brick.
        bricks = sorted(bricks, key=lambda b: len(arrays[b][1]), reverse=True)
        files = {b: _brick_file(b) for b in bricks}
        path = {b: None if in_place else os.path.abspath(os.path.join(folder, files[b]))
                for b in bricks}
        full_bricks = []
        if solid and plan.winding:
            # Every worker holds the mesh once; a worker lost takes no brick's only copy.
            mesh = client.scatter(plan.mesh_arrays(), broadcast=True)
            calls = {
                b: (_winding_brick, (arrays[b], mesh, origin, h, b, size, path[b], max_memory_mib))
                for b in bricks
            }
            stage = "solid"
        elif solid:
            faces = _run(
                client,
                {b: (_brick_faces, (arrays[b], origin, h, b, size, max_memory_mib)) for b in bricks},
                "outside labels",
                show,
                check,
            )
            exterior = vk.brick_exterior(plan, faces)
            del faces
            full_bricks = [b for b, labels in exterior.items() if b not in arrays and 1 not in labels]
            calls = {
                b: (_solid_brick, (arrays[b], origin, h, b, size, exterior[b], path[b], max_memory_mib))
                for b in bricks
            }
            stage = "solid"
        else:
            calls = {
                b: (_surface_brick, (arrays[b], origin, h, b, size, path[b], separability, max_memory_mib))
                for b in bricks
            }
            stage = "surface"
        if in_place:
            counts, held = _run(client, calls, stage, show, check, keep=True)
            bricks_done = time.perf_counter()
            _merge_in_place(client, plan, held, counts, full_bricks, output, show, check)
            del held
            merged_by = "splicing"
        else:
            counts = _run(client, calls, stage, show, check)
            bricks_done = time.perf_counter()
        peaks = list(client.run(_peak_rss_mib).values())
    # Each brick task gives its voxels (and, through files, the bytes its leaves and tiles take
    # in a merge that reads them).
    voxels = sum(v for v, _ in counts.values()) + len(full_bricks) * size**3
    merge = in_place or (not keep_bricks and _fits(plan, counts, full_bricks))
    check()
    if not in_place:
        index = os.path.join(folder, "index.json")
        if merge:
            show.show("merge", 0, len(files))
        merged_by = vk.brick_finish(plan, files, full_bricks, index, merged=output if merge else None)
        if merge:
            show.show("merge", len(files), len(files))
    if merge:
        shutil.rmtree(folder)
    return {
        "output": output if merge else index,
        "merged_by": merged_by,
        "bricks": len(bricks),
        "brick": size,
        "full_bricks": len(full_bricks),
        "inside_rule": plan.inside_reason,
        "voxels": voxels,
        "seconds": time.perf_counter() - start,
        "brick_seconds": bricks_done - start,
        "merge_seconds": time.perf_counter() - bricks_done,
        "worker_peak_mib": peaks,
    }


def _fits(plan, counts, full_bricks):
    """Whether brick files off OpenVDB's nodes, read into one grid to merge, fit in memory."""
    merged_bytes = sum(b for _, b in counts.values()) + len(full_bricks) * plan.full_brick_bytes
    available = _available_bytes()
    return available is None or merged_bytes < available


def frames(inputs, outputs, frames, solid=False, scheduler=None, workers=2, progress=False,
           client=None, **options):
    start = time.perf_counter()
    inputs, outputs = os.fspath(inputs), os.fspath(outputs)
    plan, voxel_size, origin = vk.frame_plan(inputs, frames, outputs, **options)
    # Each frame's job takes the options given that apply to one frame on the shared grid; the
    # library's defaults stand for the rest.
    applies = ("max_memory_mib", "up_axis", "inside" if solid else "separability")
    job = {name: options[name] for name in applies if name in options}
    show = _Progress(progress)
    with _stopped_by_signals() as check, _using(client, scheduler, workers) as client:
        calls = {f: (_frame, (i, o, solid, voxel_size, origin, job)) for f, i, o in plan}
        voxels = _run(client, calls, "frames", show, check, grouped=False)
        peaks = list(client.run(_peak_rss_mib).values())
    return {
        "outputs": [o for _, _, o in plan],
        "frames": len(plan),
        "voxels": [voxels[f] for f, _, _ in plan],
        "voxel_size": voxel_size,
        "origin": origin,
        "seconds": time.perf_counter() - start,
        "worker_peak_mib": peaks,
    }


def merge(index, output):
    """Merges a kept brick set (its ``index.json``) into the one .vdb ``output``, atomically, as
    a run merges it: by splicing bricks of a multiple of 128 voxels (memory that does not grow
    with the voxels), else by reading them into one grid. The brick set stays.

    Returns a dict: ``output``, ``merged_by`` (``"splicing"`` or ``"reading"``), ``voxels`` and
    ``seconds``."""
    start = time.perf_counter()
    merged_by, voxels = vk.brick_merge(os.fspath(index), os.fspath(output))
    return {
        "output": os.fspath(output),
        "merged_by": merged_by,
        "voxels": voxels,
        "seconds": time.perf_counter() - start,
    }


def _with_table_options(fn):
    """``fn`` with the table's options in its signature and docs, after its own."""
    own = [p for p in inspect.signature(fn).parameters.values() if p.kind != p.VAR_KEYWORD]
    table = _option_parameters(_FIELDS, inspect.Parameter.KEYWORD_ONLY)
    fn.__signature__ = inspect.Signature(own + table)
    fn.__doc__ = fn.__doc__ + "\n" + "\n".join(_option_lines(_FIELDS)) + "\n"
    return fn


run.__doc__ = """Voxelizes ``source`` (a path or a (vertices, faces) pair) in bricks on Dask: on
``client`` (a dask.distributed.Client) when given, else on the scheduler at ``scheduler``,
else on a local cluster of ``workers`` processes started for the call.

Returns a dict: ``output`` (the .vdb, or the brick set's index when the bricks were kept;
``voxelkit.read_vdb`` reads either), ``merged_by`` (``"splicing"``: bricks of a multiple of 128
voxels, their nodes copied without reading a voxel; ``"reading"``: other sizes, through one
grid in memory; None when kept), ``bricks`` (the bricks run), ``brick`` (their edge in voxels,
given or chosen), ``full_bricks`` (wholly inside
without a task), ``voxels``, ``inside_rule`` (a solid's rule and why), ``seconds`` (of which
``brick_seconds`` up to the last brick and ``merge_seconds`` after), and ``worker_peak_mib``
(each worker process's peak memory).

The options, as for every voxelkit function (``voxelkit.OPTIONS["distributed"]``):
"""
run = _with_table_options(run)

frames.__doc__ = """Voxelizes the frames ``frames`` (``"1-240"``, ``"1-240:2"`` or one frame) of the
input pattern ``inputs`` (``f_####.obj``: ``#`` for the zero-padded frame number) into the
output pattern ``outputs``, frame by frame over Dask (``client``, ``scheduler`` or ``workers``
as for ``run``): the surface, or with ``solid`` the solid. Every frame shares one voxel size
and origin, fitted to the union of the frames' boxes, as ``voxelkit mesh --frames`` fits them,
so that the animated volume does not jitter; each frame runs whole on one worker (``brick``
does not apply) and its file is written atomically, so that a frame whose worker dies is
written again, whole, elsewhere.

Returns a dict: ``outputs``, ``frames``, ``voxels`` (per frame), ``voxel_size``, ``origin``,
``seconds`` and ``worker_peak_mib``.

The options (``voxelkit.OPTIONS["distributed"]``):
"""
frames = _with_table_options(frames)


def mesh(source, output, **options):
    """The separating surface of ``source`` in bricks (see ``run`` for the options)."""
    return run(source, output, solid=False, **options)


def solid(source, output, **options):
    """The solid of a mesh in bricks, by the inside rule a single run takes (see ``run``)."""
    return run(source, output, solid=True, **options)


#: Short forms of the table's options on the command line, and long ones that are not the
#: field's name (as the voxelkit command names them).
_SHORT = {"resolution": "-r", "separability": "-s"}
_LONG = {"max_memory_mib": "--max-memory"}
def _xyz(text):
    """Three numbers `x,y,z`."""
    values = [float(v) for v in text.split(",")]
    if len(values) != 3:
        raise ValueError(f"expected x,y,z, got {text!r}")
    return values


#: The command-line types of the table's optional options, by their Python type.
_OPTIONAL_TYPES = {"Optional[int]": int, "Optional[float]": float, "Optional[Sequence[float]]": _xyz}


def _add_option(parser, field):
    """The command-line option of a table field: its name, type, default, choices and doc."""
    name, default, choices = field["name"], field["default"], field["choices"]
    kind = _OPTIONAL_TYPES.get(field["python_type"]) or type(default)
    flags = [_SHORT[name]] if name in _SHORT else []
    flags.append(_LONG.get(name, "--" + name.replace("_", "-")))
    extra = {"metavar": "MIB"} if name == "max_memory_mib" else {}
    if choices:
        extra["choices"] = [kind(c) for c in choices]
    shown = f" (default {default})" if default is not None else ""
    parser.add_argument(*flags, dest=name, type=kind, default=default, help=field["doc"] + shown, **extra)


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="python -m voxelkit.distributed",
        description="Voxelize one mesh over Dask workers in bricks.",
    )
    commands = parser.add_subparsers(dest="command", required=True)
    for name, help_text in (
        ("mesh", "the separating surface"),
        ("solid", "the solid (surface and inside, by the option inside)"),
    ):
        p = commands.add_parser(name, help=help_text)
        p.add_argument("input", help="mesh file (.obj, .stl, .ply, .off, .gltf, .glb); with "
                       "--frames a pattern with # for the frame number (f_####.obj)")
        p.add_argument("-o", "--output", required=True,
                       help="output .vdb; with --frames a pattern (out/f_####.vdb)")
        p.add_argument("--frames", metavar="RANGE",
                       help="FIRST-LAST, FIRST-LAST:STEP or FRAME of the input pattern, each "
                            "frame whole on one worker, all on one shared grid")
        fit = p.add_mutually_exclusive_group()
        for field in _FIELDS:
            if (field["name"], name) in (("separability", "solid"), ("inside", "mesh")):
                continue
            _add_option(fit if field["name"] in ("resolution", "voxel_size") else p, field)
        where = p.add_mutually_exclusive_group()
        where.add_argument("--scheduler", help="address of a running Dask scheduler")
        where.add_argument("--workers", type=int, default=2, help="local worker processes (default 2)")
        p.add_argument("--keep-bricks", action="store_true", help="keep the brick set instead of merging")
    p = commands.add_parser("merge", help="merge a kept brick set into one .vdb")
    p.add_argument("index", help="the brick set's index (OUT.bricks/index.json)")
    p.add_argument("-o", "--output", required=True, help="output .vdb")
    args = parser.parse_args(argv)
    if args.command == "merge":
        try:
            result = merge(args.index, args.output)
        except (ValueError, MemoryError, OSError, RuntimeError) as e:
            print(f"error: {e}", file=sys.stderr)
            return 1
        print(f"{result['output']}: {result['voxels']} voxels merged by {result['merged_by']} "
              f"in {result['seconds']:.2f} s")
        return 0
    given = vars(args)
    table = {f["name"]: given[f["name"]] for f in _FIELDS if f["name"] in given}
    if args.frames is not None and args.keep_bricks:
        print("error: --keep-bricks applies to a brick run, not to --frames", file=sys.stderr)
        return 1
    common = dict(solid=args.command == "solid", scheduler=args.scheduler, workers=args.workers,
                  progress=True, **table)
    try:
        if args.frames is None:
            result = run(args.input, args.output, keep_bricks=args.keep_bricks, **common)
        else:
            result = frames(args.input, args.output, args.frames, **common)
    except (ValueError, MemoryError, OSError, RuntimeError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt as e:
        removed = "" if args.frames else "; the partial bricks were removed"
        print(f"error: {e or 'interrupted'}{removed}", file=sys.stderr)
        return 130
    peaks = ", ".join(f"{p:.0f}" for p in result["worker_peak_mib"])
    if args.frames is None:
        done = (
            f"{result['output']}: {result['voxels']} voxels from {result['bricks']} bricks of "
            f"{result['brick']} (+{result['full_bricks']} whole)"
        )
    else:
        done = (
            f"{args.output}: {result['frames']} frames, {sum(result['voxels'])} voxels, voxel size "
            f"{result['voxel_size']:.6g},"
        )
    inside = f"; inside: {result['inside_rule']}" if result.get("inside_rule") else ""
    took = f"in {result['seconds']:.2f} s"
    if result.get("merged_by"):
        took += (f" (bricks {result['brick_seconds']:.2f} s, merge by {result['merged_by']} "
                 f"{result['merge_seconds']:.2f} s)")
    print(f"{done} {took}; worker peak memory {peaks} MiB{inside}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""The Blender add-on in headless Blender 3.4: a monkey and a shared mesh voxelized by the
operator into Volume objects whose `density` grid loads, placed by Blender exactly where
voxelkit puts the voxels, and covering the mesh object's box within one voxel."""

import json
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np

import voxelkit
from conftest import missing

SCRIPT = Path(__file__).with_name("blender_addon.py")


def test_the_add_on_voxelizes_into_volume_objects(data, tmp_path):
    blender = shutil.which("blender")
    if blender is None:
        missing("blender", "the add-on test")
    package = Path(voxelkit.__file__).resolve().parents[1]
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(filter(None, [str(package), os.environ.get("PYTHONPATH")])))
    env["TMPDIR"] = str(tmp_path)
    done = subprocess.run(
        [blender, "-b", "--factory-startup", "--python-exit-code", "1", "--python", str(SCRIPT),
         "--", str(data / "meshes" / "spot_triangulated.obj")],
        capture_output=True, text=True, timeout=600, env=env,
    )
    assert done.returncode == 0 and "DONE" in done.stdout, done.stdout[-3000:] + done.stderr[-3000:]
    results = [json.loads(l[len("RESULT "):]) for l in done.stdout.splitlines() if l.startswith("RESULT ")]
    assert [r["object"] for r in results] == ["Suzanne"] + [results[1]["object"]] * 3
    # The two solids of the same object are two files, the first left as it was.
    assert results[1]["path"] != results[3]["path"] and results[1]["voxels"] != results[3]["voxels"]
    assert len(voxelkit.read_vdb(results[1]["path"])) == results[1]["voxels"]
    for r in results:
        assert r["operator"] == ["FINISHED"] and r["loaded"] and r["density_loaded"], r
        assert r["grids"][0] == "density", r["grids"]
        h = r["voxel_size"]
        # Blender places the voxel centres where voxelkit does.
        assert np.allclose(r["blender_corners"], r["voxelkit_corners"], atol=1e-4 * h + 1e-6), r
        # The outermost voxel centres lie within a voxel of the mesh object's world box.
        lo, hi = np.array(r["voxelkit_corners"])
        mesh_lo, mesh_hi = np.array(r["mesh_box"])
        assert (np.abs(lo - mesh_lo) <= h).all() and (np.abs(hi - mesh_hi) <= h).all(), r
    assert "surface" in results[2]["grids"], "the level set is written as `surface`"
    # The properties the add-on exposes have the table's defaults and choices.
    [shown] = [json.loads(l[len("PROPERTIES "):]) for l in done.stdout.splitlines() if l.startswith("PROPERTIES ")]
    table = {f["name"]: f for f in voxelkit.OPTIONS["mesh"]["fields"]}
    for name in ("separability", "method"):
        assert shown[name]["default"] == str(table[name]["default"]), name
        assert shown[name]["items"] == [str(c) for c in table[name]["choices"]], name
    assert shown["resolution"]["default"] == voxelkit.DEFAULT_RESOLUTION
    assert table["resolution"]["default"] is None and table["voxel_size"]["default"] is None
    band = next(f["default"] for f in voxelkit.OPTIONS["solid"]["fields"] if f["name"] == "band")
    assert f"within {band:g} voxels" in shown["fill"]["description"][2]
    assert "PANEL True True" in done.stdout and "UNREGISTERED False" in done.stdout
    # The frame bake: one file per frame, on one grid, each played at its frame where the
    # animated ball stands then, growing as it grows.
    [baked] = [json.loads(l[len("FRAMES "):]) for l in done.stdout.splitlines() if l.startswith("FRAMES ")]
    assert baked["operator"] == ["FINISHED"] and baked["is_sequence"], baked
    played = baked["played"]
    assert len({p["path"] for p in played}) == 3 and all(Path(p["path"]).is_file() for p in played)
    assert {results[i]["path"] for i in range(4)}.isdisjoint(p["path"] for p in played)
    for p in played:
        assert p["loaded"] and p["grid_frame"] == p["frame"], p
        assert p["voxel_size"] == played[0]["voxel_size"] and p["origin"] == played[0]["origin"], p
        assert np.allclose(p["centre"], p["location"], atol=p["voxel_size"]), p
    assert played[0]["width"] < played[1]["width"] < played[2]["width"]

"""voxelkit.signed_distance against libigl's signed_distance and Open3D's RaycastingScene on
the same points of the same mesh, in one run.

    target/python-venv/bin/python bench/python_queries.py [MESH.obj ...] [--points N]

Default meshes: stanford-bunny (open) and bunny-closed from $VOXELKIT_DATA (or
../shared/data). Points are uniform in the mesh's box grown by a fifth. Each tool's whole
call is timed (its set-up, a tree or a scene, included), best of three; the share of points
each signs differently from voxelkit, whose signs are the exact winding number's, and the most
its distance is off voxelkit's exact one.
"""

import argparse
import os
import pathlib
import time

import igl
import numpy as np
import open3d as o3d

import voxelkit
from obj_arrays import read_obj


def best_of_three(call):
    times = []
    for _ in range(3):
        start = time.perf_counter()
        result = call()
        times.append(time.perf_counter() - start)
    return min(times), result


def open3d_signed(vertices, triangles, points):
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.core.Tensor(vertices.astype(np.float32)), o3d.core.Tensor(triangles.astype(np.uint32)))
    return scene.compute_signed_distance(o3d.core.Tensor(points.astype(np.float32))).numpy()


def main():
    data = pathlib.Path(os.environ.get("VOXELKIT_DATA", pathlib.Path(__file__).resolve().parents[2] / "shared" / "data"))
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("meshes", nargs="*", default=[data / "meshes" / "stanford-bunny.obj", data / "meshes" / "bunny-closed.obj"])
    parser.add_argument("--points", type=int, default=200_000)
    args = parser.parse_args()
    rng = np.random.default_rng(1)
    print(f"{'mesh':<20} {'triangles':>9} {'points':>8} {'voxelkit s':>10} {'libigl s':>9} {'ratio':>6} {'Open3D s':>9} {'ratio':>6}  signs differing: libigl, Open3D")
    for path in map(pathlib.Path, args.meshes):
        vertices, triangles = read_obj(path)
        lo, hi = vertices.min(0), vertices.max(0)
        points = rng.uniform(lo - 0.2 * (hi - lo), hi + 0.2 * (hi - lo), (args.points, 3))
        ours_s, ours = best_of_three(lambda: voxelkit.signed_distance((vertices, triangles), points))
        igl_s, (theirs, *_) = best_of_three(
            lambda: igl.signed_distance(points, vertices, triangles, sign_type=igl.SignedDistanceType.SIGNED_DISTANCE_TYPE_FAST_WINDING_NUMBER)
        )
        o3d_s, raycast = best_of_three(lambda: open3d_signed(vertices, triangles, points))
        differ = lambda other: 100.0 * np.mean((other < 0) != (ours < 0))
        print(
            f"{path.stem:<20} {len(triangles):>9} {len(points):>8} {ours_s:>10.3f} {igl_s:>9.3f} {igl_s / ours_s:>5.1f}x "
            f"{o3d_s:>9.3f} {o3d_s / ours_s:>5.1f}x  {differ(theirs):.2f}%, {differ(raycast):.2f}%"
        )
        off = lambda other: np.abs(np.abs(other) - np.abs(ours)).max()
        print(f"{'':<20} largest distance off voxelkit's: libigl {off(theirs):.2e}, Open3D {off(raycast):.2e}")


if __name__ == "__main__":
    main()

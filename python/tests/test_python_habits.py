"""voxelkit as trimesh and Open3D users reach for it: their mesh objects as inputs, and arrays
whose meaning is checked rather than guessed."""

import numpy as np
import pytest

import voxelkit
from conftest import voxel_set


def test_a_trimesh_mesh_voxelizes_as_its_arrays(trimesh):
    mesh = trimesh.creation.torus(major_radius=1.0, minor_radius=0.3)
    from_object = voxelkit.mesh(mesh, resolution=64)
    from_arrays = voxelkit.mesh((mesh.vertices, mesh.faces), resolution=64)
    assert len(from_object) > 1000
    assert voxel_set(from_object.ijk) == voxel_set(from_arrays.ijk)
    report = voxelkit.solid(mesh, resolution=64).report
    assert report["volume_inside"] <= mesh.volume <= report["volume_with_surface"]


def test_an_open3d_mesh_voxelizes_as_its_arrays(open3d):
    mesh = open3d.geometry.TriangleMesh.create_torus(torus_radius=1.0, tube_radius=0.3)
    vertices, triangles = np.asarray(mesh.vertices), np.asarray(mesh.triangles)
    from_object = voxelkit.mesh(mesh, resolution=64)
    assert len(from_object) > 1000
    assert voxel_set(from_object.ijk) == voxel_set(voxelkit.mesh((vertices, triangles), resolution=64).ijk)


def test_faces_must_be_whole_numbers():
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    faces = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    exact = voxelkit.mesh((vertices, faces), resolution=16)
    # Whole numbers stored as floats are the same faces.
    assert voxel_set(voxelkit.mesh((vertices, faces.astype(float)), resolution=16).ijk) == voxel_set(exact.ijk)
    with pytest.raises(ValueError, match="face 0 holds 0.7, not a vertex index"):
        voxelkit.mesh((vertices, faces + 0.7), resolution=16)
    with pytest.raises(ValueError, match="face 1 holds 2.5"):
        voxelkit.mesh((vertices, [[0, 2, 1], [0, 2.5, 3]]), resolution=16)
    with pytest.raises(TypeError, match="trimesh"):
        voxelkit.mesh(object(), resolution=16)


def _closest_distances(vertices, faces, points):
    """The distance from each point to the nearest triangle, brute force over every triangle."""
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    out = np.empty(len(points))
    for n, p in enumerate(points):
        ab, ac, ap = b - a, c - a, p - a
        d1, d2 = (ab * ap).sum(1), (ac * ap).sum(1)
        bp, cp = p - b, p - c
        d3, d4 = (ab * bp).sum(1), (ac * bp).sum(1)
        d5, d6 = (ab * cp).sum(1), (ac * cp).sum(1)
        va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
        with np.errstate(divide="ignore", invalid="ignore"):
            denom = va + vb + vc
            v, w = vb / denom, vc / denom
            closest = a + ab * v[:, None] + ac * w[:, None]
            # The Voronoi regions of corners and edges (Ericson's order).
            edge = lambda s, e, t: s + (e - s) * np.clip(t, 0, 1)[:, None]
            t_ab = d1 / (d1 - d3)
            t_ac = d2 / (d2 - d6)
            t_bc = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        regions = [
            (d1 <= 0) & (d2 <= 0), a,
            (d3 >= 0) & (d4 <= d3), b,
            (d6 >= 0) & (d5 <= d6), c,
            (vc <= 0) & (d1 >= 0) & (d3 <= 0), edge(a, b, t_ab),
            (vb <= 0) & (d2 >= 0) & (d6 <= 0), edge(a, c, t_ac),
            (va <= 0) & ((d4 - d3) >= 0) & ((d5 - d6) >= 0), edge(b, c, t_bc),
        ]
        chosen = np.zeros(len(a), bool)
        for mask, point in zip(regions[::2], regions[1::2]):
            take = mask & ~chosen
            closest[take] = point[take]
            chosen |= take
        out[n] = np.sqrt(((closest - p) ** 2).sum(1)).min()
    return out


def _winding_numbers(vertices, faces, points):
    """The exact winding number at each point: every triangle's solid angle, summed."""
    out = np.empty(len(points))
    for n, p in enumerate(points):
        a, b, c = (vertices[faces[:, k]] - p for k in range(3))
        la, lb, lc = (np.sqrt((x * x).sum(1)) for x in (a, b, c))
        numerator = (a * np.cross(b, c)).sum(1)
        denominator = la * lb * lc + (a * b).sum(1) * lc + (b * c).sum(1) * la + (c * a).sum(1) * lb
        out[n] = 2 * np.arctan2(numerator, denominator).sum() / (4 * np.pi)
    return out


def _test_points(vertices, faces, rng):
    lo, hi = vertices.min(0), vertices.max(0)
    spread = rng.uniform(lo - 0.3 * (hi - lo), hi + 0.3 * (hi - lo), (300, 3))
    # Points just off the surface, on both sides.
    f = rng.integers(0, len(faces), 200)
    weights = rng.dirichlet([1, 1, 1], 200)
    on = (vertices[faces[f]] * weights[:, :, None]).sum(1)
    normals = np.cross(vertices[faces[f, 1]] - vertices[faces[f, 0]], vertices[faces[f, 2]] - vertices[faces[f, 0]])
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    near = on + normals * rng.choice([-1e-3, 1e-3], 200)[:, None]
    return np.vstack([spread, near])


@pytest.mark.parametrize("shape", ["closed", "open", "overlapping"])
def test_signed_distance_and_contains_agree_with_brute_force(trimesh, shape):
    rng = np.random.default_rng(7)
    torus = trimesh.creation.torus(major_radius=1.0, minor_radius=0.35, major_sections=48, minor_sections=24)
    vertices, faces = np.array(torus.vertices), np.array(torus.faces)
    if shape == "open":
        faces = faces[np.arange(len(faces)) % 9 != 0]
    elif shape == "overlapping":
        vertices = np.vstack([vertices, vertices + [0.6, 0.2, 0.1]])
        faces = np.vstack([faces, faces + len(torus.vertices)])
    points = _test_points(vertices, faces, rng)
    distance = _closest_distances(vertices, faces, points)
    winding = _winding_numbers(vertices, faces, points)
    signed = voxelkit.signed_distance((vertices, faces), points)
    inside = voxelkit.contains((vertices, faces), points)
    assert signed.dtype == np.float64 and inside.dtype == np.bool_
    assert np.abs(np.abs(signed) - distance).max() < 1e-9
    decided = np.abs(winding - 0.5) > 1e-6
    assert decided.sum() > 450
    assert (inside[decided] == (winding[decided] >= 0.5)).all()
    assert ((signed < 0) == inside).all()
    assert inside.sum() > 50 and (~inside).sum() > 50


def test_dense_channels_are_named_and_valued_as_the_file_holds_them(tmp_path, pyopenvdb):
    grid = voxelkit.mesh(tetrahedron_arrays(), resolution=40, sdf=True)
    band = grid.values("surface")
    assert band.shape == (len(grid),)
    with pytest.raises(KeyError, match="surface"):
        grid.values("distance")
    dense, offset = grid.to_dense("surface")
    assert dense.dtype == np.float32 and dense.shape == grid.to_dense()[0].shape
    assert np.array_equal(dense[tuple((grid.ijk - offset).T)], band)
    grid.write(tmp_path / "t.vdb")
    level_set = pyopenvdb.read(str(tmp_path / "t.vdb"), "surface")
    theirs = np.zeros(dense.shape, np.float32)
    level_set.copyToArray(theirs, ijk=tuple(int(o) for o in offset))
    assert np.array_equal(dense, theirs)
    assert (dense < 0).any() and (dense == -level_set.background).any() and (dense == level_set.background).any()
    unsigned = voxelkit.mesh(tetrahedron_arrays(), resolution=40, udf=True)
    assert unsigned.to_dense("distance")[0].min() >= 0
    normals = voxelkit.mesh(tetrahedron_arrays(), resolution=40, normals=True)
    dense_normals, _ = normals.to_dense("normal")
    assert dense_normals.shape == normals.to_dense()[0].shape + (3,)


def tetrahedron_arrays():
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    return vertices, np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


def test_origin_places_voxel_centres_where_open3d_and_trimesh_put_them(trimesh, open3d):
    mesh = trimesh.creation.torus(major_radius=1.0, minor_radius=0.35, major_sections=64, minor_sections=32)
    h = 0.04
    # Open3D's VoxelGrid: voxel centres at the mesh's low corner plus whole voxels.
    o3d_mesh = open3d.geometry.TriangleMesh(
        open3d.utility.Vector3dVector(mesh.vertices), open3d.utility.Vector3iVector(mesh.faces)
    )
    o3d_grid = open3d.geometry.VoxelGrid.create_from_triangle_mesh(o3d_mesh, voxel_size=h)
    theirs = {tuple(v.grid_index) for v in o3d_grid.get_voxels()}
    low = np.asarray(o3d_mesh.get_min_bound())
    ours_grid = voxelkit.mesh(mesh, voxel_size=h, origin=low)
    assert np.allclose(ours_grid.origin, low)
    ours = voxel_set(ours_grid.ijk)
    # Both grids voxelize the same surface on the same centres: their sets nearly coincide.
    iou = len(ours & theirs) / len(ours | theirs)
    print(f"IoU with Open3D's VoxelGrid at voxel size {h}: {iou:.3f} ({len(ours)} and {len(theirs)} voxels)")
    assert iou > 0.7
    shifted = voxel_set(voxelkit.mesh(mesh, voxel_size=h).ijk)
    assert len(shifted & theirs) / len(shifted | theirs) < iou
    # trimesh's pitch grid: every centre on a multiple of the voxel size.
    aligned = voxelkit.mesh(mesh, voxel_size=h, origin=(0, 0, 0))
    centres = aligned.index_to_world(aligned.ijk)
    assert np.allclose(centres / h, np.round(centres / h), atol=1e-9)
    filled = mesh.voxelized(pitch=h)
    trimesh_centres = {tuple(c) for c in np.round(filled.points / h).astype(int)}
    iou_trimesh = len(voxel_set(aligned.ijk) & trimesh_centres) / len(voxel_set(aligned.ijk) | trimesh_centres)
    print(f"IoU with trimesh's voxelized at pitch {h}: {iou_trimesh:.3f}")
    assert iou_trimesh > 0.5


def test_bounds_place_and_cut_the_grid_as_open3d_does_within_bounds(trimesh, open3d):
    mesh = trimesh.creation.torus(major_radius=1.0, minor_radius=0.35, major_sections=64, minor_sections=32)
    h, low, high = 0.05, np.array([-1.5, -0.4, -0.5]), np.array([0.3, 1.5, 0.5])
    o3d_mesh = open3d.geometry.TriangleMesh(
        open3d.utility.Vector3dVector(mesh.vertices), open3d.utility.Vector3iVector(mesh.faces)
    )
    o3d_grid = open3d.geometry.VoxelGrid.create_from_triangle_mesh_within_bounds(o3d_mesh, h, low, high)
    # Open3D places its grid in the bounds but keeps the voxels beyond them: compare inside.
    dims = np.floor((high - low) / h - 0.5).astype(int) + 1  # centres within the bounds
    theirs = {tuple(v.grid_index) for v in o3d_grid.get_voxels() if np.all((0 <= v.grid_index) & (v.grid_index < dims))}
    ours_grid = voxelkit.mesh(mesh, voxel_size=h, bounds=[low, high])
    assert np.allclose(ours_grid.origin, low + h / 2)
    ours = voxel_set(ours_grid.ijk)
    iou = len(ours & theirs) / len(ours | theirs)
    print(f"IoU with Open3D's VoxelGrid within bounds at voxel size {h}: {iou:.3f} ({len(ours)} and {len(theirs)} voxels)")
    assert iou > 0.7
    centres = ours_grid.index_to_world(ours_grid.ijk)
    assert np.all(centres >= low) and np.all(centres <= high)
    # The dense array spans the bounds, whatever the mesh holds there.
    dense, corner = ours_grid.to_dense()
    assert dense.shape == tuple(dims) and tuple(corner) == (0, 0, 0)
    assert dense.sum() == len(ours_grid)


def test_bounds_keep_the_same_solid_voxels_and_measure_what_is_kept(trimesh):
    mesh = trimesh.creation.icosphere(subdivisions=4, radius=1.0)
    h, origin = 0.04, (0.0, 0.0, 0.0)
    full = voxelkit.solid(mesh, voxel_size=h, origin=origin)
    bounds = [[-2.0, -2.0, 0.0], [2.0, 2.0, 2.0]]
    upper = voxelkit.solid(mesh, voxel_size=h, origin=origin, bounds=bounds)
    centres = full.index_to_world(full.ijk)
    expected = voxel_set(full.ijk[centres[:, 2] >= 0.0])
    assert voxel_set(upper.ijk) == expected
    report = upper.report
    assert report["voxels"] == len(expected)
    assert report["voxels_outside_bounds"] == len(full) - len(expected)
    assert report["inside_voxels"] + report["surface_voxels"] == len(expected)
    assert report["volume_with_surface"] == pytest.approx(len(expected) * h**3)
    # Half the sphere's volume lies between the kept solid's inside and whole.
    assert report["volume_inside"] <= mesh.volume / 2 <= report["volume_with_surface"] * 1.02
    with pytest.raises(ValueError, match="bounds"):
        voxelkit.solid(mesh, bounds=[[1.0, 0.0, 0.0], [0.0, 1.0, 1.0]])


def test_sample_reads_a_level_set_as_openvdb_does():
    vertices, faces = tetrahedron_arrays()
    grid = voxelkit.mesh((vertices, faces), resolution=40, sdf=True)
    dense, offset = grid.to_dense("surface")
    background = float(np.abs(dense).max())
    rng = np.random.default_rng(3)
    lo, hi = vertices.min(0) - 0.1, vertices.max(0) + 0.1
    points = rng.uniform(lo, hi, (2000, 3))
    # Trilinear over the dense array, padded with the background beyond its box (outside).
    padded = np.pad(dense.astype(np.float64), 1, constant_values=background)
    q = (points - np.array(grid.origin)) / grid.voxel_size - np.array(offset) + 1
    base = np.floor(q).astype(int)
    t = q - base
    inside_box = ((base >= 0) & (base + 1 < np.array(padded.shape))).all(1)
    expected = np.zeros(len(points))
    for corner in range(8):
        d = np.array([(corner >> a) & 1 for a in range(3)])
        w = np.prod(np.where(d == 1, t, 1 - t), axis=1)
        idx = np.clip(base + d, 0, np.array(padded.shape) - 1)
        expected += w * padded[idx[:, 0], idx[:, 1], idx[:, 2]]
    got = grid.sample(points)
    assert inside_box.sum() > 1500
    assert np.allclose(got[inside_box], expected[inside_box], atol=1e-6)
    # Far outside: the background; the sign of the samples agrees with contains() away from the surface.
    assert np.allclose(grid.sample([[10.0, 10.0, 10.0]]), background)
    far = np.abs(got) > 2 * grid.voxel_size
    assert ((got[far] < 0) == voxelkit.contains((vertices, faces), points[far])).all()
    assert np.isnan(grid.sample([[np.nan, 0, 0]])[0])


def test_progress_is_heard_from_the_fill_stage_to_its_end(trimesh):
    mesh = trimesh.creation.torus(major_radius=1.0, minor_radius=0.35)
    for options, last in [
        (dict(inside="winding"), "surface and inside"),
        (dict(inside="parity"), "filling"),
        (dict(method="depth-layers"), "classifying"),
        (dict(sdf=True), "distances and inside"),
    ]:
        heard = []
        voxelkit.solid(mesh, resolution=128, progress=lambda *told: heard.append(told), **options)
        stage, done, total = heard[-1]
        assert (stage, done) == (last, total) and total > 0, (options, heard[-1])
        assert all(told[0] and told[1] <= told[2] for told in heard), options


def test_to_mesh_gives_a_closed_mesh_trimesh_takes(trimesh, tmp_path):
    """A level set's surface as numpy arrays: trimesh finds it watertight, consistently wound
    and of the torus's volume; a solid's boundary encloses its voxels; write() by a mesh
    extension writes the same mesh."""
    torus = trimesh.creation.torus(major_radius=1.0, minor_radius=0.3)
    grid = voxelkit.mesh(torus, sdf=True, resolution=96)
    vertices, triangles = grid.to_mesh()
    assert vertices.dtype == np.float64 and vertices.shape[1] == 3
    assert triangles.dtype == np.int64 and triangles.shape[1] == 3
    out = trimesh.Trimesh(vertices, triangles, process=False)
    assert out.is_watertight and out.is_winding_consistent
    assert abs(out.volume / torus.volume - 1) < 0.005
    # A solid's mesh bounds its voxels, the surface voxels included.
    voxels = voxelkit.solid(torus, resolution=96)
    solid = trimesh.Trimesh(*voxels.to_mesh(), process=False)
    assert solid.is_watertight
    report = voxels.report
    assert report["volume_inside"] < solid.volume < report["volume_with_surface"]
    grid.write(tmp_path / "torus.ply")
    back = trimesh.load(tmp_path / "torus.ply", process=False)
    assert len(back.faces) == len(triangles)
    assert np.allclose(back.vertices, vertices, atol=1e-6)


def test_to_mesh_adaptivity_merges_flat_regions(trimesh, tmp_path):
    """adaptivity (voxels) leaves fewer triangles, still watertight and of the same volume;
    write() of a mesh takes it too and refuses a file's grid options."""
    box = trimesh.creation.box(extents=(1.0, 0.8, 0.6))
    grid = voxelkit.mesh(box, sdf=True, resolution=64)
    full = trimesh.Trimesh(*grid.to_mesh(), process=False)
    merged = trimesh.Trimesh(*grid.to_mesh(adaptivity=0.5), process=False)
    assert merged.is_watertight and merged.is_winding_consistent
    assert len(merged.faces) * 3 < len(full.faces)
    assert abs(merged.volume / full.volume - 1) < 0.002
    grid.write(tmp_path / "box.ply", adaptivity=0.5)
    back = trimesh.load(tmp_path / "box.ply", process=False)
    assert len(back.faces) == len(merged.faces)
    with pytest.raises(ValueError, match="adaptivity must be 0 or a positive number"):
        grid.to_mesh(adaptivity=-1)
    with pytest.raises(ValueError, match="a result's mesh takes adaptivity"):
        grid.write(tmp_path / "iso.ply", iso=0.1)

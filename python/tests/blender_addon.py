# Run inside headless Blender by test_blender.py: registers the add-on, voxelizes a monkey
# and the mesh file given after `--` with the operator, and prints what Blender loaded.
import json
import sys

import bpy
import numpy as np

import voxelkit
import voxelkit.blender

mesh_file = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
voxelkit.register()


def world_box(obj):
    vertices, _ = voxelkit.blender.world_mesh(obj, bpy.context.evaluated_depsgraph_get())
    return vertices.min(axis=0), vertices.max(axis=0)


def voxelize(obj, **settings):
    for o in bpy.context.view_layer.objects:
        o.select_set(False)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    before = set(bpy.data.objects.keys())
    result = bpy.ops.object.voxelkit_voxelize(**settings)
    [name] = set(bpy.data.objects.keys()) - before
    volume_object = bpy.data.objects[name]
    volume = volume_object.data
    loaded = volume.grids.load()
    names = [g.name for g in volume.grids]
    density = volume.grids["density"]
    # Blender's placement of voxel centres (its grid-to-object matrix and the object's
    # matrix) against voxelkit's own reading of the file.
    grid = voxelkit.read_vdb(bpy.path.abspath(volume.filepath))
    lo, hi = (np.array(c, dtype=float) for c in grid.bbox)
    to_world = np.array(volume_object.matrix_world) @ np.array(density.matrix_object)
    corners = [(to_world @ np.append(c, 1.0))[:3] for c in (lo, hi)]
    mesh_lo, mesh_hi = world_box(obj)
    print("RESULT " + json.dumps({
        "object": obj.name,
        "operator": list(result),
        "loaded": loaded,
        "density_loaded": density.load(),
        "grids": names,
        "voxel_size": grid.voxel_size,
        "voxels": len(grid),
        "blender_corners": [list(map(float, c)) for c in corners],
        "voxelkit_corners": grid.index_to_world([lo, hi]).tolist(),
        "mesh_box": [mesh_lo.tolist(), mesh_hi.tolist()],
        "path": bpy.path.abspath(volume.filepath),
    }))


bpy.ops.mesh.primitive_monkey_add(location=(1.0, -2.0, 0.5), rotation=(0.3, 0.2, 0.1), scale=(1.5, 1.5, 1.5))
voxelize(bpy.context.active_object, resolution=64)
bpy.ops.wm.obj_import(filepath=mesh_file)
imported = bpy.context.selected_objects[0]
imported.location = (0.0, 3.0, 0.0)
voxelize(imported, resolution=96, fill="solid")
voxelize(imported, resolution=64, fill="sdf")
# A second solid of the same object, the object stretched, goes to a file of its own: the
# first volume keeps showing what it showed.
imported.scale = (1.3, 1.0, 1.0)
voxelize(imported, resolution=96, fill="solid")
# An animated ball, moving along x and growing from frame 1 to 3, baked frame by frame into
# one sequence; each frame's file read back as Blender plays it.
bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=3, radius=0.5, location=(0.0, 0.0, 0.0))
ball = bpy.context.active_object
for frame, x, size in [(1, 0.0, 1.0), (3, 4.0, 1.5)]:
    ball.location.x, ball.scale = x, (size, size, size)
    ball.keyframe_insert("location", frame=frame)
    ball.keyframe_insert("scale", frame=frame)
scene = bpy.context.scene
scene.frame_start, scene.frame_end = 1, 3
before = set(bpy.data.objects.keys())
baked = bpy.ops.object.voxelkit_bake_frames(resolution=32, fill="solid")
[name] = set(bpy.data.objects.keys()) - before
sequence = bpy.data.objects[name].data
played = []
for frame in (1, 2, 3):
    scene.frame_set(frame)
    loaded = sequence.grids.load()
    path = bpy.path.abspath(sequence.grids.frame_filepath)
    grid = voxelkit.read_vdb(path)
    lo, hi = grid.index_to_world(list(grid.bbox))
    played.append({
        "frame": frame,
        "grid_frame": sequence.grids.frame,
        "loaded": loaded,
        "path": path,
        "voxel_size": grid.voxel_size,
        "origin": list(grid.origin),
        "centre": ((lo + hi) / 2).tolist(),
        "width": float(hi[0] - lo[0]),
        "location": list(ball.matrix_world.translation),
    })
print("FRAMES " + json.dumps({"operator": list(baked), "is_sequence": sequence.is_sequence, "played": played}))
operator = bpy.ops.object.voxelkit_voxelize.get_rna_type().properties
print("PROPERTIES " + json.dumps({
    name: {
        "default": operator[name].default,
        "items": [i.identifier for i in getattr(operator[name], "enum_items", [])],
        "description": [i.description for i in getattr(operator[name], "enum_items", [])],
    }
    for name in ("resolution", "voxel_size", "separability", "method", "fill")
}))
print("PANEL", hasattr(bpy.types, "VOXELKIT_PT_panel"), hasattr(bpy.types.Scene, "voxelkit"))
voxelkit.unregister()
print("UNREGISTERED", hasattr(bpy.types, "VOXELKIT_PT_panel"))
print("DONE")

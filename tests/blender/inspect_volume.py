# Run by tests/blender.rs inside headless Blender: imports a .vdb as a volume object and
# prints its grids and bounding box.
import bpy, sys
path = sys.argv[sys.argv.index("--") + 1]
bpy.ops.object.volume_import(filepath=path)
obj = bpy.context.selected_objects[0]
vol = obj.data
print("LOADED", vol.grids.load(), vol.grids.error_message)
for g in vol.grids:
    print("GRID", g.name, g.data_type, g.load())
print("BOUNDS", [tuple(round(c, 4) for c in v) for v in obj.bound_box][0], [tuple(round(c,4) for c in v) for v in obj.bound_box][6])

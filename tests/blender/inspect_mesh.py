# Run by tests/blender.rs inside headless Blender: imports a mesh file (.obj or .glb) and
# prints its counts, whether every edge joins two faces, and its volume.
import bmesh, bpy, sys
path = sys.argv[sys.argv.index("--") + 1]
if path.endswith(".obj"):
    bpy.ops.wm.obj_import(filepath=path)
else:
    # Blender 3.4's default shading guess calls numpy's removed np.bool (Debian 12's numpy).
    bpy.ops.import_scene.gltf(filepath=path, import_shading="SMOOTH")
obj = [o for o in bpy.context.selected_objects if o.type == "MESH"][0]
bm = bmesh.new()
bm.from_mesh(obj.data)
manifold = all(e.is_manifold for e in bm.edges) and all(v.is_manifold for v in bm.verts)
print("MESH", len(bm.verts), len(bm.faces), manifold, round(bm.calc_volume(signed=True), 6))

"""voxelkit in Blender: voxelize the active mesh object into a Volume object.

Enable it with ``import voxelkit.blender; voxelkit.blender.register()`` from a script, or
install the ``voxelkit`` package folder as an add-on (its ``bl_info`` and ``register`` are
in ``__init__``; the compiled module must match Blender's Python, 3.11 for Blender 3.4). The operator ``object.voxelkit_voxelize`` takes the evaluated mesh
(modifiers applied) in its world transform and Blender's axes, voxelizes it (a surface, a
solid, or a level set), writes a ``.vdb`` beside the ``.blend`` file (or in the temporary
folder for an unsaved file) and adds a Volume object placed exactly over the mesh, showing
its ``density`` grid. The panel is in Properties > Object > voxelkit.
"""

import os
import itertools
import tempfile

import bpy
import numpy as np
from bpy.props import EnumProperty, FloatProperty, IntProperty, PointerProperty

import voxelkit

# The mesh options the panel shows, with their choices and defaults, from the library's table.
MESH_OPTIONS = {f["name"]: f for f in voxelkit.OPTIONS["mesh"]["fields"]}


def _items(name, label):
    """An EnumProperty's items and default for the mesh option ``name``."""
    field = MESH_OPTIONS[name]
    items = [(str(c), label(c), field["doc"]) for c in field["choices"]]
    return items, str(field["default"])


SEPARABILITY = _items("separability", lambda c: f"{c}-separating")
METHOD = _items("method", lambda c: str(c).capitalize())
FILL = [
    ("none", "Surface", "The surface voxels"),
    ("solid", "Solid", "The surface and everything inside it (closed meshes)"),
    (
        "sdf",
        "Level set",
        "Exact signed distances within {:g} voxels (closed meshes)".format(
            next(f["default"] for f in voxelkit.OPTIONS["solid"]["fields"] if f["name"] == "band")
        ),
    ),
]


def _options(owner):
    """The settings shared by the operator and the panel's property group."""
    owner.__annotations__ = {
        "resolution": IntProperty(
            name="Resolution",
            description="Voxels along the longest side of the mesh's box",
            default=voxelkit.DEFAULT_RESOLUTION,
            min=1,
            max=65536,
        ),
        "voxel_size": FloatProperty(
            name="Voxel size",
            description="Edge of a voxel in world units (0: use the resolution)",
            default=0.0,
            min=0.0,
            precision=5,
        ),
        "separability": EnumProperty(
            name="Separability", items=SEPARABILITY[0], default=SEPARABILITY[1]
        ),
        "method": EnumProperty(name="Method", items=METHOD[0], default=METHOD[1]),
        "fill": EnumProperty(name="Fill", items=FILL, default="none"),
    }
    return owner


def world_mesh(obj, depsgraph):
    """The evaluated mesh of ``obj`` in world coordinates: (vertices, triangles)."""
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        mesh.calc_loop_triangles()
        co = np.empty(len(mesh.vertices) * 3, dtype=np.float64)
        mesh.vertices.foreach_get("co", co)
        tris = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int64)
        mesh.loop_triangles.foreach_get("vertices", tris)
    finally:
        evaluated.to_mesh_clear()
    m = np.array(obj.matrix_world, dtype=np.float64)
    vertices = co.reshape(-1, 3) @ m[:3, :3].T + m[:3, 3]
    return vertices, tris.reshape(-1, 3)


def voxelize(vertices, triangles, settings):
    """The voxelkit call the settings ask for."""
    fit = (
        {"voxel_size": settings.voxel_size}
        if settings.voxel_size > 0
        else {"resolution": settings.resolution}
    )
    source = (vertices, triangles)
    if settings.fill == "solid":
        return voxelkit.solid(source, **fit)
    if settings.fill == "sdf":
        return voxelkit.solid(source, sdf=True, **fit)
    return voxelkit.mesh(
        source, separability=int(settings.separability), method=settings.method, **fit
    )


def output_path(name):
    """Where the volume's file goes: beside the .blend, or in the temporary folder; named
    after `name`, numbered past every file a Volume of this .blend already reads, so that a
    bake never overwrites what another object shows."""
    folder = bpy.path.abspath("//voxelkit") if bpy.data.filepath else None
    folder = folder or os.path.join(tempfile.gettempdir(), "voxelkit-blender")
    os.makedirs(folder, exist_ok=True)
    used = {os.path.normpath(bpy.path.abspath(v.filepath)) for v in bpy.data.volumes if v.filepath}
    base = bpy.path.clean_name(name)
    for n in itertools.count(1):
        path = os.path.join(folder, base + (f"-{n}" if n > 1 else "") + ".vdb")
        if os.path.normpath(path) not in used:
            return path


@_options
class VOXELKIT_OT_voxelize(bpy.types.Operator):
    """Voxelize the active mesh object into a Volume object"""

    bl_idname = "object.voxelkit_voxelize"
    bl_label = "Voxelize with voxelkit"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        obj = context.active_object
        return obj is not None and obj.type == "MESH"

    def execute(self, context):
        obj = context.active_object
        vertices, triangles = world_mesh(obj, context.evaluated_depsgraph_get())
        if len(triangles) == 0:
            self.report({"ERROR"}, f"{obj.name} has no faces to voxelize")
            return {"CANCELLED"}
        try:
            grid = voxelize(vertices, triangles, self)
            path = output_path(f"{obj.name}-{self.fill}")
            grid.write(path)
        except (ValueError, MemoryError, OSError) as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        volume = bpy.data.volumes.new(f"{obj.name} voxels")
        volume.filepath = path
        volume_object = bpy.data.objects.new(f"{obj.name} voxels", volume)
        context.collection.objects.link(volume_object)
        report = grid.report
        self.report(
            {"INFO"},
            f"{report['voxels']} voxels of size {grid.voxel_size:.4g} in {path}",
        )
        return {"FINISHED"}


@_options
class VoxelkitSettings(bpy.types.PropertyGroup):
    """The panel's settings, kept with the scene."""


class VOXELKIT_PT_panel(bpy.types.Panel):
    bl_label = "voxelkit"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "object"

    @classmethod
    def poll(cls, context):
        return VOXELKIT_OT_voxelize.poll(context)

    def draw(self, context):
        settings = context.scene.voxelkit
        layout = self.layout
        for name in ("resolution", "voxel_size", "separability", "method", "fill"):
            layout.prop(settings, name)
        op = layout.operator(VOXELKIT_OT_voxelize.bl_idname)
        for name in ("resolution", "voxel_size", "separability", "method", "fill"):
            setattr(op, name, getattr(settings, name))


CLASSES = (VoxelkitSettings, VOXELKIT_OT_voxelize, VOXELKIT_PT_panel)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Scene.voxelkit = PointerProperty(type=VoxelkitSettings)


def unregister():
    del bpy.types.Scene.voxelkit
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)

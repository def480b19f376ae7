"""voxelkit in Blender: voxelize the active mesh object into a Volume object.

Enable it with ``import voxelkit.blender; voxelkit.blender.register()`` from a script, or
install the ``voxelkit`` package folder as an add-on (its ``bl_info`` and ``register`` are
in ``__init__``; the compiled module must match Blender's Python, 3.11 for Blender 3.4). The operator ``object.voxelkit_voxelize`` takes the evaluated mesh
(modifiers applied) in its world transform and Blender's axes, voxelizes it (a surface, a
solid, or a level set), writes a ``.vdb`` beside the ``.blend`` file (or in the temporary
folder for an unsaved file) and adds a Volume object placed exactly over the mesh, showing
its ``density`` grid. ``object.voxelkit_bake_frames`` does the same for every frame of a
range (the mesh as animated: armature, shape keys, modifiers, its own motion) on one grid
fitted to all frames, into a numbered ``.vdb`` sequence that the Volume object plays. Each
bake writes files of its own, never over a file another object reads. The panel is in
Properties > Object > voxelkit.
"""

import itertools
import os
import shutil
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
    """The settings shared by the operators and the panel's property group, beside the
    owner's own."""
    owner.__annotations__ = {
        **owner.__dict__.get("__annotations__", {}),
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


def settings_fit(settings):
    """The grid the settings ask for: a voxel size when given, else the resolution."""
    if settings.voxel_size > 0:
        return {"voxel_size": settings.voxel_size}
    return {"resolution": settings.resolution}


def voxelize(vertices, triangles, settings, fit=None):
    """The voxelkit call the settings ask for; ``fit`` (voxel_size and origin) places the
    grid instead of the settings' resolution or voxel size."""
    fit = fit or settings_fit(settings)
    source = (vertices, triangles)
    if settings.fill == "solid":
        return voxelkit.solid(source, **fit)
    if settings.fill == "sdf":
        return voxelkit.solid(source, sdf=True, **fit)
    return voxelkit.mesh(
        source, separability=int(settings.separability), method=settings.method, **fit
    )


def output_folder():
    """Where bakes go: beside the .blend, or in the temporary folder for an unsaved file."""
    folder = bpy.path.abspath("//voxelkit") if bpy.data.filepath else None
    folder = folder or os.path.join(tempfile.gettempdir(), "voxelkit-blender")
    os.makedirs(folder, exist_ok=True)
    return folder


def output_path(name):
    """Where the volume's file goes: in the output folder, named after `name`, numbered past
    every file a Volume of this .blend already reads, so that a bake never overwrites what
    another object shows."""
    folder = output_folder()
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


def new_sequence_folder(name):
    """A folder of its own for a frame sequence, made now: `name`, numbered past every one
    that exists."""
    base = os.path.join(output_folder(), bpy.path.clean_name(name))
    for n in itertools.count(1):
        folder = base + (f"-{n}" if n > 1 else "")
        try:
            os.makedirs(folder)
            return folder
        except FileExistsError:
            continue


def shared_fit(frames, settings):
    """One grid for every frame: where the library places the settings' grid for all frames'
    meshes taken as one."""
    offsets = np.cumsum([0] + [len(v) for v, _ in frames[:-1]])
    vertices = np.vstack([v for v, _ in frames])
    triangles = np.vstack([t + o for (_, t), o in zip(frames, offsets)])
    voxel_size, origin = voxelkit._voxelkit.placement((vertices, triangles), **settings_fit(settings))
    return {"voxel_size": voxel_size, "origin": origin}


@_options
class VOXELKIT_OT_bake_frames(bpy.types.Operator):
    """Voxelize the active mesh object at every frame of a range into a Volume object that
    plays the sequence"""

    bl_idname = "object.voxelkit_bake_frames"
    bl_label = "Bake frames with voxelkit"
    bl_options = {"REGISTER", "UNDO"}

    frame_start: IntProperty(name="First frame", description="The first frame baked (default: the scene's)", default=-1)
    frame_end: IntProperty(name="Last frame", description="The last frame baked (default: the scene's)", default=-1)

    @classmethod
    def poll(cls, context):
        return VOXELKIT_OT_voxelize.poll(context)

    def execute(self, context):
        scene, obj = context.scene, context.active_object
        first = self.frame_start if self.frame_start >= 0 else scene.frame_start
        last = self.frame_end if self.frame_end >= 0 else scene.frame_end
        if last < first:
            self.report({"ERROR"}, f"the last frame ({last}) comes before the first ({first})")
            return {"CANCELLED"}
        shown = scene.frame_current
        frames = []
        try:
            for frame in range(first, last + 1):
                scene.frame_set(frame)
                frames.append(world_mesh(obj, context.evaluated_depsgraph_get()))
        finally:
            scene.frame_set(shown)
        if any(len(t) == 0 for _, t in frames):
            self.report({"ERROR"}, f"{obj.name} has no faces to voxelize at some frame")
            return {"CANCELLED"}
        folder = new_sequence_folder(f"{obj.name}-{self.fill}-frames")
        fit = shared_fit(frames, self)
        paths, voxels = [], 0
        window_manager = context.window_manager
        window_manager.progress_begin(0, len(frames))
        try:
            for i, (frame, (vertices, triangles)) in enumerate(zip(range(first, last + 1), frames)):
                grid = voxelize(vertices, triangles, self, fit)
                # Blender reads the number at the end of the name as the frame.
                paths.append(os.path.join(folder, f"{bpy.path.clean_name(obj.name)}_{frame:04d}.vdb"))
                grid.write(paths[-1])
                voxels += len(grid)
                window_manager.progress_update(i + 1)
        except (ValueError, MemoryError, OSError) as e:
            shutil.rmtree(folder, ignore_errors=True)
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        finally:
            window_manager.progress_end()
        volume = bpy.data.volumes.new(f"{obj.name} voxels {first}-{last}")
        volume.filepath = paths[0]
        volume.is_sequence = True
        volume.frame_start = first
        volume.frame_duration = len(paths)
        # File number n plays at frame frame_start + n - 1 - offset: the files are numbered by frame.
        volume.frame_offset = first - 1
        volume.sequence_mode = "CLIP"
        volume_object = bpy.data.objects.new(volume.name, volume)
        context.collection.objects.link(volume_object)
        self.report(
            {"INFO"},
            f"{len(paths)} frames, {voxels} voxels of size {fit['voxel_size']:.4g} in {folder}",
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
        for operator in (VOXELKIT_OT_voxelize, VOXELKIT_OT_bake_frames):
            op = layout.operator(operator.bl_idname)
            for name in ("resolution", "voxel_size", "separability", "method", "fill"):
                setattr(op, name, getattr(settings, name))


CLASSES = (VoxelkitSettings, VOXELKIT_OT_voxelize, VOXELKIT_OT_bake_frames, VOXELKIT_PT_panel)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Scene.voxelkit = PointerProperty(type=VoxelkitSettings)


def unregister():
    del bpy.types.Scene.voxelkit
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)

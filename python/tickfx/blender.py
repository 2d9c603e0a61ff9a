"""tickfx in Blender: import a folder of tickfx caches as one point object that follows the
scene's frame, every attribute a point attribute.

Register it with `import tickfx.blender; tickfx.blender.register()` (what the add-on zip's
__init__ does), or from the command line:
    blender -b --python-expr "import tickfx.blender as b; b.register()"
File > Import > tickfx cache sequence then reads `frame_N.vdb`, `.ply` or `.csv` (by the first
of these formats the folder has) through tickfx.read_cache.

The object's mesh holds the frame's points (no edges, no faces) and, as point attributes under
Houdini's names: v (FLOAT_VECTOR, m/s), id (INT: the id's low 32 bits, ids past 2^31 wrap, as
Blender has no 64-bit integer attribute), age, life, mass (FLOAT), Cd (FLOAT_COLOR), Alpha and
pscale (FLOAT), the hit attributes and custom attributes (FLOAT, INT, FLOAT_VECTOR as read_cache
gives them). Geometry nodes can instance on the points by pscale and colour by Cd. A frame
handler reloads the frame on every frame change; frames outside the caches show the nearest.
Memory: one frame's arrays at a time.
"""
import os
import re

import numpy as np

import tickfx

bl_info = {
    "name": "tickfx cache sequence",
    "author": "tickfx",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "File > Import > tickfx cache sequence",
    "description": "Point caches of tickfx runs, every attribute, following the frame",
    "category": "Import-Export",
}

_FRAME_FILE = re.compile(r"^frame_(\d+)\.(vdb|ply|csv)$")
_FORMATS = ("vdb", "ply", "csv")  # the first the folder has is read
_SEQUENCE_KEY = "tickfx_cache_folder"


class SequenceError(ValueError):
    """A folder that is not a cache sequence: no caches, gaps in the frame numbers."""


def scan_sequence(folder):
    """(format, {frame: path}) of the cache files in `folder`, frames contiguous; SequenceError
    naming the folder otherwise."""
    if not os.path.isdir(folder):
        raise SequenceError(f"{folder}: not a folder")
    found = {fmt: {} for fmt in _FORMATS}
    for name in os.listdir(folder):
        m = _FRAME_FILE.match(name)
        if m:
            found[m.group(2)][int(m.group(1))] = os.path.join(folder, name)
    for fmt in _FORMATS:
        frames = found[fmt]
        if not frames:
            continue
        first, last = min(frames), max(frames)
        missing = [f for f in range(first, last + 1) if f not in frames]
        if missing:
            raise SequenceError(f"{folder}: frame_{missing[0]:04d}.{fmt} is missing "
                                f"(frames {first} to {last} expected without gaps)")
        return fmt, frames
    raise SequenceError(f"{folder}: no tickfx caches (expected frame_0001.vdb, .ply or .csv)")


def _attribute_type(array):
    if array.ndim == 2:
        return "FLOAT_VECTOR"
    if np.issubdtype(array.dtype, np.integer):
        return "INT"
    return "FLOAT"


def fill_mesh(mesh, columns):
    """Replaces `mesh`'s geometry with the points and attributes of `columns` (read_cache's
    dict)."""
    points = columns["P"]
    mesh.clear_geometry()
    for name in [a.name for a in mesh.attributes if not a.name.startswith(".")]:
        if name != "position":
            mesh.attributes.remove(mesh.attributes[name])
    mesh.vertices.add(len(points))
    mesh.vertices.foreach_set("co", np.ascontiguousarray(points, dtype=np.float32).ravel())
    for name, array in columns.items():
        if name == "P":
            continue
        if name == "id":
            array = (array.astype(np.int64) & 0xFFFFFFFF).astype(np.uint32).view(np.int32)
        if name == "Cd":
            attribute = mesh.attributes.new("Cd", "FLOAT_COLOR", "POINT")
            rgba = np.ones((len(points), 4), dtype=np.float32)
            rgba[:, :3] = array
            attribute.data.foreach_set("color", rgba.ravel())
            continue
        kind = _attribute_type(array)
        attribute = mesh.attributes.new(name, kind, "POINT")
        key = "vector" if kind == "FLOAT_VECTOR" else "value"
        data = array.astype(np.int32 if kind == "INT" else np.float32)
        attribute.data.foreach_set(key, np.ascontiguousarray(data).ravel())
    mesh.update()


def load_frame(obj, frame):
    """Shows frame `frame` (clamped to the sequence) of the cache folder of `obj`."""
    fmt, frames = scan_sequence(obj[_SEQUENCE_KEY])
    frame = min(max(frame, min(frames)), max(frames))
    fill_mesh(obj.data, tickfx.read_cache(frames[frame]))
    obj["tickfx_frame"] = frame


def _on_frame_change(scene, *args):
    for obj in scene.objects:
        if _SEQUENCE_KEY in obj.keys():
            load_frame(obj, scene.frame_current)


def import_sequence(context, folder):
    """Makes the object of the cache sequence in `folder`, at the scene's frame, and sets the
    scene's frame range to the caches'. SequenceError or tickfx.CacheError before anything is
    made when the folder or its first frame cannot be read (no half-built object)."""
    import bpy

    fmt, frames = scan_sequence(folder)
    first = tickfx.read_cache(frames[min(frames)])  # fails before anything is made
    name = os.path.basename(os.path.normpath(folder)) or "tickfx"
    mesh = bpy.data.meshes.new(name)
    fill_mesh(mesh, first)
    obj = bpy.data.objects.new(name, mesh)
    obj[_SEQUENCE_KEY] = os.path.abspath(folder)
    context.scene.collection.objects.link(obj)
    context.scene.frame_start = min(frames)
    context.scene.frame_end = max(frames)
    load_frame(obj, context.scene.frame_current)
    return obj


def _operator_class():
    import bpy
    from bpy.props import StringProperty

    class ImportCacheSequence(bpy.types.Operator):
        """Import a folder of tickfx caches as points that follow the frame"""

        bl_idname = "import_scene.tickfx_cache_sequence"
        bl_label = "tickfx cache sequence"
        bl_options = {"REGISTER", "UNDO"}

        directory: StringProperty(subtype="DIR_PATH")

        def execute(self, context):
            try:
                import_sequence(context, self.directory)
            except (SequenceError, tickfx.CacheError, ValueError) as e:
                self.report({"ERROR"}, str(e))
                return {"CANCELLED"}
            return {"FINISHED"}

        def invoke(self, context, event):
            context.window_manager.fileselect_add(self)
            return {"RUNNING_MODAL"}

    return ImportCacheSequence


_classes = []


def _menu(self, context):
    self.layout.operator("import_scene.tickfx_cache_sequence", text="tickfx cache sequence")


def register():
    import bpy

    if _classes:
        return
    _classes.append(_operator_class())
    for cls in _classes:
        bpy.utils.register_class(cls)
    bpy.types.TOPBAR_MT_file_import.append(_menu)
    if _on_frame_change not in bpy.app.handlers.frame_change_post:
        bpy.app.handlers.frame_change_post.append(_on_frame_change)


def unregister():
    import bpy

    if _on_frame_change in bpy.app.handlers.frame_change_post:
        bpy.app.handlers.frame_change_post.remove(_on_frame_change)
    bpy.types.TOPBAR_MT_file_import.remove(_menu)
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
    _classes.clear()

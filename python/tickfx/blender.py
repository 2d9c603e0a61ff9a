"""tickfx in Blender: import a folder of tickfx caches as one point object that follows the
scene's frame, every attribute a point attribute.

Register it with `import tickfx.blender; tickfx.blender.register()`, or install the add-on zip
that `scripts/blender-addon` (write_addon_zip()) makes through Edit > Preferences > Add-ons >
Install (its __init__ registers this module), or from the command line:
    blender -b --python-expr "import tickfx.blender as b; b.register()"
File > Import > tickfx cache sequence then reads `frame_N.vdb`, `.ply` or `.csv` (by the first
of these formats the folder has) through tickfx.read_cache.

The object's mesh holds the frame's points (no edges, no faces) and, as point attributes under
Houdini's names: v (FLOAT_VECTOR, m/s), id (INT: the id's low 32 bits, ids past 2^31 wrap, as
Blender has no 64-bit integer attribute), age, life, mass (FLOAT), Cd (FLOAT_COLOR), Alpha and
pscale (FLOAT), the hit attributes and custom attributes (FLOAT, INT, FLOAT_VECTOR as read_cache
gives them). Geometry nodes can instance on the points by pscale and colour by Cd. A frame
handler reloads the frame on every frame change; frames outside the caches show the nearest.
Import reads every file once first, so a corrupt file or caches of different effects (VDB
caches record the effect's hash) are refused before anything is made, and sets the scene's
frame range and frame rate from the caches (the times VDB and PLY caches record).
Memory: one frame's arrays at a time.

The panel in the 3D view's sidebar (tab "tickfx") runs an effect file in Blender: its lint
warnings are reported, then it runs through tickfx.load_effect and advance() at the scene's frame
rate, frames at their own time, from frame 1 to the scene's end frame, each frame captured.
The object shows the captured frame on every frame change, as an imported sequence does.
Memory: every captured frame, about 40 bytes a particle a frame plus 4 an attribute.
"""
import os
import re
from fractions import Fraction

import numpy as np

import tickfx

from tickfx.blender_addon import bl_info, write_addon_zip  # noqa: F401 (the add-on's face)

_FRAME_FILE = re.compile(r"^frame_(\d+)\.(vdb|ply|csv)$")
_FORMATS = ("vdb", "ply", "csv")  # the first the folder has is read
_SEQUENCE_KEY = "tickfx_cache_folder"
_EFFECT_KEY = "tickfx_effect"
_runs = {}  # object name → the captured frames of its effect run, frame 1 first


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
        elif _EFFECT_KEY in obj.keys() and obj.name in _runs:
            frames = _runs[obj.name]
            fill_mesh(obj.data, frames[min(max(scene.frame_current, 1), len(frames)) - 1])


def scene_frame(scene):
    """One frame of `scene` in seconds, exact: 1/24, 1001/30000 for 29.97 (fps_base is a float
    close to 1.001)."""
    base = Fraction(scene.render.fps_base).limit_denominator(1001)
    return base / scene.render.fps


def run_effect(context, path, report=None):
    """Runs the effect file at `path` from frame 1 to the scene's end frame at the scene's frame
    rate, capturing each frame, and makes the object that shows them. Its lint warnings go to
    `report(level, text)`. tickfx.EffectError before anything is made for an effect with errors."""
    for line in tickfx.check(path):
        if report is not None:
            report({"WARNING"}, line)
    system = tickfx.load_effect(path)
    frame = scene_frame(context.scene)
    frames = []
    for _ in range(max(1, context.scene.frame_end)):
        system.advance(frame)
        frames.append(system.capture())
    obj = _points_object(context, os.path.splitext(os.path.basename(path))[0], frames[0],
                         _EFFECT_KEY, os.path.abspath(path))
    _runs[obj.name] = frames
    _on_frame_change(context.scene)
    return obj


def _points_object(context, name, columns, key, source):
    """A new object in the scene whose mesh shows `columns`, marked with `key` = `source`."""
    import bpy

    mesh = bpy.data.meshes.new(name)
    fill_mesh(mesh, columns)
    obj = bpy.data.objects.new(name, mesh)
    obj[key] = source
    context.scene.collection.objects.link(obj)
    return obj


def check_sequence(folder):
    """(format, {frame: path}, rate) of the cache sequence in `folder` once every file has been
    read (tickfx.cache_info): its frames per second as a Fraction (None when the files record no
    time: CSV, or a single frame). SequenceError naming the file when the files come from
    different effects (their tickfx_effect_hash differs: VDB caches record it) or a file's own
    frame number is not its name's; tickfx.CacheError naming the file when one is corrupt."""
    fmt, frames = scan_sequence(folder)
    infos = {f: tickfx.cache_info(path) for f, path in sorted(frames.items())}
    first = min(frames)
    for f, info in infos.items():
        name = os.path.basename(frames[f])
        hashes = (infos[first]["effect_hash"], info["effect_hash"])
        if hashes[0] != hashes[1]:
            raise SequenceError(f"{frames[f]}: another effect's cache (effect hash {hashes[1]}; "
                                f"{os.path.basename(frames[first])} has {hashes[0]})")
        if info["frame"] is not None and info["frame"] != f:
            raise SequenceError(f"{frames[f]}: holds frame {info['frame']}, not {f} ({name})")
    rate = None
    last = max(frames)
    if last > first and infos[first]["time"] is not None:
        span = Fraction(infos[last]["time"]) - Fraction(infos[first]["time"])
        if span > 0:  # the times were written as doubles: 1/24, 1001/30000 within 1e-12
            rate = (Fraction(last - first) / span).limit_denominator(1001)
    return fmt, frames, rate


def set_scene_rate(scene, rate):
    """Sets `scene`'s frame rate to `rate` frames per second (a Fraction) as Blender spells it:
    24 as fps 24, base 1; 30000/1001 as fps 30, base 1.001."""
    fps = -(-rate.numerator // rate.denominator)  # the whole rate at or above it
    scene.render.fps = fps
    scene.render.fps_base = float(Fraction(fps) / rate)


def import_sequence(context, folder):
    """Makes the object of the cache sequence in `folder`, at the scene's frame, and sets the
    scene's frame range and frame rate to the caches'. Every file is read first (check_sequence):
    SequenceError or tickfx.CacheError before anything is made (no half-built object)."""
    fmt, frames, rate = check_sequence(folder)
    first = tickfx.read_cache(frames[min(frames)])
    obj = _points_object(context, os.path.basename(os.path.normpath(folder)) or "tickfx", first,
                         _SEQUENCE_KEY, os.path.abspath(folder))
    context.scene.frame_start = min(frames)
    context.scene.frame_end = max(frames)
    if rate is not None:
        set_scene_rate(context.scene, rate)
    load_frame(obj, context.scene.frame_current)
    return obj


def _blender_classes():
    import bpy
    from bpy.props import StringProperty

    class PickThenAct:
        """A file browser, then act(): an error is reported in Blender's UI and nothing is
        left made (each action fails before it makes anything)."""

        bl_options = {"REGISTER", "UNDO"}

        def execute(self, context):
            try:
                self.act(context)
            except (tickfx.CacheError, ValueError, OSError) as e:  # EffectError, SequenceError
                self.report({"ERROR"}, str(e))
                return {"CANCELLED"}
            return {"FINISHED"}

        def invoke(self, context, event):
            context.window_manager.fileselect_add(self)
            return {"RUNNING_MODAL"}

    class ImportCacheSequence(PickThenAct, bpy.types.Operator):
        """Import a folder of tickfx caches as points that follow the frame"""

        bl_idname = "import_scene.tickfx_cache_sequence"
        bl_label = "tickfx cache sequence"

        directory: StringProperty(subtype="DIR_PATH")

        def act(self, context):
            import_sequence(context, self.directory)

    class RunEffect(PickThenAct, bpy.types.Operator):
        """Run a tickfx effect file at the scene's frame rate and show its frames"""

        bl_idname = "object.tickfx_run_effect"
        bl_label = "Run a tickfx effect"

        filepath: StringProperty(subtype="FILE_PATH")
        filter_glob: StringProperty(default="*.toml", options={"HIDDEN"})

        def act(self, context):
            run_effect(context, self.filepath, self.report)

    class EffectPanel(bpy.types.Panel):
        bl_idname = "VIEW3D_PT_tickfx"
        bl_label = "tickfx"
        bl_space_type = "VIEW_3D"
        bl_region_type = "UI"
        bl_category = "tickfx"

        def draw(self, context):
            self.layout.operator("object.tickfx_run_effect", text="Run an effect file")
            self.layout.operator("import_scene.tickfx_cache_sequence", text="Import caches")

    return [ImportCacheSequence, RunEffect, EffectPanel]


_classes = []


def _menu(self, context):
    self.layout.operator("import_scene.tickfx_cache_sequence", text="tickfx cache sequence")


def register():
    import bpy

    if _classes:
        return
    _classes.extend(_blender_classes())
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

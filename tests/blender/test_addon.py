# The Blender add-on (tickfx.blender) in Debian's Blender, headless:
#   blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_addon.py -- \
#       TICKFX_CLI SAMPLES_DIR WORK_DIR
# The fountain's VDB caches imported as one object: at frames 1, 12 and 24 its vertices and
# attributes equal tickfx.read_cache of the same files, a frame change updates them, the scene
# takes the caches' frame range and rate, and folders that are not one sequence (empty, a gap,
# a corrupt file, caches of two effects) are refused by name with no object left behind.
import os
import shutil
import subprocess
import sys

import bpy
import numpy as np

import tickfx
import tickfx.blender

cli, samples, work = sys.argv[sys.argv.index("--") + 1:][:3]
shutil.rmtree(work, ignore_errors=True)
caches = os.path.join(work, "fountain")
subprocess.run([cli, "run", os.path.join(samples, "fountain.toml"), "--frames", "24",
                "--format", "vdb", "--out", caches, "--quiet"], check=True)

tickfx.blender.register()
scene = bpy.context.scene
objects_before = set(bpy.data.objects.keys())
assert bpy.ops.import_scene.tickfx_cache_sequence(directory=caches) == {"FINISHED"}
obj = bpy.data.objects["fountain"]
assert (scene.frame_start, scene.frame_end) == (1, 24), (scene.frame_start, scene.frame_end)
assert (scene.render.fps, scene.render.fps_base) == (24, 1.0), scene.render.fps
print(f"imported {obj.name}: frames {scene.frame_start} to {scene.frame_end} at "
      f"{scene.render.fps} fps")


def attribute(mesh, name, width):
    a = mesh.attributes[name]
    key = {"FLOAT_VECTOR": "vector", "FLOAT_COLOR": "color"}.get(a.data_type, "value")
    dtype = np.int32 if a.data_type == "INT" else np.float32
    out = np.empty(len(mesh.vertices) * width, dtype=dtype)
    a.data.foreach_get(key, out)
    return out.reshape(-1, width) if width > 1 else out


counts = {}
for frame in (1, 12, 24):
    scene.frame_set(frame)
    expected = tickfx.read_cache(os.path.join(caches, f"frame_{frame:04d}.vdb"))
    mesh = obj.data
    n = len(expected["P"])
    assert len(mesh.vertices) == n, (frame, len(mesh.vertices), n)
    co = np.empty(n * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", co)
    assert np.array_equal(co.reshape(-1, 3), expected["P"]), frame
    assert np.array_equal(attribute(mesh, "v", 3), expected["v"]), frame
    for name in ("age", "life", "mass"):
        assert np.array_equal(attribute(mesh, name, 1), expected[name]), (frame, name)
    ids = attribute(mesh, "id", 1).view(np.uint32).astype(np.int64)
    assert np.array_equal(ids, expected["id"] & 0xFFFFFFFF), frame
    counts[frame] = n
    print(f"frame {frame}: {n} points, P, v, id, age, life, mass equal read_cache")
assert counts[1] < counts[12] < counts[24], counts  # the frame change reloaded the points

# Not a sequence: refused by name, nothing left behind.
empty = os.path.join(work, "empty")
os.makedirs(empty)
gap = os.path.join(work, "gap")
shutil.copytree(caches, gap)
os.remove(os.path.join(gap, "frame_0005.vdb"))
corrupt = os.path.join(work, "corrupt")
os.makedirs(corrupt)
with open(os.path.join(corrupt, "frame_0001.vdb"), "wb") as f:
    f.write(b"not a vdb")
# Frame 3 of the same effect with another seed: another effect hash.
mixed = os.path.join(work, "mixed")
shutil.copytree(caches, mixed)
other = os.path.join(work, "other")
subprocess.run([cli, "run", os.path.join(samples, "fountain.toml"), "--frames", "3",
                "--format", "vdb", "--out", other, "--set", "simulation.seed=2", "--quiet"],
               check=True)
shutil.copy(os.path.join(other, "frame_0003.vdb"), os.path.join(mixed, "frame_0003.vdb"))
# A corrupt file past the first frame is found at import too, before anything is made.
late = os.path.join(work, "late")
shutil.copytree(caches, late)
with open(os.path.join(late, "frame_0020.vdb"), "r+b") as f:
    f.truncate(200)
for folder, message in ((empty, "no tickfx caches"), (gap, "frame_0005.vdb is missing"),
                        (corrupt, "frame_0001.vdb"),
                        (mixed, "frame_0003.vdb: another effect's cache"),
                        (late, "frame_0020.vdb")):
    try:
        bpy.ops.import_scene.tickfx_cache_sequence(directory=folder)
        raise AssertionError(f"{folder} imported")
    except RuntimeError as e:
        assert message in str(e), str(e)
        print(f"refused {os.path.basename(folder)}: {str(e).strip()}")
assert set(bpy.data.objects.keys()) == objects_before | {"fountain"}, bpy.data.objects.keys()

# Run the effect in Blender at the scene's rate: frame f shows what a System advanced by f frames
# of the scene captures, bit for bit.
scene.render.fps, scene.render.fps_base = 24, 1.0
scene.frame_end = 12
effect = os.path.join(samples, "fountain.toml")
assert bpy.ops.object.tickfx_run_effect(filepath=effect) == {"FINISHED"}
ran = bpy.data.objects["fountain.001"]
system = tickfx.load_effect(effect)
for frame in range(1, 13):
    system.advance(tickfx.blender.scene_frame(scene))
    if frame in (1, 12):
        scene.frame_set(frame)
        expected = system.capture()
        co = np.empty(len(ran.data.vertices) * 3, dtype=np.float32)
        ran.data.vertices.foreach_get("co", co)
        assert np.array_equal(co.reshape(-1, 3), expected["P"]), frame
        assert np.array_equal(attribute(ran.data, "age", 1), expected["age"]), frame
        print(f"run frame {frame}: {len(expected['P'])} points equal capture()")
scene.render.fps, scene.render.fps_base = 30, 1.001
assert tickfx.blender.scene_frame(scene) == tickfx.blender.Fraction(1001, 30000)

# Caches written at 30000/1001 fps set the scene to Blender's 29.97: fps 30, base 1.001.
ntsc = os.path.join(work, "ntsc")
subprocess.run([cli, "run", os.path.join(samples, "fountain.toml"), "--frames", "5",
                "--fps", "30000/1001", "--format", "vdb", "--out", ntsc, "--quiet"], check=True)
scene.render.fps, scene.render.fps_base = 24, 1.0
assert bpy.ops.import_scene.tickfx_cache_sequence(directory=ntsc) == {"FINISHED"}
assert scene.render.fps == 30 and abs(scene.render.fps_base - 1.001) < 1e-6  # a float32
assert tickfx.blender.scene_frame(scene) == tickfx.blender.Fraction(1001, 30000)
print(f"imported ntsc: {scene.render.fps} fps, base {scene.render.fps_base:.3f}")

# The add-on zip, installed and enabled as a user would (into BLENDER_USER_SCRIPTS, which the
# test points at its own folder), registers the same operators.
tickfx.blender.unregister()
assert not hasattr(bpy.types, "IMPORT_SCENE_OT_tickfx_cache_sequence")
archive = os.path.join(work, "tickfx_blender.zip")
tickfx.blender.write_addon_zip(archive)
assert bpy.ops.preferences.addon_install(filepath=archive) == {"FINISHED"}
assert bpy.ops.preferences.addon_enable(module="tickfx_blender") == {"FINISHED"}
assert hasattr(bpy.types, "IMPORT_SCENE_OT_tickfx_cache_sequence")
assert hasattr(bpy.types, "OBJECT_OT_tickfx_run_effect")
print("add-on zip: installed and enabled")
print("tickfx.blender: all checks passed")

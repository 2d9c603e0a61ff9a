"""The Blender add-on's face: bl_info and the zip Blender installs. Standard library only, so
that scripts/blender-addon writes the zip without the tickfx extension built."""

bl_info = {
    "name": "tickfx cache sequence",
    "author": "tickfx",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "File > Import > tickfx cache sequence",
    "description": "Point caches of tickfx runs, every attribute, following the frame",
    "category": "Import-Export",
}


def write_addon_zip(path):
    """Writes the add-on Blender installs (Edit > Preferences > Add-ons > Install): a zip of the
    package `tickfx_blender`, whose __init__ holds bl_info (Blender reads it without running the
    file) and registers tickfx.blender. The tickfx package itself must be on Blender's sys.path
    (cmake --install puts it there)."""
    import pprint
    import zipfile

    init = (
        '"""tickfx cache sequences and effect runs in Blender: see tickfx.blender."""\n'
        f"bl_info = {pprint.pformat(bl_info)}\n\n\n"
        "def register():\n    import tickfx.blender\n\n    tickfx.blender.register()\n\n\n"
        "def unregister():\n    import tickfx.blender\n\n    tickfx.blender.unregister()\n"
    )
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("tickfx_blender/__init__.py", init)

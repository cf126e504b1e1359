"""The screenshot of docs/blender.md: the noisy bunny faired in Blender, the operator's Adjust
Last Operation panel open and its report in the status bar.

    scripts/build_blender_addon.sh
    BLENDER_USER_SCRIPTS=$(mktemp -d) xvfb-run -a -s "-screen 0 1280x800x24" \\
        blender --factory-startup --python blender/screenshot_panel.py -- \\
        target/fairmesh_blender.zip docs/blender_panel.png

Blender opens a real window (under Xvfb), installs the zip, runs Fair Mesh from the 3D view as
a click would, waits for it to finish, saves the window and quits.
"""

import os
import sys

import bpy
import numpy as np

arguments = sys.argv[sys.argv.index("--") + 1:]
ZIP, OUTPUT = os.path.abspath(arguments[0]), os.path.abspath(arguments[1])

bpy.context.preferences.view.show_splash = False
bpy.ops.preferences.addon_install(filepath=ZIP, overwrite=True)
bpy.ops.preferences.addon_enable(module="fairmesh_blender")
import fairmesh  # noqa: E402  (the add-on's own copy)

for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj)
bunny = fairmesh.load("@bunny")
faces = np.asarray(bunny.faces, dtype=np.int64)
noisy = fairmesh.noise(bunny.vertices, faces, sigma=0.3, seed=1).astype(np.float32)
mesh = bpy.data.meshes.new("Bunny")
mesh.vertices.add(len(noisy))
mesh.vertices.foreach_set("co", noisy.reshape(-1))
mesh.loops.add(faces.size)
mesh.loops.foreach_set("vertex_index", faces.astype(np.int32).reshape(-1))
mesh.polygons.add(len(faces))
mesh.polygons.foreach_set("loop_start", np.arange(0, faces.size, 3, dtype=np.int32))
mesh.polygons.foreach_set("loop_total", np.full(len(faces), 3, dtype=np.int32))
mesh.update(calc_edges=True)
obj = bpy.data.objects.new("Bunny", mesh)
bpy.context.scene.collection.objects.link(obj)
# The bunny's file is y-up: stand it on Blender's floor (z-up).
obj.rotation_euler = (np.pi / 2, 0.0, 0.0)
obj.select_set(True)
bpy.context.view_layer.objects.active = obj


def view3d():
    window = bpy.context.window_manager.windows[0]
    for area in window.screen.areas:
        if area.type == 'VIEW_3D':
            region = next(r for r in area.regions if r.type == 'WINDOW')
            return window, area, region
    raise RuntimeError("no 3D view")


def fair():
    window, area, region = view3d()
    with bpy.context.temp_override(window=window, area=area, region=region):
        bpy.ops.view3d.view_axis(type='FRONT')
        bpy.ops.view3d.view_orbit(angle=0.5, type='ORBITRIGHT')
        bpy.ops.view3d.view_selected()
        bpy.ops.object.fairmesh_fair('INVOKE_DEFAULT', start_level=2)
    bpy.app.timers.register(wait_for_the_run, first_interval=1.0)


def wait_for_the_run():
    if not bpy.context.window_manager.operators or \
            bpy.context.window_manager.operators[-1].bl_idname != "OBJECT_OT_fairmesh_fair":
        return 1.0  # still running
    bpy.app.timers.register(open_panel, first_interval=0.5)
    return None


def open_panel():
    """Adjust Last Operation as F9 opens it, at the top left of the 3D view."""
    window, area, region = view3d()
    with bpy.context.temp_override(window=window, area=area, region=region):
        window.cursor_warp(area.x + 260, area.y + area.height - 120)
        bpy.ops.screen.redo_last('INVOKE_DEFAULT')
    bpy.app.timers.register(shoot, first_interval=1.0)


def shoot():
    window, area, region = view3d()
    with bpy.context.temp_override(window=window, area=area, region=region):
        bpy.ops.screen.screenshot(filepath=OUTPUT)
    print(f"screenshot_panel: {OUTPUT}")
    bpy.ops.wm.quit_blender()


bpy.app.timers.register(fair, first_interval=2.0)

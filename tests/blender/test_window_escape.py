"""Esc stops a run started from the window, and the mesh stays as it was.

Needs a window: scripts/test_blender.sh runs it under Xvfb as
``blender --factory-startup --enable-event-simulate --python tests/blender/test_window_escape.py -- ZIP``.
Fair Mesh is invoked from the 3D view as a click would (its work on a thread, the window
responsive), Esc is pressed at once, and the script checks what the run reported and that no
vertex moved. It exits 0 when that holds, 1 otherwise.
"""

import os
import sys
import traceback

import bpy
import numpy as np

ZIP = os.path.abspath(sys.argv[sys.argv.index("--") + 1])
WAIT_S = 120


def finish(ok, message):
    print(f"{'PASS' if ok else 'FAIL'} esc_stops_the_run_and_nothing_changes: {message}")
    print(f"{int(ok)} passed, {int(not ok)} failed")
    sys.stdout.flush()
    os._exit(0 if ok else 1)


try:
    bpy.context.preferences.view.show_splash = False
    bpy.ops.preferences.addon_install(filepath=ZIP, overwrite=True)
    bpy.ops.preferences.addon_enable(module="fairmesh_blender")
    import fairmesh  # noqa: E402  (the add-on's own copy)
    from fairmesh_blender import operator as addon_operator  # noqa: E402

    # A noisy sphere of 40k vertices, 200 rounds asked: a run of many progress reports.
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=7)
    obj = bpy.context.object
    mesh = obj.data
    count = len(mesh.vertices)
    start = np.empty(count * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", start)
    mesh.calc_loop_triangles()
    faces = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", faces)
    faces = faces.reshape(-1, 3)
    noisy = fairmesh.noise(start.reshape(-1, 3), faces, sigma=0.3, seed=1).astype(np.float32)
    mesh.vertices.foreach_set("co", noisy.reshape(-1))
    mesh.update()
except Exception:
    traceback.print_exc()
    finish(False, "setting up failed")

waited = [0.0]


def start_and_press_escape():
    try:
        window = bpy.context.window_manager.windows[0]
        area = next(a for a in window.screen.areas if a.type == 'VIEW_3D')
        region = next(r for r in area.regions if r.type == 'WINDOW')
        with bpy.context.temp_override(window=window, area=area, region=region):
            started = bpy.ops.object.fairmesh_fair('INVOKE_DEFAULT', denoise='ROUNDS',
                                                   rounds=200)
        if started != {'RUNNING_MODAL'}:
            finish(False, f"the run did not start on its thread: {started}")
        window.event_simulate('ESC', 'PRESS')
        window.event_simulate('ESC', 'RELEASE')
    except Exception:
        traceback.print_exc()
        finish(False, "starting the run failed")
    bpy.app.timers.register(check, first_interval=0.5)


def check():
    if not addon_operator.last_reports:
        waited[0] += 0.5
        if waited[0] > WAIT_S:
            finish(False, f"no report after {WAIT_S} s")
        return 0.5
    after = np.empty(count * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", after)
    reports = addon_operator.last_reports
    if reports != [('WARNING', "Cancelled: nothing changed")]:
        finish(False, f"reported {reports}")
    if not np.array_equal(after, noisy.reshape(-1)):
        finish(False, "a vertex moved")
    finish(True, "cancelled, no vertex moved")


bpy.app.timers.register(start_and_press_escape, first_interval=1.0)

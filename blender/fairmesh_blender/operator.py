"""The operator ``object.fairmesh_fair`` (Fair Mesh): fairs the selected mesh objects' mesh
data, in Object or Edit mode, as one undo step.

Run from a menu or F3 (``invoke``), the work runs on a thread of its own while the window shows
the progress on the cursor; Esc stops it and nothing changes. Run again from the Adjust Last
Operation panel or from a script (``execute``), it runs at once; a change of Start Level there
costs the multires run alone, as the hierarchy of the unchanged mesh is kept (``work.kept``).
"""

import math
import threading

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, StringProperty

import fairmesh

from . import mesh_data, work

DENOISE_ITEMS = [
    ('AUTO', "Automatic",
     "Estimate the noise and remove it round by round while the estimated error falls "
     "(a clean mesh is left as it is)"),
    ('ROUNDS', "Rounds", "Remove noise with exactly the number of rounds given"),
    ('OFF', "Off", "Remove no noise first: only the start level's smoothing"),
]

BOUNDARY_ITEMS = [
    ('CURVE', "Curve", "Smooth each open boundary as a curve"),
    ('FIXED', "Fixed", "Keep open boundaries exactly where they are"),
]


#: What the last run reported, as (level, message) pairs: 'INFO' (what the automatic strength
#: found), 'WARNING' (what was skipped or left as it was) or 'ERROR'. Scripts read it; Blender
#: shows the same in the status bar and the Info editor.
last_reports = []


class OBJECT_OT_fairmesh_fair(bpy.types.Operator):
    """Remove noise and unwanted detail from the selected meshes without shrinking them
    (fairmesh's constrained fairing)"""

    bl_idname = "object.fairmesh_fair"
    bl_label = "Fair Mesh"
    bl_options = {'REGISTER', 'UNDO'}

    denoise: EnumProperty(
        name="Remove Noise First", items=DENOISE_ITEMS, default='AUTO',
        description="How much noise to remove before smoothing from the start level")
    rounds: IntProperty(
        name="Rounds", default=10, min=1, max=200,
        description="Rounds of noise removal, with Remove Noise First set to Rounds")
    start_level: IntProperty(
        name="Start Level", default=0, min=0, max=64,
        description="0 keeps all the detail the noise removal leaves; each level up smooths "
                    "away more detail (levels past the coarsest act as the coarsest)")
    keep_sharp_edges: BoolProperty(
        name="Keep Sharp Edges", default=True,
        description="Keep the edges marked Sharp and the creases sharper than the crease angle")
    crease_angle: FloatProperty(
        name="Crease Angle", subtype='ANGLE', default=math.radians(40.0), min=0.0,
        max=math.pi,
        description="Edges whose faces turn by more than this are kept sharp")
    only_selected: BoolProperty(
        name="Only Selected", default=False,
        description="Fair only the selected vertices (Edit mode) or the vertex group's, faded "
                    "by its weights; every other vertex keeps its exact position")
    vertex_group: StringProperty(
        name="Vertex Group", default="",
        description="With Only Selected: fair this vertex group, weights as the fade (empty: "
                    "the Edit mode selection)")
    falloff: IntProperty(
        name="Falloff", default=0, min=0, max=50,
        description="With Only Selected: fade the fairing out over this many rings of "
                    "vertices inside the selection's edge, so that no step shows")
    boundary: EnumProperty(
        name="Boundary", items=BOUNDARY_ITEMS, default='CURVE',
        description="What happens to open boundaries")

    @classmethod
    def poll(cls, context):
        return context.mode in {'OBJECT', 'EDIT_MESH'} and bool(_objects(context))

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        layout.prop(self, "denoise")
        row = layout.row()
        row.enabled = self.denoise == 'ROUNDS'
        row.prop(self, "rounds")
        layout.prop(self, "start_level")
        layout.prop(self, "keep_sharp_edges")
        row = layout.row()
        row.enabled = self.keep_sharp_edges
        row.prop(self, "crease_angle")
        layout.prop(self, "only_selected")
        column = layout.column()
        column.enabled = self.only_selected
        obj = context.active_object
        if obj is not None and obj.type == 'MESH':
            column.prop_search(self, "vertex_group", obj, "vertex_groups")
        else:
            column.prop(self, "vertex_group")
        column.prop(self, "falloff")
        layout.prop(self, "boundary")

    def _say(self, level, message):
        """Reports ``message`` (the status bar, the Info editor) and keeps it in
        ``last_reports`` for scripts."""
        last_reports.append((next(iter(level)), message))
        self.report(level, message)

    def settings(self) -> work.Settings:
        return work.Settings(
            denoise=self.denoise, rounds=self.rounds, start_level=self.start_level,
            keep_sharp_edges=self.keep_sharp_edges,
            crease_angle=min(max(math.degrees(self.crease_angle), 0.0), 180.0), boundary=self.boundary,
            falloff=self.falloff)

    # --- reading, working, writing -------------------------------------------------------

    def _prepare(self, context):
        """Starts a run's reports; the meshes to fair as (object, input, warnings); reports what cannot be faired.
        None when nothing can be."""
        last_reports.clear()
        in_edit_mode = context.mode == 'EDIT_MESH'
        objects = _objects(context)
        jobs = []
        if in_edit_mode:
            # The edit mesh written into the mesh data, UV maps included.
            bpy.ops.object.mode_set(mode='OBJECT')
        try:
            seen = set()
            for obj in objects:
                if obj.type == 'MESH':
                    if obj.data.as_pointer() in seen:
                        continue  # a linked duplicate: its mesh is faired once
                    seen.add(obj.data.as_pointer())
                try:
                    mesh, warnings = mesh_data.read(obj, self.only_selected, self.vertex_group,
                                                    in_edit_mode)
                except mesh_data.NotFairable as reason:
                    self._say({'WARNING'}, str(reason))
                    continue
                except Exception as error:  # reported, never a traceback
                    self._say({'WARNING'}, f"{obj.name} could not be read: {error}")
                    continue
                jobs.append((obj, mesh, warnings))
        finally:
            if in_edit_mode:
                bpy.ops.object.mode_set(mode='EDIT')
        if not jobs:
            self._say({'WARNING'}, "Nothing to fair: select a mesh object with faces")
            return None
        return jobs

    def _work(self, jobs, progress):
        """Fairs every job's mesh (no ``bpy`` touched): a list of (result or None, error)."""
        settings = self.settings()
        outcomes = []
        for index, (obj_name, mesh) in enumerate(jobs):
            share = 1.0 / len(jobs)

            def scaled(fraction, start=index * share):
                return progress(start + share * fraction) if progress else None

            try:
                outcomes.append((work.fair_mesh(mesh, settings, scaled), None))
            except fairmesh.Cancelled:
                raise
            except (ValueError, TypeError) as error:
                outcomes.append((None, f"{obj_name}: {error}"))
            except Exception as error:  # reported, never a traceback
                outcomes.append((None, f"{obj_name}: fairmesh failed: {error}"))
        return outcomes

    def _apply(self, context, jobs, outcomes):
        """Writes the results and reports; the operator's return value."""
        in_edit_mode = context.mode == 'EDIT_MESH'
        if in_edit_mode:
            bpy.ops.object.mode_set(mode='OBJECT')
        summaries = []
        written = 0
        try:
            for (obj, mesh, warnings), (result, error) in zip(jobs, outcomes):
                for warning in warnings:
                    self._say({'WARNING'}, warning)
                if error is not None:
                    self._say({'WARNING'}, error)
                    continue
                mesh_data.write(obj, mesh.vertices, result)
                written += 1
                summaries.append(result.summary if len(jobs) == 1
                                 else f"{obj.name}: {result.summary}")
        finally:
            if in_edit_mode:
                bpy.ops.object.mode_set(mode='EDIT')
        if not written:
            return {'CANCELLED'}
        self._say({'INFO'}, "; ".join(summaries))
        return {'FINISHED'}

    # --- at once (scripts, Adjust Last Operation) ------------------------------------------

    def execute(self, context):
        jobs = self._prepare(context)
        if jobs is None:
            return {'CANCELLED'}
        window_manager = context.window_manager
        window_manager.progress_begin(0, 1000)

        def progress(fraction):
            window_manager.progress_update(int(1000 * min(max(fraction, 0.0), 1.0)))
            return True

        try:
            outcomes = self._work([(obj.name, mesh) for obj, mesh, _ in jobs], progress)
        except fairmesh.Cancelled:
            self._say({'WARNING'}, "Cancelled: nothing changed")
            return {'CANCELLED'}
        finally:
            window_manager.progress_end()
        return self._apply(context, jobs, outcomes)

    # --- on a thread, with progress and Esc (menus, F3) ------------------------------------

    def invoke(self, context, event):
        jobs = self._prepare(context)
        if jobs is None:
            return {'CANCELLED'}
        self._jobs = jobs
        self._fraction = 0.0
        self._stop = threading.Event()
        self._outcome = None
        named = [(obj.name, mesh) for obj, mesh, _ in jobs]

        def progress(fraction):
            self._fraction = fraction
            return not self._stop.is_set()

        def run():
            try:
                self._outcome = ("done", self._work(named, progress))
            except fairmesh.Cancelled:
                self._outcome = ("cancelled", None)
            except Exception as error:  # reported, never a traceback
                self._outcome = ("failed", f"fairmesh failed: {error}")

        self._thread = threading.Thread(target=run, name="fairmesh", daemon=True)
        window_manager = context.window_manager
        window_manager.progress_begin(0, 1000)
        self._timer = window_manager.event_timer_add(0.1, window=context.window)
        window_manager.modal_handler_add(self)
        self._thread.start()
        return {'RUNNING_MODAL'}

    def modal(self, context, event):
        if event.type == 'ESC':
            self._stop.set()
        if event.type == 'TIMER':
            context.window_manager.progress_update(int(1000 * min(self._fraction, 1.0)))
        if self._thread.is_alive():
            # Nothing may change the meshes while the work reads them: events wait.
            return {'RUNNING_MODAL'}
        self._thread.join()
        window_manager = context.window_manager
        window_manager.event_timer_remove(self._timer)
        window_manager.progress_end()
        state, value = self._outcome or ("failed", "fairmesh stopped unexpectedly")
        if state == "cancelled":
            self._say({'WARNING'}, "Cancelled: nothing changed")
            return {'CANCELLED'}
        if state == "failed":
            self._say({'ERROR'}, value)
            return {'CANCELLED'}
        return self._apply(context, self._jobs, value)


def _objects(context):
    """The objects to fair: in Edit mode the meshes being edited; else the selected objects
    (the active one when none is selected)."""
    if context.mode == 'EDIT_MESH':
        return list(getattr(context, "objects_in_mode", None) or [context.active_object])
    selected = list(getattr(context, "selected_objects", None) or [])
    if not selected and context.active_object is not None:
        selected = [context.active_object]
    return selected


def menu_entry(self, context):
    self.layout.separator()
    self.layout.operator(OBJECT_OT_fairmesh_fair.bl_idname, icon='MOD_SMOOTH')

"""The add-on inside Blender: installed from the zip, then the operator checked against the
Python package on the same arrays, and what it keeps.

Run by scripts/test_blender.sh as
``blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_operator.py -- ZIP``.
Each test prints PASS or FAIL; the script ends with "N passed, N failed" and raises when one
failed, so that Blender exits non-zero.
"""

import math
import os
import sys
import time
import traceback

import bpy
import numpy as np

ZIP = os.path.abspath(sys.argv[sys.argv.index("--") + 1])
TESTS = []


def test(function):
    TESTS.append(function)
    return function


def install():
    """The zip installs and enables as any add-on; its own fairmesh is the one imported."""
    bpy.ops.preferences.addon_install(filepath=ZIP, overwrite=True)
    bpy.ops.preferences.addon_enable(module="fairmesh_blender")
    assert "fairmesh_blender" in bpy.context.preferences.addons, "the add-on is not enabled"
    assert hasattr(bpy.ops.object, "fairmesh_fair"), "the operator is not registered"
    import fairmesh
    assert os.path.join("fairmesh_blender", "vendor") in fairmesh.__file__, fairmesh.__file__
    from fairmesh_blender import operator as entry
    for menu in (bpy.types.VIEW3D_MT_object, bpy.types.VIEW3D_MT_edit_mesh):
        assert entry.menu_entry in menu.draw._draw_funcs, f"not in {menu.__name__}"


install()
import fairmesh  # noqa: E402  (the add-on's copy, put on sys.path by the add-on)
from fairmesh_blender import operator as addon_operator, work  # noqa: E402


# --- meshes ----------------------------------------------------------------------------------

def clear_scene():
    if bpy.context.object is not None and bpy.context.object.mode != 'OBJECT':
        bpy.ops.object.mode_set(mode='OBJECT')
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    for mesh in list(bpy.data.meshes):
        bpy.data.meshes.remove(mesh)
    work.kept.clear()


def add_object(name, vertices, faces):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([tuple(map(float, v)) for v in vertices], [], [tuple(map(int, f)) for f in faces])
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    select_only(obj)
    return obj


def select_only(obj):
    for other in bpy.context.scene.objects:
        other.select_set(False)
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj


def positions(obj):
    mesh = obj.data
    array = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", array)
    return array.reshape(-1, 3)


def triangles(obj):
    mesh = obj.data
    mesh.calc_loop_triangles()
    array = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", array)
    return array.reshape(-1, 3).astype(np.int64)


def noisy_sphere(name="Noisy", subdivisions=4, sigma=0.3):
    """An ico sphere with seeded noise: its own triangles, no UVs."""
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=subdivisions, radius=1.0)
    obj = bpy.context.object
    obj.name = name
    noisy = fairmesh.noise(positions(obj), triangles(obj), sigma=sigma, seed=1)
    obj.data.vertices.foreach_set("co", noisy.astype(np.float32).reshape(-1))
    obj.data.update()
    return obj


def diagonal(vertices):
    return float(np.linalg.norm(vertices.max(axis=0) - vertices.min(axis=0)))


def fair(**options):
    return bpy.ops.object.fairmesh_fair(**options)


# --- the tests -------------------------------------------------------------------------------

@test
def the_result_is_fairmesh_fair_on_the_same_arrays():
    clear_scene()
    obj = noisy_sphere()
    before, faces = positions(obj).copy(), triangles(obj)
    assert fair() == {'FINISHED'}
    expected, report = fairmesh.fair(before, faces)
    error = np.abs(positions(obj) - expected).max() / diagonal(before)
    assert error <= 1e-6, f"{error} of the diagonal from fairmesh.fair"
    assert np.abs(positions(obj) - before).max() > 1e-3 * diagonal(before), "nothing moved"
    info = [m for level, m in addon_operator.last_reports if level == 'INFO']
    assert info and f"{report['rounds_run']} rounds" in info[0], addon_operator.last_reports
    assert "noise about" in info[0], info


@test
def start_level_is_the_hierarchys_multires():
    clear_scene()
    obj = noisy_sphere()
    before, faces = positions(obj).copy(), triangles(obj)
    assert fair(start_level=2) == {'FINISHED'}
    hierarchy = fairmesh.hierarchy(before, faces, denoise="auto", keep_creases=True,
                                   crease_angle=40.0)
    expected = hierarchy.multires(2)
    error = np.abs(positions(obj) - expected).max() / diagonal(before)
    assert error <= 1e-6, f"{error} of the diagonal from Hierarchy.multires(2)"


@test
def rounds_and_off_are_fair_with_those_rounds_and_the_bare_hierarchy():
    clear_scene()
    obj = noisy_sphere()
    before, faces = positions(obj).copy(), triangles(obj)
    assert fair(denoise='ROUNDS', rounds=4, boundary='FIXED') == {'FINISHED'}
    expected, _ = fairmesh.fair(before, faces, rounds=4, boundary="fixed")
    assert np.abs(positions(obj) - expected).max() / diagonal(before) <= 1e-6
    info = [m for level, m in addon_operator.last_reports if level == 'INFO']
    assert info == ["4 rounds as asked, 0 sharp edges kept"], info
    obj.data.vertices.foreach_set("co", before.reshape(-1))
    obj.data.update()
    assert fair(denoise='OFF', start_level=1, keep_sharp_edges=False) == {'FINISHED'}
    expected = fairmesh.hierarchy(before, faces).multires(1)
    assert np.abs(positions(obj) - expected).max() / diagonal(before) <= 1e-6
    info = [m for level, m in addon_operator.last_reports if level == 'INFO']
    assert info and info[0].startswith("no noise removed first; faired from level 1"), info


@test
def undo_restores_the_mesh_exactly_and_a_redo_keeps_the_hierarchy():
    clear_scene()
    obj = noisy_sphere(subdivisions=5)
    before, faces = positions(obj).copy(), triangles(obj)
    bpy.ops.ed.undo_push(message="the noisy sphere")
    builds = work.kept.builds
    started = time.perf_counter()
    assert fair(start_level=2) == {'FINISHED'}
    first = time.perf_counter() - started
    assert work.kept.builds == builds + 1
    assert not np.array_equal(positions(obj), before)
    # In a window the operator's run is one undo step (REGISTER and UNDO); a script run
    # headless pushes none of its own, so the step is pushed here as the window would.
    assert {'REGISTER', 'UNDO'} <= addon_operator.OBJECT_OT_fairmesh_fair.bl_options
    bpy.ops.ed.undo_push(message="Fair Mesh")
    bpy.ops.ed.undo()
    obj = bpy.data.objects["Noisy"]
    assert np.array_equal(positions(obj), before), "undo did not restore the positions exactly"
    # What Adjust Last Operation does: undo, then run again with the new value.
    select_only(obj)
    started = time.perf_counter()
    assert fair(start_level=3) == {'FINISHED'}
    redo = time.perf_counter() - started
    assert work.kept.builds == builds + 1, "the redo built the hierarchy again"
    hierarchy = fairmesh.hierarchy(before, faces, denoise="auto", keep_creases=True,
                                   crease_angle=40.0)
    error = np.abs(positions(obj) - hierarchy.multires(3)).max() / diagonal(before)
    assert error <= 1e-6, f"the redo is {error} of the diagonal from Hierarchy.multires(3)"
    print(f"  {len(before)} vertices: first run {first:.3f} s, redo with another start level "
          f"{redo:.3f} s")


@test
def only_selected_keeps_every_other_vertex_exactly():
    clear_scene()
    obj = noisy_sphere()
    before = positions(obj).copy()
    bpy.ops.object.mode_set(mode='EDIT')
    bpy.ops.mesh.select_all(action='DESELECT')
    bpy.ops.object.mode_set(mode='OBJECT')
    obj.data.vertices.foreach_set("select", before[:, 2] > 0.2)
    bpy.ops.object.mode_set(mode='EDIT')
    assert fair(only_selected=True, falloff=2) == {'FINISHED'}
    bpy.ops.object.mode_set(mode='OBJECT')
    after = positions(obj)
    chosen = np.zeros(len(before), dtype=bool)
    obj.data.vertices.foreach_get("select", chosen)
    assert 0 < chosen.sum() < len(before)
    assert np.array_equal(after[~chosen], before[~chosen]), "an unselected vertex moved"
    assert np.abs(after[chosen] - before[chosen]).max() > 1e-3, "no selected vertex moved"


@test
def a_vertex_group_fades_by_its_weights():
    clear_scene()
    obj = noisy_sphere()
    before = positions(obj).copy()
    group = obj.vertex_groups.new(name="Face")
    inside = np.nonzero(before[:, 0] > 0.0)[0]
    group.add([int(i) for i in inside], 0.5, 'REPLACE')
    assert fair(only_selected=True, vertex_group="Face") == {'FINISHED'}
    after = positions(obj)
    outside = np.ones(len(before), dtype=bool)
    outside[inside] = False
    assert np.array_equal(after[outside], before[outside]), "a vertex of weight 0 moved"
    weights = np.zeros(len(before), dtype=np.float32)
    weights[inside] = 0.5
    expected, _ = fairmesh.fair(before, triangles(obj), mask=weights)
    error = np.abs(after - expected).max() / diagonal(before)
    assert error <= 1e-6, f"{error} of the diagonal from fairmesh.fair with the weights"


def dihedral_degrees(vertices, faces, edges):
    """The angle between the normals of the two faces at each edge."""
    corners = vertices[faces]
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    angles = []
    for a, b in edges:
        around = [i for i, f in enumerate(faces) if a in f and b in f]
        cosine = float(np.clip(np.dot(normals[around[0]], normals[around[1]]), -1, 1))
        angles.append(math.degrees(math.acos(cosine)))
    return np.array(angles)


@test
def edges_marked_sharp_stay_sharp():
    clear_scene()
    bpy.ops.mesh.primitive_cube_add(size=2.0)
    obj = bpy.context.object
    bpy.ops.object.mode_set(mode='EDIT')
    bpy.ops.mesh.select_all(action='SELECT')
    bpy.ops.mesh.subdivide(number_cuts=7)
    bpy.ops.mesh.quads_convert_to_tris()
    bpy.ops.object.mode_set(mode='OBJECT')
    mesh = obj.data
    clean = positions(obj).copy()
    faces = triangles(obj)
    noisy = fairmesh.noise(clean, faces, sigma=0.2, seed=3).astype(np.float32)
    # The cube's own edges: both ends on two of the cube's faces (two coordinates at +-1).
    on_rim = (np.abs(np.abs(clean) - 1.0) < 1e-5).sum(axis=1) >= 2
    edges = np.empty(len(mesh.edges) * 2, dtype=np.int32)
    mesh.edges.foreach_get("vertices", edges)
    edges = edges.reshape(-1, 2)
    rim = on_rim[edges[:, 0]] & on_rim[edges[:, 1]] & \
        ((np.abs(clean[edges[:, 0]] - clean[edges[:, 1]]) < 1e-5).sum(axis=1) == 2)
    sharp = np.zeros(len(edges), dtype=bool)
    sharp[rim] = True
    mesh.edges.foreach_set("use_edge_sharp", sharp)
    rim_edges = edges[rim]
    results = {}
    for keep in (True, False):
        mesh.vertices.foreach_set("co", noisy.reshape(-1))
        mesh.update()
        # A crease angle of 180 degrees finds no crease: only the marked edges can keep them.
        assert fair(keep_sharp_edges=keep, crease_angle=math.pi) == {'FINISHED'}
        results[keep] = dihedral_degrees(positions(obj), faces, rim_edges)
    kept, faired = results[True].mean(), results[False].mean()
    assert kept > 70.0, f"marked Sharp edges turned by {kept:.1f} degrees on average, not ~90"
    assert faired < kept - 10.0, f"without them {faired:.1f} degrees, with {kept:.1f}"


@test
def uvs_follow_and_colours_and_groups_are_kept():
    clear_scene()
    bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=1.0)
    obj = bpy.context.object
    mesh = obj.data
    clean = positions(obj).copy()
    noisy = fairmesh.noise(clean, triangles(obj), sigma=0.3, seed=2).astype(np.float32)
    mesh.vertices.foreach_set("co", noisy.reshape(-1))
    mesh.update()
    n = len(mesh.vertices)
    colours = mesh.color_attributes.new("Paint", 'FLOAT_COLOR', 'POINT')
    paint = np.random.default_rng(1).random(n * 4).astype(np.float32)
    colours.data.foreach_set("color", paint)
    group = obj.vertex_groups.new(name="Weights")
    for i in range(0, n, 3):
        group.add([i], (i % 10) / 10.0, 'REPLACE')
    weights_before = [(v.index, g.group, g.weight) for v in mesh.vertices for g in v.groups]
    layer = mesh.uv_layers.active
    corners = len(mesh.loops)
    uv_before = np.empty(corners * 2, dtype=np.float32)
    layer.data.foreach_get("uv", uv_before)
    uv_before = uv_before.reshape(-1, 2)
    corner_vertex = np.empty(corners, dtype=np.int32)
    mesh.loops.foreach_get("vertex_index", corner_vertex)

    assert fair() == {'FINISHED'}

    after = positions(obj)
    got = np.empty(n * 4, dtype=np.float32)
    mesh.color_attributes["Paint"].data.foreach_get("color", got)
    assert np.array_equal(got, paint), "the colour attribute changed"
    weights_after = [(v.index, g.group, g.weight) for v in mesh.vertices for g in v.groups]
    assert weights_after == weights_before, "the vertex group changed"
    uv_after = np.empty(corners * 2, dtype=np.float32)
    mesh.uv_layers.active.data.foreach_get("uv", uv_after)
    uv_after = uv_after.reshape(-1, 2)

    # The UV sphere's map is longitude and latitude: the texture at a point of the surface is
    # (about) the spherical coordinates of its direction. Followed, a corner's UV is that of
    # where its vertex went; left alone it would be that of where the vertex was.
    def spherical(points):
        u = (np.arctan2(points[:, 1], points[:, 0]) / (2 * np.pi) + 0.5) % 1.0
        v = np.arccos(np.clip(points[:, 2] / np.linalg.norm(points, axis=1), -1, 1)) / np.pi
        return np.column_stack([u, 1.0 - v])

    target = spherical(after[corner_vertex].astype(np.float64))
    away = (uv_before[:, 0] > 0.05) & (uv_before[:, 0] < 0.95) & \
        (uv_before[:, 1] > 0.15) & (uv_before[:, 1] < 0.85)
    slid = np.linalg.norm(spherical(after[corner_vertex].astype(np.float64)) -
                          spherical(noisy[corner_vertex].astype(np.float64)), axis=1) > 2e-3
    chosen = away & slid
    assert chosen.sum() > 100, "too few corners slid to test"
    followed = np.linalg.norm(uv_after[chosen] - target[chosen], axis=1).mean()
    stayed = np.linalg.norm(uv_before[chosen] - target[chosen], axis=1).mean()
    assert followed < 0.5 * stayed, f"UVs {followed:.5f} from the texture's place, {stayed:.5f} " \
                                    "had they stayed"
    unmoved = np.all(after[corner_vertex] == noisy[corner_vertex], axis=1)
    assert np.array_equal(uv_after[unmoved], uv_before[unmoved])


@test
def shape_keys_keep_their_offsets_and_custom_normals_turn():
    clear_scene()
    obj = noisy_sphere()
    before = positions(obj).copy()
    obj.shape_key_add(name="Basis")
    key = obj.shape_key_add(name="Lifted")
    lifted = before + np.array([0.0, 0.0, 0.5], dtype=np.float32)
    key.data.foreach_set("co", lifted.reshape(-1))
    mesh = obj.data
    if hasattr(mesh, "use_auto_smooth"):
        mesh.use_auto_smooth = True
    mesh.calc_loop_triangles()
    face_normals = np.empty(len(mesh.polygons) * 3, dtype=np.float32)
    mesh.polygons.foreach_get("normal", face_normals)
    face_normals = face_normals.reshape(-1, 3)
    corner_face = np.repeat(np.arange(len(mesh.polygons)), 3)  # all triangles
    mesh.normals_split_custom_set(face_normals[corner_face])
    assert mesh.has_custom_normals

    assert fair() == {'FINISHED'}

    after = positions(obj)
    basis = np.empty(len(before) * 3, dtype=np.float32)
    mesh.shape_keys.key_blocks["Basis"].data.foreach_get("co", basis)
    assert np.array_equal(basis.reshape(-1, 3), after), "the basis is not the result"
    moved_key = np.empty(len(before) * 3, dtype=np.float32)
    mesh.shape_keys.key_blocks["Lifted"].data.foreach_get("co", moved_key)
    offset = moved_key.reshape(-1, 3) - after
    assert np.abs(offset - [0.0, 0.0, 0.5]).max() < 1e-5, "the shape key lost its offset"
    # Flat custom normals stay flat: each corner's normal is its face's new normal.
    if hasattr(mesh, "calc_normals_split"):
        mesh.calc_normals_split()
        corner_normals = np.empty(len(mesh.loops) * 3, dtype=np.float32)
        mesh.loops.foreach_get("normal", corner_normals)
    else:
        corner_normals = np.empty(len(mesh.loops) * 3, dtype=np.float32)
        mesh.corner_normals.foreach_get("vector", corner_normals)
    new_face = np.empty(len(mesh.polygons) * 3, dtype=np.float32)
    mesh.polygons.foreach_get("normal", new_face)
    new_face = new_face.reshape(-1, 3)
    cosine = (corner_normals.reshape(-1, 3) * new_face[corner_face]).sum(axis=1)
    assert cosine.min() > 0.999, f"a custom normal is {math.degrees(math.acos(cosine.min())):.1f}" \
                                 " degrees off its face"


@test
def every_selected_mesh_is_faired_and_reported_by_name():
    clear_scene()
    first = noisy_sphere("First", subdivisions=3)
    second = noisy_sphere("Second", subdivisions=3)
    second.location.x = 3.0
    before = {obj.name: positions(obj).copy() for obj in (first, second)}
    for obj in (first, second):
        obj.select_set(True)
    assert fair() == {'FINISHED'}
    for obj in (first, second):
        expected, _ = fairmesh.fair(before[obj.name], triangles(obj))
        error = np.abs(positions(obj) - expected).max() / diagonal(before[obj.name])
        assert error <= 1e-6, f"{obj.name}: {error} of the diagonal from fairmesh.fair"
    info = [m for level, m in addon_operator.last_reports if level == 'INFO']
    assert info and "First: noise about" in info[0] and "Second: noise about" in info[0], info


@test
def a_mesh_shared_by_linked_duplicates_is_faired_once():
    clear_scene()
    first = noisy_sphere("First", subdivisions=3)
    twin = bpy.data.objects.new("Twin", first.data)
    bpy.context.scene.collection.objects.link(twin)
    before = positions(first).copy()
    twin.select_set(True)
    # Rounds as asked: a second fairing would move it again (the automatic strength would
    # leave the faired mesh as it is, and hide it).
    assert fair(denoise='ROUNDS', rounds=3) == {'FINISHED'}
    expected, _ = fairmesh.fair(before, triangles(first), rounds=3)
    twice, _ = fairmesh.fair(expected, triangles(first), rounds=3)
    assert np.abs(twice - expected).max() > 1e-4 * diagonal(before)
    error = np.abs(positions(first) - expected).max() / diagonal(before)
    assert error <= 1e-6, f"{error} of the diagonal from one fairmesh.fair"


@test
def a_non_mesh_object_and_an_empty_mesh_give_a_report():
    clear_scene()
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    bpy.context.scene.collection.objects.link(camera)
    select_only(camera)
    assert fair() == {'CANCELLED'}
    text = " ".join(m for _, m in addon_operator.last_reports)
    assert "Camera is not a mesh" in text, addon_operator.last_reports
    empty = add_object("Empty", [], [])
    select_only(empty)
    assert fair() == {'CANCELLED'}
    text = " ".join(m for _, m in addon_operator.last_reports)
    assert "Empty is an empty mesh" in text, addon_operator.last_reports


@test
def non_manifold_and_loose_parts_are_reported_and_the_rest_faired():
    clear_scene()
    sphere = noisy_sphere(subdivisions=3)
    vertices = positions(sphere).copy()
    faces = triangles(sphere)
    n = len(vertices)
    # A second, separate sphere; a fin on an edge of the first (a third face at that edge);
    # and a vertex in no face.
    vertices = np.vstack([vertices, vertices + [3.0, 0.0, 0.0], [[0.0, 0.0, 3.0]],
                          [[5.0, 5.0, 5.0]]])
    a, b = faces[0][0], faces[0][1]
    faces = np.vstack([faces, faces + n, [[a, b, 2 * n]]])
    clear_scene()
    obj = add_object("Parts", vertices, faces)
    before = positions(obj).copy()
    assert fair() == {'FINISHED'}
    warnings = " ".join(m for level, m in addon_operator.last_reports if level == 'WARNING')
    assert "not manifold" in warnings and "1 edge has more than two faces" in warnings, warnings
    assert "loose vert" in warnings, warnings
    after = positions(obj)
    assert np.array_equal(after[-1], before[-1]), "the loose vertex moved"
    for part in (slice(0, n), slice(n, 2 * n)):
        assert np.abs(after[part] - before[part]).max() > 1e-3, "a part was not faired"


# --- the run ---------------------------------------------------------------------------------

def main():
    passed, failed = 0, 0
    for function in TESTS:
        try:
            function()
        except Exception:  # every test runs; the failures are listed
            failed += 1
            print(f"FAIL {function.__name__}")
            traceback.print_exc()
        else:
            passed += 1
            print(f"PASS {function.__name__}")
    print(f"{passed} passed, {failed} failed")
    if failed:
        raise SystemExit(1)


main()

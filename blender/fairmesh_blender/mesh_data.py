"""Reading a Blender mesh into arrays for the work, and writing the result back, with
``foreach_get``/``foreach_set`` and numpy (no loop over the vertices in Python, except over a
vertex group's members: Blender gives vertex group weights no array access).

What is kept: the positions change and nothing else does, so colour attributes, vertex groups,
creases, seams and materials stay as they are; every UV map follows the slide (``work.follow_uvs``);
custom normals turn with their faces; shape keys keep their offsets from the basis, which takes
the result.
"""

from typing import List, Optional, Tuple

import bpy
import numpy as np

from . import work

#: The integer type Blender keeps indices in, which foreach_get then copies at once (any other
#: type is converted one value at a time, several times slower): unsigned before Blender 3.6,
#: which moved corners and edges into int attributes.
INDEX = np.uint32 if bpy.app.version < (3, 6, 0) else np.int32


def _indices(collection, name: str, count: int) -> np.ndarray:
    """``collection``'s integer property ``name`` (``count`` values in all) as int64."""
    values = np.empty(count, dtype=INDEX)
    collection.foreach_get(name, values)
    return values.astype(np.int64)


class NotFairable(Exception):
    """An object the operator cannot fair: the message says which and why, for the report."""


def read(obj, only_selected: bool, vertex_group: str,
         in_edit_mode: bool) -> Tuple[work.MeshInput, List[str]]:
    """The arrays of ``obj``'s mesh data (not the modifiers' result), and warnings about what
    stays as it is; in Object mode (``in_edit_mode``: the Edit mode selection is the mask). Raises ``NotFairable`` for an object that is not a mesh, a mesh with no
    faces, or a mask that lets nothing move."""
    if obj.type != 'MESH':
        raise NotFairable(f"{obj.name} is not a mesh (it is a {obj.type.lower()}): skipped")
    mesh = obj.data
    if mesh.library is not None or getattr(mesh, "override_library", None) is not None:
        raise NotFairable(f"{obj.name}'s mesh is linked from another file: make it local "
                          f"(Object > Relations > Make Local) to fair it")
    n = len(mesh.vertices)
    if n == 0 or len(mesh.polygons) == 0:
        raise NotFairable(f"{obj.name} is an empty mesh (no faces): nothing to fair")
    warnings = []
    vertices = np.empty(n * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", vertices)
    vertices = vertices.reshape(n, 3)
    mesh.calc_loop_triangles()
    m = len(mesh.loop_triangles)
    corner_count = len(mesh.loops)
    corner_vertex = _indices(mesh.loops, "vertex_index", corner_count)
    triangle_corners = _indices(mesh.loop_triangles, "loops", m * 3).reshape(m, 3)
    triangles = corner_vertex[triangle_corners]

    edge_count = len(mesh.edges)
    corner_edge = _indices(mesh.loops, "edge_index", corner_count)
    faces_per_edge = np.bincount(corner_edge, minlength=edge_count)
    non_manifold = int((faces_per_edge > 2).sum())
    if non_manifold:
        warnings.append(
            f"{obj.name} is not manifold: {non_manifold} edge{_s(non_manifold)} "
            f"{'have' if non_manifold != 1 else 'has'} more than two faces; the extra faces "
            f"were left out of the fairing (Select > Select All by Trait > Non Manifold shows "
            f"them)")
    in_a_face = np.zeros(n, dtype=bool)
    in_a_face[triangles.reshape(-1)] = True
    loose_vertices = int(n - in_a_face.sum())
    loose_edges = int((faces_per_edge == 0).sum())
    if loose_vertices or loose_edges:
        warnings.append(
            f"{obj.name}: {loose_vertices} loose vertex{'es' if loose_vertices != 1 else ''} "
            f"and {loose_edges} loose edge{_s(loose_edges)} (in no face) were left where they "
            f"are")

    sharp = _sharp_edges(mesh, edge_count)
    hard_edges = None
    if sharp is not None and sharp.any():
        edge_vertices = _indices(mesh.edges, "vertices", edge_count * 2).reshape(edge_count, 2)
        hard_edges = edge_vertices[sharp]

    mask = None
    if only_selected:
        mask = _mask(obj, mesh, n, vertex_group, in_edit_mode)

    uv_layers = []
    for layer in mesh.uv_layers:
        uvs = np.empty(corner_count * 2, dtype=np.float32)
        layer.data.foreach_get("uv", uvs)
        uv_layers.append(work.UvLayer(layer.name, uvs.reshape(corner_count, 2), corner_vertex,
                                      triangle_corners))
    return work.MeshInput(name=mesh.name, vertices=vertices, triangles=triangles,
                          hard_edges=hard_edges, mask=mask, uv_layers=uv_layers), warnings


def _s(count: int) -> str:
    return "" if count == 1 else "s"


def _sharp_edges(mesh, edge_count: int) -> Optional[np.ndarray]:
    """The edges marked Sharp, as a bool per edge (Blender 4.0 and newer keep them in the
    ``sharp_edge`` attribute, older ones in each edge's ``use_edge_sharp``)."""
    if edge_count == 0:
        return None
    attribute = mesh.attributes.get("sharp_edge") if hasattr(mesh, "attributes") else None
    sharp = np.zeros(edge_count, dtype=bool)
    if attribute is not None and attribute.domain == 'EDGE' and attribute.data_type == 'BOOLEAN':
        attribute.data.foreach_get("value", sharp)
        return sharp
    if hasattr(mesh.edges[0], "use_edge_sharp"):
        mesh.edges.foreach_get("use_edge_sharp", sharp)
        return sharp
    return None


def _mask(obj, mesh, n: int, vertex_group: str, in_edit_mode: bool) -> np.ndarray:
    """The vertices Only Selected lets move: the vertex group's weights when one is named,
    else the Edit mode selection."""
    if vertex_group:
        group = obj.vertex_groups.get(vertex_group)
        if group is None:
            raise NotFairable(f"{obj.name} has no vertex group called {vertex_group!r}")
        index = group.index
        weights = np.zeros(n, dtype=np.float32)
        # Blender has no array access to vertex group weights: one pass over the members.
        for vertex in mesh.vertices:
            for element in vertex.groups:
                if element.group == index:
                    weights[vertex.index] = element.weight
        weights = np.clip(weights, 0.0, 1.0)
        if not (weights > 0).any():
            raise NotFairable(f"{obj.name}: vertex group {vertex_group!r} gives every vertex "
                              f"weight 0, so nothing would move")
        return weights
    if not in_edit_mode:
        raise NotFairable(f"{obj.name}: Only Selected needs a vertex group here, or Edit mode "
                          f"with vertices selected")
    selected = np.zeros(n, dtype=bool)
    mesh.vertices.foreach_get("select", selected)
    if not selected.any():
        raise NotFairable(f"{obj.name}: no vertex is selected, so nothing would move")
    return selected


def _corner_normals(mesh) -> np.ndarray:
    """Every corner's normal, custom normals included, (L, 3)."""
    count = len(mesh.loops)
    normals = np.empty(count * 3, dtype=np.float32)
    if hasattr(mesh, "corner_normals"):  # Blender 4.1 and newer
        mesh.corner_normals.foreach_get("vector", normals)
    else:
        mesh.calc_normals_split()
        mesh.loops.foreach_get("normal", normals)
    return normals.reshape(count, 3)


def _face_normals(mesh) -> np.ndarray:
    count = len(mesh.polygons)
    normals = np.empty(count * 3, dtype=np.float32)
    mesh.polygons.foreach_get("normal", normals)
    return normals.reshape(count, 3).astype(np.float64)


def _turned(vectors: np.ndarray, before: np.ndarray, after: np.ndarray) -> np.ndarray:
    """``vectors`` each turned by the rotation that takes the unit ``before`` onto the unit
    ``after`` about their common perpendicular (left as they are where the two are opposite or
    not known)."""
    axis = np.cross(before, after)
    cosine = (before * after).sum(axis=1)
    usable = (cosine > -0.999) & np.isfinite(cosine)
    scale = np.where(usable, 1.0 / np.where(usable, 1.0 + cosine, 1.0), 0.0)[:, None]
    axis = np.where(usable[:, None], axis, 0.0)
    cross = np.cross(axis, vectors)
    return vectors + cross + np.cross(axis, cross) * scale


def write(obj, before: np.ndarray, result: work.MeshResult) -> None:
    """Puts ``result`` into ``obj``'s mesh data (Object mode): positions, the basis and every
    other shape key, every UV map, and the custom normals turned with their faces."""
    mesh = obj.data
    after = np.ascontiguousarray(result.vertices, dtype=np.float32)
    custom = bool(getattr(mesh, "has_custom_normals", False))
    if custom:
        corner_normals = _corner_normals(mesh).astype(np.float64)
        face_normals_before = _face_normals(mesh)
    mesh.vertices.foreach_set("co", after.reshape(-1))
    keys = mesh.shape_keys
    if keys is not None:
        move = after.astype(np.float64) - before.astype(np.float64)
        count = len(after)
        for block in keys.key_blocks:
            if block == keys.reference_key:
                block.data.foreach_set("co", after.reshape(-1))
                continue
            positions = np.empty(count * 3, dtype=np.float32)
            block.data.foreach_get("co", positions)
            moved = positions.reshape(count, 3).astype(np.float64) + move
            block.data.foreach_set("co", moved.astype(np.float32).reshape(-1))
    for name, uvs in result.uvs:
        layer = mesh.uv_layers.get(name)
        if layer is not None:
            layer.data.foreach_set("uv", np.ascontiguousarray(uvs, dtype=np.float32).reshape(-1))
    mesh.update()
    if custom:
        face_normals_after = _face_normals(mesh)
        face_of_corner = np.empty(len(mesh.loops), dtype=np.int32)
        starts = _indices(mesh.polygons, "loop_start", len(mesh.polygons))
        totals = _indices(mesh.polygons, "loop_total", len(mesh.polygons))
        face_of_corner[_corner_order(starts, totals)] = np.repeat(np.arange(len(starts)),
                                                                  totals)
        turned = _turned(corner_normals, face_normals_before[face_of_corner],
                         face_normals_after[face_of_corner])
        length = np.linalg.norm(turned, axis=1, keepdims=True)
        turned = np.where(length > 0, turned / np.where(length > 0, length, 1.0), turned)
        mesh.normals_split_custom_set(turned.astype(np.float32))
        mesh.update()


def _corner_order(starts: np.ndarray, totals: np.ndarray) -> np.ndarray:
    """The corner index of every (face, k) in face order."""
    offsets = np.arange(totals.sum()) - np.repeat(np.cumsum(totals) - totals, totals)
    return np.repeat(starts, totals) + offsets

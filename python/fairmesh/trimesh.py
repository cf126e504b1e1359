"""fairmesh on trimesh meshes and scenes: ``fairmesh.trimesh.fair(mesh)`` returns a new mesh with
the smoothed vertices (the same faces, visuals and metadata), and the report.

    import trimesh
    import fairmesh.trimesh
    smooth, report = fairmesh.trimesh.fair(trimesh.load("scan.ply"))

Import it as ``import fairmesh.trimesh`` and call ``fairmesh.trimesh.fair``. ``from fairmesh import
trimesh`` works too, though it takes the trimesh package's name: every name this module does not
define is looked up in the trimesh package, so ``trimesh.load`` and ``trimesh.Trimesh`` go on
meaning the package's own.

Seams: ``trimesh.load`` gives a textured or normal-split mesh one vertex per side of each UV or
normal seam. Those copies of a position are faired as one vertex, as ``fairmesh.load`` welds a
file, and every copy gets the result, so no seam opens. A ``mask`` or ``hard_edges`` over the
copies is read over the welded vertices (a position is faired as much as its most faired
copy). Texture coordinates follow the vertices' slide along the surface, as ``Mesh.save``
makes them follow in files: each moves to what the texture held where its vertex slid to, so
the texture stays where it was on the surface.

A ``trimesh.Scene`` (what ``trimesh.load`` gives for .glb and many .obj files) is faired geometry
by geometry: the result is a copy of the scene with the same graph (every transform kept) and
visuals, each mesh geometry faired, and the report a dict of the reports by geometry name. The
geometries placed once in the scene are faired together in the scene's coordinates, welded as
one mesh (an OBJ split by material comes back split, with no seam opened between its parts;
they share one report); one placed several times is faired alone in its own coordinates, so its
copies stay alike. Geometry without faces is left as it is. Anything else given (a
``PointCloud``, a ``Path``) raises ``TypeError``.

trimesh is not a dependency of fairmesh: this module needs it installed. Keyword arguments are
those of ``fairmesh.fair``.
"""

from typing import Any, Dict, Tuple, Union

import numpy as np

import fairmesh
from fairmesh import _welding


def _trimesh():
    import trimesh

    return trimesh


def __getattr__(name: str) -> Any:
    # What `from fairmesh import trimesh` hides: the trimesh package's own names (PEP 562).
    if name.startswith("__"):
        raise AttributeError(f"module 'fairmesh.trimesh' has no attribute '{name}'")
    return getattr(_trimesh(), name)


def _refuse(what: Any, call: str) -> TypeError:
    kind = type(what).__module__ + "." + type(what).__qualname__
    hint = " (points without faces cannot be faired)" if "PointCloud" in kind else ""
    return TypeError(f"fairmesh.trimesh.{call} takes a trimesh.Trimesh or a trimesh.Scene of "
                     f"them, not a {kind}{hint}")


def fair(mesh: Union["trimesh.Trimesh", "trimesh.Scene"],
         **options: Any) -> Tuple[Any, Dict[str, Any]]:
    """``fairmesh.fair`` on a ``trimesh.Trimesh``: a copy with the smoothed vertices, and the
    report; the copies of a position across UV and normal seams are faired as one. On a
    ``trimesh.Scene``: a copy with every mesh geometry faired (transforms and visuals kept),
    and a dict of the reports by geometry name. ``mesh`` itself is not changed."""
    trimesh = _trimesh()
    if isinstance(mesh, trimesh.Scene):
        return _fair_scene(trimesh, mesh, options)
    if not isinstance(mesh, trimesh.Trimesh):
        raise _refuse(mesh, "fair")
    vertices, report = _welding.fair(mesh.vertices, mesh.faces, options)
    result = mesh.copy()
    _move(result, vertices)
    return result, report


def _move(geometry, vertices):
    """Gives ``geometry`` its new ``vertices``, its texture coordinates following the slide."""
    visual = geometry.visual
    uv = getattr(visual, "uv", None) if getattr(visual, "kind", None) == "texture" else None
    if uv is not None and len(uv) == len(vertices):
        visual.uv = fairmesh.follow_texture(geometry.vertices, vertices, geometry.faces, uv)
    geometry.vertices = vertices


def _fair_scene(trimesh, scene, options):
    """A copy of ``scene`` faired, and the reports by geometry name (see the module docs)."""
    result = scene.copy()
    placed: Dict[str, list] = {}
    for node in result.graph.nodes_geometry:
        transform, name = result.graph.get(node)
        geometry = result.geometry.get(name)
        if isinstance(geometry, trimesh.Trimesh) and len(geometry.faces):
            placed.setdefault(name, []).append(np.asarray(transform, dtype=np.float64))
    reports: Dict[str, Dict[str, Any]] = {}
    # A geometry placed once is faired in the scene's coordinates with the others placed once,
    # so that what a material split cut apart is welded again.
    once = [(name, transforms[0]) for name, transforms in placed.items() if len(transforms) == 1]
    if once:
        parts = [_to_world(result.geometry[name].vertices, transform) for name, transform in once]
        offsets = np.cumsum([0] + [len(part) for part in parts])
        faces = np.concatenate([result.geometry[name].faces + offset
                                for (name, _), offset in zip(once, offsets)])
        vertices, report = _welding.fair(np.concatenate(parts), faces, options)
        for (name, transform), start, end in zip(once, offsets[:-1], offsets[1:]):
            _move(result.geometry[name], _from_world(vertices[start:end], transform))
            reports[name] = report
    # One placed several times is faired in its own coordinates, so that its copies stay alike.
    for name in (name for name, transforms in placed.items() if len(transforms) > 1):
        geometry = result.geometry[name]
        vertices, reports[name] = _welding.fair(geometry.vertices, geometry.faces, options)
        _move(geometry, vertices)
    return result, reports


def _to_world(vertices: np.ndarray, transform: np.ndarray) -> np.ndarray:
    if np.array_equal(transform, np.eye(4)):
        return np.asarray(vertices, dtype=np.float64)
    return vertices @ transform[:3, :3].T + transform[:3, 3]


def _from_world(vertices: np.ndarray, transform: np.ndarray) -> np.ndarray:
    if np.array_equal(transform, np.eye(4)):
        return vertices
    return (vertices - transform[:3, 3]) @ np.linalg.inv(transform[:3, :3]).T


def noise(mesh: "trimesh.Trimesh", **options: Any) -> "trimesh.Trimesh":
    """``fairmesh.noise`` on ``mesh``: a copy with seeded noise added (the copies of a position
    across seams moved alike)."""
    trimesh = _trimesh()
    if not isinstance(mesh, trimesh.Trimesh):
        raise _refuse(mesh, "noise")
    welded, vertices, faces = _welding.welded_arrays(mesh.vertices, mesh.faces)
    moved = fairmesh.noise(vertices, faces, **options)
    result = mesh.copy()
    result.vertices = moved if welded is None else welded.spread(moved)
    return result


def hierarchy(mesh: "trimesh.Trimesh", **options: Any) -> "fairmesh.Hierarchy":
    """``fairmesh.hierarchy`` of ``mesh``; its ``multires(level)`` gives vertices for
    ``mesh.faces`` (a mesh split at seams: weld it first, ``mesh.merge_vertices()``, or the
    seams are separate boundaries)."""
    trimesh = _trimesh()
    if not isinstance(mesh, trimesh.Trimesh):
        raise _refuse(mesh, "hierarchy")
    return fairmesh.hierarchy(mesh.vertices, mesh.faces, **options)

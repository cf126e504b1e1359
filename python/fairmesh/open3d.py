"""fairmesh on Open3D meshes: ``fairmesh.open3d.fair(mesh)`` returns a new
``open3d.geometry.TriangleMesh`` with the smoothed vertices (the same triangles, per-triangle
texture coordinates, per-vertex colours and materials; normals are recomputed when the mesh had
them), and the report.

    import open3d as o3d
    import fairmesh.open3d
    smooth, report = fairmesh.open3d.fair(o3d.io.read_triangle_mesh("scan.ply"))

Seams: a mesh read from a file with split normals or texture seams may hold one vertex per side
of a seam. Those copies of a position are faired as one vertex, as ``fairmesh.load`` welds a
file, and every copy gets the result, so no seam opens (a ``mask`` or ``hard_edges`` over the
copies is read over the welded vertices). Texture coordinates (Open3D keeps one per triangle
corner) follow the vertices' slide along the surface, as ``Mesh.save`` makes them follow in
files: each moves to what the texture held where its vertex slid to (``fairmesh.follow_texture``,
the corners of a vertex that share a coordinate moved as one), so the texture stays where it was
on the surface.

Only ``open3d.geometry.TriangleMesh`` is taken; anything else (a ``PointCloud``, a tensor
``open3d.t.geometry.TriangleMesh``: convert it with ``.to_legacy()``) raises ``TypeError``.

``from fairmesh import open3d`` takes the Open3D package's name, harmlessly: every name this module
does not define is looked up in the Open3D package, so ``open3d.geometry`` and ``open3d.io`` go
on meaning the package's own.

Open3D is not a dependency of fairmesh: this module needs it installed. Keyword arguments are
those of ``fairmesh.fair``.
"""

from typing import Any, Dict, Tuple

import numpy as np

import fairmesh
from fairmesh import _welding


def arrays(mesh: "open3d.geometry.TriangleMesh") -> Tuple[np.ndarray, np.ndarray]:
    """``mesh``'s vertices (n, 3) float64 and triangles (m, 3) int32, as numpy arrays (views of
    Open3D's own buffers, not copies)."""
    return np.asarray(mesh.vertices), np.asarray(mesh.triangles)


def __getattr__(name: str) -> Any:
    # What `from fairmesh import open3d` hides: the Open3D package's own names (PEP 562).
    if name.startswith("__"):
        raise AttributeError(f"module 'fairmesh.open3d' has no attribute '{name}'")
    import open3d

    return getattr(open3d, name)


def _checked(mesh: Any, call: str):
    import open3d

    if not isinstance(mesh, open3d.geometry.TriangleMesh):
        kind = type(mesh).__module__ + "." + type(mesh).__qualname__
        raise TypeError(f"fairmesh.open3d.{call} takes an open3d.geometry.TriangleMesh, not a "
                        f"{kind}")
    return open3d


def _with_vertices(mesh: "open3d.geometry.TriangleMesh", vertices: np.ndarray):
    import open3d

    result = open3d.geometry.TriangleMesh(mesh)
    result.vertices = open3d.utility.Vector3dVector(vertices)
    if mesh.has_vertex_normals():
        result.compute_vertex_normals()
    return result


def fair(
    mesh: "open3d.geometry.TriangleMesh", **options: Any
) -> Tuple["open3d.geometry.TriangleMesh", Dict[str, Any]]:
    """``fairmesh.fair`` on ``mesh``: a copy with the smoothed vertices, and the report; the
    copies of a position across seams are faired as one. ``mesh`` itself is not changed."""
    open3d = _checked(mesh, "fair")
    vertices, faces = arrays(mesh)
    smoothed, report = _welding.fair(vertices, faces, options)
    result = _with_vertices(mesh, smoothed)
    corner_uvs = np.asarray(mesh.triangle_uvs)
    if len(faces) and corner_uvs.shape == (3 * len(faces), 2):
        followed = _follow_corners(vertices, smoothed, faces, corner_uvs)
        result.triangle_uvs = open3d.utility.Vector2dVector(followed)
    return result, report


def _follow_corners(before: np.ndarray, after: np.ndarray, faces: np.ndarray,
                    corner_uvs: np.ndarray) -> np.ndarray:
    """Per-corner texture coordinates moved with the vertices' slide: the distinct (vertex,
    coordinate) pairs move as one, each in its own chart."""
    pairs = np.column_stack([faces.reshape(-1).astype(np.float64), corner_uvs])
    distinct, inverse = np.unique(pairs, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    moved = fairmesh.follow_texture(before, after, faces, distinct[:, 1:],
                                    uv_faces=inverse.reshape(-1, 3))
    return moved[inverse]


def noise(mesh: "open3d.geometry.TriangleMesh", **options: Any) -> "open3d.geometry.TriangleMesh":
    """``fairmesh.noise`` on ``mesh``: a copy with seeded noise added (the copies of a position
    across seams moved alike)."""
    _checked(mesh, "noise")
    welded, vertices, faces = _welding.welded_arrays(*arrays(mesh))
    moved = fairmesh.noise(vertices, faces, **options)
    return _with_vertices(mesh, moved if welded is None else welded.spread(moved))

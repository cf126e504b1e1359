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
copies is read over the welded vertices). Texture coordinates stay as they are.

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
    _checked(mesh, "fair")
    vertices, faces = arrays(mesh)
    smoothed, report = _welding.fair(vertices, faces, options)
    return _with_vertices(mesh, smoothed), report


def noise(mesh: "open3d.geometry.TriangleMesh", **options: Any) -> "open3d.geometry.TriangleMesh":
    """``fairmesh.noise`` on ``mesh``: a copy with seeded noise added (the copies of a position
    across seams moved alike)."""
    _checked(mesh, "noise")
    welded, vertices, faces = _welding.welded_arrays(*arrays(mesh))
    moved = fairmesh.noise(vertices, faces, **options)
    return _with_vertices(mesh, moved if welded is None else welded.spread(moved))

"""fairmesh on Open3D meshes: ``fairmesh.open3d.fair(mesh)`` returns a new
``open3d.geometry.TriangleMesh`` with the smoothed vertices (and the same triangles and
per-vertex colours; normals are recomputed when the mesh had them), and the report.

    import open3d as o3d, fairmesh.open3d
    smooth, report = fairmesh.open3d.fair(o3d.io.read_triangle_mesh("scan.ply"))

Open3D is not a dependency of fairmesh: this module needs it installed. Keyword arguments are
those of ``fairmesh.fair``.
"""

from typing import Any, Dict, Tuple

import numpy as np

import fairmesh


def arrays(mesh: "open3d.geometry.TriangleMesh") -> Tuple[np.ndarray, np.ndarray]:
    """``mesh``'s vertices (n, 3) float64 and triangles (m, 3) int32, as numpy arrays (views of
    Open3D's own buffers, not copies)."""
    return np.asarray(mesh.vertices), np.asarray(mesh.triangles)


def fair(
    mesh: "open3d.geometry.TriangleMesh", **options: Any
) -> Tuple["open3d.geometry.TriangleMesh", Dict[str, Any]]:
    """``fairmesh.fair`` on ``mesh``: a copy with the smoothed vertices, and the report."""
    import open3d

    vertices, faces = arrays(mesh)
    smoothed, report = fairmesh.fair(vertices, faces, **options)
    result = open3d.geometry.TriangleMesh(mesh)
    result.vertices = open3d.utility.Vector3dVector(smoothed)
    if mesh.has_vertex_normals():
        result.compute_vertex_normals()
    return result, report

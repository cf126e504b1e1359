"""fairmesh on trimesh meshes: ``fairmesh.trimesh.fair(mesh)`` returns a new ``trimesh.Trimesh``
with the smoothed vertices (and the same faces, visuals and metadata), and the report.

    import trimesh, fairmesh.trimesh
    smooth, report = fairmesh.trimesh.fair(trimesh.load("scan.ply"))

trimesh is not a dependency of fairmesh: this module needs it installed. Keyword arguments are
those of ``fairmesh.fair``.
"""

from typing import Any, Dict, Tuple

import fairmesh


def fair(mesh: "trimesh.Trimesh", **options: Any) -> Tuple["trimesh.Trimesh", Dict[str, Any]]:
    """``fairmesh.fair`` on ``mesh.vertices`` and ``mesh.faces``: a copy of ``mesh`` with the
    smoothed vertices, and the report. ``mesh`` itself is not changed."""
    vertices, report = fairmesh.fair(mesh.vertices, mesh.faces, **options)
    result = mesh.copy()
    result.vertices = vertices
    return result, report


def noise(mesh: "trimesh.Trimesh", **options: Any) -> "trimesh.Trimesh":
    """``fairmesh.noise`` on ``mesh``: a copy with seeded noise added."""
    result = mesh.copy()
    result.vertices = fairmesh.noise(mesh.vertices, mesh.faces, **options)
    return result


def hierarchy(mesh: "trimesh.Trimesh", **options: Any) -> "fairmesh.Hierarchy":
    """``fairmesh.hierarchy`` of ``mesh``; its ``multires(level)`` gives vertices for
    ``mesh.faces``."""
    return fairmesh.hierarchy(mesh.vertices, mesh.faces, **options)

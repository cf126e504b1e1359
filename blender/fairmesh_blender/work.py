"""The work of the operator on plain arrays, with no Blender in it: fairing a mesh read from
Blender (``fairmesh.fair``, or a kept ``fairmesh.Hierarchy``'s ``multires`` from a start level),
the texture coordinates that follow the slide, and the one-line summary for the status bar.

Nothing here touches ``bpy``, so that it can run on a thread of its own while Blender's window
stays responsive (the operator's Esc), and so that it reads as what it does.

The hierarchies built for ``start_level`` are kept between runs, keyed on the mesh data (its
name, positions, faces and sharp edges) and the settings the build depends on: a redo of the
operator (Adjust Last Operation) with another start level finds the mesh as it was and costs
the multires run alone.
"""

import hashlib
import threading
from collections import OrderedDict
from dataclasses import dataclass, field
from typing import Callable, List, Optional, Tuple

import numpy as np

import fairmesh

#: How many hierarchies are kept (the most recently used ones).
KEPT_HIERARCHIES = 4


@dataclass
class Settings:
    """The operator's options, as the work needs them."""

    denoise: str = "AUTO"  # 'AUTO', 'ROUNDS' or 'OFF'
    rounds: int = 10
    start_level: int = 0
    keep_sharp_edges: bool = True
    crease_angle: float = 40.0  # degrees
    boundary: str = "CURVE"  # 'CURVE' or 'FIXED'
    falloff: int = 0

    def denoise_argument(self):
        """``fairmesh.hierarchy``'s ``denoise``."""
        if self.denoise == "AUTO":
            return "auto"
        if self.denoise == "ROUNDS":
            return int(self.rounds)
        return None


@dataclass
class UvLayer:
    """One UV map: one (u, v) per corner (Blender's loops), each corner's vertex, and the
    corners of every triangle."""

    name: str
    corner_uvs: np.ndarray  # (L, 2) float32
    corner_vertex: np.ndarray  # (L,) int
    triangle_corners: np.ndarray  # (m, 3) int


@dataclass
class MeshInput:
    """What the work reads of one mesh."""

    name: str
    vertices: np.ndarray  # (n, 3) float32
    triangles: np.ndarray  # (m, 3) int
    hard_edges: Optional[np.ndarray] = None  # (k, 2) int: edges marked Sharp
    mask: Optional[np.ndarray] = None  # (n,) bool or float: None is every vertex
    uv_layers: List[UvLayer] = field(default_factory=list)


@dataclass
class MeshResult:
    """What the work gives back for one mesh."""

    vertices: np.ndarray  # (n, 3) float32
    uvs: List[Tuple[str, np.ndarray]]  # (name, (L, 2) float32) of every UV map
    summary: str
    built_hierarchy: bool


class _Kept:
    """The hierarchies kept between runs, most recently used last, and how many were built."""

    def __init__(self):
        self.lock = threading.Lock()
        self.hierarchies: "OrderedDict[tuple, fairmesh.Hierarchy]" = OrderedDict()
        self.builds = 0

    def get(self, key):
        with self.lock:
            found = self.hierarchies.get(key)
            if found is not None:
                self.hierarchies.move_to_end(key)
            return found

    def put(self, key, hierarchy):
        with self.lock:
            self.builds += 1
            self.hierarchies[key] = hierarchy
            self.hierarchies.move_to_end(key)
            while len(self.hierarchies) > KEPT_HIERARCHIES:
                self.hierarchies.popitem(last=False)

    def clear(self):
        with self.lock:
            self.hierarchies.clear()


#: The hierarchies kept between runs (``kept.builds`` counts the builds, for the tests).
kept = _Kept()


def hierarchy_key(mesh: MeshInput, settings: Settings) -> tuple:
    """What a hierarchy depends on: the mesh data and the settings of its build."""
    digest = hashlib.blake2b(digest_size=20)
    for array in (mesh.vertices, mesh.triangles, mesh.hard_edges):
        if array is None:
            digest.update(b"none")
            continue
        array = np.ascontiguousarray(array)
        digest.update(str(array.shape).encode())
        digest.update(array.tobytes())
    return (
        mesh.name,
        digest.hexdigest(),
        settings.denoise,
        int(settings.rounds) if settings.denoise == "ROUNDS" else 0,
        bool(settings.keep_sharp_edges),
        round(float(settings.crease_angle), 6) if settings.keep_sharp_edges else None,
    )


Progress = Callable[[float], Optional[bool]]


def _scaled(progress: Optional[Progress], start: float, span: float) -> Optional[Progress]:
    if progress is None:
        return None
    return lambda fraction: progress(start + span * fraction)


def fair_mesh(mesh: MeshInput, settings: Settings,
              progress: Optional[Progress] = None) -> MeshResult:
    """Fairs ``mesh`` with ``settings``: ``fairmesh.fair`` at start level 0 after a denoise
    (that is what the hierarchy's level 0 would be), else the kept hierarchy's ``multires``
    from ``settings.start_level``. ``progress`` gets the fraction done and may return False to
    stop (``fairmesh.Cancelled`` is raised then). Raises ``ValueError`` for a mesh fairmesh
    cannot work on, naming what is wrong."""
    keep = bool(settings.keep_sharp_edges)
    hard_edges = mesh.hard_edges if keep and mesh.hard_edges is not None \
        and len(mesh.hard_edges) else None
    boundary = settings.boundary.lower()
    mask = mesh.mask
    falloff = int(settings.falloff) if mask is not None else 0
    built = False
    if settings.start_level == 0 and settings.denoise != "OFF":
        rounds = None if settings.denoise == "AUTO" else int(settings.rounds)
        result, report = fairmesh.fair(
            mesh.vertices, mesh.triangles, rounds=rounds, crease_angle=settings.crease_angle,
            no_creases=not keep, hard_edges=hard_edges, boundary=boundary, mask=mask,
            mask_falloff=falloff, progress=progress)
        summary = describe(report.get("noise_estimate"), report["rounds_run"],
                           report["crease_edges"] if keep else 0, settings)
    else:
        key = hierarchy_key(mesh, settings)
        hierarchy = kept.get(key)
        share = 0.0
        if hierarchy is None:
            share = 0.8
            hierarchy = fairmesh.hierarchy(
                mesh.vertices, mesh.triangles, keep_creases=keep,
                crease_angle=settings.crease_angle if keep else None, hard_edges=hard_edges,
                denoise=settings.denoise_argument(), progress=_scaled(progress, 0.0, share))
            kept.put(key, hierarchy)
            built = True
        result = hierarchy.multires(
            int(settings.start_level), boundary=boundary, mask=mask, mask_falloff=falloff,
            progress=_scaled(progress, share, 1.0 - share))
        found = hierarchy.denoise
        level = min(int(settings.start_level), hierarchy.coarsest_level)
        where = f"from level {level} of {hierarchy.coarsest_level}"
        if found is None:
            summary = f"no noise removed first; faired {where}"
        else:
            summary = describe(found.get("noise_estimate"), found["rounds_run"],
                               found["crease_edges"] if keep else 0, settings) + f", {where}"
    result = np.ascontiguousarray(result, dtype=np.float32)
    uvs = [(layer.name, follow_uvs(mesh.vertices, result, mesh.triangles, layer))
           for layer in mesh.uv_layers]
    return MeshResult(vertices=result, uvs=uvs, summary=summary, built_hierarchy=built)


def describe(noise: Optional[float], rounds: int, sharp_edges: int, settings: Settings) -> str:
    """What the denoise found, in the words of the status bar: "noise about 0.24 edge lengths:
    34 rounds, 43 sharp edges kept"."""
    sharp = f"{sharp_edges} sharp edge{'s' if sharp_edges != 1 else ''} kept" \
        if settings.keep_sharp_edges else "sharp edges faired across"
    rounds_text = f"{rounds} round{'s' if rounds != 1 else ''}"
    if settings.denoise == "ROUNDS":
        return f"{rounds_text} as asked, {sharp}"
    if rounds == 0:
        if noise is None:
            return "no noise found: left as it was"
        return f"noise about {noise:.2f} edge lengths: too little to remove, left as it was"
    if noise is None:
        return f"{rounds_text}, {sharp}"
    return f"noise about {noise:.2f} edge lengths: {rounds_text}, {sharp}"


def follow_uvs(before: np.ndarray, after: np.ndarray, triangles: np.ndarray,
               layer: UvLayer) -> np.ndarray:
    """The UV map's corner coordinates moved with the slide (``fairmesh.follow_texture``):
    the corners of one vertex that hold the same (u, v) are one texture coordinate, so that
    each side of a UV seam follows in its own chart."""
    corner_uvs = np.ascontiguousarray(layer.corner_uvs, dtype=np.float32)
    if len(corner_uvs) == 0 or len(triangles) == 0:
        return corner_uvs.copy()
    keys = np.empty(len(corner_uvs), dtype=[("vertex", np.int64), ("u", np.float32),
                                            ("v", np.float32)])
    keys["vertex"] = layer.corner_vertex
    keys["u"] = corner_uvs[:, 0]
    keys["v"] = corner_uvs[:, 1]
    distinct, of_corner = np.unique(keys, return_inverse=True)
    of_corner = of_corner.reshape(-1)
    table = np.column_stack([distinct["u"], distinct["v"]]).astype(np.float64)
    uv_faces = of_corner[np.asarray(layer.triangle_corners, dtype=np.int64)]
    moved = fairmesh.follow_texture(before, after, triangles, table, uv_faces)
    return np.ascontiguousarray(moved[of_corner], dtype=np.float32)

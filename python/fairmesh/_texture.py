"""Texture coordinates that follow their vertices' slide along the surface, for the adapters (as
``Mesh.save`` does for files): fairing moves vertices mostly across the surface (the smoothing)
and a little along it (the slide); a texture coordinate that stays with a vertex that slid drags
the texture with it. Each moved vertex's slide is the part of its move orthogonal to its normal
after the move; its end is located, in that normal's plane, on the faces around the vertex as
they were before the move (they all use the vertex's texture coordinate: trimesh keeps one
vertex per coordinate, so each side of a seam follows in its own chart), the face that holds it
best, and the texture coordinate is what that face's coordinates give there by barycentric
interpolation (clamped onto the face when the end lies beyond every face around the vertex)."""

import numpy as np


def follow(before: np.ndarray, after: np.ndarray, faces: np.ndarray,
           uv: np.ndarray) -> np.ndarray:
    """New texture coordinates, one per vertex, for vertices moved from ``before`` to ``after``
    on ``faces``; ``uv`` (n, 2) as they were. Vertices that did not move keep theirs."""
    before = np.asarray(before, dtype=np.float64)
    after = np.asarray(after, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    uv = np.asarray(uv, dtype=np.float64)
    corners = after[faces]
    face_normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normals = np.zeros_like(after)
    for k in range(3):
        np.add.at(normals, faces[:, k], face_normals)
    length = np.linalg.norm(normals, axis=1)
    normals = np.divide(normals, length[:, None], out=np.zeros_like(normals),
                        where=length[:, None] > 0)
    move = after - before
    slide = move - (move * normals).sum(axis=1)[:, None] * normals
    slid = (np.linalg.norm(slide, axis=1) > 0) & (length > 0)
    if not slid.any():
        return uv.copy()
    # Every (vertex, face around it) pair of a vertex that slid.
    vertex = faces.reshape(-1)
    face = np.repeat(np.arange(len(faces)), 3)
    keep = slid[vertex]
    vertex, face = vertex[keep], face[keep]
    a, b, c = (before[faces[face, k]] for k in range(3))
    n = normals[vertex]

    def flat(v):
        return v - (v * n).sum(axis=1)[:, None] * n

    e1, e2, w = flat(b - a), flat(c - a), flat(before[vertex] + slide[vertex] - a)
    d11, d12, d22 = (e1 * e1).sum(1), (e1 * e2).sum(1), (e2 * e2).sum(1)
    w1, w2 = (w * e1).sum(1), (w * e2).sum(1)
    denominator = d11 * d22 - d12 * d12
    usable = denominator > 1e-30 * np.maximum(d11 * d22, 1e-300)
    safe = np.where(usable, denominator, 1.0)
    beta = (d22 * w1 - d12 * w2) / safe
    gamma = (d11 * w2 - d12 * w1) / safe
    weights = np.stack([1.0 - beta - gamma, beta, gamma], axis=1)
    # The face that holds the end best: the largest smallest barycentric coordinate.
    score = np.where(usable, weights.min(axis=1), -np.inf)
    order = np.lexsort((-score, vertex))
    first = np.ones(len(order), dtype=bool)
    first[1:] = vertex[order][1:] != vertex[order][:-1]
    best = order[first]
    best = best[np.isfinite(score[best])]
    chosen = np.clip(weights[best], 0.0, None)
    chosen /= chosen.sum(axis=1)[:, None]
    result = uv.copy()
    result[vertex[best]] = np.einsum("ij,ijk->ik", chosen, uv[faces[face[best]]])
    return result

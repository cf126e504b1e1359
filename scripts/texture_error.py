#!/usr/bin/env python3
"""How far a faired OBJ's texture coordinates are from the texture of the clean mesh.

The yardstick of `io::uv_follow` (texture coordinates that follow their vertex's slide along the
surface; docs/measurements.md, "Texture coordinates that follow the slide"). For every vertex of
REFERENCE whose two-ring holds no UV-seam vertex (one texture coordinate per vertex there), the
texture the clean surface has at the point of its faces nearest to the vertex's new position in
OTHER, against the coordinate OTHER wrote for it, in the vertex's own mean texture-space edge
length. OTHER must have REFERENCE's vertices, texture coordinates and faces in the same order (an
OBJ written back by fairmesh, e.g. `fairmesh fair REFERENCE -o OTHER --rounds 10`).

Install: `python3 -m venv venv && venv/bin/pip install numpy`
Run:     `venv/bin/python scripts/texture_error.py REFERENCE.obj OTHER.obj [OTHER2.obj ...]`
Prints, per OTHER, the root mean square, the median, the 99th percentile and the largest error.
"""

import sys

import numpy as np


def read_obj(path):
    """Positions (n x 3), texture coordinates (m x 2) and triangles of (vertex, coordinate)
    corners (polygons as fans from their first corner) of an OBJ whose faces all have `v/vt`."""
    positions, uvs, triangles = [], [], []
    with open(path) as f:
        for line in f:
            words = line.split()
            if not words:
                continue
            if words[0] == "v":
                positions.append([float(x) for x in words[1:4]])
            elif words[0] == "vt":
                uvs.append([float(x) for x in words[1:3]])
            elif words[0] == "f":
                corners = []
                for corner in words[1:]:
                    parts = corner.split("/")
                    v, t = int(parts[0]), int(parts[1])
                    corners.append((v - 1 if v > 0 else len(positions) + v,
                                    t - 1 if t > 0 else len(uvs) + t))
                for i in range(1, len(corners) - 1):
                    triangles.append((corners[0], corners[i], corners[i + 1]))
    return np.array(positions), np.array(uvs), triangles


def nearest_weights(p, a, b, c):
    """Barycentric weights of the point of triangle abc nearest to p (Ericson, Real-Time
    Collision Detection, 5.1.5)."""
    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = ab @ ap, ac @ ap
    if d1 <= 0 and d2 <= 0:
        return np.array([1.0, 0.0, 0.0])
    bp = p - b
    d3, d4 = ab @ bp, ac @ bp
    if d3 >= 0 and d4 <= d3:
        return np.array([0.0, 1.0, 0.0])
    vc = d1 * d4 - d3 * d2
    if vc <= 0 and d1 >= 0 and d3 <= 0:
        v = d1 / (d1 - d3)
        return np.array([1 - v, v, 0.0])
    cp = p - c
    d5, d6 = ab @ cp, ac @ cp
    if d6 >= 0 and d5 <= d6:
        return np.array([0.0, 0.0, 1.0])
    vb = d5 * d2 - d1 * d6
    if vb <= 0 and d2 >= 0 and d6 <= 0:
        w = d2 / (d2 - d6)
        return np.array([1 - w, 0.0, w])
    va = d3 * d6 - d5 * d4
    if va <= 0 and d4 - d3 >= 0 and d5 - d6 >= 0:
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        return np.array([0.0, 1 - w, w])
    scale = 1 / (va + vb + vc)
    v, w = vb * scale, vc * scale
    return np.array([1 - v - w, v, w])


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    positions, uvs, triangles = read_obj(sys.argv[1])
    coordinates_of = [set() for _ in positions]
    faces_of = [[] for _ in positions]
    neighbours = [set() for _ in positions]
    for f, triangle in enumerate(triangles):
        for v, t in triangle:
            coordinates_of[v].add(t)
            faces_of[v].append(f)
            neighbours[v].update(u for u, _ in triangle)
    seam = [len(c) > 1 for c in coordinates_of]
    # The vertices measured: their two-ring's faces, and their own coordinate's texture-space
    # edge length.
    measured = []
    for v in range(len(positions)):
        if seam[v] or not faces_of[v]:
            continue
        ring = {f for u in neighbours[v] for f in faces_of[u]}
        if any(seam[u] for f in ring for u, _ in triangles[f]):
            continue
        (t,) = coordinates_of[v]
        edge = np.mean([np.linalg.norm(uvs[s] - uvs[t])
                        for f in faces_of[v] for u, s in triangles[f] if u != v])
        measured.append((v, t, ring, edge))
    for path in sys.argv[2:]:
        moved, written, _ = read_obj(path)
        errors = []
        for v, t, ring, edge in measured:
            best = None
            for f in ring:
                corners = np.array([positions[u] for u, _ in triangles[f]])
                weights = nearest_weights(moved[v], *corners)
                distance = np.linalg.norm(weights @ corners - moved[v])
                if best is None or distance < best[0]:
                    texture = weights @ np.array([uvs[s] for _, s in triangles[f]])
                    best = (distance, texture)
            errors.append(np.linalg.norm(written[t] - best[1]) / edge)
        errors = np.array(errors)
        print(f"{path}: {len(errors)} vertices away from seams; texture error RMS "
              f"{np.sqrt((errors ** 2).mean()):.4f}, median {np.median(errors):.4f}, "
              f"99th percentile {np.percentile(errors, 99):.3f}, largest {errors.max():.3f} "
              f"(texture-space edge lengths)")


if __name__ == "__main__":
    main()

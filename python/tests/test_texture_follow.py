"""``follow_texture``: texture coordinates that follow a slide, per vertex and per corner; and
``hierarchy``'s ``hard_edges``, kept sharp as ``fair``'s are."""

import warnings

import numpy as np
import pytest

import fairmesh


def grid(n=5):
    """A flat n x n grid (z = 0) and its triangles."""
    y, x = np.mgrid[0:n, 0:n]
    points = np.column_stack([x.ravel(), y.ravel(), np.zeros(n * n)]).astype(np.float64)
    faces = []
    for j in range(n - 1):
        for i in range(n - 1):
            v = j * n + i
            faces += [[v, v + 1, v + n + 1], [v, v + n + 1, v + n]]
    return points, np.array(faces)


def affine(points):
    """The texture: an affine map of the plane."""
    return np.column_stack([0.3 * points[:, 0] - 0.1 * points[:, 1] + 0.2,
                            0.05 * points[:, 0] + 0.25 * points[:, 1] - 0.4])


def test_a_slide_in_the_plane_takes_the_texture_of_the_new_place():
    before, faces = grid()
    after = before.copy()
    after[12] += [0.31, -0.22, 0.0]
    uvs = affine(before)
    moved = fairmesh.follow_texture(before, after, faces, uvs)
    assert moved.shape == uvs.shape and moved.dtype == np.float64
    np.testing.assert_allclose(moved[12], affine(after[12:13])[0], atol=1e-6)
    others = np.arange(len(before)) != 12
    assert np.array_equal(moved[others], uvs[others])
    # A move along the normal alone is no slide: the coordinate stays.
    lifted = before.copy()
    lifted[12, 2] = 0.4
    np.testing.assert_allclose(fairmesh.follow_texture(before, lifted, faces, uvs)[12],
                               uvs[12], atol=1e-9)


def test_per_corner_coordinates_follow_each_in_its_own_chart():
    before, faces = grid()
    after = before.copy()
    after[12] += [0.2, 0.15, 0.0]
    # A seam along x = 2: the corners left of it use one chart, those right of it another,
    # shifted by 5 in u; vertex 12 (2, 2) lies on it and has a coordinate in each.
    uvs = list(affine(before))
    right = {}
    uv_faces = faces.copy()
    for t, face in enumerate(faces):
        if before[face][:, 0].mean() > 2.0:
            for k, v in enumerate(face):
                if v not in right:
                    right[v] = len(uvs)
                    uvs.append(affine(before[v:v + 1])[0] + [5.0, 0.0])
                uv_faces[t, k] = right[v]
    uvs = np.array(uvs)
    moved = fairmesh.follow_texture(before, after, faces, uvs, uv_faces)
    expected = affine(after[12:13])[0]
    np.testing.assert_allclose(moved[12], expected, atol=1e-6)
    np.testing.assert_allclose(moved[right[12]], expected + [5.0, 0.0], atol=1e-6)


def test_a_coordinate_shared_by_moved_vertices_stays_with_a_warning():
    before, faces = grid()
    after = before.copy()
    after[[11, 12]] += [0.2, 0.1, 0.0]
    uvs = affine(before)
    uv_faces = faces.copy()
    uv_faces[uv_faces == 11] = 12  # vertices 11 and 12 share one coordinate
    with pytest.warns(fairmesh.MeshWarning, match="1 texture coordinates are shared"):
        moved = fairmesh.follow_texture(before, after, faces, uvs, uv_faces)
    assert np.array_equal(moved[12], uvs[12])


def test_arrays_that_do_not_fit_are_refused_by_name():
    before, faces = grid()
    uvs = affine(before)
    with pytest.raises(ValueError, match="after"):
        fairmesh.follow_texture(before, before[:-1], faces, uvs)
    with pytest.raises(ValueError, match="uvs has 24 rows"):
        fairmesh.follow_texture(before, before, faces, uvs[:-1])
    with pytest.raises(ValueError, match="uv_faces has 3 rows"):
        fairmesh.follow_texture(before, before, faces, uvs, faces[:3])
    with pytest.raises(ValueError, match="uv_faces"):
        fairmesh.follow_texture(before, before, faces, uvs[:4], faces)
    bad = uvs.copy()
    bad[3, 1] = np.nan
    with pytest.raises(ValueError, match=r"uvs\[3\] is not finite"):
        fairmesh.follow_texture(before, before, faces, bad)
    with pytest.raises(ValueError, match=r"shape \(k, 2\)"):
        fairmesh.follow_texture(before, before, faces, before)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        unmoved = fairmesh.follow_texture(before, before, faces, uvs)
    assert np.array_equal(unmoved, uvs)


def cube(cuts=8):
    """A cube of side 2 made of cuts x cuts squares a side, welded, and its 12 edges' pairs."""
    points, faces = [], []
    steps = np.linspace(-1.0, 1.0, cuts + 1)
    for axis in range(3):
        for side in (-1.0, 1.0):
            a, b = [i for i in range(3) if i != axis]
            base = len(points)
            for j in steps:
                for i in steps:
                    p = [0.0, 0.0, 0.0]
                    p[axis], p[a], p[b] = side, i, j
                    points.append(p)
            n = cuts + 1
            for j in range(cuts):
                for i in range(cuts):
                    v = base + j * n + i
                    quad = [[v, v + 1, v + n + 1], [v, v + n + 1, v + n]]
                    if (side > 0) != (axis == 1):
                        quad = [f[::-1] for f in quad]
                    faces += quad
    points = np.array(points)
    unique, inverse = np.unique(points.round(9), axis=0, return_inverse=True)
    faces = inverse.reshape(-1)[np.array(faces)]
    edges = set()
    for face in faces:
        for k in range(3):
            a, b = sorted((face[k], face[(k + 1) % 3]))
            on_rim = [(np.abs(np.abs(unique[v]) - 1.0) < 1e-9).sum() >= 2 for v in (a, b)]
            same_line = (np.abs(unique[a] - unique[b]) < 1e-9).sum() == 2
            if all(on_rim) and same_line:
                edges.add((a, b))
    return unique, faces, np.array(sorted(edges))


def rim_angle(vertices, faces, edges):
    corners = vertices[faces]
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    angles = []
    for a, b in edges:
        around = np.nonzero((faces == a).any(axis=1) & (faces == b).any(axis=1))[0]
        angles.append(np.degrees(np.arccos(np.clip(normals[around[0]] @ normals[around[1]],
                                                   -1, 1))))
    return float(np.mean(angles))


def test_hierarchy_keeps_the_hard_edges_given_sharp():
    clean, faces, rim = cube()
    noisy = fairmesh.noise(clean, faces, sigma=0.2, seed=3)
    # A crease angle of 180 degrees finds no crease: only the edges given are kept.
    kept = fairmesh.hierarchy(noisy, faces, crease_angle=180.0, hard_edges=rim, denoise="auto")
    faired = fairmesh.hierarchy(noisy, faces, crease_angle=180.0, denoise="auto")
    with_edges = rim_angle(kept.multires(2), faces, rim)
    without = rim_angle(faired.multires(2), faces, rim)
    assert with_edges > 70.0, with_edges
    assert without < with_edges - 10.0, (without, with_edges)
    # Given alone, they imply keep_creases.
    implied = fairmesh.hierarchy(noisy, faces, hard_edges=rim, denoise="auto")
    assert rim_angle(implied.multires(2), faces, rim) > 70.0
    with pytest.raises(ValueError, match="hard_edges"):
        fairmesh.hierarchy(noisy, faces, hard_edges=[[0, len(noisy)]])

"""fairmesh.trimesh and fairmesh.open3d: the same results as the arrays they hold."""

import numpy as np
import pytest

import fairmesh


def test_trimesh_meshes_fair_into_a_new_mesh(bunny):
    trimesh = pytest.importorskip("trimesh")
    import fairmesh.trimesh

    noisy = fairmesh.noise(bunny.vertices, bunny.faces)
    mesh = trimesh.Trimesh(noisy, bunny.faces, process=False)
    smooth, report = fairmesh.trimesh.fair(mesh, rounds=2)
    expected, _ = fairmesh.fair(noisy, bunny.faces, rounds=2)
    assert isinstance(smooth, trimesh.Trimesh) and report["rounds_run"] == 2
    np.testing.assert_array_equal(smooth.vertices, expected)
    np.testing.assert_array_equal(smooth.faces, mesh.faces)
    np.testing.assert_array_equal(mesh.vertices, noisy)  # the input is not changed
    levels = fairmesh.trimesh.hierarchy(mesh)
    assert levels.level_sizes[0] == (len(noisy), len(bunny.faces))


def test_open3d_meshes_fair_into_a_new_mesh(bunny):
    o3d = pytest.importorskip("open3d")
    import fairmesh.open3d

    noisy = fairmesh.noise(bunny.vertices, bunny.faces)
    mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(noisy),
                                     o3d.utility.Vector3iVector(bunny.faces.astype(np.int32)))
    smooth, _ = fairmesh.open3d.fair(mesh, rounds=2)
    expected, _ = fairmesh.fair(noisy, bunny.faces, rounds=2)
    np.testing.assert_array_equal(np.asarray(smooth.vertices), expected)

"""fairmesh.trimesh and fairmesh.open3d: the same results as the arrays they hold, no seam opened
on a mesh split at its UV seams, scenes faired with their transforms kept, and a clear TypeError
for what is not a mesh."""

import numpy as np
import pytest

import fairmesh
from conftest import REPOSITORY

TEXTURED = REPOSITORY / "tests" / "data" / "roundtrip" / "textured.obj"
SCENE = REPOSITORY / "tests" / "data" / "roundtrip" / "scene.glb"


def shared_positions(vertices):
    """The groups of rows (two or more) that hold the same position."""
    _, inverse, counts = np.unique(vertices, axis=0, return_inverse=True, return_counts=True)
    inverse = inverse.reshape(-1)
    return [np.flatnonzero(inverse == group) for group in np.flatnonzero(counts > 1)]


def assert_no_seam_opened(before, after):
    groups = shared_positions(before)
    assert groups, "the input has no position shared by several vertices"
    for rows in groups:
        assert (after[rows] == after[rows[0]]).all(), f"rows {rows} no longer share a position"
    return groups


def noisy_copy(mesh, seed):
    """``mesh`` with seeded noise, the copies of a position moved alike."""
    import fairmesh.trimesh

    return fairmesh.trimesh.noise(mesh, sigma=0.3, seed=seed)


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


def test_a_mesh_split_at_its_uv_seams_is_faired_with_no_seam_opened():
    trimesh = pytest.importorskip("trimesh")
    import fairmesh.trimesh

    mesh = trimesh.load(TEXTURED, force="mesh", process=False)
    welded = fairmesh.load(TEXTURED)
    # trimesh keeps one vertex per texture coordinate: 486 where the file has 386 positions.
    assert len(mesh.vertices) == 486 and len(welded.vertices) == 386
    noisy = noisy_copy(mesh, seed=3)
    groups = assert_no_seam_opened(mesh.vertices, noisy.vertices)
    smooth, report = fairmesh.trimesh.fair(noisy, rounds=3)
    assert_no_seam_opened(mesh.vertices, smooth.vertices)
    assert report["vertices"] == 386 and report["closed"]
    # Faired as one closed surface, it comes closer to the clean mesh than the noise was.
    before = fairmesh.compare(mesh.vertices, mesh.faces, noisy.vertices)
    after = fairmesh.compare(mesh.vertices, mesh.faces, smooth.vertices)
    assert after["mean_surface_distance"] < 0.8 * before["mean_surface_distance"]
    # Copy by copy (no welding), each side of a seam would be smoothed on its own: the seam
    # opens. This is what the welding prevents.
    apart, _ = fairmesh.fair(noisy.vertices, noisy.faces, rounds=3)
    assert any((apart[rows] != apart[rows[0]]).any() for rows in groups)


def test_a_mask_over_the_copies_is_read_over_the_welded_vertices():
    trimesh = pytest.importorskip("trimesh")
    import fairmesh.trimesh

    mesh = noisy_copy(trimesh.load(TEXTURED, force="mesh", process=False), seed=4)
    upper = mesh.vertices[:, 1] > np.median(mesh.vertices[:, 1])
    by_bools, report = fairmesh.trimesh.fair(mesh, rounds=2, mask=upper)
    by_indices, _ = fairmesh.trimesh.fair(mesh, rounds=2, mask=np.flatnonzero(upper))
    np.testing.assert_array_equal(by_bools.vertices, by_indices.vertices)
    assert_no_seam_opened(mesh.vertices, by_bools.vertices)
    still = ~upper
    # A position is faired if any copy is: the rest keep their positions exactly.
    faired_positions = {tuple(p) for p in mesh.vertices[upper]}
    kept = [i for i in np.flatnonzero(still) if tuple(mesh.vertices[i]) not in faired_positions]
    assert kept and report["masked_vertices"] < 386
    np.testing.assert_array_equal(by_bools.vertices[kept], mesh.vertices[kept])
    assert (by_bools.vertices[upper] != mesh.vertices[upper]).any()


def test_hard_edges_over_the_copies_are_kept_over_the_welded_vertices():
    trimesh = pytest.importorskip("trimesh")
    import fairmesh.trimesh
    from fairmesh._welding import Welded

    mesh = noisy_copy(trimesh.load(TEXTURED, force="mesh", process=False), seed=9)
    welded = Welded(mesh.vertices)
    rows = mesh.edges_unique[::7]
    kept, _ = fairmesh.trimesh.fair(mesh, rounds=2, hard_edges=rows)
    expected, _ = fairmesh.fair(welded.positions, welded.faces(mesh.faces), rounds=2,
                                hard_edges=welded.of_row[rows])
    np.testing.assert_array_equal(kept.vertices, expected[welded.of_row])
    plain, _ = fairmesh.trimesh.fair(mesh, rounds=2)
    assert (plain.vertices != kept.vertices).any()


def test_texture_coordinates_follow_the_slide_along_the_surface():
    trimesh = pytest.importorskip("trimesh")
    import fairmesh.trimesh

    # A flat grid, jittered in its plane, textured by its own x and y (`jittered_grid`).
    k = 30
    vertices, faces, uv = jittered_grid(k)
    xy = vertices[:, :2]
    visual = trimesh.visual.TextureVisuals(uv=uv,
                                           material=trimesh.visual.material.PBRMaterial())
    mesh = trimesh.Trimesh(vertices, faces, visual=visual, process=False)
    left = xy[:, 0] < k / 2
    # The paper's operator slides vertices along the surface (here, in the plane).
    smooth, _ = fairmesh.trimesh.fair(mesh, variant="paper", rounds=1, iterations=3,
                                      boundary="fixed", mask=left)
    after = smooth.vertices[:, :2]
    assert np.abs(smooth.vertices[:, 2]).max() == 0
    assert np.abs(after - xy).max() > 0.2  # edge lengths: the slide the texture would show
    np.testing.assert_allclose(smooth.visual.uv * (k - 1), after, atol=1e-9)
    # What did not move keeps its texture coordinate exactly; the input is not changed.
    still = (after == xy).all(axis=1)
    assert still.sum() >= (~left).sum()
    np.testing.assert_array_equal(smooth.visual.uv[still], mesh.visual.uv[still])
    np.testing.assert_array_equal(mesh.visual.uv, xy / (k - 1))


def test_a_scene_split_by_material_is_faired_whole_with_its_parts_kept():
    trimesh = pytest.importorskip("trimesh")
    import fairmesh.trimesh

    # trimesh.load gives the textured OBJ as a scene of two meshes, one per material, which
    # share the positions along the material boundary.
    scene = trimesh.load(TEXTURED, process=False)
    assert isinstance(scene, trimesh.Scene) and len(scene.geometry) == 2
    before = np.concatenate([g.vertices for g in scene.geometry.values()])
    smooth, reports = fairmesh.trimesh.fair(scene, rounds=3)
    assert isinstance(smooth, trimesh.Scene) and set(reports) == set(scene.geometry)
    # Faired as one welded mesh: 386 positions, the file's.
    assert all(r["vertices"] == 386 and r["closed"] for r in reports.values())
    after = np.concatenate([g.vertices for g in smooth.geometry.values()])
    groups = assert_no_seam_opened(before, after)
    sizes = [len(g.vertices) for g in scene.geometry.values()]
    across = [rows for rows in groups if rows.min() < sizes[0] <= rows.max()]
    assert across, "no position is shared by the two parts"
    assert (after != before).any()
    for name, geometry in smooth.geometry.items():
        assert geometry.visual.kind == scene.geometry[name].visual.kind
        assert geometry.visual.uv.shape == scene.geometry[name].visual.uv.shape
        np.testing.assert_array_equal(geometry.faces, scene.geometry[name].faces)
    # The scene given is not changed.
    np.testing.assert_array_equal(
        np.concatenate([g.vertices for g in scene.geometry.values()]), before)


def test_a_scene_keeps_its_transforms_and_fairs_each_geometry_in_its_own_place():
    trimesh = pytest.importorskip("trimesh")
    import fairmesh.trimesh

    scene = trimesh.load(SCENE, process=False)
    smooth, reports = fairmesh.trimesh.fair(scene, rounds=2)
    assert set(reports) == {"ball_mesh", "block_mesh"}
    for node in scene.graph.nodes_geometry:
        before, name = scene.graph.get(node)
        after, same_name = smooth.graph.get(node)
        assert same_name == name
        np.testing.assert_array_equal(after, before)
        assert smooth.geometry[name].vertices.shape == scene.geometry[name].vertices.shape
        assert (smooth.geometry[name].vertices != scene.geometry[name].vertices).any()
    # Each geometry placed once is faired where the scene puts it: in world coordinates, the
    # result is fairmesh.fair of the scene's meshes there.
    world = scene.to_geometry() if hasattr(scene, "to_geometry") else scene.dump(concatenate=True)
    expected, _ = fairmesh.trimesh.fair(world, rounds=2)
    faired_world = smooth.to_geometry() if hasattr(smooth, "to_geometry") else \
        smooth.dump(concatenate=True)
    np.testing.assert_allclose(faired_world.vertices, expected.vertices, atol=1e-5)


def test_a_geometry_placed_twice_is_faired_alone_and_stays_one_geometry():
    trimesh = pytest.importorskip("trimesh")
    import fairmesh.trimesh

    part = noisy_copy(trimesh.load(TEXTURED, force="mesh", process=False), seed=7)
    other = noisy_copy(trimesh.creation.icosphere(subdivisions=2), seed=8)
    scene = trimesh.Scene()
    moved = trimesh.transformations.translation_matrix([5.0, 0.0, 0.0])
    scene.add_geometry(part, geom_name="part", node_name="left")
    scene.graph.update(frame_to="right", frame_from=scene.graph.base_frame, matrix=moved,
                       geometry="part")
    scene.add_geometry(other, geom_name="ball", node_name="ball", transform=moved)
    smooth, reports = fairmesh.trimesh.fair(scene, rounds=2)
    assert set(smooth.geometry) == {"part", "ball"}
    for node in ("left", "right", "ball"):
        np.testing.assert_array_equal(smooth.graph.get(node)[0], scene.graph.get(node)[0])
    # Placed twice: faired in its own coordinates, as the mesh alone is.
    alone, report = fairmesh.trimesh.fair(part, rounds=2)
    np.testing.assert_array_equal(smooth.geometry["part"].vertices, alone.vertices)
    assert reports["part"]["vertices"] == report["vertices"] == 386
    # Placed once: faired where the scene puts it, and given back in its own coordinates.
    there = other.copy()
    there.apply_transform(moved)
    faired_there, _ = fairmesh.trimesh.fair(there, rounds=2)
    np.testing.assert_allclose(smooth.geometry["ball"].vertices + [5.0, 0.0, 0.0],
                               faired_there.vertices, atol=1e-6)


def test_what_is_not_a_mesh_is_refused_by_name():
    trimesh = pytest.importorskip("trimesh")
    import fairmesh.trimesh

    cloud = trimesh.PointCloud(np.random.default_rng(1).random((10, 3)))
    with pytest.raises(TypeError, match="takes a trimesh.Trimesh or a trimesh.Scene of them, "
                                        "not a trimesh.*PointCloud .points without faces"):
        fairmesh.trimesh.fair(cloud)
    with pytest.raises(TypeError, match="not a builtins.str"):
        fairmesh.trimesh.fair("scan.ply")


def open3d_or_skip():
    return pytest.importorskip("open3d", reason="open3d is not installed: the Open3D adapter "
                                                "is not tested here")


def test_open3d_meshes_fair_into_a_new_mesh(bunny):
    o3d = open3d_or_skip()
    import fairmesh.open3d

    noisy = fairmesh.noise(bunny.vertices, bunny.faces)
    mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(noisy),
                                     o3d.utility.Vector3iVector(bunny.faces.astype(np.int32)))
    smooth, _ = fairmesh.open3d.fair(mesh, rounds=2)
    expected, _ = fairmesh.fair(noisy, bunny.faces, rounds=2)
    np.testing.assert_array_equal(np.asarray(smooth.vertices), expected)


def test_open3d_meshes_split_at_seams_keep_their_seams_closed():
    o3d = open3d_or_skip()
    trimesh = pytest.importorskip("trimesh")
    import fairmesh.open3d

    split = noisy_copy(trimesh.load(TEXTURED, force="mesh", process=False), seed=6)
    mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(split.vertices),
                                     o3d.utility.Vector3iVector(split.faces.astype(np.int32)))
    mesh.compute_vertex_normals()
    smooth, report = fairmesh.open3d.fair(mesh, rounds=3)
    after = np.asarray(smooth.vertices)
    assert_no_seam_opened(split.vertices, after)
    assert report["vertices"] == 386 and smooth.has_vertex_normals()
    np.testing.assert_array_equal(np.asarray(mesh.vertices), split.vertices)  # not changed
    with pytest.raises(TypeError, match="takes an open3d.geometry.TriangleMesh, not a "
                                        "open3d.*PointCloud"):
        fairmesh.open3d.fair(o3d.geometry.PointCloud())


def jittered_grid(k=30):
    """A flat k x k grid jittered in its plane (z = 0), its faces, and its texture coordinates:
    its own x and y over k - 1, so that wherever a vertex slides in the plane, the texture there
    is its new x and y."""
    x, y = np.meshgrid(np.arange(k, dtype=float), np.arange(k, dtype=float))
    xy = np.stack([x.ravel(), y.ravel()], axis=1)
    inside = (xy > 0).all(axis=1) & (xy < k - 1).all(axis=1)
    xy[inside] += np.random.default_rng(1).uniform(-0.3, 0.3, (inside.sum(), 2))
    xy = xy.astype(np.float32).astype(np.float64)  # what fairmesh computes in: kept exactly
    corners = np.arange(k * k).reshape(k, k)[:-1, :-1].ravel()
    faces = np.concatenate([np.stack([corners, corners + 1, corners + k + 1], axis=1),
                            np.stack([corners, corners + k + 1, corners + k], axis=1)])
    return np.column_stack([xy, np.zeros(len(xy))]), faces, xy / (k - 1)


def test_open3d_texture_coordinates_follow_the_slide_corner_by_corner():
    o3d = open3d_or_skip()
    import fairmesh.open3d

    k = 30
    vertices, faces, uv = jittered_grid(k)
    mesh = o3d.geometry.TriangleMesh(o3d.utility.Vector3dVector(vertices),
                                     o3d.utility.Vector3iVector(faces.astype(np.int32)))
    # One coordinate per corner, as Open3D keeps them.
    mesh.triangle_uvs = o3d.utility.Vector2dVector(uv[faces].reshape(-1, 2))
    left = vertices[:, 0] < k / 2
    smooth, _ = fairmesh.open3d.fair(mesh, variant="paper", rounds=1, iterations=3,
                                     boundary="fixed", mask=left)
    after = np.asarray(smooth.vertices)
    assert np.abs(after[:, 2]).max() == 0
    assert np.abs(after[:, :2] - vertices[:, :2]).max() > 0.2  # a slide the texture would show
    corners = np.asarray(smooth.triangle_uvs)
    np.testing.assert_allclose(corners * (k - 1), after[faces].reshape(-1, 3)[:, :2], atol=1e-6)
    # The input mesh is not changed.
    np.testing.assert_array_equal(np.asarray(mesh.triangle_uvs), uv[faces].reshape(-1, 2))


def test_from_fairmesh_import_trimesh_keeps_the_trimesh_package_usable(bunny):
    real = pytest.importorskip("trimesh")
    from fairmesh import trimesh

    # The package's own names through the adapter, which takes its name.
    assert trimesh.Trimesh is real.Trimesh and trimesh.load is real.load
    assert trimesh.fair is fairmesh.trimesh.fair
    mesh = trimesh.Trimesh(bunny.vertices, bunny.faces, process=False)
    smooth, _ = trimesh.fair(mesh, rounds=1)
    assert isinstance(smooth, real.Trimesh)
    with pytest.raises(AttributeError):
        trimesh.no_such_name_in_trimesh


def test_from_fairmesh_import_open3d_keeps_the_open3d_package_usable():
    real = open3d_or_skip()
    from fairmesh import open3d

    assert open3d.geometry is real.geometry and open3d.utility is real.utility
    assert open3d.fair is fairmesh.open3d.fair

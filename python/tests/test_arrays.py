"""Arrays in, arrays out: shapes, dtypes, no change to the inputs, any layout read alike."""

import numpy as np
import pytest

import fairmesh


def test_loaded_mesh_gives_read_only_float64_vertices_and_int64_faces(bunny):
    assert bunny.vertices.shape == (37706, 3)
    assert bunny.vertices.dtype == np.float64
    assert bunny.faces.shape == (75408, 3)
    assert bunny.faces.dtype == np.int64
    assert not bunny.vertices.flags.writeable
    assert bunny.faces.min() == 0 and bunny.faces.max() == 37705
    assert bunny.closed and bunny.format == "obj"


def test_fair_keeps_the_vertex_count_and_the_float_type(bunny):
    noisy = fairmesh.noise(bunny.vertices, bunny.faces, sigma=0.3, seed=2)
    assert noisy.shape == bunny.vertices.shape and noisy.dtype == np.float64
    smooth, report = fairmesh.fair(noisy, bunny.faces, rounds=2)
    assert smooth.shape == noisy.shape and smooth.dtype == np.float64
    assert report["rounds_run"] == 2 and report["iterations_run"] == 20
    assert report["vertices"] == 37706 and report["faces"] == 75408
    single, _ = fairmesh.fair(noisy.astype(np.float32), bunny.faces, rounds=2)
    assert single.dtype == np.float32
    # The library computes in float32 positions either way: the same result.
    np.testing.assert_array_equal(single, smooth.astype(np.float32))


def test_fair_moves_vertices_towards_the_clean_surface(bunny):
    noisy = fairmesh.noise(bunny.vertices, bunny.faces, sigma=0.3, seed=1)
    smooth, report = fairmesh.fair(noisy, bunny.faces)
    before = fairmesh.compare(bunny.vertices, bunny.faces, noisy)
    after = fairmesh.compare(bunny.vertices, bunny.faces, smooth)
    assert after["mean_surface_distance"] < 0.7 * before["mean_surface_distance"]
    assert abs(report["volume_change_percent"]) < 0.1
    assert report["rounds_run"] > 1


def test_inputs_are_not_changed_and_any_layout_or_integer_type_reads_alike(bunny):
    noisy = fairmesh.noise(bunny.vertices, bunny.faces, seed=3)
    kept = noisy.copy()
    reference, _ = fairmesh.fair(noisy, bunny.faces, rounds=1)
    np.testing.assert_array_equal(noisy, kept)
    fortran = np.asfortranarray(noisy)
    strided = np.hstack([noisy, noisy])[:, :3]  # rows of a wider array: not contiguous
    assert not strided.flags.c_contiguous
    np.testing.assert_array_equal(strided, noisy)
    for vertices in (fortran, strided, noisy.tolist()):
        for faces in (bunny.faces.astype(np.int32), bunny.faces.astype(np.uint32),
                      bunny.faces.astype(np.uint64)):
            result, _ = fairmesh.fair(vertices, faces, rounds=1)
            np.testing.assert_array_equal(result, reference)


def test_results_are_new_writable_arrays(bunny):
    smooth, _ = fairmesh.fair(bunny.vertices, bunny.faces, rounds=1)
    assert smooth.flags.writeable and smooth.flags.c_contiguous
    assert not np.shares_memory(smooth, bunny.vertices)


def test_baselines_run_with_their_options(bunny):
    noisy = fairmesh.noise(bunny.vertices, bunny.faces)
    lap, report = fairmesh.fair(noisy, bunny.faces, method="laplacian", iterations=5)
    assert report["method"] == "laplacian" and report["variant"] is None
    assert report["iterations_run"] == 5
    stronger, _ = fairmesh.fair(noisy, bunny.faces, method="laplacian", iterations=5,
                                lambda_=0.9)
    assert not np.array_equal(lap, stronger)
    taubin, report = fairmesh.fair(noisy, bunny.faces, method="taubin", mu=-0.6)
    assert report["method"] == "taubin"
    hc, report = fairmesh.fair(noisy, bunny.faces, method="HC", alpha=0.2, beta=0.6)
    assert report["method"] == "hc"


def test_a_mask_keeps_every_other_vertex_in_place(bunny):
    noisy = fairmesh.noise(bunny.vertices, bunny.faces)
    inside = np.arange(0, 5000)
    smooth, report = fairmesh.fair(noisy, bunny.faces, rounds=2, mask=inside)
    assert report["masked_vertices"] == 5000
    np.testing.assert_array_equal(smooth[5000:], noisy[5000:].astype(np.float32))
    assert np.any(smooth[:5000] != noisy[:5000].astype(np.float32))
    weights = np.zeros(len(noisy))
    weights[:5000] = 1.0
    by_weight, _ = fairmesh.fair(noisy, bunny.faces, rounds=2, mask=weights)
    np.testing.assert_array_equal(by_weight, smooth)


def test_measure_adds_the_distances_to_the_report(bunny):
    noisy = fairmesh.noise(bunny.vertices, bunny.faces)
    _, report = fairmesh.fair(noisy, bunny.faces, rounds=1, measure=True)
    assert report["mean_surface_distance"] > 0 and report["hausdorff"] > 0
    assert report["rms"] > 0


def test_a_small_open_mesh_with_a_repeated_corner_triangle(tmp_path):
    # A square of two triangles plus one that repeats a vertex (left out, as loading does).
    vertices = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.2]], dtype=np.float64)
    faces = np.array([[0, 1, 2], [0, 2, 3], [1, 1, 2]])
    smooth, report = fairmesh.fair(vertices, faces, rounds=1)
    assert smooth.shape == (4, 3) and not report["closed"]


def test_save_and_load_arrays_round_trip(tmp_path, bunny):
    path = tmp_path / "bunny.ply"
    fairmesh.save(path, bunny.vertices, bunny.faces)
    again = fairmesh.load(path)
    np.testing.assert_array_equal(again.vertices, bunny.vertices)
    np.testing.assert_array_equal(again.faces, bunny.faces)
    assert str(path) == again.path


def test_the_bundled_bunny_loads_by_name():
    bunny = fairmesh.load("@bunny")
    assert bunny.vertices.shape == (37706, 3)


def test_hierarchy_levels_and_repeated_multires(bunny):
    noisy = fairmesh.noise(bunny.vertices, bunny.faces)
    levels = fairmesh.hierarchy(noisy, bunny.faces)
    sizes = levels.level_sizes
    assert len(sizes) == levels.level_count == levels.coarsest_level + 1
    assert sizes[0] == (37706, 75408)
    assert all(a[0] > b[0] for a, b in zip(sizes, sizes[1:]))
    vertices, faces, original = levels.level(levels.coarsest_level)
    assert vertices.shape == (sizes[-1][0], 3) and faces.shape[1] == 3
    assert faces.max() < len(vertices)
    # Each kept vertex sits where its level-0 vertex is.
    np.testing.assert_array_equal(vertices, noisy[original].astype(np.float32))
    first = levels.multires(8)
    again = levels.multires(8)
    np.testing.assert_array_equal(first, again)
    smoother = levels.multires(12)
    assert first.shape == noisy.shape
    # The coarser the start, the smoother: further from the noisy input.
    moved8 = fairmesh.compare(noisy, bunny.faces, first)["rms"]
    moved12 = fairmesh.compare(noisy, bunny.faces, smoother)["rms"]
    assert 0 < moved8 < moved12


def test_vertices_no_face_uses_stay_where_they_are(bunny):
    noisy = fairmesh.noise(bunny.vertices, bunny.faces)
    loose = np.vstack([noisy, [[5.0, 5.0, 5.0]]])
    smooth, report = fairmesh.fair(loose, bunny.faces, rounds=2)
    expected, _ = fairmesh.fair(noisy, bunny.faces, rounds=2)
    np.testing.assert_array_equal(smooth[-1], [5.0, 5.0, 5.0])
    np.testing.assert_array_equal(smooth[:-1], expected)
    assert report["vertices"] == len(loose)


def test_a_loaded_mesh_saves_back_its_own_positions(tmp_path, bunny):
    out = tmp_path / "same.obj"
    bunny.save(out)
    np.testing.assert_array_equal(fairmesh.load(out).vertices, bunny.vertices)

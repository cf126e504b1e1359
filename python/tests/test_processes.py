"""Processes: a pool made by fork, forkserver or spawn after the parent used every entry point
gets every result (the thread pool is the process's own); a Mesh pickles; the batch recipe runs
on a handful of files."""

import multiprocessing
import pickle
import shutil
import warnings

import numpy as np
import pytest

import fairmesh
import fairmesh.batch
from conftest import REPOSITORY

ELEPHANT = REPOSITORY / "tests" / "data" / "elephant.obj"
MUSHROOM = REPOSITORY / "tests" / "data" / "mushroom_open.obj"
# What a pool that hangs is given before the test calls it a hang: far beyond the seconds the
# work takes, so only a child that never answers reaches it.
HANG = 600


def every_entry_point(path):
    """Every call of the package on one file, as arrays a parent can compare: load, noise,
    compare, fair (arrays and Mesh, with threads=1 and without), hierarchy (arrays, and Mesh
    with a denoise), multires (with a mask too), level, hard_edges (``saved_and_read_back``:
    Mesh.save and save)."""
    mesh = fairmesh.load(path)
    noisy = fairmesh.noise(mesh.vertices, mesh.faces, sigma=0.3, seed=5)
    smooth, report = fairmesh.fair(noisy, mesh.faces, rounds=3)
    single, _ = fairmesh.fair(noisy, mesh.faces, rounds=3, threads=1)
    from_mesh, _ = fairmesh.fair(mesh, rounds=2)
    distances = fairmesh.compare(mesh.vertices, mesh.faces, smooth)
    levels = fairmesh.hierarchy(noisy, mesh.faces, min_vertices=200)
    multires = levels.multires(2)
    coarse, _, _ = levels.level(levels.coarsest_level)
    denoised = fairmesh.hierarchy(mesh, keep_creases=True, denoise="auto", min_vertices=200)
    from_file = denoised.multires(2, mask=mesh.vertices[:, 1] > 0)
    return {
        "noisy": noisy,
        "smooth": smooth,
        "single": single,
        "from_mesh": from_mesh,
        "rounds_run": report["rounds_run"],
        "hausdorff": distances["hausdorff"],
        "multires": multires,
        "coarse": coarse,
        "from_file": from_file,
        "hard_edges": mesh.hard_edges,
    }


def saved_and_read_back(folder):
    mesh = fairmesh.load(ELEPHANT)
    mesh.save(folder / "elephant.ply", mesh.vertices)
    fairmesh.save(folder / "bare.off", mesh.vertices, mesh.faces)
    return (fairmesh.load(folder / "elephant.ply").vertices,
            fairmesh.load(folder / "bare.off").vertices)


@pytest.fixture(scope="module")
def in_parent(tmp_path_factory):
    """The parent's results, every entry point used (so its thread pool runs) before any pool
    is made."""
    results = every_entry_point(ELEPHANT)
    saved = saved_and_read_back(tmp_path_factory.mktemp("parent"))
    return results, saved


def child_saves(folder):
    return saved_and_read_back(folder)


@pytest.mark.parametrize("method", ["fork", "forkserver", "spawn"])
def test_a_pool_made_after_the_parent_used_fairmesh_gets_every_result(method, in_parent,
                                                                      tmp_path):
    if method not in multiprocessing.get_all_start_methods():
        pytest.skip(f"this platform has no {method!r} start method")
    expected, saved = in_parent
    context = multiprocessing.get_context(method)
    with warnings.catch_warnings():
        # Python 3.12 and newer warn that forking a process with threads may deadlock: the
        # warning this test proves wrong for fairmesh.
        warnings.simplefilter("ignore", DeprecationWarning)
        with context.Pool(2) as pool:
            pending = pool.map_async(every_entry_point, [ELEPHANT, ELEPHANT])
            folders = [tmp_path / "a", tmp_path / "b"]
            for folder in folders:
                folder.mkdir()
            written = pool.map_async(child_saves, folders)
            results = pending.get(timeout=HANG)
            files = written.get(timeout=HANG)
    for result in results:
        assert set(result) == set(expected)
        for key, value in expected.items():
            np.testing.assert_array_equal(result[key], value, err_msg=key)
    for ply, off in files:
        np.testing.assert_array_equal(ply, saved[0])
        np.testing.assert_array_equal(off, saved[1])


def test_a_loaded_mesh_pickles_as_its_file(tmp_path):
    copy = tmp_path / "mushroom.obj"
    shutil.copy(MUSHROOM, copy)
    mesh = fairmesh.load(copy)
    again = pickle.loads(pickle.dumps(mesh))
    assert isinstance(again, fairmesh.Mesh)
    np.testing.assert_array_equal(again.vertices, mesh.vertices)
    np.testing.assert_array_equal(again.faces, mesh.faces)
    assert again.path == str(copy) and again.format == "obj" and again.closed == mesh.closed
    # It saves as the original does.
    smooth, _ = fairmesh.fair(mesh, rounds=2)
    mesh.save(tmp_path / "first.obj", smooth)
    again.save(tmp_path / "second.obj", smooth)
    assert (tmp_path / "first.obj").read_bytes() == (tmp_path / "second.obj").read_bytes()
    bunny = pickle.loads(pickle.dumps(fairmesh.load("@bunny")))
    assert bunny.path == "@bunny" and len(bunny.vertices) == 37706
    # A file changed since is refused, naming it.
    pickled = pickle.dumps(mesh)
    shutil.copy(ELEPHANT, copy)
    with pytest.raises(ValueError, match="mushroom.obj changed since this fairmesh.Mesh was "
                                         "pickled"):
        pickle.loads(pickled)


def test_the_batch_recipe_fairs_a_handful_of_files_in_a_process_pool(tmp_path):
    sources = []
    for name in ("elephant.obj", "mushroom_open.obj", "bunny_npm.obj"):
        source = tmp_path / name
        shutil.copy(REPOSITORY / "tests" / "data" / name, source)
        sources.append(source)
    broken = tmp_path / "broken.obj"
    broken.write_text("v 0 0 0\nf 1 2 3\n")
    sources.append(broken)
    jobs = [(s, s.with_name(s.stem + "_faired" + s.suffix)) for s in sources]
    # The parent has used fairmesh; fork is the start method that hung.
    fairmesh.load(ELEPHANT)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        outcomes = dict(fairmesh.batch.fair_files(jobs, processes=2, start_method="fork",
                                                  rounds=2))
    assert set(outcomes) == {str(s) for s in sources}
    assert isinstance(outcomes[str(broken)], fairmesh.MeshFileError)
    assert "broken.obj" in str(outcomes[str(broken)])
    for source, destination in jobs[:3]:
        report = outcomes[str(source)]
        assert report["rounds_run"] == 2 and report["output"] == str(destination)
        # What the worker wrote is what fairing the file here gives.
        expected, _ = fairmesh.fair(fairmesh.load(source), rounds=2)
        np.testing.assert_array_equal(fairmesh.load(destination).vertices, expected)
    assert not jobs[3][1].exists()

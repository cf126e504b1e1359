"""Bad arguments and bad files: exceptions that name the argument or the file."""

import numpy as np
import pytest

import fairmesh


def test_bad_arrays_name_the_argument(bunny):
    v, f = bunny.vertices, bunny.faces
    with pytest.raises(ValueError, match=r"vertices must have shape \(n, 3\), not \(37706, 2\)"):
        fairmesh.fair(v[:, :2], f)
    with pytest.raises(TypeError, match="vertices must be an array of floats"):
        fairmesh.fair(v.astype(np.int64), f)
    with pytest.raises(TypeError, match="faces must be an array of integers"):
        fairmesh.fair(v, f.astype(np.float64))
    with pytest.raises(ValueError, match=r"faces must have shape \(m, 3\)"):
        fairmesh.fair(v, f.ravel())
    bad = f.copy()
    bad[7, 1] = 37706
    with pytest.raises(ValueError, match=r"faces\[7\] names vertex 37706, but there are 37706"):
        fairmesh.fair(v, bad)
    bad[7, 1] = -1
    with pytest.raises(ValueError, match=r"faces\[7\] names vertex -1"):
        fairmesh.fair(v, bad)
    nan = v.copy()
    nan[3, 0] = np.nan
    with pytest.raises(ValueError, match=r"vertices\[3\] is not finite"):
        fairmesh.fair(nan, f)
    with pytest.raises(TypeError, match="faces is needed"):
        fairmesh.fair(v)
    with pytest.raises(TypeError, match="vertices must be an array, not None"):
        fairmesh.noise(None, f)


@pytest.mark.parametrize(
    "options, error, pattern",
    [
        ({"method": "gauss"}, ValueError, "method must be one of"),
        ({"iterations": -1}, ValueError, "iterations must be 0 or more"),
        ({"iterations": "ten"}, TypeError, "iterations"),
        ({"rounds": -2}, ValueError, "rounds must be 0 or more"),
        ({"crease_angle": 200}, ValueError, "crease_angle must be a number from 0 to 180"),
        ({"tangential": 1.5}, ValueError, "tangential must be a number from 0 to 1"),
        ({"boundary": "loose"}, ValueError, "boundary must be one of \"curve\", \"fixed\""),
        ({"variant": "exact"}, ValueError, "variant must be one of"),
        ({"lambda_": float("nan")}, ValueError, "lambda_ must be a finite number"),
        ({"mask": np.zeros(5)}, ValueError, "mask has 5 weights but there are 37706"),
        ({"mask": np.zeros(37706)}, ValueError, "mask lets no vertex move"),
        ({"mask_falloff": 2}, ValueError, "mask_falloff needs a mask"),
        ({"no_such_option": 1}, TypeError, "no_such_option"),
    ],
)
def test_bad_options_name_the_argument(bunny, options, error, pattern):
    with pytest.raises(error, match=pattern):
        fairmesh.fair(bunny.vertices, bunny.faces, **options)


def test_bad_hierarchy_and_multires_arguments(bunny):
    with pytest.raises(ValueError, match="min_vertices must be 0 or more"):
        fairmesh.hierarchy(bunny, min_vertices=-1)
    levels = fairmesh.hierarchy(bunny)
    with pytest.raises(ValueError, match="level must be from 0 to"):
        levels.level(1000)
    with pytest.raises(ValueError, match="start_level must be 0 or more"):
        levels.multires(-1)
    with pytest.raises(ValueError, match="variant must be one of \"improved\", \"paper\""):
        levels.multires(3, variant="exact")
    with pytest.raises(ValueError, match="denoise must be None, \"auto\", \"off\" or a number"):
        fairmesh.hierarchy(bunny, denoise="lots")
    with pytest.raises(TypeError, match="denoise must be"):
        fairmesh.hierarchy(bunny, denoise=True)


def test_a_missing_file_is_a_file_not_found_error_naming_it(tmp_path):
    missing = tmp_path / "nowhere.obj"
    with pytest.raises(FileNotFoundError) as caught:
        fairmesh.load(missing)
    assert caught.value.filename == str(missing)
    assert str(missing) in str(caught.value)


def test_a_broken_file_names_the_file_and_the_line(tmp_path):
    broken = tmp_path / "broken.obj"
    broken.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n")
    with pytest.raises(fairmesh.MeshFileError) as caught:
        fairmesh.load(broken)
    message = str(caught.value)
    assert message.startswith(f"{broken}: line 4:"), message
    assert caught.value.filename == str(broken)
    assert isinstance(caught.value, ValueError)
    unknown = tmp_path / "mesh.xyz"
    unknown.write_text("1 2 3\n")
    with pytest.raises(fairmesh.MeshFileError, match="unknown file extension"):
        fairmesh.load(unknown)


def test_saving_checks_the_vertices_and_warns_what_it_cannot_keep(tmp_path, bunny):
    textured = fairmesh.load(bunny.path.replace("assets/bunny00.obj",
                                                "tests/data/roundtrip/textured.obj"))
    with pytest.raises(ValueError, match="vertices has 3 rows but the mesh has"):
        textured.save(tmp_path / "out.obj", np.zeros((3, 3)))
    with pytest.warns(fairmesh.MeshWarning, match="out.stl"):
        textured.save(tmp_path / "out.stl")
    with pytest.raises(fairmesh.MeshFileError, match="unknown file extension"):
        textured.save(tmp_path / "out.abc")
    nowhere = tmp_path / "no" / "such" / "folder.ply"
    with pytest.raises(OSError, match=f"{nowhere}: cannot write the file: the folder .* does not"):
        fairmesh.save(nowhere, bunny.vertices, bunny.faces)


def test_a_mask_is_unambiguous(bunny):
    v, f = bunny.vertices, bunny.faces
    upper = v[:, 1] > np.median(v[:, 1])
    # Bools, float weights and the indices of the same vertices are the same mask.
    by_bools, report = fairmesh.fair(v, f, rounds=1, mask=upper)
    assert report["masked_vertices"] == upper.sum()
    for same in (upper.astype(np.float32), np.flatnonzero(upper), upper.tolist()):
        result, _ = fairmesh.fair(v, f, rounds=1, mask=same)
        np.testing.assert_array_equal(result, by_bools)
    # One 0 or 1 per vertex as integers could be either: refused, with how to write each.
    for ambiguous in (upper.astype(np.int64), upper.astype(np.uint8), upper.astype(int).tolist()):
        with pytest.raises(ValueError, match=r"mask is an integer array of 37706 values, each 0 "
                                             r"or 1, one per vertex: it could be weights or "
                                             r"vertex indices\. .*mask\.astype\(bool\).*"
                                             r"mask\.nonzero\(\)\[0\]"):
            fairmesh.fair(v, f, rounds=1, mask=ambiguous)
    levels = fairmesh.hierarchy(v, f)
    with pytest.raises(ValueError, match="mask is an integer array of 37706 values"):
        levels.multires(3, mask=upper.astype(np.int32))
    # Indices that are not one a vertex are indices, as before.
    few, _ = fairmesh.fair(v, f, rounds=1, mask=np.array([0, 1, 1, 0]))
    assert (few[2:] == v[2:]).all()


def test_old_variant_names_are_accepted_and_numbers_read_plainly(bunny):
    v, f = bunny.vertices, bunny.faces
    new, report = fairmesh.fair(v, f, rounds=1, variant="improved")
    paper, _ = fairmesh.fair(v, f, rounds=1, variant="paper")
    assert not np.array_equal(paper, new)  # so the names below choose something
    for old in ("normal-projected", "normal_projected", "projected", "Improved"):
        result, _ = fairmesh.fair(v, f, rounds=1, variant=old)
        np.testing.assert_array_equal(result, new)
    assert report["variant"] == "improved"  # as `fairmesh fair --json` names it
    with pytest.raises(ValueError, match=r'variant must be one of "improved", "paper", not '
                                         r'"exact"$'):
        fairmesh.fair(v, f, variant="exact")
    with pytest.raises(ValueError, match=r"sigma must be a finite number of 0 or more, not -1$"):
        fairmesh.noise(v, f, sigma=-1)
    with pytest.raises(ValueError, match=r"tolerance must be a finite number of 0 or more, not "
                                         r"-0\.5$"):
        fairmesh.fair(v, f, tolerance=-0.5)


def test_compare_with_other_vertices_asks_for_their_faces(bunny):
    other = fairmesh.load(bunny.path.replace("assets/bunny00.obj", "tests/data/elephant.obj"))
    with pytest.raises(ValueError, match=r"vertices has 2775 rows but the reference has 37706 "
                                         r"vertices: without faces, .* pass faces="):
        fairmesh.compare(bunny.vertices, bunny.faces, other.vertices)
    result = fairmesh.compare(bunny.vertices, bunny.faces, other.vertices, other.faces)
    assert not result["same_connectivity"]

"""The same results as the command-line tool on the bundled bunny."""

import json
import subprocess

import numpy as np

import fairmesh
from conftest import BUNNY


def run(cli, *args):
    done = subprocess.run([cli, *map(str, args)], capture_output=True, text=True, check=True)
    return done.stdout


def test_noise_and_fair_match_the_command_line(cli, tmp_path, bunny):
    noisy_file = tmp_path / "noisy.ply"
    run(cli, "noise", BUNNY, "-o", noisy_file, "--sigma", "0.3", "--seed", "1")
    noisy = fairmesh.noise(bunny.vertices, bunny.faces, sigma=0.3, seed=1)
    from_cli = fairmesh.load(noisy_file)
    np.testing.assert_array_equal(from_cli.vertices, noisy)

    faired_file = tmp_path / "faired.ply"
    cli_report = json.loads(run(cli, "fair", noisy_file, "-o", faired_file, "--json"))
    smooth, report = fairmesh.fair(from_cli)
    np.testing.assert_array_equal(fairmesh.load(faired_file).vertices, smooth)
    assert set(report) == set(cli_report)
    for field in ("method", "variant", "vertices", "faces", "closed", "iterations_run",
                  "rounds_run", "crease_edges", "loose_triangles", "masked_vertices"):
        assert report[field] == cli_report[field], field
    for field in ("noise_estimate", "max_move", "volume_change_percent"):
        assert report[field] == cli_report[field], field
    assert report["risk_by_round"] == cli_report["risk_by_round"]
    assert set(report["phases_ms"]) == set(cli_report["phases_ms"])
    assert report["input"] == str(noisy_file)
    # From arrays the same (the bunny's file marks no sharp edges).
    from_arrays, array_report = fairmesh.fair(noisy, bunny.faces)
    np.testing.assert_array_equal(from_arrays, smooth)
    assert array_report["input"] is None and set(array_report) == set(cli_report)


def test_options_reach_the_fairing_as_the_command_line_passes_them(cli, tmp_path, bunny):
    noisy = tmp_path / "noisy.ply"
    run(cli, "noise", BUNNY, "-o", noisy, "--seed", "4", "--mode", "iso")
    out = tmp_path / "out.ply"
    cli_report = json.loads(run(cli, "fair", noisy, "-o", out, "--json", "--rounds", "3",
                                "--crease-angle", "30", "--tangential", "0.3",
                                "--boundary", "fixed", "--no-volume-correction"))
    smooth, report = fairmesh.fair(fairmesh.load(noisy), rounds=3, crease_angle=30,
                                   tangential=0.3, boundary="fixed",
                                   no_volume_correction=True)
    np.testing.assert_array_equal(fairmesh.load(out).vertices, smooth)
    assert report["crease_edges"] == cli_report["crease_edges"]
    taubin = tmp_path / "taubin.ply"
    run(cli, "fair", noisy, "-o", taubin, "--method", "taubin", "--iterations", "7",
        "--mu", "-0.6")
    result, _ = fairmesh.fair(fairmesh.load(noisy), method="taubin", iterations=7, mu=-0.6)
    np.testing.assert_array_equal(fairmesh.load(taubin).vertices, result)


def test_multires_matches_the_command_line(cli, tmp_path, bunny):
    out = tmp_path / "multires.ply"
    # The hierarchy as `fairmesh hierarchy` builds it (no creases unless asked), no denoise.
    run(cli, "multires", BUNNY, "--level", "9", "-o", out, "--denoise", "off", "--no-creases")
    levels = fairmesh.hierarchy(bunny)
    np.testing.assert_array_equal(fairmesh.load(out).vertices, levels.multires(9))
    listed = json.loads(run(cli, "hierarchy", BUNNY, "--json"))["levels"]
    assert [(level["vertices"], level["faces"]) for level in listed] == levels.level_sizes


def test_a_hierarchy_denoised_first_is_the_command_lines_multires(cli, tmp_path):
    # The editor's pipeline: denoised as `fair` does, then the levels built on the result.
    noisy_file = tmp_path / "noisy.ply"
    run(cli, "noise", BUNNY, "-o", noisy_file, "--sigma", "0.3")
    noisy = fairmesh.load(noisy_file)
    levels = fairmesh.hierarchy(noisy, denoise="auto", keep_creases=True)
    faired_file = tmp_path / "fair.ply"
    report = json.loads(run(cli, "fair", noisy_file, "-o", faired_file, "--json"))
    assert levels.denoise["rounds_run"] == report["rounds_run"] > 0
    assert levels.denoise["crease_edges"] == report["crease_edges"]
    np.testing.assert_array_equal(levels.multires(0), fairmesh.load(faired_file).vertices)
    coarse_file = tmp_path / "level4.ply"
    run(cli, "multires", noisy_file, "--level", "4", "-o", coarse_file)
    np.testing.assert_array_equal(levels.multires(4), fairmesh.load(coarse_file).vertices)
    assert fairmesh.hierarchy(noisy).denoise is None


def test_compare_matches_the_command_line(cli, tmp_path, bunny):
    noisy_file = tmp_path / "noisy.ply"
    run(cli, "noise", BUNNY, "-o", noisy_file)
    cli_result = json.loads(run(cli, "compare", BUNNY, noisy_file, "--json"))
    result = fairmesh.compare(bunny.vertices, bunny.faces, fairmesh.load(noisy_file).vertices)
    for field, value in result.items():
        assert cli_result[field] == value, field
    assert set(cli_result) - set(result) == {"reference", "other"}


def test_a_loaded_file_is_written_back_as_the_command_line_writes_it(cli, tmp_path):
    textured = BUNNY.parent.parent / "tests" / "data" / "roundtrip" / "textured.obj"
    out_cli = tmp_path / "cli" / "out.obj"
    out_cli.parent.mkdir()
    run(cli, "fair", textured, "-o", out_cli, "--rounds", "2")
    mesh = fairmesh.load(textured)
    smooth, _ = fairmesh.fair(mesh, rounds=2)
    out_py = tmp_path / "py" / "out.obj"
    out_py.parent.mkdir()
    mesh.save(out_py, smooth)
    assert out_py.read_bytes() == out_cli.read_bytes()

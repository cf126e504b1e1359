#!/usr/bin/env python3
"""fairmesh's default `fair` against the smoothers users would pick instead, on meshes nobody
tuned fairmesh for.

For each mesh, noise mode and seed: `fairmesh noise` (sigma 0.3 mean edge lengths, seed 1 or
`--seed S[,S...]`), then
`fairmesh fair` with its defaults (no flags), and each peer at every iteration count of a scan;
each result is measured with `fairmesh compare CLEAN RESULT --json` (one metric for all: mean
surface distance both ways, in mean edge lengths of the clean mesh; mean face-normal error in
degrees; volume change against the clean mesh in percent; sharpened edges: how many edges bend
over 30° beyond the clean mesh's, the ridges a smoothing added or the noise it left). A peer's
row is its best iteration count by mean distance, picked knowing the clean mesh (an advantage no
user has).

Peers: fairmesh's own baselines (`fair --method laplacian|taubin|hc`, the "Laplacian, Taubin and
HC baselines" the default's targets name), and those installed of trimesh (Taubin, Humphrey,
Laplacian), PyMeshLab (Taubin, HC Laplacian), Open3D (Taubin). Install them in a virtual
environment:
    python3 -m venv venv && venv/bin/pip install -r scripts/peers/requirements.txt

With fairmesh's Python package installed there too (`venv/bin/pip install ./python`), the
baselines and the measures of the peers' results run in the script's own process (much faster:
no file is written and no command started per iteration count); the command line still makes the
noise, runs the default `fair` and measures it. Run from the repository root after
`cargo build --release`:
    venv/bin/python scripts/peers/compare_peers.py MESH [MESH ...] [--modes normal,iso]
        [--fair-flags "--no-creases --rounds 3"] [--no-peers] [--seed 1,2,3]
`--fair-flags` gives `fair` other flags than its defaults; `--no-peers` runs `fair` alone (to
compare settings of `fair` on a set of meshes); `--seed` noises with other seeds, and with
several it ends with each mesh and mode over the seeds. Prints a Markdown table per mesh and noise mode, then a summary: for each, `fair`'s mean distance
against the best peer's, and in how many cases `fair` ends closer. The set of clean meshes the
project measures on (the repository's, the CAD-like parts, and those `docs/measurements.md` names)
is written as PLY files by
    cargo run --release --example fairing_default -- --save DIR --files ...
"""

import argparse
import json
import os
import shlex
import subprocess
import sys
import tempfile

import numpy as np
import trimesh

try:
    # fairmesh's Python package (`pip install ./python`): the baselines and the measures of
    # every peer's result then run in this process, with no file written and no command started.
    import fairmesh as fairmesh_package
except ImportError:
    fairmesh_package = None

FAIRMESH = os.environ.get("FAIRMESH", "target/release/fairmesh")
ITERATIONS = [1, 2, 5, 10, 20, 50, 100, 200]


def run(*args):
    out = subprocess.run([FAIRMESH, *args], capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"fairmesh {' '.join(args)} failed: {out.stderr.strip()}")
    return out.stdout


def measure(clean, result):
    return measured(json.loads(run("compare", clean, result, "--json")))


def measure_arrays(clean, vertices, faces):
    """`measure` of a result given as arrays, against `clean`, a mesh `fairmesh_package.load`
    read (the command's own reading of the file)."""
    return measured(fairmesh_package.compare(clean.vertices, clean.faces, vertices, faces))


def measured(m):
    edge = m["reference_mean_edge_length"]
    return {
        "mean": m["mean_surface_distance"] / edge,
        "hausdorff": m["hausdorff"] / edge,
        "normal": m.get("normal_error_deg"),
        "volume": m["volume_change_percent"],
        "sharpened": m.get("sharpened_edges"),
    }


def load(path):
    # process=False keeps fairmesh's vertex order (the noisy file is already welded).
    # Positions and triangles only: a textured mesh's visuals would need Pillow.
    mesh = trimesh.load(path, process=False, force="mesh")
    return trimesh.Trimesh(np.asarray(mesh.vertices), np.asarray(mesh.faces), process=False)


def fairmesh_baseline(method):
    """fairmesh's own baseline `method` (`fair --method laplacian|taubin|hc`) as a peer: the
    default's targets name these three at their best iteration count (Laplacian, Taubin, HC)."""

    def smooth(v, f, k):
        if fairmesh_package is not None:
            return fairmesh_package.fair(v, f, method=method, iterations=k)[0]
        with tempfile.TemporaryDirectory() as tmp:
            given, smoothed = os.path.join(tmp, "in.ply"), os.path.join(tmp, "out.ply")
            trimesh.Trimesh(v, f, process=False).export(given)
            run("fair", given, "-o", smoothed, "--method", method, "--iterations", str(k))
            result = np.asarray(load(smoothed).vertices)
            if len(result) != len(v):
                sys.exit(f"fair --method {method} wrote {len(result)} vertices for {len(v)}")
            return result

    return smooth


def peers():
    """(name, function(vertices, faces, iterations) -> vertices) for fairmesh's own baselines and
    the installed peers."""
    found = [
        ("fairmesh Laplacian", fairmesh_baseline("laplacian")),
        ("fairmesh Taubin", fairmesh_baseline("taubin")),
        ("fairmesh HC", fairmesh_baseline("hc")),
    ]

    def trimesh_filter(kind):
        def smooth(v, f, k):
            mesh = trimesh.Trimesh(v.copy(), f, process=False)
            if kind == "taubin":
                trimesh.smoothing.filter_taubin(mesh, lamb=0.5, nu=0.53, iterations=k)
            elif kind == "humphrey":
                trimesh.smoothing.filter_humphrey(mesh, alpha=0.1, beta=0.5, iterations=k)
            else:
                trimesh.smoothing.filter_laplacian(mesh, lamb=0.5, iterations=k)
            return np.asarray(mesh.vertices)

        return smooth

    found += [
        ("trimesh Taubin", trimesh_filter("taubin")),
        ("trimesh Humphrey", trimesh_filter("humphrey")),
        ("trimesh Laplacian", trimesh_filter("laplacian")),
    ]
    try:
        import pymeshlab

        def meshlab(kind):
            def smooth(v, f, k):
                ms = pymeshlab.MeshSet()
                ms.add_mesh(pymeshlab.Mesh(v, f))
                if kind == "taubin":
                    ms.apply_coord_taubin_smoothing(stepsmoothnum=k)
                else:
                    for _ in range(k):
                        ms.apply_coord_hc_laplacian_smoothing()
                return ms.current_mesh().vertex_matrix()

            return smooth

        found += [("PyMeshLab Taubin", meshlab("taubin")), ("PyMeshLab HC", meshlab("hc"))]
    except ImportError:
        print("(PyMeshLab not installed: skipped)", file=sys.stderr)
    try:
        import open3d as o3d

        def open3d_taubin(v, f, k):
            mesh = o3d.geometry.TriangleMesh(
                o3d.utility.Vector3dVector(v), o3d.utility.Vector3iVector(f)
            )
            return np.asarray(mesh.filter_smooth_taubin(number_of_iterations=k).vertices)

        found.append(("Open3D Taubin", open3d_taubin))
    except ImportError:
        print("(Open3D not installed: skipped)", file=sys.stderr)
    return found


def normal_error(m):
    """A measure's mean face-normal error, or "-" where the vertices do not correspond."""
    return "-" if m["normal"] is None else f"{m['normal']:.1f}"


def sharpened(m):
    """A measure's count of edges bent over 30° beyond the clean mesh's, or "-"."""
    return "-" if m["sharpened"] is None else str(m["sharpened"])


def row(name, setting, m):
    return (
        f"| {name} | {setting} | {m['mean']:.4f} | {m['hausdorff']:.3f} | {normal_error(m)} "
        f"| {m['volume']:+.3f} | {sharpened(m)} |"
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("meshes", nargs="+")
    parser.add_argument("--modes", default="normal,iso")
    parser.add_argument("--fair-flags", default="", help="flags for `fair` (default: none)")
    parser.add_argument("--no-peers", action="store_true", help="run `fair` alone")
    parser.add_argument(
        "--seed",
        default="1",
        help="the noise's seed, or several separated by commas (one seed's rows differ from "
        "another's by a few per cent, as much as fair and the best peer differ on the closest "
        "rows: compare over several; the summary then ends with each row over the seeds)",
    )
    args = parser.parse_args()
    seeds = [seed.strip() for seed in args.seed.split(",") if seed.strip()]
    for seed in seeds:
        if not seed.isdigit():
            sys.exit(f"--seed: {seed!r} is not a whole number")
    fair_flags = shlex.split(args.fair_flags)
    smoothers = [] if args.no_peers else peers()
    # (mesh, mode, fair's row, (best peer's name, its iterations, its row) or None)
    summary = []
    with tempfile.TemporaryDirectory() as tmp:
        for path in args.meshes:
            clean = os.path.join(tmp, "clean.ply")
            run("convert", path, "-o", clean)
            for mode, seed in ((mode, seed) for mode in args.modes.split(",") for seed in seeds):
                noisy = os.path.join(tmp, "noisy.ply")
                run("noise", clean, "-o", noisy, "--sigma", "0.3", "--seed", seed, "--mode", mode)
                print(f"\n{os.path.basename(path)}, noise 0.3 mean edge lengths, mode {mode}, "
                      f"seed {seed}\n")
                print("| smoother | setting | mean dist | Hausdorff | normal ° | volume % "
                      "| sharpened edges |")
                print("|---|---|---:|---:|---:|---:|---:|")
                print(row("noisy input", "", measure(clean, noisy)))
                ours = os.path.join(tmp, "ours.ply")
                report = json.loads(run("fair", noisy, "-o", ours, "--json", *fair_flags))
                noise = report["noise_estimate"]
                setting = (
                    f"{args.fair_flags or 'default'} (noise "
                    f"{'-' if noise is None else f'{noise:.3f}'}, "
                    f"{report['rounds_run']} rounds, {report['crease_edges']} crease edges)"
                )
                ours_measured = measure(clean, ours)
                print(row("fairmesh fair", setting, ours_measured), flush=True)
                best_peer = None
                mesh = load(noisy)
                v_all = np.asarray(mesh.vertices, dtype=np.float64)
                f_all = np.asarray(mesh.faces, dtype=np.int32)
                # Some peers (trimesh's filters) need every vertex used by a face: they smooth
                # the used vertices, and the unused ones are written back where they were.
                used = np.unique(f_all)
                index = np.full(len(v_all), -1, dtype=np.int32)
                index[used] = np.arange(len(used), dtype=np.int32)
                v, f = v_all[used], index[f_all]
                out = os.path.join(tmp, "peer.ply")
                clean_loaded = fairmesh_package.load(clean) if fairmesh_package else None
                for name, smooth in smoothers:
                    best = None
                    for k in ITERATIONS:
                        smoothed = v_all.copy()
                        smoothed[used] = smooth(v, f, k)
                        if clean_loaded is not None:
                            m = measure_arrays(clean_loaded, smoothed, f_all)
                        else:
                            trimesh.Trimesh(smoothed, f_all, process=False).export(out)
                            m = measure(clean, out)
                        if best is None or m["mean"] < best[1]["mean"]:
                            best = (k, m)
                    print(row(name, f"best of {ITERATIONS}: {best[0]} iterations", best[1]),
                          flush=True)
                    if best_peer is None or best[1]["mean"] < best_peer[2]["mean"]:
                        best_peer = (name, best[0], best[1])
                summary.append((os.path.basename(path), mode, seed, ours_measured, best_peer))
    print_summary(summary, args.fair_flags)
    if len(seeds) > 1:
        print_over_seeds(summary, seeds)


def print_summary(summary, fair_flags):
    """fair (with `fair_flags`, or its defaults) against the best peer (the least mean distance
    over every peer and iteration count) for each mesh and noise mode, and the count of cases
    where fair ends closer."""
    fair = f"`fair {fair_flags}`" if fair_flags else "default `fair`"
    print(f"\nSummary: {fair} against the best peer at its best iteration count\n")
    print("| mesh | noise | seed | fair: mean dist / normal ° | best peer | its mean dist / normal "
          "° | fair / best |")
    print("|---|---|---:|---:|---|---:|---:|")
    closer = 0
    for mesh, mode, seed, ours, best in summary:
        if best is None:
            print(f"| {mesh} | {mode} | {seed} | {ours['mean']:.4f} / {normal_error(ours)} | (no "
                  "peer run) | - | - |")
            continue
        name, k, theirs = best
        ratio = ours["mean"] / theirs["mean"]
        closer += ratio < 1.0
        print(f"| {mesh} | {mode} | {seed} | {ours['mean']:.4f} / {normal_error(ours)} | {name}, "
              f"{k} iterations | {theirs['mean']:.4f} / {normal_error(theirs)} | {ratio:.3f} |")
    compared = sum(1 for *_, best in summary if best is not None)
    if compared:
        print(f"\nfair ends closer than the best peer in {closer} of {compared} cases")


def print_over_seeds(summary, seeds):
    """Each mesh and noise mode over the seeds: fair's mean distance over the best peer's on each
    seed (each seed's own best peer), their geometric mean, and on how many seeds fair is closer."""
    print(f"\nOver the seeds {', '.join(seeds)}: fair / best peer on each, geometric mean\n")
    print("| mesh | noise | fair / best, each seed | geometric mean | seeds closer |")
    print("|---|---|---|---:|---:|")
    rows = {}
    for mesh, mode, seed, ours, best in summary:
        if best is not None:
            rows.setdefault((mesh, mode), []).append(ours["mean"] / best[2]["mean"])
    closer = 0
    for (mesh, mode), ratios in rows.items():
        mean = float(np.exp(np.mean(np.log(ratios))))
        ahead = sum(ratio < 1.0 for ratio in ratios)
        closer += mean < 1.0
        each = " / ".join(f"{ratio:.3f}" for ratio in ratios)
        print(f"| {mesh} | {mode} | {each} | {mean:.3f} | {ahead} of {len(ratios)} |")
    print(f"\nfair ends closer than the best peer on average over the seeds in {closer} of "
          f"{len(rows)} cases")


if __name__ == "__main__":
    main()

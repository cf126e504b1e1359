#!/usr/bin/env python3
"""Where the automatic strength stops against where it should: per round, the risk `fair` reads,
the true error it estimates, and the mean surface distance the peers are judged by.

For one clean mesh and noise mode: `fairmesh noise` (sigma 0.3 mean edge lengths, seed 1), the
default `fair` with `--json` (its rounds and `risk_by_round`), then `fair --rounds K` for every
K up to --rounds, each measured against the clean mesh two ways:
- the true risk: the mean squared distance along the result's vertex normals (area-weighted) to
  the clean vertices, plus sigma squared, which is what the risk `fair` reads estimates (Stein's
  unbiased risk estimate without its constant; `src/fairing/strength/risk.rs`);
- the mean surface distance both ways (`fairmesh compare`), the yardstick of the peer tables.
Both in mean edge lengths of the clean mesh (the risk squared). `--rounds K` gives the same
rounds as the default's first K (the same operator, creases and schedule), so the default's
stop can be read off the table.

With --r2r ALPHA (and --draws D), also the recorrupted-to-recorrupted estimate (Pang et al.,
"Recorrupted-to-Recorrupted", CVPR 2021), which needs no derivative and so sees the creases'
discrete decisions: y + ALPHA s z n is faired (s the noise estimate, z a standard normal draw, n
the input's normals) and compared with y - s z n / ALPHA; it estimates the risk at the noise
raised by a factor sqrt(1 + ALPHA^2).

Run from the repository root after `cargo build --release`:
    venv/bin/python scripts/peers/stopping_truth.py CLEAN [--mode normal|iso] [--rounds 12]
        [--r2r 0.5 --draws 4] [--fair-flags="--no-creases"]
CLEAN is any mesh fairmesh reads; the noisy mesh keeps its vertices (the noise moves them), so
the clean vertex of each result vertex is known. Needs numpy and trimesh (requirements.txt).
"""

import argparse
import json
import os
import sys
import tempfile

import numpy as np
import trimesh

# The same `fairmesh` runner and loader as the peer tables (FAIRMESH names the binary).
import compare_peers
from compare_peers import run


def load(path):
    mesh = compare_peers.load(path)
    return np.asarray(mesh.vertices, dtype=np.float64), np.asarray(mesh.faces)


def vertex_normals(v, f):
    """Unit vertex normals, the sum of the faces' area normals (as fairmesh's risk takes them)."""
    area = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])
    n = np.zeros_like(v)
    for corner in range(3):
        np.add.at(n, f[:, corner], area)
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return np.divide(n, length, out=np.zeros_like(n), where=length > 0)


def mean_edge(v, f):
    edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    edges = np.unique(np.sort(edges, axis=1), axis=0)
    return float(np.mean(np.linalg.norm(v[edges[:, 0]] - v[edges[:, 1]], axis=1)))


def write_ply(path, v, f):
    trimesh.Trimesh(v, f, process=False).export(path)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("clean")
    parser.add_argument("--mode", default="normal", choices=["normal", "iso"])
    parser.add_argument("--sigma", type=float, default=0.3)
    parser.add_argument("--rounds", type=int, default=12)
    parser.add_argument("--r2r", type=float, help="also the recorrupted estimate, this alpha")
    parser.add_argument("--draws", type=int, default=4)
    parser.add_argument("--fair-flags", default="",
                        help='more flags for every `fair` run, written with = (--fair-flags="--no-creases")')
    args = parser.parse_args()
    flags = args.fair_flags.split()

    with tempfile.TemporaryDirectory() as tmp:
        clean = os.path.join(tmp, "clean.ply")
        noisy = os.path.join(tmp, "noisy.ply")
        out = os.path.join(tmp, "out.ply")
        run("convert", args.clean, "-o", clean)
        run("noise", clean, "-o", noisy, "--sigma", str(args.sigma), "--seed", "1",
            "--mode", args.mode)
        x, faces = load(clean)
        y, noisy_faces = load(noisy)
        if len(x) != len(y):
            sys.exit(f"{args.clean}: the noisy mesh has other vertices than the clean one")
        edge = mean_edge(x, faces)
        sigma = args.sigma * edge
        default = json.loads(run("fair", noisy, "-o", out, "--json", *flags))
        read = default.get("risk_by_round") or []

        def along_normals(path, target):
            """The mean squared distance of the result in `path` from `target` (per vertex)
            along the result's normals."""
            v, f = load(path)
            if len(v) != len(x):
                sys.exit(f"{path}: fair changed the vertex count")
            return np.mean(np.sum(vertex_normals(v, f) * (v - target), axis=1) ** 2)

        true_risk, distance = [], []
        for k in range(1, args.rounds + 1):
            run("fair", noisy, "-o", out, "--rounds", str(k), *flags)
            true_risk.append(along_normals(out, x) + sigma**2)
            m = json.loads(run("compare", clean, out, "--json"))
            distance.append(m["mean_surface_distance"] / m["reference_mean_edge_length"])

        recorrupted = None
        if args.r2r:
            alpha = args.r2r
            s = default["noise_estimate"] * mean_edge(y, noisy_faces)
            n0 = vertex_normals(y, noisy_faces)
            rng = np.random.default_rng(12345)
            recorrupted = np.zeros(args.rounds)
            more = os.path.join(tmp, "more.ply")
            for _ in range(args.draws):
                z = rng.standard_normal(len(y))[:, None] * n0
                write_ply(more, y + alpha * s * z, noisy_faces)
                target = y - s * z / alpha
                for k in range(1, args.rounds + 1):
                    run("fair", more, "-o", out, "--rounds", str(k), *flags)
                    recorrupted[k - 1] += along_normals(out, target) / args.draws

    print(f"{args.clean}, noise {args.sigma} mode {args.mode}"
          f"{', flags ' + args.fair_flags if flags else ''}: default `fair` stops after "
          f"{default.get('rounds_run')} rounds (risk read for {len(read)})")
    header = "| round | risk read | true risk | mean distance |"
    rule = "|---:|---:|---:|---:|"
    if recorrupted is not None:
        header += f" recorrupted (alpha {args.r2r}, {args.draws} draws) |"
        rule += "---:|"
    print(header)
    print(rule)
    for k in range(args.rounds):
        cells = [
            f"{read[k] / edge**2:.4f}" if k < len(read) else "-",
            f"{true_risk[k] / edge**2:.4f}",
            f"{distance[k]:.4f}",
        ]
        if recorrupted is not None:
            cells.append(f"{recorrupted[k] / edge**2:.4f}")
        print(f"| {k + 1} | " + " | ".join(cells) + " |")
    least = [f"true risk {int(np.argmin(true_risk)) + 1}", f"distance {int(np.argmin(distance)) + 1}"]
    if read:
        least.insert(0, f"read {int(np.argmin(read)) + 1}")
    if recorrupted is not None:
        least.append(f"recorrupted {int(np.argmin(recorrupted)) + 1}")
    print("least at: " + ", ".join(least))


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Sharp edges kept (`on`, `fair`'s default) against faired across (`off`, `--no-creases`) on clean
meshes made noisy, as docs/measurements.md ("Sharp edges: kept or not") reports them.

    scripts/peers/crease_modes.py BINARY CLEAN.ply... [--modes on,off,NAME=FLAGS] [--sigma 0.3,0.1]
        [--noise normal,iso] [--seed 1,2] [--env NAME=VALUE ...]

A mode is `on`, `off` or `NAME=FLAGS` (a candidate rule behind flags or, with --env, an
environment variable). For every clean mesh and every noise level, mode and seed: `fairmesh
noise`, then `fairmesh fair --json` with the mode's flags and `fairmesh compare CLEAN OUT
--json`. Per mesh it prints each mode's
geometric mean distance over the better of `on` and `off` row by row, and the sharpened edges
(`compare`'s `sharpened_edges`: edges whose dihedral angle exceeds the clean mesh's by more than
30 degrees) summed; then how many rows each mode misses the bar on (within 1 % of the better of
on and off, sharpened edges at most that one's + 10 %). Needs only the binary and Python 3."""
import argparse
import json
import math
import os
import subprocess
import tempfile


def run(args, env=None):
    done = subprocess.run(args, capture_output=True, text=True, env=env, check=True)
    return done.stdout


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("binary")
    parser.add_argument("clean", nargs="+")
    parser.add_argument("--modes", default="on,off")
    parser.add_argument("--sigma", default="0.3,0.1")
    parser.add_argument("--noise", default="normal,iso")
    parser.add_argument("--seed", default="1,2")
    parser.add_argument("--env", nargs="*", default=[], help="NAME=VALUE for the fair runs")
    args = parser.parse_args()
    flags = {"on": [], "off": ["--no-creases"]}
    modes = []
    for mode in args.modes.split(","):
        name, _, given = mode.partition("=")
        flags.setdefault(name, given.split())
        modes.append(name)
    for needed in ("on", "off"):
        if needed not in modes:
            modes.append(needed)
    env = dict(os.environ, **dict(kv.split("=", 1) for kv in args.env))
    missed = {mode: 0 for mode in modes}
    rows = 0
    with tempfile.TemporaryDirectory() as tmp:
        for clean in args.clean:
            name = os.path.splitext(os.path.basename(clean))[0]
            ratios = {mode: [] for mode in modes}
            sharpened = {mode: 0 for mode in modes}
            for sigma in args.sigma.split(","):
                for noise in args.noise.split(","):
                    for seed in args.seed.split(","):
                        noisy = os.path.join(tmp, f"{name}.noisy.ply")
                        run([args.binary, "noise", clean, "-o", noisy, "--sigma", sigma,
                             "--mode", noise, "--seed", seed])
                        found = {}
                        for mode in modes:
                            out = os.path.join(tmp, f"{name}.{mode}.ply")
                            run([args.binary, "fair", noisy, "-o", out, "--json",
                                 *flags[mode]], env)
                            compared = json.loads(run([args.binary, "compare", clean, out,
                                                       "--json"]))
                            found[mode] = (compared["mean_surface_distance"],
                                           compared.get("sharpened_edges") or 0)
                        best = min(found["on"], found["off"])
                        rows += 1
                        for mode, (distance, sharp) in found.items():
                            ratios[mode].append(distance / best[0])
                            sharpened[mode] += sharp
                            if distance > 1.01 * best[0] or sharp > 1.1 * best[1]:
                                missed[mode] += 1
            print(name, " | ".join(
                f"{mode} {math.exp(sum(map(math.log, ratios[mode])) / len(ratios[mode])):.4f} "
                f"{sharpened[mode]}" for mode in modes))
    print(f"rows missing the bar, of {rows}:",
          ", ".join(f"{mode} {count}" for mode, count in missed.items()))


if __name__ == "__main__":
    main()

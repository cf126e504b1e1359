#!/usr/bin/env python3
"""fairmesh's whole decimation hierarchy against one meshoptimizer simplification, side by side.

The yardstick: building every level of the hierarchy of a mesh should take well under
one `meshopt_simplify` of the same mesh to 1 % of its faces (meshoptimizer is the fast,
widely used simplifier; it builds one level, we build all of them). The runs alternate, so a
busy machine slows both alike.

Install (meshoptimizer's Python package builds its C++ code; numpy reads the mesh):
    python3 -m venv venv && venv/bin/pip install numpy meshoptimizer
Run from the repository root after `cargo build --release -p fairmesh-cli --no-default-features`:
    venv/bin/python scripts/peers/meshopt_hierarchy.py MESH [--runs 3] [--threads 2]
MESH is any file fairmesh reads (it is converted to a binary PLY once, outside the timings).
Prints each run's times and the ratio of the medians.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import meshoptimizer
import numpy as np

FAIRMESH = os.environ.get("FAIRMESH", "target/release/fairmesh")


def read_ply(path):
    """Positions (float32, n x 3) and triangles (uint32, m x 3) of a binary PLY as fairmesh
    writes it: x, y, z floats per vertex, a uchar count and int indices per face."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    if "format binary_little_endian 1.0" not in header:
        sys.exit(f"{path}: expected a binary little-endian PLY")
    counts = {line.split()[1]: int(line.split()[2]) for line in header if line.startswith("element")}
    vertex_props = [line for line in header if line.startswith("property float")]
    if len(vertex_props) != 3:
        sys.exit(f"{path}: expected exactly the x, y, z float properties per vertex")
    n, m = counts["vertex"], counts["face"]
    positions = np.frombuffer(data, dtype="<f4", count=3 * n, offset=end).reshape(n, 3)
    faces = np.frombuffer(data, dtype=np.dtype([("k", "u1"), ("i", "<i4", 3)]), count=m,
                          offset=end + 12 * n)
    if np.any(faces["k"] != 3):
        sys.exit(f"{path}: expected triangles only")
    return np.ascontiguousarray(positions), np.ascontiguousarray(faces["i"].astype(np.uint32))


def fairmesh_hierarchy_ms(path, threads):
    env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
    out = subprocess.run([FAIRMESH, "hierarchy", path, "--json"], capture_output=True,
                         text=True, env=env)
    if out.returncode != 0:
        sys.exit(f"fairmesh hierarchy {path} failed: {out.stderr.strip()}")
    return json.loads(out.stdout)["total_ms"]


def meshopt_ms(positions, triangles):
    indices = triangles.reshape(-1)
    destination = np.zeros_like(indices)
    target = max(3, (len(indices) // 100) // 3 * 3)
    started = time.perf_counter()
    count = meshoptimizer.simplify(destination, indices, positions,
                                   target_index_count=target, target_error=1.0)
    ms = (time.perf_counter() - started) * 1e3
    return ms, count // 3


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mesh")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--threads", type=int, default=2, help="fairmesh's threads")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        ply = os.path.join(tmp, "mesh.ply")
        subprocess.run([FAIRMESH, "convert", args.mesh, "-o", ply], check=True,
                       capture_output=True)
        positions, triangles = read_ply(ply)
        print(f"{args.mesh}: {len(positions)} vertices, {len(triangles)} faces")
        ours, theirs = [], []
        for run in range(args.runs):
            ms, faces = meshopt_ms(positions, triangles)
            theirs.append(ms)
            ours.append(fairmesh_hierarchy_ms(ply, args.threads))
            print(f"run {run + 1}: meshopt_simplify to {faces} faces {ms:.0f} ms, "
                  f"fairmesh hierarchy ({args.threads} threads) {ours[-1]:.0f} ms")
    ratio = statistics.median(ours) / statistics.median(theirs)
    print(f"median: meshopt {statistics.median(theirs):.0f} ms, fairmesh "
          f"{statistics.median(ours):.0f} ms = {100 * ratio:.0f} % of meshopt")


if __name__ == "__main__":
    main()

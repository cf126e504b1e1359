#!/usr/bin/env bash
# fair_set.sh DIR [FAIR FLAGS...]: `fairmesh fair` with the given flags (none: the default) on every
# clean mesh DIR/*.ply, each with noise 0.3 mean edge lengths along the normals and isotropic
# (seed 1, the noisy files cached in DIR/noisy/), measured against the clean mesh. Prints one line
# per mesh and mode: mesh, mode, rounds run, crease edges, mean surface distance (clean mean edge
# lengths), mean face-normal error (degrees), Hausdorff distance (edge lengths).
# DIR comes from `cargo run --release --no-default-features --example fairing_default -- --save DIR`.
# FAIRMESH names the binary (default target/release/fairmesh). docs/measurements.md ("The whole
# set against the peers") has what it printed for the settings tried.
set -euo pipefail
dir=${1:?usage: fair_set.sh DIR [FAIR FLAGS...]}
shift
bin=${FAIRMESH:-target/release/fairmesh}
mkdir -p "$dir/noisy"
out=$(mktemp --suffix=.ply)
trap 'rm -f "$out"' EXIT
for clean in "$dir"/*.ply; do
  name=$(basename "$clean" .ply)
  for mode in normal iso; do
    noisy="$dir/noisy/${name}_$mode.ply"
    [ -f "$noisy" ] || "$bin" noise "$clean" -o "$noisy" --sigma 0.3 --seed 1 --mode "$mode" 2>/dev/null
    report=$("$bin" fair "$noisy" -o "$out" "$@" --json 2>/dev/null)
    measured=$("$bin" compare "$clean" "$out" --json)
    python3 - "$report" "$measured" "$name" "$mode" <<'PY'
import json, sys
report, measured = json.loads(sys.argv[1]), json.loads(sys.argv[2])
edge = measured["reference_mean_edge_length"]
normal = measured.get("normal_error_deg")
print(sys.argv[3], sys.argv[4], report.get("rounds_run", "-"), report.get("crease_edges", "-"),
      "%.4f" % (measured["mean_surface_distance"] / edge),
      "-" if normal is None else "%.2f" % normal,
      "%.3f" % (measured["hausdorff"] / edge))
PY
  done
done

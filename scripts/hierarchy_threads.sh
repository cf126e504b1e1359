#!/usr/bin/env bash
# The hierarchy build on one thread against two (the yardstick: two threads at least
# 1.7x faster than one), for one or more fairmesh binaries side by side.
#
#   scripts/hierarchy_threads.sh MESH RUNS [BINARY...]
#
# Runs `RAYON_NUM_THREADS=T BINARY hierarchy MESH --json` RUNS times for each binary and for
# T = 1 and 2, alternating (binary by binary, thread count by thread count, then the next
# round), so that a shared machine's drift from minute to minute falls on all alike; prints the
# median `total_ms` (the build alone, loading excluded) per binary and thread count, every run
# sorted, and the ratio of the medians. BINARY defaults to target/release/fairmesh (build it
# with `cargo build --release -p fairmesh-cli --no-default-features`). Needs python3 for the JSON.
set -euo pipefail
if [ $# -lt 2 ]; then
    echo "usage: $0 MESH RUNS [BINARY...]" >&2
    exit 2
fi
mesh=$1
runs=$2
shift 2
binaries=("$@")
[ ${#binaries[@]} -gt 0 ] || binaries=(target/release/fairmesh)
for binary in "${binaries[@]}"; do
    [ -x "$binary" ] || { echo "$0: $binary is not an executable" >&2; exit 2; }
done
[ -r "$mesh" ] || { echo "$0: cannot read $mesh" >&2; exit 2; }

results=$(mktemp)
trap 'rm -f "$results"' EXIT
for _ in $(seq "$runs"); do
    for binary in "${binaries[@]}"; do
        for threads in 1 2; do
            ms=$(RAYON_NUM_THREADS=$threads "$binary" hierarchy "$mesh" --json |
                python3 -c 'import json, sys; print(json.load(sys.stdin)["total_ms"])')
            printf '%s\t%s\t%s\n' "$binary" "$threads" "$ms" >>"$results"
        done
    done
done
python3 - "$results" "${binaries[@]}" <<'EOF'
import statistics
import sys

path, binaries = sys.argv[1], sys.argv[2:]
times = {}
with open(path) as rows:
    for row in rows:
        binary, threads, ms = row.rstrip("\n").split("\t")
        times.setdefault((binary, int(threads)), []).append(float(ms))
for binary in binaries:
    one, two = sorted(times[(binary, 1)]), sorted(times[(binary, 2)])
    m1, m2 = statistics.median(one), statistics.median(two)
    print(f"{binary}: 1 thread {m1:.0f} ms {[round(t) for t in one]}, "
          f"2 threads {m2:.0f} ms {[round(t) for t in two]}: {m1 / m2:.2f}x")
EOF

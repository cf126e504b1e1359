#!/usr/bin/env bash
# Instructions a hierarchy build executes, for one or more fairmesh binaries side by side: a
# yardstick that does not drift with a shared machine's load, where wall-clock timings of two
# builds (scripts/hierarchy_threads.sh) can differ by 20 % from one minute to the next.
#
#   scripts/hierarchy_instructions.sh MESH [BINARY...]
#
# Runs `RAYON_NUM_THREADS=1 BINARY hierarchy MESH --json` under valgrind's callgrind and prints
# the instructions of the whole run and of the load alone (`BINARY info MESH`, which loads and
# checks the mesh the same way), and their difference: the build, its checks and the JSON.
# Instructions are not time (a build that waits on memory runs slower than its count says),
# so compare builds that do the same memory traffic, and confirm a gain with timings. Valgrind
# runs about 50x slower: use a mesh of ~150k vertices (`fairmesh convert assets/bunny00.obj
# --subdivide 1 -o b150k.ply`), not the 1.2M one. BINARY defaults to target/release/fairmesh.
# Needs valgrind (Debian: `apt-get install valgrind`).
set -euo pipefail
if [ $# -lt 1 ]; then
    echo "usage: $0 MESH [BINARY...]" >&2
    exit 2
fi
mesh=$1
shift
binaries=("$@")
[ ${#binaries[@]} -gt 0 ] || binaries=(target/release/fairmesh)
command -v valgrind >/dev/null || { echo "$0: needs valgrind (apt-get install valgrind)" >&2; exit 2; }
for binary in "${binaries[@]}"; do
    [ -x "$binary" ] || { echo "$0: $binary is not an executable" >&2; exit 2; }
done
[ -r "$mesh" ] || { echo "$0: cannot read $mesh" >&2; exit 2; }

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# The instructions callgrind collected in one run of the command.
instructions() {
    RAYON_NUM_THREADS=1 valgrind --tool=callgrind --callgrind-out-file="$work/out" "$@" \
        >/dev/null 2>"$work/log" || { cat "$work/log" >&2; exit 1; }
    sed -n 's/^==[0-9]*== Collected : \([0-9]*\)$/\1/p' "$work/log"
}
for binary in "${binaries[@]}"; do
    whole=$(instructions "$binary" hierarchy "$mesh" --json)
    load=$(instructions "$binary" info "$mesh")
    # (A failed run prints its log and leaves the count empty.)
    [ -n "$whole" ] && [ -n "$load" ] || exit 1
    awk -v b="$binary" -v w="$whole" -v l="$load" 'BEGIN {
        printf "%s: hierarchy %.0fM instructions, load %.0fM, build %.0fM\n", b, w / 1e6, l / 1e6, (w - l) / 1e6
    }'
done

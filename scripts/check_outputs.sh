#!/usr/bin/env bash
# Byte-identical outputs: runs one `fairmesh` binary over the repository's meshes and round-trip
# assets (noise, `fair` default / `--no-creases` / `--variant paper`, `hierarchy --write-levels`,
# `multires`, and a save into every format) and prints one `sha256  name` line per file written.
#
#   scripts/check_outputs.sh BINARY > sums.txt        # the sums of one build
#   scripts/check_outputs.sh BINARY --check FILE      # compare with stored sums; exit 1 on change
#
# CI checks the debug build against scripts/output_sums.txt (the files do not depend on the build
# profile or on the number of threads). A change that keeps behaviour keeps every line; a change
# that means to move results says so in its commit and stores the new sums:
#   scripts/check_outputs.sh target/release/fairmesh > scripts/output_sums.txt
set -euo pipefail
bin=$(realpath "$1")
shift
check=""
if [ "${1:-}" = "--check" ]; then
  check=$(realpath "$2")
fi
cd "$(dirname "$0")/.."
root=$(pwd)
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

meshes=(assets/bunny00.obj tests/data/elephant.obj tests/data/mushroom_open.obj
  tests/data/bunny_npm.obj tests/data/creases/folded_sheet.obj)
for mesh in "${meshes[@]}"; do
  name=$(basename "$mesh" .obj)
  "$bin" noise "$mesh" -o "$out/$name.noisy.obj" --sigma 0.3 --seed 1 >/dev/null
  "$bin" fair "$out/$name.noisy.obj" -o "$out/$name.fair.obj" >/dev/null
  "$bin" fair "$out/$name.noisy.obj" -o "$out/$name.fair_no_creases.obj" --no-creases >/dev/null
  "$bin" fair "$out/$name.noisy.obj" -o "$out/$name.fair_paper.obj" --variant paper >/dev/null
  "$bin" multires "$out/$name.noisy.obj" -o "$out/$name.multires.obj" --level 3 >/dev/null
  mkdir -p "$out/$name.levels"
  "$bin" hierarchy "$out/$name.noisy.obj" --write-levels "$out/$name.levels" --keep-creases >/dev/null
done

# Every round-trip asset faired into its own format and converted into each of the others.
for asset in tests/data/roundtrip/*.{obj,ply,glb,gltf}; do
  base=$(basename "$asset")
  stem=${base%.*}
  ext=${base##*.}
  mkdir -p "$out/rt.$stem.$ext"
  "$bin" fair "$asset" -o "$out/rt.$stem.$ext/fair.$ext" >/dev/null 2>&1
  for to in obj ply stl off glb gltf; do
    "$bin" convert "$asset" -o "$out/rt.$stem.$ext/convert.$to" >/dev/null 2>&1
  done
done

(cd "$out" && find . -type f | LC_ALL=C sort | xargs sha256sum) >"$out.sums"
if [ -n "$check" ]; then
  if diff -u "$check" "$out.sums"; then
    echo "outputs: all $(wc -l <"$out.sums") files byte-identical to $(basename "$check")"
    rm -f "$out.sums"
  else
    rm -f "$out.sums"
    echo "outputs: files differ from $(basename "$check") (lines above)" >&2
    exit 1
  fi
else
  cat "$out.sums"
  rm -f "$out.sums"
fi

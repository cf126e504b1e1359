#!/usr/bin/env bash
# Mutation testing of the library's core with cargo-mutants: each mutant (a small change to the
# code: an operator flipped, a function returning a default, a condition negated) is built and
# the library's tests are run against it; a mutant the tests do not catch is a place the tests
# do not look. The library alone is built (no GUI), so a mutant builds in seconds.
#
#   scripts/mutants.sh                      the whole core: 3,600 mutants, each a library build
#                                           and its tests (about a minute on 2 cores), so run
#                                           it sharded over machines or sittings, as below
#   scripts/mutants.sh --shard 3/8          the third of eight shards of the core
#   scripts/mutants.sh --in-diff change.diff  only the mutants in the lines a diff touches
#                                             (git diff > change.diff): minutes
#   scripts/mutants.sh -f src/fairing/baseline.rs [-- --lib --test fairing]
#                                           one file, optionally with fewer tests
#
# Arguments go to cargo mutants (`cargo mutants --help`); what follows `--` goes to cargo test.
# What follows `--` reaches only the tests (the build still compiles every example); `-C --lib
# -C --test=fairing ...` limits both. `--in-place` saves copying the tree: stop such a run only
# between mutants, or move target/debug/incremental/fairmesh-* away after, as a run stopped
# mid-build left a stale incremental cache that kept the mutant in later builds.
# `npm ci` first: tests/io_keep.rs validates its glTF files with the Khronos validator.
# Installs cargo-mutants when missing. Results: target/mutants/mutants.out/ (caught.txt,
# missed.txt, timeout.txt, unviable.txt, outcomes.json); docs/mutants.md has the figures of
# the runs, per module, and the missed mutants judged equivalent, with the reason.
set -euo pipefail
cd "$(dirname "$0")/.."
command -v cargo-mutants >/dev/null 2>&1 || cargo install --locked cargo-mutants
# The core: fairing, hierarchy, multires, metrics and the io writers.
core=(
  -f 'src/fairing/**/*.rs' -f 'src/hierarchy/**/*.rs' -f 'src/multires/**/*.rs'
  -f 'src/metrics/**/*.rs' -f 'src/io/**/write*.rs' -f 'src/io/save*.rs'
)
# Files or a diff named on the command line replace the core.
for arg in "$@"; do
  case "$arg" in -f | --file | -D | --in-diff | --file=* | --in-diff=*) core=() ;; esac
done
# cargo-mutants makes target/mutants but not target/ itself (a fresh clone has none).
mkdir -p target
exec cargo mutants --package fairmesh --output target/mutants --timeout-multiplier 3 \
  "${core[@]}" "$@"

#!/usr/bin/env bash
# The checks that keep the code as it is meant to be, run by CI after the tests (it reuses the
# test build): clippy with no warning on every crate of the workspace, the binary with and without
# the editor (the lints of Cargo.toml's `[workspace.lints]`); the API docs with no broken link
# (rustdoc, the workspace's own crates); the library with no GUI dependency; no import cycle
# between the files of a module
# (scripts/import_cycles.py); every file the `fairmesh` binary writes on the repository's meshes byte-identical to
# scripts/output_sums.txt (scripts/check_outputs.sh); the README and the guide short enough and with
# no broken link (scripts/check_docs.py, offline).
set -euo pipefail
cd "$(dirname "$0")/.."
if cargo clippy --version >/dev/null 2>&1; then
  # The library, the editor and the binary (the workspace's default members).
  cargo clippy --all-targets -- -D warnings
  # The binary without the editor.
  cargo clippy -p fairmesh-cli --no-default-features --all-targets -- -D warnings
  # The Python package (python/, a member of the workspace that the commands above leave out).
  cargo clippy -p fairmesh-python --all-targets -- -D warnings
else
  echo "check_code: cargo clippy is not installed (rustup component add clippy); lints not checked" >&2
fi
# Every intra-doc link resolves (the crates' own docs: a few seconds on the test build).
RUSTDOCFLAGS="-D warnings" cargo doc --quiet --no-deps
python3 scripts/check_docs.py
for source in src editor/src cli/src; do
  python3 scripts/import_cycles.py "$source"
done
# The test build's binary (default features); built here when the tests did not build it.
cargo build --quiet --bin fairmesh
scripts/check_outputs.sh target/debug/fairmesh --check scripts/output_sums.txt

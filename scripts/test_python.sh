#!/usr/bin/env bash
# The Python package's tests (python/): makes a virtual environment (python/.venv), installs
# maturin, numpy, pytest, trimesh (for fairmesh.trimesh) and Pillow (trimesh's textures) into it,
# Open3D (for fairmesh.open3d, when PyPI has it for this Python), builds the wheel (release, abi3),
# installs it and runs pytest, which compares results with the
# command-line tool built by the Rust tests (target/debug/fairmesh, built here when missing; or
# $FAIRMESH_CLI). Run by .ci/run after them.
set -euo pipefail
cd "$(dirname "$0")/.."
python=${PYTHON:-python3}
if ! "$python" -c 'import venv, ensurepip' >/dev/null 2>&1; then
  # Debian splits venv out of python3.
  sudo_cmd=()
  [ "$(id -u)" -ne 0 ] && sudo_cmd=(sudo)
  echo "test_python: installing python3-venv"
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends python3-venv >/dev/null
fi
venv=python/.venv
[ -x "$venv/bin/python" ] || "$python" -m venv "$venv"
"$venv/bin/python" -m pip install --quiet --upgrade "maturin>=1.9.4,<2" numpy pytest trimesh pillow
# Open3D's wheels (400 MB with what they need) exist for CPython 3.8-3.12 on x86-64 Linux; where
# pip cannot get one, its tests are the one skip allowed, and it is said here.
allowed_skips=""
if ! "$venv/bin/python" -c 'import open3d' >/dev/null 2>&1 &&
  ! "$venv/bin/python" -m pip install --quiet "open3d>=0.18"; then
  echo "test_python: Open3D cannot be installed for this Python: fairmesh.open3d goes untested" >&2
  allowed_skips="open3d is not installed"
fi
target=${CARGO_TARGET_DIR:-target}
# The command line the tests compare with: $FAIRMESH_CLI, else the test build's binary.
if [ -z "${FAIRMESH_CLI:-}" ]; then
  cargo build --quiet --bin fairmesh
  FAIRMESH_CLI="$(realpath "$target/debug/fairmesh")"
fi
FAIRMESH_CLI="$(realpath "$FAIRMESH_CLI")"
rm -rf python/dist
(cd python && ../"$venv"/bin/maturin build --release --locked --out dist)
"$venv/bin/python" -m pip install --quiet --force-reinstall --no-deps python/dist/fairmesh-*.whl
# From the tests' folder, so that `import fairmesh` finds the installed wheel, not python/fairmesh.
cd python/tests
# -rs: every skipped test says why.
# Any other skip fails the run (conftest.py). `-p no:dash`: Open3D brings Dash, whose pytest
# plugin is not wanted here.
FAIRMESH_ALLOWED_SKIPS="$allowed_skips" FAIRMESH_CLI="$FAIRMESH_CLI" \
  "../../$venv/bin/python" -m pytest -q -rs -p no:dash

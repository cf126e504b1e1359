#!/usr/bin/env bash
# The Python package's tests (python/): makes a virtual environment (python/.venv), installs
# maturin, numpy, pytest, trimesh (for fairmesh.trimesh) and Pillow (trimesh's textures) into it,
# builds the wheel (release, abi3), installs it and runs pytest, which compares results with the
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
# -rs: every skipped test says why (open3d, for one, is not installed here).
FAIRMESH_CLI="$FAIRMESH_CLI" "../../$venv/bin/python" -m pytest -q -rs

#!/usr/bin/env bash
# Builds target/fairmesh_blender.zip, the Blender add-on an artist installs (blender/): the
# package fairmesh_blender/ with the fairmesh wheel twice, unpacked in fairmesh_blender/vendor/
# (what the classic add-on imports, Blender 3.3 and newer) and as the wheel itself in
# fairmesh_blender/wheels/ (what Blender 4.2 and newer install from blender_manifest.toml, whose
# wheels line the zip's copy gets). The wheel is python/dist/fairmesh-*.whl when it is newer than
# the sources it is built from (as scripts/test_python.sh leaves it), else built here with
# maturin (python/.venv's, made as scripts/test_python.sh makes it, when none is on the PATH).
set -euo pipefail
cd "$(dirname "$0")/.."
target=${CARGO_TARGET_DIR:-target}

wheel_up_to_date() {
  local wheel
  wheel=$(ls python/dist/fairmesh-*.whl 2>/dev/null | head -n 1) || return 1
  [ -n "$wheel" ] || return 1
  # Any source of the wheel changed after it was built: build it again.
  [ -z "$(find src python/src python/fairmesh python/Cargo.toml python/pyproject.toml \
        python/build.rs Cargo.toml Cargo.lock -newer "$wheel" -type f -print -quit)" ]
}

if ! wheel_up_to_date; then
  maturin=$(command -v maturin || true)
  if [ -z "$maturin" ]; then
    venv=python/.venv
    [ -x "$venv/bin/python" ] || "${PYTHON:-python3}" -m venv "$venv"
    "$venv/bin/python" -m pip install --quiet "maturin>=1.9.4,<2"
    maturin=$(realpath "$venv/bin/maturin")
  fi
  echo "build_blender_addon: building the fairmesh wheel"
  rm -rf python/dist
  (cd python && "$maturin" build --release --locked --out dist)
fi
wheel=$(ls python/dist/fairmesh-*.whl | head -n 1)

python3 - "$wheel" "$target" <<'EOF'
import os
import re
import sys
import tempfile
import zipfile

wheel, target = sys.argv[1], sys.argv[2]
source = os.path.join("blender", "fairmesh_blender")
os.makedirs(target, exist_ok=True)
output = os.path.join(target, "fairmesh_blender.zip")
wheel_name = os.path.basename(wheel)

with zipfile.ZipFile(wheel) as bundled:
    # The package itself; the wheel's .dist-info is pip's, not the add-on's.
    vendored = [(name, bundled.read(name)) for name in bundled.namelist()
                if name.startswith("fairmesh/") and not name.endswith("/")]
if not any(re.match(r"fairmesh/_fairmesh\..*(so|pyd)$", name) for name, _ in vendored):
    sys.exit(f"build_blender_addon: {wheel} holds no fairmesh/_fairmesh extension module")

with open(os.path.join(source, "blender_manifest.toml"), encoding="utf-8") as file:
    manifest = file.read()
manifest, count = re.subn(r'(?m)^wheels = \[.*\]$', f'wheels = ["./wheels/{wheel_name}"]',
                          manifest)
if count != 1:
    sys.exit("build_blender_addon: blender_manifest.toml has no one-line wheels = [...]")

# Written beside the target and renamed over it: a failed build leaves no half-written zip.
handle, temporary = tempfile.mkstemp(prefix=".fairmesh_blender.", suffix=".zip", dir=target)
os.close(handle)
try:
    with zipfile.ZipFile(temporary, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        for name in sorted(os.listdir(source)):
            path = os.path.join(source, name)
            if name == "blender_manifest.toml":
                archive.writestr(f"fairmesh_blender/{name}", manifest)
            elif name.endswith(".py"):
                archive.write(path, f"fairmesh_blender/{name}")
        archive.write(wheel, f"fairmesh_blender/wheels/{wheel_name}")
        for name, data in vendored:
            archive.writestr(f"fairmesh_blender/vendor/{name}", data)
    os.replace(temporary, output)
except BaseException:
    os.unlink(temporary)
    raise
print(f"build_blender_addon: {output} ({os.path.getsize(output) // 1024} KiB, {wheel_name})")
EOF

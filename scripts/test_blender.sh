#!/usr/bin/env bash
# The Blender add-on's tests (tests/blender/test_*.py), run inside Blender itself: installs
# Debian's blender and python3-numpy (and xvfb, xauth) when missing, builds target/fairmesh_blender.zip
# (scripts/build_blender_addon.sh, reusing python/dist/*.whl that scripts/test_python.sh left),
# then runs each test script headless with the zip. Blender installs the add-on into a scratch
# user folder, so the machine's own Blender settings are not touched. Exits non-zero when a test
# fails. Run by .ci/run after scripts/test_python.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
# Debian's Blender runs the system Python, which finds numpy in Debian's python3-numpy; the
# window test runs under xvfb-run, which needs xauth.
missing=()
for package in blender python3-numpy xvfb xauth; do
  dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" \
    || missing+=("$package")
done
if [ "${#missing[@]}" -gt 0 ]; then
  sudo_cmd=()
  [ "$(id -u)" -ne 0 ] && sudo_cmd=(sudo)
  echo "test_blender: installing ${missing[*]}"
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq \
    --no-install-recommends "${missing[@]}" >/dev/null
fi
scripts/build_blender_addon.sh
zip="$(realpath "${CARGO_TARGET_DIR:-target}/fairmesh_blender.zip")"
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
failed=0
for script in tests/blender/test_*.py; do
  echo "test_blender: $script"
  case "$(basename "$script")" in
    test_window_*)
      # Needs a window (events, the modal run): a real one under Xvfb.
      if ! command -v xvfb-run >/dev/null 2>&1; then
        echo "test_blender: xvfb-run is missing (scripts/setup.sh installs it): $script not run"
        failed=1
        continue
      fi
      run=(xvfb-run -a -s "-screen 0 1280x800x24" blender --factory-startup
           --enable-event-simulate --python "$script" -- "$zip") ;;
    *)
      run=(blender -b --factory-startup --python-exit-code 1 --python "$script" -- "$zip") ;;
  esac
  BLENDER_USER_SCRIPTS="$scratch/scripts" BLENDER_USER_CONFIG="$scratch/config" \
    timeout 600 "${run[@]}" > "$scratch/log" 2>&1 && status=0 || status=$?
  grep -v -E '^(Read prefs|Blender quit|Color management|Saved session recovery)' "$scratch/log" || true
  if [ "$status" -ne 0 ]; then
    echo "test_blender: $script failed (exit status $status)"
    failed=1
  fi
done
exit "$failed"

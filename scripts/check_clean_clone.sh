#!/usr/bin/env bash
# Checks that fairmesh stands on its own, as a new user gets it:
# 1. clones the repository (its committed HEAD) into an empty temporary folder with nothing
#    beside it, checks that no file refers to anything outside it, builds the binary and runs
#    examples/quickstart.rs there;
# 2. copies that binary alone into another empty folder and runs `fairmesh info @bunny` (the
#    bunny compiled into the binary), checks that the help lists STL, and, when xvfb-run is
#    there, opens the editor with no file argument in a virtual X server and waits until it has
#    loaded the bunny and closed itself.
# It shares the build folder of the checkout it runs from (CARGO_TARGET_DIR, default ./target),
# so after `scripts/test.sh` only this package is compiled again; it does not run the test suite
# a second time. FAIRMESH_CHECK_PROFILE=release checks a release binary instead (a clean release
# build takes 12-14 minutes on 2 cores).
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
profile=${FAIRMESH_CHECK_PROFILE:-debug}
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-$repo/target}
case "$profile" in
  debug) profile_flag=() ;;
  release) profile_flag=(--release) ;;
  *) echo "FAIRMESH_CHECK_PROFILE must be debug or release, not $profile" >&2; exit 2 ;;
esac

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir "$work/alone" "$work/binary-only"
clone="$work/alone/fairmesh"
step() { echo "check_clean_clone: $*"; }

step "cloning $repo into an empty folder"
git clone --quiet --no-hardlinks "$repo" "$clone"
[ "$(ls -A "$work/alone")" = "fairmesh" ] || { echo "the clone's folder holds more" >&2; exit 1; }

step "no file refers to anything outside the repository"
if git -C "$clone" grep -n -I -e '\.\./shared' -e 'paper/NOTES' -- ':!scripts/check_clean_clone.sh'; then
  echo "the files above refer to the folder beside the repository or to the paper notes there, which a clone does not have" >&2
  exit 1
fi
for file in README.md LICENSE-MIT LICENSE-APACHE NOTICE CHANGELOG.md docs/architecture.md \
  docs/paper.md docs/measurements.md assets/bunny00.obj; do
  [ -s "$clone/$file" ] || { echo "the clone has no $file" >&2; exit 1; }
done

step "building the binary and the quickstart example in the clone ($profile)"
(cd "$clone" && cargo build --locked "${profile_flag[@]}" --bin fairmesh --example quickstart)
step "running examples/quickstart.rs in the clone"
quickstart_out=$(cd "$clone" && "$CARGO_TARGET_DIR/$profile/examples/quickstart")
echo "$quickstart_out"
grep -q "^37706 vertices, 75408 faces" <<<"$quickstart_out" ||
  { echo "quickstart did not load the bundled bunny" >&2; exit 1; }
grep -q "^multiresolution from level" <<<"$quickstart_out" ||
  { echo "quickstart did not get to multiresolution fairing" >&2; exit 1; }

step "copying the binary alone into an empty folder"
cp "$CARGO_TARGET_DIR/$profile/fairmesh" "$work/binary-only/"
cd "$work/binary-only"
[ "$(ls -A .)" = "fairmesh" ] || { echo "the binary's folder holds more" >&2; exit 1; }

step "fairmesh info @bunny"
info=$(./fairmesh info @bunny --json)
echo "$info"
grep -q '"vertices": *37706' <<<"$info" && grep -q '"faces": *75408' <<<"$info" ||
  { echo "fairmesh info @bunny did not report the bunny's 37706 vertices and 75408 faces" >&2; exit 1; }
help=$(./fairmesh --help)
grep -q '\.stl \.off, to read and to write' <<<"$help" ||
  { echo "fairmesh --help does not say that STL is written" >&2; exit 1; }
./fairmesh convert @bunny -o bunny.stl >/dev/null
stl_info=$(./fairmesh info bunny.stl --json)
grep -q '"faces": *75408' <<<"$stl_info" ||
  { echo "the STL written by the binary does not read back" >&2; exit 1; }
rm bunny.stl

if command -v xvfb-run >/dev/null 2>&1; then
  step "the editor with no file argument, in a virtual X server"
  runtime=$(mktemp -d -p "$work")
  chmod 700 "$runtime"
  # Settings go to a throwaway folder; the editor closes itself once the bunny is loaded,
  # its hierarchy built and the first result measured.
  editor_out=$(XDG_RUNTIME_DIR=$runtime XDG_DATA_HOME=$work/data HOME=$work/home \
    timeout 600 xvfb-run -a ./fairmesh edit --exit-when-settled 2>"$work/editor.err") || {
    cat "$work/editor.err" >&2
    echo "the editor failed or did not close by itself" >&2
    exit 1
  }
  echo "$editor_out"
  grep -q "^editor: bunny00.obj loaded" <<<"$editor_out" ||
    { cat "$work/editor.err" >&2; echo "the editor did not open the bundled bunny" >&2; exit 1; }
else
  step "xvfb-run is missing (scripts/setup.sh installs it): the editor was not started"
fi
step "all good"

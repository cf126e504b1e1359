#!/usr/bin/env bash
# How long the editor makes input wait, in a real window: runs `fairmesh edit FILE --log-frames 50`
# under Xvfb while xdotool moves the pointer every 10 ms, then prints the waits the editor logged
# (frames that took input more than 50 ms after the previous frame began) and when each background
# result arrived. Needs xvfb-run, xdotool and a build with the editor.
#
#   scripts/input_latency.sh BINARY FILE [SECONDS] [X Y] [SCREEN]
#   e.g. scripts/input_latency.sh target/release/fairmesh big.ply 80 500 350 1400x900
set -euo pipefail
bin=$1 file=$2 seconds=${3:-60} x=${4:-500} y=${5:-350} screen=${6:-1400x900}
log=$(mktemp) moves=$(mktemp)
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-$(mktemp -d)}
# One xdotool command for the whole run (no process start per move): a small circle around (x, y).
awk -v n=$((seconds * 100)) -v x="$x" -v y="$y" 'BEGIN {
  for (i = 0; i < n; i++) printf "mousemove %d %d sleep 0.01 ", x + 60 * cos(i * 0.05), y + 60 * sin(i * 0.05)
}' >"$moves"
xvfb-run -a -s "-screen 0 ${screen}x24" sh -c "
  '$bin' edit '$file' --log-frames 50 2>'$log' &
  app=\$!
  sleep 1
  xdotool \$(cat '$moves')
  kill \$app
  wait \$app 2>/dev/null || true
"
grep -E 'arrived|waited' "$log" | grep -v 'waited up to [5-9][0-9]\.\|waited up to 1[0-9][0-9]\.' || true
grep 'input waited' "$log" | sed 's/.*up to \([0-9.]*\) ms.*/\1/' | sort -n |
  awk '{a[NR] = $1} END {if (NR) printf "frames with input waiting over 50 ms: %d; median %s ms, 90th percentile %s ms, longest %s ms\n", NR, a[int((NR + 1) / 2)], a[int(NR * 0.9)], a[NR]}'
rm -f "$log" "$moves"

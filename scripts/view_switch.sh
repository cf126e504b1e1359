#!/usr/bin/env bash
# Seconds from a click to the 3D view's next image, in a real window: runs
# `fairmesh edit FILE --log-frames 4` on its own Xvfb screen (1280×800; the software renderer
# unless the machine has a GPU), waits for the first faired image and its measures, then clicks
# the toolbar's Input mesh and Faired buttons in turn and the Start level slider's track at two
# places, ROUNDS times each. For every click it prints the time until the frame log's next
# "image of the 3D view arrived" line (a drawn image, or a held mesh's kept image), the log
# polled every 10 ms; for a level change, the next one after "a fairing result arrived" or "a kept
# result arrived" (a level seen before, or faired ahead while the slider rested). First
# it prints the log's own time of the first faired image (load to first faired image).
# Needs Xvfb and xdotool.
#
#   scripts/view_switch.sh BINARY FILE [ROUNDS] [DISPLAY]
#   e.g. scripts/view_switch.sh target/release/fairmesh big_noisy.ply 5 :78
set -euo pipefail
bin=$1 file=$2 rounds=${3:-5} display=${4:-:78}
# Where the toolbar's buttons and the Start level slider are on a 1280×800 screen.
input_x=921 faired_x=759 toolbar_y=16 slider_y=519 slider_a=1050 slider_b=1003
log=$(mktemp)
export DISPLAY=$display XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-$(mktemp -d)}
Xvfb "$display" -screen 0 1280x800x24 >/dev/null 2>&1 &
xvfb=$!
sleep 1
"$bin" edit "$file" --log-frames 4 2>"$log" >/dev/null &
app=$!
trap 'kill $app $xvfb 2>/dev/null || true; rm -f "$log"' EXIT

now() { date +%s.%N; }

# Waits (at most 60 s) for an image line after the log's first `after` line counted from line
# `from`; prints the seconds since `start`.
wait_image() {
  local start=$1 from=$2 after=${3:-}
  for _ in $(seq 6000); do
    if tail -n +"$from" "$log" | { if [ -n "$after" ]; then sed -n "/$after/,\$p"; else cat; fi; } |
      grep -q 'image of the 3D view arrived'; then
      echo "$(now) - $start" | bc
      return
    fi
    sleep 0.01
  done
  echo "none within 60 s"
}

for _ in $(seq 1800); do
  grep -q 'measures arrived' "$log" && break
  sleep 0.1
done
first=$(sed -n '/a fairing result arrived/,$p' "$log" | grep -m1 'image of the 3D view arrived' |
  sed 's/at \([0-9.]*\) s.*/\1/')
echo "load to the first faired image: ${first:-none} s"
sleep 3

click() { xdotool mousemove "$1" "$2" click 1; }
for round in $(seq "$rounds"); do
  for button in "Input mesh:$input_x" "Faired:$faired_x"; do
    from=$(($(wc -l <"$log") + 1)) start=$(now)
    click "${button#*:}" $toolbar_y
    echo "round $round, to ${button%%:*}: $(wait_image "$start" "$from") s"
    sleep 2
  done
done
for round in $(seq "$rounds"); do
  for x in $slider_a $slider_b; do
    from=$(($(wc -l <"$log") + 1)) start=$(now)
    click "$x" $slider_y
    echo "round $round, level change: $(wait_image "$start" "$from" 'a fairing result arrived\|a kept result arrived') s"
    sleep 4
  done
done

#!/usr/bin/env bash
# "See what a stroke did" in the real Anthesis window (issue 40 item 2):
# under Xvfb with software Vulkan, paints a late-key stroke on the default
# lily (keyframe 54, the step-50 key's e-growth-in map), waits for its run,
# then holds B, lets go, turns the difference overlay on and holds B
# again, taking a screenshot at each step. Fails unless holding B changes
# the viewport, letting go brings back exactly the picture before, and the
# difference overlay changes it.
#
#   xvfb-run -a -s "-screen 0 1600x1000x24" app/tests/xvfb-before-after.sh [--binary PATH] [--keep DIR]
#
#   --binary PATH  the anthesis binary (default: build this checkout's
#                  release binary with cargo)
#   --keep DIR     keep the screenshots (after, before-held, released,
#                  difference, difference-before-held) and the app's log
#
# Needs: xvfb xdotool mesa-vulkan-drivers libvulkan1 imagemagick. Positions
# are those of the window at 1600x1000 with the default panel sizes (the
# viewport spans x 270-1259, y 25-780; its "Difference" toggle is in its
# top-right corner).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
cd "$here/../.."

binary=""
keep=""
while [ $# -gt 0 ]; do
  case "$1" in
    --binary) binary="$2"; shift 2 ;;
    --keep) keep="$2"; shift 2 ;;
    -h | --help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    *) echo "unknown argument $1 (see --help)" >&2; exit 2 ;;
  esac
done
[ -n "${DISPLAY:-}" ] || { echo "run it under xvfb-run (see --help)" >&2; exit 2; }

. app/tests/xvfb-window.sh
[ -n "$binary" ] || binary="$(release_binary)"
binary="$(realpath "$binary")"
unset WGPU_BACKEND  # empty means "no backends"

work="$(mktemp -d)"
out="${keep:-$work}"
mkdir -p "$out"
app=""
cleanup() {
  [ -z "$app" ] || kill "$app" 2>/dev/null || true
  wait 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT

XDG_CONFIG_HOME="$work" XDG_DATA_HOME="$work" ANTHESIS_CACHE_DIR= "$binary" \
  >"$out/app.log" 2>&1 &
app=$!
wait_window

park="700 850"
ticks() { awk '{ print $14 + $15 }' /proc/$app/stat; }
# Until the app used under 0.05 core over 4 s, twice in a row (a run has
# finished; on a loaded machine the solver may get less than half a core,
# so xvfb-window.sh's `busy` cannot tell).
idle() {
  local n=0 a b
  while [ $n -lt 2 ]; do
    a=$(ticks); sleep 4; b=$(ticks)
    if [ $((b - a)) -lt 20 ]; then n=$((n + 1)); else n=0; fi
  done
}
shot() { import -window root "$out/$1.png"; }
click() { xdotool mousemove $1 click 1; sleep 0.7; xdotool mousemove $park; }
# Viewport pixels that differ between two screenshots.
changed() {
  local a b
  for a in "$1" "$2"; do convert "$out/$a.png" -crop 990x650+270+65 +repage "$work/crop-$a.png"; done
  compare -metric AE "$work/crop-$1.png" "$work/crop-$2.png" null: 2>&1 || true
}

idle
click "863 926"   # keyframe 54 on the scrubber
click "1472 107"  # the step-50 key
canvas_x=1330; y=300
xdotool mousemove $canvas_x $y; sleep 0.3; xdotool mousedown 1; sleep 0.4
for s in 1 2 3 4 5 6 7 8 9 10; do
  xdotool mousemove $((canvas_x + s * 8)) $((y - s * 10)); sleep 0.2
done
sleep 0.3; xdotool mouseup 1; xdotool mousemove $park
idle
shot after
xdotool windowfocus "$window"; sleep 0.3
xdotool keydown b; sleep 3; shot before-held
xdotool keyup b; sleep 2; shot released
click "1215 52"; sleep 3; shot difference
xdotool windowfocus "$window"; sleep 0.3
xdotool keydown b; sleep 3; shot difference-before-held
xdotool keyup b; sleep 1

held=$(changed after before-held)
back=$(changed after released)
overlay=$(changed after difference)
echo "viewport pixels changed: B held $held, released $back, difference overlay $overlay"
[ "$held" -gt 1000 ] || { echo "holding B did not change the view" >&2; exit 1; }
[ "$back" -eq 0 ] || { echo "letting go of B did not bring the view back" >&2; exit 1; }
[ "$overlay" -gt 1000 ] || { echo "the difference overlay did not show" >&2; exit 1; }

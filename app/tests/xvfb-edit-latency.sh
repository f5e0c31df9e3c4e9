#!/usr/bin/env bash
# Measures what a user waits for after a brush stroke: the time from
# releasing the mouse to the viewed keyframe of the new result on screen,
# as the app logs it ("edit on screen after … ms"). Starts the real window
# under Xvfb on the software Vulkan driver with the default flower (the
# lily), parks the playhead at keyframe 54, picks the step-50 time key and
# paints STROKES strokes on the UV canvas, first on the whole flower, then
# in the single-organ preview of petal-1. Prints every logged latency and
# the median of each.
#
#   app/tests/xvfb-edit-latency.sh [STROKES]      (default: 7)
#
# Needs: xvfb xdotool mesa-vulkan-drivers libvulkan1. Builds the release
# binary first. Positions are those of a 1600x1000 window with the default
# panel sizes; a fresh config folder is used so the first launch is what a
# new user sees. Run it on an otherwise idle machine.
set -euo pipefail
cd "$(dirname "$0")/../.."
strokes="${1:-7}"
. app/tests/xvfb-window.sh
binary="$(release_binary)"

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
export XDG_CONFIG_HOME="$work" XDG_DATA_HOME="$work"
unset WGPU_BACKEND  # empty means "no backends"

xvfb-run -a -s "-screen 0 1600x1000x24" bash -c '
  set -euo pipefail
  binary="$1"; log="$2"; strokes="$3"
  . app/tests/xvfb-window.sh
  "$binary" > "$log" 2>&1 & app=$!
  trap "kill $app 2>/dev/null || true" EXIT
  wait_window
  # Until the first run has finished (the status line is not readable
  # from here: wait for the solver thread to go quiet).
  sleep 5
  while busy; do :; done
  # A stroke on the UV canvas (x 1270-1590, y 145-465), held long enough
  # that slow software-rendered frames see the press, the moves and the
  # release apart.
  stroke() {
    xdotool mousemove 1330 "$1"; sleep 0.3; xdotool mousedown 1; sleep 0.4
    for s in 1 2 3 4 5 6; do
      xdotool mousemove $((1330 + s * 4)) $(($1 - s * 6)); sleep 0.15
    done
    sleep 0.3; xdotool mouseup 1; sleep 0.3; xdotool mousemove 700 600
  }
  settle() {
    sleep 1
    while busy; do :; done
  }
  paint() {
    # Keyframe 54 on the timeline, then the step-50 time key.
    xdotool mousemove 863 926 click 1; sleep 1
    xdotool mousemove 1424 84 click 1; sleep 1
    for i in $(seq 1 "$strokes"); do
      stroke $((250 + (i % 7) * 25)); settle
    done
  }
  paint
  # Single-organ preview (the organs panel check box), then the same.
  xdotool mousemove 15 199 click 1; settle
  paint
' bash "$binary" "$work/app.log" "$strokes"

grep "edit on screen" "$work/app.log" || { echo "no latency logged" >&2; exit 1; }
for what in "the whole flower" "the preview"; do
  grep "edit on screen" "$work/app.log" | grep "of $what" |
    sed 's/.*after \([0-9]*\) ms.*/\1/' | sort -n |
    awk -v what="$what" '{ v[NR] = $1 } END {
      if (NR == 0) { print what ": none"; exit }
      m = (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2
      printf "%s: median %d ms of %d strokes (min %d, max %d)\n", what, m, NR, v[1], v[NR]
    }'
done

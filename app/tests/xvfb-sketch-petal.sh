#!/usr/bin/env bash
# A petal sketched from scratch in the real window becomes the five-petal
# flower's petal and the flower opens with it (issue 14 item 9). Starts the
# window under Xvfb on the software Vulkan driver on `builtin:five-petal`,
# opens Flower → Shape → Sketch a new shape, draws the two outline strokes,
# the primary vein and one cross-section with xdotool (press, moves,
# release), applies the sketch, waits for the new run, and saves
# screenshots to OUT_DIR: before.png (the five petals as shipped),
# sketched.png (the canvas and the flower open at keyframe 100 with the
# sketched petals) and bud.png (keyframe 0). Fails when the app logs no
# edit on screen or the viewport did not change.
#
#   app/tests/xvfb-sketch-petal.sh [OUT_DIR]      (default: target/screenshots)
#
# Needs: xvfb xdotool imagemagick mesa-vulkan-drivers libvulkan1. Builds
# the release binary first. Positions are those of a 1600x1000 window with
# a fresh config folder (the default panel sizes); the sketch canvas's
# mapping was measured there (sketch point (x, y) at screen
# (210.5 + 10.6 x, 342 - 10.6 (y - 11)) after five wheel clicks down).
set -euo pipefail
cd "$(dirname "$0")/../.."
out="${1:-target/screenshots}"
mkdir -p "$out"
. app/tests/xvfb-window.sh
binary="$(release_binary)"
import=/usr/bin/import   # ImageMagick's own, not a stand-in earlier on PATH

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
export XDG_CONFIG_HOME="$work" XDG_DATA_HOME="$work" HOME="$work"
unset WGPU_BACKEND  # empty means "no backends"

xvfb-run -a -s "-screen 0 1600x1000x24" bash -c '
  set -euo pipefail
  binary="$1"; log="$2"; out="$3"; import="$4"
  . app/tests/xvfb-window.sh
  "$binary" builtin:five-petal > "$log" 2>&1 & app=$!
  trap "kill $app 2>/dev/null || true" EXIT
  wait_window
  settle() { sleep 2; while busy; do :; done; }
  settle
  "$import" -window root "$out/before.png"

  # Flower tab, the Shape section, Sketch a new shape, then the canvas
  # scrolled into view.
  xdotool mousemove 233 37 click 1; sleep 2
  xdotool mousemove 43 349 click 1; sleep 2
  xdotool mousemove 89 516 click 1; sleep 2
  xdotool mousemove 150 500
  for _ in 1 2 3 4 5; do xdotool click 5; sleep 0.3; done
  sleep 1

  # A stroke through sketch points "x1 y1 x2 y2 ...", six moves a segment.
  to_screen() {
    awk -v x="$1" -v y="$2" "BEGIN { printf \"%d %d\", 210.5 + 10.6 * x, 342 - 10.6 * (y - 11) }"
  }
  draw() {
    local p=("$@") n=$(( $# / 2 )) i s
    xdotool mousemove $(to_screen "${p[0]}" "${p[1]}"); sleep 0.3
    xdotool mousedown 1; sleep 0.3
    for ((i = 1; i < n; i++)); do
      for s in 1 2 3 4 5 6; do
        xdotool mousemove $(awk -v a="${p[2*i-2]}" -v b="${p[2*i-1]}" \
          -v c="${p[2*i]}" -v d="${p[2*i+1]}" -v s=$s "BEGIN {
            t = s / 6; x = a + (c - a) * t; y = b + (d - b) * t
            printf \"%d %d\", 210.5 + 10.6 * x, 342 - 10.6 * (y - 11) }")
        sleep 0.06
      done
    done
    sleep 0.3; xdotool mouseup 1; sleep 1.5
  }
  # A wide, rounded petal 19 long: left and right outlines, the vein,
  # then a cross-section sagging towards the base (a cupped petal).
  draw -1 0 -4 5 -6 10 -5 15 -2 18.5
  draw 1 0 4 5 6 10 5 15 2 18.5
  draw 0 0 0 6 0 12 0 19
  draw -6.5 10.8 -3 9.2 0 8.6 3 9.2 6.5 10.8
  sleep 2
  # Apply sketch (below the side view of the bent rows).
  xdotool mousemove 69 670 click 1
  settle
  xdotool mousemove 700 760; sleep 2
  "$import" -window root "$out/sketched.png"
  # Keyframe 0: the bud of the sketched petals.
  xdotool mousemove 30 903 click 1; sleep 3
  xdotool mousemove 700 760; sleep 2
  "$import" -window root "$out/bud.png"
' bash "$binary" "$work/app.log" "$out" "$import"

cat "$work/app.log"
grep -q "edit on screen" "$work/app.log" || { echo "the sketch started no run" >&2; exit 1; }
# The viewport (x 410-1255, y 30-780) shows other petals than before.
convert "$out/before.png" -crop 845x750+410+30 +repage "$work/before-view.png"
convert "$out/sketched.png" -crop 845x750+410+30 +repage "$work/sketched-view.png"
changed=$(compare -metric AE -fuzz 10% "$work/before-view.png" "$work/sketched-view.png" \
  null: 2>&1 || true)
echo "viewport pixels changed: $changed"
[ "${changed%%.*}" -gt 20000 ] || { echo "the flower did not change" >&2; exit 1; }
echo "screenshots in $out"

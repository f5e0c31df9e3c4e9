#!/usr/bin/env bash
# Starts the real Anthesis window under Xvfb on the software Vulkan driver,
# waits for the flower to open, paints a stroke on the UV canvas with
# xdotool, and saves screenshots (ImageMagick's `import`) to OUT_DIR.
#
#   app/tests/xvfb-screenshots.sh [--binary PATH] [OUT_DIR]
#
#   --binary PATH  the anthesis binary to drive (also BINARY=PATH; default:
#                  build this checkout's release binary with cargo)
#   OUT_DIR        where the screenshots go (default: target/screenshots)
#
# Needs: xvfb xdotool imagemagick mesa-vulkan-drivers libvulkan1. A fresh
# config folder is used so the first launch (the default flower) is what
# is shown. Takes screenshots only (the checks are in
# xvfb-crash-recovery.sh and xvfb-sketch-petal.sh).
set -euo pipefail
cd "$(dirname "$0")/../.."
. app/tests/xvfb-window.sh
parse_arguments "$@"
binary="$(anthesis_binary "$binary")"

config="$(mktemp -d)"
trap 'rm -rf "$config"' EXIT
export XDG_CONFIG_HOME="$config" XDG_DATA_HOME="$config"
unset WGPU_BACKEND  # empty means "no backends"

xvfb-run -a -s "-screen 0 1600x1000x24" bash -c '
  set -euo pipefail
  out="$1"; binary="$2"; import="$3"
  . app/tests/xvfb-window.sh
  "$binary" & app=$!
  trap "kill $app 2>/dev/null || true" EXIT
  wait_window
  sleep 4
  "$import" -window root "$out/app-start.png"
  sleep 25
  "$import" -window root "$out/app-open.png"
  # A stroke on the UV canvas (the right panel, below the map choice; in
  # a 1600x1000 window it spans about x 1270-1590, y 145-465).
  xdotool mousemove 1340 400 mousedown 1
  for step in $(seq 0 15); do
    xdotool mousemove $((1340 + step * 3)) $((400 - step * 12)); sleep 0.08
  done
  xdotool mouseup 1
  sleep 12
  "$import" -window root "$out/app-after-stroke.png"
  # Wireframe (W) and single-organ preview (P).
  xdotool windowfocus "$window"; sleep 0.5
  xdotool mousemove 800 400 key --window "$window" w key --window "$window" p
  sleep 10
  "$import" -window root "$out/app-preview-wireframe.png"
' bash "$out" "$binary" "$import"
echo "screenshots in $out"

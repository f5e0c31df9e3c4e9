#!/usr/bin/env bash
# Starts the real Anthesis window under Xvfb on the software Vulkan driver,
# waits for the flower to open, paints a stroke on the UV canvas with
# xdotool, and saves screenshots (ImageMagick's `import`) to OUT_DIR.
#
#   app/tests/xvfb-screenshots.sh [OUT_DIR]      (default: target/screenshots)
#
# Needs: xvfb xdotool imagemagick mesa-vulkan-drivers libvulkan1.
# Builds the release binary first. A fresh config folder is used so the
# first launch (the default flower) is what is shown.
set -euo pipefail
cd "$(dirname "$0")/../.."
out="${1:-target/screenshots}"
mkdir -p "$out"
cargo build --release --bin anthesis
binary="${CARGO_TARGET_DIR:-target}/release/anthesis"
import=/usr/bin/import   # ImageMagick's own, not a stand-in earlier on PATH

config="$(mktemp -d)"
trap 'rm -rf "$config"' EXIT
export XDG_CONFIG_HOME="$config" XDG_DATA_HOME="$config"
unset WGPU_BACKEND  # empty means "no backends"

xvfb-run -a -s "-screen 0 1600x1000x24" bash -c '
  set -euo pipefail
  out="$1"; binary="$2"; import="$3"
  "$binary" & app=$!
  trap "kill $app 2>/dev/null || true" EXIT
  # Wait for the window.
  for _ in $(seq 1 120); do
    window=$(xdotool search --name "Anthesis" 2>/dev/null | head -n1 || true)
    [ -n "$window" ] && break
    sleep 0.5
  done
  [ -n "$window" ] || { echo "no Anthesis window" >&2; exit 1; }
  xdotool windowsize "$window" 1600 1000 windowmove "$window" 0 0
  sleep 4
  "$import" -window root "$out/app-start.png"
  sleep 20
  "$import" -window root "$out/app-opening.png"
  # A stroke on the UV canvas (right panel, lower half).
  xdotool mousemove 1380 760 mousedown 1
  for step in $(seq 0 12); do
    xdotool mousemove $((1380 + step * 4)) $((760 - step * 12)); sleep 0.05
  done
  xdotool mouseup 1
  sleep 8
  "$import" -window root "$out/app-after-stroke.png"
' bash "$out" "$binary" "$import"
echo "screenshots in $out"

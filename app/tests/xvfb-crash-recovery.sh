#!/usr/bin/env bash
# Autosave and recovery in the real window, under Xvfb on the software
# Vulkan driver: paints a stroke on the UV canvas, waits for the autosave
# (ANTHESIS_AUTOSAVE_SECONDS=3), kills the app with SIGKILL, starts it
# again, screenshots the "Recover unsaved work?" prompt, clicks Recover and
# screenshots the recovered stroke. Screenshots go to OUT_DIR.
#
#   app/tests/xvfb-crash-recovery.sh [OUT_DIR]    (default: target/screenshots)
#
# Needs: xvfb xdotool imagemagick mesa-vulkan-drivers libvulkan1. Builds
# the release binary first (BINARY=path uses another build). A fresh data
# folder is used, so the first launch shows the default flower.
set -euo pipefail
cd "$(dirname "$0")/../.."
out="${1:-target/screenshots}"
mkdir -p "$out"
if [ -z "${BINARY:-}" ]; then
  cargo build --release --bin anthesis
  BINARY="${CARGO_TARGET_DIR:-target}/release/anthesis"
fi
import=/usr/bin/import   # ImageMagick's own, not a stand-in earlier on PATH

data="$(mktemp -d)"
trap 'rm -rf "$data"' EXIT
export XDG_CONFIG_HOME="$data" XDG_DATA_HOME="$data" ANTHESIS_AUTOSAVE_SECONDS=3
unset WGPU_BACKEND  # empty means "no backends"

xvfb-run -a -s "-screen 0 1600x1000x24" bash -c '
  set -euo pipefail
  out="$1"; binary="$2"; import="$3"; data="$4"
  . app/tests/xvfb-window.sh

  "$binary" & app=$!
  wait_window
  sleep 20
  # A stroke on the UV canvas (right panel; about x 1270-1590, y 145-465).
  xdotool mousemove 1340 400 mousedown 1
  for step in $(seq 0 15); do
    xdotool mousemove $((1340 + step * 3)) $((400 - step * 12)); sleep 0.08
  done
  xdotool mouseup 1
  sleep 10
  "$import" -window root "$out/crash-1-painted.png"
  note=$(find "$data" -name recovery.toml | head -n1)
  [ -n "$note" ] || { echo "no recovery was written" >&2; exit 1; }
  echo "autosaved: $note"
  kill -9 "$app"
  wait "$app" 2>/dev/null || true

  "$binary" & app=$!
  trap "kill $app 2>/dev/null || true" EXIT
  wait_window
  sleep 15
  "$import" -window root "$out/crash-2-offer.png"
  # The prompt is centred in the 1600x1000 window; its Recover button
  # sits at its lower left (for the prompt of the default flower).
  xdotool mousemove "${RECOVER_X:-541}" "${RECOVER_Y:-529}" click 1
  sleep 15
  "$import" -window root "$out/crash-3-recovered.png"
' bash "$out" "$BINARY" "$import" "$data"
echo "screenshots in $out"

#!/usr/bin/env bash
# The window opens, shows the flower, takes a stroke, and gives the stroke
# back after a crash: in the real window, under Xvfb on the software
# Vulkan driver. Starts the app on a fresh data folder (the default
# flower), waits until the viewport shows the flower, paints a stroke on
# the UV canvas, waits for the autosave (ANTHESIS_AUTOSAVE_SECONDS=3),
# kills the app with SIGKILL, starts it again, clicks Recover on the
# "Recover unsaved work?" prompt and screenshots the recovered stroke.
# Screenshots go to OUT_DIR.
#
#   app/tests/xvfb-crash-recovery.sh [--binary PATH] [OUT_DIR]
#
#   --binary PATH  the anthesis binary to drive (also BINARY=PATH; default:
#                  build this checkout's release binary with cargo)
#   OUT_DIR        where the screenshots go (default: target/screenshots)
#
# Fails (exit 1, saying which) when: the viewport shows no flower within
# two minutes (fewer than 2 % of its pixels coloured); the stroke changes
# fewer than 300 pixels of the UV canvas; no recovery is written; or the
# canvas after Recover is not the painted one (it must differ from the
# unpainted canvas at least four times as much as from the painted one).
# .ci/xvfb runs it on every submission.
#
# Needs: xvfb xdotool imagemagick mesa-vulkan-drivers libvulkan1.
# Positions are those of the 1600x1000 window with the default panel
# sizes (xvfb-window.sh).
set -euo pipefail
cd "$(dirname "$0")/../.."
. app/tests/xvfb-window.sh
parse_arguments "$@"
binary="$(anthesis_binary "$binary")"

data="$(mktemp -d)"
trap 'rm -rf "$data"' EXIT
export XDG_CONFIG_HOME="$data" XDG_DATA_HOME="$data" HOME="$data" ANTHESIS_AUTOSAVE_SECONDS=3
unset WGPU_BACKEND  # empty means "no backends"

xvfb-run -a -s "-screen 0 1600x1000x24" bash -c '
  set -euo pipefail
  out="$1"; binary="$2"; data="$3"
  . app/tests/xvfb-window.sh

  "$binary" > "$out/crash-app-1.log" 2>&1 & app=$!
  trap "kill $app 2>/dev/null || true" EXIT
  wait_window
  wait_for_flower "$out/crash-0-start.png"
  "$import" -window root "$out/crash-0-start.png"
  stroke_uv_canvas 1340 400
  # The pointer off the canvas (no brush ring) for the screenshots.
  xdotool mousemove 800 10
  sleep 3
  "$import" -window root "$out/crash-1-painted.png"
  painted=$(changed_pixels "$out/crash-0-start.png" "$out/crash-1-painted.png" "$UV_CANVAS")
  echo "the stroke changed $painted pixels of the UV canvas"
  [ "$painted" -ge 300 ] || { echo "FAIL: the stroke did not paint the UV canvas" >&2; exit 1; }
  note=""
  for _ in $(seq 1 40); do
    note=$(find "$data" -name recovery.toml | head -n1)
    [ -n "$note" ] && break
    sleep 0.5
  done
  [ -n "$note" ] || { echo "FAIL: no recovery was written" >&2; exit 1; }
  echo "autosaved: $note"
  kill -9 "$app"
  wait "$app" 2>/dev/null || true

  "$binary" > "$out/crash-app-2.log" 2>&1 & app=$!
  wait_window
  # The prompt, once the window has its size: a dark box over the
  # middle of the viewport.
  shown=""
  for _ in $(seq 1 60); do
    "$import" -window root "$out/crash-2-offer.png"
    dark "$out/crash-2-offer.png" "$PROMPT" && ! dark "$out/crash-2-offer.png" "$BESIDE_PROMPT" 0.1 &&
      { shown=1; break; }
    sleep 1
  done
  [ -n "$shown" ] || { echo "FAIL: no recovery prompt (crash-2-offer.png)" >&2; exit 1; }
  sleep 2
  "$import" -window root "$out/crash-2-offer.png"
  # Its Recover button sits at its lower left, 37 pixels in from its
  # edge; clicked again if a slow frame missed the click.
  left=$(prompt_left "$out/crash-2-offer.png")
  [ -n "$left" ] || { echo "FAIL: no prompt box on crash-2-offer.png" >&2; exit 1; }
  for _ in 1 2 3; do
    # The pointer stays on the button for a few frames (a slow frame
    # sees the press, the release and where the pointer is then).
    xdotool mousemove $((left + 37)) 529; sleep 0.5; xdotool click 1; sleep 2
    xdotool mousemove 800 10
    shown=""
    for _ in $(seq 1 10); do
      sleep 1
      "$import" -window root "$out/crash-3-recovered.png"
      dark "$out/crash-3-recovered.png" "$PROMPT" || { shown=gone; break; }
    done
    [ "$shown" = gone ] && break
  done
  [ "$shown" = gone ] || { echo "FAIL: the prompt stayed after Recover" >&2; exit 1; }
  wait_for_flower "$out/crash-3-recovered.png"
  sleep 2
  "$import" -window root "$out/crash-3-recovered.png"
  from_painted=$(changed_pixels "$out/crash-1-painted.png" "$out/crash-3-recovered.png" "$UV_CANVAS")
  from_start=$(changed_pixels "$out/crash-0-start.png" "$out/crash-3-recovered.png" "$UV_CANVAS")
  echo "recovered UV canvas: $from_painted pixels off the painted one, $from_start off the unpainted one"
  [ "$from_start" -ge $((4 * from_painted)) ] && [ "$from_start" -ge 300 ] || {
    echo "FAIL: the recovered canvas is not the painted one" >&2; exit 1; }
' bash "$out" "$binary" "$data"
echo "screenshots in $out"

#!/usr/bin/env bash
# Measures what a user waits for in the real Anthesis window, from the
# screen's pixels (not from the app's log). Starts Xvfb with -fbdir (its
# screen is then a memory-mapped XWD file, read at any moment without a
# screenshot), drives the window with xdotool, and has
# app/tests/pixel_watch.py poll the viewport every few milliseconds for
# the first and the last change after each action.
#
#   app/tests/xvfb-edit-latency.sh [--binary PATH] [--strokes N] [--keep DIR] [CASE...]
#
#   --binary PATH  the anthesis binary to measure (default: build this
#                  checkout's release binary with cargo)
#   --strokes N    repetitions per case (default: $STROKES, else 7)
#   --keep DIR     keep every measurement (JSON lines), the app's logs and
#                  a screenshot of each case's set-up in DIR
#   CASE           any of the cases below (default: all, in this order)
#
# Cases (whole built-in lily, 1600x1000 window, fresh settings per launch):
#   key-step        Home and End in turn, nothing simulating: key press to
#                   the first changed viewport pixel.
#   late-stroke     playhead on keyframe 54, a stroke on the step-50 key's
#                   map (UV canvas).
#   early-stroke    the same on the step-40 key, playhead on keyframe 100.
#   preview-stroke  single-organ preview (P), step-50 key, keyframe 54.
#   first-launch    from the window's first frame (default 1400x900 size)
#                   to the first change of the viewport after it (the lily
#                   opening) and to its last change (the run done).
# For a stroke, "proxy" is the first change of the viewport after the
# mouse button is released and "final" its last change before the screen
# settles (nothing watched changes for SETTLE seconds, default 3; the
# timeline is watched too, so a run still computing keyframes keeps it
# from settling). Changes from runs started while the button was down
# count if they reach the screen after the release; a stroke whose result
# was on screen before the release (no change after it) counts as 0 ms. A
# key step that changed nothing is left out of the median. A strip along the
# viewport's top edge (where a "proxy" badge may be drawn) and the
# timeline's scrubber are watched separately and reported in the details.
# The pointer stays off the viewport while watching.
#
# Output: one line per case,
#   CASE: median N ms (proxy), M ms (final)      (key-step: median N ms)
# after the load average at the start and end, and each repetition's
# numbers as "  CASE #i: ..." lines before it.
#
# Needs: xvfb xdotool mesa-vulkan-drivers libvulkan1 python3 (standard
# library only); imagemagick for --keep's screenshots. Positions are those
# of the window at 1600x1000 with the default panel sizes (check them on
# a --keep screenshot after a layout change). Run it on an otherwise idle
# machine: it prints `uptime` before and after.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
cd "$here/../.."

strokes="${STROKES:-7}"
settle="${SETTLE:-3}"
binary=""
keep=""
cases=()
while [ $# -gt 0 ]; do
  case "$1" in
    --binary) binary="$2"; shift 2 ;;
    --strokes) strokes="$2"; shift 2 ;;
    --keep) keep="$2"; shift 2 ;;
    -h | --help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
    -*) echo "unknown option $1 (see --help)" >&2; exit 2 ;;
    *) cases+=("$1"); shift ;;
  esac
done
[ ${#cases[@]} -gt 0 ] || cases=(key-step late-stroke early-stroke preview-stroke first-launch)
for c in "${cases[@]}"; do
  case "$c" in
    key-step | late-stroke | early-stroke | preview-stroke | first-launch) ;;
    *) echo "unknown case $c (see --help)" >&2; exit 2 ;;
  esac
done

. app/tests/xvfb-window.sh
[ -n "$binary" ] || binary="$(release_binary)"
binary="$(realpath "$binary")"
[ -x "$binary" ] || { echo "no binary at $binary" >&2; exit 1; }
watcher="$here/pixel_watch.py"
unset WGPU_BACKEND  # empty means "no backends"

work="$(mktemp -d)"
[ -z "$keep" ] || mkdir -p "$keep"
app=""
xvfb=""
cleanup() {
  [ -z "$app" ] || kill "$app" 2>/dev/null || true
  [ -z "$xvfb" ] || kill "$xvfb" 2>/dev/null || true
  wait 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT

# Xvfb on a display it picks itself (-displayfd), black root.
mkdir "$work/fb"
Xvfb -displayfd 3 -screen 0 1600x1000x24 -fbdir "$work/fb" -nolisten tcp -br \
  3>"$work/display" >"$work/xvfb.log" 2>&1 &
xvfb=$!
for _ in $(seq 1 100); do
  [ -s "$work/display" ] && [ -s "$work/fb/Xvfb_screen0" ] && break
  sleep 0.1
done
[ -s "$work/display" ] || { echo "Xvfb did not start:" >&2; cat "$work/xvfb.log" >&2; exit 1; }
export DISPLAY=":$(head -n1 "$work/display")"
fb="$work/fb/Xvfb_screen0"

# Screen regions, X,Y,W,H, of the 1600x1000 window at the screen's corner
# (the viewport spans x 270-1259, y 25-780).
viewport=270,65,990,716  # the 3D view below its top strip
badge=270,25,990,40      # the strip along its top edge
timeline=8,917,1584,22   # the scrubber
# Where the pointer rests while watching: over the log, off the viewport.
park="700 850"
# The UV canvas of the paint panel (x 1269-1592, y 166-488), keyframes 54
# and 100 on the scrubber, the step-40 and step-50 keys, the single-organ
# preview check box.
canvas_x=1330
keyframe_54="863 926"
keyframe_100="1588 926"
key_40="1400 107"
key_50="1472 107"
preview_box="15 199"
# The same for the first launch, in the window's default 1400x900 size
# (the viewport spans x 270-1059, y 25-680).
launch_viewport=270,65,790,616
launch_badge=270,25,790,40
launch_timeline=8,817,1384,22

# Runs pixel_watch.py over the regions of `regions` with the given
# options; the JSON result goes to stdout.
watch() {
  python3 "$watcher" "$fb" --settle "$settle" "${regions[@]}" "$@"
}
regions=(--watch "viewport=$viewport" --watch "badge=$badge" --watch "timeline=$timeline")

# Starts the binary with fresh settings (a new user's first launch) and
# waits for its window; sets `app`, `window`.
launch() {
  local home="$work/home-$1"
  mkdir -p "$home"
  XDG_CONFIG_HOME="$home" XDG_DATA_HOME="$home" "$binary" >"$work/app-$1.log" 2>&1 &
  app=$!
}
quit() {
  kill "$app" 2>/dev/null || true
  wait "$app" 2>/dev/null || true
  app=""
}
# Gives the window the keyboard (there is no window manager).
focus() { xdotool windowfocus "$window"; sleep 0.3; }
# Waits until nothing watched changes for SETTLE seconds and the app is
# idle (a run has finished).
settled() {
  watch --timeout 600 >/dev/null
  while busy; do :; done
}
click() { xdotool mousemove $1 click 1; sleep 0.5; xdotool mousemove $park; }
screenshot() {
  [ -z "$keep" ] || convert "xwd:$fb" "$keep/$1.png" 2>/dev/null || true
}

# The JSON results of one case, one line each, in $work/CASE.jsonl.
record() { cat >>"$work/$1.jsonl"; }

# A stroke on the UV canvas at height y, held long enough that slow
# software-rendered frames see the press, the moves and the release apart;
# the release is the measured action.
stroke() {
  local y="$1" s
  xdotool mousemove "$canvas_x" "$y"; sleep 0.3; xdotool mousedown 1; sleep 0.4
  for s in 1 2 3 4 5 6; do
    xdotool mousemove $((canvas_x + s * 4)) $((y - s * 6)); sleep 0.15
  done
  sleep 0.3
  watch -- xdotool mouseup 1
  while busy; do :; done
}

# Each stroke is undone (Ctrl+Z) and the window left to settle before the
# next, so every stroke edits the shipped maps: strokes piled on one
# another drive the lily's petals through its sepals, and the run then
# stops at the crossing instead of reaching the viewed keyframe.
strokes_case() {
  local name="$1" i
  for i in $(seq 1 "$strokes"); do
    stroke $((250 + (i % 7) * 25)) | record "$name"
    focus; xdotool key ctrl+z; xdotool mousemove $park
    settled
  done
}

case_key_step() {
  launch key-step; wait_window; settled
  xdotool mousemove $park; focus; sleep 1
  screenshot key-step
  local i key
  for i in $(seq 1 "$strokes"); do
    for key in Home End; do
      watch --settle 1 -- xdotool key "$key" | record key-step
    done
  done
  quit
}

case_late_stroke() {
  launch late; wait_window; settled
  click "$keyframe_54"; click "$key_50"; settled
  screenshot late-stroke
  strokes_case late-stroke
  quit
}

case_early_stroke() {
  launch early; wait_window; settled
  # Near the scrubber's end, then one keyframe on: exactly keyframe 100.
  click "$keyframe_100"; focus; xdotool key Right; sleep 0.5
  click "$key_40"; settled
  screenshot early-stroke
  strokes_case early-stroke
  quit
}

case_preview_stroke() {
  launch preview; wait_window; settled
  click "$preview_box"; settled
  click "$keyframe_54"; click "$key_50"; settled
  screenshot preview-stroke
  strokes_case preview-stroke
  quit
}

case_first_launch() {
  local i
  for i in $(seq 1 "$strokes"); do
    # The whole screen is black until the window's first frame.
    python3 "$watcher" "$fb" --settle "$settle" --timeout 600 --zero-on-change screen \
      --watch screen=0,0,1600,1000 --watch "viewport=$launch_viewport" \
      --watch "badge=$launch_badge" --watch "timeline=$launch_timeline" \
      >"$work/launch.json" &
    local watching=$!
    sleep 0.5
    launch "first-$i"
    wait "$watching"
    record first-launch <"$work/launch.json"
    [ "$i" -gt 1 ] || screenshot first-launch
    quit
    sleep 1
  done
}

# The median of the numbers on stdin ("-" when there are none).
median() {
  sort -n | awk '{ v[NR] = $1 } END {
    if (NR == 0) { print "-"; exit }
    m = (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2
    printf "%d\n", m + 0.5
  }'
}
# Field FIELD of region REGION from each JSON line on stdin; with a third
# argument, a region that did not change counts as that many ms (a stroke
# whose result was already on screen at the release), else it is left out.
field() {
  python3 -c '
import json, sys
region, field = sys.argv[1], sys.argv[2]
missing = sys.argv[3] if len(sys.argv) > 3 else None
for line in sys.stdin:
    value = json.loads(line)["regions"].get(region, {}).get(field)
    if value is None:
        value = missing
    if value is not None:
        print(value)' "$@"
}
details() {
  python3 -c '
import json, sys
name = sys.argv[1]
for i, line in enumerate(sys.stdin, 1):
    r = json.loads(line)
    parts = []
    for region, v in r["regions"].items():
        first, last, n = v["first_ms"], v["last_ms"], v["changes"]
        parts.append(f"{region} {first}..{last} ms ({n} changes)")
    extra = " TIMED OUT" if r.get("timed_out") else ""
    print(f"  {name} #{i}: " + ", ".join(parts) + extra)' "$1"
}

echo "load before: $(uptime)"
for c in "${cases[@]}"; do
  "case_${c//-/_}"
done
echo "load after: $(uptime)"
[ -z "$keep" ] || cp "$work"/*.jsonl "$work"/app-*.log "$keep/"
echo "binary: $binary"
for c in "${cases[@]}"; do
  details "$c" <"$work/$c.jsonl"
done
for c in "${cases[@]}"; do
  if [ "$c" = key-step ] || [ "$c" = first-launch ]; then
    first=$(field viewport first_ms <"$work/$c.jsonl" | median)
  else
    first=$(field viewport first_ms 0 <"$work/$c.jsonl" | median)
  fi
  if [ "$c" = key-step ]; then
    echo "key-step: median $first ms"
  else
    if [ "$c" = first-launch ]; then
      last=$(field viewport last_ms <"$work/$c.jsonl" | median)
    else
      last=$(field viewport last_ms 0 <"$work/$c.jsonl" | median)
    fi
    echo "$c: median $first ms (proxy), $last ms (final)"
  fi
done

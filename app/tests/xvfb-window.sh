# Sourced by the app/tests/xvfb-*.sh scripts (from the repository root,
# and inside their xvfb-run shell): what each of them needs to drive the
# real Anthesis window.

# The scripts' arguments, `[--binary PATH] [OUT_DIR]` (`--help` prints the
# calling script's header): sets `binary` (empty: build one) and `out`,
# made and absolute (target/screenshots by default).
parse_arguments() {
  binary=""
  out=""
  while [ $# -gt 0 ]; do
    case "$1" in
      --binary) binary="$2"; shift 2 ;;
      -h | --help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
      -*) echo "unknown option $1 (see --help)" >&2; exit 2 ;;
      *) out="$1"; shift ;;
    esac
  done
  out="${out:-target/screenshots}"
  mkdir -p "$out"
  out="$(realpath "$out")"
}

# Builds the release binary and prints its absolute path (under
# CARGO_TARGET_DIR when that is set, absolute or relative).
release_binary() {
  cargo build --release --bin anthesis >&2
  local target_dir="${CARGO_TARGET_DIR:-target}"
  case "$target_dir" in /*) ;; *) target_dir="$(pwd)/$target_dir" ;; esac
  echo "$target_dir/release/anthesis"
}

# Waits (up to 2 minutes) for the Anthesis window, then sizes it to
# 1600x1000 at the screen's corner, where the scripts' pointer positions
# are measured. Sets `window`.
wait_window() {
  window=""
  for _ in $(seq 1 240); do
    window=$(xdotool search --name "Anthesis" 2>/dev/null | head -n1 || true)
    [ -n "$window" ] && break
    sleep 0.5
  done
  [ -n "$window" ] || { echo "no Anthesis window" >&2; exit 1; }
  xdotool windowsize "$window" 1600 1000 windowmove "$window" 0 0
}

# Whether the app (process id in `app`) used more than half a core in the
# next second: its solver thread keeps it near a whole core while a run
# computes. Takes that second to answer.
busy() {
  local before; before=$(awk '{ print $14 + $15 }' /proc/$app/stat); sleep 1
  [ $(( $(awk '{ print $14 + $15 }' /proc/$app/stat) - before )) -gt 50 ]
}

# The anthesis binary to drive, as an absolute path: $1 when given (a
# script's --binary PATH), else $BINARY when set, else this checkout's
# release build (built now).
anthesis_binary() {
  local given="${1:-${BINARY:-}}"
  [ -n "$given" ] || given="$(release_binary)"
  given="$(realpath "$given")"
  [ -x "$given" ] || { echo "no binary at $given" >&2; exit 1; }
  echo "$given"
}

# ImageMagick's own tools, not stand-ins earlier on PATH.
import=/usr/bin/import
convert=/usr/bin/convert
compare=/usr/bin/compare

# Regions of the 1600x1000 window with the default panel sizes (check
# them on a screenshot after a layout change): the middle of the 3D
# viewport, and the UV paint canvas in the right panel.
VIEWPORT=900x700+320+40
UV_CANVAS=300x300+1280+155

# The fraction of the pixels of region $2 (WxH+X+Y) of picture $1 with a
# saturated colour (HSL saturation above 25 %): the flower's petals
# against the grey viewport background, which has none.
saturated() {
  "$convert" "$1" -crop "$2" +repage -colorspace HSL -channel G -separate +channel \
    -threshold 25% -format "%[fx:mean]" info:
}

# How many pixels of region $3 differ by more than 10 % between pictures
# $1 and $2.
changed_pixels() {
  local n
  n=$("$compare" -metric AE -fuzz 10% "$1[$3]" "$2[$3]" null: 2>&1 || true)
  echo "${n%%.*}"
}

# Takes screenshots into $1 every 2 seconds until the viewport shows the
# flower (more than 2 % of its pixels saturated) or $2 seconds (default
# 120) pass; fails then. Prints the seconds it took.
wait_for_flower() {
  local shot="$1" limit="${2:-120}" start=$SECONDS fraction
  while true; do
    "$import" -window root "$shot"
    fraction=$(saturated "$shot" "$VIEWPORT")
    if awk -v f="$fraction" 'BEGIN { exit !(f > 0.02) }'; then
      echo "the flower is shown after $((SECONDS - start)) s ($fraction of the viewport)"
      return 0
    fi
    if [ $((SECONDS - start)) -ge "$limit" ]; then
      echo "FAIL: no flower in the viewport after $limit s ($fraction saturated; $shot)" >&2
      return 1
    fi
    sleep 2
  done
}

# A stroke on the UV canvas with the primary button: pressed at (x, y),
# 16 moves up and to the right.
stroke_uv_canvas() {
  local x="${1:-1340}" y="${2:-400}" step
  xdotool mousemove "$x" "$y" mousedown 1
  for step in $(seq 0 15); do
    xdotool mousemove $((x + step * 3)) $((y - step * 12)); sleep 0.08
  done
  xdotool mouseup 1
}

# Whether region $2 of picture $1 is darker than $3 (mean brightness,
# default 0.3): the "Recover unsaved work?" prompt's box over the
# viewport; below 0.1, a screen not drawn yet.
dark() {
  local mean
  mean=$("$convert" "$1" -crop "$2" +repage -colorspace Gray -format "%[fx:mean]" info:)
  awk -v m="$mean" -v t="${3:-0.3}" 'BEGIN { exit !(m < t) }'
}

# A line of the recovery prompt's text, centred in the 1600x1000 window,
# and a patch of the viewport beside the prompt.
PROMPT=400x30+600+478
BESIDE_PROMPT=50x50+1000+200

# The left edge of the recovery prompt's box in picture $1, on the row of
# its buttons (y $2, default 529): where the first 5 pixels in a row as
# dark as its box (not its buttons) start, from x 300 on. Its width
# follows its text, so its buttons move. (awk reads to the end: a reader
# that stops early would make convert fail on a closed pipe.)
prompt_left() {
  "$convert" "$1" -crop 1000x1+300+"${2:-529}" +repage -colorspace Gray -depth 8 txt:- |
    awk -F'[,:() ]+' 'NR > 1 && left == "" {
      x = $1; v = $(NF - 1) + 0
      if (v < 35) { run++; if (run == 5) left = 300 + x - 4 } else run = 0
    }
    END { print left }'
}

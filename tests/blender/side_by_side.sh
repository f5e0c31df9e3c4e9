#!/usr/bin/env bash
# The README's side-by-side picture: one keyframe of a built-in flower as
# `anthesis render` draws it, as three.js plays its .glb (tests/browser)
# and as Blender imports and draws the same .glb (tests/blender: studio
# light, then the unlit base colour the Blender test compares), all seen by
# anthesis render's camera.
#
#   bash tests/blender/side_by_side.sh ANTHESIS OUT.png [FLOWER] [KEYFRAME]
#
# ANTHESIS is the binary (target/release/anthesis); FLOWER defaults to
# lily, KEYFRAME to 100. Needs what .ci/run installs (Chromium and
# tests/browser's npm packages, tests/blender/.venv) and ImageMagick.
set -euo pipefail
if [ $# -lt 2 ] || [ $# -gt 4 ]; then
    echo "usage: $0 ANTHESIS OUT.png [FLOWER] [KEYFRAME]" >&2
    exit 2
fi
anthesis=$(realpath "$1")
out=$(realpath -m "$2")
flower=${3:-lily}
keyframe=${4:-100}
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$(dirname "$here")")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

width=640
height=480
background=a7b1bb
"$anthesis" simulate "builtin:$flower" --out "$work/flower.glb"
mkdir "$work/anthesis" "$work/three" "$work/blender"
"$anthesis" render "builtin:$flower" --frames "$keyframe" --size "${width}x$height" \
    --elevation 35 --background "$background" --out "$work/anthesis"

# The jobs of the two checks, with anthesis render's camera.
"$anthesis" info "builtin:$flower" >"$work/info.txt"
/usr/bin/python3 - "$work" "$keyframe" "$width" "$height" <<'EOF'
import json, re, sys
work, keyframe, width, height = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
camera = json.load(open(f"{work}/anthesis/camera.json"))
info = open(f"{work}/info.txt").read()
# anthesis render's camera is in project units, the exports in metres:
# one unit is what `anthesis info` says (one metre when the project does
# not say).
unit = re.search(r"one unit is ([0-9.]+) ?(µm|mm|cm|m)\)", info)
metres = float(unit.group(1)) * {"µm": 1e-6, "mm": 1e-3, "cm": 1e-2, "m": 1.0}[unit.group(2)] if unit else 1.0
for key in ("eye", "target"):
    camera[key] = [x * metres for x in camera[key]]
camera["near"] *= metres
time = keyframe / 24
json.dump({"width": width, "height": height, "times": [time], "camera": camera, "hide": [],
           "files": [{"name": "flower", "path": f"{work}/flower.glb"}], "out": f"{work}/three"},
          open(f"{work}/three.json", "w"))
json.dump({"file": f"{work}/flower.glb", "width": width, "height": height, "fps": 24,
           "times": [time], "camera": camera, "looks": ["studio", "albedo"],
           "out": f"{work}/blender"}, open(f"{work}/blender.json", "w"))
EOF
node "$root/tests/browser/render.mjs" "$work/three.json" >/dev/null
"$root/tests/blender/.venv/bin/python" "$here/render.py" "$work/blender.json" >/dev/null 2>&1

# three.js clears to magenta: put its drawn pixels (green in the ids
# picture, no antialiasing) on the background; Blender's are transparent.
convert -size "${width}x$height" "xc:#$background" "$work/three/flower-0-shaded.png" \
    \( "$work/three/flower-0-ids.png" -channel G -separate \) -composite "$work/three.png"
for look in studio albedo; do
    convert "$work/blender/blender-0-$look.png" -background "#$background" -flatten "$work/$look.png"
done
# One crop for all four: the flower's box in anthesis render's picture, with a margin.
box=$(convert "$work/anthesis/frame-$(printf %03d "$keyframe").png" -fuzz 8% -trim -format '%wx%h%X%Y' info:)
read -r w h x y < <(echo "$box" | sed -E 's/([0-9]+)x([0-9]+)\+([0-9]+)\+([0-9]+)/\1 \2 \3 \4/')
m=12
crop="$((w + 2 * m))x$((h + 2 * m))+$((x > m ? x - m : 0))+$((y > m ? y - m : 0))"
cp "$work/anthesis/frame-$(printf %03d "$keyframe").png" "$work/ours.png"
for panel in ours three studio albedo; do
    convert "$work/$panel.png" -crop "$crop" +repage "$work/$panel-cropped.png"
done
# Left to right, unlabelled (no fonts needed): anthesis render, three.js,
# Blender with studio light, Blender's unlit base colour.
montage -background white -geometry +2+2 -tile 4x1 "$work/ours-cropped.png" \
    "$work/three-cropped.png" "$work/studio-cropped.png" "$work/albedo-cropped.png" "$out"
echo "wrote $out"

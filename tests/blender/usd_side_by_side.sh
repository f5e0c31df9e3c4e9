#!/usr/bin/env bash
# The README's USD picture: one keyframe of a built-in flower as
# `anthesis render` draws it and as Blender imports its USD layer
# (UsdPreviewSurface with the colour maps as UsdUVTexture images at `st`)
# and draws it with Workbench (studio light, then the unlit base colour),
# all seen by anthesis render's camera. Top row: the whole flower; bottom
# row: the same pictures where the lily's crimson spots are, enlarged, to
# compare their shape.
#
#   bash tests/blender/usd_side_by_side.sh ANTHESIS OUT.png [FLOWER] [KEYFRAME]
#
# ANTHESIS is the binary (target/release/anthesis); FLOWER defaults to
# lily, KEYFRAME to 100. Needs tests/blender/.venv (what .ci/run installs)
# and ImageMagick.
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
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

width=1280
height=960
background=a7b1bb
"$anthesis" simulate "builtin:$flower" --out "$work/flower.usdc"
mkdir "$work/anthesis" "$work/blender"
"$anthesis" render "builtin:$flower" --frames "$keyframe" --size "${width}x$height" \
    --elevation 35 --background "$background" --out "$work/anthesis"

"$anthesis" info "builtin:$flower" >"$work/info.txt"
/usr/bin/python3 - "$work" "$keyframe" "$width" "$height" <<'PY'
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
# Time code k is Blender's frame k: at 24 frames a second, k / 24 seconds.
json.dump({"file": f"{work}/flower.usdc", "width": width, "height": height, "fps": 24,
           "times": [keyframe / 24], "camera": camera, "looks": ["studio", "albedo"],
           "out": f"{work}/blender"}, open(f"{work}/blender.json", "w"))
PY
"$here/.venv/bin/python" "$here/render.py" "$work/blender.json" >"$work/blender.log" 2>&1 ||
    { cat "$work/blender.log" >&2; exit 1; }

cp "$work/anthesis/frame-$(printf %03d "$keyframe").png" "$work/ours.png"
for look in studio albedo; do
    convert "$work/blender/blender-0-$look.png" -background "#$background" -flatten "$work/$look.png"
done
# Top row: the flower's box (where Blender drew, its background is
# transparent), with a margin; bottom row: the box of the crimson spots in
# anthesis render's picture, with a margin; every tile 400 pixels wide.
box() {
    read -r w h x y < <(sed -E 's/([0-9]+)x([0-9]+)\+([0-9]+)\+([0-9]+)/\1 \2 \3 \4/' <<<"$1")
    m=$2
    echo "$((w + 2 * m))x$((h + 2 * m))+$((x > m ? x - m : 0))+$((y > m ? y - m : 0))"
}
whole=$(box "$(convert "$work/blender/blender-0-albedo.png" -alpha extract -trim -format '%wx%h%X%Y' info:)" 16)
spots=$(box "$(convert "$work/ours.png" -fx 'r > 0.3 && g < 0.45 * r && b < 0.45 * r' -trim -format '%wx%h%X%Y' info:)" 8)
for panel in ours studio albedo; do
    convert "$work/$panel.png" -crop "$whole" +repage -resize 400x "$work/$panel-whole.png"
    convert "$work/$panel.png" -crop "$spots" +repage -resize 400x "$work/$panel-middle.png"
done
# Left to right, unlabelled (no fonts needed): anthesis render, Blender
# with studio light, Blender's unlit base colour.
montage -background white -geometry +2+2 -tile 3x2 \
    "$work/ours-whole.png" "$work/studio-whole.png" "$work/albedo-whole.png" \
    "$work/ours-middle.png" "$work/studio-middle.png" "$work/albedo-middle.png" "$out"
echo "wrote $out"

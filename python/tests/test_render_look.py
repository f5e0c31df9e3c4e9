"""`Result.render` draws what `anthesis render` draws: the painted colour
maps and the parts (stamens, pistil, receptacle), not only each template's
colour."""

import subprocess

import numpy as np
import pytest

import anthesis


def png(path):
    """An RGBA PNG as uint8 [h, w, 4], without Pillow: zlib and the filters."""
    import struct
    import zlib
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, chunks, width, height = 8, b"", 0, 0
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind = data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour = struct.unpack(">IIBB", body[:10])
            assert (depth, colour) == (8, 6), "8-bit RGBA"
        elif kind == b"IDAT":
            chunks += body
        pos += 12 + length
    raw = zlib.decompress(chunks)
    stride = 4 * width
    out = np.zeros((height, stride), dtype=np.int32)
    for y in range(height):
        kind = raw[y * (stride + 1)]
        line = np.frombuffer(raw, dtype=np.uint8, count=stride, offset=y * (stride + 1) + 1).astype(np.int32)
        up = out[y - 1] if y > 0 else np.zeros(stride, dtype=np.int32)
        row = np.zeros(stride, dtype=np.int32)
        for x in range(stride):
            left = row[x - 4] if x >= 4 else 0
            corner = up[x - 4] if x >= 4 else 0
            if kind == 0:
                predicted = 0
            elif kind == 1:
                predicted = left
            elif kind == 2:
                predicted = up[x]
            elif kind == 3:
                predicted = (left + up[x]) // 2
            else:
                p = left + up[x] - corner
                pa, pb, pc = abs(p - left), abs(p - up[x]), abs(p - corner)
                predicted = left if pa <= pb and pa <= pc else (up[x] if pb <= pc else corner)
            row[x] = (line[x] + predicted) & 0xFF
        out[y] = row
    return out.reshape(height, width, 4).astype(np.uint8)


def test_render_shows_the_colour_maps_and_the_parts_as_the_command_line(lily, anthesis_bin, tmp_path):
    result = lily.simulate(keyframes=1)
    try:
        picture = result.render(keyframe=1, width=96, height=72)
    except anthesis.RenderError as error:
        pytest.fail(f"no renderer (CI installs Mesa's lavapipe): {error}")
    subprocess.run([anthesis_bin, "render", "builtin:lily", "--keyframes", "1", "--frames", "1",
                    "--size", "96x72", "--no-cache", "--out", str(tmp_path)],
                   check=True, capture_output=True)
    expected = png(tmp_path / "frame-001.png")
    assert picture.shape == expected.shape
    # The same scene through the same renderer and camera: the same
    # picture, up to a step of rounding here and there.
    difference = np.abs(picture.astype(int) - expected.astype(int))
    assert (difference > 2).mean() < 0.002, f"{(difference > 2).mean():.4f} of the values differ"
    # Before, the tepals were drawn in one template colour and the stamens
    # and pistil left out: the pictures differed over most of the flower.
    assert (picture[..., 3] > 0).sum() > 500

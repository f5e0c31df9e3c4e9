#!/usr/bin/env python3
"""Watches regions of an Xvfb screen for pixel changes, to measure what a
user waits for from the pixels themselves (not from the app's log).

Xvfb started with `-fbdir DIR` keeps its screen in DIR/Xvfb_screen0, an XWD
file the server draws into through a memory map: reading it shows the
screen as it is at that moment, with no round trip through the X server.

    pixel_watch.py FRAMEBUFFER [options] [-- ACTION...]

Each `--watch NAME=X,Y,W,H` region (screen pixels) is compared with its
state when the measurement starts. Time zero is when ACTION (a command
such as `xdotool key End`, run once) has returned: xdotool has sent the
event by then, and the time it took to start (`action_ms`, tens of
milliseconds on a busy machine) is not counted. Or, with
`--zero-on-change NAME`, the first moment region NAME changes (e.g. a
window's first frame); the other regions' baselines are then read at that
moment (once region NAME holds still for a poll, at most 0.1 s later, so
a frame read half-written does not count as a change). For every region
it reports the first change after time zero and
the last change before the screen settled: nothing changed in any watched
region for `--settle` seconds (or `--timeout` passed). One JSON object is
printed on stdout:

    {"action_ms": 4.1, "zero_epoch": 1765100000.1234, "timed_out": false,
     "regions": {"viewport": {"first_ms": 61.3, "last_ms": 1830.0,
                              "changes": 12}, ...}}

`zero_epoch` is time zero in seconds since 1970 (to line the
measurement up with a log). `first_ms`/`last_ms` are null for a region that did not change. Times are
from time zero, in milliseconds, at a resolution of the polling period
(`--poll-ms`, default 4) plus the time one poll takes (printed as
`poll_ms`). Every `--rows`-th row of a region is compared (default 2), so
a change of a single row can be missed: watch small regions with
`--rows 1`.

`pixel_watch.py FRAMEBUFFER --snapshot OUT.ppm` writes the screen as a
binary PPM (for `convert` or a viewer) and exits.

Standard library only.
"""

import argparse
import json
import mmap
import struct
import subprocess
import sys
import time


class Screen:
    """The XWD file Xvfb keeps its screen in, memory-mapped."""

    def __init__(self, path):
        self.file = open(path, "rb")
        self.map = mmap.mmap(self.file.fileno(), 0, access=mmap.ACCESS_READ)
        header = self.map[:100]
        fields = struct.unpack(">25I", header)
        if fields[1] != 7:  # file_version: Xvfb writes the header big-endian
            fields = struct.unpack("<25I", header)
        if fields[1] != 7:
            raise SystemExit(f"{path}: not an XWD version 7 file")
        header_size = fields[0]
        self.width, self.height = fields[4], fields[5]
        self.pixel_byte_order = fields[7]  # 0: LSBFirst
        self.bits_per_pixel = fields[11]
        self.bytes_per_line = fields[12]
        masks = fields[14:17]
        ncolors = fields[19]
        if self.bits_per_pixel != 32:
            raise SystemExit(
                f"{path}: {self.bits_per_pixel} bits per pixel; start Xvfb with a "
                "depth-24 screen (-screen 0 WxHx24)"
            )
        self.masks = masks
        self.offset = header_size + 12 * ncolors

    def region(self, x, y, w, h, every):
        """The bytes of every `every`-th row of the region, concatenated."""
        x = max(0, min(x, self.width))
        w = max(0, min(w, self.width - x))
        y = max(0, min(y, self.height))
        h = max(0, min(h, self.height - y))
        start = self.offset + 4 * x
        length = 4 * w
        line = self.bytes_per_line
        m = self.map
        return b"".join(
            m[start + row * line : start + row * line + length]
            for row in range(y, y + h, every)
        )

    def snapshot(self, out):
        """Writes the whole screen as a binary PPM."""
        shifts = [(mask & -mask).bit_length() - 1 for mask in self.masks]
        if self.pixel_byte_order != 0:
            raise SystemExit("big-endian pixels are not supported")
        rows = []
        for y in range(self.height):
            start = self.offset + y * self.bytes_per_line
            raw = self.map[start : start + 4 * self.width]
            pixels = struct.unpack(f"<{self.width}I", raw)
            row = bytearray(3 * self.width)
            for i, p in enumerate(pixels):
                row[3 * i] = (p >> shifts[0]) & 0xFF
                row[3 * i + 1] = (p >> shifts[1]) & 0xFF
                row[3 * i + 2] = (p >> shifts[2]) & 0xFF
            rows.append(bytes(row))
        with open(out, "wb") as f:
            f.write(f"P6\n{self.width} {self.height}\n255\n".encode())
            f.writelines(rows)


def region_arg(text):
    name, _, numbers = text.partition("=")
    try:
        x, y, w, h = (int(n) for n in numbers.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: expected NAME=X,Y,W,H")
    if not name or w <= 0 or h <= 0:
        raise argparse.ArgumentTypeError(f"{text!r}: expected NAME=X,Y,W,H")
    return name, (x, y, w, h)


def main():
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("framebuffer", help="DIR/Xvfb_screen0 of Xvfb -fbdir DIR")
    parser.add_argument("--watch", type=region_arg, action="append", default=[])
    parser.add_argument("--zero-on-change", metavar="NAME")
    parser.add_argument("--settle", type=float, default=3.0, metavar="SECONDS")
    parser.add_argument("--timeout", type=float, default=120.0, metavar="SECONDS")
    parser.add_argument("--poll-ms", type=float, default=4.0)
    parser.add_argument("--rows", type=int, default=2, help="compare every N-th row")
    parser.add_argument("--snapshot", metavar="OUT.ppm")
    argv = sys.argv[1:]
    action = argv[argv.index("--") + 1 :] if "--" in argv else []
    args = parser.parse_args(argv[: len(argv) - len(action) - (1 if action else 0)])

    screen = Screen(args.framebuffer)
    if args.snapshot:
        screen.snapshot(args.snapshot)
        return
    regions = dict(args.watch)
    if not regions:
        parser.error("nothing to watch: give --watch NAME=X,Y,W,H")
    if args.zero_on_change and args.zero_on_change not in regions:
        parser.error(f"--zero-on-change {args.zero_on_change}: no such region")
    every = max(1, args.rows)
    read = {name: (lambda r=r: screen.region(*r, every)) for name, r in regions.items()}
    period = args.poll_ms / 1000.0
    clock = time.monotonic

    previous = {name: get() for name, get in read.items()}
    action_ms = None
    if args.zero_on_change:
        name = args.zero_on_change
        deadline = clock() + args.timeout
        while True:
            now = clock()
            current = read[name]()
            if current != previous[name]:
                zero = now
                zero_epoch = time.time() - (clock() - now)
                break
            if now > deadline:
                print(json.dumps({"timed_out": True, "regions": {}}))
                return
            time.sleep(period)
        # The first frame may have been read while the server was still
        # writing it: take the baselines once the screen holds still for a
        # poll (a frame takes far longer than that to draw).
        settle_until = clock() + 0.1
        current = read[name]()
        while clock() < settle_until:
            time.sleep(period)
            again = read[name]()
            if again == current:
                break
            current = again
        previous = {name: get() for name, get in read.items()}
    else:
        started = clock()
        if action:
            subprocess.run(action, check=True)
        zero = clock()
        zero_epoch = time.time()
        action_ms = (zero - started) * 1000.0

    first = dict.fromkeys(regions)
    last = dict.fromkeys(regions)
    changes = dict.fromkeys(regions, 0)
    last_any = zero
    polls = 0
    poll_seconds = 0.0
    timed_out = False
    while True:
        before = clock()
        for name, get in read.items():
            current = get()
            if current != previous[name]:
                previous[name] = current
                changes[name] += 1
                if first[name] is None:
                    first[name] = before
                last[name] = before
                last_any = before
        after = clock()
        polls += 1
        poll_seconds += after - before
        if after - last_any >= args.settle:
            break
        if after - zero >= args.timeout:
            timed_out = True
            break
        time.sleep(max(0.0, period - (after - before)))

    def ms(t):
        return None if t is None else round((t - zero) * 1000.0, 1)

    print(
        json.dumps(
            {
                "action_ms": None if action_ms is None else round(action_ms, 1),
                "zero_epoch": round(zero_epoch, 4),
                "poll_ms": round(poll_seconds / max(polls, 1) * 1000.0, 2),
                "timed_out": timed_out,
                "regions": {
                    name: {
                        "first_ms": ms(first[name]),
                        "last_ms": ms(last[name]),
                        "changes": changes[name],
                    }
                    for name in regions
                },
            }
        )
    )


if __name__ == "__main__":
    sys.exit(main())

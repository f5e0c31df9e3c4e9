"""The edge-growth lily (`builtin:lily-edge`, issue 41 item 4) does what
Liang and Mahadevan (PNAS 2011) report of the lily: its tepals grow only in
their plane, more at the margins than along the midrib, and the bud opens,
each tepal turning from a cup (Gaussian curvature K > 0) into a saddle
(K < 0); with the midrib no stiffer than the lamina it still opens; and
the margins ripple, with amplitude a, wavelength w and arc length L
following a = c·√(w(L − w)) (Portet, Holmes and Keller, Biophys. J. 2022).
The ripple measurement of docs/python/lily_edge.py is checked on a margin of
known ripples. The full measurement (finer meshes) is the
documented command of the README's "Edge growth" section; this is its
quick check at the built-in's resolution (two runs of the whole flower,
about 10 to 30 s each in release)."""

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest

import anthesis

SCRIPT = Path(__file__).resolve().parents[2] / "docs" / "python" / "lily_edge.py"


@pytest.fixture(scope="module")
def edge():
    """docs/python/lily_edge.py as a module (its measurements)."""
    spec = importlib.util.spec_from_file_location("lily_edge", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    sys.modules["lily_edge"] = module
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def runs(edge):
    """Every tenth keyframe of the built-in and of its soft-midrib variant,
    at the built-in's resolution (at the paper's coarser edge, 1.3, the
    tepals open only to about 54 degrees instead of 84: not converged)."""
    return {soft: edge.frames_from_run(None, soft, None) for soft in (False, True)}


def test_the_tepals_grow_in_their_plane_and_more_at_the_margins():
    project = anthesis.load("builtin:lily-edge")
    for template in project.templates:
        assert project.map_keys(template) == [0]
        for along, inner in (("e_growth", "e_growth_in"), ("w_growth", "w_growth_in")):
            np.testing.assert_array_equal(project.get_map(template, along),
                                          project.get_map(template, inner))
        e = project.get_map(template, "e_growth")
        u, v = project.map_grid(template, "e_growth")
        row = np.argmin(np.abs(v[:, 0] - 0.6))
        midrib = e[row, np.argmin(np.abs(u[row] - 0.5))]
        margin = e[row, np.argmin(np.abs(u[row] - 0.0))]
        dg = project.get_parameter("dg", template=template)
        ratio = ((1 + dg * margin) / (1 + dg * midrib)) ** 100
        # 1.40 at the margin itself; the outermost pixel's centre lies half a
        # pixel (1/128 in u) inside it, where the profile (half s², half a
        # narrow layer s^16) gives 1.340.
        assert 1.335 < ratio < 1.345, ratio


def test_the_bud_opens_from_cup_to_saddle_and_the_margins_outgrow_the_midrib(edge, runs):
    frames = runs[False]
    first, last = min(frames), max(frames)
    assert last == 100
    for organ in frames[last]:
        bud = edge.organ_summary(*frames[first][organ])
        open_ = edge.organ_summary(*frames[last][organ])
        # A cup in the bud, a saddle when open (median over the interior).
        assert bud["median_gaussian"] > 0, (organ, bud)
        assert open_["median_gaussian"] < 0, (organ, open_)
        # Open: the tip turns out from the axis by more than 60 degrees (about
        # 70 for the petals, 91 for the sepals, from about -2 in the bud).
        assert open_["tip_angle_deg"] - bud["tip_angle_deg"] > 60.0, (organ, bud, open_)
        # The margin lengthens more than the midrib: the maps ask for up to
        # 1.40 times; the shape takes about 1.29 (petals) and 1.28 (sepals)
        # along the margin's zigzag-free chain.
        margin = open_["margin"] / bud["margin"]
        midrib = open_["midrib"] / bud["midrib"]
        assert margin / midrib > 1.1, (organ, margin, midrib)


def test_with_the_midrib_no_stiffer_than_the_lamina_it_still_opens(edge, runs):
    frames = runs[True]
    first, last = min(frames), max(frames)
    for organ in frames[last]:
        bud = edge.organ_summary(*frames[first][organ])
        open_ = edge.organ_summary(*frames[last][organ])
        assert open_["tip_angle_deg"] - bud["tip_angle_deg"] > 60.0, (organ, bud, open_)
        assert open_["median_gaussian"] < 0, (organ, open_)


def margin_ripples(edge, frames):
    """The ripples of every margin at the last keyframe, by organ and side."""
    last = max(frames)
    return {(organ, side): edge.ripples(*frames[last][organ], side)
            for organ in frames[last] for side in (0, 1)}


@pytest.mark.parametrize("soft", [False, True])
def test_the_margins_ripple_and_follow_the_scaling(edge, runs, soft):
    found = margin_ripples(edge, runs[soft])
    for key, ripples in found.items():
        # Measured: three on every petal margin, four on every sepal margin
        # (both variants); the bud had none (a smooth cup).
        assert len(ripples) >= 3, (key, ripples)
        # Each ripple several mesh edges long (the built-in's mean edge is
        # 0.59): measured 2.1 to 14.2 units, mean 9.0.
        for r in ripples:
            assert 1.5 < r["w"] < 20.0, (key, r)
    for key, ripples in margin_ripples(edge, {0: runs[soft][0]}).items():
        assert ripples == [], (key, ripples)
    fit = edge.ripple_fit([r for rs in found.values() for r in rs])
    # a = c·√(w(L − w)) over every ripple found: measured c = 0.128 (0.127
    # soft), the value of the finer meshes (0.124 at edge 0.39, 0.126 at
    # 0.31; README, "Edge growth"), correlation 0.96 (0.53 soft), misfit
    # 0.19 (0.40 soft). Tolerance: c within 35 % of 0.125, and for the
    # built-in a strong correlation and a misfit under 0.3; the soft
    # midrib's short sepal ripples (w about 2) fit worse.
    assert 0.08 < fit["c"] < 0.17, fit
    if soft:
        assert fit["r"] > 0.4, fit
        assert fit["misfit"] < 0.5, fit
    else:
        assert fit["r"] > 0.8, fit
        assert fit["misfit"] < 0.3, fit


def rippled_strip(amplitude: float, wavelength: float, waves: int, width: float = 4.0,
                  step: float = 0.1):
    """A flat strip along x whose margin y = width ripples out of its plane
    as z = amplitude·sin(2πx/w)·(y/width)², meshed in triangles with UVs
    (u across, v along)."""
    length = waves * wavelength
    nx, ny = int(round(length / step)) + 1, int(round(width / step)) + 1
    x, y = np.meshgrid(np.linspace(0, length, nx), np.linspace(-width, width, 2 * ny - 1))
    z = amplitude * np.sin(2 * np.pi * x / wavelength) * (y / width) ** 2
    positions = np.stack([y.ravel(), x.ravel(), z.ravel()], axis=1)
    uvs = np.stack([(y.ravel() + width) / (2 * width), x.ravel() / length], axis=1)
    rows, cols = x.shape
    faces = []
    for i in range(rows - 1):
        for j in range(cols - 1):
            a, b, c, d = i * cols + j, i * cols + j + 1, (i + 1) * cols + j, (i + 1) * cols + j + 1
            faces += [(a, b, d), (a, d, c)]
    return positions, np.array(faces), uvs


def test_the_ripple_measurement_finds_known_ripples(edge):
    # Margins with 8 waves of known amplitude and wavelength: each ripple
    # found has them, and its arc length is a sinusoid's, so a follows
    # a = √(w(L − w))/π.
    for amplitude, wavelength in ((0.3, 4.0), (0.6, 5.0), (0.15, 3.0)):
        positions, faces, uvs = rippled_strip(amplitude, wavelength, 8)
        for side in (0, 1):
            found = edge.ripples(positions, faces, uvs, side)
            assert len(found) >= 4, found
            for r in found:
                assert r["w"] == pytest.approx(wavelength, rel=0.1), r
                assert r["a"] == pytest.approx(amplitude, rel=0.1), r
        fit = edge.ripple_fit(found)
        assert fit["c"] == pytest.approx(1 / np.pi, rel=0.1), fit
    # A margin without ripples has none.
    positions, faces, uvs = rippled_strip(0.0, 4.0, 8)
    assert edge.ripples(positions, faces, uvs, 0) == []

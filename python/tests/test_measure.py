"""The measurements' discrete curvature checked on surfaces with known
curvature, and the lengths on shapes with known lengths."""

import numpy as np
import pytest

from anthesis.measure import angle_defects_and_areas, margin_length, midrib_length, organ_measures, vertex_curvatures


def icosphere(radius: float, levels: int):
    t = (1 + 5 ** 0.5) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
         (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
         (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    points = [np.array(p, float) / np.linalg.norm(p) for p in v]
    for _ in range(levels):
        middle = {}

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in middle:
                p = points[a] + points[b]
                points.append(p / np.linalg.norm(p))
                middle[key] = len(points) - 1
            return middle[key]

        f = [t for a, b, c in f for t in
             ((a, mid(a, b), mid(c, a)), (b, mid(b, c), mid(a, b)),
              (c, mid(c, a), mid(b, c)), (mid(a, b), mid(b, c), mid(c, a)))]
    return radius * np.array(points), np.array(f)


def grid(nx: int, ny: int):
    """A triangulated grid over [0, 1]^2: uvs [n, 2] and faces [m, 3]."""
    u, v = np.meshgrid(np.linspace(0, 1, nx), np.linspace(0, 1, ny))
    uv = np.stack([u.ravel(), v.ravel()], axis=1)
    faces = []
    for j in range(ny - 1):
        for i in range(nx - 1):
            a, b, c, d = j * nx + i, j * nx + i + 1, (j + 1) * nx + i, (j + 1) * nx + i + 1
            faces += [(a, b, d), (a, d, c)]
    return uv, np.array(faces)


def test_a_sphere_has_h_one_over_r_and_k_one_over_r_squared():
    radius = 2.0
    x, f = icosphere(radius, 4)
    # The faces wind counter-clockwise seen from outside.
    n = np.cross(x[f[:, 1]] - x[f[:, 0]], x[f[:, 2]] - x[f[:, 0]])
    assert (np.einsum("ij,ij->i", n, x[f[:, 0]]) > 0).all()
    h, k = vertex_curvatures(x, f)
    assert np.allclose(h, 1 / radius, rtol=0.02)
    assert np.allclose(k, 1 / radius ** 2, rtol=0.05)
    # Reversed winding flips the sign of H only.
    h2, k2 = vertex_curvatures(x, f[:, ::-1])
    assert np.allclose(h2, -h) and np.allclose(k2, k)


def test_the_angle_defects_of_a_closed_surface_sum_to_4_pi():
    # Descartes: exact on any closed genus-0 mesh, however coarse or bumpy;
    # and the mixed areas tile the surface.
    x, f = icosphere(1.0, 2)
    x = x * (1 + 0.2 * np.sin(5 * x[:, :1]))
    defect, area = angle_defects_and_areas(x, f)
    assert defect.sum() == pytest.approx(4 * np.pi, abs=1e-9)
    total = 0.5 * np.linalg.norm(np.cross(x[f[:, 1]] - x[f[:, 0]], x[f[:, 2]] - x[f[:, 0]]),
                                 axis=1).sum()
    assert area.sum() == pytest.approx(total, rel=1e-12)


def test_a_saddle_has_negative_k_and_zero_h_at_its_centre():
    a = 0.5
    uv, f = grid(41, 41)
    xy = 2 * uv - 1
    x = np.column_stack([xy, a * (xy[:, 0] ** 2 - xy[:, 1] ** 2)])
    h, k = vertex_curvatures(x, f)
    centre = np.argmin(np.linalg.norm(xy, axis=1))
    assert k[centre] == pytest.approx(-4 * a * a, rel=0.03)
    assert abs(h[centre]) < 1e-9
    # A cup z = a (x^2 + y^2): K = 4 a^2 and H = 2 a at the centre (normal up).
    cup = np.column_stack([xy, a * (xy[:, 0] ** 2 + xy[:, 1] ** 2)])
    h, k = vertex_curvatures(cup, f)
    assert k[centre] == pytest.approx(4 * a * a, rel=0.03)
    # The normal is up (+z), on the cup's concave side: H < 0.
    assert h[centre] == pytest.approx(-2 * a, rel=0.03)
    assert np.isnan(k[0]) and np.isnan(h[0])


def test_midrib_and_margin_of_a_flat_and_a_rolled_petal():
    width, length = 0.6, 2.0
    uv, f = grid(13, 41)
    flat = np.column_stack([uv[:, 0] * width, uv[:, 1] * length, np.zeros(len(uv))])
    assert midrib_length(flat, f, uv) == pytest.approx(length, rel=1e-12)
    # The outline above the base (v > 0.05): two sides and the tip.
    assert margin_length(flat, f, uv) == pytest.approx(2 * 0.95 * length + width, rel=1e-12)
    assert margin_length(flat, f, uv, base_v=0.0) == pytest.approx(2 * length + width, rel=1e-12)
    # Bent along its length into a quarter circle of radius R: the midrib
    # is the arc (a chord polygon of it), the margin two arcs and the tip.
    radius = length / (np.pi / 2)
    angle = uv[:, 1] * np.pi / 2
    rolled = np.column_stack([uv[:, 0] * width, radius * np.sin(angle),
                              radius * (1 - np.cos(angle))])
    assert midrib_length(rolled, f, uv) == pytest.approx(length, rel=1e-3)
    chord = 2 * radius * np.sin(np.pi / 4 / 40) * 38  # the 38 chords above v = 0.05
    assert margin_length(rolled, f, uv) == pytest.approx(2 * chord + width, rel=1e-12)


def test_measures_of_a_run(five_petal):
    result = five_petal.simulate(keyframes=3, organ="petal-1")
    m = organ_measures(result, "petal-1")
    assert m["gaussian_curvature"].shape == (4, 121)
    assert m["midrib_length"].shape == (4,)
    positions, faces, uvs = five_petal.mesh("petal")
    # The bud's midrib and margin, measured on the template mesh (placing it
    # on the receptacle moves it rigidly).
    assert m["midrib_length"][0] == pytest.approx(midrib_length(positions, faces, uvs), rel=1e-9)
    assert m["margin_length"][0] == pytest.approx(margin_length(positions, faces, uvs), rel=1e-9)
    # The petal grows: its midrib lengthens.
    assert m["midrib_length"][-1] > m["midrib_length"][0]


"""The measurements' discrete curvature checked on surfaces with known
curvature, and the lengths on shapes with known lengths."""

import numpy as np
import pytest

from anthesis.measure import angle_defects_and_areas, margin_length, principal_stretches, midrib_length, organ_measures, vertex_curvatures


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


def test_principal_stretches_of_known_deformations():
    uv, f = grid(5, 7)
    sheet = np.column_stack([uv, np.zeros(len(uv))])
    # Stretched 1.4 along v and 0.9 along u, then turned and moved: every
    # triangle has stretches (1.4, 0.9).
    stretched = np.column_stack([0.9 * uv[:, 0], 1.4 * uv[:, 1], np.zeros(len(uv))])
    angle = 0.7
    turn = np.array([[1, 0, 0], [0, np.cos(angle), -np.sin(angle)], [0, np.sin(angle), np.cos(angle)]])
    moved = stretched @ turn.T + [3.0, -1.0, 2.0]
    s = principal_stretches(sheet, moved, f)
    assert s.shape == (len(f), 2)
    np.testing.assert_allclose(s, np.tile([1.4, 0.9], (len(f), 1)), rtol=1e-12)
    # A simple shear x += k y: stretches sqrt(1 + k^2/4) +- k/2.
    k = 0.5
    sheared = np.column_stack([uv[:, 0] + k * uv[:, 1], uv[:, 1], np.zeros(len(uv))])
    s = principal_stretches(sheet, sheared, f)
    root = np.sqrt(1 + k * k / 4)
    np.testing.assert_allclose(s, np.tile([root + k / 2, root - k / 2], (len(f), 1)), rtol=1e-12)
    # Rolled up without stretching: a cylinder's developable bend keeps 1.
    radius = 0.5
    rolled = np.column_stack([radius * np.sin(uv[:, 0] / radius), uv[:, 1],
                              radius * (1 - np.cos(uv[:, 0] / radius))])
    s = principal_stretches(sheet, rolled, f)
    assert np.abs(s - 1).max() < 0.02  # chords of the arc: a little shorter


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
    # The petal grows: its midrib lengthens, its triangles stretch.
    assert m["midrib_length"][-1] > m["midrib_length"][0]
    np.testing.assert_allclose(m["principal_stretches"][0], 1.0, rtol=1e-9)
    assert m["principal_stretches"][-1].shape == (200, 2)
    assert m["principal_stretches"][-1, :, 0].max() > 1.0


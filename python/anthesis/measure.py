"""Measurements of simulated organs (issue 41 item 3, from Python).

Discrete differential geometry on the triangle meshes of a run, numpy only:

- :func:`vertex_curvatures`: mean curvature H and Gaussian curvature K per
  vertex. K is the angle defect over the mixed Voronoi area, H half the
  length of the cotangent Laplacian of the positions (the mean-curvature
  normal), signed along the vertex normal (Meyer, Desbrun, Schröder and
  Barr, "Discrete differential-geometry operators for triangulated
  2-manifolds", 2003). On a sphere of radius R whose triangles wind
  counter-clockwise seen from outside, H = 1/R and K = 1/R². Units: 1/length
  and 1/length² in the project's units. Vertices on the boundary get NaN
  (their angle defect is the boundary's geodesic curvature, not K).
- :func:`midrib_length`: the length of the curve u = 0.5 from the base
  (v = 0) to the tip (v = 1), traced through the UV layout.
- :func:`margin_length`: the length of the organ's outline without its base
  (boundary edges with an end above ``base_v``).
- :func:`principal_stretches`: per triangle, the principal stretches of the
  deformation from the bud (the singular values of the map from the bud
  triangle to the current one; 1 = unchanged, 1.4 = 40 % longer), largest
  first.
- :func:`organ_measures`: all of them for every keyframe of a run, with
  the contact area (the mixed Voronoi area of the organ's vertices within
  twice the collision offset of another organ or a part) and the summaries
  ``anthesis measure`` writes.

The computations are the engine's (``anthesis_sim::measure`` in Rust, the
code behind ``anthesis measure`` and the window's Measure panel), called
through the compiled module; this module keeps the numpy interface.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from . import _anthesis

__all__ = ["vertex_curvatures", "angle_defects_and_areas", "principal_stretches", "midrib_length", "margin_length", "organ_measures"]


def _points(x: Any) -> np.ndarray:
    return np.ascontiguousarray(x, dtype=np.float64)


def _faces(f: Any) -> np.ndarray:
    return np.ascontiguousarray(f, dtype=np.int64)


def _check(x: np.ndarray, f: np.ndarray) -> None:
    if x.ndim != 2 or x.shape[1] != 3 or f.ndim != 2 or f.shape[1] != 3:
        raise ValueError(f"positions must be [n, 3] and faces [m, 3], got {x.shape} and {f.shape}")


def boundary_vertices(faces: np.ndarray, n: int) -> np.ndarray:
    """Boolean [n]: whether a vertex lies on an edge used by one triangle."""
    return _anthesis.measure_boundary(_faces(faces), n)


def vertex_curvatures(positions: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean and Gaussian curvature per vertex: (H [n], K [n]), NaN on the
    boundary. ``positions`` float [n, 3], ``faces`` int [m, 3]. H > 0 where
    the surface bends away from its normal (a sphere with outward normals),
    H < 0 where it bends towards it."""
    x, f = _points(positions), _faces(faces)
    _check(x, f)
    return _anthesis.measure_curvatures(x, f)


def angle_defects_and_areas(positions: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per vertex: the angle defect 2π − Σθ (radians) and the mixed Voronoi
    area (project units²); K = defect / area at interior vertices."""
    x, f = _points(positions), _faces(faces)
    _check(x, f)
    return _anthesis.measure_angle_defects(x, f)


def principal_stretches(rest: np.ndarray, current: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Principal stretches per triangle from `rest` to `current` positions
    ([n, 3] each): float [m, 2], largest first. Rigid motions leave them at
    1; they are the square roots of the eigenvalues of the right
    Cauchy-Green tensor of the in-plane deformation."""
    x0, x1, f = _points(rest), _points(current), _faces(faces)
    _check(x0, f)
    _check(x1, f)
    return _anthesis.measure_stretches(x0, x1, f)


def midrib_length(positions: np.ndarray, faces: np.ndarray, uvs: np.ndarray,
                  samples: int = 400) -> float:
    """Length of the midrib: the curve u = 0.5 from v = 0 to v = 1, traced
    through the UV layout at `samples` points (project units)."""
    x, f = _points(positions), _faces(faces)
    _check(x, f)
    return _anthesis.measure_midrib(x, f, _points(uvs), samples)


def margin_length(positions: np.ndarray, faces: np.ndarray, uvs: np.ndarray,
                  base_v: float = 0.05) -> float:
    """Length of the outline without the base: boundary edges with at least
    one end at v > base_v (project units)."""
    x, f = _points(positions), _faces(faces)
    _check(x, f)
    return _anthesis.measure_margin(x, f, _points(uvs), base_v)


def organ_measures(result: Any, organ: str | int, base_v: float = 0.05) -> dict[str, np.ndarray]:
    """Per keyframe of `result` (an ``anthesis.Result``) for one organ:
    ``mean_curvature`` and ``gaussian_curvature`` [k + 1, n] (NaN on the
    boundary), the median of the Gaussian curvature over the interior
    vertices ``median_gaussian`` [k + 1], ``midrib_length`` and
    ``margin_length`` [k + 1], and ``principal_stretches`` [k + 1, m, 2]
    against the bud (keyframe 0).

    Also, as ``Result.measures`` gives them: ``contact`` (bool [k + 1, n]:
    the vertices within twice the collision offset of another organ or a
    part), ``contact_area`` (their mixed Voronoi area),
    ``contact_area``, ``area``, ``mean_curvature_median``,
    ``mean_curvature_mean`` and ``gaussian_curvature_mean`` (means weighted
    by the vertices' areas), ``gaussian_curvature_median``,
    ``stretch_major_mean``, ``stretch_minor_mean`` [k + 1] (the columns of
    ``anthesis measure``, here in project units), and per vertex
    ``vertex_stretches`` [k + 1, n, 2]."""
    return dict(result.measures(organ, base_v=base_v))

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
- :func:`organ_measures`: all of them for every keyframe of a run.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["vertex_curvatures", "angle_defects_and_areas", "principal_stretches", "midrib_length", "margin_length", "organ_measures"]


def _cot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cotangent of the angle between vectors a and b (rows)."""
    cross = np.linalg.norm(np.cross(a, b), axis=1)
    return np.einsum("ij,ij->i", a, b) / np.maximum(cross, 1e-300)


def boundary_vertices(faces: np.ndarray, n: int) -> np.ndarray:
    """Boolean [n]: whether a vertex lies on an edge used by one triangle."""
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    unique, counts = np.unique(edges, axis=0, return_counts=True)
    on_boundary = np.zeros(n, dtype=bool)
    on_boundary[unique[counts == 1].ravel()] = True
    return on_boundary


def vertex_curvatures(positions: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean and Gaussian curvature per vertex: (H [n], K [n]), NaN on the
    boundary. ``positions`` float [n, 3], ``faces`` int [m, 3]. H > 0 where
    the surface bends away from its normal (a sphere with outward normals),
    H < 0 where it bends towards it."""
    x = np.asarray(positions, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    angle_sum, area, laplacian, normal = _parts(x, f)
    boundary = boundary_vertices(f, len(x))
    with np.errstate(divide="ignore", invalid="ignore"):
        gaussian = (2.0 * np.pi - angle_sum) / area
        mean_normal = laplacian / (2.0 * area[:, None])
        unit = normal / np.linalg.norm(normal, axis=1, keepdims=True)
        mean = 0.5 * np.einsum("ij,ij->i", mean_normal, unit)
    gaussian[boundary] = np.nan
    mean[boundary] = np.nan
    return mean, gaussian


def angle_defects_and_areas(positions: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per vertex: the angle defect 2π − Σθ (radians) and the mixed Voronoi
    area (project units²); K = defect / area at interior vertices."""
    x = np.asarray(positions, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    angle_sum, area, _, _ = _parts(x, f)
    return 2.0 * np.pi - angle_sum, area


def _parts(x: np.ndarray, f: np.ndarray):
    """Angle sums, mixed areas, cotangent Laplacian and area-weighted normals."""
    n = len(x)
    if x.ndim != 2 or x.shape[1] != 3 or f.ndim != 2 or f.shape[1] != 3:
        raise ValueError(f"positions must be [n, 3] and faces [m, 3], got {x.shape} and {f.shape}")
    angle_sum = np.zeros(n)
    area = np.zeros(n)
    laplacian = np.zeros((n, 3))
    normal = np.zeros((n, 3))
    p = [x[f[:, k]] for k in range(3)]
    face_normal = np.cross(p[1] - p[0], p[2] - p[0])  # length 2 * area
    face_area = 0.5 * np.linalg.norm(face_normal, axis=1)
    cots = []
    angles = []
    for k in range(3):
        a, b, c = p[k], p[(k + 1) % 3], p[(k + 2) % 3]
        u, v = b - a, c - a
        cos = np.einsum("ij,ij->i", u, v) / np.maximum(
            np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1), 1e-300)
        angles.append(np.arccos(np.clip(cos, -1.0, 1.0)))
        cots.append(_cot(u, v))
    obtuse = np.stack(angles, axis=1) > np.pi / 2
    any_obtuse = obtuse.any(axis=1)
    for k in range(3):
        i, j, l = f[:, k], f[:, (k + 1) % 3], f[:, (k + 2) % 3]
        np.add.at(angle_sum, i, angles[k])
        np.add.at(normal, i, face_normal)
        # Edge (j, l) is opposite vertex k: weight cot(angle at k).
        w = cots[k][:, None] * (x[j] - x[l])
        np.add.at(laplacian, j, w)
        np.add.at(laplacian, l, -w)
        # Mixed area: Voronoi in non-obtuse triangles, else a half or a quarter.
        e_ij = np.einsum("ij,ij->i", x[j] - x[i], x[j] - x[i])
        e_il = np.einsum("ij,ij->i", x[l] - x[i], x[l] - x[i])
        voronoi = (e_ij * cots[(k + 2) % 3] + e_il * cots[(k + 1) % 3]) / 8.0
        share = np.where(~any_obtuse, voronoi,
                         np.where(obtuse[:, k], face_area / 2.0, face_area / 4.0))
        np.add.at(area, i, share)
    return angle_sum, area, laplacian, normal


def principal_stretches(rest: np.ndarray, current: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Principal stretches per triangle from `rest` to `current` positions
    ([n, 3] each): float [m, 2], largest first. Rigid motions leave them at
    1; they are the square roots of the eigenvalues of the right
    Cauchy-Green tensor of the in-plane deformation."""
    x0 = np.asarray(rest, dtype=np.float64)
    x1 = np.asarray(current, dtype=np.float64)
    f = np.asarray(faces, dtype=np.int64)
    e1, e2 = x0[f[:, 1]] - x0[f[:, 0]], x0[f[:, 2]] - x0[f[:, 0]]
    # An orthonormal frame in each rest triangle: the edges in 2D.
    t1 = e1 / np.linalg.norm(e1, axis=1, keepdims=True)
    normal = np.cross(e1, e2)
    t2 = np.cross(normal / np.linalg.norm(normal, axis=1, keepdims=True), t1)
    rest_2d = np.stack([np.stack([np.einsum("ij,ij->i", e, t1), np.einsum("ij,ij->i", e, t2)],
                                 axis=1) for e in (e1, e2)], axis=2)  # [m, 2, 2], columns = edges
    now = np.stack([x1[f[:, 1]] - x1[f[:, 0]], x1[f[:, 2]] - x1[f[:, 0]]], axis=2)  # [m, 3, 2]
    gradient = now @ np.linalg.inv(rest_2d)  # [m, 3, 2]
    return np.linalg.svd(gradient, compute_uv=False)


def _trace_uv(positions: np.ndarray, faces: np.ndarray, uvs: np.ndarray,
              points_uv: np.ndarray) -> np.ndarray:
    """The 3D points at `points_uv` [s, 2] through the UV layout (each in the
    first triangle holding it; points outside every triangle are dropped)."""
    a, b, c = (uvs[faces[:, k]] for k in range(3))
    v0, v1 = b - a, c - a
    det = v0[:, 0] * v1[:, 1] - v0[:, 1] * v1[:, 0]
    out = []
    for q in points_uv:
        d = q - a
        with np.errstate(divide="ignore", invalid="ignore"):
            s = (d[:, 0] * v1[:, 1] - d[:, 1] * v1[:, 0]) / det
            t = (v0[:, 0] * d[:, 1] - v0[:, 1] * d[:, 0]) / det
        inside = np.flatnonzero((s >= -1e-12) & (t >= -1e-12) & (s + t <= 1 + 1e-12))
        if len(inside) == 0:
            continue
        m = inside[0]
        tri = faces[m]
        out.append((1 - s[m] - t[m]) * positions[tri[0]] + s[m] * positions[tri[1]]
                   + t[m] * positions[tri[2]])
    return np.array(out).reshape(-1, 3)


def midrib_length(positions: np.ndarray, faces: np.ndarray, uvs: np.ndarray,
                  samples: int = 400) -> float:
    """Length of the midrib: the curve u = 0.5 from v = 0 to v = 1, traced
    through the UV layout at `samples` points (project units)."""
    v = np.linspace(0.0, 1.0, samples)
    points = _trace_uv(np.asarray(positions, float), np.asarray(faces, np.int64),
                       np.asarray(uvs, float), np.stack([np.full_like(v, 0.5), v], axis=1))
    return float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum())


def margin_length(positions: np.ndarray, faces: np.ndarray, uvs: np.ndarray,
                  base_v: float = 0.05) -> float:
    """Length of the outline without the base: boundary edges with at least
    one end at v > base_v (project units)."""
    f = np.asarray(faces, dtype=np.int64)
    x = np.asarray(positions, dtype=np.float64)
    uv = np.asarray(uvs, dtype=np.float64)
    edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    unique, counts = np.unique(edges, axis=0, return_counts=True)
    rim = unique[counts == 1]
    keep = (uv[rim[:, 0], 1] > base_v) | (uv[rim[:, 1], 1] > base_v)
    rim = rim[keep]
    return float(np.linalg.norm(x[rim[:, 0]] - x[rim[:, 1]], axis=1).sum())


def organ_measures(result: Any, organ: str | int, base_v: float = 0.05) -> dict[str, np.ndarray]:
    """Per keyframe of `result` (an ``anthesis.Result``) for one organ:
    ``mean_curvature`` and ``gaussian_curvature`` [k + 1, n] (NaN on the
    boundary), the median of the Gaussian curvature over the interior
    vertices ``median_gaussian`` [k + 1], ``midrib_length`` and
    ``margin_length`` [k + 1], and ``principal_stretches`` [k + 1, m, 2]
    against the bud (keyframe 0)."""
    positions = result.positions(organ)
    faces = result.faces(organ).astype(np.int64)
    uvs = result.uvs(organ)
    hs, ks, midrib, margin, stretches = [], [], [], [], []
    for frame in positions:
        stretches.append(principal_stretches(positions[0], frame, faces))
        h, k = vertex_curvatures(frame, faces)
        hs.append(h)
        ks.append(k)
        midrib.append(midrib_length(frame, faces, uvs))
        margin.append(margin_length(frame, faces, uvs, base_v))
    ks = np.array(ks)
    return {
        "mean_curvature": np.array(hs),
        "gaussian_curvature": ks,
        "median_gaussian": np.nanmedian(ks, axis=1),
        "midrib_length": np.array(midrib),
        "margin_length": np.array(margin),
        "principal_stretches": np.array(stretches),
    }

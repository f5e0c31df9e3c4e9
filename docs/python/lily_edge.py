"""Measures the edge-growth lily (`builtin:lily-edge`, issue 41 item 4)
against what Liang and Mahadevan ("Growth, geometry, and mechanics of a
blooming lily", PNAS 2011) and Portet, Holmes and Keller (Biophys. J. 2022)
report: the bud opens, the tepals turn from cup (Gaussian curvature K > 0)
to saddle (K < 0), the margins outgrow the midrib, and the ripples along the
margins follow a ∝ √(w(L − w)).

    python docs/python/lily_edge.py [--mean-edge E] [--soft-midrib] [--keyframes N]
    python docs/python/lily_edge.py --objs FOLDER      # OBJs of the lily_edge example

The first form simulates with the anthesis wheel (see docs/python.md); the
second reads the keyframes `cargo run --release -p anthesis-garden
--example lily_edge -- SCALE FOLDER` wrote (k000_organ0.obj, ...), for
resolutions the built-in does not use. The measurements are the functions
below; python/tests/test_lily_edge.py checks them and the coarse run.
"""

from __future__ import annotations

import argparse
import re
import sys
from pathlib import Path

import numpy as np

from anthesis.measure import margin_length, midrib_length, vertex_curvatures


# ---------------------------------------------------------------------------
# Measurements of one organ at one keyframe: positions [n, 3] (world frame,
# flower axis +Y), faces [m, 3], UVs [n, 2] (u across, midrib 0.5; v base 0
# to tip 1).


def _at_uv(positions: np.ndarray, uvs: np.ndarray, uv: tuple[float, float]) -> np.ndarray:
    """The particle nearest `uv` in the UV layout."""
    return positions[np.argmin(np.linalg.norm(uvs - np.asarray(uv), axis=1))]


def tip_angle_deg(positions: np.ndarray, uvs: np.ndarray) -> float:
    """Angle between the flower axis (+Y) and the line from the organ's base
    (u = 0.5, v = 0) to its tip (v = 1), positive when the tip leans away
    from the axis: about 0 in a closed bud, 90 when the tepal lies flat, more
    when it bends back. Degrees."""
    base = _at_uv(positions, uvs, (0.5, 0.0))
    tip = _at_uv(positions, uvs, (0.5, 1.0))
    radial = np.array([base[0], 0.0, base[2]])
    radial /= max(np.linalg.norm(radial), 1e-12)
    d = tip - base
    return float(np.degrees(np.arctan2(d @ radial, d[1])))


def median_gaussian(positions: np.ndarray, faces: np.ndarray, uvs: np.ndarray,
                    v_min: float = 0.15) -> float:
    """Median Gaussian curvature (1/length²) over the interior vertices above
    the claw (v > v_min): the claw does not grow and is held at the base."""
    _, k = vertex_curvatures(positions, faces)
    keep = np.isfinite(k) & (uvs[:, 1] > v_min)
    return float(np.median(k[keep]))


def margin_chain(faces: np.ndarray, uvs: np.ndarray, side: int, v_min: float = 0.1) -> np.ndarray:
    """The boundary vertices of one margin (side 0: u < 0.5, side 1: u > 0.5)
    above v_min, ordered from the base to the tip along the boundary."""
    f = np.asarray(faces, dtype=np.int64)
    edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    unique, counts = np.unique(edges, axis=0, return_counts=True)
    rim = unique[counts == 1]
    neighbours: dict[int, list[int]] = {}
    for a, b in rim:
        neighbours.setdefault(int(a), []).append(int(b))
        neighbours.setdefault(int(b), []).append(int(a))
    on_side = (uvs[:, 0] < 0.5) if side == 0 else (uvs[:, 0] > 0.5)
    # Start at the lowest rim vertex of this side above v_min and walk up.
    candidates = [i for i in neighbours if on_side[i] and uvs[i, 1] > v_min]
    start = min(candidates, key=lambda i: uvs[i, 1])
    chain, previous = [start], -1
    while True:
        here = chain[-1]
        nxt = [j for j in neighbours[here] if j != previous and j not in chain]
        nxt = [j for j in nxt if uvs[j, 1] > uvs[here, 1] - 1e-9 and (on_side[j] or uvs[j, 1] > 0.98)]
        if not nxt:
            break
        previous = here
        chain.append(max(nxt, key=lambda j: uvs[j, 1]))
        if uvs[chain[-1], 1] > 0.97:
            break
    return np.array(chain)


def vertex_normals(positions: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Area-weighted unit vertex normals."""
    f = np.asarray(faces, dtype=np.int64)
    p = [positions[f[:, k]] for k in range(3)]
    fn = np.cross(p[1] - p[0], p[2] - p[0])
    n = np.zeros_like(positions)
    for k in range(3):
        np.add.at(n, f[:, k], fn)
    return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)


def _smooth(values: np.ndarray, s: np.ndarray, sigma: float) -> np.ndarray:
    """Gaussian smoothing of `values` [k, d] over the arc length s [k]
    (weights renormalised at the ends)."""
    w = np.exp(-0.5 * ((s[:, None] - s[None, :]) / sigma) ** 2)
    w /= w.sum(axis=1, keepdims=True)
    return w @ values


def margin_wobble(positions: np.ndarray, faces: np.ndarray, uvs: np.ndarray, side: int,
                  sigma_fraction: float = 0.06):
    """One margin's out-of-surface wobble: the margin's offset from itself
    smoothed over `sigma_fraction` of its length (a Gaussian), along the
    smoothed surface normal. Returns the margin's points [k, 3], their
    smoothed positions [k, 3], the arc length s [k] and the wobble [k]."""
    chain = margin_chain(faces, uvs, side)
    x = positions[chain]
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(x, axis=0), axis=1))])
    sigma = sigma_fraction * s[-1]
    smooth = _smooth(x, s, sigma)
    normals = _smooth(vertex_normals(positions, faces)[chain], s, sigma)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    return x, smooth, s, np.einsum("ij,ij->i", x - smooth, normals)


def ripples(positions: np.ndarray, faces: np.ndarray, uvs: np.ndarray, side: int,
            sigma_fraction: float = 0.06) -> list[dict[str, float]]:
    """The ripples of one margin (see :func:`margin_wobble`): each full wave
    between every other zero crossing of the wobble, away from the ends
    (two smoothing widths), is a ripple: its wavelength w (length of the
    smoothed margin over the wave), its arc length L (length of the margin
    itself over the wave) and its amplitude a (half the wobble's peak to
    peak over the wave). Lengths in project units."""
    x, smooth, s, wobble = margin_wobble(positions, faces, uvs, side, sigma_fraction)
    total = s[-1]
    # Leave out the ends, where the smoothing window is cut off.
    inside = (s > 2 * sigma_fraction * total) & (s < total - 2 * sigma_fraction * total)
    idx = np.flatnonzero(inside)
    if len(idx) < 4:
        return []
    sign = np.sign(wobble[idx])
    crossings = idx[np.flatnonzero(sign[1:] * sign[:-1] < 0)]
    # Arc lengths of the margin and of the smoothed margin at each zero
    # crossing, interpolated between the vertices either side.
    s_smooth = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(smooth, axis=0), axis=1))])

    def at_crossing(i: int, along: np.ndarray) -> float:
        t = wobble[i] / (wobble[i] - wobble[i + 1])
        return float(along[i] + t * (along[i + 1] - along[i]))

    found = []
    for a, b in zip(crossings[:-2:2], crossings[2::2]):
        amplitude = 0.5 * float(wobble[a:b + 2].max() - wobble[a:b + 2].min())
        found.append({
            "w": at_crossing(b, s_smooth) - at_crossing(a, s_smooth),
            "L": at_crossing(b, s) - at_crossing(a, s),
            "a": amplitude,
            "start": float(s[a]),
        })
    return found


def organ_summary(positions: np.ndarray, faces: np.ndarray, uvs: np.ndarray) -> dict[str, float]:
    """Tip angle, median Gaussian curvature, midrib and margin length."""
    return {
        "tip_angle_deg": tip_angle_deg(positions, uvs),
        "median_gaussian": median_gaussian(positions, faces, uvs),
        "midrib": midrib_length(positions, faces, uvs),
        "margin": margin_length(positions, faces, uvs, 0.1),
    }


def ripple_fit(found: list[dict[str, float]]) -> dict[str, float]:
    """Least-squares c of a = c·√(w(L − w)) through the origin over the
    ripples found, with the correlation r of a against √(w(L − w)), the
    relative rms misfit, the spread of the ripples' own c = a/√(w(L − w))
    (c_mean, c_std) and of their wavelengths (w_mean, w_std); a sinusoid
    has c = 1/π ≈ 0.318."""
    a = np.array([r["a"] for r in found])
    x = np.sqrt(np.maximum([r["w"] * (r["L"] - r["w"]) for r in found], 0.0))
    w = np.array([r["w"] for r in found])
    nan = float("nan")
    if len(a) < 2 or not np.any(x > 0):
        return {"ripples": float(len(a)), "c": nan, "r": nan, "misfit": nan,
                "c_mean": nan, "c_std": nan, "w_mean": nan, "w_std": nan}
    c = float(a @ x / (x @ x))
    r = float(np.corrcoef(a, x)[0, 1]) if len(a) > 2 else nan
    misfit = float(np.sqrt(np.mean((a - c * x) ** 2)) / np.mean(a))
    own = a[x > 0] / x[x > 0]
    return {"ripples": float(len(a)), "c": c, "r": r, "misfit": misfit,
            "c_mean": float(own.mean()), "c_std": float(own.std()),
            "w_mean": float(w.mean()), "w_std": float(w.std())}


# ---------------------------------------------------------------------------
# Sources of keyframes.


def read_obj(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Positions, faces and UVs of an OBJ written by anthesis (v/vt/vn)."""
    v, vt, f = [], [], []
    for line in path.read_text().splitlines():
        if line.startswith("v "):
            v.append([float(t) for t in line.split()[1:4]])
        elif line.startswith("vt "):
            vt.append([float(t) for t in line.split()[1:3]])
        elif line.startswith("f "):
            f.append([int(t.split("/")[0]) - 1 for t in line.split()[1:4]])
    return np.array(v), np.array(f, dtype=np.int64), np.array(vt)


def frames_from_objs(folder: Path) -> dict[int, dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]]]:
    """{keyframe: {organ: (positions, faces, uvs)}} from the example's OBJs."""
    out: dict[int, dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]]] = {}
    for path in sorted(folder.glob("k*_organ*.obj")):
        m = re.fullmatch(r"k(\d+)_organ(\d+)\.obj", path.name)
        if m:
            out.setdefault(int(m.group(1)), {})[int(m.group(2))] = read_obj(path)
    return out


def frames_from_run(mean_edge: float | None, soft_midrib: bool, keyframes: int | None,
                    every: int = 10):
    """The same from a run of the anthesis wheel."""
    import anthesis

    project = anthesis.load("builtin:lily-edge")
    if soft_midrib:
        for template in project.templates:
            project.set_map(template, "stretch", np.full_like(project.get_map(template, "stretch"), project.get_map(template, "stretch").min()))
            project.set_map(template, "bend", np.full_like(project.get_map(template, "bend"), project.get_map(template, "bend").min()))
    if mean_edge is not None:
        project.set_parameter("mean_edge", mean_edge)
    result = project.simulate(keyframes=keyframes)
    out: dict[int, dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]]] = {}
    for organ_index, organ in enumerate(result.organs):
        positions = result.positions(organ)
        faces = result.faces(organ).astype(np.int64)
        uvs = result.uvs(organ)
        for k in range(0, len(positions), every):
            out.setdefault(k, {})[organ_index] = (positions[k], faces, uvs)
        last = len(positions) - 1
        out.setdefault(last, {})[organ_index] = (positions[last], faces, uvs)
    return out


def report(frames) -> dict[str, object]:
    """Prints and returns the measurements of every organ over time and the
    ripples of the last keyframe."""
    keys = sorted(frames)
    first, last = keys[0], keys[-1]
    organs = sorted(frames[last])
    print("keyframe  organ  tip_angle_deg  median_K  midrib  margin")
    summary = {}
    for k in keys:
        for o in organs:
            m = organ_summary(*frames[k][o])
            summary[(k, o)] = m
            print(f"{k:8d}  {o:5d}  {m['tip_angle_deg']:13.1f}  {m['median_gaussian']:+.2e}"
                  f"  {m['midrib']:6.2f}  {m['margin']:6.2f}")
    print("\nover the opening (last / bud):")
    for o in organs:
        a, b = summary[(first, o)], summary[(last, o)]
        print(f"organ {o}: tip angle {a['tip_angle_deg']:.1f} -> {b['tip_angle_deg']:.1f} deg,"
              f" midrib x{b['midrib'] / a['midrib']:.3f}, margin x{b['margin'] / a['margin']:.3f}"
              f" (margin/midrib {b['margin'] / a['margin'] / (b['midrib'] / a['midrib']):.3f})")
    found = []
    for o in organs:
        for side in (0, 1):
            rs = ripples(*frames[last][o], side)
            found += rs
            wobble = margin_wobble(*frames[last][o], side)[3]
            print(f"organ {o} margin {side}: wobble rms {np.sqrt(np.mean(wobble ** 2)):.3f},"
                  f" {len(rs)} ripples "
                  + " ".join(f"(w {r['w']:.2f}, L {r['L']:.2f}, a {r['a']:.3f})" for r in rs))
    fit = ripple_fit(found)
    print(f"\nripples found: {int(fit['ripples'])}; a = c sqrt(w (L - w)) with c = {fit['c']:.3f}"
          f" (sinusoid 1/pi = {1 / np.pi:.3f}), correlation r = {fit['r']:.3f},"
          f" relative rms misfit {fit['misfit']:.2f}; each ripple's c {fit['c_mean']:.3f}"
          f" ± {fit['c_std']:.3f}; wavelength w {fit['w_mean']:.2f} ± {fit['w_std']:.2f}")
    return {"summary": summary, "ripples": found, "fit": fit}


def main(argv: list[str]) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--objs", type=Path)
    parser.add_argument("--mean-edge", type=float)
    parser.add_argument("--soft-midrib", action="store_true")
    parser.add_argument("--keyframes", type=int)
    args = parser.parse_args(argv)
    if args.objs:
        frames = frames_from_objs(args.objs)
    else:
        frames = frames_from_run(args.mean_edge, args.soft_midrib, args.keyframes)
    report(frames)


if __name__ == "__main__":
    main(sys.argv[1:])

"""The tutorial of docs/python.md as one script: load the lily, paint a
growth map, simulate a tepal both ways, measure and plot its midrib and
margin over time, export.

    python docs/python/tutorial.py [OUT_FOLDER] [KEYFRAMES]

Needs the anthesis wheel (see docs/python.md); the plot needs matplotlib
and is skipped without it.
"""

import sys
from pathlib import Path

import numpy as np

import anthesis
from anthesis.measure import organ_measures

out = Path(sys.argv[1] if len(sys.argv) > 1 else "lily-out")
keyframes = int(sys.argv[2]) if len(sys.argv) > 2 else 100
out.mkdir(exist_ok=True)

# 1. Load the built-in lily (or a project file: anthesis.load("my.anthesis.toml")).
lily = anthesis.load("builtin:lily")
print(lily)
print("organs:", lily.organs)
print("petal parameters:", lily.parameters(template="petal"))

# 2. Change a map. Maps are arrays on the UV grid in image order: row 0 is
#    the tip of the tepal (v = 1), the last row its base (v = 0); u runs
#    across, from column 0. map_grid gives u and v of every pixel, so a map
#    can be written as a formula. Here the outer layer grows more along the
#    margins (|2u - 1| near 1) than along the midrib (u = 0.5), the
#    hypothesis of Liang and Mahadevan (2011). The lily's maps have two keys
#    in time (steps 40 and 50; before the first key its maps hold): change
#    both.
margins = lily.copy()
for key, step in enumerate(lily.map_keys("petal")):
    u, v = lily.map_grid("petal", "e_growth", key=key)
    before = lily.get_map("petal", "e_growth", key=key)
    margins.set_map("petal", "e_growth", np.clip(before * (0.6 + 0.8 * np.abs(2 * u - 1)), 0, 1),
                    key=key)

# 3. Simulate one tepal alone (no collisions: the neighbours' margins would
#    cross once one tepal grows differently), as built and changed, with a
#    progress line.
def progress(k, total):
    print(f"\rkeyframe {k}/{total}", end="", flush=True)

runs = {}
for name, project in [("as built", lily), ("margins grow more", margins)]:
    runs[name] = project.simulate(keyframes=keyframes, organ="petal-1", progress=progress)
    print(f"  {name}: done")

# 4. Quantities over time (anthesis.measure): the midrib's and the margin's
#    length in the project's length units, and the median Gaussian
#    curvature over the tepal (positive: cup, negative: saddle).
measures = {name: organ_measures(run, "petal-1") for name, run in runs.items()}
for name, m in measures.items():
    print(f"{name}: midrib {m['midrib_length'][0]:.2f} -> {m['midrib_length'][-1]:.2f}, "
          f"margin {m['margin_length'][0]:.2f} -> {m['margin_length'][-1]:.2f}, "
          f"median K {m['median_gaussian'][-1]:+.2e}")

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(8, 3.2))
    for name, m in measures.items():
        axes[0].plot(m["margin_length"] / m["margin_length"][0], label=f"margin, {name}")
        axes[0].plot(m["midrib_length"] / m["midrib_length"][0], "--", label=f"midrib, {name}")
        axes[1].plot(m["median_gaussian"], label=name)
    axes[0].set_xlabel("keyframe")
    axes[0].set_ylabel("length / length in the bud")
    axes[0].legend(fontsize=7)
    axes[1].set_xlabel("keyframe")
    axes[1].set_ylabel("median Gaussian curvature")
    axes[1].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "petal-1.png", dpi=120)
    print("wrote", out / "petal-1.png")
except ImportError:
    print("matplotlib is not installed: no plot (pip install matplotlib)")

# 5. Export the changed run for Blender, three.js or a USD pipeline, and
#    save the changed project (its maps as PNGs beside it).
runs["margins grow more"].export(out / "petal-1.glb")
runs["margins grow more"].export(out / "petal-1.usdc")
(out / "project").mkdir(exist_ok=True)
margins.save(out / "project" / "lily-margins.anthesis.toml")
print("wrote", out / "petal-1.glb", out / "petal-1.usdc", out / "project")

"""The tutorial of docs/python.md as one script: load the lily, paint a
growth map, simulate, plot the opening over time, export.

    python docs/python/tutorial.py [OUT_FOLDER] [KEYFRAMES]

Needs the anthesis wheel (see docs/python.md); the plot needs matplotlib
and is skipped without it.
"""

import sys
from pathlib import Path

import numpy as np

import anthesis

out = Path(sys.argv[1] if len(sys.argv) > 1 else "lily-out")
keyframes = int(sys.argv[2]) if len(sys.argv) > 2 else 100
out.mkdir(exist_ok=True)

# 1. Load the built-in lily (or a project file: anthesis.load("my.anthesis.toml")).
lily = anthesis.load("builtin:lily")
print(lily)
print("organs:", lily.organs)
print("petal parameters:", lily.parameters(template="petal"))

# 2. Change a map. Maps are arrays on the UV grid in image order: row 0 is
#    the tip of the petal (v = 1), the last row its base (v = 0); u runs
#    across, from column 0. map_grid gives u and v of every pixel, so a map
#    can be written as a formula. Here the petals' outer layer grows more
#    along the margins (|2u - 1| near 1) than along the midrib (u = 0.5).
key = len(lily.map_keys("petal")) - 1          # the last key of the maps
u, v = lily.map_grid("petal", "e_growth", key=key)
before = lily.get_map("petal", "e_growth", key=key)
edge_weighted = np.clip(before * (0.6 + 0.8 * np.abs(2 * u - 1)), 0.0, 1.0)
changed = lily.copy()
changed.set_map("petal", "e_growth", edge_weighted, key=key)

# 3. Simulate both, with a progress line.
def progress(k, total):
    print(f"\rkeyframe {k}/{total}", end="", flush=True)

runs = {}
for name, project in [("as built", lily), ("margins grow more", changed)]:
    runs[name] = project.simulate(keyframes=keyframes, progress=progress)
    print(f"  {name}: done")

# 4. A quantity over time: how far the petal tips open from the flower axis
#    (the y axis), in the project's units (cm), per keyframe.
def tip_distance(result, organ="petal-1"):
    positions = result.positions(organ)               # [keyframes + 1, n, 3]
    tip = np.argmax(positions[0, :, 1])               # highest particle in the bud
    xz = positions[:, tip, [0, 2]]
    return np.hypot(xz[:, 0], xz[:, 1])

table = {name: tip_distance(run) for name, run in runs.items()}
for name, series in table.items():
    print(f"{name}: tip from axis {series[0]:.3f} -> {series[-1]:.3f} cm")

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5, 3.2))
    for name, series in table.items():
        ax.plot(series, label=name)
    ax.set_xlabel("keyframe")
    ax.set_ylabel("petal-1 tip from axis (cm)")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out / "tip-distance.png", dpi=120)
    print("wrote", out / "tip-distance.png")
except ImportError:
    print("matplotlib is not installed: no plot (pip install matplotlib)")

# 5. Export the changed run for Blender, three.js or a USD pipeline.
runs["margins grow more"].export(out / "lily.glb")
runs["margins grow more"].export(out / "lily.usdc")
(out / "project").mkdir(exist_ok=True)
changed.save(out / "project" / "lily-margins.anthesis.toml")  # maps saved as PNGs beside it
print("wrote", out / "lily.glb", out / "lily.usdc", out / "project")

"""Anthesis for Python: simulate flower opening by painted growth.

Load a project (a file, its folder or ``"builtin:NAME"``), change its growth
maps (numpy arrays on the UV grid) and parameters, simulate, and get every
keyframe as numpy arrays; export (.glb, .usda, .usdc, OBJ) and render.

Units: lengths in the project's length units, angles in degrees, time in keyframes (0 is the bud). The
engine is the one the ``anthesis`` command line runs: the same project and
keyframe count give the same bits, in any process (on machines whose CPUs
offer the same vector instructions).

>>> import anthesis
>>> lily = anthesis.load("builtin:lily")
>>> result = lily.simulate(keyframes=10)
>>> result.positions("petal-1").shape      # (keyframes + 1, particles, 3)
(11, 1016, 3)
"""

from ._anthesis import (
    MAX_KEYFRAMES,
    AnthesisError,
    Cancelled,
    ExportError,
    FitError,
    Project,
    ProjectError,
    RenderError,
    Result,
    SimulationError,
    builtins,
    load,
    map_names,
)

__all__ = [
    "MAX_KEYFRAMES",
    "AnthesisError",
    "Cancelled",
    "ExportError",
    "FitError",
    "Project",
    "ProjectError",
    "RenderError",
    "Result",
    "SimulationError",
    "builtins",
    "load",
    "map_names",
]

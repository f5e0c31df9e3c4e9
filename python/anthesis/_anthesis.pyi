"""Type stubs of the compiled engine (python/src/lib.rs)."""

import os
import threading
from typing import Any, Callable, final

import numpy as np
import numpy.typing as npt

__all__ = [
    "AnthesisError",
    "Cancelled",
    "ExportError",
    "FitError",
    "MAX_KEYFRAMES",
    "Project",
    "ProjectError",
    "RenderError",
    "Result",
    "SimulationError",
    "builtins",
    "load",
    "map_names",
    "measure_angle_defects",
    "measure_boundary",
    "measure_curvatures",
    "measure_margin",
    "measure_midrib",
    "measure_stretches",
]

MAX_KEYFRAMES: int

class AnthesisError(Exception):
    """Base class of the errors the engine reports."""

class ProjectError(AnthesisError):
    """A project that cannot be loaded, checked or saved."""

class SimulationError(AnthesisError):
    """A run that stopped: no convergence, organs crossing, too little memory."""

    result: Result
    """The keyframes computed before the stop (the bud included); absent
    when the run did not start."""

class Cancelled(AnthesisError):
    """The run was cancelled through ``Project.simulate(cancel=...)``."""

    result: Result
    """The keyframes computed before the cancellation (the bud included)."""

class FitError(AnthesisError):
    """A fit that could not start or go on (a bad target, a failed simulation)."""

class ExportError(AnthesisError):
    """An export that could not be written."""

class RenderError(AnthesisError):
    """A picture that could not be rendered (no Vulkan driver, too large)."""

def load(source: str | os.PathLike[str]) -> Project:
    """A project file (``*.anthesis.toml``), its folder, or ``"builtin:NAME"``."""

def builtins() -> list[str]:
    """The names of the built-in flowers (``load("builtin:NAME")``)."""

def map_names() -> list[str]:
    """The six scalar map names and ``"direction"``."""

@final
class Project:
    """A flower project; edits are checked by the rules of the project file."""

    @property
    def name(self) -> str: ...
    @property
    def source(self) -> str:
        """Where the project was loaded from (a path or ``builtin:NAME``)."""
    @property
    def organs(self) -> list[str]: ...
    @property
    def templates(self) -> list[str]: ...
    def template_of(self, organ: str) -> str: ...
    def map_keys(self, template: str) -> list[int]:
        """The step of each key of the template's maps (usually ``[0]``)."""
    def mesh(
        self, template: str
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.uint32], npt.NDArray[np.float64]]:
        """Bud mesh in the template frame: positions [n, 3], faces [m, 3], UVs [n, 2]."""
    def get_map(self, template: str, name: str, key: int = 0) -> npt.NDArray[np.float32]:
        """float32 [h, w] (``direction``: [h, w, 2]); row 0 at the tip (v = 1)."""
    def set_map(self, template: str, name: str, values: npt.ArrayLike, key: int = 0) -> None:
        """Replace a map; ValueError for a wrong shape or values out of range."""
    def map_grid(
        self, template: str, name: str, key: int = 0
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """(u, v) of the map's pixel centres, each of the map's [h, w] shape."""
    def get_parameter(
        self, name: str, template: str | None = None
    ) -> float | int | str | None:
        """A template parameter (``template=``: dg, thickness, stretch_stiffness,
        bend_stiffness) or a simulation setting (keyframes, relative_tolerance,
        max_iterations, collision_offset, mean_edge, lengths_from, bend_from).
        ``lengths_from`` is ``"shape"`` (each step grows every triangle as it
        is now) or ``"rest"`` (its rest triangle: the rest state accumulates
        the growth); ``bend_from`` is ``"dihedral"`` or ``"rest_angle"``."""
    def set_parameter(
        self, name: str, value: float | int | str | None, template: str | None = None
    ) -> None:
        """Set a parameter (names and values as in ``get_parameter``); ValueError
        for a value out of range or not one of the choices, TypeError for a
        value of the wrong kind; nothing changes then."""
    def parameters(self, template: str | None = None) -> dict[str, float | int | str | None]: ...
    def copy(self) -> Project: ...
    def __copy__(self) -> Project: ...
    def __deepcopy__(self, memo: Any) -> Project: ...
    def save(self, path: str | os.PathLike[str]) -> None: ...
    def simulate(
        self,
        keyframes: int | None = None,
        organ: str | None = None,
        progress: Callable[[int, int], object] | None = None,
        cancel: threading.Event | Callable[[], bool] | None = None,
        allow_crossings: bool = False,
    ) -> Result:
        """Run as ``anthesis simulate``; the GIL is released while it runs.

        A run that stops raises with the keyframes before the stop as the
        exception's ``result``."""

    def export(
        self,
        path: str | os.PathLike[str],
        keyframes: int | None = None,
        organ: str | None = None,
        fps: float = 24.0,
        subdivide: int = 0,
        normals: bool = True,
        progress: Callable[[int, int], object] | None = None,
        cancel: threading.Event | Callable[[], bool] | None = None,
    ) -> Result:
        """Simulate and write the run as ``anthesis simulate --out PATH``; returns the run."""
    def fit(
        self,
        organ: str,
        target: str | os.PathLike[str],
        *,
        register: bool = False,
        register_scale: bool = False,
        flip_inner_side: bool = False,
        keys: int = 1,
        nodes: tuple[int, int] = (3, 4),
        direction_nodes: tuple[int, int] = (3, 2),
        max_seconds: float = 100.0,
        max_iterations: int = 30,
        progress: Callable[[int, float, float], object] | None = None,
        cancel: threading.Event | Callable[[], bool] | None = None,
    ) -> tuple[Project, dict[str, Any]]:
        """Fit the maps of ``organ``'s template to an OBJ target, as ``anthesis fit``.

        Returns the fitted project and a report (``rms``, ``max``,
        ``guess_rms`` as fractions of the organ's length, ``reached``,
        ``stopped``, ``iterations``, ``simulations``, ``seconds``,
        ``verdict``)."""

@final
class Result:
    """Every keyframe of a run (0 is the bud), world frame, project units."""

    @property
    def organs(self) -> list[str]: ...
    @property
    def keyframes(self) -> int:
        """Keyframes computed after the bud."""
    @property
    def stats(self) -> dict[str, npt.NDArray[Any]]:
        """energy, relative_gradient, seconds, iterations, contact_particles, pushed_particles."""
    def positions(self, organ: str | int) -> npt.NDArray[np.float64]:
        """float64 [keyframes + 1, n, 3]."""
    def faces(self, organ: str | int) -> npt.NDArray[np.uint32]:
        """uint32 [m, 3]."""
    def uvs(self, organ: str | int) -> npt.NDArray[np.float64]:
        """float64 [n, 2]."""
    def measures(
        self, organ: str | int, base_v: float = 0.05, contact_distance: float | None = None
    ) -> dict[str, npt.NDArray[Any]]:
        """Every measurement of one organ per keyframe (see ``anthesis.measure.organ_measures``)."""
    def export(
        self,
        path: str | os.PathLike[str],
        fps: float = 24.0,
        subdivide: int = 0,
        normals: bool = True,
    ) -> None:
        """.glb, .usda, .usdc by extension; any other path: a folder of OBJs."""
    def render(
        self,
        keyframe: int | None = None,
        width: int = 640,
        height: int = 480,
        azimuth: float = 30.0,
        elevation: float = 20.0,
    ) -> npt.NDArray[np.uint8]:
        """RGBA uint8 [height, width, 4] of one keyframe (default: the last)."""
    def __len__(self) -> int: ...

# The measurements of ``anthesis.measure`` (``anthesis_sim::measure``); use
# that module, which checks and converts its arguments.
def measure_curvatures(
    positions: npt.NDArray[np.float64], faces: npt.NDArray[np.int64]
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Mean and Gaussian curvature per vertex, NaN on the rim."""
def measure_angle_defects(
    positions: npt.NDArray[np.float64], faces: npt.NDArray[np.int64]
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Angle defect and mixed Voronoi area per vertex."""
def measure_boundary(faces: npt.NDArray[np.int64], n: int) -> npt.NDArray[np.bool_]:
    """Whether each vertex lies on the rim."""
def measure_stretches(
    rest: npt.NDArray[np.float64], current: npt.NDArray[np.float64], faces: npt.NDArray[np.int64]
) -> npt.NDArray[np.float64]:
    """Principal stretches per triangle, [m, 2], largest first."""
def measure_midrib(
    positions: npt.NDArray[np.float64],
    faces: npt.NDArray[np.int64],
    uvs: npt.NDArray[np.float64],
    samples: int,
) -> float:
    """Length of the curve u = 0.5 through the UV layout."""
def measure_margin(
    positions: npt.NDArray[np.float64],
    faces: npt.NDArray[np.int64],
    uvs: npt.NDArray[np.float64],
    base_v: float,
) -> float:
    """Length of the rim edges with an end above v = base_v."""

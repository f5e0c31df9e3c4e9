"""Parameter sweeps: many runs of one project, on Dask distributed or serially.

A sweep is a list of :class:`Member` s, each a project source with changes
(parameters, maps, keyframe count). :func:`run_member` runs one member and
returns plain numpy arrays; :func:`run_on_dask` submits every member to a
``dask.distributed`` client (a ``LocalCluster``, a Slurm cluster through
``dask_jobqueue.SLURMCluster``, a Kubernetes cluster through
``dask_kubernetes``) and collects every member, as a result or as a
failure with its error: nothing is lost, and a member that fails does not
stop the others. Dask does the scheduling; this module only describes the
work. The engine is deterministic, so a member's arrays are the same bits
whichever worker or process ran it, and on whichever machine where the
CPUs offer the same vector instructions (:func:`run_serial` runs the same
function in this process, for comparison).

Workers need the ``anthesis`` wheel installed (``pip install anthesis-*.whl``
in the workers' environment); nothing else is shipped to them.
"""

from __future__ import annotations

import traceback
import uuid
from dataclasses import dataclass, field
from typing import Any, Iterable, Mapping

import numpy as np

from . import load

__all__ = ["Member", "MemberResult", "Sweep", "run_member", "run_serial", "run_on_dask"]


@dataclass(frozen=True)
class Member:
    """One run of a sweep.

    ``parameters`` maps a simulation setting's name (``"keyframes"``,
    ``"relative_tolerance"``, ...) or a ``(template, name)`` pair
    (``("petal", "dg")``) to its value; ``maps`` maps ``(template, map
    name)`` to an array (see ``Project.set_map``). ``keyframes`` and
    ``organ`` are passed to ``Project.simulate``.
    """

    name: str
    source: str
    parameters: Mapping[Any, Any] = field(default_factory=dict)
    maps: Mapping[tuple[str, str], Any] = field(default_factory=dict)
    keyframes: int | None = None
    organ: str | None = None


@dataclass
class MemberResult:
    """What one member produced: per organ, positions [k + 1, n, 3] and
    faces [m, 3]; per keyframe, the elastic energy."""

    name: str
    organs: list[str]
    positions: dict[str, np.ndarray]
    faces: dict[str, np.ndarray]
    energy: np.ndarray

    def same_bits(self, other: "MemberResult") -> bool:
        """Whether two results hold the same bits (every position and energy)."""
        if self.organs != other.organs:
            return False
        arrays = [(self.energy, other.energy)]
        arrays += [(self.positions[o], other.positions[o]) for o in self.organs]
        arrays += [(self.faces[o], other.faces[o]) for o in self.organs]
        return all(
            a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()
            for a, b in arrays
        )


@dataclass
class Sweep:
    """Every member of a sweep: ``results`` by member name, ``failures``
    (member name to the error's type, message and traceback)."""

    results: dict[str, MemberResult]
    failures: dict[str, str]

    def __len__(self) -> int:
        return len(self.results) + len(self.failures)


def run_member(member: Member) -> MemberResult:
    """Loads, changes and simulates one member (the function a worker runs)."""
    project = load(member.source)
    for key, value in member.parameters.items():
        if isinstance(key, tuple):
            template, name = key
            project.set_parameter(name, value, template=template)
        else:
            project.set_parameter(key, value)
    for (template, name), values in member.maps.items():
        project.set_map(template, name, values)
    result = project.simulate(keyframes=member.keyframes, organ=member.organ)
    organs = result.organs
    return MemberResult(
        name=member.name,
        organs=organs,
        positions={o: result.positions(o) for o in organs},
        faces={o: result.faces(o) for o in organs},
        energy=result.stats["energy"],
    )


def _failure(error: BaseException, tb: Any = None) -> str:
    if tb is None:
        tb = error.__traceback__
    lines = traceback.format_exception(type(error), error, tb)
    return "".join(lines).rstrip()


def run_serial(members: Iterable[Member]) -> Sweep:
    """Every member in this process, one after the other."""
    sweep = Sweep(results={}, failures={})
    for member in _unique(members):
        try:
            sweep.results[member.name] = run_member(member)
        except Exception as error:  # recorded, never lost
            sweep.failures[member.name] = _failure(error)
    return sweep


def run_on_dask(client: Any, members: Iterable[Member], retries: int = 0) -> Sweep:
    """Every member on the Dask cluster of ``client``
    (``distributed.Client``); waits for all of them.

    Each member is one task (key ``anthesis-<name>``); ``retries`` reruns a
    member whose worker died or that raised. A member that still fails is
    recorded in ``failures`` with its error and traceback as the worker
    raised it (a ``KilledWorker`` when its workers kept dying).
    """
    from distributed import wait

    members = _unique(members)
    run = uuid.uuid4().hex[:8]
    futures = client.map(
        run_member,
        members,
        key=[f"anthesis-{m.name}-{run}" for m in members],
        retries=retries,
        pure=False,
    )
    wait(futures)
    sweep = Sweep(results={}, failures={})
    for member, future in zip(members, futures):
        if future.status == "finished":
            sweep.results[member.name] = future.result()
        else:
            try:
                error, tb = future.exception(), future.traceback()
            except Exception as lost:  # cancelled or lost: still recorded
                error, tb = lost, None
            sweep.failures[member.name] = f"{future.status}: {_failure(error, tb)}"
        future.release()
    return sweep


def _unique(members: Iterable[Member]) -> list[Member]:
    members = list(members)
    names = [m.name for m in members]
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        raise ValueError(f"member names must be unique; repeated: {', '.join(repeated)}")
    return members

"""Fitting growth maps to a target shape, as `anthesis fit` does."""

import numpy as np
import pytest

import anthesis


def target_of(project, organ, keyframes, folder):
    """The final shape of `organ` simulated alone, as an OBJ (world frame)."""
    project.simulate(keyframes=keyframes, organ=organ).export(folder)
    return sorted(folder.glob("*.obj"))[-1]


def test_a_fit_comes_closer_to_a_shape_other_maps_made(five_petal, tmp_path):
    start = five_petal.copy()
    start.set_parameter("keyframes", 10)
    # The target: the same petal grown with more growth towards its tip.
    grown = start.copy()
    u, v = np.meshgrid(np.linspace(0, 1, 16), np.linspace(1, 0, 16))
    grown.set_map("petal", "e_growth", np.clip(0.2 + 0.8 * v, 0, 1))
    target = target_of(grown, "petal-1", 10, tmp_path / "target")

    seen = []
    fitted, report = start.fit(
        "petal-1", target, nodes=(2, 3), max_iterations=4, max_seconds=60,
        progress=lambda i, rms, worst: seen.append((i, rms)))
    assert seen and seen[0][0] == 0
    # From the first guess to within a fifth of its distance, and within
    # the 2 % of the organ's length the engine calls reached.
    assert report["rms"] < 0.2 * report["guess_rms"]
    assert report["reached"]
    assert report["rms"] <= seen[0][1]
    assert report["stopped"] in {"goal", "converged", "max-iterations", "max-seconds"}
    assert "RMS" in report["verdict"]
    # The fitted project holds other maps and is independent of the start.
    assert not np.array_equal(fitted.get_map("petal", "e_growth"),
                              start.get_map("petal", "e_growth"))
    assert start.get_map("petal", "e_growth").shape == (1, 1)


def test_fit_errors_name_what_is_wrong(five_petal, tmp_path):
    with pytest.raises(anthesis.FitError, match="cannot read the target"):
        five_petal.fit("petal-1", tmp_path / "missing.obj")
    with pytest.raises(KeyError, match="no organ named `sepal-1`"):
        five_petal.fit("sepal-1", tmp_path / "missing.obj")
    with pytest.raises(ValueError, match="max_seconds must be a positive number"):
        five_petal.fit("petal-1", tmp_path / "missing.obj", max_seconds=0)

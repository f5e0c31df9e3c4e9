"""Loading, maps and parameters: shapes, ranges and the engine's checks."""

import numpy as np
import pytest

import anthesis


def test_builtins_load_and_name_their_organs(five_petal):
    assert "lily" in anthesis.builtins()
    assert five_petal.organs == [f"petal-{i}" for i in range(1, 6)]
    assert five_petal.templates == ["petal"]
    assert five_petal.template_of("petal-3") == "petal"
    positions, faces, uvs = five_petal.mesh("petal")
    assert positions.shape == (121, 3) and uvs.shape == (121, 2)
    assert faces.shape == (200, 3) and faces.dtype == np.uint32
    assert faces.max() == 120


def test_unknown_builtin_and_missing_file_raise_project_errors(tmp_path):
    with pytest.raises(anthesis.ProjectError, match="no built-in flower `tulip`.*lily"):
        anthesis.load("builtin:tulip")
    with pytest.raises(anthesis.ProjectError, match="cannot open project"):
        anthesis.load(tmp_path / "missing.anthesis.toml")


def test_maps_round_trip_on_their_uv_grid(lily):
    project = lily.copy()
    keys = project.map_keys("petal")
    assert len(keys) >= 2 and keys == sorted(keys)
    current = project.get_map("petal", "e_growth", key=1)
    assert current.dtype == np.float32 and current.shape == (64, 64)
    u, v = project.map_grid("petal", "e_growth", key=1)
    assert u.shape == v.shape == current.shape
    h, w = current.shape
    # Row 0 is the tip (v = 1), column 0 is u = 0: pixel centres.
    assert v[0, 0] == pytest.approx(1 - 0.5 / h) and v[-1, 0] == pytest.approx(0.5 / h)
    assert u[0, 0] == pytest.approx(0.5 / w) and u[0, -1] == pytest.approx(1 - 0.5 / w)
    painted = 0.5 * v * (1 - np.abs(2 * u - 1))
    project.set_map("petal", "e_growth", painted, key=1)
    np.testing.assert_array_equal(
        project.get_map("petal", "e_growth", key=1), painted.astype(np.float32))
    # The original is untouched.
    np.testing.assert_array_equal(lily.get_map("petal", "e_growth", key=1), current)
    direction = project.get_map("petal", "direction", key=1)
    assert direction.shape[-1] == 2 and np.abs(direction).max() <= 1
    with pytest.raises(IndexError, match="key 9 does not exist"):
        project.get_map("petal", "e_growth", key=9)


def test_maps_refuse_bad_shapes_and_values(lily):
    project = lily.copy()
    h, w = project.get_map("petal", "bend", key=1).shape
    with pytest.raises(ValueError, match=r"values must lie in \[0(\.0)?, 1(\.0)?\]"):
        project.set_map("petal", "bend", np.full((h, w), 1.5), key=1)
    with pytest.raises(ValueError, match="values must lie in"):
        project.set_map("petal", "bend", np.full((h, w), np.nan), key=1)
    with pytest.raises(ValueError, match=r"shape \[h, w\]"):
        project.set_map("petal", "bend", np.zeros((h, w, 3)), key=1)
    with pytest.raises(ValueError, match=r"shape \[h, w, 2\]"):
        project.set_map("petal", "direction", np.zeros((h, w)), key=1)
    with pytest.raises(ValueError, match=r"must be \[64, 64\] \(or \[1, 1\], a constant\), got \[65, 64\]"):
        project.set_map("petal", "bend", np.zeros((h + 1, w)), key=1)
    with pytest.raises(KeyError, match="no map named `growth`"):
        project.set_map("petal", "growth", np.zeros((h, w)))
    with pytest.raises(KeyError, match="no template named `tepal`"):
        project.get_map("tepal", "bend")
    with pytest.raises(TypeError, match="array of numbers"):
        project.set_map("petal", "bend", "dark")
    # Nothing refused was kept; a constant fits any template.
    np.testing.assert_array_equal(project.get_map("petal", "bend", key=1),
                                  lily.get_map("petal", "bend", key=1))
    project.set_map("petal", "bend", [[0.25]], key=1)
    assert project.get_map("petal", "bend", key=1).shape == (1, 1)


def test_parameters_are_checked_like_the_project_file(five_petal):
    project = five_petal.copy()
    assert project.get_parameter("keyframes") == 100
    assert set(project.parameters(template="petal")) == {
        "dg", "thickness", "stretch_stiffness", "bend_stiffness"}
    project.set_parameter("dg", 0.02, template="petal")
    assert project.get_parameter("dg", template="petal") == 0.02
    with pytest.raises(ValueError, match="thickness must be greater than 0"):
        project.set_parameter("thickness", 0.0, template="petal")
    with pytest.raises(ValueError, match="dg must be a number greater than -1"):
        project.set_parameter("dg", -1.5, template="petal")
    with pytest.raises(ValueError, match="keyframes must be at least 1"):
        project.set_parameter("keyframes", 0)
    with pytest.raises(ValueError, match="whole number"):
        project.set_parameter("keyframes", 2.5)
    with pytest.raises(KeyError, match="give template="):
        project.set_parameter("dg", 0.1)
    # A refused change leaves the project as it was.
    assert project.get_parameter("thickness", template="petal") == five_petal.get_parameter(
        "thickness", template="petal")
    project.set_parameter("mean_edge", None)
    assert project.get_parameter("mean_edge") is None

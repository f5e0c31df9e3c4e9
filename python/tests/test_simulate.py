"""Simulation through Python: determinism, progress, cancellation, exports,
and the same bits as the `anthesis` command line."""

import subprocess
import threading
from pathlib import Path

import numpy as np
import pytest

import anthesis


def read_obj_positions(path: Path) -> dict[str, np.ndarray]:
    """Each object's `v` lines of an OBJ the engine wrote (shortest
    round-trip decimals, so float() gives back the exact f64)."""
    organs: dict[str, list[list[float]]] = {}
    current = None
    for line in path.read_text().splitlines():
        if line.startswith("o "):
            current = organs.setdefault(line[2:].strip(), [])
        elif line.startswith("v ") and current is not None:
            current.append([float(x) for x in line.split()[1:4]])
    return {name: np.array(v, dtype=np.float64) for name, v in organs.items()}


def test_runs_are_deterministic_and_shaped(five_petal):
    a = five_petal.simulate(keyframes=4)
    b = five_petal.simulate(keyframes=4)
    assert a.keyframes == 4 and len(a) == 5
    assert a.organs == five_petal.organs
    for organ in a.organs:
        p = a.positions(organ)
        assert p.shape == (5, 121, 3) and p.dtype == np.float64
        assert p.tobytes() == b.positions(organ).tobytes()
        assert a.faces(organ).shape == (200, 3)
        # The organs grow: the last keyframe is not the bud.
        assert not np.array_equal(p[0], p[-1])
    stats = a.stats
    assert stats["energy"].shape == (5,) and stats["energy"][0] == 0.0
    assert stats["energy"].tobytes() == b.stats["energy"].tobytes()
    assert (stats["iterations"][1:] > 0).all()


def test_a_map_changes_the_run(five_petal):
    base = five_petal.simulate(keyframes=3, organ="petal-1")
    still = five_petal.copy()
    for name in ("e_growth", "w_growth", "e_growth_in", "w_growth_in"):
        still.set_map("petal", name, [[0.0]])
    run = still.simulate(keyframes=3, organ="petal-1")
    assert run.organs == ["petal-1"]
    assert not np.array_equal(run.positions(0)[-1], base.positions(0)[-1])


def test_the_growth_rules_are_settings_that_change_the_run(five_petal, tmp_path):
    """`lengths_from` and `bend_from` (the project file's [simulation]) are
    read and set as strings; each other rule changes the run, and going back
    to the default gives the default run bit for bit."""
    assert five_petal.get_parameter("lengths_from") == "shape"
    assert five_petal.get_parameter("bend_from") == "dihedral"
    assert anthesis.load("builtin:lily-edge").get_parameter("lengths_from") == "rest"
    assert {"lengths_from", "bend_from"} <= set(five_petal.parameters())
    base = five_petal.simulate(keyframes=3, organ="petal-1").positions(0)
    for name, other, default in (("lengths_from", "rest", "shape"),
                                 ("bend_from", "rest_angle", "dihedral")):
        project = five_petal.copy()
        project.set_parameter(name, other)
        assert project.get_parameter(name) == other
        changed = project.simulate(keyframes=3, organ="petal-1").positions(0)
        # The bud is the same; the grown keyframes are not.
        assert changed[0].tobytes() == base[0].tobytes()
        assert np.abs(changed[-1] - base[-1]).max() > 1e-3, name
        project.set_parameter(name, default)
        again = project.simulate(keyframes=3, organ="petal-1").positions(0)
        assert again.tobytes() == base.tobytes(), name
    # Saved as the project file says, and read back.
    project = five_petal.copy()
    project.set_parameter("lengths_from", "rest")
    project.save(tmp_path / "rest.anthesis.toml")
    text = (tmp_path / "rest.anthesis.toml").read_text()
    assert 'lengths_from = "rest"' in text and "version = 10" in text
    assert anthesis.load(tmp_path / "rest.anthesis.toml").get_parameter("lengths_from") == "rest"
    # Refused values name the choices and change nothing.
    with pytest.raises(ValueError, match='`lengths_from` must be "shape" or "rest", got "rest_length"'):
        project.set_parameter("lengths_from", "rest_length")
    with pytest.raises(ValueError, match='`bend_from` must be "dihedral" or "rest_angle", got "rest"'):
        project.set_parameter("bend_from", "rest")
    with pytest.raises(TypeError, match='`lengths_from` takes a string: "shape" or "rest"'):
        project.set_parameter("lengths_from", 1)
    with pytest.raises(KeyError, match="is a simulation setting"):
        project.set_parameter("lengths_from", "rest", template="petal")
    assert project.get_parameter("lengths_from") == "rest"
    assert project.get_parameter("bend_from") == "dihedral"


def test_progress_is_reported_and_cancel_stops_the_run(five_petal):
    seen = []
    five_petal.simulate(keyframes=3, progress=lambda k, total: seen.append((k, total)))
    assert seen == [(1, 3), (2, 3), (3, 3)]

    event = threading.Event()

    def stop_after_two(k, total):
        if k == 2:
            event.set()

    with pytest.raises(anthesis.Cancelled, match="cancelled after keyframe 2 of 10") as stopped:
        five_petal.simulate(keyframes=10, progress=stop_after_two, cancel=event)
    # The keyframes before the stop are kept, the same bits as a full run's.
    partial = stopped.value.result
    assert partial.keyframes == 2
    full = five_petal.simulate(keyframes=10)
    assert partial.positions(0).tobytes() == full.positions(0)[:3].tobytes()
    with pytest.raises(anthesis.Cancelled, match="after keyframe 0"):
        five_petal.simulate(keyframes=10, cancel=lambda: True)


def test_an_error_in_the_progress_callback_reaches_the_caller(five_petal):
    def broken(k, total):
        raise RuntimeError("plot window closed")

    with pytest.raises(RuntimeError, match="plot window closed"):
        five_petal.simulate(keyframes=2, progress=broken)


def test_the_same_bits_as_the_command_line(anthesis_bin, tmp_path):
    """The built-in lily, 3 keyframes, every organ: Python's positions are
    the command line's, bit for bit (OBJ decimals round-trip exactly)."""
    keyframes = 3
    out = tmp_path / "cli"
    subprocess.run(
        [anthesis_bin, "simulate", "builtin:lily", "--keyframes", str(keyframes),
         "--out", str(out)],
        check=True, capture_output=True, text=True)
    result = anthesis.load("builtin:lily").simulate(keyframes=keyframes)
    files = sorted(out.glob("*.obj"))
    assert len(files) == keyframes + 1
    for k, file in enumerate(files):
        cli = read_obj_positions(file)
        for organ in result.organs:
            mine = result.positions(organ)[k]
            assert cli[organ].shape == mine.shape
            assert cli[organ].tobytes() == mine.tobytes(), f"{organ} differs at keyframe {k}"


def test_exports_by_extension(five_petal, tmp_path):
    result = five_petal.simulate(keyframes=2)
    result.export(tmp_path / "open.glb")
    assert (tmp_path / "open.glb").read_bytes()[:4] == b"glTF"
    result.export(tmp_path / "open.usda")
    assert (tmp_path / "open.usda").read_text().startswith("#usda 1.0")
    result.export(tmp_path / "open.usdc")
    assert (tmp_path / "open.usdc").read_bytes()[:8] == b"PXR-USDC"
    result.export(tmp_path / "objs")
    files = sorted((tmp_path / "objs").glob("*.obj"))
    assert len(files) == 3
    last = read_obj_positions(files[-1])
    assert last["petal-1"].tobytes() == result.positions("petal-1")[-1].tobytes()
    # Project.export is simulate then export, as `anthesis simulate --out`.
    again = five_petal.export(tmp_path / "again.glb", keyframes=2)
    assert (tmp_path / "again.glb").read_bytes() == (tmp_path / "open.glb").read_bytes()
    assert again.positions(0).tobytes() == result.positions(0).tobytes()
    with pytest.raises(anthesis.ExportError, match="cannot write"):
        result.export(tmp_path / "missing" / "open.glb")
    with pytest.raises(ValueError, match="fps must be a positive number"):
        result.export(tmp_path / "x.glb", fps=0)


def test_render_draws_the_flower(five_petal):
    result = five_petal.simulate(keyframes=1)
    try:
        picture = result.render(keyframe=1, width=96, height=64)
    except anthesis.RenderError as error:
        pytest.fail(f"no renderer (CI installs Mesa's lavapipe): {error}")
    assert picture.shape == (64, 96, 4) and picture.dtype == np.uint8
    # The flower fills the middle; the corners are background.
    corner = picture[0, 0].astype(int)
    middle = picture[24:40, 36:60].reshape(-1, 4).astype(int)
    assert (np.abs(middle - corner).sum(axis=1) > 30).mean() > 0.5
    with pytest.raises(IndexError, match="past the end"):
        result.render(keyframe=2)

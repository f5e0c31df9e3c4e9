"""The measurements from Python are the engine's, as `anthesis measure`
writes them: the same numbers on the same run, lengths scaled by the
project's unit, and the contact area of the whole flower."""

import csv
import subprocess

import numpy as np
import pytest

from anthesis.measure import angle_defects_and_areas, organ_measures


def test_organ_measures_are_the_command_lines_table(five_petal, anthesis_bin, tmp_path):
    table = tmp_path / "table.csv"
    subprocess.run([anthesis_bin, "measure", "builtin:five-petal", "--keyframes", "2",
                    "--no-cache", "--out", str(table)], check=True, capture_output=True)
    with open(table, newline="") as f:
        rows = list(csv.reader(f))
    header, rows = rows[0], rows[1:]
    columns = {h.split(" [")[0]: i for i, h in enumerate(header)}
    result = five_petal.simulate(keyframes=2)
    assert len(rows) == 3 * len(result.organs)
    scales = []
    for organ in result.organs:
        m = organ_measures(result, organ)
        mine = [r for r in rows if r[1] == organ]
        assert [int(r[0]) for r in mine] == [0, 1, 2]
        for k, row in enumerate(mine):
            value = lambda name: float(row[columns[name]])
            # Ratios are the same numbers, to the last bit of the text.
            for name in ("stretch_major_mean", "stretch_minor_mean"):
                assert value(name) == m[name][k]
            # Lengths are in the project's unit (mm): one scale for all.
            scales.append(value("midrib_length") / m["midrib_length"][k])
            for name, power in (("margin_length", 1), ("area", 2),
                                ("mean_curvature_mean", -1), ("gaussian_curvature_mean", -2)):
                assert value(name) == pytest.approx(m[name][k] * scales[-1] ** power, rel=1e-12)
            assert value("contact_area") == pytest.approx(
                m["contact_area"][k] * scales[-1] ** 2, rel=1e-12, abs=0)
    assert np.ptp(scales) < 1e-12 * scales[0]


def test_contact_area_is_the_area_of_the_touching_triangles(five_petal):
    result = five_petal.simulate(keyframes=2)
    organ = result.organs[0]
    m = result.measures(organ, contact_distance=1e6)
    # Every vertex is within a distance larger than the flower of another
    # organ; none within 0 (the organs do not cross).
    assert m["contact"].all()
    np.testing.assert_allclose(m["contact_area"], m["area"], rtol=1e-12)
    none = result.measures(organ, contact_distance=0.0)
    assert not none["contact"].any() and (none["contact_area"] == 0).all()
    # The area is the sum of the triangles' areas.
    x, f = result.positions(organ)[-1], result.faces(organ).astype(np.int64)
    areas = 0.5 * np.linalg.norm(np.cross(x[f[:, 1]] - x[f[:, 0]], x[f[:, 2]] - x[f[:, 0]]), axis=1)
    assert m["area"][-1] == pytest.approx(areas.sum(), rel=1e-12)
    # The contact area is the vertices' mixed areas, which tile the surface.
    _, vertex_areas = angle_defects_and_areas(result.positions(organ)[0], f)
    assert m["contact_area"][0] == pytest.approx(vertex_areas.sum(), rel=1e-12)
    # Alone, an organ touches only the parts: the receptacle it sits on,
    # within a distance larger than the flower, all over.
    alone = five_petal.simulate(keyframes=1, organ=organ)
    near = alone.measures(organ, contact_distance=1e6)
    np.testing.assert_allclose(near["contact_area"], near["area"], rtol=1e-12)
    assert alone.measures(organ, contact_distance=0.0)["contact_area"].max() == 0.0
    with pytest.raises(ValueError, match="contact_distance"):
        result.measures(organ, contact_distance=-1.0)

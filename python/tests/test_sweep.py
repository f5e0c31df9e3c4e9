"""A small sweep on a Dask LocalCluster: every member is collected, the
failing one with its error, and the results are the serial runs' bits."""

import numpy as np
import pytest

distributed = pytest.importorskip("distributed")

from anthesis.sweep import Member, run_member, run_on_dask, run_serial  # noqa: E402


def members():
    ramp = np.linspace(0.2, 1.0, 8)[:, None] * np.ones((8, 8))
    return [
        Member("base", "builtin:five-petal", keyframes=3),
        Member("fast", "builtin:five-petal", parameters={("petal", "dg"): 0.03}, keyframes=3),
        Member("ramp", "builtin:five-petal", maps={("petal", "e_growth"): ramp}, keyframes=3),
        # Refused by the project file's rules on the worker: recorded, not lost.
        Member("flat", "builtin:five-petal", parameters={("petal", "thickness"): 0.0},
               keyframes=3),
    ]


def test_a_sweep_on_a_local_cluster_matches_serial_runs_bit_for_bit():
    serial = run_serial(members())
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            sweep = run_on_dask(client, members())
    assert len(sweep) == 4
    assert sorted(sweep.results) == ["base", "fast", "ramp"]
    assert list(sweep.failures) == ["flat"]
    assert "ValueError" in sweep.failures["flat"]
    assert "thickness must be greater than 0" in sweep.failures["flat"]
    assert sweep.failures.keys() == serial.failures.keys()
    for name, result in sweep.results.items():
        assert result.same_bits(serial.results[name]), name
    # The members differ from one another: the comparison can fail.
    assert not sweep.results["base"].same_bits(sweep.results["fast"])
    assert not sweep.results["base"].same_bits(sweep.results["ramp"])


def test_member_names_must_be_unique():
    with pytest.raises(ValueError, match="repeated: a"):
        run_serial([Member("a", "builtin:five-petal"), Member("a", "builtin:lily")])


def test_a_member_returns_plain_arrays():
    result = run_member(Member("one", "builtin:five-petal", keyframes=1, organ="petal-2"))
    assert result.organs == ["petal-2"]
    assert result.positions["petal-2"].shape == (2, 121, 3)
    assert result.energy.shape == (2,)

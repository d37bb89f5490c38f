"""The field memo: a kept field is the one a new generation makes, bit for bit (the plant's
wind, the field and a LIDAR's evolved field); it keeps no more than its byte limit, oldest out
first; a bad limit is named."""
from __future__ import annotations

import numpy as np
import pytest

import linearize
from mpc_wt.simulation.scenario import FieldMemo, Scenario, lidar_field, make_wind


@pytest.fixture(scope="module")
def turbine() -> linearize.Turbine:
    return linearize.load_turbine()


def _same(a: np.ndarray, b: np.ndarray) -> bool:
    return a.shape == b.shape and a.dtype == b.dtype and np.array_equal(a, b)


def test_a_kept_field_is_the_one_a_new_generation_makes(turbine: linearize.Turbine) -> None:
    sc = Scenario(13.0, "B", 4, duration=20.0)
    memo = FieldMemo()
    wind, field = make_wind(turbine, sc, "u", fields=memo)
    again, field2 = make_wind(turbine, sc, "u", fields=memo)
    assert again is wind and field2 is field and (memo.hits, memo.misses) == (1, 1)
    fresh, fresh_field = make_wind(turbine, sc, "u")
    assert _same(fresh.u, wind.u) and _same(fresh_field.u, field.u)
    # another seed, turbulence or component set is another field
    other, _ = make_wind(turbine, Scenario(13.0, "B", 5, duration=20.0), "u", fields=memo)
    assert not _same(other.u, wind.u) and memo.misses == 2
    make_wind(turbine, sc, "uvw", fields=memo)
    assert memo.misses == 3
    # the LIDAR's evolved field, 54 m upstream
    seen = lidar_field(turbine, sc, field, 54.0, fields=memo)
    assert lidar_field(turbine, sc, field, 54.0, fields=memo) is seen
    new = lidar_field(turbine, sc, fresh_field, 54.0)
    assert all(_same(getattr(new, c), getattr(seen, c)) for c in "uvw")
    assert not _same(lidar_field(turbine, sc, field, 80.0, fields=memo).u, seen.u)
    # the kept arrays are read-only: no run can change another's wind
    with pytest.raises(ValueError):
        wind.u[0, 0, 0] = 1.0


def test_the_memo_keeps_within_its_limit_oldest_out(turbine: linearize.Turbine) -> None:
    probe = FieldMemo()
    wind, field = make_wind(turbine, Scenario(9.0, "A", 1, duration=20.0), "u", fields=probe)
    size = probe.nbytes
    # at least the plant's wind, at most it and every component of the field
    assert wind.u.nbytes <= size <= wind.u.nbytes + sum(
        getattr(field, c).nbytes for c in "uvw")
    memo = FieldMemo(max_bytes=1.5 * size)
    for seed in (1, 2, 1):
        make_wind(turbine, Scenario(9.0, "A", seed, duration=20.0), "u", fields=memo)
    # seed 2 pushed seed 1 out: the third call made it again
    assert (len(memo), memo.misses, memo.hits) == (1, 3, 0)
    assert 0 < memo.nbytes <= 1.5 * size
    none = FieldMemo(max_bytes=0)
    make_wind(turbine, Scenario(9.0, "A", 1, duration=20.0), "u", fields=none)
    assert len(none) == 0
    # deterministic and steady winds are not kept (nothing to save)
    make_wind(turbine, Scenario(9.0, condition="eog"), "u", fields=memo)
    assert memo.misses == 3


@pytest.mark.parametrize("bad", [-1.0, float("nan"), float("inf")])
def test_a_bad_limit_is_named(bad: float) -> None:
    with pytest.raises(ValueError, match="max_bytes"):
        FieldMemo(max_bytes=bad)


def test_runs_without_a_memo_share_the_process_fields(turbine: linearize.Turbine) -> None:
    """Two controllers run on one case without a memo: the second meets the field the first
    made (the process's ``DEFAULT_FIELDS``), and its run equals, bit for bit, one on a field
    made afresh (``FieldMemo(0)`` keeps none)."""
    from mpc_wt.run import run_controller
    from mpc_wt.simulation.scenario import DEFAULT_FIELDS

    sc = Scenario(13.0, "B", 7, duration=20.0)
    run_controller(turbine, "baseline", sc)
    hits, misses = DEFAULT_FIELDS.hits, DEFAULT_FIELDS.misses
    shared = run_controller(turbine, "derate90", sc)
    assert (DEFAULT_FIELDS.hits, DEFAULT_FIELDS.misses) == (hits + 1, misses)
    fresh = run_controller(turbine, "derate90", sc, fields=FieldMemo(0))
    assert (DEFAULT_FIELDS.hits, DEFAULT_FIELDS.misses) == (hits + 1, misses)
    assert _same(shared.z, fresh.z) and _same(shared.u, fresh.u)


def test_a_run_that_does_not_fit_first_releases_the_kept_fields(
        turbine: linearize.Turbine, monkeypatch, caplog) -> None:
    """With more memory than the run needs, the kept fields stay; with less, they are released
    (logged, with their size) before the run is refused, naming the memory it needs."""
    import logging

    from mpc_wt.errors import RunTooLargeError
    from mpc_wt.run import build_controller
    from mpc_wt.simulation import memory

    memo = FieldMemo()
    make_wind(turbine, Scenario(11.0, "A", 2, duration=20.0), "u", fields=memo)
    monkeypatch.setattr(memory, "available_memory", lambda: 1e12)
    build_controller(turbine, "baseline", Scenario(11.0, "A", 3, duration=20.0), fields=memo)
    assert len(memo) == 2
    held = memo.nbytes
    monkeypatch.setattr(memory, "available_memory", lambda: 1e6)
    with caplog.at_level(logging.INFO, logger="mpc_wt.run"), \
            pytest.raises(RunTooLargeError, match="needs about"):
        build_controller(turbine, "baseline", Scenario(11.0, "A", 4, duration=20.0),
                         fields=memo)
    assert len(memo) == 0
    assert f"releasing {held / 1e6:.0f} MB of kept wind fields" in caplog.text

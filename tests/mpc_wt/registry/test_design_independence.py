"""A controller's design depends on the turbine and its options only.

Each advanced kind is built for cases at 5, 11, 18 and 25 m/s (different seeds, turbulence
classes, conditions), the whole controller made anew for each (the parts it is made of -- a
model family, the TS LMIs, a C_P table -- kept in the cache under keys of the turbine and the
options, which nothing of a case can enter): the designs' digests (every gain, model and QP
array they hold) are equal. A build that reads the case's wind or field fails with
:class:`~mpc_wt.errors.CaseDataError`. A design reused from the cache runs a case exactly as a
fresh one (``reset()`` forgets everything of the case before).
"""
from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import linearize
from mpc_wt.errors import CaseDataError
from mpc_wt.registry.context import Built, DesignCache, design_digest
from mpc_wt.registry.registry import _KINDS, register
from mpc_wt.run import build_controller, design_controller, run_controller
from mpc_wt.simulation.scenario import Scenario

ADVANCED = ["mpc", "mpc-lidar", "mpc-collective", "lqr-pio", "ts", "baseline+lidar-ff", "ibc",
            "coleman-ipc"]

#: four cases that share nothing a design could read
CASES = [Scenario(5.0, "C", 11, 5.0), Scenario(11.0, "B", 23, 5.0),
         Scenario(18.0, "A", 37, 5.0, shear_exponent=0.1),
         Scenario(25.0, "steady", 1, 5.0, condition="nwp")]


@pytest.fixture(scope="module")
def turbine() -> linearize.Turbine:
    return linearize.load_turbine()


@pytest.mark.parametrize("kind", ADVANCED)
def test_the_design_is_the_same_for_every_case(turbine: linearize.Turbine, kind: str) -> None:
    digests, made = set(), set()
    cache = DesignCache()
    for sc in CASES:
        cache.clear("built")
        built, _, _ = build_controller(turbine, kind, sc, cache=cache)
        assert built.meta["design"]["new"] is True
        digests.add(design_digest(built.designed))
        made.add(built.meta["design"]["digest"])
    assert cache.made["built"] == len(CASES)
    assert len(digests) == 1, f"{kind}: {len(digests)} different designs for {len(CASES)} cases"
    assert made == digests


def test_the_digest_sees_a_design_change(turbine: linearize.Turbine) -> None:
    """The digest is not blind: other options give another design."""
    a, _ = _design(turbine, "ibc", {"loop_gain_1p": 0.8})
    b, _ = _design(turbine, "ibc", {})
    c, _ = _design(turbine, "coleman-ipc", {"crossover_rad_s": 0.3})
    d, _ = _design(turbine, "coleman-ipc", {})
    assert a != b and c != d and b == _design(turbine, "ibc", {})[0]


def test_the_digest_does_not_depend_on_where_the_turbine_was_read_from(
        turbine: linearize.Turbine, tmp_path) -> None:
    """The same turbine data read from another folder (an install elsewhere, a worktree) give
    the same design digest, so a campaign resumed from there does not compute its cases again;
    a turbine whose data differ (the generator's torque limit 1 % lower) gives another."""
    import shutil

    src = Path(turbine.source).parent
    shutil.copytree(src, tmp_path / "copy")
    moved = linearize.load_turbine(tmp_path / "copy" / Path(turbine.source).name)
    assert moved.source != turbine.source
    gen = dataclasses.replace(turbine.generator,
                              max_torque=0.99 * turbine.generator.max_torque)
    changed = dataclasses.replace(turbine, generator=gen)
    digests = [_design(t, "ibc", {})[0] for t in (turbine, moved, changed)]
    assert digests[0] == digests[1] != digests[2]


def _design(turbine: linearize.Turbine, kind: str, options: dict) -> tuple[str, Built]:
    from mpc_wt.run import design_controller

    built, _ = design_controller(turbine, kind, options, cache=DesignCache())
    return design_digest(built.designed), built


@pytest.mark.parametrize("reads", ["scenario", "field", "op"])
def test_a_build_that_reads_the_case_fails(turbine: linearize.Turbine, reads: str) -> None:
    from mpc_wt.registry import Options

    @dataclasses.dataclass(frozen=True)
    class NoOptions(Options):
        pass

    name = f"peek-{reads}"

    def build(ctx, opts):
        getattr(ctx, reads)
        raise AssertionError("unreachable: the case was readable")

    register(name, NoOptions, summary="reads the case")(build)
    try:
        with pytest.raises(CaseDataError, match=f"BuildContext.{reads}: a controller's design "
                                                "depends on the turbine"):
            build_controller(turbine, name, Scenario(12.0, "steady", 1, 2.0), cache=DesignCache())
    finally:
        _KINDS.pop(name, None)


@pytest.mark.parametrize("kind", ["mpc", "baseline+lidar-ff"])
def test_a_reused_design_runs_as_a_fresh_one(turbine: linearize.Turbine, kind: str) -> None:
    """Run case A, then case B with the same design from the cache: B equals B run with a fresh
    design, bit for bit (reset forgets the schedule, the estimators, the filters and the
    LIDAR's history). The fresh design is a new controller made from the same parts."""
    a = Scenario(16.0, "A", 5, 4.0)
    b = Scenario(13.0, "B", 6, 4.0)
    cache = DesignCache()
    run_controller(turbine, kind, a, cache=cache)
    reused = run_controller(turbine, kind, b, cache=cache)
    cache.clear("built")
    fresh = run_controller(turbine, kind, b, cache=cache)
    assert reused.meta["design"]["new"] is False and fresh.meta["design"]["new"] is True
    assert cache.made["built"] == 2
    for ch in ("pitch_1", "gen_torque", "rotor_speed"):
        np.testing.assert_array_equal(reused.channel(ch), fresh.channel(ch))


def test_the_design_does_not_depend_on_the_processs_blas_threads(
        turbine: linearize.Turbine) -> None:
    """A campaign's workers run numpy's and scipy's BLAS on one thread, the process that
    checks the finished cases' designs on as many as it has: a multi-threaded BLAS sums in
    another order, and before designs were made on one thread the IBC design's digest (like
    the MPC's and LQR-PIO's) differed between the two, so a resumed campaign computed every
    case of those kinds again. Made with the BLAS on one and on two threads, the designs are
    the same."""
    from threadpoolctl import threadpool_limits

    digests = set()
    for n in (1, 2):
        with threadpool_limits(limits=n):
            built, _ = design_controller(turbine, "ibc", cache=DesignCache())
        digests.add(built.meta["design"]["digest"])
    assert len(digests) == 1


def test_the_cache_drops_the_design_used_longest_ago(turbine: linearize.Turbine) -> None:
    """With room for two: A, B, A again (a hit), then C drops B, not A; a campaign worker
    that runs nine kinds in turn keeps each kind's design (the default room is 64)."""
    cache = DesignCache(max_items=2)
    made = []

    def make(name):
        return lambda: made.append(name) or name

    for name in ("A", "B", "A", "C", "A", "B"):
        assert cache.get(turbine, ("part", name), make(name)) == name
    assert made == ["A", "B", "C", "B"] and cache.hits == 2
    assert DesignCache().max_items == 64

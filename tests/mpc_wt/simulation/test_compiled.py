"""The closed loop compiled with the plant around the baseline's shipped law
(mpc_wt.simulation.compiled) is the Python loop of simulate_closed_loop, operation for
operation: the same states, inputs, outputs, signals, counts and errors."""
from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

import linearize
from mpc_wt.controllers.baseline import BaselineController, tune_baseline
from mpc_wt.run import build_controller, law_controller
from mpc_wt.simulation.loop import SimulationDivergedError, simulate_closed_loop
from mpc_wt.simulation.scenario import Scenario


def _both(params, make, wind, duration, op, **kw):
    out = []
    for compiled in (True, False):
        ctl = make()
        out.append((simulate_closed_loop(params, ctl, wind, duration, x0=op.x, u0=op.u,
                                         compiled=compiled, **kw), ctl))
    return out


def _same(a, b) -> None:
    # the same operations in the same order: equal to rounding. Measured: bit for bit (0.0)
    # on every channel; the bound allows an FMA contraction in another LLVM (1e-12 relative)
    for name in ("x", "u", "z"):
        ra, rb = getattr(a, name), getattr(b, name)
        assert ra.shape == rb.shape
        assert_allclose(ra, rb, rtol=1e-12, atol=1e-12 * np.abs(rb).max())
    assert sorted(a.controller) == sorted(b.controller)
    for k, v in b.controller.items():
        assert_allclose(a.controller[k], v, rtol=1e-12, atol=1e-12 * np.abs(v).max())
    assert a.meta.get("commands_clipped") == b.meta.get("commands_clipped")


def _baseline(turbine, gains, dt=1.0 / 80.0):
    return law_controller(BaselineController(turbine, gains, dt=dt), "baseline", turbine)


@pytest.mark.parametrize("wind, ratio", [(18.0, 1), (8.0, 1), (11.5, 2)])
def test_compiled_baseline_loop_is_the_python_loop(turbine: linearize.Turbine,
                                                   params: linearize.PlantParams,
                                                   wind: float, ratio: int) -> None:
    """Turbulent 20 s runs in region 3, region 2 and around rated (there with the controller
    at half the plant's rate): both loops give the same run."""
    gains = tune_baseline(turbine)
    _, op, w = build_controller(turbine, "baseline", Scenario(wind, "A", 3, 20.0))
    dt = ratio / 80.0
    (a, ca), (b, cb) = _both(params, lambda: _baseline(turbine, gains, dt), w, 20.0, op,
                             controller_dt=dt)
    assert a.meta["loop"] == "compiled" and b.meta["loop"] == "python"
    _same(a, b)
    assert np.ptp(a.u[:, 0]) > 1e-3 or wind < 11.0       # the pitch loop acted above rated
    assert ca.signals == pytest.approx(cb.signals, rel=1e-12)


def test_compiled_loop_diverges_like_the_python_loop(turbine: linearize.Turbine,
                                                     params: linearize.PlantParams) -> None:
    """A 90 m/s wind on blades at zero pitch bends a blade beyond its envelope before the
    pitch loop can feather it (measured: flap_1 at t = 1.66 s): both loops stop at the same
    step, name the same state and keep the same samples."""
    gains = tune_baseline(turbine)
    op = linearize.trim(turbine, 25.0)
    x0 = op.x.copy()
    x0[5:8] = 0.0
    errs = []
    for compiled in (True, False):
        with pytest.raises(SimulationDivergedError, match="state 'flap_") as exc:
            simulate_closed_loop(params, _baseline(turbine, gains),
                                 linearize.SteadyWind(90.0), 20.0, x0=x0, u0=op.u,
                                 compiled=compiled)
        errs.append(exc.value)
    assert str(errs[0]) == str(errs[1])
    assert errs[0].partial.t.size == errs[1].partial.t.size > 10
    _same(errs[0].partial, errs[1].partial)

"""The closed loop: bad controllers and commands, divergence, controller periods, the LIDAR in
the loop and the wind the harness reads.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

import lidar
import linearize
from mpc_wt.simulation.loop import SimulationDivergedError, simulate_closed_loop


class _NaNController:
    signals: dict = {}

    def reset(self) -> None:
        pass

    def step(self, t, meas):
        return (np.array([0.1, 0.1, np.nan]), 40000.0) if t > 0.5 else (np.zeros(3), 40000.0)


class _Fixed:
    """A controller that always commands the same pitch [rad] and generator torque [N m]."""

    signals: dict = {}

    def __init__(self, pitch: float = 0.0, torque: float = 0.0) -> None:
        self.pitch, self.torque = pitch, torque

    def reset(self) -> None:
        pass

    def step(self, t, meas):
        return np.full(3, self.pitch), self.torque


class _PreviewProbe:
    def __init__(self) -> None:
        self.signals: dict = {}
        self.seen: list = []

    def reset(self) -> None:
        self.seen = []

    def step(self, t, meas):
        self.seen.append((t, meas["preview"]))
        return np.full(3, 0.26), 43093.55


def test_controller_returning_nan(turbine: linearize.Turbine,
                                  params: linearize.PlantParams) -> None:
    op = linearize.trim(turbine, 12.0)
    with pytest.raises(ValueError, match=r"controller returned pitch .* at t = 0.5125 s"):
        simulate_closed_loop(params, _NaNController(), linearize.SteadyWind(12.0), 2.0,
                             x0=op.x, u0=op.u)


def test_diverging_closed_loop_keeps_the_partial_result(turbine: linearize.Turbine,
                                                        params: linearize.PlantParams) -> None:
    op = linearize.trim(turbine, 25.0)
    x0 = op.x.copy()
    x0[5:8] = 0.0
    with pytest.raises(SimulationDivergedError, match=r"state '(rotor|gen)_speed'") as exc:
        simulate_closed_loop(params, _Fixed(), linearize.SteadyWind(25.0), 300.0,
                             x0=x0, u0=op.u)
    assert exc.value.partial.t.size > 100 and np.all(np.isfinite(exc.value.partial.z))


def test_controller_period_must_divide(turbine: linearize.Turbine,
                                      params: linearize.PlantParams) -> None:
    op = linearize.trim(turbine, 12.0)
    with pytest.raises(ValueError, match="whole multiple of dt"):
        simulate_closed_loop(params, _Fixed(), linearize.SteadyWind(12.0), 1.0, x0=op.x,
                             u0=op.u, controller_dt=0.03)


def test_out_of_range_commands_are_recorded(turbine: linearize.Turbine,
                                            params: linearize.PlantParams,
                                            caplog: pytest.LogCaptureFixture) -> None:
    op = linearize.trim(turbine, 14.0)
    with caplog.at_level("WARNING"):
        r = simulate_closed_loop(params, _Fixed(math.radians(120.0), 40000.0),
                                 linearize.SteadyWind(14.0), 1.0, x0=op.x, u0=op.u)
    assert r.meta["commands_clipped"] == 80
    assert "out of the actuator range" in caplog.text
    assert r.x[:, 5].max() <= math.radians(90.0) + 1e-9


def test_lidar_preview_in_the_loop(turbine: linearize.Turbine,
                                   params: linearize.PlantParams) -> None:
    # the controller receives a (15, 3) per-blade preview from a simulated LIDAR measuring the
    # field the plant meets; idealized LIDAR + frozen field: it is the wind each blade meets
    from mpc_wt.simulation.preview import LidarPreview

    f = lidar.generate_field(lidar.TurbulenceSpec(18.0, "A", duration=40.0), 5)
    gw = linearize.GridWind(t=f.t, y=f.y, z=f.z, u=np.maximum(f.u, 0.0))
    op = linearize.trim(turbine, 18.0)
    probe = _PreviewProbe()
    lid = lidar.CWLidar(63.0, range_weighting=False, los_error=False)
    sensor = lidar.LidarSensor(lid, field=f)
    r = simulate_closed_loop(params, probe, gw, 20.0, x0=op.x, u0=op.u, controller_dt=0.1,
                             preview=LidarPreview(sensor, 15, 0.1, preview_time=3.0))
    t, p = next((tt, pp) for tt, pp in probe.seen if tt >= 15.0)   # steps inside the run
    assert p.blade.shape == (15, 3) and p.measured.all()
    # exact plumbing (the preview time fixed at the field's D / V): each step's preview is the
    # wind at the position predicted when it was measured (t_m = t - T_p): azimuth psi(t_m) +
    # omega(t_m) T_p, at 75 % span, at time t
    tp = 54.0 / 18.0
    tm = p.t - tp
    psi_m = np.interp(tm, r.t, r.x[:, 16])
    om_m = np.interp(tm, r.t, r.x[:, 2])
    predicted = lidar.blade_effective_wind(f, p.t, psi_m + om_m * tp, lid.radius)
    assert_allclose(p.blade, predicted, rtol=0, atol=1e-9)
    # with the preview time the LIDAR measures (its mean wind since the start, within 4 % of
    # the field's 18 m/s over these 20 s) the preview is the same wind moved by that error
    measured = LidarPreview(lidar.LidarSensor(lid, field=f), 15, 0.1)
    for k in range(200):
        measured(k * 0.1, float(np.interp(k * 0.1, r.t, r.x[:, 16])),
                 float(np.interp(k * 0.1, r.t, r.x[:, 2])))
    assert measured.preview_time == pytest.approx(tp, rel=0.04)
    # the blade actually arrives where the rotor turned to; with fixed pitch and torque its
    # speed drifts over T_p, so the preview is only as good as that prediction (here < 2 m/s)
    truth = lidar.blade_effective_wind(f, p.t, np.interp(p.t, r.t, r.x[:, 16]), lid.radius)
    assert np.abs(p.blade - truth).max() < 2.5


def test_a_rotor_driven_backwards_is_reported_as_divergence(turbine: linearize.Turbine,
                                                            params: linearize.PlantParams) -> None:
    # feathered blades and full generator torque stop the rotor and drive it backwards: the
    # envelope allows at most -10 % of rated speed (found when an unstable observer loop ran at
    # -0.26 rad/s unreported)
    op = linearize.trim(turbine, 12.0)
    with pytest.raises(SimulationDivergedError,
                       match=r"state '(rotor|gen)_speed' = -\d") as exc:
        simulate_closed_loop(params, _Fixed(math.radians(90.0), 43093.55),
                             linearize.SteadyWind(12.0), 120.0, x0=op.x, u0=op.u)
    assert exc.value.partial.x[:, 2].min() > -0.2


@settings(max_examples=60, deadline=None)
@given(dt=st.floats(0.01, 0.5), n=st.integers(2, 400), t0=st.floats(-5.0, 5.0),
       q=st.lists(st.floats(-10.0, 250.0), min_size=1, max_size=20), seed=st.integers(0, 999))
def test_hub_wind_reads_the_field_as_linear_interpolation(dt, n, t0, q, seed) -> None:
    """The hub wind handed to controllers is read by index on a uniform grid; it is
    numpy's linear interpolation of the hub column (held at the ends) at any time."""
    from mpc_wt.simulation.loop import _hub_wind

    rng = np.random.default_rng(seed)
    t = t0 + dt * np.arange(n)
    y, z = np.linspace(-80, 80, 5), np.linspace(10, 170, 5)
    u = rng.normal(10, 2, (n, 5, 5))
    gw = linearize.GridWind(t=t, y=y, z=z, u=u)
    f = _hub_wind(gw, 90.0)
    hub = gw.u[:, 2, 2].astype(float)           # the column as stored (float32)
    for tq in q:
        assert f(tq) == pytest.approx(np.interp(tq, t, hub), rel=1e-12, abs=1e-12)


def test_first_run_says_it_compiles_and_shows_no_eta(monkeypatch) -> None:
    """A process's first closed loop: the bar says the kernels compile and has no ETA (it would
    be wrong while numba compiles); after the first block it names the run and shows one."""
    from mpc_wt.simulation import loop as lp

    monkeypatch.setattr(lp, "_WARM", [False])
    bar = lp._progress_bar(1600, "simulate baseline", True)
    assert bar.desc.startswith("loading kernels (compiled once per machine)")
    assert "remaining" not in bar.bar_format
    bar.update(800)
    assert bar.desc.startswith("simulate baseline") and bar.bar_format is None
    bar.close()
    again = lp._progress_bar(1600, "simulate mpc", True)
    assert again.desc.startswith("simulate mpc")
    again.close()


def test_torque_pinned_at_its_maximum_is_counted(turbine: linearize.Turbine,
                                                 params: linearize.PlantParams) -> None:
    """A controller asking for twice the generator's maximum torque at 14 m/s for 2 s: the
    applied torque climbs from the trim's at the generator's rate limit and sits at the
    maximum from then on. By hand: sample k holds the trim's torque plus k rate steps, so the
    samples from ceil((max - trim) / (rate * dt)) on, of 161, are pinned; the run's warnings
    say so."""
    from mpc_wt.run import run_warnings

    op = linearize.trim(turbine, 14.0)
    g = turbine.generator
    r = simulate_closed_loop(params, _Fixed(op.pitch_rad, 2.0 * g.max_torque),
                             linearize.SteadyWind(14.0), 2.0, x0=op.x, u0=op.u)
    climb = math.ceil((g.max_torque - op.gen_torque) / (g.max_torque_rate / 80.0))
    assert r.meta["torque_pinned_steps"] == 161 - climb
    assert any(w.startswith("the generator torque sat at its maximum in "
                            f"{161 - climb} of 161 steps") for w in run_warnings(r))
    calm = simulate_closed_loop(params, _Fixed(op.pitch_rad, op.gen_torque),
                                linearize.SteadyWind(14.0), 1.0, x0=op.x, u0=op.u)
    assert calm.meta["torque_pinned_steps"] == 0 and run_warnings(calm) == []


def test_a_moment_at_the_torque_limit_is_counted_not_warned() -> None:
    """A run warns of the pinned torque only above 1 % of its steps: 10 of 1001 steps are
    counted and not warned of, 11 are warned of (a constant-power law touches the limit for a
    moment in gusts: the baseline at 18 m/s, class A, 0.3 % of 600 s)."""
    from types import SimpleNamespace

    from mpc_wt.run import run_warnings

    def res(n):
        return SimpleNamespace(meta={"torque_pinned_steps": n}, t=np.arange(1001) / 80.0,
                               controller={})
    assert run_warnings(res(10)) == []
    assert run_warnings(res(11)) == ["the generator torque sat at its maximum in 11 of 1001 "
                                     "steps (1.1 %)"]


def test_electrical_power_above_the_grids_bound_is_warned() -> None:
    """Hand-made: 1001 steps at 80 Hz of 5 MW with 40 steps at 5.6 MW (1.12 x rated, from
    t = 5 s) warn once, with the count, the time above and the peak; 5.5 MW (1.1 x) is within
    the bound; without the rated power the power is not checked."""
    from types import SimpleNamespace

    from mpc_wt.run import POWER_BOUND, run_warnings

    t = np.arange(1001) / 80.0
    p = np.full(t.size, 5e6)
    p[400:440] = 5.6e6

    def res(power):
        return SimpleNamespace(meta={}, t=t, controller={}, channels=lambda: ["gen_power"],
                               channel=lambda name: power)
    assert POWER_BOUND == 1.1
    assert run_warnings(res(p), 5e6) == ["the electrical power passed 1.1 x rated in 40 of 1001 "
                                         "steps (0.5 s); largest 1.120 x rated at t = 5 s"]
    assert run_warnings(res(np.minimum(p, 5.5e6)), 5e6) == []
    assert run_warnings(res(p)) == []

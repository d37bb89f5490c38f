"""Baseline controller: tuning against the published gains, closed-loop behaviour on the plant,
the harness's results and its errors."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

import lidar
import linearize
from mpc_wt.baseline import BaselineController, tune_baseline
from mpc_wt.simulate import (ClosedLoopResult, ResultFileError, SimulationDivergedError,
                             simulate_closed_loop)


@pytest.fixture(scope="module")
def gains(turbine: linearize.Turbine):
    return tune_baseline(turbine)


def test_gains_match_the_published_baseline(gains) -> None:
    # published: DISCON.F90 (Jonkman's baseline, report sec. 7.4): PC_KP = 0.01882681 s,
    # PC_KI = 0.008068634, PC_KK = 0.1099965 rad (6.302336 deg), dP/dtheta at zero pitch
    # -25.52e6 W/rad, VS_Rgn2K = 2.332287 N m/(rad/s)^2. Issue 5 asked for 20 %; measured:
    # KP and KI +4.6 %, theta_K -9.7 %, dP/dtheta_0 -5.0 %, K_opt -2.5 % (our frozen-wake
    # sensitivities are within 8.3 % of the report's, the fit's points differ, and the rotor
    # inertia from the blade table is 0.6 % below the report's). Bounds: the measured value
    # plus about 1.5 points (the README states both).
    assert_allclose(gains.kp, 0.01882681, rtol=0.06)
    assert_allclose(gains.ki, 0.008068634, rtol=0.06)
    assert_allclose(gains.theta_k_rad, math.radians(6.302336), rtol=0.11)
    assert_allclose(gains.dpdtheta_0, -25.52e6, rtol=0.065)
    assert_allclose(gains.k_opt, 2.332287, rtol=0.035)


def test_pole_placement_formula() -> None:
    # analytic: with the report's own numbers (J = 43,784,725 kg m^2, dP/dtheta = -25.52e6,
    # Omega = 12.1 rpm, N = 97, 0.6 rad/s, 0.7) the formulas give DISCON's KP and KI
    j, om = 43784725.0, 12.1 * math.pi / 30
    kp = 2 * j * om * 0.7 * 0.6 / (97 * 25.52e6)
    ki = j * om * 0.36 / (97 * 25.52e6)
    assert_allclose([kp, ki], [0.01882681, 0.008068634], rtol=2e-4)
    # (the tuning's own gains are checked against DISCON's in the test above; re-deriving them
    # here from its own inertia and sensitivity would test the code against itself)


def _field(v: float, turb, seed: int) -> tuple[linearize.GridWind, lidar.WindField]:
    f = lidar.generate_field(lidar.TurbulenceSpec(v, turb, duration=610.0), seed)
    return linearize.GridWind(t=f.t, y=f.y, z=f.z, u=np.maximum(f.u, 0.0)), f


@pytest.fixture(scope="module")
def run18(turbine: linearize.Turbine, params: linearize.PlantParams, gains):
    gw, _ = _field(18.0, "A", 1)
    op = linearize.trim(turbine, 18.0)
    return simulate_closed_loop(params, BaselineController(turbine, gains), gw, 600.0,
                                x0=op.x, u0=op.u)


def test_region3_closed_loop(run18: ClosedLoopResult) -> None:
    # issue 5: 18 m/s, turbulent (class A): rated power held, generator speed std below 5 %
    # of rated (first 60 s of start-up transient left out). Measured: mean power 0.005 % off
    # 5 MW, speed std 3.5 %; bounds 0.05 % and 4 % (the README states both).
    late = run18.t > 60.0
    assert_allclose(run18.channel("gen_power")[late].mean(), 5e6, rtol=5e-4)
    assert run18.channel("gen_speed")[late].std() < 0.04 * 122.9096


def test_no_actuator_limit_violated(run18: ClosedLoopResult, turbine: linearize.Turbine) -> None:
    pitch = run18.x[:, 5:8]
    dt = run18.t[1] - run18.t[0]
    pa = turbine.pitch_actuator
    assert pitch.min() >= pa.min_pitch_rad - 1e-9 and pitch.max() <= pa.max_pitch_rad + 1e-9
    assert np.abs(np.diff(pitch, axis=0)).max() / dt <= pa.max_rate_rad_s * (1 + 1e-6)
    tq = run18.channel("gen_torque")
    g = turbine.generator
    assert tq.max() <= g.max_torque + 1e-6 and tq.min() >= g.min_torque - 1e-6
    assert np.abs(np.diff(tq)).max() / dt <= g.max_torque_rate * (1 + 1e-9)


def test_region2_tracks_optimal_tsr(turbine: linearize.Turbine, params: linearize.PlantParams,
                                    gains) -> None:
    # issue 5: at 8 m/s the turbine tracks the optimal tip-speed ratio (mean within 3 %),
    # here in Do et al.'s region-II turbulence (12 %); the tip-speed ratio uses the rotor-
    # averaged wind. (In class A, 23 % at 8 m/s, the mean is 10 % above optimal: lulls hold the
    # rotor at its minimum speed and gusts are not followed.)
    gw, f = _field(8.0, 0.12, 3)
    op = linearize.trim(turbine, 8.0)
    r = simulate_closed_loop(params, BaselineController(turbine, gains), gw, 600.0,
                             x0=op.x, u0=op.u)
    late = r.t > 60.0
    rews = np.interp(r.t[late], f.t, lidar.rotor_effective_wind(f, 63.0))
    tsr = r.channel("rotor_speed")[late].mean() * 63.0 * math.cos(math.radians(2.5)) / rews.mean()
    # measured 1.4 % above optimal; bound 2 % (issue 5 asked for 3 %; the README states both)
    assert_allclose(tsr, gains.info["tsr_opt"], rtol=0.02)


def test_result_round_trip(run18: ClosedLoopResult, tmp_path: Path) -> None:
    p = run18.save(tmp_path / "run.nc")
    back = ClosedLoopResult.load(p)
    assert_allclose(back.z, run18.z, rtol=0, atol=0)
    assert_allclose(back.channel("pitch_integral"), run18.channel("pitch_integral"), rtol=0)
    assert back.meta["software_version"] == run18.meta["software_version"]
    import xarray as xr     # self-describing: readable without mpc-wt

    with xr.open_dataset(p, engine="scipy") as ds:
        assert ds["gen_power"].attrs["units"] == "W" and ds["time"].attrs["units"] == "s"


def test_broken_result_files(run18: ClosedLoopResult, tmp_path: Path) -> None:
    p = run18.save(tmp_path / "run.nc")
    raw = p.read_bytes()
    (tmp_path / "cut.nc").write_bytes(raw[: len(raw) // 3])
    with pytest.raises(ResultFileError, match="not a readable result file"):
        ClosedLoopResult.load(tmp_path / "cut.nc")
    with pytest.raises(ResultFileError, match="file not found"):
        ClosedLoopResult.load(tmp_path / "none.nc")
    with pytest.raises(KeyError, match=r"no channel 'gen_powr'"):
        run18.channel("gen_powr")


class _NaNController:
    signals: dict = {}

    def reset(self) -> None:
        pass

    def step(self, t, meas):
        return (np.array([0.1, 0.1, np.nan]), 40000.0) if t > 0.5 else (np.zeros(3), 40000.0)


def test_controller_returning_nan(turbine: linearize.Turbine,
                                  params: linearize.PlantParams) -> None:
    op = linearize.trim(turbine, 12.0)
    with pytest.raises(ValueError, match=r"controller returned pitch .* at t = 0.5125 s"):
        simulate_closed_loop(params, _NaNController(), linearize.SteadyWind(12.0), 2.0,
                             x0=op.x, u0=op.u)


class _Fixed:
    """A controller that always commands the same pitch [rad] and generator torque [N m]."""

    signals: dict = {}

    def __init__(self, pitch: float = 0.0, torque: float = 0.0) -> None:
        self.pitch, self.torque = pitch, torque

    def reset(self) -> None:
        pass

    def step(self, t, meas):
        return np.full(3, self.pitch), self.torque


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


def test_shaft_bending_channel(run18: ClosedLoopResult) -> None:
    f = run18.z[:, 10:13]
    assert_allclose(run18.channel("shaft_bending_blade1"), f[:, 0] - 0.5 * (f[:, 1] + f[:, 2]),
                    rtol=0, atol=0)


def test_result_from_another_version(run18: ClosedLoopResult, tmp_path: Path) -> None:
    import xarray as xr

    p = run18.save(tmp_path / "run.nc")
    with xr.open_dataset(p, engine="scipy") as ds:
        ds = ds.load()
    ds.attrs["schema_version"] = 99
    ds.to_netcdf(tmp_path / "v99.nc", engine="scipy")
    with pytest.raises(ResultFileError, match=r"schema_version must be 1, got 99"):
        ClosedLoopResult.load(tmp_path / "v99.nc")


class _PreviewProbe:
    def __init__(self) -> None:
        self.signals: dict = {}
        self.seen: list = []

    def reset(self) -> None:
        self.seen = []

    def step(self, t, meas):
        self.seen.append((t, meas["preview"]))
        return np.full(3, 0.26), 43093.55


def test_lidar_preview_in_the_loop(turbine: linearize.Turbine,
                                   params: linearize.PlantParams) -> None:
    # the controller receives a (15, 3) per-blade preview from a simulated LIDAR measuring the
    # field the plant meets; idealized LIDAR + frozen field: it is the wind each blade meets
    from mpc_wt.simulate import LidarPreview

    f = lidar.generate_field(lidar.TurbulenceSpec(18.0, "A", duration=40.0), 5)
    gw = linearize.GridWind(t=f.t, y=f.y, z=f.z, u=np.maximum(f.u, 0.0))
    op = linearize.trim(turbine, 18.0)
    probe = _PreviewProbe()
    lid = lidar.CWLidar(63.0, range_weighting=False, los_error=False)
    r = simulate_closed_loop(params, probe, gw, 20.0, x0=op.x, u0=op.u, controller_dt=0.1,
                             preview=LidarPreview(lid, f, 15, 0.1))
    t, p = next((tt, pp) for tt, pp in probe.seen if tt >= 15.0)   # steps inside the run
    assert p.blade.shape == (15, 3) and p.measured.all()
    # exact plumbing: each step's preview is the wind at the position predicted when it was
    # measured (t_m = t - T_p): azimuth psi(t_m) + omega(t_m) T_p, at 75 % span, at time t
    tp = 54.0 / 18.0
    tm = p.t - tp
    psi_m = np.interp(tm, r.t, r.x[:, 16])
    om_m = np.interp(tm, r.t, r.x[:, 2])
    predicted = lidar.blade_effective_wind(f, p.t, psi_m + om_m * tp, lid.radius)
    assert_allclose(p.blade, predicted, rtol=0, atol=1e-9)
    # the blade actually arrives where the rotor turned to; with fixed pitch and torque its
    # speed drifts over T_p, so the preview is only as good as that prediction (here < 2 m/s)
    truth = lidar.blade_effective_wind(f, p.t, np.interp(p.t, r.t, r.x[:, 16]), lid.radius)
    assert np.abs(p.blade - truth).max() < 2.5


def test_torque_law_is_continuous_and_monotone(turbine: linearize.Turbine, gains) -> None:
    # regions 1.5 -> 2 -> 2.5 -> 3 meet without jumps below rated (the 2 -> 2.5 switch is where
    # K w^2 meets the 2.5 line, as DISCON's VS_TrGnSp), and the torque rises with speed
    c = BaselineController(turbine, gains)
    w = np.linspace(60.0, c.w_rated - 1e-6, 20001)
    tq = np.array([c.torque(x, 0.0) for x in w])
    assert np.all(np.diff(tq) >= -1e-9)
    # no jump: every step is bounded by the steepest segment's slope (region 2.5) times the step
    steep = max(c.slope25, c.slope15, 2 * gains.k_opt * c.w_rated)
    assert np.max(np.abs(np.diff(tq))) <= steep * (w[1] - w[0]) * (1 + 1e-9)
    assert_allclose(c.torque(c.w_trans, 0.0), gains.k_opt * c.w_trans**2, rtol=1e-9)


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
    """Issue 23: the hub wind handed to controllers is read by index on a uniform grid; it is
    numpy's linear interpolation of the hub column (held at the ends) at any time."""
    from mpc_wt.simulate import _hub_wind

    rng = np.random.default_rng(seed)
    t = t0 + dt * np.arange(n)
    y, z = np.linspace(-80, 80, 5), np.linspace(10, 170, 5)
    u = rng.normal(10, 2, (n, 5, 5))
    gw = linearize.GridWind(t=t, y=y, z=z, u=u)
    f = _hub_wind(gw, 90.0)
    hub = gw.u[:, 2, 2].astype(float)           # the column as stored (float32, issue 23)
    for tq in q:
        assert f(tq) == pytest.approx(np.interp(tq, t, hub), rel=1e-12, abs=1e-12)

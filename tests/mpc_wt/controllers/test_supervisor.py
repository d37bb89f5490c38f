"""The supervisory layer: shutdown to feather in the expected time, the overspeed
stop at its limit, the grid loss, bad input."""
from __future__ import annotations

import math

import numpy as np
import pytest

import lidar
import linearize
from mpc_wt.controllers.baseline import BaselineController
from mpc_wt.run import law_controller
from mpc_wt.controllers.supervisor import Supervisor
from mpc_wt.simulation.loop import simulate_closed_loop


@pytest.fixture(scope="module")
def steady18(turbine: linearize.Turbine) -> tuple:
    return linearize.trim(turbine, 18.0), linearize.SteadyWind(18.0, 0.2)


def _run(turbine, ctl, wind, op, duration):
    return simulate_closed_loop(linearize.plant_params(turbine), ctl, wind, duration, x0=op.x,
                                u0=op.u)



def _baseline(turbine):
    """The baseline's shipped law."""
    return law_controller(BaselineController(turbine), "baseline", turbine)


def test_shutdown_reaches_feather_in_the_expected_time(turbine, steady18) -> None:
    """From the trim pitch at 18 m/s (about 15 deg) to feather (90 deg) at the actuator's 8
    deg/s: (90 - theta_0) / 8 s after the trip, plus the actuator's first-order lag (0.1 s
    here; its rate limit is the same 8 deg/s): feather within 3 time constants of that. The
    pitch rate never exceeds the maximum, the torque ramps to zero in torque_ramp_s, the
    rotor slows down."""
    op, wind = steady18
    pa = turbine.pitch_actuator
    sup = Supervisor(_baseline(turbine), turbine, shutdown_at=2.0, torque_ramp_s=4.0)
    res = _run(turbine, sup, wind, op, 16.0)
    pitch = np.column_stack([res.channel(f"pitch_{i}") for i in (1, 2, 3)])
    theta0 = pitch[int(2.0 / res.meta["dt"])].mean()
    expected = 2.0 + (pa.max_pitch_rad - theta0) / pa.max_rate_rad_s
    reached = res.t[np.argmax(pitch.min(axis=1) >= pa.max_pitch_rad - math.radians(0.5))]
    assert pitch.min(axis=1).max() >= pa.max_pitch_rad - math.radians(0.5)
    assert expected - 0.05 <= reached <= expected + 3 * pa.time_constant + 0.05
    rate = np.abs(np.diff(pitch, axis=0)) / res.meta["dt"]
    assert rate.max() <= pa.max_rate_rad_s * (1 + 1e-6)
    tq = res.channel("gen_torque")
    assert tq[res.t >= 6.0 + 2 * res.meta["dt"]].max() == pytest.approx(0.0, abs=1.0)
    assert res.controller["supervisor_state"][-1] == 1.0
    assert res.controller["supervisor_trip_time"][-1] == pytest.approx(2.0)
    speed = res.channel("rotor_speed")
    assert speed[-1] < 0.8 * speed[0]


def test_overspeed_stop_trips_at_the_limit(turbine) -> None:
    """An EOG at 13 m/s (class I A: +4.6 m/s at its peak) lifts the rotor above rated; with the
    limit at 1.01 rated the stop trips at the first controller step whose measured rotor speed
    exceeds it, and not before."""
    site = lidar.IECSite("I", "A", turbine.geometry.hub_height,
                         2 * turbine.geometry.tip_radius)
    f = lidar.iec_field("eog", 13.0, site, t_start=5.0, n=12)
    wind = linearize.GridWind(t=f.t, y=f.y, z=f.z, u=f.u)
    op = linearize.trim(turbine, 13.0)
    sup = Supervisor(_baseline(turbine), turbine, overspeed=1.01)
    res = _run(turbine, sup, wind, op, 25.0)
    limit = 1.01 * turbine.operation.rated_rotor_speed_rad_s
    speed = res.channel("rotor_speed")
    over = np.flatnonzero(speed > limit)
    assert over.size, "the gust did not reach the limit"
    trip = res.controller["supervisor_trip_time"][-1]
    assert res.controller["supervisor_state"][-1] == 2.0
    assert trip == pytest.approx(res.t[over[0]], abs=1e-9)   # controller at every plant step
    assert np.all(speed[res.t < trip] <= limit)


def test_grid_loss_drops_the_torque_at_once(turbine, steady18) -> None:
    op, wind = steady18
    sup = Supervisor(_baseline(turbine), turbine, grid_loss_at=1.0)
    res = _run(turbine, sup, wind, op, 3.0)
    dt = res.meta["dt"]
    tq = res.channel("gen_torque")
    k = int(round(1.0 / dt))
    assert tq[k - 1] > 0.5 * turbine.generator.max_torque / 1.1
    assert np.all(tq[k + 1:] == 0.0)                  # no torque-rate limit on a grid loss
    assert res.controller["supervisor_state"][-1] == 3.0
    # the unloaded rotor speeds up at first, until the blades pitching at 8 deg/s catch it
    speed = res.channel("rotor_speed")
    assert speed[k:].max() > speed[k] * 1.005 and speed[-1] < speed[k:].max()


@pytest.mark.parametrize("kwargs, match", [
    (dict(overspeed=0.9), r"overspeed must be a fraction of rated rotor speed > 1.*got 0.9"),
    (dict(shutdown_at=-1.0), r"shutdown_at must be a finite time >= 0 s.*got -1.0"),
    (dict(grid_loss_at=math.nan), r"grid_loss_at must be a finite time"),
    (dict(pitch_rate=1.0), r"pitch_rate must be in \(0, 0.1396\d*\] rad/s.*got 1.0"),
    (dict(torque_ramp_s=0.0), r"torque_ramp_s must be > 0 s, got 0.0"),
    (dict(pitch_fault_at=5.0, pitch_fault="stuck"), r"pitch_fault must be one of .*'stuck'"),
    (dict(pitch_fault_at=5.0, pitch_fault_blade=4), r"pitch_fault_blade must be 1, 2 or 3"),
    (dict(pitch_fault_at=-2.0), r"pitch_fault_at must be a finite time >= 0 s"),
    (dict(fault_detect_s=math.inf), r"fault_detect_s must be a finite time >= 0 s, got inf"),
    (dict(pitch_fault_at=5.0, pitch_fault_azimuth_deg=360.0),
     r"pitch_fault_azimuth_deg must be an azimuth in \[0, 360\) deg.*got 360.0"),
    (dict(pitch_fault_at=5.0, pitch_fault_azimuth_deg="up"),
     r"pitch_fault_azimuth_deg must be an azimuth.*got 'up'"),
])
def test_bad_settings_are_named(turbine, kwargs, match) -> None:
    with pytest.raises(ValueError, match=match):
        Supervisor(_baseline(turbine), turbine, **kwargs)


@pytest.mark.parametrize("fault", ["seized", "runaway"])
def test_pitch_fault_on_one_blade_and_the_protection(turbine, steady18, fault) -> None:
    """A pitch fault on blade 2 at 2 s at 18 m/s (trim pitch about 15 deg), detected 1 s later.
    Seized: blade 2's command holds its pitch at the fault until the end (to 1e-9 rad), while
    the healthy blades feather from the stop. Runaway: blade 2's command falls at the actuator's
    8 deg/s for the detection's 1 s, and the drive is cut where the blade is: its first-order
    lag (tau = 0.1 s) trails a ramp by rate x tau, so the blade stops 8 x (1 - 0.1) = 7.2 deg
    below its pitch at the fault (hand-worked; measured 7.0), and holds. The stop (state 4) trips
    at 3 s; the torque ramps to zero."""
    op, wind = steady18
    pa = turbine.pitch_actuator
    sup = Supervisor(_baseline(turbine), turbine, pitch_fault_at=2.0,
                     pitch_fault=fault, pitch_fault_blade=2, fault_detect_s=1.0,
                     torque_ramp_s=4.0)
    res = _run(turbine, sup, wind, op, 9.0)
    t, dt = res.t, res.meta["dt"]
    assert res.controller["supervisor_state"][-1] == 4.0
    assert res.controller["supervisor_trip_time"][-1] == pytest.approx(3.0, abs=dt)
    p1, p2 = res.channel("pitch_1"), res.channel("pitch_2")
    k = int(round(2.0 / dt))
    theta = p2[k]
    if fault == "seized":
        assert np.max(np.abs(p2[t > 2.0 + 5 * pa.time_constant] - theta)) < math.radians(0.05)
    else:
        drop = theta - p2[t > 3.0 + 5 * pa.time_constant].mean()
        expect = pa.max_rate_rad_s * (1.0 - pa.time_constant)
        assert drop == pytest.approx(expect, abs=math.radians(0.5))
        assert np.ptp(p2[t > 3.5]) < math.radians(0.05)
    assert p1[-1] > theta + math.radians(25.0)           # the healthy blades feather
    assert res.channel("gen_torque")[t > 7.0 + 2 * dt].max() == pytest.approx(0.0, abs=1.0)


@pytest.mark.parametrize("blade, target", [(1, 0.0), (2, 90.0), (3, 250.0)])
def test_a_pitch_fault_at_an_azimuth(turbine, steady18, blade, target) -> None:
    """With ``pitch_fault_azimuth_deg`` the fault waits for the faulty blade: it comes at the
    first step from ``pitch_fault_at`` on at which that blade (blade k at blade 1's azimuth
    + (k - 1) x 120 deg) has reached the azimuth, so within one step's turn past it (rated
    speed 1.27 rad/s x 12.5 ms = 0.9 deg), and less than a revolution (4.9 s at 18 m/s) after
    ``pitch_fault_at``; the protection then trips fault_detect_s later."""
    op, wind = steady18
    sup = Supervisor(_baseline(turbine), turbine, pitch_fault_at=2.0,
                     pitch_fault="seized", pitch_fault_blade=blade, fault_detect_s=1.0,
                     pitch_fault_azimuth_deg=target)
    res = _run(turbine, sup, wind, op, 9.0)
    assert sup.fault_time is not None and 2.0 <= sup.fault_time < 2.0 + 2 * math.pi / 1.2
    t = res.t
    k = int(np.searchsorted(t, sup.fault_time - 1e-9))
    psi = np.degrees(res.channel("azimuth")[k] + (blade - 1) * 2 * math.pi / 3) % 360.0
    passed = (psi - target) % 360.0
    assert passed < 1.0, (psi, target)
    assert res.controller["supervisor_trip_time"][-1] == pytest.approx(sup.fault_time + 1.0,
                                                                      abs=res.meta["dt"])


class _MaxTorque:
    """Commands fine pitch and the generator's largest torque, whatever it measures."""

    def __init__(self, turbine):
        self.tq = turbine.generator.max_torque
        self.signals = {"inner": 1.0}

    def reset(self):
        pass

    def step(self, t, meas):
        return np.zeros(3), self.tq


def test_torque_law_guard_caps_only_in_a_lull() -> None:
    """At fine pitch below rated speed the torque is the baseline's law (region 2: K omega^2
    with K from its design; region 2.5 between); above rated speed, or with the pitch beyond
    the band, the guarded torque passes unchanged."""
    from mpc_wt.controllers.baseline import tune_baseline
    from mpc_wt.controllers.supervisor import TorqueLawGuard

    tb = linearize.load_turbine("nrel5mw")
    g = TorqueLawGuard(_MaxTorque(tb), tb)
    k = tune_baseline(tb).k_opt
    w2 = 100.0                                  # rad/s on the generator: region 2 (K w^2)
    _, tq = g.step(0.0, {"gen_speed": w2, "pitch": np.zeros(3)})
    assert tq == pytest.approx(k * w2**2, rel=1e-12) and g.signals["torque_law_active"] == 1.0
    assert g.signals["inner"] == 1.0
    rated = tb.operation.rated_rotor_speed_rad_s * tb.drivetrain.gearbox_ratio
    _, tq = g.step(0.1, {"gen_speed": 1.01 * rated, "pitch": np.zeros(3)})
    assert tq == tb.generator.max_torque and g.signals["torque_law_active"] == 0.0
    _, tq = g.step(0.2, {"gen_speed": w2, "pitch": np.full(3, np.radians(1.5))})
    assert tq == tb.generator.max_torque                         # pitch beyond the 1 deg band
    wide = TorqueLawGuard(_MaxTorque(tb), tb, fine_band=np.radians(2.0))
    _, tq = wide.step(0.0, {"gen_speed": w2, "pitch": np.full(3, np.radians(1.5))})
    assert tq == pytest.approx(k * w2**2, rel=1e-12)
    with pytest.raises(ValueError, match=r"fine_band must be a finite pitch >= 0 rad, got -1"):
        TorqueLawGuard(_MaxTorque(tb), tb, fine_band=-1)


def test_torque_law_guard_measures_its_band_from_the_minimum_pitch_table() -> None:
    """The IEA-22-280-RWT deck as published: fine pitch -4.01 deg, its ROSCO table holds region
    2 at -1.3 to +0.6 deg. At the trim of 9 m/s (5.10 rpm, pitch -1.15 deg on the table, read
    back from the turbine's trim) the guard caps the torque at the law's; 2 deg above the table
    it lets it pass. Measured from the fine pitch, its band ended at -3.01 deg and it never
    acted on this turbine."""
    from pathlib import Path

    from mpc_wt.controllers.supervisor import TorqueLawGuard

    deck = (Path(__file__).parents[2] / "data" / "iea22" / "OpenFAST" / "IEA-22-280-RWT-Monopile"
            / "IEA-22-280-RWT-Monopile.fst")
    tb = linearize.load_turbine(deck)
    op = linearize.trim(tb, 9.0)
    assert math.degrees(op.pitch_rad) > math.degrees(tb.operation.fine_pitch_rad) + 2.5
    g = TorqueLawGuard(_MaxTorque(tb), tb)
    w = op.rotor_speed_rad_s * tb.drivetrain.gearbox_ratio
    _, tq = g.step(0.0, {"gen_speed": w, "pitch": np.full(3, op.pitch_rad)})
    assert g.signals["torque_law_active"] == 1.0 and tq < tb.generator.max_torque
    _, tq = g.step(0.1, {"gen_speed": w, "pitch": np.full(3, op.pitch_rad + math.radians(2.0))})
    assert g.signals["torque_law_active"] == 0.0 and tq == tb.generator.max_torque

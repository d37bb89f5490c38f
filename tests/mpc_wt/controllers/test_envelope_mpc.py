"""The scheduled MPC over the whole operating envelope: below rated it tracks the power-optimal
operating point (the trim at the wind it measures), through rated it moves no actuator faster
than its rate limit, in an extreme operating gust at rated wind it keeps the rotor below
1.2 x rated speed, and a failed QP takes the logged fallback while the run goes on."""
from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import pytest

import lidar
import linearize
from mpc_wt.run import build_controller, run_controller
from mpc_wt.simulation.scenario import Scenario, field_grid


def _uniform_file(path: Path, turbine: linearize.Turbine, t: np.ndarray, u: np.ndarray) -> str:
    """A uniform wind (no shear, no turbulence) u(t) over the rotor, written as a field file."""
    width, n = field_grid(turbine)
    y = np.linspace(-width / 2, width / 2, n)
    hub = turbine.geometry.hub_height
    z = np.linspace(hub - width / 2, hub + width / 2, n)
    uu = np.repeat(np.asarray(u, np.float32)[:, None, None], n, 1).repeat(n, 2)
    zero = np.zeros_like(uu)
    f = lidar.WindField(t=t, y=y, z=z, u=uu, v=zero, w=zero, mean_speed=float(np.mean(u)),
                        hub_height=hub, meta={"model": "uniform"})
    f.save(path)
    return str(path)


def test_below_rated_it_tracks_the_trim_at_the_wind_it_meets(turbine, tmp_path) -> None:
    """A slow ramp from 6 to 9 m/s over 300 s (no shear): after the first 60 s the rotor's
    aerodynamic power is within 1 % of the trim's at the wind of the moment (the operating
    point of the power-optimal tip-speed ratio: an independent steady solution of the plant;
    the aerodynamic power, because the generator's is short of it by the power that
    accelerates the rotor along the ramp, about 2 %), and the pitch stays at fine pitch."""
    t = np.arange(0.0, 340.0, 0.05)
    wind = np.clip(6.0 + 3.0 * (t - 20.0) / 300.0, 6.0, 9.0)
    path = _uniform_file(tmp_path / "ramp.npz", turbine, t, wind)
    res = run_controller(turbine, "mpc", Scenario(wind_file=path, duration=320.0,
                                                  shear_exponent=0.0))
    keep = (res.t >= 60.0) & (res.t <= 320.0)
    grid = np.arange(6.0, 9.01, 0.25)
    trim = [linearize.trim(turbine, v, shear_exponent=0.0) for v in grid]
    p_trim = np.interp(np.interp(res.t[keep], t, wind), grid, [op.aero_power for op in trim])
    p = res.channel("aero_power")[keep]
    err = np.abs(p / p_trim - 1.0)
    assert err.max() <= 0.01, f"largest power error {100 * err.max():.2f} %"
    assert np.degrees(res.channel("pitch_1")[keep]).max() <= 0.1


def _step_through_rated(turbine, tmp_path, controller: str):
    """A uniform step from 10 to 14 m/s and back (180 s)."""
    t = np.arange(0.0, 200.0, 0.05)
    wind = np.where((t >= 60.0) & (t < 120.0), 14.0, 10.0)
    path = _uniform_file(tmp_path / "step.npz", turbine, t, wind)
    return run_controller(turbine, controller, Scenario(wind_file=path, duration=180.0,
                                                        shear_exponent=0.0))


def test_a_step_through_rated_moves_no_actuator_beyond_its_rate(turbine, tmp_path) -> None:
    """A uniform step from 10 to 14 m/s and back: no torque command moves faster than the
    generator's rate limit, no pitch command asks the actuator (first order, time constant
    tau) for more than its rate, (ref - pitch) / tau <= the limit, the electrical power stays
    within 1.1 x rated (the ceiling is 1.08; 1.23 x rated without it) and no QP fails."""
    res = _step_through_rated(turbine, tmp_path, "mpc")
    dt, every = 0.1, 8                      # the MPC's commands at 10 Hz in the 80 Hz record
    k = np.arange(len(res.t))[res.t >= 5.0][::every]
    assert np.diff(res.t[k]) == pytest.approx(dt)
    pa, gen = turbine.pitch_actuator, turbine.generator
    torque = res.channel("gen_torque_ref")[k]
    assert np.abs(np.diff(torque)).max() <= gen.max_torque_rate * dt * (1 + 1e-6)
    demand = (res.channel("pitch_ref_1")[k] - res.channel("pitch_1")[k]) / pa.time_constant
    assert np.abs(demand).max() <= pa.max_rate_rad_s * (1 + 1e-6)
    assert res.channel("gen_power").max() <= 1.1 * turbine.operation.rated_power
    assert np.sum(res.controller["qp_fallback"] > 0) == 0


@pytest.mark.xfail(strict=True, reason="with its power held to 1.08 x rated the MPC's torque "
                   "no longer brakes the rotor in a 4 m/s step: its peak is 1.136 x rated "
                   "against the baseline's 1.131 (1.120 with the torque at 1.23 x rated power); "
                   "its torque rises 0.5 s after the baseline's, on the estimated wind")
def test_a_step_through_rated_peaks_below_the_baseline(turbine, tmp_path) -> None:
    """In the step from 10 to 14 m/s the rotor's peak stays below the baseline's in the same
    step."""
    res = _step_through_rated(turbine, tmp_path, "mpc")
    base = _step_through_rated(turbine, tmp_path, "baseline")
    assert res.channel("rotor_speed").max() < base.channel("rotor_speed").max()


def test_an_extreme_gust_at_rated_wind_keeps_the_rotor_below_1p2_rated(turbine) -> None:
    """IEC 61400-1 ed. 3 EOG (class IA) at the rated wind: the rotor stays below 1.2 x rated
    speed (the supervisor's overspeed limit is 1.25 x rated in the sign-off)."""
    v = round(linearize.rated_wind_speed(turbine), 1)
    res = run_controller(turbine, "mpc", Scenario(v, "A", 0, 60.0, condition="eog",
                                                  iec_class="I", event_at=20.0))
    rated = turbine.operation.rated_rotor_speed_rad_s
    peak = res.channel("rotor_speed").max() / rated
    assert peak < 1.2, f"rotor speed peaked at {peak:.3f} x rated"


@pytest.mark.parametrize("sign", [1, -1])
def test_a_gust_with_direction_change_below_rated_does_not_stall_the_rotor(turbine,
                                                                            sign) -> None:
    """IEC ECD at 9.4 m/s (class I, both directions) with the sign-off's LIDAR: the rotor keeps
    turning (measured lowest 0.78 rad/s, 0.62 x rated). The direction change cuts the wind
    the rotor and the LIDAR see; a region floor that read the pitch whatever the rotor speed
    kept a region-3 design acting and braked the rotor to a stop 35 s after the gust."""
    opts = {"lidar": {"evolution": True, "focus_distance": 54.0, "los_error": True,
                      "range_weighting": True}}
    res = run_controller(turbine, "mpc-lidar", Scenario(
        9.4, "A", 0, 120.0, condition="ecd", iec_class="I", event_at=70.0,
        shear_exponent=0.2, sign=sign), options=opts)
    assert res.channel("rotor_speed").min() > 0.5 * turbine.operation.rated_rotor_speed_rad_s


def _held(ctl, turbine: linearize.Turbine, speed: float, pitch_deg: float,
          steps: int) -> float:
    """The MPC law's torque command after ``steps`` calls with the rotor held at ``speed`` x
    rated and the blades at ``pitch_deg``, the measured torque its last command."""
    op = linearize.trim(turbine, 13.0)
    n = turbine.drivetrain.gearbox_ratio
    w = speed * turbine.operation.rated_rotor_speed_rad_s
    tq = float(op.u[3])
    for k in range(steps):
        meas = {"pitch": np.full(3, np.radians(pitch_deg)), "flap_moment": np.zeros(3),
                "edge_moment": np.zeros(3), "rotor_speed": w, "gen_speed": n * w,
                "gen_torque": tq, "gen_power": 0.944 * tq * n * w}
        _, tq = ctl.step(0.1 * k, meas)
    return float(tq)


@pytest.mark.parametrize("speed, lo, hi", [(0.65, 0.0, 0.36), (0.97, 0.95, 1.1)])
def test_a_pitched_rotor_far_below_rated_speed_is_in_a_lull_not_in_region_3(
        turbine, speed, lo, hi) -> None:
    """With the blades 5 deg above fine pitch and the rotor held at 0.65 x rated speed for
    15 s, the torque command falls to region 2's: at most Jonkman et al.'s (2009, sec. 7.3)
    K omega^2 there, K = 0.0255764 N m/rpm^2 at 762.9 rpm, 14.9 kN m or 0.345 x rated (+4 %;
    region 1.5's is less). At 0.97 x rated speed the same pitch is region 3 and the command
    holds rated power (their constant power, 5 MW / (0.944 x 119.2 rad/s) = 1.03 x rated;
    measured 0.99). The torque law tells region 3 from the pitch; with the MPC's own pitch in a
    lull taken for region 3 the target was rated power's torque, the command here about half
    of rated and rising, and on the IEA-22-280-RWT at 9 m/s the rotor stalled."""
    built, _, _ = build_controller(turbine, "mpc", Scenario(13.0))
    tq = _held(built.controller, turbine, speed, 5.0, 150)
    rated = turbine.rated_generator_torque
    assert lo * rated <= tq <= hi * rated, f"torque {tq / rated:.3f} x rated"


def test_a_solve_over_its_time_budget_takes_the_fallback(turbine, caplog) -> None:
    """With a time budget no solve can meet (1 ns), every step's plan counts as late: the law
    takes its fallback at every controller step (10 Hz over 5 s: 50), warns each time with the
    time the solve took, and the run continues; with no budget (the default) the same case
    has no fallback. A budget <= 0 is refused, naming it."""
    from mpc_wt.controllers.mpc import MPCSettings
    from mpc_wt.errors import OptionsError

    case = Scenario(15.0, "B", 4, 5.0)
    with caplog.at_level(logging.WARNING, logger="mpc_wt.controllers.discon"):
        res = run_controller(turbine, "mpc", case, {"design_wind_mps": 15.0,
                                                    "time_budget_ms": 1e-6})
    assert res.t[-1] == pytest.approx(5.0)
    assert np.all(res.controller["qp_fallback"][::8] > 0)
    assert np.all(res.controller["library_warning"][::8] == 1.0)
    msgs = [r.getMessage() for r in caplog.records if "over its budget" in r.getMessage()]
    assert len(msgs) == 50 and "fallback 2 (1 so far)" in msgs[0]
    free = run_controller(turbine, "mpc", case, {"design_wind_mps": 15.0})
    assert np.all(free.controller["qp_fallback"] == 0)
    with pytest.raises(ValueError, match="time_budget_ms"):
        MPCSettings(time_budget_ms=0.0)
    with pytest.raises(OptionsError, match="time_budget_ms"):
        run_controller(turbine, "mpc", case, {"time_budget_ms": 0.0})


def test_cost_scales_follow_the_turbine() -> None:
    """The MPC's default scales are the NREL 5-MW's typical magnitudes; for another turbine
    they follow its rated values: on the IEA-15-240-RWT the power scale is 3x (15 MW against
    5 MW, both published ratings) and the rotor-speed scale 7.56 / 12.1 rpm = 0.625x (the
    published rated speeds); the pitch rate's scale goes with the pitch drives' largest rates
    (2 deg/s against 8, both published) to the power 0.25: 0.25 ** 0.25 = 0.707x, and the
    LQR's pitch scale to the power 0.5: 0.5x; angles keep theirs; for the NREL 5-MW nothing
    changes."""
    from mpc_wt.controllers.mpc import MPCWeights, pitch_drive_scale_ratio, turbine_scale_ratios

    five, fifteen = linearize.load_turbine("nrel5mw"), linearize.load_turbine("iea15mw")
    assert set(turbine_scale_ratios(five).values()) == {1.0}
    r = turbine_scale_ratios(fifteen)
    assert r["gen_power"] == pytest.approx(3.0, rel=1e-9)
    assert r["rotor_speed"] == pytest.approx(7.56 / 12.1, rel=2e-3)
    w0 = MPCWeights()
    w = w0.for_turbine(fifteen)
    assert w.scales["gen_power"] == pytest.approx(3.0 * w0.scales["gen_power"])
    assert r["pitch_rate"] == pytest.approx(0.25 ** 0.25, rel=1e-3)
    assert w.scales["pitch_rate"] == pytest.approx(0.25 ** 0.25 * w0.scales["pitch_rate"],
                                                   rel=1e-3)
    assert pitch_drive_scale_ratio(fifteen, 0.5) == pytest.approx(0.5, rel=1e-3)
    assert pitch_drive_scale_ratio(five, 0.5) == 1.0
    with pytest.raises(ValueError, match="exponent"):
        pitch_drive_scale_ratio(fifteen, -1.0)
    assert w.scales["pitch"] == w0.scales["pitch"]
    assert w0.for_turbine(five) == w0


def test_a_pitch_drive_faster_than_the_nrel5mw_does_not_cheapen_the_pitch() -> None:
    """BAR_10's deck gives its pitch drives 2 rad/s (ROSCO's ``PC_MaxRat``, 115 deg/s): the
    scales go with the NREL 5-MW's 8 deg/s, so the designs weigh a blade's motion as on the
    NREL 5-MW (ratio 1), the scheduled LQR's pitch-rate scale is 8 deg/s, and the MPC without
    preview keeps the NREL 5-MW's soft speed limit (1.1 x rated; 1.22 with the deck's rate)."""
    import dataclasses
    import math

    from mpc_wt.controllers.mpc import (pitch_drive_scale_ratio, scaling_pitch_rate,
                                        turbine_scale_ratios)
    from mpc_wt.kinds.mpc import ENVELOPE_SPEED_LIMIT, MPCOptions, _mpc_settings, \
        _no_preview_drives

    five = linearize.load_turbine("nrel5mw")
    fast = dataclasses.replace(five, pitch_actuator=dataclasses.replace(
        five.pitch_actuator, max_rate_rad_s=2.0))
    assert scaling_pitch_rate(fast) == pytest.approx(math.radians(8.0))
    assert pitch_drive_scale_ratio(fast, 0.5) == 1.0
    assert turbine_scale_ratios(fast)["pitch_rate"] == 1.0
    _, limit = _no_preview_drives(fast, _mpc_settings(MPCOptions(), False, False))
    assert limit == pytest.approx(ENVELOPE_SPEED_LIMIT) == pytest.approx(1.1)


def test_the_torque_bound_and_the_torque_rate_weight_act(turbine, tmp_path) -> None:
    """The 10-14 m/s step of the test above, three designs without the power ceiling
    (``power_limit: null``, ``speed_limit: 1.065``). With ``torque_limit: 1.0`` no
    torque command exceeds the rated torque, 5 MW / (0.944 x 122.91 rad/s) = 43.09 kN m by
    hand (without it the command reaches the generator's 47.4 kN m maximum). A torque-rate
    weight of 10 in every design (a 4 kN m move per step weighs as much as the scaled power
    error) moves the torque less in total than none in any (measured 0.89 of it: the torque
    law's target, not the rate, sets most of the torque's path)."""
    t = np.arange(0.0, 200.0, 0.05)
    wind = np.where((t >= 60.0) & (t < 120.0), 14.0, 10.0)
    path = _uniform_file(tmp_path / "step.npz", turbine, t, wind)
    sc = Scenario(wind_file=path, duration=180.0, shear_exponent=0.0)
    travel, peak = {}, {}
    # no rate weight anywhere, and no power ceiling (which would hide both), the speed limit
    # at 1.065 x rated (with the ceiling the default 1.1 lets the rotor carry the gust)
    old = {"power_limit": None, "speed_limit": 1.065}
    none = {"below_rated_weights": {"gen_torque_ref_rate": 0.0}, **old}
    for name, opts in (("free", none), ("bound", {**none, "torque_limit": 1.0}),
                       ("rate", {"weights": {"gen_torque_ref_rate": 10.0}, **old})):
        res = run_controller(turbine, "mpc", sc, options=opts)
        q = res.channel("gen_torque_ref")[res.t >= 5.0]
        travel[name], peak[name] = np.abs(np.diff(q)).sum(), q.max()
    assert peak["bound"] <= 5e6 / (0.944 * 122.90967) * (1 + 1e-6)
    assert peak["free"] > 5e6 / (0.944 * 122.90967) * 1.02
    assert travel["rate"] < 0.95 * travel["free"]


def test_below_rated_designs_take_their_own_weights_and_limit(turbine) -> None:
    """``below_rated_weights`` and ``below_rated_speed_limit`` set the designs at grid winds
    below rated (11.40 m/s for the NREL 5-MW) and leave those above as ``weights`` and
    ``speed_limit`` say; the rate weights land in the cost's rate terms (below rated the
    designs' own torque-rate weight, 10, unless ``below_rated_weights`` sets one)."""
    opts = {"weights": {"rotor_speed": 0.5, "gen_torque_ref_rate": 0.2},
            "below_rated_weights": {"rotor_speed": 0.1, "gen_torque_ref": 2.0},
            "speed_limit": 1.08, "below_rated_speed_limit": 1.01}
    built, _, _ = build_controller(turbine, "mpc", Scenario(12.0, "steady", 1, 1.0), opts)
    ctl = built.designed
    rated_speed = turbine.operation.rated_rotor_speed_rad_s
    for k, v in enumerate(ctl.family.wind_mps):
        mpc = ctl.controller(k)
        below = v < linearize.rated_wind_speed(turbine)
        assert mpc.w.outputs["rotor_speed"] == (0.1 if below else 0.5)
        assert mpc.w.inputs["gen_torque_ref"] == (2.0 if below else 0.01)
        assert mpc.w.outputs["flap_moment"] == 0.0          # no preview: no cyclic pitch
        # BELOW_RATED_WEIGHTS's torque-rate weight below rated where below_rated_weights sets none
        assert mpc.w.rate["gen_torque_ref"] == (10.0 if below else 0.2)
        assert mpc.max_rotor_speed == pytest.approx((1.01 if below else 1.08) * rated_speed)


def test_the_torque_notch_sits_at_the_plants_drivetrain_mode(turbine) -> None:
    """The default notch centre is the drivetrain torsion mode of the full linearization at
    rated wind. Hand-worked check: the free-free torsion of three inertias, the generator
    (J_g N^2), the rotor (J_r) and the blades' collective edge mode (3 M_e, coupled to the
    rotor by 3 S_e, stiffness 3 K_e with the centrifugal terms at rated speed), on the shaft's
    spring; the same masses with the generator locked give FAST's 0.6205 Hz within 5 %
    (tests/linearize/test_plant.py). Within 2 % (measured 0.22 %), and below the rigid-blade
    2.22 Hz the designs' models have. The notch (Q = 2 at 10 Hz) takes 20 dB or more off
    there and leaves the tower's first modes (0.32 Hz) within 0.1 dB and 10 deg."""
    import math

    import scipy.linalg as sl

    from mpc_wt.controllers import drivetrain_frequency

    p = linearize.plant_params(turbine)
    pk = p.pack
    w = turbine.operation.rated_rotor_speed_rad_s
    me, se = p.edge_modal_mass, p.edge_rotor_coupling
    ke = p.edge_modal_stiffness + w**2 * (p.edge_centrifugal_stiffness - me)
    m = np.array([[pk.j_rot, 3 * se, 0.0], [3 * se, 3 * me, 0.0],
                  [0.0, 0.0, pk.j_gen * pk.ngear**2]])
    k = np.array([[pk.k_shaft, 0.0, -pk.k_shaft], [0.0, 3 * ke, 0.0],
                  [-pk.k_shaft, 0.0, pk.k_shaft]])
    w2 = sl.eigh(k, m, eigvals_only=True)
    f_hand = float(np.sqrt(w2[1]) / (2 * math.pi))
    f = drivetrain_frequency(turbine)
    assert f == pytest.approx(f_hand, rel=0.02)
    assert f < 2.0
    built, _, _ = build_controller(turbine, "mpc", Scenario(13.0))
    ctl = built.designed
    assert ctl.torque_notch_hz == pytest.approx(f)
    h = ctl._notch.response([0.32, f], 1.0 / ctl.dt)
    assert 20 * np.log10(abs(h[1])) <= -20.0
    assert abs(20 * np.log10(abs(h[0]))) <= 0.1 and abs(np.degrees(np.angle(h[0]))) <= 10.0


def test_the_tower_notch_sits_at_the_plants_side_side_mode(turbine) -> None:
    """With ``tower_notch`` the torque command passes a second notch at the plant's first
    tower side-side mode: 0.323 Hz on the NREL 5-MW, within 4 % of FAST's 0.3120 Hz (Jonkman
    et al. 2009, Table 9-1; measured +3.5 %, the plant's own check is
    tests/linearize/test_plant.py). Both notches take 20 dB
    or more off at their centres; at 0.02 Hz, where the torque holds the speed, the pair
    changes the command by at most 0.1 dB and 3 deg. Without the option the design has none."""
    from mpc_wt.controllers import drivetrain_frequency

    built, _, _ = build_controller(turbine, "mpc", Scenario(13.0), {"tower_notch": True})
    ctl = built.designed
    f_ss, f_dt = ctl.tower_notch_hz, drivetrain_frequency(turbine)
    assert f_ss == pytest.approx(0.3120, rel=0.04)
    h = ctl._notch.response([0.02, f_ss, f_dt], 1.0 / ctl.dt)
    assert 20 * np.log10(abs(h[1])) <= -20.0 and 20 * np.log10(abs(h[2])) <= -20.0
    assert abs(20 * np.log10(abs(h[0]))) <= 0.1 and abs(np.degrees(np.angle(h[0]))) <= 3.0
    plain, _, _ = build_controller(turbine, "mpc", Scenario(13.0))
    assert plain.designed.tower_notch_hz is None


@pytest.mark.slow
def test_the_notch_takes_the_drivetrain_out_of_the_shaft_torque(turbine) -> None:
    """`mpc-lidar` at 13 m/s (class A, seed 12, 300 s after 30 s) against the baseline: with
    the designs chosen by the wind alone and the soft speed limit at 1.028 x rated (where it
    binds in most gusts), the shaft-torque DEL (m = 4) is within 1.25x the baseline's with the
    notch at the drivetrain mode (measured 1.037x) and more than 1.5x without it (1.903x): the
    designs' commands near the plant's drivetrain mode are what raised it. With the defaults
    (the region floor, limit 1.065) it is within 1.25x too (measured 0.943x)."""
    from mpc_wt.assessment.fatigue import damage_equivalent_load

    def shaft_del(kind: str, opts: dict) -> float:
        r = run_controller(turbine, kind, Scenario(13.0, "A", 12, 330.0), options=opts)
        keep = r.t >= 30.0
        return damage_equivalent_load(r.channel("lss_torque")[keep], 4.0, duration=300.0)

    old = {"region_floor": False, "region3_pitch_deg": 0.0, "speed_limit": 1.028}
    base = shaft_del("baseline", {})
    with_notch, without = shaft_del("mpc-lidar", old), shaft_del("mpc-lidar",
                                                                  {**old, "torque_notch_hz": 0.0})
    default = shaft_del("mpc-lidar", {})
    print(f"shaft-torque DEL / baseline's: {with_notch / base:.3f} with the notch, "
          f"{without / base:.3f} without, {default / base:.3f} with the defaults")
    assert with_notch <= 1.25 * base
    assert without > 1.5 * base
    assert default <= 1.25 * base


def test_torque_notch_options_are_checked(turbine) -> None:
    """A centre at or above the controller's Nyquist frequency is refused naming the option;
    0 turns the notch off; a direct drive's mode (the IEA-15's with a flexible shaft, above
    4 Hz) gets none, and a rigid drivetrain (its deck's DrTrDOF False) has no mode."""
    import dataclasses

    from mpc_wt.controllers import drivetrain_frequency

    with pytest.raises(ValueError, match="torque_notch_hz = 6 Hz must be below"):
        build_controller(turbine, "mpc", Scenario(13.0), {"torque_notch_hz": 6.0})
    built, _, _ = build_controller(turbine, "mpc", Scenario(13.0), {"torque_notch_hz": 0.0})
    assert built.designed.torque_notch_hz is None
    assert built.meta["mpc"]["torque_notch_hz"] is None
    iea15 = linearize.load_turbine("iea15mw")
    assert drivetrain_frequency(dataclasses.replace(iea15, rigid_dofs=())) > 4.0
    with pytest.raises(ValueError, match="no drivetrain torsion mode"):
        drivetrain_frequency(iea15)


@pytest.mark.parametrize("kind, opts, above", [
    ("mpc", {}, 0.0),
    ("mpc", {"weights": {"flap_moment": 0.2}}, 0.2),
    ("mpc-lidar", {}, 0.1024),
])
def test_cyclic_pitch_only_with_a_preview_or_when_asked(turbine, kind, opts, above) -> None:
    """The scheduled designs' flap-moment weight (what makes them pitch cyclically) above rated
    wind: none on the Kalman estimator without a preview unless ``weights.flap_moment`` asks;
    the tuned 0.1024 with the LIDAR's preview; none below rated in any case."""
    built, _, _ = build_controller(turbine, kind, Scenario(12.0, "steady", 1, 1.0), opts)
    ctl = built.designed
    for k, v in enumerate(ctl.family.wind_mps):
        below = v < linearize.rated_wind_speed(turbine)
        w = ctl.controller(k).w.outputs["flap_moment"]
        assert w == (0.0 if below else pytest.approx(above))


def test_without_a_preview_the_mpc_adds_no_shaft_bending(turbine) -> None:
    """`mpc` (Kalman estimator, no preview) at 18 m/s, class A, seed 12, 300 s after 30 s,
    against the baseline: shaft-bending DEL (m = 4) within +5 % (measured +0.2 %; with the
    flap weight of the preview's designs +15.6 %) and pitch travel below 2x (1.38x; 2.83x)."""
    from mpc_wt.assessment.fatigue import damage_equivalent_load

    def case(kind: str) -> tuple[float, float]:
        r = run_controller(turbine, kind, Scenario(18.0, "A", 12, 330.0))
        keep = r.t >= 30.0
        sb = damage_equivalent_load(r.channel("shaft_bending_blade1")[keep], 4.0,
                                    duration=300.0)
        travel = sum(float(np.abs(np.diff(r.channel(f"pitch_{b}")[keep])).sum())
                     for b in (1, 2, 3))
        return sb, travel

    sb_b, tr_b = case("baseline")
    sb_m, tr_m = case("mpc")
    print(f"shaft bending {sb_m / sb_b - 1:+.1%}, pitch travel {tr_m / tr_b:.2f}x")
    assert sb_m <= 1.05 * sb_b
    assert tr_m < 2.0 * tr_b


def test_the_below_rated_pitch_weight_rises_only_where_the_pitch_can_move_both_ways() -> None:
    """The NREL 5-MW's region-2 pitch is its fine pitch, 0 deg, the drives' lowest (its
    published report): the below-rated designs keep the pitch weight above rated. With the
    drives allowed 2 deg below fine pitch (as the NREL-2.8-127's deck allows 10), or with a
    minimum-pitch schedule above the lowest pitch (the IEA-15's 3.8 deg at cut-in, WISDEM's
    schedule), the pitch can move both ways around a flat power coefficient and the designs
    below rated weigh it :data:`BELOW_RATED_FREE_PITCH_WEIGHT`."""
    import dataclasses
    import math

    from mpc_wt.controllers.baseline import BaselineController, tune_baseline
    from mpc_wt.kinds.mpc import (BELOW_RATED_FREE_PITCH_WEIGHT, _pitch_free_below_rated)

    def law(t: linearize.Turbine) -> BaselineController:
        return BaselineController(t, tune_baseline(t))

    five = linearize.load_turbine("nrel5mw")
    assert not _pitch_free_below_rated(law(five))
    lower = dataclasses.replace(five, pitch_actuator=dataclasses.replace(
        five.pitch_actuator, min_pitch_rad=math.radians(-2.0)))
    assert _pitch_free_below_rated(law(lower))
    assert _pitch_free_below_rated(law(linearize.load_turbine("iea15mw")))
    assert BELOW_RATED_FREE_PITCH_WEIGHT > 0.01

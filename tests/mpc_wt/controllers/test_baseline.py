"""Baseline controller: tuning against the published gains and its closed-loop behaviour on the
plant."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

import lidar
import linearize
from mpc_wt.controllers.baseline import BaselineController, tune_baseline
from mpc_wt.run import law_controller
from mpc_wt.simulation.loop import ClosedLoopResult, simulate_closed_loop


def _field(v: float, turb, seed: int) -> tuple[linearize.GridWind, lidar.WindField]:
    f = lidar.generate_field(lidar.TurbulenceSpec(v, turb, duration=610.0), seed)
    return linearize.GridWind(t=f.t, y=f.y, z=f.z, u=np.maximum(f.u, 0.0)), f


def test_gains_match_the_published_baseline(gains) -> None:
    # published: DISCON.F90 (Jonkman's baseline, report sec. 7.4): PC_KP = 0.01882681 s,
    # PC_KI = 0.008068634, PC_KK = 0.1099965 rad (6.302336 deg), dP/dtheta at zero pitch
    # -25.52e6 W/rad, VS_Rgn2K = 2.332287 N m/(rad/s)^2. The bound asked is 20 %; measured:
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


def test_region3_closed_loop(run18: ClosedLoopResult) -> None:
    # 18 m/s, turbulent (class A): rated power held, generator speed std below 5 %
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
    # At 8 m/s the turbine tracks the optimal tip-speed ratio (mean within 3 %),
    # here in Do et al.'s region-II turbulence (12 %); the tip-speed ratio uses the rotor-
    # averaged wind. (In class A, 23 % at 8 m/s, the mean is 10 % above optimal: lulls hold the
    # rotor at its minimum speed and gusts are not followed.)
    gw, f = _field(8.0, 0.12, 3)
    op = linearize.trim(turbine, 8.0)
    r = simulate_closed_loop(params, law_controller(BaselineController(turbine, gains),
                                                    "baseline", turbine), gw, 600.0,
                             x0=op.x, u0=op.u)
    late = r.t > 60.0
    rews = np.interp(r.t[late], f.t, lidar.rotor_effective_wind(f, 63.0))
    tsr = r.channel("rotor_speed")[late].mean() * 63.0 * math.cos(math.radians(2.5)) / rews.mean()
    # measured 1.4 % above optimal; bound 2 % (3 % asked; the README states both)
    assert_allclose(tsr, gains.info["tsr_opt"], rtol=0.02)


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


@pytest.mark.slow
def test_the_default_pi_design_scales_to_a_larger_rotor() -> None:
    """The PI's natural frequency is the NREL 5-MW report's 0.6 rad/s on that turbine
    (Jonkman et al. 2009, sec. 7.2) and scales with rated rotor speed for others. On the IEA-15
    (7.56 rpm, 2 deg/s pitch drives) at 13 m/s in class-B turbulence (200 s, seed 3: not one
    the default was chosen on) the scaled design keeps the rotor below 1.2 x rated with no
    protection stop; the unscaled 0.6 rad/s took it to 1.30 x (seed 1) and tripped."""
    from mpc_wt.controllers.baseline import default_omega_n, tune_baseline
    from mpc_wt.run import run_controller
    from mpc_wt.simulation.scenario import Scenario

    five = linearize.load_turbine("nrel5mw")
    assert tune_baseline(five).omega_n_rad_s == 0.6
    tb = linearize.load_turbine("iea15mw")
    assert 0.3 < default_omega_n(tb) < 0.45
    res = run_controller(tb, "baseline", Scenario(13.0, "B", 3, 200.0), {},
                         supervisor={"overspeed": 1.25})
    w = res.channel("rotor_speed")[res.t >= 30.0] / tb.operation.rated_rotor_speed_rad_s
    assert res.channel("supervisor_state").max() == 0.0
    assert w.max() < 1.2, w.max()


def test_the_torque_law_of_the_scheduled_kinds_holds_a_minimum_pitch_schedule() -> None:
    """The IEA-15 trims to 2.9 deg of pitch at 5 m/s (its minimum-pitch schedule at minimum
    rotor speed). The baseline's schedule, given that pitch as a controller tracking the trim
    holds it, read region 3 (pitch above fine + 1 deg) and asked for rated power at minimum
    speed: the generator's 21.8 MN m limit, and LQR-PIO stalled the rotor in 13 s. The law the
    scheduled kinds share counts the pitch from the largest below-rated trim pitch there: at the
    5 m/s trim's speed and pitch it asks for no more than the trim's own torque (2.9 MN m; the
    region-1.5 ramp starts at that speed), where the bare schedule asks for more than five
    times it. On the NREL 5-MW (fine pitch below rated) the offset is 0."""
    import math

    from mpc_wt.controllers.baseline import LawTorque, below_rated_pitch

    assert below_rated_pitch(linearize.load_turbine("nrel5mw")) == 0.0
    tb = linearize.load_turbine("iea15mw")
    op = linearize.trim(tb, 5.0)
    pitch = float(np.mean(op.u[:3]))
    assert math.degrees(pitch) > 2.0
    law = LawTorque(BaselineController(tb), 0.1)
    w_gen = op.x[linearize.STATE_NAMES.index("gen_speed")]
    assert w_gen < law.law.w_rgn2            # below region 2: the law counts from the offset
    assert law._offset >= pitch - tb.operation.fine_pitch_rad
    assert law.law.torque(w_gen, pitch) > 5.0 * op.u[3]
    q = law.law.torque(w_gen, pitch - law._offset)
    assert 0.0 <= q <= op.u[3], (q, op.u[3])


_WISDEM = Path(__file__).parents[2] / "data" / "iea15mw_steady_state_tabular.csv"


@pytest.fixture(scope="module")
def iea15_low_wind() -> dict[float, tuple[ClosedLoopResult, linearize.OperatingPoint]]:
    """The IEA-15's baseline, 150 s in steady wind of 3.5, 5 and 6 m/s from the trim."""
    tb = linearize.load_turbine("iea15mw")
    p = linearize.plant_params(tb)
    gains = tune_baseline(tb)
    out = {}
    for v in (3.5, 5.0, 6.0):
        op = linearize.trim(tb, v)
        ctl = law_controller(BaselineController(tb, gains), "baseline", tb)
        out[v] = (simulate_closed_loop(p, ctl, linearize.SteadyWind(v), 150.0, x0=op.x,
                                       u0=op.u), op)
    return out


def test_the_minimum_pitch_schedule_keeps_the_iea15_power_in_region_15(iea15_low_wind) -> None:
    """Below 7 m/s the IEA-15 runs at its minimum speed, at tip-speed ratios of 12-21 where
    fine pitch loses most of the torque. At fine pitch the baseline made 87 %, 20 % and 11 % less
    power than the trim at 3.5, 5 and 6 m/s (measured); with the minimum-pitch schedule it
    makes at most 5 % less (measured -4.3, -3.7, -3.0 %: region 1.5's torque line lets the rotor
    run to 5.05-5.5 rpm, above the trim's 5 rpm). The steady pitch is within 0.5 deg of
    WISDEM's power-maximizing pitch at 5 rpm (the published schedule, tests/data) at 3.5 and
    5 m/s (measured 0.2 deg below at 3.5, 0.2 above at 5), and within 1 deg at 6 m/s (0.7 above:
    the faster rotor wants more pitch). The Cp-table steady solution
    (:func:`~mpc_wt.controllers.derating.steady_power_curve`) gives the same power within
    0.2 % (measured 0.03 %)."""
    from mpc_wt.controllers.derating import steady_power_curve

    tab = np.genfromtxt(_WISDEM, delimiter=",", names=True)
    tb = linearize.load_turbine("iea15mw")
    curve = steady_power_curve(tb, tune_baseline(tb), [3.5, 5.0, 6.0])
    for k, (v, (res, op)) in enumerate(sorted(iea15_low_wind.items())):
        power = float(np.mean(res.channel("gen_power")[-1600:]))
        assert power >= 0.95 * op.power, (v, power / op.power - 1)
        assert abs(curve["power_W"][k] / power - 1) <= 2e-3, (v, curve["power_W"][k], power)
        pitch = math.degrees(float(np.mean(res.channel("pitch_1")[-1600:])))
        ref = float(np.interp(v, tab["wind_speed_mps"], tab["pitch_deg"]))
        assert abs(pitch - ref) <= (0.5 if v < 5.5 else 1.0), (v, pitch, ref)


def test_the_nrel5mw_baseline_keeps_fine_pitch_below_rated(gains) -> None:
    """Jonkman's NREL 5-MW baseline has no minimum-pitch schedule (its rotor at 6.9 rpm does
    not brake at cut-in), and the tuned design keeps fine pitch."""
    from mpc_wt.controllers.baseline import min_pitch_schedule

    tb = linearize.load_turbine("nrel5mw")
    assert gains.min_pitch_speeds == () and min_pitch_schedule(tb, gains.k_opt) == ((), ())
    ctl = BaselineController(tb, gains)
    assert ctl.min_pitch(ctl.w_cutin) == ctl.min_pitch(ctl.w_rated) == 0.0


@pytest.mark.parametrize("speeds, offsets", [((1.0,), (0.0,)), ((1.0, 2.0), (0.1,)),
                                             ((2.0, 1.0), (0.1, 0.0)),
                                             ((1.0, 2.0), (-0.1, 0.0)),
                                             ((1.0, float("nan")), (0.1, 0.0))])
def test_a_bad_minimum_pitch_schedule_is_refused(gains, speeds, offsets) -> None:
    import dataclasses

    with pytest.raises(ValueError, match="min_pitch_speeds and min_pitch_offsets"):
        dataclasses.replace(gains, min_pitch_speeds=speeds, min_pitch_offsets=offsets)


def test_a_turbine_whose_fine_pitch_is_one_degree_stays_in_region_2(turbine) -> None:
    """Jonkman et al.'s torque law switches to region 3 at 1 deg of pitch (VS_Rgn3MP) on a
    turbine whose fine pitch is 0; counted from the turbine's own fine pitch, a turbine at
    1 deg of fine pitch stays in region 2 at 9 m/s: its rotor runs at the trim's speed (the
    trim solves the same turbine at fine pitch; 1 % asked) instead of braking at rated torque.
    The NREL 5-MW with its fine pitch raised to 1 deg is that turbine."""
    import dataclasses

    from mpc_wt.run import run_controller

    t1 = dataclasses.replace(turbine, operation=dataclasses.replace(
        turbine.operation, fine_pitch_rad=math.radians(1.0)))
    op = linearize.trim(t1, 9.0)
    assert op.pitch_rad == pytest.approx(math.radians(1.0), abs=1e-9)
    res = run_controller(t1, "baseline", 9.0, duration=60.0, turbulence="steady")
    late = res.t > 40.0
    assert res.channel("rotor_speed")[late].mean() == pytest.approx(op.rotor_speed_rad_s,
                                                                     rel=0.01)
    pitch = np.asarray(res.channel("pitch_1"))[late]
    assert np.all(pitch < math.radians(1.5))

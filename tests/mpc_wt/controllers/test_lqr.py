"""Gain synthesis: LQR against closed forms and python-control, the PI
observer of Do et al. (eqs 13-16), LQR+PIO in the loop, bad input."""
from __future__ import annotations

import functools
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import linearize
from mpc_wt.controllers.lqr import (
    REGION3_SCALES,
    REGION3_WEIGHTS,
    TURBINE_MEASURED,
    LQRPIOController,
    design_lqr,
    design_lqr_family,
    design_pi_observer,
    turbine_scales,
)
from mpc_wt.errors import SynthesisError


@functools.lru_cache(maxsize=1)
def _rotor_speed_model() -> linearize.LinearModel:
    """A real model's structure (names, units) to put the scalar systems in."""
    base = linearize.linearize(linearize.load_turbine(), 18.0,
                               config=linearize.PlantConfig.madsen())
    return base.select(outputs=["rotor_speed"])


def _scalar_model(a: float, b: float, dt: float | None = None) -> linearize.LinearModel:
    m = _rotor_speed_model()
    import dataclasses

    return dataclasses.replace(
        m, A=np.array([[a]]), B_u=np.array([[b]]), B_d=np.zeros((1, 1)),
        C_z=np.array([[1.0]]), D_u=np.zeros((1, 1)), D_d=np.zeros((1, 1)),
        states=("rotor_speed",), inputs=("pitch_ref_1",), disturbances=("wind_1",),
        outputs=("rotor_speed",), state_units=("rad/s",), input_units=("rad",),
        disturbance_units=("m/s",), output_units=("rad/s",), x0=np.zeros(1), u0=np.zeros(1),
        d0=np.zeros(1), z0=np.zeros(1), dt=dt)


@settings(max_examples=40, deadline=None)
@given(a=st.floats(-3, 3), b=st.floats(0.1, 5) | st.floats(-5, -0.1), q=st.floats(0.01, 100),
       r=st.floats(0.01, 100))
def test_scalar_lqr_matches_the_closed_form(a: float, b: float, q: float, r: float) -> None:
    # analytic: 2 a p - p^2 b^2 / r + q = 0, p = r (a + sqrt(a^2 + b^2 q / r)) / b^2, k = b p / r
    d = design_lqr(_scalar_model(a, b), state_weights={"rotor_speed": q},
                   input_weights={"pitch_ref_1": r}, inputs=("pitch_ref_1",))
    p = r * (a + math.sqrt(a * a + b * b * q / r)) / (b * b)
    assert d.P[0, 0] == pytest.approx(p, rel=1e-8)
    assert d.K[0, 0] == pytest.approx(b * p / r, rel=1e-8)
    assert d.closed_loop_eigs.real.max() < 0


def test_scalar_discrete_lqr_matches_the_closed_form() -> None:
    # analytic DARE for x+ = a x + b u: p = q + a^2 p - a^2 b^2 p^2 / (r + b^2 p)
    a, b, q, r = 1.2, 0.5, 2.0, 0.7
    d = design_lqr(_scalar_model(a, b, dt=0.1), state_weights={"rotor_speed": q},
                   input_weights={"pitch_ref_1": r}, inputs=("pitch_ref_1",))
    # b^2 p^2 + (r - a^2 r - q b^2) p - q r = 0
    cc = r - a * a * r - q * b * b
    p = (-cc + math.sqrt(cc * cc + 4 * b * b * q * r)) / (2 * b * b)
    assert d.P[0, 0] == pytest.approx(p, rel=1e-9)
    assert d.K[0, 0] == pytest.approx(a * b * p / (r + b * b * p), rel=1e-9)


@pytest.fixture(scope="module")
def do_model(turbine: linearize.Turbine) -> linearize.LinearModel:
    return linearize.linearize(turbine, 18.0, config=linearize.PlantConfig.do())


def test_lqr_on_the_turbine_solves_the_riccati_equation(do_model) -> None:
    """Independent of the solver it wraps: with the weights built by hand (state weights, an
    output weight on a root moment and one on a pitch rate, whose feedthrough from the pitch
    reference enters R and the cross term N: the cost w (C_i x + D_i u)^2), K = R^-1 (B'P + N')
    where P solves A'P + PA - (PB + N) R^-1 (B'P + N') + Q = 0 (Do et al. eq 10 with the cross
    term) to the Riccati residual's rounding, P is symmetric positive semidefinite and A - BK
    is Hurwitz."""
    w = {"rotor_speed": 5.0, "tower_fa_velocity": 1.0, "flap_rate_1": 1.0}
    ow = {"flap_moment_2": 1e-14, "pitch_rate_3": 0.3}
    d = design_lqr(do_model, state_weights=w, output_weights=ow)
    nx = do_model.A.shape[0]
    q, r, n = np.zeros((nx, nx)), np.eye(3), np.zeros((nx, 3))
    for name, v in w.items():
        i = do_model.states.index(name)
        q[i, i] = v
    for name, v in ow.items():
        c = do_model.C_z[do_model.outputs.index(name)]
        dd = do_model.D_u[do_model.outputs.index(name), :3]
        q += v * np.outer(c, c)
        r += v * np.outer(dd, dd)
        n += v * np.outer(c, dd)
    # the pitch rate is (pitch_ref - pitch) / tau: the servo's time constant, by hand
    tau = 1.0 / do_model.D_u[do_model.outputs.index("pitch_rate_3"), 2]
    assert 0.01 < tau < 1.0 and r[2, 2] == pytest.approx(1.0 + 0.3 / tau ** 2)
    a, b, p = do_model.A, do_model.B_u[:, :3], d.P
    g = p @ b + n
    res = a.T @ p + p @ a - g @ np.linalg.solve(r, g.T) + q
    scale = np.abs(a.T @ p).max() + np.abs(q).max()
    assert np.abs(res).max() < 1e-8 * scale
    np.testing.assert_allclose(d.K, np.linalg.solve(r, g.T), rtol=1e-9,
                               atol=1e-12 * np.abs(d.K).max())
    np.testing.assert_allclose(p, p.T, atol=1e-9 * np.abs(p).max())
    assert np.linalg.eigvalsh(0.5 * (p + p.T)).min() > -1e-9 * np.abs(p).max()
    assert np.linalg.eigvals(a - b @ d.K).real.max() < 0


def _pitch_rate_cost(model: linearize.LinearModel, k: np.ndarray) -> float:
    """The pitch rates' share of the cost, sum_i int z_i^2 dt with z_i = (C_i - D_i K) x, from
    x0 ~ N(0, I) under u = -K x: trace of the closed loop's Lyapunov solution (closed form)."""
    import scipy.linalg

    rows = [model.outputs.index(f"pitch_rate_{i}") for i in (1, 2, 3)]
    cz = model.C_z[rows] - model.D_u[rows, :3] @ k
    acl = model.A - model.B_u[:, :3] @ k
    return float(np.trace(scipy.linalg.solve_continuous_lyapunov(acl.T, -cz.T @ cz)))


@settings(max_examples=12, deadline=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(w1=st.floats(0.0, 2.0), dw=st.floats(0.05, 3.0))
def test_a_heavier_pitch_rate_weight_never_lets_the_pitch_move_faster(do_model, w1, dw) -> None:
    """Optimality alone orders the designs: with J = J_rest + w J_rate minimised by K_w,
    J_rate(K_w2) <= J_rate(K_w1) for w2 > w1 (add the two optimality inequalities), with J_rate
    from the closed-loop Lyapunov equation, not from the design's Riccati solution."""
    w = {"rotor_speed": 5.0, "tower_fa_velocity": 1.0}
    costs = [_pitch_rate_cost(do_model, design_lqr(
        do_model, state_weights=w, output_weights={f"pitch_rate_{i}": v for i in (1, 2, 3)},
        scales={**{f"pitch_rate_{i}": math.radians(8.0) for i in (1, 2, 3)}}).K)
        for v in (w1, w1 + dw)]
    assert costs[1] <= costs[0] * (1.0 + 1e-7)


def test_lqr_family_gives_one_gain_per_wind(turbine) -> None:
    fam = linearize.linearize_family(turbine, [14.0, 18.0, 22.0],
                                     config=linearize.PlantConfig.do())
    gains = design_lqr_family(fam, state_weights={"rotor_speed": 1.0})
    assert [g.wind_mps for g in gains] == [14.0, 18.0, 22.0]
    # the pitch sensitivity grows with wind, so the speed gain needed falls
    ks = [abs(g.K[0, g.states.index("rotor_speed")]) for g in gains]
    assert ks[0] > ks[1] > ks[2]


def test_pi_observer_is_stable_and_integral_gain_grows_with_q(do_model) -> None:
    # Do et al. eqs 15-16: A_e - L C_e stable; q >> 1 raises ||L2||_F / ||L1||_F
    ratios = []
    for q in (1e3, 1e5, 1e7):
        ob = design_pi_observer(do_model, q=q)
        assert ob.error_eigs.real.max() < 0
        ratios.append(ob.gain_ratio)
    assert ratios[0] < ratios[1] < ratios[2]


def test_pi_observer_recovers_a_constant_unknown_input(do_model) -> None:
    # on its own (linear) model, a step of blade wind is estimated exactly in steady state
    ob = design_pi_observer(do_model, q=1e5)
    nx = do_model.A.shape[0]
    f = np.array([1.0, -0.5, 0.25])
    # the plant's steady state under the step, stabilized by an LQR (the open loop drifts)
    lq = design_lqr(do_model)
    acl = do_model.A - do_model.B_u[:, :3] @ lq.K
    x_ss = -np.linalg.solve(acl, do_model.B_d @ f)
    y = ob.C_e[:, :nx] @ x_ss
    # observer steady state with u = -K x_ss: 0 = (Ae - L Ce) xe + Be u + L y
    u = np.zeros(4)
    u[:3] = -lq.K @ x_ss
    ao = ob.A_e - ob.L @ ob.C_e
    xe = -np.linalg.solve(ao, ob.B_e @ u + ob.L @ y)
    np.testing.assert_allclose(xe[nx:], f, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(xe[:nx], x_ss, rtol=1e-6, atol=1e-9)


def test_pi_observer_on_turbine_measurements_recovers_a_constant_wind(do_model) -> None:
    """Generator speed, tower-top acceleration and root moments (what a turbine's controller
    gets), generated from the model's own output equations with the wind's direct part
    (z = C_z x + D_u u + D_d f): the observer's steady state has the wind deviation and the
    states exactly. (An observer that left out D_d would read the moments' direct response to
    the wind as flap deflection.)"""
    ob = design_pi_observer(do_model, q=1e3, measured=TURBINE_MEASURED,
                            scales=turbine_scales(do_model))
    nx = do_model.A.shape[0]
    f = np.array([0.8, -0.4, 0.3])
    lq = design_lqr(do_model)
    acl = do_model.A - do_model.B_u[:, :3] @ lq.K
    x_ss = -np.linalg.solve(acl, do_model.B_d @ f)
    u = np.zeros(4)
    u[:3] = -lq.K @ x_ss
    rows = [do_model.outputs.index(n) for n in TURBINE_MEASURED]
    y = do_model.C_z[rows] @ x_ss + do_model.D_u[rows] @ u + do_model.D_d[rows] @ f
    xe = -np.linalg.solve(ob.A_e - ob.L @ ob.C_e, (ob.B_e - ob.L @ ob.D_e) @ u + ob.L @ y)
    np.testing.assert_allclose(xe[nx:], f, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(xe[:nx], x_ss, rtol=1e-6, atol=1e-9)


def test_turbine_scales_are_the_structures_response(do_model) -> None:
    """The tower-top acceleration per metre of displacement is the first fore-aft mode's
    (2 pi f)^2: f = 0.324 Hz for the NREL 5-MW (Jonkman et al. 2009, table 9-1, 0.3240 Hz),
    within 10 % (the model's tower carries the nacelle's rotary inertia and aerodynamic
    stiffness)."""
    s = turbine_scales(do_model)
    assert s["tower_fa_acceleration"] == pytest.approx((2 * math.pi * 0.324) ** 2, rel=0.1)
    assert s["flap_moment_1"] > 1e5
    assert s["flap_moment_2"] == pytest.approx(s["flap_moment_1"], rel=1e-9)
    assert s["flap_moment_3"] == pytest.approx(s["flap_moment_1"], rel=1e-9)


@pytest.mark.parametrize("kwargs, match", [
    ({"state_weights": {"rotor_speed": -1.0}}, "weight 'rotor_speed' must be finite and >= 0"),
    ({"state_weights": {"rotor_sped": 1.0}}, "unknown state 'rotor_sped'"),
    ({"input_weights": {"pitch_ref_1": 0.0}}, "must be finite and > 0"),
    ({"inputs": ("yaw",)}, "not among the model's inputs"),
    ({"scales": {"rotor_speed": 0.0}}, "scale 'rotor_speed' must be finite and > 0"),
])
def test_lqr_bad_weights(do_model, kwargs, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        design_lqr(do_model, **kwargs)


def test_uncontrollable_pair_is_named() -> None:
    # an unstable mode the input cannot reach
    m = _scalar_model(1.0, 0.0)
    with pytest.raises(SynthesisError, match="not stabilizable.*1\\+0j"):
        design_lqr(m, inputs=("pitch_ref_1",))


def test_unobservable_pair_is_named(do_model) -> None:
    # measuring only the tower cannot see the blade-wind integrators in full
    with pytest.raises(SynthesisError, match="not detectable from \\['tower_fa_displacement'\\]"):
        design_pi_observer(do_model, measured=("tower_fa_displacement",))


def test_observer_bad_input(do_model) -> None:
    with pytest.raises(ValueError, match="q must be finite and > 0"):
        design_pi_observer(do_model, q=-1.0)
    with pytest.raises(ValueError, match="neither outputs nor states"):
        design_pi_observer(do_model, measured=("lidar",))
    with pytest.raises(ValueError, match="continuous model"):
        design_pi_observer(do_model.discretize(0.1))


def _on_turbine_signals(model, q=1e3):
    """The PI observer on what a turbine's controller measures (its shipped law's signals)."""
    from mpc_wt.controllers.lqr import TURBINE_MEASURED, turbine_scales

    sy = {k: v * (10.0 if k.startswith("flap_moment") else 1.0)
          for k, v in turbine_scales(model).items()}
    return design_pi_observer(model, q=q, measured=TURBINE_MEASURED, scales=sy)


def _shipped(turbine, *design):
    from mpc_wt.run import law_controller

    return law_controller(LQRPIOController(*design), "lqr-pio", turbine)


def test_lqr_pio_regulates_speed_in_turbulence(turbine, params, do_model) -> None:
    """One design at 18 m/s run by its shipped law, in the loop on the nonlinear plant, 18 m/s
    class A, 60 s: the rotor within 3 % of rated on average, its std under 0.05 rad/s."""
    from mpc_wt.simulation.loop import simulate_closed_loop
    from mpc_wt.simulation.scenario import Scenario, make_wind

    lq = design_lqr(do_model, state_weights={"rotor_speed": 5.0, "tower_fa_velocity": 1.0},
                    scales={"rotor_speed": 0.05, "tower_fa_velocity": 0.1,
                            **{f"pitch_ref_{i}": math.radians(1) for i in (1, 2, 3)}})
    # q = 1e3: with q = 1e5 and the feedforward the loop diverges on the nonlinear plant (the
    # high-gain observer takes the plant's 1P gravity/shear flap content for wind)
    ctl = _shipped(turbine, do_model, turbine, lq, _on_turbine_signals(do_model))
    wind, _ = make_wind(turbine, Scenario(18.0, "A", 1, 60.0, 0.2))
    op = linearize.trim(turbine, 18.0)
    r = simulate_closed_loop(params, ctl, wind, 60.0, x0=op.x, u0=op.u)
    keep = r.t > 10
    speed = r.x[keep, 2]
    assert abs(speed.mean() / 1.2671 - 1) < 0.03
    assert speed.std() < 0.05


def test_high_gain_pi_observer_holds_the_loop_in_turbulence(turbine, params, do_model) -> None:
    """Do et al. (sec. 2.4) ask for ||L2||_F >> ||L1||_F. On the paper's displacements the
    default q = 1e3 gives the ratio 0.28 and q = 1e7 1.98. Run by the shipped law on what a
    turbine measures (generator speed, tower-top acceleration, root moments), with the pitch
    command held to what the actuator can follow, the high-gain observer keeps the loop in
    class-A turbulence at 18 m/s over 120 s and regulates the rotor speed at least as well
    as the default (std within 10 % of the default's or below it; measured 0.016 against 0.023
    rad/s, 1.3 and 1.8 % of rated). Before that hold, the observer read the gap to the
    rate-limited pitch as an unknown input and the loop diverged from q = 1e4 on."""
    from mpc_wt.simulation.loop import simulate_closed_loop
    from mpc_wt.simulation.scenario import Scenario, make_wind

    lq = design_lqr(do_model, state_weights=REGION3_WEIGHTS, scales=REGION3_SCALES)
    default, high = design_pi_observer(do_model), design_pi_observer(do_model, q=1e7)
    # the ratio of the default and of the paper's "high gain" direction (Do et al. sec. 2.4)
    assert default.q == 1e3 and default.gain_ratio < 0.3 and high.gain_ratio > 1.9
    default, high = _on_turbine_signals(do_model), _on_turbine_signals(do_model, q=1e7)
    wind, _ = make_wind(turbine, Scenario(18.0, "A", 1, 120.0, 0.2))
    op = linearize.trim(turbine, 18.0)
    std = []
    for obs in (default, high):
        r = simulate_closed_loop(params, _shipped(turbine, do_model, turbine, lq, obs), wind,
                                 120.0, x0=op.x, u0=op.u)
        std.append(r.x[r.t > 10, 2].std())
    assert std[0] < 0.05
    assert std[1] <= 1.10 * std[0]


@pytest.mark.parametrize("observer_q, speed_tol", [
    pytest.param(1000.0, 0.003, marks=pytest.mark.slow), (None, 0.01)])
def test_scheduled_lqr_pio_switches_without_a_bump(observer_q, speed_tol) -> None:
    """The scheduled lqr-pio on a ramp 16 -> 18 m/s over 40 s (uniform wind, from the 16 m/s trim):
    it moves to the grid winds 17 and 18 on its own wind estimate (low-passed over 30 s, so
    it trails the ramp), and at each switch
    the pitch command moves by no more than the 99th percentile of its step-to-step moves
    elsewhere (measured: 0.0007 deg at the switches against 0.0016 deg), the rotor speed
    within 0.3 % of rated throughout with the PI observer's q = 1000 (measured 0.16 %), within
    1 % with the kind's default q = 100, slower to follow the ramp (measured 0.8 %)."""
    from mpc_wt.run import build_controller
    from mpc_wt.simulation.loop import simulate_closed_loop
    from mpc_wt.simulation.scenario import Scenario

    tb = linearize.load_turbine()
    opts = {} if observer_q is None else {"observer_q": observer_q}
    built, _, _ = build_controller(tb, "lqr-pio", Scenario(16.0, "steady", 1, 5.0), opts)
    t = np.arange(0.0, 100.0, 0.5)
    y = np.linspace(-80.0, 80.0, 9)
    z = tb.geometry.hub_height + y
    v = np.clip(16.0 + (t - 5.0) * 2.0 / 40.0, 16.0, 18.0)
    wind = linearize.GridWind(t=t, y=y, z=z, u=np.broadcast_to(v[:, None, None],
                                                               (t.size, 9, 9)).copy())
    op = linearize.trim(tb, 16.0)
    r = simulate_closed_loop(linearize.plant_params(tb), built.controller, wind, 85.0,
                             x0=op.x, u0=op.u)
    grid = r.controller["schedule_grid_wind"]
    at = np.flatnonzero(np.diff(grid) != 0) + 1
    assert list(grid[at]) == [17.0, 18.0]
    step = np.abs(np.diff(np.degrees(r.channel("pitch_ref_1"))))
    assert step[at - 1].max() <= np.percentile(step, 99)
    rated = tb.operation.rated_rotor_speed_rad_s
    assert np.abs(r.channel("rotor_speed") / rated - 1.0).max() < speed_tol


@pytest.mark.parametrize("wind", [11.0, pytest.param(12.0, marks=pytest.mark.slow), 13.0])
def test_scheduled_lqr_pio_rides_turbulence_through_rated(turbine, wind: float) -> None:
    """Near rated wind in class-A turbulence (200 s, seed 5, not one its settings were chosen
    on; 12 m/s in the slow suite) the scheduled LQR-PIO neither stalls nor runs away: the
    rotor stays within 0.5..1.15 x rated speed and the mean power within 2 % of the
    baseline's on the same field. (Before
    its pitch command was held to what the actuator can follow, the observer read the gap to
    a rate-limited pitch as wind, estimated 55-83 m/s and pitched the rotor to a stop.)"""
    from mpc_wt.run import run_controller
    from mpc_wt.simulation.scenario import Scenario

    sc = Scenario(wind, "A", 5, 200.0)
    res = run_controller(turbine, "lqr-pio", sc)
    base = run_controller(turbine, "baseline", sc)
    rated = turbine.operation.rated_rotor_speed_rad_s
    w = res.channel("rotor_speed")[res.t >= 30.0] / rated
    assert 0.5 <= w.min() and w.max() <= 1.15, (w.min(), w.max())
    p = res.channel("gen_power")[res.t >= 30.0].mean()
    p0 = base.channel("gen_power")[base.t >= 30.0].mean()
    assert abs(p / p0 - 1.0) <= 0.02, p / p0
    if wind >= 13.0:
        # above rated, where both pitch, the sign-off's bound: at most 3x the baseline's pitch
        # travel (measured 2.72x at 13 m/s; 4.4x at 11 m/s, where the baseline hardly
        # pitches; 5-6x with the PI observer's earlier default q = 1000)
        def travel(r):
            p = np.column_stack([r.channel(f"pitch_{i}") for i in (1, 2, 3)])[r.t >= 30.0]
            return float(np.abs(np.diff(p, axis=0)).sum())
        assert travel(res) <= 3.0 * travel(base), travel(res) / travel(base)


def test_lqr_pio_rides_through_an_eog_at_rated() -> None:
    """The IEC 61400-1 extreme operating gust at 11.3 m/s (class I; the rotor reversed at
    36 s in an earlier design): the rotor stays within 1.2 x rated and never below 0.8 x
    rated (measured 0.96-1.12 x), no run warning."""
    import linearize
    from mpc_wt.run import run_controller
    from mpc_wt.simulation.scenario import Scenario

    t = linearize.load_turbine()
    res = run_controller(t, "lqr-pio", Scenario(11.3, "A", 1, 60.0, condition="eog",
                                                 event_at=20.0))
    w = res.channel("rotor_speed") / t.operation.rated_rotor_speed_rad_s
    assert 0.8 < w.min() and w.max() < 1.2
    assert res.meta["run_warnings"] == []


def test_the_scheduled_lqr_weights_follow_the_pitch_drives() -> None:
    """The scheduled LQR-PIO's default rotor-speed weight (region III) goes with the inverse
    square root of the pitch drives' rate over 8 deg/s and its tower fore-aft weight with that
    ratio itself: on the NREL 5-MW (8 deg/s) exactly Do et al.'s defaults as before (10 and
    1), on the IEA-15-240-RWT (2 deg/s) 20 and 0.25. Weights set as options, and the
    single-point design, are left as given; the single point has no pitch-rate weight unless
    one is set."""
    from mpc_wt.kinds import LQRPIOOptions

    five, fifteen = linearize.load_turbine("nrel5mw"), linearize.load_turbine("iea15mw")
    opts = LQRPIOOptions()
    for region in ("II", "III"):
        assert opts.lqr_weights(region, five) == opts.lqr_weights(region)
    w3, _ = opts.lqr_weights("III", fifteen)
    assert w3["rotor_speed"] == pytest.approx(20.0, rel=1e-3)
    assert w3["tower_fa_velocity"] == pytest.approx(0.25, rel=1e-3)
    w2, _ = opts.lqr_weights("II", fifteen)
    assert "rotor_speed" not in w2 and w2["tower_fa_velocity"] == pytest.approx(0.25, rel=1e-3)
    given = LQRPIOOptions(w_rotor_speed=3.0, w_tower_fa_velocity=0.7)
    assert given.lqr_weights("III", fifteen)[0] == {"rotor_speed": 3.0, "tower_fa_velocity": 0.7}
    single = LQRPIOOptions(design_wind_mps=18.0)
    assert single.lqr_weights("III", fifteen) == single.lqr_weights("III")
    # the pitch rate: weighted by default in the scheduled designs, not in the single point
    assert opts.output_weights() == {f"pitch_rate_{i}": 0.4 for i in (1, 2, 3)}
    assert single.output_weights() == {}
    assert LQRPIOOptions(design_wind_mps=18.0, w_pitch_rate=1.0).output_weights()[
        "pitch_rate_2"] == 1.0

"""MPC: Coleman weighting, LQR limit, constraints, bad input."""
from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

import linearize
from mpc_wt.controllers.mpc import MPC, MPCSettings, MPCWeights, coleman_weight


@settings(max_examples=100, deadline=None)
@given(psi=st.floats(0, 2 * math.pi), m=st.lists(st.floats(-1e7, 1e7), min_size=3, max_size=3))
def test_coleman_weight_gives_tilt_and_yaw_squared(psi: float, m: list[float]) -> None:
    # analytic (Madsen eqs 8, 9, 21): M^T T M = M_t^2 + M_y^2 for every azimuth, with
    # T = (2^2 / 3^2) [[1, -1/2, -1/2], ...]; the printed 2^2 / 3^3 (eq 22) does not hold
    ang = psi + 2 * math.pi * np.arange(3) / 3
    tc = 2 / 3 * np.vstack([np.cos(ang), np.sin(ang)])
    mv = np.array(m)
    mt, my = tc @ mv
    assert_allclose(mv @ coleman_weight() @ mv, mt**2 + my**2, rtol=1e-9,
                    atol=1e-9 * (mv @ mv + 1.0))


@settings(max_examples=60, deadline=None)
@given(psi=st.floats(0, 2 * math.pi), m=st.lists(st.floats(-1e7, 1e7), min_size=3, max_size=3))
def test_printed_constant_fails_the_identity(psi: float, m: list[float]) -> None:
    """Madsen eq 21 (M' T M = M_t^2 + M_y^2) checked directly on random blade moments with
    eq 22 as printed, T = (2^2 / 3^3) [[1, -1/2, -1/2], ...] written out here: it gives a third
    of M_t^2 + M_y^2 whenever the moments are not all equal, so the printed constant is wrong
    by 3 (coleman_weight uses 2^2 / 3^2, the property test above)."""
    ang = psi + 2 * math.pi * np.arange(3) / 3
    tc = 2 / 3 * np.vstack([np.cos(ang), np.sin(ang)])
    mv = np.array(m)
    tilt_yaw = float(np.sum((tc @ mv) ** 2))
    printed = 2 ** 2 / 3 ** 3 * np.array([[1.0, -0.5, -0.5], [-0.5, 1.0, -0.5],
                                          [-0.5, -0.5, 1.0]])
    assert_allclose(mv @ printed @ mv, tilt_yaw / 3, rtol=1e-9, atol=1e-9 * (mv @ mv + 1.0))
    # (where the squares are normal numbers: subnormal ones carry a few bits only)
    if tilt_yaw > max(1e-6 * (mv @ mv), 1e6 * np.finfo(float).tiny):
        assert abs(mv @ printed @ mv - tilt_yaw) > 0.6 * tilt_yaw


@pytest.fixture(scope="module")
def model(turbine: linearize.Turbine) -> linearize.LinearModel:
    return linearize.linearize(turbine, 18.0, config=linearize.PlantConfig.madsen())


def test_long_horizon_converges_to_discrete_lqr(model, turbine: linearize.Turbine) -> None:
    # The unconstrained MPC with a long horizon converges to the discrete LQR gain
    # with the same weights: cost z'Qz + u'Ru with z = C x + D u gives state weight C'QC,
    # cross term C'QD, input weight R + D'QD (python-control dlqr)
    import control

    ctl = MPC(model, turbine, MPCSettings(estimator="full-state", horizon=200, control_horizon=200, backend="osqp"))
    q, r = ctl._weights()
    m = ctl.model
    qx = m.C_z.T @ q @ m.C_z
    ru = r + m.D_u.T @ q @ m.D_u
    k_lqr, _, _ = control.dlqr(m.A, m.B_u, 0.5 * (qx + qx.T), 0.5 * (ru + ru.T),
                               m.C_z.T @ q @ m.D_u)
    # first move of the unconstrained QP: u_0 = -[H^-1 Theta' Qbar Psi]_(0) x
    k_mpc = np.linalg.solve(ctl._h, ctl._theta.T @ ctl._qbar @ ctl._psi)[:4]
    assert_allclose(k_mpc, k_lqr, rtol=1e-4, atol=1e-6 * np.abs(k_lqr).max())


def test_qp_solution_equals_the_unconstrained_one_when_nothing_binds(model, turbine) -> None:
    ctl = MPC(model, turbine, MPCSettings(estimator="full-state", backend="osqp"))
    x = np.zeros(8)
    x[2] = 0.005                                     # small rotor overspeed [rad/s]
    plan, status = ctl.solve(x)
    assert status == "solved"
    exact = -np.linalg.solve(ctl._h, ctl._theta.T @ ctl._qbar @ ctl._psi @ x)
    # tolerance from OSQP's eps_abs = eps_rel = 1e-6 on a scaled problem
    assert_allclose(plan.ravel(), exact, rtol=1e-3, atol=1e-3 * np.abs(exact).max())
    assert plan[0, 0] > 0                            # overspeed: pitch toward feather


def test_constraints_hold_when_they_bind(model, turbine: linearize.Turbine) -> None:
    ctl = MPC(model, turbine, MPCSettings(estimator="full-state", backend="osqp"))
    x = np.zeros(8)
    x[2] = 0.3                                       # large overspeed: the pitch rate binds
    plan, status = ctl.solve(x)
    assert status == "solved"
    pa = turbine.pitch_actuator
    u = model.u0 + plan
    tol = 1e-4
    assert u[:, :3].min() >= pa.min_pitch_rad - tol and u[:, :3].max() <= pa.max_pitch_rad + tol
    # predicted pitch rates within +-8 deg/s (to the solver tolerance)
    z = ctl._psi @ x + ctl._theta @ plan.ravel()
    rates = z[ctl._prate_rows]
    assert np.abs(rates).max() <= pa.max_rate_rad_s * (1 + 1e-3)
    assert np.abs(rates).max() >= pa.max_rate_rad_s * 0.99   # it does bind here
    tq = u[:, 3]
    assert np.abs(np.diff(np.r_[model.u0[3], tq])).max() <= 15000.0 * 0.1 * (1 + 1e-3)


def test_collective_variant(model, turbine: linearize.Turbine) -> None:
    """Madsen's collective MPC plans one pitch and the torque; a rotor above its operating
    point's speed is met by pitching to feather."""
    ctl = MPC(model, turbine, MPCSettings(estimator="full-state", collective=True, backend="osqp"))
    x = np.zeros(8)
    x[2] = 0.01
    plan, status = ctl.solve(x)
    assert status == "solved" and plan.shape == (ctl.hu, 2) and plan[0, 0] > 0.0


@pytest.mark.parametrize("kwargs, match", [
    (dict(horizon=0), "horizon must be an integer >= 1"),
    (dict(horizon=5, control_horizon=8), "must not exceed horizon"),
    (dict(weights=None, dt=-0.1), "dt must be > 0"),
])
def test_bad_arguments(model, turbine, kwargs, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        MPC(model, turbine, MPCSettings(**kwargs))


def test_negative_weight_is_rejected() -> None:
    with pytest.raises(ValueError, match=r"weight 'rotor_speed' must be finite and >= 0 "
                                         r"\(the QP must be convex\)"):
        MPCWeights(outputs={"rotor_speed": -1.0})


def test_preview_of_wrong_shape(model, turbine) -> None:
    ctl = MPC(model, turbine, MPCSettings(estimator="full-state", backend="osqp"))
    with pytest.raises(ValueError, match=r"d_preview has shape \(10, 3\); expected \(H_p, n_d\)"):
        ctl.solve(np.zeros(8), np.zeros((10, 3)))
    with pytest.raises(ValueError, match=r"x has shape \(7,\)"):
        ctl.solve(np.zeros(7))


def test_mpc_in_the_loop_respects_limits(turbine: linearize.Turbine,
                                         params: linearize.PlantParams, model) -> None:
    """One design at 18 m/s run by its shipped law in a steady sheared 18 m/s for 30 s: rated
    power within 2 %, no QP fallback, the pitch above fine pitch and within the drives' rate."""
    from mpc_wt.run import law_controller
    from mpc_wt.simulation.loop import simulate_closed_loop

    op = linearize.trim(turbine, 18.0)
    ctl = law_controller(MPC(model, turbine, MPCSettings(backend="daqp")), "mpc", turbine)
    r = simulate_closed_loop(params, ctl, linearize.SteadyWind(18.0, 0.2), 30.0, x0=op.x,
                             u0=op.u, controller_dt=0.1)
    late = r.t > 5
    assert abs(r.channel("gen_power")[late].mean() / 5e6 - 1) < 0.02
    assert np.all(r.controller["qp_fallback"] == 0)
    pa = turbine.pitch_actuator
    assert r.x[:, 5:8].min() >= pa.min_pitch_rad - 1e-9
    assert np.abs(np.diff(r.x[:, 5:8], axis=0)).max() / r.t[1] <= pa.max_rate_rad_s * (1 + 1e-6)


@pytest.mark.parametrize("overspeed", [0.005, 0.3])
def test_daqp_backend_agrees_with_osqp(model, turbine, overspeed: float) -> None:
    pytest.importorskip("daqp")
    x = np.zeros(8)
    x[2] = overspeed
    a, sa = MPC(model, turbine, MPCSettings(estimator="full-state", backend="osqp")).solve(x)
    b, sb = MPC(model, turbine, MPCSettings(estimator="full-state", backend="daqp")).solve(x)
    assert sa == sb == "solved"
    # First moves agree within 0.01 deg pitch and 0.1 % of rated torque
    assert np.abs(a[0, :3] - b[0, :3]).max() < math.radians(0.01)
    assert abs(a[0, 3] - b[0, 3]) < 0.001 * 43093.55


def test_unknown_backend(model, turbine) -> None:
    with pytest.raises(ValueError, match="backend must be 'osqp' or 'daqp'"):
        MPC(model, turbine, MPCSettings(estimator="full-state", backend="qpoases"))


def test_lidar_preview_reduces_asymmetric_loads(turbine: linearize.Turbine,
                                                params: linearize.PlantParams, model) -> None:
    """One design at 18 m/s run by its shipped law, with the idealized CW LIDAR's per-blade
    preview of a frozen field (the host fills the lidar records) against the same law on its
    Kalman filter's wind alone: the tilt and yaw moments and the 1P flap moment fall, the
    power's std does not grow. 18 m/s, class A, 60 s after 10 s. Measured (2026-12-04): tilt
    std x0.44, yaw std x0.49, 1P flap x0.36, power std x0.99; bounds about 10 % above each."""
    import lidar
    from mpc_wt.assessment.performance import harmonic_psd
    from mpc_wt.run import law_controller
    from mpc_wt.simulation.loop import simulate_closed_loop
    from mpc_wt.simulation.preview import LidarPreview

    f = lidar.generate_field(lidar.TurbulenceSpec(18.0, "A", duration=80.0), 3)
    gw = linearize.GridWind(t=f.t, y=f.y, z=f.z, u=np.maximum(f.u, 0.0))
    op = linearize.trim(turbine, 18.0)
    lid = lidar.CWLidar(63.0, range_weighting=False, los_error=False)
    design = MPC(model, turbine, MPCSettings(backend="daqp"))
    out = {}
    for label in ("none", "lidar"):
        if label == "none":
            ctl = law_controller(design, "mpc", turbine)
        else:
            prev = LidarPreview(lidar.LidarSensor(lid, field=f), 15, 0.1,
                                preview_time=54.0 / 18.0)
            ctl = law_controller(design, "mpc", turbine, lidar=prev.sensor, preview=prev)
        r = simulate_closed_loop(params, ctl, gw, 70.0, x0=op.x, u0=op.u, controller_dt=0.1)
        late = r.t > 10.0
        frot = float(r.channel("rotor_speed")[late].mean()) / (2 * math.pi)
        out[label] = (r.channel("tilt_moment")[late].std(), r.channel("yaw_moment")[late].std(),
                      harmonic_psd(r.channel("flap_moment_1")[late], 80.0, frot, (1,),
                                   nperseg=2048)[1], r.channel("gen_power")[late].std())
        assert r.controller["qp_fallback"].sum() == 0
    for k, bound in enumerate((0.49, 0.54, 0.40, 1.05)):
        assert out["lidar"][k] < bound * out["none"][k], (k, out)


def test_from_turbine_matches_the_explicit_model(model, turbine) -> None:
    ctl = MPC.from_turbine(turbine, 18.0, MPCSettings(estimator="full-state", horizon=15, backend="osqp"))
    ref = MPC(model, turbine, MPCSettings(estimator="full-state", backend="osqp"))
    x = np.zeros(8)
    x[2] = 0.05
    assert_allclose(ctl.solve(x)[0], ref.solve(x)[0], atol=1e-9)


@pytest.mark.parametrize("wind", [math.nan, -3.0, 40.0, "18"])
def test_from_turbine_rejects_wind_outside_the_operating_range(turbine, wind) -> None:
    with pytest.raises(ValueError, match=r"wind_mps must be a finite mean wind within the "
                                         r"turbine's operating range 3\.\.25 m/s, got"):
        MPC.from_turbine(turbine, wind)


def test_from_turbine_rejects_wind_outside_the_family(turbine) -> None:
    fam = linearize.linearize_family(turbine, [16.0, 18.0],
                                     config=linearize.PlantConfig.madsen())
    ctl = MPC.from_turbine(turbine, 17.0, family=fam)
    assert ctl.model.A.shape == (8, 8)
    with pytest.raises(ValueError, match=r"wind_mps = 20 m/s is outside the family's range "
                                         r"16\.\.18 m/s"):
        MPC.from_turbine(turbine, 20.0, family=fam)


def _speeds(ctl: MPC, x: np.ndarray, plan: np.ndarray) -> np.ndarray:
    """Predicted rotor-speed deviations over the horizon for a plan."""
    k = ctl.model.outputs.index("rotor_speed")
    z = ctl._psi @ x + ctl._theta @ plan.ravel()
    return z[k::len(ctl.model.outputs)]


@pytest.fixture(params=["osqp", "daqp"])
def backend(request: pytest.FixtureRequest) -> str:
    if request.param == "daqp":
        pytest.importorskip("daqp")
    return str(request.param)


def test_soft_speed_limit_far_away_changes_nothing(model, turbine, backend: str) -> None:
    w0 = model.z0[model.outputs.index("rotor_speed")]
    x = np.zeros(8)
    x[2], x[0] = 0.01, 0.02
    a, sa = MPC(model, turbine,
                MPCSettings(estimator="full-state", backend=backend, max_rotor_speed=w0 + 1.0)).solve(x)
    b, _ = MPC(model, turbine, MPCSettings(estimator="full-state", backend=backend)).solve(x)
    assert sa == "solved"
    assert np.abs(a[:, :3] - b[:, :3]).max() < math.radians(0.01)
    assert np.abs(a[:, 3] - b[:, 3]).max() < 0.001 * turbine.rated_generator_torque


def test_soft_speed_limit_keeps_the_qp_feasible(model, turbine, backend: str) -> None:
    # the rotor already runs 0.03 rad/s fast, 0.01 above the limit: no input can change the
    # first predicted speed, so a hard limit would be infeasible; the slack takes the excess
    w0 = model.z0[model.outputs.index("rotor_speed")]
    x = np.zeros(8)
    x[2], x[3] = 0.03, 0.03 * turbine.drivetrain.gearbox_ratio
    soft = MPC(model, turbine, MPCSettings(estimator="full-state", backend=backend, max_rotor_speed=w0 + 0.02))
    plan, status = soft.solve(x)
    assert status == "solved"
    assert soft._last_slack == pytest.approx(0.01, abs=1e-5)
    free, _ = MPC(model, turbine, MPCSettings(estimator="full-state", backend=backend)).solve(x)
    s_soft, s_free = _speeds(soft, x, plan), _speeds(soft, x, free)
    assert np.all(s_soft <= s_free + 1e-6)
    assert (s_free - s_soft).max() > 1e-3       # the limit acts: the rotor is slowed faster


@pytest.mark.parametrize("kwargs, match", [
    (dict(max_rotor_speed=-1.0), "max_rotor_speed must be a finite speed > 0 rad/s or None, "
                                 "got -1.0"),
    (dict(max_rotor_speed=math.nan), "max_rotor_speed must be a finite speed"),
    (dict(max_rotor_speed=1.5, slack_weight=0.0), "slack_weight must be finite and > 0, got 0.0"),
    (dict(max_rotor_speed=1.5, slack_linear=math.inf), "slack_linear must be finite and > 0"),
])
def test_soft_constraint_bad_arguments(model, turbine, kwargs, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        MPC(model, turbine, MPCSettings(**kwargs))


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), size=st.floats(0.0, 3.0),
       soft=st.sampled_from([None, 1.35]))
def test_sparse_formulation_gives_the_condensed_moves(model, turbine, seed: int, size: float,
                                                      soft: float | None) -> None:
    # OSQP on the sparse formulation (states as variables, dynamics as
    # equalities) solves the same QP: the first move within 0.01 deg pitch and 0.1 % of rated
    # torque of the condensed one (the agreement tolerance), constraints binding or not
    rng = np.random.default_rng(seed)
    x = rng.normal(size=8) * 0.02 * size
    d = rng.normal(size=(15, 3)) * 0.5 * size
    up = rng.normal(size=4) * np.r_[0.005, 0.005, 0.005, 1000.0] * size
    cond = MPC(model, turbine, MPCSettings(estimator="full-state", max_rotor_speed=soft, backend="osqp"))
    sparse = MPC(model, turbine, MPCSettings(estimator="full-state", formulation="sparse", max_rotor_speed=soft,
                                             backend="osqp"))
    a, sa = cond.solve(x, d, up)
    b, sb = sparse.solve(x, d, up)
    if a is None:                  # infeasible hard constraints: both must say so
        assert b is None and sb == sa
        return
    assert sa == sb == "solved"
    assert np.abs(a[0, :3] - b[0, :3]).max() < math.radians(0.01)
    assert abs(a[0, 3] - b[0, 3]) < 0.001 * 43093.55
    assert sparse._last_slack == pytest.approx(cond._last_slack, abs=1e-4)


def test_osqp_without_an_answer_is_resolved_exactly(model, turbine, caplog) -> None:
    """At far-off states (shaft twist 0.06 rad,
    12x rated; 4.6 deg pitch error) OSQP can reach its iteration limit on a feasible QP (here
    forced with max_iter = 10, so the test does not hang on OSQP's version). The backend then
    re-solves it with Clarabel (logged); the first move equals DAQP's on the condensed QP (an
    independent, active-set solver) within the issue-6 agreement tolerance (0.01 deg, 0.1 % of
    rated torque). Over 304 draws at size 3 the two formulations now agree in every case;
    before, 31 of 400 OSQP solves ended without an answer."""
    import logging
    rng = np.random.default_rng(4194303)
    size = 3.0                          # the property test's draw, to the last bit
    x = rng.normal(size=8) * 0.02 * size
    d = rng.normal(size=(15, 3)) * 0.5 * size
    up = rng.normal(size=4) * np.r_[0.005, 0.005, 0.005, 1000.0] * size
    sparse = MPC(model, turbine, MPCSettings(estimator="full-state", formulation="sparse", max_rotor_speed=1.35,
                                             backend="osqp", solver_options={"max_iter": 10}))
    with caplog.at_level(logging.WARNING, logger="mpc_wt.controllers.qp"):
        b, sb = sparse.solve(x, d, up)
    assert "re-solved by Clarabel: solved" in caplog.text
    a, sa = MPC(model, turbine, MPCSettings(estimator="full-state", max_rotor_speed=1.35, backend="daqp")).solve(x, d, up)
    assert sa == sb == "solved"
    assert np.abs(a[0, :3] - b[0, :3]).max() < math.radians(0.01)
    assert abs(a[0, 3] - b[0, 3]) < 0.001 * 43093.55


def test_sparse_formulation_is_sparse(model, turbine) -> None:
    # the point of the formulation: P and A stay block-banded (nnz linear in the horizon)
    nnz = []
    for hp in (10, 20, 40):
        c = MPC(model, turbine, MPCSettings(estimator="full-state", horizon=hp, formulation="sparse", backend="osqp"))
        nnz.append(c._sparse_nnz)
    assert nnz[2] - nnz[1] == pytest.approx(2 * (nnz[1] - nnz[0]), rel=0.05)
    dense = MPC(model, turbine, MPCSettings(estimator="full-state", horizon=40, backend="osqp"))
    assert dense._h_s.size + dense._a_gen_s.size > 5 * nnz[2] / 2


def test_bad_formulation(model, turbine) -> None:
    with pytest.raises(ValueError, match="formulation must be 'condensed' or 'sparse', got 'x'"):
        MPC(model, turbine, MPCSettings(estimator="full-state", formulation="x", backend="osqp"))
    with pytest.raises(ValueError, match="formulation='sparse' needs backend='osqp'"):
        MPC(model, turbine, MPCSettings(estimator="full-state", formulation="sparse", backend="daqp"))


@pytest.mark.parametrize("formulation", ["condensed", "sparse"])
def test_osqp_public_interface_fallback_gives_the_same_moves(model, turbine,
                                                              formulation: str) -> None:
    # the compiled-object fast path and OSQP's public interface solve the same problem
    rng = np.random.default_rng(3)
    fast = MPC(model, turbine, MPCSettings(estimator="full-state", formulation=formulation, backend="osqp"))
    slow = MPC(model, turbine, MPCSettings(estimator="full-state", formulation=formulation, backend="osqp"))
    slow.qp_backend.fast = False
    for _ in range(20):
        x = rng.normal(size=8) * 0.03
        a, _ = fast.solve(x)
        b, _ = slow.solve(x)
        assert np.abs(a - b).max() < 1e-5 * (1 + np.abs(a).max())


def test_warm_start_never_holds_subnormal_numbers(model, turbine) -> None:
    """Regression: over many unconstrained QPs in a row (the shifted optimum at zero) OSQP's
    warm-started ADMM iterates decayed into subnormal numbers and every iteration became ~50
    times slower; they are rounded to 2^-52 absolute before each warm start now. 1600 QPs of
    small random states: no subnormal number in the warm start."""
    c = MPC(model, turbine, MPCSettings(estimator="full-state", backend="osqp"))
    rng = np.random.default_rng(5)
    seen = []
    for _ in range(1600):
        c.solve(1e-4 * rng.standard_normal(8))
        for v in c.qp_backend.warm:
            small = np.abs(v[v != 0])
            seen.append(int(np.sum(small < np.finfo(float).tiny)))
    assert len(seen) > 1500 and sum(seen) == 0


@pytest.mark.parametrize("rows", [15, 4, 1])
def test_the_backends_give_one_plan_with_a_preview(model, turbine, rows: int) -> None:
    """One QP with a per-blade preview of the horizon's length (a short preview held at its
    last row to the horizon, as the law holds it): DAQP through its C interface and through
    its Python Model give the same plan to 1e-9, OSQP within its tolerance."""
    pytest.importorskip("daqp")
    rng = np.random.default_rng(rows)
    dx = 0.02 * rng.standard_normal(8)
    blade = rng.normal(0.0, 1.5, (rows, 3))
    held = np.vstack([blade, np.repeat(blade[-1:], 15 - rows, 0)])
    plans = []
    for backend, opts in (("daqp", {}), ("daqp", {"interface": "python"}), ("osqp", {})):
        c = MPC(model, turbine, MPCSettings(estimator="full-state", backend=backend,
                                            solver_options=opts))
        plan, status = c.solve(dx, held)
        assert status == "solved"
        plans.append(plan)
    assert_allclose(plans[0], plans[1], rtol=0, atol=1e-9)
    assert np.abs(plans[0][0, :3] - plans[2][0, :3]).max() < math.radians(0.01)


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2**31 - 1))
def test_factored_step_map_equals_the_full_map(model, turbine, seed: int) -> None:
    """The step's affine map is evaluated on the rows it needs (c and one row per distinct
    bound): for random data z the shift and the bounds equal W z from numpy on the
    full map, condensed and sparse."""
    from mpc_wt.controllers.mpc import _bound_map

    rng = np.random.default_rng(seed)
    for form in ("condensed", "sparse"):
        c = MPC(model, turbine, MPCSettings(estimator="full-state", backend="osqp", formulation=form))
        nv, nc = len(c._c), len(c._lo)
        w = c._w_orig                        # W of the unshifted QP; shift it as the MPC does
        yt, const, sgn, kmap = _bound_map(np.vstack([w[:nv], w[nv:nv + nc], w[nv + nc:]]), nv)
        assert yt.shape[1] < nv + 2 * nc
        z = np.concatenate([[1.0], rng.standard_normal(w.shape[1] - 1)])
        y = yt.T @ z
        assert_allclose(const + sgn * y[kmap], w[nv:] @ z, rtol=1e-12, atol=1e-9)
        assert_allclose(y[:nv], w[:nv] @ z, rtol=1e-12, atol=1e-12)

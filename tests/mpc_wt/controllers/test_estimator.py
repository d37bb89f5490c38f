"""Kalman state and wind estimator: the MPC on measured signals only."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import linearize
from mpc_wt.controllers.estimator import MEASURED_SIGNALS, STATE_NOISE, KalmanEstimator
from mpc_wt.controllers.mpc import MPC, MPCSettings, turbine_noise
from mpc_wt.run import law_controller
from mpc_wt.simulation.loop import simulate_closed_loop


@pytest.fixture(scope="module")
def model(turbine: linearize.Turbine) -> linearize.LinearModel:
    return linearize.linearize(turbine, 18.0, config=linearize.PlantConfig.madsen())


def test_mpc_on_measured_signals_estimates_the_wind(turbine: linearize.Turbine,
                                                     params: linearize.PlantParams,
                                                     model) -> None:
    """One design at 18 m/s run by its shipped law, the plant in a steady 19 m/s without
    shear: the Kalman filter's blade winds (logged by the law) move from the operating point's
    18 m/s to the true wind: their mean over the last 10 s within 0.5 m/s of 19 (the residual
    bias is the gravity/tilt 1P content of the flap moments, which the averaged linear model
    does not have), no QP fallback, the power within 2 % of rated."""
    design = MPC(model, turbine, MPCSettings(estimator="kalman", backend="daqp"))
    assert design.estimator.spectral_radius < 1
    op = linearize.trim(turbine, 18.0)
    r = simulate_closed_loop(params, law_controller(design, "mpc", turbine),
                             linearize.SteadyWind(19.0, 0.0), 40.0, x0=op.x, u0=op.u,
                             controller_dt=0.1)
    late = r.t > 30
    est = np.mean([r.controller[f"wind_est_{i}"][late].mean() for i in (1, 2, 3)])
    assert est == pytest.approx(19.0, abs=0.5)
    assert np.all(r.controller["qp_fallback"] == 0)
    assert r.channel("gen_power")[late].mean() == pytest.approx(5e6, rel=0.02)


def test_estimator_follows_the_true_state_on_the_linear_model(model) -> None:
    """The filter's gain on its own linear model, driven by a wind ramp: the textbook current
    estimator (predict x = A x + B u, correct x += K (y - y0 - C x - D u); Simon 2006, ch. 5)
    with the design's augmented model and gain converges to the truth: after 30 s the winds
    within 0.02 m/s (a ramp leaves a small lag), the rotor speed within 1e-4 rad/s."""
    md = model.discretize(0.1) if model.dt is None else model
    est = KalmanEstimator(md)
    iy = [md.outputs.index(n) for n in est.signals]
    x = np.zeros(md.A.shape[0])
    u = np.zeros(md.B_u.shape[1])
    xa = np.zeros(est.a.shape[0])
    for k in range(300):
        d = np.full(3, 1.0 + 0.002 * k)
        y = md.z0[iy] + md.C_z[iy] @ x + md.D_u[iy] @ u + md.D_d[iy] @ d
        if k:
            xa = est.a @ xa + est.b @ u
        xa = xa + est.gain @ (y - est.y0 - est.c @ xa - est.d @ u)
        err_x, err_d = np.abs(xa[:est.nx] - x), np.abs(xa[est.nx:] - d)
        x = md.A @ x + md.B_u @ u + md.B_d @ d
    assert err_d.max() < 0.02
    assert err_x[md.states.index("rotor_speed")] < 1e-4


def test_estimator_bad_input(model, turbine) -> None:
    md = model.discretize(0.1) if model.dt is None else model
    with pytest.raises(ValueError, match="estimator must be one of \\('kalman', "
                                         "'full-state'\\) or a KalmanEstimator, got 'ekf'"):
        MPC(model, turbine, MPCSettings(estimator="ekf", backend="osqp"))
    with pytest.raises(ValueError, match="wind_std_per_step must be finite and > 0 m/s, got 0"):
        KalmanEstimator(md, wind_std_per_step=0)
    with pytest.raises(ValueError, match="measurement_std: unknown signal 'lidar'"):
        KalmanEstimator(md, measurement_std={"lidar": 1.0})
    with pytest.raises(ValueError, match="must be discrete"):
        KalmanEstimator(linearize.linearize(turbine, 18.0,
                                            config=linearize.PlantConfig.madsen()))


def test_scheduled_mpc_switches_to_the_wind_it_meets(turbine: linearize.Turbine,
                                                     params: linearize.PlantParams) -> None:
    """A schedule of four designs (16-22 m/s) run by its shipped law from the 18 m/s trim in a
    steady 20 m/s: it switches once, to the 20 m/s design, with no QP fallback, and holds
    rated power within 1 %."""
    from mpc_wt.controllers.mpc import ScheduledMPC

    fam = linearize.linearize_family(turbine, [16.0, 18.0, 20.0, 22.0],
                                     config=linearize.PlantConfig.madsen())
    ctl = law_controller(ScheduledMPC(fam, turbine, time_constant=5.0), "mpc", turbine)
    op = linearize.trim(turbine, 18.0)
    r = simulate_closed_loop(params, ctl, linearize.SteadyWind(20.0, 0.0), 40.0, x0=op.x,
                             u0=op.u, controller_dt=0.1)
    late = r.t > 30
    grid = r.controller["schedule_grid_wind"]
    assert int(np.sum(np.diff(grid) != 0)) == 1 and grid[-1] == 20.0
    assert np.all(r.controller["qp_fallback"] == 0)
    assert r.channel("gen_power")[late].mean() == pytest.approx(5e6, rel=0.01)


def test_scheduled_mpc_bad_input(turbine: linearize.Turbine) -> None:
    from mpc_wt.controllers.mpc import ScheduledMPC

    fam = linearize.linearize_family(turbine, [16.0, 18.0],
                                     config=linearize.PlantConfig.madsen())
    with pytest.raises(ValueError, match="wind_source must be 'estimator' or 'preview', got "
                                         "'mast'"):
        ScheduledMPC(fam, turbine, wind_source="mast")
    with pytest.raises(ValueError, match="time_constant must be finite and >= 0 s, got -1"):
        ScheduledMPC(fam, turbine, time_constant=-1.0)


def test_the_kinds_options_and_the_mpcs_settings_agree_on_every_shared_default() -> None:
    """One configuration: a setting both the kind's options (``mpcwt run --controller mpc``,
    campaign specs) and the MPC on a linear model take has one default, and names its
    state source with the same words; the MPC estimates its state by default, as a turbine's
    controller must (the true states are asked for by name, for the design's QP alone)."""
    import dataclasses

    from mpc_wt.controllers.mpc import ESTIMATORS
    from mpc_wt.kinds.mpc import MPCOptions

    opts = {f.name: f.default for f in dataclasses.fields(MPCOptions)}
    st = MPCSettings()
    shared = [n for n in opts if n in {f.name for f in dataclasses.fields(MPCSettings)}
              and n != "weights"]
    assert set(shared) >= {"horizon", "time_budget_ms"}
    for name in shared:
        assert getattr(st, name) == opts[name], name
    assert st.estimator == "kalman" and ESTIMATORS == ("kalman", "full-state")
    assert "estimator" not in opts          # the kinds run the law, which estimates its state


IEA22 = (Path(__file__).parents[2] / "data" / "iea22" / "OpenFAST" / "IEA-22-280-RWT-Monopile"
         / "IEA-22-280-RWT-Monopile.fst")


def _steady_speed_estimate(est: KalmanEstimator, m: linearize.LinearModel,
                           mean: dict[str, float], u: np.ndarray) -> float:
    """The filter's fixed point for measurements and inputs held at ``mean`` and ``u``
    (predict x+ = A x + B u, correct x = x+ + K (y - C x+ - D u): x = (I - K C)(A x + B u)
    + K (y - D u), solved for x), its rotor speed [rad/s]."""
    y = np.array([mean[s] for s in est.signals]) - est.y0
    du = u - m.u0
    ikc = np.eye(est.a.shape[0]) - est.gain @ est.c
    x = np.linalg.solve(np.eye(est.a.shape[0]) - ikc @ est.a,
                        ikc @ (est.b @ du) + est.gain @ (y - est.d @ du))
    i = m.states.index("rotor_speed")
    return float(x[i] + m.x0[i])


def test_the_estimator_carried_to_a_22_mw_rotor_reads_its_rotor_speed_without_bias() -> None:
    """The MPC's Kalman design on the IEA-22-280-RWT (tests/data/iea22) at the grid wind
    18.4 m/s, the nonlinear plant held by the baseline in a steady 18 m/s with shear 0.2: the
    filter's steady estimate of the rotor speed within 0.1 % of the measured one with the noise
    carried to the turbine (:func:`turbine_noise`). With the NREL 5-MW's noise it sat 0.77 %
    below (the flap moments, 10.7x the NREL 5-MW's, counted 18x as much as intended), and the
    MPC on it held the rotor 1.3 % above rated speed in steady wind."""
    from mpc_wt.run import run_controller
    from mpc_wt.simulation.scenario import Scenario

    t = linearize.load_turbine(IEA22)
    r = run_controller(t, "baseline", Scenario(wind_mps=18.0, turbulence="steady",
                                               duration=60.0, shear_exponent=0.2))
    late = r.t >= 30.0
    mean = {c: float(np.mean(r.channel(c)[late])) for c in MEASURED_SIGNALS}
    u = np.array([mean["pitch_1"], mean["pitch_2"], mean["pitch_3"],
                  float(np.mean(r.channel("gen_torque")[late]))])
    m = linearize.linearize(t, 18.4, config=linearize.PlantConfig.madsen()).discretize(0.1)
    est = KalmanEstimator(m, wind_std_per_step=0.118, **turbine_noise(t, 4.2e5))
    assert _steady_speed_estimate(est, m, mean, u) == pytest.approx(mean["rotor_speed"],
                                                                    rel=1e-3)


def test_the_estimator_noise_of_the_nrel5mw_is_the_tuned_default(turbine) -> None:
    """Carried to the NREL 5-MW itself, the noise is the defaults exactly (the sign-off's
    designs unchanged)."""
    noise = turbine_noise(turbine, 4.2e5)
    assert noise["measurement_std"] == {"rotor_speed": MEASURED_SIGNALS["rotor_speed"],
                                        "gen_speed": MEASURED_SIGNALS["gen_speed"],
                                        **{f"flap_moment_{b}": 4.2e5 for b in (1, 2, 3)}}
    assert all(noise["state_std"][k] == STATE_NOISE[k] for k in noise["state_std"])
    with pytest.raises(ValueError, match="flap_std"):
        turbine_noise(turbine, -1.0)
    with pytest.raises(ValueError, match="state_std: unknown state 'speed'"):
        KalmanEstimator(linearize.linearize(turbine, 18.0, config=linearize.PlantConfig.madsen())
                        .discretize(0.1), state_std={"speed": 1.0})

"""Linearization: exact derivatives of the plant, published sensitivities and frequencies,
prediction of the nonlinear plant, forms, family, I/O and bad input."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

import linearize
from linearize import (
    LinearizationError,
    LinearModelFamily,
    PlantConfig,
    TrimError,
    augment_actuator,
    jacobian_check,
    linearize_family,
    sensitivities,
    with_power_input,
)
from linearize import linearize as lin
from linearize.linear import _D_SCALE, _U_SCALE, _X_SCALE

AXISYM = linearize.AeroOptions().azimuth_independent


@pytest.fixture(scope="module")
def cfg_axisym() -> PlantConfig:
    return PlantConfig(aero=AXISYM)


@pytest.fixture(scope="module")
def params_ax(turbine: linearize.Turbine, cfg_axisym: PlantConfig) -> linearize.PlantParams:
    return linearize.plant_params(turbine, cfg_axisym)


# --------------------------------------------------------------------------------------------
# The derivatives are the plant's
# --------------------------------------------------------------------------------------------
def _output_scales(z0: np.ndarray) -> np.ndarray:
    floor = {"W": 1e5, "rad": 0.01, "rad/s": 0.01, "m/s": 0.01, "N m": 1e4, "N": 1e3,
             "m": 0.01, "m/s^2": 0.01}
    return np.array([max(abs(v), floor[u]) for v, u in zip(z0, linearize.OUTPUT_UNITS)])


@pytest.mark.parametrize("wind, wake", [(8.0, "quasi-steady"), (18.0, "quasi-steady"),
                                        (18.0, "frozen")])
def test_finite_differences_match_complex_step(turbine: linearize.Turbine,
                                               params: linearize.PlantParams, wind: float,
                                               wake: str) -> None:
    """Every Jacobian entry agrees with an independent derivative (complex step
    through the same kernels, the implicit BEM solve differentiated by the implicit-function
    theorem) to 1e-4 relative or 1e-8 absolute, whichever is looser.

    The entries are compared in scaled variables (each state, input, wind and output divided by
    its typical magnitude, the scales the finite-difference steps use): in physical units they
    span 1e-3 rad to 1e7 N m, and a 1e-8 absolute bound would then only be meaningful for some
    rows. The azimuth column and the wrapped-azimuth output are not part of the linear model.
    """
    fd, cs = jacobian_check(turbine, wind, wake=wake, params=params, shear_exponent=0.2)
    op = linearize.trim(turbine, wind, params=params, shear_exponent=0.2)
    z0 = linearize.plant_outputs(0.0, op.x, op.u, linearize.element_wind(params, 0.0, wind, 0.2),
                                 params)
    sx = np.maximum(np.abs(op.x), _X_SCALE)
    su = np.maximum(np.abs(op.u), _U_SCALE)
    sd = np.maximum(np.full(3, wind), _D_SCALE)
    sz = _output_scales(z0)
    cols = {0: sx, 1: su, 2: sd, 3: sx, 4: su, 5: sd}
    keep_x = np.arange(16)                       # without azimuth
    keep_z = np.array([i for i in range(31) if linearize.OUTPUT_NAMES[i] != "azimuth"])
    for k, (a, b) in enumerate(zip(fd, cs)):
        rows = sx if k < 3 else sz
        sa = a / rows[:, None] * cols[k][None, :]
        sb = b / rows[:, None] * cols[k][None, :]
        r = keep_x if k < 3 else keep_z
        c = keep_x if k in (0, 3) else np.arange(a.shape[1])
        sa, sb = sa[np.ix_(r, c)], sb[np.ix_(r, c)]
        err = np.abs(sa - sb)
        tol = np.maximum(1e-4 * np.abs(sb), 1e-8)
        bad = np.argwhere(err > tol)
        assert bad.size == 0, (k, bad[:5], sa[tuple(bad[0])], sb[tuple(bad[0])])


def test_linear_model_reproduces_rhs_increments(turbine: linearize.Turbine,
                                                params_ax: linearize.PlantParams,
                                                cfg_axisym: PlantConfig) -> None:
    # single azimuth, no tower: the plant is time-invariant and A must be its Jacobian
    cfg = PlantConfig(frozenset({"generator", "drivetrain", "blade_flap", "pitch_actuator"}),
                      AXISYM)
    p = linearize.plant_params(turbine, cfg)
    m = lin(turbine, 15.0, config=cfg, params=p)
    op = linearize.trim(turbine, 15.0, params=p)
    f0 = linearize.plant_rhs(0.0, op.x, op.u, np.full(3, 15.0), p)
    si = [linearize.STATE_NAMES.index(n) for n in m.states]
    for j, name in enumerate(m.states):
        dx = np.zeros(len(linearize.STATE_NAMES))
        h = 1e-6 * max(abs(op.x[si[j]]), 0.1)
        dx[si[j]] = h
        f1 = linearize.plant_rhs(0.0, op.x + dx, op.u, np.full(3, 15.0), p)
        # tolerance: central vs one-sided difference, O(h) = 1e-6 relative
        assert_allclose((f1 - f0)[si] / h, m.A[:, j], rtol=1e-4,
                        atol=1e-6 * np.abs(m.A).max(), err_msg=name)


# --------------------------------------------------------------------------------------------
# Published values
# --------------------------------------------------------------------------------------------
def test_frozen_wake_pitch_sensitivity_matches_report(turbine: linearize.Turbine,
                                                      params: linearize.PlantParams) -> None:
    # published: Jonkman et al. (2009) sec. 7.4: dP/dtheta = -25.52e6 W/rad extrapolated to
    # zero pitch, growing linearly with pitch, doubling at theta_K = 6.302336 deg (the
    # baseline's gain-scheduling corner, DISCON PC_KK), from FAST linearizations with frozen
    # wake. Bound: within 15 % over 12-25 m/s.
    fam = linearize_family(turbine, np.arange(12.0, 25.5, 1.0), wake="frozen", params=params)
    for m in fam.models:
        pub = -25.52e6 * (1.0 + m.info["pitch_deg"] / 6.302336)
        assert_allclose(sensitivities(m)["dP_dpitch_W_per_rad"], pub, rtol=0.15, atol=0,
                        err_msg=f"{m.wind_mps} m/s")


@pytest.mark.parametrize("wind", [13.0, 18.0, 24.0])
def test_quasi_steady_sensitivity_is_the_cp_slope(turbine: linearize.Turbine, wind: float,
                                                  cfg_axisym: PlantConfig,
                                                  params_ax: linearize.PlantParams) -> None:
    # analytic: with the induction re-solved, dP/dbeta at fixed rotor speed and wind is
    # 1/2 rho A V^3 dC_P/dbeta of our own steady surface (same options)
    m = lin(turbine, wind, config=cfg_axisym, params=params_ax)
    op = linearize.trim(turbine, wind, params=params_ax)
    rp = turbine.geometry.tip_radius
    tsr = op.rotor_speed_rad_s * rp / wind
    h = 0.01
    cp = linearize.steady_coefficients(turbine, tsr, [op.pitch_deg - h, op.pitch_deg + h],
                                       AXISYM)[0]
    dcp = (cp[1] - cp[0]) / math.radians(2 * h)
    expected = 0.5 * 1.225 * math.pi * rp**2 * wind**3 * dcp
    # tolerance: central difference of C_P with a 0.01 deg step, O(h^2) ~ 1e-6
    assert_allclose(sensitivities(m)["dP_dpitch_W_per_rad"], expected, rtol=1e-4, atol=0)


def test_tower_fore_aft_frequency_from_eig(turbine: linearize.Turbine,
                                           params: linearize.PlantParams) -> None:
    # published: Jonkman et al. (2009) Table 9-1: 1st tower fore-aft 0.3240 Hz (FAST, parked,
    # report value not re-read). Operating at 18 m/s adds aerodynamic stiffness and damping;
    # Within 5 %.
    m = lin(turbine, 18.0, params=params)
    fa = [md for md in m.modes() if md["name"] == "tower fore-aft"]
    assert len(fa) == 1
    assert_allclose(fa[0]["frequency_Hz"], 0.3240, rtol=0.05, atol=0)


def test_drivetrain_frequency_is_the_two_mass_value(turbine: linearize.Turbine,
                                                    params: linearize.PlantParams) -> None:
    # analytic, with the published inputs (not the plant's parameters): the free-free
    # two-mass drivetrain sqrt(K (J_r + N^2 J_g) / (J_r N^2 J_g)) with OpenFAST ElastoDyn's
    # rotor inertia 38,677,041 kg m^2, GenIner 534.116 kg m^2, GBRatio 97 and DTTorSpr
    # 867,637,000 N m/rad (Jonkman et al. 2009, Table 5-1; ElastoDyn summary) is 2.2229 Hz; 1 % covers
    # our rotor inertia (0.5 % below ElastoDyn's) and the aerodynamic and generator damping.
    # Rigid blades (no edge DOF): the closed form is the rigid-blade one.
    cfg = PlantConfig(frozenset(linearize.DOF_NAMES) - {"blade_edge"})
    m = lin(turbine, 18.0, config=cfg)
    dt = [md for md in m.modes() if md["name"] == "drivetrain torsion"]
    assert len(dt) == 1
    j_r, j_g, n, k = 38677041.0, 534.116, 97.0, 867637000.0
    j_eq = j_r * j_g * n**2 / (j_r + j_g * n**2)
    assert_allclose(math.sqrt(k / j_eq) / (2 * math.pi), 2.2229, rtol=1e-4)   # by hand
    assert_allclose(dt[0]["frequency_Hz"], 2.2229, rtol=0.01, atol=0)


def test_drivetrain_frequency_matches_fast(turbine: linearize.Turbine,
                                           params: linearize.PlantParams) -> None:
    """Jonkman et al. (2009) Table 9-1, 1st drivetrain torsion 0.6205 Hz (FAST),
    computed with the generator locked (RotSpeed = 0, GenDOF = False; J. Jonkman, NREL forum
    "Full-System natural frequencies"): the shaft twisting against the rotor's collective edge
    bending. From eig(A) of the full linear model with the generator-speed state removed
    (locked), at 5 m/s (light aerodynamic loading; the rotor cannot be parked in a trim).
    Tolerance 5 % (the issue's). With rigid blades the same is 0.756 Hz (22 % high). The
    asymmetric edge modes of the same model against Table 9-1's 1.0793 / 1.0898 Hz, 5 %."""
    m = lin(turbine, 5.0, params=params)
    keep = [i for i, n in enumerate(m.states) if n != "gen_speed"]
    a = m.A[np.ix_(keep, keep)]
    lam, vec = np.linalg.eig(a)
    i_shaft = [m.states[i] for i in keep].index("shaft_torsion")
    osc = np.flatnonzero(lam.imag > 1e-6)
    k = osc[np.argmax(np.abs(vec[i_shaft, osc]) / np.linalg.norm(vec[:, osc], axis=0))]
    assert_allclose(abs(lam[k]) / (2 * math.pi), 0.6205, rtol=0.05, atol=0)
    # the asymmetric edge modes (Table 9-1: 1.0793 / 1.0898 Hz, 5 %): the modes whose
    # participation is mostly the edge states (measured 1.10 Hz)
    edge = [i for i, n in enumerate(m.states) if n.startswith("edge")]
    f_edge = [md["frequency_Hz"] for md in m.modes() if md["name"].startswith("blade edge")]
    assert edge and f_edge
    for f in f_edge:
        if f < 1.5:                        # the collective edge mode sits on the shaft, above
            assert_allclose(f, 1.0793, rtol=0.05, atol=0)
            assert_allclose(f, 1.0898, rtol=0.05, atol=0)


# --------------------------------------------------------------------------------------------
# The linear model predicts the nonlinear plant
# --------------------------------------------------------------------------------------------
_STEP_CASES = [(v, kind) for v in (8.0, 12.0, 18.0, 25.0) for kind in ("pitch", "wind", "torque")]


def _step_case(turbine: linearize.Turbine, p: linearize.PlantParams, cfg: PlantConfig,
               v: float, kind: str) -> dict[str, float]:
    """Worst error over 20 s of the discretized MBC model, as a fraction of the nonlinear
    response's peak deviation, for the four outputs compared."""
    dt, dur = 1.0 / 80.0, 20.0
    op = linearize.trim(turbine, v, params=p)
    m = lin(turbine, v, config=cfg, disturbance="rotor", coordinates="mbc", params=p,
            operating_point=op).discretize(dt)
    u, vw = op.u.copy(), v
    if kind == "pitch":
        u[:3] += math.radians(0.5)
    elif kind == "torque":
        u[3] *= 1.01
    else:
        vw = v + 0.5
    res = linearize.rk4_simulate(p, op.x, u, linearize.SteadyWind(vw), dur, dt)
    n = res.t.size
    du_b = res.u - op.u             # applied inputs (after the torque rate limit)
    du = np.column_stack([du_b[:, :3].mean(axis=1), np.zeros(n), np.zeros(n), du_b[:, 3]])
    dd = np.full((n, 1), vw - v)
    x = np.zeros(m.n_x)
    zl = np.empty((n, len(m.outputs)))
    for k in range(n):
        zl[k] = m.C_z @ x + m.D_u @ du[k] + m.D_d @ dd[k]
        x = m.A @ x + m.B_u @ du[k] + m.B_d @ dd[k]
    psi = res.x[:, 16]
    out = {}
    for o in ("gen_speed", "gen_power", "tower_fa_displacement", "flap_moment_1"):
        if o == "flap_moment_1":     # blade 1 from the MBC components (T row 1)
            io = [m.index("output", f"flap_moment_{c}") for c in ("coll", "cos", "sin")]
            zlin = zl[:, io[0]] + np.cos(psi) * zl[:, io[1]] + np.sin(psi) * zl[:, io[2]]
            z0 = m.z0[io[0]]
        else:
            zlin = zl[:, m.index("output", o)]
            z0 = m.z0[m.index("output", o)]
        zn = res.output(o) - z0
        out[o] = float(np.max(np.abs(zlin - zn)) / np.max(np.abs(zn)))
    return out


@pytest.mark.parametrize("wind, kind", [c for c in _STEP_CASES if c != (8.0, "pitch")])
def test_linear_model_predicts_nonlinear_steps(turbine: linearize.Turbine, wind: float,
                                               kind: str, cfg_axisym: PlantConfig,
                                               params_ax: linearize.PlantParams) -> None:
    """0.5 deg collective pitch, 0.5 m/s wind, 1 % torque steps at 8, 12, 18, 25 m/s:
    generator speed, electrical power, tower deflection and blade flap moment of the discretized
    model within 5 % of the nonlinear response's peak deviation over 20 s. The rotor is
    periodic in azimuth through the tower's motion (nodding reaches each blade as cos psi_i), so
    the blade flap moment is predicted by the MBC model and reconstructed with the rotor's
    azimuth."""
    errs = _step_case(turbine, params_ax, cfg_axisym, wind, kind)
    assert max(errs.values()) < 0.05, errs


@pytest.mark.xfail(strict=True, reason=(
    "At 8 m/s the rotor runs at fine pitch, which is within a fraction of a degree of the "
    "C_P-optimal pitch: dQ/dbeta is small (-0.43e6 N m/rad) and the 0.5 deg step's quadratic "
    "term is larger than its linear one (the secant slope is -1.0e6 N m/rad). Measured: "
    "generator speed and power off by 66 % of the peak deviation; tower 2.4 %, flap 3.3 %. No "
    "linear model meets 5 % for this step; a step below fine pitch is not allowed."))
def test_linear_model_predicts_pitch_step_at_fine_pitch(turbine: linearize.Turbine,
                                                        cfg_axisym: PlantConfig,
                                                        params_ax: linearize.PlantParams
                                                        ) -> None:
    errs = _step_case(turbine, params_ax, cfg_axisym, 8.0, "pitch")
    assert max(errs.values()) < 0.05, errs


# --------------------------------------------------------------------------------------------
# Forms and conversions
# --------------------------------------------------------------------------------------------
def test_madsen_model_has_madsen_states(turbine: linearize.Turbine) -> None:
    m = lin(turbine, 18.0, config=PlantConfig.madsen())
    assert m.states == linearize.STATE_NAMES[:8]
    assert m.inputs == linearize.INPUT_NAMES
    assert m.disturbances == ("wind_1", "wind_2", "wind_3")
    assert m.outputs[:13] == linearize.MADSEN_OUTPUTS
    assert m.A.shape == (8, 8) and m.B_d.shape == (8, 3)


def test_actuator_augmentation_equals_plant_actuator(turbine: linearize.Turbine) -> None:
    # Do et al. (2020) eq 6 applied to the model without pitch servo gives the model with it
    dofs = {"tower_fa", "drivetrain", "generator"}
    no_act = lin(turbine, 16.0, config=PlantConfig(frozenset(dofs)))
    with_act = lin(turbine, 16.0, config=PlantConfig(frozenset(dofs | {"pitch_actuator"})))
    aug = augment_actuator(no_act, turbine.pitch_actuator.time_constant)
    order = [aug.states.index(n) for n in with_act.states]
    # tolerance: both from central differences with 2e-5 relative steps
    assert_allclose(aug.A[np.ix_(order, order)], with_act.A, rtol=1e-5,
                    atol=1e-7 * np.abs(with_act.A).max())
    assert_allclose(aug.B_u[order], with_act.B_u, rtol=1e-5, atol=1e-9)
    with pytest.raises(ValueError, match="already has states"):
        augment_actuator(with_act, 0.1)
    with pytest.raises(ValueError, match="time_constant must be > 0"):
        augment_actuator(no_act, 0.0)


def test_power_input_form(turbine: linearize.Turbine) -> None:
    m = lin(turbine, 15.0, power_W=4.0e6)
    pm = with_power_input(m, turbine.drivetrain.generator_efficiency)
    io = pm.index("output", "gen_power")
    # analytic: with T_g = P_ref / (eta omega_g), P_e = P_ref exactly
    assert_allclose(pm.D_u[io, pm.index("input", "power_ref")], 1.0, rtol=1e-12, atol=0)
    assert abs(pm.C_z[io, pm.index("state", "gen_speed")]) < 1e-6 * abs(
        m.C_z[io, m.index("state", "gen_speed")])
    assert pm.u0[pm.index("input", "power_ref")] == pytest.approx(4.0e6, rel=1e-9)
    assert m.info["power_reference_W"] == 4.0e6


def test_mbc_whirl_split_of_a_time_invariant_rotor(turbine: linearize.Turbine) -> None:
    # analytic (Bir 2008): without tower, tilt, gravity and shear the rotor is time-invariant;
    # in multi-blade coordinates its collective eigenvalues stay and each asymmetric pair
    # (lambda, lambda) of the blade frame becomes the whirl pair lambda + j Omega, lambda - j Omega
    cfg = PlantConfig(frozenset({"generator", "drivetrain", "blade_flap", "pitch_actuator"}),
                      AXISYM)
    mb = lin(turbine, 14.0, config=cfg)
    mm = lin(turbine, 14.0, config=cfg, coordinates="mbc")
    omega = mm.x0[mm.index("state", "rotor_speed")]
    eb = list(np.linalg.eigvals(mb.A))
    expected = []
    while eb:
        lam = eb.pop(0)
        twin = [k for k, mu in enumerate(eb) if abs(mu - lam) < 1e-6 * max(1.0, abs(lam))]
        if twin:
            eb.pop(twin[0])
            expected += [lam + 1j * omega, lam - 1j * omega]
        else:
            expected.append(lam)
    from scipy.optimize import linear_sum_assignment

    got = np.linalg.eigvals(mm.A)
    want = np.array(expected)
    rows, cols = linear_sum_assignment(np.abs(got[:, None] - want[None, :]))
    # tolerance: eigenvalues of central-difference Jacobians (2e-5 relative steps)
    assert_allclose(got[rows], want[cols], rtol=1e-6, atol=1e-7)
    assert "flap_coll" in mm.states and "pitch_ref_cos" in mm.inputs
    assert "flap_moment_sin" in mm.outputs


def test_discretize_zero_order_hold(turbine: linearize.Turbine) -> None:
    m = lin(turbine, 18.0, config=PlantConfig.madsen())
    d = m.discretize(0.1)
    # analytic: A_d = expm(A dt); for every eigenvalue, lambda_d = exp(lambda dt)
    assert_allclose(np.sort_complex(np.linalg.eigvals(d.A)),
                    np.sort_complex(np.exp(np.linalg.eigvals(m.A) * 0.1)), rtol=1e-9, atol=1e-12)
    # analytic: the ZOH steady-state gain equals the continuous one
    g_c = -m.C_z @ np.linalg.solve(m.A, m.B_u) + m.D_u
    g_d = d.C_z @ np.linalg.solve(np.eye(8) - d.A, d.B_u) + d.D_u
    assert_allclose(g_d, g_c, rtol=1e-7, atol=1e-9 * np.abs(g_c).max())
    with pytest.raises(ValueError, match="dt must be > 0"):
        m.discretize(0.0)
    with pytest.raises(ValueError, match="already discrete"):
        d.discretize(0.1)


def test_to_statespace(turbine: linearize.Turbine) -> None:
    import control

    m = lin(turbine, 18.0, config=PlantConfig.madsen())
    sys = m.to_statespace()
    assert_allclose(np.sort_complex(control.poles(sys)), np.sort_complex(np.linalg.eigvals(m.A)),
                    rtol=1e-12, atol=1e-12)
    assert sys.input_labels[:4] == list(m.inputs) and sys.output_labels[0] == "gen_power"
    assert m.discretize(0.1).to_statespace().dt == 0.1


# --------------------------------------------------------------------------------------------
# Family, interpolation and I/O
# --------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def family(turbine: linearize.Turbine) -> LinearModelFamily:
    return linearize_family(turbine, [10.0, 14.0, 18.0], config=PlantConfig.madsen())


def test_family_interpolation(family: LinearModelFamily) -> None:
    assert_allclose(family.at(14.0).A, family.models[1].A, rtol=0, atol=0)
    mid = family.at(16.0)
    assert_allclose(mid.A, 0.5 * (family.models[1].A + family.models[2].A), rtol=1e-12, atol=0)
    assert_allclose(mid.u0, 0.5 * (family.models[1].u0 + family.models[2].u0), rtol=1e-12)
    assert family.stacked("A").shape == (3, 8, 8)
    with pytest.raises(ValueError, match=r"wind_mps = 19 m/s is outside the family's range "
                                         r"10..18 m/s"):
        family.at(19.0)


@pytest.mark.parametrize("suffix", [".mat", ".npz", ".json"])
def test_family_round_trip(family: LinearModelFamily, tmp_path: Path, suffix: str) -> None:
    path = family.save(tmp_path / f"fam{suffix}")
    back = LinearModelFamily.load(path)
    assert_allclose(back.wind_mps, family.wind_mps, rtol=0, atol=0)
    for a, b in zip(back.models, family.models):
        for k in ("A", "B_u", "B_d", "C_z", "D_u", "D_d", "x0", "u0", "z0"):
            assert_allclose(getattr(a, k), getattr(b, k), rtol=1e-15, atol=0)
        assert a.states == b.states and a.outputs == b.outputs and a.wake == b.wake


def test_mat_file_has_matlab_layout(family: LinearModelFamily, tmp_path: Path) -> None:
    import scipy.io

    raw = scipy.io.loadmat(family.save(tmp_path / "f.mat"))
    assert raw["A"].shape == (8, 8, 3)           # A(:, :, k) for wind_speed(k)
    assert raw["Bu"].shape == (8, 4, 3) and raw["wind_speed"].shape == (3, 1)
    assert str(raw["state_names"][0, 0][0]) == "tower_fa_displacement"


def test_family_load_rejects_other_schema(family: LinearModelFamily, tmp_path: Path) -> None:
    import json

    p = family.save(tmp_path / "f.json")
    d = json.loads(p.read_text())
    d["schema_version"] = 99
    p.write_text(json.dumps(d))
    with pytest.raises(ValueError, match="schema_version must be 1, got 99"):
        LinearModelFamily.load(p)
    with pytest.raises(ValueError, match="suffix must be .mat, .npz or .json"):
        family.save(tmp_path / "f.txt")


# --------------------------------------------------------------------------------------------
# Bad input
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("wind, match", [(2.0, r"wind_mps = 2 m/s is outside"),
                                         (30.0, r"wind_mps = 30 m/s is outside")])
def test_wind_outside_envelope(turbine: linearize.Turbine, wind: float, match: str) -> None:
    with pytest.raises(TrimError, match=match):
        lin(turbine, wind)


def test_grid_not_strictly_increasing(turbine: linearize.Turbine) -> None:
    with pytest.raises(ValueError, match=r"strictly increasing; 12 follows 14 m/s"):
        linearize_family(turbine, [10.0, 14.0, 12.0])
    with pytest.raises(ValueError, match=r"strictly increasing"):
        linearize_family(turbine, [10.0, 10.0])


@pytest.mark.parametrize("kwargs, match", [
    (dict(wake="dynamic"), "wake must be one of"),
    (dict(disturbance="hub"), "disturbance must be 'blade' or 'rotor'"),
    (dict(coordinates="polar"), "coordinates must be 'blade' or 'mbc'"),
    (dict(n_azimuth=0), "n_azimuth must be >= 1"),
])
def test_bad_options(turbine: linearize.Turbine, kwargs, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        lin(turbine, 12.0, **kwargs)


def test_nan_jacobian_is_reported(turbine: linearize.Turbine, params: linearize.PlantParams,
                                  monkeypatch: pytest.MonkeyPatch) -> None:
    import linearize.linear as L

    real = L._jac_fd

    def broken(*args):
        jf, jz = real(*args)
        jf = jf.copy()
        jf[2, 5] = np.nan
        return jf, jz

    monkeypatch.setattr(L, "_jac_fd", broken)
    with pytest.raises(LinearizationError,
                       match=r"Jacobian A\[2, 5\] is not finite at 18 m/s, azimuth 0 deg"):
        lin(turbine, 18.0, params=params)


# --------------------------------------------------------------------------------------------
# Frozen wake as FAST/OpenFAST define it: the induced velocities are held
# --------------------------------------------------------------------------------------------
def _frozen_rotor_loads(turbine, ua, ut, pitch_rad):
    """Thrust and torque of three equal blades from the element equations written out here:
    inflow angle, angle of attack, the airfoil polars interpolated with numpy (not the
    kernel's table), W^2 = u_a^2 + u_t^2, midpoint rule with the element lengths."""
    b, rho = turbine.blade, turbine.environment.air_density
    phi = np.arctan2(ua, ut)
    alpha = phi - (b.twist_rad + pitch_rad)
    cl = np.array([np.interp(a, turbine.polars[k].alpha_rad, turbine.polars[k].cl)
                   for a, k in zip(alpha, b.airfoil)])
    cd = np.array([np.interp(a, turbine.polars[k].alpha_rad, turbine.polars[k].cd)
                   for a, k in zip(alpha, b.airfoil)])
    q = 0.5 * rho * (ua ** 2 + ut ** 2) * b.chord
    normal = q * (cl * np.cos(phi) + cd * np.sin(phi))
    tangential = q * (cl * np.sin(phi) - cd * np.cos(phi))
    return 3 * np.sum(normal * b.dr), 3 * np.sum(tangential * b.r * b.dr)


@pytest.mark.parametrize("wind", [8.0, 11.0, 14.0, 18.0])
def test_frozen_wake_holds_the_induced_velocities(turbine: linearize.Turbine, wind: float
                                                  ) -> None:
    """dT/dV, dQ/dV and dT/dOmega of the frozen-wake model against central differences of the
    element equations with the trim's induced velocities held (computed in this test; no tilt,
    cone or gravity, so V_x = V and V_y = Omega r). Before the fix the factors (1 - a),
    (1 + a') were held and dT/dV, dQ/dV came out 27-88 % off. Tolerance 2 %: the kernel
    interpolates a resampled polar table, this test the published polar points (measured
    0.75 % at most)."""
    opts = linearize.AeroOptions(tilt=False, cone=False, gravity=False)
    cfg = PlantConfig(frozenset({"generator"}), opts)
    op = linearize.trim(turbine, wind, config=cfg)
    om, pitch = op.rotor_speed_rad_s, op.pitch_rad
    r = turbine.blade.r
    vx, vy = np.full(r.size, wind), om * r
    u_ind, v_ind = linearize.element_induction(turbine, vx, vy, pitch, opts)
    ua, ut = vx - u_ind, vy + v_ind
    hv, hw = 1e-3 * wind, 1e-4 * om
    (tp, qp), (tm, qm) = (_frozen_rotor_loads(turbine, ua + s * hv, ut, pitch) for s in (1, -1))
    (tpw, _), (tmw, _) = (_frozen_rotor_loads(turbine, ua, ut + s * hw * r, pitch)
                          for s in (1, -1))
    m = lin(turbine, wind, wake="frozen", config=cfg)
    i_t, i_q = m.outputs.index("thrust"), m.outputs.index("aero_torque")
    j_w = m.states.index("rotor_speed")
    assert_allclose([m.D_d[i_t].sum(), m.D_d[i_q].sum(), m.C_z[i_t, j_w]],
                    [(tp - tm) / (2 * hv), (qp - qm) / (2 * hv), (tpw - tmw) / (2 * hw)],
                    rtol=0.02)


@pytest.mark.parametrize("wind, tol_qw", [(7.0, 0.03), (9.0, 0.03), (11.0, 0.12), (14.0, 0.03),
                                          (18.0, 0.03), (22.0, 0.03)])
def test_quasi_steady_derivatives_follow_rosco_table_slopes(turbine: linearize.Turbine,
                                                            rosco_nrel5mw, wind: float,
                                                            tol_qw: float) -> None:
    """Quasi-steady dQ/dV, dQ/dOmega and dT/dV against the slopes of ROSCO's NREL 5-MW C_P and
    C_T tables (CCBlade; bicubic spline of the table) at the trim of the same options
    (trapezoid rule, precone, tilt, shear 0.2): P = q A V^3 C_P(lambda, theta),
    T = q A V^2 C_T with lambda = Omega 63 m / V and A = pi (63 cos 2.5 deg)^2 as in the table.
    Tolerance 3 % (measured 0.4-2.4 %: the tables differ by up to 0.006 in C_P here); 12 % for
    dQ/dOmega at 11 m/s, a difference of two near-equal terms at the C_P optimum (measured
    10 %)."""
    from scipy.interpolate import RectBivariateSpline

    pitch, tsr, cp, ct = rosco_nrel5mw
    s_cp, s_ct = RectBivariateSpline(tsr, pitch, cp), RectBivariateSpline(tsr, pitch, ct)
    cfg = PlantConfig(frozenset({"generator"}), linearize.AeroOptions(), "trapezoid")
    op = linearize.trim(turbine, wind, config=cfg, shear_exponent=0.2)
    om, th = op.rotor_speed_rad_s, math.degrees(op.pitch_rad)
    lam = om * 63.0 / wind
    qa = 0.5 * 1.225 * math.pi * (63.0 * math.cos(math.radians(2.5))) ** 2
    c_p, dcp = s_cp(lam, th)[0, 0], s_cp(lam, th, dx=1)[0, 0]
    c_t, dct = s_ct(lam, th)[0, 0], s_ct(lam, th, dx=1)[0, 0]
    dq_dv = qa * wind ** 2 * (3 * c_p - lam * dcp) / om
    dq_dw = qa * wind ** 2 * dcp * 63.0 / om - qa * wind ** 3 * c_p / om ** 2
    dt_dv = qa * wind * (2 * c_t - lam * dct)
    m = lin(turbine, wind, config=cfg, shear_exponent=0.2)
    i_t, i_q = m.outputs.index("thrust"), m.outputs.index("aero_torque")
    assert_allclose([m.D_d[i_q].sum(), m.D_d[i_t].sum()], [dq_dv, dt_dv], rtol=0.03)
    assert_allclose(m.C_z[i_q, m.states.index("rotor_speed")], dq_dw, rtol=tol_qw)


def test_operating_point_outputs_use_the_trims_inflow(turbine: linearize.Turbine) -> None:
    """Z0 was evaluated with uniform hub-height wind at azimuth 0; with shear 0.2 at
    18 m/s its aerodynamic torque was 2.9 % and its thrust 3.6 % off the trim's. Now the
    sheared inflow averaged over a revolution: equal to the trim's to the averaging's
    aliasing (1e-5)."""
    op = linearize.trim(turbine, 18.0, shear_exponent=0.2)
    m = lin(turbine, 18.0, shear_exponent=0.2, operating_point=op)
    z = dict(zip(m.outputs, m.z0))
    assert_allclose([z["aero_torque"], z["thrust"]], [op.aero_torque, op.thrust], rtol=1e-5)
    with pytest.raises(ValueError, match="differs from the operating point's 18 m/s"):
        lin(turbine, 17.0, operating_point=op)


def test_rigid_drivetrain_has_no_generator_speed_state(turbine: linearize.Turbine) -> None:
    """With a rigid shaft the generator turns at N = 97 times the rotor, so
    gen_speed was a redundant state (an exact zero, uncontrollable eigenvalue). Now it is not
    a state; the outputs act through the rotor speed: gen_speed = 97 omega_r and, at 18 m/s in
    region 3, d(gen_power)/d(omega_r) = eta T_g N = 0.944 x 43,093.55 N m x 97 (published
    efficiency, rated torque, gearbox ratio; report Table 1-1 / DISCON)."""
    cfg = PlantConfig(frozenset({"generator", "tower_fa"}))
    m = lin(turbine, 18.0, config=cfg)
    assert "gen_speed" not in m.states and "shaft_torsion" not in m.states
    assert np.abs(np.linalg.eigvals(m.A)).min() > 1e-3
    j = m.states.index("rotor_speed")
    assert_allclose(m.C_z[m.outputs.index("gen_speed"), j], 97.0, rtol=1e-9)
    assert_allclose(m.C_z[m.outputs.index("gen_power"), j], 0.944 * 43093.55 * 97.0, rtol=1e-5)
    flexible = lin(turbine, 18.0, config=PlantConfig(frozenset({"generator", "drivetrain",
                                                                "tower_fa"})))
    assert "gen_speed" in flexible.states


def _lin_matrix(text: list[str], name: str) -> np.ndarray:
    """One matrix of an OpenFAST .lin file (``NAME: r x c`` then r rows)."""
    import re

    i = next(k for k, ln in enumerate(text) if ln.strip().startswith(name + ":"))
    r, c = map(int, re.findall(r"(\d+) x (\d+)", text[i])[0])
    return np.array([ln.split() for ln in text[i + 1:i + 1 + r]], float)


def test_fine_pitch_derivatives_against_openfast(turbine: linearize.Turbine) -> None:
    """OpenFAST's FASTLin.lin (tests/data; quasi-steady BEM, 11 m/s, 11.81 rpm, pitch 0) at
    the same operating point (`operating_point`), tower fore-aft and generator DOFs: the wind
    derivatives of thrust and torque and the pitch derivative of thrust agree to 3 % (measured
    0.1-1.7 %). The pitch derivative of torque does not: ours -2.35e6 against -1.56e6 N m/rad
    (+50 %). It is small because fine pitch sits near the C_P-optimal pitch, where
    dQ/dtheta = Q'' (theta - theta_opt) with Q'' = -2.7e8 N m/rad^2: the whole difference is
    the optimum 0.16 deg apart (CCBlade's table puts it another 0.4 deg away, -2.01e6). The
    test states the +50 % and bounds the equivalent optimum shift by 0.25 deg."""
    text = (Path(__file__).resolve().parents[1] / "data" / "FASTLin.lin").read_text().splitlines()
    d = _lin_matrix(text, "D")
    of = {"dQ_dV": d[15, 0], "dT_dV": d[14, 0], "dT_dpitch": d[14, 8], "dQ_dpitch": d[15, 8]}
    cfg = PlantConfig(frozenset({"generator", "tower_fa"}))
    op = linearize.operating_point(turbine, 11.0, 1.23670995, 0.0, config=cfg)
    m = lin(turbine, 11.0, config=cfg, operating_point=op)
    i_q, i_t = m.outputs.index("aero_torque"), m.outputs.index("thrust")
    ours = {"dQ_dV": m.D_d[i_q].sum(), "dT_dV": m.D_d[i_t].sum(),
            "dT_dpitch": m.D_u[i_t, :3].sum(), "dQ_dpitch": m.D_u[i_q, :3].sum()}
    for k in ("dQ_dV", "dT_dV", "dT_dpitch"):
        assert_allclose(ours[k], of[k], rtol=0.03, err_msg=k)
    assert ours["dQ_dpitch"] / of["dQ_dpitch"] == pytest.approx(1.50, abs=0.03)
    # Q'' from our steady torque at this rotor speed, over pitch +-1 deg
    r_proj = 63.0 * math.cos(math.radians(2.5))
    th = np.radians(np.linspace(-1.0, 1.0, 21))
    cp, _ = linearize.steady_coefficients(turbine, np.full(th.size, 1.23670995 * r_proj / 11.0),
                                          np.degrees(th))
    torque = 0.5 * 1.225 * math.pi * r_proj ** 2 * 11.0 ** 3 * cp / 1.23670995
    q2 = np.polyfit(th, torque, 2)[0] * 2
    shift = (of["dQ_dpitch"] - ours["dQ_dpitch"]) / q2
    assert abs(math.degrees(shift)) < 0.25

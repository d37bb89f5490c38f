"""The plant's OpenFAST-fidelity terms, each against a hand-worked number from published data or
a closed form: the blades' own normal forces, the in-plane wind, the tower's potential flow and
drag, the unsteady airfoil model, the twisted modes."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

import linearize
from linearize import OUTPUT_NAMES, PlantConfig
from linearize.bem import polar_table_of
from linearize.kernel import _tower_potential_flow
from linearize.unsteady import _chain, _initial, ua_steady

_Z = {n: i for i, n in enumerate(OUTPUT_NAMES)}
#: rigid blades: their root moments are then the applied loads alone
_RIGID = frozenset({"tower_fa", "tower_ss", "drivetrain", "generator", "pitch_actuator"})


def _outputs(params: linearize.PlantParams, x: np.ndarray, wind: object) -> np.ndarray:
    st = linearize.PlantStepper(params, wind, 0.0125, 1.0)
    return st.outputs(0.0, x, np.array([x[5], x[6], x[7], 0.0]))


def _state(omega: float, psi: float) -> np.ndarray:
    x = np.zeros(len(linearize.STATE_NAMES))
    x[2], x[3], x[16] = omega, omega * 97.0, psi
    return x


@pytest.mark.parametrize("psi_deg", [90.0, 0.0])
def test_blade_body_forces_are_the_hand_worked_moments(turbine: linearize.Turbine,
                                                       psi_deg: float) -> None:
    """The NREL 5-MW at 12.1 rpm in still air, blade 1 horizontal (psi = 90 deg) or up: its
    out-of-plane root moment grows by the coned blade's centrifugal moment
    Omega^2 sin(c) cos(c) int m r s ds and its weight along the tilted shaft,
    g (sin(t) cos(c) - sin(c) cos(t) cos(psi)) int m s ds. The mass moments are ElastoDyn's
    summary of the blade (5MW_Land_DLL_WTurb.ED.sum: first 362,132.653 kg m, second
    11,752,352.265 kg m^2 about the root; hub radius 1.5 m), not the plant's integrals; 1 %
    covers the plant's 2001-point quadrature of the distributed mass."""
    omega = 12.1 * math.pi / 30
    c, t, g = math.radians(2.5), math.radians(5.0), 9.80665
    s1, s2 = 362132.653, 11752352.265
    i_r = s2 + 1.5 * s1                       # int m (r_hub + s) s ds
    psi = math.radians(psi_deg)
    expected = (omega**2 * math.sin(c) * math.cos(c) * i_r
                + g * (math.sin(t) * math.cos(c) - math.sin(c) * math.cos(t) * math.cos(psi)) * s1)
    still = linearize.SteadyWind(0.0)
    on = _outputs(linearize.plant_params(turbine, PlantConfig(_RIGID, blade_body_forces=True)),
                  _state(omega, psi), still)
    off = _outputs(linearize.plant_params(turbine, PlantConfig(_RIGID, blade_body_forces=False)), _state(omega, psi),
                   still)
    assert_allclose(on[_Z["flap_moment_1"]] - off[_Z["flap_moment_1"]], expected, rtol=0.01)
    # the forces act on the blade only: the rotor's torque and thrust are the same
    assert_allclose(on[_Z["aero_torque"]], off[_Z["aero_torque"]], rtol=1e-12)


def test_vertical_wind_is_a_shaft_tilted_the_other_way(turbine: linearize.Turbine) -> None:
    """Closed form: a uniform wind turned up by delta meets a rotor tilted by t exactly as a
    horizontal wind meets one tilted by t + delta (the same wind vector in the shaft's frame),
    so the aerodynamic torque and thrust agree at every azimuth."""
    delta = math.radians(3.0)
    speed = 11.0
    geo = turbine.geometry
    tilted = dataclasses.replace(turbine, geometry=dataclasses.replace(
        geo, shaft_tilt_rad=geo.shaft_tilt_rad + delta))
    cfg = PlantConfig(_RIGID, aero=linearize.AeroOptions(gravity=False))
    t = np.array([0.0, 2.0])
    y = np.array([-80.0, 80.0])
    z = np.array([0.0, 200.0])
    shape = (2, 2, 2)
    up = linearize.GridWind(t, y, z, np.full(shape, speed * math.cos(delta), np.float32),
                            v=np.zeros(shape), w=np.full(shape, speed * math.sin(delta)))
    level = linearize.GridWind(t, y, z, np.full(shape, speed, np.float32),
                               v=np.zeros(shape), w=np.zeros(shape))
    for psi in (0.0, 0.7, 2.0):
        x = _state(1.1, psi)
        a = _outputs(linearize.plant_params(turbine, cfg), x, up)
        b = _outputs(linearize.plant_params(tilted, cfg), x, level)
        for name in ("aero_torque", "thrust"):
            assert_allclose(a[_Z[name]], b[_Z[name]], rtol=2e-6)


def test_tower_potential_flow_below_the_hub_is_the_cylinder_closed_form(
        turbine: linearize.Turbine) -> None:
    """Potential flow past a cylinder of radius R on its upstream symmetry line, d upstream of
    its axis: u / U = 1 - (R / d)^2, v = 0. Blade 1 pointing down (psi = 180 deg), element at
    r = 40 m: d = OverHang cos(t) + r (cos(c) sin(t) + sin(c) cos(t)) and R from AeroDyn's tower
    table (NRELOffshrBsline5MW_Onshore_AeroDyn15.dat: 6.0 m at the base to 3.87 m at
    85.268 m), all from the published deck."""
    params = linearize.plant_params(turbine, PlantConfig(tower_shadow=True))
    r = 40.0
    c, t = math.radians(2.5), math.radians(5.0)
    d = 5.0191 * math.cos(t) + r * (math.cos(c) * math.sin(t) + math.sin(c) * math.cos(t))
    height = 90.0 - r * math.cos(c) * math.cos(t)
    radius = 0.5 * np.interp(height, [0.0, 85.268, 87.6], [6.0, 3.87, 3.87])
    trig = (math.cos(c), math.sin(c), math.cos(t), math.sin(t))
    fu, fv = _tower_potential_flow(r, -1.0, 0.0, *trig, params.pack)
    assert_allclose(fu, 1.0 - (radius / d) ** 2, rtol=2e-3)
    assert abs(fv) < 1e-12
    # above the tower top the tower does not act
    assert _tower_potential_flow(r, 1.0, 0.0, *trig, params.pack) == (1.0, 0.0)


def test_tower_drag_base_moment_is_the_closed_form_integral(turbine: linearize.Turbine) -> None:
    """Uniform wind U on the rigid NREL 5-MW tower: the drag adds
    int_0^H 0.5 rho C_d D(h) U^2 h dh to the tower-base fore-aft moment, with D linear from
    6.0 m at the ground to 3.87 m at 85.268 m and constant to 87.6 m, C_d = 1 (AeroDyn's tower
    table), integrated exactly; 0.5 % covers the plant's 20-point midpoint rule."""
    speed, rho = 12.0, 1.225
    h1, h2 = 85.268, 87.6
    slope = (3.87 - 6.0) / h1
    # int_0^h1 (6 + slope h) h dh + int_h1^h2 3.87 h dh
    integral = 6.0 * h1**2 / 2 + slope * h1**3 / 3 + 3.87 * (h2**2 - h1**2) / 2
    expected = 0.5 * rho * 1.0 * speed**2 * integral
    dofs = frozenset({"drivetrain", "generator"})
    x = _state(1.2, 0.3)
    wind = linearize.SteadyWind(speed)
    on = _outputs(linearize.plant_params(turbine, PlantConfig(dofs, tower_drag=True)), x, wind)
    off = _outputs(linearize.plant_params(turbine, PlantConfig(dofs)), x, wind)
    assert_allclose(on[_Z["tower_base_fa_moment"]] - off[_Z["tower_base_fa_moment"]], expected,
                    rtol=5e-3)
    assert_allclose(on[_Z["tower_base_ss_moment"]], off[_Z["tower_base_ss_moment"]], rtol=1e-12)


def _ua(turbine: linearize.Turbine, name: str) -> tuple[int, np.ndarray, object]:
    k = [p.name for p in turbine.polars].index(name)
    return k, np.array(turbine.polars[k].ua.row()), polar_table_of(turbine)


@pytest.mark.parametrize("alpha_deg", [-2.0, 0.0, 3.0])
def test_unsteady_model_steady_normal_force_is_the_attached_line_where_the_polar_is_above(
        turbine: linearize.Turbine, alpha_deg: float) -> None:
    """AeroDyn's steady behaviour with the NREL 5-MW's DU25 coefficients (Jonkman 2020, OpenFAST
    r-test, "Incorrect Unsteady Airfoil Aerodynamic Input Parameters"): where the static normal force lies above the attached-flow line, the model's steady
    normal force is that line, C_n = C_n,alpha / beta (alpha - alpha0), with
    alpha0 = -3.2 deg and C_n,alpha = 6.4462 /rad from DU25_A17.dat and beta the Prandtl-Glauert
    factor at W = 60 m/s, a = 335 m/s."""
    k, par, tab = _ua(turbine, "DU25_A17")
    alpha = math.radians(alpha_deg)
    w = 60.0
    beta = math.sqrt(1 - (w / 335.0) ** 2)
    line = 6.4462 / beta * (alpha - math.radians(-3.2))
    cl_st, cd_st = np.interp(alpha, turbine.polars[k].alpha_rad, turbine.polars[k].cl), \
        np.interp(alpha, turbine.polars[k].alpha_rad, turbine.polars[k].cd)
    assert cl_st * math.cos(alpha) + (cd_st - 0.006) * math.sin(alpha) > line   # the premise
    cl, cd = ua_steady(alpha, w, par, tab.table, k, tab.alpha0, tab.dalpha)
    cn = cl * math.cos(alpha) + (cd - 0.006) * math.sin(alpha)
    assert_allclose(cn, line, rtol=1e-9)


def test_unsteady_model_is_the_static_polar_where_it_lies_below_the_line(
        turbine: linearize.Turbine) -> None:
    """Where the static normal force lies below the attached-flow line (NACA64 at 12 deg,
    past the linear range), the model's steady coefficients are the static polar's."""
    k, par, tab = _ua(turbine, "NACA64_A17")
    alpha = math.radians(12.0)
    cl, cd = ua_steady(alpha, 60.0, par, tab.table, k, tab.alpha0, tab.dalpha)
    pol = turbine.polars[k]
    assert_allclose([cl, cd], [np.interp(alpha, pol.alpha_rad, pol.cl),
                               np.interp(alpha, pol.alpha_rad, pol.cd)], rtol=2e-3)


def test_unsteady_model_step_follows_wagners_indicial_function(
        turbine: linearize.Turbine) -> None:
    """Closed form (Leishman and Beddoes 1989; AeroDyn's UA manual eq 1.15): after a step
    Delta alpha at constant W in attached flow, incompressible (M -> 0), unfiltered, the
    circulatory normal force is C_n,alpha (alpha_1 - alpha0 - Delta alpha (A1 e^(-b1 s) +
    A2 e^(-b2 s))) with s the semichords travelled, A1 = 0.3, A2 = 0.7, b1 = 0.14, b2 = 0.53
    (the NREL 5-MW's airfoil files' defaults). DU25 at 1 -> 2 deg, where the normal force is the
    attached-flow line; 2 % of the step covers the discrete update's half-step offset. The
    first step also carries the apparent-mass impulse (the non-circulatory term's
    incompressible limit, 3 c / W d(alpha)/dt, which also throws the separation lookup out of
    the attached range for that step) and is left out."""
    k, par, tab = _ua(turbine, "DU25_A17")
    par = par.copy()
    par[10] = 1e6            # no angle-of-attack filter
    par[12] = 1e9            # M -> 0: no compressibility, no non-circulatory term
    par[8] = par[9] = 1e-6   # no separation lags
    chord, w, dt = 3.0, 60.0, 0.0025
    a0, a1 = math.radians(1.0), math.radians(2.0)
    ua = par.reshape(1, -1)
    st = _initial(a0, w, ua, 0, tab.table, k, tab.alpha0, tab.dalpha).reshape(-1, 1, 1)
    cnalpha, alpha0 = par[2], par[1]
    cl, cd = _chain(a1, w, chord, dt, ua, 0, st, 0, 0, 0, tab.table, k, tab.alpha0, tab.dalpha)
    impulse = cl * math.cos(a1) + (cd - par[3]) * math.sin(a1) - cnalpha * (a0 - alpha0)
    assert 0.5 * 3 * chord / w * (a1 - a0) / dt < impulse <= 3 * chord / w * (a1 - a0) / dt
    for n in range(2, 161):
        cl, cd = _chain(a1, w, chord, dt, ua, 0, st, 0, 0, 0, tab.table, k, tab.alpha0,
                        tab.dalpha)
        s = 2 * w * dt * n / chord
        expected = cnalpha * (a1 - alpha0 - (a1 - a0) * (0.3 * math.exp(-0.14 * s)
                                                          + 0.7 * math.exp(-0.53 * s)))
        cn = cl * math.cos(a1) + (cd - par[3]) * math.sin(a1)
        assert abs(cn - expected) <= 0.02 * cnalpha * (a1 - a0), n


def test_twisted_modes_without_pitch_or_twist_are_the_rotor_plane_modes(
        turbine: linearize.Turbine) -> None:
    """With no structural twist and zero pitch the principal axes are the rotor plane's: the
    twisted-mode plant equals the rotor-plane one, in every derivative and output."""
    flat = dataclasses.replace(turbine, blade_structure=dataclasses.replace(
        turbine.blade_structure,
        structural_twist_rad=np.zeros_like(turbine.blade_structure.span_fraction)))
    x = _state(1.1, 0.4)
    x[13:16] = [0.3, -0.2, 0.1]
    x[20:23] = [0.05, -0.02, 0.01]
    u = np.zeros(4)
    d = np.full(3, 10.0)
    a = linearize.plant_rhs(0.0, x, u, d, linearize.plant_params(
        flat, PlantConfig(twisted_modes=True)))
    b = linearize.plant_rhs(0.0, x, u, d, linearize.plant_params(flat, PlantConfig()))
    assert_allclose(a, b, rtol=1e-12, atol=1e-12)


def _flap_damping(params: linearize.PlantParams, pitch: float, wind: float) -> float:
    """Damping ratio of blade 1's flap mode on a parked rotor (the 2x2 block of flap_1,
    flap_rate_1 of the plant's Jacobian, central differences)."""
    names = list(linearize.STATE_NAMES)
    sel = [names.index("flap_1"), names.index("flap_rate_1")]
    x0 = np.zeros(len(names))
    x0[5:8] = pitch
    u, d = np.array([pitch, pitch, pitch, 0.0]), np.full(3, wind)
    jac = np.zeros((2, 2))
    for k, s in enumerate(sel):
        xp, xm = x0.copy(), x0.copy()
        xp[s] += 1e-4
        xm[s] -= 1e-4
        jac[:, k] = (linearize.plant_rhs(0.0, xp, u, d, params)[sel]
                     - linearize.plant_rhs(0.0, xm, u, d, params)[sel]) / 2e-4
    lam = np.linalg.eigvals(jac)
    lam = lam[np.argmax(lam.imag)]
    return float(-lam.real / abs(lam))


def test_feathered_blade_flap_mode_has_the_plunge_damping(turbine: linearize.Turbine) -> None:
    """A feathered blade (90 deg) on a parked rotor in 25 m/s: the twisted flap mode moves the
    sections perpendicular to their chords, across the wind, and a section plunging at h' in
    attached flow meets dL = 0.5 rho U c (c_l,alpha + c_d) h' (quasi-steady thin-airfoil
    plunge, Hansen 2015 sec. 10; the drag term from turning the wind by h'/U). Modal:
    zeta = zeta_struct + int 0.5 rho U c (c_l,alpha + c_d) phi^2 ds / (2 omega int mu phi^2 ds),
    with the turbine's polars at alpha = -twist, its mass and mode shape: 28 % of critical.
    The plant's twisted modes give it within 15 %; the rotor-plane modes (the default) move the
    feathered blade along its chord and keep little more than the structural 0.48 %."""
    from linearize.turbine import mode_shape

    t, g, b = turbine, turbine.geometry, turbine.blade
    rho, u_w = t.environment.air_density, 25.0
    lb = g.tip_radius - g.hub_radius
    xs = (b.r - g.hub_radius) / lb
    phi = mode_shape(t.mode_shapes.blade_flap1, xs)
    slope = np.empty(b.r.size)
    cd = np.empty(b.r.size)
    for j in range(b.r.size):
        pol = t.polars[int(b.airfoil[j])]
        a = -float(b.twist_rad[j])
        h = math.radians(1.0)
        slope[j] = (np.interp(a + h, pol.alpha_rad, pol.cl)
                    - np.interp(a - h, pol.alpha_rad, pol.cl)) / (2 * h)
        cd[j] = np.interp(a, pol.alpha_rad, pol.cd)
    c_aero = float(np.trapezoid(0.5 * rho * u_w * b.chord * (slope + cd) * phi**2, b.r))
    fine = np.linspace(0.0, 1.0, 2001)
    bs = t.blade_structure
    mu = np.interp(fine, bs.span_fraction, bs.mass_per_length)
    ei = np.interp(fine, bs.span_fraction, bs.flap_stiffness)
    m_b = float(np.trapezoid(mu * mode_shape(t.mode_shapes.blade_flap1, fine)**2, fine * lb))
    k_b = float(np.trapezoid(ei * (mode_shape(t.mode_shapes.blade_flap1, fine, 2) / lb**2)**2,
                             fine * lb))
    omega = math.sqrt(k_b / m_b)
    expected = t.damping.blade + c_aero / (2 * omega * m_b)
    assert expected == pytest.approx(0.28, abs=0.03)
    twisted = _flap_damping(linearize.plant_params(t, PlantConfig(twisted_modes=True)),
                            math.pi / 2, u_w)
    assert twisted == pytest.approx(expected, rel=0.15)
    plane = _flap_damping(linearize.plant_params(t, PlantConfig()), math.pi / 2, u_w)
    assert plane < 0.02


def _turned_wind(speed: float, delta: float, lateral: bool) -> linearize.GridWind:
    t = np.array([0.0, 2.0])
    y = np.array([-80.0, 80.0])
    z = np.array([0.0, 200.0])
    shape = (2, 2, 2)
    side = np.full(shape, speed * math.sin(delta))
    return linearize.GridWind(t, y, z, np.full(shape, speed * math.cos(delta), np.float32),
                              v=side if lateral else np.zeros(shape),
                              w=np.zeros(shape) if lateral else side)


def test_skewed_wake_turns_with_the_wind(turbine: linearize.Turbine) -> None:
    """Closed form (symmetry): without tilt, gravity or shear, a wind turned sideways by delta
    is one turned up by delta seen a quarter turn later, so with the skewed-wake correction
    blade 1 at psi - 90 deg in the first carries the loads it carries at psi in the second
    (a correction that did not follow the in-plane wind's direction would break this). The
    tower stays still: its fore-aft mode meets the tilt moment and not the yaw moment."""
    cfg = PlantConfig(frozenset({"drivetrain", "generator", "pitch_actuator"}),
                      aero=linearize.AeroOptions(gravity=False, tilt=False), skewed_wake=True)
    params = linearize.plant_params(turbine, cfg)
    delta = math.radians(12.0)
    up, side = _turned_wind(11.0, delta, False), _turned_wind(11.0, delta, True)
    for psi in (0.0, 0.9, 2.3):
        a = _outputs(params, _state(1.1, psi), up)
        b = _outputs(params, _state(1.1, psi - 0.5 * math.pi), side)
        for name in ("flap_moment_1", "edge_moment_1", "aero_torque", "thrust"):
            assert_allclose(b[_Z[name]], a[_Z[name]], rtol=1e-9)


def test_skewed_wake_moves_load_off_the_side_the_wake_leans_to(turbine: linearize.Turbine
                                                                 ) -> None:
    """Pitt and Peters: the induction is largest where the skewed wake leans, downwind in the
    rotor plane. In a wind turned up by 12 deg, the blade pointing up meets more induction and
    carries less normal load with the correction than without (its flapwise root moment lower
    by more than 1 %), the blade pointing down more; for three blades the correction is odd
    in azimuth and cancels in the rotor's thrust and torque to first order (within 0.5 %)."""
    wind = _turned_wind(11.0, math.radians(12.0), False)
    base = PlantConfig(_RIGID, aero=linearize.AeroOptions(gravity=False, tilt=False))
    off = linearize.plant_params(turbine, base)
    on = linearize.plant_params(turbine, dataclasses.replace(base, skewed_wake=True))
    for psi, sign in ((0.0, -1.0), (math.pi, 1.0)):
        a = _outputs(off, _state(1.1, psi), wind)
        b = _outputs(on, _state(1.1, psi), wind)
        assert sign * (b[_Z["flap_moment_1"]] / a[_Z["flap_moment_1"]] - 1.0) > 0.01
        for name in ("aero_torque", "thrust"):
            assert b[_Z[name]] == pytest.approx(a[_Z[name]], rel=5e-3)

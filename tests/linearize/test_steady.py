"""Steady rotor coefficients over the whole pitch range asked for.

Aerodynamic tables must cover the pitch asked for: the actuator's minimum (0 deg for the
NREL 5-MW) belongs to the plant and the controllers, not to C_P(lambda, beta). Checked against
the plant's own outputs at a pitch state below the actuator limit (a second path through the
public API) and against ROSCO's published NREL 5-MW table, which starts at -5 deg.
"""
from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

import linearize


@pytest.fixture(scope="module")
def turbine() -> linearize.Turbine:
    return linearize.load_turbine()


def test_negative_pitch_is_not_clipped(turbine) -> None:
    pitch = np.array([-4.0, -2.0, -1.0, 0.0])
    cp, ct = linearize.steady_coefficients(turbine, 8.0, pitch)
    # four different rows; at TSR 8 more negative pitch raises the angle of attack, so
    # thrust rises monotonically and power falls past the optimum near 0 deg (ROSCO's table
    # shows the same order)
    assert np.all(np.diff(ct) < -1e-3) and np.all(np.diff(cp) > 1e-3)


def test_table_equals_the_plant_outputs_at_that_pitch(turbine) -> None:
    """C_P from the table equals aerodynamic power / (q A V) from ``plant_outputs`` with the
    pitch-actuator state at -4 deg (a state, not a clipped command): uniform wind, no tilt, so
    one azimuth suffices; precone on, area and TSR with R cos(precone) as in the table."""
    opts = linearize.AeroOptions(tilt=False, gravity=False)
    params = linearize.plant_params(
        turbine, linearize.PlantConfig(frozenset({"generator", "pitch_actuator"}), opts))
    v, lam, beta = 9.0, 8.0, math.radians(-4.0)
    r_proj = turbine.geometry.tip_radius * math.cos(turbine.geometry.precone_rad)
    om = lam * v / r_proj
    x = np.zeros(len(linearize.STATE_NAMES))
    x[linearize.STATE_NAMES.index("rotor_speed")] = om
    x[linearize.STATE_NAMES.index("gen_speed")] = om * turbine.drivetrain.gearbox_ratio
    for i in (1, 2, 3):
        x[linearize.STATE_NAMES.index(f"pitch_{i}")] = beta
    u = np.array([beta, beta, beta, 0.0])
    z = linearize.plant_outputs(0.0, x, u, linearize.element_wind(params, 0.0, v), params)
    q_area = 0.5 * turbine.environment.air_density * math.pi * r_proj ** 2
    cp_plant = z[linearize.OUTPUT_NAMES.index("aero_power")] / (q_area * v ** 3)
    ct_plant = z[linearize.OUTPUT_NAMES.index("thrust")] / (q_area * v ** 2)
    cp, ct = linearize.steady_coefficients(turbine, lam, -4.0, opts)
    # two evaluations of the same BEM solution: agreement to the solver tolerance (1e-9)
    np.testing.assert_allclose([cp, ct], [cp_plant, ct_plant], rtol=1e-7, atol=1e-9)


def test_negative_pitch_against_rosco_table(turbine, rosco_nrel5mw) -> None:
    """ROSCO's table (CCBlade: trapezoid integration, precone, tilt, shear 0.2) at TSR 8 and
    pitch -4..0 deg. Tolerance |dC_P| <= 0.01 from the table's README for matched options
    (measured: at most 0.006); the values at -4 deg were the 0 deg ones before the fix
    (0.469 against ROSCO's 0.410)."""
    pitch, tsr, cp_ref, _ = rosco_nrel5mw
    i = int(np.flatnonzero(tsr == 8.0)[0])
    cols = [int(np.flatnonzero(pitch == b)[0]) for b in (-4.0, -2.0, -1.0, 0.0)]
    cp, _ = linearize.steady_coefficients(turbine, 8.0, pitch[cols], shear_exponent=0.2,
                                          integration="trapezoid")
    np.testing.assert_allclose(cp, cp_ref[i, cols], rtol=0, atol=0.01)


#: CCBlade's BEM has no limits on the induction (AeroDyn 15's, on in our plant, act only in
#: the braking region here: TSR 12 at 25 deg, C_P = -5).
_CCBLADE_AERO = linearize.AeroOptions(induction_limits=False)


def _ccblade_setup(turbine: linearize.Turbine) -> linearize.Turbine:
    """The NREL 5-MW as ROSCO's tuning tool hands it to CCBlade (rosco/toolbox/turbine.py):
    the 19 AeroDyn-15 nodes at r = BlSpn + HubRad, the last at 62.9999 m (the deck's BlSpn
    61.4999), loads integrated by trapezoid between them; the polars as CCBlade's CCAirfoil
    holds them, smoothing splines of C_l (s = 0.1) and C_d (s = 0.001) over alpha [rad], cubic.
    The spline is scipy's, the same routine CCAirfoil calls; nothing of our BEM changes."""
    from scipy.interpolate import UnivariateSpline

    ad = np.genfromtxt(Path(__file__).parents[1] / "data" / "blade_aero_nodes_ad15.csv",
                       delimiter=",", names=True, dtype=None, encoding="utf-8")
    r = ad["r_from_apex_m"].astype(float)
    r[0] += 1e-4                   # on the hub radius itself the hub-loss factor is 0
    r[-1] = 62.9999
    g = turbine.geometry
    dr = np.maximum(np.minimum(np.gradient(r), 2 * np.minimum(r - g.hub_radius,
                                                               g.tip_radius - r)), 1e-6)
    blade = dataclasses.replace(turbine.blade, r=r, dr=dr, chord=ad["BlChord_m"].astype(float),
                                twist_rad=np.radians(ad["BlTwist_deg"].astype(float)),
                                airfoil=ad["BlAFID"].astype(int) - 1)
    fine = np.radians(np.linspace(-180.0, 180.0, 3601))

    def smooth(p: linearize.Polar) -> linearize.Polar:
        if p.alpha_rad.size < 10:            # the cylinders' constant polars
            return p
        # RectBivariateSpline over (alpha, two equal Re columns), kx=3, ky=1, as CCAirfoil:
        # the smoothing sum counts each residual twice, hence s / 2 here
        cl = UnivariateSpline(p.alpha_rad, p.cl, k=3, s=0.1 / 2)(fine)
        cd = UnivariateSpline(p.alpha_rad, p.cd, k=3, s=0.001 / 2)(fine)
        return dataclasses.replace(p, alpha_rad=fine, cl=cl, cd=cd)

    return dataclasses.replace(turbine, blade=blade,
                               polars=tuple(smooth(p) for p in turbine.polars))


def test_cp_ct_surface_reproduces_rosco_table(turbine, rosco_nrel5mw) -> None:
    """The whole C_P and C_T surface against ROSCO's table (CCBlade) over the
    range its README sets, TSR 3-12, pitch -2..20 deg where C_P > 0, with CCBlade's
    discretization and polar smoothing (``_ccblade_setup``) and its options (trapezoid,
    precone, tilt, shear 0.2). README tolerance |dC_P| <= 0.01, |dC_T| <= 0.02; asserted
    0.003 for both (measured 0.0015 and 0.0011).

    With the plant's own 17 AeroDyn-v13 elements and the raw polars the same grid differs by
    up to 0.0152 in C_P (pitch 3-6 deg at TSR 8-12: the smoothed C_l near zero lift) and 0.026
    in C_T (TSR 12, pitch -1 deg: CCBlade's node at 62.9999 m carries a tip load unlike the
    one AeroDyn 15's fixed-induction tip node carries; 0.048 without that tip node), which the
    last assertion pins so that a change of either is seen."""
    pitch, tsr, cp_ref, ct_ref = rosco_nrel5mw
    rows = (tsr >= 3.0) & (tsr <= 12.0)
    cols = (pitch >= -2.0) & (pitch <= 20.0)
    lam, beta = np.meshgrid(tsr[rows], pitch[cols], indexing="ij")
    cp_r, ct_r = cp_ref[np.ix_(rows, cols)], ct_ref[np.ix_(rows, cols)]
    on = cp_r > 0.0
    cp, ct = linearize.steady_coefficients(_ccblade_setup(turbine), lam, beta, _CCBLADE_AERO,
                                           shear_exponent=0.2, integration="trapezoid")
    assert np.max(np.abs(cp - cp_r)[on]) <= 0.003
    assert np.max(np.abs(ct - ct_r)[on]) <= 0.003
    cp0, ct0 = linearize.steady_coefficients(turbine, lam, beta, shear_exponent=0.2,
                                             integration="trapezoid")
    assert 0.010 < np.max(np.abs(cp0 - cp_r)[on]) < 0.016
    assert 0.020 < np.max(np.abs(ct0 - ct_r)[on]) < 0.032


def test_cp_ct_whole_grid_rms_and_max(turbine, rosco_nrel5mw) -> None:
    """RMS and maximum difference over the issue's whole grid, TSR 2-12 and pitch
    -2..25 deg (588 points, C_P down to -5), CCBlade's discretization and polars as above.

    Tolerances: RMS 0.005 in C_P and 0.003 in C_T (measured 0.0030 and 0.0014); pointwise
    0.003 + 0.005 |C_P| and 0.003 + 0.002 |C_T| (worst measured at 0.56 and 0.61 of that),
    an absolute part for the table's accuracy where the coefficients are O(0.1-1) and a relative
    part where the rotor brakes hard (C_P = -5 at TSR 12, pitch 25 deg: there the coefficient is
    a difference of large element loads and the table's 8 azimuth sectors against our 12 per
    third of a revolution show). With the plant's defaults the RMS is 0.0102 and 0.0129 and the
    maximum 0.046 (C_P) and 0.048 (C_T)."""
    pitch, tsr, cp_ref, ct_ref = rosco_nrel5mw
    rows = (tsr >= 2.0) & (tsr <= 12.0)
    cols = (pitch >= -2.0) & (pitch <= 25.0)
    lam, beta = np.meshgrid(tsr[rows], pitch[cols], indexing="ij")
    cp_r, ct_r = cp_ref[np.ix_(rows, cols)], ct_ref[np.ix_(rows, cols)]
    assert lam.size == 588
    cp, ct = linearize.steady_coefficients(_ccblade_setup(turbine), lam, beta, _CCBLADE_AERO,
                                           shear_exponent=0.2, integration="trapezoid")
    assert np.sqrt(np.mean((cp - cp_r) ** 2)) <= 0.005
    assert np.sqrt(np.mean((ct - ct_r) ** 2)) <= 0.003
    assert np.all(np.abs(cp - cp_r) <= 0.003 + 0.005 * np.abs(cp_r))
    assert np.all(np.abs(ct - ct_r) <= 0.003 + 0.002 * np.abs(ct_r))

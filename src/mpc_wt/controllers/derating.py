"""Down-regulation: steady power curves of the derated baseline and the change of annual energy.
"""
from __future__ import annotations

import math
from typing import Any, Callable, Mapping, Sequence

import numpy as np

import linearize
from mpc_wt.assessment.performance import aep_Wh, pct_change
from mpc_wt.controllers.baseline import BaselineController, BaselineGains, check_power_fraction

__all__ = ["steady_power_curve", "aep_change"]


# --------------------------------------------------------------------------------------------
# Down-regulation: steady power curve and AEP
# --------------------------------------------------------------------------------------------
def steady_power_curve(turbine: linearize.Turbine, gains: BaselineGains,
                       winds: Any) -> dict[str, np.ndarray]:
    """Steady electrical power and rotor speed of the baseline torque law with ``gains``
    (normal or derated) in uniform steady wind, below rated at fine pitch or the design's
    minimum-pitch schedule (:func:`~mpc_wt.controllers.baseline.min_pitch_schedule`).

    Below rated, the rotor speed solves Q_aero(V, Omega, theta_min(N Omega)) = N T_law(N Omega),
    with C_P from :func:`linearize.steady_coefficients`; where the aerodynamic torque exceeds the law
    at rated speed, the pitch loop holds rated speed and the power is the (derated) rated power.

    Returns
    -------
    dict
        ``wind_mps``, ``power_W``, ``rotor_speed_rad_s`` (n_v,) and ``region`` (n_v,) of str.

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    gains : BaselineGains
        Normal or derated design.
    winds : array_like
        Steady winds [m/s].
    """
    from scipy.optimize import brentq

    v = np.asarray(winds, float)
    if v.ndim != 1 or not np.all(np.isfinite(v)) or np.any(v < 0):
        raise ValueError(f"winds must be a 1-D array of finite wind speeds >= 0 m/s, got {winds!r}")
    ctl = BaselineController(turbine, gains)
    op = turbine.operation
    dtr = turbine.drivetrain
    n = dtr.gearbox_ratio
    eta = dtr.generator_efficiency * dtr.gearbox_efficiency
    rproj = turbine.geometry.tip_radius * math.cos(turbine.geometry.precone_rad)
    rho = turbine.environment.air_density
    lam = np.linspace(0.5, 25.0, 400)
    fine = op.fine_pitch_rad
    w_top = ctl.w_rated / n
    cp_at = _cp_below_rated(turbine, ctl, lam)

    def resid(om: float, vv: float) -> float:
        q = 0.5 * rho * math.pi * rproj**2 * vv**3 * cp_at(om * rproj / vv, om) / om
        return q - n * ctl.torque(om * n, fine)

    power, speed, region = [], [], []
    for vv in v:
        if not op.cut_in_wind <= vv <= op.cut_out_wind:
            power.append(0.0), speed.append(0.0), region.append("off")
            continue
        w_lo = ctl.w_cutin / n * (1 + 1e-6)
        if resid(w_top, vv) >= 0:
            power.append(gains.rated_power)
            speed.append(gains.rated_gen_speed_rad_s / n)
            region.append("3")
            continue
        if resid(w_lo, vv) <= 0:
            power.append(0.0), speed.append(w_lo), region.append("1")
            continue
        om = brentq(resid, w_lo, w_top, args=(vv,), xtol=1e-10)
        power.append(eta * n * ctl.torque(om * n, fine) * om)
        speed.append(om)
        region.append("2.5" if om * n >= ctl.w_trans else "2" if om * n >= ctl.w_rgn2
                      else "1.5")
    return {"wind_mps": v, "power_W": np.asarray(power), "rotor_speed_rad_s": np.asarray(speed),
            "region": np.asarray(region)}


def _cp_below_rated(turbine: linearize.Turbine, ctl: BaselineController, lam: np.ndarray
                    ) -> Callable[[float, float], float]:
    """C_P(tip-speed ratio, rotor speed [rad/s]) below rated: at fine pitch, or at the
    controller's minimum-pitch schedule on the generator speed (a cubic table over tip-speed
    ratio and pitch)."""
    fine = turbine.operation.fine_pitch_rad
    n = turbine.drivetrain.gearbox_ratio
    offs = np.asarray(ctl.min_pitch_offsets, float)
    if not np.any(offs > 0):
        cp_fine, _ = linearize.steady_coefficients(turbine, lam, math.degrees(fine))
        return lambda x, om: float(np.interp(x, lam, cp_fine))
    from scipy.interpolate import RegularGridInterpolator

    lam2 = np.linspace(float(lam[0]), float(lam[-1]), 200)
    pit = np.linspace(fine, fine + float(offs.max()), 13)
    grid, _ = linearize.steady_coefficients(turbine, lam2[:, None], np.degrees(pit)[None, :])
    table = RegularGridInterpolator((lam2, pit), grid, method="cubic", bounds_error=False,
                                    fill_value=None)
    return lambda x, om: float(table((x, ctl.min_pitch(om * n))))


def aep_change(turbine: linearize.Turbine, fractions: Sequence[float] = (0.9, 0.8), *,
               kind: str = "rayleigh", mean: float | None = 10.0, shape: float = 2.0,
               scale: float | None = None, wind_step: float = 0.5,
               gains: Mapping[float, BaselineGains] | None = None) -> dict[str, Any]:
    """AEP of the steady power curve, normal and derated, weighted by a Rayleigh (IEC: mean
    0.2 v_ref, 10 m/s for class I) or Weibull wind distribution over cut-in..cut-out.

    Returns
    -------
    dict
        ``aep_Wh`` per fraction (1.0 included), ``change_pct`` per derated fraction, the
        curves (``curves``) and the distribution.

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    fractions : sequence of float
        Derating fractions to compare with full power.
    kind : {"rayleigh", "weibull"}
        Wind distribution.
    mean : float, optional
        Rayleigh mean [m/s].
    shape : float
        Weibull shape.
    scale : float, optional
        Weibull scale [m/s].
    wind_step : float
        Step of the steady power curve [m/s].
    gains : mapping of float to BaselineGains, optional
        Designs per fraction (default tuned here).
    """
    from mpc_wt.assessment.fatigue import wind_bin_probabilities
    from mpc_wt.controllers.baseline import tune_baseline

    fr = sorted({1.0, *(check_power_fraction(f, "fractions") for f in fractions)}, reverse=True)
    op = turbine.operation
    v = np.arange(op.cut_in_wind, op.cut_out_wind + 1e-9, wind_step)
    prob = wind_bin_probabilities(v, kind, mean=mean if kind == "rayleigh" else None,
                                  shape=shape, scale=scale)
    gains = dict(gains or {})
    out: dict[str, Any] = {"aep_Wh": {}, "change_pct": {}, "curves": {},
                           "distribution": {"kind": kind, "mean": mean, "shape": shape,
                                            "scale": scale}}
    for f in fr:
        g = gains.get(f) or tune_baseline(turbine, power_fraction=f)
        curve = steady_power_curve(turbine, g, v)
        out["curves"][f] = curve
        out["aep_Wh"][f] = aep_Wh(curve["power_W"], prob)
    for f in fr[1:]:
        out["change_pct"][f] = pct_change(out["aep_Wh"][1.0], out["aep_Wh"][f])
    return out

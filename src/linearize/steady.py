"""Steady rotor performance through the plant's own aerodynamics.

C_P(lambda, beta) and C_T(lambda, beta) are evaluated by the same kernel the simulation uses,
with the rotor rigid and at rest structurally, averaged over azimuth when tilt or shear make
the loads azimuth-dependent (one third of a revolution suffices for three equal blades).
"""
from __future__ import annotations

import math

import numba as nb
import numpy as np
from scipy.optimize import minimize_scalar

from linearize._typing import FloatArray
from linearize.bem import MODE_NOLIMITS, AeroOptions
from linearize.jitcache import key_caches_on_callees
from linearize.kernel import NO_GRID, evaluate_plant, sample_wind
from linearize.params import PlantConfig, PlantParams, n_x, plant_params
from linearize.turbine import Turbine

__all__ = ["steady_coefficients", "optimal_tsr", "rotor_average"]

_TWO_PI_3 = 2.0 * math.pi / 3.0


@nb.njit(cache=True, error_model="numpy")
def _avg_eval(x, u, speed, shear, p, n_az, mode=0):  # pragma: no cover - compiled
    """Derivatives and outputs averaged over ``n_az`` azimuths in [0, 2 pi / 3); ``mode`` as
    the plant kernel's (MODE_NOLIMITS: no actuator limits on the pitch and torque given)."""
    dx_avg = np.zeros(n_x)
    z_avg = np.zeros(31)
    hint = np.full((4, 3, p.r.size), np.nan)
    wpar = np.array([speed, shear])
    xx = x.copy()
    for k in range(n_az):
        xx[16] = k * _TWO_PI_3 / n_az
        w = sample_wind(0.0, xx[16], p, np.int64(0), wpar, NO_GRID)
        dx, z, phis = evaluate_plant(xx, u, w, p, hint, mode)
        hint = phis
        dx_avg += dx
        z_avg += z
    return dx_avg / n_az, z_avg / n_az


@nb.njit(cache=True, error_model="numpy")
def _coeff_grid(tsr, pitch, speed, shear, p, n_az, ngear):  # pragma: no cover - compiled
    n = tsr.size
    cp = np.empty(n)
    ct = np.empty(n)
    rproj = p.rtip * math.cos(p.cone)
    qdyn = 0.5 * p.rho * math.pi * rproj * rproj * speed * speed
    x = np.zeros(n_x)
    u = np.zeros(4)
    for k in range(n):
        om = tsr[k] * speed / rproj
        x[2] = om
        x[3] = om * ngear
        for i in range(3):
            x[5 + i] = pitch[k]
            u[i] = pitch[k]
        _, z = _avg_eval(x, u, speed, shear, p, n_az, np.int64(MODE_NOLIMITS))
        cp[k] = z[22] * om / (qdyn * speed)
        ct[k] = z[23] / qdyn
    return cp, ct


def _n_az(params: PlantParams, shear_exponent: float) -> int:
    a = params.config.aero
    return 12 if (a.tilt or shear_exponent != 0.0) else 1


def rotor_average(params: PlantParams, x: FloatArray, u: FloatArray, wind_mps: float,
                  shear_exponent: float = 0.0) -> tuple[FloatArray, FloatArray]:
    """State derivative and outputs averaged over azimuth in steady power-law wind.

    Parameters
    ----------
    params : PlantParams
        The plant.
    x : (n_x,) ndarray
        State.
    u : (n_u,) ndarray
        Inputs.
    wind_mps : float
        Hub-height wind speed [m/s].
    shear_exponent : float
        Power-law shear exponent [-].

    Returns
    -------
    dxdt : (n_x,) ndarray
    z : (n_z,) ndarray
    """
    return _avg_eval(np.array(x, dtype=float), np.array(u, dtype=float), float(wind_mps),
                     float(shear_exponent), params.pack, _n_az(params, shear_exponent), 0)


def steady_coefficients(turbine: Turbine, tsr: FloatArray | float, pitch_deg: FloatArray | float,
                        options: AeroOptions | None = None, *, shear_exponent: float = 0.0,
                        integration: str = "midpoint") -> tuple[FloatArray, FloatArray]:
    """Steady power and thrust coefficients C_P(lambda, beta), C_T(lambda, beta).

    Rigid rotor in steady wind. Tip-speed ratio and coefficients use the projected rotor
    radius R cos(precone) when precone is on (as CCBlade does). With tilt or shear the loads
    are averaged over azimuth. The pitch is taken as asked for: actuator limits belong to the
    plant and the controllers, not to the aerodynamic tables (ROSCO's tables start at -5 deg).

    Parameters
    ----------
    turbine : Turbine
    tsr : array_like
        Tip-speed ratio lambda = Omega R / V [-], finite and >= 0.
    pitch_deg : array_like
        Collective pitch [deg], broadcast against ``tsr``.
    options : AeroOptions, optional
        Aerodynamic switches (default: all effects on).
    shear_exponent : float
        Power-law shear exponent of the steady wind [-].
    integration : {"midpoint", "trapezoid"}
        Spanwise load integration (see :class:`PlantConfig`).

    Returns
    -------
    cp, ct : ndarray
        Of the broadcast shape of ``tsr`` and ``pitch_deg`` [-].

    Raises
    ------
    ValueError
        If an input is not finite or a tip-speed ratio is negative.

    Examples
    --------
    >>> from linearize import load_turbine, steady_coefficients
    >>> cp, ct = steady_coefficients(load_turbine("nrel5mw"), 7.5, 0.0)
    """
    lam = np.asarray(tsr, dtype=float)
    pit = np.asarray(pitch_deg, dtype=float)
    if not np.all(np.isfinite(lam)) or np.any(lam < 0):
        raise ValueError(f"tsr must be finite and >= 0, got {tsr!r}")
    if not np.all(np.isfinite(pit)):
        raise ValueError(f"pitch_deg must be finite, got {pitch_deg!r}")
    if not math.isfinite(shear_exponent):
        raise ValueError(f"shear_exponent must be finite, got {shear_exponent!r}")
    opts = options or AeroOptions()
    params = plant_params(turbine, PlantConfig(frozenset({"generator"}), opts, integration))
    lam_b, pit_b = np.broadcast_arrays(lam, pit)
    cp, ct = _coeff_grid(np.ascontiguousarray(lam_b.ravel()),
                         np.radians(np.ascontiguousarray(pit_b.ravel())), 10.0,
                         float(shear_exponent), params.pack, _n_az(params, shear_exponent),
                         turbine.drivetrain.gearbox_ratio)
    return cp.reshape(lam_b.shape), ct.reshape(lam_b.shape)


def optimal_tsr(turbine: Turbine, pitch_deg: float = 0.0, options: AeroOptions | None = None,
                *, shear_exponent: float = 0.0, integration: str = "midpoint"
                ) -> tuple[float, float]:
    """Tip-speed ratio of maximum C_P at a fixed pitch.

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    pitch_deg : float
        Blade pitch [deg].
    options : AeroOptions, optional
        Aerodynamic options.
    shear_exponent : float
        Power-law shear exponent [-].
    integration : {"midpoint", "trapezoid"}
        Span integration.

    Returns
    -------
    tsr : float
        [-]
    cp_max : float
        [-]
    """
    def neg(lam: float) -> float:
        return -float(steady_coefficients(turbine, lam, pitch_deg, options,
                                          shear_exponent=shear_exponent,
                                          integration=integration)[0])

    grid = np.linspace(2.0, 16.0, 57)
    vals = steady_coefficients(turbine, grid, pitch_deg, options, shear_exponent=shear_exponent,
                               integration=integration)[0]
    i = int(np.argmax(vals))
    lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]
    res = minimize_scalar(neg, bounds=(lo, hi), method="bounded", options={"xatol": 1e-6})
    return float(res.x), -float(res.fun)


key_caches_on_callees(__name__)

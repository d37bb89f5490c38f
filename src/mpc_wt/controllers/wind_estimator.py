"""Rotor-effective wind speed from what a turbine controller measures: the design of the
estimator the shipped laws run (``mpc_wt/io/discon_c/windest.c``).

An extended Kalman filter on the drivetrain's one-degree-of-freedom model with the wind as a
random walk, the estimator of ROSCO's ``WE_Mode = 2`` in its simplest form:

    J d omega / dt = Q_a(v, omega, theta) - N Q_g / eta_gb,      dv / dt = w,
    Q_a = 1/2 rho pi R_p^2 v^3 C_P(lambda, theta) / omega,      lambda = omega R_p / v,

with J the rotor's and the generator's inertia on the low-speed shaft, N the gearbox ratio and
eta_gb its efficiency (its loss brakes the rotor, as ElastoDyn's GBoxEff does),
R_p = R cos(precone) the projected radius and C_P the turbine's steady power coefficient
(:func:`linearize.rotor_performance`, a smooth bicubic fit). It measures the rotor speed
omega; the collective pitch theta and the generator torque Q_g enter as known inputs. So it uses
measurements alone (rotor speed, pitch, generator torque) and the turbine's design data; it
starts from the wind that balances the measured torque at the first step. Where that torque is
not positive (OpenFAST's ServoDyn sends 0 at its first call: it has no torque of a previous
step yet), it takes the torque schedule's instead, the torque the generator will take once the
controller acts: K omega^2 with K = 1/2 rho pi R_p^5 C_P* / (lambda*^3 N) from the table's best
C_P* at lambda*, the rated torque Q_rated = P_rated / (eta omega_g,rated) from rated speed on,
and a line between them over the last 1 % below rated speed (Jonkman et al. 2009, NREL
TP-500-38060, section 7.1: regions 2, 2 1/2 and 3).

References
----------
Julian, Jonkman, Abbas, Pao (2021), ROSCO reference controller, NREL (``WE_Mode`` 2).
Simon (2006), Optimal State Estimation, Wiley, ch. 13 (the extended Kalman filter).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numba as nb
import numpy as np
from scipy.interpolate import RectBivariateSpline

import linearize
from linearize.validate import check_positive, check_range

__all__ = ["WindEstimatorSettings", "WindSpeedEstimator", "estimator_performance"]


@dataclass(frozen=True)
class WindEstimatorSettings:
    """Tuning of :class:`WindSpeedEstimator` (design data, no case data).

    Parameters
    ----------
    wind_std_per_sqrt_s : float
        Random-walk intensity of the wind state: its std grows by this times sqrt(t) [m/s per
        sqrt(s)]. Larger follows gusts faster and passes more speed noise.
    speed_std : float
        Rotor-speed measurement noise std [rad/s].
    torque_model_std : float
        Model-error std of the aerodynamic torque [N m] (process noise on the speed state).
    shear_exponent : float
        Power-law shear of the C_P table [-] (IEC 61400-1's normal wind profile: 0.2).
    """

    wind_std_per_sqrt_s: float = 0.6
    speed_std: float = 0.005
    torque_model_std: float = 2.0e5
    shear_exponent: float = 0.2

    def __post_init__(self) -> None:
        check_positive("wind_std_per_sqrt_s", self.wind_std_per_sqrt_s)
        check_positive("speed_std", self.speed_std)
        check_positive("torque_model_std", self.torque_model_std)
        check_range("shear_exponent", self.shear_exponent, -1.0, 1.0)


def estimator_performance(turbine: linearize.Turbine, shear_exponent: float = 0.2) -> Any:
    """The C_P table of :class:`WindSpeedEstimator` (tip-speed ratio 1-18, pitch -5 to 40 deg;
    it takes seconds, and :func:`linearize.rotor_performance` keeps it for the process).

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    shear_exponent : float
        Power-law shear of the table [-].

    Returns
    -------
    linearize.RotorPerformance
        From :func:`linearize.rotor_performance`.
    """
    return linearize.rotor_performance(turbine, np.linspace(1.0, 18.0, 69),
                                       np.linspace(-5.0, 40.0, 91),
                                       shear_exponent=shear_exponent)


@nb.njit(cache=True, nogil=True)
def _basis(t: np.ndarray, k: int, x: float, out: np.ndarray,
           dout: np.ndarray) -> int:  # pragma: no cover (compiled)
    """The k + 1 B-spline basis functions of degree k on knots ``t`` that are non-zero at x
    and their first derivatives (de Boor's recurrence, Piegl and Tiller's algorithms A2.2 and
    A2.3), into ``out`` and ``dout``; x is clamped to the spline's interval, as FITPACK's
    ``bispev`` does. Returns the index of the first of them."""
    n = t.shape[0] - k - 1
    x = min(max(x, t[k]), t[n])
    span = k
    while span < n - 1 and x >= t[span + 1]:
        span += 1
    left = np.empty(k + 1)
    right = np.empty(k + 1)
    out[0] = 1.0
    for j in range(1, k + 1):
        left[j] = x - t[span + 1 - j]
        right[j] = t[span + j] - x
        saved = 0.0
        for r in range(j):
            tmp = out[r] / (right[r + 1] + left[j - r])
            out[r] = saved + right[r + 1] * tmp
            saved = left[j - r] * tmp
        out[j] = saved
        if j == k - 1:          # degree k - 1: the derivative's ingredients
            for r in range(k + 1):
                i = span - k + r
                a = out[r - 1] / (t[i + k] - t[i]) if r >= 1 else 0.0
                b = out[r] / (t[i + k + 1] - t[i + 1]) if r <= k - 1 else 0.0
                dout[r] = k * (a - b)
    if k == 0:
        dout[0] = 0.0
    return span - k


@nb.njit(cache=True, nogil=True)
def _spline2(tx: np.ndarray, ty: np.ndarray, c: np.ndarray, kx: int, ky: int, x: float,
             y: float) -> tuple[float, float]:  # pragma: no cover (compiled)
    """A tensor-product spline (FITPACK's tx, ty, c) and its x-derivative at (x, y)."""
    bx, dbx = np.empty(kx + 1), np.empty(kx + 1)
    by, dby = np.empty(ky + 1), np.empty(ky + 1)
    ix = _basis(tx, kx, x, bx, dbx)
    iy = _basis(ty, ky, y, by, dby)
    ncy = ty.shape[0] - ky - 1
    val, dval = 0.0, 0.0
    for r in range(kx + 1):
        row = 0.0
        for q in range(ky + 1):
            row += c[(ix + r) * ncy + iy + q] * by[q]
        val += bx[r] * row
        dval += dbx[r] * row
    return val, dval


#: :class:`WindSpeedEstimator`'s constants in one array for the compiled step.
_RADIUS, _RHO, _GEAR, _INERTIA, _DT, _Q0, _Q1, _R, _VMIN, _VMAX, _TSR0, _TSR1 = range(12)


@nb.njit(cache=True, nogil=True)
def _aero_torque(tx: np.ndarray, ty: np.ndarray, c: np.ndarray, kx: int, ky: int,
                 k: np.ndarray, wind: float, rotor_speed: float,
                 pitch: float) -> tuple[float, float, float]:  # pragma: no cover (compiled)
    """:meth:`WindSpeedEstimator.aero_torque`, compiled."""
    v, w = max(wind, 0.1), max(rotor_speed, 1e-3)
    radius = k[_RADIUS]
    lam = min(max(w * radius / v, k[_TSR0]), k[_TSR1])
    cp, dcp = _spline2(tx, ty, c, kx, ky, lam, pitch)
    g = 0.5 * k[_RHO] * math.pi * radius**2
    q = g * v**3 * cp / w
    dq_dv = g * (3.0 * v**2 * cp - v**3 * dcp * lam / v) / w
    dq_dw = g * v**3 * (dcp * radius / v / w - cp / w**2)
    return q, dq_dv, dq_dw


class WindSpeedEstimator:
    """The design of the extended Kalman filter for the rotor-effective wind speed (module
    docstring): its C_P table, constants and noise settings, which a law's input file carries
    (the filter itself runs in the shipped C law, ``mpc_wt/io/discon_c/windest.c``).

    Parameters
    ----------
    turbine : Turbine
        The turbine (C_P table, radius, inertia, gearbox ratio, air density).
    dt : float
        Step [s], > 0.
    settings : WindEstimatorSettings, optional
        Noise intensities and the table's shear.
    performance : linearize.RotorPerformance, optional
        The C_P table made beforehand (:func:`estimator_performance` with the settings'
        shear); default: made now.

    Raises
    ------
    ValueError
        A non-positive step.
    """

    def __init__(self, turbine: linearize.Turbine, dt: float,
                 settings: WindEstimatorSettings | None = None, *,
                 performance: Any = None) -> None:
        self.dt = check_positive("dt", dt)
        self.settings = settings or WindEstimatorSettings()
        g = turbine.geometry
        self.radius = g.tip_radius * math.cos(g.precone_rad)
        self.rho = turbine.environment.air_density
        self.gear = turbine.drivetrain.gearbox_ratio
        #: the low-speed shaft's torque per unit of generator torque, N / eta_gb
        self.torque_ratio = self.gear / turbine.drivetrain.gearbox_efficiency
        params = linearize.plant_params(turbine)
        self.inertia = params.rotor_inertia + self.gear**2 * turbine.drivetrain.generator_inertia
        op = turbine.operation
        self.wind_range = (0.5 * op.cut_in_wind, 1.5 * op.cut_out_wind)
        table = (estimator_performance(turbine, self.settings.shear_exponent)
                 if performance is None else performance)
        tsr, pitch = np.asarray(table.tsr, float), np.asarray(table.pitch_deg, float)
        spline = RectBivariateSpline(tsr, np.radians(pitch), table.cp, kx=3, ky=3)
        tx, ty, c = spline.tck
        self._spline = (np.ascontiguousarray(tx, float), np.ascontiguousarray(ty, float),
                        np.ascontiguousarray(c, float), *spline.degrees)
        s = self.settings
        self._k = np.array([self.radius, self.rho, self.torque_ratio, self.inertia, self.dt,
                            (s.torque_model_std / self.inertia) ** 2 * self.dt,
                            s.wind_std_per_sqrt_s**2 * self.dt, s.speed_std**2,
                            *self.wind_range, tsr[0], tsr[-1]])
        i, j = np.unravel_index(int(np.argmax(table.cp)), table.cp.shape)
        gain = 0.5 * self.rho * math.pi * self.radius**5 * float(table.cp[i, j]) \
            / float(tsr[i]) ** 3 / self.torque_ratio
        #: the first step's torque schedule where none is measured: K [N m s^2/rad^2] on the
        #: rotor speed, rated torque [N m], rated rotor speed [rad/s]
        self.start_torque = (gain, turbine.rated_generator_torque, op.rated_rotor_speed_rad_s)

    def aero_torque(self, wind: float, rotor_speed: float, pitch: float
                    ) -> tuple[float, float, float]:
        """The aerodynamic torque of the C_P table and its partial derivatives.

        Parameters
        ----------
        wind : float
            Rotor-effective wind speed [m/s].
        rotor_speed : float
            [rad/s].
        pitch : float
            Collective pitch [rad].

        Returns
        -------
        q : float
            Aerodynamic torque [N m].
        dq_dv : float
            Its derivative with respect to the wind [N s].
        dq_domega : float
            Its derivative with respect to the rotor speed [N m s/rad].
        """
        # d/dv: lambda = w R / v, d lambda / dv = -lambda / v
        return _aero_torque(*self._spline, self._k, float(wind), float(rotor_speed),
                            float(pitch))

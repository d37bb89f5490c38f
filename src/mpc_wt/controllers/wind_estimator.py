"""Rotor-effective wind speed from what a turbine controller measures.

An extended Kalman filter on the drivetrain's one-degree-of-freedom model with the wind as a
random walk, the estimator of ROSCO's ``WE_Mode = 2`` in its simplest form:

    J d omega / dt = Q_a(v, omega, theta) - N Q_g,      dv / dt = w,
    Q_a = 1/2 rho pi R_p^2 v^3 C_P(lambda, theta) / omega,      lambda = omega R_p / v,

with J the rotor's and the generator's inertia on the low-speed shaft, N the gearbox ratio,
R_p = R cos(precone) the projected radius and C_P the turbine's steady power coefficient
(:func:`linearize.rotor_performance`, a smooth bicubic fit). It measures the rotor speed
omega; the collective pitch theta and the generator torque Q_g enter as known inputs. So it uses
measurements alone (rotor speed, pitch, generator torque) and the turbine's design data; it
starts from the wind that balances the measured torque at the first step.

References
----------
Julian, Jonkman, Abbas, Pao (2021), ROSCO reference controller, NREL (``WE_Mode`` 2).
Simon (2006), Optimal State Estimation, Wiley, ch. 13 (the extended Kalman filter).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.interpolate import RectBivariateSpline
from scipy.optimize import brentq

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
    """The C_P table of :class:`WindSpeedEstimator` (tip-speed ratio 1-18, pitch -5 to 40 deg),
    to make once and share between estimators of one turbine (it takes seconds).

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


class WindSpeedEstimator:
    """Extended Kalman filter for the rotor-effective wind speed (module docstring).

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
        params = linearize.plant_params(turbine)
        self.inertia = params.rotor_inertia + self.gear**2 * turbine.drivetrain.generator_inertia
        op = turbine.operation
        self.wind_range = (0.5 * op.cut_in_wind, 1.5 * op.cut_out_wind)
        table = (estimator_performance(turbine, self.settings.shear_exponent)
                 if performance is None else performance)
        tsr, pitch = np.asarray(table.tsr, float), np.asarray(table.pitch_deg, float)
        self._cp = RectBivariateSpline(tsr, np.radians(pitch), table.cp, kx=3, ky=3)
        self._tsr_range = (tsr[0], tsr[-1])
        s = self.settings
        self._q = np.diag([(s.torque_model_std / self.inertia) ** 2 * self.dt,
                           s.wind_std_per_sqrt_s**2 * self.dt])
        self._r = s.speed_std**2
        self.reset()

    def reset(self) -> None:
        """Forget the estimate: the next step starts again from the measured torque balance."""
        self.x: np.ndarray | None = None          # [rotor speed, wind]
        self.p = np.diag([self.settings.speed_std**2, 1.0])

    @property
    def estimate(self) -> float | None:
        """The current rotor-effective wind estimate [m/s] (None before the first step)."""
        return None if self.x is None else float(self.x[1])

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
        v, w = max(wind, 0.1), max(rotor_speed, 1e-3)
        lam = min(max(w * self.radius / v, self._tsr_range[0]), self._tsr_range[1])
        cp = float(self._cp.ev(lam, pitch))
        dcp = float(self._cp.ev(lam, pitch, dx=1))
        k = 0.5 * self.rho * math.pi * self.radius**2
        q = k * v**3 * cp / w
        # d/dv: lambda = w R / v, d lambda / dv = -lambda / v
        dq_dv = k * (3.0 * v**2 * cp - v**3 * dcp * lam / v) / w
        dq_dw = k * v**3 * (dcp * self.radius / v / w - cp / w**2)
        return q, dq_dv, dq_dw

    def _balance(self, rotor_speed: float, pitch: float, gen_torque: float) -> float:
        """The wind at which the aerodynamic torque balances the generator's, or the nearest
        end of the turbine's wind range."""
        lo, hi = self.wind_range
        f = (lambda v: self.aero_torque(v, rotor_speed, pitch)[0] - self.gear * gen_torque)
        a, b = f(lo), f(hi)
        if a * b < 0.0:
            return float(brentq(f, lo, hi, xtol=1e-6))
        return lo if abs(a) < abs(b) else hi

    def step(self, rotor_speed: float, pitch: float, gen_torque: float) -> float:
        """Take one step's measurements and return the updated estimate.

        Parameters
        ----------
        rotor_speed : float
            Measured rotor speed [rad/s].
        pitch : float
            Collective (mean) pitch [rad].
        gen_torque : float
            Generator torque [N m] (high-speed shaft).

        Returns
        -------
        float
            Rotor-effective wind speed estimate [m/s].

        Raises
        ------
        ValueError
            A non-finite measurement (naming it).
        """
        for name, val in (("rotor_speed", rotor_speed), ("pitch", pitch),
                          ("gen_torque", gen_torque)):
            if not math.isfinite(val):
                raise ValueError(f"measurement {name} must be finite, got {val!r}")
        if self.x is None:
            self.x = np.array([rotor_speed, self._balance(rotor_speed, pitch, gen_torque)])
            self._u = (pitch, gen_torque)
            return float(self.x[1])
        # predict with the previous step's inputs (held over the step)
        w, v = self.x
        q, dq_dv, dq_dw = self.aero_torque(v, w, self._u[0])
        dt, j = self.dt, self.inertia
        x_pred = np.array([w + dt / j * (q - self.gear * self._u[1]), v])
        f = np.array([[1.0 + dt / j * dq_dw, dt / j * dq_dv], [0.0, 1.0]])
        p = f @ self.p @ f.T + self._q
        # update with the measured rotor speed
        s = p[0, 0] + self._r
        k = p[:, 0] / s
        self.x = x_pred + k * (rotor_speed - x_pred[0])
        self.x[1] = min(max(self.x[1], self.wind_range[0]), self.wind_range[1])
        self.p = p - np.outer(k, p[0, :])
        self._u = (pitch, gen_torque)
        return float(self.x[1])

    def step_measurements(self, meas: dict[str, Any]) -> float:
        """:meth:`step` on a harness measurement dict (``rotor_speed``, ``pitch`` (3,),
        ``gen_torque``).

        Parameters
        ----------
        meas : dict
            The closed loop's measurements.

        Returns
        -------
        float
            The estimate [m/s].
        """
        return self.step(float(meas["rotor_speed"]), float(np.mean(meas["pitch"])),
                         float(meas["gen_torque"]))

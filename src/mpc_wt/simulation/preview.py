"""A simulated LIDAR in the loop: per-blade preview served at each controller step.
"""
from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["LidarPreview"]


class LidarPreview:
    """A simulated LIDAR in the loop: measures the wind field at the rotor's current azimuth
    and speed at every controller step and serves the per-blade preview of the next
    ``horizon`` steps from the measurements taken T_p earlier (:class:`lidar.PreviewBuffer`).
    Only the last measurements are kept (a fixed-size ring), so a step costs the same at any
    time of a run.

    The preview time is the LIDAR's own: T_p = D / V_m with V_m the low-passed mean of its
    rotor-mean measurements (first order, ``mean_time_constant``), started at the first
    measurement. Nothing of the case is known to it.

    Parameters
    ----------
    sensor : lidar.LidarSensor
        The instrument and the wind it measures (bound by the simulator).
    horizon : int
        Preview steps H_p (default 15).
    dt : float
        Controller step [s] (default 0.1).
    mean_time_constant : float
        Low-pass of the measured mean wind [s] (default 30).
    min_wind : float
        The lowest mean wind the preview time is kept for [m/s] (default 2).
    """

    def __init__(self, sensor: Any, horizon: int = 15, dt: float = 0.1,
                 mean_time_constant: float = 30.0, min_wind: float = 2.0) -> None:
        self.sensor = sensor
        self.horizon = int(horizon)
        self.dt = float(dt)
        self.mean_tau, self.min_wind = float(mean_time_constant), float(min_wind)
        self.reset()

    def reset(self) -> None:
        """Forget the measurement history and the mean wind."""
        #: the kept measurements (:class:`lidar.PreviewBuffer`), made at the first call
        self.buffer: Any = None
        self.mean_wind: float | None = None

    @property
    def preview_time(self) -> float:
        """T_p at the measured mean wind [s] (nan before the first measurement)."""
        if self.mean_wind is None:
            return float("nan")
        return self.sensor.focus_distance / max(self.mean_wind, self.min_wind)

    def __call__(self, t: float, azimuth_rad: float, rotor_speed_rad_s: float) -> Any:
        """Measure at ``t`` and return the :class:`lidar.Preview` of the next H_p steps."""
        import lidar

        m = self.sensor.measure(np.array([t]), np.array([azimuth_rad]), rotor_speed_rad_s)
        u = float(np.mean(m.u_hat[0]))
        if self.mean_wind is None:
            self.mean_wind = u
            d = self.sensor.focus_distance
            self.buffer = lidar.PreviewBuffer(d / max(u, self.min_wind), self.dt,
                                              max_preview_time=max(d / self.min_wind,
                                                                   d / max(u, self.min_wind)))
        else:
            self.mean_wind += min(1.0, self.dt / self.mean_tau) * (u - self.mean_wind)
        self.buffer.push(t, m.u_hat[0])
        return self.buffer.preview(t, self.horizon, self.preview_time)

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

    The preview time is the LIDAR's own: T_p = D / V_m with V_m the mean of its rotor-mean
    measurements over about the last ``mean_time_constant`` (10 minutes, the mean wind that
    carries the turbulence in Taylor's hypothesis; the average of all samples before that,
    :class:`~mpc_wt.controllers.filters.MeanTracker`). Nothing of the case is known to it.

    Parameters
    ----------
    sensor : lidar.LidarSensor
        The instrument and the wind it measures (bound by the simulator).
    horizon : int
        Preview steps H_p (default 15).
    dt : float
        Controller step [s] (default 0.1).
    mean_time_constant : float
        Averaging time of the measured mean wind [s] (default 600).
    min_wind : float
        The lowest mean wind the preview time is kept for [m/s] (default 2).
    preview_time : float, optional
        A fixed T_p [s] instead of the measured one (a configured instrument; an idealization
        when it is the simulator's D / V).
    """

    def __init__(self, sensor: Any, horizon: int = 15, dt: float = 0.1,
                 mean_time_constant: float = 600.0, min_wind: float = 2.0,
                 preview_time: float | None = None) -> None:
        self.sensor = sensor
        self.horizon = int(horizon)
        self.dt = float(dt)
        from mpc_wt.controllers.filters import MeanTracker

        self.min_wind = float(min_wind)
        if preview_time is not None and not (np.isfinite(preview_time) and preview_time > 0):
            raise ValueError(f"preview_time must be > 0 s, got {preview_time!r}")
        self.fixed = None if preview_time is None else float(preview_time)
        self.mean_time_constant = float(mean_time_constant)
        self.mean = MeanTracker(mean_time_constant, self.dt)
        self.reset()

    def reset(self) -> None:
        """Forget the measurement history and the mean wind."""
        #: the kept measurements (:class:`lidar.PreviewBuffer`), made at the first call
        self.buffer: Any = None
        self.mean.reset()

    @property
    def mean_wind(self) -> float | None:
        """The LIDAR's measured mean wind [m/s] (None before the first measurement)."""
        return self.mean.value

    @property
    def preview_time(self) -> float:
        """T_p at the measured mean wind [s] (nan before the first measurement), or the fixed
        one."""
        if self.fixed is not None:
            return self.fixed
        if self.mean_wind is None:
            return float("nan")
        return self.sensor.focus_distance / max(self.mean_wind, self.min_wind)

    def __call__(self, t: float, azimuth_rad: float, rotor_speed_rad_s: float) -> Any:
        """Measure at ``t`` and return the :class:`lidar.Preview` of the next H_p steps."""
        import lidar

        m = self.sensor.measure(np.array([t]), np.array([azimuth_rad]), rotor_speed_rad_s)
        u = self.mean.update(float(np.mean(m.u_hat[0])))
        if self.buffer is None:
            d = self.sensor.focus_distance
            first = self.fixed or d / max(u, self.min_wind)
            self.buffer = lidar.PreviewBuffer(first, self.dt, max_preview_time=max(
                first, d / self.min_wind if self.fixed is None else first))
        self.buffer.push(t, m.u_hat[0])
        return self.buffer.preview(t, self.horizon, self.preview_time)

"""A simulated LIDAR in the loop: per-blade preview served at each controller step.
"""
from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["LidarPreview"]


class LidarPreview:
    """A simulated LIDAR in the loop: measures the wind field at the rotor's current azimuth
    and speed at every controller step and serves the per-blade preview of the next
    ``horizon`` steps from the measurements taken T_p earlier (:func:`lidar.preview`). Only
    the last T_p of measurements is kept (a fixed-size ring, :class:`lidar.PreviewBuffer`), so
    a step costs the same at any time of a run.

    Parameters
    ----------
    lidar_model : lidar.CWLidar
        The instrument.
    field : lidar.WindField
        The same field the plant meets (as its GridWind).
    horizon : int
        Preview steps H_p (default 15).
    dt : float
        Controller step [s] (default 0.1).
    """

    def __init__(self, lidar_model: Any, field: Any, horizon: int = 15, dt: float = 0.1) -> None:
        self.lidar = lidar_model
        self.field = field
        self.horizon = int(horizon)
        self.dt = float(dt)
        self.reset()

    def reset(self) -> None:
        """Forget the measurement history."""
        #: the kept measurements (:class:`lidar.PreviewBuffer`, the last T_p), made at the
        #: first call when the instrument's preview time is known
        self.buffer: Any = None

    def __call__(self, t: float, azimuth_rad: float, rotor_speed_rad_s: float) -> Any:
        """Measure at ``t`` and return the :class:`lidar.Preview` of the next H_p steps."""
        import lidar

        m = self.lidar.measure(self.field, np.array([t]), np.array([azimuth_rad]),
                               rotor_speed_rad_s)
        if self.buffer is None:
            self.buffer = lidar.PreviewBuffer(m.preview_time, self.dt)
        self.buffer.push(t, m.u_hat[0])
        return self.buffer.preview(t, self.horizon)

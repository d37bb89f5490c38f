"""InflowWind's single-point lidar (OpenFAST v5.0.0, ``SensorType = 1``), as a controller meets
it through ServoDyn's extended swap array.

InflowWind measures at up to five points fixed relative to the rotor's apex (``FocalDistanceX``,
``FocalDistanceY``, ``FocalDistanceZ`` from the hub plus ``RotorApexOffsetPos``; they do not
turn with the rotor), and gives at each the wind's magnitude ``|V|`` (not a line-of-sight
speed). It measures only at a time that is an exact multiple of ``MeasurementInterval`` (the
test is ``MeasurementInterval * INT(t / MeasurementInterval) == t`` in floating point, so a few
samples of a run are skipped) and holds the last values in between (``Lidar.f90``,
``Lidar_CalcOutput``). ServoDyn writes them to records 2001-2500 (``BladedInterface_EX.f90``):
2001 the sensor type, 2002 the beams, 2003 the pulse gates (1), 2004 the reference wind (0),
then the n speeds from 2005 and the points' x, y, z (n each).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from lidar._typing import FloatArray
from lidar.field import WindField

__all__ = ["PointLidar"]


def _points(name: str, value: Any) -> FloatArray:
    a = np.asarray(value, float)
    if a.ndim != 2 or a.shape[1] != 3 or not 1 <= a.shape[0] <= 5:
        raise ValueError(f"{name} must be an (n, 3) array of x, y, z [m] with 1 <= n <= 5 "
                         f"(InflowWind's NumBeam), got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite, got {a.tolist()}")
    if np.any(a[:, 0] >= 0.0):
        raise ValueError(f"{name}: every point must be upwind of the hub (x < 0, x downwind as "
                         f"OpenFAST's), got x = {a[:, 0].tolist()}")
    return a


@dataclass(frozen=True)
class PointLidar:
    """InflowWind's single-point lidar on a wind field.

    Parameters
    ----------
    points : (n, 3) array_like
        The points from the hub [m]: x (downwind, < 0: upwind), y (to the left looking
        downwind), z (up); ``FocalDistanceX/Y/Z`` plus ``RotorApexOffsetPos``.
    interval : float
        ``MeasurementInterval`` [s].
    hub : (3,) array_like
        The hub's position in OpenFAST's global frame [m] (the records' positions are the
        points' there): x of the apex, y 0, z the hub height.
    field : WindField, optional
        What it measures (:meth:`bind`).
    sensor_type : {1, 2}
        1: single points, the wind's magnitude at each; 2: InflowWind's CW lidar, one beam
        with ``LidRadialVel False`` (its estimate of the wind along x), taken here as the x
        component at its focus point (InflowWind weights it along the beam).
    """

    points: Any
    interval: float
    hub: Any = (0.0, 0.0, 0.0)
    field: WindField | None = None
    sensor_type: int = 1

    def __post_init__(self) -> None:
        object.__setattr__(self, "points", _points("points", self.points))
        if not (isinstance(self.interval, (int, float)) and math.isfinite(self.interval)
                and self.interval > 0.0):
            raise ValueError(f"interval must be a time > 0 s (MeasurementInterval), got "
                             f"{self.interval!r}")
        hub = np.asarray(self.hub, float)
        if hub.shape != (3,) or not np.all(np.isfinite(hub)):
            raise ValueError(f"hub must be a finite (x, y, z) [m], got {self.hub!r}")
        object.__setattr__(self, "hub", hub)
        if self.sensor_type not in (1, 2) or (self.sensor_type == 2 and len(self.points) != 1):
            raise ValueError(f"sensor_type must be 1 (single points) or 2 (one CW beam, one "
                             f"point), got {self.sensor_type!r} with {len(self.points)} points")

    def bind(self, field: WindField) -> "PointLidar":
        """This lidar on ``field``.

        Parameters
        ----------
        field : WindField
            The wind as the rotor meets it (``t`` its arrival at the rotor plane); a point x
            upwind sees at time t the field's wind at t - x / mean_speed (frozen turbulence,
            as InflowWind carries a TurbSim field).

        Returns
        -------
        PointLidar
        """
        if not isinstance(field, WindField):
            raise TypeError(f"field must be a WindField, got {type(field).__name__}")
        return PointLidar(self.points, self.interval, self.hub, field, self.sensor_type)

    def due(self, t: float) -> bool:
        """Whether InflowWind measures at ``t``: ``interval * int(t / interval) == t``.

        Parameters
        ----------
        t : float
            The simulation time [s].

        Returns
        -------
        bool
        """
        return self.interval * int(t / self.interval) == t

    def records(self, t: float) -> FloatArray:
        """Records 2001 to 2004 + 4 n (their values in order) at time ``t``.

        Parameters
        ----------
        t : float
            The measurement's time [s].

        Returns
        -------
        (4 + 4 n,) ndarray
            The sensor type, n beams, 1 gate, 0, the n speeds (``|V|``, or u for the CW
            beam) [m/s], then the points' x, y, z in OpenFAST's frame [m].

        Raises
        ------
        RuntimeError
            Before :meth:`bind`.
        ValueError
            A point outside the field's grid or its time.
        """
        f = self.field
        if f is None:
            raise RuntimeError("the lidar has no wind to measure: bind the case's field first")
        p = self.points
        tt = t - p[:, 0] / float(f.mean_speed)
        z = f.hub_height + p[:, 2]
        uvw = np.stack(f.sample_components(tt, p[:, 1], z, "uvw")).astype(float)
        speed = np.sqrt(np.sum(uvw ** 2, axis=0)) if self.sensor_type == 1 else uvw[0]
        pos = p + self.hub
        n = p.shape[0]
        return np.concatenate([[float(self.sensor_type), float(n), 1.0, 0.0], speed, pos[:, 0],
                               pos[:, 1], pos[:, 2]])

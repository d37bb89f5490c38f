"""Which design of a gain-scheduled controller acts: a grid of mean winds, a scheduling wind
that the controller measures, and hysteresis against chattering.

The scheduling wind is the rotor-effective wind of :class:`WindSpeedEstimator` (rotor speed,
pitch and generator torque) or, for a controller with a LIDAR, the rotor mean of the LIDAR's
own measurements; either one is low-passed (first order, ``time_constant``) so that the
schedule follows the mean wind, not the gusts. At the first step the schedule starts at the
grid wind nearest the first estimate: nothing of the case is known before it.
"""
from __future__ import annotations

import bisect
import math
from typing import Any

import numpy as np

import linearize
from linearize.validate import check_number
from mpc_wt.controllers.wind_estimator import WindEstimatorSettings, WindSpeedEstimator

__all__ = ["WindSchedule", "envelope_winds", "SCHEDULE_SOURCES"]

#: Where a schedule's wind comes from.
SCHEDULE_SOURCES = ("estimator", "preview")


def envelope_winds(turbine: linearize.Turbine, step: float = 1.0) -> np.ndarray:
    """The grid of a design over the whole operating envelope: cut-in to cut-out every
    ``step``, with the rated wind speed added (where the regions meet).

    Parameters
    ----------
    turbine : Turbine
        Its operating range and rated wind.
    step : float
        Grid spacing [m/s], > 0.

    Returns
    -------
    (n,) ndarray
        Mean winds [m/s], increasing.
    """
    check_number("step", step, lo=0.0, lo_open=True, unit="m/s")
    op = turbine.operation
    grid = np.arange(op.cut_in_wind, op.cut_out_wind + 1e-9, step)
    rated = linearize.rated_wind_speed(turbine)
    if op.cut_in_wind < rated < op.cut_out_wind and np.min(np.abs(grid - rated)) > 0.05:
        grid = np.sort(np.append(grid, round(rated, 2)))
    return grid


class WindSchedule:
    """The active grid point of a wind-scheduled controller.

    Parameters
    ----------
    grid : (n,) array
        The designs' mean winds [m/s], increasing.
    turbine : Turbine
        For the wind estimator.
    dt : float
        The controller's step [s].
    source : {"estimator", "preview"}
        The scheduling wind: :class:`WindSpeedEstimator` on the measurements, or the LIDAR's
        rotor-mean measurement (``meas["preview"].rotor[0]``; the estimator stands in, from
        the measured torque balance, while no preview is given).
    time_constant : float
        Low-pass of the scheduling wind [s] (default 30).
    hysteresis : float
        Beyond the midpoint between grid winds before a switch [m/s] (default 0.25).
    estimator : WindSpeedEstimator or WindEstimatorSettings, optional
        The wind estimator (at ``dt``), or its tuning.
    """

    def __init__(self, grid: Any, turbine: linearize.Turbine, dt: float, *,
                 source: str = "estimator", time_constant: float = 30.0,
                 hysteresis: float = 0.25,
                 estimator: WindSpeedEstimator | WindEstimatorSettings | None = None) -> None:
        g = np.asarray(grid, dtype=float)
        if g.ndim != 1 or g.size < 1 or not np.all(np.isfinite(g)) or np.any(np.diff(g) <= 0):
            raise ValueError(f"grid must be increasing finite mean winds [m/s], got {grid!r}")
        if source not in SCHEDULE_SOURCES:
            raise ValueError(f"source must be one of {SCHEDULE_SOURCES}, got {source!r}")
        self.grid, self.source = g, source
        self._mid = (0.5 * (g[1:] + g[:-1])).tolist()     # the midpoints between grid winds
        self.dt = check_number("dt", dt, lo=0.0, lo_open=True, unit="s")
        self.tau = check_number("time_constant", time_constant, lo=0.0, unit="s")
        self.hyst = check_number("hysteresis", hysteresis, lo=0.0, unit="m/s")
        if isinstance(estimator, WindSpeedEstimator):
            if abs(estimator.dt - self.dt) > 1e-12:
                raise ValueError(f"the wind estimator runs at {estimator.dt:g} s, the schedule "
                                 f"at {self.dt:g} s")
            self.estimator = estimator
        else:
            self.estimator = WindSpeedEstimator(turbine, dt, estimator)
        self.reset()

    def reset(self) -> None:
        """Forget the wind: the next :meth:`update` starts the schedule again."""
        self.estimator.reset()
        self.wind: float | None = None
        self.measured: float | None = None      # this step's wind before the low-pass
        self.active: int | None = None
        self.switches = 0
        self._from_estimator = False

    #: how far beyond the grid's ends the scheduling wind may lie before :attr:`outside` [m/s]
    OUTSIDE_MARGIN = 1.0

    @property
    def outside(self) -> bool:
        """Whether the low-passed scheduling wind lies more than :attr:`OUTSIDE_MARGIN` beyond
        the grid's ends: the acting design is then the nearest, used outside its range."""
        return self.wind is not None and not (
            self.grid[0] - self.OUTSIDE_MARGIN <= self.wind <= self.grid[-1] + self.OUTSIDE_MARGIN)

    @property
    def estimator_outside(self) -> bool:
        """Whether this step's scheduling wind came from the wind estimator and the estimate
        left its validity (:attr:`WindSpeedEstimator.outside`)."""
        return self._from_estimator and self.estimator.outside

    def measured_wind(self, meas: dict[str, Any]) -> float:
        """This step's scheduling wind before the low-pass [m/s].

        Parameters
        ----------
        meas : dict
            The harness's measurements.

        Returns
        -------
        float
        """
        self._from_estimator = not (self.source == "preview"
                                    and meas.get("preview") is not None)
        if not self._from_estimator:
            return float(meas["preview"].rotor[0])
        return self.estimator.step_measurements(meas)

    def update(self, meas: dict[str, Any]) -> tuple[int, bool]:
        """Take this step's measurements; the active grid index and whether it changed.

        Parameters
        ----------
        meas : dict
            The harness's measurements (``rotor_speed``, ``pitch``, ``gen_torque``; ``preview``
            for the LIDAR source).

        Returns
        -------
        k : int
            The active grid index.
        switched : bool
            True when ``k`` differs from the last step's (never at the first step).
        """
        w = self.measured_wind(meas)
        if not math.isfinite(w):
            raise ValueError(f"scheduling wind is not finite ({w!r})")
        self.measured = w
        if self.wind is None:
            self.wind = w
            self.active = bisect.bisect_left(self._mid, w)      # the nearest grid wind
            return self.active, False
        a = 1.0 if self.tau == 0 else min(1.0, self.dt / self.tau)
        self.wind += a * (w - self.wind)
        k, now = bisect.bisect_left(self._mid, self.wind), int(self.active or 0)
        if k != now and abs(self.wind - 0.5 * (self.grid[k] + self.grid[now])) > self.hyst:
            self.active = k
            self.switches += 1
            return k, True
        return now, False

    def acting(self, meas: dict[str, Any], design: Any) -> tuple[int, Any]:
        """Update with this step's measurements and return the design that acts now; on a
        switch it is reset and continues from the one before (``hand_over``: bumpless).

        Parameters
        ----------
        meas : dict
            The harness's measurements.
        design : callable
            Grid index -> its controller (with ``reset()`` and ``hand_over(other)``).

        Returns
        -------
        k : int
            The active grid index.
        controller : object
            ``design(k)``.
        """
        before = self.active
        k, switched = self.update(meas)
        ctl = design(k)
        if switched:
            ctl.reset()
            ctl.hand_over(design(before))
        return k, ctl

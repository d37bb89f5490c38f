"""Which design of a gain-scheduled controller acts: a grid of mean winds, a scheduling wind
that the controller measures, and hysteresis against chattering.

The scheduling wind is the rotor-effective wind of :class:`WindSpeedEstimator` (rotor speed,
pitch and generator torque) or, for a controller with a LIDAR, the rotor mean of the LIDAR's
own measurements; either one is low-passed (first order, ``time_constant``) so that the
schedule follows the mean wind, not the gusts. At the first step the schedule starts at the
grid wind nearest the first estimate: nothing of the case is known before it.

Near rated wind the aerodynamic torque is flat in pitch: the power coefficient has its maximum
at fine pitch, so a linearization at the rated trim (pitch at fine) sees almost no pitch
sensitivity (the NREL 5-MW's rotor-speed response to collective pitch is 0.068 1/s per rad at
rated wind against 0.44 at 12 m/s, where the trim pitch is 3.9 deg), and a design made on it
commands large pitch moves whose effect the plant multiplies once the blades leave fine pitch.
Which design fits is told by the pitch the turbine is at, not only by the wind: a
:class:`RegionFloor` raises the scheduling wind to what the measured collective pitch says
(the trim's pitch curve read backwards) and, while the rotor runs above rated speed, to the
first design inside region 3; and :func:`envelope_winds` can put that first design where the
trim has left fine pitch (``region3_pitch``) instead of at rated wind. The same idea is the
baseline's gain schedule on the measured pitch (Jonkman et al. 2009, sec. 7.4).
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

import linearize
from linearize.validate import check_number
from mpc_wt.controllers.wind_estimator import WindEstimatorSettings, WindSpeedEstimator

__all__ = ["WindSchedule", "RegionFloor", "envelope_winds", "region3_wind", "SCHEDULE_SOURCES"]

#: Where a schedule's wind comes from.
SCHEDULE_SOURCES = ("estimator", "preview")


def region3_wind(turbine: linearize.Turbine, pitch_rad: float, *,
                 config: linearize.PlantConfig | None = None) -> float:
    """The wind above rated at which the trim's collective pitch reaches ``pitch_rad`` above
    the region-2 pitch at rated wind (fine pitch, or a minimum-pitch schedule's there:
    :func:`linearize.region2_pitch`; bisection on :func:`linearize.trim`).

    Parameters
    ----------
    turbine : Turbine
    pitch_rad : float
        Pitch above fine pitch [rad], > 0, below the trim's pitch at cut-out.
    config : PlantConfig, optional
        The plant configuration of the trim (the designs').

    Returns
    -------
    float
        [m/s], rounded to 0.01 m/s.

    Raises
    ------
    ValueError
        If ``pitch_rad`` is not positive or the trim does not reach it by cut-out wind.
    """
    check_number("pitch_rad", pitch_rad, lo=0.0, lo_open=True, unit="rad")
    lo, hi = linearize.rated_wind_speed(turbine, config=config), turbine.operation.cut_out_wind
    fine = linearize.region2_pitch(turbine, lo)     # fine pitch, or the schedule's at rated

    def excess(v: float) -> float:
        return linearize.trim(turbine, v, config=config).pitch_rad - fine - pitch_rad

    if excess(hi) <= 0.0:
        raise ValueError(f"pitch_rad = {pitch_rad:g} rad: the trim's pitch at cut-out "
                         f"({hi:g} m/s) does not reach it")
    from scipy.optimize import brentq

    return round(float(brentq(excess, lo, hi, xtol=1e-3)), 2)


def envelope_winds(turbine: linearize.Turbine, step: float = 1.0, *,
                   region3_pitch: float | None = None,
                   config: linearize.PlantConfig | None = None) -> np.ndarray:
    """The grid of a design over the whole operating envelope: cut-in to cut-out every
    ``step``, with the rated wind speed added (where the regions meet) or, with
    ``region3_pitch``, the wind where the trim's pitch has left fine pitch by that much
    (:func:`region3_wind`) in its place: the first design above rated then sees the pitch
    sensitivity of the pitch moves it will make, not the flat torque of fine pitch.

    Parameters
    ----------
    turbine : Turbine
        Its operating range and rated wind.
    step : float
        Grid spacing [m/s], > 0.
    region3_pitch : float, optional
        Pitch above fine pitch of the first design above rated [rad], > 0.
    config : PlantConfig, optional
        The designs' plant configuration (for ``region3_pitch``'s trim).

    Returns
    -------
    (n,) ndarray
        Mean winds [m/s], increasing.
    """
    check_number("step", step, lo=0.0, lo_open=True, unit="m/s")
    op = turbine.operation
    grid = np.arange(op.cut_in_wind, op.cut_out_wind + 1e-9, step)
    rated = linearize.rated_wind_speed(turbine)
    if not op.cut_in_wind < rated < op.cut_out_wind:
        return grid
    if region3_pitch is not None:
        v3 = region3_wind(turbine, region3_pitch, config=config)
        grid = grid[(grid <= rated) | (grid >= v3 + 0.05)]     # none between rated and v3
        return np.sort(np.append(grid[np.abs(grid - v3) > 0.05], v3))
    if np.min(np.abs(grid - rated)) > 0.05:
        grid = np.sort(np.append(grid, round(rated, 2)))
    return grid


class RegionFloor:
    """The least design wind that the measured operating region allows: above rated the
    trim's collective pitch rises with the wind, so a measured collective pitch above fine
    pitch says the turbine is at least at the wind whose trim has that pitch (the pitch curve
    read backwards), and a rotor above rated speed says it is past rated wind however the
    wind estimate lags. :class:`WindSchedule` takes the larger of its scheduling wind and this
    floor before its low-pass.

    Parameters
    ----------
    winds, pitches : (n,) array
        The trim's pitch curve above rated: winds [m/s] and collective pitches [rad], both
        increasing (e.g. a design family's grid points above rated, :meth:`from_family`).
    pitch_threshold : float
        A measured collective pitch above this [rad] counts (fine pitch + a margin).
    rated_speed : float
        Rated rotor speed [rad/s].
    speed_margin : float
        A rotor speed above ``speed_margin`` x rated counts [-], >= 1 (default 1.01).
    region3_wind : float, optional
        The floor while the rotor runs above rated speed [m/s] (default ``winds[0]``).
    pitch_min_speed : float
        The pitch counts only while the rotor runs above this fraction of rated speed [-]
        (default 0.95): in region 3 the rotor is held near rated speed, while a pitched rotor
        far below it is in a lull or a direction change (an extreme coherent gust with
        direction change at 9.4 m/s let a region-3 design brake the rotor to a stop), or,
        on rotors whose trim pitches below rated (the IEA-15 at 3-7 m/s, 0.66 x rated), in
        region 1.5.
    """

    def __init__(self, winds: Any, pitches: Any, pitch_threshold: float, rated_speed: float,
                 speed_margin: float = 1.01, region3_wind: float | None = None,
                 pitch_min_speed: float = 0.95) -> None:
        w, p = np.asarray(winds, dtype=float), np.asarray(pitches, dtype=float)
        if w.ndim != 1 or w.size < 1 or w.shape != p.shape or not np.all(np.isfinite(w)) \
                or not np.all(np.isfinite(p)) or np.any(np.diff(w) <= 0) \
                or np.any(np.diff(p) <= 0):
            raise ValueError(f"winds and pitches must be increasing finite arrays of one shape, "
                             f"got {winds!r} and {pitches!r}")
        self.winds, self.pitches = w, p
        self.pitch_threshold = check_number("pitch_threshold", pitch_threshold, unit="rad")
        self.rated_speed = check_number("rated_speed", rated_speed, lo=0.0, lo_open=True,
                                        unit="rad/s")
        self.speed_margin = check_number("speed_margin", speed_margin, lo=1.0)
        self.region3_wind = float(w[0]) if region3_wind is None else check_number(
            "region3_wind", region3_wind, lo=0.0, lo_open=True, unit="m/s")
        self.pitch_min_speed = check_number("pitch_min_speed", pitch_min_speed, lo=0.0,
                                            hi=self.speed_margin)

    #: the default margin above fine pitch [rad] (0.3 deg: above the pitch's noise at fine)
    PITCH_MARGIN = math.radians(0.3)

    @classmethod
    def from_family(cls, family: Any, turbine: linearize.Turbine,
                    pitch_margin: float | None = None, speed_margin: float = 1.01
                    ) -> "RegionFloor":
        """The floor of a design family: its grid winds above rated wind and their trims'
        collective pitch.

        Parameters
        ----------
        family : LinearModelFamily
        turbine : Turbine
            Fine pitch (or its minimum-pitch schedule's at rated wind: the threshold's base),
            rated wind and rotor speed.
        pitch_margin : float, optional
            Above fine pitch [rad] (default :attr:`PITCH_MARGIN`).
        speed_margin : float
            Above rated rotor speed [-] (default 1.01).

        Returns
        -------
        RegionFloor

        Raises
        ------
        ValueError
            If the family has no design above rated wind.
        """
        rated = linearize.rated_wind_speed(turbine)
        winds = np.asarray(family.wind_mps, dtype=float)
        pitch = np.array([float(np.mean(m.u0[:3])) for m in family.models])
        keep = winds > rated + 0.01
        if not np.any(keep):
            raise ValueError(f"the family's winds {winds.tolist()} have none above rated "
                             f"({rated:.3g} m/s): no region floor")
        w, p = winds[keep], pitch[keep]
        rising = np.cumprod(np.concatenate([[True], np.diff(p) > 0])).astype(bool)
        w, p = w[rising], p[rising]                     # the rising part of the curve
        margin = cls.PITCH_MARGIN if pitch_margin is None else pitch_margin
        return cls(w, p, linearize.region2_pitch(turbine, rated) + margin,
                   turbine.operation.rated_rotor_speed_rad_s, speed_margin)

    def floor(self, pitch: float, rotor_speed: float) -> float:
        """The floor [m/s] at a measured collective pitch [rad] and rotor speed [rad/s]; -inf
        when neither says region 3 (the pitch counts above ``pitch_min_speed`` x rated speed).

        Parameters
        ----------
        pitch : float
            Mean of the three measured pitches [rad].
        rotor_speed : float
            [rad/s]

        Returns
        -------
        float
        """
        f = -math.inf
        if pitch > self.pitch_threshold and rotor_speed > self.pitch_min_speed * self.rated_speed:
            f = float(np.interp(pitch, self.pitches, self.winds))
        if rotor_speed > self.speed_margin * self.rated_speed:
            f = max(f, self.region3_wind)
        return f


class WindSchedule:
    """The schedule of a wind-scheduled controller's designs, as its shipped law runs it
    (``mpc_wt/io/discon_c/windest.c``): the scheduling wind (the estimator's, or the LIDAR's
    rotor-mean measurement) raised to the region floor, low-passed, the nearest grid wind
    acting, a switch only beyond the hysteresis past the midpoint between grid winds; the
    first step at the grid wind nearest the first wind.

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
    floor : RegionFloor, optional
        The least wind the measured pitch and rotor speed allow (default none): the
        scheduling wind is the larger of the two before the low-pass; :attr:`measured` stays
        the wind itself, :attr:`floored` is the larger.
    """

    def __init__(self, grid: Any, turbine: linearize.Turbine, dt: float, *,
                 source: str = "estimator", time_constant: float = 30.0,
                 hysteresis: float = 0.25,
                 estimator: WindSpeedEstimator | WindEstimatorSettings | None = None,
                 floor: RegionFloor | None = None) -> None:
        g = np.asarray(grid, dtype=float)
        if g.ndim != 1 or g.size < 1 or not np.all(np.isfinite(g)) or np.any(np.diff(g) <= 0):
            raise ValueError(f"grid must be increasing finite mean winds [m/s], got {grid!r}")
        if source not in SCHEDULE_SOURCES:
            raise ValueError(f"source must be one of {SCHEDULE_SOURCES}, got {source!r}")
        self.grid, self.source = g, source
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
        self.floor = floor



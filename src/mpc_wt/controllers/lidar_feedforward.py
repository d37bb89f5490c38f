"""Collective pitch feedforward from a CW LIDAR on the baseline PI (Schlipf et al. 2013,
"LIDAR-assisted collective pitch control"; Schlipf 2015, dissertation, ch. 5).

At each LIDAR sample the rotor-effective wind is estimated as the mean of the three beams'
reconstructed speeds and low-pass filtered (second order, damping 0.7, by default; or first
order) at the corner where the coherence between the LIDAR's and the rotor's effective wind
falls to 0.5. That corner is designed from the turbulence model (the IEC Kaimal spectra and
coherence, the LIDAR's geometry and range weighting, Simley and Pao's wind evolution;
:func:`lidar.coherence_corner_model`) over mean wind, once per turbine and LIDAR, and read in
operation at the LIDAR's own measured mean wind. The filtered estimate is stored under the time
it reaches the rotor, t + T_p, with T_p = focus distance / the measured mean wind. At control
time t the feedforward pitch is the static pitch curve theta_ss(v) of the trim at the filtered
wind due at t + tau, tau = the actuator's time constant + the filter's delay (1.4 / omega_c for
the second order, 1 / omega_c for the first), so the pitch arrives when the wind does. Its
change enters the PI's integral at every step, so the feedback acts on what the feedforward
leaves and the two never fight. The law is the baseline's C law with its feedforward
(``mpc_wt/io/discon_c/baseline.c``), reading the beams from OpenFAST's lidar records; this
module designs it.
"""
from __future__ import annotations

import logging
import math
from typing import Any

import numpy as np

import linearize
from mpc_wt.controllers.base import DesignBase

__all__ = ["LidarFeedforward", "static_pitch_curve", "rews_coherence_corner",
           "corner_within_preview", "model_corner_table"]

#: Low-frequency group delay of the low-pass times its corner, by order (second: damping 0.7).
FILTER_DELAY = {1: 1.0, 2: 1.4}


def static_pitch_curve(turbine: linearize.Turbine, power_W: float | None = None
                       ) -> tuple[np.ndarray, np.ndarray]:
    """theta_ss(v): the trimmed collective pitch over wind, cut-in to cut-out every 0.5 m/s.

    Parameters
    ----------
    turbine : Turbine
    power_W : float, optional
        A derated power reference [W].

    Returns
    -------
    wind : (n,) ndarray
        [m/s]
    pitch : (n,) ndarray
        [rad]
    """
    op = turbine.operation
    v = np.arange(op.cut_in_wind, op.cut_out_wind + 1e-9, 0.5)
    pts = linearize.operating_schedule(turbine, v, power_W)
    return v, np.array([p.pitch_rad for p in pts])


class LidarFeedforward(DesignBase):
    """The design of the baseline PI with LIDAR collective pitch feedforward, run by its shipped
    law (the ``lidar-ff`` kind) on the LIDAR records.

    Everything it uses in operation is measured: the rotor-effective wind estimate (mean of the
    three beams), and its own mean over about 10 minutes (``mean_time_constant``), which sets the preview
    time T_p = D / V_m and, through the design's corner table, the filter's corner at that
    wind. Nothing of the case is known to it.

    Parameters
    ----------
    base : BaselineController
        The feedback controller (derated or not).
    sensor : lidar.LidarSensor
        The LIDAR (range weighting and line-of-sight error on by default); the simulator binds
        the wind it measures.
    turbine : Turbine
        For the static pitch curve and the actuator lag.
    corner : float or (winds, corners)
        The estimate's low-pass corner omega_c [rad/s]: one value, or a table over mean wind
        [m/s] -> [rad/s] (from the turbulence model, :func:`model_corner_table`), read at the
        measured mean wind.
    lead_s : float, optional
        tau [s]; default the actuator time constant + the filter's delay, with the corner raised
        where needed so that tau fits the preview time (:func:`corner_within_preview`).
    sample_dt : float
        LIDAR sample period [s] (default 0.1).
    filter_order : {1, 2}
        Second order with damping 0.7 (default; delay 1.4 / omega_c at low frequency, steeper
        above the corner) or first order (delay 1 / omega_c).
    power_W : float, optional
        A derated design's power for its pitch curve [W].
    mean_time_constant : float
        The measured mean wind's averaging time [s] (default 600: the mean wind that carries
        the turbulence in Taylor's hypothesis;
        :class:`~mpc_wt.controllers.filters.MeanTracker`).
    """

    def __init__(self, base: Any, sensor: Any, turbine: linearize.Turbine, *,
                 corner: Any, lead_s: float | None = None, sample_dt: float = 0.1,
                 filter_order: int = 2, power_W: float | None = None,
                 mean_time_constant: float = 600.0) -> None:
        self.kind = "baseline+lidar-ff"
        if isinstance(corner, (int, float)):
            cw_, cc = np.array([0.0, 1.0]), np.array([float(corner)] * 2)
        else:
            cw_, cc = (np.asarray(a, dtype=float) for a in corner)
        if cc.ndim != 1 or cc.shape != cw_.shape or cc.size < 1 or \
                not np.all(np.isfinite(cc) & (cc > 0)):
            raise ValueError(f"corner must be > 0 rad/s (or a table of them), got {corner!r}")
        if filter_order not in (1, 2):
            raise ValueError(f"filter_order must be 1 or 2, got {filter_order!r}")
        if lead_s is not None and not (math.isfinite(lead_s) and lead_s >= 0):
            raise ValueError(f"lead_s must be >= 0 s, got {lead_s!r}")
        self.base, self.sensor = base, sensor
        self.dt = base.dt
        self.corner_winds, self.corners = cw_, cc
        self.order = filter_order
        self.tau_act = turbine.pitch_actuator.time_constant
        self.lead_given = lead_s
        self.sample_dt = float(sample_dt)
        self.mean_time_constant = float(mean_time_constant)
        self.curve_v, self.curve_pitch = static_pitch_curve(turbine, power_W)


def model_corner_table(lidar_model: Any, turbine: linearize.Turbine, turbulence: str | float = "A",
                       *, evolution: bool = True, step: float = 1.0
                       ) -> tuple[np.ndarray, np.ndarray]:
    """The feedforward filter's corner over mean wind from the turbulence model: where the
    model coherence of the LIDAR's and the rotor's effective wind falls to 0.5
    (:func:`lidar.coherence_corner_model`; Schlipf 2015, sec. 5.2), cut-in to cut-out.

    Parameters
    ----------
    lidar_model : lidar.CWLidar
        The instrument.
    turbine : Turbine
        Rotor radius, hub height, operating range.
    turbulence : str or float
        The design's IEC class ("A", "B", "C") or turbulence intensity.
    evolution : bool
        With wind evolution over the focus distance.
    step : float
        Grid spacing [m/s].

    Returns
    -------
    winds : (n,) ndarray
        [m/s]
    corners : (n,) ndarray
        omega_c [rad/s].
    """
    import lidar

    op = turbine.operation
    winds = np.arange(op.cut_in_wind, op.cut_out_wind + 1e-9, step)
    corners = np.array([2.0 * math.pi * lidar.coherence_corner_model(
        lidar_model, lidar.TurbulenceSpec(float(v), turbulence,
                                          hub_height=turbine.geometry.hub_height),
        turbine.geometry.tip_radius, evolution=evolution) for v in winds])
    return winds, corners


def rews_coherence_corner(lidar_model: Any, field: Any, turbine: linearize.Turbine,
                          mean_wind_mps: float, sample_dt: float = 0.1, *,
                          seen: Any = None) -> float:
    """The feedforward filter's corner from the coherence between the LIDAR's rotor-effective
    wind estimate (mean of the three beams, moved by T_p) and the true rotor-effective wind of
    the field (disc average, :func:`lidar.rotor_effective_wind`) where it falls to 0.5
    (Schlipf 2015, sec. 5.2: the filter passes what the LIDAR can see of the rotor's wind).

    Parameters
    ----------
    lidar_model : lidar.CWLidar
    field : lidar.WindField
        The field the rotor meets.
    turbine : Turbine
        Rotor radius and the rotor speed of the trim (the beams turn with it).
    mean_wind_mps : float
        [m/s]
    sample_dt : float
        LIDAR sample period [s].
    seen : lidar.WindField, optional
        The field the LIDAR measures (default ``field``: frozen turbulence; with wind evolution,
        :func:`lidar.evolve_field` of it over the focus distance).

    Returns
    -------
    float
        omega_c [rad/s].
    """
    import lidar

    tp = lidar_model.preview_time(mean_wind_mps)
    t = np.arange(field.t[0], field.t[-1] - tp - 1e-9, sample_dt)
    if t.size * sample_dt < 120.0:
        logging.getLogger(__name__).warning(
            "feedforward corner estimated from %.0f s of field only (Welch segments of 25.6 s): "
            "it scatters; give filter_corner_hz (--ff-corner-hz) for short runs",
            t.size * sample_dt)
    omega = linearize.trim(turbine, mean_wind_mps).rotor_speed_rad_s
    m = lidar_model.measure(field if seen is None else seen, t, omega * t, omega)
    est = m.u_hat.mean(axis=1)
    truth = np.interp(t + tp, field.t, lidar.rotor_effective_wind(
        field, turbine.geometry.tip_radius))
    f, g2 = lidar.coherence(est - est.mean(), truth - truth.mean(), 1.0 / sample_dt)
    return 2.0 * math.pi * lidar.coherence_bandwidth(f, g2)


def _fitting_corner(preview_time_s: float, actuator_tau_s: float, filter_order: int,
                    sample_dt: float) -> float:
    """The lowest corner whose filter delay fits the preview less the actuator constant and one
    LIDAR sample [rad/s] (inf when nothing fits)."""
    room = preview_time_s - actuator_tau_s - sample_dt
    return FILTER_DELAY[filter_order] / room if room > 0 else math.inf


def corner_within_preview(corner_rad_s: float, preview_time_s: float, actuator_tau_s: float,
                          filter_order: int = 2, sample_dt: float = 0.1) -> tuple[float, bool]:
    """The coherence corner, raised where needed so that the lead (actuator time constant + the
    filter's delay) fits in the preview time less one LIDAR sample.

    With wind evolution the coherence bandwidth can fall so low that the filter's delay alone
    exceeds the preview (54 m at 18 m/s: 3 s, which a second-order filter spends at
    omega_c = 0.48 rad/s). Then the feedforward would act late on everything it passes; the
    smallest corner that keeps it on time, omega = k / (T_p - tau - dt_s), passes a little
    more of the incoherent band instead (Schlipf 2015, sec. 5.2: the filter delay must be
    covered by the preview). The raise is logged.

    Parameters
    ----------
    corner_rad_s : float
        The coherence corner [rad/s].
    preview_time_s : float
        T_p [s].
    actuator_tau_s : float
        Pitch actuator time constant [s].
    filter_order : {1, 2}
    sample_dt : float
        LIDAR sample period [s].

    Returns
    -------
    corner : float
        [rad/s]
    raised : bool

    Raises
    ------
    ValueError
        If the preview is too short for any corner (naming the preview and what it must cover).
    """
    need = _fitting_corner(preview_time_s, actuator_tau_s, filter_order, sample_dt)
    if not math.isfinite(need):
        raise ValueError(f"preview time {preview_time_s:.3g} s does not cover the actuator time "
                         f"constant {actuator_tau_s:.3g} s and one LIDAR sample "
                         f"{sample_dt:.3g} s: focus further upstream")
    if corner_rad_s >= need:
        return corner_rad_s, False
    logging.getLogger(__name__).warning(
        "feedforward corner raised from %.3f to %.3f rad/s so that the filter's delay fits the "
        "%.2f s preview (the LIDAR-rotor coherence falls to 0.5 below that)", corner_rad_s, need,
        preview_time_s)
    return need, True

"""Evaluate a CW LIDAR's per-blade preview on a wind field for a turbine (``mpcwt lidar``)."""
from __future__ import annotations

import math
from typing import Any

import numpy as np

import lidar
import linearize

__all__ = ["lidar_evaluation"]


def lidar_evaluation(field: lidar.WindField, turbine: linearize.Turbine, *,
                   focus_distance: float | None = None, sample_rate: float = 10.0, horizon: int = 15,
                   dt_ctrl: float = 0.1, evolution: bool = False, evolution_seed: int = 0,
                   **lidar_options: Any) -> tuple[dict[str, Any], dict[str, Any]]:
    """Run the LIDAR over the field with the rotor at its trimmed speed and judge the preview.

    The rotor turns at the trimmed speed of the field's mean wind (constant); measurements run
    from the field's start to its end less the preview time. Returns the coherence bandwidth
    (gamma^2 = 0.5, mean of the blades) and wavenumber, the RMS preview error over the horizon
    against the wind each blade meets at 75 % span, the preview time and the lead angle.


    Parameters
    ----------
    field : lidar.WindField
        The wind field.
    turbine : Turbine
        The turbine (rotor radius, trimmed speed).
    focus_distance : float, optional
        Axial focus distance [m] (default :class:`lidar.CWLidar`'s for the rotor: 54 m on the
        NREL 5-MW).
    sample_rate : float
        LIDAR samples per second [Hz].
    horizon : int
        Preview steps H_p.
    dt_ctrl : float
        Controller step [s].
    evolution : bool
        Measure the field evolved over the focus distance (:func:`lidar.evolve_field`, Simley
        and Pao's coherence) instead of frozen turbulence (Madsen's assumption, the default).
    evolution_seed : int
        Seed of the evolution's independent field.
    **lidar_options
        Further :class:`lidar.CWLidar` settings (``range_weighting``, ``noise_std`` ...).

    Returns
    -------
    summary : dict
        ``coherence_bandwidth_hz``, wavenumber, RMS preview error, preview time and lead angle.
    curves : dict
        What the plots show: ``frequency_hz`` and ``coherence`` (n_f, 3) per blade, the beam's
        and the blades' azimuth over one revolution [rad], ``lidar_radius`` [m].

    Raises
    ------
    ValueError
        If the field is too short or too narrow for the LIDAR (the message says which).
    """
    op = linearize.trim(turbine, float(np.clip(field.mean_speed, turbine.operation.cut_in_wind,
                                               turbine.operation.cut_out_wind)))
    omega = op.rotor_speed_rad_s
    lid = lidar.CWLidar(turbine.geometry.tip_radius, focus_distance=focus_distance,
                        sample_rate=sample_rate, **lidar_options)
    tp = lid.preview_time(field.mean_speed)
    t_end = field.t[-1] - tp - horizon * dt_ctrl - 1.0
    if t_end <= field.t[0] + 10.0:
        raise ValueError(f"the field ({field.duration:g} s) is too short for a preview of "
                         f"{tp:.2f} s plus a {horizon * dt_ctrl:g} s horizon")
    t = np.arange(field.t[0], t_end, 1.0 / sample_rate)
    psi = omega * t
    seen = lidar.evolve_field(field, lid.focus_distance, seed=evolution_seed) if evolution else field
    meas = lid.measure(seen, t, psi, omega)
    later = lidar.blade_effective_wind(field, t + tp, psi + omega * tp, lid.radius)
    fs = sample_rate
    f = lidar.coherence(meas.u_hat[:, 0], later[:, 0], fs, nperseg=256)[0]
    gamma2 = np.column_stack([lidar.coherence(meas.u_hat[:, i], later[:, i], fs,
                                              nperseg=256)[1] for i in range(3)])
    bw = lidar.coherence_bandwidth(f, gamma2.mean(axis=1))
    res = {"focus_m": lid.focus_distance, "preview_time_s": tp,
           "lead_angle_deg": math.degrees(omega * tp) % 360.0,
           "rotor_speed_rpm": omega * 30 / math.pi, "coherence_bandwidth_Hz": bw,
           "coherence_bandwidth_rad_per_m": 2 * math.pi * bw / field.mean_speed,
           "rms_preview_error_mps": _rms_preview_error(meas, field, lid, omega, horizon,
                                                       dt_ctrl, sample_rate),
           "half_width_m": lid.half_width, "cone_angle_deg": math.degrees(lid.cone_angle_rad),
           "mean_speed_mps": field.mean_speed, "evolution": bool(evolution)}
    n_rev = int(round(2 * math.pi / omega * sample_rate))
    curves = {"frequency_hz": f, "coherence": gamma2, "beam_azimuth_rad": meas.beam_azimuth_rad[:n_rev],
              "blade_azimuth_rad": psi[:n_rev], "lidar_radius": lid.radius}
    return res, curves


def _rms_preview_error(meas: Any, field: lidar.WindField, lid: Any, omega: float, horizon: int,
                       dt_ctrl: float, sample_rate: float) -> float:
    """RMS error of the preview over the horizon against the wind each blade meets."""
    t, tp = meas.t, meas.preview_time
    k_ctrl = t[(t >= t[0] + tp) & (t <= t[-1] - horizon * dt_ctrl)][::max(1, int(round(
        dt_ctrl * sample_rate)))]
    prev = lidar.preview_series(meas, k_ctrl, horizon, dt_ctrl)
    steps = k_ctrl[:, None] + dt_ctrl * np.arange(1, horizon + 1)[None, :]
    truth = np.stack([lidar.blade_effective_wind(field, steps[:, j], omega * steps[:, j],
                                                 lid.radius) for j in range(horizon)], axis=1)
    return lidar.rms_preview_error(prev, truth)

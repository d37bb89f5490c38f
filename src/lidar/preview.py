"""Per-blade wind preview from LIDAR measurements, the true blade and rotor winds, and the
metrics that judge a preview (coherence bandwidth, preview error, preview lag).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import signal

from lidar._typing import FloatArray
from lidar.cw import LidarMeasurement
from lidar.field import WindField

__all__ = ["Preview", "PreviewBuffer", "preview", "preview_series", "blade_effective_wind",
           "rotor_effective_wind", "coherence", "coherence_bandwidth", "rms_preview_error",
           "peak_lag"]


@dataclass(frozen=True)
class Preview:
    """Wind each blade will meet over the next controller steps.

    Parameters
    ----------
    t : (n_h,) ndarray
        Times of the steps [s] (t_k + j dt, j = 1..n_h).
    blade : (n_h, 3) ndarray
        Per-blade wind at 75 % span [m/s].
    rotor : (n_h,) ndarray
        Rotor-effective estimate (mean of the three beams) [m/s].
    measured : (n_h,) ndarray of bool
        False where the step lies beyond the preview time and the last measurement is held.
    """

    t: FloatArray
    blade: FloatArray
    rotor: FloatArray
    measured: np.ndarray


def preview(meas: LidarMeasurement, t_now: float, horizon: int = 15,
            dt: float = 0.1) -> Preview:
    """The preview at controller time ``t_now``: measurement taken at t - T_p for each step t.

    Parameters
    ----------
    meas : LidarMeasurement
        The LIDAR's measurements.
    t_now : float
        Controller time [s].
    horizon : int
        Preview steps H_p.
    dt : float
        Controller step [s].

    Returns
    -------
    Preview
        The per-blade wind over the next ``horizon`` steps.

    Raises
    ------
    ValueError
        If ``horizon`` < 1, ``dt`` <= 0, or ``t_now`` lies outside the measured times.
    """
    if not isinstance(horizon, (int, np.integer)) or horizon < 1:
        raise ValueError(f"horizon must be an integer >= 1, got {horizon!r}")
    if not (math.isfinite(dt) and dt > 0):
        raise ValueError(f"dt must be > 0 s, got {dt!r}")
    if not meas.t[0] <= t_now <= meas.t[-1] + 1e-9:
        raise ValueError(f"t_now = {t_now:g} s is outside the measurements "
                         f"{meas.t[0]:g}..{meas.t[-1]:g} s")
    steps = t_now + dt * np.arange(1, horizon + 1)
    tm = steps - meas.preview_time
    measured = tm <= t_now + 1e-9
    tm = np.clip(np.minimum(tm, t_now), meas.t[0], meas.t[-1])
    blade = np.column_stack([np.interp(tm, meas.t, meas.u_hat[:, i]) for i in range(3)])
    return Preview(t=steps, blade=blade, rotor=blade.mean(axis=1), measured=measured)


class PreviewBuffer:
    """The last measurements of a LIDAR in the loop, in a fixed-size ring buffer, and the
    per-blade preview from them (the same preview as :func:`preview` on the whole history).

    A preview at t needs the measurements back to t - T_p + dt only (the step t + dt was
    measured at t + dt - T_p), so the buffer keeps ceil(T_p / dt) + 3 samples at the
    controller step and a step costs the same at the end of a long run as at its start. Each
    sample is written twice (at i and i + capacity), so the newest ``capacity`` samples are
    always one contiguous, ordered view.

    Parameters
    ----------
    preview_time : float
        T_p of the instrument [s] (``LidarMeasurement.preview_time``), > 0: the default of
        :meth:`preview`.
    dt : float
        Interval between pushes (the controller step) [s], > 0.
    max_preview_time : float, optional
        The longest T_p a :meth:`preview` will ask for [s] (a preview time that follows the
        measured mean wind); the buffer keeps enough samples for it (default ``preview_time``).
    """

    def __init__(self, preview_time: float, dt: float,
                 max_preview_time: float | None = None) -> None:
        if not (math.isfinite(preview_time) and preview_time > 0):
            raise ValueError(f"preview_time must be > 0 s, got {preview_time!r}")
        if not (math.isfinite(dt) and dt > 0):
            raise ValueError(f"dt must be > 0 s, got {dt!r}")
        longest = preview_time if max_preview_time is None else max_preview_time
        if not (math.isfinite(longest) and longest >= preview_time):
            raise ValueError(f"max_preview_time must be >= preview_time = {preview_time:g} s, "
                             f"got {max_preview_time!r}")
        self.preview_time, self.dt = float(preview_time), float(dt)
        self.capacity = int(math.ceil(longest / self.dt)) + 3
        self._t = np.empty(2 * self.capacity)
        self._u = np.empty((3, 2 * self.capacity))
        self._n = 0                           # samples pushed so far
        self._last = -math.inf

    def __len__(self) -> int:
        return min(self._n, self.capacity)

    def push(self, t: float, u_hat: FloatArray) -> None:
        """Add the measurement of the three beams at ``t`` (later than the last one).

        Parameters
        ----------
        t : float
            Measurement time [s].
        u_hat : (3,) array
            Reconstructed longitudinal wind of each beam [m/s].
        """
        if not t > self._last:
            raise ValueError(f"t = {t!r} s must be later than the last measurement "
                             f"{self._last:g} s")
        i = self._n % self.capacity
        self._t[i] = self._t[i + self.capacity] = t
        self._u[:, i] = self._u[:, i + self.capacity] = u_hat
        self._n += 1
        self._last = t

    def history(self) -> tuple[FloatArray, FloatArray]:
        """The kept samples, oldest first: times (n,) [s] and winds (3, n) [m/s] (views).

        Returns
        -------
        t : (n,) ndarray
            Times [s].
        u : (3, n) ndarray
            Each beam's wind estimate [m/s].
        """
        n = len(self)
        lo = self._n % self.capacity if self._n >= self.capacity else 0
        return self._t[lo:lo + n], self._u[:, lo:lo + n]

    def preview(self, t_now: float, horizon: int = 15,
                preview_time: float | None = None) -> Preview:
        """The preview of the next ``horizon`` steps at ``t_now`` (eq. of :func:`preview`).

        Parameters
        ----------
        t_now : float
            Controller time, within the kept measurements [s].
        horizon : int
            Steps H_p (>= 1).
        preview_time : float, optional
            T_p for this preview [s], at most the buffer's ``max_preview_time`` (default the
            buffer's ``preview_time``).

        Returns
        -------
        Preview
        """
        tk, uk = self.history()
        if tk.size == 0 or not tk[0] <= t_now <= tk[-1] + 1e-9:
            span = f"{tk[0]:g}..{tk[-1]:g} s" if tk.size else "none yet"
            raise ValueError(f"t_now = {t_now!r} s is outside the kept measurements ({span})")
        if not isinstance(horizon, (int, np.integer)) or horizon < 1:
            raise ValueError(f"horizon must be an integer >= 1, got {horizon!r}")
        tp = self.preview_time if preview_time is None else float(preview_time)
        if not (math.isfinite(tp) and 0 < tp <= (self.capacity - 3) * self.dt + 1e-9):
            raise ValueError(f"preview_time must be in (0, {(self.capacity - 3) * self.dt:g}] s "
                             f"(the buffer's longest), got {preview_time!r}")
        steps = t_now + self.dt * np.arange(1, horizon + 1)
        tm = steps - tp
        measured = tm <= t_now + 1e-9
        tm = np.clip(np.minimum(tm, t_now), tk[0], tk[-1])
        blade = np.column_stack([np.interp(tm, tk, uk[i]) for i in range(3)])
        return Preview(t=steps, blade=blade, rotor=blade.mean(axis=1), measured=measured)


def preview_series(meas: LidarMeasurement, t_ctrl: FloatArray, horizon: int = 15,
                   dt: float = 0.1) -> FloatArray:
    """Previews for a sequence of controller times, (n_k, horizon, 3) [m/s] (vectorized).

    Parameters
    ----------
    meas : LidarMeasurement
        The LIDAR's measurements.
    t_ctrl : (n_k,) ndarray
        Controller times [s].
    horizon : int
        Preview steps H_p.
    dt : float
        Controller step [s].

    Returns
    -------
    (n_k, horizon, 3) ndarray
        The previews [m/s].
    """
    t_ctrl = np.asarray(t_ctrl, float)
    steps = t_ctrl[:, None] + dt * np.arange(1, horizon + 1)[None, :]
    tm = np.clip(np.minimum(steps - meas.preview_time, t_ctrl[:, None]), meas.t[0], meas.t[-1])
    return np.stack([np.interp(tm, meas.t, meas.u_hat[:, i]) for i in range(3)], axis=-1)


def blade_effective_wind(field: WindField, t: FloatArray, blade_azimuth_rad: FloatArray,
                         radius: float) -> FloatArray:
    """Longitudinal wind at each blade's point at ``radius`` (75 % span), (n_t, 3) [m/s].

    Parameters
    ----------
    field : WindField
        The wind field.
    t : (n_t,) ndarray
        Times [s].
    blade_azimuth_rad : (n_t,) ndarray
        Azimuth of blade 1 [rad].
    radius : float
        Radius of the point on each blade [m].

    Returns
    -------
    (n_t, 3) ndarray
        Longitudinal wind at each blade's point [m/s].
    """
    t = np.asarray(t, float)
    ang = np.asarray(blade_azimuth_rad, float)[:, None] + 2 * math.pi * np.arange(3) / 3
    y = -radius * np.sin(ang)
    z = field.hub_height + radius * np.cos(ang)
    return field.sample(np.broadcast_to(t[:, None], y.shape), y, z, "u")


def rotor_effective_wind(field: WindField, rotor_radius: float, method: str = "mean"
                         ) -> FloatArray:
    """Rotor-effective wind speed over the field's times, (n_t,) [m/s].

    ``"mean"``: the disc average of u (grid points inside the rotor disc); ``"cube"``: the
    cube root of the disc average of u^3 (the power-equivalent speed of IEC 61400-12-1).

    Parameters
    ----------
    field : WindField
        The wind field.
    rotor_radius : float
        Rotor radius [m].
    method : {"mean", "cube"}
        Disc average of u, or the cube root of the disc average of u^3.

    Returns
    -------
    (n_t,) ndarray
        Rotor-effective wind speed [m/s].
    """
    yy, zz = np.meshgrid(field.y, field.z - field.hub_height, indexing="ij")
    inside = yy**2 + zz**2 <= rotor_radius**2
    if not inside.any():
        raise ValueError(f"no field point lies within rotor_radius = {rotor_radius:g} m")
    u = field.u[:, inside]
    if method == "mean":
        return u.mean(axis=1)
    if method == "cube":
        return np.cbrt((u**3).mean(axis=1))
    raise ValueError(f"method must be 'mean' or 'cube', got {method!r}")


def coherence(estimate: FloatArray, truth: FloatArray, fs: float,
              nperseg: int = 256) -> tuple[FloatArray, FloatArray]:
    """Magnitude-squared coherence (Welch) between an estimate and the truth.

    Parameters
    ----------
    estimate, truth : (n_t,) ndarray
        The two series, sampled together.
    fs : float
        Sample rate [Hz].
    nperseg : int
        Welch segment length [samples].

    Returns
    -------
    f : (n_f,) ndarray
        [Hz]
    gamma2 : (n_f,) ndarray
        [-]
    """
    f, g = signal.coherence(estimate, truth, fs=fs, nperseg=min(nperseg, len(estimate)))
    return f, g


def coherence_bandwidth(f: FloatArray, gamma2: FloatArray, level: float = 0.5,
                        bands_per_decade: int = 12) -> float:
    """Frequency where the coherence first falls below ``level`` [Hz].

    The Welch estimate scatters from bin to bin (dips of a single bin would decide a
    first-crossing on the raw curve), so the coherence is first averaged in logarithmic bands
    (``bands_per_decade``; 0 uses the raw bins). Returns the interpolated crossing, or the
    highest frequency if the coherence never falls below the level.

    Parameters
    ----------
    f : (n_f,) ndarray
        Frequencies [Hz].
    gamma2 : (n_f,) ndarray
        Magnitude-squared coherence [-].
    level : float
        The coherence that marks the bandwidth [-].
    bands_per_decade : int
        Logarithmic bands the coherence is averaged in (0: raw bins).

    Returns
    -------
    float
        The bandwidth [Hz].
    """
    f = np.asarray(f, float)
    g = np.asarray(gamma2, float)
    keep = f > 0
    f, g = f[keep], g[keep]
    if bands_per_decade > 0 and f.size > 2:
        edges = 10 ** np.arange(np.log10(f[0]), np.log10(f[-1]) + 1e-9, 1.0 / bands_per_decade)
        edges = np.append(edges, f[-1] * 1.0001)
        fc, gc = [], []
        for a, b in zip(edges[:-1], edges[1:]):
            m = (f >= a) & (f < b)
            if m.any():
                fc.append(f[m].mean())
                gc.append(g[m].mean())
        f, g = np.array(fc), np.array(gc)
    idx = np.flatnonzero(g < level)
    if idx.size == 0:
        return float(f[-1])
    k = int(idx[0])
    if k == 0:
        return float(f[0])
    f0, f1, g0, g1 = f[k - 1], f[k], g[k - 1], g[k]
    return float(f0 + (g0 - level) * (f1 - f0) / (g0 - g1))


def rms_preview_error(previews: FloatArray, truth: FloatArray) -> float:
    """RMS of preview minus truth over all steps and blades [m/s].

    Parameters
    ----------
    previews : (n_k, n_h, 3) ndarray
        Previews [m/s].
    truth : (n_k, n_h, 3) ndarray
        The wind each blade meets at the same steps [m/s].

    Returns
    -------
    float
        The RMS error [m/s].
    """
    d = np.asarray(previews, float) - np.asarray(truth, float)
    return float(np.sqrt(np.mean(d**2)))


def peak_lag(estimate: FloatArray, later: FloatArray, dt: float, max_lag: float) -> float:
    """Lag [s] that maximizes the cross-correlation of ``later`` against ``estimate``
    (positive: ``later`` follows ``estimate``), refined by a parabola through the peak.

    Parameters
    ----------
    estimate, later : (n_t,) ndarray
        The two series, sampled together.
    dt : float
        Sample time [s].
    max_lag : float
        Largest lag searched [s].

    Returns
    -------
    float
        The lag [s].
    """
    a = np.asarray(estimate, float) - np.mean(estimate)
    b = np.asarray(later, float) - np.mean(later)
    n = len(a)
    m = int(round(max_lag / dt))
    lags = np.arange(-m, m + 1)
    cc = np.array([np.dot(a[max(0, -k):n - max(0, k)], b[max(0, k):n - max(0, -k)])
                   / (n - abs(k)) for k in lags])
    i = int(np.argmax(cc))
    shift = 0.0
    if 0 < i < len(cc) - 1:
        den = cc[i - 1] - 2 * cc[i] + cc[i + 1]
        shift = 0.5 * (cc[i - 1] - cc[i + 1]) / den if den != 0 else 0.0
    return float((lags[i] + shift) * dt)

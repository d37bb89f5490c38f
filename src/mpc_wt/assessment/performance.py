"""Performance measures: covariance ellipses CS1-CS5, spectra, pitch duty, energy, tracking.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import signal

from linearize.validate import check_number
from mpc_wt._typing import FloatArray
from mpc_wt.assessment.fatigue import check_series

__all__ = ["CSMeasures", "cs_measures", "psd", "harmonic_psd", "pitch_duty", "energy_Wh", "aep_Wh",
           "tracking_response", "pct_change"]


@dataclass(frozen=True)
class CSMeasures:
    """Covariance-ellipse measures of Do et al. (2020), eqs 21-26.

    Parameters
    ----------
    cs1, cs2 : float
        Standard deviations along the ellipse axes nearest the load and the power axis
        [load unit], [W].
    cs3, cs4 : float
        Means of load and power.
    cs5 : float
        min(alpha, 90 - alpha) [deg].
    alpha_deg : float
        Angle of the major axis to the load axis [deg].
    covariance : (2, 2) ndarray
        Covariance of (load, power).
    s : float
        Chi-square scale of the ellipse (5.99: 95 %).
    """

    cs1: float
    cs2: float
    cs3: float
    cs4: float
    cs5: float
    alpha_deg: float
    covariance: FloatArray
    s: float = 5.99

    def ellipse(self, n: int = 200) -> tuple[FloatArray, FloatArray]:
        """Points of the s-scaled ellipse.

        Parameters
        ----------
        n : int
            Number of points.

        Returns
        -------
        load, power : (n,) ndarray
            The ellipse's points.
        """
        lam, vec = np.linalg.eigh(self.covariance)
        th = np.linspace(0, 2 * np.pi, n)
        pts = vec @ (np.sqrt(self.s * np.maximum(lam, 0))[:, None]
                     * np.vstack([np.cos(th), np.sin(th)]))
        return self.cs3 + pts[0], self.cs4 + pts[1]


def cs_measures(load: Any, power: Any, s: float = 5.99) -> CSMeasures:
    """CS1-CS5 from load and power samples (Do et al. eqs 21-26).

    Parameters
    ----------
    load : (n_t,) array_like
        Load samples (Do: tower-base fore-aft moment) [N m].
    power : (n_t,) array_like
        Power samples [W].
    s : float
        Chi-square scale of the ellipse (5.99: 95 %).

    Returns
    -------
    CSMeasures
        The five measures, the ellipse's angle and the covariance.
    """
    x = check_series("load", load)
    y = check_series("power", power)
    if x.shape != y.shape or x.size < 3:
        raise ValueError(f"load and power must have equal length >= 3, got {x.size}, {y.size}")
    c = np.cov(np.vstack([x, y]))                 # eqs 22-23 (1 / (N - 1))
    lam, vec = np.linalg.eigh(c)
    i_load = int(np.argmax(np.abs(vec[0])))       # eigenvector nearest the load (x) axis
    i_pow = 1 - i_load
    vmax = vec[:, int(np.argmax(lam))]
    alpha = math.degrees(math.atan(abs(vmax[1]) / abs(vmax[0]))) if vmax[0] != 0 else 90.0
    return CSMeasures(cs1=float(np.sqrt(lam[i_load])), cs2=float(np.sqrt(lam[i_pow])),
                      cs3=float(x.mean()), cs4=float(y.mean()), cs5=min(alpha, 90.0 - alpha),
                      alpha_deg=alpha, covariance=c, s=s)


def psd(x: Any, fs: float, nperseg: int = 4096) -> tuple[FloatArray, FloatArray]:
    """One-sided power spectral density (Welch, Hann, 50 % overlap) of the detrended series.

    Parameters
    ----------
    x : (n_t,) array_like
        The series.
    fs : float
        Sample rate [Hz].
    nperseg : int
        Segment length (at most the series').

    Returns
    -------
    f : ndarray
        Frequencies [Hz].
    p : ndarray
        PSD [unit^2/Hz].
    """
    arr = check_series("x", x)
    return signal.welch(arr - arr.mean(), fs=fs, nperseg=min(nperseg, arr.size))


def harmonic_psd(x: Any, fs: float, rotor_hz: float, harmonics: tuple[int, ...] = (1, 3, 6),
                 nperseg: int = 4096, half_width: float = 0.1) -> dict[int, float]:
    """Spectral amplitude at n P: the PSD integrated over n f_rotor (1 +- half_width)
    [unit^2], i.e. the variance the nP peak carries (Madsen et al. 2012, sec. IV).

    Parameters
    ----------
    x : (n_t,) array_like
        The series.
    fs : float
        Sample rate [Hz].
    rotor_hz : float
        Rotor frequency 1P [Hz].
    harmonics : tuple of int
        The multiples n of 1P.
    nperseg : int
        Welch segment length.
    half_width : float
        Relative half width of each band [-].

    Returns
    -------
    dict of int to float
        n -> variance in the band [unit^2].
    """
    f, p = psd(x, fs, nperseg)
    out = {}
    df = f[1] - f[0]
    for n in harmonics:
        lo, hi = n * rotor_hz * (1 - half_width), n * rotor_hz * (1 + half_width)
        m = (f >= lo) & (f <= hi)
        out[n] = float(p[m].sum() * df)
    return out


def pitch_duty(pitch_rad: Any, dt: float) -> dict[str, float]:
    """Pitch activity (Pettas and Cheng sec. 4).

    Parameters
    ----------
    pitch_rad : (n_t,) or (n_t, n_blade) array_like
        Pitch angles [rad].
    dt : float
        Sample period [s].

    Returns
    -------
    dict
        ``pitch_travel_deg`` (total travel summed over blades), ``pitch_rate_std_degps`` and
        ``pitch_acc_std_degps2`` (std of rate and acceleration, mean over blades).
    """
    p = np.asarray(pitch_rad, float)
    if p.ndim == 1:
        p = p[:, None]
    rate = np.diff(p, axis=0) / dt
    acc = np.diff(rate, axis=0) / dt
    return {"pitch_travel_deg": float(np.degrees(np.abs(np.diff(p, axis=0)).sum())),
            "pitch_rate_std_degps": float(np.degrees(rate.std(axis=0)).mean()),
            "pitch_acc_std_degps2": float(np.degrees(acc.std(axis=0)).mean())}


def energy_Wh(power_W: Any, dt: float) -> float:
    """Energy of a power series (trapezoid).

    Parameters
    ----------
    power_W : (n_t,) array_like
        Power [W].
    dt : float
        Sample period [s].

    Returns
    -------
    float
        Energy [Wh].
    """
    p = check_series("power_W", power_W)
    return float(np.trapezoid(p, dx=dt) / 3600.0)


def aep_Wh(mean_power_W: Any, probabilities: Any, availability: float = 1.0) -> float:
    """Annual energy from the mean power per wind bin and the bins' probabilities.

    Parameters
    ----------
    mean_power_W : (n_bin,) array_like
        Mean power of each bin [W].
    probabilities : (n_bin,) array_like
        Probability of each bin [-].
    availability : float
        Fraction of the year in operation [-].

    Returns
    -------
    float
        Annual energy [Wh/yr] (8766 h a year).
    """
    p = np.asarray(mean_power_W, float)
    w = np.asarray(probabilities, float)
    if p.shape != w.shape:
        raise ValueError(f"mean_power_W {p.shape} and probabilities {w.shape} differ in shape")
    return float(availability * 8766.0 * np.sum(p * w))


def tracking_response(t: Any, reference: Any, output: Any, frequency_hz: float
                      ) -> tuple[float, float]:
    """Amplitude ratio [-] and phase [deg] (negative: lag) of ``output`` against ``reference``
    at one frequency, from least-squares fits of a sine, a cosine and an offset to each
    (power tracking, Clemens et al. fig. 3).

    Parameters
    ----------
    t : (n_t,) array_like
        Time [s].
    reference, output : (n_t,) array_like
        The two series.
    frequency_hz : float
        The frequency [Hz], > 0.

    Returns
    -------
    amplitude_ratio : float
        abs(output) / abs(reference) at the frequency [-].
    phase_deg : float
        Phase of the output against the reference [deg].

    Raises
    ------
    ValueError
        If the series differ in length, are not finite, or the frequency is not positive, or
        the reference carries no component at that frequency.
    """
    tt = check_series("t", t)
    r = check_series("reference", reference)
    y = check_series("output", output)
    if not (tt.shape == r.shape == y.shape):
        raise ValueError(f"t {tt.shape}, reference {r.shape} and output {y.shape} must match")
    f = check_number("frequency_hz", frequency_hz, lo=0.0, lo_open=True, unit="Hz")
    basis = np.c_[np.sin(2 * np.pi * f * tt), np.cos(2 * np.pi * f * tt), np.ones_like(tt)]
    cr = np.linalg.lstsq(basis, r, rcond=None)[0]
    cy = np.linalg.lstsq(basis, y, rcond=None)[0]
    zr, zy = complex(cr[0], cr[1]), complex(cy[0], cy[1])
    if abs(zr) <= 1e-12 * max(1.0, float(np.abs(r).max())):
        raise ValueError(f"reference has no component at {f:g} Hz")
    g = zy / zr
    return float(abs(g)), float(math.degrees(np.angle(g)))


def pct_change(base: float, other: float) -> float:
    """Change of ``other`` against ``base`` in percent, 100 (other / base - 1).

    Parameters
    ----------
    base, other : float
        The reference and the compared value.

    Returns
    -------
    float
        [%]; NaN when ``base`` is 0 or either value is not finite (no change can be
        stated).
    """
    if not (base and math.isfinite(base) and math.isfinite(other)):
        return float("nan")
    return 100.0 * (other / base - 1.0)

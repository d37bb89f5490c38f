"""Load and performance assessment: rainflow, damage-equivalent loads, lifetime damage and
extension, covariance-ellipse measures CS1-CS5, spectra at rotor harmonics, pitch duty, energy.

Pure functions on arrays (the run-level wrappers come with the simulation harness).

References
----------
ASTM E1049-85 (2017), Standard practices for cycle counting in fatigue analysis, sec. 5.4.4.
Do et al. (2020), Wind Energy, eqs 19-26 (Miner, DEL, CS1-CS5).
Clemens et al., DEL assessment of active power control, eqs 12-18 (lifetime DEL).
Pettas and Cheng (2018), eq 1 (lifetime extension).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Mapping, Sequence

import numba as nb
import numpy as np
from scipy import signal
from scipy import stats

from linearize.validate import check_number

__all__ = ["rainflow", "damage_equivalent_load", "DELConvention", "DEL_CONVENTIONS",
           "del_convention", "CycleCount", "cycle_count", "lifetime_del", "wind_bin_probabilities",
           "miner_damage", "lifetime_extension", "CSMeasures", "cs_measures", "psd",
           "harmonic_psd", "pitch_duty", "energy_Wh", "aep_Wh", "tracking_response",
           "pct_change", "DEFAULT_CHANNELS", "assess_series", "reductions",
           "lifetime_comparison"]

FloatArray = np.ndarray


def _check_series(name: str, x: Any) -> FloatArray:
    arr = np.asarray(x, dtype=float)
    if arr.ndim != 1:
        raise ValueError(f"{name} must be 1-D, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        i = int(np.argmax(~np.isfinite(arr)))
        raise ValueError(f"{name} must be finite; sample {i} is {float(arr[i])!r}")
    return arr


@nb.njit(cache=True)
def _reversals(x):  # pragma: no cover - compiled
    """Peaks and valleys (ASTM: reversals), endpoints included, plateaus collapsed."""
    n = x.size
    out = np.empty(n)
    k = 0
    if n == 0:
        return out[:0]
    out[0] = x[0]
    k = 1
    direction = 0
    for i in range(1, n):
        d = x[i] - out[k - 1]
        if d == 0.0:
            continue
        s = 1 if d > 0 else -1
        if direction == 0 or s == direction:
            if direction == 0:
                out[k] = x[i]
                k += 1
            else:
                out[k - 1] = x[i]          # extend the current excursion
            direction = s
        else:
            out[k] = x[i]
            k += 1
            direction = s
    return out[:k]


@nb.njit(cache=True)
def _count(rev, start_half=True):  # pragma: no cover - compiled
    """ASTM E1049-85 5.4.4 three-point rainflow: (range, mean, count) rows; residue 0.5.

    With ``start_half=False`` a range containing the starting point is not counted as a half
    cycle (the four-point rule): the starting point stays in the residue, which is returned
    last, as repeated-residue counting needs.
    """
    n = rev.size
    ranges = np.empty(n)
    means = np.empty(n)
    counts = np.empty(n)
    m = 0
    stack = np.empty(n)
    top = 0
    for i in range(n):
        stack[top] = rev[i]
        top += 1
        while top >= 3:
            x = abs(stack[top - 1] - stack[top - 2])
            y = abs(stack[top - 2] - stack[top - 3])
            if x < y:
                break
            if top == 3:
                if not start_half:
                    break
                # Y contains the starting point: count Y as a half cycle, drop its first point
                ranges[m] = y
                means[m] = 0.5 * (stack[0] + stack[1])
                counts[m] = 0.5
                m += 1
                stack[0] = stack[1]
                stack[1] = stack[2]
                top = 2
            else:
                ranges[m] = y
                means[m] = 0.5 * (stack[top - 2] + stack[top - 3])
                counts[m] = 1.0
                m += 1
                stack[top - 3] = stack[top - 1]
                top -= 2
    for j in range(top - 1):
        ranges[m] = abs(stack[j + 1] - stack[j])
        means[m] = 0.5 * (stack[j + 1] + stack[j])
        counts[m] = 0.5
        m += 1
    return ranges[:m], means[:m], counts[:m], stack[:top].copy()


def rainflow(x: Any) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Rainflow cycles of a load series (ASTM E1049-85, sec. 5.4.4): the residue's reversals
    count as half cycles of weight 0.5.

    Parameters
    ----------
    x : (n_t,) array_like
        Load series (any unit).

    Returns
    -------
    ranges, means, counts : (n_c,) ndarray
        Cycle ranges (peak to valley), means [unit of x] and counts (1 or 0.5) [-].
    """
    arr = _check_series("x", x)
    r, mu, c, _ = _count(_reversals(arr), True)
    return r, mu, c


@dataclass(frozen=True)
class DELConvention:
    """How a damage-equivalent load is stated.

    Parameters
    ----------
    name : str
        Its name in :data:`DEL_CONVENTIONS`.
    amplitude : bool
        Cycles as amplitudes S_a = range / 2 (Clemens et al.) instead of ranges.
    counted : bool
        N_eq = the counted cycle number sum n_i (Clemens eq 17) instead of f_eq x duration.
    counting : {"astm", "pcrunch"}
        ASTM E1049 with half cycles (our kernel), or pCrunch's quantised fatpack counting.
    """

    name: str
    amplitude: bool
    counted: bool
    counting: str


#: The DEL conventions by name: ``range-1hz`` (the IEC / MLife convention, the default and
#: what the studies use), ``clemens`` (Clemens et al. eqs 17-18: amplitudes, counted cycles)
#: and ``pcrunch`` (ranges, 1 Hz, pCrunch's counting).
DEL_CONVENTIONS: dict[str, DELConvention] = {
    c.name: c for c in (DELConvention("range-1hz", False, False, "astm"),
                        DELConvention("clemens", True, True, "astm"),
                        DELConvention("pcrunch", False, False, "pcrunch"))}


def del_convention(name: str) -> DELConvention:
    """The convention called ``name``.

    Parameters
    ----------
    name : str
        A key of :data:`DEL_CONVENTIONS`.

    Returns
    -------
    DELConvention
        The convention.

    Raises
    ------
    ValueError
        Naming the conventions.
    """
    if name not in DEL_CONVENTIONS:
        raise ValueError(f"convention must be one of {list(DEL_CONVENTIONS)}, got {name!r}")
    return DEL_CONVENTIONS[name]


@dataclass(frozen=True)
class CycleCount:
    """The rainflow cycles of one series in a convention, from which its DEL at any Woehler
    exponent follows (Clemens eq 17): DEL(m) = (sum_i n_i S_i^m / N_eq)^(1/m).

    Parameters
    ----------
    sizes : (n_c,) ndarray
        Cycle sizes S_i: ranges, or amplitudes in the ``clemens`` convention [unit of x].
    counts : (n_c,) ndarray
        Their counts n_i (1 or 0.5; histogram counts with pCrunch's counting) [-].
    n_eq : float
        The equivalent cycle number N_eq [-].
    convention : str
        The convention's name.
    """

    sizes: FloatArray
    counts: FloatArray
    n_eq: float
    convention: str

    def del_at(self, m: float) -> float:
        """The DEL at Woehler exponent ``m``.

        Parameters
        ----------
        m : float
            Woehler exponent, > 0.

        Returns
        -------
        float
            (sum n_i S_i^m / N_eq)^(1/m) [unit of x]; 0 without cycles.
        """
        check_number("m (Woehler exponent)", m, lo=0.0, lo_open=True, say_finite=False)
        if self.sizes.size == 0:
            return 0.0
        scale = float(self.sizes.max())
        if scale == 0.0:
            return 0.0
        return float(scale * (np.sum(self.counts * (self.sizes / scale) ** m) / self.n_eq)
                     ** (1.0 / m))


def cycle_count(x: Any, *, convention: str = "range-1hz", n_eq: float | None = None,
                duration: float | None = None, f_eq: float = 1.0, bins: int = 100
                ) -> CycleCount:
    """Count the rainflow cycles of a load series in a DEL convention.

    Parameters
    ----------
    x : (n_t,) array_like
        Load series.
    convention : str
        A key of :data:`DEL_CONVENTIONS`.
    n_eq : float, optional
        Equivalent cycle count (ranges conventions); else ``f_eq * duration``.
    duration : float, optional
        Record length [s] (ranges conventions, unless ``n_eq`` is given).
    f_eq : float
        Equivalent-load frequency [Hz].
    bins : int
        Range histogram bins of the ``pcrunch`` counting.

    Returns
    -------
    CycleCount
        Sizes, counts and N_eq.

    Raises
    ------
    ValueError
        A non-finite series, an unknown convention, a non-positive duration or n_eq.
    """
    conv = del_convention(convention)
    if conv.counting == "pcrunch":
        try:
            import fatpack
        except ImportError as err:
            raise ImportError("convention='pcrunch' needs fatpack: pip install "
                              "'mpc-wt[pcrunch]'") from err
        ranges = fatpack.find_rainflow_ranges(_check_series("x", x), k=256)
        c, r = fatpack.find_range_count(ranges, bins) if ranges.size else (np.zeros(0),
                                                                          np.zeros(0))
    else:
        r, _, c = rainflow(x)
    r, c = np.asarray(r, float), np.asarray(c, float)
    if conv.counted:
        neq = float(c.sum()) if c.size else 1.0
    elif n_eq is None:
        neq = f_eq * check_number("duration", duration, lo=0.0, lo_open=True, unit="s",
                                  reason="n_eq is not given", say_finite=False)
    else:
        neq = check_number("n_eq", n_eq, lo=0.0, lo_open=True, say_finite=False)
    return CycleCount(sizes=0.5 * r if conv.amplitude else r, counts=c, n_eq=neq,
                      convention=conv.name)


def damage_equivalent_load(x: Any, m: float, *, n_eq: float | None = None,
                           duration: float | None = None, f_eq: float = 1.0,
                           method: str = "astm", bins: int = 100,
                           convention: str = "range-1hz") -> float:
    """Short-term damage-equivalent load (Do et al. eq 20; Clemens eq 17).

    DEL = (sum_i n_i S_i^m / N_eq)^(1/m) with the rainflow cycles S_i, their counts n_i and,
    by ``convention`` (:data:`DEL_CONVENTIONS`): ``"range-1hz"`` (default; IEC / MLife) S_i
    ranges and N_eq = f_eq * duration; ``"clemens"`` (Clemens et al. eq 17) S_i amplitudes
    (range / 2) and N_eq the counted cycle number; ``"pcrunch"`` ranges counted as pCrunch
    does.

    Parameters
    ----------
    x : (n_t,) array_like
        Load series.
    m : float
        Woehler exponent (4 steel, 10 composite), > 0.
    n_eq : float, optional
        Equivalent cycle count; else ``f_eq * duration``.
    duration : float, optional
        Record length [s] (required unless ``n_eq`` is given or the convention counts).
    f_eq : float
        Equivalent-load frequency [Hz] (default 1).
    method : {"astm", "pcrunch"}
        ASTM counting with half-cycle residue (our kernel); or exactly what pCrunch does
        (``FatigueParams.compute_del``): fatpack's rainflow on reversals quantized to 256
        levels with the residue repeated, ranges histogrammed into ``bins`` bins at their
        centres (the same as ``convention="pcrunch"``; needs the optional fatpack, ``pip
        install 'mpc-wt[pcrunch]'``).
    bins : int
        Histogram bins of the pCrunch counting.
    convention : str
        A key of :data:`DEL_CONVENTIONS`.

    Returns
    -------
    float
        The DEL [unit of x]: a range, or an amplitude in the ``clemens`` convention; 0 for a
        constant series.

    Raises
    ------
    ValueError
        On a non-positive m, duration or n_eq, a non-finite series or an unknown method or
        convention.
    """
    check_number("m (Woehler exponent)", m, lo=0.0, lo_open=True, say_finite=False)
    if method not in ("astm", "pcrunch"):
        raise ValueError(f"method must be 'astm' or 'pcrunch', got {method!r}")
    if method == "pcrunch":
        convention = "pcrunch"
    return cycle_count(x, convention=convention, n_eq=n_eq, duration=duration, f_eq=f_eq,
                       bins=bins).del_at(m)


def wind_bin_probabilities(v: Any, kind: str = "rayleigh", *, mean: float | None = None,
                           shape: float = 2.0, scale: float | None = None) -> FloatArray:
    """Probability of each wind bin centred at ``v`` (edges midway between centres).

    Parameters
    ----------
    v : (n_bin,) array_like
        Bin centres, strictly increasing [m/s].
    kind : {"rayleigh", "weibull"}
        The distribution.
    mean : float, optional
        Rayleigh mean (IEC: 0.2 v_ref, e.g. 10 m/s for class I) [m/s].
    shape : float
        Weibull shape k [-].
    scale : float, optional
        Weibull scale A [m/s].

    Returns
    -------
    (n_bin,) ndarray
        Probability of each bin [-] (their sum is below 1 when the bins do not cover all
        winds).

    Raises
    ------
    ValueError
        For bins that do not increase, or a missing or non-positive parameter.
    """
    v = np.asarray(v, dtype=float)
    if v.ndim != 1 or v.size < 1 or np.any(np.diff(v) <= 0):
        raise ValueError("v must be a strictly increasing 1-D array of bin centres")
    if kind == "rayleigh":
        if mean is None or not mean > 0:
            raise ValueError(f"mean must be > 0 m/s for a Rayleigh distribution, got {mean!r}")
        k, a = 2.0, 2.0 * mean / math.sqrt(math.pi)
    elif kind == "weibull":
        if scale is None or not scale > 0 or not shape > 0:
            raise ValueError(f"weibull needs shape > 0 and scale > 0, got {shape!r}, {scale!r}")
        k, a = shape, scale
    else:
        raise ValueError(f"kind must be 'rayleigh' or 'weibull', got {kind!r}")
    mid = 0.5 * (v[1:] + v[:-1])
    half = (v[1] - v[0]) / 2 if v.size > 1 else 0.5
    edges = np.concatenate([[v[0] - half], mid, [v[-1] + (v[-1] - v[-2]) / 2 if v.size > 1
                                                  else v[0] + 0.5]])
    cdf = stats.weibull_min.cdf(np.maximum(edges, 0.0), k, scale=a)
    return np.diff(cdf)


def lifetime_del(dels: Any, m: float, probabilities: Any, n_eq: Any | None = None) -> float:
    """Lifetime DEL over mean-wind bins (Clemens eq 18): the m-power mean weighted by the wind
    distribution and the bins' cycle counts, never the arithmetic mean of the DELs.

    DEL_life = (sum_j p_j n_j DEL_j^m / sum_j p_j n_j)^(1/m), n_j the equivalent cycle count
    of bin j (equal by default); the lifetime factor L_F cancels.

    Parameters
    ----------
    dels : (n_bin,) array_like
        Short-term DEL of each bin, >= 0.
    m : float
        Woehler exponent [-].
    probabilities : (n_bin,) array_like
        Probability of each bin [-].
    n_eq : (n_bin,) array_like, optional
        Equivalent cycle count of each bin (default equal).

    Returns
    -------
    float
        The lifetime DEL [unit of the DELs].

    Raises
    ------
    ValueError
        For shapes that differ, negative values or a zero total weight.
    """
    d = np.asarray(dels, float)
    p = np.asarray(probabilities, float)
    n = np.ones_like(d) if n_eq is None else np.asarray(n_eq, float)
    if not (d.shape == p.shape == n.shape and d.ndim == 1):
        raise ValueError(f"dels, probabilities and n_eq must be 1-D of equal length, got "
                         f"{d.shape}, {p.shape}, {n.shape}")
    if np.any(p < 0) or p.sum() <= 0 or np.any(d < 0) or np.any(n <= 0):
        raise ValueError("probabilities must be >= 0 with a positive sum, dels >= 0, n_eq > 0")
    w = p * n
    return float((np.sum(w * d**m) / np.sum(w)) ** (1.0 / m))


def miner_damage(ranges: Any, counts: Any, m: float, s_ref: float, n_ref: float) -> float:
    """Palmgren-Miner damage sum n_i / N_i with N(S) = n_ref (s_ref / S)^m (Clemens eqs 13-16).

    Parameters
    ----------
    ranges : (n_c,) array_like
        Cycle ranges S_i.
    counts : (n_c,) array_like
        Their counts n_i.
    m : float
        Woehler exponent [-].
    s_ref, n_ref : float
        A point of the S-N curve: N(s_ref) = n_ref.

    Returns
    -------
    float
        The damage D [-] (failure at 1).
    """
    r = np.asarray(ranges, float)
    c = np.asarray(counts, float)
    if not (s_ref > 0 and n_ref > 0 and m > 0):
        raise ValueError("s_ref, n_ref and m must be > 0")
    return float(np.sum(c * (r / s_ref) ** m) / n_ref)


def lifetime_extension(del_base: float, del_upd: float, m: float, *, t_base: float = 15.0,
                       t_upd: float = 5.0, t_lifetime: float = 20.0) -> dict[str, float]:
    """Combined damage and lifetime extension of a controller retrofit (Pettas and Cheng eq 1).

    D_comb = T_base / T_life + T_upd / T_life (DEL_upd / DEL_base)^m, with the baseline damage
    over the design life taken as 1. The reserve 1 - D_comb, used at the updated controller's
    damage rate (DEL_upd / DEL_base)^m / T_life per year, gives the extension in years.

    Parameters
    ----------
    del_base, del_upd : float
        Lifetime DELs of the baseline and the updated controller (same unit).
    m : float
        Woehler exponent [-].
    t_base, t_upd, t_lifetime : float
        Years run with the baseline, with the update, and the design life [years].

    Returns
    -------
    dict
        ``damage`` (D_comb) [-] and ``extension_years`` [years] (negative: lifetime lost).
    """
    for name, val in (("del_base", del_base), ("m", m), ("t_lifetime", t_lifetime)):
        if not val > 0:
            raise ValueError(f"{name} must be > 0, got {val!r}")
    ratio = (del_upd / del_base) ** m
    d_comb = t_base / t_lifetime + t_upd / t_lifetime * ratio
    rate = ratio / t_lifetime
    ext = (1.0 - d_comb) / rate if rate > 0 else math.inf
    return {"damage": d_comb, "extension_years": ext, "damage_rate_ratio": ratio}


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
    x = _check_series("load", load)
    y = _check_series("power", power)
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
    arr = _check_series("x", x)
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
    p = _check_series("power_W", power_W)
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
        |output| / |reference| at the frequency [-].
    phase_deg : float
        Phase of the output against the reference [deg].

    Raises
    ------
    ValueError
        If the series differ in length, are not finite, or the frequency is not positive, or
        the reference carries no component at that frequency.
    """
    tt = _check_series("t", t)
    r = _check_series("reference", reference)
    y = _check_series("output", output)
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


#: Woehler exponents at which every assessed channel's DEL is kept (besides its own), so that
#: lifetime DELs at another exponent come from the channel's cycles (Pettas and Cheng's
#: lifetime extension at m = 4 and 10 of every channel).
WOEHLER_EXPONENTS = (3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0)

#: Load channels and their default Woehler exponents (10 composite blades, 4 steel elsewhere).
DEFAULT_CHANNELS = {"flap_moment_1": 10.0, "flap_moment_2": 10.0, "flap_moment_3": 10.0,
                    "edge_moment_1": 10.0, "edge_moment_2": 10.0, "edge_moment_3": 10.0,
                    "tower_base_fa_moment": 4.0, "tower_base_ss_moment": 4.0,
                    "lss_torque": 4.0, "tilt_moment": 4.0, "yaw_moment": 4.0,
                    "shaft_bending_blade1": 4.0}



def assess_series(t: np.ndarray, cols: dict[str, np.ndarray],
                  channels: dict[str, float] | None = None,
                  m_override: float | None = None,
                  convention: str = "range-1hz") -> dict[str, Any]:
    """DEL per channel, CS1-CS5 (tower-base fore-aft moment vs power), pitch duty, power std,
    energy and the 1P/3P/6P content of the blade-1 flap moment, for one run.

    Parameters
    ----------
    t : (n_t,) ndarray
        Time [s].
    cols : dict of str to (n_t,) ndarray
        Channels by our names (SI).
    channels : dict of str to float, optional
        Channel -> Woehler exponent (default: the :data:`DEFAULT_CHANNELS` present).
    m_override : float, optional
        One Woehler exponent for every channel.
    convention : str
        The DEL convention (:data:`DEL_CONVENTIONS`; default ``range-1hz``).

    Returns
    -------
    dict
        ``duration_s``, ``del_convention``, ``channels`` {name: {del, m, n_eq, del_at_m}}
        (``del_at_m``: the DEL at each exponent of :data:`WOEHLER_EXPONENTS` and the channel's,
        keyed ``f"{m:g}"``, from the channel's own cycles), and when the signals are there
        ``power_mean_W``, ``power_std_W``, ``energy_Wh``, ``cs1``..``cs5``, the pitch duty,
        ``gen_speed_std_rad_s``, ``gen_torque_std_Nm``, ``flap_1_harmonics``.

    Raises
    ------
    KeyError
        Naming a channel that is not among the columns.
    """
    chans = dict(channels or {k: v for k, v in DEFAULT_CHANNELS.items() if k in cols})
    missing = [c for c in chans if c not in cols]
    if missing:
        raise KeyError(f"no channel {missing[0]!r}; channels are {sorted(cols)}")
    dt = float(np.median(np.diff(t)))
    duration = float(t[-1] - t[0])
    out: dict[str, Any] = {"duration_s": duration, "del_convention": convention,
                           "channels": {}}
    for name, m in chans.items():
        mm = m_override if m_override is not None else m
        cc = cycle_count(cols[name], convention=convention, duration=duration)
        out["channels"][name] = {"del": cc.del_at(mm), "m": mm, "n_eq": cc.n_eq,
                                 "del_at_m": {f"{w:g}": cc.del_at(w)
                                              for w in sorted({*WOEHLER_EXPONENTS, mm})}}
    if "gen_power" in cols:
        p = cols["gen_power"]
        out["power_mean_W"] = float(p.mean())
        out["power_std_W"] = float(p.std())
        out["energy_Wh"] = energy_Wh(p, dt)
        if "tower_base_fa_moment" in cols:
            cs = cs_measures(cols["tower_base_fa_moment"], p)
            out.update({f"cs{i}": getattr(cs, f"cs{i}") for i in range(1, 6)})
    pitch = [cols[f"pitch_{i}"] for i in (1, 2, 3) if f"pitch_{i}" in cols]
    if pitch:
        out.update(pitch_duty(np.column_stack(pitch), dt))
    if "gen_speed" in cols:
        out["gen_speed_std_rad_s"] = float(cols["gen_speed"].std())
    if "gen_torque" in cols:
        out["gen_torque_std_Nm"] = float(cols["gen_torque"].std())
    if "rotor_speed" in cols and "flap_moment_1" in cols:
        frot = float(cols["rotor_speed"].mean()) / (2 * math.pi)
        out["flap_1_harmonics"] = {f"{n}P": v for n, v in
                                   harmonic_psd(cols["flap_moment_1"], 1 / dt, frot).items()}
    return out


def reductions(base: dict[str, Any], other: dict[str, Any]) -> dict[str, Any]:
    """Change of ``other`` against ``base`` in percent.

    Parameters
    ----------
    base, other : dict
        Two :func:`assess_series` results.

    Returns
    -------
    dict
        ``del_change_pct`` per channel, ``flap_1_harmonic_change_pct`` (1P/3P/6P content of
        the blade-1 flap moment, Madsen sec. IV), and ``{key}_change_pct`` for the power and
        generator-speed std, pitch travel, CS1 and CS2 [%].
    """
    out: dict[str, Any] = {"del_change_pct": {c: pct_change(base["channels"][c]["del"], d["del"])
                                               for c, d in other["channels"].items()
                                               if c in base["channels"]}}
    if "flap_1_harmonics" in base and "flap_1_harmonics" in other:
        out["flap_1_harmonic_change_pct"] = {k: pct_change(base["flap_1_harmonics"][k], v)
                                             for k, v in other["flap_1_harmonics"].items()}
    for k in ("power_std_W", "gen_speed_std_rad_s", "pitch_travel_deg", "cs1", "cs2"):
        if k in base and k in other:
            out[f"{k}_change_pct"] = pct_change(base[k], other[k])
    return out




_STD_KEYS = ("gen_speed_std_rad_s", "gen_torque_std_Nm", "power_std_W")
_PITCH_KEYS = ("pitch_travel_deg", "pitch_rate_std_degps", "pitch_acc_std_degps2")


def _lifetime_at(runs: Sequence[Mapping[str, Any]], channel: str, m: float,
                 p: np.ndarray) -> float:
    """Lifetime DEL of ``channel`` at exponent ``m`` over bins (Clemens eq 18), each bin's DEL
    at m from its own cycles and weighted by its equivalent cycle count."""
    dels, weights = [], []
    for r in runs:
        ch = r["channels"][channel]
        if float(ch["m"]) == m:
            dels.append(ch["del"])
        else:
            at = ch.get("del_at_m", {})
            if f"{m:g}" not in at:
                raise ValueError(f"the {channel} DELs hold exponents {sorted(at)} and the "
                                 f"channel's own m = {ch['m']:g}, not m = {m:g}: assess the runs "
                                 f"with that exponent")
            dels.append(at[f"{m:g}"])
        weights.append(ch.get("n_eq", 1.0))
    return lifetime_del(np.array(dels), m, p, np.array(weights, float))


def lifetime_comparison(probabilities: Any, base: Sequence[Mapping[str, Any]],
                        updated: Sequence[Mapping[str, Any]], *,
                        woehler: Sequence[float] = (4.0, 10.0), t_base: float = 15.0,
                        t_upd: float = 5.0, t_lifetime: float = 20.0) -> dict[str, Any]:
    """Lifetime-weighted change of a retrofit controller against the baseline.

    Parameters
    ----------
    probabilities : (n_bin,) array_like
        Probability of each mean-wind bin [-].
    base, updated : sequence of dict
        One :func:`assess_series` result per bin (seeds merged by the caller).

    Returns
    -------
    dict
        ``del_change_pct`` per channel (lifetime DEL, Clemens eq 18, at each channel's own
        Woehler exponent), ``lifetime_del`` {channel: (base, updated)}, ``aep_change_pct``
        (probability-weighted mean power), ``pitch_change_pct`` and ``std_change_pct``
        (probability-weighted means of the per-run metrics), and ``extension`` {channel: {m:
        {"damage", "extension_years"}}} from eq 1 with the lifetime DEL ratio at each m in
        ``woehler`` (the paper's 15 + 5 years by default). Each lifetime DEL at an exponent m
        aggregates the bins' DELs at m computed from their own cycles (``del_at_m``), weighted
        by probability and equivalent cycle count (eq 18).

    Raises
    ------
    ValueError
        Bins that differ in number, or an exponent not among a channel's ``del_at_m``.
    """
    p = np.asarray(probabilities, float)
    if not (len(base) == len(updated) == p.size):
        raise ValueError(f"probabilities ({p.size}), base ({len(base)}) and updated "
                         f"({len(updated)}) must have one entry per wind bin")

    def wmean(runs: Sequence[Mapping[str, Any]], key: str) -> float:
        return float(np.sum(p * np.array([r[key] for r in runs])) / p.sum())

    chans = [c for c in base[0]["channels"] if all(c in r["channels"] for r in updated)]
    out: dict[str, Any] = {"del_change_pct": {}, "lifetime_del": {}, "extension": {},
                           "pitch_change_pct": {}, "std_change_pct": {}}
    for c in chans:
        m = float(base[0]["channels"][c]["m"])
        lb, lu = (_lifetime_at(runs, c, m, p) for runs in (base, updated))
        out["lifetime_del"][c] = (lb, lu)
        out["del_change_pct"][c] = pct_change(lb, lu)
        out["extension"][c] = {}
        for mw in woehler:
            lbm, lum = (_lifetime_at(runs, c, float(mw), p) for runs in (base, updated))
            out["extension"][c][float(mw)] = lifetime_extension(
                lbm, lum, mw, t_base=t_base, t_upd=t_upd, t_lifetime=t_lifetime)
    if all("power_mean_W" in r for r in [*base, *updated]):
        out["aep_change_pct"] = pct_change(wmean(base, "power_mean_W"), wmean(updated, "power_mean_W"))
    for keys, dest in ((_PITCH_KEYS, "pitch_change_pct"), (_STD_KEYS, "std_change_pct")):
        for k in keys:
            if all(k in r for r in [*base, *updated]):
                out[dest][k] = pct_change(wmean(base, k), wmean(updated, k))
    return out

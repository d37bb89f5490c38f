"""Fatigue: rainflow counting, damage-equivalent loads, Miner damage, lifetime DEL and extension.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numba as nb
import numpy as np
from scipy import stats

from linearize.validate import check_number
from mpc_wt._typing import FloatArray

__all__ = ["check_series", "rainflow", "DELConvention", "DEL_CONVENTIONS", "del_convention",
           "CycleCount", "cycle_count", "damage_equivalent_load", "wind_bin_probabilities",
           "lifetime_del", "miner_damage", "lifetime_extension", "WOEHLER_EXPONENTS"]


def check_series(name: str, x: Any) -> FloatArray:
    """A load or signal series as a finite 1-D float array, or an error naming it.

    Parameters
    ----------
    name : str
        The argument's name, for the message.
    x : array_like
        The series.

    Returns
    -------
    (n_t,) ndarray
        The series as contiguous floats (one compiled version of the counting kernels for
        every caller: numba compiles a strided array's apart).

    Raises
    ------
    ValueError
        If it is not 1-D or holds a non-finite value.
    """
    arr = np.asarray(x, dtype=float)
    if arr.ndim != 1:
        raise ValueError(f"{name} must be 1-D, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        i = int(np.argmax(~np.isfinite(arr)))
        raise ValueError(f"{name} must be finite; sample {i} is {float(arr[i])!r}")
    return np.ascontiguousarray(arr)


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
    arr = check_series("x", x)
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
        ranges = fatpack.find_rainflow_ranges(check_series("x", x), k=256)
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


#: Woehler exponents at which every assessed channel's DEL is kept (besides its own), so that
#: lifetime DELs at another exponent come from the channel's cycles (Pettas and Cheng's
#: lifetime extension at m = 4 and 10 of every channel).
WOEHLER_EXPONENTS = (3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0)

"""Ultimate loads over a campaign (IEC 61400-1 ed. 3, sections 7.6.2 and 7.6.1).

Per case and channel the extremes are the largest and the smallest value and their times
(:func:`case_extremes`). Over a campaign (:func:`ultimate_table`):

* the campaign's extreme of each channel, with the case that produced it;
* for turbulent cases the characteristic load of a load case (DLC and mean wind) is the mean
  over its seeds of each seed's extreme (the standard's approach for a set of turbulent
  simulations; a deterministic case has one "seed"), and of a DLC the largest of those over its
  winds;
* the design load is the characteristic load times the partial safety factor for loads of the
  DLC's family (table 3: normal 1.35, abnormal 1.1, transport and erection 1.5).

Optionally (:func:`extrapolate_maxima`) a turbulent DLC's per-seed maxima are extrapolated to
the load with a 50-year return period, the standard's approach for DLC 1.1 (7.6.2.1 and annex
F; partial safety factor 1.25): a Gumbel distribution per mean wind (method of moments, 10-min
maxima), weighted by the wind distribution's bin probabilities, solved for the exceedance
probability of one run in 50 years.
"""
from __future__ import annotations

import math
from collections import defaultdict
from typing import Any, Iterable, Mapping, Sequence

import numpy as np

__all__ = ["SAFETY_FACTORS", "EXTRAPOLATED_SAFETY_FACTOR", "case_extremes", "ultimate_table",
           "extrapolate_maxima"]

#: Partial safety factors for loads, IEC 61400-1 ed. 3 table 3 (unfavourable loads).
SAFETY_FACTORS = {"N": 1.35, "A": 1.1, "T": 1.5}
#: Partial safety factor of a load extrapolated to 50 years (DLC 1.1, IEC 61400-1 ed. 3
#: 7.6.2.1).
EXTRAPOLATED_SAFETY_FACTOR = 1.25
_EULER_GAMMA = 0.5772156649015329
_YEAR_S = 365.25 * 24 * 3600.0


def extrapolate_maxima(maxima: Mapping[float, Sequence[float]],
                       probabilities: Mapping[float, float], *, run_s: float = 600.0,
                       return_years: float = 50.0) -> dict[str, Any]:
    """The load whose exceedance in one run has the probability of once in ``return_years``.

    Per mean wind v the run maxima are taken as Gumbel distributed with the method-of-moments
    parameters beta_v = s_v sqrt(6) / pi and mu_v = mean_v - 0.5772 beta_v (s_v: sample
    standard deviation, ddof 1); the long-term exceedance of a load l is
    P(l) = sum_v p_v (1 - exp(-exp(-(l - mu_v) / beta_v))), and the extrapolated load solves
    P(l) = run_s / (return_years * 1 year) (IEC 61400-1 ed. 3 annex F's procedure).

    Parameters
    ----------
    maxima : mapping
        Mean wind [m/s] -> the maxima of its runs (at least 3 per wind).
    probabilities : mapping
        Mean wind -> probability of the wind bin (the time share of the bin; the rest of the
        time, outside these winds, produces no load).
    run_s : float
        Length of one run [s].
    return_years : float
        Return period [years].

    Returns
    -------
    dict
        ``load`` (the extrapolated load), ``exceedance`` (the target probability per run),
        ``gumbel`` (wind -> (mu, beta)), ``max_observed``.

    Raises
    ------
    ValueError
        A wind with fewer than 3 maxima, non-finite maxima, a wind without a probability,
        probabilities outside [0, 1] or summing above 1, non-positive run length or period.
    """
    from scipy.optimize import brentq

    if not (math.isfinite(run_s) and run_s > 0 and math.isfinite(return_years)
            and return_years > 0):
        raise ValueError(f"run_s and return_years must be > 0, got {run_s!r}, "
                         f"{return_years!r}")
    if not maxima:
        raise ValueError("extrapolate_maxima needs the maxima of at least one wind")
    gum: dict[float, tuple[float, float]] = {}
    p = []
    for v, xs in sorted(maxima.items()):
        x = np.asarray(xs, float)
        if x.size < 3 or not np.all(np.isfinite(x)):
            raise ValueError(f"wind {v:g} m/s: needs at least 3 finite maxima, got "
                             f"{list(map(float, x))}")
        if v not in probabilities or not 0.0 <= probabilities[v] <= 1.0:
            raise ValueError(f"wind {v:g} m/s: probability must be in [0, 1], got "
                             f"{probabilities.get(v)!r}")
        beta = max(float(np.std(x, ddof=1)) * math.sqrt(6.0) / math.pi,
                   1e-12 * max(1.0, float(np.abs(x).max())))
        gum[v] = (float(x.mean()) - _EULER_GAMMA * beta, beta)
        p.append(float(probabilities[v]))
    if sum(p) > 1.0 + 1e-9 or sum(p) <= 0.0:
        raise ValueError(f"wind probabilities must sum to (0, 1], got {sum(p):g}")
    target = run_s / (return_years * _YEAR_S)
    mu = np.array([g[0] for g in gum.values()])
    beta = np.array([g[1] for g in gum.values()])
    pw = np.asarray(p)

    def excess(load: float) -> float:
        return float(np.sum(pw * -np.expm1(-np.exp(-(load - mu) / beta)))) - target

    lo = float(np.min(mu))
    hi = float(np.max(mu + beta * 60.0))
    if excess(lo) <= 0.0:       # the bins' total probability is below the target itself
        raise ValueError(f"the winds' probabilities ({sum(p):g}) are below the target "
                         f"exceedance {target:.3g}: no load reaches it")
    load = float(brentq(excess, lo, hi, xtol=1e-12 * max(1.0, abs(hi)), maxiter=200))
    return {"load": load, "exceedance": target, "gumbel": gum,
            "max_observed": max(float(np.max(x)) for x in maxima.values())}


def case_extremes(t: np.ndarray, cols: Mapping[str, np.ndarray],
                  channels: Iterable[str]) -> dict[str, dict[str, float]]:
    """The largest and smallest value of each channel in one case, and when.

    Parameters
    ----------
    t : (n,) ndarray
        Times [s].
    cols : mapping
        Channel name -> (n,) series.
    channels : iterable of str
        The channels to take.

    Returns
    -------
    dict
        Channel -> {"max", "t_max", "min", "t_min"}.

    Raises
    ------
    ValueError
        A channel that is missing, of another length than ``t``, or not finite.
    """
    t = np.asarray(t, float)
    out = {}
    for ch in channels:
        if ch not in cols:
            raise ValueError(f"channel {ch!r} is not in the case; it has {sorted(cols)}")
        x = np.asarray(cols[ch], float)
        if x.shape != t.shape:
            raise ValueError(f"channel {ch!r} has shape {x.shape}; expected {t.shape} like t")
        if not np.all(np.isfinite(x)):
            raise ValueError(f"channel {ch!r} has non-finite values at t = "
                             f"{t[~np.isfinite(x)][0]:g} s")
        i, j = int(np.argmax(x)), int(np.argmin(x))
        out[ch] = {"max": float(x[i]), "t_max": float(t[i]), "min": float(x[j]),
                   "t_min": float(t[j])}
    return out


def _family(dlc: str, families: Mapping[str, str]) -> str:
    fam = families.get(dlc, "N")
    if fam not in SAFETY_FACTORS:
        raise ValueError(f"load case family of DLC {dlc!r} must be one of "
                         f"{sorted(SAFETY_FACTORS)} (IEC 61400-1 table 3), got {fam!r}")
    return fam


def ultimate_table(rows: Iterable[Mapping[str, Any]], channels: Iterable[str], *,
                   families: Mapping[str, str] | None = None) -> dict[str, dict[str, Any]]:
    """Ultimate loads of a campaign from its cases' extremes (module docstring).

    Parameters
    ----------
    rows : iterable of mapping
        One per case: ``case_id``, ``dlc`` (e.g. "1.3"), ``wind_mps``, ``seed`` and
        ``extremes`` (:func:`case_extremes`).
    channels : iterable of str
        The channels.
    families : mapping, optional
        DLC -> "N", "A" or "T" (default "N" for every DLC).

    Returns
    -------
    dict
        Channel -> {"max", "max_case", "min", "min_case" (the campaign's extremes and their
        cases), "by_dlc": {dlc: {"characteristic_max", "characteristic_min" (the largest
        and smallest seed-mean extreme over the DLC's winds), "wind_max", "wind_min",
        "family", "safety_factor", "design_max", "design_min" (the characteristic loads times
        the safety factor: None for a maximum <= 0 or a minimum >= 0, which the factor would
        make less unfavourable), "seeds"}}}.

    Raises
    ------
    ValueError
        No cases, a case without a channel, an unknown family.
    """
    rows = list(rows)
    if not rows:
        raise ValueError("ultimate_table needs at least one case")
    families = dict(families or {})
    out: dict[str, dict[str, Any]] = {}
    for ch in channels:
        groups: dict[tuple[str, float], dict[str, list[float]]] = defaultdict(
            lambda: {"max": [], "min": []})
        best = {"max": (-math.inf, ""), "min": (math.inf, "")}
        for r in rows:
            ex = r["extremes"].get(ch)
            if ex is None:
                raise ValueError(f"case {r['case_id']!r} has no extremes of channel {ch!r}")
            g = groups[(str(r["dlc"]), float(r["wind_mps"]))]
            g["max"].append(ex["max"])
            g["min"].append(ex["min"])
            if ex["max"] > best["max"][0]:
                best["max"] = (ex["max"], r["case_id"])
            if ex["min"] < best["min"][0]:
                best["min"] = (ex["min"], r["case_id"])
        by_dlc: dict[str, dict[str, Any]] = {}
        for (dlc, wind), g in sorted(groups.items()):
            hi, lo = float(np.mean(g["max"])), float(np.mean(g["min"]))
            d = by_dlc.setdefault(dlc, {"characteristic_max": -math.inf,
                                        "characteristic_min": math.inf, "wind_max": None,
                                        "wind_min": None, "seeds": len(g["max"])})
            if hi > d["characteristic_max"]:
                d["characteristic_max"], d["wind_max"] = hi, wind
            if lo < d["characteristic_min"]:
                d["characteristic_min"], d["wind_min"] = lo, wind
        for dlc, d in by_dlc.items():
            fam = _family(dlc, families)
            gf = SAFETY_FACTORS[fam]
            # the factor makes a load more unfavourable: a maximum above zero larger, a
            # minimum below zero more negative; the other sides have no design value
            d.update(family=fam, safety_factor=gf,
                     design_max=(gf * d["characteristic_max"] if d["characteristic_max"] > 0
                                 else None),
                     design_min=(gf * d["characteristic_min"] if d["characteristic_min"] < 0
                                 else None))
        out[ch] = {"max": best["max"][0], "max_case": best["max"][1],
                   "min": best["min"][0], "min_case": best["min"][1], "by_dlc": by_dlc}
    return out

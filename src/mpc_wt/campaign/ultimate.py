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
"""
from __future__ import annotations

import math
from collections import defaultdict
from typing import Any, Iterable, Mapping

import numpy as np

__all__ = ["SAFETY_FACTORS", "case_extremes", "ultimate_table"]

#: Partial safety factors for loads, IEC 61400-1 ed. 3 table 3 (unfavourable loads).
SAFETY_FACTORS = {"N": 1.35, "A": 1.1, "T": 1.5}


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
        "family", "safety_factor", "design_max", "design_min", "seeds"}}}.

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
            d.update(family=fam, safety_factor=gf, design_max=gf * d["characteristic_max"],
                     design_min=gf * d["characteristic_min"])
        out[ch] = {"max": best["max"][0], "max_case": best["max"][1],
                   "min": best["min"][0], "min_case": best["min"][1], "by_dlc": by_dlc}
    return out

"""Ultimate loads per design load case and the sign-off summary of a campaign.

A campaign with ``load_cases`` (IEC 61400-1 ed. 3 table 2 style: DLC 1.2 fatigue, 1.3 ETM,
1.4 ECD, 1.5 EWS, 2.x faults, 4.2 shutdown in a gust, 5.1 emergency stop) is reported per
controller and DLC:

* :func:`ultimate_rows`: per channel the DLC's extremes and their cases, its characteristic
  loads (seed means of the per-case extremes, largest over the winds), its design loads (times
  the family's partial safety factor, :data:`~.ultimate.SAFETY_FACTORS`) and, for a DLC marked
  ``extrapolate``, the 50-year load (:func:`~.ultimate.extrapolate_maxima`, factor 1.25);
* :func:`governing_rows`: per controller and channel the largest design load over the DLCs and
  the DLC that sets it, against the reference controller's (the extrapolated loads are shown
  beside, not taken: with a few seeds per wind their Gumbel fits are indicative);
* :func:`signoff_rows`: per controller and DLC the largest rotor speed against rated and the
  margin to the supervisor's overspeed limit, the stops that tripped, the largest pitch rate
  against the actuator's limit and the time at that limit in the cases that ran without a stop
  (a stop pitches at the maximum rate by design), and the failed cases.
"""
from __future__ import annotations

import math
from collections import defaultdict
from typing import Any, Mapping, Sequence

import numpy as np
from scipy import stats

from mpc_wt.assessment.performance import pct_change
from mpc_wt.assessment.ultimate import (
    EXTRAPOLATED_SAFETY_FACTOR,
    extrapolate_maxima,
    ultimate_table,
)
from mpc_wt.campaign.spec import CampaignSpec, Case, turbulence_tag
from mpc_wt.campaign.store import CaseRow
from mpc_wt.campaign.task import load_case_turbine

__all__ = ["dlc_label", "ultimate_rows", "governing_rows", "signoff_rows"]


def dlc_label(spec: CampaignSpec, case: Case | None, row: CaseRow) -> str:
    """The DLC a finished case belongs to ("1.2" for a spec without load cases; with several
    turbulences "1.2-A", "1.2-ti12").

    Parameters
    ----------
    spec : CampaignSpec
        The campaign.
    case : Case or None
        The case of the row (None: no longer in the spec).
    row : CaseRow
        The finished case.

    Returns
    -------
    str
    """
    if case is not None and spec.load_cases and not spec.load_cases[0].legacy:
        return case.dlc
    turbs = spec.load_cases[0].turbulence if spec.load_cases else spec.turbulence
    return "1.2" if len(turbs) == 1 else f"1.2-{turbulence_tag(row.turbulence_value)}"


def _by_controller_dlc(spec: CampaignSpec, rows: Sequence[CaseRow]
                       ) -> dict[tuple[str, str], list[tuple[CaseRow, Case | None]]]:
    cases = {c.case_id: c for c in spec.cases()}
    out: dict[tuple[str, str], list[tuple[CaseRow, Case | None]]] = defaultdict(list)
    for r in rows:
        c = cases.get(r.case_id)
        out[(r.controller, dlc_label(spec, c, r))].append((r, c))
    order = [c.name for c in spec.controllers]
    dlcs = [lc.dlc for lc in spec.load_cases]
    return dict(sorted(out.items(), key=lambda kv: (
        order.index(kv[0][0]) if kv[0][0] in order else 99,
        dlcs.index(kv[0][1]) if kv[0][1] in dlcs else 99, kv[0][1])))


def _load_case(spec: CampaignSpec, dlc: str) -> Any:
    return next((lc for lc in spec.load_cases if lc.dlc == dlc), None)


def _extrapolated(spec: CampaignSpec, lc: Any, items: list[tuple[CaseRow, Case | None]],
                  ch: str, side: str) -> float | None:
    """The 50-year load of a channel's maxima (``side`` "max") or minima ("min", as the
    negated maxima of -x) in load case ``lc``; None with fewer than 3 seeds at some wind."""
    by: dict[float, list[float]] = defaultdict(list)
    for r, _ in items:
        x = r.metrics["extremes"][ch][side]
        by[r.wind_mps].append(x if side == "max" else -x)
    if min(len(v) for v in by.values()) < 3:
        return None
    winds = sorted(by)
    p = dict(zip(winds, spec.bin_probabilities(winds).tolist()))
    val = extrapolate_maxima(by, p, run_s=lc.duration)["load"]
    return val if side == "max" else -val


def ultimate_rows(spec: CampaignSpec, rows: Sequence[CaseRow]) -> list[dict[str, Any]]:
    """Ultimate loads per controller, DLC and channel (module docstring).

    Parameters
    ----------
    spec : CampaignSpec
        The campaign.
    rows : sequence of CaseRow
        Its finished cases (with ``extremes`` in their metrics).

    Returns
    -------
    list of dict
        ``controller``, ``dlc``, ``family``, ``channel``, ``max``/``max_case``,
        ``min``/``min_case`` (the DLC's extremes), ``characteristic_max``, ``wind_max``,
        ``design_max``, ``characteristic_min``, ``design_min``, ``safety_factor``, ``seeds``,
        ``cases``, ``characteristic_max_se``/``_min_se`` (the standard error of the seed mean,
        s / sqrt(n), at the characteristic's wind; None for a deterministic load case or a
        single seed) and, for an ``extrapolate`` DLC, ``extrapolated_max``/``_min`` and
        ``design_extrapolated_max``/``_min`` (factor 1.25). The per-case extremes at the
        characteristic's wind are kept under ``_cases_max``/``_cases_min`` (case id without
        the controller -> extreme) for :func:`governing_rows`' pairing.
    """
    out = []
    for (ctl, dlc), items in _by_controller_dlc(spec, rows).items():
        items = [(r, c) for r, c in items if r.metrics and "extremes" in r.metrics]
        if not items:
            continue
        lc = _load_case(spec, dlc)
        fam = lc.family if lc is not None and not lc.legacy else "N"
        turbulent = lc is None or not lc.deterministic
        urows = [{"case_id": r.case_id, "dlc": dlc, "wind_mps": r.wind_mps, "seed": r.seed,
                  "extremes": r.metrics["extremes"]} for r, _ in items]
        chans = [ch for ch in (*spec.ultimate, "rotor_speed")
                 if all(ch in u["extremes"] for u in urows)]
        for ch, u in ultimate_table(urows, chans, families={dlc: fam}).items():
            d = u["by_dlc"][dlc]
            row = {"controller": ctl, "dlc": dlc, "family": fam, "channel": ch,
                   "max": u["max"], "max_case": u["max_case"], "min": u["min"],
                   "min_case": u["min_case"], **{k: d[k] for k in (
                       "characteristic_max", "wind_max", "design_max", "characteristic_min",
                       "wind_min", "design_min", "safety_factor", "seeds")},
                   "cases": len(urows)}
            for side in ("max", "min"):
                at = {_paired(r): r.metrics["extremes"][ch][side] for r, _ in items
                      if r.wind_mps == d[f"wind_{side}"]}
                row[f"characteristic_{side}_se"] = _std_error(at.values()) if turbulent else None
                row[f"_cases_{side}"] = at
            if ch not in spec.ultimate:        # the rotor speed: extremes, not a load
                row.update(design_max=None, design_min=None, safety_factor=None)
            elif lc is not None and lc.extrapolate:
                for side in ("max", "min"):
                    x = _extrapolated(spec, lc, items, ch, side)
                    row[f"extrapolated_{side}"] = x
                    row[f"design_extrapolated_{side}"] = (
                        None if x is None else EXTRAPOLATED_SAFETY_FACTOR * x)
            out.append(row)
    return out


def governing_rows(spec: CampaignSpec, ult: Sequence[Mapping[str, Any]]
                   ) -> list[dict[str, Any]]:
    """The largest design load (in magnitude) per controller and channel over its DLCs, the
    DLC that sets it, and its change against the reference controller's governing load
    (seed-mean characteristic loads times the safety factors; not the extrapolated ones).

    Parameters
    ----------
    spec : CampaignSpec
        For the reference controller.
    ult : sequence of dict
        :func:`ultimate_rows`.

    Returns
    -------
    list of dict
        ``controller``, ``channel``, ``design`` (signed: the governing design max or min),
        ``side``, ``dlc``, ``wind`` (where the characteristic load is), ``case`` (the case of
        that DLC's extreme), ``change_pct`` and ``change_se_pct``: the standard error of the
        change from the seeds' scatter, in % of the reference's governing design load. Where
        both governing loads come from the same DLC, side and wind, it is paired by case (the
        same fields and events: the standard error of the seeds' differences); otherwise the
        two seed means' standard errors combine as independent. None where neither load has
        seeds to scatter (deterministic load cases).
    """
    best: dict[tuple[str, str], dict[str, Any]] = {}
    for u in ult:
        for side in ("max", "min"):
            val = u[f"design_{side}"]
            if val is None:
                continue
            key = (u["controller"], u["channel"])
            if key not in best or abs(val) > abs(best[key]["design"]):
                best[key] = {"controller": u["controller"], "channel": u["channel"],
                             "design": val, "side": side, "dlc": u["dlc"],
                             "wind": u.get(f"wind_{side}"), "case": u[f"{side}_case"],
                             "_se": u.get(f"characteristic_{side}_se"),
                             "_cases": u.get(f"_cases_{side}", {}),
                             "_factor": u["safety_factor"]}
    out = list(best.values())
    for b in out:
        ref = best.get((spec.reference, b["channel"]))
        b["change_pct"] = b["change_se_pct"] = None
        if ref is not None and ref["design"] != 0:
            v = pct_change(abs(ref["design"]), abs(b["design"]))
            b["change_pct"] = v if math.isfinite(v) else None
            b["change_se_pct"] = _change_se(b, ref)
    return [{k: v for k, v in b.items() if not k.startswith("_")} for b in out]


def _paired(row: CaseRow) -> str:
    """The case a row ran, without its controller: the key that pairs two controllers' runs of
    the same field and events."""
    return row.case_id.split("__", 1)[-1]


def _std_error(values: Any) -> float | None:
    """The standard error of a mean (scipy's ``sem``: s / sqrt(n)); None for fewer than two
    values."""
    v = np.asarray(list(values), float)
    return float(stats.sem(v)) if v.size >= 2 else None


def _change_se(b: Mapping[str, Any], ref: Mapping[str, Any]) -> float | None:
    """Standard error of a governing load's change against the reference's, in % of the
    reference's design load (:func:`governing_rows`)."""
    common = sorted(set(b["_cases"]) & set(ref["_cases"]))
    paired = ((b["dlc"], b["side"], b["wind"]) == (ref["dlc"], ref["side"], ref["wind"])
              and len(common) >= 2 and b["_se"] is not None and ref["_se"] is not None)
    if paired:
        se = b["_factor"] * _std_error(abs(b["_cases"][k]) - abs(ref["_cases"][k])
                                       for k in common)
    elif b["_se"] is None and ref["_se"] is None:
        return None
    else:
        se = math.hypot(b["_factor"] * (b["_se"] or 0.0), ref["_factor"] * (ref["_se"] or 0.0))
    return 100.0 * se / abs(ref["design"])


def _largest(done: Sequence[tuple[CaseRow, Any]], channel: str) -> tuple[float, str] | None:
    """The largest value of ``channel`` over finished cases that record its extremes, and
    the case's id; None where none does."""
    ex = [(r.metrics["extremes"][channel]["max"], r.case_id) for r, _ in done
          if channel in r.metrics.get("extremes", {})]
    return max(ex) if ex else None


def signoff_rows(spec: CampaignSpec, rows: Sequence[CaseRow],
                 failed: Sequence[CaseRow] = ()) -> list[dict[str, Any]]:
    """Rotor overspeed, stops and pitch-rate demand per controller and DLC.

    Parameters
    ----------
    spec : CampaignSpec
        The campaign (its turbine gives rated rotor speed and the pitch rate limit).
    rows : sequence of CaseRow
        Finished cases.
    failed : sequence of CaseRow
        Failed cases (counted per controller and DLC).

    Returns
    -------
    list of dict
        ``controller``, ``dlc``, ``cases``, ``failed``, ``rotor_speed_max_rel`` (largest rotor
        speed / rated), ``rotor_speed_max_case``, ``power_max_rel`` and ``torque_max_rel``
        (largest electrical power and generator torque / rated, where the cases record them)
        with their ``*_case``, ``overspeed_limit_rel`` (the supervisor's,
        None without protection), ``overspeed_margin_pct`` (limit minus largest, in % of
        rated), ``overspeed_stops`` (cases stopped by the protection), ``stops`` (cases in
        which any stop sequence ran), ``pitch_rate_max_degps``, ``pitch_rate_max_rel`` (of the
        actuator's limit), ``pitch_rate_limit_s`` (mean time per case at the limit): these
        three over the cases without a stop (None if every case stopped).
    """
    tb = load_case_turbine(spec.turbine)
    rated = tb.operation.rated_rotor_speed_rad_s
    lim_rate = math.degrees(tb.pitch_actuator.max_rate_rad_s)
    groups = _by_controller_dlc(spec, [*rows, *failed])
    out = []
    for (ctl, dlc), items in groups.items():
        done = [(r, c) for r, c in items if r.status == "done" and r.metrics]
        row: dict[str, Any] = {"controller": ctl, "dlc": dlc, "cases": len(done),
                               "failed": len(items) - len(done)}
        ex = _largest(done, "rotor_speed")
        if ex:
            w, case = ex
            row.update(rotor_speed_max_rel=w / rated, rotor_speed_max_case=case)
        for ch, key, ref in (("gen_power", "power", tb.operation.rated_power),
                             ("gen_torque", "torque", tb.rated_generator_torque)):
            peak = _largest(done, ch)
            if peak:
                row.update({f"{key}_max_rel": peak[0] / ref, f"{key}_max_case": peak[1]})
        lims = {(c.supervisor or {}).get("overspeed") for _, c in done if c is not None}
        lim = min((x for x in lims if x is not None), default=None)
        row["overspeed_limit_rel"] = lim
        row["overspeed_margin_pct"] = (100.0 * (lim - row["rotor_speed_max_rel"])
                                       if lim is not None and ex else None)
        states = [r.metrics.get("supervisor_state") or 0 for r, _ in done]
        row["overspeed_stops"] = sum(1 for s in states if s == 2)
        row["stops"] = sum(1 for s in states if s > 0)
        # the controller's demand: cases in operation only (a stop pitches at the actuator's
        # maximum rate by design)
        run = [r for r, _ in done if not r.metrics.get("supervisor_state")]
        rates = [r.metrics["pitch_rate_max_degps"] for r in run
                 if r.metrics.get("pitch_rate_max_degps") is not None]
        row.update(pitch_rate_max_degps=max(rates) if rates else None,
                   pitch_rate_max_rel=max(rates) / lim_rate if rates else None)
        at = [r.metrics.get("pitch_rate_limit_s") or 0.0 for r in run]
        row["pitch_rate_limit_s"] = float(np.mean(at)) if at else None
        out.append(row)
    return out

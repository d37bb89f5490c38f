"""Aggregate a campaign's cases: per controller, turbulence and channel.

Short-term DELs per wind bin and seed; the DEL per bin over seeds (m-power mean of equal-length
runs); the lifetime DEL, the m-power mean weighted by the wind distribution (Clemens et al.
eq 18, :func:`mpc_wt.assessment.fatigue.lifetime_del`); AEP from the mean power per bin; pitch
duty weighted the same way (Pettas and Cheng sec. 4); CS1-CS5 per bin (Do et al. eqs 21-26);
lifetime extension for a retrofit after 15 of 20 years (Pettas and Cheng eq 1). Every
comparison with the reference controller is made over the winds both ran.
"""
from __future__ import annotations

import math
from collections import defaultdict
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from mpc_wt.assessment.fatigue import lifetime_del, lifetime_extension
from mpc_wt.assessment.performance import aep_Wh, pct_change
from mpc_wt.campaign.signoff import governing_rows, signoff_rows, ultimate_rows
from mpc_wt.campaign.spec import CampaignSpec, spec_from_dict
from mpc_wt.campaign.store import CampaignStore, CaseRow
from mpc_wt.errors import ResultFileError

__all__ = ["OUTLIER_RATIO", "PITCH_METRICS", "RELATIVE_METRICS", "ABSOLUTE_METRICS",
           "relative_metrics", "absolute_metrics", "aggregate"]

#: A seed whose DEL exceeds this multiple of its bin's median (3 seeds or more) is listed as
#: suspect in the report: with m = 10 one such run can carry a lifetime DEL.
OUTLIER_RATIO = 3.0


PITCH_METRICS = ("pitch_travel_deg", "pitch_rate_std_degps", "pitch_acc_std_degps2")


#: regulation measures: metric key, or (key, sub-key) for nested metrics
_REGULATION = (("rotor_speed_std_rad_s",), ("power_std_W",), ("flap_1_harmonics", "1P"),
               ("flap_1_harmonics", "3P"))


_CS = ("cs1", "cs2", "cs3", "cs4", "cs5")


#: Scalar measures of :func:`relative_metrics`: name -> metric key (or key path) of a case.
RELATIVE_METRICS: dict[str, tuple[str, ...]] = {
    **{k: (k,) for k in _CS}, "power_mean": ("power_mean_W",), "power_std": ("power_std_W",),
    "rotor_speed_std": ("rotor_speed_std_rad_s",), "rotor_speed_max": ("rotor_speed_max_rad_s",),
    "pitch_travel": ("pitch_travel_deg",), "pitch_rate_std": ("pitch_rate_std_degps",),
    "pitch_acc_std": ("pitch_acc_std_degps2",), "flap_1p": ("flap_1_harmonics", "1P"),
    "flap_3p": ("flap_1_harmonics", "3P")}


#: Measures of :func:`absolute_metrics` (per case, not relative: the reference may have none).
ABSOLUTE_METRICS: dict[str, tuple[str, ...]] = {
    "pitch_rate_limit_hits": ("pitch_rate_limit_hits",),
    "pitch_rate_limit_s": ("pitch_rate_limit_s",),
    "pitch_rate_max_degps": ("pitch_rate_max_degps",)}


def _pct(a: float | None, b: float | None) -> float | None:
    """:func:`mpc_wt.assessment.performance.pct_change`, None where it states no change (JSON/CSV cells)."""
    if a is None or b is None:
        return None
    v = pct_change(a, b)
    return v if math.isfinite(v) else None


def _load(root: Path) -> tuple[CampaignSpec, list[CaseRow], list[CaseRow]]:
    with CampaignStore(root) as st:
        meta = st.meta()
        every = st.rows()
        rows = [r for r in every if r.status == "done" and r.metrics]
        failed = [r for r in every if r.status == "failed"]
        changed = st.changed_files()
    if changed:
        shown = "; ".join(f"{cid} ({why})" for cid, why in changed[:5])
        more = f" and {len(changed) - 5} more" if len(changed) > 5 else ""
        raise ResultFileError(
            f"{root}: {len(changed)} case(s) do not match the checksum recorded when they "
            f"were written: {shown}{more}; resuming the campaign (mpcwt campaign run SPEC "
            f"--out {root}) computes them again")
    if "spec_raw" not in meta:
        raise ValueError(f"{root}: the index holds no spec (was the campaign ever run?)")
    spec = spec_from_dict(meta["spec_raw"], import_plugins=False)   # runs none of its code
    if not rows:
        raise ValueError(f"{root}: no finished case to report; run the campaign first "
                         f"(mpcwt campaign run SPEC --out {root})")
    return spec, rows, failed


def _bin_del(cases: list[CaseRow], ch: str, m: float) -> float | None:
    """The DEL of a wind bin over its seeds: their cycles taken together, i.e. the m-power mean
    of the seeds' DELs weighted by their equivalent cycle counts (equal for ``range-1hz``)."""
    d, n = _seed_dels(cases, ch)
    return float((np.sum(n * d ** m) / n.sum()) ** (1 / m)) if d.size else None


def _bin_neq(cases: list[CaseRow], ch: str) -> float:
    """The equivalent cycle count of a bin per run (its seeds' mean; Clemens eq 18's n_eq,j)."""
    d, n = _seed_dels(cases, ch)
    return float(n.mean()) if d.size else 1.0


def _seed_dels(cases: list[CaseRow], ch: str) -> tuple[np.ndarray, np.ndarray]:
    rows = [c.metrics["channels"][ch] for c in cases if ch in c.metrics["channels"]]
    return (np.array([r["del"] for r in rows], float),
            np.array([r.get("n_eq", 1.0) for r in rows], float))


def _metric(c: CaseRow, key: str | tuple[str, ...]) -> Any:
    v: Any = c.metrics
    for k in (key,) if isinstance(key, str) else key:
        v = v.get(k) if isinstance(v, dict) else None
    return v


def _bin_mean(cases: list[CaseRow], key: str | tuple[str, ...]) -> float | None:
    v = [_metric(c, key) for c in cases if _metric(c, key) is not None]
    return float(np.mean(v)) if v else None


class _Group:
    """The cases of one controller and turbulence, by wind, with the reference's."""

    def __init__(self, spec: CampaignSpec, ctl: str, turb: str | float,
                 bins: dict[float, list[CaseRow]], rbins: dict[float, list[CaseRow]]) -> None:
        self.spec, self.ctl, self.turb, self.bins, self.rbins = spec, ctl, turb, bins, rbins
        self.winds = sorted(bins)
        self.common = [v for v in self.winds if v in rbins]
        self.p_all = spec.bin_probabilities(self.winds)
        self.p_com = spec.bin_probabilities(self.common) if self.common else None
        self.key = {"controller": ctl, "turbulence": turb}

    def missing_seeds(self) -> list[float]:
        cs = self.spec.controller(self.ctl) if self.ctl in {c.name for c in
                                                            self.spec.controllers} else None
        if not self.spec.load_cases[0].legacy:      # the fatigue load cases' grid
            want: dict[float, int] = {}
            for lc in self.spec.load_cases:
                if lc.fatigue and (cs is None or cs.dlcs is None or lc.dlc in cs.dlcs):
                    for v, n in lc.runs_per_wind().items():
                        want[v] = want.get(v, 0) + n
            return sorted(v for v, n in want.items() if len(self.bins.get(v, [])) < n)
        winds = set(cs.winds if cs and cs.winds else self.spec.winds)
        n_seed = len(cs.seeds if cs and cs.seeds else self.spec.seeds)
        return sorted(v for v in winds if len(self.bins.get(v, [])) < n_seed)

    def outliers(self) -> list[dict[str, Any]]:
        out = []
        for v in self.winds:
            if len(self.bins[v]) < 3:
                continue
            for ch in self.spec.channels:
                d = {c.seed: c.metrics["channels"][ch]["del"] for c in self.bins[v]
                     if ch in c.metrics["channels"]}
                med = float(np.median(list(d.values()))) if d else 0.0
                out += [{**self.key, "wind_mps": v, "seed": seed, "channel": ch, "del": x,
                         "ratio_to_median": x / med} for seed, x in d.items()
                        if med > 0 and x > OUTLIER_RATIO * med]
        return out

    def short_term(self) -> list[dict[str, Any]]:
        return [{**self.key, "wind_mps": v, "seed": c.seed, "channel": ch, "m": m,
                 "del": c.metrics["channels"][ch]["del"]}
                for v in self.winds for c in self.bins[v]
                for ch, m in self.spec.channels.items() if ch in c.metrics["channels"]]

    def per_wind(self) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
        dels, cs_rows = [], []
        for v in self.winds:
            ref = self.rbins.get(v)
            row = {**self.key, "wind_mps": v, "seeds": len(self.bins[v])}
            for ch, m in self.spec.channels.items():
                row[ch] = _bin_del(self.bins[v], ch, m)
                row[f"{ch}_change_pct"] = _pct(_bin_del(ref, ch, m), row[ch]) if ref else None
            dels.append(row)
            crow = {**self.key, "wind_mps": v}
            for k in _CS + ("power_mean_W", "power_std_W", "rotor_speed_std_rad_s") + PITCH_METRICS:
                crow[k] = _bin_mean(self.bins[v], k)
                crow[f"{k}_change_pct"] = _pct(_bin_mean(ref, k), crow[k]) if ref else None
            cs_rows.append(crow)
        return dels, cs_rows

    def lifetime(self) -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
        life, ext = [], []
        for ch, m in self.spec.channels.items():
            d = [_bin_del(self.bins[v], ch, m) for v in self.winds]
            if any(x is None for x in d):
                continue
            lt = lifetime_del(d, m, self.p_all, [_bin_neq(self.bins[v], ch) for v in self.winds])
            row = {**self.key, "channel": ch, "m": m,
                   "winds": f"{self.winds[0]:g}-{self.winds[-1]:g}", "lifetime_del": lt,
                   "lifetime_del_MNm": lt / 1e6, "change_pct": None, "ref_lifetime_del": None}
            if self.common:
                mine = self._life(self.bins, ch, m)
                base = self._life(self.rbins, ch, m)
                is_ref = self.ctl == self.spec.reference
                row["change_pct"] = 0.0 if is_ref else _pct(base, mine)
                row["ref_lifetime_del"] = base
                if not is_ref and base > 0:
                    e = lifetime_extension(base, mine, m, t_base=15.0, t_upd=5.0,
                                           t_lifetime=self.spec.lifetime_years)
                    ext.append({**self.key, "channel": ch, "m": m, "damage_15_5": e["damage"],
                                "extension_years": e["extension_years"]})
            life.append(row)
        return life, ext

    def _life(self, bins: dict[float, list[CaseRow]], ch: str, m: float) -> float:
        """Lifetime DEL over the winds both controllers ran (Clemens eq 18)."""
        return lifetime_del([_bin_del(bins[v], ch, m) for v in self.common], m, self.p_com,
                            [_bin_neq(bins[v], ch) for v in self.common])

    def aep(self) -> list[dict[str, Any]]:
        pw = [_bin_mean(self.bins[v], "power_mean_W") for v in self.winds]
        if any(x is None for x in pw):
            return []
        row = {**self.key, "aep_MWh": aep_Wh(pw, self.p_all) / 1e6, "change_pct": None}
        if self.common:
            a = aep_Wh([_bin_mean(self.bins[v], "power_mean_W") for v in self.common],
                       self.p_com)
            b = aep_Wh([_bin_mean(self.rbins[v], "power_mean_W") for v in self.common],
                       self.p_com)
            row["change_pct"] = _pct(b, a)
        return [row]

    def pitch(self, keys: Sequence[Any] = PITCH_METRICS) -> dict[str, Any]:
        prow: dict[str, Any] = dict(self.key)
        for k in keys:
            vals = [_bin_mean(self.bins[v], k) for v in self.winds]
            if any(x is None for x in vals):
                continue
            name = k if isinstance(k, str) else "_".join(k)
            prow[name] = float(np.sum(self.p_all * np.asarray(vals)) / self.p_all.sum())
            if self.common:
                mine = np.sum(self.p_com * np.asarray([_bin_mean(self.bins[v], k)
                                                       for v in self.common]))
                base = np.sum(self.p_com * np.asarray([_bin_mean(self.rbins[v], k)
                                                       for v in self.common]))
                prow[f"{name}_change_pct"] = _pct(float(base), float(mine))
        return prow

    def regulation(self) -> dict[str, Any]:
        """Rotor-speed std, power std and the blade-1 flap 1P and 3P content, weighted over
        the winds like the pitch duty, with their changes against the reference."""
        return self.pitch(_REGULATION)


def _groups(spec: CampaignSpec, rows: list[CaseRow]) -> list[_Group]:
    by: dict[tuple[str, str], dict[float, list[CaseRow]]] = defaultdict(lambda: defaultdict(list))
    for r in rows:
        by[(r.controller, r.turbulence)][r.wind_mps].append(r)
    order = [c.name for c in spec.controllers]
    keys = sorted(by, key=lambda k: (order.index(k[0]) if k[0] in order else 99, k[1]))
    return [_Group(spec, ctl, turb, by[(ctl, turb)], by.get((spec.reference, turb), {}))
            for ctl, turb in keys]


def _fatigue_done(spec: CampaignSpec, rows: Sequence[CaseRow]) -> list[CaseRow]:
    """The finished cases but those of the spec's non-fatigue load cases (all of a spec without
    load cases; a row the spec does not know is kept)."""
    other = {c.case_id for c in spec.cases() if not c.fatigue}
    return [r for r in rows if r.status == "done" and r.metrics and r.case_id not in other]


def relative_metrics(spec: CampaignSpec, rows: Sequence[CaseRow], controller: str
                     ) -> dict[str, float]:
    """A controller's measures as ratios to the spec's reference over the winds both ran (1:
    the same as the reference), for a tuning objective.

    ``del:CHANNEL``: lifetime DEL (Clemens eq 18, the spec's wind distribution and Woehler
    exponent); every name of :data:`RELATIVE_METRICS`: the seed mean per wind, weighted over
    the winds by the distribution (as the report's pitch duty). Several turbulences: the
    ratios' mean.

    Parameters
    ----------
    spec : CampaignSpec
    rows : sequence of CaseRow
        Finished cases of the controller and of the reference.
    controller : str
        Its name in the spec.

    Returns
    -------
    dict of str to float
        Name -> ratio; a measure the reference has as 0 (or either lacks) is left out.

    Raises
    ------
    ValueError
        If the controller and the reference share no wind with finished cases.
    """
    done = _fatigue_done(spec, rows)
    groups = [g for g in _groups(spec, done) if g.ctl == controller and g.common]
    if not groups:
        raise ValueError(f"controller {controller!r} and the reference {spec.reference!r} "
                         f"share no wind with finished cases")
    acc: dict[str, list[float]] = defaultdict(list)
    for g in groups:
        for ch, m in spec.channels.items():
            if any(_bin_del(b[v], ch, m) is None for b in (g.bins, g.rbins) for v in g.common):
                continue
            mine, base = g._life(g.bins, ch, m), g._life(g.rbins, ch, m)
            if base > 0 and math.isfinite(mine):
                acc[f"del:{ch}"].append(mine / base)
        for name, key in RELATIVE_METRICS.items():
            mine_v = [_bin_mean(g.bins[v], key) for v in g.common]
            base_v = [_bin_mean(g.rbins[v], key) for v in g.common]
            if any(x is None for x in mine_v + base_v):
                continue
            b = float(np.sum(g.p_com * np.asarray(base_v)))
            if b > 0:
                acc[name].append(float(np.sum(g.p_com * np.asarray(mine_v))) / b)
    return {k: float(np.mean(v)) for k, v in acc.items()}


def absolute_metrics(spec: CampaignSpec, rows: Sequence[CaseRow], controller: str
                     ) -> dict[str, float]:
    """A controller's :data:`ABSOLUTE_METRICS` per case: the seed mean per wind, weighted over
    its winds by the spec's distribution (several turbulences: their mean).

    Parameters
    ----------
    spec : CampaignSpec
    rows : sequence of CaseRow
    controller : str

    Returns
    -------
    dict of str to float
        Name -> value; a measure some wind lacks is left out.
    """
    done = _fatigue_done(spec, rows)
    acc: dict[str, list[float]] = defaultdict(list)
    for g in (g for g in _groups(spec, done) if g.ctl == controller):
        for name, key in ABSOLUTE_METRICS.items():
            vals = [_bin_mean(g.bins[v], key) for v in g.winds]
            if vals and all(x is not None for x in vals):
                acc[name].append(float(np.sum(g.p_all * np.asarray(vals)) / g.p_all.sum()))
    return {k: float(np.mean(v)) for k, v in acc.items()}


def aggregate(root: str | Path) -> dict[str, Any]:
    """All tables of a campaign directory as lists of row dicts (see the module docstring).

    Parameters
    ----------
    root : str or Path
        The campaign directory.

    Returns
    -------
    dict
        ``spec``, ``rows`` (finished cases), ``short_term``, ``per_wind``, ``lifetime``,
        ``aep``, ``pitch``, ``cs``, ``extension`` (of the fatigue load cases), ``ultimate``,
        ``governing``, ``signoff`` (:mod:`.signoff`; every load case), ``failed`` (each failed
        case with the first line of its error), ``fatigue_rows``
        (the finished cases of the fatigue load cases), ``sweep``,
        ``incomplete`` and ``outliers``.

    Raises
    ------
    ValueError
        If no case has finished.
    """
    spec, rows, failed = _load(Path(root))
    out: dict[str, Any] = {"spec": spec, "rows": rows, "short_term": [], "per_wind": [],
                           "lifetime": [], "aep": [], "pitch": [], "regulation": [], "cs": [],
                           "extension": [], "sweep": [], "incomplete": [], "outliers": []}
    out["failed"] = [{"case_id": r.case_id, "controller": r.controller, "wind_mps": r.wind_mps,
                      "reason": (r.error or "unknown error").strip().splitlines()[0][:400]}
                     for r in failed]
    out["ultimate"] = ultimate_rows(spec, rows)
    out["governing"] = governing_rows(spec, out["ultimate"])
    out["signoff"] = signoff_rows(spec, rows, failed) if not spec.load_cases[0].legacy else []
    out["fatigue_rows"] = _fatigue_done(spec, rows)
    for g in _groups(spec, out["fatigue_rows"]):
        missing = g.missing_seeds()
        if missing:
            out["incomplete"].append(f"{g.ctl} ({g.turb}): winds {missing} lack seeds")
        out["outliers"] += g.outliers()
        out["short_term"] += g.short_term()
        dels, cs_rows = g.per_wind()
        out["per_wind"] += dels
        out["cs"] += cs_rows
        life, ext = g.lifetime()
        out["lifetime"] += life
        out["extension"] += ext
        out["aep"] += g.aep()
        out["pitch"].append(g.pitch())
        out["regulation"].append(g.regulation())
    for c in spec.controllers:
        f = c.options.get("apc_frequency")
        if f is not None:
            out["sweep"] += [{"controller": c.name, "apc_frequency_Hz": f, **{
                k: r[k] for k in ("turbulence", "channel", "lifetime_del", "change_pct")}}
                for r in out["lifetime"] if r["controller"] == c.name]
    return out

"""Aggregate a campaign into the papers' tables and figures.

Per controller, turbulence and channel: short-term DELs per wind bin and seed; the DEL per bin
over seeds (m-power mean of equal-length runs); the lifetime DEL, the m-power mean weighted by
the wind distribution (Clemens et al. eq 18, :func:`mpc_wt.assessment.series.lifetime_del`); AEP from the
mean power per bin; pitch duty weighted the same way (Pettas and Cheng sec. 4); CS1-CS5 per bin
(Do et al. eqs 21-26); lifetime extension for a retrofit after 15 of 20 years (Pettas and Cheng
eq 1). Every comparison with the reference controller is made over the winds both ran.
Tables go to CSV and Markdown, figures to PNG, and ``report.paper`` rows of the spec put our
numbers next to the paper's.
"""
from __future__ import annotations

import csv
import math
from collections import defaultdict
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from mpc_wt.assessment.fatigue import lifetime_del, lifetime_extension
from mpc_wt.assessment.performance import aep_Wh, cs_measures, pct_change, psd
from mpc_wt.campaign.signoff import governing_rows, signoff_rows, ultimate_rows
from mpc_wt.campaign.spec import CampaignSpec, spec_from_dict, turbulence_tag
from mpc_wt.campaign.store import CampaignStore, CaseRow

__all__ = ["aggregate", "make_report", "relative_metrics", "absolute_metrics",
           "RELATIVE_METRICS", "ABSOLUTE_METRICS"]

#: A seed whose DEL exceeds this multiple of its bin's median (3 seeds or more) is listed as
#: suspect in the report: with m = 10 one such run can carry a lifetime DEL.
OUTLIER_RATIO = 3.0
_PITCH = ("pitch_travel_deg", "pitch_rate_std_degps", "pitch_acc_std_degps2")
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
    """:func:`mpc_wt.assessment.series.pct_change`, None where it states no change (JSON/CSV cells)."""
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
    if "spec_raw" not in meta:
        raise ValueError(f"{root}: the index holds no spec (was the campaign ever run?)")
    spec = spec_from_dict(meta["spec_raw"])
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
                    for v in lc.winds:
                        want[v] = want.get(v, 0) + len(lc.seeds)
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
            for k in _CS + ("power_mean_W", "power_std_W", "rotor_speed_std_rad_s") + _PITCH:
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

    def pitch(self, keys: Sequence[Any] = _PITCH) -> dict[str, Any]:
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
        ``governing``, ``signoff`` (:mod:`.signoff`; every load case), ``fatigue_rows``
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


# -- paper comparison -------------------------------------------------------------------------
def _ours(agg: dict[str, Any], p: dict[str, Any]) -> float | None:
    spec: CampaignSpec = agg["spec"]
    turb = str(p.get("turbulence", spec.turbulence[0]))
    ctl, metric = p["controller"], p["metric"]

    def pick(table: str, **kw: Any) -> dict[str, Any] | None:
        for r in agg[table]:
            if r["controller"] == ctl and r["turbulence"] == turb and all(
                    r.get(k) == v for k, v in kw.items()):
                return r
        return None

    if metric == "del_change_pct":
        r = pick("per_wind", wind_mps=float(p["wind"]))
        return r.get(f"{p['channel']}_change_pct") if r else None
    if metric == "lifetime_del_change_pct":
        r = pick("lifetime", channel=p["channel"])
        return r["change_pct"] if r else None
    if metric == "aep_change_pct":
        r = pick("aep")
        return r["change_pct"] if r else None
    if metric == "extension_years":
        r = pick("extension", channel=p["channel"])
        return r["extension_years"] if r else None
    if metric == "pitch_change_pct":
        r = pick("pitch")
        return r.get(f"{p.get('measure', 'pitch_travel_deg')}_change_pct") if r else None
    if metric == "cs_change_pct":
        r = pick("cs", wind_mps=float(p["wind"]))
        return r.get(f"{p.get('measure', 'cs1')}_change_pct") if r else None
    r = pick("cs", wind_mps=float(p["wind"])) if "wind" in p else None
    return r.get(p.get("measure", "")) if r else None


def _agree(ours: float | None, paper: float | str) -> str:
    if ours is None or not math.isfinite(ours):
        return "n/a"
    if isinstance(paper, str):
        return "yes" if (ours > 0) == (paper == "increase") else "**no**"
    if abs(paper) < 1.0 and abs(ours) < 1.0:
        return "yes"
    return "yes" if np.sign(ours) == np.sign(paper) else "**no**"


# -- output -----------------------------------------------------------------------------------
def _fmt(v: Any) -> str:
    if v is None:
        return "-"
    if isinstance(v, float):
        if not math.isfinite(v):
            return str(v)
        a = abs(v)
        return f"{v:.3g}" if a >= 1e4 or (a < 0.01 and a > 0) else f"{v:.2f}"
    return str(v)


def _write_csv(path: Path, rows: list[dict[str, Any]]) -> None:
    cols: list[str] = []
    for r in rows:
        cols += [k for k in r if k not in cols]
    tmp = path.with_suffix(".csv.tmp")
    with tmp.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=cols)
        w.writeheader()
        for r in rows:
            w.writerow({k: ("" if r.get(k) is None else r.get(k)) for k in cols})
    tmp.replace(path)


def _md(rows: list[dict[str, Any]], cols: Sequence[str], heads: Sequence[str] | None = None
        ) -> str:
    if not rows:
        return "_none_\n"
    heads = list(heads or cols)
    out = ["| " + " | ".join(heads) + " |", "|" + "---|" * len(heads)]
    for r in rows:
        out.append("| " + " | ".join(_fmt(r.get(c)) for c in cols) + " |")
    return "\n".join(out) + "\n"


def _plots(agg: dict[str, Any], root: Path, out: Path) -> list[str]:
    """Every figure of the report, as PNG in ``out``; returns their paths."""
    from mpc_wt.plotting import plot_signoff, plot_ultimate

    made = []
    if agg["ultimate"] and agg["signoff"]:
        made += [str(plot_ultimate(agg["ultimate"], out / "ultimate.png")),
                 str(plot_signoff(agg["signoff"], agg["governing"], out / "signoff.png"))]
    ctls = list(dict.fromkeys(r["controller"] for r in agg["per_wind"]))
    turbs = list(dict.fromkeys(r["turbulence"] for r in agg["per_wind"]))
    if not turbs:           # no fatigue load case finished
        return made
    made += [_plot_del_vs_wind(agg, ctls, turbs, out)]
    made += _plot_lifetime_bars(agg, ctls, turbs, out)
    series, cs_w, psd_w = _plot_series(agg, root, turbs[0])
    made += _plot_cs_psd(agg, ctls, series, cs_w, psd_w, turbs[0], out)
    made += _plot_sweep(agg, turbs[0], out)
    return made


def _plot_del_vs_wind(agg: dict[str, Any], ctls: list[str], turbs: list[Any], out: Path) -> str:
    """DEL vs mean wind per controller (Clemens fig. 6 / Pettas fig. 4 layout)."""
    from mpc_wt.plotting import pyplot, save_figure

    plt = pyplot()
    spec: CampaignSpec = agg["spec"]
    chans = list(spec.channels)
    nc = min(3, len(chans))
    nr = math.ceil(len(chans) / nc)
    fig, axs = plt.subplots(nr, nc, figsize=(4.2 * nc, 3.0 * nr), dpi=110, squeeze=False)
    for ax, ch in zip(axs.flat, chans):
        for k, ctl in enumerate(ctls):
            for j, turb in enumerate(turbs):
                pts = [(r["wind_mps"], r[ch]) for r in agg["per_wind"]
                       if r["controller"] == ctl and r["turbulence"] == turb and r.get(ch)]
                if not pts:
                    continue
                v, d = np.array(pts).T
                lab = ctl if len(turbs) == 1 else f"{ctl} ({turb})"
                ax.plot(v, d / 1e6, "o-" if j == 0 else "s--", color=f"C{k}", ms=3, lw=1.2,
                        label=lab)
                sv = [(r["wind_mps"], r["del"]) for r in agg["short_term"]
                      if r["controller"] == ctl and r["turbulence"] == turb
                      and r["channel"] == ch]
                if sv:
                    a, b = np.array(sv).T
                    ax.plot(a, b / 1e6, ".", color=f"C{k}", ms=2, alpha=0.4)
        ax.set_title(f"{ch} (m = {spec.channels[ch]:g})", fontsize=8)
        ax.set_xlabel("mean wind [m/s]", fontsize=8)
        ax.set_ylabel("DEL [MN m]", fontsize=8)
        ax.grid(alpha=0.3)
    for ax in list(axs.flat)[len(chans):]:
        ax.axis("off")
    axs.flat[0].legend(fontsize=6)
    return str(save_figure(fig, out / "del_vs_wind.png"))


def _plot_lifetime_bars(agg: dict[str, Any], ctls: list[str], turbs: list[Any],
                        out: Path) -> list[str]:
    """Lifetime DEL change bars (Pettas fig. 5 / Clemens fig. 7 layout)."""
    from mpc_wt.plotting import pyplot, save_figure

    plt = pyplot()
    spec: CampaignSpec = agg["spec"]
    chans = list(spec.channels)
    made: list[str] = []
    others = [c for c in ctls if c != spec.reference]
    if others:
        width = min(12.0, max(6.0, 0.3 * len(chans) * len(others) * len(turbs) + 2.0))
        fig, ax = plt.subplots(figsize=(width, 4.2), dpi=110)
        w = 0.8 / (len(others) * len(turbs))
        i = 0
        for ctl in others:
            for turb in turbs:
                vals = []
                for ch in chans:
                    r = next((x for x in agg["lifetime"] if x["controller"] == ctl
                              and x["turbulence"] == turb and x["channel"] == ch), None)
                    vals.append(r["change_pct"] if r and r["change_pct"] is not None
                                else np.nan)
                lab = ctl if len(turbs) == 1 else f"{ctl} ({turb})"
                ax.bar(np.arange(len(chans)) + (i - (len(others) * len(turbs) - 1) / 2) * w,
                       vals, w, label=lab, color=f"C{ctls.index(ctl)}",
                       alpha=1.0 if turbs.index(turb) == 0 else 0.55)
                i += 1
        ax.axhline(0, color="k", lw=0.8)
        ax.set_xticks(np.arange(len(chans)))
        ax.set_xticklabels(chans, rotation=35, ha="right", fontsize=7)
        ax.set_ylabel(f"lifetime DEL change vs {spec.reference} [%]")
        ax.legend(fontsize=7)
        ax.grid(alpha=0.3, axis="y")
        made.append(str(save_figure(fig, out / "lifetime_del.png")))
    return made


def _plot_series(agg: dict[str, Any], root: Path, turb0: Any
                 ) -> tuple[dict[tuple[str, float], list[Any]], float, float]:
    """The stored time series at the CS and PSD winds (Do fig. 4 / Madsen fig. 8)."""
    from mpc_wt.simulation.results import ClosedLoopResult

    spec: CampaignSpec = agg["spec"]
    winds = sorted({r.wind_mps for r in agg["fatigue_rows"]})

    def near(target: float) -> float:
        return min(winds, key=lambda v: abs(v - target))

    cs_w = near(float(spec.report.get("cs_wind", 18.0)))
    psd_w = near(float(spec.report.get("psd_wind", 18.0)))
    series: dict[tuple[str, float], list[tuple[np.ndarray, dict[str, np.ndarray]]]] = \
        defaultdict(list)
    for r in agg["fatigue_rows"]:
        if r.turbulence == turb0 and r.wind_mps in (cs_w, psd_w) and r.file:
            try:
                res = ClosedLoopResult.load(root / r.file)
            except Exception:  # noqa: BLE001 - a lost file only drops it from the plot
                continue
            k = res.t >= res.t[0] + spec.transient
            series[(r.controller, r.wind_mps)].append(
                (res.t[k], {n: res.channel(n)[k] for n in ("tower_base_fa_moment", "gen_power",
                                                            "flap_moment_1", "rotor_speed")}))
    return series, cs_w, psd_w


def _plot_cs_psd(agg: dict[str, Any], ctls: list[str], series: dict[tuple[str, float], Any],
                 cs_w: float, psd_w: float, turb0: Any, out: Path) -> list[str]:
    """CS ellipses and PSDs at one wind, mean over seeds."""
    from mpc_wt.plotting import plot_cs_ellipses, pyplot, save_figure

    plt = pyplot()
    made = []
    items = []
    for ctl in ctls:
        runs = series.get((ctl, cs_w), [])
        if runs:
            load = np.concatenate([c["tower_base_fa_moment"] for _, c in runs])
            powr = np.concatenate([c["gen_power"] for _, c in runs])
            items.append((ctl, cs_measures(load, powr), load, powr))
    if items:
        made.append(str(plot_cs_ellipses(items, out / "cs_ellipses.png")))
    fig, axs = plt.subplots(1, 2, figsize=(11, 4.0), dpi=110)
    frot = None
    for k, ctl in enumerate(ctls):
        runs = series.get((ctl, psd_w), [])
        for ax, ch in zip(axs, ("flap_moment_1", "tower_base_fa_moment")):
            spectra = []
            for t, c in runs:
                fs = 1.0 / float(np.median(np.diff(t)))
                spectra.append(psd(c[ch], fs, nperseg=min(8192, t.size)))
                frot = float(c["rotor_speed"].mean()) / (2 * math.pi)
            if spectra:
                f = spectra[0][0]
                p = np.mean([s[1] for s in spectra if s[1].shape == spectra[0][1].shape], axis=0)
                ax.loglog(f[1:], p[1:], lw=0.9, color=f"C{k}", label=ctl)
    for ax, ch in zip(axs, ("blade-1 flap moment", "tower-base fore-aft moment")):
        if frot:
            for n in (1, 3, 6):
                ax.axvline(n * frot, color="0.5", ls=":", lw=0.8)
        ax.set_title(f"{ch}, {psd_w:g} m/s ({turb0}), mean over seeds", fontsize=9)
        ax.set_xlabel("frequency [Hz]")
        ax.set_ylabel("PSD [(N m)^2/Hz]")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7)
    made.append(str(save_figure(fig, out / "psd.png")))
    return made


def _plot_sweep(agg: dict[str, Any], turb0: Any, out: Path) -> list[str]:
    """Lifetime DEL against APC frequency (Clemens fig. 8 layout)."""
    from mpc_wt.plotting import pyplot, save_figure

    plt = pyplot()
    spec: CampaignSpec = agg["spec"]
    chans = list(spec.channels)
    made: list[str] = []
    if agg["sweep"]:
        fig, ax = plt.subplots(figsize=(6.5, 4.0), dpi=110)
        for j, ch in enumerate(chans):
            pts = sorted((r["apc_frequency_Hz"], r["change_pct"]) for r in agg["sweep"]
                         if r["channel"] == ch and r["turbulence"] == turb0
                         and r["change_pct"] is not None)
            if pts:
                f, c = np.array(pts).T
                ax.plot(f, c, "o-", color=f"C{j % 10}", label=ch, ms=4)
        ax.axhline(0, color="k", lw=0.8)
        ax.set_xlabel("APC frequency f_r [Hz]")
        ax.set_ylabel(f"lifetime DEL change vs {spec.reference} [%]")
        ax.set_title("Lifetime DEL against APC frequency (Clemens fig. 8 layout)", fontsize=9)
        ax.legend(fontsize=6, ncol=2)
        ax.grid(alpha=0.3)
        made.append(str(save_figure(fig, out / "apc_sweep.png")))
    return made


def make_report(root: str | Path, out: str | Path | None = None) -> Path:
    """Write the tables (CSV), the plots (PNG) and ``report.md`` of a campaign directory.

    Parameters
    ----------
    root : str or Path
        The campaign directory.
    out : str or Path, optional
        The report folder (default ``root/report``).

    Returns
    -------
    Path
        The path of ``report.md``.

    Raises
    ------
    ValueError
        If no case has finished.
    FileNotFoundError
        If ``root`` is not a campaign directory.
    """
    root = Path(root)
    agg = aggregate(root)
    out = Path(out) if out else root / "report"
    out.mkdir(parents=True, exist_ok=True)
    for name in ("short_term", "per_wind", "lifetime", "aep", "pitch", "cs", "extension",
                 "sweep", "outliers", "ultimate", "governing", "signoff"):
        if agg[name]:
            fname = {"short_term": "short_term_del", "per_wind": "del_by_wind",
                     "lifetime": "lifetime_del"}.get(name, name)
            _write_csv(out / f"{fname}.csv", agg[name])
    plots = _plots(agg, root, out)
    paper = _paper_rows(agg)
    if paper:
        _write_csv(out / "paper_comparison.csv", paper)
    md = _md_head(agg, paper) + _md_signoff(agg) + _md_loads(agg) + _md_more(agg)
    md += ["Plots: " + ", ".join(Path(p).name for p in plots), ""]
    path = out / "report.md"
    tmp = path.with_suffix(".md.tmp")
    tmp.write_text("\n".join(md))
    tmp.replace(path)
    return path


def _paper_rows(agg: dict[str, Any]) -> list[dict[str, Any]]:
    """The spec's ``report.paper`` rows with our numbers next to the paper's."""
    spec: CampaignSpec = agg["spec"]
    paper = []
    for p in spec.report.get("paper", []) or []:
        ours = _ours(agg, p)
        where = p.get("channel") or p.get("measure") or ""
        paper.append({"what": f"{p['metric']} {where}".strip(), "controller": p["controller"],
                      "wind": p.get("wind", "lifetime"),
                      "turbulence": p.get("turbulence", spec.turbulence[0]),
                      "paper": p.get("direction") or float(p["value"]), "ours": ours,
                      "direction_agrees": _agree(ours, p.get("direction")
                                                 or float(p["value"])),
                      "source": p.get("source", ""), "note": p.get("note", "")})
    return paper


def _md_head(agg: dict[str, Any], paper: list[dict[str, Any]]) -> list[str]:
    """Title, the campaign's settings, incomplete cases, the paper table, suspect cases."""
    from mpc_wt._version import __version__

    spec: CampaignSpec = agg["spec"]
    versions = sorted({r.software_version for r in agg["rows"] if r.software_version})
    md = [f"# {spec.report.get('title', 'Campaign ' + spec.name)}", ""]
    if spec.description:
        md += [spec.description.strip(), ""]
    md += [f"Generated by `mpcwt campaign report` (mpc-wt {__version__}; cases computed by "
           f"{', '.join(versions)}) from {len(agg['rows'])} finished cases. Turbine "
           f"{spec.turbine}; " + (
               f"{spec.duration:g} s per case after a {spec.transient:g} s transient; "
               f"turbulence {', '.join(turbulence_tag(t) for t in spec.turbulence)}; "
               f"seeds {list(spec.seeds)}; " if spec.load_cases[0].legacy else
               f"{spec.transient:g} s of transient before each case; ")
           + f"shear {spec.shear_exponent:g}; wind distribution {spec.wind_distribution}; "
           f"lifetime {spec.lifetime_years:g} years; reference controller "
           f"`{spec.reference}`.", ""]
    if not spec.load_cases[0].legacy:
        md += ["Load cases (IEC 61400-1 ed. 3, class "
               f"{spec.iec_class}; times after each case's transient):", "",
               _md([_load_case_row(lc) for lc in spec.load_cases],
                   ["dlc", "condition", "winds", "runs", "family", "fatigue", "length",
                    "events"],
                   ["DLC", "wind condition", "winds [m/s]", "seeds / signs", "family",
                    "fatigue", "length [s]", "supervisor"]), ""]
    if agg["incomplete"]:
        md += ["**Incomplete:** " + "; ".join(agg["incomplete"]) + " (failed or not run; "
               "`mpcwt campaign status` lists them).", ""]
    if paper:
        md += ["## Ours next to the paper", "",
               _md(paper, ["what", "controller", "wind", "turbulence", "paper", "ours",
                           "direction_agrees", "source", "note"],
                   ["quantity", "controller", "wind [m/s]", "turbulence", "paper", "ours",
                    "same direction", "source", "note"]), ""]
    if agg["outliers"]:
        md += ["## Suspect cases", "", f"Seeds whose DEL is more than {OUTLIER_RATIO:g}x the "
               "median of their wind bin; they are kept in every table (look at their time "
               "series in `cases/`):", "",
               _md(agg["outliers"], ["controller", "turbulence", "wind_mps", "seed", "channel",
                                     "del", "ratio_to_median"]), ""]
    if spec.report.get("notes"):
        md += ["## Where we differ, and why", "", str(spec.report["notes"]).strip(), ""]
    return md


def _load_case_row(lc: Any) -> dict[str, Any]:
    """A load case as a row of the report's head."""
    runs = (f"signs {', '.join(f'{g:+d}' for g in lc.signs)}" if lc.deterministic
            else f"{len(lc.seeds)} seeds")
    return {"dlc": lc.dlc, "condition": f"{lc.condition.upper()} "
                                         f"({', '.join(map(turbulence_tag, lc.turbulence))})",
            "winds": ", ".join(f"{v:g}" for v in lc.winds), "runs": runs, "family": lc.family,
            "fatigue": "yes" if lc.fatigue else "", "length": f"{lc.duration:g}",
            "events": ", ".join(f"{k} {v:g}" for k, v in lc.supervisor.items()
                                if v is not None)
            + (f"; event at {lc.event_at:g} s" if lc.deterministic else "")}


def _md_loads(agg: dict[str, Any]) -> list[str]:
    """Lifetime DEL, DEL per wind, energy and pitch."""
    return ["## Lifetime DEL", "", "m-power mean over the wind bins weighted by the wind "
            "distribution (Clemens eq 18); change against the reference over the winds both "
            "ran.", "",
            _md(agg["lifetime"], ["controller", "turbulence", "channel", "m", "winds",
                                  "lifetime_del_MNm", "change_pct"],
                ["controller", "turbulence", "channel", "m", "winds [m/s]",
                 "lifetime DEL [MN m]", "change [%]"]), "", "![lifetime DEL](lifetime_del.png)",
            "", "## DEL per mean wind", "", "![DEL vs wind](del_vs_wind.png)", "",
            "Per wind and channel (m-power mean over seeds) in `del_by_wind.csv`; per seed in "
            "`short_term_del.csv`.", "", "## Energy and pitch", "",
            _md(agg["aep"], ["controller", "turbulence", "aep_MWh", "change_pct"],
                ["controller", "turbulence", "AEP [MWh]", "change [%]"]), "",
            _md(agg["pitch"], ["controller", "turbulence", *_PITCH,
                               *[f"{k}_change_pct" for k in _PITCH]],
                ["controller", "turbulence", "travel [deg/run]", "rate std [deg/s]",
                 "acc std [deg/s^2]", "travel [%]", "rate std [%]", "acc std [%]"]), ""]


def _md_signoff(agg: dict[str, Any]) -> list[str]:
    """Fatigue and ultimate loads side by side with the overspeed margin and the pitch-rate
    demand, one row per controller (campaigns with load cases)."""
    spec: CampaignSpec = agg["spec"]
    if not agg["signoff"]:
        return []
    rows = []
    for c in spec.controllers:
        so = [r for r in agg["signoff"] if r["controller"] == c.name]
        if not so:
            continue
        row: dict[str, Any] = {"controller": c.name}
        for ch in spec.channels:
            life = [r["change_pct"] for r in agg["lifetime"] if r["controller"] == c.name
                    and r["channel"] == ch]
            gov = [r for r in agg["governing"] if r["controller"] == c.name
                   and r["channel"] == ch]
            row[f"{ch}_del"] = life[0] if life else None
            row[f"{ch}_ult"] = gov[0]["change_pct"] if gov else None
            row[f"{ch}_dlc"] = gov[0]["dlc"] if gov else None
        w = [r for r in so if r.get("rotor_speed_max_rel") is not None]
        top = max(w, key=lambda r: r["rotor_speed_max_rel"]) if w else None
        row["speed_max"] = top["rotor_speed_max_rel"] if top else None
        row["speed_dlc"] = top["dlc"] if top else None
        margins = [r["overspeed_margin_pct"] for r in so if r["overspeed_margin_pct"] is not None]
        row["margin"] = min(margins) if margins else None
        row["stops"] = sum(r["overspeed_stops"] for r in so)
        rates = [r["pitch_rate_max_rel"] for r in so if r.get("pitch_rate_max_rel") is not None]
        row["rate"] = max(rates) if rates else None
        row["failed"] = sum(r["failed"] for r in so)
        rows.append(row)
    keys = ["controller", *[f"{ch}_{k}" for ch in spec.channels for k in ("del", "ult", "dlc")],
            "speed_max", "speed_dlc", "margin", "stops", "rate", "failed"]
    heads = ["controller", *[f"{ch} {k}" for ch in spec.channels
                             for k in ("lifetime DEL [%]", "design load [%]", "governing DLC")],
             "rotor speed max / rated", "in DLC", "overspeed margin [% rated]",
             "overspeed stops", "pitch rate max / limit", "failed cases"]
    return ["## Sign-off: fatigue and ultimate loads side by side", "",
            f"Per controller, against `{spec.reference}`: the change of the lifetime DEL "
            "(fatigue load cases) and of the governing design load (the largest design load "
            "over every DLC) per channel, with the DLC that governs; "
            "the largest rotor speed over every case against rated and the smallest margin to "
            "the supervisor's overspeed limit (negative: the limit was crossed, in operation "
            "or during a stop already under way); the cases the overspeed protection stopped; "
            "the largest pitch rate of the cases without a stop (a stop pitches at the maximum "
            "rate by design) against the actuator's limit; failed cases (diverged; "
            "`mpcwt campaign status` lists them).", "", _md(rows, keys, heads), "",
            "![sign-off](signoff.png)", ""]


def _md_ultimate(agg: dict[str, Any]) -> list[str]:
    """The governing design loads, the per-DLC ultimate loads and the overspeed and pitch-rate
    demand per DLC."""
    if not agg["ultimate"]:
        return []
    extra = any("extrapolated_max" in r for r in agg["ultimate"])
    md = ["## Ultimate loads", "",
          "Each case's extremes after its transient; characteristic: per mean wind the mean "
          "over seeds of each seed's extreme (a deterministic case counts once per sign), the "
          "largest over the winds; design: times the partial safety factor of the DLC's family "
          "(IEC 61400-1 ed. 3 table 3: normal 1.35, abnormal 1.1); extrapolated: the 50-year "
          "load of a DLC's maxima (Gumbel per wind, weighted by the wind distribution; factor "
          "1.25). Governing: the largest design load in magnitude over the DLCs.", "",
          _md(agg["governing"], ["controller", "channel", "design", "side", "dlc", "case",
                                 "change_pct"],
              ["controller", "channel", "governing design load", "max/min", "DLC",
               "case of the extreme", "change [%]"]), "",
          "Per DLC (all columns in `ultimate.csv`):", "",
          _md(agg["ultimate"], ["controller", "dlc", "family", "channel", "max", "max_case",
                                "characteristic_max", "wind_max", "design_max", "min",
                                "design_min", *(["extrapolated_max", "design_extrapolated_max"]
                                                if extra else [])],
              ["controller", "DLC", "family", "channel", "max", "its case",
               "characteristic max", "at wind [m/s]", "design max", "min", "design min",
               *(["extrapolated max (50 y)", "design extrapolated"] if extra else [])]), ""]
    if agg["signoff"]:
        md += ["### Overspeed and pitch-rate demand per DLC", "",
               _md(agg["signoff"], ["controller", "dlc", "cases", "failed",
                                    "rotor_speed_max_rel", "rotor_speed_max_case",
                                    "overspeed_margin_pct", "overspeed_stops", "stops",
                                    "pitch_rate_max_degps", "pitch_rate_max_rel",
                                    "pitch_rate_limit_s"],
                   ["controller", "DLC", "cases", "failed", "rotor speed max / rated",
                    "its case", "overspeed margin [% rated]", "overspeed stops",
                    "stop sequences", "pitch rate max [deg/s]", "of the limit",
                    "at the limit [s/case]"]), "", "![ultimate loads](ultimate.png)", ""]
    return md


def _md_more(agg: dict[str, Any]) -> list[str]:
    """Lifetime extension, CS1-CS5 and the APC sweep."""
    md: list[str] = []
    md += _md_ultimate(agg)
    if agg["extension"]:
        md += ["## Lifetime extension (retrofit after 15 years, 5 more at the new rate; "
               "Pettas and Cheng eq 1)", "",
               _md(agg["extension"], ["controller", "turbulence", "channel", "m",
                                      "damage_15_5", "extension_years"],
                   ["controller", "turbulence", "channel", "m", "damage after 20 y",
                    "extension [years]"]), ""]
    reg = ["rotor_speed_std_rad_s", "power_std_W", "flap_1_harmonics_1P",
           "flap_1_harmonics_3P"]
    md += ["## Regulation and 1P content", "",
           "Wind-weighted like the pitch duty; changes against the reference. The nP content "
           "is the variance of the blade-1 flap moment in a band around n times the rotor "
           "frequency.", "",
           _md(agg["regulation"], ["controller", "turbulence", *reg,
                                   *[f"{k}_change_pct" for k in reg]],
               ["controller", "turbulence", "speed std [rad/s]", "power std [W]",
                "flap 1P [(N m)^2]", "flap 3P [(N m)^2]", "speed std [%]", "power std [%]",
                "flap 1P [%]", "flap 3P [%]"]), ""]
    md += ["## CS1-CS5 per wind (Do et al.)", "",
           _md(agg["cs"], ["controller", "turbulence", "wind_mps", "cs1", "cs2", "cs3", "cs4",
                           "cs5", "cs1_change_pct", "cs2_change_pct"],
               ["controller", "turbulence", "wind [m/s]", "CS1 [N m]", "CS2 [W]", "CS3 [N m]",
                "CS4 [W]", "CS5 [deg]", "CS1 [%]", "CS2 [%]"]), "",
           "![CS ellipses](cs_ellipses.png)", "", "![PSD](psd.png)", ""]
    if agg["sweep"]:
        md += ["## APC frequency sweep", "", "![APC sweep](apc_sweep.png)", "",
               _md(agg["sweep"], ["controller", "apc_frequency_Hz", "turbulence",
                                  "channel", "lifetime_del", "change_pct"]), ""]
    return md

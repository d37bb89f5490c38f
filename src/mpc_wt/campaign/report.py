"""A campaign's report: its aggregate (:mod:`.aggregate`) as Markdown and CSV tables, with the
figures of :mod:`.plots`.

Per controller, turbulence and channel: short-term DELs per wind bin and seed; the DEL per bin
over seeds (m-power mean of equal-length runs); the lifetime DEL, the m-power mean weighted by
the wind distribution (Clemens et al. eq 18, :func:`mpc_wt.assessment.fatigue.lifetime_del`); AEP from the
mean power per bin; pitch duty weighted the same way (Pettas and Cheng sec. 4); CS1-CS5 per bin
(Do et al. eqs 21-26); lifetime extension for a retrofit after 15 of 20 years (Pettas and Cheng
eq 1). Every comparison with the reference controller is made over the winds both ran.
Tables go to CSV and Markdown, figures to PNG, and ``report.paper`` rows of the spec put our
numbers next to the paper's.
"""
from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from mpc_wt.campaign.aggregate import OUTLIER_RATIO, PITCH_METRICS, aggregate
from mpc_wt.campaign.plots import campaign_plots
from mpc_wt.campaign.spec import CampaignSpec, turbulence_tag

__all__ = ["make_report"]


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
    for r in rows:        # keys with a leading underscore are the aggregate's, not the table's
        cols += [k for k in r if k not in cols and not k.startswith("_")]
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
    plots = campaign_plots(agg, root, out)
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
    if agg.get("failed"):
        md += ["## Failed cases", "", "Left out of every table; `mpcwt campaign status DIR "
               "--failed` prints their tracebacks.", "",
               _md(agg["failed"], ["case_id", "controller", "wind_mps", "reason"],
                   ["case", "controller", "wind [m/s]", "reason"]), ""]
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
            else f"{len(lc.wind_files)} wind files" if lc.wind_files
            else f"{len(lc.seeds)} seeds")
    return {"dlc": lc.dlc, "condition": f"{lc.condition.upper()} "
                                         f"({', '.join(map(turbulence_tag, lc.turbulence))})",
            "winds": ", ".join(f"{v:g}" for v in lc.winds), "runs": runs, "family": lc.family,
            "fatigue": "yes" if lc.fatigue else "", "length": f"{lc.duration:g}",
            "events": ", ".join(f"{k} {v:g}" if isinstance(v, (int, float)) else f"{k} {v}"
                                for k, v in lc.supervisor.items() if v is not None)
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
            _md(agg["pitch"], ["controller", "turbulence", *PITCH_METRICS,
                               *[f"{k}_change_pct" for k in PITCH_METRICS]],
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
            row[f"{ch}_del"] = life[0] if life else None
        for ch in spec.ultimate:
            gov = [r for r in agg["governing"] if r["controller"] == c.name
                   and r["channel"] == ch]
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
    # per channel its lifetime DEL, then its governing design load where it has one; then the
    # design loads of the ultimate channels that are not fatigue channels
    cols = [(ch, k) for ch in spec.channels for k in ("del", "ult", "dlc")
            if k == "del" or ch in spec.ultimate]
    cols += [(ch, k) for ch in spec.ultimate if ch not in spec.channels for k in ("ult", "dlc")]
    names = {"del": "lifetime DEL [%]", "ult": "design load [%]", "dlc": "governing DLC"}
    keys = ["controller", *[f"{ch}_{k}" for ch, k in cols],
            "speed_max", "speed_dlc", "margin", "stops", "rate", "failed"]
    heads = ["controller", *[f"{ch} {names[k]}" for ch, k in cols],
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


def _unit_of(channel: str) -> str:
    """The SI unit of a result channel (the plant's outputs and states; derived moments N m)."""
    import linearize

    table = {**dict(zip(linearize.STATE_NAMES, linearize.STATE_UNITS)),
             **dict(zip(linearize.OUTPUT_NAMES, linearize.OUTPUT_UNITS))}
    if channel in table:
        return table[channel]
    return "N m" if "moment" in channel or channel.startswith("shaft_bending") else "-"


def _md_ultimate(agg: dict[str, Any]) -> list[str]:
    """The governing design loads, the per-DLC ultimate loads and the overspeed and pitch-rate
    demand per DLC; every load with its channel's unit."""
    if not agg["ultimate"]:
        return []
    for rows in (agg["governing"], agg["ultimate"]):
        for r in rows:
            r.setdefault("unit", _unit_of(str(r.get("channel", ""))))
    extra = any("extrapolated_max" in r for r in agg["ultimate"])
    md = ["## Ultimate loads", "",
          "Each case's extremes after its transient; characteristic: per mean wind the mean "
          "over seeds of each seed's extreme (a deterministic case counts once per sign), the "
          "largest over the winds; design: times the partial safety factor of the DLC's family "
          "(IEC 61400-1 ed. 3 table 3: normal 1.35, abnormal 1.1); extrapolated: the 50-year "
          "load of a DLC's maxima (Gumbel per wind, weighted by the wind distribution; factor "
          "1.25). Governing: the largest design load in magnitude over the DLCs; its change "
          "against the reference's with the standard error the seeds' scatter leaves on it "
          "(paired by case where both come from the same DLC and wind).", "",
          _md(agg["governing"], ["controller", "channel", "unit", "design", "side", "dlc",
                                 "case", "change_pct", "change_se_pct"],
              ["controller", "channel", "unit", "governing design load", "max/min", "DLC",
               "case of the extreme", "change [%]", "standard error [%]"]), "",
          "Per DLC (all columns in `ultimate.csv`):", "",
          _md(agg["ultimate"], ["controller", "dlc", "family", "channel", "unit", "max",
                                "max_case",
                                "characteristic_max", "wind_max", "design_max", "min",
                                "design_min", *(["extrapolated_max", "design_extrapolated_max"]
                                                if extra else [])],
              ["controller", "DLC", "family", "channel", "unit", "max", "its case",
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

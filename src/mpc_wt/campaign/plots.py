"""The figures of a campaign's report (PNG): DEL against mean wind, lifetime DEL changes, CS
ellipses and spectra at a chosen wind, and lifetime DEL against the APC frequency.
"""
from __future__ import annotations

import math
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

from mpc_wt.assessment.performance import cs_measures, psd
from mpc_wt.campaign.spec import CampaignSpec

__all__ = ["campaign_plots"]


def campaign_plots(agg: dict[str, Any], root: Path, out: Path) -> list[str]:
    """Every figure of the report, as PNG in ``out``.

    Parameters
    ----------
    agg : dict
        The campaign's aggregate (:func:`mpc_wt.campaign.aggregate.aggregate`).
    root : Path
        The campaign directory (the case files the spectra are read from).
    out : Path
        Where the figures go.

    Returns
    -------
    list of str
        The files written.
    """
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
            res = ClosedLoopResult.load(root / r.file)      # checked against its checksum
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

"""What a tuning writes: best design and its gain table, trials, Pareto front, report."""
from __future__ import annotations

import inspect
import json
import logging
import math
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from .run import REPORT_METRICS, TuneOutcome, pareto_front, write_trials_csv
from .spec import TuneSpec

__all__ = ["write_outputs", "export_design"]

log = logging.getLogger(__name__)


def _design_kwargs(spec: TuneSpec, params: Mapping[str, float]) -> tuple[Any, dict] | None:
    """The kind's gain synthesis and its arguments for a design (None: the kind has none)."""
    import linearize

    from ..controllers import resolve

    sel = resolve(spec.kind)
    fn = sel.base.design
    if fn is None:
        return None
    opts = sel.options(spec.options(params))[0]
    given = opts.to_dict()
    winds = [float(v) for v in spec.campaign_raw["winds"]]
    kw: dict[str, Any] = {"winds": winds}
    if hasattr(opts, "lqr_weights"):
        turbine = linearize.load_turbine(spec.campaign_raw.get("turbine", "nrel5mw"))
        region = "II" if max(winds) < linearize.rated_wind_speed(turbine) else "III"
        kw["weights"], kw["input_weights"] = opts.lqr_weights(region)
    kw.update({k: v for k, v in given.items() if v is not None})
    if "loop_gain_1p" in given:
        kw["loop_gain"] = given["loop_gain_1p"]
    wanted = inspect.signature(fn).parameters
    return fn, {k: v for k, v in kw.items() if k in wanted}


def export_design(spec: TuneSpec, params: Mapping[str, float], out: Path) -> list[Path]:
    """The gain table of a design (``design.json``, CSV, JSON and, for a baseline, ROSCO) in
    ``out``; nothing for a kind without a gain synthesis (its options are in best.json).

    Parameters
    ----------
    spec : TuneSpec
    params : mapping
        The design's parameters.
    out : Path

    Returns
    -------
    list of Path
    """
    import linearize

    from ..export import export, save_design

    got = _design_kwargs(spec, params)
    if got is None:
        return []
    fn, kw = got
    turbine = linearize.load_turbine(spec.campaign_raw.get("turbine", "nrel5mw"))
    doc, _note = fn(turbine, **kw)
    files = [save_design(doc, out)]
    for fmt in ("csv", "json") + (("rosco",) if doc.get("kind") == "baseline" else ()):
        try:
            files += export(out, fmt, out, turbine)
        except ValueError as err:       # a format the table's kind does not support
            log.info("tuning: no %s export of %s: %s", fmt, doc.get("kind"), err)
    return files


def _pct(v: float | None) -> str:
    return "-" if v is None or not math.isfinite(v) else f"{100.0 * (v - 1.0):+.1f} %"


def _rows(spec: TuneSpec, outcome: TuneOutcome) -> list[str]:
    names = ["objective"] + [m for m, _ in spec.objective] + \
        [c.metric for c in spec.constraints] + list(REPORT_METRICS)
    names = list(dict.fromkeys(names))
    cols = [(f"{d} ({s})", tab.get(d, {})) for s, tab in (("tuning seeds", outcome.tuning),
                                                         ("held-out seeds", outcome.holdout))
            for d in ("hand-set", "tuned") if tab]
    lines = ["| measure (change against the reference) | " + " | ".join(c for c, _ in cols)
             + " |", "|---|" + "---|" * len(cols)]
    for n in names:
        lines.append(f"| {n} | " + " | ".join(_pct(m.get(n)) for _, m in cols) + " |")
    return lines


def _zoom(ax: Any, pts: np.ndarray, extra: list[Any]) -> None:
    """Axis limits over the trials up to 1.5x their 80th percentile (and the reference and
    hand-set): a few diverging designs would otherwise squash the front into a corner."""
    if pts.shape[0] < 3:
        return
    for col, setter in ((1, ax.set_xlim), (0, ax.set_ylim)):
        v = np.concatenate([pts[:, col], [1.0], [e for e in extra[1 - col:2 - col]
                                                 if e is not None]])
        hi = min(float(v.max()), 1.5 * float(np.percentile(v, 80)))
        lo = float(v.min())
        pad = 0.05 * (hi - lo) if hi > lo else 0.05
        setter(lo - pad, hi + pad)


def _plot_pareto(spec: TuneSpec, outcome: TuneOutcome, path: Path) -> Path | None:
    """Objective, and each of its measures, against each constraint measure: every completed
    trial (feasible or not), the non-dominated front of the pair, the bound, hand-set, best."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    done = [t for t in outcome.result.trials if t.state == "COMPLETE"]
    if not done:
        return None
    xs = [c.metric for c in spec.constraints] or ["rotor_speed_std", "pitch_travel"]
    ys = list(dict.fromkeys(["objective"] + [m for m, _ in spec.objective]))
    fig, axes = plt.subplots(len(ys), len(xs), figsize=(4.6 * len(xs), 3.4 * len(ys)),
                             squeeze=False)
    ok = np.array([t.feasible for t in done])
    hand = outcome.tuning.get("hand-set", {})
    b = outcome.result.best
    for r, y in enumerate(ys):
        for c, x in enumerate(xs):
            ax = axes[r][c]
            pts = np.array([[t.metrics.get(y, math.nan), t.metrics.get(x, math.nan)]
                            for t in done], float)
            ax.scatter(pts[~ok, 1], pts[~ok, 0], c="0.7", s=16, label="infeasible")
            ax.scatter(pts[ok, 1], pts[ok, 0], c="tab:blue", s=16, label="feasible")
            good = np.all(np.isfinite(pts), axis=1)
            if good.sum() >= 2:
                front = np.flatnonzero(good)[pareto_front(pts[good][:, ::-1])]
                ax.plot(pts[front, 1], pts[front, 0], "-", c="tab:orange", lw=1.2,
                        label="Pareto front")
            for con in spec.constraints:
                if con.metric == x:
                    ax.axvline(con.upper, ls="--", c="k", lw=0.8, label="bound")
            if x in hand and y in hand:
                ax.plot(hand[x], hand[y], "D", c="k", label="hand-set")
            if b is not None:
                ax.plot(b.metrics.get(x, math.nan), b.metrics.get(y, math.nan), "*",
                        c="tab:red", ms=13, label="best")
            ax.axhline(1.0, c="0.5", lw=0.6)
            _zoom(ax, pts[good], [hand.get(x), hand.get(y)])
            ax.set_xlabel(x if x in ("pitch_rate_limit_hits", "pitch_rate_limit_s",
                                     "pitch_rate_max_degps") else f"{x} / reference")
            ax.set_ylabel(f"{y} / reference")
            ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=7)
    fig.suptitle(f"{spec.name}: {len(done)} completed trials (ratios to "
                 f"{spec.reference['name']})")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def write_outputs(spec: TuneSpec, outcome: TuneOutcome, out: Path) -> list[Path]:
    """best.json, trials.csv, pareto.png, report.md and best/ (gain table) in ``out``."""
    res = outcome.result
    files = [write_trials_csv(res, out / "trials.csv")]
    best = res.best
    doc: dict[str, Any] = {
        "name": spec.name, "controller": spec.kind, "reference": spec.reference,
        "trials": len(res.trials), "completed": len(res.completed),
        "evaluated_now": res.evaluated, "wall_s": outcome.wall_s,
        "best": None if best is None else {
            "trial": best.number, "params": best.params, "options": spec.options(best.params),
            "objective": best.value, "metrics": best.metrics},
        "tuning": outcome.tuning, "holdout": outcome.holdout,
        "holdout_seeds": list(spec.holdout_seeds)}
    (out / "best.json").write_text(json.dumps(doc, indent=1))
    files.append(out / "best.json")
    png = _plot_pareto(spec, outcome, out / "pareto.png")
    if png:
        files.append(png)
    if best is not None:
        try:
            files += export_design(spec, best.params, out / "best")
        except Exception as err:  # noqa: BLE001 - the search's results stay written
            log.warning("tuning: the best design's gain table could not be written: %s", err)
    lines = [f"# Tuning {spec.name}: {spec.kind} against {spec.reference['name']}", "",
             spec.description.strip(), "",
             f"{len(res.trials)} trials ({len(res.completed)} completed, "
             f"{sum(t.feasible for t in res.trials)} feasible, {res.evaluated} evaluated in "
             f"the last run, {outcome.wall_s:.0f} s); sampler {spec.sampler}, seed {spec.seed}. "
             f"Objective: " + " + ".join(f"{w:g} x {m}" for m, w in spec.objective)
             + " (weighted mean of ratios to the reference); constraints: "
             + (", ".join(f"{c.metric} <= {c.upper:g}" for c in spec.constraints) or "none")
             + ".", ""]
    if best is None:
        lines += ["**No trial met the constraints.**", ""]
    else:
        lines += [f"Best: trial {best.number}, " + ", ".join(
            f"{k} = {v:.4g}" for k, v in best.params.items()) + "; gain table in `best/` "
            "(for kinds with a synthesis).", ""]
    lines += _rows(spec, outcome) + ["", "![Pareto](pareto.png)", ""]
    failed = [t for t in res.trials if t.state == "FAIL"]
    if failed:
        lines += [f"Failed trials ({len(failed)}): " + "; ".join(
            f"{t.number} ({(t.error or '')[:90]})" for t in failed), ""]
    (out / "report.md").write_text("\n".join(lines))
    files.append(out / "report.md")
    return files

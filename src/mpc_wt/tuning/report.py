"""What a tuning writes: best design and its gain table, trials, Pareto front, report."""
from __future__ import annotations

import inspect
import logging
import math
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from mpc_wt.io.json_text import write_json
from mpc_wt.tuning.outcome import REPORT_METRICS, TuneOutcome, pareto_front, write_trials_csv
from mpc_wt.tuning.spec import TuneSpec

__all__ = ["write_outputs", "export_design"]

log = logging.getLogger(__name__)


def _design_kwargs(spec: TuneSpec, params: Mapping[str, float]) -> tuple[Any, dict] | None:
    """The kind's gain synthesis and its arguments for a design (None: the kind has none)."""
    import linearize
    from mpc_wt.registry.registry import resolve

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
    from mpc_wt.io.gain_tables import export, save_design

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


def _plot_pareto(spec: TuneSpec, outcome: TuneOutcome, path: Path) -> Path | None:
    """Objective, and each of its measures, against each constraint measure
    (:func:`mpc_wt.plotting.plot_pareto`)."""
    from mpc_wt.plotting import plot_pareto

    done = [t for t in outcome.result.trials if t.state == "COMPLETE"]
    if not done:
        return None
    xs = [c.metric for c in spec.constraints] or ["rotor_speed_std", "pitch_travel"]
    ys = list(dict.fromkeys(["objective"] + [m for m, _ in spec.objective]))
    fronts = {}
    for y in ys:
        for x in xs:
            pts = np.array([[t.metrics.get(x, math.nan), t.metrics.get(y, math.nan)]
                            for t in done], float)
            good = np.flatnonzero(np.all(np.isfinite(pts), axis=1))
            fronts[(y, x)] = good[pareto_front(pts[good])] if good.size >= 2 else good[:0]
    b = outcome.result.best
    marks = {"hand-set": outcome.tuning.get("hand-set", {}),
             "best": b.metrics if b is not None else {}}
    absolute = {"pitch_rate_limit_hits", "pitch_rate_limit_s", "pitch_rate_max_degps"}
    return plot_pareto([t.metrics for t in done], [t.feasible for t in done], xs, ys, fronts,
                       {c.metric: c.upper for c in spec.constraints}, marks, path,
                       title=f"{spec.name}: {len(done)} completed trials (ratios to "
                             f"{spec.reference['name']})", absolute=absolute)


def write_outputs(spec: TuneSpec, outcome: TuneOutcome, out: Path) -> list[Path]:
    """Write best.json, trials.csv, pareto.png, report.md and best/ (gain table).

    Parameters
    ----------
    spec : TuneSpec
    outcome : TuneOutcome
    out : Path
        The tuning directory.

    Returns
    -------
    list of Path
        The files written.
    """
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
    write_json(out / "best.json", doc)
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
             + (", ".join(str(c) for c in spec.constraints) or "none")
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

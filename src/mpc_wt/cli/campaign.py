"""``mpcwt campaign run|status|report`` (load-case campaigns on Dask), ``mpcwt tune`` (design
parameters optimized over load cases) and ``mpcwt bench mpc``."""
from __future__ import annotations

import argparse
import logging
from pathlib import Path
from typing import Any

from mpc_wt.campaign.runner import ENGINES
from mpc_wt.cli.common import check_out_folder, to_json
from mpc_wt.errors import UsageError

__all__ = ["add_parsers"]

log = logging.getLogger(__name__)


def add_parsers(sub: Any) -> None:
    """Add ``campaign``, ``tune`` and ``bench`` to the subcommands.

    Parameters
    ----------
    sub : argparse subparsers action
        Of the top-level parser.
    """
    p = sub.add_parser("bench", help="benchmarks")
    bench = p.add_subparsers(dest="bench_command", required=True)
    q = bench.add_parser("mpc", help="MPC QP solver comparison on a closed-loop run (18 m/s)")
    q.add_argument("--steps", type=int, default=3000, help="closed-loop steps (default 3000)")
    q.add_argument("--json", action="store_true")
    q.add_argument("--plot", help="PNG of the solve times")
    q.set_defaults(func=_bench_mpc)

    p = sub.add_parser("campaign", help="load-case campaigns (DLC 1.2) on Dask: run, status, "
                                        "report")
    camp = p.add_subparsers(dest="campaign_command", required=True)
    q = camp.add_parser("run", help="run (or resume) a campaign spec")
    q.add_argument("spec", help="campaign YAML file")
    q.add_argument("--workers", type=int, default=None,
                   help="local worker processes (default: one per core)")
    q.add_argument("--scheduler", default=None,
                   help="address of a running Dask scheduler, tcp://HOST:PORT")
    q.add_argument("--out", default=None, help="campaign directory (default campaigns/NAME)")
    q.add_argument("--engine", choices=ENGINES, default="dask",
                   help="dask (default), a plain process pool, or this process")
    q.add_argument("--report", action="store_true", help="write the report when all cases "
                                                         "finished")
    q.add_argument("--quiet", action="store_true", help="no progress bar")
    q.add_argument("--trust", action="store_true",
                   help="run a spec, plugins or libraries that another user wrote (they are "
                        "code; see the docs' Security page)")
    q.set_defaults(func=_run)
    q = camp.add_parser("status", help="cases done, failed, pending of a campaign directory")
    q.add_argument("dir")
    q.add_argument("--failed", action="store_true", help="print the tracebacks of failed cases")
    q.add_argument("--json", action="store_true")
    q.set_defaults(func=_status)
    q = camp.add_parser("report", help="tables (CSV, Markdown) and plots (PNG) of a campaign")
    q.add_argument("dir")
    q.add_argument("--out", default=None, help="report folder (default DIR/report)")
    q.set_defaults(func=_report)

    q = sub.add_parser("tune", help="tune a controller kind's design parameters over load "
                                    "cases (Optuna; resumable)")
    q.add_argument("spec", help="tuning YAML file")
    q.add_argument("--out", default=None, help="tuning directory (default tunings/NAME)")
    q.add_argument("--trials", type=int, default=None, help="total trials (default: the "
                                                            "spec's)")
    q.add_argument("--workers", type=int, default=None,
                   help="local worker processes (default: one per core)")
    q.add_argument("--scheduler", default=None,
                   help="address of a running Dask scheduler, tcp://HOST:PORT")
    q.add_argument("--engine", choices=ENGINES, default="dask")
    q.add_argument("--trust", action="store_true",
                   help="run a spec, plugins or libraries that another user wrote (they are "
                        "code; see the docs' Security page)")
    q.add_argument("--quiet", action="store_true", help="no progress bar")
    q.set_defaults(func=_tune)


def _bench_mpc(args: argparse.Namespace) -> int:
    from mpc_wt.simulation.solver_timing import (
        format_table,
        plot_solver_times,
        run_solver_benchmark,
    )

    if args.steps < 10:
        raise UsageError(f"--steps must be >= 10, got {args.steps}")
    from mpc_wt.run import law_controller

    res = run_solver_benchmark(law_controller, args.steps, progress=not args.json)
    print(to_json(res) if args.json else format_table(res))
    if args.plot:
        plot_solver_times(res, args.plot)
    return 0


def _check_trust(args: argparse.Namespace) -> None:
    """Refuse, before anything of it runs, a spec whose code another user wrote, unless
    ``--trust``."""
    from mpc_wt.campaign.spec import foreign_code

    found = foreign_code(args.spec)
    if found and not args.trust:
        raise UsageError(f"{args.spec}: written by another user: {'; '.join(found)}. A spec's "
                         f"plugins and controller libraries are code that runs with your "
                         f"rights; read them, then give --trust to run them")
    if found:
        log.warning("running code another user wrote (--trust): %s", "; ".join(found))


def _run(args: argparse.Namespace) -> int:
    from mpc_wt.campaign.runner import run_campaign
    from mpc_wt.campaign.spec import load_spec

    if args.scheduler and args.workers:
        raise UsageError("give --workers (local cluster) or --scheduler (running cluster), "
                         "not both")
    check_out_folder("--out", args.out)
    _check_trust(args)
    spec = load_spec(args.spec)
    out = Path(args.out) if args.out else Path("campaigns") / spec.name
    if args.engine == "dask":
        _quiet_dask()
    log.info("campaign %s -> %s", spec.name, out)
    s = run_campaign(spec, out, workers=args.workers, scheduler=args.scheduler,
                     engine=args.engine, progress=not args.quiet)
    print(f"campaign {spec.name}: {s.total} cases; {s.skipped} already finished, "
          f"{s.done} done now ({s.reused} from files already written), {s.failed} failed; "
          f"{s.wall_s:.0f} s wall, {s.cases_per_min:.2f} cases/min ({s.engine}, "
          f"{'scheduler ' + args.scheduler if args.scheduler else f'{s.workers} workers'})")
    print(f"  directory {out}")
    for cid, err in s.failures[:10]:
        print(f"  failed {cid}: {err.splitlines()[0] if err else ''}")
    if s.failed:
        print(f"  tracebacks: mpcwt campaign status {out} --failed; rerun the same command "
              f"to retry failed cases")
    if args.report and not s.failed:
        from mpc_wt.campaign.report import make_report

        rep = make_report(out)
        print(f"  report {rep}")
    return 1 if s.failed else 0


def _status(args: argparse.Namespace) -> int:
    from mpc_wt.campaign.store import CampaignStore

    with CampaignStore(args.dir) as st:
        meta = st.meta()
        rows = st.rows()
        counts = st.counts()
        stray = st.stray_temp_files()
    if args.json:
        print(to_json({"meta": meta, "counts": counts,
                       "cases": [{"case_id": r.case_id, "status": r.status,
                                  "error": r.error, "wall_s": r.wall_s,
                                  "software_version": r.software_version} for r in rows]}))
        return 0
    print(f"campaign {meta.get('name')} in {args.dir}: spec {str(meta.get('spec_hash'))[:12]}, "
          f"last run {meta.get('last_run')}, mpc-wt {meta.get('software_version')}")
    print("  " + ", ".join(f"{k} {v}" for k, v in counts.items() if v or k in ("done",
                                                                              "pending")))
    per: dict[str, list[int]] = {}
    for r in rows:
        d = per.setdefault(r.controller, [0, 0, 0])
        d[0] += 1
        d[1] += r.status == "done"
        d[2] += r.status == "failed"
    print(f"  {'controller':<24} {'done':>6} {'failed':>7} {'cases':>6}")
    for k, (n, d, f) in per.items():
        print(f"  {k:<24} {d:>6} {f:>7} {n:>6}")
    versions = sorted({r.software_version for r in rows if r.software_version})
    if len(versions) > 1:
        print(f"  note: cases were computed by mpc-wt versions {versions}")
    if stray:
        print(f"  {len(stray)} temp files of interrupted writers in {Path(args.dir) / 'cases'} "
              f"(safe to delete when no worker runs)")
    for r in rows:
        if r.status == "failed":
            print(f"  failed {r.case_id}: {(r.error or '').splitlines()[0]}")
            if args.failed and r.traceback:
                print("    " + r.traceback.rstrip().replace("\n", "\n    "))
    return 0


def _report(args: argparse.Namespace) -> int:
    from mpc_wt.campaign.report import make_report

    check_out_folder("--out", args.out)
    rep = make_report(args.dir, out=args.out)
    print(f"report {rep}")
    return 0


def _quiet_dask() -> None:
    try:    # import first: distributed sets its loggers' levels when imported
        import distributed  # noqa: F401
    except ImportError:
        return
    for name in list(logging.root.manager.loggerDict):
        if name.startswith("distributed"):
            logging.getLogger(name).setLevel(logging.ERROR)


def _tune(args: argparse.Namespace) -> int:
    from mpc_wt.tuning.run import tune
    from mpc_wt.tuning.spec import load_tune_spec

    if args.scheduler and args.workers:
        raise UsageError("give --workers (local cluster) or --scheduler (running cluster), "
                         "not both")
    if args.trials is not None and args.trials < 1:
        raise UsageError(f"--trials must be >= 1, got {args.trials}")
    check_out_folder("--out", args.out)
    _check_trust(args)
    spec = load_tune_spec(args.spec)
    out = Path(args.out) if args.out else Path("tunings") / spec.name
    if args.engine == "dask":
        _quiet_dask()
    res = tune(spec, out, engine=args.engine, workers=args.workers, scheduler=args.scheduler,
               n_trials=args.trials, progress=not args.quiet)
    r = res.result
    print(f"tuning {spec.name}: {len(r.trials)} trials ({len(r.completed)} completed, "
          f"{sum(t.feasible for t in r.trials)} feasible; {r.evaluated} run now), "
          f"{res.wall_s:.0f} s")
    if r.best is None:
        print("  no trial met the constraints")
    else:
        print(f"  best trial {r.best.number}: objective {r.best.value:.4f} x the reference; "
              + ", ".join(f"{k} = {v:.4g}" for k, v in r.best.params.items()))
    for label, tab in (("tuning seeds", res.tuning), ("held-out seeds", res.holdout)):
        for name, m in tab.items():
            print(f"  {label:14s} {name:8s} objective {m['objective']:.4f}")
    print(f"  directory {out}: report.md, best.json, trials.csv, pareto.png")
    return 0 if r.best is not None else 1

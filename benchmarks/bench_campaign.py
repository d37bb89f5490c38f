"""Campaign throughput: IEC DLC 1.2 for the baseline on this machine.

The spec is benchmarks/studies/dlc12_baseline.yaml: cut-in to cut-out (3-25 m/s) in 2 m/s
steps, 6 seeds, 600 s after a 60 s transient, class A -- 72 cases. Runs, each into a fresh
campaign directory, wall time from the call to the last commit (cluster start included):

1. Dask, LocalCluster with 2 single-threaded workers, all 72 cases (the headline);
2. on a subset (``--subset-seeds`` seeds, default 2: 24 cases, every wind): a plain
   ``concurrent.futures`` process pool of 2 and Dask with 2 workers (Dask's overhead), and Dask
   with 1 worker (scaling 1 -> 2 workers on the same cases).

Prints wall time, cases per minute, the sum of the cases' own wall times and the parallel
efficiency (sum of case times / (wall x workers)), and writes bench_campaign.json. The first
campaign's directory keeps its report (``--keep``); the others' case files are deleted.

Run:  python benchmarks/bench_campaign.py [--out bench-campaign] [--duration 600]
"""
from __future__ import annotations

import argparse
import json
import platform
import shutil
import time
from pathlib import Path

from mpc_wt.campaign import CampaignStore, load_spec, run_campaign, spec_from_dict
from mpc_wt.campaign.report import make_report

HERE = Path(__file__).parent


def _run(raw: dict, out: Path, engine: str, workers: int) -> dict:
    if out.exists():
        shutil.rmtree(out)
    spec = spec_from_dict(raw)
    s = run_campaign(spec, out, engine=engine, workers=workers, progress=True)
    with CampaignStore(out) as st:
        rows = st.rows()
    case_s = sum(r.wall_s or 0.0 for r in rows)
    res = {"engine": engine, "workers": workers, "cases": s.total, "done": s.done,
           "failed": s.failed, "wall_s": s.wall_s, "cases_per_min": s.cases_per_min,
           "sum_case_s": case_s, "mean_case_s": case_s / max(1, len(rows)),
           "efficiency": case_s / (s.wall_s * workers)}
    print(json.dumps(res))
    return res


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="bench-campaign")
    ap.add_argument("--duration", type=float, default=None, help="override 600 s (quick look)")
    ap.add_argument("--subset-seeds", type=int, default=2)
    ap.add_argument("--skip", default="", help="comma list of runs to skip: dask,pool,scaling")
    args = ap.parse_args()
    base = load_spec(HERE / "studies" / "dlc12_baseline.yaml").raw
    # the throughput figure is the baseline's DLC 1.2 (72 cases); the spec also runs ROSCO
    # for its report
    base["controllers"] = [c for c in base["controllers"] if c == "baseline"]
    if args.duration:
        base["duration"] = args.duration
    root = Path(args.out)
    root.mkdir(parents=True, exist_ok=True)
    skip = set(filter(None, args.skip.split(",")))
    out: dict = {"date": time.strftime("%Y-%m-%d"), "machine": platform.node(),
                 "cores": 2, "spec": base}
    if "dask" not in skip:
        out["dask_2"] = _run(base, root / "dask2", "dask", 2)
        rep = make_report(root / "dask2")
        print("report", rep)
        for f in (root / "dask2" / "cases").glob("*.nc"):
            f.unlink()
    sub = {**base, "seeds": args.subset_seeds}
    if "pool" not in skip:
        out["pool_2"] = _run(sub, root / "pool2", "processes", 2)
        shutil.rmtree(root / "pool2" / "cases")
        out["subset_dask_2"] = _run(sub, root / "sub2", "dask", 2)
        shutil.rmtree(root / "sub2" / "cases")
        out["dask_overhead_pct"] = 100 * (out["subset_dask_2"]["wall_s"]
                                          / out["pool_2"]["wall_s"] - 1)
    if "scaling" not in skip:
        out["subset_dask_1"] = _run(sub, root / "sub1", "dask", 1)
        shutil.rmtree(root / "sub1" / "cases")
        if "subset_dask_2" in out:
            out["speedup_1_to_2"] = (out["subset_dask_1"]["wall_s"]
                                     / out["subset_dask_2"]["wall_s"])
    (root / "bench_campaign.json").write_text(json.dumps(out, indent=1))
    print()
    print(f"{'run':<12} {'cases':>6} {'wall [s]':>9} {'cases/min':>10} {'mean case [s]':>14} "
          f"{'efficiency':>10}")
    for k in ("dask_2", "pool_2", "subset_dask_2", "subset_dask_1"):
        if k in out:
            r = out[k]
            print(f"{k:<12} {r['cases']:>6} {r['wall_s']:>9.1f} {r['cases_per_min']:>10.2f} "
                  f"{r['mean_case_s']:>14.2f} {r['efficiency']:>10.2f}")
    if "dask_overhead_pct" in out:
        print(f"Dask overhead against the process pool: {out['dask_overhead_pct']:+.1f} % "
              f"(floor < 10 %)")
    if "speedup_1_to_2" in out:
        print(f"speed-up 1 -> 2 workers: {out['speedup_1_to_2']:.2f}x")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

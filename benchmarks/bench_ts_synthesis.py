"""Speed of the TS synthesis: LMI controller (7 states + rotor-speed integral = 8) and
TS wind observer (7 states + wind = 8) by cvxpy, for 8 vertices (4 winds x 2 power reductions)
and the default 18 (6 x 3), with each installed open-source SDP solver; certificate checked after
each solve (its time included). Floor: 8 vertices, 8-state model, under 10 s.

No other Python package designs TS/LMI gains for wind turbines, so the ratio reported is between
SDP solvers on the same LMIs.

Run:  python benchmarks/bench_ts_synthesis.py [--repeat 3]
"""
from __future__ import annotations

import argparse
import json
import platform
import time

import linearize
from mpc_wt.controllers.takagi_sugeno import (
    build_ts_model,
    design_ts_controller,
    design_ts_observer,
)
from mpc_wt.errors import SynthesisError

GRIDS = {"8 vertices": ((12.0, 16.0, 20.0, 25.0), (0.0, 0.8)),
         "18 vertices": ((12.0, 14.0, 16.0, 19.0, 22.0, 25.0), (0.0, 0.4, 0.8))}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=3, help="best of N")
    ap.add_argument("--solvers", default="CLARABEL,SCS")
    args = ap.parse_args()
    tb = linearize.load_turbine()
    rows = []
    for label, (wg, rg) in GRIDS.items():
        t0 = time.perf_counter()
        ts = build_ts_model(tb, wg, rg)
        build = time.perf_counter() - t0
        for solver in args.solvers.split(","):
            best: dict = {}
            for _ in range(args.repeat):
                try:
                    t0 = time.perf_counter()
                    c = design_ts_controller(ts, solver=solver)
                    t1 = time.perf_counter()
                    o = design_ts_observer(ts, solver=solver)
                    t2 = time.perf_counter()
                except SynthesisError as err:
                    best = {"error": str(err)[:120]}
                    break
                run = {"controller_s": t1 - t0, "observer_s": t2 - t1, "total_s": t2 - t0,
                       "certified": c.certificate.ok and o.certificate.ok}
                if not best or run["total_s"] < best["total_s"]:
                    best = run
            rows.append({"grid": label, "vertices": ts.n_vertices, "solver": solver,
                         "build_s": build, **best})
            print(json.dumps(rows[-1]))
    print(f"\nmachine: {platform.processor() or platform.machine()}, "
          f"python {platform.python_version()}")
    print(f"{'grid':<12} {'solver':<9} {'build [s]':>9} {'controller [s]':>15} "
          f"{'observer [s]':>13} {'total [s]':>10}  certified")
    for r in rows:
        if "error" in r:
            print(f"{r['grid']:<12} {r['solver']:<9} failed: {r['error']}")
            continue
        print(f"{r['grid']:<12} {r['solver']:<9} {r['build_s']:9.2f} {r['controller_s']:15.2f} "
              f"{r['observer_s']:13.2f} {r['total_s']:10.2f}  {r['certified']}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

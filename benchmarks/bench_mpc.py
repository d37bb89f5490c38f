"""MPC solver comparison (issue 6): the QPs of one 3000-step closed-loop run at 18 m/s in class-A
turbulence, solved by our OSQP and DAQP backends, cvxpy with parameters, Clarabel and qpOASES
(CasADi), with the first-move error against a tight-tolerance reference. See
``mpc_wt.bench`` for what is timed.

Run:  python benchmarks/bench_mpc.py [--json] [--steps N] [--plot FILE.png]
Same as ``mpcwt bench mpc``.
"""
from __future__ import annotations

import argparse
import json
import sys

from mpc_wt.bench import format_table, plot_solver_times, run_solver_benchmark


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--steps", type=int, default=3000, help="closed-loop steps (default 3000)")
    ap.add_argument("--plot", help="PNG of the solve times")
    args = ap.parse_args()
    res = run_solver_benchmark(args.steps, progress=not args.json)
    print(json.dumps(res, indent=1) if args.json else format_table(res))
    if args.plot:
        plot_solver_times(res, args.plot)
    return 0


if __name__ == "__main__":
    sys.exit(main())

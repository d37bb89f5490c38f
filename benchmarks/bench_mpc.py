"""MPC solve time (issue 6, first figures): Madsen's 8-state model at 18 m/s, H_p = H_u = 15,
3 pitch + torque inputs, constraints, 10 Hz; states drawn around a slow oscillation so that the
constraints are inactive (small) and active (large) part of the time. OSQP and DAQP backends.

Run:  python benchmarks/bench_mpc.py [--json]
(The full closed-loop solver comparison of issue 6 -- cvxpy, condensed vs sparse OSQP, more
solvers, move errors against a tight reference -- is still to come.)
"""
from __future__ import annotations

import argparse
import json
import platform
import sys
import time

import numpy as np

import linearize
from mpc_wt.mpc import MPC


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    t = linearize.load_turbine()
    m = linearize.linearize(t, 18.0, config=linearize.PlantConfig.madsen())
    res: dict = {"date": time.strftime("%Y-%m-%d"), "machine": platform.machine(),
                 "python": platform.python_version()}
    rng = np.random.default_rng(1)
    for backend in ("osqp", "daqp"):
        try:
            ctl = MPC(m, t, backend=backend)
        except ImportError as err:
            res[backend] = str(err)
            continue
        for label, amp in (("small", 0.02), ("binding", 0.3)):
            ts = []
            for k in range(3000):
                x = np.zeros(8)
                x[2] = amp * (1 + 0.1 * np.sin(0.01 * k))
                x[0] = 0.05 * rng.standard_normal()
                t0 = time.perf_counter()
                ctl.solve(x)
                ts.append(time.perf_counter() - t0)
            ts = np.array(ts) * 1e6
            res[f"{backend}_{label}_median_us"] = float(np.median(ts))
            res[f"{backend}_{label}_p99_us"] = float(np.percentile(ts, 99))
            res[f"{backend}_{label}_max_us"] = float(ts.max())
    if args.json:
        print(json.dumps(res, indent=1))
    else:
        for k, v in res.items():
            print(f"{k:28s} {v:.4g}" if isinstance(v, float) else f"{k:28s} {v}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

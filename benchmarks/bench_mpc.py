"""MPC solver comparison: the QPs of one 3000-step closed-loop run at 18 m/s in class-A
turbulence, solved by our OSQP and DAQP backends, cvxpy with parameters, Clarabel and qpOASES
(CasADi), with the first-move error against a tight-tolerance reference. See
``mpc_wt.simulation.solver_timing`` for what is timed.

Run:  python benchmarks/bench_mpc.py [--json] [--steps N] [--plot FILE.png]
The same as ``mpcwt bench mpc``, which this script calls.
"""
from __future__ import annotations

import sys

from mpc_wt.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", "mpc", *sys.argv[1:]]))

"""The memory estimate a run is checked against before it starts, beside the peak it reaches:
each run in a fresh process (``python -c``; its peak resident size from the operating system),
turbulent class A at 12 m/s, seed 1.

Run:  python benchmarks/bench_memory.py

Prints, per run: the estimate (wind fields, result, the process's share) and the measured peak
[MB], and their ratio (the estimate must stay above the peak: ratio > 1), with the date and
the machine.
"""
from __future__ import annotations

import datetime
import platform
import resource
import subprocess
import sys

import linearize
from mpc_wt.simulation.memory import estimate_run_memory
from mpc_wt.simulation.scenario import Scenario

RUNS = [("nrel5mw", "baseline", 600.0, 0), ("nrel5mw", "baseline", 3600.0, 0),
        ("nrel5mw", "mpc-lidar", 600.0, 1), ("iea15mw", "baseline", 1800.0, 0)]

CHILD = """
import linearize
from mpc_wt.run import run_controller
from mpc_wt.simulation.scenario import Scenario
run_controller(linearize.load_turbine({turbine!r}), {kind!r}, Scenario(12.0, "A", 1, {dur!r}))
"""


def _peak(code: str) -> float:
    """The peak resident size of a child running ``code`` [B] (Linux reports kB)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    subprocess.run([sys.executable, "-c", code], check=True, capture_output=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    if after <= before:
        raise RuntimeError("the child's peak was not above an earlier child's: run the runs "
                           "in increasing size")
    return after * 1024.0


def main() -> int:
    print(f"# {datetime.date.today()} on {platform.node()} ({platform.machine()}, "
          f"Python {platform.python_version()})")
    print(f"{'turbine':8} {'kind':10} {'duration':>9} {'fields':>8} {'result':>8} "
          f"{'estimate':>9} {'peak':>8} {'ratio':>6}")
    order = sorted(RUNS, key=lambda r: estimate_run_memory(
        linearize.load_turbine(r[0]), Scenario(12.0, "A", 1, r[2]), lidar_fields=r[3]).total)
    for turbine, kind, dur, lidars in order:
        m = estimate_run_memory(linearize.load_turbine(turbine), Scenario(12.0, "A", 1, dur),
                                lidar_fields=lidars)
        peak = _peak(CHILD.format(turbine=turbine, kind=kind, dur=dur))
        print(f"{turbine:8} {kind:10} {dur:8.0f}s {m.field / 1e6:7.0f}M {m.result / 1e6:7.0f}M "
              f"{m.total / 1e6:8.0f}M {peak / 1e6:7.0f}M {m.total / peak:6.2f}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

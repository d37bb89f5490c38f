"""The cost of running a controller library in a child process: ROSCO in the loop for 600 s at
18 m/s, IEC class A, seed 1, NREL 5-MW, with the library in its own process (the default,
``isolate=True``: a library that exits or crashes fails the run only) and loaded in the
simulation's process (``isolate=False``).

Run:  python benchmarks/bench_discon_isolation.py [--repeat 3] [--json]

Prints best-of-N wall times of ``simulate_closed_loop`` (the field and the trim made before the
clock starts), the real-time factors and the cost per library call (the difference over the
run's 48,000 calls at 80 Hz), with the date and the machine.
"""
from __future__ import annotations

import argparse
import datetime
import json
import platform
import tempfile
import time

import linearize
from mpc_wt.controllers.baseline import tune_baseline
from mpc_wt.controllers.discon import DisconController, rosco_library
from mpc_wt.io.gain_tables import export
from mpc_wt.kinds.baseline import baseline_table
from mpc_wt.simulation.loop import simulate_closed_loop
from mpc_wt.simulation.scenario import Scenario, make_wind


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    t = linearize.load_turbine()
    p = linearize.plant_params(t)
    sc = Scenario(18.0, "A", 1, 600.0)
    op = linearize.trim(t, 18.0, params=p)
    wind, _ = make_wind(t, sc, "u")
    out: dict[str, float] = {}
    with tempfile.TemporaryDirectory() as d:
        discon, _ = export(baseline_table(t, tune_baseline(t)), "rosco", d)
        for isolate in (True, False):
            ctl = DisconController(rosco_library(), discon, t, isolate=isolate)
            best = float("inf")
            for _ in range(args.repeat):
                t0 = time.perf_counter()
                simulate_closed_loop(p, ctl, wind, sc.duration, x0=op.x, u0=op.u)
                best = min(best, time.perf_counter() - t0)
            out["child_process_s" if isolate else "in_process_s"] = best
    calls = sc.duration * 80.0
    out["cost_per_call_us"] = (out["child_process_s"] - out["in_process_s"]) / calls * 1e6
    out["rtf_child"] = sc.duration / out["child_process_s"]
    out["rtf_in_process"] = sc.duration / out["in_process_s"]
    out["date"] = datetime.datetime.now().strftime("%Y-%m-%d %H:%M")
    out["machine"] = f"{platform.node()} ({platform.processor() or platform.machine()})"
    if args.json:
        print(json.dumps(out, indent=1))
        return 0
    print(f"ROSCO 600 s at 18 m/s, class A, seed 1 (best of {args.repeat}), {out['date']}, "
          f"{out['machine']}")
    print(f"  library in a child process: {out['child_process_s']:.2f} s "
          f"({out['rtf_child']:.0f}x real time)")
    print(f"  library in this process:    {out['in_process_s']:.2f} s "
          f"({out['rtf_in_process']:.0f}x real time)")
    print(f"  cost of the child process per call: {out['cost_per_call_us']:.1f} us "
          f"({calls:.0f} calls)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

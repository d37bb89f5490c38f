"""Closed-loop and assessment speed: 600 s baseline run at 80 Hz, rainflow + DEL of 48,000
samples (ours vs the rainflow and fatpack packages in the same run).

Run:  python benchmarks/bench_closed_loop.py [--json]
"""
from __future__ import annotations

import argparse
import json
import platform
import sys
import time

import numpy as np

import lidar
import linearize
from mpc_wt.assessment.fatigue import damage_equivalent_load
from mpc_wt.controllers.baseline import BaselineController, tune_baseline
from mpc_wt.run import law_controller
from mpc_wt.simulation.loop import simulate_closed_loop


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    res: dict = {"date": time.strftime("%Y-%m-%d"), "machine": platform.machine(),
                 "python": platform.python_version()}
    t = linearize.load_turbine()
    p = linearize.plant_params(t)
    g = tune_baseline(t)
    f = lidar.generate_field(lidar.TurbulenceSpec(18.0, "A", duration=610.0), 1)
    gw = linearize.GridWind(t=f.t, y=f.y, z=f.z, u=np.maximum(f.u, 0.0))
    op = linearize.trim(t, 18.0)
    ctl = law_controller(BaselineController(t, g), "baseline", t)
    simulate_closed_loop(p, ctl, gw, 2.0, x0=op.x, u0=op.u)
    times = []
    for _ in range(3):
        t0 = time.perf_counter()
        r = simulate_closed_loop(p, ctl, gw, 600.0, x0=op.x, u0=op.u)
        times.append(time.perf_counter() - t0)
    res["closed_loop_600s_best_s"] = min(times)
    res["closed_loop_600s_median_s"] = float(np.median(times))
    res["closed_loop_realtime_factor"] = 600.0 / min(times)
    x = r.channel("tower_base_fa_moment")[:48000]
    damage_equivalent_load(x, 4, duration=600.0)
    n = 200
    t0 = time.perf_counter()
    for _ in range(n):
        damage_equivalent_load(x, 4, duration=600.0)
    res["rainflow_del_48000_ms"] = (time.perf_counter() - t0) / n * 1e3
    try:
        import rainflow

        t0 = time.perf_counter()
        for _ in range(5):
            d = (sum(c * rr**4 for rr, _, c, _, _ in rainflow.extract_cycles(x)) / 600.0) ** 0.25
        res["rainflow_pkg_del_48000_ms"] = (time.perf_counter() - t0) / 5 * 1e3
        res["rainflow_pkg_over_ours"] = res["rainflow_pkg_del_48000_ms"] / res["rainflow_del_48000_ms"]
        res["rainflow_pkg_del_rel_diff"] = abs(d / damage_equivalent_load(x, 4, duration=600.0) - 1)
    except ImportError:
        res["rainflow_pkg"] = "not installed"
    try:
        import fatpack

        t0 = time.perf_counter()
        for _ in range(20):
            rr = fatpack.find_rainflow_ranges(x, k=256)
            (np.sum(rr**4) / 600.0) ** 0.25
        res["fatpack_del_48000_ms"] = (time.perf_counter() - t0) / 20 * 1e3
        res["fatpack_over_ours"] = res["fatpack_del_48000_ms"] / res["rainflow_del_48000_ms"]
    except ImportError:
        res["fatpack"] = "not installed"
    if args.json:
        print(json.dumps(res, indent=1))
    else:
        for k, v in res.items():
            print(f"{k:30s} {v:.4g}" if isinstance(v, float) else f"{k:30s} {v}")
    ok = res["closed_loop_realtime_factor"] >= 50 and res["rainflow_del_48000_ms"] < 5
    print(f"# floors (>= 50x real time, rainflow + DEL < 5 ms): {'met' if ok else 'NOT met'}",
          file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())

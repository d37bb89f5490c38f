"""A Bladed-style library in the loop (issue 20): 600 s with ROSCO against the same run with our
baseline, closed loop only (the field and the trim are made before the clock starts).

Run:  python benchmarks/bench_discon.py [--json]

Prints best-of-3 wall times of ``simulate_closed_loop`` for 600 s at 18 m/s, IEC class A, seed
1, NREL 5-MW: ROSCO (the rosco package's libdiscon.so called at 80 Hz through ctypes) with the
DISCON.IN exported from our baseline and with ROSCO's own NREL-5MW file (which writes a .dbg
line per call), and our baseline; the real-time factors (floor for ROSCO: 30x) and the cost of
one library call net of our baseline's (the difference over 48,000 calls).
"""
from __future__ import annotations

import argparse
import json
import platform
import time
import timeit

import linearize
from mpc_wt.run import build_controller
from mpc_wt.simulation.loop import simulate_closed_loop
from mpc_wt.simulation.scenario import Scenario


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    t = linearize.load_turbine()
    p = linearize.plant_params(t)
    sc = Scenario(wind_mps=18.0, turbulence="A", seed=1, duration=600.0)
    res = {"date": time.strftime("%Y-%m-%d %H:%M"), "machine": platform.machine(),
           "python": platform.python_version()}
    runs = {"rosco": ("rosco", {}), "rosco_shipped": ("rosco", {"discon_in": "shipped"}),
            "baseline": ("baseline", {})}
    for key, (kind, opts) in runs.items():
        built, op, wind = build_controller(t, kind, sc, opts)

        def run() -> None:
            simulate_closed_loop(p, built.controller, wind, 600.0, x0=op.x, u0=op.u,
                                 controller_dt=built.controller_dt)
        best = min(timeit.repeat(run, number=1, repeat=3))
        res[key] = {"seconds": best, "real_time_factor": 600.0 / best}
    res["per_call_us"] = (res["rosco"]["seconds"] - res["baseline"]["seconds"]) / 48000 * 1e6
    if args.json:
        print(json.dumps(res, indent=1))
        return 0
    print(f"# {res['date']} {res['machine']} Python {res['python']}")
    for key in runs:
        print(f"600 s, {key:13s}: {res[key]['seconds']:.2f} s "
              f"({res[key]['real_time_factor']:.0f}x real time)")
    print(f"ROSCO call through ctypes, net of our baseline: {res['per_call_us']:.1f} us")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""A Bladed-style library in the loop: 600 s with ROSCO and with our own exported baseline
library against the same run with our Python baseline, closed loop only (the field and the trim
are made before the clock starts).

Run:  python benchmarks/bench_discon.py [--json]

Prints best-of-3 wall times of ``simulate_closed_loop`` for 600 s at 18 m/s, IEC class A, seed
1, NREL 5-MW: ROSCO (the rosco package's libdiscon.so called at 80 Hz through ctypes) with the
DISCON.IN exported from our baseline and with ROSCO's own NREL-5MW file (which writes a .dbg
line per call), the baseline, the scheduled MPC, the scheduled LQR-PIO and the TS controller
exported as libraries by :func:`mpc_wt.run.export_discon` (built with the system's C compiler)
beside the Python controllers they came from; the real-time factors (floor for ROSCO: 30x), the
cost of one library call net of our baseline's (the difference over 48,000 calls), and the step
time (median, p99) of the exported library (through ctypes, as the harness calls it) beside the
Python controller's ``step`` over the same 600 s.
"""
from __future__ import annotations

import argparse
import json
import platform
import time
import timeit

import tempfile

import numpy as np

import linearize
from mpc_wt.io.discon_export import find_compiler
from mpc_wt.run import build_controller, export_discon
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
    tmp = tempfile.TemporaryDirectory(prefix="mpcwt_bench_discon_")
    exported = ("baseline", "mpc", "lqr-pio", "ts")
    for kind in exported[1:]:
        runs[kind] = (kind, {})
    if find_compiler() is not None:
        for kind in exported:
            ex = export_discon(t, kind, f"{tmp.name}/{kind}")
            runs[f"exported_{kind}"] = ("discon", {"discon_library": str(ex.library),
                                                   "discon_in": str(ex.input_file),
                                                   "discon_dt": ex.dt})
    for key, (kind, opts) in runs.items():
        built, op, wind = build_controller(t, kind, sc, opts)

        def run() -> None:
            simulate_closed_loop(p, built.controller, wind, 600.0, x0=op.x, u0=op.u,
                                 controller_dt=built.controller_dt)
        best = min(timeit.repeat(run, number=1, repeat=3))
        res[key] = {"seconds": best, "real_time_factor": 600.0 / best}
    res["per_call_us"] = (res["rosco"]["seconds"] - res["baseline"]["seconds"]) / 48000 * 1e6
    steps = [k for kind in exported for k in (kind, f"exported_{kind}")]
    for key in steps:
        if key in runs:
            res[key]["step_us"] = _step_times(t, p, sc, *runs[key])
    tmp.cleanup()
    if args.json:
        print(json.dumps(res, indent=1))
        return 0
    print(f"# {res['date']} {res['machine']} Python {res['python']}")
    for key in runs:
        print(f"600 s, {key:17s}: {res[key]['seconds']:.2f} s "
              f"({res[key]['real_time_factor']:.0f}x real time)")
    print(f"ROSCO call through ctypes, net of our baseline: {res['per_call_us']:.1f} us")
    for key in steps:
        if "step_us" in res.get(key, {}):
            med, p99, *call = res[key]["step_us"]
            print(f"step time, {key:17s}: median {med:.1f} us, p99 {p99:.1f} us"
                  + (f" (the DISCON call alone: median {call[0]:.1f} us, p99 {call[1]:.1f} us)"
                     if call else ""))
    if "exported_baseline" not in res:
        print("no C compiler: the exported library was not timed")
    return 0


def _step_times(t, p, sc, kind, opts) -> tuple[float, ...]:
    """Median and p99 of the controller's step over a 600 s run [us] (the step timed on the
    instance, which also keeps the baseline off the loop compiled with the plant), and of a
    library's DISCON call alone."""
    built, op, wind = build_controller(t, kind, sc, opts)
    ctl, times, calls = built.controller, [], []
    inner = ctl.step

    def timed(tt, meas):
        t0 = time.perf_counter_ns()
        out = inner(tt, meas)
        times.append(time.perf_counter_ns() - t0)
        return out
    ctl.step = timed
    if hasattr(ctl, "_fn"):                 # the library's DISCON call alone (ctypes)
        fn = ctl._fn

        def call(*a):
            t0 = time.perf_counter_ns()
            fn(*a)
            calls.append(time.perf_counter_ns() - t0)
        ctl._fn = call
    simulate_closed_loop(p, ctl, wind, 600.0, x0=op.x, u0=op.u,
                         controller_dt=built.controller_dt)
    out = []
    for series in (times, calls):
        us = np.array(series) / 1e3
        out += [float(np.median(us)), float(np.percentile(us, 99))] if len(us) else []
    return tuple(out)


if __name__ == "__main__":
    raise SystemExit(main())

"""Closed loops at the plant's speed, the MPC step at the solver's, a run's memory.

Measured side by side in one run, on one 600 s IEC class-A field at 18 m/s (seed 1, 32 x 32
points, 20 Hz), all DOFs, one core:

- the plant alone: ``linearize.rk4_simulate`` with the trim inputs held (compiled loop), and
  the same through ``PlantStepper`` one step at a time from Python;
- the baseline closed loop (80 Hz controller; compiled with the plant, the default, and the
  Python loop, ``compiled=False``) and Madsen's MPC with the realistic LIDAR's per-blade
  preview (``mpc-lidar``: range weighting, LOS error, wind evolution; 10 Hz), each as a
  real-time factor and as a ratio to the plant alone;
- the envelope MPC below rated: ``mpc-lidar`` 600 s at 8 m/s, its loop and its own step;
- the scheduled kinds, which know only measurements (``mpc``, ``mpc-lidar`` on the Kalman
  estimator and the wind they estimate or the LIDAR measures; ``lqr-pio`` over its 24 designs),
  each beside its point design (the case's 18 m/s: ``design_wind_mps: 18``), every one run by
  its shipped law: 600 s wall time, the cost per controller step in the first and the last
  minute (a loop whose cost grows with elapsed time shows a ratio above 1), and each law's
  step (the library's call through the host) replayed on its loop's measurements;
- the MPC-with-LIDAR law's whole step (measurements and lidar records in, commands out),
  replayed on the recorded measurements, median and p99, for the point design and the
  scheduled one, in this process and (point design) in a few fresh ones;
- peak resident memory of ``mpcwt simulate`` for 600 s (baseline and mpc-lidar), every signal
  kept and written, each in its own process;
- with ``--signoff DIR``: a finished sign-off campaign's wall time (its start to its last
  case) and its cases, per controller the mean case time.

Run:  python benchmarks/bench_loop.py [--json] [--repeat 3] [--skip-memory] [--signoff DIR]
"""
from __future__ import annotations

import argparse
import json
import pickle
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

import linearize
from mpc_wt.controllers.baseline import BaselineController, tune_baseline
from mpc_wt.run import build_controller, law_controller
from mpc_wt.simulation.loop import simulate_closed_loop
from mpc_wt.simulation.scenario import Scenario

DURATION = 600.0


def _best(fn: Any, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def _plant(t: Any, wind: Any, op: Any, repeat: int) -> dict[str, float]:
    p = linearize.plant_params(t)
    linearize.rk4_simulate(p, op.x, op.u, wind, 1.0)          # compile / load the cache
    compiled = _best(lambda: linearize.rk4_simulate(p, op.x, op.u, wind, DURATION), repeat)

    def stepped() -> None:
        st = linearize.PlantStepper(p, wind, 1 / 80, DURATION)
        x, u = op.x.copy(), op.u.copy()
        for k in range(int(DURATION * 80)):
            x, _ = st.step(k / 80, x, u)
    return {"plant_compiled_s": compiled, "plant_stepper_s": _best(stepped, repeat)}


def _baseline(t: Any, wind: Any, op: Any, repeat: int, compiled: bool = True) -> float:
    p, g = linearize.plant_params(t), tune_baseline(t)
    ctl = law_controller(BaselineController(t, g), "baseline", t)
    simulate_closed_loop(p, ctl, wind, 2.0, x0=op.x, u0=op.u, compiled=compiled)
    return _best(lambda: simulate_closed_loop(p, ctl, wind, DURATION, x0=op.x, u0=op.u,
                                              compiled=compiled), repeat)


#: The paper's point design (the case's 18 m/s).
POINT = {"design_wind_mps": 18.0}

#: Loops timed per controller step: name -> (kind, options). Each scheduled kind beside its
#: point design.
LOOPS = {"mpc_lidar_point": ("mpc-lidar", POINT), "mpc_lidar": ("mpc-lidar", None),
         "mpc_point": ("mpc", POINT), "mpc": ("mpc", None),
         "lqr_pio_point": ("lqr-pio", POINT), "lqr_pio": ("lqr-pio", None)}
#: scheduled loop -> its point design
FORMER = {"mpc_lidar": "mpc_lidar_point", "mpc": "mpc_point", "lqr_pio": "lqr_pio_point"}


def _timed_loop(t: Any, kind: str, options: Any, wind_mps: float = 18.0) -> dict[str, Any]:
    """One 600 s loop with the controller's calls time-stamped and their measurements kept."""
    built, op, wind = build_controller(t, kind, Scenario(wind_mps, "A", 1, DURATION), options)
    ctl = built.controller
    stamps: list[float] = []
    rec: list[tuple[float, dict[str, Any]]] = []
    step0 = ctl.step

    def step(tt: float, meas: dict[str, Any]) -> Any:
        stamps.append(time.perf_counter())
        rec.append((tt, {k: (np.array(v) if isinstance(v, np.ndarray) else v)
                         for k, v in meas.items()}))
        return step0(tt, meas)
    ctl.step = step
    t0 = time.perf_counter()
    simulate_closed_loop(linearize.plant_params(t), ctl, wind, DURATION, x0=op.x, u0=op.u,
                         controller_dt=built.controller_dt, preview=built.preview,
                         compiled=False)
    wall = time.perf_counter() - t0
    del ctl.step
    s = np.diff(np.array(stamps))
    dt = built.controller_dt or 1.0 / 80.0
    per_min = int(round(60.0 / dt))
    first, last = s[:per_min].mean(), s[-per_min:].mean()
    return {"s": wall, "first_minute_us_per_step": first * 1e6,
            "last_minute_us_per_step": last * 1e6, "last_over_first": last / first,
            "rec": rec}


def _whole_step(t: Any, rec: list[tuple[float, dict[str, Any]]],
                options: Any = None) -> dict[str, float]:
    """The MPC-with-LIDAR law's step replayed on the recorded measurements (its own state),
    the point design by default."""
    return _replay(t, "mpc-lidar", POINT if options is None else options, rec)[0]


def _replay(t: Any, kind: str, options: Any, rec: list[tuple[float, dict[str, Any]]]
            ) -> tuple[dict[str, float], Any]:
    """A law's step (the library's call through the host: estimators, schedule, QP) replayed
    on its loop's recorded measurements (the LIDAR's on the loop's field): median, p99 and max
    [us], and the controller."""
    built, _, _ = build_controller(t, kind, Scenario(18.0, "A", 1, DURATION), options)
    c = built.controller
    c.reset()
    times = []
    for tt, meas in rec:
        t0 = time.perf_counter()
        c.step(tt, meas)
        times.append(time.perf_counter() - t0)
    us = np.array(times[10:]) * 1e6
    return {"median_us": float(np.median(us)), "p99_us": float(np.percentile(us, 99)),
            "max_us": float(us.max())}, c


def _whole_step_processes(rec: list[tuple[float, dict[str, Any]]], n: int
                          ) -> list[dict[str, Any]]:
    """The replay in ``n`` fresh processes (this VM's speed differs from process to process by
    up to 1.8x: one process's figure is one draw)."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "rec.pkl"
        path.write_bytes(pickle.dumps(rec))
        runs = []
        for _ in range(n):
            out = subprocess.run([sys.executable, __file__, "--replay", str(path)], check=True,
                                 capture_output=True, text=True)
            runs.append(json.loads(out.stdout))
    return runs


def _peak_memory(controller: str) -> float:
    """Peak resident set of ``mpcwt simulate --controller C --duration 600`` [MB]."""
    with tempfile.TemporaryDirectory() as tmp:
        code = ("import resource, subprocess, sys; subprocess.run(sys.argv[1:], check=True); "
                "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)")
        out = subprocess.run([sys.executable, "-c", code, sys.executable, "-m", "mpc_wt.cli",
                              "simulate", "--controller", controller, "--wind", "18",
                              "--duration", str(int(DURATION)), "--out",
                              str(Path(tmp) / "run")],
                             check=True, capture_output=True, text=True)
    return int(out.stdout.split()[-1]) / 1024.0


def _signoff_wall(root: str) -> dict[str, Any]:
    """A finished campaign's wall time: from its last start (``meta.last_run``) to its last
    finished case; cases and mean case time per controller."""
    import datetime
    import sqlite3

    db = sqlite3.connect(str(Path(root) / "index.sqlite"))
    try:
        start = json.loads(dict(db.execute("select key, value from meta"))["last_run"])
        t0 = datetime.datetime.fromisoformat(start).timestamp()
        rows = list(db.execute("select controller, status, wall_s, updated from cases"))
    finally:
        db.close()
    done = [r for r in rows if r[1] == "done"]
    per: dict[str, list[float]] = {}
    for ctl, _, w, _ in done:
        per.setdefault(ctl, []).append(float(w or 0.0))
    return {"cases": len(rows), "done": len(done),
            "wall_s": max(r[3] for r in done) - t0 if done else None,
            "mean_case_s": {k: float(np.mean(v)) for k, v in per.items()}}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--repeat", type=int, default=3, help="best of N for the timed loops")
    ap.add_argument("--skip-memory", action="store_true")
    ap.add_argument("--step-processes", type=int, default=3,
                    help="fresh processes for the MPC step replay (default 3)")
    ap.add_argument("--signoff", help="a finished sign-off campaign's directory (its wall time)")
    ap.add_argument("--replay", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.replay:
        rec = pickle.loads(Path(args.replay).read_bytes())
        tb = linearize.load_turbine()
        print(json.dumps({"library": _whole_step(tb, rec)}))
        return 0
    res: dict[str, Any] = {"date": time.strftime("%Y-%m-%d %H:%M"),
                           "machine": f"{platform.node()} {platform.machine()}",
                           "python": platform.python_version(), "duration_s": DURATION}
    t = linearize.load_turbine()
    _, op, wind = build_controller(t, "baseline", Scenario(18.0, "A", 1, DURATION))
    res.update(_plant(t, wind, op, args.repeat))
    res["baseline_s"] = _baseline(t, wind, op, args.repeat)
    res["baseline_python_s"] = _baseline(t, wind, op, args.repeat, compiled=False)
    recs = {}
    for name, (kind, opts) in LOOPS.items():
        m = _timed_loop(t, kind, opts)
        recs[name] = m.pop("rec")
        res[name] = m
        res[f"{name}_s"] = m["s"]
    res["step_replay"] = {name: _replay(t, kind, opts, recs[name])[0]
                          for name, (kind, opts) in LOOPS.items()}
    # the envelope MPC below rated: a 600 s loop at 8 m/s and its own step
    m = _timed_loop(t, "mpc-lidar", None, 8.0)
    rec8 = m.pop("rec")
    res["mpc_lidar_8mps"] = m
    res["mpc_lidar_8mps_realtime"] = DURATION / m["s"]
    res["step_replay"]["mpc_lidar_8mps"] = _replay(t, "mpc-lidar", None, rec8)[0]
    rec = recs["mpc_lidar_point"]
    res["whole_step"] = {"library": _whole_step(t, rec)}
    res["whole_step_scheduled"] = {"library": _whole_step(t, recs["mpc_lidar"], {})}
    res["whole_step_processes"] = _whole_step_processes(rec, args.step_processes)
    for k in ("plant_compiled", "plant_stepper", "baseline", "baseline_python", *LOOPS):
        res[f"{k}_realtime"] = DURATION / res[f"{k}_s"]
    res["baseline_over_plant"] = res["baseline_s"] / res["plant_compiled_s"]
    res["baseline_python_over_plant"] = res["baseline_python_s"] / res["plant_compiled_s"]
    res["mpc_lidar_over_plant"] = res["mpc_lidar_s"] / res["plant_compiled_s"]
    if args.signoff:
        res["signoff"] = _signoff_wall(args.signoff)
    if not args.skip_memory:
        res["peak_rss_mb"] = {c: _peak_memory(c) for c in ("baseline", "mpc-lidar")}
    if args.json:
        print(json.dumps(res, indent=1))
        return 0
    print(f"{res['date']}  {res['machine']}  python {res['python']}  (600 s, 18 m/s class A)")
    for k, label in (("plant_compiled", "plant alone, compiled loop"),
                     ("plant_stepper", "plant alone, PlantStepper from Python"),
                     ("baseline", "baseline closed loop (80 Hz), compiled"),
                     ("baseline_python", "the same, Python loop (compiled=False)"),
                     ("mpc_lidar_point", "mpc-lidar, the paper's design (10 Hz)"),
                     ("mpc_lidar", "mpc-lidar, scheduled on measurements"),
                     ("mpc_point", "mpc, the paper's design (10 Hz)"),
                     ("mpc", "mpc, scheduled on measurements"),
                     ("lqr_pio_point", "lqr-pio, one design at 18 m/s (80 Hz)"),
                     ("lqr_pio", "lqr-pio, scheduled (80 Hz)")):
        print(f"{label:42s} {res[k + '_s']:7.2f} s  {res[k + '_realtime']:6.1f}x real time")
    print(f"baseline / plant alone {res['baseline_over_plant']:.2f} (Python loop "
          f"{res['baseline_python_over_plant']:.2f}), "
          f"mpc-lidar / plant alone {res['mpc_lidar_over_plant']:.2f}")
    for k in LOOPS:
        print(f"{k} loop per controller step: first minute "
              f"{res[k]['first_minute_us_per_step']:.0f} us, last minute "
              f"{res[k]['last_minute_us_per_step']:.0f} us (ratio "
              f"{res[k]['last_over_first']:.2f})")
    w8, s8 = res["mpc_lidar_8mps"], res["step_replay"]["mpc_lidar_8mps"]
    print(f"full-envelope mpc-lidar at 18 m/s: {res['mpc_lidar_s']:.2f} s, "
          f"{res['mpc_lidar_realtime']:.1f}x real time; its law's whole step (replayed) median "
          f"{res['whole_step_scheduled']['library']['median_us']:.1f} us, p99 "
          f"{res['whole_step_scheduled']['library']['p99_us']:.0f} us")
    print(f"mpc-lidar at 8 m/s (below rated): {w8['s']:.2f} s, "
          f"{res['mpc_lidar_8mps_realtime']:.1f}x real time; its step median "
          f"{s8['median_us']:.1f} us, p99 {s8['p99_us']:.0f} us")
    for k, former in FORMER.items():
        a, b0 = res["step_replay"][k], res["step_replay"][former]
        print(f"{k} step (replayed) median {a['median_us']:.1f} us, p99 {a['p99_us']:.0f} us;"
              f" point design {b0['median_us']:.1f} us, p99 {b0['p99_us']:.0f} us; loop "
              f"{res[k + '_s'] / res[former + '_s']:.3f} x the point design's")
    for name, key in (("scheduled", "whole_step_scheduled"), ("paper's design", "whole_step")):
        w = res[key]["library"]
        print(f"MPC-with-LIDAR law's whole step, {name}: median {w['median_us']:6.1f} us, "
              f"p99 {w['p99_us']:6.1f} us, max {w['max_us']:6.0f} us (this process)")
    med = [r["library"]["median_us"] for r in res["whole_step_processes"]]
    p99 = [r["library"]["p99_us"] for r in res["whole_step_processes"]]
    print(f"  in {len(med)} fresh processes: medians {', '.join(f'{v:.1f}' for v in med)} us; "
          f"p99 {', '.join(f'{v:.0f}' for v in p99)} us")
    so = res.get("signoff")
    if so:
        print(f"sign-off campaign {args.signoff}: {so['done']} of {so['cases']} cases done, wall "
              f"{so['wall_s'] / 60:.1f} min; mean case time "
              + ", ".join(f"{k} {v:.1f} s" for k, v in so["mean_case_s"].items()))
    for c, mb in res.get("peak_rss_mb", {}).items():
        print(f"peak resident memory, mpcwt simulate --controller {c} (600 s): {mb:.0f} MB")
    return 0


if __name__ == "__main__":
    sys.exit(main())

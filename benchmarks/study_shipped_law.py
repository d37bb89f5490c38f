"""Each exportable kind with a Python step of its own (the MPC kinds, LQR-PIO, TS; the baseline's
family has none: its law is the C law) run by its shipped law (its compiled C library through
the host, as ``run_controller`` runs it) against the design's Python step (``shipped=False``) on
the same case: the largest pitch and torque differences over the run, and each run's wall
time.

Run:  python benchmarks/study_shipped_law.py [--wind 14] [--duration 120] [--seed 11]
                                             [--kinds baseline mpc ...] [--supervised]

``--supervised`` runs every case under the supervisor with the sign-off's overspeed
protection (1.25 x rated), as the sign-off does (the shipped law's loop compiled up to a trip).
``--main-job`` prints the main job's comparison table (``mpcwt run``: 600 s at 18 m/s, class
A, seed 1, its controllers and options) with the Python steps and with the shipped laws.

The two runs share the case's field (``FieldMemo``); the design is made once (before the first
run's clock starts) and shared by both.
"""
from __future__ import annotations

import argparse
import platform
import time

import numpy as np

import linearize
from mpc_wt.run import design_controller, run_controller
from mpc_wt.simulation.scenario import FieldMemo

#: the exportable kinds whose design has a Python step beside its shipped law
PYTHON_STEPS = ("mpc", "mpc-collective", "mpc-lidar", "lqr-pio", "ts")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--wind", type=float, default=14.0, help="[m/s]")
    ap.add_argument("--duration", type=float, default=120.0, help="[s]")
    ap.add_argument("--seed", type=int, default=11)
    ap.add_argument("--kinds", nargs="+", default=list(PYTHON_STEPS))
    ap.add_argument("--supervised", action="store_true")
    ap.add_argument("--main-job", action="store_true")
    args = ap.parse_args()
    if args.main_job:
        return _main_job()
    t = linearize.load_turbine("nrel5mw")
    fields = FieldMemo()
    print(f"# {time.strftime('%Y-%m-%d %H:%M')} {platform.machine()} Python "
          f"{platform.python_version()}; NREL 5-MW, {args.wind:g} m/s, class A, seed "
          f"{args.seed}, {args.duration:g} s{', supervised' if args.supervised else ''}")
    print("| kind | law (loop) | largest pitch difference [deg] | largest torque difference "
          "[rated] | shipped [s] | Python [s] |\n|---|---|---|---|---|---|")
    kw = dict(duration=args.duration, turbulence="A", seed=args.seed, fields=fields,
              supervisor={"overspeed": 1.25} if args.supervised else None)
    for kind in args.kinds:
        design_controller(t, kind)
        design_controller(t, kind, shipped=True)
        runs = []
        for shipped in (True, False):
            t0 = time.perf_counter()
            r = run_controller(t, kind, args.wind, shipped=shipped, **kw)
            runs.append((r, time.perf_counter() - t0))
        (a, ta), (b, tb) = runs
        dp = float(np.degrees(np.max(np.abs(a.u[:, :3] - b.u[:, :3]))))
        dq = float(np.max(np.abs(a.u[:, 3] - b.u[:, 3]))) / t.rated_generator_torque
        print(f"| {kind} | {a.meta.get('law', 'python')} ({a.meta['loop']}) | {dp:.2e} | "
              f"{dq:.2e} | {ta:.2f} | {tb:.2f} |")
    return 0


def _main_job() -> int:
    """The main job's table, each controller with its Python step and its shipped law."""
    import lidar
    from mpc_wt.assessment.series import assess_series
    from mpc_wt.cli.runs import MAIN_JOB_OPTIONS, _comparison_row
    from mpc_wt.simulation.scenario import Scenario

    t = linearize.load_turbine()
    sc = Scenario(18.0, "A", 1, 600.0)
    print(f"# {time.strftime('%Y-%m-%d %H:%M')} {platform.machine()}; the main job's case")
    print("| law | controller | P mean [MW] | P std [kW] | speed std [rpm] | pitch [deg] | "
          "DEL flap / tower / shaft [MN m] |\n|---|---|---|---|---|---|---|")
    for shipped in (False, True):
        samplers = lidar.SamplerCache()
        for name in ("baseline", "baseline+lidar-ff", "mpc-lidar"):
            res = run_controller(t, name, sc, options=MAIN_JOB_OPTIONS.get(name, {}),
                                 samplers=samplers, shipped=shipped)
            keep = res.t >= 60.0
            cols = {n: res.channel(n)[keep] for n in res.channels()}
            r = _comparison_row(name, assess_series(res.t[keep], cols), cols, None, "")
            print(f"| {res.meta.get('law', 'python')} | {name} | {r['power_mean_MW']:.3f} | "
                  f"{r['power_std_kW']:.1f} | {r['rotor_speed_std_rpm']:.3f} | "
                  f"{r['pitch_travel_deg']:.0f} | {r['del_flap_moment_1_MNm']:.3f} / "
                  f"{r['del_tower_base_fa_moment_MNm']:.3f} / "
                  f"{r['del_shaft_bending_blade1_MNm']:.3f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""Pitch travel against fatigue: controller settings compared with the baseline on a turbine.

Each setting (a controller kind with options) runs DLC 1.2-style turbulence on seeds no design
or sign-off uses (``--seeds`` 11 and 12 by default; the sign-offs run 1-6), beside the
baseline on the same fields. Printed per setting: the lifetime changes of the DELs
(``assessment.fatigue.wind_bin_probabilities``, Rayleigh with mean 10 m/s, and
``lifetime_del``, Clemens et al. eq 18), the AEP change, the pitch travel over all cases
against the baseline's, and the largest rotor speed over rated. This is how the defaults for
slow pitch drives were chosen (the MPC's pitch-rate scale, the LQR's pitch scale, the IPC
kinds' cyclic amplitude and IBC's loop gain on the IEA-15-240-RWT).

Run:  python benchmarks/study_pitch_budget.py --turbine iea15mw --turbulence B \\
          --setting 'mpc-lidar' --setting 'mpc-lidar {"weights": {"pitch_rate": 0.06}}' \\
          [--winds 5,9,13,17,21,25] [--seeds 11,12] [--duration 300] [--workers 2]
"""
from __future__ import annotations

import argparse
import json
from concurrent.futures import ProcessPoolExecutor

import numpy as np
from _study import Sized, add_grid_args, grid

#: The channels compared and their Woehler exponents (the sign-off's).
CHANNELS = {"flap_moment_1": 10, "shaft_bending_blade1": 4, "tower_base_fa_moment": 4,
            "tower_base_ss_moment": 4, "lss_torque": 4}


def _case(job: tuple) -> tuple:
    """One run: (turbine, kind, options JSON, wind, seed, turbulence, duration, transient)."""
    import linearize
    from mpc_wt.assessment.series import assess_series
    from mpc_wt.run import run_controller
    from mpc_wt.simulation.scenario import Scenario

    name, kind, opts, wind, seed, turb, duration, transient = job
    turbine = linearize.load_turbine(name)
    r = run_controller(turbine, kind, Scenario(wind, turb, seed, transient + duration),
                       options=json.loads(opts))
    keep = r.t >= transient
    cols = {n: r.channel(n)[keep] for n in r.channels()}
    a = assess_series(r.t[keep], cols)
    out = {"power": a["power_mean_W"], "travel": a["pitch_travel_deg"],
           "speed": float(cols["rotor_speed"].max()) / turbine.operation.rated_rotor_speed_rad_s}
    out.update({n: a["channels"][n]["del"] for n in CHANNELS})
    return job, out


def _setting(text: str) -> tuple[str, str]:
    """'KIND' or 'KIND {json options}' -> (kind, canonical options JSON)."""
    kind, _, opts = text.strip().partition(" ")
    try:
        parsed = json.loads(opts) if opts.strip() else {}
    except json.JSONDecodeError as err:
        raise SystemExit(f"--setting {text!r}: the options are not JSON ({err})") from None
    if not isinstance(parsed, dict):
        raise SystemExit(f"--setting {text!r}: the options must be a JSON object")
    return kind, json.dumps(parsed, sort_keys=True)


def main() -> int:
    from linearize.progress import progress
    from mpc_wt.assessment.fatigue import lifetime_del, wind_bin_probabilities

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--turbine", default="nrel5mw")
    ap.add_argument("--turbulence", default="B", help="IEC turbulence class (A, B, C)")
    ap.add_argument("--setting", action="append", required=True,
                    help="a kind and its options as JSON, e.g. 'ibc {\"loop_gain_1p\": 0.4}' "
                         "(repeat for more)")
    add_grid_args(ap, "5,9,13,17,21,25")
    args = ap.parse_args()
    winds, seeds = grid(args)
    settings = [("baseline", "{}")] + [_setting(s) for s in args.setting]
    jobs = [(args.turbine, k, o, w, s, args.turbulence, args.duration, args.transient)
            for k, o in dict.fromkeys(settings) for w in winds for s in seeds]
    res: dict[tuple, dict] = {}
    with ProcessPoolExecutor(args.workers) as pool:
        for job, out in progress(Sized(pool.map(_case, jobs), len(jobs)),
                                 "pitch-budget study", "run"):
            res[job[1:5]] = out
    p = wind_bin_probabilities(winds, "rayleigh", mean=10.0)

    def per_wind(kind: str, opts: str, name: str, m: float = 1.0) -> list[float]:
        return [float(np.mean([res[(kind, opts, w, s)][name] ** m for s in seeds])) ** (1 / m)
                for w in winds]

    base = settings[0]
    print(f"{args.turbine}, class {args.turbulence}, seeds {seeds}, {args.duration:g} s per "
          f"case; lifetime changes against the baseline (Rayleigh mean 10 m/s over {winds} m/s)")
    print("| setting | pitch travel | " + " | ".join(CHANNELS) + " | AEP | largest rotor "
          "speed / rated |")
    print("|---" * (len(CHANNELS) + 4) + "|")
    for kind, opts in settings:
        row = []
        for n, m in CHANNELS.items():
            ratio = (lifetime_del(per_wind(kind, opts, n, m), m, p)
                     / lifetime_del(per_wind(*base, n, m), m, p))
            row.append(f"{100 * (ratio - 1):+.1f} %")
        aep = float(np.dot(p, per_wind(kind, opts, "power"))
                    / np.dot(p, per_wind(*base, "power")) - 1)
        travel = sum(per_wind(kind, opts, "travel")) / sum(per_wind(*base, "travel"))
        speed = max(res[(kind, opts, w, s)]["speed"] for w in winds for s in seeds)
        label = kind if opts == "{}" else f"{kind} {opts}"
        print(f"| {label} | {travel:.2f}x | " + " | ".join(row) + f" | {100 * aep:+.2f} % | "
              f"{speed:.3f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

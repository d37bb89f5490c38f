"""TS's wind observer speed: the tower's fatigue in turbulence against the rotor speed in a gust.

The TS kind (Clemens et al.'s Takagi-Sugeno controller and wind observer) with its observer at
each decay rate given, against the baseline, on seeds no design or sign-off uses (class A,
``--seeds`` 11 and 12 by default; the sign-off runs 1-6): per mean wind the changes of the
short-term DELs, then lifetime-weighted (``assessment.fatigue.wind_bin_probabilities``,
Rayleigh with mean 10 m/s, and ``lifetime_del``, Clemens et al. eq 18) with the AEP change and
the pitch travel; and the largest rotor speed in an extreme operating gust (IEC 61400-1 ed. 3,
class I, deterministic) at ``--eog-wind`` without the protection.

Run:  python benchmarks/study_ts_observer.py [--rates 1,0.5,0.35] [--winds 5,9,11,13,17,21,25]
      [--seeds 11,12] [--duration 300] [--workers 2]
"""
from __future__ import annotations

import argparse
import json
from concurrent.futures import ProcessPoolExecutor

import numpy as np
from _study import Sized, add_grid_args, grid

#: The channels compared and their Woehler exponents (the sign-off's).
CHANNELS = {"tower_base_fa_moment": 4, "tower_base_ss_moment": 4, "lss_torque": 4,
            "flap_moment_1": 10, "shaft_bending_blade1": 4}


def _case(job: tuple) -> tuple:
    """One run: (kind, options JSON, wind, seed, duration, transient, eog) -> its figures."""
    import linearize
    from mpc_wt.assessment.series import assess_series
    from mpc_wt.run import run_controller
    from mpc_wt.simulation.scenario import Scenario

    kind, opts, wind, seed, duration, transient, eog = job
    turbine = linearize.load_turbine()
    if eog:
        sc = Scenario(wind, "A", 0, transient + 60.0, 0.2, condition="eog", iec_class="I",
                      sign=1, event_at=transient)
    else:
        sc = Scenario(wind, "A", seed, transient + duration)
    r = run_controller(turbine, kind, sc, options=json.loads(opts))
    keep = r.t >= transient
    cols = {n: r.channel(n)[keep] for n in r.channels()}
    speed = float(cols["rotor_speed"].max()) / turbine.operation.rated_rotor_speed_rad_s
    if eog:
        return job, {"speed": speed}
    a = assess_series(r.t[keep], cols)
    out = {"power": a["power_mean_W"], "travel": a["pitch_travel_deg"], "speed": speed}
    out.update({n: a["channels"][n]["del"] for n in CHANNELS})
    return job, out


def main() -> int:
    from linearize.progress import progress
    from mpc_wt.assessment.fatigue import lifetime_del, wind_bin_probabilities

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rates", default="1,0.5,0.35", help="observer decay rates [1/s]")
    add_grid_args(ap, "5,9,11,13,17,21,25")
    ap.add_argument("--eog-wind", type=float, default=25.0, help="the EOG's mean wind [m/s]")
    args = ap.parse_args()
    rates = [float(x) for x in args.rates.split(",")]
    winds, seeds = grid(args)
    settings = [("baseline", "{}")] + [("ts", json.dumps({"observer_decay_rate": r}))
                                       for r in rates]
    jobs = [(k, o, w, s, args.duration, args.transient, False) for k, o in settings
            for w in winds for s in seeds]
    jobs += [(k, o, args.eog_wind, 0, args.duration, args.transient, True) for k, o in settings]
    res: dict[tuple, dict] = {}
    with ProcessPoolExecutor(args.workers) as pool:
        for job, out in progress(Sized(pool.map(_case, jobs), len(jobs)),
                                 "TS observer study", "run"):
            res[job[:4] + (job[6],)] = out
    p = wind_bin_probabilities(winds, "rayleigh", mean=10.0)

    def figures(kind: str, opts: str, name: str) -> list[float]:
        return [float(np.mean([res[(kind, opts, w, s, False)][name] for s in seeds]))
                for w in winds]

    base = settings[0]
    print(f"changes against the baseline, seeds {seeds}, class A, {args.duration:g} s; lifetime: "
          f"Rayleigh mean 10 m/s over {winds} m/s")
    print("| observer decay rate | " + " | ".join(CHANNELS) + " | AEP | pitch travel | "
          "largest rotor speed / rated | EOG at %g m/s, rotor / rated |" % args.eog_wind)
    print("|---" * (len(CHANNELS) + 5) + "|")
    for (kind, opts), label in zip(settings, ["baseline"] + [f"{r:g} 1/s" for r in rates]):
        row = []
        for n, m in CHANNELS.items():
            mine = [float(np.mean([res[(kind, opts, w, s, False)][n] ** m for s in seeds]))
                    ** (1 / m) for w in winds]
            ref = [float(np.mean([res[(*base, w, s, False)][n] ** m for s in seeds])) ** (1 / m)
                   for w in winds]
            row.append(f"{100 * (lifetime_del(mine, m, p) / lifetime_del(ref, m, p) - 1):+.1f} %")
        aep = float(np.dot(p, figures(kind, opts, "power")) /
                    np.dot(p, figures(*base, "power")) - 1)
        travel = sum(figures(kind, opts, "travel")) / sum(figures(*base, "travel"))
        speed = max(res[(kind, opts, w, s, False)]["speed"] for w in winds for s in seeds)
        eog = res[(kind, opts, args.eog_wind, 0, True)]["speed"]
        print(f"| {label} | " + " | ".join(row) + f" | {100 * aep:+.2f} % | {travel:.2f}x | "
              f"{speed:.3f} | {eog:.3f} |")
    print("\nper wind, tower fore-aft / shaft torque DEL change:")
    for kind, opts in settings[1:]:
        cells = []
        for w in winds:
            ch = [float(np.mean([res[(kind, opts, w, s, False)][n] /
                                 res[(*base, w, s, False)][n] - 1 for s in seeds])) * 100
                  for n in ("tower_base_fa_moment", "lss_torque")]
            cells.append(f"{w:g}: {ch[0]:+.1f} / {ch[1]:+.1f} %")
        print(f"  {json.loads(opts)['observer_decay_rate']:g} 1/s  " + ", ".join(cells))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""Madsen et al. (2012) section IV on our plant: MPC with LIDAR preview against the same MPC
without, one run each at 18 m/s, IEC class A, seed 1 (issue 6; the full multi-seed study belongs
to the campaign issue).

Reports power std [% of mean], the 1P PSD content of the blade-1 flap moment and of the shaft
bending moment seen by blade 1, and the DELs of shaft, flap (m = 10) and tower base (m = 4), next
to the paper's numbers (power std 0.29 % with LIDAR vs 0.36 % without; 1P reductions 60 % flap,
85 % shaft; DEL reductions 11.6 % flap, 33.9 % shaft, 15.6 % tower). Writes the two runs
(netCDF), a JSON of the figures and PSD plots to --out.

Run:  python benchmarks/study_madsen.py [--duration 600] [--out study-madsen]
"""
from __future__ import annotations

import json
import math
import sys
import time

import numpy as np
from _study import study_args

import linearize
from mpc_wt import run_controller
from mpc_wt.assessment.fatigue import damage_equivalent_load
from mpc_wt.assessment.performance import harmonic_psd, psd
from mpc_wt.plotting import plot_psd_comparison
from mpc_wt.simulation.scenario import Scenario

PAPER = {"power_std_pct_lidar": 0.29, "power_std_pct_no_lidar": 0.36,
         "flap_1P_reduction_pct": 60.0, "shaft_1P_reduction_pct": 85.0,
         "flap_del_reduction_pct": 11.6, "shaft_del_reduction_pct": 33.9,
         "tower_del_reduction_pct": 15.6}
CHANNELS = {"flap": ("flap_moment_1", 10.0), "shaft": ("shaft_bending_blade1", 4.0),
            "tower": ("tower_base_fa_moment", 4.0)}


def main() -> int:
    args, out = study_args(__doc__, "study-madsen",
                           lambda ap: ap.add_argument("--seed", type=int, default=1))
    t = linearize.load_turbine()
    figs: dict = {"date": time.strftime("%Y-%m-%d"), "wind_mps": 18.0, "turbulence": "A",
                  "seed": args.seed, "duration_s": args.duration, "paper": PAPER}
    series = {}
    for ctl in ("mpc", "mpc-lidar"):
        t0 = time.perf_counter()
        # the paper's LIDAR model assumes Taylor's frozen turbulence (sec. II-E): no evolution
        r = run_controller(t, ctl, Scenario(18.0, "A", seed=args.seed, duration=args.duration + args.transient), progress=True, options={"lidar": {"evolution": False}} if ctl == "mpc-lidar"
                           else None)
        figs[f"{ctl}_wall_s"] = time.perf_counter() - t0
        r.save(out / f"{ctl}.nc")
        keep = r.t >= args.transient
        cols = {n: r.channel(n)[keep] for n in ("gen_power", "rotor_speed", "flap_moment_1",
                                               "shaft_bending_blade1", "tower_base_fa_moment")}
        dt = float(np.median(np.diff(r.t)))
        frot = float(cols["rotor_speed"].mean()) / (2 * math.pi)
        m = {"power_std_pct": 100 * cols["gen_power"].std() / cols["gen_power"].mean(),
             "fallbacks": int(np.sum(r.controller["qp_fallback"] > 0))}
        for key, (name, wexp) in CHANNELS.items():
            m[f"{key}_del"] = damage_equivalent_load(cols[name], wexp, duration=args.duration)
            m[f"{key}_1P"] = harmonic_psd(cols[name], 1 / dt, frot)[1]
        figs[ctl] = m
        series[ctl] = (dt, cols, frot)
    a, b = figs["mpc"], figs["mpc-lidar"]

    def red(k: str) -> float:
        return 100.0 * (1.0 - b[k] / a[k])
    figs["ours"] = {"power_std_pct_lidar": b["power_std_pct"],
                    "power_std_pct_no_lidar": a["power_std_pct"],
                    "flap_1P_reduction_pct": red("flap_1P"), "shaft_1P_reduction_pct": red("shaft_1P"),
                    "flap_del_reduction_pct": red("flap_del"),
                    "shaft_del_reduction_pct": red("shaft_del"),
                    "tower_del_reduction_pct": red("tower_del")}
    (out / "study_madsen.json").write_text(json.dumps(figs, indent=1))
    for key, (name, _) in CHANNELS.items():
        spectra = []
        for ctl in ("mpc", "mpc-lidar"):
            dt, cols, frot = series[ctl]
            f, p = psd(cols[name], 1 / dt)
            spectra.append((ctl, f, p))
        plot_psd_comparison(spectra, frot, out / f"psd_{key}.png", f"{name} PSD [(N m)^2/Hz]")
    print(f"{'quantity':28s} {'mpc-wt':>10s} {'Madsen et al.':>14s}")
    for k, v in figs["ours"].items():
        print(f"{k:28s} {v:10.2f} {PAPER[k]:14.2f}")
    print(f"QP fallbacks: mpc {a['fallbacks']}, mpc-lidar {b['fallbacks']}; wall "
          f"{figs['mpc_wall_s']:.0f} s / {figs['mpc-lidar_wall_s']:.0f} s; wrote {out}/")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Cost of the plant's OpenFAST-fidelity effects: a 600 s closed loop (the baseline, compiled with
the plant, 80 Hz) in a class-A turbulent field with u, v and w (32 x 32 points over 150 m,
20 Hz, 12 m/s, shear 0.2), with each effect alone and all of them (``PlantConfig.openfast()``),
on one core.

Run:  python benchmarks/bench_plant_features.py [--repeat 2] [--json]
"""
from __future__ import annotations

import argparse
import json
import time

import numpy as np

import lidar
import linearize
from mpc_wt.controllers.baseline import BaselineController
from mpc_wt.run import law_controller
from mpc_wt.simulation.loop import simulate_closed_loop

CONFIGS = (("default plant", {}),
           ("+ blade body forces", {"blade_body_forces": True}),
           ("+ tower shadow", {"tower_shadow": True}),
           ("+ tower drag", {"tower_drag": True}),
           ("+ twisted modes", {"twisted_modes": True}),
           ("+ unsteady aerodynamics", {"unsteady_aero": True}),
           ("+ skewed wake", {"skewed_wake": True}),
           ("+ deflected blades", {"deflected_blades": True}),
           ("all (PlantConfig.openfast())", None))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--duration", type=float, default=600.0)
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    turbine = linearize.load_turbine("nrel5mw")
    f = lidar.generate_field(lidar.TurbulenceSpec(12.0, "A", duration=args.duration + 20.0), 7)
    wind = linearize.GridWind(t=f.t, y=f.y, z=f.z, u=np.maximum(f.u, 0.0), v=f.v, w=f.w)
    op = linearize.trim(turbine, 12.0, shear_exponent=0.2)
    out = {}
    for label, kw in CONFIGS:
        cfg = linearize.PlantConfig.openfast() if kw is None else linearize.PlantConfig(**kw)
        params = linearize.plant_params(turbine, cfg)
        times = []
        for k in range(args.repeat + 1):       # the first run compiles
            ctl = law_controller(BaselineController(turbine), "baseline", turbine)
            t0 = time.perf_counter()
            simulate_closed_loop(params, ctl, wind, args.duration, x0=op.x, u0=op.u)
            if k:
                times.append(time.perf_counter() - t0)
        best = min(times)
        out[label] = {"best_s": best, "real_time_factor": args.duration / best}
        if not args.json:
            print(f"{label:32s} {best:6.2f} s  {args.duration / best:6.1f}x real time")
    if args.json:
        print(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

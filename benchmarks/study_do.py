"""Do et al. (2020) region III on our plant: LQR full-state feedback on PI-observer estimates
(FSF, eqs 9-16) against the PI baseline with constant torque, 18 m/s, IEC class C (12 %), shear
0.2, 600 s per seed, same seeds for both. Both run by their shipped laws; the observer reads
what a turbine's controller measures (generator speed, tower-top fore-aft acceleration, blade
root moments; the paper observes the tower-top and flap displacements).

Reports CS1 (tower-base fore-aft moment std along its ellipse axis), CS2 (electrical power),
CS5, and the tower-base DEL (m = 4), each as the mean over seeds and the FSF change against PI,
next to the paper's table 3 (CS1 -27 %, CS2 -79 %, tower DEL -29 %). Then section 4.4's weight
sweep: the rotor-speed weight held at 5 and the blade-flap weight at 10, 15 and 20 (Do et al.
table 4), CS1..CS5 per combination.

Run:  python benchmarks/study_do.py [--duration 600] [--seeds 1,2,3] [--out study-do]
"""
from __future__ import annotations

import json
import time

import numpy as np
from _study import study_args

import linearize
from mpc_wt import SimulationDivergedError, simulate_closed_loop
from mpc_wt.assessment.fatigue import damage_equivalent_load
from mpc_wt.assessment.performance import cs_measures
from mpc_wt.controllers.baseline import BaselineController, tune_baseline
from mpc_wt.run import law_controller
from mpc_wt.controllers.lqr import (
    REGION3_SCALES,
    REGION3_WEIGHTS,
    TURBINE_MEASURED,
    LQRPIOController,
    design_lqr,
    design_pi_observer,
    turbine_scales,
)
from mpc_wt.simulation.scenario import Scenario, make_wind

PAPER = {"cs1_change_pct": -27.0, "cs2_change_pct": -79.0, "tower_del_change_pct": -29.0,
         "table4": {"5-10": [0.144, 149.9], "5-15": [0.122, 102.8], "5-20": [0.134, 102.7]}}
PITCH_SCALES = {k: v for k, v in REGION3_SCALES.items() if k.startswith("pitch_ref")}


def _fsf(model: linearize.LinearModel, turbine: linearize.Turbine,
         weights: dict[str, float], scales: dict[str, float]) -> object:
    lq = design_lqr(model, state_weights=weights, scales={**scales, **PITCH_SCALES})
    sy = {k: v * (10.0 if k.startswith("flap_moment") else 1.0)
          for k, v in turbine_scales(model).items()}
    obs = design_pi_observer(model, q=1e3, measured=TURBINE_MEASURED, scales=sy)
    return law_controller(LQRPIOController(model, turbine, lq, obs), "lqr-pio", turbine)


def _metrics(r, transient: float) -> dict:
    k = r.t >= transient
    load = r.channel("tower_base_fa_moment")[k]
    power = r.channel("gen_power")[k]
    cs = cs_measures(load / 1e3, power / 1e3)
    return {"cs1_kNm": cs.cs1, "cs2_kW": cs.cs2, "cs3_kNm": cs.cs3, "cs4_kW": cs.cs4,
            "cs5_deg": cs.cs5,
            "tower_del_MNm": damage_equivalent_load(load, 4.0, duration=float(np.ptp(r.t[k])))
            / 1e6,
            "rotor_std_pct": float(100 * r.channel("rotor_speed")[k].std()
                                   / r.channel("rotor_speed")[k].mean())}


def main() -> int:
    args, out = study_args(__doc__, "study-do",
                           lambda ap: ap.add_argument("--seeds", default="1,2,3"))
    tb = linearize.load_turbine()
    params = linearize.plant_params(tb)
    v = 18.0
    model = linearize.linearize(tb, v, config=linearize.PlantConfig.do())
    op = linearize.trim(tb, v)
    gains = tune_baseline(tb)
    dur = args.duration + args.transient
    cases = {"PI": None,
             "FSF": (REGION3_WEIGHTS, REGION3_SCALES)}
    for w in (10.0, 15.0, 20.0):
        cases[f"5-{w:g}"] = ({"rotor_speed": 5.0, **{f"flap_{i}": w for i in (1, 2, 3)}},
                             {"rotor_speed": 0.05, **{f"flap_{i}": 2.0 for i in (1, 2, 3)}})
    res: dict = {name: [] for name in cases}
    for seed in (int(s) for s in args.seeds.split(",")):
        wind, _ = make_wind(tb, Scenario(v, "C", seed, dur, 0.2))
        for name, spec in cases.items():
            ctl = law_controller(BaselineController(tb, gains, region3="constant_torque"),
                                 "baseline", tb) if spec is None \
                else _fsf(model, tb, *spec)
            try:
                r = simulate_closed_loop(params, ctl, wind, dur, x0=op.x, u0=op.u, progress=True)
            except SimulationDivergedError as err:
                res[name].append({"seed": seed, "diverged": str(err)})
                print(name, seed, "diverged:", err)
                continue
            m = {"seed": seed, **_metrics(r, args.transient)}
            res[name].append(m)
            print(name, json.dumps(m))

    def mean(name: str, key: str) -> float:
        vals = [m[key] for m in res[name] if key in m]
        return float(np.mean(vals)) if vals else float("nan")

    keys = ("cs1_kNm", "cs2_kW", "cs3_kNm", "cs4_kW", "cs5_deg", "tower_del_MNm",
            "rotor_std_pct")
    summary = {name: {k: mean(name, k) for k in keys} for name in cases}
    change = {k: 100 * (summary["FSF"][k] / summary["PI"][k] - 1)
              for k in ("cs1_kNm", "cs2_kW", "tower_del_MNm")}
    doc = {"date": time.strftime("%Y-%m-%d"), "wind_mps": v, "turbulence": "C",
           "seeds": args.seeds, "duration_s": args.duration, "runs": res, "mean": summary,
           "fsf_change_pct": change, "paper": PAPER}
    (out / "do.json").write_text(json.dumps(doc, indent=1))
    print("\nmean over seeds        CS1 [kN m]  CS2 [kW]  CS3 [kN m]  CS4 [kW]  CS5 [deg]  "
          "tower DEL [MN m]  rotor std [%]")
    for name in cases:
        s = summary[name]
        print(f"{name:<22} {s['cs1_kNm']:10.1f} {s['cs2_kW']:9.1f} {s['cs3_kNm']:11.1f} "
              f"{s['cs4_kW']:9.1f} {s['cs5_deg']:10.2f} {s['tower_del_MNm']:17.3f} "
              f"{s['rotor_std_pct']:14.3f}")
    print(f"FSF vs PI: CS1 {change['cs1_kNm']:+.1f} % (paper -27), CS2 {change['cs2_kW']:+.1f} % "
          f"(paper -79), tower DEL {change['tower_del_MNm']:+.1f} % (paper -29)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

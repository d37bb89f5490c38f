"""Clemens et al. on our plant: the TS controller (eq 7) with the TS wind observer (eqs 8-10),
LMI-designed and run by its shipped law on the tower-top accelerations and the rotor and generator
speeds (what a turbine's controller measures; the paper observes the tower-top displacements),
regulating rated speed over 12-25 m/s in turbulence, tracking the sinusoidal power
reference of eq 11 at f_r = 0.05-0.2 Hz, and estimating the rotor-effective wind.

Per mean wind (IEC class A, seed 1): rotor speed mean / std / max against rated, and the same
for the PI baseline on the same wind for context; wind estimate RMS error against the disc mean
of the field and its coherence (Welch). Per f_r at 15 m/s (the paper's Fig. 3 case): amplitude
ratio and phase of electrical power against the reference (least-squares sine fit at f_r after
the transient). Eq 11 as printed asks for 175 % of rated at its troughs; we use
Delta P = 3/8 (1 + sin 2 pi f_r t) (peak reduction 3/4, as printed) -- see mpc_wt.controllers.takagi_sugeno.apc_reference.

Run:  python benchmarks/study_clemens.py [--duration 600] [--out study-clemens]
"""
from __future__ import annotations

import argparse
import json
import time

import numpy as np
from _study import study_args

import lidar
import linearize
from mpc_wt import run_controller
from mpc_wt.assessment.performance import tracking_response
from mpc_wt.controllers.apc import apc_reference
from mpc_wt.controllers.takagi_sugeno import (
    TURBINE_MEASURED,
    TSController,
    build_ts_model,
    design_ts_controller,
    design_ts_observer,
)
from mpc_wt.run import law_controller
from mpc_wt.simulation.loop import simulate_closed_loop
from mpc_wt.simulation.scenario import Scenario, make_wind


def main() -> int:
    def extra(ap: argparse.ArgumentParser) -> None:
        ap.add_argument("--winds", default="12,15,18,21,25")
        ap.add_argument("--frequencies", default="0.05,0.1,0.15,0.2")
        ap.add_argument("--seed", type=int, default=1)

    args, out = study_args(__doc__, "study-clemens", extra)
    tb = linearize.load_turbine()
    params = linearize.plant_params(tb)
    rated = tb.operation.rated_rotor_speed_rad_s
    figs: dict = {"date": time.strftime("%Y-%m-%d"), "turbulence": "A", "seed": args.seed,
                  "duration_s": args.duration}
    t0 = time.perf_counter()
    ts = build_ts_model(tb, measured=TURBINE_MEASURED, progress=True)
    t1 = time.perf_counter()
    ctl = design_ts_controller(ts)
    obs = design_ts_observer(ts)
    figs["design"] = {"vertices": ts.n_vertices, "build_s": t1 - t0,
                      "controller_s": ctl.solve_time_s, "observer_s": obs.solve_time_s,
                      "solver": ctl.solver, "decay_rate": ctl.decay_rate,
                      "observer_decay_rate": obs.decay_rate,
                      "certificates": [ctl.certificate.ok, obs.certificate.ok]}
    dur = args.duration + args.transient
    figs["regulation"] = []
    keep_plot = {}
    for v in (float(s) for s in args.winds.split(",")):
        wind, field = make_wind(tb, Scenario(v, "A", args.seed, dur, 0.2))
        op = linearize.trim(tb, v)
        c = law_controller(TSController(ts, ctl, obs, tb), "ts", tb)
        r = simulate_closed_loop(params, c, wind, dur, x0=op.x, u0=op.u, progress=True)
        k = r.t >= args.transient
        w = r.channel("rotor_speed")[k]
        truth = np.interp(r.t, field.t, lidar.rotor_effective_wind(field, tb.geometry.tip_radius))
        est = r.channel("wind_est")
        fs = 1.0 / float(np.median(np.diff(r.t)))
        f, g2 = lidar.coherence(est[k], truth[k], fs, nperseg=int(120 * fs))
        b = run_controller(tb, "baseline", Scenario(v, "A", seed=args.seed, duration=dur))
        wb = b.channel("rotor_speed")[b.t >= args.transient]
        row = {"wind_mps": v, "rotor_mean_pct": 100 * (w.mean() / rated - 1),
               "rotor_std_pct": 100 * w.std() / rated, "rotor_max_pct": 100 * (w.max() / rated - 1),
               "baseline_rotor_std_pct": 100 * wb.std() / rated,
               "baseline_rotor_max_pct": 100 * (wb.max() / rated - 1),
               "power_mean_MW": float(r.channel("gen_power")[k].mean() / 1e6),
               "wind_rms_error": float(np.sqrt(np.mean((est[k] - truth[k]) ** 2))),
               "wind_bias": float(np.mean(est[k] - truth[k])),
               "wind_std": float(truth[k].std()),
               "coherence_at_0.02Hz": float(np.interp(0.02, f, g2)),
               "coherence_at_0.1Hz": float(np.interp(0.1, f, g2)),
               "coherence_band_0.5": lidar.coherence_bandwidth(f, g2, 0.5),
               "premise_clipped_pct": 100 * float(np.mean(r.channel("premise_clipped")[k]))}
        figs["regulation"].append(row)
        print(json.dumps(row))
        if v == 15.0 or "wind" not in keep_plot:
            keep_plot["wind"] = (v, r.t, truth, est)
    figs["apc"] = []
    v = 15.0
    wind, field = make_wind(tb, Scenario(v, "A", args.seed, dur, 0.2))
    op = linearize.trim(tb, v)
    for fr in (float(s) for s in args.frequencies.split(",")):
        c = law_controller(TSController(ts, ctl, obs, tb, power_reduction=apc_reference(fr)), "ts",
                           tb)
        r = simulate_closed_loop(params, c, wind, dur, x0=op.x, u0=op.u, progress=True)
        k = r.t >= args.transient
        amp, ph = tracking_response(r.t[k], r.channel("power_ref")[k],
                                    r.channel("gen_power")[k], fr)
        err = r.channel("gen_power")[k] - r.channel("power_ref")[k]
        row = {"f_r_Hz": fr, "amplitude_ratio": amp, "phase_deg": ph,
               "tracking_rms_kW": float(np.sqrt(np.mean(err**2)) / 1e3),
               "rotor_std_pct": float(100 * r.channel("rotor_speed")[k].std() / rated)}
        figs["apc"].append(row)
        print(json.dumps(row))
        if abs(fr - 0.1) < 1e-9:
            keep_plot["apc"] = (r.t, r.channel("power_ref"), r.channel("gen_power"))
    (out / "clemens.json").write_text(json.dumps(figs, indent=1))
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(3, 1, figsize=(9, 9))
    vw, t, tr, es = keep_plot["wind"]
    ax[0].plot(t, tr, label="rotor-disc mean of the field", lw=0.8)
    ax[0].plot(t, es, label="TS observer estimate", lw=0.8)
    ax[0].set(xlabel="t [s]", ylabel="wind [m/s]", title=f"wind estimate, {vw:g} m/s class A")
    ax[0].legend()
    if "apc" in keep_plot:
        t, pr, pg = keep_plot["apc"]
        sel = (t > args.transient) & (t < args.transient + 60)
        ax[1].plot(t[sel], pr[sel] / 1e6, label="reference (eq 11)")
        ax[1].plot(t[sel], pg[sel] / 1e6, label="electrical power")
        ax[1].set(xlabel="t [s]", ylabel="[MW]", title="active power control, f_r = 0.1 Hz, 15 m/s")
        ax[1].legend()
    fa = [r["f_r_Hz"] for r in figs["apc"]]
    ax[2].plot(fa, [r["amplitude_ratio"] for r in figs["apc"]], "o-", label="amplitude ratio")
    ax2 = ax[2].twinx()
    ax2.plot(fa, [r["phase_deg"] for r in figs["apc"]], "s--", color="C1", label="phase [deg]")
    ax[2].set(xlabel="f_r [Hz]", ylabel="|P / P_ref| [-]")
    ax2.set_ylabel("phase [deg]")
    fig.tight_layout()
    fig.savefig(out / "clemens.png", dpi=110)
    print(f"wrote {out / 'clemens.json'} and {out / 'clemens.png'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

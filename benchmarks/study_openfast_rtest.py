"""The plant against OpenFAST's regression case ``5MW_Land_DLL_WTurb`` in turbulence.

Runs mpc-wt's plant through the case (its wind, its start at 12.1 rpm, Jonkman's gains, pitch
as commanded) with the OpenFAST-fidelity effects switched on one after another, and prints, per
step, the differences from OpenFAST's output over 10-60 s and 20-60 s against the targets;
writes the table (JSON), the PSD overlays of the full plant (PNG) and the AeroMap root moments.

    python benchmarks/study_openfast_rtest.py [--out benchmarks/studies/reports/openfast_rtest]
"""
from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np

import linearize
from mpc_wt.assessment.compare import compare_series, window_psd
from mpc_wt.io.openfast_case import aeromap_comparison, read_openfast_case
from mpc_wt.io.openfast_output import read_openfast_output, to_mpcwt_channels
from mpc_wt.plotting import plot_psd_grid
from mpc_wt.run import run_openfast_case

V = Path(__file__).resolve().parents[2] / "shared" / "validation" / "nrel5mw" / "openfast_rtest"
CASE = V / "5MW_Land_DLL_WTurb"
#: the effects, switched on in this order (each row keeps the ones before)
STEPS = (("plant before (none)", {}),
         ("+ blade body forces", {"blade_body_forces": True}),
         ("+ in-plane wind", {"inplane_wind": True}),
         ("+ tower shadow", {"tower_shadow": True}),
         ("+ tower drag", {"tower_drag": True}),
         ("+ twisted modes", {"twisted_modes": True}),
         ("+ skewed wake", {"skewed_wake": True}),
         ("+ unsteady aerodynamics", {"unsteady_aero": True}),
         ("+ AeroDyn 15's node integration", {"integration": "trapezoid"}),
         ("+ deflected blades (all on)", {"deflected_blades": True}))
#: target per statistic: (channel, statistic, bound, unit)
TARGETS = (("flapwise_moment_1", "del_diff_pct", 10.0), ("edgewise_moment_1", "del_diff_pct", 10.0),
           ("lss_torque", "del_diff_pct", 10.0), ("tower_base_fa_moment", "del_diff_pct", 10.0),
           ("tower_base_ss_moment", "del_diff_pct", 10.0),
           ("flapwise_moment_1", "mean_diff_pct", 5.0),
           ("tower_base_fa_moment", "mean_diff_pct", 5.0),
           ("rotor_speed", "std_diff_pct", 10.0))


def _config(on: dict[str, object], dofs: frozenset[str]) -> linearize.PlantConfig:
    base = dict(blade_body_forces=False, inplane_wind=False, tower_shadow=False,
                tower_drag=False, twisted_modes=False, unsteady_aero=False, skewed_wake=False,
                deflected_blades=False, integration="midpoint")
    return linearize.PlantConfig(dofs, **{**base, **on})


def _summary(rows: list[dict]) -> dict[str, float]:
    by = {r["channel"]: r for r in rows}
    out = {f"{c}.{k}": float(by[c][k]) for c, k, _ in TARGETS}
    out["pitch_mean_diff_deg"] = math.degrees(by["pitch_1"]["mean"] - by["pitch_1"]["mean_ref"])
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="benchmarks/studies/reports/openfast_rtest")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    case = read_openfast_case(CASE / "5MW_Land_DLL_WTurb.fst", wind=V / "wind" /
                              "90m_12mps_twr.bts", turbine=linearize.load_turbine("nrel5mw"))
    of = read_openfast_output(CASE / "5MW_Land_DLL_WTurb.outb")
    cols_of, _ = to_mpcwt_channels(of, "outb")
    table, on, last = [], {}, None
    for label, extra in STEPS:
        on = {**on, **extra}
        tic = time.perf_counter()
        res = run_openfast_case(case, "jonkman", config=_config(on, case.config.dofs))
        wall = time.perf_counter() - tic
        ours = {n: res.channel(n) for n in res.channels()}
        entry = {"step": label, "wall_s": wall}
        for w in ((10.0, 60.0), (20.0, 60.0)):
            entry[f"{w[0]:g}-{w[1]:g}"] = _summary(compare_series(of.t, cols_of, res.t, ours, w))
        table.append(entry)
        last = res
        s = entry["10-60"]
        print(f"{label:34s} pitch {s['pitch_mean_diff_deg']:+5.2f} deg | " + " ".join(
            f"{c.split('_')[0][:6]}.{k.split('_')[0]} {s[f'{c}.{k}']:+6.1f}"
            for c, k, _ in TARGETS) + f" | {wall:.1f} s")
    print("targets: " + ", ".join(f"{c} {k} within {b:g} %" for c, k, b in TARGETS)
          + ", pitch mean within 0.4 deg")
    aero = aeromap_comparison(V / "5MW_Land_AeroMap" / "5MW_Land_AeroMap.outb",
                              linearize.load_turbine("nrel5mw"))
    worst = max(abs(r["flapwise_kNm"] / r["flapwise_of_kNm"] - 1) for r in aero
                if abs(r["flapwise_of_kNm"]) > 1000)
    print(f"AeroMap flapwise root moment (|M| > 1 MN m, {len(aero)} points): largest difference "
          f"{100 * worst:.1f} %")
    (out / "comparison.json").write_text(json.dumps({"steps": table, "aeromap": aero},
                                                    indent=1))
    panels = []
    for name, unit, scale in (("flapwise_moment_1", "(kN m)^2/Hz", 1e3),
                              ("edgewise_moment_1", "(kN m)^2/Hz", 1e3),
                              ("lss_torque", "(kN m)^2/Hz", 1e3),
                              ("tower_base_fa_moment", "(kN m)^2/Hz", 1e3),
                              ("tower_base_ss_moment", "(kN m)^2/Hz", 1e3),
                              ("rotor_speed", "(rpm)^2/Hz", math.pi / 30)):
        runs = [(lab, *window_psd(t, np.asarray(x) / scale, (10.0, 60.0)))
                for lab, t, x in (("OpenFAST", of.t, cols_of[name]),
                                  ("mpc-wt, all effects", last.t, last.channel(name)))]
        panels.append((name, unit, runs))
    plot_psd_grid(panels, out / "psd.png", rotor_hz=12.1 / 60,
                  title="5MW_Land_DLL_WTurb, 10-60 s")
    print(f"wrote {out / 'comparison.json'} and {out / 'psd.png'}")


if __name__ == "__main__":
    main()

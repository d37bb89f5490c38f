"""What the lidar OpenFAST can give costs the LIDAR kinds against mpc-wt's hub-mounted CW lidar:
each exported LIDAR kind on mpc-wt's plant in OpenFAST's regression case (its start, wind and
plant effects; 60 s, statistics over 10-60 s), its lidar records filled by

* ``cw``: mpc-wt's CW lidar, three beams turning with the rotor, 54 m ahead of each blade
  (range weighting and line-of-sight error on, frozen turbulence as InflowWind carries the
  case's field);
* ``points3``: InflowWind's three single points of the docs' file (fixed, 54 m upwind on the
  beams' ring, |V|, one call old);
* ``points5``: five single points on that ring (InflowWind's most), the 1P fitted by least
  squares;
* ``points1``: one single point 54 m upwind of the hub (the collective wind only);

against the baseline on the same plant.

Run:  python benchmarks/openfast_lidar_configs.py [--out DIR]
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

import linearize
import lidar
from mpc_wt.assessment.fatigue import damage_equivalent_load
from mpc_wt.controllers.discon import DisconController
from mpc_wt.io.openfast_case import case_grid_wind, case_wind_field, read_openfast_case
from mpc_wt.io.openfast_run import lidar_points
from mpc_wt.run import export_discon
from mpc_wt.simulation.loop import simulate_closed_loop

SHARED = Path(__file__).resolve().parents[2] / "shared"
FST = (SHARED / "validation" / "nrel5mw" / "openfast_rtest" / "5MW_Land_DLL_WTurb_v5"
       / "5MW_Land_DLL_WTurb.fst")
R = 47.25


def _sensor(config: str, field, turbine):
    if config == "none":
        return None
    g = turbine.geometry
    if config == "cw":
        return lidar.LidarSensor(lidar.CWLidar(g.tip_radius), evolution=False, field=field)
    n = int(config[len("points"):])
    pts = lidar_points(54.0, R, n) if n >= 3 else np.array([[-54.0, 0.0, 0.0]])
    hub = (-g.overhang * math.cos(g.shaft_tilt_rad), 0.0, g.hub_height)
    return lidar.PointLidar(pts, 0.1, hub).bind(field)


def _run(kind: str, config: str, out: Path) -> dict[str, float]:
    turbine = linearize.load_turbine("nrel5mw")
    ex = export_discon(turbine, kind, out / kind, None)
    case = read_openfast_case(FST, turbine=turbine)
    field = case_wind_field(case)
    wind, _ = case_grid_wind(case, field)
    ctl = DisconController(ex.library, ex.input_file, turbine, dt=ex.dt,
                           pitch_control="individual", isolate=False,
                           lidar=_sensor(config, field[0], turbine))
    params = linearize.plant_params(turbine, case.config)
    x0 = case.x0.copy()
    u0 = np.array([x0[5], x0[6], x0[7], turbine.rated_generator_torque])
    res = simulate_closed_loop(params, ctl, wind, case.duration, x0=x0, u0=u0,
                               controller_dt=ex.dt)
    m = res.t >= 10.0
    d = float(res.t[m][-1] - res.t[m][0])

    def dl(name: str, wohler: float) -> float:
        return damage_equivalent_load(res.channel(name)[m], wohler, duration=d)

    pitch = np.degrees(res.channel("pitch_1")[m])
    return {"power_kw": res.channel("gen_power")[m].mean() / 1e3,
            "speed_std_rpm": res.channel("rotor_speed")[m].std() * 30.0 / math.pi,
            "flap": dl("flap_moment_1", 10.0) / 1e6, "shaft": dl("lss_torque", 4.0) / 1e3,
            "tower": dl("tower_base_fa_moment", 4.0) / 1e6,
            "travel": float(np.abs(np.diff(pitch)).sum())}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="openfast-lidar-configs")
    args = ap.parse_args()
    out = Path(args.out)
    base = _run("baseline", "none", out)
    print("| kind | lidar | mean power [kW] | rotor speed std [rpm] | blade 1 out-of-plane DEL "
          "[MN m] | shaft torque DEL [kN m] | tower base fore-aft DEL [MN m] | pitch travel "
          "[deg] |")
    print("|---|---|---|---|---|---|---|---|")

    def row(kind: str, config: str, r: dict[str, float]) -> str:
        rel = {k: (r[k] / base[k] - 1.0) * 100.0 for k in ("flap", "shaft", "tower")}
        return (f"| `{kind}` | {config} | {r['power_kw']:.1f} | {r['speed_std_rpm']:.3f} | "
                f"{r['flap']:.2f} ({rel['flap']:+.1f} %) | {r['shaft']:.0f} "
                f"({rel['shaft']:+.1f} %) | {r['tower']:.2f} ({rel['tower']:+.1f} %) | "
                f"{r['travel']:.0f} |")

    print(row("baseline", "none", base), flush=True)
    for kind in ("mpc-lidar", "baseline+lidar-ff"):
        for config in ("cw", "points3", "points5", "points1"):
            print(row(kind, config, _run(kind, config, out)), flush=True)


if __name__ == "__main__":
    main()

"""Every exportable kind in OpenFAST and on mpc-wt's plant, on OpenFAST's own regression case:
``mpc_wt.run.verify_openfast`` for each, one table (the docs' OpenFAST validation page).

Run:  python benchmarks/openfast_verify_kinds.py CASE.fst --openfast PATH [--out DIR]
      [--kinds baseline mpc ...] [--tmax 60]

``apc`` and ``ts-apc`` are active power control and TS with the power reduction of Clemens et
al. eq 11, both at f_r = 0.05 Hz.

CASE.fst is the v5 input of ``5MW_Land_DLL_WTurb`` (or any NREL 5-MW deck). The LIDAR kinds
run with five single points on the design's ring written into a copy of the deck's InflowWind
file, or with ``--lidar-inflow FILE`` (an InflowWind file with a single-point lidar).
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

import linearize
from mpc_wt.run import verify_openfast

KINDS = ("baseline", "baseline-ct", "ibc", "mpc", "mpc-collective", "lqr-pio", "ts",
         "mpc-lidar", "baseline+lidar-ff", "coleman-ipc", "derate80", "apc", "ts-apc")
#: the rows that are a kind with options: row -> (kind, options)
WITH_OPTIONS = {"apc": ("apc", {"apc_frequency": 0.05}),
                "ts-apc": ("ts", {"apc_frequency": 0.05})}
LIDAR_KINDS = ("mpc-lidar", "baseline+lidar-ff")


def _row(kind: str, doc: dict) -> str:
    r = {x["channel"]: x for x in doc["rows"]}
    g, w, t = r["gen_power"], r["rotor_speed"], r["tower_base_fa_moment"]
    rpm = 30.0 / math.pi
    a, b = doc["pitch_travel_deg"]
    return (f"| `{kind}` | {g['mean_ref'] / 1e3:.1f} / {g['mean'] / 1e3:.1f} | "
            f"{w['mean_ref'] * rpm:.3f} / {w['mean'] * rpm:.3f} | "
            f"{g['max_ref'] / 1e3:.0f} / {g['max'] / 1e3:.0f} | "
            f"{r['flap_moment_1']['del_diff_pct']:+.1f} | {r['lss_torque']['del_diff_pct']:+.1f} | "
            f"{t['del_ref'] / 1e6:.2f} ({t['del_diff_pct']:+.1f}) | {a:.0f} / {b:.0f} | "
            f"{'; '.join(doc['flags']) or 'none'} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("fst")
    ap.add_argument("--openfast", default=None)
    ap.add_argument("--out", default="openfast-verify")
    ap.add_argument("--kinds", nargs="+", default=list(KINDS))
    ap.add_argument("--tmax", type=float, default=None)
    ap.add_argument("--lidar-inflow", default=None)
    args = ap.parse_args()
    turbine = linearize.load_turbine("nrel5mw")
    print("| kind | mean power OpenFAST / mpc-wt [kW] | mean rotor speed [rpm] | largest power "
          "[kW] | blade 1 out-of-plane DEL d% | shaft torque DEL d% | tower base fore-aft DEL "
          "OpenFAST [MN m] (d%) | pitch travel [deg] | flags |")
    print("|---|---|---|---|---|---|---|---|---|")
    for row in args.kinds:
        kind, options = WITH_OPTIONS.get(row, (row, None))
        lidar = kind in LIDAR_KINDS
        doc = verify_openfast(turbine, kind, args.fst, Path(args.out) / row, options,
                              openfast=args.openfast, tmax=args.tmax,
                              inflow=args.lidar_inflow if lidar else None)
        print(_row(row, doc), flush=True)


if __name__ == "__main__":
    main()

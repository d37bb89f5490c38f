"""Every exportable kind in OpenFAST and on mpc-wt's plant on 600 s IEC class-A fields that
mpc-wt writes as TurbSim ``.bts`` (8, 13 and 18 m/s by default): one table per speed, the
docs' OpenFAST validation page.

Run:  python benchmarks/openfast_bts_cases.py CASE.fst --openfast PATH [--out DIR]
      [--speeds 8 13 18] [--kinds baseline mpc ...] [--tmax 600]

CASE.fst is an NREL 5-MW deck (the v5 input of ``5MW_Land_DLL_WTurb``); each speed gets a copy
whose InflowWind file reads the new field and whose ElastoDyn file starts at mpc-wt's trim for
the speed (``mpc_wt.io.openfast_run.write_wind_deck``). The fields' seeds (8xx) are seen by no
design or tuning. Statistics over 60 s to the end.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import linearize
import lidar
from mpc_wt.io.openfast_run import write_wind_deck
from mpc_wt.run import verify_openfast

sys.path.insert(0, str(Path(__file__).parent))
from openfast_verify_kinds import KINDS, _row  # noqa: E402

HEAD = ("| kind | mean power OpenFAST / mpc-wt [kW] | mean rotor speed [rpm] | largest power "
        "[kW] | blade 1 out-of-plane DEL d% | shaft torque DEL d% | tower base fore-aft DEL "
        "OpenFAST [MN m] (d%) | pitch travel [deg] | flags |\n"
        "|---|---|---|---|---|---|---|---|---|")


def case_deck(turbine: linearize.Turbine, fst: str, out: Path, speed: float, seed: int,
              tmax: float) -> Path:
    """The deck of one speed: a class-A field of ``tmax`` + 30 s and the trim at ``speed``.

    The grid is 150 m wide and reaches 5.3 m above the ground (36 rows of 4.84 m), below the
    tower's lowest aerodynamic node above ground (8.5 m): OpenFAST refuses a field that does
    not cover it and has no tower points."""
    out.mkdir(parents=True, exist_ok=True)
    bts = out / f"classA_{speed:g}mps_seed{seed}.bts"
    if not bts.is_file():
        spec = lidar.TurbulenceSpec(mean_speed=speed, turbulence="A", duration=tmax + 30.0,
                                    dt=0.05, width=150.0, height=35 * 150.0 / 31, n_y=32,
                                    n_z=36)
        lidar.generate_field(spec, seed).save(bts)
    start = linearize.trim(turbine, speed)
    return write_wind_deck(fst, out / "deck", bts, tmax=tmax, start=start)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("fst")
    ap.add_argument("--openfast", default=None)
    ap.add_argument("--out", default="openfast-bts")
    ap.add_argument("--speeds", type=float, nargs="+", default=[8.0, 13.0, 18.0])
    ap.add_argument("--kinds", nargs="+", default=list(KINDS))
    ap.add_argument("--tmax", type=float, default=600.0)
    args = ap.parse_args()
    turbine = linearize.load_turbine("nrel5mw")
    for speed in args.speeds:
        seed = 800 + int(round(speed))
        out = Path(args.out) / f"{speed:g}mps"
        deck = case_deck(turbine, args.fst, out, speed, seed, args.tmax)
        print(f"\n### {speed:g} m/s, class A, seed {seed}, {args.tmax:g} s\n\n{HEAD}", flush=True)
        for kind in args.kinds:
            doc = verify_openfast(turbine, kind, deck, out / kind, openfast=args.openfast,
                                  tmax=args.tmax, window=(60.0, None))
            print(_row(kind, doc), flush=True)


if __name__ == "__main__":
    main()

"""``mpcwt trim``, ``mpcwt linearize`` and ``mpcwt aero cp-surface``: the turbine's steady
operation, its linear models and its rotor aerodynamics."""
from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

import numpy as np

import linearize
from mpc_wt.cli.common import (
    to_json,
    add_turbine,
    check_suffix,
    format_table,
    parse_range,
    schedule,
    write_surface_csv,
)
from mpc_wt.errors import UsageError

__all__ = ["add_parsers"]


def add_parsers(sub: Any) -> None:
    """Add ``trim``, ``linearize`` and ``aero`` to the subcommands.

    Parameters
    ----------
    sub : argparse subparsers action
        Of the top-level parser.
    """
    p = sub.add_parser("trim", help="steady operating points")
    add_turbine(p)
    p.add_argument("--wind", default="4:25:1", help="START:STOP:STEP in m/s (default 4:25:1)")
    p.add_argument("--power-W", dest="power_W", type=float, default=None,
                   help="power reference below rated [W]")
    p.add_argument("--json", action="store_true", help="print a JSON list")
    p.add_argument("--report", action="store_true",
                   help="print what the turbine loader read from which file and key (OpenFAST "
                        "decks) before the table")
    p.set_defaults(func=_trim)

    p = sub.add_parser("linearize", help="linear models over mean wind")
    add_turbine(p)
    p.add_argument("--wind", default="4:25:1", help="START:STOP:STEP in m/s (default 4:25:1)")
    p.add_argument("--frozen-wake", action="store_true",
                   help="hold the induced velocities at trim (OpenFAST's FrozenWake; default: "
                        "quasi-steady, as OpenFAST linearizes without it)")
    p.add_argument("--disturbance", choices=("blade", "rotor"), default="blade",
                   help="one wind per blade (default) or one rotor-effective wind")
    p.add_argument("--mbc", action="store_true", help="multi-blade (Coleman) coordinates")
    p.add_argument("--rotor-speed-rpm", type=float, default=None,
                   help="linearize at this rotor speed instead of the trim (with --pitch-deg and "
                        "a single --wind): e.g. an OpenFAST .lin file's operating point")
    p.add_argument("--pitch-deg", type=float, default=None,
                   help="collective pitch of that operating point [deg]")
    p.add_argument("--out", help="models file: .mat (MATLAB), .npz or .json")
    p.add_argument("--json", action="store_true", help="print sensitivities and modes as JSON")
    p.add_argument("--compare", nargs="+", metavar="FILE.lin",
                   help="OpenFAST .lin file(s) (several: one operating point at several "
                        "azimuths, MBC3-averaged): linearize our plant at the file's operating "
                        "point and print the aerodynamic derivatives and modes side by side")
    p.set_defaults(func=_linearize)

    p = sub.add_parser("aero", help="rotor aerodynamics")
    aero = p.add_subparsers(dest="aero_command", required=True)
    q = aero.add_parser("cp-surface", help="C_P(lambda, pitch) table and plot")
    add_turbine(q)
    q.add_argument("--out", help="CSV file (rows pitch, columns tip-speed ratio), or with "
                                 "--format rosco a Cp_Ct_Cq.txt performance table")
    q.add_argument("--format", choices=("csv", "rosco"), default="csv",
                   help="csv: C_P only; rosco: C_P, C_T and C_Q in ROSCO's Cp_Ct_Cq.txt layout "
                        "(read by linearize.read_rotor_performance and by ROSCO's toolbox)")
    q.add_argument("--shear", type=float, default=0.0,
                   help="power-law shear exponent of the steady wind (ROSCO's tuning uses 0.2)")
    q.add_argument("--plot", help="PNG file")
    q.add_argument("--tsr", default="2:16:0.25", help="START:STOP:STEP (default 2:16:0.25)")
    q.add_argument("--pitch", default="-2:24:0.5",
                   help="START:STOP:STEP in deg; write --pitch=-2:24:0.5 for a negative start")
    q.set_defaults(func=_cp_surface)


def _trim(args: argparse.Namespace) -> int:
    winds = parse_range(args.wind, "--wind")
    turbine = linearize.load_turbine(args.turbine)
    if args.report and str(turbine.report):
        print(turbine.report)
    points = schedule(turbine, winds, args.power_W, progress=not args.json)
    if args.json:
        print(to_json([p.as_dict() for p in points]))
    else:
        print(f"# {turbine.name}")
        print(format_table(points))
    return 0


def _cp_surface(args: argparse.Namespace) -> int:
    if not (args.out or args.plot):
        raise UsageError("mpcwt aero cp-surface: give --out FILE.csv and/or --plot FILE.png")
    tsr = parse_range(args.tsr, "--tsr")
    pitch = parse_range(args.pitch, "--pitch")
    if np.any(tsr < 0):
        raise UsageError(f"--tsr must be >= 0, got {args.tsr!r}")
    turbine = linearize.load_turbine(args.turbine)
    if args.format == "rosco":
        if not args.out:
            raise UsageError("--format rosco needs --out FILE.txt")
        if np.any(tsr <= 0):
            raise UsageError(f"--tsr must be > 0 for a ROSCO table (C_Q = C_P / TSR), "
                             f"got {args.tsr!r}")
        perf = linearize.rotor_performance(turbine, tsr, pitch, shear_exponent=args.shear)
        linearize.write_rotor_performance(perf, args.out)
        print(f"wrote {args.out} (ROSCO Cp_Ct_Cq layout, {tsr.size} TSR x {pitch.size} pitch)")
        cp = perf.cp.T
    else:
        lam, pit = np.meshgrid(tsr, pitch)
        cp = linearize.steady_coefficients(turbine, lam, pit, shear_exponent=args.shear)[0]
        if args.out:
            write_surface_csv(tsr, pitch, cp, Path(args.out))
            print(f"wrote {args.out}")
    if args.plot:
        from mpc_wt.plotting import plot_cp_surface

        plot_cp_surface(tsr, pitch, cp, args.plot, title=f"{turbine.name}: C_P")
        print(f"wrote {args.plot}")
    i, j = np.unravel_index(int(np.argmax(cp)), cp.shape)
    print(f"C_P max {cp[i, j]:.4f} at tip-speed ratio {tsr[j]:.3f}, pitch {pitch[i]:.2f} deg")
    return 0


def _compare(args: argparse.Namespace) -> int:
    from linearize.openfast_lin import compare_with_openfast

    files = args.compare
    model = linearize.read_lin(files[0]) if len(files) == 1 else linearize.read_lin_set(files)
    res = compare_with_openfast(linearize.load_turbine(args.turbine), model)
    if args.json:
        print(to_json(res))
        return 0
    op = res["operating_point"]
    print(f"# {files[0]}{' + %d more' % (len(files) - 1) if len(files) > 1 else ''}: "
          f"{op['wind_mps']:g} m/s, {op['rotor_speed_rpm']:.3f} rpm, pitch "
          f"{op['pitch_deg']:.3f} deg; our DOFs {', '.join(op['dofs'])}")
    print(f"{'derivative [SI]':22s} {'OpenFAST':>14s} {'mpc-wt':>14s} {'ratio':>8s}")
    for k, d in res["derivatives"].items():
        cells = [f"{d[c]:14.5g}" if d[c] is not None else f"{'n/a':>14s}"
                 for c in ("openfast", "mpc_wt")]
        ratio = f"{d['ratio']:8.4f}" if d["ratio"] is not None else f"{'n/a':>8s}"
        print(f"{k:22s} {cells[0]} {cells[1]} {ratio}")
    for who in ("openfast", "mpc_wt"):
        modes = ", ".join(f"{m['name']} {m['frequency_Hz']:.3f} Hz ({m['damping_ratio']:.3f})"
                          for m in res["modes"][who][:8])
        print(f"# modes {who}: {modes}")
    return 0


def _linearize(args: argparse.Namespace) -> int:
    if args.compare:
        return _compare(args)
    winds = parse_range(args.wind, "--wind")
    check_suffix(args.out, "--out", (".mat", ".npz", ".json"))
    given = (args.rotor_speed_rpm, args.pitch_deg)
    if given != (None, None) and (None in given or winds.size != 1):
        raise UsageError("--rotor-speed-rpm and --pitch-deg go together, with a single --wind")
    turbine = linearize.load_turbine(args.turbine)
    opts = dict(wake="frozen" if args.frozen_wake else "quasi-steady",
                disturbance=args.disturbance, coordinates="mbc" if args.mbc else "blade")
    if None in given:
        fam = linearize.linearize_family(turbine, winds, progress=not args.json, **opts)
    else:
        op = linearize.operating_point(turbine, float(winds[0]),
                                       args.rotor_speed_rpm * math.pi / 30.0,
                                       math.radians(args.pitch_deg))
        fam = linearize.LinearModelFamily(
            winds, (linearize.linearize(turbine, float(winds[0]), operating_point=op, **opts),))
    if args.out:
        fam.save(args.out)
        if not args.json:
            print(f"wrote {args.out}: {len(fam.models)} models, {fam.models[0].n_x} states, "
                  f"inputs {list(fam.models[0].inputs)}")
    rows = [{"wind_mps": m.wind_mps, "pitch_deg": m.info["pitch_deg"],
             "rotor_speed_rpm": m.info["rotor_speed_rpm"], **linearize.sensitivities(m),
             "modes": m.modes()} for m in fam.models]
    if args.json:
        print(to_json(rows))
        return 0
    print(f"{'wind [m/s]':>10s} {'pitch [deg]':>11s} {'dP/dpitch [MW/rad]':>18s} "
          f"{'dQ/domega [kNms]':>16s} {'dT/dV [kN s/m]':>14s}  modes [Hz, damping]")
    for r in rows:
        modes = ", ".join(f"{md['name']} {md['frequency_Hz']:.3f} {md['damping_ratio']:.3f}"
                          for md in r["modes"])
        print(f"{r['wind_mps']:10.2f} {r['pitch_deg']:11.3f} "
              f"{r['dP_dpitch_W_per_rad'] / 1e6:18.3f} {r['dQ_domega'] / 1e3:16.1f} "
              f"{r['dT_dV'] / 1e3:14.2f}  {modes}")
    return 0

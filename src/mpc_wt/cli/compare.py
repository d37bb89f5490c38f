"""``mpcwt compare-openfast``: an OpenFAST run reproduced on mpc-wt's plant and compared with
it, channel by channel (means, standard deviations, DELs) with PSD overlays. ``mpcwt
verify-openfast``: a design exported, run in the user's OpenFAST on the user's deck and on
mpc-wt's plant, compared and its differences beyond stated bounds flagged.
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

import numpy as np

import linearize
from mpc_wt.cli.common import check_out_folder, pairs, to_json
from mpc_wt.errors import UsageError

__all__ = ["add_parsers"]

#: the channels whose PSDs are drawn (when both runs have them), with their unit after scaling
_PSD = (("flapwise_moment_1", "(kN m)^2/Hz", 1e3), ("edgewise_moment_1", "(kN m)^2/Hz", 1e3),
        ("lss_torque", "(kN m)^2/Hz", 1e3), ("tower_base_fa_moment", "(kN m)^2/Hz", 1e3),
        ("tower_base_ss_moment", "(kN m)^2/Hz", 1e3), ("rotor_speed", "(rpm)^2/Hz", math.pi / 30),
        ("pitch_1", "(deg)^2/Hz", math.pi / 180), ("gen_power", "(kW)^2/Hz", 1e3))


def add_parsers(sub: Any) -> None:
    """Add ``compare-openfast`` to the subcommands.

    Parameters
    ----------
    sub : argparse subparsers action
        Of the top-level parser.
    """
    p = sub.add_parser("compare-openfast",
                       help="run an OpenFAST case on mpc-wt's plant and compare it with the "
                            "case's OpenFAST output")
    p.add_argument("fst", help="the case's .fst")
    p.add_argument("--outb", required=True, help="the case's OpenFAST output (.outb or .out)")
    p.add_argument("--wind", default=None,
                   help="the TurbSim .bts the case runs in (default: InflowWind's FileName_BTS, "
                        "or its steady wind)")
    p.add_argument("--turbine", default=None,
                   help="turbine name or file, when the deck alone does not make one (a deck "
                        "with Jonkman's compiled controller has no DISCON.IN)")
    p.add_argument("--controller", default="auto", choices=("auto", "jonkman", "rosco",
                                                            "discon"),
                   help="jonkman: the baseline with Jonkman's published gains; rosco: ROSCO's "
                        "library with the case's DISCON.IN; discon: --library with "
                        "--discon-in; auto (default): rosco when ServoDyn names a DISCON.IN")
    p.add_argument("--library", default=None, help="a controller library, for --controller "
                                                   "discon")
    p.add_argument("--discon-in", default=None, help="its input file (default: the case's)")
    p.add_argument("--plant", default="case", choices=("case", "default"),
                   help="case (default): the DOFs and aerodynamic effects of the case's "
                        "ElastoDyn and AeroDyn files; default: mpc-wt's default plant")
    p.add_argument("--window", nargs=2, type=float, default=None, metavar=("FROM", "TO"),
                   help="statistics window [s] (default: 10 s to the end)")
    p.add_argument("--out", default=None,
                   help="folder for comparison.json, psd.png and our run (ours.nc)")
    p.add_argument("--json", action="store_true", help="print the rows as JSON")
    p.set_defaults(func=_compare)
    _add_verify(sub)


def _add_verify(sub: Any) -> None:
    from mpc_wt.io.openfast_run import OPENFAST_ENV
    from mpc_wt.run import VERIFY_BOUNDS

    bounds = ", ".join(f"{what} {b:g}" for _, _, b, what in VERIFY_BOUNDS)
    p = sub.add_parser(
        "verify-openfast",
        help="export a controller kind, run it in your OpenFAST on your deck and on mpc-wt's "
             "plant, and flag where they differ",
        description="Export KIND for the turbine, run OpenFAST on a copy of the deck's main "
                    "and ServoDyn files pointed at the library (the deck is not written to), "
                    "run the same case on mpc-wt's plant, print both side by side and flag "
                    f"each difference beyond its bound ({bounds}; the largest power 2 % of "
                    "rated, pitch travel 10 %, OpenFAST's largest power 1.1 x rated). Exit "
                    "status 3 when a difference is flagged.")
    p.add_argument("kind", help="an exportable controller kind (mpcwt controllers lists them)")
    p.add_argument("fst", help="the deck's main file (.fst)")
    p.add_argument("--turbine", default="nrel5mw",
                   help="turbine name or file the design is for (default nrel5mw)")
    p.add_argument("--openfast", default=None,
                   help=f"the OpenFAST executable (default ${OPENFAST_ENV}, else openfast on "
                        "PATH)")
    p.add_argument("--tmax", type=float, default=None, help="run length [s] (default the "
                                                             "deck's TMax)")
    p.add_argument("--window", nargs=2, type=float, default=None, metavar=("FROM", "TO"),
                   help="statistics window [s] (default: 10 s to the end)")
    p.add_argument("--inflow", default=None, metavar="FILE",
                   help="an InflowWind file in place of the deck's (a LIDAR kind needs one "
                        "with a single-point lidar, SensorType 1)")
    p.add_argument("--option", action="append", metavar="NAME=VALUE",
                   help="an option of the kind (repeatable; YAML values)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", dest="values",
                   help="a value in the copies of the deck both plants run (repeatable): "
                        "KEY of the main file, FILEKEY:KEY of the file it names under FILEKEY, "
                        "e.g. --set CompHydro=0 --set EDFile:PtfmSgDOF=False (docs: offshore "
                        "decks)")
    p.add_argument("--out", required=True, help="folder for the library, OpenFAST's run, "
                                               "ours.nc, verify.json and verify.png")
    p.add_argument("--json", action="store_true", help="print verify.json")
    p.set_defaults(func=_verify)


def _verify(args: argparse.Namespace) -> int:
    from mpc_wt.run import verify_openfast

    check_out_folder("--out", args.out)
    if not Path(args.fst).is_file():
        raise UsageError(f"fst: {args.fst} does not exist")
    if args.inflow is not None and not Path(args.inflow).is_file():
        raise UsageError(f"--inflow: {args.inflow} does not exist")
    if args.tmax is not None and not args.tmax > 0:
        raise UsageError(f"--tmax must be > 0 s, got {args.tmax:g}")
    turbine = linearize.load_turbine(args.turbine)
    window = tuple(args.window) if args.window else (10.0, None)
    doc = verify_openfast(turbine, args.kind, args.fst, args.out,
                          pairs(args.option, "--option") or None, openfast=args.openfast,
                          tmax=args.tmax, window=window, progress=True,
                          inflow=args.inflow, values=pairs(args.values, "--set") or None)
    if args.json:
        print(to_json(doc))
    else:
        print(_verify_table(doc))
    return 3 if doc["flags"] else 0


def _verify_table(doc: dict[str, Any]) -> str:
    w = doc["window_s"]
    lines = [f"{doc['controller']} in OpenFAST ({doc['openfast']}) and on mpc-wt's plant, "
             f"{w[0]:g}-{w[1]:g} s",
             f"{'channel':24s} {'mean OF':>11s} {'mpc-wt':>11s} {'d%':>7s} {'std d%':>7s} "
             f"{'max OF':>11s} {'mpc-wt':>11s} {'DEL d%':>7s}"]
    for r in doc["rows"]:
        d = f"{r['del_diff_pct']:7.1f}" if "del_diff_pct" in r else f"{'':7s}"
        lines.append(f"{r['channel']:24s} {r['mean_ref']:11.5g} {r['mean']:11.5g} "
                     f"{r['mean_diff_pct']:7.2f} {r['std_diff_pct']:7.1f} {r['max_ref']:11.5g} "
                     f"{r['max']:11.5g} {d}")
    a, b = doc["pitch_travel_deg"]
    lines.append(f"pitch travel (blade 1): OpenFAST {a:.1f} deg, mpc-wt {b:.1f} deg")
    lines += ([f"FLAG {f}" for f in doc["flags"]] or ["no difference beyond its bound"])
    plot = doc["files"]["plot"]
    lines.append(f"wrote {plot}, {Path(plot).with_name('verify.json')}")
    return "\n".join(lines)


def _compare(args: argparse.Namespace) -> int:
    from mpc_wt.assessment.compare import compare_series
    from mpc_wt.io.openfast_case import check_case_output, read_openfast_case
    from mpc_wt.io.openfast_output import read_openfast_output, to_mpcwt_channels
    from mpc_wt.run import run_openfast_case

    if args.controller == "discon" and args.library is None:
        raise UsageError("--controller discon needs --library LIB")
    check_out_folder("--out", args.out)
    turbine = linearize.load_turbine(args.turbine) if args.turbine else None
    case = read_openfast_case(args.fst, wind=args.wind, turbine=turbine)
    of = read_openfast_output(args.outb)
    check_case_output(case, of, str(args.outb))
    cols_of, _ = to_mpcwt_channels(of, str(args.outb))
    t_of = of.t
    config = linearize.PlantConfig() if args.plant == "default" else None
    res = run_openfast_case(case, args.controller, library=args.library,
                            discon_in=args.discon_in, config=config, progress=True)
    ours = {n: res.channel(n) for n in res.channels()}
    window = tuple(args.window) if args.window else (10.0, None)
    if window[1] is not None and window[1] > min(t_of[-1], res.t[-1]) + 1e-9:
        raise UsageError(f"--window: {window[1]:g} s is past the runs' end "
                         f"{min(t_of[-1], res.t[-1]):g} s")
    rows = compare_series(t_of, cols_of, res.t, ours, window)
    if args.json:
        print(to_json(rows))
    else:
        print(_table(rows, window, res.meta))
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        res.save(out / "ours.nc")
        (out / "comparison.json").write_text(to_json(
            {"window_s": list(window), "case": res.meta["openfast_case"],
             "controller": res.meta["controller"], "rows": rows}))
        png = _plot(t_of, cols_of, res, window, out / "psd.png", Path(args.fst).stem)
        print(f"wrote {out / 'comparison.json'}, {png}, {out / 'ours.nc'}")
    return 0


def _table(rows: list[dict[str, Any]], window: tuple[float, float | None],
           meta: dict[str, Any]) -> str:
    hi = "end" if window[1] is None else f"{window[1]:g} s"
    lines = [f"OpenFAST vs mpc-wt, {window[0]:g} s to {hi}; controller {meta['controller']}",
             f"{'channel':24s} {'mean OF':>12s} {'mean ours':>12s} {'d%':>7s} "
             f"{'std OF':>11s} {'std ours':>11s} {'d%':>7s} {'DEL d%':>7s}"]
    for r in rows:
        d = f"{r['del_diff_pct']:7.1f}" if "del_diff_pct" in r else f"{'':7s}"
        lines.append(f"{r['channel']:24s} {r['mean_ref']:12.5g} {r['mean']:12.5g} "
                     f"{r['mean_diff_pct']:7.2f} {r['std_ref']:11.4g} {r['std']:11.4g} "
                     f"{r['std_diff_pct']:7.1f} {d}")
    return "\n".join(lines)


def _plot(t_of: np.ndarray, cols_of: dict[str, np.ndarray], res: Any,
          window: tuple[float, float | None], path: Path, title: str) -> Path:
    from mpc_wt.assessment.compare import window_psd
    from mpc_wt.plotting import plot_psd_grid

    hi = window[1] if window[1] is not None else float(min(t_of[-1], res.t[-1]))
    panels = []
    for name, unit, scale in _PSD:
        if name not in cols_of or name not in res.channels():
            continue
        runs = []
        for label, t, x in (("OpenFAST", t_of, cols_of[name]), ("mpc-wt", res.t,
                                                                res.channel(name))):
            f, p = window_psd(t, np.asarray(x) / scale, (window[0], hi))
            runs.append((label, f, p))
        panels.append((name, unit, runs))
    rotor = float(np.mean(res.channel("rotor_speed"))) / (2 * math.pi)
    return plot_psd_grid(panels, path, rotor_hz=rotor,
                         title=f"{title}: {window[0]:g}-{hi:g} s")

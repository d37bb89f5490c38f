"""``mpcwt design`` and ``mpcwt export``: gain synthesis of the registered kinds that have a
design function, and export of their gain tables."""
from __future__ import annotations

import argparse
import inspect
from pathlib import Path
from typing import Any

import linearize
from mpc_wt.cli.common import add_turbine, check_out_folder, floats, number_pairs, parse_range
from mpc_wt.controllers.ipc import IBC_LOOP_GAIN
from mpc_wt.errors import GainTableError, UsageError
from mpc_wt.io.gain_tables import FORMATS

__all__ = ["add_parsers"]


def add_parsers(sub: Any) -> None:
    """Add ``design`` and ``export`` to the subcommands.

    Parameters
    ----------
    sub : argparse subparsers action
        Of the top-level parser.
    """
    from mpc_wt.registry.registry import designs

    p = sub.add_parser("design", help="gain synthesis: baseline PI, LQR family, TS by LMIs, "
                                      "IBC, Coleman IPC; the scheduled MPC's grid (mpc, mpc-collective, "
                                      "mpc-lidar); the LIDAR feedforward (baseline+lidar-ff)")
    p.add_argument("kind", choices=list(designs()))
    add_turbine(p)
    p.add_argument("--out", required=True, help="design directory (design.json, gains.png)")
    p.add_argument("--wind", help="lqr, ts: START:STOP:STEP or a comma list (default lqr "
                                  "12:25:1, ts 12,14,16,19,22,25) [m/s]")
    p.add_argument("--reductions", default="0,0.4,0.8",
                   help="ts: comma list of vertex power reductions (default 0,0.4,0.8)")
    p.add_argument("--decay-rate", type=float, default=None,
                   help="ts: controller decay [1/s] (default: the fastest of 0.2, 0.15, 0.1 "
                        "whose loop, scheduled on the estimated wind, decays on the whole "
                        "plant's linear models)")
    p.add_argument("--observer-decay-rate", type=float, default=None,
                   help="ts: observer decay [1/s] (default: the fastest of 1, 0.7, 0.5, 0.35, "
                        "0.25 whose loop decays with the controller's)")
    p.add_argument("--weight", action="append",
                   help="lqr: NAME=VALUE weight on a state or output (repeatable; default "
                        "rotor_speed=5, tower_fa_velocity=1)")
    p.add_argument("--scale", action="append",
                   help="lqr: NAME=VALUE typical magnitude dividing a weight (repeatable)")
    p.add_argument("--observer-q", type=float, default=1e3,
                   help="lqr: PI observer q of Q_obs = diag(I, q I) (0: no observer)")
    p.add_argument("--omega-n", type=float, default=None,
                   help="baseline: PI design [rad/s] (default 0.6 x rated rotor speed / 12.1 "
                        "rpm)")
    p.add_argument("--zeta", type=float, default=0.7, help="baseline: PI damping [-]")
    p.add_argument("--power-fraction", type=float, default=1.0,
                   help="baseline, ibc, coleman-ipc: tune for a derated turbine at this "
                        "fraction of rated power, in (0, 1]")
    p.add_argument("--loop-gain", type=float, default=None,
                   help=f"ibc: loop gain at 1P [-] (default {IBC_LOOP_GAIN:g}, less on pitch "
                        "drives too slow for a 2 deg cyclic at half their rate)")
    p.set_defaults(func=_design)

    p = sub.add_parser("export", help="export a design: its gain table (csv, json, mat), a "
                                      "ROSCO DISCON.IN (rosco) or a Bladed-style controller "
                                      "library with its C sources (discon)")
    p.add_argument("design", help="design directory (from `mpcwt design`) or gain-table JSON")
    p.add_argument("--format", required=True, choices=FORMATS)
    p.add_argument("--to", "--out", dest="to",
                   help="output directory (default: the design directory)")
    p.add_argument("--turbine", default=None,
                   help="rosco, discon: the design's turbine, if it is not a packaged one (a "
                        "turbine.yaml or an OpenFAST .fst deck)")
    p.set_defaults(func=_export)


def _positive(name: str, value: float, allow_zero: bool = False) -> float:
    ok = value >= 0 if allow_zero else value > 0
    if not (ok and value == value and abs(value) != float("inf")):
        raise UsageError(f"{name} must be {'>= 0' if allow_zero else '> 0'}, got {value!r}")
    return value


def _design_args(args: argparse.Namespace) -> dict[str, Any]:
    """Every design argument, checked before any work (names the flag)."""
    from mpc_wt.controllers.baseline import check_power_fraction

    try:
        frac = check_power_fraction(args.power_fraction, "--power-fraction")
    except ValueError as err:
        raise UsageError(str(err)) from None
    winds = parse_range(args.wind, "--wind") if args.wind else None
    return {"power_fraction": frac,
            "omega_n_rad_s": (None if args.omega_n is None
                              else _positive("--omega-n", args.omega_n)),
            "zeta": _positive("--zeta", args.zeta),
            "loop_gain": (None if args.loop_gain is None
                          else _positive("--loop-gain", args.loop_gain)), "winds": winds,
            "reductions": floats(args.reductions, "--reductions"),
            "decay_rate": (None if args.decay_rate is None
                           else _positive("--decay-rate", args.decay_rate)),
            "observer_decay_rate": (None if args.observer_decay_rate is None else _positive(
                "--observer-decay-rate", args.observer_decay_rate)),
            "weights": number_pairs(args.weight, "--weight") or None,
            "scales": number_pairs(args.scale, "--scale"),
            "observer_q": _positive("--observer-q", args.observer_q, allow_zero=True)}


def _design(args: argparse.Namespace) -> int:
    from mpc_wt.io.gain_tables import save_design
    from mpc_wt.plotting import plot_design
    from mpc_wt.registry.registry import designs

    check_out_folder("--out", args.out)
    kind = designs()[args.kind]
    every = _design_args(args)
    wanted = inspect.signature(kind.design).parameters
    turbine = linearize.load_turbine(args.turbine)
    doc, note = kind.design(turbine, **{k: v for k, v in every.items() if k in wanted})
    p = save_design(doc, args.out)
    plot_design(doc, Path(args.out) / "gains.png")
    print(f"wrote {p} and {Path(args.out) / 'gains.png'} ({args.kind}: {note})")
    return 0


def _export_discon(args: argparse.Namespace, turbine: Any) -> list[Path] | None:
    """``--format discon``: the saved design exported as a controller library (its kind's
    export, :func:`mpc_wt.run.export_saved_design`); None for the other formats."""
    from mpc_wt.io.gain_tables import design_turbine, load_design
    from mpc_wt.run import export_saved_design

    if args.format != "discon":
        return None
    try:
        doc = load_design(args.design)
        p = Path(args.design)
        out = Path(args.to) if args.to else (p if p.is_dir() else p.parent)
        ex = export_saved_design(doc, design_turbine(doc, turbine), out)
    except (GainTableError, ValueError) as err:
        raise UsageError(f"{args.design}: {err}") from None
    if ex.note:
        print(f"note: {ex.note}")
    return ex.files()


def _export(args: argparse.Namespace) -> int:
    from mpc_wt.io.gain_tables import export

    check_out_folder("--to", args.to)
    turbine = linearize.load_turbine(args.turbine) if args.turbine else None
    try:
        files = _export_discon(args, turbine) or export(args.design, args.format, args.to,
                                                             turbine)
    except GainTableError as err:
        raise UsageError(str(err)) from None
    print("wrote " + ", ".join(str(f) for f in files))
    return 0

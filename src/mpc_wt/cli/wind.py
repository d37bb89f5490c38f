"""``mpcwt wind generate`` and ``mpcwt lidar evaluate``: turbulent fields and the CW LIDAR."""
from __future__ import annotations

import argparse
import math
from typing import Any

import linearize
from lidar.iec import CONDITIONS, IEC_TURBULENCE
from mpc_wt.cli.common import add_turbine, to_json
from mpc_wt.errors import UsageError

__all__ = ["add_parsers"]


def add_parsers(sub: Any) -> None:
    """Add ``wind`` and ``lidar`` to the subcommands.

    Parameters
    ----------
    sub : argparse subparsers action
        Of the top-level parser.
    """
    p = sub.add_parser("wind", help="turbulent wind fields")
    wind = p.add_subparsers(dest="wind_command", required=True)
    q = wind.add_parser("generate", help="IEC 61400-1 Kaimal field (TurbSim IECKAI model)")
    q.add_argument("--mean", type=float, required=True, help="hub-height mean speed [m/s]")
    q.add_argument("--class", dest="turbulence_class", choices=sorted(IEC_TURBULENCE),
                   default="A")
    q.add_argument("--ti", type=float, default=None, help="turbulence intensity instead of a class")
    q.add_argument("--seed", type=int, default=1)
    q.add_argument("--duration", type=float, default=600.0, help="[s]")
    q.add_argument("--dt", type=float, default=0.05, help="[s] (default 0.05: 20 Hz)")
    q.add_argument("--n", type=int, default=32, help="grid points per side (default 32)")
    q.add_argument("--width", type=float, default=150.0, help="grid side [m]")
    q.add_argument("--hub-height", type=float, default=90.0, help="[m]")
    q.add_argument("--shear", type=float, default=0.2, help="power-law exponent")
    q.add_argument("--condition", default=None,
                   choices=sorted(CONDITIONS),
                   help="an IEC 61400-1 ed. 3 wind condition (default: the NTM field, or --ti)")
    q.add_argument("--iec-class", default="I", help="wind turbine class I, II or III (for "
                   "--condition; V_ref 50, 42.5, 37.5 m/s)")
    q.add_argument("--diameter", type=float, default=126.0, help="rotor diameter [m] (for "
                   "--condition)")
    q.add_argument("--cut-in", type=float, default=None, help="[m/s] operating events below "
                   "it are refused")
    q.add_argument("--cut-out", type=float, default=None, help="[m/s] operating events above "
                   "it are refused")
    q.add_argument("--sign", type=int, default=1, choices=(1, -1),
                   help="direction of a direction change or shear")
    q.add_argument("--t-start", type=float, default=30.0, help="start of the transient [s]")
    q.add_argument("--plot", default=None, help="PNG of the condition over time")
    q.add_argument("--out", required=True, help=".bts (TurbSim) or .npz (native)")
    q.set_defaults(func=_generate)

    p = sub.add_parser("lidar", help="CW LIDAR preview")
    lid = p.add_subparsers(dest="lidar_command", required=True)
    q = lid.add_parser("evaluate", help="coherence bandwidth and preview error on a field")
    q.add_argument("--field", required=True, help=".bts or .npz wind field")
    add_turbine(q)
    q.add_argument("--focus", type=float, default=None,
                   help="axial focus distance [m] (default 6/7 of the rotor radius: 54 m on "
                        "the NREL 5-MW)")
    q.add_argument("--point", action="store_true", help="point measurement (no range weighting)")
    q.add_argument("--no-los-error", action="store_true", help="measure u directly")
    q.add_argument("--noise", type=float, default=0.0, help="LOS noise std [m/s]")
    q.add_argument("--evolution", action="store_true",
                   help="wind evolution between the focus and the rotor (Simley and Pao)")
    q.add_argument("--json", action="store_true")
    q.add_argument("--plots", help="directory for lidar_coherence.png and lidar_scan.png")
    q.set_defaults(func=_evaluate)


def _generate(args: argparse.Namespace) -> int:
    import lidar
    from mpc_wt.cli.common import check_suffix

    check_suffix(args.out, "--out", (".bts", ".npz"))
    _check_size(args)
    if args.condition is not None:
        return _generate_condition(args)
    turb: str | float = args.turbulence_class if args.ti is None else args.ti
    try:
        spec = lidar.TurbulenceSpec(args.mean, turb, hub_height=args.hub_height,
                                    width=args.width, height=args.width, n_y=args.n, n_z=args.n,
                                    duration=args.duration, dt=args.dt,
                                    shear_exponent=args.shear)
    except TypeError as err:
        raise UsageError(str(err)) from None
    field = lidar.generate_field(spec, args.seed)
    out = field.save(args.out)
    u = field.u
    print(f"wrote {out}: {u.shape[0]} steps x {u.shape[1]} x {u.shape[2]} points, "
          f"hub TI {u[:, u.shape[1] // 2, u.shape[2] // 2].std() / args.mean:.3f}")
    return 0


def _check_size(args: argparse.Namespace) -> None:
    """Refuse a field too long, too fine or too large for the memory available, before any
    work (3 wind components in float32, about twice that while generated)."""
    from mpc_wt.simulation.memory import FIELD_PEAK, RunMemory, check_run_memory
    from mpc_wt.simulation.scenario import MAX_DURATION_S

    if not (math.isfinite(args.duration) and 0.0 < args.duration <= MAX_DURATION_S):
        raise UsageError(f"--duration must be in (0, {MAX_DURATION_S:g}] s (3 h), got "
                         f"{args.duration:g}")
    if not (math.isfinite(args.dt) and 0.0 < args.dt <= 1.0):
        raise UsageError(f"--dt must be in (0, 1] s, got {args.dt:g}")
    if not 2 <= args.n <= MAX_GRID_POINTS:
        raise UsageError(f"--n must be between 2 and {MAX_GRID_POINTS} grid points per side, "
                         f"got {args.n}")
    one = (args.duration / args.dt + 1) * args.n**2 * 4.0 * 3
    check_run_memory(RunMemory(FIELD_PEAK * one, 0.0),
                     what=f"{args.duration:g} s field of {args.n} x {args.n} points every "
                          f"{args.dt:g} s")


#: The finest grid ``wind generate`` makes (points per side; TurbSim's fields are 10-64).
MAX_GRID_POINTS = 256


def _generate_condition(args: argparse.Namespace) -> int:
    """An IEC wind condition (:func:`lidar.iec_field`) written as a field, with its plot."""
    import lidar

    if args.ti is not None:
        raise UsageError("--ti does not go with --condition: the condition sets sigma_1 from "
                         "--class and --iec-class")
    try:
        site = lidar.IECSite(args.iec_class, args.turbulence_class, args.hub_height,
                             args.diameter, args.shear, cut_in=args.cut_in,
                             cut_out=args.cut_out)
        turbulent = args.condition in ("ntm", "etm")
        field = lidar.iec_field(args.condition, args.mean, site, t_start=args.t_start,
                                duration=args.duration if turbulent else None, dt=args.dt,
                                width=args.width, n=args.n, sign=args.sign, seed=args.seed)
    except ValueError as err:
        raise UsageError(f"--condition {args.condition}: {err}") from None
    out = field.save(args.out)
    m = field.meta
    mags = ", ".join(f"{k} {m[k]:.4g}" for k in ("gust_mps", "direction_change_deg",
                                                  "shear_amplitude_mps", "sigma_1") if k in m)
    print(f"wrote {out}: IEC {args.condition.upper()} at {args.mean:g} m/s, class "
          f"{site.turbine_class}{site.turbulence_class}; {mags}")
    if args.plot:
        from mpc_wt.plotting import plot_wind_condition

        print(f"wrote {plot_wind_condition(field, args.plot)}")
    return 0


def _evaluate(args: argparse.Namespace) -> int:
    import lidar
    from mpc_wt.assessment.lidar import lidar_evaluation

    field = lidar.WindField.load(args.field)
    turbine = linearize.load_turbine(args.turbine)
    res, curves = lidar_evaluation(field, turbine, focus_distance=args.focus,
                                   range_weighting=not args.point,
                                   los_error=not args.no_los_error, noise_std=args.noise,
                                   evolution=args.evolution)
    if args.plots:
        from mpc_wt.plotting import plot_lidar_evaluation

        res["plots"] = plot_lidar_evaluation(res, curves, turbine.geometry.tip_radius,
                                             args.plots)
    if args.json:
        print(to_json(res))
    else:
        for k, v in res.items():
            print(f"{k:32s} {v:.4g}" if isinstance(v, float) else f"{k:32s} {v}")
    return 0

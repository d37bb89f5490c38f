"""The ``mpcwt`` command line.

Subcommands
-----------
run        the main job on a turbine: steady operating table, C_P surface and plots
trim       steady operating points against wind speed (table or ``--json``)
linearize  linear models over mean wind, saved as .mat/.npz/.json (``--json`` summary)
aero       rotor aerodynamics: ``aero cp-surface --out FILE.csv [--plot FILE.png]``
simulate   closed loop on the plant: ``simulate --controller baseline --wind 18 --out RUN``
assess     DELs, CS1-CS5, pitch duty, energy of runs or CSV time series
wind       turbulent wind fields: ``wind generate --mean 18 --class A --out FIELD.bts``
lidar      CW LIDAR preview: ``lidar evaluate --field FIELD [--focus 54] [--json]``
design     gain synthesis: ``design baseline|lqr|ts|ibc|coleman-ipc [...] --out DIR``
           (DIR/design.json + plot)
export     gain tables: ``export DIR --format csv|json|mat|rosco``
campaign   load-case campaigns on Dask: ``campaign run SPEC.yaml [--workers N | --scheduler
           ADDR] [--out DIR]``, ``campaign status DIR``, ``campaign report DIR``

Errors in the arguments or the turbine file print one line naming the parameter and the value
to stderr and exit with status 2.
"""
from __future__ import annotations

import argparse
import csv
import json
import logging
import math
import sys
from pathlib import Path
from typing import Any, Sequence

import numpy as np

import linearize
from linearize import OperatingPoint, TrimError, TurbineFileError

from .campaign.store import CampaignLockedError

__all__ = ["main", "parse_range"]

log = logging.getLogger(__name__)


class UsageError(ValueError):
    """A command-line value that is not allowed."""


def parse_range(text: str, name: str) -> np.ndarray:
    """Parse ``START:STOP:STEP`` (STOP included), ``START:STOP`` (step 1) or ``A,B,C``.

    Raises
    ------
    UsageError
        Naming the option and the value if it is not a finite, increasing range.
    """
    try:
        if ":" in text:
            parts = [float(p) for p in text.split(":")]
            if len(parts) == 2:
                parts.append(1.0)
            if len(parts) != 3:
                raise ValueError
            a, b, s = parts
            if not all(math.isfinite(v) for v in parts) or s <= 0 or b < a:
                raise ValueError
            n = int(math.floor((b - a) / s + 1e-9)) + 1
            vals = a + s * np.arange(n)
        else:
            vals = np.array([float(p) for p in text.split(",")])
    except ValueError:
        raise UsageError(f"{name} must be START:STOP:STEP with STEP > 0 and STOP >= START, "
                         f"or a comma list of numbers; got {text!r}") from None
    if vals.size == 0 or not np.all(np.isfinite(vals)):
        raise UsageError(f"{name} must hold finite numbers; got {text!r}")
    return vals


def _schedule(turbine: linearize.Turbine, winds: np.ndarray, power_W: float | None,
              progress: bool) -> list[OperatingPoint]:
    from tqdm import tqdm

    params = linearize.plant_params(turbine)
    out = []
    for v in tqdm(winds, desc="trim", unit="pt", disable=not progress, file=sys.stderr):
        out.append(linearize.trim(turbine, float(v), power_W, params=params))
    return out


_TABLE_COLS = (("wind_mps", "wind [m/s]", "{:8.2f}"), ("region", "region", "{:>6s}"),
               ("pitch_deg", "pitch [deg]", "{:11.3f}"),
               ("rotor_speed_rpm", "rotor [rpm]", "{:11.3f}"),
               ("gen_torque_Nm", "gen torque [N m]", "{:16.1f}"),
               ("power_W", "power [kW]", "{:10.1f}"), ("thrust_N", "thrust [kN]", "{:11.1f}"),
               ("cp", "C_P", "{:6.3f}"), ("tower_fa_deflection_m", "tower FA [m]", "{:12.4f}"))


def _format_table(points: Sequence[OperatingPoint]) -> str:
    head = " ".join(f"{h:>{len(fmt.format(0.0 if 's' not in fmt else ''))}s}"
                    for _, h, fmt in _TABLE_COLS)
    lines = [head]
    for p in points:
        d = p.as_dict()
        cells = []
        for key, _, fmt in _TABLE_COLS:
            val = d[key]
            if key == "power_W" or key == "thrust_N":
                val = val / 1e3
            cells.append(fmt.format(val))
        lines.append(" ".join(cells))
    return "\n".join(lines)


def _write_points_csv(points: Sequence[OperatingPoint], path: Path) -> None:
    rows = [p.as_dict() for p in points]
    with path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


def _cp_surface(turbine: linearize.Turbine, tsr: np.ndarray,
                pitch: np.ndarray) -> np.ndarray:
    lam, pit = np.meshgrid(tsr, pitch)
    cp, _ = linearize.steady_coefficients(turbine, lam, pit)
    return cp


def _write_surface_csv(tsr: np.ndarray, pitch: np.ndarray, cp: np.ndarray, path: Path) -> None:
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["pitch_deg \\ tsr"] + [f"{v:g}" for v in tsr])
        for b, row in zip(pitch, cp):
            w.writerow([f"{b:g}"] + [f"{c:.6f}" for c in row])


def _cmd_trim(args: argparse.Namespace) -> int:
    turbine = linearize.load_turbine(args.turbine)
    winds = parse_range(args.wind, "--wind")
    points = _schedule(turbine, winds, args.power_W, progress=not args.json)
    if args.json:
        print(json.dumps([p.as_dict() for p in points], indent=1))
    else:
        print(f"# {turbine.name}")
        print(_format_table(points))
    return 0


def _cmd_cp_surface(args: argparse.Namespace) -> int:
    turbine = linearize.load_turbine(args.turbine)
    tsr = parse_range(args.tsr, "--tsr")
    pitch = parse_range(args.pitch, "--pitch")
    if np.any(tsr < 0):
        raise UsageError(f"--tsr must be >= 0, got {args.tsr!r}")
    cp = _cp_surface(turbine, tsr, pitch)
    if args.out:
        _write_surface_csv(tsr, pitch, cp, Path(args.out))
        print(f"wrote {args.out}")
    if args.plot:
        from .plotting import plot_cp_surface

        plot_cp_surface(tsr, pitch, cp, args.plot, title=f"{turbine.name}: C_P")
        print(f"wrote {args.plot}")
    i, j = np.unravel_index(int(np.argmax(cp)), cp.shape)
    print(f"C_P max {cp[i, j]:.4f} at tip-speed ratio {tsr[j]:.3f}, pitch {pitch[i]:.2f} deg")
    return 0


def _cmd_linearize(args: argparse.Namespace) -> int:
    turbine = linearize.load_turbine(args.turbine)
    winds = parse_range(args.wind, "--wind")
    fam = linearize.linearize_family(
        turbine, winds, wake="frozen" if args.frozen_wake else "quasi-steady",
        disturbance=args.disturbance, coordinates="mbc" if args.mbc else "blade",
        progress=not args.json)
    if args.out:
        fam.save(args.out)
        if not args.json:
            print(f"wrote {args.out}: {len(fam.models)} models, {fam.models[0].n_x} states, "
                  f"inputs {list(fam.models[0].inputs)}")
    rows = []
    for m in fam.models:
        row = {"wind_mps": m.wind_speed, "pitch_deg": m.info["pitch_deg"],
               "rotor_speed_rpm": m.info["rotor_speed_rpm"], **linearize.sensitivities(m),
               "modes": m.modes()}
        rows.append(row)
    if args.json:
        print(json.dumps(rows, indent=1))
    else:
        print(f"{'wind [m/s]':>10s} {'pitch [deg]':>11s} {'dP/dpitch [MW/rad]':>18s} "
              f"{'dQ/domega [kNms]':>16s} {'dT/dV [kN s/m]':>14s}  modes [Hz, damping]")
        for r in rows:
            modes = ", ".join(f"{md['name']} {md['frequency_Hz']:.3f} {md['damping_ratio']:.3f}"
                              for md in r["modes"])
            print(f"{r['wind_mps']:10.2f} {r['pitch_deg']:11.3f} "
                  f"{r['dP_dpitch_W_per_rad'] / 1e6:18.3f} {r['dQ_domega'] / 1e3:16.1f} "
                  f"{r['dT_dV'] / 1e3:14.2f}  {modes}")
    return 0


def _cmd_wind_generate(args: argparse.Namespace) -> int:
    import lidar

    turb: str | float = args.turbulence_class
    if args.ti is not None:
        turb = args.ti
    spec = lidar.TurbulenceSpec(args.mean, turb, hub_height=args.hub_height, width=args.width,
                                height=args.width, n_y=args.n, n_z=args.n,
                                duration=args.duration, dt=args.dt, shear_exponent=args.shear)
    field = lidar.generate_field(spec, args.seed)
    out = field.save(args.out)
    u = field.u
    print(f"wrote {out}: {u.shape[0]} steps x {u.shape[1]} x {u.shape[2]} points, "
          f"hub TI {u[:, u.shape[1] // 2, u.shape[2] // 2].std() / args.mean:.3f}")
    return 0


def _cmd_lidar_evaluate(args: argparse.Namespace) -> int:
    import lidar

    from .lidar_eval import evaluate_lidar

    field = lidar.WindField.load(args.field)
    turbine = linearize.load_turbine(args.turbine)
    res = evaluate_lidar(field, turbine, focus_distance=args.focus, plots=args.plots,
                         range_weighting=not args.point, los_error=not args.no_los_error,
                         noise_std=args.noise)
    if args.json:
        print(json.dumps(res, indent=1))
    else:
        for k, v in res.items():
            print(f"{k:32s} {v:.4g}" if isinstance(v, float) else f"{k:32s} {v}")
    return 0


def _cmd_simulate(args: argparse.Namespace) -> int:
    from .runs import parse_controller, run_controller

    try:
        kind, _, addon = parse_controller(args.controller)
    except ValueError as err:
        raise UsageError(f"--controller: {err}") from None
    turbine = linearize.load_turbine(args.turbine)
    mpc_opts: dict[str, Any] = {}
    if args.controller.startswith("mpc"):
        mpc_opts = {"backend": args.backend, "formulation": args.formulation,
                    "horizon": args.horizon, "scheduled": args.scheduled,
                    "estimator": None if args.estimator == "none" else args.estimator}
    elif (args.backend, args.formulation, args.estimator, args.scheduled) != \
            (None, "condensed", "none", False) or args.horizon != 15:
        raise UsageError(f"--backend/--formulation/--horizon/--estimator/--scheduled apply to "
                         f"the MPC controllers only, not to --controller {args.controller}")
    if args.apc_frequency is not None and kind not in ("ts", "apc"):
        raise UsageError("--apc-frequency applies to --controller ts and apc only")
    if kind == "apc" and args.apc_frequency is None:
        raise UsageError("--controller apc needs --apc-frequency F [Hz] (0: constant reduction)")
    if (args.apc_amplitude, args.apc_offset) != (0.375, 0.375) and kind not in ("ts", "apc"):
        raise UsageError("--apc-amplitude/--apc-offset apply to --controller ts and apc only")
    ropts = {}
    if args.loop_gain is not None or args.keep_collective:
        if addon != "ibc":
            raise UsageError("--loop-gain/--keep-collective apply to the ibc controllers only")
        ropts = {"remove_collective": not args.keep_collective}
        if args.loop_gain is not None:
            ropts["loop_gain_1p"] = args.loop_gain
    try:
        res = run_controller(turbine, args.controller, args.wind, args.turbulence, args.seed,
                             args.duration, progress=True, mpc_options=mpc_opts,
                             apc_frequency=args.apc_frequency, apc_amplitude=args.apc_amplitude,
                             apc_offset=args.apc_offset, retrofit_options=ropts or None)
    except ValueError as err:
        if "apc" in str(err) or "power" in str(err):
            raise UsageError(str(err)) from None
        raise
    out = Path(args.out)
    if out.suffix == "":
        out = out.with_suffix(".nc")
    res.save(out)
    p = res.channel("gen_power")
    print(f"wrote {out}: {res.t.size} samples; mean power {p.mean() / 1e6:.3f} MW, "
          f"gen speed std {res.channel('gen_speed').std():.3f} rad/s")
    return 0


def _cmd_assess(args: argparse.Namespace) -> int:
    from .runs import DEFAULT_CHANNELS, assess_plots, assess_series, load_series, reductions

    chans = None
    if args.channels:
        chans = {c: DEFAULT_CHANNELS.get(c, 4.0) for c in args.channels.split(",")}
    rows, runs = [], []
    for path in args.runs:
        t, cols = load_series(path, args.time_column)
        keep = t >= args.t_start
        if keep.sum() < 3:
            raise UsageError(f"--t-start = {args.t_start:g} s leaves fewer than 3 samples of "
                             f"{path} (it ends at {t[-1]:g} s)")
        t, cols = t[keep], {k: v[keep] for k, v in cols.items()}
        res = assess_series(t, cols, chans, args.m)
        row = {"run": str(path), **res}
        if rows:
            row["relative_to_first"] = reductions(rows[0], res)
        rows.append(row)
        runs.append((Path(path).stem, t, cols))
    if args.plots:
        made = assess_plots(runs, args.plots)
        for r in rows:
            r["plots"] = made
    if args.json:
        print(json.dumps(rows, indent=1))
    else:
        for r in rows:
            print(f"# {r['run']} ({r['duration_s']:.0f} s)")
            for name, d in r["channels"].items():
                print(f"  DEL {name:24s} {d['del']:14.4g}  (m = {d['m']:g})")
            for k in ("cs1", "cs2", "cs3", "cs4", "cs5", "power_std_W", "energy_Wh",
                      "pitch_travel_deg"):
                if k in r:
                    print(f"  {k:28s} {r[k]:14.6g}")
    return 0


def _cmd_run(args: argparse.Namespace) -> int:
    from .plotting import plot_cp_surface, plot_operating_schedule

    turbine = linearize.load_turbine(args.turbine)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    op = turbine.operation
    winds = np.arange(op.cut_in_wind, op.cut_out_wind + 1e-9, 1.0)
    points = _schedule(turbine, winds, None, progress=True)
    v_rated = linearize.rated_wind_speed(turbine)
    lam_opt, cp_max = linearize.optimal_tsr(turbine, math.degrees(op.fine_pitch_rad))
    print(f"# {turbine.name}: steady operating table, cut-in to cut-out")
    print(_format_table(points))
    print(f"# rated wind speed {v_rated:.3f} m/s; C_P max {cp_max:.4f} at tip-speed ratio "
          f"{lam_opt:.3f} (fine pitch)")
    _write_points_csv(points, out / "operating_points.csv")
    (out / "operating_points.json").write_text(json.dumps([p.as_dict() for p in points],
                                                          indent=1))
    tsr = np.arange(2.0, 16.0 + 1e-9, 0.25)
    pitch = np.arange(-2.0, 24.0 + 1e-9, 0.5)
    cp = _cp_surface(turbine, tsr, pitch)
    _write_surface_csv(tsr, pitch, cp, out / "cp_surface.csv")
    plot_cp_surface(tsr, pitch, cp, out / "cp_surface.png", title=f"{turbine.name}: C_P")
    plot_operating_schedule(points, out / "operating_schedule.png",
                            title=f"{turbine.name}: steady operating schedule")
    print(f"# wrote {out}/operating_points.csv, operating_points.json, cp_surface.csv, "
          f"cp_surface.png, operating_schedule.png")
    if args.duration > 0:
        from .baseline import tune_baseline
        from .runs import assess_plots, assess_series, run_baseline

        g = tune_baseline(turbine)
        print(f"# baseline tuned from the linear models: KP {g.kp:.5f} s, KI {g.ki:.5f}, "
              f"theta_K {math.degrees(g.theta_k_rad):.2f} deg, K_opt {g.k_opt:.4f} "
              f"N m/(rad/s)^2 (published 0.01883, 0.00807, 6.30 deg, 2.3323)")
        res = run_baseline(turbine, args.wind, args.turbulence, args.seed, args.duration,
                           progress=True)
        res.save(out / "baseline_run.nc")
        keep = res.t >= min(60.0, 0.1 * args.duration)
        cols = {n: res.channel(n)[keep] for n in res.channels()}
        a = assess_series(res.t[keep], cols)
        (out / "baseline_assessment.json").write_text(json.dumps(a, indent=1))
        assess_plots([("baseline", res.t[keep], cols)], out)
        print(f"# {args.duration:g} s at {args.wind:g} m/s, turbulence {args.turbulence}, "
              f"seed {args.seed}: mean power {a['power_mean_W'] / 1e6:.3f} MW, power std "
              f"{a['power_std_W'] / 1e3:.1f} kW, gen speed std {a['gen_speed_std_rad_s']:.2f} "
              f"rad/s, pitch travel {a['pitch_travel_deg']:.0f} deg")
        for name, d in a["channels"].items():
            print(f"#   DEL {name:22s} {d['del']:12.4g} N m (m = {d['m']:g})")
        print(f"# wrote {out}/baseline_run.nc, baseline_assessment.json, cs_ellipses.png, "
              f"psd_flap_moment_1.png")
    return 0


def _cmd_bench_mpc(args: argparse.Namespace) -> int:
    from .bench import format_table, plot_solver_times, run_solver_benchmark

    res = run_solver_benchmark(args.steps, progress=not args.json)
    print(json.dumps(res, indent=1) if args.json else format_table(res))
    if args.plot:
        plot_solver_times(res, args.plot)
    return 0


def _pairs(items: Sequence[str] | None, name: str) -> dict[str, float]:
    """NAME=VALUE options to a dict of floats."""
    out: dict[str, float] = {}
    for it in items or []:
        key, sep, val = it.partition("=")
        try:
            out[key.strip()] = float(val)
        except ValueError:
            sep = ""
        if not sep or not key.strip():
            raise UsageError(f"{name} takes NAME=VALUE with a number, got {it!r}")
    return out


def _floats(text: str, name: str) -> list[float]:
    try:
        vals = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise UsageError(f"{name} takes a comma list of numbers, got {text!r}") from None
    if not vals or not all(math.isfinite(v) for v in vals):
        raise UsageError(f"{name} takes a comma list of finite numbers, got {text!r}")
    return vals


def _plot_design(doc: dict[str, Any], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    s = doc["schedule"]
    rows = np.asarray(s["rows"], dtype=float)
    x = rows[:, 0]
    fig, ax = plt.subplots(figsize=(7, 4))
    scalar = {"baseline": (("kp", "ki"), "PI gain on generator speed [s], [-]"),
              "ibc": (("gain",), "IBC gain [rad/(N m)]"),
              "coleman-ipc": (("ki",), "IPC integral gain [rad/(N m s)]")}
    if doc["kind"] in scalar:
        names, label = scalar[doc["kind"]]
        for c in names:
            ax.plot(x, rows[:, s["columns"].index(c)], "o-", label=c)
        ax.set_ylabel(label)
    else:
        k = np.asarray(doc["matrices"]["K"]["data"])
        m = doc["matrices"]["K"]
        flat = k.reshape(k.shape[0], -1)
        big = np.argsort(-np.abs(flat).max(axis=0))[:6]
        for j in big:
            lab = f"K[{m['rows'][j // len(m['cols'])]}, {m['cols'][j % len(m['cols'])]}]"
            v = flat[:, j] / max(np.abs(flat[:, j]).max(), 1e-300)
            ax.plot(np.arange(len(x)) if doc["kind"] == "ts" else x, v, "o-", label=lab)
        ax.set_ylabel("gain / its largest magnitude [-]")
    ax.set_xlabel("vertex index (wind outer, power reduction inner)" if doc["kind"] == "ts"
                  else "wind speed [m/s]")
    ax.set_title(f"{doc['kind']} gains, {doc['turbine']}")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _cmd_design(args: argparse.Namespace) -> int:
    from .export import (baseline_table, coleman_ipc_table, ibc_table, lqr_table, save_design,
                         ts_table)

    turbine = linearize.load_turbine(args.turbine)
    try:
        from .baseline import check_power_fraction

        frac = check_power_fraction(args.power_fraction, "--power-fraction")
    except ValueError as err:
        raise UsageError(str(err)) from None
    if args.kind == "baseline":
        from .baseline import tune_baseline

        doc = baseline_table(turbine, tune_baseline(turbine, omega_n_rad_s=args.omega_n,
                                                    zeta=args.zeta, power_fraction=frac))
        note = f"kp {doc['settings']['kp']:.4g} s, ki {doc['settings']['ki']:.4g}"
    elif args.kind == "ibc":
        from .retrofit import tune_ibc

        g = tune_ibc(turbine, power_fraction=frac, loop_gain_1p=args.loop_gain)
        doc = ibc_table(turbine, g)
        note = (f"{g.gain.size} points, gain margin >= {g.gain_margin.min():.3g}, "
                f"high-pass {g.highpass_hz:.3g} Hz")
    elif args.kind == "coleman-ipc":
        from .retrofit import tune_coleman_ipc

        g = tune_coleman_ipc(turbine, power_fraction=frac)
        doc = coleman_ipc_table(turbine, g)
        note = f"{g.ki.size} points, gain margin >= {g.gain_margin.min():.3g}"
    elif args.kind == "lqr":
        from .synthesis import (REGION3_SCALES, REGION3_WEIGHTS, design_lqr_family,
                                design_pi_observer)

        winds = parse_range(args.wind or "12:25:1", "--wind")
        fam = linearize.linearize_family(turbine, winds, config=linearize.PlantConfig.do(),
                                         progress=True)
        weights = _pairs(args.weight, "--weight") or dict(REGION3_WEIGHTS)
        scales = {**REGION3_SCALES, **_pairs(args.scale, "--scale")}
        sw = {k: v for k, v in weights.items() if k in fam.models[0].states}
        ow = {k: v for k, v in weights.items() if k not in sw}
        designs = design_lqr_family(fam, state_weights=sw, output_weights=ow, scales=scales)
        obs = [design_pi_observer(m, q=args.observer_q) for m in fam.models] \
            if args.observer_q > 0 else None
        doc = lqr_table(turbine, designs, obs)
        note = f"{len(designs)} operating points"
        if obs:
            note += f", PIO ||L2||/||L1|| {min(o.gain_ratio for o in obs):.3g}.." \
                    f"{max(o.gain_ratio for o in obs):.3g}"
    else:
        from .ts import build_ts_model, design_ts_controller, design_ts_observer

        ts = build_ts_model(turbine, _floats(args.wind or "12,14,16,19,22,25", "--wind"),
                            _floats(args.reductions, "--reductions"), progress=True)
        ctl = design_ts_controller(ts, decay_rate=args.decay_rate)
        obs = design_ts_observer(ts, decay_rate=args.observer_decay_rate)
        doc = ts_table(turbine, ts, ctl, obs)
        note = (f"{ts.n_vertices} vertices, {ctl.solver} {ctl.solve_time_s:.1f} s + "
                f"{obs.solve_time_s:.1f} s, certificates ok")
    p = save_design(doc, args.out)
    _plot_design(doc, Path(args.out) / "gains.png")
    print(f"wrote {p} and {Path(args.out) / 'gains.png'} ({args.kind}: {note})")
    return 0


def _cmd_export(args: argparse.Namespace) -> int:
    from .export import GainTableError, export

    try:
        files = export(args.design, args.format, args.to)
    except GainTableError as err:
        raise UsageError(str(err)) from None
    print("wrote " + ", ".join(str(f) for f in files))
    return 0


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="mpcwt", description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="command", required=True)
    turb = dict(default="nrel5mw", help="packaged turbine name or path to a turbine.yaml "
                                         "(default nrel5mw)")

    p = sub.add_parser("run", help="main job: operating table, C_P surface, baseline run, "
                                   "assessment, plots")
    p.add_argument("--turbine", **turb)
    p.add_argument("--out", default="mpcwt-out", help="output directory (default mpcwt-out)")
    p.add_argument("--wind", type=float, default=18.0, help="wind of the baseline run [m/s]")
    p.add_argument("--turbulence", choices=("A", "B", "C", "steady"), default="A")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--duration", type=float, default=600.0,
                   help="baseline run length [s] (0 skips the run)")
    p.set_defaults(func=_cmd_run)

    p = sub.add_parser("trim", help="steady operating points")
    p.add_argument("--turbine", **turb)
    p.add_argument("--wind", default="4:25:1", help="START:STOP:STEP in m/s (default 4:25:1)")
    p.add_argument("--power-W", dest="power_W", type=float, default=None,
                   help="power reference below rated [W]")
    p.add_argument("--json", action="store_true", help="print a JSON list")
    p.set_defaults(func=_cmd_trim)

    p = sub.add_parser("linearize", help="linear models over mean wind")
    p.add_argument("--turbine", **turb)
    p.add_argument("--wind", default="4:25:1", help="START:STOP:STEP in m/s (default 4:25:1)")
    p.add_argument("--frozen-wake", action="store_true",
                   help="hold the induction at trim (as FAST/OpenFAST linearize)")
    p.add_argument("--disturbance", choices=("blade", "rotor"), default="blade",
                   help="one wind per blade (default) or one rotor-effective wind")
    p.add_argument("--mbc", action="store_true", help="multi-blade (Coleman) coordinates")
    p.add_argument("--out", help="models file: .mat (MATLAB), .npz or .json")
    p.add_argument("--json", action="store_true", help="print sensitivities and modes as JSON")
    p.set_defaults(func=_cmd_linearize)

    p = sub.add_parser("simulate", help="closed-loop simulation on the plant")
    p.add_argument("--turbine", **turb)
    p.add_argument("--controller", default="baseline",
                   help="baseline | mpc | mpc-lidar | mpc-collective | lqr-pio | ts | ibc | "
                        "coleman-ipc | derateNN (NN %% of rated, e.g. derate90) | derateNN+ibc "
                        "| derateNN+coleman-ipc | apc")
    p.add_argument("--wind", type=float, required=True, help="mean hub-height wind [m/s]")
    p.add_argument("--turbulence", choices=("A", "B", "C", "steady"), default="A")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--duration", type=float, default=600.0, help="[s]")
    p.add_argument("--out", required=True, help="result file (netCDF, .nc)")
    p.add_argument("--backend", choices=("osqp", "daqp"),
                   help="MPC QP solver (default DAQP when installed, else OSQP)")
    p.add_argument("--formulation", choices=("condensed", "sparse"), default="condensed",
                   help="MPC QP formulation (sparse: OSQP only)")
    p.add_argument("--horizon", type=int, default=15, help="MPC H_p = H_u (default 15)")
    p.add_argument("--estimator", choices=("none", "kalman"), default="none",
                   help="kalman: MPC on measured signals (state and blade-wind Kalman filter); "
                        "none: full-state information (default)")
    p.add_argument("--scheduled", action="store_true",
                   help="MPC scheduled over a model family 12-25 m/s on the estimated wind "
                        "(or the preview with mpc-lidar)")
    p.add_argument("--apc-frequency", type=float, default=None,
                   help="ts, apc: sinusoidal power reduction of Clemens eq 11 at this f_r [Hz]")
    p.add_argument("--apc-amplitude", type=float, default=0.375,
                   help="ts, apc: amplitude of Delta P (fraction of rated, default 0.375)")
    p.add_argument("--apc-offset", type=float, default=0.375,
                   help="ts, apc: mean of Delta P (default 0.375: Delta P in [0, 0.75])")
    p.add_argument("--loop-gain", type=float, default=None,
                   help="ibc: loop gain at 1P of each blade loop (default 1)")
    p.add_argument("--keep-collective", action="store_true",
                   help="ibc: keep the blades' mean IBC pitch (the paper's independent loops; "
                        "default: subtract it, cyclic action only)")
    p.set_defaults(func=_cmd_simulate)

    p = sub.add_parser("design", help="gain synthesis: baseline PI, LQR family, TS by LMIs")
    p.add_argument("kind", choices=("baseline", "lqr", "ts", "ibc", "coleman-ipc"))
    p.add_argument("--turbine", **turb)
    p.add_argument("--out", required=True, help="design directory (design.json, gains.png)")
    p.add_argument("--wind", help="lqr: START:STOP:STEP (default 12:25:1); ts: comma list of "
                                  "vertex winds (default 12,14,16,19,22,25) [m/s]")
    p.add_argument("--reductions", default="0,0.4,0.8",
                   help="ts: comma list of vertex power reductions (default 0,0.4,0.8)")
    p.add_argument("--decay-rate", type=float, default=0.2, help="ts: controller decay [1/s]")
    p.add_argument("--observer-decay-rate", type=float, default=1.0,
                   help="ts: observer decay [1/s]")
    p.add_argument("--weight", action="append",
                   help="lqr: NAME=VALUE weight on a state or output (repeatable; default "
                        "rotor_speed=5, tower_fa_velocity=1)")
    p.add_argument("--scale", action="append",
                   help="lqr: NAME=VALUE typical magnitude dividing a weight (repeatable)")
    p.add_argument("--observer-q", type=float, default=1e3,
                   help="lqr: PI observer q of Q_obs = diag(I, q I) (0: no observer)")
    p.add_argument("--omega-n", type=float, default=0.6, help="baseline: PI design [rad/s]")
    p.add_argument("--zeta", type=float, default=0.7, help="baseline: PI damping [-]")
    p.add_argument("--power-fraction", type=float, default=1.0,
                   help="baseline, ibc, coleman-ipc: tune for a derated turbine at this "
                        "fraction of rated power, in (0, 1]")
    p.add_argument("--loop-gain", type=float, default=1.0, help="ibc: loop gain at 1P [-]")
    p.set_defaults(func=_cmd_design)

    p = sub.add_parser("export", help="export a design's gain table")
    p.add_argument("design", help="design directory (from `mpcwt design`) or gain-table JSON")
    p.add_argument("--format", required=True, choices=("csv", "json", "mat", "rosco"))
    p.add_argument("--to", help="output directory (default: the design directory)")
    p.set_defaults(func=_cmd_export)

    p = sub.add_parser("assess", help="loads and performance of runs or CSV time series")
    p.add_argument("runs", nargs="+", help="result files (.nc) or CSV with a time column")
    p.add_argument("--channels", help="comma list of channels (default: blade, tower, shaft)")
    p.add_argument("--m", type=float, default=None, help="Woehler exponent for all channels")
    p.add_argument("--time-column", default="time", help="CSV time column (default time)")
    p.add_argument("--t-start", type=float, default=0.0,
                   help="discard samples before this time, e.g. the start-up transient [s]")
    p.add_argument("--json", action="store_true")
    p.add_argument("--plots", help="directory for cs_ellipses.png and psd_flap_moment_1.png")
    p.set_defaults(func=_cmd_assess)

    p = sub.add_parser("wind", help="turbulent wind fields")
    wind = p.add_subparsers(dest="wind_command", required=True)
    q = wind.add_parser("generate", help="IEC 61400-1 Kaimal field (TurbSim IECKAI model)")
    q.add_argument("--mean", type=float, required=True, help="hub-height mean speed [m/s]")
    q.add_argument("--class", dest="turbulence_class", choices=("A", "B", "C"), default="A")
    q.add_argument("--ti", type=float, default=None, help="turbulence intensity instead of a class")
    q.add_argument("--seed", type=int, default=1)
    q.add_argument("--duration", type=float, default=600.0, help="[s]")
    q.add_argument("--dt", type=float, default=0.05, help="[s] (default 0.05: 20 Hz)")
    q.add_argument("--n", type=int, default=32, help="grid points per side (default 32)")
    q.add_argument("--width", type=float, default=150.0, help="grid side [m]")
    q.add_argument("--hub-height", type=float, default=90.0, help="[m]")
    q.add_argument("--shear", type=float, default=0.2, help="power-law exponent")
    q.add_argument("--out", required=True, help=".bts (TurbSim) or .npz (native)")
    q.set_defaults(func=_cmd_wind_generate)

    p = sub.add_parser("lidar", help="CW LIDAR preview")
    lid = p.add_subparsers(dest="lidar_command", required=True)
    q = lid.add_parser("evaluate", help="coherence bandwidth and preview error on a field")
    q.add_argument("--field", required=True, help=".bts or .npz wind field")
    q.add_argument("--turbine", **turb)
    q.add_argument("--focus", type=float, default=54.0, help="axial focus distance [m]")
    q.add_argument("--point", action="store_true", help="point measurement (no range weighting)")
    q.add_argument("--no-los-error", action="store_true", help="measure u directly")
    q.add_argument("--noise", type=float, default=0.0, help="LOS noise std [m/s]")
    q.add_argument("--json", action="store_true")
    q.add_argument("--plots", help="directory for lidar_coherence.png and lidar_scan.png")
    q.set_defaults(func=_cmd_lidar_evaluate)

    p = sub.add_parser("bench", help="benchmarks")
    bench = p.add_subparsers(dest="bench_command", required=True)
    q = bench.add_parser("mpc", help="MPC QP solver comparison on a closed-loop run (18 m/s)")
    q.add_argument("--steps", type=int, default=3000, help="closed-loop steps (default 3000)")
    q.add_argument("--json", action="store_true")
    q.add_argument("--plot", help="PNG of the solve times")
    q.set_defaults(func=_cmd_bench_mpc)

    p = sub.add_parser("campaign", help="load-case campaigns (DLC 1.2) on Dask: run, status, "
                                        "report")
    camp = p.add_subparsers(dest="campaign_command", required=True)
    q = camp.add_parser("run", help="run (or resume) a campaign spec")
    q.add_argument("spec", help="campaign YAML file")
    q.add_argument("--workers", type=int, default=None,
                   help="local worker processes (default: one per core)")
    q.add_argument("--scheduler", default=None,
                   help="address of a running Dask scheduler, tcp://HOST:PORT")
    q.add_argument("--out", default=None, help="campaign directory (default campaigns/NAME)")
    q.add_argument("--engine", choices=("dask", "processes", "serial"), default="dask",
                   help="dask (default), a plain process pool, or this process")
    q.add_argument("--report", action="store_true", help="write the report when all cases "
                                                         "finished")
    q.add_argument("--quiet", action="store_true", help="no progress bar")
    q.set_defaults(func=_cmd_campaign_run)
    q = camp.add_parser("status", help="cases done, failed, pending of a campaign directory")
    q.add_argument("dir")
    q.add_argument("--failed", action="store_true", help="print the tracebacks of failed cases")
    q.add_argument("--json", action="store_true")
    q.set_defaults(func=_cmd_campaign_status)
    q = camp.add_parser("report", help="tables (CSV, Markdown) and plots (PNG) of a campaign")
    q.add_argument("dir")
    q.add_argument("--out", default=None, help="report folder (default DIR/report)")
    q.set_defaults(func=_cmd_campaign_report)

    p = sub.add_parser("aero", help="rotor aerodynamics")
    aero = p.add_subparsers(dest="aero_command", required=True)
    q = aero.add_parser("cp-surface", help="C_P(lambda, pitch) table and plot")
    q.add_argument("--turbine", **turb)
    q.add_argument("--out", help="CSV file (rows pitch, columns tip-speed ratio)")
    q.add_argument("--plot", help="PNG file")
    q.add_argument("--tsr", default="2:16:0.25", help="START:STOP:STEP (default 2:16:0.25)")
    q.add_argument("--pitch", default="-2:24:0.5",
                   help="START:STOP:STEP in deg; write --pitch=-2:24:0.5 for a negative start")
    q.set_defaults(func=_cmd_cp_surface)
    return ap


def _cmd_campaign_run(args: argparse.Namespace) -> int:
    from .campaign import load_spec, run_campaign

    spec = load_spec(args.spec)
    if args.scheduler and args.workers:
        raise UsageError("give --workers (local cluster) or --scheduler (running cluster), "
                         "not both")
    out = Path(args.out) if args.out else Path("campaigns") / spec.name
    if args.engine == "dask":
        try:    # import first: distributed sets its loggers' levels when imported
            import distributed  # noqa: F401
        except ImportError:
            pass
        for name in list(logging.root.manager.loggerDict):
            if name.startswith("distributed"):
                logging.getLogger(name).setLevel(logging.ERROR)
    log.info("campaign %s -> %s", spec.name, out)
    s = run_campaign(spec, out, workers=args.workers, scheduler=args.scheduler,
                     engine=args.engine, progress=not args.quiet)
    print(f"campaign {spec.name}: {s.total} cases; {s.skipped} already finished, "
          f"{s.done} done now ({s.reused} from files already written), {s.failed} failed; "
          f"{s.wall_s:.0f} s wall, {s.cases_per_min:.2f} cases/min ({s.engine}, "
          f"{'scheduler ' + args.scheduler if args.scheduler else f'{s.workers} workers'})")
    print(f"  directory {out}")
    for cid, err in s.failures[:10]:
        print(f"  failed {cid}: {err.splitlines()[0] if err else ''}")
    if s.failed:
        print(f"  tracebacks: mpcwt campaign status {out} --failed; rerun the same command "
              f"to retry failed cases")
    if args.report and not s.failed:
        from .campaign.report import make_report

        rep = make_report(out)
        print(f"  report {rep}")
    return 1 if s.failed else 0


def _cmd_campaign_status(args: argparse.Namespace) -> int:
    from .campaign.store import CampaignStore

    with CampaignStore(args.dir) as st:
        meta = st.meta()
        rows = st.rows()
        counts = st.counts()
        stray = st.stray_temp_files()
    if args.json:
        print(json.dumps({"meta": meta, "counts": counts,
                          "cases": [{"case_id": r.case_id, "status": r.status,
                                     "error": r.error, "wall_s": r.wall_s,
                                     "software_version": r.software_version} for r in rows]},
                         indent=1))
        return 0
    print(f"campaign {meta.get('name')} in {args.dir}: spec {str(meta.get('spec_hash'))[:12]}, "
          f"last run {meta.get('last_run')}, mpc-wt {meta.get('software_version')}")
    print("  " + ", ".join(f"{k} {v}" for k, v in counts.items() if v or k in ("done",
                                                                              "pending")))
    per: dict[str, list[int]] = {}
    for r in rows:
        d = per.setdefault(r.controller, [0, 0, 0])
        d[0] += 1
        d[1] += r.status == "done"
        d[2] += r.status == "failed"
    print(f"  {'controller':<24} {'done':>6} {'failed':>7} {'cases':>6}")
    for k, (n, d, f) in per.items():
        print(f"  {k:<24} {d:>6} {f:>7} {n:>6}")
    versions = sorted({r.software_version for r in rows if r.software_version})
    if len(versions) > 1:
        print(f"  note: cases were computed by mpc-wt versions {versions}")
    if stray:
        print(f"  {len(stray)} temp files of interrupted writers in {Path(args.dir) / 'cases'} "
              f"(safe to delete when no worker runs)")
    for r in rows:
        if r.status == "failed":
            print(f"  failed {r.case_id}: {(r.error or '').splitlines()[0]}")
            if args.failed and r.traceback:
                print("    " + r.traceback.rstrip().replace("\n", "\n    "))
    return 0


def _cmd_campaign_report(args: argparse.Namespace) -> int:
    from .campaign.report import make_report

    rep = make_report(args.dir, out=args.out)
    print(f"report {rep}")
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``mpcwt``; returns the exit status."""
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    args = _parser().parse_args(argv)
    if getattr(args, "command", None) == "aero" and not (args.out or args.plot):
        print("mpcwt aero cp-surface: give --out FILE.csv and/or --plot FILE.png",
              file=sys.stderr)
        return 2
    try:
        return int(args.func(args))
    except (UsageError, TurbineFileError, TrimError, FileNotFoundError, ValueError, KeyError,
            linearize.LinearizationError, CampaignLockedError) as err:
        print(f"mpcwt {args.command}: error: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

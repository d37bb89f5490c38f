"""Run-level helpers behind ``mpcwt simulate`` and ``mpcwt assess``."""
from __future__ import annotations

import csv
import math
import re
from pathlib import Path
from typing import Any, Sequence

import numpy as np

import lidar
import linearize

from .assess import cs_measures, damage_equivalent_load, energy_Wh, harmonic_psd, pitch_duty, psd
from .baseline import BaselineController, tune_baseline
from .simulate import ClosedLoopResult, ResultFileError, simulate_closed_loop

__all__ = ["DEFAULT_CHANNELS", "CONTROLLERS", "run_controller", "run_baseline", "load_series",
           "assess_series", "reductions"]

#: Load channels and their default Woehler exponents (10 composite blades, 4 steel elsewhere).
DEFAULT_CHANNELS = {"flap_moment_1": 10.0, "flap_moment_2": 10.0, "flap_moment_3": 10.0,
                    "edge_moment_1": 10.0, "edge_moment_2": 10.0, "edge_moment_3": 10.0,
                    "tower_base_fa_moment": 4.0, "tower_base_ss_moment": 4.0,
                    "lss_torque": 4.0, "tilt_moment": 4.0, "yaw_moment": 4.0,
                    "shaft_bending_blade1": 4.0}


CONTROLLERS = ("baseline", "baseline-ct", "mpc", "mpc-lidar", "mpc-collective", "lqr-pio", "ts",
               "ibc", "coleman-ipc", "derate90", "derate80", "derate90+ibc", "derate80+ibc", "apc")
_DERATE = re.compile(r"^derate(\d+(?:\.\d+)?)(\+ibc|\+coleman-ipc)?$")


def parse_controller(name: str) -> tuple[str, float, str | None]:
    """Split a controller name into (collective kind, power fraction, add-on).

    ``"derateNN"`` is the baseline derated to NN % of rated power (any NN in (0, 100]), with
    ``+ibc`` or ``+coleman-ipc`` on top; ``"ibc"`` and ``"coleman-ipc"`` sit on the normal
    baseline. Other names return (name, 1.0, None).

    Raises
    ------
    ValueError
        If the name is unknown or the derating is outside (0, 100] %.
    """
    mt = _DERATE.match(name)
    if mt:
        pct = float(mt.group(1))
        if not 0.0 < pct <= 100.0:
            raise ValueError(f"derating in {name!r} is {pct:g} % of rated power; allowed: "
                             f"(0, 100] %")
        return "baseline", pct / 100.0, (mt.group(2) or "")[1:] or None
    if name in ("ibc", "coleman-ipc"):
        return "baseline", 1.0, name
    if name not in CONTROLLERS:
        raise ValueError(f"controller must be one of {list(CONTROLLERS)} or derateNN[+ibc|"
                         f"+coleman-ipc], got {name!r}")
    return name, 1.0, None


def _wind(turbine: linearize.Turbine, wind_mps: float, turbulence: str, seed: int,
          duration: float, shear_exponent: float) -> tuple[Any, lidar.WindField]:
    """The plant's wind and the same field as a lidar.WindField (for a LIDAR in the loop)."""
    hub = turbine.geometry.hub_height
    if turbulence == "steady":
        spec = lidar.TurbulenceSpec(wind_mps, 0.01, hub_height=hub, duration=duration + 20.0,
                                    dt=1.0, n_y=8, n_z=8, shear_exponent=shear_exponent)
        t, y, z = spec.grid()
        u = np.broadcast_to(wind_mps * (z / hub) ** shear_exponent, (t.size, y.size, z.size))
        zero = np.zeros(u.shape)
        f = lidar.WindField(t=t, y=y, z=z, u=u, v=zero, w=zero, mean_speed=wind_mps,
                            hub_height=hub, meta={"model": "steady power law"})
        return linearize.SteadyWind(wind_mps, shear_exponent), f
    spec = lidar.TurbulenceSpec(wind_mps, turbulence, hub_height=hub, duration=duration + 20.0,
                                shear_exponent=shear_exponent)
    f = lidar.generate_field(spec, seed)
    return linearize.GridWind(t=f.t, y=f.y, z=f.z, u=np.maximum(f.u, 0.0)), f


#: Designs kept per process: key -> (turbine kept alive so its id stays unique, design...).
_DESIGNS: dict[tuple[str, int], tuple[Any, ...]] = {}


def run_controller(turbine: linearize.Turbine, controller: str, wind_mps: float,
                   turbulence: str = "A", seed: int = 1, duration: float = 600.0,
                   progress: bool = False, shear_exponent: float = 0.2,
                   mpc_options: dict[str, Any] | None = None,
                   apc_frequency: float | None = None, apc_amplitude: float = 0.375,
                   apc_offset: float = 0.375,
                   retrofit_options: dict[str, Any] | None = None,
                   lidar_options: dict[str, Any] | None = None) -> ClosedLoopResult:
    """Trim, design the controller, generate the wind and simulate.

    ``controller``: "baseline" (tuned PI and torque law, 80 Hz), "mpc" (Madsen's 8-state
    individual-pitch MPC at 10 Hz, disturbance held at the mean), "mpc-collective" (the same with
    one pitch input), "mpc-lidar" (individual pitch with the preview of a CW LIDAR -- range
    weighting and LOS error on -- measuring the field the plant meets).

    ``mpc_options`` (MPC controllers only): ``backend`` ("osqp" or "daqp"; default DAQP when
    installed), ``formulation`` ("condensed" or "sparse", OSQP), ``horizon`` (H_p = H_u),
    ``estimator`` (None or "kalman": states and blade winds estimated from measured signals),
    ``scheduled`` (True: a :class:`~mpc_wt.mpc.ScheduledMPC` over a model family from the
    first whole m/s above rated to 25 m/s in 1 m/s steps, scheduled on the estimated wind, or
    on the preview with "mpc-lidar").

    "lqr-pio": Do et al.'s LQR on PI-observer estimates at the mean wind
    (:mod:`mpc_wt.synthesis`): above rated wind region III (constant torque, speed regulation
    and tower damping), below it region II (torque law, pitch moved around the operating point
    to damp tower and blades). "baseline-ct": the baseline PI with constant torque in region
    III (Do et al.'s PI). "ts": Clemens et al.'s TS controller and wind observer, LMI-designed
    on the default vertex grid (:mod:`mpc_wt.ts`); ``apc_frequency`` [Hz] adds
    the sinusoidal power reduction of eq 11 (:func:`mpc_wt.retrofit.apc_reference`, with
    ``apc_amplitude`` and ``apc_offset``).

    Retrofit strategies (Pettas and Cheng; :mod:`mpc_wt.retrofit`): "ibc" (individual blade
    control on the baseline), "coleman-ipc" (tilt/yaw integral IPC), "derateNN" (baseline
    derated to NN % of rated power, PI re-tuned), "derateNN+ibc" / "derateNN+coleman-ipc"
    (both, IBC tuned on the derated points), "apc" (baseline following P_r (1 - Delta P(t)),
    ``apc_frequency`` required, pitch PI scheduled on the reference). ``retrofit_options``
    go to :func:`~mpc_wt.retrofit.tune_ibc` / :func:`~mpc_wt.retrofit.tune_coleman_ipc`.
    ``lidar_options`` ("mpc-lidar" only) are :class:`lidar.CWLidar` settings (focus_distance,
    noise_std, ...).

    Designs that cost seconds (the TS model and its LMI gains) are kept per process for the
    same turbine object, so a campaign worker designs once.
    """
    kind, frac, addon = parse_controller(controller)
    params = linearize.plant_params(turbine)
    wind, field = _wind(turbine, wind_mps, turbulence, seed, duration, shear_exponent)
    p_init = None if frac == 1.0 else frac * turbine.operation.rated_power
    if kind == "apc":
        from .retrofit import apc_reference

        if apc_frequency is None:
            raise ValueError("controller 'apc' needs apc_frequency [Hz] (0 for a constant "
                             "reduction at the offset)")
        dp = apc_reference(apc_frequency, amplitude=apc_amplitude, offset=apc_offset)
        p_init = turbine.operation.rated_power * (1.0 - dp(0.0))
        # the reference peaks at P_r (1 - offset + amplitude): the mean wind must give it
        p_peak = turbine.operation.rated_power * (1.0 - apc_offset + apc_amplitude)
        try:
            linearize.trim(turbine, wind_mps, min(p_peak, turbine.operation.rated_power))
        except linearize.TrimError as err:
            raise ValueError(f"apc: the power reference peaks at {p_peak:g} W, above the power "
                             f"available at the mean wind {wind_mps:g} m/s ({err})") from err
    try:
        op = linearize.trim(turbine, wind_mps, p_init)
    except linearize.TrimError:
        if p_init is None or kind == "apc":
            raise
        op = linearize.trim(turbine, wind_mps)    # derated turbine below its rated power
    meta: dict[str, Any] = {"controller": controller, "wind_mps": wind_mps,
                            "turbulence": turbulence, "seed": seed, "duration_s": duration,
                            "shear_exponent": shear_exponent, "turbine": turbine.name}
    preview = None
    cdt = None
    if apc_frequency is not None and kind not in ("ts", "apc"):
        raise ValueError("apc_frequency applies to the 'ts' and 'apc' controllers only")
    if lidar_options and kind != "mpc-lidar":
        raise ValueError("lidar_options apply to the 'mpc-lidar' controller only")
    if retrofit_options and addon is None:
        raise ValueError("retrofit_options apply to the ibc and coleman-ipc controllers only")
    if kind == "lqr-pio":
        from .synthesis import (REGION2_SCALES, REGION2_WEIGHTS, REGION3_SCALES,
                                REGION3_WEIGHTS, LQRPIOController, design_lqr,
                                design_pi_observer)

        model = linearize.linearize(turbine, wind_mps, config=linearize.PlantConfig.do())
        region = "II" if wind_mps < linearize.rated_wind_speed(turbine) else "III"
        w, sc = ((REGION3_WEIGHTS, REGION3_SCALES) if region == "III"
                 else (REGION2_WEIGHTS, REGION2_SCALES))
        lq = design_lqr(model, state_weights=w, scales=sc)
        ctl = LQRPIOController(model, turbine, lq, design_pi_observer(model, q=1e3),
                               region=region, k_opt=(tune_baseline(turbine).k_opt
                                                     if region == "II" else None),
                               feedforward=region == "III")
        meta["lqr"] = {"weights": lq.weights, "observer_q": 1e3, "region": region}
    elif kind == "ts":
        from .retrofit import apc_reference
        from .ts import TSController, build_ts_model, design_ts_controller, design_ts_observer

        key = ("ts", id(turbine))
        if key not in _DESIGNS:
            ts0 = build_ts_model(turbine)
            _DESIGNS[key] = (turbine, ts0, design_ts_controller(ts0), design_ts_observer(ts0))
        _, ts, c, o = _DESIGNS[key]
        ctl = TSController(ts, c, o, turbine, initial_wind=float(np.clip(
            wind_mps, ts.wind_grid[0], ts.wind_grid[-1])),
            power_reduction=None if apc_frequency is None else apc_reference(
                apc_frequency, amplitude=apc_amplitude, offset=apc_offset))
        meta["ts"] = {"vertices": ts.n_vertices, "decay_rate": c.decay_rate,
                      "observer_decay_rate": o.decay_rate, "apc_frequency_Hz": apc_frequency}
    elif kind == "apc":
        from .baseline import tune_baseline_schedule

        sched = tune_baseline_schedule(turbine)
        ctl = BaselineController(turbine, gain_schedule=sched, power_reference=lambda t: (
            turbine.operation.rated_power * (1.0 - dp(t))))
        meta["apc"] = {"frequency_Hz": apc_frequency, "amplitude": apc_amplitude,
                       "offset": apc_offset,
                       "schedule_fractions": [g.power_fraction for g in sched]}
    elif kind in ("baseline", "baseline-ct"):
        region3 = "constant_torque" if kind == "baseline-ct" else "constant_power"
        gains = tune_baseline(turbine, power_fraction=frac)
        ctl: Any = BaselineController(turbine, gains, region3=region3)
        meta["gains"] = {"kp": gains.kp, "ki": gains.ki, "theta_k_rad": gains.theta_k_rad,
                         "k_opt": gains.k_opt, "power_fraction": frac, "region3": region3}
        if addon is not None:
            from . import retrofit

            opts = dict(retrofit_options or {})
            if addon == "ibc":
                rc = bool(opts.pop("remove_collective", True))
                ig = retrofit.tune_ibc(turbine, power_fraction=frac, dt=ctl.dt, **opts)
                ctl = retrofit.IBCController(ctl, ig, remove_collective=rc)
                opts["remove_collective"] = rc
                meta["ibc"] = {"gain": ig.gain.tolist(), "pitch_rad": ig.pitch_rad.tolist(),
                               "highpass_hz": ig.highpass_hz,
                               "notch_harmonics": list(ig.notch_harmonics), **opts}
            else:
                cg = retrofit.tune_coleman_ipc(turbine, power_fraction=frac, **opts)
                ctl = retrofit.ColemanIPCController(ctl, cg)
                meta["coleman_ipc"] = {"ki": cg.ki.tolist(), "pitch_rad": cg.pitch_rad.tolist(),
                                       "azimuth_offset_rad": cg.azimuth_offset_rad.tolist(),
                                       **opts}
    else:
        from .mpc import MPC, ScheduledMPC

        opts = dict(mpc_options or {})
        unknown = set(opts) - {"backend", "formulation", "horizon", "estimator", "scheduled"}
        if unknown:
            raise ValueError(f"mpc_options has unknown keys {sorted(unknown)}; allowed: backend, "
                             f"formulation, horizon, estimator, scheduled")
        backend = opts.get("backend")
        if backend is None:
            try:
                import daqp  # noqa: F401
                backend = "osqp" if opts.get("formulation") == "sparse" else "daqp"
            except ImportError:
                backend = "osqp"
        kw = dict(collective=kind == "mpc-collective", backend=backend,
                  formulation=opts.get("formulation", "condensed"),
                  horizon=int(opts.get("horizon", 15)), estimator=opts.get("estimator"))
        if opts.get("scheduled"):
            lo = float(np.floor(linearize.rated_wind_speed(turbine))) + 1.0
            winds = np.arange(lo, min(25.0, turbine.operation.cut_out_wind) + 0.5, 1.0)
            if not winds[0] <= wind_mps <= winds[-1]:
                raise ValueError(f"scheduled MPC covers {winds[0]:g}..{winds[-1]:g} m/s; the "
                                 f"wind {wind_mps:g} m/s is outside")
            fam = linearize.linearize_family(turbine, winds,
                                             config=linearize.PlantConfig.madsen())
            src = "preview" if kind == "mpc-lidar" else "estimator"
            if src == "estimator" and kw["estimator"] is None:
                kw["estimator"] = "kalman"
            ctl = ScheduledMPC(fam, turbine, wind_source=src, initial_wind_mps=wind_mps, **kw)
            cdt = ctl.controller(ctl.active).dt
            hp = kw["horizon"]
        else:
            model = linearize.linearize(turbine, wind_mps,
                                        config=linearize.PlantConfig.madsen(), params=None)
            ctl = MPC(model, turbine, **kw)
            cdt, hp = ctl.dt, ctl.hp
        meta["mpc"] = {"horizon": hp, "backend": backend, "dt": cdt,
                       "formulation": kw["formulation"], "estimator": str(kw["estimator"]),
                       "scheduled": bool(opts.get("scheduled"))}
        if kind == "mpc-lidar":
            from .simulate import LidarPreview

            try:
                cw = lidar.CWLidar(turbine.geometry.tip_radius, **(lidar_options or {}))
            except TypeError as err:
                raise ValueError(f"lidar_options: {err}") from err
            meta["lidar"] = dict(lidar_options or {})
            preview = LidarPreview(cw, field, hp, cdt)
    return simulate_closed_loop(params, ctl, wind, duration, x0=op.x, u0=op.u,
                                controller_dt=cdt, preview=preview, progress=progress, meta=meta)


def run_baseline(turbine: linearize.Turbine, wind_mps: float, turbulence: str = "A",
                 seed: int = 1, duration: float = 600.0, progress: bool = False,
                 shear_exponent: float = 0.2) -> ClosedLoopResult:
    """Trim, tune the baseline, generate the wind and simulate (the main job's run)."""
    return run_controller(turbine, "baseline", wind_mps, turbulence, seed, duration, progress,
                          shear_exponent)


def load_series(path: str | Path, time_column: str = "time") -> tuple[np.ndarray,
                                                                       dict[str, np.ndarray]]:
    """Time and channels of a run: our netCDF result, or any CSV with a time column.

    Raises
    ------
    ResultFileError
        If the file cannot be read, has no time column or non-numeric cells.
    """
    path = Path(path)
    if path.suffix.lower() == ".csv":
        if not path.is_file():
            raise ResultFileError(f"{path}: file not found")
        with path.open(newline="") as fh:
            rows = list(csv.reader(fh))
        if not rows:
            raise ResultFileError(f"{path}: empty file")
        head = [h.strip() for h in rows[0]]
        if time_column not in head:
            raise ResultFileError(f"{path}: no time column {time_column!r}; columns {head}")
        try:
            data = np.array([[float(c) for c in r] for r in rows[1:] if r], dtype=float)
        except ValueError as err:
            raise ResultFileError(f"{path}: non-numeric cell ({err})") from err
        if data.ndim != 2 or data.shape[1] != len(head):
            raise ResultFileError(f"{path}: ragged rows")
        cols = {h: data[:, i] for i, h in enumerate(head)}
        return cols.pop(time_column), cols
    res = ClosedLoopResult.load(path)
    return res.t, {n: res.channel(n) for n in res.channels()}


def assess_series(t: np.ndarray, cols: dict[str, np.ndarray],
                  channels: dict[str, float] | None = None,
                  m_override: float | None = None) -> dict[str, Any]:
    """DEL per channel, CS1-CS5 (tower-base fore-aft moment vs power), pitch duty, power std,
    energy and the 1P/3P/6P content of the blade-1 flap moment, for one run."""
    chans = dict(channels or {k: v for k, v in DEFAULT_CHANNELS.items() if k in cols})
    missing = [c for c in chans if c not in cols]
    if missing:
        raise KeyError(f"no channel {missing[0]!r}; channels are {sorted(cols)}")
    dt = float(np.median(np.diff(t)))
    duration = float(t[-1] - t[0])
    out: dict[str, Any] = {"duration_s": duration, "channels": {}}
    for name, m in chans.items():
        mm = m_override if m_override is not None else m
        out["channels"][name] = {"del": damage_equivalent_load(cols[name], mm,
                                                               duration=duration), "m": mm}
    if "gen_power" in cols:
        p = cols["gen_power"]
        out["power_mean_W"] = float(p.mean())
        out["power_std_W"] = float(p.std())
        out["energy_Wh"] = energy_Wh(p, dt)
        if "tower_base_fa_moment" in cols:
            cs = cs_measures(cols["tower_base_fa_moment"], p)
            out.update({f"cs{i}": getattr(cs, f"cs{i}") for i in range(1, 6)})
    pitch = [cols[f"pitch_{i}"] for i in (1, 2, 3) if f"pitch_{i}" in cols]
    if pitch:
        out.update(pitch_duty(np.column_stack(pitch), dt))
    if "gen_speed" in cols:
        out["gen_speed_std_rad_s"] = float(cols["gen_speed"].std())
    if "gen_torque" in cols:
        out["gen_torque_std_Nm"] = float(cols["gen_torque"].std())
    if "rotor_speed" in cols and "flap_moment_1" in cols:
        frot = float(cols["rotor_speed"].mean()) / (2 * math.pi)
        out["flap_1_harmonics"] = {f"{n}P": v for n, v in
                                   harmonic_psd(cols["flap_moment_1"], 1 / dt, frot).items()}
    return out


def reductions(base: dict[str, Any], other: dict[str, Any]) -> dict[str, Any]:
    """Change of ``other`` against ``base`` (two :func:`assess_series` results), in percent:
    DEL per channel, the 1P/3P/6P content of the blade-1 flap moment (Madsen sec. IV), power
    and generator-speed std, pitch travel."""
    def pct(a: float, b: float) -> float:
        return 100.0 * (b / a - 1.0) if a else float("nan")

    out: dict[str, Any] = {"del_change_pct": {c: pct(base["channels"][c]["del"], d["del"])
                                               for c, d in other["channels"].items()
                                               if c in base["channels"]}}
    if "flap_1_harmonics" in base and "flap_1_harmonics" in other:
        out["flap_1_harmonic_change_pct"] = {k: pct(base["flap_1_harmonics"][k], v)
                                             for k, v in other["flap_1_harmonics"].items()}
    for k in ("power_std_W", "gen_speed_std_rad_s", "pitch_travel_deg", "cs1", "cs2"):
        if k in base and k in other:
            out[f"{k}_change_pct"] = pct(base[k], other[k])
    return out


def assess_plots(runs: Sequence[tuple[str, np.ndarray, dict[str, np.ndarray]]],
                 out_dir: str | Path) -> list[str]:
    """CS ellipses (Do et al. fig. 4) and flap-moment PSDs of several runs, as PNG."""
    from .plotting import plot_cs_ellipses, plot_psd_comparison

    d = Path(out_dir)
    d.mkdir(parents=True, exist_ok=True)
    made = []
    items = [(name, cs_measures(c["tower_base_fa_moment"], c["gen_power"]),
              c["tower_base_fa_moment"], c["gen_power"]) for name, _, c in runs
             if "tower_base_fa_moment" in c and "gen_power" in c]
    if items:
        made.append(str(plot_cs_ellipses(items, d / "cs_ellipses.png")))
    spectra = []
    frot = 0.2
    for name, t, c in runs:
        if "flap_moment_1" in c:
            dt = float(np.median(np.diff(t)))
            f, p = psd(c["flap_moment_1"], 1 / dt)
            spectra.append((name, f, p))
            if "rotor_speed" in c:
                frot = float(c["rotor_speed"].mean()) / (2 * math.pi)
    if spectra:
        made.append(str(plot_psd_comparison(spectra, frot, d / "psd_flap_moment_1.png",
                                             "flap moment PSD [(N m)^2/Hz]")))
    return made

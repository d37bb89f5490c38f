"""Clemens et al.'s Takagi-Sugeno controller and wind observer (LMI gains)."""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import Any, Optional

import numpy as np


import linearize
from mpc_wt.registry.context import BuildContext, Built
from mpc_wt.registry.options import Options, option
from mpc_wt.registry.registry import register
from mpc_wt.io import gain_tables as gt
from mpc_wt.io.discon_export import LawExport, signal_codes
from mpc_wt.kinds.common import law_entries

log = logging.getLogger(__name__)

def _ts_designs(turbine: linearize.Turbine, ts: Any, rate: float | None,
                observer_rate: float | None, law: Any,
                side_side_feedback: bool = False) -> tuple[Any, Any]:
    """The TS controller and observer at the given decay rates [1/s]; a rate left None is the
    fastest whose loop, scheduled on the estimated wind, decays on the whole plant
    (:func:`~mpc_wt.controllers.takagi_sugeno.robustness.design_for_loop`). Without
    ``side_side_feedback`` the law leaves the tower's side-side states alone
    (:data:`~mpc_wt.controllers.takagi_sugeno.SIDE_SIDE_STATES`)."""
    from mpc_wt.controllers.takagi_sugeno import design_ts_controller, design_ts_observer
    from mpc_wt.controllers.takagi_sugeno.robustness import (
        design_for_loop,
        design_observer_for_loop,
    )

    from mpc_wt.controllers.takagi_sugeno import SIDE_SIDE_STATES

    unc = () if side_side_feedback else SIDE_SIDE_STATES
    if rate is None:
        kw = {} if observer_rate is None else {"observer_candidates": (observer_rate,)}
        return design_for_loop(ts, turbine, torque_law=law, uncontrolled=unc, **kw)[:2]
    ctl = design_ts_controller(ts, decay_rate=rate, uncontrolled=unc)
    if observer_rate is not None:
        return ctl, design_ts_observer(ts, decay_rate=observer_rate)
    return ctl, design_observer_for_loop(ts, ctl, turbine, torque_law=law)[0]




def _design_ts(turbine: linearize.Turbine, *, winds: Any = None,
               reductions: Any = (0.0, 0.4, 0.8), decay_rate: float | None = None,
               observer_decay_rate: float | None = None) -> tuple[dict, str]:
    from mpc_wt.controllers.takagi_sugeno import (
        TURBINE_MEASURED,
        build_ts_model,
    )
    from mpc_wt.controllers.takagi_sugeno.model import DEFAULT_WIND_GRID

    grid = DEFAULT_WIND_GRID if winds is None else winds
    ts = build_ts_model(turbine, [float(v) for v in grid], list(reductions),
                        measured=TURBINE_MEASURED, progress=True)
    from mpc_wt.controllers.baseline import BaselineController, tune_baseline

    ctl, obs = _ts_designs(turbine, ts, decay_rate, observer_decay_rate,
                           BaselineController(turbine, tune_baseline(turbine)))
    doc = ts_table(turbine, ts, ctl, obs)
    doc["settings"]["options"] = {"decay_rate": float(ctl.decay_rate),
                                  "observer_decay_rate": float(obs.decay_rate)}
    return doc, (
        f"{ts.n_vertices} vertices, {ctl.solver} {ctl.solve_time_s:.1f} s + "
        f"{obs.solve_time_s:.1f} s, certificates ok, decay rates {ctl.decay_rate:g} (controller) "
        f"and {obs.decay_rate:g} 1/s (observer)")




# -- Takagi-Sugeno ------------------------------------------------------------------------------
@dataclass(frozen=True)
class TSOptions(Options):
    """Clemens et al.'s TS controller and wind observer, LMI-designed on the default grid."""

    apc_frequency: Optional[float] = option(None, help="sinusoidal power reduction of eq 11 "
                                            "at this f_r", unit="Hz", lo=0.0, hi=5.0)
    apc_amplitude: float = option(0.375, help="amplitude of Delta P (fraction of rated)",
                                  unit="-", lo=0.0, hi=1.0)
    apc_offset: float = option(0.375, help="mean of Delta P", unit="-", lo=0.0, hi=1.0)
    decay_rate: Optional[float] = option(
        None, help="controller decay rate (default: the fastest of 0.2, 0.15, 0.1 whose loop, "
        "scheduled on the estimated wind, decays on the whole plant's linear models)",
        unit="1/s", lo=0.0, lo_open=True, flag="")
    observer_decay_rate: Optional[float] = option(
        None, help="observer decay rate (default: the fastest of 1, 0.7, 0.5, 0.35, 0.25, at "
        "most half the tower's first fore-aft frequency, whose loop decays with the "
        "controller's)",
        unit="1/s", lo=0.0, lo_open=True, flag="")
    generator_torque: str = option("baseline", help="baseline: the baseline's torque "
                                   "schedule (power-optimal tip-speed ratio below rated, "
                                   "constant power above), the TS law setting the pitch; ts: "
                                   "the TS law's own torque everywhere (Clemens et al.'s "
                                   "full-load design)", choices=("baseline", "ts"))
    side_side_feedback: bool = option(False, help="the law acts on the tower's side-side "
                                      "states too and requires their decay at the "
                                      "controller's rate (Clemens et al.'s full-state PDC); "
                                      "default: it leaves that mode to its own damping")


def _ts_entries(ctl: Any, preview: Any = None) -> list[tuple[str, Any, str]]:
    """The numbers of a :class:`~mpc_wt.controllers.takagi_sugeno.TSController`: its grids,
    the observer's blended zero-order-hold maps, the vertex equilibria and gains."""
    from mpc_wt.controllers.takagi_sugeno import TSController

    if type(ctl) is not TSController:
        raise ValueError(f"the TS export takes a TSController, got {type(ctl).__name__}")
    dp = ctl.power_reduction
    ts, gen, pa = ctl.ts, ctl.turbine.generator, ctl.turbine.pitch_actuator
    codes = signal_codes(ts.measured, "TS observer")
    n, nx = ctl._phi.shape[1], len(ts.states)
    dp0 = float(ts.reduction_grid[0])
    eq = np.array([ts.blend(ts.membership(float(v), dp0))["u0"][0] for v in ts.wind_grid])
    order = np.argsort(eq)
    kk = np.asarray(ctl._K, float)
    rows: list[tuple[str, Any, str]] = [
        ("dt", ctl.dt, "controller period [s] (ServoDyn DLL_DT)"),
        ("sizes", np.array([ts.wind_grid.size, ts.reduction_grid.size, n, len(ts.inputs),
                            len(ts.measured), kk.shape[2], -1 if ctl._ki is None else ctl._ki,
                            float(ctl.torque_law is None)], float),
         "winds, reductions, observer states (x and v), inputs, measurements, gain columns, "
         "integral state (-1: none), 1: the TS law's torque applied"),
        ("signals", codes, "measured: " + ", ".join(ts.measured)),
        ("limits", np.array([pa.min_pitch_rad, pa.max_pitch_rad, gen.min_torque,
                             gen.max_torque,
                             ctl._reach if math.isfinite(ctl._reach) else -1.0], float),
         "pitch min, max [rad], torque min, max [N m], how far a pitch command may lead the "
         "measured pitch [rad] (-1: no bound)"),
        ("rated_power", float(ts.rated_power), "electrical power the torque schedule holds [W]"),
        ("integral_source", float(-1 if ctl._int_src is None else ctl._int_src),
         "the measurement whose deviation is integrated (-1: the estimate)"),
        ("torque_law", float(ctl._law is not None), "1: the generator torque from the "
                                                    "baseline's schedule"),
        ("wind_grid", np.asarray(ts.wind_grid, float), "vertex winds [m/s]"),
        ("reduction_grid", np.asarray(ts.reduction_grid, float), "vertex power reductions [-]"),
        ("start_pitch", eq[order], "the vertex pitch without reduction, increasing [rad]"),
        ("start_wind", np.asarray(ts.wind_grid, float)[order], "its wind [m/s]"),
        ("terms", np.asarray(ctl._terms, float).ravel(),
         "the observer's terms: vertex i and j (weight h_i h_j; j = -1: h_i)"),
        ("phi", ctl._phi.ravel(), "each term's state map over a period (row-major)"),
        ("gamma", ctl._gam.ravel(), "each term's map of [u; y; 1] over a period (row-major)"),
        ("x0", np.asarray(ts.x0, float).ravel(), f"vertex equilibria ({nx} states each)"),
        ("u0", np.asarray(ts.u0, float).ravel(), "vertex inputs [rad, N m]"),
        ("gain", kk.ravel(), "vertex gains K_i (inputs x gain columns, row-major)"),
    ]
    if dp is not None:
        rows.append(("apc", np.array([dp.frequency_hz, dp.amplitude, dp.offset], float),
                     "power reduction Delta P = offset + amplitude sin(2 pi f t): f [Hz], "
                     "amplitude, offset [-]"))
    if ctl._law is not None:
        rows += law_entries(ctl._law)
    return rows


def _check_saved_ts(doc: Any) -> None:
    """A saved TS design exports when it is on the kind's vertex grid (the export builds the
    kind again from the design's options)."""
    from mpc_wt.controllers.takagi_sugeno.model import DEFAULT_REDUCTION_GRID, DEFAULT_WIND_GRID

    s = doc["settings"]
    if (list(s.get("wind_grid", [])) != list(DEFAULT_WIND_GRID)
            or list(s.get("reduction_grid", [])) != list(DEFAULT_REDUCTION_GRID)):
        raise ValueError(
            f"this TS design's vertex grid (winds {s.get('wind_grid')}, reductions "
            f"{s.get('reduction_grid')}) is not the one the controller kind 'ts' is built on "
            f"(winds {list(DEFAULT_WIND_GRID)}, reductions {list(DEFAULT_REDUCTION_GRID)}); "
            f"design it with the default --wind, or export a TSController built on your grid "
            f"with mpc_wt.run.export_controller")


#: The TS controller's export: its C law, the observer's maps and the vertex gains
TS_EXPORT = LawExport(
    "ts", "Clemens et al.'s Takagi-Sugeno controller and wind observer, observing the tower-top "
    "accelerations and the rotor and generator speeds", "ts", _ts_entries, sources=("ts.c",),
    log=("wind_est", "premise_clipped", "power_reduction", "power_ref"),
    check_saved=_check_saved_ts)


@register("ts", TSOptions, field_components="u", design=_design_ts, export=TS_EXPORT,
          summary="Clemens et al.'s Takagi-Sugeno controller and wind observer (LMI gains)")
def _build_ts(ctx: BuildContext, opts: TSOptions) -> Built:
    from mpc_wt.controllers.apc import apc_reference
    from mpc_wt.controllers.takagi_sugeno import TURBINE_MEASURED, TSController, build_ts_model

    measured = TURBINE_MEASURED

    law = None
    if opts.generator_torque == "baseline":
        from mpc_wt.controllers.baseline import BaselineController, tune_baseline

        law = BaselineController(ctx.turbine, tune_baseline(ctx.turbine))

    def make() -> tuple[Any, Any, Any]:
        ts0 = build_ts_model(ctx.turbine, measured=measured)
        return (ts0,) + _ts_designs(ctx.turbine, ts0, opts.decay_rate, opts.observer_decay_rate,
                                    law, opts.side_side_feedback)

    ts, c, o = ctx.cache.get(ctx.turbine, ("ts", opts.decay_rate, opts.observer_decay_rate,
                                           measured, opts.generator_torque,
                                           opts.side_side_feedback), make)
    dp = None if opts.apc_frequency is None else apc_reference(
        opts.apc_frequency, amplitude=opts.apc_amplitude, offset=opts.apc_offset)
    ctl = TSController(ts, c, o, ctx.turbine, power_reduction=dp,  # starts from its measurements
                       torque_law=law)
    return Built(ctl, meta={"ts": {"vertices": ts.n_vertices, "decay_rate": c.decay_rate,
                                   "observer_decay_rate": o.decay_rate,
                                   "apc_frequency_Hz": opts.apc_frequency}})



# -- the gain table ----------------------------------------------------------------------------
def ts_table(turbine: linearize.Turbine, ts: Any, controller: Any,
             observer: Any | None = None) -> dict[str, Any]:
    """A TS design (:mod:`mpc_wt.controllers.takagi_sugeno`) as a gain table: one row per premise vertex (wind,
    power reduction, equilibrium x0, u0), the PDC gains K_i and observer gains L_i, with the
    membership breakpoints and the LMI settings and certificate.

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    ts : TSModel
        The model.
    controller : TSControllerDesign
        The PDC gains.
    observer : TSObserverDesign, optional
        The observer gains.

    Returns
    -------
    dict
        The gain-table document (schema "mpc-wt gain table"): kind, turbine, settings, the
        schedule (columns with units, rows) and matrices.
    """
    su = dict(zip(linearize.STATE_NAMES, linearize.STATE_UNITS))
    st_units = [su.get(n, "-") for n in ts.states]
    in_units = ["rad", "N m"]
    vt = ts.vertices
    cols = ["wind_speed", "power_reduction"] + [f"x0_{n}" for n in ts.states] + \
        [f"u0_{n}" for n in ts.inputs]
    units = ["m/s", "-"] + st_units + in_units
    rows = [[vt[i, 0], vt[i, 1], *ts.x0[i], *ts.u0[i]] for i in range(ts.n_vertices)]
    kcols = list(ts.states) + ([f"integral_{controller.integral_of}"]
                               if controller.integral_of else [])
    kunits = st_units + ([su.get(controller.integral_of, "-") + " s"]
                         if controller.integral_of else [])
    mats = {"K": gt.matrix(controller.K, ts.inputs, kcols, "input unit / state unit",
                         [gt.unit_ratio(i, s) for i in in_units for s in kunits])}
    settings = {"wind_grid": ts.wind_grid.tolist(), "reduction_grid": ts.reduction_grid.tolist(),
                "membership": "product of piecewise-linear hats on wind_grid x reduction_grid",
                "rated_power": ts.rated_power, "measured": list(ts.measured),
                "decay_rate": controller.decay_rate, "disk_radius": controller.disk_radius,
                "input_bounds": controller.input_bounds.tolist(), "solver": controller.solver,
                "certificate_ok": controller.certificate.ok,
                "convention": "u = sum_i h_i (u0_i - K_i (x_hat - x0_i)) (Clemens eq 7)"}
    if observer is not None:
        yunits = [su.get(n, "-") for n in ts.measured]
        mats["L"] = gt.matrix(observer.L, list(ts.states) + ["wind"], list(ts.measured),
                            "xi unit / measurement unit",
                            [gt.unit_ratio(s, y) for s in st_units + ["m/s"] for y in yunits])
        settings.update({"tau_v": observer.tau_v, "observer_decay_rate": observer.decay_rate,
                         "observer_disk_radius": observer.disk_radius,
                         "observer_certificate_ok": observer.certificate.ok})
    return gt.document("ts", turbine, settings, cols, units, rows, mats, plot={"x": "vertex"})

"""Clemens et al.'s Takagi-Sugeno controller and wind observer (LMI gains)."""
from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import Any, Optional


import linearize
from mpc_wt.registry.context import BuildContext, Built
from mpc_wt.registry.options import Options, option
from mpc_wt.registry.registry import register
from mpc_wt.kinds.common import shipped_law

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
    from mpc_wt.io.gain_tables import ts_table

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
    observer_signals: str = option("turbine", help="the wind observer's measurements: "
                                   "turbine (tower-top fore-aft and side-side accelerations, "
                                   "rotor and generator speed, as a turbine's controller gets "
                                   "them; exportable) or paper (Clemens et al.'s tower-top "
                                   "displacements in place of the accelerations)",
                                   choices=("turbine", "paper"))
    generator_torque: str = option("baseline", help="baseline: the baseline's torque "
                                   "schedule (power-optimal tip-speed ratio below rated, "
                                   "constant power above), the TS law setting the pitch; ts: "
                                   "the TS law's own torque everywhere (Clemens et al.'s "
                                   "full-load design)", choices=("baseline", "ts"))
    side_side_feedback: bool = option(False, help="the law acts on the tower's side-side "
                                      "states too and requires their decay at the "
                                      "controller's rate (Clemens et al.'s full-state PDC); "
                                      "default: it leaves that mode to its own damping")


@register("ts", TSOptions, field_components="u", design=_design_ts, shipped=shipped_law("ts"),
          summary="Clemens et al.'s Takagi-Sugeno controller and wind observer (LMI gains)")
def _build_ts(ctx: BuildContext, opts: TSOptions) -> Built:
    from mpc_wt.controllers.apc import apc_reference
    from mpc_wt.controllers.takagi_sugeno import (
        CLEMENS_MEASURED,
        TURBINE_MEASURED,
        TSController,
        build_ts_model,
    )

    measured = TURBINE_MEASURED if opts.observer_signals == "turbine" else CLEMENS_MEASURED

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

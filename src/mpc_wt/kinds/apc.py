"""Clemens et al.'s active power control on the baseline."""
from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import Any

import numpy as np

import linearize
from mpc_wt.registry.context import BuildContext, Built
from mpc_wt.registry.options import REQUIRED, Options, option
from mpc_wt.registry.registry import register
from mpc_wt.simulation.scenario import Scenario, start_wind
from mpc_wt.io.discon_export import LawExport
from mpc_wt.kinds.common import BASELINE_LOG, baseline_entries

log = logging.getLogger(__name__)

# -- active power control -----------------------------------------------------------------
@dataclass(frozen=True)
class APCOptions(Options):
    """Sinusoidal power reduction of Clemens et al. eq 11."""

    apc_frequency: float = option(REQUIRED, help="F [Hz] (0: constant reduction at the offset)",
                                  unit="Hz", lo=0.0, hi=5.0)
    apc_amplitude: float = option(0.375, help="amplitude of Delta P (fraction of rated)",
                                  unit="-", lo=0.0, hi=1.0)
    apc_offset: float = option(0.375, help="mean of Delta P (0.375: Delta P in [0, 0.75])",
                               unit="-", lo=0.0, hi=1.0)


def _apc_trim(turbine: linearize.Turbine, sc: Scenario, opts: APCOptions
              ) -> linearize.OperatingPoint:
    from mpc_wt.controllers.apc import apc_reference

    dp = apc_reference(opts.apc_frequency, amplitude=opts.apc_amplitude, offset=opts.apc_offset)
    rated = turbine.operation.rated_power
    p_peak = rated * (1.0 - opts.apc_offset + opts.apc_amplitude)
    try:    # the reference peaks at P_r (1 - offset + amplitude): the mean wind must give it
        linearize.trim(turbine, start_wind(turbine, sc), min(p_peak, rated))
    except linearize.TrimError as err:
        which = "mean" if sc.wind_file is None else "start"
        raise ValueError(f"apc: the power reference peaks at {p_peak:g} W, above the power "
                         f"available at the {which} wind {start_wind(turbine, sc):g} m/s "
                         f"({err})") from err
    return linearize.trim(turbine, start_wind(turbine, sc), rated * (1.0 - dp(0.0)))


def _apc_entries(ctl: Any, preview: Any = None) -> list[tuple[str, Any, str]]:
    """The baseline law with the power reference of Clemens et al. eq 11 and the PI's gains
    scheduled on it (:class:`~mpc_wt.controllers.baseline.BaselineController` with a
    :class:`~mpc_wt.controllers.apc.PowerReference` and a gain schedule)."""
    from mpc_wt.controllers.apc import PowerReference

    ref, sched = ctl.power_reference, ctl.gain_schedule
    if not isinstance(ref, PowerReference) or not sched:
        raise ValueError("the apc export takes a BaselineController with a PowerReference and "
                         "a gain schedule")
    g = ctl.gains
    if abs(g.rated_power / g.power_fraction - ref.rated_power_W) > 1e-6 * ref.rated_power_W:
        raise ValueError(f"the apc export needs the gains at full power to refer to the "
                         f"reference's {ref.rated_power_W:g} W, got {g.rated_power:g} W at "
                         f"fraction {g.power_fraction:g}")
    dp = ref.reduction
    rows = np.array([[s.power_fraction, s.kp, s.ki, s.theta_k_rad, s.dpdtheta_0]
                     for s in sched], float)
    return baseline_entries(ctl, schedule=True) + [
        ("feedforward", 0.0, "no LIDAR feedforward"),
        ("ibc", 0.0, "no individual blade control"),
        ("apc", np.array([dp.frequency_hz, dp.amplitude, dp.offset, ref.rated_power_W]),
         "power reference P_r (1 - offset - amplitude sin(2 pi f t)): f [Hz], amplitude, "
         "offset [-], P_r [W]"),
        ("apc_schedule", rows.ravel(), "per design: power fraction, kp [s], ki [-], theta_K "
                                       "[rad], dP/dtheta at fine pitch [W/rad]")]


@register("apc", APCOptions, field_components="u", operating_point=_apc_trim,
          export=LawExport("apc", "Clemens et al.'s active power control: the baseline "
                           "following P_r (1 - Delta P(t)), its PI scheduled on the reference",
                           "baseline", _apc_entries,
                           log=(*BASELINE_LOG, "power_reference", "apc_saturated")),
          summary="the baseline following P_r (1 - Delta P(t)), PI scheduled on the reference")
def _build_apc(ctx: BuildContext, opts: APCOptions) -> Built:
    from mpc_wt.controllers.apc import PowerReference, apc_reference
    from mpc_wt.controllers.baseline import BaselineController, tune_baseline_schedule

    dp = apc_reference(opts.apc_frequency, amplitude=opts.apc_amplitude, offset=opts.apc_offset)
    rated = ctx.turbine.operation.rated_power
    sched = tune_baseline_schedule(ctx.turbine)
    ctl = BaselineController(ctx.turbine, gain_schedule=sched,
                             power_reference=PowerReference(rated, dp))
    return Built(ctl, meta={"apc": {"frequency_Hz": opts.apc_frequency,
                                    "amplitude": opts.apc_amplitude, "offset": opts.apc_offset,
                                    "schedule_fractions": [g.power_fraction for g in sched]}})

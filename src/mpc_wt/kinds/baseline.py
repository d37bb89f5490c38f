"""The baseline family: the tuned PI pitch and torque law (Jonkman et al. 2009, sec. 7.2), with
constant power or constant torque in region III, and derated (Pettas and Cheng)."""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import Any, Optional, Sequence

import numpy as np


import linearize
from mpc_wt.registry.context import BuildContext, Built
from mpc_wt.registry.options import REQUIRED, Options, option
from mpc_wt.registry.registry import register
from mpc_wt.simulation.scenario import Scenario, start_wind
from mpc_wt.io import gain_tables as gt
from mpc_wt.io.discon_export import LawExport
from mpc_wt.kinds.common import BASELINE_LOG, baseline_entries

log = logging.getLogger(__name__)

# -- baseline family ---------------------------------------------------------------------------
@dataclass(frozen=True)
class BaselineOptions(Options):
    """The baseline PI's design (Jonkman et al. 2009, sec. 7.2)."""

    omega_n_rad_s: Optional[float] = option(None, help="PI closed-loop natural frequency "
                                            "(default 0.6 rad/s x rated rotor speed / 12.1 rpm: "
                                            "the NREL 5-MW report's 0.6 on that turbine)",
                                            unit="rad/s", lo=0.0, lo_open=True, flag="")
    zeta: float = option(0.7, help="PI closed-loop damping ratio", unit="-", lo=0.0,
                         lo_open=True, flag="")


@dataclass(frozen=True)
class DerateOptions(BaselineOptions):
    """The baseline derated to a fraction of rated power (Pettas and Cheng sec. 3.2)."""

    power_fraction: float = option(REQUIRED, help="fraction of rated power, in (0, 1]",
                                   unit="-", lo=0.0, lo_open=True, hi=1.0, flag="")


def baseline_build(region3: str) -> Any:
    def build(ctx: BuildContext, opts: BaselineOptions) -> Built:
        from mpc_wt.controllers.baseline import BaselineController, tune_baseline

        frac = getattr(opts, "power_fraction", 1.0)
        gains = tune_baseline(ctx.turbine, omega_n_rad_s=opts.omega_n_rad_s, zeta=opts.zeta,
                              power_fraction=frac)
        ctl = BaselineController(ctx.turbine, gains, region3=region3)
        meta = {"gains": {"kp": gains.kp, "ki": gains.ki, "theta_k_rad": gains.theta_k_rad,
                          "k_opt": gains.k_opt, "power_fraction": frac, "region3": region3}}
        return Built(ctl, meta=meta, power_fraction=frac)
    return build


def derated_trim(turbine: linearize.Turbine, sc: Scenario, opts: DerateOptions
                  ) -> linearize.OperatingPoint:
    """Trim at the derated power; below it (low wind) at the turbine's own optimum."""
    try:
        return linearize.trim(turbine, start_wind(turbine, sc), opts.power_fraction
                              * turbine.operation.rated_power)
    except linearize.TrimError:
        return linearize.trim(turbine, start_wind(turbine, sc))


def _derate_preset(mt: Any) -> dict[str, Any]:
    pct = float(mt.group(1))
    if not 0.0 < pct <= 100.0:
        raise ValueError(f"derating in {mt.group(0)!r} is {pct:g} % of rated power; allowed: "
                         f"(0, 100] %")
    return {"power_fraction": pct / 100.0}


def _design_baseline(turbine: linearize.Turbine, *, omega_n_rad_s: float | None = None,
                     zeta: float = 0.7, power_fraction: float = 1.0) -> tuple[dict, str]:
    from mpc_wt.controllers.baseline import tune_baseline

    doc = baseline_table(turbine, tune_baseline(turbine, omega_n_rad_s=omega_n_rad_s, zeta=zeta,
                                                power_fraction=power_fraction))
    return doc, f"kp {doc['settings']['kp']:.4g} s, ki {doc['settings']['ki']:.4g}"


def _baseline_input(ctl: Any, preview: Any) -> list[tuple[str, Any, str]]:
    """The baseline's input file: its law, no feedforward, no IBC."""
    return baseline_entries(ctl) + [("feedforward", 0.0, "no LIDAR feedforward"),
                                    ("ibc", 0.0, "no individual blade control")]


register("baseline", BaselineOptions, field_components="u", design=_design_baseline,
         export=LawExport("baseline", "the tuned PI pitch loop and torque law, constant power "
                          "in region III", "baseline", _baseline_input, rebuilt=False,
                          log=BASELINE_LOG),
         summary="tuned PI pitch and torque law, constant power in region III (80 Hz)"
         )(baseline_build("constant_power"))
register("baseline-ct", BaselineOptions, field_components="u",
         export=LawExport("baseline-ct", "the baseline with constant torque in region III",
                          "baseline", _baseline_input, rebuilt=False, log=BASELINE_LOG),
         summary="the baseline with constant torque in region III (Do et al.'s PI)"
         )(baseline_build("constant_torque"))
register("derate", DerateOptions, field_components="u", pattern=r"derate(\d+(?:\.\d+)?)",
         pattern_options=_derate_preset, pattern_help="derateNN (NN % of rated power)",
         operating_point=derated_trim,
         export=LawExport("derate", "the baseline derated to a fraction of rated power, its PI "
                          "re-tuned", "baseline", _baseline_input, log=BASELINE_LOG),
         summary="the baseline derated to NN % of rated power, PI re-tuned")(
    baseline_build("constant_power"))



# -- the gain table ----------------------------------------------------------------------------
def baseline_table(turbine: linearize.Turbine, gains: Any,
                   winds: Sequence[float] | None = None) -> dict[str, Any]:
    """The PI baseline (:class:`~mpc_wt.controllers.baseline.BaselineGains`) as a gain table: the pitch
    gain schedule -- the gains the controller applies, :func:`~mpc_wt.controllers.baseline.effective_pi_gains`
    (kp, ki / (1 + 2 theta / theta_K) of the DISCON form), not the design's kp GK(theta) --
    at the trim pitch of each wind speed from rated (the first row: the wind at which the design's rated or
    derated power is reached at fine pitch) to cut-out in 1 m/s steps, with the set points.

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    gains : BaselineGains
        The design.
    winds : sequence of float, optional
        Wind speeds of the rows [m/s].

    Returns
    -------
    dict
        The gain-table document (schema "mpc-wt gain table"): kind, turbine, settings, the
        schedule (columns with units, rows) and matrices.
    """
    from mpc_wt.controllers.baseline import effective_pi_gains

    op = turbine.operation
    p_w = None if gains.power_fraction == 1.0 else gains.rated_power
    if winds is None:
        v0 = _rated_wind(turbine, p_w)
        winds = np.r_[v0, np.arange(math.floor(v0) + 1.0, op.cut_out_wind + 0.5, 1.0)]
    rows = []
    for v in winds:
        p = linearize.trim(turbine, float(v), p_w)
        kp, ki = effective_pi_gains(gains.kp, gains.ki, gains.theta_k_rad, p.pitch_rad)
        rows.append([float(v), p.pitch_rad, float(kp), float(ki), p.gen_torque,
                     p.gen_speed_rad_s, p.power])
    settings = {"kp": gains.kp, "ki": gains.ki, "theta_k_rad": gains.theta_k_rad,
                "k_opt": gains.k_opt, "rated_gen_speed_rad_s": gains.rated_gen_speed_rad_s,
                "rated_torque": gains.rated_torque, "rated_power": gains.rated_power,
                "omega_n_rad_s": gains.omega_n_rad_s, "zeta": gains.zeta,
                "power_fraction": gains.power_fraction, "min_pitch_rad": op.fine_pitch_rad,
                "max_pitch_rad": turbine.pitch_actuator.max_pitch_rad,
                "max_pitch_rate_rad_s": turbine.pitch_actuator.max_rate_rad_s,
                "max_torque": turbine.generator.max_torque,
                "min_torque": turbine.generator.min_torque,
                "max_torque_rate": turbine.generator.max_torque_rate,
                "min_gen_speed_rad_s": op.min_rotor_speed_rad_s
                * turbine.drivetrain.gearbox_ratio,
                "min_pitch_speeds_rad_s": list(gains.min_pitch_speeds),
                "min_pitch_offsets_rad": list(gains.min_pitch_offsets),
                "units": {"kp": "s", "ki": "-", "theta_k_rad": "rad",
                          "k_opt": "N m/(rad/s)^2", "rated_torque": "N m", "rated_power": "W"}}
    return gt.document("baseline", turbine, settings,
                ["wind_speed", "pitch", "kp", "ki", "gen_torque", "gen_speed", "power"],
                ["m/s", "rad", "s", "-", "N m", "rad/s", "W"], rows, {},
                       plot={"columns": ["kp", "ki"],
                             "label": "PI gains as applied: kp [s], ki [-]",
                             "title": "baseline: the small-signal PI gains of the DISCON form, "
                                      "kp and ki / (1 + 2 theta / theta_K)"})


def _rated_wind(turbine: linearize.Turbine, power_W: float | None) -> float:
    """The lowest wind at which ``power_W`` (default rated) is reached at fine pitch [m/s]."""
    v_rated = linearize.rated_wind_speed(turbine)
    if power_W is None:
        return v_rated
    from scipy.optimize import brentq

    def short(v: float) -> float:
        return linearize.trim(turbine, v).power - power_W

    lo = turbine.operation.cut_in_wind
    return float(brentq(short, lo, v_rated, xtol=1e-6)) if short(lo) < 0 else lo

"""Add-ons on a baseline: Pettas and Cheng's individual blade control and Coleman IPC."""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import Any, Optional

import numpy as np


import linearize
from mpc_wt.controllers.ipc import IBC_LOOP_GAIN
from mpc_wt.registry.context import BuildContext, Built
from mpc_wt.registry.options import Options, option
from mpc_wt.registry.registry import register
from mpc_wt.io import gain_tables as gt
from mpc_wt.io.discon_export import LawExport
from mpc_wt.kinds.common import BASELINE_LOG, baseline_entries

log = logging.getLogger(__name__)

def _design_ibc(turbine: linearize.Turbine, *, power_fraction: float = 1.0,
                loop_gain: float | None = None) -> tuple[dict, str]:
    from mpc_wt.controllers.ipc import tune_ibc

    g = tune_ibc(turbine, power_fraction=power_fraction, loop_gain_1p=loop_gain)
    doc = ibc_table(turbine, g)
    doc["settings"]["options"] = {"loop_gain_1p": float(g.info["target_loop_gain_1p"])}
    return doc, (f"{g.gain.size} points, gain margin >= "
                                   f"{g.gain_margin.min():.3g}, high-pass {g.highpass_hz:.3g} Hz")




def _design_coleman(turbine: linearize.Turbine, *, power_fraction: float = 1.0
                    ) -> tuple[dict, str]:
    from mpc_wt.controllers.ipc import tune_coleman_ipc

    g = tune_coleman_ipc(turbine, power_fraction=power_fraction)
    return coleman_ipc_table(turbine, g), (f"{g.ki.size} points, gain margin >= "
                                           f"{g.gain_margin.min():.3g}")




# -- add-ons: IBC and Coleman IPC -----------------------------------------------------------
@dataclass(frozen=True)
class IBCOptions(Options):
    """Individual blade control (Pettas and Cheng sec. 3.1; :func:`mpc_wt.controllers.ipc.tune_ibc`)."""

    loop_gain_1p: Optional[float] = option(None, help="loop gain at 1P of each blade loop "
                                           f"(default {IBC_LOOP_GAIN:g}, less on pitch drives "
                                           "too slow for a 2 deg cyclic at half their rate)",
                                           unit="-", lo=0.0, lo_open=True, flag="--loop-gain")
    remove_collective: bool = option(True, help="subtract the blades' mean IBC pitch (cyclic "
                                     "action only)",
                                     flag="--keep-collective", flag_value=False)
    min_gain_margin: float = option(2.0, help="smallest gain margin allowed", unit="-",
                                    lo=1.0, lo_open=True, flag="")
    highpass_hz: Optional[float] = option(None, help="input high-pass corner (default half "
                                          "the rated 1P)", unit="Hz", lo=0.0, lo_open=True,
                                          flag="")
    notch_harmonics: tuple[int, ...] = option((3,), help="output band-stops at these "
                                              "multiples of rated 1P", lo=1, flag="")
    notch_q: float = option(1.0, help="band-stop quality factor", unit="-", lo=0.0,
                            lo_open=True, flag="")
    weight_range: tuple[float, ...] = option((0.8, 0.95), help="power fractions of the fade-in",
                                             unit="-", lo=0.0, flag="")
    lowpass_hz: Optional[float] = option(None, help="output low-pass corner", unit="Hz",
                                         lo=0.0, lo_open=True, flag="")
    max_amplitude_deg: Optional[float] = option(None, help="largest IBC pitch of each blade "
                                                "(default 2 deg, or less where a cyclic of it "
                                                "at rated 1P would take more than half the "
                                                "actuator's rate)", unit="deg", lo=0.0,
                                                lo_open=True, hi=20.0, flag="")


def _addon_settings(ctl: Any) -> list[float]:
    """What IBC's and Coleman IPC's settings share, in their laws' order: the fade-in's power
    fractions, the power it refers to [W], the power low-pass's pole, the pitch limits [rad]
    and rate [rad/s] on the summed command."""
    g = ctl.gains
    return [g.weight_range[0], g.weight_range[1], g.rated_power,
            math.exp(-ctl.dt / ctl.power_tau), ctl.pitch_min, ctl.pitch_max,
            ctl.step_max / ctl.dt]


def _ibc_entries(ctl: Any, preview: Any = None) -> list[tuple[str, Any, str]]:
    """An :class:`~mpc_wt.controllers.ipc.IBCController` on the baseline: the baseline's law
    and the IBC's gain schedule, filters (second-order sections and their unit-step states),
    power fade-in and limits."""
    from mpc_wt.controllers.ipc import IBCController

    if type(ctl) is not IBCController:
        raise ValueError(f"the IBC export takes an IBCController, got {type(ctl).__name__}")
    g = ctl.gains
    return baseline_entries(ctl.collective) + [
        ("feedforward", 0.0, "no LIDAR feedforward"),
        ("ibc", 1.0, "1: individual blade control on the collective command"),
        ("ibc_settings", np.array([*_addon_settings(ctl), float(ctl.remove_collective),
                                   min(g.max_amplitude_rad, 1e300)], float),
         "the fade-in's power fractions [-], the power it refers to [W], the power filter's "
         "pole, pitch min, max [rad], pitch rate [rad/s], 1: the blades' mean removed, each "
         "blade's largest IBC pitch [rad] (1e300: none)"),
        ("ibc_gain_pitch", np.asarray(g.pitch_rad, float), "mean pitch of the gain schedule "
                                                           "[rad]"),
        ("ibc_gain", np.asarray(g.gain, float), "gain [rad/(N m)]"),
        ("ibc_input_sos", np.asarray(ctl.input_sos, float).ravel(),
         "input (high-pass) sections b0 b1 b2 a0 a1 a2"),
        ("ibc_input_zi", np.asarray(ctl.input_zi, float).ravel(),
         "their state at a unit input's steady state"),
        ("ibc_output_sos", np.asarray(ctl.output_sos, float).ravel(),
         "output (band-stop, low-pass) sections"),
        ("ibc_output_zi", np.asarray(ctl.output_zi, float).ravel(),
         "their state at a unit input's steady state"),
    ]


def _check_saved_full_power(doc: Any) -> None:
    """A saved add-on design exports when it is on the full-power baseline (the export builds
    it again with its kind's default base)."""
    frac = doc["settings"].get("power_fraction", 1.0)
    if frac != 1.0:
        kind = doc.get("kind")
        raise ValueError(
            f"this {kind} design is on a derated baseline (power fraction {frac:g}); a saved "
            f"design exports on the full-power baseline: export derate{100 * frac:g}+{kind} "
            f"with mpc_wt.run.export_discon, or your own {kind} controller object with "
            f"mpc_wt.run.export_controller")


#: IBC's export: the baseline's law with the IBC on its collective command
IBC_EXPORT = LawExport(
    "ibc", "Pettas and Cheng's individual blade control on the baseline: each blade's root "
    "moment filtered, scaled by the gain scheduled on the mean pitch, faded in with the power",
    "baseline", _ibc_entries, base=("baseline", "derate"),
    log=(*BASELINE_LOG, "ibc_weight", "ibc_gain", "ibc_pitch_1", "ibc_pitch_2",
         "ibc_pitch_3"),
    check_saved=_check_saved_full_power)


@register("ibc", IBCOptions, field_components="u", addon_to=("baseline", "derate"),
          default_base="baseline", design=_design_ibc, export=IBC_EXPORT,
          group="the ibc controllers",
          summary="individual blade control on a baseline (ibc, derateNN+ibc)")
def _build_ibc(ctx: BuildContext, opts: IBCOptions, base: Built) -> Built:
    from mpc_wt.controllers.ipc import IBCController, tune_ibc

    tune = {k: v for k, v in opts.to_dict().items() if k != "remove_collective"}
    tune["notch_harmonics"] = tuple(opts.notch_harmonics)
    tune["weight_range"] = tuple(opts.weight_range)
    g = tune_ibc(ctx.turbine, power_fraction=base.power_fraction, dt=base.controller.dt, **tune)
    ctl = IBCController(base.controller, g, remove_collective=opts.remove_collective)
    meta = {"gain": g.gain.tolist(), "pitch_rad": g.pitch_rad.tolist(),
            "highpass_hz": g.highpass_hz, "notch_harmonics": list(g.notch_harmonics),
            **opts.to_dict()}
    return Built(ctl, base.controller_dt, base.preview, {**base.meta, "ibc": meta},
                 base.power_fraction)


@dataclass(frozen=True)
class ColemanIPCOptions(Options):
    """Tilt/yaw integral IPC in the Coleman frame (:func:`mpc_wt.controllers.ipc.tune_coleman_ipc`)."""

    crossover_rad_s: float = option(0.2, help="crossover of the integral loops", unit="rad/s",
                                    lo=0.0, lo_open=True, flag="")
    max_amplitude_deg: Optional[float] = option(None, help="largest cyclic pitch amplitude "
                                                "(default 2 deg, or less where the cyclic "
                                                "at rated 1P would take more than half the "
                                                "actuator's rate)", unit="deg",
                                                lo=0.0, lo_open=True, flag="")
    weight_range: tuple[float, ...] = option((0.8, 0.95), help="power fractions of the fade-in",
                                             unit="-", lo=0.0, flag="")


def _coleman_entries(ctl: Any, preview: Any = None) -> list[tuple[str, Any, str]]:
    """A :class:`~mpc_wt.controllers.ipc.ColemanIPCController` on the baseline: the baseline's
    law and the IPC's gain schedule, power fade-in and limits."""
    from mpc_wt.controllers.ipc import ColemanIPCController

    if type(ctl) is not ColemanIPCController:
        raise ValueError(f"the coleman-ipc export takes a ColemanIPCController, got "
                         f"{type(ctl).__name__}")
    g = ctl.gains
    return baseline_entries(ctl.collective) + [
        ("feedforward", 0.0, "no LIDAR feedforward"),
        ("ibc", 0.0, "no individual blade control"),
        ("coleman_ipc", 1.0, "1: Coleman-frame integral IPC on the collective command"),
        ("coleman_settings", np.array([*_addon_settings(ctl),
                                       min(g.max_amplitude_rad, 1e300)], float),
         "the fade-in's power fractions [-], the power it refers to [W], the power filter's "
         "pole, pitch min, max [rad], pitch rate [rad/s], the largest cyclic amplitude [rad]"),
        ("coleman_pitch", np.asarray(g.pitch_rad, float), "mean pitch of the gain schedule "
                                                          "[rad]"),
        ("coleman_ki", np.asarray(g.ki, float), "integral gain [rad/(N m s)]"),
        ("coleman_azimuth_offset", np.asarray(g.azimuth_offset_rad, float),
         "azimuth offset phi that decouples tilt and yaw [rad]"),
    ]


#: Coleman IPC's export: the baseline's law with the IPC on its collective command
COLEMAN_EXPORT = LawExport(
    "coleman-ipc", "Coleman-frame integral IPC on the baseline: the blades' root moments to "
    "tilt and yaw, integrated to a cyclic pitch with the gain scheduled on the mean pitch, "
    "faded in with the power", "baseline", _coleman_entries, base=("baseline", "derate"),
    log=(*BASELINE_LOG, "ipc_weight", "ipc_tilt_moment", "ipc_yaw_moment", "ipc_pitch_cos",
         "ipc_pitch_sin"),
    check_saved=_check_saved_full_power)


@register("coleman-ipc", ColemanIPCOptions, field_components="u", addon_to=("baseline", "derate"),
          default_base="baseline", design=_design_coleman, export=COLEMAN_EXPORT,
          summary="tilt/yaw integral IPC on a baseline (coleman-ipc, derateNN+coleman-ipc)")
def _build_coleman(ctx: BuildContext, opts: ColemanIPCOptions, base: Built) -> Built:
    from mpc_wt.controllers.ipc import ColemanIPCController, tune_coleman_ipc

    d = opts.to_dict()
    d["weight_range"] = tuple(opts.weight_range)
    g = tune_coleman_ipc(ctx.turbine, power_fraction=base.power_fraction, **d)
    meta = {"ki": g.ki.tolist(), "pitch_rad": g.pitch_rad.tolist(),
            "azimuth_offset_rad": g.azimuth_offset_rad.tolist(), **opts.to_dict()}
    return Built(ColemanIPCController(base.controller, g), base.controller_dt, base.preview,
                 {**base.meta, "coleman_ipc": meta}, base.power_fraction)



# -- the gain table ----------------------------------------------------------------------------
def ibc_table(turbine: linearize.Turbine, gains: Any) -> dict[str, Any]:
    """Individual blade control (:class:`~mpc_wt.controllers.ipc.IBCGains`) as a gain table: the
    proportional gain per mean-pitch breakpoint, with its gain margin and 1P loop gain, and the
    filters (high-pass corner, band-stop frequencies and Q) and power fade-in in ``settings``.

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    gains : IBCGains
        The design.

    Returns
    -------
    dict
        The gain-table document (schema "mpc-wt gain table"): kind, turbine, settings, the
        schedule (columns with units, rows) and matrices.
    """
    rows = [[w, p, k, gm if math.isfinite(gm) else 1e300, lg] for w, p, k, gm, lg in zip(
        gains.wind_mps, gains.pitch_rad, gains.gain, gains.gain_margin, gains.loop_gain_1p)]
    settings = {"dt": gains.dt, "highpass_hz": gains.highpass_hz,
                "notch_hz": [h * gains.one_p_hz for h in gains.notch_harmonics],
                "notch_harmonics": list(gains.notch_harmonics), "notch_q": gains.notch_q,
                "weight_range": list(gains.weight_range), "rated_power": gains.rated_power,
                "power_fraction": gains.power_fraction,
                "rotor_speed_rad_s": gains.rotor_speed_rad_s,
                "max_amplitude_rad": min(gains.max_amplitude_rad, 1e300),
                "convention": "theta_i = theta_collective + w(P) BS(K(theta_mean) HP(M_flap_i)) "
                              "(Pettas and Cheng sec. 3.1); gain margin 1e300: none"}
    return gt.document("ibc", turbine, settings,
                ["wind_speed", "pitch", "gain", "gain_margin", "loop_gain_1p"],
                ["m/s", "rad", "rad/(N m)", "-", "-"], rows, {},
                       plot={"columns": ["gain"], "label": "IBC gain [rad/(N m)]",
                             "title": "ibc: the gain scheduled on the mean pitch"})


def coleman_ipc_table(turbine: linearize.Turbine, gains: Any) -> dict[str, Any]:
    """Coleman-frame IPC (:class:`~mpc_wt.controllers.ipc.ColemanIPCGains`) as a gain table: integral
    gain and azimuth offset per mean-pitch breakpoint; ``settings["baseline"]`` holds the
    baseline's gain table (:func:`mpc_wt.kinds.baseline.baseline_table`) of the same power
    fraction, ROSCO's pitch schedule in its ``rosco`` export.

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    gains : ColemanIPCGains
        The design.

    Returns
    -------
    dict
        The gain-table document (schema "mpc-wt gain table"): kind, turbine, settings, the
        schedule (columns with units, rows) and matrices.
    """
    from mpc_wt.controllers.baseline import tune_baseline
    from mpc_wt.kinds.baseline import baseline_table

    rows = [[w, p, k, a, gm] for w, p, k, a, gm in zip(
        gains.wind_mps, gains.pitch_rad, gains.ki, gains.azimuth_offset_rad, gains.gain_margin)]
    base = baseline_table(turbine, tune_baseline(turbine, power_fraction=gains.power_fraction))
    settings = {"crossover_rad_s": gains.crossover_rad_s,
                "max_amplitude_rad": gains.max_amplitude_rad,
                "weight_range": list(gains.weight_range), "rated_power": gains.rated_power,
                "power_fraction": gains.power_fraction,
                "convention": "theta_cs = -K_I R(-phi) int M_cs dt, M_cs = 2/3 sum M_i "
                              "[cos psi_i, sin psi_i]; theta_i += theta_c cos psi_i + theta_s "
                              "sin psi_i",
                "baseline": base}
    return gt.document("coleman-ipc", turbine, settings,
                ["wind_speed", "pitch", "ki", "azimuth_offset", "gain_margin"],
                ["m/s", "rad", "rad/(N m s)", "rad", "-"], rows, {},
                       plot={"columns": ["ki"], "label": "IPC integral gain [rad/(N m s)]"})

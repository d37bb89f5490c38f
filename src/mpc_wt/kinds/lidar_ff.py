"""The CW LIDAR's collective pitch feedforward on a baseline."""
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
from mpc_wt.kinds.baseline import BaselineOptions, baseline_build
from mpc_wt.io import gain_tables as gt
from mpc_wt.io.discon_export import LawExport
from mpc_wt.kinds.common import BASELINE_LOG, LidarOptions, baseline_entries

log = logging.getLogger(__name__)

# -- LIDAR collective pitch feedforward -------------------------------------------------------
@dataclass(frozen=True)
class LidarFFOptions(Options):
    """Collective pitch feedforward from the CW LIDAR (:class:`mpc_wt.controllers.lidar_feedforward.LidarFeedforward`)."""

    lidar: LidarOptions = option(LidarOptions(), help="CW LIDAR settings (focus_distance, "
                                 "range_weighting, los_error, ...)", flag="")
    filter_corner_hz: Optional[float] = option(None, help="low-pass corner of the wind estimate "
                                               "(default: where the model coherence of the "
                                               "LIDAR's and the rotor's effective wind falls "
                                               "to 0.5 at the measured mean wind, raised if "
                                               "its delay would not fit the preview)",
                                               unit="Hz", lo=0.0, lo_open=True,
                                               flag="--ff-corner-hz")
    design_turbulence: str = option("A", help="IEC turbulence class of the corner's design "
                                    "(the turbine's class)", choices=("A", "B", "C"),
                                    flag="--ff-design-class")
    lead_time: Optional[float] = option(None, help="lead of the pitch over the wind's arrival "
                                        "(default: actuator time constant + the filter's "
                                        "delay)", unit="s", lo=0.0, flag="--ff-lead-time")
    filter_order: int = option(2, help="order of the low-pass (2: damping 0.7)",
                               choices=(1, 2), flag="--ff-filter-order")


def _design_lidar_ff(turbine: linearize.Turbine) -> tuple[dict, str]:
    """The baseline with the LIDAR feedforward, default options, as a table over mean wind
    (``mpcwt design baseline+lidar-ff``; ``mpcwt export --format discon`` builds it again)."""
    from mpc_wt.registry.context import DEFAULT_CACHE

    ctx = BuildContext(turbine=turbine, params=linearize.plant_params(turbine),
                       cache=DEFAULT_CACHE)
    base = baseline_build("constant_power")(ctx, BaselineOptions())
    ctl = _build_lidar_ff(ctx, LidarFFOptions(), base).controller
    doc = lidar_ff_table(turbine, ctl, "baseline+lidar-ff", options={})
    rows = doc["schedule"]["rows"]
    return doc, (f"filter corner {min(r[1] for r in rows):.3g}-{max(r[1] for r in rows):.3g} "
                 f"rad/s over {rows[0][0]:g}-{rows[-1][0]:g} m/s")


def _ff_entries(ctl: Any, preview: Any = None) -> list[tuple[str, Any, str]]:
    """A :class:`~mpc_wt.controllers.lidar_feedforward.LidarFeedforward` on the baseline: the
    baseline's law and the feedforward's LIDAR processing, filter, lead and pitch curve."""
    from mpc_wt.controllers.lidar_feedforward import LidarFeedforward

    if type(ctl) is not LidarFeedforward:
        raise ValueError(f"the feedforward export takes a LidarFeedforward, got "
                         f"{type(ctl).__name__}")
    inst = ctl.sensor.instrument
    return baseline_entries(ctl.base) + [
        ("feedforward", 1.0, "1: the LIDAR's collective pitch feedforward"),
        ("ff", np.array([math.cos(inst.cone_angle_rad), inst.focus_distance, ctl.sample_dt,
                         ctl.mean_time_constant, ctl.tau_act,
                         -1.0 if ctl.lead_given is None else ctl.lead_given, ctl.order], float),
         "cos(cone), focus distance [m], LIDAR sample period [s], the mean wind's averaging "
         "time [s], pitch actuator time constant [s], a fixed lead [s] (-1: from the filter), "
         "filter order"),
        ("ff_corner_winds", np.asarray(ctl.corner_winds, float), "mean winds of the filter "
                                                                 "corners [m/s]"),
        ("ff_corners", np.asarray(ctl.corners, float), "filter corners [rad/s]"),
        ("ff_curve_winds", np.asarray(ctl.curve_v, float), "winds of the static pitch curve "
                                                           "[m/s]"),
        ("ff_curve_pitch", np.asarray(ctl.curve_pitch, float), "static pitch [rad]"),
    ]


#: The LIDAR feedforward's export: the baseline's law with the feedforward in its integral
LIDAR_FF_EXPORT = LawExport(
    "baseline+lidar-ff", "the baseline with the collective pitch feedforward of a hub-mounted "
    "CW LIDAR, read from OpenFAST's lidar records", "baseline", _ff_entries,
    base=("baseline", "derate"),
    log=(*BASELINE_LOG, "ff_wind", "ff_pitch", "ff_mean_wind", "ff_corner"))


@register("lidar-ff", LidarFFOptions, addon_to=("baseline", "derate"), default_base="baseline",
          field_components="u", group="the lidar feedforward", design=_design_lidar_ff,
          export=LIDAR_FF_EXPORT,
          design_name="baseline+lidar-ff",
          summary="collective pitch feedforward from the CW LIDAR on a baseline "
                  "(baseline+lidar-ff, derate80+lidar-ff)")
def _build_lidar_ff(ctx: BuildContext, opts: LidarFFOptions, base: Built) -> Built:
    from mpc_wt.controllers.lidar_feedforward import LidarFeedforward, model_corner_table

    cw = opts.lidar.instrument(ctx.turbine)
    sensor = ctx.lidar(cw, opts.lidar.evolution)
    if opts.filter_corner_hz is None:
        key = (*sorted(opts.lidar.given().items()), ("evolution", opts.lidar.evolution),
               ("class", opts.design_turbulence))
        corner: Any = ctx.cache.get(ctx.turbine, ("lidar-ff-corner", key),
                                    lambda: model_corner_table(cw, ctx.turbine,
                                                               opts.design_turbulence,
                                                               evolution=opts.lidar.evolution))
        shown = {"corner_winds_mps": corner[0].tolist(),
                 "corner_rad_s": corner[1].tolist(), "corner_design": "turbulence model"}
    else:
        corner = 2.0 * math.pi * opts.filter_corner_hz
        shown = {"corner_rad_s": corner, "corner_design": "given"}
    frac = base.power_fraction
    ctl = LidarFeedforward(base.controller, sensor, ctx.turbine, corner=corner,
                           lead_s=opts.lead_time, filter_order=opts.filter_order,
                           power_W=None if frac == 1.0
                           else frac * ctx.turbine.operation.rated_power)
    meta = {**shown, "lead_s": opts.lead_time, "filter_order": opts.filter_order,
            "design_turbulence": opts.design_turbulence,
            "focus_distance_m": cw.focus_distance, "evolution": opts.lidar.evolution}
    return Built(ctl, base.controller_dt, base.preview, {**base.meta, "lidar_ff": meta},
                 base.power_fraction)



# -- the gain table ----------------------------------------------------------------------------
def lidar_ff_table(turbine: linearize.Turbine, ctl: Any, kind: str,
                   options: dict[str, Any] | None = None) -> dict[str, Any]:
    """The LIDAR feedforward's design as a table over mean wind: the filter corner of the
    turbulence model and the static pitch curve the feedforward follows; the settings hold the
    kind's options (from which it is built again), the baseline's PI gains and the filter.

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    ctl : LidarFeedforward
        The design.
    kind : str
        Its kind (``baseline+lidar-ff``).
    options : dict, optional
        The options it was built with.

    Returns
    -------
    dict
        The gain-table document.
    """
    winds = np.asarray(ctl.corner_winds, float)
    pitch = np.interp(winds, ctl.curve_v, ctl.curve_pitch)
    rows = [[float(v), float(c), float(p)] for v, c, p in zip(winds, ctl.corners, pitch)]
    g = ctl.base.gains
    settings = {"options": dict(options or {}), "kp": g.kp, "ki": g.ki,
                "filter_order": ctl.order, "sample_dt": ctl.sample_dt,
                "lead_s": ctl.lead_given, "focus_distance": ctl.sensor.focus_distance,
                "units": {"kp": "s", "ki": "-", "sample_dt": "s", "lead_s": "s",
                          "focus_distance": "m"}}
    return gt.document(kind, turbine, settings, ["wind_speed", "filter_corner", "static_pitch"],
                ["m/s", "rad/s", "rad"], rows, {},
                plot={"columns": ["filter_corner"], "label": "feedforward filter corner [rad/s]",
                      "title": f"{kind}: the filter corner over mean wind"})

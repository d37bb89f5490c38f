"""What the kinds share: the shipped law of a kind that exports, the LIDAR's options, the
wind estimator and schedule checks of the scheduled designs."""
from __future__ import annotations

import dataclasses
import logging
import math
from dataclasses import dataclass
from typing import Any, Optional


import numpy as np

import linearize
from mpc_wt.registry.context import BuildContext, Built
from mpc_wt.registry.options import Options, option

log = logging.getLogger(__name__)

# -- the shipped laws: a kind that exports runs its compiled C law --------------------------
def run_as_shipped(ctx: BuildContext, export: Any, built: Built) -> Built:
    """A design as it is shipped: its numbers written to its law's input file, its compiled
    library (:func:`mpc_wt.io.discon_export.shipped_library`) called through the host in this
    process, so that every run of the kind calls the law users run in OpenFAST. A plugin's
    design with a step of its own that its law does not take keeps that step (logged); the
    run's metadata says which law ran (``meta["law"]``; ``meta["design"]["law"]`` the build
    key of its library, :func:`mpc_wt.io.discon_export.shipped_law_key`).

    Parameters
    ----------
    ctx : BuildContext
        The design's context (its turbine).
    export : LawExport
        The kind's export (:attr:`mpc_wt.registry.Selection.export`).
    built : Built
        The design with its Python objects.

    Returns
    -------
    Built
        The library's host as the controller, the design in ``design``; or ``built`` with
        ``meta["law"] = "python"``.

    Raises
    ------
    ValueError
        A design that has no step of its own (:class:`~mpc_wt.controllers.base.DesignBase`)
        and that its law does not take.
    """
    from mpc_wt.controllers.base import DesignBase

    try:
        ctl = shipped_host(built.controller, export, ctx.turbine, built.preview,
                           lidar=built.sensors[-1] if built.sensors else None)
    except ValueError as err:
        if isinstance(built.controller, DesignBase):
            raise
        log.info("%s: the design does not export (%s); its Python step runs", export.name, err)
        return dataclasses.replace(built, meta={**built.meta, "law": "python"})
    from mpc_wt.io.discon_export import shipped_law_key

    design = {**built.meta.get("design", {}), "law": shipped_law_key(export)}
    return dataclasses.replace(built, controller=ctl, controller_dt=ctl.dt, preview=None,
                               design=built.controller,
                               meta={**built.meta, "law": "shipped",
                                     "library": ctl.library.name, "design": design})


def shipped_host(design: Any, export: Any, turbine: linearize.Turbine, preview: Any = None, *,
                 lidar: Any = None) -> Any:
    """The host of a design's shipped law in this process: its numbers in its law's input
    file (:func:`mpc_wt.io.discon_export.shipped_input`), its compiled library
    (:func:`~mpc_wt.io.discon_export.shipped_library`), called as OpenFAST's ServoDyn calls it.

    Parameters
    ----------
    design : object
        The design (of the type its kind builds).
    export : LawExport
        Its kind's export.
    turbine : Turbine
        Its turbine.
    preview : LidarPreview, optional
        The design's LIDAR preview (the MPC with LIDAR).
    lidar : lidar.LidarSensor, optional
        The LIDAR whose measurements fill the lidar records (the LIDAR kinds).

    Returns
    -------
    DisconController
        The host (``isolate=False``), at the design's period, reset for its first call.

    Raises
    ------
    ValueError
        A design the law does not take.
    """
    from mpc_wt.controllers.discon import DisconController
    from mpc_wt.io.discon_export import shipped_input, shipped_library

    infile = shipped_input(design, export, turbine, preview)
    host = DisconController(shipped_library(export), infile, turbine, dt=float(design.dt),
                            lidar=lidar, isolate=False, log_names=export.log)
    host.reset()                                 # ready for its first call
    return host


#: the logging channels of the baseline's law, which every law on it returns first
BASELINE_LOG = ("gen_speed_filtered", "speed_error", "pitch_integral", "gain_schedule")


_CW = "lidar.CWLidar setting (unset: its default)"


@dataclass(frozen=True)
class LidarOptions(Options):
    """Settings of the CW LIDAR (:class:`lidar.CWLidar`); unset ones keep its defaults."""

    focus_distance: Optional[float] = option(None, help=_CW, unit="m", lo=0.0, lo_open=True)
    span_fraction: Optional[float] = option(None, help=_CW, unit="-", lo=0.0, lo_open=True)
    wavelength: Optional[float] = option(None, help=_CW, unit="m", lo=0.0, lo_open=True)
    beam_radius: Optional[float] = option(None, help=_CW, unit="m", lo=0.0, lo_open=True)
    sample_rate: Optional[float] = option(None, help=_CW, unit="Hz", lo=0.0, lo_open=True)
    noise_std: Optional[float] = option(None, help=_CW, unit="m/s", lo=0.0)
    misalignment_rad: Optional[float] = option(None, help=_CW, unit="rad")
    perfect_alignment: Optional[bool] = option(None, help=_CW)
    los_error: Optional[bool] = option(None, help=_CW)
    range_weighting: Optional[bool] = option(None, help=_CW)
    n_range: Optional[int] = option(None, help=_CW, lo=1)
    evolution: bool = option(True, help="wind evolution between the focus and the rotor "
                             "(Simley and Pao's coherence, lidar.evolve_field); false: frozen "
                             "turbulence, Madsen's assumption")

    def given(self) -> dict[str, Any]:
        """The :class:`lidar.CWLidar` settings that were set.

        Returns
        -------
        dict
            Name -> value of the CWLidar options that are not None (``evolution`` is not one:
            it acts on the field the LIDAR sees, :func:`mpc_wt.simulation.scenario.lidar_field`).
        """
        return {k: v for k, v in self.to_dict().items() if v is not None and k != "evolution"}

    def instrument(self, turbine: linearize.Turbine) -> Any:
        """The CW LIDAR of these settings on the turbine's rotor.

        Parameters
        ----------
        turbine : Turbine
            For the rotor radius.

        Returns
        -------
        lidar.CWLidar

        Raises
        ------
        ValueError
            A setting CWLidar refuses, prefixed "lidar options:".
        """
        import lidar

        try:
            return lidar.CWLidar(turbine.geometry.tip_radius, **self.given())
        except (TypeError, ValueError) as err:
            raise ValueError(f"lidar options: {err}") from err


def envelope_family(ctx: BuildContext, config: str, step: float,
                     region3_pitch_deg: float = 0.0) -> Any:
    """The turbine's linear models from cut-in to cut-out (kept in the design cache); with
    ``region3_pitch_deg`` > 0 the first design above rated where the trim's pitch has left fine
    pitch by that much (:func:`~mpc_wt.controllers.scheduling.envelope_winds`)."""
    from mpc_wt.controllers.scheduling import envelope_winds

    conf = {"madsen": linearize.PlantConfig.madsen, "do": linearize.PlantConfig.do}[config]
    r3 = math.radians(region3_pitch_deg) if region3_pitch_deg > 0.0 else None
    grid = ctx.cache.get(ctx.turbine, ("envelope-grid", config, step, r3),
                         lambda: envelope_winds(ctx.turbine, step, region3_pitch=r3,
                                                config=conf()))
    return ctx.cache.get(ctx.turbine, ("family", config, tuple(grid)),
                         lambda: linearize.linearize_family(ctx.turbine, grid, config=conf()))


def wind_estimator(ctx: BuildContext, dt: float) -> Any:
    """A wind estimator at ``dt`` on the turbine's C_P table (which
    :func:`linearize.rotor_performance` keeps for the process)."""
    from mpc_wt.controllers.wind_estimator import WindSpeedEstimator

    return WindSpeedEstimator(ctx.turbine, dt)


def check_design_wind(turbine: linearize.Turbine, v: float) -> float:
    op = turbine.operation
    if not op.cut_in_wind <= v <= op.cut_out_wind:
        raise ValueError(f"design_wind_mps = {v:g} m/s is outside the turbine's operating range "
                         f"{op.cut_in_wind:g}..{op.cut_out_wind:g} m/s")
    return float(v)


# -- what the exports share: the baseline law's numbers (every law's torque schedule), the
# wind estimator's and a schedule's region floor ------------------------------------------


def baseline_entries(ctl: Any, prefix: str = "", *, schedule: bool = False
                     ) -> list[tuple[str, Any, str]]:
    """The numbers of a :class:`~mpc_wt.controllers.baseline.BaselineController` as input-file
    entries: the baseline law's, which every law's torque schedule is.

    Parameters
    ----------
    ctl : BaselineController
        The design.
    prefix : str
        Before every key (``law.`` for the torque schedule in another law).
    schedule : bool
        Allow a power reference and a gain schedule (active power control), whose entries
        the caller adds.

    Returns
    -------
    list of (str, object, str)
        Key, value (a number or an array) and its meaning, in the input file's order.

    Raises
    ------
    ValueError
        Another controller, or a baseline with a power reference or gain schedule.
    """
    from mpc_wt.controllers.baseline import BaselineController

    if type(ctl) is not BaselineController:
        raise ValueError(f"the baseline export takes a BaselineController, got "
                         f"{type(ctl).__name__}")
    if not schedule and (ctl.power_reference is not None or ctl.gain_schedule):
        raise ValueError("a baseline with a power reference or a gain schedule (active power "
                         "control) does not export yet: export the plain design")
    g, tb = ctl.gains, ctl.turbine
    rows = [
        ("dt", ctl.dt, "communication interval [s] (ServoDyn DLL_DT)"),
        ("speed_filter_corner_hz", ctl.wc / (2 * math.pi),
         "generator-speed low-pass corner [Hz]"),
        ("gen_speed_setpoint", g.rated_gen_speed_rad_s, "PI speed set-point [rad/s]"),
        ("kp", g.kp, "proportional gain at fine pitch [s]"),
        ("ki", g.ki, "integral gain at fine pitch [-]"),
        ("theta_k", g.theta_k_rad, "pitch at which the gain has halved [rad]"),
        ("pitch_min", ctl.pitch_min, "minimum pitch command [rad]"),
        ("pitch_max", ctl.pitch_max, "maximum pitch command [rad]"),
        ("pitch_rate_max", ctl.rate, "pitch-rate limit [rad/s]"),
        ("torque_rate_max", ctl.tq_rate, "generator-torque rate limit [N m/s]"),
        ("torque_max", ctl.tq_max, "maximum generator torque [N m]"),
        ("gen_speed_cutin", ctl.w_cutin, "region 1.5 starts [rad/s]"),
        ("gen_speed_region2", ctl.w_rgn2, "region 2 starts [rad/s]"),
        ("gen_speed_transition", ctl.w_trans, "region 2.5 starts [rad/s]"),
        ("gen_speed_rated", ctl.w_rated, "region 3 speed [rad/s]"),
        ("gen_speed_sync", ctl.w_sync, "region 2.5 line's zero-torque speed [rad/s]"),
        ("slope_region15", ctl.slope15, "region 1.5 torque slope [N m s/rad]"),
        ("slope_region25", ctl.slope25, "region 2.5 torque slope [N m s/rad]"),
        ("k_opt", g.k_opt, "region 2 torque gain [N m s^2/rad^2]"),
        ("torque_cap", ctl.tq_cap, "largest torque below rated [N m]"),
        ("rated_power", g.rated_power, "rated electrical power [W]"),
        ("gen_efficiency", tb.drivetrain.generator_efficiency, "generator efficiency [-]"),
        ("rated_torque", g.rated_torque, "region 3 torque (constant torque) [N m]"),
        ("region3_constant_power", float(ctl.region3 == "constant_power"),
         "1: constant power above rated, 0: constant torque"),
    ]
    rows += [
        ("min_pitch_speeds", np.array(ctl.min_pitch_speeds, float),
         "minimum-pitch schedule: filtered generator speeds [rad/s]"),
        ("min_pitch_offsets", np.array(ctl.min_pitch_offsets, float),
         "minimum-pitch schedule: pitch above pitch_min [rad]"),
    ]
    return [(prefix + k, v, doc) for k, v, doc in rows]


def law_entries(law: Any) -> list[tuple[str, Any, str]]:
    """A :class:`~mpc_wt.controllers.baseline.LawTorque` (the baseline's torque schedule in
    another controller) as input-file entries.

    Parameters
    ----------
    law : LawTorque
        The torque schedule.

    Returns
    -------
    list of (str, object, str)
        Key, value (a number or an array) and its meaning, in the input file's order.
    """
    return baseline_entries(law.law, "law.") + [
        ("law_torque", np.array([law._a, law._offset, law._lo, law._hi], float),
         "speed filter pole, below-rated pitch offset [rad], torque min, max [N m]")]


def windest_entries(est: Any, prefix: str) -> list[tuple[str, Any, str]]:
    """A :class:`~mpc_wt.controllers.wind_estimator.WindSpeedEstimator` (a schedule's wind)
    as input-file entries: its C_P spline and constants.

    Parameters
    ----------
    est : WindSpeedEstimator
        The estimator.
    prefix : str
        Before every key.

    Returns
    -------
    list of (str, object, str)
        Key, value (a number or an array) and its meaning, in the input file's order.
    """
    tx, ty, c, kx, ky = est._spline
    k = np.concatenate([est._k, [est.settings.speed_std ** 2, 1.0], est.start_torque])
    return [
        (prefix + "spline_degrees", np.array([kx, ky], float), "C_P spline degrees"),
        (prefix + "spline_tx", np.asarray(tx, float), "C_P spline knots in tip-speed ratio"),
        (prefix + "spline_ty", np.asarray(ty, float), "C_P spline knots in pitch [rad]"),
        (prefix + "spline_c", np.asarray(c, float), "C_P spline coefficients"),
        (prefix + "constants", k,
         "radius [m], air density [kg/m^3], gearbox ratio, inertia [kg m^2], dt [s], process "
         "noise of speed and wind, speed noise, wind range [m/s], tip-speed ratio range, "
         "initial variances of speed and wind, the torque schedule of the first step where "
         "no torque is measured (K [N m s^2/rad^2] on the rotor speed, rated torque [N m], "
         "rated rotor speed [rad/s])"),
    ]


def floor_entries(floor: Any, pre: str) -> list[tuple[str, Any, str]]:
    """A schedule's region floor (:class:`~mpc_wt.controllers.scheduling.RegionFloor`) as
    input-file entries.

    Parameters
    ----------
    floor : RegionFloor or None
        The floor (None: none).
    pre : str
        Before every key.

    Returns
    -------
    list of (str, object, str)
        Key, value (a number or an array) and its meaning, in the input file's order.
    """
    if floor is None:
        return [(pre + "region_floor", 0.0, "0: the designs chosen by the measured wind alone")]
    return [(pre + "region_floor", 1.0, "1: at least the design the measured pitch and rotor "
                                        "speed tell"),
            (pre + "floor_winds", np.asarray(floor.winds, float),
             "the trim's pitch curve above rated: winds [m/s]"),
            (pre + "floor_pitches", np.asarray(floor.pitches, float),
             "... and their collective pitch [rad]"),
            (pre + "floor_limits", np.array([floor.pitch_threshold,
                                             floor.pitch_min_speed * floor.rated_speed,
                                             floor.speed_margin * floor.rated_speed,
                                             floor.region3_wind], float),
             "a pitch above [rad] with the rotor above [rad/s]; a rotor speed above [rad/s] "
             "and the design wind then [m/s]")]

"""The controller kinds mpc-wt ships, each one registration.

baseline, baseline-ct, derateNN, apc (Jonkman's baseline and its retrofits, Pettas and Cheng),
ibc and coleman-ipc (add-ons on a baseline), mpc, mpc-collective, mpc-lidar (Madsen et al.),
lqr-pio (Do et al.), ts (Clemens et al.); rosco and discon (Bladed-style libraries in the
loop, :mod:`mpc_wt.controllers.discon`).
"""
from __future__ import annotations

import dataclasses
import logging
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional

import numpy as np

import linearize
from mpc_wt.controllers.ipc import IBC_LOOP_GAIN
from mpc_wt.registry.context import BuildContext, Built
from mpc_wt.registry.options import REQUIRED, Options, option
from mpc_wt.registry.registry import register
from mpc_wt.simulation.scenario import Scenario, start_wind

log = logging.getLogger(__name__)

__all__ = ["BaselineOptions", "DerateOptions", "APCOptions", "IBCOptions", "ColemanIPCOptions",
           "MPCOptions", "MPCWeightOptions", "LidarOptions", "MPCLidarOptions", "LQRPIOOptions", "TSOptions",
           "DisconOptions", "RoscoOptions"]


# -- the shipped laws: a kind that exports runs its compiled C law --------------------------
def _shipped(kind: str, base: str | None = None) -> Any:
    """The ``shipped`` hook of an exportable kind: the design's numbers written to its input
    file, its compiled library (:func:`mpc_wt.io.discon_export.shipped_library`) called through
    the host in this process, every run of the kind then calls the law users run in OpenFAST.
    ``base``: for an add-on, the base its export is made on (another base keeps the Python
    step). A design with options the library does not take (an MPC on OSQP, the sparse
    formulation) keeps its Python step too; the run's metadata says which law ran."""
    def hook(ctx: BuildContext, sel: Any, opts: Any, built: Built) -> Built:
        from mpc_wt.controllers.discon import DisconController
        from mpc_wt.io.discon_export import log_channels, shipped_input, shipped_library

        if base is not None and sel.base.name != base:
            return built
        try:
            infile = shipped_input(built.controller, kind, ctx.turbine, built.preview)
        except ValueError as err:
            log.info("%s: the design does not export (%s); its Python step runs", kind, err)
            return dataclasses.replace(built, meta={**built.meta, "law": "python"})
        dt = float(built.controller.dt)
        ctl = DisconController(shipped_library(kind), infile, ctx.turbine, dt=dt,
                               lidar=built.sensors[-1] if built.sensors else None,
                               isolate=False, log_names=log_channels(kind))
        return dataclasses.replace(built, controller=ctl, controller_dt=dt, preview=None,
                                   design=built.controller,
                                   meta={**built.meta, "law": "shipped",
                                         "library": ctl.library.name})
    return hook


# -- designs behind `mpcwt design` ------------------------------------------------------------
def _design_ibc(turbine: linearize.Turbine, *, power_fraction: float = 1.0,
                loop_gain: float | None = None) -> tuple[dict, str]:
    from mpc_wt.controllers.ipc import tune_ibc
    from mpc_wt.io.gain_tables import ibc_table

    g = tune_ibc(turbine, power_fraction=power_fraction, loop_gain_1p=loop_gain)
    doc = ibc_table(turbine, g)
    doc["settings"]["options"] = {"loop_gain_1p": float(g.info["target_loop_gain_1p"])}
    return doc, (f"{g.gain.size} points, gain margin >= "
                                   f"{g.gain_margin.min():.3g}, high-pass {g.highpass_hz:.3g} Hz")


def _design_coleman(turbine: linearize.Turbine, *, power_fraction: float = 1.0
                    ) -> tuple[dict, str]:
    from mpc_wt.controllers.ipc import tune_coleman_ipc
    from mpc_wt.io.gain_tables import coleman_ipc_table

    g = tune_coleman_ipc(turbine, power_fraction=power_fraction)
    return coleman_ipc_table(turbine, g), (f"{g.ki.size} points, gain margin >= "
                                           f"{g.gain_margin.min():.3g}")


def _design_lqr(turbine: linearize.Turbine, *, winds: Any = None,
                weights: dict[str, float] | None = None, scales: dict[str, float] | None = None,
                observer_q: float = 1e3, input_weights: dict[str, float] | None = None
                ) -> tuple[dict, str]:
    from mpc_wt.controllers.lqr import (
        REGION2_SCALES,
        REGION3_SCALES,
        REGION3_WEIGHTS,
        design_lqr_family,
        design_pi_observer,
    )
    from mpc_wt.io.gain_tables import lqr_table

    winds = np.arange(12.0, 25.5, 1.0) if winds is None else np.asarray(winds, float)
    fam = linearize.linearize_family(turbine, winds, config=linearize.PlantConfig.do(),
                                     progress=True)
    weights = dict(weights or REGION3_WEIGHTS)
    scales = {**REGION2_SCALES, **REGION3_SCALES, **(scales or {})}
    sw = {k: v for k, v in weights.items() if k in fam.models[0].states}
    ow = {k: v for k, v in weights.items() if k not in sw}
    designs = design_lqr_family(fam, state_weights=sw, output_weights=ow, scales=scales,
                                input_weights=input_weights)
    obs = [design_pi_observer(m, q=observer_q) for m in fam.models] if observer_q > 0 else None
    note = f"{len(designs)} operating points"
    if obs:
        note += (f", PIO ||L2||/||L1|| {min(o.gain_ratio for o in obs):.3g}.."
                 f"{max(o.gain_ratio for o in obs):.3g}")
    return lqr_table(turbine, designs, obs), note


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


def _baseline(region3: str) -> Any:
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


def _derated_trim(turbine: linearize.Turbine, sc: Scenario, opts: DerateOptions
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
    from mpc_wt.io.gain_tables import baseline_table

    doc = baseline_table(turbine, tune_baseline(turbine, omega_n_rad_s=omega_n_rad_s, zeta=zeta,
                                                power_fraction=power_fraction))
    return doc, f"kp {doc['settings']['kp']:.4g} s, ki {doc['settings']['ki']:.4g}"


register("baseline", BaselineOptions, field_components="u", design=_design_baseline,
         shipped=_shipped("baseline"), summary="tuned PI pitch and torque law, constant power in region III (80 Hz)"
         )(_baseline("constant_power"))
register("baseline-ct", BaselineOptions, field_components="u",
         shipped=_shipped("baseline-ct"), summary="the baseline with constant torque in region III (Do et al.'s PI)"
         )(_baseline("constant_torque"))
register("derate", DerateOptions, field_components="u", pattern=r"derate(\d+(?:\.\d+)?)",
         pattern_options=_derate_preset, pattern_help="derateNN (NN % of rated power)",
         operating_point=_derated_trim,
         summary="the baseline derated to NN % of rated power, PI re-tuned")(
    _baseline("constant_power"))


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


@register("ibc", IBCOptions, field_components="u", addon_to=("baseline", "derate"),
          default_base="baseline", design=_design_ibc, shipped=_shipped("ibc", "baseline"),
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


@register("coleman-ipc", ColemanIPCOptions, field_components="u", addon_to=("baseline", "derate"),
          default_base="baseline", design=_design_coleman,
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


# -- MPC -----------------------------------------------------------------------------------
_MW = "weight of the MPC cost on the scaled signal (unset: mpc_wt.MPCWeights' default)"


@dataclass(frozen=True)
class MPCWeightOptions(Options):
    """Weights of Madsen's MPC cost (:class:`mpc_wt.MPCWeights`); unset ones keep the default.
    Outputs are divided by their scales (0.5 MW, 1 deg/s, 0.1 m/s, 0.05 rad/s, 1 mrad, 1 MN m)
    and inputs by theirs (1 deg, 4 kN m) before weighting."""

    gen_power: Optional[float] = option(None, help=_MW, unit="-", lo=0.0)
    pitch_rate: Optional[float] = option(None, help=_MW, unit="-", lo=0.0)
    tower_fa_velocity: Optional[float] = option(None, help=_MW, unit="-", lo=0.0)
    rotor_speed: Optional[float] = option(None, help=_MW, unit="-", lo=0.0)
    shaft_torsion: Optional[float] = option(None, help=_MW, unit="-", lo=0.0)
    flap_moment: Optional[float] = option(None, help=_MW + "; Coleman-weighted", unit="-",
                                          lo=0.0)
    pitch_ref: Optional[float] = option(None, help="input " + _MW, unit="-", lo=0.0)
    gen_torque_ref: Optional[float] = option(None, help="input " + _MW, unit="-", lo=0.0)
    pitch_ref_rate: Optional[float] = option(None, help="the pitch input's change per step "
                                             + _MW, unit="-", lo=0.0)
    gen_torque_ref_rate: Optional[float] = option(None, help="the torque input's change per "
                                                  "step " + _MW, unit="-", lo=0.0)

    def weights(self, defaults: dict[str, float] | None = None) -> Any:
        """The cost weights.

        Parameters
        ----------
        defaults : dict, optional
            Output weights in place of :class:`mpc_wt.MPCWeights`' defaults where no option
            is set (the scheduled designs' tuned ones, :data:`ENVELOPE_WEIGHTS`).

        Returns
        -------
        MPCWeights
            :class:`mpc_wt.MPCWeights` with the set options in place of its defaults.
        """
        from mpc_wt.controllers.mpc import MPCWeights

        return self.over(_placed(MPCWeights(), defaults or {}))

    def over(self, weights: Any) -> Any:
        """``weights`` with the set options in place of theirs.

        Parameters
        ----------
        weights : MPCWeights

        Returns
        -------
        MPCWeights
        """
        return _placed(weights, {k: v for k, v in self.to_dict().items() if v is not None})


def _placed(weights: Any, given: dict[str, float]) -> Any:
    """``weights`` (MPCWeights) with ``given`` in place: option names of inputs and input
    rates (``*_rate``) to theirs, the others to the outputs'."""
    given = dict(given)
    ins = {k: given.pop(k) for k in ("pitch_ref", "gen_torque_ref") if k in given}
    rate = {k[:-5]: given.pop(k) for k in ("pitch_ref_rate", "gen_torque_ref_rate")
            if k in given}
    return dataclasses.replace(weights, outputs={**weights.outputs, **given},
                               inputs={**weights.inputs, **ins}, rate={**weights.rate, **rate})


@dataclass(frozen=True)
class MPCOptions(Options):
    """Madsen et al.'s MPC at 10 Hz (:class:`mpc_wt.MPCSettings` holds the full set)."""

    backend: Optional[str] = option(None, help="QP solver (default DAQP when installed, else "
                                    "OSQP)", choices=(None, "osqp", "daqp"))
    formulation: str = option("condensed", help="QP formulation (sparse: OSQP only)",
                              choices=("condensed", "sparse"))
    horizon: int = option(15, help="H_p = H_u", lo=1, hi=200)
    estimator: str = option("kalman", help="kalman: states and blade winds estimated from "
                            "measured signals (rotor and generator speed, pitch, flap moments, "
                            "tower-top acceleration); full-state: the plant's true states, an "
                            "idealization no turbine has (labelled so in results)",
                            choices=("kalman", "full-state"))
    design_wind_mps: Optional[float] = option(None, help="one design at this mean wind "
                                              "(Madsen's single-point design); default: "
                                              "designs from cut-in to cut-out scheduled on the "
                                              "measured wind", unit="m/s", lo=0.0,
                                              lo_open=True)
    schedule_step: float = option(1.0, help="spacing of the scheduled designs' grid",
                                  unit="m/s", lo=0.1, hi=5.0, flag="")
    kalman_wind_std: float = option(0.118, help="the Kalman estimator's random walk of each "
                                    "blade wind per step (larger follows gusts faster and "
                                    "passes more noise into the pitch)", unit="m/s", lo=0.0,
                                    lo_open=True, flag="")
    kalman_flap_std: float = option(4.2e5, help="the Kalman estimator's flap-moment "
                                    "measurement noise (default tuned with the scheduled "
                                    "design)", unit="N m", lo=0.0, lo_open=True,
                                    flag="")
    schedule_time_constant: float = option(3.0, help="low-pass of the scheduling wind "
                                           "(the designs switch at 0.25 m/s past the midpoint "
                                           "between grid winds)", unit="s", lo=0.0, hi=600.0,
                                           flag="")
    speed_limit: Optional[float] = option(None, help="soft upper limit of the predicted rotor "
                                          "speed, a fraction of rated (default 1.065 for the "
                                          "scheduled designs, none for design_wind_mps)",
                                          unit="-", lo=0.5, hi=2.0)
    torque_limit: Optional[float] = option(
        None, help="the QP's upper bound on the generator torque, a fraction of rated torque "
        "(default: the generator's maximum)", unit="-", lo=0.5, hi=2.0, flag="")
    below_rated_speed_limit: Optional[float] = option(
        None, help="the scheduled designs' soft rotor-speed limit below rated wind, a fraction "
        "of rated (default speed_limit when that is given, else 1.065)", unit="-", lo=0.5,
        hi=2.0, flag="")
    weights: MPCWeightOptions = option(MPCWeightOptions(), help="cost weights (gen_power, "
                                       "flap_moment, rotor_speed, ...)", flag="")
    below_rated_weights: MPCWeightOptions = option(
        MPCWeightOptions(), help="the scheduled designs' weights below rated wind where they "
        "differ from weights (default: weights without the flap moment's, and those of "
        "BELOW_RATED_WEIGHTS)", flag="")
    time_budget_ms: Optional[float] = option(None, help="wall time a QP may take; a slower "
                                             "solve takes the logged fallback (default none: "
                                             "reproducible runs, the solver's iteration limit "
                                             "is the budget)", unit="ms", lo=0.0, lo_open=True)
    torque_notch_hz: Optional[float] = option(
        None, help="centre of the scheduled designs' notch on the generator-torque command "
        "(default: the drivetrain torsion mode of the turbine's full linearization at rated "
        "wind, when below 0.8 x the controller's Nyquist frequency; 0: no notch)", unit="Hz",
        lo=0.0, flag="")
    torque_notch_q: float = option(2.0, help="the torque notch's quality factor (bandwidth = "
                                   "centre / Q)", unit="-", lo=0.0, lo_open=True, flag="")
    tower_notch: bool = option(False, help="a second notch on the scheduled designs' "
                               "generator-torque command at the tower's first side-side mode "
                               "(the designs' models have no side-side freedom; the torque's "
                               "reaction drives it), when below 0.8 x the controller's Nyquist "
                               "frequency", flag="")
    region_floor: bool = option(True, help="the scheduled designs are chosen also by the "
                                "operating region the measurements tell: at least the design "
                                "whose trim has the measured collective pitch, and one inside "
                                "region 3 while the rotor runs above rated speed (false: by "
                                "the measured wind alone)", flag="")
    region3_pitch_deg: float = option(2.0, help="the first scheduled design above rated wind "
                                      "is made where the trim's pitch is this far above fine "
                                      "pitch (0: at rated wind, where the torque is flat in "
                                      "pitch)", unit="deg", lo=0.0, hi=10.0, flag="")


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


@dataclass(frozen=True)
class MPCLidarOptions(MPCOptions):
    """The MPC with a CW LIDAR's per-blade preview."""

    lidar: LidarOptions = option(LidarOptions(), help="CW LIDAR settings (focus_distance, "
                                 "noise_std, ...)", flag="")


#: The scheduled MPC designs' weights where the options set none: tuned with
#: ``benchmarks/studies/tune_mpc_envelope.yaml`` (mpc-lidar at 9, 13 and 18 m/s, class A,
#: seed 1; held-out seeds 3-4: power -0.2 %, pitch travel 2.6x and the largest rotor speed
#: +1.0 % against the baseline). Madsen's single-point design keeps the paper's.
ENVELOPE_WEIGHTS = {"pitch_rate": 0.0235, "flap_moment": 0.1024}
#: The scheduled designs' weights without a preview, on the Kalman estimator: no flap moment's
#: (no cyclic pitch). The blade winds the estimator infers from the root moments come late
#: for the 1P load: with the flap weight of ENVELOPE_WEIGHTS the MPC without preview moved
#: the pitch twice as far for a higher flap DEL and 16 % more shaft bending at 18-21 m/s than
#: without it (class A, seeds 12-13; ``weights.flap_moment`` turns it back on).
NO_PREVIEW_WEIGHTS = {"flap_moment": 0.0}
#: The scheduled designs' weights below rated wind in place of theirs above: no flap
#: moment's (the pitch rests at fine pitch there), and a weight on the torque's change per
#: step (the designs track the optimal tip-speed ratio with the torque, which moved it 10x as
#: much as the baseline's torque law at 0.2-1 Hz, where the tower's modes are: on `mpc-lidar`
#: at 5-13 m/s, class A, seeds 11-12, the tower fore-aft DEL against the baseline's +3.1 ->
#: -1.7 %, side-side +25.6 -> +20.5 %, power +0.7 -> +0.8 %).
BELOW_RATED_WEIGHTS = {"flap_moment": 0.0, "gen_torque_ref_rate": 10.0}
#: The soft rotor-speed limit of the scheduled designs below rated wind (a fraction of rated).
BELOW_RATED_SPEED_LIMIT = 1.065
#: The scheduled designs' soft rotor-speed limit (a fraction of rated). With the exact
#: penalty the limit acts as a hard one: the MPC brakes at it with the torque at its maximum
#: and a fast pitch pulse, which loads the tower; 1.028 (tuned before the region floor) had it
#: binding in most gusts near rated (tower fore-aft DEL +36 % against the baseline at 11 m/s).
ENVELOPE_SPEED_LIMIT = 1.065


def _mpc_settings(opts: MPCOptions, collective: bool, preview: bool) -> Any:
    from mpc_wt.controllers.mpc import MPCSettings

    defaults = None
    if opts.design_wind_mps is None:
        defaults = dict(ENVELOPE_WEIGHTS)
        if not preview and not collective and opts.estimator == "kalman":
            defaults.update(NO_PREVIEW_WEIGHTS)
    return MPCSettings(horizon=opts.horizon, backend=opts.backend,
                       formulation=opts.formulation,
                       estimator=None if opts.estimator == "full-state" else opts.estimator,
                       estimator_settings={
                           "wind_std_per_step": opts.kalman_wind_std,
                           "measurement_std": {f"flap_moment_{b}": opts.kalman_flap_std
                                               for b in (1, 2, 3)}},
                       collective=collective, weights=opts.weights.weights(defaults),
                       time_budget_ms=opts.time_budget_ms)


#: The result label of a design that reads the plant's true states.
FULL_STATE = "full-state information (idealization)"


def _envelope_family(ctx: BuildContext, config: str, step: float,
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


def _wind_estimator(ctx: BuildContext, dt: float) -> Any:
    """A wind estimator at ``dt`` on the turbine's C_P table (which
    :func:`linearize.rotor_performance` keeps for the process)."""
    from mpc_wt.controllers.wind_estimator import WindSpeedEstimator

    return WindSpeedEstimator(ctx.turbine, dt)


def _check_design_wind(turbine: linearize.Turbine, v: float) -> float:
    op = turbine.operation
    if not op.cut_in_wind <= v <= op.cut_out_wind:
        raise ValueError(f"design_wind_mps = {v:g} m/s is outside the turbine's operating range "
                         f"{op.cut_in_wind:g}..{op.cut_out_wind:g} m/s")
    return float(v)


#: The default torque notch is left out when the drivetrain mode lies above this fraction of
#: the controller's Nyquist frequency (a stiff or direct drive: the designs' commands do not
#: reach it).
NOTCH_NYQUIST_SHARE = 0.8


def _torque_notch(ctx: BuildContext, opts: MPCOptions, dt: float) -> Optional[float]:
    """The scheduled MPC's torque-notch centre [Hz] from the options (None: no notch)."""
    from mpc_wt.controllers.mpc import drivetrain_frequency

    nyquist = 0.5 / dt
    f = opts.torque_notch_hz
    if f is not None:
        if f == 0.0:
            return None
        if f >= nyquist:
            raise ValueError(f"torque_notch_hz = {f:g} Hz must be below the controller's "
                             f"Nyquist frequency {nyquist:g} Hz (0: no notch)")
        return float(f)
    try:
        f = ctx.cache.get(ctx.turbine, ("drivetrain-mode",),
                          lambda: drivetrain_frequency(ctx.turbine))
    except ValueError as err:
        log.info("MPC: no torque notch (%s)", err)
        return None
    if f >= NOTCH_NYQUIST_SHARE * nyquist:
        log.info("MPC: no torque notch: the drivetrain mode at %.3g Hz is above %g x the "
                 "controller's Nyquist frequency %g Hz", f, NOTCH_NYQUIST_SHARE, nyquist)
        return None
    return float(f)


def _tower_notch(ctx: BuildContext, opts: MPCOptions, dt: float) -> Optional[float]:
    """The scheduled MPC's second torque notch [Hz]: the plant's first tower side-side mode
    (None: switched off, or above :data:`NOTCH_NYQUIST_SHARE` x the Nyquist frequency)."""
    if not opts.tower_notch:
        return None
    f = ctx.cache.get(ctx.turbine, ("tower-ss-mode",), lambda: float(
        linearize.structural_frequencies(linearize.plant_params(ctx.turbine))["tower_ss"]))
    if not f < NOTCH_NYQUIST_SHARE * 0.5 / dt:
        log.info("MPC: no tower notch: the side-side mode at %.3g Hz is above %g x the "
                 "controller's Nyquist frequency %g Hz", f, NOTCH_NYQUIST_SHARE, 0.5 / dt)
        return None
    return f


def _below_rated(ctx: BuildContext, opts: MPCOptions, settings: Any) -> Any:
    """The scheduled designs' settings below rated wind: their weights
    (:data:`BELOW_RATED_WEIGHTS` and the options' ``below_rated_weights`` over the others) and
    soft speed limit (``below_rated_speed_limit``, default :data:`BELOW_RATED_SPEED_LIMIT`)."""
    weights = opts.below_rated_weights.over(MPCWeightOptions(**BELOW_RATED_WEIGHTS).over(
        settings.weights))
    limit = opts.below_rated_speed_limit
    if limit is None:
        limit = BELOW_RATED_SPEED_LIMIT if opts.speed_limit is None else opts.speed_limit
    return settings.replace(weights=weights, max_rotor_speed=limit
                            * ctx.turbine.operation.rated_rotor_speed_rad_s)


def _mpc(collective: bool, with_lidar: bool) -> Any:
    def build(ctx: BuildContext, opts: MPCOptions) -> Built:
        from mpc_wt.controllers.mpc import MPC, ScheduledMPC

        settings = _mpc_settings(opts, collective, with_lidar)
        settings = settings.replace(weights=settings.weights.for_turbine(ctx.turbine))
        limit = opts.speed_limit
        if limit is None and opts.design_wind_mps is None:
            limit = ENVELOPE_SPEED_LIMIT
        if limit is not None:
            settings = settings.replace(
                max_rotor_speed=limit * ctx.turbine.operation.rated_rotor_speed_rad_s)
        if opts.torque_limit is not None:
            settings = settings.replace(max_torque=opts.torque_limit
                                        * ctx.turbine.rated_generator_torque)
        if opts.design_wind_mps is None:
            fam = _envelope_family(ctx, "madsen", opts.schedule_step, opts.region3_pitch_deg)
            from mpc_wt.controllers.baseline import BaselineController, tune_baseline

            law = BaselineController(ctx.turbine, ctx.cache.get(
                ctx.turbine, ("baseline-gains",), lambda: tune_baseline(ctx.turbine)))
            ctl = ScheduledMPC(fam, ctx.turbine, settings,
                               wind_source="preview" if with_lidar else "estimator",
                               wind_estimator=_wind_estimator(ctx, settings.dt),
                               time_constant=opts.schedule_time_constant,
                               torque_law=law, below_rated=_below_rated(ctx, opts, settings),
                               torque_notch_hz=_torque_notch(ctx, opts, settings.dt),
                               torque_notch_q=opts.torque_notch_q,
                               tower_notch_hz=_tower_notch(ctx, opts, settings.dt),
                               region_floor=opts.region_floor)
            grid = [float(fam.wind_mps[0]), float(fam.wind_mps[-1])]
        else:
            v = _check_design_wind(ctx.turbine, opts.design_wind_mps)
            model = linearize.linearize(ctx.turbine, v, config=linearize.PlantConfig.madsen())
            ctl = MPC(model, ctx.turbine, settings)
            grid = [v, v]
        cdt = ctl.dt
        meta: dict[str, Any] = {"mpc": {
            "horizon": settings.horizon, "backend": settings.resolved_backend, "dt": cdt,
            "formulation": settings.formulation, "estimator": opts.estimator,
            "design_winds_mps": grid, "schedule_step_mps": opts.schedule_step,
            "torque_notch_hz": getattr(ctl, "torque_notch_hz", None),
            **({"idealization": FULL_STATE} if opts.estimator == "full-state" else {})}}
        preview = None
        if with_lidar:
            from mpc_wt.simulation.preview import LidarPreview

            lidar_opts = opts.lidar  # type: ignore[attr-defined]
            sensor = ctx.lidar(lidar_opts.instrument(ctx.turbine), lidar_opts.evolution)
            preview = LidarPreview(sensor, settings.horizon, cdt)
            meta["lidar"] = {**lidar_opts.given(), "evolution": lidar_opts.evolution}
        return Built(ctl, cdt, preview, meta)
    return build


def _design_mpc(collective: bool, with_lidar: bool = False) -> Any:
    """The design function of a scheduled MPC kind: its design with the default options, as a
    table of its grid points (``mpcwt design mpc``; ``mpcwt export --format discon`` builds it
    again from the table's options)."""
    kind = "mpc-lidar" if with_lidar else "mpc-collective" if collective else "mpc"

    def design(turbine: linearize.Turbine) -> tuple[dict, str]:
        from mpc_wt.io.gain_tables import mpc_table
        from mpc_wt.registry.context import DEFAULT_CACHE

        ctx = BuildContext(turbine=turbine, params=linearize.plant_params(turbine),
                           cache=DEFAULT_CACHE)
        opts = MPCLidarOptions() if with_lidar else MPCOptions()
        ctl = _mpc(collective, with_lidar)(ctx, opts).controller
        doc = mpc_table(turbine, ctl, kind, options={})
        n = len(doc["schedule"]["rows"])
        return doc, f"{n} grid winds {doc['schedule']['rows'][0][0]:g}-" \
                    f"{doc['schedule']['rows'][-1][0]:g} m/s, horizon {ctl.settings.horizon}"
    return design


_MPC_GROUP = "the MPC controllers"
register("mpc", MPCOptions, field_components="u", group=_MPC_GROUP, design=_design_mpc(False),
         shipped=_shipped("mpc"),
         summary="Madsen's Coleman-weighted individual-pitch MPC, scheduled from cut-in to "
                 "cut-out on the estimated wind, Kalman estimator (without a preview no cyclic "
                 "pitch unless weights.flap_moment is set)"
         )(_mpc(False, False))
register("mpc-collective", MPCOptions, field_components="u", group=_MPC_GROUP,
         design=_design_mpc(True), shipped=_shipped("mpc-collective"),
         summary="the scheduled MPC with one collective pitch input")(_mpc(True, False))
register("mpc-lidar", MPCLidarOptions, field_components="u", group=_MPC_GROUP,
         design=_design_mpc(False, True), shipped=_shipped("mpc-lidar"), summary="the individual-pitch MPC with a CW LIDAR's per-blade preview "
                 "(range weighting, LOS error and wind evolution on)")(_mpc(False, True))


@dataclass(frozen=True)
class TorqueLawOptions(Options):
    """The torque-law guard in lulls (:class:`mpc_wt.controllers.supervisor.TorqueLawGuard`)."""

    fine_band_deg: float = option(1.0, help="pitch above fine within which the guard acts",
                                  unit="deg", lo=0.0, flag="")


@register("torque-law", TorqueLawOptions, field_components="u",
          addon_to=("mpc", "mpc-lidar", "mpc-collective"), default_base="mpc",
          group=_MPC_GROUP, summary="caps the MPC's torque at the baseline's torque-speed law "
                                    "at fine pitch below rated speed (mpc+torque-law, "
                                    "mpc-lidar+torque-law)")
def _build_torque_law(ctx: BuildContext, opts: TorqueLawOptions, base: Built) -> Built:
    from mpc_wt.controllers.supervisor import TorqueLawGuard

    ctl = TorqueLawGuard(base.controller, ctx.turbine,
                         fine_band=math.radians(opts.fine_band_deg))
    return Built(ctl, base.controller_dt, base.preview,
                 {**base.meta, "torque_law": opts.to_dict()}, base.power_fraction)


# -- LQR + PI observer ------------------------------------------------------------------------
#: The scheduled LQR-PIO's region-III rotor-speed weight where the options set none (Do et al.'s
#: designs keep 5, ``mpc_wt.controllers.lqr.REGION3_WEIGHTS``): with the PI observer's q = 100,
#: 5 let a gust at the start of a 25 m/s case (seed 1) take the rotor to 1.251 x rated in 2.3 s
#: and trip the protection; 10 holds it to 1.236 x (the baseline's: 1.235 x) for the same pitch
#: travel within 3 %.
LQR_REGION3_ROTOR_SPEED_WEIGHT = 10.0


#: The scheduled LQR's weight on each blade's pitch rate, on the scale of the pitch drives'
#: largest rate (0.1 on (rate / 1 deg/s)^2 on the IEA-15-240-RWT's 2 deg/s drives, 0.006 on
#: the NREL 5-MW's 8 deg/s). On the IEA-15, class B, seeds 11-12 (not the sign-off's), 5-25
#: m/s, 600 s, against the baseline: the pitch travel 3.29x -> 2.83x, the shaft's lifetime
#: bending DEL +1.4 -> +3.2 % (the rate weight at 0.5 and 2 on the 1 deg/s scale: 2.42x and
#: 2.11x, +6.8 % and +13.0 %).
LQR_PITCH_RATE_WEIGHT = 0.4


@dataclass(frozen=True)
class LQRPIOOptions(Options):
    """Do et al.'s LQR on PI-observer estimates."""

    observer_q: float = option(1e2, help="PI observer q of Q_obs = diag(I, q I) (100: "
                               "1000 made the pitch travel 5.7x the baseline's in "
                               "turbulence, 100 about 2x with the speed held as well)",
                               unit="-", lo=0.0, lo_open=True, flag="")
    w_rotor_speed: Optional[float] = option(None, help="LQR weight on the rotor speed (scale "
                                            "0.05 rad/s; default 0 in region II, in III 10 "
                                            "over the square root of the pitch drives' rate "
                                            "over 8 deg/s (5 with design_wind_mps))",
                                            unit="-", lo=0.0)
    w_tower_fa_velocity: Optional[float] = option(None, help="LQR weight on the tower-top "
                                                  "fore-aft velocity (scale 0.1 m/s; default 1 "
                                                  "x the pitch drives' rate over 8 deg/s (1 "
                                                  "with design_wind_mps))",
                                                  unit="-", lo=0.0)
    w_flap_rate: Optional[float] = option(None, help="LQR weight on each blade's flap tip rate "
                                          "(scale 1 m/s; default 0 in region III, 0.2 in II)",
                                          unit="-", lo=0.0)
    w_pitch: float = option(1.0, help="LQR input weight on each blade's pitch (scale 1 deg "
                            "x the square root of the pitch drives' rate over 8 deg/s)",
                            unit="-", lo=0.0, lo_open=True)
    w_pitch_rate: Optional[float] = option(None, help="LQR weight on each blade's pitch "
                                           "rate, the output (pitch_ref - pitch) / tau of the "
                                           "servo model (scale: the pitch drives' largest "
                                           "rate; default 0.4, 0 with design_wind_mps)",
                                           unit="-", lo=0.0)
    design_wind_mps: Optional[float] = option(None, help="one design at this mean wind (Do et "
                                              "al.'s single point); default: designs from "
                                              "cut-in to cut-out scheduled on the measured "
                                              "wind", unit="m/s", lo=0.0, lo_open=True)
    schedule_step: float = option(1.0, help="spacing of the scheduled designs' grid",
                                  unit="m/s", lo=0.1, hi=5.0, flag="")
    schedule_time_constant: float = option(3.0, help="low-pass of the scheduling wind",
                                           unit="s", lo=0.0, hi=600.0, flag="")
    observer_signals: str = option("turbine", help="the PI observer's measurements: turbine "
                                   "(generator speed, tower-top fore-aft acceleration, blade "
                                   "root out-of-plane moments, as a turbine's controller gets "
                                   "them; exportable) or paper (Do et al.'s tower-top and flap "
                                   "displacements)", choices=("turbine", "paper"))
    region2_torque: str = option("baseline", help="region-II torque: the baseline's schedule "
                                 "(1.5/2/2.5 on filtered speed, as the PI it is compared with) "
                                 "or Do's bare K_opt Omega_g^2 on raw speed",
                                 choices=("baseline", "k_opt"))

    def lqr_weights(self, region: str, turbine: linearize.Turbine | None = None
                    ) -> tuple[dict[str, float], dict[str, float]]:
        """The state weights and input weights of the design in ``region``: the region's
        defaults (:data:`mpc_wt.controllers.lqr.REGION3_WEIGHTS`, ``REGION2_WEIGHTS``) with the
        options that are set in their place.

        Parameters
        ----------
        region : {"II", "III"}
        turbine : Turbine, optional
            The scheduled designs' defaults follow its pitch drives
            (:data:`LQR_DRIVE_SPEED_EXPONENT`, :data:`LQR_DRIVE_TOWER_EXPONENT`); without it,
            the NREL 5-MW's.

        Returns
        -------
        state_weights, input_weights : dict of str to float
            For :func:`mpc_wt.controllers.lqr.design_lqr` (zero weights left out; the
            weights on the pitch rates come from :meth:`output_weights`).
        """
        from mpc_wt.controllers.lqr import REGION2_WEIGHTS, REGION3_WEIGHTS
        from mpc_wt.controllers.mpc import pitch_drive_scale_ratio

        w = dict(REGION3_WEIGHTS if region == "III" else REGION2_WEIGHTS)
        if self.design_wind_mps is None and turbine is not None:   # slower drives
            w["tower_fa_velocity"] *= pitch_drive_scale_ratio(turbine, LQR_DRIVE_TOWER_EXPONENT)
        if region == "III" and self.design_wind_mps is None:    # the scheduled designs
            w["rotor_speed"] = LQR_REGION3_ROTOR_SPEED_WEIGHT
            if turbine is not None:
                w["rotor_speed"] /= pitch_drive_scale_ratio(turbine, LQR_DRIVE_SPEED_EXPONENT)
        for name, val in (("rotor_speed", self.w_rotor_speed),
                          ("tower_fa_velocity", self.w_tower_fa_velocity)):
            if val is not None:
                w[name] = val
        if self.w_flap_rate is not None:
            w.update({f"flap_rate_{i}": self.w_flap_rate for i in (1, 2, 3)})
        return ({k: v for k, v in w.items() if v > 0},
                {f"pitch_ref_{i}": self.w_pitch for i in (1, 2, 3)})

    def output_weights(self) -> dict[str, float]:
        """The weights on the model's outputs: each blade's pitch rate, on the scale of the
        drives' largest rate (``w_pitch_rate``; unset, :data:`LQR_PITCH_RATE_WEIGHT` for the
        scheduled designs and none for Do et al.'s single point); none when it is 0.

        Returns
        -------
        dict of str to float
            For :func:`mpc_wt.controllers.lqr.design_lqr`'s ``output_weights``.
        """
        w = self.w_pitch_rate
        if w is None:
            w = LQR_PITCH_RATE_WEIGHT if self.design_wind_mps is None else 0.0
        return {f"pitch_rate_{i}": w for i in (1, 2, 3)} if w > 0 else {}


def _design_lqr_pio(turbine: linearize.Turbine) -> tuple[dict, str]:
    """The scheduled LQR-PIO with the default options, as a table of its designs from cut-in
    to cut-out (``mpcwt design lqr-pio``; ``mpcwt export --format discon`` builds it again from
    the table's options)."""
    from mpc_wt.io.gain_tables import lqr_pio_table
    from mpc_wt.registry.context import DEFAULT_CACHE

    ctx = BuildContext(turbine=turbine, params=linearize.plant_params(turbine),
                       cache=DEFAULT_CACHE)
    ctl = _build_lqr_pio(ctx, LQRPIOOptions()).controller
    doc = lqr_pio_table(turbine, ctl, "lqr-pio", options={})
    w = ctl.winds
    return doc, (f"{w.size} designs {w[0]:g}-{w[-1]:g} m/s observing "
                 f"{', '.join(ctl.controllers[0].obs.measured)}")


@register("lqr-pio", LQRPIOOptions, field_components="u", design=_design_lqr,
          shipped=_shipped("lqr-pio"),
          design_name="lqr", more_designs=(("lqr-pio", _design_lqr_pio),),
          summary="Do et al.'s LQR with a PI observer, scheduled from cut-in to cut-out on the "
                  "estimated wind (region II below rated, III above)")
def _build_lqr_pio(ctx: BuildContext, opts: LQRPIOOptions) -> Built:
    from mpc_wt.controllers.baseline import tune_baseline
    from mpc_wt.controllers.lqr import ScheduledLQRPIO

    turbine = ctx.turbine
    if opts.design_wind_mps is not None:
        v = _check_design_wind(turbine, opts.design_wind_mps)
        ctl: Any = _lqr_pio_at(turbine, linearize.linearize(turbine, v,
                                                            config=linearize.PlantConfig.do()),
                               v, opts, tune_baseline(turbine))
        winds = [v]
    else:
        fam = _envelope_family(ctx, "do", opts.schedule_step)
        winds = [float(w) for w in fam.wind_mps]
        base = tune_baseline(turbine)
        ctl = ScheduledLQRPIO([_lqr_pio_at(turbine, m, w, opts, base, stall_guard=True)
                               for m, w in zip(fam.models, winds)], winds, turbine,
                              time_constant=opts.schedule_time_constant,
                              wind_estimator=_wind_estimator(ctx, 1.0 / 80.0))
    rated = linearize.rated_wind_speed(turbine)
    return Built(ctl, meta={"lqr": {
        "weights": {r: {**dict(zip(("state", "input"),
                                   opts.lqr_weights(r, None if opts.design_wind_mps
                                                    else turbine))),
                        "output": opts.output_weights()} for r in ("II", "III")},
        "observer_q": opts.observer_q, "design_winds_mps": [winds[0], winds[-1]],
        "regions": "II below, III above " + f"{rated:.2f} m/s"}})


#: The scheduled LQR's pitch scale goes with the pitch drives' largest rate to this power
#: (:func:`mpc_wt.controllers.mpc.pitch_drive_scale_ratio`): 0.5 deg on the IEA-15-240-RWT
#: (2 deg/s), 1 deg on the NREL 5-MW. On the IEA-15, seeds 11-12 of class B (not the
#: sign-off's), the weight x 1 / 2 / 4 gave 4.56x / 3.34x / 2.86x the baseline's pitch travel;
#: in the sign-off's IEA-15 subset x 1 / 4 / 8 gave 4.94x / 3.50x / 3.34x, the largest rotor
#: speed 1.160 / 1.165 / 1.199 x rated.
LQR_PITCH_SCALE_EXPONENT = 0.5
#: The scheduled LQR's default weights follow the pitch drives too: the region-III rotor-speed
#: weight divided by (rate / 8 deg/s) to this power (x 2 on the IEA-15), so that the dearer
#: pitch still holds the speed, and the tower fore-aft velocity's weight times it to this
#: power (x 0.25 on the IEA-15): the tower damping the pitch adds costs slow drives most. On
#: the IEA-15, class B, seeds 11-12 (not the sign-off's), 5-25 m/s: the pitch travel against
#: the baseline's 3.06x -> 2.86x, the largest rotor speed 1.145 -> 1.132 x rated, the tower
#: fore-aft lifetime DEL -7.9 -> -4.8 % against the baseline's; the tower weight alone at
#: x 0.25 gave 2.64x and 1.144 x rated.
LQR_DRIVE_SPEED_EXPONENT = 0.5
LQR_DRIVE_TOWER_EXPONENT = 1.0


def _lqr_pio_at(turbine: linearize.Turbine, model: linearize.LinearModel, wind: float,
                opts: LQRPIOOptions, base: Any, stall_guard: bool = False) -> Any:
    """Do et al.'s LQR-PIO at one grid wind: region II below the rated wind, III above (the
    baseline's gains ``base`` give region II's torque law; with ``stall_guard`` region III's
    constant torque is capped by that law, as a scheduled design needs in lulls)."""
    from mpc_wt.controllers.baseline import BaselineController
    from mpc_wt.controllers.lqr import (
        PAPER_MEASURED,
        REGION2_SCALES,
        REGION3_SCALES,
        TURBINE_MEASURED,
        LQRPIOController,
        design_lqr,
        design_pi_observer,
        turbine_scales,
    )

    from mpc_wt.controllers.mpc import pitch_drive_scale_ratio

    region = "II" if wind < linearize.rated_wind_speed(turbine) else "III"
    w, iw = opts.lqr_weights(region, turbine)
    scales = {**REGION2_SCALES, **REGION3_SCALES}
    r = pitch_drive_scale_ratio(turbine, LQR_PITCH_SCALE_EXPONENT)   # slower drives: dearer
    scales.update({k: v * r for k, v in scales.items() if k.startswith("pitch_ref_")})
    scales.update({f"pitch_rate_{i}": turbine.pitch_actuator.max_rate_rad_s for i in (1, 2, 3)})
    lq = design_lqr(model, state_weights=w, output_weights=opts.output_weights(),
                    input_weights=iw, scales=scales)
    if opts.observer_signals == "turbine":
        obs = design_pi_observer(model, q=opts.observer_q, measured=TURBINE_MEASURED,
                                 scales=turbine_scales(model))
    else:
        obs = design_pi_observer(model, q=opts.observer_q, measured=PAPER_MEASURED)
    return LQRPIOController(model, turbine, lq, obs,
                            region=region,
                            k_opt=base.k_opt if region == "II" else None,
                            feedforward=region == "III",
                            torque_law=BaselineController(turbine, base)
                            if (region == "II" and opts.region2_torque == "baseline")
                            or (region == "III" and stall_guard) else None)


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


@register("ts", TSOptions, field_components="u", design=_design_ts, shipped=_shipped("ts"),
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


@register("apc", APCOptions, field_components="u", operating_point=_apc_trim,
          summary="the baseline following P_r (1 - Delta P(t)), PI scheduled on the reference")
def _build_apc(ctx: BuildContext, opts: APCOptions) -> Built:
    from mpc_wt.controllers.apc import apc_reference
    from mpc_wt.controllers.baseline import BaselineController, tune_baseline_schedule

    dp = apc_reference(opts.apc_frequency, amplitude=opts.apc_amplitude, offset=opts.apc_offset)
    rated = ctx.turbine.operation.rated_power
    sched = tune_baseline_schedule(ctx.turbine)
    ctl = BaselineController(ctx.turbine, gain_schedule=sched,
                             power_reference=lambda t: rated * (1.0 - dp(t)))
    return Built(ctl, meta={"apc": {"frequency_Hz": opts.apc_frequency,
                                    "amplitude": opts.apc_amplitude, "offset": opts.apc_offset,
                                    "schedule_fractions": [g.power_fraction for g in sched]}})


# -- Bladed-style libraries: ROSCO and any DISCON ---------------------------------------------
_ISOLATE = ("run the library in a child process of its own, so that a library that exits or "
            "crashes fails the case only (about 0.1 ms per call); false loads it in this "
            "process, uncontained")


@dataclass(frozen=True)
class DisconOptions(Options):
    """Any Bladed-style controller library (``DISCON``) in the loop (:mod:`mpc_wt.controllers.discon`)."""

    discon_library: str = option(REQUIRED, help="the shared library exporting DISCON")
    discon_in: str = option(REQUIRED, help="its input file (accINFILE, e.g. DISCON.IN)")
    pitch_control: str = option("individual", help="avrSWAP(28): read records 42-44 "
                                "(individual) or 45 (collective)",
                                choices=("individual", "collective"))
    discon_dt: float = option(1.0 / 80.0, help="communication interval, a multiple of the "
                              "plant step", unit="s", lo=0.0, lo_open=True, hi=1.0)
    lidar_records: bool = option(False, help="fill OpenFAST's lidar records (2001-2016) from a "
                                 "hub-mounted CW LIDAR (the lidar options)", flag="")
    lidar: LidarOptions = option(LidarOptions(), help="CW LIDAR settings (focus_distance, "
                                 "noise_std, ...)", flag="")
    isolate: bool = option(True, help=_ISOLATE, flag="")


@dataclass(frozen=True)
class RoscoOptions(Options):
    """ROSCO, the rosco package's compiled controller, in the loop."""

    discon_in: Optional[str] = option(None, help="ROSCO input file; 'shipped' for the DISCON.IN "
                                      "ROSCO ships for the turbine (nrel5mw, iea15mw); default: "
                                      "one exported from our baseline design")
    power_fraction: float = option(1.0, help="with the exported design: derate to this "
                                   "fraction of rated power", unit="-", lo=0.0, lo_open=True,
                                   hi=1.0, flag="--rosco-power-fraction")
    pitch_control: str = option("individual", help="avrSWAP(28): read records 42-44 "
                                "(individual) or 45 (collective)",
                                choices=("individual", "collective"))
    discon_dt: float = option(1.0 / 80.0, help="communication interval, a multiple of the "
                              "plant step", unit="s", lo=0.0, lo_open=True, hi=1.0)
    isolate: bool = option(True, help=_ISOLATE, flag="")


def _discon_built(ctx: BuildContext, library: Any, discon_in: Any, opts: Any,
                  kind: str, power_fraction: float = 1.0, **meta: Any) -> Built:
    from mpc_wt.controllers.discon import DisconController

    sensor = None
    if getattr(opts, "lidar_records", False):
        sensor = ctx.lidar(opts.lidar.instrument(ctx.turbine), opts.lidar.evolution)
        meta["lidar"] = {**opts.lidar.given(), "evolution": opts.lidar.evolution}
    ctl = DisconController(library, discon_in, ctx.turbine, dt=opts.discon_dt,
                           pitch_control=opts.pitch_control, lidar=sensor,
                           isolate=opts.isolate)
    return Built(ctl, controller_dt=opts.discon_dt,
                 meta={kind: {"library": str(ctl.library), "discon_in": str(ctl.discon_in),
                              "pitch_control": opts.pitch_control, "dt": opts.discon_dt,
                              **meta}},
                 power_fraction=power_fraction)


def _discon_operating_point(turbine: linearize.Turbine, sc: Scenario, opts: DisconOptions
                            ) -> linearize.OperatingPoint:
    """The trim, or for a ROSCO-style input file with a TSR-tracking law the point where that
    law holds the rotor (:func:`_file_start`)."""
    op = linearize.trim(turbine, start_wind(turbine, sc))
    return _file_start(turbine, op, Path(opts.discon_in))


@register("discon", DisconOptions, field_components="u",
          operating_point=_discon_operating_point,
          summary="any Bladed-style controller library (DISCON) with its input file")
def _build_discon(ctx: BuildContext, opts: DisconOptions) -> Built:
    return _discon_built(ctx, opts.discon_library, opts.discon_in, opts, "discon")


_ROSCO_FILES = {"NREL 5-MW": "NREL-5MW", "IEA-15-240-RWT": "IEA-15-240-RWT"}


def _shipped_name(turbine: linearize.Turbine) -> str | None:
    """The name of the ROSCO deck shipped for this turbine, or None."""
    return next((v for k, v in _ROSCO_FILES.items() if turbine.name.startswith(k)), None)


def _rosco_operating_point(turbine: linearize.Turbine, sc: Scenario, opts: RoscoOptions
                           ) -> linearize.OperatingPoint:
    if opts.discon_in is None:
        if opts.power_fraction < 1.0:
            return _derated_trim(turbine, sc, opts)     # type: ignore[arg-type]
        return linearize.trim(turbine, start_wind(turbine, sc))
    op = linearize.trim(turbine, start_wind(turbine, sc))
    if opts.discon_in == "shipped":
        from mpc_wt.controllers.discon import rosco_discon

        name = _shipped_name(turbine)
        if name is None:
            return op
        path = rosco_discon(name)
    else:
        path = Path(opts.discon_in)
    return _file_start(turbine, op, path)


def _file_start(turbine: linearize.Turbine, op: linearize.OperatingPoint, path: Path
                ) -> linearize.OperatingPoint:
    """Where a ROSCO file's own below-rated law holds the rotor, so the run starts in its
    equilibrium rather than in our schedule's.

    A TSR-tracking file (``VS_ControlMode`` 2-4) holds the generator speed at
    ``VS_TSRopt * v / WE_BladeRadius * WE_GearboxRatio`` within ``VS_MinOMSpd..VS_RefSpd``;
    ROSCO's shipped NREL 5-MW file allows 34.6 rad/s (3.4 rpm at the rotor), where our schedule
    (and the turbine's definition) keeps 6.9 rpm. Started at ours, its torque controller brakes
    the rotor at full torque rate (3.9 MN m and 0.23 x rated rotor speed at 3 m/s). Above the
    file's rated speed, or for any other law, or where no equilibrium exists at that speed,
    the trim is kept (it is the file's region-3 point too)."""
    from mpc_wt.io.gain_tables import read_rosco

    try:
        f = read_rosco(path)
        mode = int(f["VS_ControlMode"])
        tsr, lo, hi = (float(f[k]) for k in ("VS_TSRopt", "VS_MinOMSpd", "VS_RefSpd"))
        radius, gear = float(f["WE_BladeRadius"]), float(f["WE_GearboxRatio"])
    except (OSError, KeyError, ValueError, TypeError):
        return op
    if mode not in (2, 3, 4) or min(tsr, lo, hi, radius, gear) <= 0:
        return op
    gen = min(max(tsr * op.wind_mps / radius * gear, lo), hi)
    omega = gen / turbine.drivetrain.gearbox_ratio
    if gen >= hi * (1 - 1e-6) or abs(omega - op.rotor_speed_rad_s) <= 1e-3 * omega:
        return op
    try:
        return linearize.operating_point(turbine, op.wind_mps, omega, op.pitch_rad,
                                         shear_exponent=op.shear_exponent)
    except linearize.TrimError:
        return op


@register("rosco", RoscoOptions, field_components="u", operating_point=_rosco_operating_point,
          summary="ROSCO (the rosco package's libdiscon) with a DISCON.IN exported from our "
                  "baseline, ROSCO's own ('shipped') or any file")
def _build_rosco(ctx: BuildContext, opts: RoscoOptions) -> Built:
    from mpc_wt.controllers.discon import rosco_discon, rosco_library

    discon_in = opts.discon_in
    source = {}
    if discon_in == "shipped":
        name = _shipped_name(ctx.turbine)
        if name is None:
            raise ValueError(f"rosco: no DISCON.IN shipped for turbine {ctx.turbine.name!r}; "
                             f"give discon_in (--discon-in FILE)")
        source = {"shipped_file": str(rosco_discon(name))}
        discon_in = ctx.cache.get(ctx.turbine, ("rosco-shipped", name),
                                  lambda: _quiet_copy(rosco_discon(name)))
    elif discon_in is None:
        discon_in = ctx.cache.get(ctx.turbine, ("rosco-export", opts.power_fraction),
                                  lambda: _export_rosco(ctx.turbine, opts.power_fraction))
    ours = opts.discon_in is None
    return _discon_built(ctx, rosco_library(), discon_in, opts, "rosco",
                         power_fraction=opts.power_fraction if ours else 1.0,
                         design=("ours" if ours else
                                 "shipped" if opts.discon_in == "shipped" else "file"),
                         **source)


def _process_folder(prefix: str) -> Path:
    """A temporary folder kept for the process (removed when it exits)."""
    import atexit
    import shutil
    import tempfile

    out = Path(tempfile.mkdtemp(prefix=prefix))
    atexit.register(shutil.rmtree, out, ignore_errors=True)
    return out


def _quiet_copy(discon_in: Path) -> str:
    """ROSCO's shipped DISCON.IN with ``LoggingLevel`` 0 (its debug file written every call
    takes about a quarter of a run) and ``PerfFileName`` made absolute, in a folder kept for the
    process; every control parameter as shipped."""
    lines = discon_in.read_text().splitlines()
    for i, line in enumerate(lines):
        words = line.split()
        if len(words) >= 3 and words[2] == "LoggingLevel":
            lines[i] = "0" + line[len(words[0]):]
        elif len(words) >= 3 and words[2] == "PerfFileName":
            perf = words[0].strip('"')
            if not Path(perf).is_absolute():
                lines[i] = f'"{(discon_in.parent / perf).resolve()}"' + line[len(words[0]):]
    out = _process_folder("mpcwt_rosco_shipped_") / discon_in.name
    out.write_text("\n".join(lines) + "\n")
    return str(out)


def _export_rosco(turbine: linearize.Turbine, power_fraction: float) -> str:
    """Our baseline design as a ROSCO DISCON.IN in a folder kept for the process (removed when
    it exits)."""
    from mpc_wt.controllers.baseline import tune_baseline
    from mpc_wt.io.gain_tables import baseline_table
    from mpc_wt.io.rosco import write_rosco_discon

    out = _process_folder("mpcwt_rosco_export_")
    doc = baseline_table(turbine, tune_baseline(turbine, power_fraction=power_fraction))
    return str(write_rosco_discon(turbine, doc, out)[0])


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
    from mpc_wt.io.gain_tables import lidar_ff_table
    from mpc_wt.registry.context import DEFAULT_CACHE

    ctx = BuildContext(turbine=turbine, params=linearize.plant_params(turbine),
                       cache=DEFAULT_CACHE)
    base = _baseline("constant_power")(ctx, BaselineOptions())
    ctl = _build_lidar_ff(ctx, LidarFFOptions(), base).controller
    doc = lidar_ff_table(turbine, ctl, "baseline+lidar-ff", options={})
    rows = doc["schedule"]["rows"]
    return doc, (f"filter corner {min(r[1] for r in rows):.3g}-{max(r[1] for r in rows):.3g} "
                 f"rad/s over {rows[0][0]:g}-{rows[-1][0]:g} m/s")


@register("lidar-ff", LidarFFOptions, addon_to=("baseline", "derate"), default_base="baseline",
          field_components="u", group="the lidar feedforward", design=_design_lidar_ff,
          shipped=_shipped("baseline+lidar-ff", "baseline"),
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

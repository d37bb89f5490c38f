"""One closed-loop run from a controller name: trim, build, wind, simulate (STYLE rule 12)."""
from __future__ import annotations

import contextlib
import dataclasses
import logging
from pathlib import Path
from typing import Any, Iterator, Mapping, Sequence

import numpy as np
from threadpoolctl import threadpool_limits

import lidar
import linearize
from mpc_wt.errors import RunTooLargeError
from mpc_wt.registry.context import DEFAULT_CACHE, BuildContext, Built, DesignCache, design_digest
from mpc_wt.registry.options import Options
from mpc_wt.registry.registry import API_NAMING, Naming, Selection, law_export, resolve
from mpc_wt.simulation.memory import RunMemory, check_run_memory, estimate_run_memory
from mpc_wt.simulation.loop import PLANT_DT, simulate_closed_loop
from mpc_wt.simulation.results import ClosedLoopResult
from mpc_wt.simulation.scenario import (DEFAULT_FIELDS, FieldMemo, Scenario, lidar_field,
                                       make_wind, start_wind)

__all__ = ["run_controller", "build_controller", "design_controller", "export_discon",
           "export_controller", "law_controller",
           "run_openfast_case", "run_warnings", "verify_openfast", "CASE_CONTROLLERS",
           "VALIDITY_SIGNALS", "VERIFY_BOUNDS", "POWER_BOUND"]

log = logging.getLogger(__name__)


def _operating_point(turbine: linearize.Turbine, sel: Selection, opts: Sequence[Options],
                     scenario: Scenario) -> linearize.OperatingPoint:
    if sel.base.operating_point is not None:
        return sel.base.operating_point(turbine, scenario, opts[0])
    return linearize.trim(turbine, start_wind(turbine, scenario))


_CONDITION_KEYS = ("condition", "iec_class", "sign", "event_at")


def _condition(raw: Mapping[str, Any] | None) -> dict[str, Any]:
    if raw is None:
        return {}
    extra = set(raw) - set(_CONDITION_KEYS)
    if extra:
        raise ValueError(f"condition: unknown key {sorted(extra)[0]!r}; allowed: "
                         f"{list(_CONDITION_KEYS)}")
    return dict(raw)


def design_controller(turbine: linearize.Turbine, controller: str,
                      options: Mapping[str, Any] | None = None, *,
                      cache: DesignCache = DEFAULT_CACHE, naming: Naming = API_NAMING,
                      params: linearize.PlantParams | None = None,
                      shipped: bool = False) -> tuple[Built, bool]:
    """The design of a controller for a turbine: made once and kept in ``cache`` (keyed on the
    turbine's content, the name and the options), so that every case after the first runs the
    same design. The build sees the turbine, its options and the harness's step only
    (:class:`~mpc_wt.registry.context.BuildContext`).

    A kind that exports (:func:`mpc_wt.registry.exportable`) gives its design's objects (what
    an export writes out; :class:`~mpc_wt.controllers.base.DesignBase`, no step): a run
    (:func:`build_controller`, :func:`run_controller`) runs them as they are shipped, their
    numbers in the input file of the kind's compiled C law, which the host calls as
    OpenFAST's ServoDyn does (:class:`~mpc_wt.controllers.discon.DisconController`, in this
    process).

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    controller : str
        A registered name, with a pattern or add-ons (``derate80+ibc``).
    options : mapping or tuple of Options, optional
        Flat option name -> value, split over the base and its add-ons; or the options
        ``Selection.options`` checked (taken as they are).
    cache : DesignCache
        Where designs are kept.
    naming : Naming
        How error messages name options.
    params : PlantParams, optional
        The turbine's plant parameters, if already derived.
    shipped : bool
        The design as its runs run it (default False): a kind that exports as the host of its
        compiled law, ``meta["design"]["law"]`` that law's build key
        (:func:`mpc_wt.io.discon_export.shipped_law_key`).

    Returns
    -------
    built : Built
        The design; ``meta["design"]`` holds its digest
        (:func:`~mpc_wt.registry.context.design_digest`, of the design's numbers either way).
    new : bool
        True when it was made now, False when it came from the cache.
    """
    sel = resolve(controller)
    return _design(turbine, sel, sel.options(options, naming), cache, params, shipped=shipped)


def _design(turbine: linearize.Turbine, sel: Selection, opts: Sequence[Options],
            cache: DesignCache, params: linearize.PlantParams | None,
            shipped: bool = False) -> tuple[Built, bool]:
    """The design of a resolved selection with checked options (see design_controller); with
    ``shipped``, that design run as it is shipped where the selection has a shipped law."""
    made: list[bool] = []

    def make() -> Built:
        made.append(True)
        ctx = BuildContext(turbine=turbine, params=params or linearize.plant_params(turbine),
                           cache=cache)
        # one BLAS thread, as in a campaign's workers: a multi-threaded BLAS sums in another
        # order, and the design's last bits (and its digest) would depend on the process
        with threadpool_limits(limits=1):
            built = sel.base.build(ctx, opts[0])
            for kind, o in zip(sel.addons, opts[1:]):
                built = kind.build(ctx, o, built)
        built.sensors = list(ctx.sensors)
        built.meta["design"] = {"digest": design_digest(built.controller)}
        return built

    export = sel.export
    if shipped and export is None and sel.addons and sel.base.export is not None:
        return _wrapping_the_shipped_base(turbine, sel, opts, cache, params)
    key = ("built", sel.name, tuple(repr(o) for o in opts))
    built = cache.get(turbine, key, make)
    if export is None or not shipped:
        return built, bool(made)
    from mpc_wt.kinds.common import run_as_shipped

    ctx = BuildContext(turbine=turbine, params=params or linearize.plant_params(turbine),
                       cache=cache)
    return cache.get(turbine, ("shipped", *key[1:], built.meta["design"]["digest"]),
                     lambda: run_as_shipped(ctx, export, built)), bool(made)


def _wrapping_the_shipped_base(turbine: linearize.Turbine, sel: Selection,
                               opts: Sequence[Options], cache: DesignCache,
                               params: linearize.PlantParams | None) -> tuple[Built, bool]:
    """A selection whose add-ons do not export around a base that does (the MPC's torque-law
    guard): the base run as it is shipped, the add-ons built around its host."""
    base, new = _design(turbine, dataclasses.replace(sel, addons=()), opts[:1], cache, params,
                        shipped=True)

    def make() -> Built:
        ctx = BuildContext(turbine=turbine, params=params or linearize.plant_params(turbine),
                           cache=cache)
        built = base
        for kind, o in zip(sel.addons, opts[1:]):
            built = kind.build(ctx, o, built)
        built.sensors = list(base.sensors) + list(ctx.sensors)
        return built

    key = ("shipped", sel.name, tuple(repr(o) for o in opts), base.meta["design"]["digest"])
    return cache.get(turbine, key, make), new


def build_controller(turbine: linearize.Turbine, controller: str, scenario: Scenario,
                     options: Mapping[str, Any] | None = None, *,
                     cache: DesignCache = DEFAULT_CACHE, naming: Naming = API_NAMING,
                     params: linearize.PlantParams | None = None,
                     samplers: lidar.SamplerCache | None = None,
                     fields: FieldMemo | None = None
                     ) -> tuple[Built, linearize.OperatingPoint, Any]:
    """The controller's design (:func:`design_controller`, from the cache when it is there) as
    it runs: a kind that exports as it is shipped, its compiled C law called through the host
    (``meta["law"]``); the scenario's trim point and wind; the design's LIDARs bound to the
    wind they see.

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    controller : str
        A registered name (``mpc_wt.registry.kinds()``), with a pattern or add-ons
        (``derate80+ibc``).
    scenario : Scenario
        The load case: the simulator's, never the design's.
    options : mapping or tuple of Options, optional
        Flat option name -> value, split over the base and its add-ons; or the options
        ``Selection.options`` checked (taken as they are).
    cache : DesignCache
        For designs (kept between runs).
    naming : Naming
        How error messages name options (keys, or command-line flags).
    params : PlantParams, optional
        The turbine's plant parameters, if already derived (:func:`linearize.plant_params`).
    samplers : lidar.SamplerCache, optional
        Keeps the turbulence generator's sampler for the next field of the same wind and grid.
    fields : FieldMemo, optional
        Keeps the scenario's fields for the next run of the same scenario (default: the
        process's :data:`~mpc_wt.simulation.scenario.DEFAULT_FIELDS`; ``FieldMemo(0)`` keeps
        none).

    Returns
    -------
    built : Built
        Controller (reset), its period, LIDAR preview and design metadata
        (``meta["design"]["new"]``: made for this run or reused).
    op : OperatingPoint
        The trim point the run starts from.
    wind : SteadyWind or GridWind
        The plant's wind.

    Raises
    ------
    ValueError
        An unknown name (listing the kinds); :class:`~mpc_wt.errors.OptionsError` for options.
    """
    sel = resolve(controller)
    opts = sel.options(options, naming)
    op = _operating_point(turbine, sel, opts, scenario)
    built, new = _design(turbine, sel, opts, cache, params, shipped=True)
    comps = sel.field_components
    lidars = len(built.sensors) + (built.preview is not None)
    fields = DEFAULT_FIELDS if fields is None else fields
    _check_memory(estimate_run_memory(turbine, scenario, components=len(comps),
                                      lidar_fields=lidars),
                  f"a {scenario.duration:g} s run of {controller}", fields)
    wind, field = make_wind(turbine, scenario, comps,
                            samplers=samplers, fields=fields)
    for sensor in built.sensors:
        sensor.bind(lidar_field(turbine, scenario, field, sensor.distance, samplers, fields))
    built.controller.reset()
    if built.preview is not None:
        built.preview.reset()
    meta = {**built.meta, "design": {**built.meta["design"], "new": new}}
    return dataclasses.replace(built, meta=meta), op, wind


def _check_memory(need: RunMemory, what: str, fields: FieldMemo) -> None:
    """:func:`check_run_memory`; where the run does not fit while earlier fields are kept,
    they are released (logged) and the run is checked again."""
    try:
        check_run_memory(need, what=what)
    except RunTooLargeError:
        if not len(fields):
            raise
        log.info("releasing %.0f MB of kept wind fields to make room for %s",
                 fields.nbytes / 1e6, what)
        fields.clear()
        check_run_memory(need, what=what)


def _scenario_of(scenario: Scenario | float, fields: dict[str, Any]) -> Scenario:
    """The run's scenario: given whole, or made from a mean wind and the keyword fields."""
    given = {k: v for k, v in fields.items() if v is not None}
    if isinstance(scenario, Scenario):
        if given:
            raise TypeError(f"run_controller: {sorted(given)} apply only with a mean wind; "
                            f"a Scenario carries them (dataclasses.replace(scenario, ...))")
        return scenario
    if isinstance(scenario, bool) or not isinstance(scenario, (int, float)):
        raise TypeError(f"scenario must be a Scenario or a mean wind speed [m/s], got "
                        f"{type(scenario).__name__}")
    cond = _condition(given.pop("condition", None))
    return Scenario(float(scenario), **given, **cond)


def run_controller(turbine: linearize.Turbine, controller: str, scenario: Scenario | float,
                   options: Mapping[str, Any] | None = None, *,
                   supervisor: Mapping[str, Any] | None = None, progress: bool = False,
                   cache: DesignCache = DEFAULT_CACHE, naming: Naming = API_NAMING,
                   samplers: lidar.SamplerCache | None = None,
                   fields: FieldMemo | None = None,
                   turbulence: str | float | None = None, seed: int | None = None,
                   duration: float | None = None, shear_exponent: float | None = None,
                   condition: Mapping[str, Any] | None = None,
                   plant: Mapping[str, bool] | None = None) -> ClosedLoopResult:
    """Trim, build the controller, generate the scenario's wind and simulate.

    Parameters
    ----------
    turbine : Turbine
        The turbine (:func:`linearize.load_turbine`).
    controller : str
        A registered kind (``mpc_wt.registry.kinds()`` lists them with their options):
        ``baseline``, ``baseline-ct``, ``derateNN``, ``apc``, ``ibc``, ``coleman-ipc``,
        ``derateNN+ibc``, ``mpc``, ``mpc-collective``, ``mpc-lidar``, ``lqr-pio``, ``ts``, or a
        user-registered one.
    scenario : Scenario or float
        The load case (:class:`~mpc_wt.simulation.scenario.Scenario`: mean wind, turbulence,
        seed, duration, shear, IEC condition). A mean wind speed [m/s] instead makes one with
        the keyword fields below (a shorthand for ``Scenario(wind, turbulence=..., ...)``).
    options : mapping, optional
        The kind's options by name, e.g. ``{"apc_frequency": 0.1}`` for ``apc`` or
        ``{"horizon": 10, "lidar": {"focus_distance": 80}}`` for ``mpc-lidar``.
    supervisor : mapping, optional
        Runs the controller under :class:`mpc_wt.controllers.supervisor.Supervisor` with these
        settings (``overspeed``, ``shutdown_at``, ``grid_loss_at`` [s], ``pitch_rate``,
        ``torque_ramp_s``).
    progress : bool
        Show a progress bar.
    cache : DesignCache
        For designs that cost seconds (the TS LMIs), keyed on the turbine's content.
    naming : Naming
        How messages name options.
    samplers, fields : lidar.SamplerCache, FieldMemo, optional
        Keep the generator's sampler and the fields for the next runs (the same fields with or
        without them); fields default to :data:`~mpc_wt.simulation.scenario.DEFAULT_FIELDS`.
    turbulence, seed, duration, shear_exponent : optional
        With a mean wind only: the :class:`Scenario`'s fields (defaults "A", 1, 600 s, 0.2).
    condition : mapping, optional
        With a mean wind only: an IEC 61400-1 wind condition, ``condition`` ("etm", "eog",
        "edc", "ecd", "ews-v", "ews-h", "nwp"), ``iec_class`` ("I"), ``sign`` (1),
        ``event_at`` (when the transient starts [s]).
    plant : mapping of str to bool, optional
        The plant's effects switched from their defaults (``meta["plant"]``), e.g.
        ``{"twisted_modes": True}`` (:meth:`linearize.PlantConfig.with_switches`).

    Returns
    -------
    ClosedLoopResult
        With ``meta["controller"]`` and the case and design data in ``meta``.

    Raises
    ------
    ValueError
        Unknown controller or bad options (naming the option and what is allowed), a bad
        scenario (naming the field), or a wind at which the kind cannot operate.
    TypeError
        Scenario fields given beside a whole :class:`Scenario`.
    SimulationDivergedError
        The run left the physical envelope (``.partial`` keeps what was simulated).
    """
    scenario = _scenario_of(scenario, dict(turbulence=turbulence, seed=seed, duration=duration,
                                           shear_exponent=shear_exponent, condition=condition))
    params = _checked_case(turbine, plant, scenario, supervisor)   # before the design
    built, op, wind = build_controller(turbine, controller, scenario, options, cache=cache,
                                       naming=naming, params=params, samplers=samplers,
                                       fields=fields)
    meta = _run_meta(controller, scenario, turbine, built, op, plant)
    return _warned(simulate_closed_loop(
        params, _supervised(built.controller, turbine, supervisor, meta), wind,
        scenario.duration, x0=op.x, u0=op.u, controller_dt=built.controller_dt,
        preview=built.preview, progress=progress, meta=meta), controller, turbine)


#: The supervisor's events, each at a time [s] that must fall within the run.
SUPERVISOR_EVENTS = ("shutdown_at", "grid_loss_at", "pitch_fault_at")


def _checked_case(turbine: linearize.Turbine, plant: Mapping[str, bool] | None,
                  scenario: Scenario, supervisor: Mapping[str, Any] | None
                  ) -> linearize.PlantParams:
    """The plant's parameters, refused if its step cannot integrate the drivetrain; a
    supervisor event at or after the run's end refused (it would never happen)."""
    for key in SUPERVISOR_EVENTS:
        at = (supervisor or {}).get(key)
        if isinstance(at, (int, float)) and not isinstance(at, bool) \
                and at >= scenario.duration:
            raise ValueError(f"supervisor {key} = {at:g} s is at or after the run's end "
                             f"({scenario.duration:g} s): the event would not happen; allowed "
                             f"0 <= {key} < {scenario.duration:g} s")
    params = linearize.plant_params(turbine, linearize.PlantConfig().with_switches(plant))
    linearize.check_plant_step(params, PLANT_DT)
    return params


def _run_meta(controller: str, scenario: Scenario, turbine: linearize.Turbine, built: Built,
              op: linearize.OperatingPoint, plant: Mapping[str, bool] | None) -> dict[str, Any]:
    """A run's metadata: the controller, the case, the turbine, the design and the plant."""
    return {"controller": controller, **scenario.meta(), "turbine": turbine.name, **built.meta,
            **({} if scenario.wind_file is None else {"start_wind_mps": op.wind_mps}),
            **({"plant": {k: bool(v) for k, v in plant.items()}} if plant else {})}


def _supervised(ctl: Any, turbine: linearize.Turbine, supervisor: Mapping[str, Any] | None,
                meta: dict[str, Any]) -> Any:
    """``ctl`` under a :class:`~mpc_wt.controllers.supervisor.Supervisor` with the settings
    ``supervisor`` (recorded in ``meta``), or ``ctl`` itself without them."""
    if supervisor is None:
        return ctl
    from mpc_wt.controllers.supervisor import Supervisor

    meta["supervisor"] = {k: v for k, v in dict(supervisor).items() if v is not None}
    return Supervisor(ctl, turbine, **dict(supervisor))


def _warned(res: ClosedLoopResult, controller: str, turbine: linearize.Turbine
            ) -> ClosedLoopResult:
    """``res`` with its :func:`run_warnings` in ``meta["run_warnings"]``, each logged."""
    res.meta["run_warnings"] = run_warnings(res, turbine.operation.rated_power)
    for w in res.meta["run_warnings"]:
        log.warning("%s: %s", controller, w)
    return res


#: The largest electrical power a grid takes from a turbine in power production, a fraction of
#: its rated power: a run above it is warned (:func:`run_warnings`), the sign-off bounds it.
POWER_BOUND = 1.1

#: controller signals that flag a step outside the design's validity: signal -> what it means
VALIDITY_SIGNALS = {
    "premise_clipped": "the TS premise (estimated wind, power reduction) left the vertex grid "
                       "and was clipped to it",
    "qp_fallback": "the MPC's QP failed or ran over its time budget and the fallback command "
                   "was applied",
    "library_warning": "the controller library warned (aviFAIL > 0)",
    "schedule_outside": "the scheduling wind lay more than 1 m/s beyond the designs' grid (the "
                        "nearest design acted outside its range)",
    "estimator_outside": "the wind estimate was held at an end of the estimator's range or lay "
                         "at a tip-speed ratio beyond its C_P table",
}


#: Share of a run's steps with the generator torque pinned at its maximum above which the run
#: warns (a constant-power law touches the limit for a moment in most gusts: the baseline at
#: 18 m/s, class A, 0.3 % of 600 s); the count is in ``meta["torque_pinned_steps"]`` always.
PINNED_WARN_SHARE = 0.01


def run_warnings(res: Any, rated_power_W: float | None = None) -> list[str]:
    """Where a run left its controller's validity, one line each, with how often: commands the
    actuators' limits clipped, steps with the generator torque pinned at its maximum (more
    than :data:`PINNED_WARN_SHARE` of them), the steps a controller flagged
    (:data:`VALIDITY_SIGNALS`), and the electrical power above :data:`POWER_BOUND` x rated.

    Parameters
    ----------
    res : ClosedLoopResult
    rated_power_W : float, optional
        The turbine's rated power [W] (None: the power is not checked).

    Returns
    -------
    list of str
        Empty when the run stayed within them.
    """
    out = []
    clipped = int(res.meta.get("commands_clipped", 0) or 0)
    if clipped:
        out.append(f"{clipped} commands beyond the actuators' limits were clipped")
    pinned = int(res.meta.get("torque_pinned_steps", 0) or 0)
    if pinned > PINNED_WARN_SHARE * len(res.t):
        out.append(f"the generator torque sat at its maximum in {pinned} of {len(res.t)} steps "
                   f"({100.0 * pinned / len(res.t):.1f} %)")
    for name, what in VALIDITY_SIGNALS.items():
        sig = res.controller.get(name)
        if sig is None:
            continue
        n = int(np.count_nonzero(np.asarray(sig) != 0))
        if n:
            out.append(f"{what} in {n} of {len(sig)} steps ({100.0 * n / len(sig):.1f} %)")
    if rated_power_W and "gen_power" in res.channels():
        p = np.asarray(res.channel("gen_power")) / rated_power_W
        n = int(np.count_nonzero(p > POWER_BOUND))
        if n:
            k = int(np.argmax(p))
            out.append(f"the electrical power passed {POWER_BOUND:g} x rated in {n} of {p.size} "
                       f"steps ({n * float(np.median(np.diff(res.t))):g} s); largest "
                       f"{p[k]:.3f} x rated at t = {res.t[k]:g} s")
    return out


def export_discon(turbine: linearize.Turbine, controller: str, out: str | Path,
                  options: Mapping[str, Any] | None = None, *, build: bool = True,
                  compiler: str | None = None) -> Any:
    """Design a controller kind for a turbine and export it as a Bladed-style library.

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    controller : str
        The kind (one of :func:`mpc_wt.registry.exportable`).
    out : path
        The export folder (created; files of an earlier export are replaced).
    options : mapping, optional
        The kind's options, as :func:`mpc_wt.run.design_controller` takes them.
    build : bool
        Compile the library now (default); without a compiler the export still writes the
        sources, and ``note`` says so.
    compiler : str, optional
        The C compiler (default :func:`mpc_wt.io.discon_export.find_compiler`).

    Returns
    -------
    mpc_wt.io.discon_export.DisconExport

    Raises
    ------
    ValueError
        A kind that does not export (listing those that do), or bad options.
    ControllerLibraryError
        The compiler failed.
    SolverSourceError
        An MPC kind whose QP solver's sources are neither cached nor downloadable (checked
        before the design is made).
    """
    from mpc_wt.io import discon_export as dx

    export = law_export(controller)
    dx.prepare_sources(export)
    built, _ = design_controller(turbine, controller, options)
    opts = ", ".join(f"{k}={v}" for k, v in sorted((options or {}).items()))
    return dx.export_controller(built.designed, export, turbine, out, build=build,
                                compiler=compiler,
                                source=f"options: {opts}" if opts else "default options",
                                preview=built.preview)


def export_controller(controller: Any, kind: str, turbine: linearize.Turbine, out: str | Path,
                      *, build: bool = True, compiler: str | None = None, source: str = "",
                      preview: Any = None) -> Any:
    """Export a controller object a kind builds (a design changed by hand, a derated
    baseline) as a Bladed-style library
    (:func:`mpc_wt.io.discon_export.export_controller` with the kind's export).

    Parameters
    ----------
    kind : str
        The controller's kind (one of :func:`mpc_wt.registry.exportable`).
    controller, turbine, out, build, compiler, source, preview
        As :func:`mpc_wt.io.discon_export.export_controller` takes them (``controller`` is of
        the type the kind builds: ``Built.designed``).

    Returns
    -------
    mpc_wt.io.discon_export.DisconExport

    Raises
    ------
    ValueError
        A kind that does not export, or a controller its law does not take.
    """
    from mpc_wt.io import discon_export as dx

    export = law_export(kind)
    dx.prepare_sources(export)
    return dx.export_controller(controller, export, turbine, out, build=build,
                                compiler=compiler, source=source, preview=preview)


def law_controller(controller: Any, kind: str, turbine: linearize.Turbine, *,
                   lidar: Any = None, preview: Any = None) -> Any:
    """A controller object a kind builds (a design changed by hand, a derated baseline, a
    :class:`~mpc_wt.controllers.baseline.BaselineController` of your gains) run by its kind's
    shipped law: its numbers in the law's input file, the compiled library called in this
    process as OpenFAST's ServoDyn calls it (what ``run_controller`` runs).

    Parameters
    ----------
    controller : object
        The design (of the type the kind builds; ``Built.designed``).
    kind : str
        Its kind (one of :func:`mpc_wt.registry.exportable`; a design's ``kind`` attribute
        names it).
    turbine : Turbine
        Its turbine.
    lidar : lidar.LidarSensor, optional
        The LIDAR whose measurements fill the lidar records (default: the design's
        ``sensor``, if it has one: the LIDAR feedforward).
    preview : LidarPreview, optional
        The design's LIDAR preview (the MPC with LIDAR).

    Returns
    -------
    mpc_wt.controllers.discon.DisconController
        A controller for :func:`~mpc_wt.simulation.loop.simulate_closed_loop`, at the design's
        period (``dt``).

    Raises
    ------
    ValueError
        A kind that does not export, or a controller its law does not take.
    ControllerLibraryError
        No C compiler, or the build failed.
    """
    from mpc_wt.io import discon_export as dx
    from mpc_wt.kinds.common import shipped_host

    export = law_export(kind)
    dx.prepare_sources(export)
    return shipped_host(controller, export, turbine, preview,
                        lidar=lidar if lidar is not None else getattr(controller, "sensor", None))


def estimate_wind(turbine: linearize.Turbine, result: Any, estimator: Any = None,
                  every: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """The rotor-effective wind the shipped laws' estimator (``windest.c``, an extended Kalman
    filter on rotor speed, pitch and generator torque) finds in a run's measurements, replayed
    through a library as OpenFAST calls it (its first call without a measured torque).

    Parameters
    ----------
    turbine : Turbine
        The run's turbine.
    result : ClosedLoopResult
        The run (any controller): its measured channels are the estimator's input.
    estimator : WindSpeedEstimator, optional
        The estimator's design (its tuning and C_P table; default
        ``WindSpeedEstimator(turbine, 0.1)``); its ``dt`` is the replay's step.
    every : int
        Plant steps per estimator step (default 8: 10 Hz on the 80 Hz plant).

    Returns
    -------
    t : ndarray
        The estimator's times [s].
    wind : ndarray
        Its estimates [m/s].

    Raises
    ------
    ValueError
        ``every`` below 1.
    """
    from mpc_wt.controllers.mpc import MPC, MPCSettings, ScheduledMPC
    from mpc_wt.controllers.wind_estimator import WindSpeedEstimator

    if int(every) < 1:
        raise ValueError(f"every must be >= 1 plant step, got {every!r}")
    est = estimator or WindSpeedEstimator(turbine, 0.1)
    # a one-point MPC whose schedule does not low-pass: its logged schedule wind is the
    # estimator's (the MPC's own commands are not applied: the run is only read)
    model = linearize.linearize(turbine, linearize.rated_wind_speed(turbine) + 1.0,
                                config=linearize.PlantConfig.madsen())
    design = ScheduledMPC.of_one(MPC(model, turbine, MPCSettings(dt=est.dt)),
                                 time_constant=0.0, wind_estimator=est)
    host = law_controller(design, "mpc", turbine)
    out = []
    idx = range(0, result.t.size, int(every))
    blades = {n: np.array([result.channel(f"{n}_{b}") for b in (1, 2, 3)])
              for n in ("pitch", "flap_moment", "edge_moment")}
    scalars = {n: result.channel(n) for n in (
        "gen_speed", "rotor_speed", "gen_torque", "gen_power", "azimuth",
        "tower_fa_acceleration", "tower_ss_acceleration")}
    try:
        for i in idx:
            host.step(float(result.t[i]), {**{n: v[:, i] for n, v in blades.items()},
                                           **{n: float(v[i]) for n, v in scalars.items()}})
            out.append(host.signals["schedule_wind"])
    finally:
        host.finalize()
    return result.t[::int(every)], np.array(out)


def export_saved_design(doc: Mapping[str, Any], turbine: linearize.Turbine, out: str | Path,
                        *, build: bool = True, compiler: str | None = None) -> Any:
    """Export a saved design (a gain-table document of ``mpcwt design``) as a library: a
    baseline's from its gain table, a kind whose export builds it again from the options the
    document keeps (:attr:`mpc_wt.io.discon_export.LawExport.rebuilt`) through
    :func:`export_discon`.

    Parameters
    ----------
    doc : mapping
        The design document (:func:`mpc_wt.io.gain_tables.load_design`).
    turbine, out, build, compiler
        As :func:`export_discon` takes them.

    Returns
    -------
    mpc_wt.io.discon_export.DisconExport

    Raises
    ------
    ValueError
        A design of a kind that does not export, or one its kind cannot build again from
        the document (:attr:`~mpc_wt.io.discon_export.LawExport.check_saved`).
    """
    from mpc_wt.io import discon_export as dx

    export = law_export(str(doc.get("kind")))
    if not export.rebuilt:
        return dx.export_design(doc, export, turbine, out, build=build, compiler=compiler)
    if export.check_saved is not None:
        export.check_saved(doc)
    return export_discon(turbine, export.name, out,
                         (doc.get("settings") or {}).get("options") or None, build=build,
                         compiler=compiler)


#: the controllers :func:`run_openfast_case` runs a case with
CASE_CONTROLLERS = ("auto", "jonkman", "rosco", "discon")


def _case_interval(case: Any, dt: float) -> float:
    """The interval a case's ServoDyn calls its library at, on the plant's step ``dt``: its
    ``DLL_DT`` where that is a whole number of steps (the MPC's 0.1 s), else every step (a
    ``DLL_DT`` of OpenFAST's own 0.00625 s step runs at the plant's)."""
    dll = case.dll_dt
    if dll is None or dll <= dt * (1 + 1e-9):
        return dt
    n = round(dll / dt)
    if abs(n * dt - dll) > 1e-9 * dll:
        raise ValueError(f"ServoDyn's DLL_DT = {dll:g} s is not a whole number of the plant's "
                         f"{dt:g} s steps; pass another dt")
    return n * dt


def run_openfast_case(case: Any, controller: str = "auto", *, library: str | Path | None = None,
                      discon_in: str | Path | None = None, config: Any = None,
                      dt: float = 1.0 / 80.0, progress: bool = False,
                      workdir: str | Path | None = None) -> ClosedLoopResult:
    """Run mpc-wt's plant through an OpenFAST case: its wind as the rotor meets it, its initial
    state, its degrees of freedom and aerodynamic options, and its controller.

    Parameters
    ----------
    case : mpc_wt.io.openfast_case.OpenFASTCase
        From :func:`mpc_wt.io.openfast_case.read_openfast_case`.
    controller : {"auto", "jonkman", "rosco", "discon"}
        ``jonkman``: the baseline kind with Jonkman's published gains
        (:func:`mpc_wt.controllers.baseline.jonkman_gains`); ``rosco``: ROSCO's library (the
        ``rosco`` package's) with the case's ``DISCON.IN``; ``discon``: ``library`` with
        ``discon_in``; ``auto``: ``rosco`` when ServoDyn names a controller input file, else
        ``jonkman``.
    library, discon_in : str or Path, optional
        For ``discon`` (``discon_in`` defaults to the case's).
    config : linearize.PlantConfig, optional
        The plant in place of the case's (:attr:`OpenFASTCase.config`).
    dt : float
        Plant and controller step [s].
    progress : bool
        Show a progress bar.
    workdir : str or Path, optional
        The library's working folder (where it writes its files; default a temporary one).

    Returns
    -------
    ClosedLoopResult
        ``meta`` holds the case, the controller and the wind's time shift. Where the case's
        InflowWind has a single-point lidar (``SensorType`` 1), the library's lidar records
        are filled from it as OpenFAST v5.0.0 fills them (:class:`lidar.PointLidar`).

    Raises
    ------
    ValueError
        An unknown controller, or ``discon`` without a library or input file.
    SimulationDivergedError
        If the run leaves the physical envelope (``.partial`` keeps what was simulated).
    """
    from mpc_wt.controllers.baseline import BaselineController, jonkman_gains
    from mpc_wt.controllers.discon import DisconController, rosco_library
    from mpc_wt.io.openfast_case import case_grid_wind, case_lidar, case_wind_field, describe

    if controller not in CASE_CONTROLLERS:
        raise ValueError(f"controller must be one of {list(CASE_CONTROLLERS)}, got "
                         f"{controller!r}")
    if controller == "auto":
        controller = "rosco" if case.discon_in is not None else "jonkman"
    turbine = case.turbine
    field = case_wind_field(case) if case.steady_wind is None else None
    wind, shift = case_grid_wind(case, field)
    if controller == "jonkman":
        ctl: Any = law_controller(BaselineController(turbine, jonkman_gains(), dt=dt),
                                  "baseline", turbine)
    else:
        lib = rosco_library() if controller == "rosco" else library
        dis = discon_in if discon_in is not None else case.discon_in
        if lib is None or dis is None:
            raise ValueError(f"controller {controller!r} needs a library and a controller input "
                             f"file (library={library!r}, discon_in={dis!r})")
        ctl = DisconController(lib, dis, turbine, dt=_case_interval(case, dt),
                               pitch_control="individual" if case.individual_pitch
                               else "collective",
                               lidar=None if field is None else case_lidar(case, field[0]),
                               workdir=workdir)
    params = linearize.plant_params(turbine, config or case.config)
    x0 = case.x0.copy()
    wg = x0[3]
    rated = turbine.rated_generator_speed_rad_s
    tq0 = min(turbine.rated_generator_torque * (wg / rated) ** 2 if wg < rated
              else turbine.rated_generator_torque, turbine.generator.max_torque)
    u0 = np.array([x0[5], x0[6], x0[7], tq0])
    meta = {"controller": controller, "openfast_case": describe(case),
            "wind_shift_s": shift, "turbine": turbine.name}
    return simulate_closed_loop(params, ctl, wind, case.duration, x0=x0, u0=u0, dt=dt,
                                controller_dt=getattr(ctl, "dt", dt), progress=progress,
                                meta=meta)


#: what :func:`verify_openfast` flags: (row key, channel, bound, what it is), a difference of
#: mpc-wt's run from OpenFAST's beyond the bound is flagged
VERIFY_BOUNDS = (("mean_diff_pct", "gen_power", 1.0, "mean power [%]"),
                 ("mean_diff_pct", "rotor_speed", 1.0, "mean rotor speed [%]"),
                 ("std_diff_pct", "rotor_speed", 10.0, "rotor speed std [%]"),
                 ("del_diff_pct", "flapwise_moment_1", 10.0, "blade 1 flapwise DEL [%]"),
                 ("del_diff_pct", "flap_moment_1", 10.0, "blade 1 out-of-plane DEL [%]"),
                 ("del_diff_pct", "lss_torque", 10.0, "shaft torque DEL [%]"),
                 ("del_diff_pct", "tower_base_fa_moment", 10.0, "tower base fore-aft DEL [%]"),
                 ("del_diff_pct", "tower_base_ss_moment", 10.0, "tower base side-side DEL [%]"))


def _verify_flags(rows: list[dict[str, Any]], travel: tuple[float, float],
                  rated: float) -> list[str]:
    """The differences beyond :data:`VERIFY_BOUNDS`, the largest power's beyond 2 % of rated,
    pitch travel's beyond 10 %, and OpenFAST's largest power above 1.1 x rated."""
    by = {r["channel"]: r for r in rows}
    flags = []
    for key, ch, bound, what in VERIFY_BOUNDS:
        v = by.get(ch, {}).get(key)
        if v is not None and not abs(v) <= bound:
            flags.append(f"{what}: {v:+.2f} (bound {bound:g})")
    p = by.get("gen_power")
    if p is not None:
        d = 100.0 * (p["max"] - p["max_ref"]) / rated
        if not abs(d) <= 2.0:
            flags.append(f"largest power: {d:+.2f} % of rated (bound 2)")
        if p["max_ref"] > 1.1 * rated:
            flags.append(f"OpenFAST's largest power {p['max_ref'] / rated:.3f} x rated (> 1.1)")
    if travel[0] > 0 and not abs(100.0 * (travel[1] / travel[0] - 1.0)) <= 10.0:
        flags.append(f"pitch travel: {100.0 * (travel[1] / travel[0] - 1.0):+.1f} % (bound 10)")
    return flags


def _pitch_travel(t: np.ndarray, pitch: np.ndarray, window: tuple[float, float]) -> float:
    """Blade 1's pitch travel over the window [deg]
    (:func:`~mpc_wt.assessment.performance.pitch_duty`)."""
    from mpc_wt.assessment.performance import pitch_duty

    k = (t >= window[0]) & (t <= window[1])
    return pitch_duty(np.asarray(pitch, float)[k], 1.0)["pitch_travel_deg"]


def verify_openfast(turbine: linearize.Turbine, controller: str, fst: str | Path,
                    out: str | Path, options: Mapping[str, Any] | None = None, *,
                    openfast: str | Path | None = None, tmax: float | None = None,
                    window: tuple[float, float | None] = (10.0, None),
                    progress: bool = False, inflow: str | Path | None = None,
                    values: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """Prove a design in the user's OpenFAST: export it, run OpenFAST on the user's deck with
    it, run the same case on mpc-wt's plant, compare them channel by channel and flag every
    difference beyond :data:`VERIFY_BOUNDS` (and the largest power beyond 2 % of rated, pitch
    travel beyond 10 %, OpenFAST's largest power above 1.1 x rated).

    Parameters
    ----------
    turbine : Turbine
        The turbine the design is for (the deck's).
    controller : str
        An exportable kind (:func:`mpc_wt.registry.exportable`).
    fst : str or Path
        The user's deck (its main file); it is not written to.
    out : str or Path
        The folder for the library (``library/``), the deck's copies and OpenFAST's output
        (``openfast/``), mpc-wt's run (``ours.nc``), ``verify.json`` and ``verify.png``.
    options : mapping, optional
        The kind's options (:func:`design_controller`'s).
    openfast : str or Path, optional
        The OpenFAST executable (else ``$MPCWT_OPENFAST``, else ``openfast`` on ``PATH``).
    tmax : float, optional
        The run's length [s] in place of the deck's ``TMax``.
    window : (float, float or None)
        The statistics' window [s] (None: to the end).
    progress : bool
        Show progress bars (OpenFAST's simulated time, then mpc-wt's run).
    inflow : str or Path, optional
        An InflowWind file in place of the deck's. A LIDAR kind on a deck whose InflowWind has
        no single-point lidar (``SensorType 1``) runs with a copy of it that has five on the
        design's ring (:func:`mpc_wt.io.openfast_run.write_lidar_inflow`).
    values : mapping, optional
        Values in the deck's copies both plants run (``prepare_deck``'s ``values``).

    Returns
    -------
    dict
        ``rows`` (:func:`mpc_wt.assessment.compare.compare_series`, OpenFAST the reference),
        ``pitch_travel_deg`` (OpenFAST, mpc-wt), ``flags``, ``window_s``, ``files``.

    Raises
    ------
    OpenFASTRunError
        No OpenFAST executable, or OpenFAST did not finish (its last lines in the message).
    ValueError
        A kind that does not export.
    """
    from mpc_wt.assessment.compare import compare_series
    from mpc_wt.io.json_text import write_json
    from mpc_wt.io.openfast_run import find_openfast, prepare_deck
    from mpc_wt.plotting import plot_verify

    exe, out = find_openfast(openfast), Path(out)
    ex = export_discon(turbine, controller, out / "library", options)
    deck = prepare_deck(fst, out / "openfast", ex.library, ex.input_file, ex.dt, tmax=tmax,
                        inflow=inflow, values=values)
    deck, case = _with_lidar(deck, out, ex, turbine, tmax)
    of_path, of, ref = _openfast_run(exe, deck, tmax, progress)
    res = run_openfast_case(case, "discon", library=ex.library, discon_in=ex.input_file,
                            progress=progress)
    ours = {n: res.channel(n) for n in res.channels()}
    hi = window[1] if window[1] is not None else float(min(of.t[-1], res.t[-1]))
    rows = compare_series(of.t, ref, res.t, ours, (window[0], hi))
    travel = (_pitch_travel(of.t, ref["pitch_1"], (window[0], hi)),
              _pitch_travel(res.t, ours["pitch_1"], (window[0], hi)))
    flags = _verify_flags(rows, travel, turbine.operation.rated_power)
    res.save(out / "ours.nc")
    png = plot_verify(of.t, ref, res.t, ours, out / "verify.png",
                      f"{controller} in {Path(fst).name}: OpenFAST and mpc-wt")
    doc = {"controller": controller, "deck": str(Path(fst).resolve()), "openfast": str(exe),
           "window_s": [window[0], hi], "rows": rows, "pitch_travel_deg": list(travel),
           "flags": flags, "files": {"library": str(ex.library), "openfast_output": str(of_path),
                                     "ours": str(out / "ours.nc"), "plot": str(png)}}
    write_json(out / "verify.json", doc)
    return doc


def _with_lidar(deck: Path, out: Path, ex: Any, turbine: linearize.Turbine,
                tmax: float | None) -> tuple[Path, Any]:
    """The prepared deck and its case; for a LIDAR kind on a deck whose InflowWind has no
    single-point lidar, the deck again with a copy of that file with the five single points the
    kind reads (:func:`mpc_wt.io.openfast_run.lidar_points` on the design's focus distance and
    cone, ``inflow.dat`` in ``out/openfast``)."""
    from linearize.openfast import OpenFASTFile
    from mpc_wt.io.discon_export import lidar_geometry, lidar_inflow
    from mpc_wt.io.openfast_case import read_openfast_case
    from mpc_wt.io.openfast_run import prepare_deck

    case = read_openfast_case(deck, turbine=turbine)
    if lidar_geometry(ex.input_file) is None or (case.lidar is not None
                                                 and case.lidar["sensor_type"] == 1):
        return deck, case
    inflow = OpenFASTFile(deck).file("InflowFile")
    if inflow is None:
        raise ValueError(f"{deck}: no InflowFile to give the LIDAR kind its lidar")
    iw = lidar_inflow(ex.input_file, inflow, out / "openfast" / "inflow.dat", ex.dt)
    log.info("the deck's InflowWind has no single-point lidar; %s has five on the design's "
             "ring", iw)
    deck = prepare_deck(deck, out / "openfast", ex.library, ex.input_file, ex.dt, tmax=tmax,
                        inflow=iw)
    return deck, read_openfast_case(deck, turbine=turbine)


def _openfast_run(exe: Path, deck: Path, tmax: float | None, progress: bool
                  ) -> tuple[Path, Any, dict[str, np.ndarray]]:
    """OpenFAST on a prepared deck: its output file, the series read and its channels by
    mpc-wt's names."""
    from mpc_wt.io.openfast_output import read_openfast_output, to_mpcwt_channels
    from mpc_wt.io.openfast_run import run_openfast

    with _time_bar(progress, "OpenFAST", tmax) as tick:
        path = run_openfast(exe, deck, progress=tick)
    series = read_openfast_output(path)
    return path, series, to_mpcwt_channels(series, str(path))[0]


@contextlib.contextmanager
def _time_bar(show: bool, what: str, total: float | None) -> Iterator[Any]:
    """A progress bar over a run's simulated time (a callable taking it), or a no-op."""
    if not show:
        yield None
        return
    from tqdm import tqdm

    with tqdm(total=total, desc=what, unit="s") as bar:
        def tick(t: float) -> None:
            bar.update(max(t - bar.n, 0.0))
        yield tick

"""Closed-loop simulation: plant + wind + controller, with results that keep everything.

The plant (:mod:`linearize`) is integrated with fixed-step RK4 at its rate (default 80 Hz,
:class:`linearize.PlantStepper`); the controller runs at its own rate and its commands are held
between its steps (zero-order hold). A controller is any object with ``reset()`` and
``step(t, measurements) -> (pitch_ref (3,), gen_torque_ref)``; it may expose a dict ``signals``
of internal signals, recorded every step.

Measurements given to the controller: ``t``, ``gen_speed``, ``rotor_speed``, ``pitch`` (3,),
``flap_moment`` (3,), ``edge_moment`` (3,), ``tower_fa_acceleration``,
``tower_ss_acceleration``, ``azimuth``, ``gen_power``, ``gen_torque`` (applied),
``aero_power``, ``lss_torque``, ``thrust``, ``tilt_moment``, ``yaw_moment``,
``hub_wind_speed`` (the free wind at the hub, as a nacelle anemometer would see it without the
rotor: OpenFAST's ``HorWindV``); ``state``, the full plant state
(:data:`linearize.STATE_NAMES`), for full-state-information designs (Madsen's MPC);
``outputs``, the plant's output row (:data:`linearize.OUTPUT_NAMES`; a wrapper that changes a
measurement must drop it, the library host reads its records from it); and
``preview`` when a LIDAR preview is attached. A controller with a ``finalize()`` method gets
it called once after the run (also after a failed one): a Bladed-style library's last call.
A controller whose ``grid_connected`` attribute turns False (a grid loss,
:class:`mpc_wt.controllers.supervisor.Supervisor`) gets zero generator torque from the next plant step on,
without the torque-rate limit.
"""
from __future__ import annotations

import logging
import math
from typing import Any

import numpy as np
from tqdm import tqdm

import linearize
from mpc_wt._version import __version__
from mpc_wt.errors import ControllerLibraryError, SimulationDivergedError
from mpc_wt.simulation.preview import LidarPreview
from mpc_wt.simulation.results import ClosedLoopResult

__all__ = ["simulate_closed_loop"]

log = logging.getLogger(__name__)


_Z = {n: i for i, n in enumerate(linearize.OUTPUT_NAMES)}


_IX_ROTOR = linearize.STATE_NAMES.index("rotor_speed")


_IX_AZ = linearize.STATE_NAMES.index("azimuth")


_IDX = tuple(_Z[n] for n in (
    "gen_speed", "rotor_speed", "tower_fa_acceleration", "tower_ss_acceleration", "azimuth",
    "gen_power", "gen_torque", "aero_power", "lss_torque", "thrust", "tilt_moment",
    "yaw_moment"))


def _measurements(t: float, x: np.ndarray, z: np.ndarray) -> dict[str, Any]:
    # the scalars as Python floats through one tolist() (indexing the array once per signal
    # costs more than the whole conversion)
    v = z.tolist()
    gs, rs, fa, ss, az, gp, gt, ap, lss, th, tm, ym = _IDX
    return {"t": t, "gen_speed": v[gs], "rotor_speed": v[rs], "pitch": z[1:4].copy(),
            "flap_moment": z[10:13].copy(), "edge_moment": z[13:16].copy(),
            "tower_fa_acceleration": v[fa], "tower_ss_acceleration": v[ss], "azimuth": v[az],
            "gen_power": v[gp], "gen_torque": v[gt], "aero_power": v[ap], "lss_torque": v[lss],
            "thrust": v[th], "tilt_moment": v[tm], "yaw_moment": v[ym], "state": x.copy(),
            "outputs": z}


def _hub_wind(wind: Any, hub_height: float) -> Any:
    """t -> free wind speed at the hub [m/s] (the grid point nearest the hub, linear in t).

    A uniform time grid (every generated or ``.bts`` field) is read by index, O(1) a call;
    others by a binary search. The series is copied once, contiguous: ``np.interp`` on a strided
    column would copy the whole series at every call."""
    if isinstance(wind, linearize.GridWind):
        j = int(np.argmin(np.abs(wind.y)))
        k = int(np.argmin(np.abs(wind.z - hub_height)))
        series = np.ascontiguousarray(wind.u[:, j, k], dtype=float)
        tt = np.ascontiguousarray(wind.t, dtype=float)
        step = (tt[-1] - tt[0]) / (tt.size - 1) if tt.size > 1 else 0.0
        if step > 0 and np.allclose(np.diff(tt), step, rtol=1e-9, atol=1e-12):
            t0, last, vals = float(tt[0]), tt.size - 1, series.tolist()

            def uniform(t: float) -> float:
                s = min(max((t - t0) / step, 0.0), float(last))
                i = min(int(s), last - 1)
                a = s - i
                return (1.0 - a) * vals[i] + a * vals[i + 1]
            return uniform
        return lambda t: float(np.interp(t, tt, series))
    speed = float(getattr(wind, "speed", math.nan))
    return lambda t: speed


class _Loop:
    """The state of one closed-loop run: the recorded arrays, the held commands and the
    controller's signals. Private: :func:`simulate_closed_loop` is the interface."""

    def __init__(self, params: linearize.PlantParams, controller: Any, n: int, dt: float,
                 x0: np.ndarray, u0: np.ndarray, preview: Any, hub_wind: Any = None) -> None:
        self.params, self.controller, self.preview = params, controller, preview
        self.hub_wind = hub_wind
        self.n, self.dt = n, dt
        self.xs, self.us = np.empty((n + 1, len(linearize.STATE_NAMES))), np.empty((n + 1, 4))
        self.zs = np.empty((n + 1, 31))
        self.sig: dict[str, list[float]] = {}
        self._sig_keys: tuple[str, ...] = ()
        self._sig_rows: list[tuple[float, ...]] = []
        self.x = np.asarray(x0, float).copy()
        self.u = np.asarray(u0, float).copy()
        self.u_tq = float(self.u[3])
        self.clipped = 0
        self.grid_lost = False
        self.k_done = 0
        self.rate = params.turbine.generator.max_torque_rate * dt
        pa, gen = params.turbine.pitch_actuator, params.turbine.generator
        self._p_lo, self._p_hi = pa.min_pitch_rad - 1e-9, pa.max_pitch_rad + 1e-9
        self._q_lo, self._q_hi = gen.min_torque - 1e-6, gen.max_torque + 1e-6

    def command(self, t: float, z: np.ndarray) -> None:
        """Ask the controller for new commands and hold them."""
        meas = _measurements(t, self.x, z)
        if self.hub_wind is not None:
            meas["hub_wind_speed"] = self.hub_wind(t)
        if self.preview is not None:
            meas["preview"] = self.preview(t, float(self.x[_IX_AZ]), float(self.x[_IX_ROTOR]))
        pitch, tq = self.controller.step(t, meas)
        pitch = np.asarray(pitch, float)
        fin = math.isfinite
        if (pitch.shape != (3,) or not fin(tq)
                or not (fin(pitch[0]) and fin(pitch[1]) and fin(pitch[2]))):
            raise ValueError(f"controller returned pitch {pitch!r}, torque {tq!r} at "
                             f"t = {t:g} s: need 3 finite pitch angles [rad] and a "
                             f"finite torque [N m]")
        p1, p2, p3 = pitch.tolist()
        lo, hi = min(p1, p2, p3), max(p1, p2, p3)
        if not (self._p_lo <= lo and hi <= self._p_hi and self._q_lo <= tq <= self._q_hi):
            if self.clipped == 0:
                log.warning("controller command out of the actuator range at t = %g s "
                            "(pitch %s rad, torque %g N m): the plant clips it; the "
                            "count is in result.meta['commands_clipped']", t,
                            np.round(pitch, 4), tq)
            self.clipped += 1
        self.u[:3] = pitch
        self.u_tq = float(tq)
        if not self.grid_lost and getattr(self.controller, "grid_connected", True) is False:
            self.grid_lost = True
            log.info("grid lost at t = %g s: generator torque zero from here", t)

    def record_signals(self) -> None:
        """Append the controller's internal signals of this plant step (as rows while the
        names stay the same; :meth:`flush_signals` moves them into ``sig``)."""
        sig = getattr(self.controller, "signals", None)
        if not sig:
            return
        keys = tuple(sig)
        if keys != self._sig_keys:
            self.flush_signals()
            self._sig_keys = keys
        self._sig_rows.append(tuple(map(float, sig.values())))

    def flush_signals(self) -> None:
        """Move the recorded rows into ``sig`` (name -> values)."""
        if self._sig_rows:
            for name, col in zip(self._sig_keys, zip(*self._sig_rows)):
                self.sig.setdefault(name, []).extend(col)
            self._sig_rows = []

    def apply_torque_rate(self) -> None:
        """Move the applied torque toward the command by at most the generator's rate (after
        a grid loss: zero at once)."""
        if self.grid_lost:
            self.u[3] = 0.0
            return
        self.u[3] += min(max(self.u_tq - self.u[3], -self.rate), self.rate)

    def pinned(self) -> int:
        """Plant steps with the applied generator torque at its maximum."""
        top = self.params.turbine.generator.max_torque * (1.0 - 1e-6)
        return int(np.count_nonzero(self.us[:, 3] >= top))

    def result(self, k: int, meta: dict[str, Any]) -> ClosedLoopResult:
        """The first ``k`` samples as a result."""
        self.flush_signals()
        return ClosedLoopResult(t=self.dt * np.arange(k), x=self.xs[:k], u=self.us[:k],
                                z=self.zs[:k],
                                controller={s: np.array(v[:k]) for s, v in self.sig.items()},
                                meta=meta)


def _check_rates(duration: float, dt: float, controller_dt: float | None
                 ) -> tuple[int, int, float]:
    n = int(round(duration / dt))
    if n < 1:
        raise ValueError(f"duration ({duration!r} s) must be at least one step dt = {dt!r} s")
    cdt = dt if controller_dt is None else controller_dt
    ratio = int(round(cdt / dt))
    if ratio < 1 or abs(ratio * dt - cdt) > 1e-9:
        raise ValueError(f"controller_dt = {cdt!r} s must be a whole multiple of dt = {dt!r} s")
    return n, ratio, cdt


def _compiled_library(loop: _Loop, compiled: bool, ratio: int) -> Any:
    """The controller library's host, its arrays for the compiled loop and the supervisor
    around it (a library loaded in this process, alone or under a supervisor that is
    running; no preview of the harness's), else None."""
    ctl, sup = loop.controller, None
    if callable(getattr(ctl, "compiled_gate", None)):
        sup, ctl = ctl, getattr(ctl, "controller", None)
    offer = getattr(ctl, "compiled_library", None)
    if not compiled or loop.preview is not None or not callable(offer):
        return None
    gate = (math.inf, loop.n + 1) if sup is None else \
        sup.compiled_gate(loop.dt, ratio, loop.n)
    call = offer()
    if call is None or gate is None:
        return None
    lidar = getattr(ctl, "lidar", None) is not None
    return ctl, call, sup, np.array([gate[0], gate[1], -math.inf, 1.0 if lidar else 0.0])


def _run_library(loop: _Loop, stepper: linearize.PlantStepper, ratio: int, bar: Any,
                 host: tuple[Any, ...]) -> str:
    """:func:`_run` for a controller library loaded in this process
    (:func:`mpc_wt.simulation.compiled.run_library_steps`): the same steps in compiled blocks
    of 800; the library's warnings reported where they happen, its stop raised; the LIDAR's
    samples taken where they are due; the steps from a supervisor's trip on in Python."""
    from mpc_wt.simulation.compiled import run_library_steps

    ctl, call, sup, gate = host
    n, dt = loop.n, loop.dt
    loop.xs[0] = loop.x
    hub = (np.array([loop.hub_wind(k * dt) for k in range(n + 1)]) if loop.hub_wind is not None
           else np.zeros(n + 1))
    fn, swap, fail, bufs, rec, zi, lib = call
    sigs = np.zeros((n + 1, 4 + int(swap[61])))     # the host's signals, the logging channels
    held, counts = np.array([loop.u_tq]), np.zeros(2, dtype=np.int64)
    act = np.array([loop.rate, loop._p_lo, loop._p_hi, loop._q_lo, loop._q_hi])
    arrays = (loop.xs, loop.us, loop.zs, loop.u, held, fn, swap, fail, bufs, rec, zi, hub, lib,
              gate, sigs, act, counts)
    k = 0
    try:
        with ctl.quiet_calls():
            while k < n:
                block = min(k + 800 - k % 800, n)
                done, flag = run_library_steps(k, block, ratio, stepper, arrays)
                loop.k_done = done
                bar.update(done - k)
                k = done
                if flag == -5:                       # a warning at the step before
                    ctl.compiled_report((done - 1) * dt, call)
                elif flag in (-4, -6):               # a stop, demands not finite
                    ctl.compiled_report(done * dt, call, flag == -4)
                elif flag == -8:
                    psi = float(loop.xs[done, _IX_AZ])     # the plant's azimuth output
                    gate[2] = ctl.sample_lidar(done * dt,
                                               psi - 2.0 * math.pi *
                                               math.floor(psi / (2.0 * math.pi)),
                                               float(loop.xs[done, _IX_ROTOR]))
                elif flag == -7:
                    break
                elif flag >= 0:
                    raise _Diverged(done, flag, float(loop.xs[done, flag]))
        if k >= n:
            loop.us[n] = loop.u
            loop.zs[n] = stepper.outputs(n * dt, loop.xs[n], loop.u)
            sigs[n] = sigs[n - 1]
    finally:
        _adopt_library(loop, ctl, call, sup, sigs, counts, held, k if k < n else n + 1)
    if k >= n:
        return "compiled"
    _run(loop, stepper, ratio, bar, k)
    return "compiled+python"


def _adopt_library(loop: _Loop, ctl: Any, call: tuple[Any, ...], sup: Any, sigs: np.ndarray,
                   counts: np.ndarray, held: np.ndarray, kept: int) -> None:
    """The state a compiled library run left, taken by the loop, the host and the supervisor:
    the first ``kept`` signal rows (as lists when the Python loop goes on from there)."""
    loop.clipped, loop.u_tq = int(counts[0]), float(held[0])
    names = ctl.compiled_signals(call)
    if kept <= loop.n:
        loop.sig = {name: sigs[:kept, i].tolist() for i, name in enumerate(names)}
    else:
        loop.sig = {name: sigs[:, i] for i, name in enumerate(names)}
    ctl.adopt_compiled_state(call, sigs[max(min(loop.k_done, kept) - 1, 0), :len(names)])
    if sup is not None:
        sup.adopt_running()
        m = min(kept, loop.n + 1)
        loop.sig["supervisor_state"] = [0.0] * m
        loop.sig["supervisor_trip_time"] = [math.nan] * m
    if counts[0]:
        log.warning("controller command out of the actuator range at t = %g s: the plant "
                    "clips it; the count is in result.meta['commands_clipped']",
                    counts[1] * loop.dt)


def _advance(loop: _Loop, stepper: linearize.PlantStepper, ratio: int, bar: Any,
             compiled: bool) -> str:
    """The whole run: compiled where the controller is a library loaded in this process
    (:func:`_run_library`), else in Python (:func:`_run`); says which (``meta["loop"]``)."""
    call = _compiled_library(loop, compiled, ratio)
    if call is not None:
        return _run_library(loop, stepper, ratio, bar, call)
    _run(loop, stepper, ratio, bar)
    return "python"


def _run(loop: _Loop, stepper: linearize.PlantStepper, ratio: int, bar: Any,
         k0: int = 0) -> None:
    """Advance the loop over its steps from ``k0`` (where a compiled run handed over); raises :class:`_Diverged` at the first state
    outside the envelope (``loop.k_done`` then counts the samples kept).

    The plant writes each new state and the outputs straight into the record rows
    (:meth:`~linearize.PlantStepper.step_into`), so a step moves no arrays through Python."""
    n, dt = loop.n, loop.dt
    xs, us, zs = loop.xs, loop.us, loop.zs
    if k0 == 0:
        xs[0] = loop.x
    for k in range(k0, n + 1):
        t = k * dt
        x, z = xs[k], zs[k]
        loop.x = x
        us[k] = loop.u
        if k == n:
            z[:] = stepper.outputs(t, x, loop.u)
        else:
            bad = stepper.step_into(t, x, loop.u, xs[k + 1], z)
        if k % ratio == 0 and k < n:
            loop.command(t, z)
        loop.record_signals()
        if k == n:
            break
        loop.apply_torque_rate()
        loop.k_done = k + 1
        if bad >= 0:
            raise _Diverged(k + 1, bad, float(xs[k + 1, bad]))
        if k % 800 == 0:
            bar.update(min(800, n - bar.n))


#: The plant's integration step [s] (80 Hz: OpenFAST's step for the NREL 5-MW deck, 1/80 s).
PLANT_DT = 1.0 / 80.0


def simulate_closed_loop(params: linearize.PlantParams, controller: Any,
                         wind: linearize.SteadyWind | linearize.GridWind, duration: float, *,
                         x0: np.ndarray, u0: np.ndarray, dt: float = PLANT_DT,
                         controller_dt: float | None = None, progress: bool = False,
                         preview: LidarPreview | None = None,
                         meta: dict[str, Any] | None = None,
                         compiled: bool = True) -> ClosedLoopResult:
    """Run plant, wind and controller together.

    Parameters
    ----------
    params : PlantParams
        The plant (:func:`linearize.plant_params`).
    controller : Controller
        Anything with ``reset()`` and ``step(t, meas)``.
    wind : SteadyWind or GridWind
        The free wind; it must cover the rotor and the run.
    duration : float
        [s]
    x0, u0 : ndarray
        Initial state and inputs (e.g. a trim point's).
    dt : float
        Plant step [s] (default 1/80).
    controller_dt : float, optional
        Controller period [s], a multiple of ``dt`` (default ``dt``).
    progress : bool
        Show a progress bar.
    preview : LidarPreview, optional
        A simulated LIDAR; its preview is passed to the controller as ``meas["preview"]``
        (a :class:`lidar.Preview`).
    meta : dict, optional
        Configuration stored with the result.
    compiled : bool
        A controller library in this process (every shipped law; alone or under a
        supervisor, with or without a LIDAR) runs in a loop compiled with the plant (the same
        loop to the last bit; default); False: Python.

    Returns
    -------
    ClosedLoopResult
        ``round(duration / dt) + 1`` samples; ``meta`` gains ``dt``, ``controller_dt``,
        ``commands_clipped``, ``torque_pinned_steps`` (plant steps with the generator torque at
        its maximum), ``software_version`` and ``loop`` (``compiled``, ``python``, or
        ``compiled+python``: in Python from a supervisor's trip on).

    Raises
    ------
    SimulationDivergedError
        If a state leaves the physical envelope; names the time and the state and keeps the
        samples before in ``.partial``.
    ValueError
        If the controller returns a non-finite or wrongly shaped command (names the time).
    """
    n, ratio, cdt = _check_rates(duration, dt, controller_dt)
    stepper = linearize.PlantStepper(params, wind, dt, n * dt)
    controller.reset()
    if preview is not None:
        preview.reset()
    loop = _Loop(params, controller, n, dt, x0, u0, preview,
                 _hub_wind(wind, params.turbine.geometry.hub_height))
    bar = _progress_bar(n, f"simulate {(meta or {}).get('controller', 'closed loop')}",
                        progress)
    try:
        how = _advance(loop, stepper, ratio, bar, compiled)
    except _Diverged as d:
        raise SimulationDivergedError(
            f"simulation diverged at t = {d.k * dt:.4f} s: state "
            f"{linearize.STATE_NAMES[d.state]!r} = {d.value!r} "
            f"{linearize.STATE_UNITS[d.state]} left its envelope; the {loop.k_done} samples "
            f"before are kept in .partial", loop.result(loop.k_done, meta or {})) from None
    except ControllerLibraryError as err:
        raise ControllerLibraryError(f"{err} ({loop.k_done} samples before are kept in "
                                     f".partial)", loop.result(loop.k_done, meta or {})) from None
    finally:
        bar.close()
        _finalize(controller)
    return loop.result(n + 1, {**(meta or {}), "dt": dt,
                               "controller_dt": cdt, "commands_clipped": loop.clipped,
                               "torque_pinned_steps": loop.pinned(),
                               "software_version": __version__, "loop": how})


def _finalize(controller: Any) -> None:
    """A controller's last call (a Bladed-style library's), if it has one."""
    finalize = getattr(controller, "finalize", None)
    if callable(finalize):
        finalize()


#: whether this process has run a closed loop (its kernels compiled or loaded)
_WARM = [False]


class _Warming:
    """A progress bar that says the kernels are compiling, without an ETA, until its first
    update (the first block of steps, after which the kernels are compiled), then shows
    ``desc`` and the usual rate and ETA."""

    def __init__(self, bar: Any, desc: str) -> None:
        self._bar, self._desc = bar, desc

    def update(self, k: int) -> None:
        if not _WARM[0]:
            _WARM[0] = True
            self._bar.bar_format = None
            self._bar.set_description(self._desc, refresh=False)
        self._bar.update(k)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._bar, name)


def _progress_bar(n: int, desc: str, progress: bool) -> Any:
    """The run's progress bar: named by what runs; on a process's first run it says
    "loading kernels (compiled once per machine)" and shows no ETA until the first steps are
    done (every command is a new process: the kernels load from numba's cache, or compile the
    first time on a machine)."""
    if _WARM[0] or not progress:
        return tqdm(total=n, desc=desc, unit="step", disable=not progress, mininterval=0.5)
    bar = tqdm(total=n, desc="loading kernels (compiled once per machine)", unit="step",
               mininterval=0.5, bar_format="{desc}: {n_fmt}/{total_fmt} {unit} [{elapsed}]")
    return _Warming(bar, desc)


class _Diverged(Exception):
    def __init__(self, k: int, state: int, value: float) -> None:
        super().__init__(k, state, value)
        self.k, self.state, self.value = k, state, value

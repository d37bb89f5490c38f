"""Closed-loop simulation: plant + wind + controller, with results that keep everything.

The plant (:mod:`linearize`) is integrated with fixed-step RK4 at its rate (default 80 Hz); the
controller runs at its own rate and its commands are held between its steps (zero-order hold).
A controller is any object with ``reset()`` and ``step(t, measurements) -> (pitch_ref (3,),
gen_torque_ref)``; it may expose a dict ``signals`` of internal signals, recorded every step.

Measurements given to the controller: ``t``, ``gen_speed``, ``rotor_speed``, ``pitch`` (3,),
``flap_moment`` (3,), ``edge_moment`` (3,), ``tower_fa_acceleration``,
``tower_ss_acceleration``, ``azimuth``, ``gen_power``; ``state``, the full plant state
(:data:`linearize.STATE_NAMES`), for full-state-information designs (Madsen's MPC); and
``preview`` when a LIDAR preview is attached.
"""
from __future__ import annotations

import json
import logging
import math
import os
import uuid
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

import numpy as np
from tqdm import tqdm

import linearize
from linearize.plant import _bad_state, _rk4, _state_limits

from . import __version__

__all__ = ["Controller", "ClosedLoopResult", "ResultFileError", "LidarPreview",
           "simulate_closed_loop"]

log = logging.getLogger(__name__)
SCHEMA_VERSION = 1
_Z = {n: i for i, n in enumerate(linearize.OUTPUT_NAMES)}


class Controller(Protocol):
    """What the harness needs from a controller."""

    def reset(self) -> None: ...

    def step(self, t: float, meas: dict[str, Any]) -> tuple[np.ndarray, float]: ...


class ResultFileError(ValueError):
    """A result file is missing, truncated, of another schema, or misses a channel."""


@dataclass(frozen=True)
class ClosedLoopResult:
    """Everything a closed-loop run produced.

    Parameters
    ----------
    t : (n_t,) ndarray
        [s]
    x : (n_t, n_x) ndarray
        Plant states (:data:`linearize.STATE_NAMES`).
    u : (n_t, n_u) ndarray
        Applied inputs (after the plant's torque rate limit).
    z : (n_t, n_z) ndarray
        Plant outputs (:data:`linearize.OUTPUT_NAMES`).
    controller : dict of str to (n_t,) ndarray
        The controller's internal signals.
    meta : dict
        Configuration and software version.
    """

    t: np.ndarray
    x: np.ndarray
    u: np.ndarray
    z: np.ndarray
    controller: dict[str, np.ndarray] = field(default_factory=dict)
    meta: dict[str, Any] = field(default_factory=dict)

    def channel(self, name: str) -> np.ndarray:
        """A time series by name: output, state, input, controller signal, or the derived
        ``shaft_bending_blade1``: the rotating low-speed-shaft bending moment in the direction
        of blade 1 from the blades' flap moments, M_1 - (M_2 + M_3) / 2 [N m] (rotor weight
        and hub inertia left out)."""
        if name == "shaft_bending_blade1":
            f = self.z[:, _Z["flap_moment_1"]:_Z["flap_moment_3"] + 1]
            return f[:, 0] - 0.5 * (f[:, 1] + f[:, 2])
        if name in _Z:
            return self.z[:, _Z[name]]
        if name in linearize.STATE_NAMES:
            return self.x[:, linearize.STATE_NAMES.index(name)]
        if name in linearize.INPUT_NAMES:
            return self.u[:, linearize.INPUT_NAMES.index(name)]
        if name in self.controller:
            return self.controller[name]
        raise KeyError(f"no channel {name!r}; channels are {self.channels()}")

    def channels(self) -> list[str]:
        """All channel names."""
        return (list(linearize.OUTPUT_NAMES) + [n for n in linearize.STATE_NAMES
                                                if n not in _Z]
                + list(linearize.INPUT_NAMES) + ["shaft_bending_blade1"]
                + list(self.controller))

    def save(self, path: str | Path) -> Path:
        """Write a self-describing netCDF file (xarray; openable without mpc-wt) with units,
        the configuration and the software version; written to a temporary file, then renamed."""
        import xarray as xr

        path = Path(path)
        data = {}
        units = dict(zip(linearize.OUTPUT_NAMES, linearize.OUTPUT_UNITS))
        units.update(zip(linearize.STATE_NAMES, linearize.STATE_UNITS))
        units.update(zip(linearize.INPUT_NAMES, linearize.INPUT_UNITS))
        for n in self.channels():
            key = n if n not in data else f"{n}_state"
            data[key] = xr.Variable("time", self.channel(n),
                                    {"units": units.get(n, ""),
                                     "source": "controller" if n in self.controller else "plant"})
        ds = xr.Dataset(data, coords={"time": ("time", self.t, {"units": "s"})},
                        attrs={"schema_version": SCHEMA_VERSION, "software": "mpc-wt",
                               "software_version": __version__,
                               "meta_json": json.dumps(self.meta)})
        # a name of this writer's own: two writers of one case (a retried task) never share it
        tmp = path.with_name(f".{path.name}.{os.getpid()}.{uuid.uuid4().hex[:8]}.tmp")
        try:
            ds.to_netcdf(tmp, engine="scipy")
            tmp.replace(path)
        finally:
            tmp.unlink(missing_ok=True)
        return path

    @classmethod
    def load(cls, path: str | Path) -> "ClosedLoopResult":
        """Read a result written by :meth:`save`.

        Raises
        ------
        ResultFileError
            If the file is missing, truncated, of another schema or misses plant channels.
        """
        import xarray as xr

        path = Path(path)
        if not path.is_file():
            raise ResultFileError(f"{path}: file not found")
        try:
            with xr.open_dataset(path, engine="scipy") as ds:
                ds = ds.load()
        except Exception as err:  # noqa: BLE001 - any reader failure means a broken file
            raise ResultFileError(f"{path}: not a readable result file ({err})") from err
        ver = ds.attrs.get("schema_version")
        if isinstance(ver, (np.integer, int)):
            ver = int(ver)
        if ver != SCHEMA_VERSION:
            raise ResultFileError(f"{path}: schema_version must be {SCHEMA_VERSION}, got {ver!r} "
                                  f"(written by {ds.attrs.get('software_version', '?')})")
        missing = [n for n in linearize.OUTPUT_NAMES if n not in ds]
        if missing:
            raise ResultFileError(f"{path}: missing channels {missing}")
        z = np.column_stack([ds[n].values for n in linearize.OUTPUT_NAMES])
        x = np.column_stack([ds[n if n not in _Z else n].values for n in linearize.STATE_NAMES])
        u = np.column_stack([ds[n].values for n in linearize.INPUT_NAMES])
        ctrl = {n: ds[n].values for n in ds.data_vars
                if ds[n].attrs.get("source") == "controller"}
        return cls(t=ds["time"].values, x=x, u=u, z=z, controller=ctrl,
                   meta=json.loads(ds.attrs.get("meta_json", "{}")))


class LidarPreview:
    """A simulated LIDAR in the loop: measures the wind field at the rotor's current azimuth
    and speed at every controller step and serves the per-blade preview of the next
    ``horizon`` steps from the measurements taken T_p earlier (:func:`lidar.preview`).

    Parameters
    ----------
    lidar_model : lidar.CWLidar
    field : lidar.WindField
        The same field the plant meets (as its GridWind).
    horizon : int
        Preview steps H_p (default 15).
    dt : float
        Controller step [s] (default 0.1).
    """

    def __init__(self, lidar_model: Any, field: Any, horizon: int = 15, dt: float = 0.1) -> None:
        self.lidar = lidar_model
        self.field = field
        self.horizon = int(horizon)
        self.dt = float(dt)
        self.reset()

    def reset(self) -> None:
        """Forget the measurement history."""
        self._t: list[float] = []
        self._u: list[np.ndarray] = []
        self._az: list[np.ndarray] = []

    def __call__(self, t: float, azimuth_rad: float, rotor_speed_rad_s: float) -> Any:
        import lidar

        m = self.lidar.measure(self.field, np.array([t]), np.array([azimuth_rad]),
                               rotor_speed_rad_s)
        self._t.append(t)
        self._u.append(m.u_hat[0])
        self._az.append(m.beam_azimuth_rad[0])
        hist = lidar.LidarMeasurement(t=np.array(self._t), los=np.array(self._u) * 0.0,
                                      u_hat=np.array(self._u),
                                      beam_azimuth_rad=np.array(self._az),
                                      preview_time=m.preview_time, radius=m.radius)
        return lidar.preview(hist, t, self.horizon, self.dt)


class SimulationDivergedError(RuntimeError):
    """A closed-loop run left the physical envelope; ``partial`` keeps what was simulated."""

    def __init__(self, message: str, partial: ClosedLoopResult) -> None:
        super().__init__(message)
        self.partial = partial


def _measurements(t: float, x: np.ndarray, z: np.ndarray) -> dict[str, Any]:
    return {"t": t, "gen_speed": z[_Z["gen_speed"]], "rotor_speed": z[_Z["rotor_speed"]],
            "pitch": z[1:4].copy(), "flap_moment": z[10:13].copy(),
            "edge_moment": z[13:16].copy(),
            "tower_fa_acceleration": z[_Z["tower_fa_acceleration"]],
            "tower_ss_acceleration": z[_Z["tower_ss_acceleration"]],
            "azimuth": z[_Z["azimuth"]], "gen_power": z[_Z["gen_power"]], "state": x.copy()}


def simulate_closed_loop(params: linearize.PlantParams, controller: Any,
                         wind: linearize.SteadyWind | linearize.GridWind, duration: float, *,
                         x0: np.ndarray, u0: np.ndarray, dt: float = 1.0 / 80.0,
                         controller_dt: float | None = None, progress: bool = False,
                         preview: LidarPreview | None = None,
                         meta: dict[str, Any] | None = None) -> ClosedLoopResult:
    """Run plant, wind and controller together.

    Parameters
    ----------
    params : PlantParams
    controller : Controller
    wind : SteadyWind or GridWind
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

    Raises
    ------
    SimulationDivergedError
        If a state leaves the physical envelope; names the time and the state and keeps the
        samples before in ``.partial``.
    ValueError
        If the controller returns a non-finite or wrongly shaped command (names the time).
    """
    n = int(round(duration / dt))
    if n < 1:
        raise ValueError(f"duration ({duration!r} s) must be at least one step dt = {dt!r} s")
    cdt = dt if controller_dt is None else controller_dt
    ratio = int(round(cdt / dt))
    if ratio < 1 or abs(ratio * dt - cdt) > 1e-9:
        raise ValueError(f"controller_dt = {cdt!r} s must be a whole multiple of dt = {dt!r} s")
    wind.check_covers(params, n * dt)
    kind, wpar, grid = wind._kernel_args()
    pk = params.pack
    lim = _state_limits(params)
    controller.reset()
    if preview is not None:
        preview.reset()
    xs = np.empty((n + 1, 17))
    us = np.empty((n + 1, 4))
    zs = np.empty((n + 1, 31))
    sig: dict[str, list[float]] = {}
    x = np.asarray(x0, float).copy()
    u = np.asarray(u0, float).copy()
    hint = np.full((4, 3, pk.r.size), np.nan)
    dphi = np.zeros((3, pk.r.size))
    rate = params.turbine.generator.max_torque_rate * dt
    applied_tq = u[3]
    clipped = 0
    k_done = 0
    bar = tqdm(total=n, desc="simulate", unit="step", disable=not progress, mininterval=0.5)
    try:
        for k in range(n + 1):
            t = k * dt
            if k == n:
                from linearize.plant import _eval, _sample_wind

                w = _sample_wind(t, x[16], pk, kind, wpar, grid)
                z = _eval(x, u, w, pk, hint, 0)[1]
            else:
                xn, z, hint, dphi = _rk4(t, x, u, dt, pk, kind, wpar, grid, hint, dphi)
            xs[k], us[k], zs[k] = x, u, z
            if k % ratio == 0 and k < n:
                meas = _measurements(t, x, z)
                if preview is not None:
                    meas["preview"] = preview(t, float(x[16]), float(x[2]))
                pitch, tq = controller.step(t, meas)
                pitch = np.asarray(pitch, float)
                if pitch.shape != (3,) or not np.all(np.isfinite(pitch)) or not math.isfinite(tq):
                    raise ValueError(f"controller returned pitch {pitch!r}, torque {tq!r} at "
                                     f"t = {t:g} s: need 3 finite pitch angles [rad] and a "
                                     f"finite torque [N m]")
                pa = params.turbine.pitch_actuator
                gen = params.turbine.generator
                if (pitch.min() < pa.min_pitch_rad - 1e-9 or pitch.max() > pa.max_pitch_rad + 1e-9
                        or not gen.min_torque - 1e-6 <= tq <= gen.max_torque + 1e-6):
                    if clipped == 0:
                        log.warning("controller command out of the actuator range at t = %g s "
                                    "(pitch %s rad, torque %g N m): the plant clips it; the "
                                    "count is in result.meta['commands_clipped']", t,
                                    np.round(pitch, 4), tq)
                    clipped += 1
                u[:3] = pitch
                u_tq = float(tq)
            for name, val in getattr(controller, "signals", {}).items():
                sig.setdefault(name, []).append(float(val))
            if k == n:
                break
            applied_tq += min(max(u_tq - applied_tq, -rate), rate)
            u[3] = applied_tq
            bad = _bad_state(xn, lim)
            if bad >= 0:
                k_done = k + 1
                raise _Diverged(k + 1, bad, float(xn[bad]))
            x = xn
            k_done = k + 1
            if k % 800 == 0:
                bar.update(min(800, n - bar.n))
    except _Diverged as d:
        part = ClosedLoopResult(t=dt * np.arange(k_done), x=xs[:k_done], u=us[:k_done],
                                z=zs[:k_done], controller={k: np.array(v[:k_done])
                                                           for k, v in sig.items()},
                                meta=meta or {})
        raise SimulationDivergedError(
            f"simulation diverged at t = {d.k * dt:.4f} s: state "
            f"{linearize.STATE_NAMES[d.state]!r} = {d.value!r} "
            f"{linearize.STATE_UNITS[d.state]} left its envelope; the {k_done} samples before "
            f"are kept in .partial", part) from None
    finally:
        bar.close()
    ctrl = {k: np.array(v[:n + 1]) for k, v in sig.items()}
    return ClosedLoopResult(t=dt * np.arange(n + 1), x=xs, u=us, z=zs, controller=ctrl,
                            meta={**(meta or {}), "dt": dt, "controller_dt": cdt,
                                  "commands_clipped": clipped,
                                  "software_version": __version__})


class _Diverged(Exception):
    def __init__(self, k: int, state: int, value: float) -> None:
        self.k, self.state, self.value = k, state, value

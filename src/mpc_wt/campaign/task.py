"""The campaign's unit of work: one case in, one result file and its metrics out.

:func:`run_case` is a pure function of its arguments (the case's plain data and the campaign
directory): it never touches the index and never raises for a case that fails -- it returns
the error with its traceback -- so any engine (Dask, a process pool, a plain loop) can run it,
retry it after a worker died, or run it twice without harm: the file is written to a name of
the writer's own and renamed over the final name.
"""
from __future__ import annotations

import functools
import math
import os
import socket
import time
import traceback
from pathlib import Path
from typing import Any, Sequence

import numpy as np

import lidar
from mpc_wt.assessment.ultimate import case_extremes
from mpc_wt.simulation.scenario import FieldMemo, Scenario

__all__ = ["run_case", "case_metrics", "case_file", "actuator_limit_metrics",
           "load_case_turbine"]

#: A pitch rate at or above this fraction of the actuator's limit counts as at the limit.
RATE_LIMIT_FRACTION = 0.98

#: the turbulence generator's sampler, kept by a worker process from one case to the next (a
#: worker's next case is often the next seed of the same wind; the fields are the same with or
#: without it)
WORKER_SAMPLERS = lidar.SamplerCache()

#: the fields of a worker's last scenarios: the runner hands a worker the controllers of one
#: scenario one after another, and they meet the same field (the same with or without it)
WORKER_FIELDS = FieldMemo()


def case_file(case_id: str) -> str:
    """The result file of a case, relative to the campaign directory.

    Parameters
    ----------
    case_id : str
        The case.

    Returns
    -------
    str
        ``cases/CASE_ID.nc``.

    Raises
    ------
    ValueError
        If the case id is not one file name (a separator, ``..``, or a leading dot): its file
        would lie outside ``cases/``.
    """
    if (not case_id or case_id.startswith(".") or "/" in case_id or "\\" in case_id
            or "\0" in case_id or Path(case_id).name != case_id):
        raise ValueError(f"case id {case_id!r} is not a file name: its result would lie "
                         f"outside the campaign's cases/ folder")
    return f"cases/{case_id}.nc"


@functools.lru_cache(maxsize=8)
def load_case_turbine(ref: str) -> Any:
    """A campaign's turbine, loaded once per process.

    Parameters
    ----------
    ref : str
        Packaged name or resolved path (:attr:`Case.turbine`).

    Returns
    -------
    linearize.Turbine
    """
    import linearize

    return linearize.load_turbine(ref)


#: The channels whose extremes every case records beside its load channels: what a grid, a
#: generator and the protection bound (the sign-off's largest rotor speed, power and torque).
PEAKS = ("rotor_speed", "gen_power", "gen_torque")


def case_metrics(t: np.ndarray, cols: dict[str, np.ndarray], channels: dict[str, float],
                 transient: float, convention: str = "range-1hz", *,
                 extremes_of: Sequence[str] = ()) -> dict[str, Any]:
    """The per-case numbers a campaign aggregates, after discarding ``transient`` [s]: DEL per
    channel (Woehler exponent of the spec, 1 Hz equivalent cycles), mean and std of power,
    energy, CS1-CS5 (tower-base fore-aft moment vs electrical power, Do et al. eqs 21-26), pitch
    duty, rotor/generator speed statistics and the blade-1 flap 1P/3P/6P content.


    Parameters
    ----------
    t : (n_t,) ndarray
        Time [s].
    cols : dict of str to (n_t,) ndarray
        The run's channels.
    channels : dict of str to float
        Channel -> Woehler exponent.
    transient : float
        Discarded start [s].
    convention : str
        The DEL convention (:data:`mpc_wt.assessment.fatigue.DEL_CONVENTIONS`).
    extremes_of : sequence of str
        Further channels whose extremes are recorded (the ultimate loads' channels).

    Returns
    -------
    dict
        JSON-safe metrics (:func:`mpc_wt.assessment.series.assess_series` plus rotor-speed statistics and
        ``extremes``: each channel's and :data:`PEAKS`' maximum and minimum and their times,
        :func:`mpc_wt.assessment.ultimate.case_extremes`); with a supervisor in the loop
        ``supervisor_state`` (the largest :data:`mpc_wt.controllers.supervisor.STATES` code after the
        transient) and ``supervisor_trip_s`` (when it tripped, even within the transient); for
        an MPC ``qp_fallback_s``, the time its commands came from the QP fallback [s].

    Raises
    ------
    ValueError
        If less than 10 s remain after the transient, or a series holds NaN.
    """
    from mpc_wt.assessment.series import assess_series

    k = t >= t[0] + transient
    if np.count_nonzero(k) < 2 or t[k][-1] - t[k][0] < 10.0:
        raise ValueError(f"transient {transient:g} s leaves {t[-1] - t[0] - transient:g} s of "
                         f"a {t[-1] - t[0]:g} s run; allowed: at least 10 s")
    sub = {n: np.asarray(c)[k] for n, c in cols.items()}
    for n in channels:
        if n in sub and not np.all(np.isfinite(sub[n])):
            raise ValueError(f"channel {n!r} holds NaN or inf")
    out = assess_series(t[k], sub, channels, convention=convention)
    # ultimate loads: each channel's extremes and when
    out["extremes"] = case_extremes(t[k], sub, [
        n for n in dict.fromkeys((*channels, *extremes_of, *PEAKS)) if n in sub])
    if "rotor_speed" in sub:
        out["rotor_speed_mean_rad_s"] = float(sub["rotor_speed"].mean())
        out["rotor_speed_std_rad_s"] = float(sub["rotor_speed"].std())
        out["rotor_speed_max_rad_s"] = float(sub["rotor_speed"].max())
    if "tower_base_fa_moment" in sub:
        out["tower_base_fa_mean_Nm"] = float(sub["tower_base_fa_moment"].mean())
    if "supervisor_state" in sub:       # the stop sequence (mpc_wt.controllers.supervisor.STATES codes)
        out["supervisor_state"] = int(np.max(sub["supervisor_state"]))
        # when it tripped, also if that was in the discarded transient (the signal holds it)
        trip = float(np.asarray(cols.get("supervisor_trip_time", [math.nan]))[-1])
        out["supervisor_trip_s"] = trip if math.isfinite(trip) else None
    if "qp_fallback" in sub:            # the MPC's QP fallbacks: seconds under a fallback
        dt = float(np.median(np.diff(t[k])))
        out["qp_fallback_s"] = float(np.count_nonzero(sub["qp_fallback"] > 0) * dt)
    for key in ("power_ref",):
        if key in sub:
            out[f"{key}_mean_W"] = float(np.mean(sub[key]))
    return _plain(out)


def actuator_limit_metrics(t: np.ndarray, cols: dict[str, np.ndarray], max_rate_rad_s: float,
                           transient: float) -> dict[str, Any]:
    """How often the pitch actuator ran at its rate limit, after ``transient`` [s].

    Parameters
    ----------
    t : (n_t,) ndarray
        Time [s].
    cols : dict
        The run's channels (``pitch_1..3`` [rad]).
    max_rate_rad_s : float
        The actuator's rate limit [rad/s].
    transient : float
        Discarded start [s].

    Returns
    -------
    dict
        ``pitch_rate_max_degps`` (largest rate of any blade), ``pitch_rate_limit_hits`` (times
        any blade reached :data:`RATE_LIMIT_FRACTION` of the limit: rising edges) and
        ``pitch_rate_limit_s`` (time spent there); empty without pitch channels.
    """
    k = t >= t[0] + transient
    blades = [np.asarray(cols[n])[k] for n in ("pitch_1", "pitch_2", "pitch_3") if n in cols]
    if not blades or np.count_nonzero(k) < 3:
        return {}
    dt = float(np.median(np.diff(t[k])))
    rate = np.abs(np.diff(np.column_stack(blades), axis=0)) / dt
    at = (rate >= RATE_LIMIT_FRACTION * max_rate_rad_s).any(axis=1)
    hits = int(at[0]) + int(np.count_nonzero(at[1:] & ~at[:-1]))
    return {"pitch_rate_max_degps": float(np.degrees(rate.max())),
            "pitch_rate_limit_hits": hits, "pitch_rate_limit_s": float(at.sum() * dt)}


def _plain(obj: Any) -> Any:
    """JSON-safe copy: numpy scalars to float, non-finite floats to None."""
    if isinstance(obj, dict):
        return {str(k): _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    if isinstance(obj, (np.floating, float)):
        return float(obj) if math.isfinite(obj) else None
    if isinstance(obj, np.integer):
        return int(obj)
    return obj


def run_case(case: dict[str, Any], root: str) -> dict[str, Any]:
    """Simulate one case (or reuse its finished file) and assess it.

    Parameters
    ----------
    case : dict
        :meth:`mpc_wt.campaign.spec.Case.to_dict`.
    root : str
        The campaign directory (shared by client and workers).

    Returns
    -------
    dict
        ``status`` "done" with ``file`` (relative), ``metrics``, ``reused`` (the file already
        held this case's simulation: only the assessment ran) and the file's ``sha256``, or
        "failed" with ``error`` and
        ``traceback``; both with ``wall_s``, ``worker`` (host:pid) and ``software_version``.
    """
    from mpc_wt._version import __version__
    from mpc_wt.errors import ResultFileError
    from mpc_wt.simulation.loop import SimulationDivergedError
    from mpc_wt.simulation.results import ClosedLoopResult

    t0 = time.perf_counter()
    base = {"case_id": case["case_id"], "worker": f"{socket.gethostname()}:{os.getpid()}",
            "software_version": __version__}
    rel = case_file(case["case_id"])
    path = Path(root) / rel
    try:
        res = None
        reused = False
        if path.is_file():
            try:
                old = ClosedLoopResult.load(path)
                made = old.meta.get("campaign_case", {})
                if (made.get("case_hash") == case["case_hash"]
                        and made.get("design_hash") == case.get("design_hash")):
                    res, reused = old, True
            except ResultFileError:
                res = None
        if res is None:
            from mpc_wt.registry.registry import load_plugins
            from mpc_wt.run import run_controller

            load_plugins(case.get("plugins", ()), case.get("plugin_folder"))
            try:
                res = run_controller(load_case_turbine(case["turbine"]), case["run_name"],
                                     Scenario(**case["scenario"]), case["options"],
                                     supervisor=case.get("supervisor"),
                                     samplers=WORKER_SAMPLERS, fields=WORKER_FIELDS,
                                     plant=case.get("plant"))
            except SimulationDivergedError as err:
                if getattr(err, "partial", None) is not None:
                    err.partial.meta["campaign_case"] = {"case_id": case["case_id"],
                                                         "case_hash": case["case_hash"],
                                                         "partial": True}
                    err.partial.save(path.with_name(f"{case['case_id']}.partial.nc"))
                raise
            res.meta["campaign_case"] = {"case_id": case["case_id"],
                                         "case_hash": case["case_hash"],
                                         "design_hash": case.get("design_hash"),
                                         "worker": base["worker"]}
            path.parent.mkdir(parents=True, exist_ok=True)
            res.save(path)
        cols = {n: res.channel(n) for n in res.channels()}
        metrics = case_metrics(res.t, cols, case["channels"], case["transient"],
                               case.get("del_convention", "range-1hz"),
                               extremes_of=case.get("extremes_of", ()))
        metrics.update(_plain(actuator_limit_metrics(
            res.t, cols, load_case_turbine(case["turbine"]).pitch_actuator.max_rate_rad_s,
            case["transient"])))
        from mpc_wt.campaign.checksum import file_sha256

        return {**base, "status": "done", "file": rel, "metrics": metrics, "reused": reused,
                "sha256": file_sha256(path), "wall_s": time.perf_counter() - t0}
    except Exception as err:  # noqa: BLE001 - every failure is recorded, none stops others
        return {**base, "status": "failed", "error": f"{type(err).__name__}: {err}",
                "traceback": traceback.format_exc(), "wall_s": time.perf_counter() - t0}

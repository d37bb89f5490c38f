"""One run's summary and comparisons: every channel's damage-equivalent loads, CS1-CS5, pitch
duty, power and the blade-1 flap moment's harmonics (:func:`assess_series`), the changes
between two runs (:func:`reductions`) and lifetime comparisons over wind bins.

Pure functions on arrays, built on :mod:`mpc_wt.assessment.fatigue` and
:mod:`mpc_wt.assessment.performance`.

References
----------
ASTM E1049-85 (2017), Standard practices for cycle counting in fatigue analysis, sec. 5.4.4.
Do et al. (2020), Wind Energy, eqs 19-26 (Miner, DEL, CS1-CS5).
Clemens et al., DEL assessment of active power control, eqs 12-18 (lifetime DEL).
Pettas and Cheng (2018), eq 1 (lifetime extension).
"""
from __future__ import annotations

import math
from typing import Any, Mapping, Sequence

import numpy as np

from mpc_wt.assessment.fatigue import (
    WOEHLER_EXPONENTS,
    cycle_count,
    lifetime_del,
    lifetime_extension,
)
from mpc_wt.assessment.performance import (
    cs_measures,
    energy_Wh,
    harmonic_psd,
    pct_change,
    pitch_duty,
)

__all__ = ["DEFAULT_CHANNELS", "TIME_STEP_TOLERANCE", "assess_series", "check_time", "reductions",
           "lifetime_comparison"]


#: Load channels and their default Woehler exponents (10 composite blades, 4 steel elsewhere).
DEFAULT_CHANNELS = {"flap_moment_1": 10.0, "flap_moment_2": 10.0, "flap_moment_3": 10.0,
                    "edge_moment_1": 10.0, "edge_moment_2": 10.0, "edge_moment_3": 10.0,
                    "tower_base_fa_moment": 4.0, "tower_base_ss_moment": 4.0,
                    "lss_torque": 4.0, "tilt_moment": 4.0, "yaw_moment": 4.0,
                    "shaft_bending_blade1": 4.0}


#: The start of a run the statistics leave out by default [s]: the controller's and the
#: plant's start-up transient (at most a tenth of the run, for short runs).
START_TRANSIENT_S = 60.0


def default_window_start(t0: float, t_end: float) -> float:
    """Where a run's statistics begin by default: :data:`START_TRANSIENT_S` after its start,
    or a tenth of its length if that is shorter (``mpcwt run``'s table, ``comparison.json``
    and ``mpcwt assess`` alike).

    Parameters
    ----------
    t0, t_end : float
        The run's first and last time [s].

    Returns
    -------
    float
        [s].
    """
    return t0 + min(START_TRANSIENT_S, 0.1 * (t_end - t0))


#: how far a time step may differ from the run's median step, relative to it: a text time
#: column rounded to its last digit (0.0062, 0.0063 for 160 Hz) stays within it, a lost sample
#: (a step of 2x) or a gap does not
TIME_STEP_TOLERANCE = 0.1


def check_time(t: Any) -> np.ndarray:
    """A run's time vector: 1-D, finite, at least 2 samples, strictly increasing and uniform
    (every step within :data:`TIME_STEP_TOLERANCE` of the median step), as the rainflow
    counts, spectra and energies assume; or an error that says where it is not.

    Parameters
    ----------
    t : array_like
        Time [s].

    Returns
    -------
    (n_t,) ndarray

    Raises
    ------
    ValueError
        Naming the first duplicate, backward step or gap, with its time.
    """
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size < 2:
        raise ValueError(f"the time must be 1-D with at least 2 samples, got shape {t.shape}")
    if not np.all(np.isfinite(t)):
        i = int(np.argmax(~np.isfinite(t)))
        raise ValueError(f"the time is {float(t[i])!r} at sample {i}")
    d = np.diff(t)
    if np.any(d <= 0):
        i = int(np.argmax(d <= 0))
        what = "repeats" if d[i] == 0 else "goes back"
        raise ValueError(f"the time {what} at sample {i + 1}: {t[i]:g} s then {t[i + 1]:g} s; "
                         f"it must increase strictly")
    step = float(np.median(d))
    off = np.abs(d - step) > TIME_STEP_TOLERANCE * step
    if off.any():
        i = int(np.argmax(off))
        raise ValueError(f"the time step is {d[i]:g} s from t = {t[i]:g} s, the run's step "
                         f"{step:g} s: a gap or an uneven step (allowed within "
                         f"{TIME_STEP_TOLERANCE:.0%}); resample the run to a uniform step")
    return t


def assess_series(t: np.ndarray, cols: dict[str, np.ndarray],
                  channels: dict[str, float] | None = None,
                  m_override: float | None = None,
                  convention: str = "range-1hz") -> dict[str, Any]:
    """DEL per channel, CS1-CS5 (tower-base fore-aft moment vs power), pitch duty, power std,
    energy and the 1P/3P/6P content of the blade-1 flap moment, for one run.

    Parameters
    ----------
    t : (n_t,) ndarray
        Time [s].
    cols : dict of str to (n_t,) ndarray
        Channels by our names (SI).
    channels : dict of str to float, optional
        Channel -> Woehler exponent (default: the :data:`DEFAULT_CHANNELS` present).
    m_override : float, optional
        One Woehler exponent for every channel.
    convention : str
        The DEL convention (:data:`DEL_CONVENTIONS`; default ``range-1hz``).

    Returns
    -------
    dict
        ``duration_s``, ``del_convention``, ``channels`` {name: {del, m, n_eq, del_at_m}}
        (``del_at_m``: the DEL at each exponent of :data:`WOEHLER_EXPONENTS` and the channel's,
        keyed ``f"{m:g}"``, from the channel's own cycles), and when the signals are there
        ``power_mean_W``, ``power_std_W``, ``energy_Wh``, ``cs1``..``cs5``, the pitch duty,
        ``gen_speed_std_rad_s``, ``gen_torque_std_Nm``, ``flap_1_harmonics``.

    Raises
    ------
    KeyError
        Naming a channel that is not among the columns.
    ValueError
        If the time is not uniform and increasing (:func:`check_time`).
    """
    t = check_time(t)
    chans = dict(channels or {k: v for k, v in DEFAULT_CHANNELS.items() if k in cols})
    missing = [c for c in chans if c not in cols]
    if missing:
        raise KeyError(f"no channel {missing[0]!r}; channels are {sorted(cols)}")
    dt = float(np.median(np.diff(t)))
    duration = float(t[-1] - t[0])
    out: dict[str, Any] = {"duration_s": duration, "del_convention": convention,
                           "channels": {}}
    for name, m in chans.items():
        mm = m_override if m_override is not None else m
        cc = cycle_count(cols[name], convention=convention, duration=duration)
        out["channels"][name] = {"del": cc.del_at(mm), "m": mm, "n_eq": cc.n_eq,
                                 "del_at_m": {f"{w:g}": cc.del_at(w)
                                              for w in sorted({*WOEHLER_EXPONENTS, mm})}}
    if "gen_power" in cols:
        p = cols["gen_power"]
        out["power_mean_W"] = float(p.mean())
        out["power_std_W"] = float(p.std())
        out["energy_Wh"] = energy_Wh(p, dt)
        if "tower_base_fa_moment" in cols:
            cs = cs_measures(cols["tower_base_fa_moment"], p)
            out.update({f"cs{i}": getattr(cs, f"cs{i}") for i in range(1, 6)})
    pitch = [cols[f"pitch_{i}"] for i in (1, 2, 3) if f"pitch_{i}" in cols]
    if pitch:
        out.update(pitch_duty(np.column_stack(pitch), dt))
    if "gen_speed" in cols:
        out["gen_speed_std_rad_s"] = float(cols["gen_speed"].std())
    if "gen_torque" in cols:
        out["gen_torque_std_Nm"] = float(cols["gen_torque"].std())
    if "rotor_speed" in cols and "flap_moment_1" in cols:
        frot = float(cols["rotor_speed"].mean()) / (2 * math.pi)
        out["flap_1_harmonics"] = {f"{n}P": v for n, v in
                                   harmonic_psd(cols["flap_moment_1"], 1 / dt, frot).items()}
    return out


def reductions(base: dict[str, Any], other: dict[str, Any]) -> dict[str, Any]:
    """Change of ``other`` against ``base`` in percent.

    Parameters
    ----------
    base, other : dict
        Two :func:`assess_series` results.

    Returns
    -------
    dict
        ``del_change_pct`` per channel, ``flap_1_harmonic_change_pct`` (1P/3P/6P content of
        the blade-1 flap moment, Madsen sec. IV), and ``{key}_change_pct`` for the power and
        generator-speed std, pitch travel, CS1 and CS2 [%].
    """
    out: dict[str, Any] = {"del_change_pct": {c: pct_change(base["channels"][c]["del"], d["del"])
                                               for c, d in other["channels"].items()
                                               if c in base["channels"]}}
    if "flap_1_harmonics" in base and "flap_1_harmonics" in other:
        out["flap_1_harmonic_change_pct"] = {k: pct_change(base["flap_1_harmonics"][k], v)
                                             for k, v in other["flap_1_harmonics"].items()}
    for k in ("power_std_W", "gen_speed_std_rad_s", "pitch_travel_deg", "cs1", "cs2"):
        if k in base and k in other:
            out[f"{k}_change_pct"] = pct_change(base[k], other[k])
    return out


_STD_KEYS = ("gen_speed_std_rad_s", "gen_torque_std_Nm", "power_std_W")


_PITCH_KEYS = ("pitch_travel_deg", "pitch_rate_std_degps", "pitch_acc_std_degps2")


def _lifetime_at(runs: Sequence[Mapping[str, Any]], channel: str, m: float,
                 p: np.ndarray) -> float:
    """Lifetime DEL of ``channel`` at exponent ``m`` over bins (Clemens eq 18), each bin's DEL
    at m from its own cycles and weighted by its equivalent cycle count."""
    dels, weights = [], []
    for r in runs:
        ch = r["channels"][channel]
        if float(ch["m"]) == m:
            dels.append(ch["del"])
        else:
            at = ch.get("del_at_m", {})
            if f"{m:g}" not in at:
                raise ValueError(f"the {channel} DELs hold exponents {sorted(at)} and the "
                                 f"channel's own m = {ch['m']:g}, not m = {m:g}: assess the runs "
                                 f"with that exponent")
            dels.append(at[f"{m:g}"])
        weights.append(ch.get("n_eq", 1.0))
    return lifetime_del(np.array(dels), m, p, np.array(weights, float))


def lifetime_comparison(probabilities: Any, base: Sequence[Mapping[str, Any]],
                        updated: Sequence[Mapping[str, Any]], *,
                        woehler: Sequence[float] = (4.0, 10.0), t_base: float = 15.0,
                        t_upd: float = 5.0, t_lifetime: float = 20.0) -> dict[str, Any]:
    """Lifetime-weighted change of a retrofit controller against the baseline.

    Parameters
    ----------
    probabilities : (n_bin,) array_like
        Probability of each mean-wind bin [-].
    base, updated : sequence of dict
        One :func:`assess_series` result per bin (seeds merged by the caller).

    Returns
    -------
    dict
        ``del_change_pct`` per channel (lifetime DEL, Clemens eq 18, at each channel's own
        Woehler exponent), ``lifetime_del`` {channel: (base, updated)}, ``aep_change_pct``
        (probability-weighted mean power), ``pitch_change_pct`` and ``std_change_pct``
        (probability-weighted means of the per-run metrics), and ``extension`` {channel: {m:
        {"damage", "extension_years"}}} from eq 1 with the lifetime DEL ratio at each m in
        ``woehler`` (the paper's 15 + 5 years by default). Each lifetime DEL at an exponent m
        aggregates the bins' DELs at m computed from their own cycles (``del_at_m``), weighted
        by probability and equivalent cycle count (eq 18).

    Raises
    ------
    ValueError
        Bins that differ in number, or an exponent not among a channel's ``del_at_m``.
    """
    p = np.asarray(probabilities, float)
    if not (len(base) == len(updated) == p.size):
        raise ValueError(f"probabilities ({p.size}), base ({len(base)}) and updated "
                         f"({len(updated)}) must have one entry per wind bin")

    def wmean(runs: Sequence[Mapping[str, Any]], key: str) -> float:
        return float(np.sum(p * np.array([r[key] for r in runs])) / p.sum())

    chans = [c for c in base[0]["channels"] if all(c in r["channels"] for r in updated)]
    out: dict[str, Any] = {"del_change_pct": {}, "lifetime_del": {}, "extension": {},
                           "pitch_change_pct": {}, "std_change_pct": {}}
    for c in chans:
        m = float(base[0]["channels"][c]["m"])
        lb, lu = (_lifetime_at(runs, c, m, p) for runs in (base, updated))
        out["lifetime_del"][c] = (lb, lu)
        out["del_change_pct"][c] = pct_change(lb, lu)
        out["extension"][c] = {}
        for mw in woehler:
            lbm, lum = (_lifetime_at(runs, c, float(mw), p) for runs in (base, updated))
            out["extension"][c][float(mw)] = lifetime_extension(
                lbm, lum, mw, t_base=t_base, t_upd=t_upd, t_lifetime=t_lifetime)
    if all("power_mean_W" in r for r in [*base, *updated]):
        out["aep_change_pct"] = pct_change(wmean(base, "power_mean_W"), wmean(updated, "power_mean_W"))
    for keys, dest in ((_PITCH_KEYS, "pitch_change_pct"), (_STD_KEYS, "std_change_pct")):
        for k in keys:
            if all(k in r for r in [*base, *updated]):
                out[dest][k] = pct_change(wmean(base, k), wmean(updated, k))
    return out

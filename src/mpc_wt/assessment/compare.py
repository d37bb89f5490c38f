"""Two runs of one case side by side, channel by channel: means, standard deviations, damage-
equivalent loads and spectra over a time window, with the differences of the second from the
first (a reference such as OpenFAST's output). Channels by mpc-wt's names, in SI.
"""
from __future__ import annotations

from typing import Any, Mapping, Sequence

import numpy as np

from mpc_wt.assessment.fatigue import damage_equivalent_load
from mpc_wt.assessment.performance import psd
from mpc_wt.assessment.series import DEFAULT_CHANNELS

__all__ = ["COMPARE_CHANNELS", "compare_series", "window_psd"]

#: the channels compared when both runs have them, in this order (not the Coleman tilt and yaw
#: moments: OpenFAST's yaw-bearing moments, which the channel map reads as them, are other
#: quantities)
COMPARE_CHANNELS = ("gen_power", "rotor_speed", "gen_torque", "pitch_1", "thrust",
                    "aero_torque", "flapwise_moment_1", "edgewise_moment_1", "flap_moment_1",
                    "edge_moment_1", "lss_torque", "tower_base_fa_moment",
                    "tower_base_ss_moment",
                    "tower_fa_displacement", "tower_ss_displacement", "tower_fa_acceleration",
                    "tower_ss_acceleration", "hub_wind_speed")


#: the Woehler exponent of the blade-frame root moments (composite blades, as the out-of-plane
#: and in-plane ones in :data:`DEFAULT_CHANNELS`)
_BLADE_FRAME_M = 10.0


def _window(t: np.ndarray, window: tuple[float, float | None]) -> np.ndarray:
    lo, hi = window
    hi = float(t[-1]) if hi is None else hi
    if not lo < hi:
        raise ValueError(f"window must run forward, got {lo:g}..{hi:g} s")
    keep = (t >= lo - 1e-9) & (t <= hi + 1e-9)
    if keep.sum() < 16:
        raise ValueError(f"window {lo:g}..{hi:g} s holds {int(keep.sum())} samples of the run "
                         f"({t[0]:g}..{t[-1]:g} s); at least 16 needed")
    return keep


def compare_series(t_ref: np.ndarray, ref: Mapping[str, np.ndarray], t: np.ndarray,
                   ours: Mapping[str, np.ndarray], window: tuple[float, float | None] = (10.0,
                                                                                      None),
                   channels: Sequence[str] | None = None) -> list[dict[str, Any]]:
    """Statistics of each channel both runs have, over ``window`` [s].

    Parameters
    ----------
    t_ref, t : ndarray
        The runs' times [s].
    ref, ours : mapping of str to ndarray
        Channels by our names (SI); ``ref`` is the reference.
    window : (float, float or None)
        From, to [s] (None: the end of the shorter run).
    channels : sequence of str, optional
        The channels (default: :data:`COMPARE_CHANNELS` that both have).

    Returns
    -------
    list of dict
        Per channel: ``channel``, ``mean_ref``, ``mean``, ``mean_diff_pct``, ``std_ref``,
        ``std``, ``std_diff_pct``, ``max_ref``, ``max`` (the largest values); for load channels (:data:`DEFAULT_CHANNELS` and the
        blade-frame root moments, m = 10, with their Woehler exponent ``m``) also ``del_ref``, ``del``, ``del_diff_pct`` (1 Hz equivalent
        cycles over the window). A mean or DEL difference of a reference of zero is NaN.

    Raises
    ------
    ValueError
        A bad window, or a named channel one run lacks.
    """
    hi = window[1] if window[1] is not None else float(min(t_ref[-1], t[-1]))
    kr, ko = _window(np.asarray(t_ref), (window[0], hi)), _window(np.asarray(t), (window[0], hi))
    names = list(channels) if channels is not None else [c for c in COMPARE_CHANNELS
                                                        if c in ref and c in ours]
    missing = [c for c in names if c not in ref or c not in ours]
    if missing:
        raise ValueError(f"channel {missing[0]!r} is not in both runs; both have "
                         f"{sorted(set(ref) & set(ours))}")
    span = hi - window[0]
    rows = []
    for c in names:
        a, b = np.asarray(ref[c], float)[kr], np.asarray(ours[c], float)[ko]
        row: dict[str, Any] = {"channel": c, "mean_ref": float(a.mean()), "mean": float(b.mean()),
                               "std_ref": float(a.std()), "std": float(b.std()),
                               "max_ref": float(a.max()), "max": float(b.max())}
        row["mean_diff_pct"] = _pct(row["mean_ref"], row["mean"])
        row["std_diff_pct"] = _pct(row["std_ref"], row["std"])
        m = _BLADE_FRAME_M if c.startswith(("flapwise_", "edgewise_")) else \
            DEFAULT_CHANNELS.get(c)
        if m is not None:
            row.update(m=m, del_ref=damage_equivalent_load(a, m, n_eq=span),
                       **{"del": damage_equivalent_load(b, m, n_eq=span)})
            row["del_diff_pct"] = _pct(row["del_ref"], row["del"])
        rows.append(row)
    return rows


def _pct(ref: float, other: float) -> float:
    return 100.0 * (other / ref - 1.0) if ref != 0 else float("nan")


def window_psd(t: np.ndarray, x: np.ndarray, window: tuple[float, float | None],
               segment_s: float = 20.0) -> tuple[np.ndarray, np.ndarray]:
    """Welch power spectral density of one channel over a window.

    Parameters
    ----------
    t, x : ndarray
        Time [s] and the channel (uniformly sampled).
    window : (float, float or None)
        From, to [s].
    segment_s : float
        Welch segment length [s] (shortened to the window).

    Returns
    -------
    f : ndarray
        [Hz]
    p : ndarray
        [unit^2 / Hz]
    """
    keep = _window(np.asarray(t), window)
    tt, xx = np.asarray(t)[keep], np.asarray(x, float)[keep]
    fs = 1.0 / float(np.median(np.diff(tt)))
    n = int(min(len(xx), round(segment_s * fs)))
    return psd(xx - xx.mean(), fs, nperseg=n)

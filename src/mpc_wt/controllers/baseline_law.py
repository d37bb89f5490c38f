"""The baseline's law (DISCON form) as compiled functions on a state and a parameter vector.
"""
from __future__ import annotations

import math
from typing import Any

import numba as nb
import numpy as np

__all__ = ['SIGNALS', 'law_arrays']

_JIT = dict(cache=True, error_model="numpy")


#: the law's signals, in the order of the recorded columns (BaselineController.signals)
SIGNALS = ("gen_speed_filtered", "speed_error", "pitch_integral", "gain_schedule",
           "pitch_command", "torque_command")


# parameter vector layout
(_A, _W_RATED_SET, _KP, _KI, _THETA_K, _DT, _P_MIN, _P_MAX, _RATE, _TQ_RATE, _TQ_MAX,
 _W_CUTIN, _W_RGN2, _W_TRANS, _W_RATED, _W_SYNC, _SLOPE15, _SLOPE25, _K_OPT, _TQ_CAP,
 _P_RATED, _ETA, _TQ_RATED, _CONST_POWER, _ONE_DEG, _I_GEN_SPEED) = range(26)


# state vector layout: filtered speed, integral, last pitch, last torque, started (0 / 1)
_W_FILT, _INTEGRAL, _LAST_PITCH, _LAST_TQ, _STARTED = range(5)


def law_arrays(ctl: Any, gen_speed_index: int) -> tuple[np.ndarray, np.ndarray]:
    """The state and parameter vectors of a baseline controller's law.

    Parameters
    ----------
    ctl : BaselineController
        A controller whose law is the plain one (see the module docstring); its state (a run
        under way) is carried over.
    gen_speed_index : int
        Index of the generator speed in the plant's outputs.

    Returns
    -------
    state : (5,) ndarray
    params : (26,) ndarray
    """
    g = ctl.gains
    par = np.empty(26)
    par[[_A, _W_RATED_SET, _KP, _KI, _THETA_K, _DT, _P_MIN, _P_MAX, _RATE, _TQ_RATE]] = (
        ctl._a_filt, g.rated_gen_speed_rad_s, g.kp, g.ki, g.theta_k_rad, ctl.dt, ctl.pitch_min,
        ctl.pitch_max, ctl.rate, ctl.tq_rate)
    par[[_TQ_MAX, _W_CUTIN, _W_RGN2, _W_TRANS, _W_RATED, _W_SYNC, _SLOPE15, _SLOPE25]] = (
        ctl.tq_max, ctl.w_cutin, ctl.w_rgn2, ctl.w_trans, ctl.w_rated, ctl.w_sync, ctl.slope15,
        ctl.slope25)
    par[[_K_OPT, _TQ_CAP, _P_RATED, _ETA, _TQ_RATED, _CONST_POWER, _ONE_DEG, _I_GEN_SPEED]] = (
        g.k_opt, ctl.tq_cap, g.rated_power, ctl.turbine.drivetrain.generator_efficiency,
        g.rated_torque, float(ctl.region3 == "constant_power"), math.radians(1.0),
        gen_speed_index)
    st = np.zeros(5)
    if ctl.w_filt is not None:          # a run under way (the filter and last commands set)
        st[:] = (ctl.w_filt, ctl.integral, ctl.last_pitch, ctl.last_torque, 1.0)
    return st, par


@nb.njit(**_JIT)
def torque(w, pitch, par):  # pragma: no cover - compiled
    """BaselineController.torque without a power reference."""
    p3 = par[_P_RATED]
    if w >= par[_W_RATED] or pitch >= par[_ONE_DEG]:
        if par[_CONST_POWER] != 0.0:
            return p3 / par[_ETA] / max(w, 1e-6)
        return par[_TQ_RATED] * p3 / par[_P_RATED]
    if w <= par[_W_CUTIN]:
        return 0.0
    if w < par[_W_RGN2]:
        tq = par[_SLOPE15] * (w - par[_W_CUTIN])
    elif w < par[_W_TRANS]:
        tq = par[_K_OPT] * w * w
    else:
        tq = par[_SLOPE25] * (w - par[_W_SYNC])
    return min(min(tq, par[_TQ_CAP]), p3 / par[_ETA] / max(w, 1e-6))


@nb.njit(**_JIT)
def law(z, st, par, cmd, sig):  # pragma: no cover - compiled
    """BaselineController.step on the plant's outputs z: writes the commands (3 pitch, torque)
    and the signals; returns 1 on a non-finite generator speed, else 0."""
    w = z[int(par[_I_GEN_SPEED])]
    if not math.isfinite(w):
        return 1
    pitch_meas = (z[1] + z[2] + z[3]) / 3.0
    first = st[_STARTED] == 0.0
    if first:
        st[_W_FILT] = w
        st[_LAST_PITCH] = pitch_meas
    a = par[_A]
    st[_W_FILT] = a * st[_W_FILT] + (1 - a) * w
    kp, ki, dt = par[_KP], par[_KI], par[_DT]
    err = st[_W_FILT] - par[_W_RATED_SET]
    gk = 1.0 / (1.0 + st[_LAST_PITCH] / par[_THETA_K])
    if first:
        st[_INTEGRAL] = (pitch_meas / gk - kp * err) / ki
    st[_INTEGRAL] += err * dt + 0.0 / (gk * ki)
    lo, hi = par[_P_MIN] / (gk * ki), par[_P_MAX] / (gk * ki)
    st[_INTEGRAL] = min(max(st[_INTEGRAL], lo), hi)
    p = gk * (kp * err + ki * st[_INTEGRAL])
    p = min(max(p, par[_P_MIN]), par[_P_MAX])
    step = par[_RATE] * dt
    p = min(max(p, st[_LAST_PITCH] - step), st[_LAST_PITCH] + step)
    st[_LAST_PITCH] = p
    tq = min(torque(st[_W_FILT], p, par), par[_TQ_MAX])
    if st[_STARTED] == 1.0:
        d = par[_TQ_RATE] * dt
        tq = min(max(tq, st[_LAST_TQ] - d), st[_LAST_TQ] + d)
    st[_LAST_TQ] = tq
    st[_STARTED] = 1.0
    sig[0], sig[1], sig[2], sig[3], sig[4], sig[5] = st[_W_FILT], err, st[_INTEGRAL], gk, p, tq
    cmd[0], cmd[1], cmd[2], cmd[3] = p, p, p, tq
    return 0

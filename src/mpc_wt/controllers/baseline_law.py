"""The baseline's law in DISCON form, written once as compiled functions on a state and a
parameter vector.

The law of Jonkman's baseline (NREL/TP-500-38060, sec. 7): a first-order low-pass on the
generator speed; a PI on the filtered speed error with the gain schedule
GK = 1 / (1 + theta / theta_K) applied at the previous command, the integral kept within the
pitch limits (anti-windup) and a bumpless start at the measured pitch; the lower pitch limit
raised by the minimum-pitch schedule on the filtered speed (region 3 of the torque law then
counts from that minimum); the pitch-rate limit; the
torque law of regions 1.5, 2, 2.5 and 3 (constant power or constant torque) capped at the
maximum torque, and its rate limit. :class:`~mpc_wt.controllers.baseline.BaselineController`
runs it from Python at each step (:func:`law_step`); the closed loop compiled with the plant
(:mod:`mpc_wt.simulation.compiled`) runs it on the plant's outputs (:func:`law`). Both are the
same operations in the same order, so the two loops agree to the last bit.
"""
from __future__ import annotations

import math
from typing import Any

import numba as nb
import numpy as np

__all__ = ["SIGNALS", "N_STATE", "N_PARAMS", "law_parameters", "law_step", "torque", "law",
           "min_pitch_offset"]

_JIT = dict(cache=True, error_model="numpy")

#: The torque law is in region 3 where the pitch (less the minimum-pitch schedule's offset)
#: stands this far above the fine pitch, or the speed at rated [rad]: Jonkman et al.'s
#: VS_Rgn3MP, 1 deg on the NREL 5-MW, whose fine pitch is 0 (sec. 7.1); counted from the
#: turbine's own fine pitch, so that a turbine whose region-2 pitch is not 0 stays in region 2.
REGION3_PITCH_MARGIN = math.radians(1.0)

#: the law's signals, in the order of the recorded columns (BaselineController.signals)
SIGNALS = ("gen_speed_filtered", "speed_error", "pitch_integral", "gain_schedule",
           "pitch_command", "torque_command")

# parameter vector layout
(_A, _W_RATED_SET, _KP, _KI, _THETA_K, _DT, _P_MIN, _P_MAX, _RATE, _TQ_RATE, _TQ_MAX,
 _W_CUTIN, _W_RGN2, _W_TRANS, _W_RATED, _W_SYNC, _SLOPE15, _SLOPE25, _K_OPT, _TQ_CAP,
 _P_RATED, _ETA, _TQ_RATED, _CONST_POWER, _RGN3_PITCH, _I_GEN_SPEED, _N_MIN_PITCH) = range(27)
#: length of the parameter vector's fixed part; the minimum-pitch schedule's speeds and offsets
#: follow it (``par[_N_MIN_PITCH]`` points each)
N_PARAMS = 27

# state vector layout: filtered speed, integral, last pitch, last torque, started (0 / 1)
_W_FILT, _INTEGRAL, _LAST_PITCH, _LAST_TQ, _STARTED = range(5)
#: length of the state vector
N_STATE = 5


def law_parameters(ctl: Any, gen_speed_index: int = -1) -> np.ndarray:
    """The parameter vector of a baseline controller's law.

    Parameters
    ----------
    ctl : BaselineController
        The controller (its gains, breakpoints, limits and period).
    gen_speed_index : int
        Index of the generator speed in the plant's outputs (for :func:`law`; -1: unused).

    Returns
    -------
    (N_PARAMS + 2 k,) ndarray
        The fixed part, then the minimum-pitch schedule's k speeds [rad/s] and offsets above
        the minimum pitch [rad] (the controller's ``min_pitch_speeds``, ``min_pitch_offsets``).
    """
    g = ctl.gains
    ws, offs = np.array(ctl.min_pitch_speeds, float), np.array(ctl.min_pitch_offsets, float)
    k = ws.size
    par = np.empty(N_PARAMS + 2 * k)
    par[_N_MIN_PITCH] = k
    par[N_PARAMS:N_PARAMS + k], par[N_PARAMS + k:] = ws, offs
    par[[_A, _W_RATED_SET, _KP, _KI, _THETA_K, _DT, _P_MIN, _P_MAX, _RATE, _TQ_RATE]] = (
        ctl.filter_pole, g.rated_gen_speed_rad_s, g.kp, g.ki, g.theta_k_rad, ctl.dt,
        ctl.pitch_min, ctl.pitch_max, ctl.rate, ctl.tq_rate)
    par[[_TQ_MAX, _W_CUTIN, _W_RGN2, _W_TRANS, _W_RATED, _W_SYNC, _SLOPE15, _SLOPE25]] = (
        ctl.tq_max, ctl.w_cutin, ctl.w_rgn2, ctl.w_trans, ctl.w_rated, ctl.w_sync, ctl.slope15,
        ctl.slope25)
    par[[_K_OPT, _TQ_CAP, _P_RATED, _ETA, _TQ_RATED, _CONST_POWER, _RGN3_PITCH, _I_GEN_SPEED]] = (
        g.k_opt, ctl.tq_cap, g.rated_power, ctl.turbine.drivetrain.generator_efficiency,
        g.rated_torque, float(ctl.region3 == "constant_power"),
        ctl.pitch_min + REGION3_PITCH_MARGIN,
        gen_speed_index)
    return par


@nb.njit(**_JIT)
def torque(w, pitch, p3, par):  # pragma: no cover - compiled
    """Generator torque demand [N m] at filtered generator speed ``w`` [rad/s] and collective
    pitch [rad], with ``p3`` [W] in place of rated power in region 3."""
    if w >= par[_W_RATED] or pitch >= par[_RGN3_PITCH]:
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
def min_pitch_offset(w, par):  # pragma: no cover - compiled
    """The minimum-pitch schedule's pitch above the minimum [rad] at filtered generator speed
    ``w`` [rad/s], held beyond the schedule's ends."""
    k = int(par[_N_MIN_PITCH])
    return np.interp(w, par[N_PARAMS:N_PARAMS + k], par[N_PARAMS + k:N_PARAMS + 2 * k])


@nb.njit(**_JIT)
def law_step(w, pitch_meas, ff, p3, st, par, cmd, sig):  # pragma: no cover - compiled
    """One step of the law: measured generator speed ``w`` [rad/s] and mean pitch [rad], the
    change of an add-on's feedforward pitch since the last step ``ff`` [rad] (it enters the
    integral, so the PI stays consistent with it) and the power ``p3`` [W] of region 3. Updates
    the state ``st`` and writes the commands ``cmd`` (3 pitch [rad], torque [N m]) and the
    signals ``sig`` (:data:`SIGNALS`)."""
    first = st[_STARTED] == 0.0
    if first:
        st[_W_FILT] = w
        st[_LAST_PITCH] = pitch_meas
    a = par[_A]
    st[_W_FILT] = a * st[_W_FILT] + (1 - a) * w
    kp, ki, dt = par[_KP], par[_KI], par[_DT]
    err = st[_W_FILT] - par[_W_RATED_SET]
    gk = 1.0 / (1.0 + st[_LAST_PITCH] / par[_THETA_K])
    if first:                                   # bumpless start at the measured pitch
        st[_INTEGRAL] = (pitch_meas / gk - kp * err) / ki
    st[_INTEGRAL] += err * dt + ff / (gk * ki)
    off = min_pitch_offset(st[_W_FILT], par)
    p_lo = par[_P_MIN] + off
    lo, hi = p_lo / (gk * ki), par[_P_MAX] / (gk * ki)
    st[_INTEGRAL] = min(max(st[_INTEGRAL], lo), hi)
    p = gk * (kp * err + ki * st[_INTEGRAL])
    p = min(max(p, p_lo), par[_P_MAX])
    step = par[_RATE] * dt
    p = min(max(p, st[_LAST_PITCH] - step), st[_LAST_PITCH] + step)
    st[_LAST_PITCH] = p
    tq = min(torque(st[_W_FILT], p - off, p3, par), par[_TQ_MAX])
    if st[_STARTED] == 1.0:
        d = par[_TQ_RATE] * dt
        tq = min(max(tq, st[_LAST_TQ] - d), st[_LAST_TQ] + d)
    st[_LAST_TQ] = tq
    st[_STARTED] = 1.0
    sig[0], sig[1], sig[2], sig[3], sig[4], sig[5] = st[_W_FILT], err, st[_INTEGRAL], gk, p, tq
    cmd[0], cmd[1], cmd[2], cmd[3] = p, p, p, tq


@nb.njit(**_JIT)
def law(z, st, par, cmd, sig):  # pragma: no cover - compiled
    """:func:`law_step` on the plant's outputs ``z`` at rated power, without feedforward;
    returns 1 on a non-finite generator speed, else 0."""
    w = z[int(par[_I_GEN_SPEED])]
    if not math.isfinite(w):
        return 1
    law_step(w, (z[1] + z[2] + z[3]) / 3.0, 0.0, par[_P_RATED], st, par, cmd, sig)
    return 0

"""The baseline's static curves as compiled functions on a parameter vector: the torque law of
regions 1.5, 2, 2.5 and 3 (Jonkman et al. 2009, sec. 7.3; constant power or constant torque)
and the minimum-pitch schedule, which a design's steady curves
(:mod:`mpc_wt.controllers.derating`) and other designs' torque schedules
(:class:`~mpc_wt.controllers.baseline.LawTorque`) read. The baseline's law itself is the C law
it is shipped as (``mpc_wt/io/discon_c/baseline.c``).
"""
from __future__ import annotations

import math
from typing import Any

import numba as nb
import numpy as np

__all__ = ["N_PARAMS", "law_parameters", "torque", "min_pitch_offset"]

_JIT = dict(cache=True, error_model="numpy")

#: The torque law is in region 3 where the pitch (less the minimum-pitch schedule's offset)
#: stands this far above the fine pitch, or the speed at rated [rad]: Jonkman et al.'s
#: VS_Rgn3MP, 1 deg on the NREL 5-MW, whose fine pitch is 0 (sec. 7.1); counted from the
#: turbine's own fine pitch, so that a turbine whose region-2 pitch is not 0 stays in region 2.
REGION3_PITCH_MARGIN = math.radians(1.0)

# parameter vector layout
(_W_CUTIN, _W_RGN2, _W_TRANS, _W_RATED, _W_SYNC, _SLOPE15, _SLOPE25, _K_OPT, _TQ_CAP,
 _P_RATED, _ETA, _TQ_RATED, _CONST_POWER, _RGN3_PITCH, _N_MIN_PITCH) = range(15)
#: length of the parameter vector's fixed part; the minimum-pitch schedule's speeds and offsets
#: follow it (``par[_N_MIN_PITCH]`` points each)
N_PARAMS = 15


def law_parameters(ctl: Any) -> np.ndarray:
    """The parameter vector of a baseline design's torque law and minimum-pitch schedule.

    Parameters
    ----------
    ctl : BaselineController
        The design (its gains and breakpoints).

    Returns
    -------
    (N_PARAMS + 2 k,) ndarray
        The fixed part, then the minimum-pitch schedule's k speeds [rad/s] and offsets above
        the minimum pitch [rad] (the design's ``min_pitch_speeds``, ``min_pitch_offsets``).
    """
    g = ctl.gains
    ws, offs = np.array(ctl.min_pitch_speeds, float), np.array(ctl.min_pitch_offsets, float)
    k = ws.size
    par = np.empty(N_PARAMS + 2 * k)
    par[_N_MIN_PITCH] = k
    par[N_PARAMS:N_PARAMS + k], par[N_PARAMS + k:] = ws, offs
    par[[_W_CUTIN, _W_RGN2, _W_TRANS, _W_RATED, _W_SYNC, _SLOPE15, _SLOPE25]] = (
        ctl.w_cutin, ctl.w_rgn2, ctl.w_trans, ctl.w_rated, ctl.w_sync, ctl.slope15,
        ctl.slope25)
    par[[_K_OPT, _TQ_CAP, _P_RATED, _ETA, _TQ_RATED, _CONST_POWER, _RGN3_PITCH]] = (
        g.k_opt, ctl.tq_cap, g.rated_power, ctl.turbine.drivetrain.generator_efficiency,
        g.rated_torque, float(ctl.region3 == "constant_power"),
        ctl.pitch_min + REGION3_PITCH_MARGIN)
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

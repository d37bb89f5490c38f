"""The baseline's closed loop compiled with the plant (issue 23).

A closed loop in Python pays some 30 µs a plant step around an ~80 µs plant step: the
measurement dict, the controller's call, the command checks, the signals. For the baseline PI
and torque law at the plant's rate that is more than the law itself. This module runs the whole
loop (RK4 step, the law, the command checks, the generator's torque-rate limit, the signals and
the envelope check) in one compiled call per block of steps.

It is the same loop as :func:`mpc_wt.simulate.simulate_closed_loop`'s Python path, operation for
operation: :class:`~mpc_wt.baseline.BaselineController`'s ``step`` (DISCON form: the speed
low-pass, the PI on the filtered speed error with the gain schedule GK = 1 / (1 + theta /
theta_K) and its anti-windup, the pitch-rate limit, the torque law of regions 1.5, 2, 2.5 and 3
and its rate limit), in the same floating-point order, so the two paths agree to rounding (the
test compares them over turbulent runs in regions 2 and 3). It applies only where the law is
exactly that: no power reference, gain schedule or add-on feedforward
(:meth:`~mpc_wt.baseline.BaselineController.compiled_law` says None otherwise), and no LIDAR.
"""
from __future__ import annotations

import hashlib
import logging
import math
from pathlib import Path
from typing import Any

import numba as nb
import numpy as np

import linearize
from linearize.plant import step_kernel

log = logging.getLogger(__name__)

__all__ = ["SIGNALS", "law_arrays", "run_steps"]

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
def _torque(w, pitch, par):  # pragma: no cover - compiled
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
def _law(z, st, par, cmd, sig):  # pragma: no cover - compiled
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
    tq = min(_torque(st[_W_FILT], p, par), par[_TQ_MAX])
    if st[_STARTED] == 1.0:
        d = par[_TQ_RATE] * dt
        tq = min(max(tq, st[_LAST_TQ] - d), st[_LAST_TQ] + d)
    st[_LAST_TQ] = tq
    st[_STARTED] = 1.0
    sig[0], sig[1], sig[2], sig[3], sig[4], sig[5] = st[_W_FILT], err, st[_INTEGRAL], gk, p, tq
    cmd[0], cmd[1], cmd[2], cmd[3] = p, p, p, tq
    return 0


@nb.njit(**_JIT)
def _loop(k0, k1, ratio, h, pk, kind, wpar, grid, hint, dphi, lim, xs, us, zs, u, held, st,
          par, sigs, act, counts):  # pragma: no cover - compiled
    """Plant steps k0..k1-1 of the closed loop (simulate._run's order). ``u`` holds the
    applied inputs, ``held`` the commanded torque, ``act`` the torque step per plant step and
    the actuator ranges (pitch lo, hi, torque lo, hi), ``counts`` the commands out of range
    and the first step with one. Returns (steps done, -1 | the state leaving the envelope |
    -2 for a non-finite generator speed | -3 for a non-finite command)."""
    cmd = np.empty(4)
    for k in range(k0, k1):
        t = k * h
        us[k] = u
        bad = step_kernel(t, xs[k], u, h, pk, kind, wpar, grid, hint, dphi, lim, xs[k + 1],
                          zs[k])
        if k % ratio == 0:
            if _law(zs[k], st, par, cmd, sigs[k]) != 0:
                return k, -2
            if not (math.isfinite(cmd[0]) and math.isfinite(cmd[3])):
                return k, -3
            lo, hi = min(min(cmd[0], cmd[1]), cmd[2]), max(max(cmd[0], cmd[1]), cmd[2])
            if not (act[1] <= lo and hi <= act[2] and act[3] <= cmd[3] <= act[4]):
                if counts[0] == 0:
                    counts[1] = k
                counts[0] += 1
            u[0], u[1], u[2] = cmd[0], cmd[1], cmd[2]
            held[0] = cmd[3]
        else:
            sigs[k] = sigs[k - 1]
        u[3] += min(max(held[0] - u[3], -act[0]), act[0])
        if bad >= 0:
            return k + 1, bad
    return k1, -1


def _tie_cache_to_sources(dispatcher: Any, paths: tuple[str, ...]) -> None:
    """numba keys a kernel's disk cache on its own file's source only; :func:`_loop` compiles
    the plant's kernels into itself, so their sources enter the key too: an edit of
    linearize's plant or BEM recompiles the loop instead of loading a stale one. Through
    numba's cache object (its attributes as of numba 0.68); without them, numba's own key
    and a debug log."""
    try:
        cache_file = dispatcher._cache._cache_file
        h = hashlib.sha256(repr(cache_file._source_stamp).encode())
        for path in paths:
            h.update(Path(path).read_bytes())
        cache_file._source_stamp = h.hexdigest()
    except (AttributeError, OSError) as err:      # pragma: no cover - another numba
        log.debug("compiled loop's cache keyed on its own source only: %s", err)


_tie_cache_to_sources(_loop, (linearize.plant.__file__, linearize.bem.__file__))


def run_steps(k0: int, k1: int, ratio: int, stepper: Any, arrays: tuple[np.ndarray, ...]
              ) -> tuple[int, int]:
    """Run plant steps ``k0`` to ``k1 - 1`` of a compiled closed loop.

    Parameters
    ----------
    k0, k1 : int
        The block of steps.
    ratio : int
        Plant steps per controller step.
    stepper : linearize.PlantStepper
        The plant and its BEM warm start (advanced in place).
    arrays : tuple of ndarray
        (xs, us, zs, u, held, state, params, signals, actuator, counts), see :func:`_loop`;
        written in place.

    Returns
    -------
    done : int
        Steps done (k1, or the step after a divergence).
    flag : int
        -1, the index of the state that left its envelope, -2 for a non-finite generator
        speed or -3 for a non-finite command (both at step ``done``).
    """
    h, pk, kind, wpar, grid, hint, dphi, lim = stepper.kernel_args()
    done, flag = _loop(k0, k1, ratio, h, pk, kind, wpar, grid, hint, dphi, lim, *arrays)
    return int(done), int(flag)

"""Closed loops compiled with the plant around a Bladed-style controller library loaded in
this process.

A closed loop in Python pays some 30 µs a plant step around an ~80 µs plant step: the
measurement dict, the controller's call, the command checks, the signals. For a law called at
the plant's rate (the baseline's) that is more than the law itself. This module runs the whole
loop (RK4 step, the library's call, the command checks, the generator's torque-rate limit, the
signals and the envelope check) in one compiled call per block of steps.

It is the same loop as :func:`mpc_wt.simulation.loop.simulate_closed_loop`'s Python path,
operation for operation: the swap records filled from the plant's outputs, ``DISCON`` called
through its function pointer, the demands read back, as
:meth:`~mpc_wt.controllers.discon.DisconController.step` does them, record for record, so the
two paths agree to the last bit (tested). It applies to a
:class:`~mpc_wt.controllers.discon.DisconController` with ``isolate=False`` (every shipped law).
"""
from __future__ import annotations

from typing import Any

import numba as nb
import numpy as np

from linearize.jitcache import key_caches_on_callees
from linearize import STATE_NAMES
from linearize.kernel import step_kernel
from mpc_wt.controllers.discon_kernel import library_call

__all__ = ["run_library_steps"]

_JIT = dict(cache=True, error_model="numpy")

#: the rotor speed's index in the plant's state (the supervisor's overspeed check)
_ROTOR = STATE_NAMES.index("rotor_speed")


@nb.njit(**_JIT)
def _hold(k, cmd, u, held, act, counts):  # pragma: no cover - compiled
    """Hold the commands of plant step ``k`` (pitch into ``u``, torque into ``held``),
    counting those out of the actuator ranges ``act`` and the first step with one."""
    lo, hi = min(min(cmd[0], cmd[1]), cmd[2]), max(max(cmd[0], cmd[1]), cmd[2])
    if not (act[1] <= lo and hi <= act[2] and act[3] <= cmd[3] <= act[4]):
        if counts[0] == 0:
            counts[1] = k
        counts[0] += 1
    u[0], u[1], u[2] = cmd[0], cmd[1], cmd[2]
    held[0] = cmd[3]


@nb.njit(**_JIT)
def _library_loop(k0, k1, ratio, h, pk, kind, wpar, grid, hint, dphi, lim, xs, us, zs, u,
                  held, fn, swap, fail, bufs, rec, zi, hub, lib, gate, sigs, act, counts
                  ):  # pragma: no cover - compiled
    """Plant steps k0..k1-1 of the closed loop around a controller library's call
    (simulate._run's order). ``u`` holds the applied inputs, ``held`` the commanded torque,
    ``act`` the torque step per plant step and the actuator ranges (pitch lo, hi, torque lo,
    hi), ``counts`` the commands out of range and the first step with one. ``gate`` holds
    where the host takes a call step back before the plant steps: a rotor speed above
    ``gate[0]`` or the step ``gate[1]`` (a supervisor's trip), and, with ``gate[3]`` set, the
    time ``gate[2]`` of the next LIDAR sample. Returns (steps done, -1 | the state leaving the
    envelope | -4 for aviFAIL < 0 | -5 after a step with a warning (aviFAIL > 0), to be
    reported | -6 for a non-finite demand | -7 for the supervisor's step | -8 for a LIDAR
    sample due)."""
    cmd = np.zeros(sigs.shape[1] + 1)
    for k in range(k0, k1):
        t = k * h
        if k % ratio == 0:
            if xs[k, _ROTOR] > gate[0] or k >= gate[1]:
                return k, -7
            if gate[3] != 0.0 and t >= gate[2] - 1e-9:
                return k, -8
        us[k] = u
        bad = step_kernel(t, xs[k], u, h, pk, kind, wpar, grid, hint, dphi, lim, xs[k + 1],
                          zs[k])
        warned = 0
        if k % ratio == 0:
            flag = library_call(k, t, zs[k], fn, swap, fail, bufs, rec, zi, hub, lib, cmd)
            if flag < 0:
                return k, -4
            if flag == 2:
                return k, -6
            warned = flag
            _hold(k, cmd, u, held, act, counts)
            sigs[k, 0] = (cmd[0] + cmd[1] + cmd[2]) / 3.0
            sigs[k, 1], sigs[k, 2], sigs[k, 3] = cmd[3], cmd[4], 1.0 if warned > 0 else 0.0
            for i in range(4, sigs.shape[1]):
                sigs[k, i] = cmd[i + 1]
        else:
            sigs[k] = sigs[k - 1]
        u[3] += min(max(held[0] - u[3], -act[0]), act[0])
        if bad >= 0:
            return k + 1, bad
        if warned > 0:
            return k + 1, -5
    return k1, -1


def run_library_steps(k0: int, k1: int, ratio: int, stepper: Any,
                      arrays: tuple[Any, ...]) -> tuple[int, int]:
    """Run plant steps ``k0`` to ``k1 - 1`` of a closed loop around a controller library.

    Parameters
    ----------
    k0, k1 : int
        The block of steps.
    ratio : int
        Plant steps per library call.
    stepper : linearize.PlantStepper
        The plant and its BEM warm start (advanced in place).
    arrays : tuple
        (xs, us, zs, u, held, DISCON, swap, aviFAIL, string buffers, records, output
        indices, hub wind, library state, gate, signals, actuator, counts), see
        :func:`_library_loop`; written in place.

    Returns
    -------
    done : int
        Steps done.
    flag : int
        -1; the index of a state that left its envelope; -4: the library stopped the run at
        step ``done``; -5: it warned at step ``done - 1``; -6: a non-finite demand at ``done``;
        -7: the supervisor's step ``done`` (not stepped); -8: a LIDAR sample due at step
        ``done`` (not stepped).
    """
    h, pk, kind, wpar, grid, hint, dphi, lim = stepper.kernel_args()
    done, flag = _library_loop(k0, k1, ratio, h, pk, kind, wpar, grid, hint, dphi, lim,
                               *arrays)
    return int(done), int(flag)


key_caches_on_callees(__name__)

"""One call of a Bladed-style controller library loaded in this process, compiled: the swap
records of the call filled from the plant's outputs, ``DISCON`` through its function pointer,
the demands and logging channels read back. The host's step
(:meth:`mpc_wt.controllers.discon.DisconController.step`) and the closed loop compiled with the
plant (:mod:`mpc_wt.simulation.compiled`) both call it, so the two paths are one.
"""
from __future__ import annotations

import math

import numba as nb

from linearize.jitcache import key_caches_on_callees

__all__ = ["library_call"]

_JIT = dict(cache=True, error_model="numpy")


@nb.njit(**_JIT)
def library_call(k, t, z, fn, swap, fail, bufs, rec, zi, hub, lib, cmd):  # pragma: no cover
    """One call of the library at plant step ``k`` (time ``t``): the records of this call,
    ``DISCON``, the demands into ``cmd`` (pitch 1-3, torque, contactor, then the logging
    channels). ``lib`` holds the status, the last pitch demand of blade 1, the individual-pitch
    flag, the pitch limits, the largest torque, the most logging channels seen and this call's.
    The first call (status 0) is ServoDyn's: measured generator torque and electrical power
    (records 23 and 15: the previous step's in ServoDyn) 0, the demanded pitch (record 11) the
    initial pitch. Returns aviFAIL, or 2 for a non-finite demand."""
    swap[0] = lib[0]
    swap[1] = t
    swap[26] = hub[k]
    for j in range(rec.size):
        swap[rec[j]] = z[zi[j]]
    if lib[0] == 0.0:               # ServoDyn's first call: no torque or power yet, the
        swap[10] = swap[3]          # demanded pitch is the initial pitch
        swap[14] = 0.0
        swap[22] = 0.0
    else:
        swap[10] = lib[1]
    fail[0] = 0
    bufs[2, 0] = 0
    bufs[1, :] = bufs[3, :]
    fn(swap.ctypes, fail.ctypes, bufs[0].ctypes, bufs[1].ctypes, bufs[2].ctypes)
    if fail[0] < 0:
        return fail[0]
    lib[0] = 1.0
    if lib[2] != 0.0:
        p0, p1, p2 = float(swap[41]), float(swap[42]), float(swap[43])
    else:
        p0 = p1 = p2 = float(swap[44])
    contactor = float(swap[34])
    torque = float(swap[46]) if contactor != 0.0 else 0.0
    hi = lib[5]
    if hi < torque <= hi * (1 + 1e-6):
        torque = hi
    cmd[0], cmd[1], cmd[2] = p0, p1, p2
    for i in range(3):
        if lib[3] - 1e-6 <= cmd[i] < lib[3]:
            cmd[i] = lib[3]
        elif lib[4] < cmd[i] <= lib[4] + 1e-6:
            cmd[i] = lib[4]
    cmd[3], cmd[4] = torque, contactor
    if not (math.isfinite(cmd[0] + cmd[1] + cmd[2]) and math.isfinite(torque)):
        return 2
    lib[1] = cmd[0]
    n = min(int(swap[64]), cmd.size - 5)
    first = int(swap[62]) - 1               # record 63: the first channel's record
    for i in range(max(n, 0)):
        cmd[5 + i] = swap[first + i]
    lib[6] = max(lib[6], float(n))
    lib[7] = float(max(n, 0))
    return fail[0]


key_caches_on_callees(__name__)

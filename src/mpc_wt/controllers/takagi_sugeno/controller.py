"""The Takagi-Sugeno controller and wind observer at run time (Clemens et al. eqs 7-10): the
gains of the vertices blended on the estimated premise, the observer's rotor-effective wind.
"""
from __future__ import annotations

import logging
import math
from typing import Any, Callable

import numba as nb
import numpy as np
import scipy.linalg

import linearize
from linearize.jitcache import key_caches_on_callees
from linearize.validate import check_number
from mpc_wt.controllers.base import ControllerBase
from mpc_wt.controllers.baseline import LawTorque
from mpc_wt.controllers.estimator import SignalReader
from mpc_wt.controllers.takagi_sugeno.model import TSModel, hat_weights, memberships
from mpc_wt.controllers.takagi_sugeno.synthesis import TSControllerDesign, TSObserverDesign

log = logging.getLogger(__name__)

__all__ = ["TSController"]


# --------------------------------------------------------------------------------------------
# Controller in the harness
# --------------------------------------------------------------------------------------------
class TSController(ControllerBase):
    """TS controller (eq 7) on TS observer estimates (eq 10) for the simulation harness.

    The observer is integrated exactly (zero-order hold on u and y) per vertex at the controller
    period and the vertex maps are blended with the memberships of the current premise: for
    slowly varying premises this is the discretization of eq 10. The premise is the estimated
    wind v_hat and the power reduction Delta P(t) of ``power_reduction``; a premise outside the
    vertex grid is clipped to it (logged once per run, counted in ``premise_clipped``); above
    the last vertex wind the equilibrium pitch is extrapolated along the last cell's slope
    (d theta_0 / dv of the last two vertices), so that the pitch keeps following a wind beyond
    the grid (a gust above cut-out) instead of holding the last vertex's equilibrium.

    Parameters
    ----------
    ts, controller, observer : the model and the two designs
    turbine : Turbine (actuator limits)
    dt : controller period [s]
    power_reduction : callable t -> Delta P [-], optional (active power control, eq 11)
    initial_wind_mps : float, optional
        Initial wind estimate [m/s]. Default: from the first step's measured collective pitch,
        the wind whose vertex equilibrium (no power reduction) has that pitch, interpolated
        over the wind grid (clipped to it): the controller starts in operation from what it
        measures.
    torque_law : BaselineController, optional
        The generator torque from this baseline's torque schedule on the generator speed
        low-passed at its filter corner (power-optimal tip-speed ratio below rated, regions
        1.5-2.5; constant power (1 - Delta P) P_rated above), the TS law setting the pitch; the
        observer is fed the torque applied. Without it (Clemens et al.'s design) the TS law
        sets both: a full-load design whose torque, below rated, drives the rotor towards the
        lowest vertex's rated speed, off the optimal tip-speed ratio, and above rated lets the
        power exceed rated with the rotor speed. The pitch then keeps above the baseline's
        minimum-pitch schedule on that filtered speed, where the design has one (the
        IEA-15-240-RWT in region 1.5: at 5 m/s, class B, the TS at fine pitch made 10 % less
        power than the baseline).

    Signals recorded: ``wind_est`` [m/s], ``power_reduction`` [-], ``power_ref`` [W],
    ``premise_clipped`` (0/1).
    """

    def __init__(self, ts: TSModel, controller: TSControllerDesign,
                 observer: TSObserverDesign, turbine: linearize.Turbine, *,
                 dt: float = 1.0 / 80.0,
                 power_reduction: Callable[[float], float] | None = None,
                 initial_wind_mps: float | None = None,
                 torque_law: Any = None) -> None:
        check_number("dt", dt, lo=0.0, lo_open=True, unit="s")
        self.ts, self.ctl, self.obs, self.turbine = ts, controller, observer, turbine
        self.dt = float(dt)
        self.power_reduction = power_reduction
        if initial_wind_mps is not None:
            ts.check_premise(float(initial_wind_mps), float(ts.reduction_grid[0]))
        self._v_given = None if initial_wind_mps is None else float(initial_wind_mps)
        aa, bb, cc = observer.A_aug, observer.B_aug, observer.C_aug
        nv, n = aa.shape[:2]
        nu, ny = bb.shape[2], cc.shape[-2]
        ki = controller.integral_of
        self._ki = None if ki is None else ts.states.index(ki)
        self._int_src = ts.measured.index(ki) if ki in ts.measured else None
        # the observer's terms: one per vertex when the vertices measure alike (weights h_i),
        # else one per pair of vertices active together (weights h_i h_j: the output
        # prediction is blended as the plant's measurement is)
        if ts.common_output:
            terms = [(i, -1) for i in range(nv)]
        else:
            terms = ts.active_pairs()
        self._terms = np.array(terms, dtype=np.int64)
        self._phi = np.empty((len(terms), n, n))
        self._gam = np.empty((len(terms), n, nu + ny + 1))
        xi0 = np.hstack([ts.x0, ts.v0[:, None]])
        off = ts.output_offset()
        for k, (i, j) in enumerate(terms):
            jj = i if j < 0 else j
            f = aa[i] - observer.L[i] @ cc[jj]
            const = -aa[i] @ xi0[i] - bb[i] @ ts.u0[i] - observer.L[i] @ off[jj]
            g = np.hstack([bb[i] - observer.L[i] @ ts.D[jj], observer.L[i], const[:, None]])
            m = np.zeros((n + g.shape[1], n + g.shape[1]))
            m[:n, :n], m[:n, n:] = f, g
            e = scipy.linalg.expm(m * dt)
            self._phi[k], self._gam[k] = e[:n, :n], e[:n, n:]
        self.torque_law = torque_law
        self._law = LawTorque(torque_law, dt) if torque_law is not None else None
        # how far a command may lead the measured pitch: a first-order actuator (time
        # constant tau) then moves at most at its rate
        pa = turbine.pitch_actuator
        self._reach = (pa.max_rate_rad_s * pa.time_constant if pa.time_constant > 0
                       else math.inf)
        self._read = SignalReader(ts.measured)
        self._K = np.ascontiguousarray(controller.K, dtype=float)
        self._w = np.zeros((2, nv))
        self.reset()

    def reset(self) -> None:
        """Forget the estimates; with no initial wind given, the next step starts from its
        measurements."""
        self.xi: np.ndarray | None = None
        if self._v_given is not None:
            self._start(self._v_given)
        self.signals: dict[str, float] = {}
        self.premise_clipped = 0
        self._warned = False
        self._q = 0.0
        if self._law is not None:
            self._law.reset()

    def _start(self, v_init: float) -> None:
        """The observer's state at the vertex equilibrium of wind ``v_init``."""
        m = self.ts.blend(self.ts.membership(v_init, float(self.ts.reduction_grid[0])))
        self.xi = np.concatenate([m["x0"], [v_init]])
        self._u = m["u0"].copy()

    def step(self, t: float, meas: dict[str, Any]) -> tuple[np.ndarray, float]:
        # Observer update, memberships, PDC control law (Clemens eqs 5-10), compiled.
        y = self._read(meas)
        if not all(map(math.isfinite, y.tolist())):
            raise ValueError(f"non-finite measurement at t = {t:g} s: "
                             f"{dict(zip(self.ts.measured, y))}")
        if self.xi is None:                 # start in operation from the measured pitch
            self._start(self.ts.wind_at_pitch(float(np.mean(meas["pitch"]))))
        dp_raw = float(self.power_reduction(t)) if self.power_reduction else 0.0
        if not math.isfinite(dp_raw):
            raise ValueError(f"power_reduction({t:g}) returned {dp_raw!r}")
        ts, pa, gen = self.ts, self.turbine.pitch_actuator, self.turbine.generator
        v_seen = float(self.xi[-1])
        # the command within what the actuator can follow from the measured pitch, counted
        # from the blades farthest each way: one blade that runs away or seizes must not
        # drag the others' collective command with it
        p = meas["pitch"]
        p_lo = min(float(p[0]), float(p[1]), float(p[2]))
        p_hi = max(float(p[0]), float(p[1]), float(p[2]))
        lo = max(pa.min_pitch_rad, p_lo - self._reach)
        # the baseline's minimum-pitch schedule on the torque law's filtered speed
        floor = None if self._law is None else self._law.min_pitch()
        if floor is not None and floor > self._law.law.pitch_min:
            lo = max(lo, floor)
        q, dp, clipped = _ts_step(
            self.xi, self._u, y, dp_raw, ts.wind_grid, ts.reduction_grid, self._terms,
            self._phi, self._gam, ts.x0, ts.u0, self._K, -1 if self._ki is None else self._ki,
            -1 if self._int_src is None else self._int_src, self._q, self.dt,
            lo, min(pa.max_pitch_rad, p_hi + self._reach),
            gen.min_torque, gen.max_torque, self.torque_law is None, self._w)
        if clipped:
            self.premise_clipped += 1
            if not self._warned:
                log.warning("TS premise (v = %.3g m/s, dP = %.3g) outside the vertex grid; "
                            "clipped to it (further clips are counted in premise_clipped)",
                            v_seen, dp_raw)
                self._warned = True
        self._q = q
        pitch, torque = float(self._u[0]), float(self._u[1])
        if self._law is not None:           # torque from the schedule, pitch from the TS law
            torque = self._law(float(meas["gen_speed"]), pitch, ts.rated_power * (1.0 - dp))
            self._u[1] = torque
        self.signals = {"wind_est": float(self.xi[-1]), "power_reduction": dp,
                        "power_ref": ts.rated_power * (1.0 - dp),
                        "premise_clipped": float(clipped)}
        return np.array((pitch, pitch, pitch)), torque


@nb.njit(cache=True, nogil=True)
def _ts_step(xi: np.ndarray, u: np.ndarray, y: np.ndarray, dp_raw: float, wg: np.ndarray,
             rg: np.ndarray, terms: np.ndarray, phi: np.ndarray, gam: np.ndarray,
             x0: np.ndarray, u0: np.ndarray,
             kk: np.ndarray, ki: int, src: int, q_prev: float, dt: float, pmin: float,
             pmax: float, tmin: float, tmax: float, own_torque: bool, work: np.ndarray
             ) -> tuple[float, float, bool]:
    """One TS step in place: xi (observer, eq 10, exact ZOH per vertex, blended) and u (PDC
    law, eq 7, clipped to the actuators); returns the integral, the clipped dp and whether the
    premise was clipped. ``own_torque``: the TS torque is applied (else only a saturated pitch
    holds the integral). ``work`` is (2, N) scratch for the memberships. The observer's term k
    (``phi[k]``, ``gam[k]``) has weight h_i (``terms[k] = (i, -1)``) or h_i h_j."""
    nv, n = x0.shape[0], phi.shape[1]
    nu, ny = u.size, y.size
    h = work[0]
    dp, c1 = memberships(wg, rg, xi[n - 1], dp_raw, h)
    w = np.empty(nu + ny + 1)
    w[:nu] = u
    w[nu:nu + ny] = y
    w[nu + ny] = 1.0
    new = np.zeros(n)
    for k in range(terms.shape[0]):
        wk = h[terms[k, 0]]
        if terms[k, 1] >= 0:
            wk *= h[terms[k, 1]]
        if wk == 0.0:
            continue
        new += wk * (phi[k] @ xi + gam[k] @ w)
    xi[:] = new
    h2 = work[1]
    dp, c2 = memberships(wg, rg, xi[n - 1], dp_raw, h2)
    nx = n - 1
    q = q_prev
    if ki >= 0:
        ref = 0.0
        for i in range(nv):
            ref += h2[i] * x0[i, ki]
        err = (y[src] if src >= 0 else xi[ki]) - ref
        q = q_prev + err * dt
    out = np.zeros(nu)
    for i in range(nv):
        if h2[i] == 0.0:
            continue
        for r in range(nu):
            acc = u0[i, r]
            for j in range(nx):
                acc -= kk[i, r, j] * (xi[j] - x0[i, j])
            if ki >= 0:
                acc -= kk[i, r, nx] * q
            out[r] += h2[i] * acc
    v_top = wg[wg.size - 1]
    if wg.size > 1 and xi[n - 1] > v_top:   # beyond the last vertex: its pitch schedule goes on
        nb_ = rg.size
        kb, wb0, wb1, _c = hat_weights(rg, dp)
        slope = 0.0
        for ib, wb in ((kb, wb0), (kb + 1, wb1)):
            if wb == 0.0 or ib >= nb_:
                continue
            last, prev = (wg.size - 1) * nb_ + ib, (wg.size - 2) * nb_ + ib
            slope += wb * (u0[last, 0] - u0[prev, 0]) / (v_top - wg[wg.size - 2])
        out[0] += slope * (xi[n - 1] - v_top)
    pitch = min(max(out[0], pmin), pmax)
    torque = min(max(out[1], tmin), tmax)
    if pitch != out[0] or (own_torque and torque != out[1]):
        q = q_prev        # anti-windup: no integration while an applied input saturates
    u[0], u[1] = pitch, torque
    return q, dp, c1 or c2


key_caches_on_callees(__name__)

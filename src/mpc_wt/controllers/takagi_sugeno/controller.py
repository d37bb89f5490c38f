"""The Takagi-Sugeno controller and wind observer at run time (Clemens et al. eqs 7-10): the
gains of the vertices blended on the estimated premise, the observer's rotor-effective wind.
"""
from __future__ import annotations

import logging
import math
from typing import Any, Callable

import numpy as np
import scipy.linalg

import linearize
from linearize.validate import check_number
from mpc_wt.controllers.base import ControllerBase
from mpc_wt.controllers.estimator import SignalReader
from mpc_wt.controllers.takagi_sugeno.model import TSModel
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
    vertex grid is clipped to it (logged once per run, counted in ``premise_clipped``).

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

    Signals recorded: ``wind_est`` [m/s], ``power_reduction`` [-], ``power_ref`` [W],
    ``premise_clipped`` (0/1).
    """

    def __init__(self, ts: TSModel, controller: TSControllerDesign,
                 observer: TSObserverDesign, turbine: linearize.Turbine, *,
                 dt: float = 1.0 / 80.0,
                 power_reduction: Callable[[float], float] | None = None,
                 initial_wind_mps: float | None = None) -> None:
        check_number("dt", dt, lo=0.0, lo_open=True, unit="s")
        self.ts, self.ctl, self.obs, self.turbine = ts, controller, observer, turbine
        self.dt = float(dt)
        self.power_reduction = power_reduction
        if initial_wind_mps is not None:
            ts.check_premise(float(initial_wind_mps), float(ts.reduction_grid[0]))
        self._v_given = None if initial_wind_mps is None else float(initial_wind_mps)
        aa, bb, cc = observer.A_aug, observer.B_aug, observer.C_aug
        nv, n = aa.shape[:2]
        nu, ny = bb.shape[2], cc.shape[0]
        ki = controller.integral_of
        self._ki = None if ki is None else ts.states.index(ki)
        self._int_src = ts.measured.index(ki) if ki in ts.measured else None
        self._phi = np.empty((nv, n, n))
        self._gam = np.empty((nv, n, nu + ny + 1))
        xi0 = np.hstack([ts.x0, ts.v0[:, None]])
        for i in range(nv):
            f = aa[i] - observer.L[i] @ cc
            const = -aa[i] @ xi0[i] - bb[i] @ ts.u0[i]
            g = np.hstack([bb[i], observer.L[i], const[:, None]])
            m = np.zeros((n + g.shape[1], n + g.shape[1]))
            m[:n, :n], m[:n, n:] = f, g
            e = scipy.linalg.expm(m * dt)
            self._phi[i], self._gam[i] = e[:n, :n], e[:n, n:]
        self._read = SignalReader(ts.measured)
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

    def _start(self, v_init: float) -> None:
        """The observer's state at the vertex equilibrium of wind ``v_init``."""
        m = self.ts.blend(self.ts.membership(v_init, float(self.ts.reduction_grid[0])))
        self.xi = np.concatenate([m["x0"], [v_init]])
        self._u = m["u0"].copy()

    def _premise(self, v: float, dp: float) -> tuple[float, float, bool]:
        g1, g2 = self.ts.wind_grid, self.ts.reduction_grid
        vc, dc = float(np.clip(v, g1[0], g1[-1])), float(np.clip(dp, g2[0], g2[-1]))
        clipped = (vc != v) or (dc != dp)
        if clipped:
            self.premise_clipped += 1
            if not self._warned:
                log.warning("TS premise (v = %.3g m/s, dP = %.3g) outside the vertex grid; "
                            "clipped to it (further clips are counted in premise_clipped)",
                            v, dp)
                self._warned = True
        return vc, dc, clipped

    def step(self, t: float, meas: dict[str, Any]) -> tuple[np.ndarray, float]:
        # Observer update, memberships, PDC control law (Clemens eqs 5-10).
        y = self._read(meas)
        if not np.all(np.isfinite(y)):
            raise ValueError(f"non-finite measurement at t = {t:g} s: "
                             f"{dict(zip(self.ts.measured, y))}")
        if self.xi is None:                 # start in operation from the measured pitch
            self._start(self.ts.wind_at_pitch(float(np.mean(meas["pitch"]))))
        dp_raw = float(self.power_reduction(t)) if self.power_reduction else 0.0
        if not math.isfinite(dp_raw):
            raise ValueError(f"power_reduction({t:g}) returned {dp_raw!r}")
        v, dp, clipped = self._premise(float(self.xi[-1]), dp_raw)
        h = self.ts.membership(v, dp)
        act = np.nonzero(h)[0]
        w = np.concatenate([self._u, y, [1.0]])
        self.xi = sum(h[i] * (self._phi[i] @ self.xi + self._gam[i] @ w) for i in act)
        v, dp, clipped2 = self._premise(float(self.xi[-1]), dp_raw)
        h = self.ts.membership(v, dp)
        act = np.nonzero(h)[0]
        xh = self.xi[:-1]
        q_prev = self._q
        if self._ki is not None:
            src = self._int_src
            err = (y[src] if src is not None else xh[self._ki]) - h @ self.ts.x0[:, self._ki]
            self._q = q_prev + err * self.dt
        u = sum(h[i] * (self.ts.u0[i] - self.ctl.K[i] @ (
            np.append(xh - self.ts.x0[i], self._q) if self._ki is not None
            else xh - self.ts.x0[i])) for i in act)
        pa, gen = self.turbine.pitch_actuator, self.turbine.generator
        pitch = float(np.clip(u[0], pa.min_pitch_rad, pa.max_pitch_rad))
        torque = float(np.clip(u[1], gen.min_torque, gen.max_torque))
        if pitch != u[0] or torque != u[1]:
            self._q = q_prev  # anti-windup: no integration while an input saturates
        self._u = np.array([pitch, torque])
        self.signals = {"wind_est": float(self.xi[-1]), "power_reduction": dp,
                        "power_ref": self.ts.rated_power * (1.0 - dp),
                        "premise_clipped": float(clipped or clipped2)}
        return np.full(3, pitch), torque

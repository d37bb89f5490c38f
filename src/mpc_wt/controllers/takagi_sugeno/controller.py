"""The Takagi-Sugeno controller and wind observer as they are shipped (Clemens et al. eqs
7-10): the observer's zero-order-hold maps per vertex, the vertex gains and the torque law,
the numbers of the ``ts`` kind's C law.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np
import scipy.linalg

import linearize
from linearize.validate import check_number
from mpc_wt.controllers.apc import PowerReduction
from mpc_wt.controllers.base import DesignBase
from mpc_wt.controllers.baseline import LawTorque
from mpc_wt.controllers.takagi_sugeno.model import TSModel
from mpc_wt.controllers.takagi_sugeno.synthesis import TSControllerDesign, TSObserverDesign

__all__ = ["TSController"]


class TSController(DesignBase):
    """The design of the TS controller (eq 7) on TS observer estimates (eq 10), run by its
    shipped law (the ``ts`` kind's C law, ``mpc_wt/io/discon_c/ts.c``;
    :func:`mpc_wt.run.law_controller` runs a design made by hand).

    The observer is integrated exactly (zero-order hold on u and y) per vertex at the controller
    period; the law blends the vertex maps with the memberships of the current premise: for
    slowly varying premises this is the discretization of eq 10. The premise is the estimated
    wind v_hat and the power reduction Delta P(t) of ``power_reduction``; a premise outside the
    vertex grid is clipped to it (counted in the logged ``premise_clipped``); above the last
    vertex wind the equilibrium pitch is extrapolated along the last cell's slope (d theta_0 /
    dv of the last two vertices), so that the pitch keeps following a wind beyond the grid (a
    gust above cut-out) instead of holding the last vertex's equilibrium. The law starts in
    operation from what it measures: at its first call, the observer at the vertex equilibrium
    (no power reduction) of the wind whose pitch is the measured collective pitch,
    interpolated over the wind grid (clipped to it). A pitch command stays within the
    actuator's rate times its time constant of the measured pitch, counted from the blades
    farthest each way; the observer is fed the command applied.

    Parameters
    ----------
    ts : TSModel
        The model; its measured signals must be ones a turbine's controller reads
        (:data:`~mpc_wt.controllers.takagi_sugeno.TURBINE_MEASURED`).
    controller : TSControllerDesign
        The vertex gains (eq 7).
    observer : TSObserverDesign
        The observer gains (eq 10).
    turbine : Turbine
        Its actuator limits.
    dt : float
        Controller period [s].
    power_reduction : PowerReduction, optional
        Active power control (eq 11): Clemens et al.'s sinusoid on the simulation time
        (:func:`mpc_wt.controllers.apc.apc_reference`).
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

    Raises
    ------
    TypeError
        A power reduction that is not a :class:`~mpc_wt.controllers.apc.PowerReduction`.

    Notes
    -----
    The law logs ``wind_est`` [m/s], ``premise_clipped`` (0/1), ``power_reduction`` [-] and
    ``power_ref`` [W].
    """

    kind = "ts"

    def __init__(self, ts: TSModel, controller: TSControllerDesign,
                 observer: TSObserverDesign, turbine: linearize.Turbine, *,
                 dt: float = 1.0 / 80.0, power_reduction: PowerReduction | None = None,
                 torque_law: Any = None) -> None:
        check_number("dt", dt, lo=0.0, lo_open=True, unit="s")
        if power_reduction is not None and not isinstance(power_reduction, PowerReduction):
            raise TypeError(f"power_reduction must be a PowerReduction (Clemens et al.'s "
                            f"sinusoid, mpc_wt.controllers.apc.apc_reference) or None, got "
                            f"{type(power_reduction).__name__}: the law computes Delta P(t) "
                            f"from the simulation time")
        self.ts, self.ctl, self.obs, self.turbine = ts, controller, observer, turbine
        self.dt = float(dt)
        self.power_reduction = power_reduction
        ki = controller.integral_of
        self._ki = None if ki is None else ts.states.index(ki)
        self._int_src = ts.measured.index(ki) if ki in ts.measured else None
        self._terms, self._phi, self._gam = _observer_maps(ts, observer, self.dt)
        self.torque_law = torque_law
        self._law = LawTorque(torque_law, dt) if torque_law is not None else None
        # how far a command may lead the measured pitch: a first-order actuator (time
        # constant tau) then moves at most at its rate
        pa = turbine.pitch_actuator
        self._reach = (pa.max_rate_rad_s * pa.time_constant if pa.time_constant > 0
                       else math.inf)
        self._K = np.ascontiguousarray(controller.K, dtype=float)


def _observer_maps(ts: TSModel, observer: TSObserverDesign, dt: float
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The observer's terms and their zero-order-hold maps over a period ``dt`` (eq 10): one
    term per vertex when the vertices measure alike (weights h_i), else one per pair of
    vertices active together (weights h_i h_j: the output prediction is blended as the plant's
    measurement is). Each term's state map ``phi`` and its map ``gamma`` of [u; y; 1]."""
    aa, bb, cc = observer.A_aug, observer.B_aug, observer.C_aug
    n = aa.shape[1]
    nu, ny = bb.shape[2], cc.shape[-2]
    terms = [(i, -1) for i in range(aa.shape[0])] if ts.common_output else ts.active_pairs()
    phi = np.empty((len(terms), n, n))
    gam = np.empty((len(terms), n, nu + ny + 1))
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
        phi[k], gam[k] = e[:n, :n], e[:n, n:]
    return np.array(terms, dtype=np.int64), phi, gam


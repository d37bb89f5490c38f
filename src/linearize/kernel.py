"""The plant's compiled kernels: the right-hand side and outputs (:func:`evaluate_plant`), the
wind each blade element meets (:func:`sample_wind`) and the fixed-step RK4 steps, pure
functions on packed arrays (numba, nopython).
"""
from __future__ import annotations

import math

import numba as nb
import numpy as np

from linearize.bem import (
    MODE_NOLIMITS,
    element_kernel,
    locate_cell,
)
from linearize.params import n_x

#: the blades' azimuth spacing [rad]
TWO_PI_3 = 2.0 * math.pi / 3.0

__all__ = ["evaluate_plant", "sample_wind", "step_kernel"]

DENSE_STRIDES = (8,)                   # the strides of a 1-D C-contiguous float64 array


# --------------------------------------------------------------------------------------------
# Kernels
# --------------------------------------------------------------------------------------------
_JIT = dict(cache=True, error_model="numpy")


@nb.njit(**_JIT)
def _clip(v, lo, hi):  # pragma: no cover - compiled
    return lo + 0.0 * v if v.real < lo else (hi + 0.0 * v if v.real > hi else v)


@nb.njit(**_JIT)
def evaluate_plant(x, u, wind, p, hint, mode):  # pragma: no cover - compiled
    """Derivatives, outputs and BEM state at one instant (generic over float and complex).

    ``wind``: (3, n_r) [m/s]. ``hint``: (4, 3, n_r) BEM state of a nearby earlier solve --
    inflow angle, residual slope, axial and tangential induced velocities (NaN: none); the same
    layout is returned.
    ``mode``: bits of :mod:`linearize.bem` (frozen wake, complex step, tight, no limits).
    """
    dof_fa, dof_ss, dof_dt, dof_gen, dof_flap, dof_pitch = (p.dof[0], p.dof[1], p.dof[2],
                                                            p.dof[3], p.dof[4], p.dof[5])
    dof_edge = p.dof[6]
    limits = (mode & MODE_NOLIMITS) == 0
    nr = p.r.size
    dx = np.zeros(n_x, dtype=x.dtype)
    z = np.zeros(31, dtype=x.dtype)
    bem = np.empty((4, 3, nr), dtype=x.dtype)
    xd = x[1]
    wr = x[2]
    wg = x[3]
    th = x[4]
    yd = x[9]
    psi = x[16]
    # pitch actually applied and its rate
    pitch = np.empty(3, dtype=x.dtype)
    prate = np.zeros(3, dtype=x.dtype)
    for i in range(3):
        ref = _clip(u[i], p.min_p, p.max_p) if limits else u[i]
        if dof_pitch:
            pitch[i] = x[5 + i]
            rate = (ref - x[5 + i]) / p.tau_p
            prate[i] = _clip(rate, -p.rate_p, p.rate_p) if limits else rate
        else:
            pitch[i] = ref
    tq = _clip(u[3], p.min_tq, p.max_tq) if limits else u[3]
    cc = math.cos(p.cone)
    sc = math.sin(p.cone)
    ct = math.cos(p.tilt)
    st = math.sin(p.tilt)
    vhub_x = p.hub_fa * xd if dof_fa else 0.0 * xd
    vhub_y = p.hub_ss * yd if dof_ss else 0.0 * yd
    nod = p.slope_fa * xd if dof_fa else 0.0 * xd       # tower-top pitch rate
    roll = -p.slope_ss * yd if dof_ss else 0.0 * yd     # tower-top roll rate about +x
    torque = 0.0 * wr
    thrust = 0.0 * wr
    fy = 0.0 * wr
    mtilt = 0.0 * wr
    myaw = 0.0 * wr
    mflap_aero = np.zeros(3, dtype=x.dtype)
    medge_aero = np.zeros(3, dtype=x.dtype)
    gq = np.zeros(3, dtype=x.dtype)
    ge = np.zeros(3, dtype=x.dtype)
    for i in range(3):
        psi_i = psi + i * TWO_PI_3
        sp = np.sin(psi_i)
        cp = np.cos(psi_i)
        qd = x[13 + i] if dof_flap else 0.0 * x[13 + i]
        ed = x[20 + i] if dof_edge else 0.0 * x[20 + i]
        tor_i = 0.0 * wr
        thr_i = 0.0 * wr
        mf = 0.0 * wr
        me = 0.0 * wr
        gqi = 0.0 * wr
        for j in range(nr):
            rj = p.r[j]
            vrel = wind[i, j] - vhub_x - nod * rj * cc * cp
            vx = vrel * (ct * cc + st * sc * cp) - qd * p.phi_flap[j]
            vy = (wr + roll) * rj * cc + vrel * st * sp - vhub_y * cp + ed * p.phi_edge[j]
            npr, tpr, ph, sl, u_ind, v_ind = element_kernel(
                vx, vy, rj, p.chord[j], p.twist[j] + pitch[i], p.af[j], p.table, p.alpha0,
                p.dalpha, p.nb, p.rtip, p.rhub, p.flags, p.rho, hint[0, i, j].real,
                hint[1, i, j].real, hint[2, i, j].real, hint[3, i, j].real, mode)
            bem[0, i, j] = ph
            bem[1, i, j] = sl
            bem[2, i, j] = u_ind
            bem[3, i, j] = v_ind
            wj = p.w[j]
            tor_i += tpr * rj * cc * wj
            thr_i += npr * cc * wj
            mf += npr * (rj - p.rhub) * wj
            me += tpr * (rj - p.rhub) * wj
            gqi += npr * p.phi_flap[j] * wj
            ge[i] += tpr * p.phi_edge[j] * wj
            fy += -tpr * cp * wj
        torque += tor_i
        thrust += thr_i
        mflap_aero[i] = mf
        medge_aero[i] = me
        gq[i] = gqi
        if p.opt[0]:
            ge[i] += p.grav * p.g_e * sp * ct
        mtilt += mf * cp
        myaw += mf * sp
    # edgewise modes: elastic, damping and aerodynamic/gravity forces F_i; the rotor and the
    # edges share the inertia S_e = int m phi_e r ds (M_e q'' + S_e Omega' = F)
    fe = np.zeros(3, dtype=x.dtype)
    cpl = 0.0 * wr
    j_cut = 0.0
    if dof_edge:
        ke = p.k_e + wr * wr * (p.k_cf_e - p.m_e)
        for i in range(3):
            fe[i] = ge[i] - p.c_e * x[20 + i] - ke * x[17 + i]
        cpl = p.s_e / p.m_e * (fe[0] + fe[1] + fe[2])
        j_cut = 3.0 * p.s_e * p.s_e / p.m_e
    # drivetrain (Madsen eq 11), rotor inertia less what the edge modes carry
    if dof_gen:
        if dof_dt:
            qs = p.k_shaft * th + p.c_shaft * (wr - wg / p.ngear)
            dwr = (torque - qs - cpl) / (p.j_rot - j_cut)
            dwg = (qs / p.ngear - tq) / p.j_gen
            dth = wr - wg / p.ngear
        else:
            jt = p.j_rot + p.ngear * p.ngear * p.j_gen
            dwr = (torque - p.ngear * tq - cpl) / (jt - j_cut)
            dwg = p.ngear * dwr
            dth = 0.0 * dwr
    else:
        dwr = 0.0 * wr
        dwg = 0.0 * wr
        dth = 0.0 * wr
        qs = p.k_shaft * th if dof_dt else p.ngear * tq
    edd = np.zeros(3, dtype=x.dtype)
    if dof_edge:
        for i in range(3):
            edd[i] = (fe[i] - p.s_e * dwr) / p.m_e
    if dof_gen and not dof_dt:
        # rotor side: J_r Omega' + S_e sum q'' = Q_aero - Q_shaft
        qs = torque - p.j_rot * dwr - p.s_e * (edd[0] + edd[1] + edd[2])
    # reaction torque on the nacelle about +x (rotor and generator spin the same way)
    m_react = tq + (1.0 - 1.0 / p.ngear) * qs
    # tower fore-aft + blade flap (inertially coupled)
    omega2 = wr * wr
    kq = p.k_b + omega2 * p.k_cf
    fq = np.zeros(3, dtype=x.dtype)
    for i in range(3):
        if dof_flap:
            fq[i] = gq[i] - p.c_b * x[13 + i] - kq * x[10 + i]
    xdd = 0.0 * wr
    if dof_fa:
        ft = (thrust * ct * p.hub_fa + mtilt * p.slope_fa - p.c_fa * xd - p.k_fa * x[0])
        if dof_flap:
            ratio = p.m_c / p.m_b
            xdd = (ft - ratio * (fq[0] + fq[1] + fq[2])) / (p.m_fa - 3.0 * p.m_c * ratio)
        else:
            xdd = ft / p.m_fa
    qdd = np.zeros(3, dtype=x.dtype)
    if dof_flap:
        for i in range(3):
            qdd[i] = (fq[i] - p.m_c * xdd) / p.m_b
    ydd = 0.0 * wr
    if dof_ss:
        fss = fy * p.hub_ss - m_react * p.slope_ss - p.c_ss * yd - p.k_ss * x[8]
        ydd = fss / p.m_ss
    # derivatives
    if dof_fa:
        dx[0] = xd
        dx[1] = xdd
    dx[2] = dwr
    dx[3] = dwg
    dx[4] = dth
    if dof_pitch:
        dx[5] = prate[0]
        dx[6] = prate[1]
        dx[7] = prate[2]
    if dof_ss:
        dx[8] = yd
        dx[9] = ydd
    if dof_flap:
        for i in range(3):
            dx[10 + i] = x[13 + i]
            dx[13 + i] = qdd[i]
    dx[16] = wr
    if dof_edge:
        for i in range(3):
            dx[17 + i] = x[20 + i]
            dx[20 + i] = edd[i]
    # outputs
    z[0] = p.eta_gen * tq * wg
    for i in range(3):
        z[1 + i] = pitch[i]
        z[4 + i] = prate[i]
    z[7] = xd
    z[8] = wr
    z[9] = th
    for i in range(3):
        psi_i = psi + i * TWO_PI_3
        q = x[10 + i] if dof_flap else 0.0 * x[10 + i]
        mf = (mflap_aero[i] - p.hub_fa * xdd * p.s1 - qdd[i] * p.s_phi_s
              - omega2 * q * p.s_phi_r)
        me = medge_aero[i] - dwr * p.i_edge - edd[i] * p.s_phie_s
        if p.opt[0]:
            me += p.grav * p.s1 * np.sin(psi_i) * ct
        z[10 + i] = mf
        z[13 + i] = me
    z[16] = (thrust * ct * p.zhub + mtilt + p.fa_static + p.fa_pdelta * x[0]
             - p.fa_inertia * xdd)
    z[17] = m_react - fy * p.zhub - p.ss_pdelta * x[8] + p.ss_inertia * ydd
    z[18] = qs
    tl = 0.0 * wr
    yw = 0.0 * wr
    for i in range(3):
        psi_i = psi + i * TWO_PI_3
        tl += np.cos(psi_i) * z[10 + i]
        yw += np.sin(psi_i) * z[10 + i]
    z[19] = 2.0 / 3.0 * tl
    z[20] = 2.0 / 3.0 * yw
    z[21] = psi - 2.0 * math.pi * math.floor(psi.real / (2.0 * math.pi))
    z[22] = torque
    z[23] = thrust
    z[24] = torque * wr
    z[25] = wg
    z[26] = tq
    z[27] = xdd
    z[28] = ydd
    z[29] = x[0]
    z[30] = x[8]
    return dx, z, bem


# wind kinds: 0 = steady power law (speed, exponent), 1 = grid (t, y, z) trilinear
@nb.njit(**_JIT)
def _element_positions(psi, p):  # pragma: no cover - compiled
    nr = p.r.size
    ys = np.empty((3, nr))
    zs = np.empty((3, nr))
    cc = math.cos(p.cone)
    ct = math.cos(p.tilt)
    for i in range(3):
        psi_i = psi + i * TWO_PI_3
        s = math.sin(psi_i)
        c = math.cos(psi_i)
        for j in range(nr):
            rr = p.r[j] * cc
            ys[i, j] = -rr * s
            zs[i, j] = p.zhub + rr * c * ct
    return ys, zs


@nb.njit(**_JIT)
def sample_wind(t, psi, p, kind, wpar, grid):  # pragma: no cover - compiled
    ys, zs = _element_positions(psi, p)
    nr = p.r.size
    out = np.empty((3, nr))
    if kind == 0:
        v = wpar[0]
        a = wpar[1]
        for i in range(3):
            for j in range(nr):
                zz = zs[i, j] if zs[i, j] > 1e-3 else 1e-3
                out[i, j] = v * (zz / p.zhub) ** a if a != 0.0 else v
        return out
    t0, dt, y0, dy, z0, dz = wpar[0], wpar[1], wpar[2], wpar[3], wpar[4], wpar[5]
    nt, ny, nz = grid.shape
    if nt == 1:
        it, at = 0, 0.0
    else:
        it, at = locate_cell((t - t0) / dt, nt)
    for i in range(3):
        for j in range(nr):
            iy, ay = locate_cell((ys[i, j] - y0) / dy, ny)
            iz, az = locate_cell((zs[i, j] - z0) / dz, nz)
            acc = 0.0
            for kt in range(2):
                if nt == 1 and kt == 1:
                    break
                wt = (1.0 - at) if kt == 0 else at
                if nt == 1:
                    wt = 1.0
                g = grid[it + kt]
                acc += wt * ((1 - ay) * (1 - az) * g[iy, iz] + ay * (1 - az) * g[iy + 1, iz]
                             + (1 - ay) * az * g[iy, iz + 1] + ay * az * g[iy + 1, iz + 1])
            out[i, j] = acc
    return out


@nb.njit(**_JIT)
def _rk4(t, x, u, h, p, kind, wpar, grid, hint, dphi):  # pragma: no cover - compiled
    """One RK4 step. ``hint`` seeds the BEM solves; ``dphi`` is each element's change of
    inflow angle over the previous step, used to extrapolate the hints of stages 2 and 4.

    Returns the new state, the outputs at t, the stage-4 BEM state and the new ``dphi``.
    """
    w1 = sample_wind(t, x[16], p, kind, wpar, grid)
    k1, z, ph1 = evaluate_plant(x, u, w1, p, hint, 0)
    x2 = x + 0.5 * h * k1
    hint2 = ph1.copy()
    hint2[0] += 0.5 * dphi
    k2, _, ph2 = evaluate_plant(x2, u, sample_wind(t + 0.5 * h, x2[16], p, kind, wpar, grid), p, hint2,
                       0)
    x3 = x + 0.5 * h * k2
    k3, _, ph3 = evaluate_plant(x3, u, sample_wind(t + 0.5 * h, x3[16], p, kind, wpar, grid), p, ph2, 0)
    x4 = x + h * k3
    hint4 = ph3.copy()
    hint4[0] += 0.5 * dphi
    k4, _, ph4 = evaluate_plant(x4, u, sample_wind(t + h, x4[16], p, kind, wpar, grid), p, hint4, 0)
    xn = x + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    new_dphi = ph4[0] - ph1[0]
    for i in range(new_dphi.shape[0]):
        for j in range(new_dphi.shape[1]):
            if new_dphi[i, j] != new_dphi[i, j]:
                new_dphi[i, j] = 0.0
    return xn, z, ph4, new_dphi


@nb.njit(**_JIT)
def bad_state(x, lim):  # pragma: no cover - compiled
    # lim: (2, n_x) lower and upper bounds
    for k in range(x.size):
        if not (lim[0, k] <= x[k] <= lim[1, k]):   # also catches NaN
            return k
    return -1


@nb.njit(**_JIT)
def _rk4_into(t, x, u, h, p, kind, wpar, grid, hint, dphi, lim, x_out, z_out):  # pragma: no cover
    """:func:`_rk4` with its results written into ``x_out``, ``z_out`` and the warm start
    (``hint``, ``dphi``) in place; returns the first state outside the envelope ``lim`` (-1:
    none). Nothing is returned to Python but an int: no arrays to box at every step."""
    xn, z, ph4, nd = _rk4(t, x, u, h, p, kind, wpar, grid, hint, dphi)
    x_out[:] = xn
    z_out[:] = z
    hint[:] = ph4
    dphi[:] = nd
    return bad_state(xn, lim)


#: The compiled RK4 step of :meth:`PlantStepper.step_into`, for closed loops compiled with their
#: controller: ``step_kernel(t, x, u, *stepper.kernel_args(), x_out, z_out)`` in nopython code
#: advances the plant and the stepper's warm start and returns the first state outside the
#: envelope (-1: none).
step_kernel = _rk4_into


@nb.njit(**_JIT)
def simulate_kernel(x0, u_seq, t0, h, n_steps, p, kind, wpar, grid, lim, rate_tq):  # pragma: no cover
    nx = x0.size
    xs = np.empty((n_steps + 1, nx))
    zs = np.empty((n_steps + 1, 31))
    us = np.empty((n_steps + 1, 4))
    x = x0.copy()
    hint = np.full((4, 3, p.r.size), np.nan)
    dphi = np.zeros((3, p.r.size))
    u = u_seq[0].copy()
    tq = u[3]
    for k in range(n_steps + 1):
        uk = u_seq[min(k, u_seq.shape[0] - 1)]
        for i in range(3):
            u[i] = uk[i]
        step = rate_tq * h
        tq = tq + _clip(uk[3] - tq, -step, step)
        u[3] = tq
        xs[k] = x
        us[k] = u
        t = t0 + k * h
        if k == n_steps:
            w = sample_wind(t, x[16], p, kind, wpar, grid)
            _, z, _ = evaluate_plant(x, u, w, p, hint, 0)
            zs[k] = z
            break
        xn, z, hint, dphi = _rk4(t, x, u, h, p, kind, wpar, grid, hint, dphi)
        zs[k] = z
        bad = bad_state(xn, lim)
        if bad >= 0:
            return xs[:k + 1], zs[:k + 1], us[:k + 1], k + 1, bad, xn[bad]
        x = xn
    return xs, zs, us, n_steps + 1, -1, 0.0

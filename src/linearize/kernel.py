"""The plant's compiled kernels: the right-hand side and outputs (:func:`evaluate_plant`), the
wind each blade element meets (:func:`sample_wind`) and the fixed-step RK4 steps, pure
functions on packed arrays (numba, nopython).
"""
from __future__ import annotations

import math

import numba as nb
import numpy as np

from linearize.bem import (
    MODE_CS,
    MODE_FROZEN,
    MODE_NOLIMITS,
    element_kernel,
    polar_lookup,
    locate_cell,
)
from linearize.jitcache import key_caches_on_callees
from linearize.params import n_x
from linearize.unsteady import HINT_ROWS_UA, UA_ROW, ua_increment, ua_update

_ALPHA_ROW, _W_ROW = HINT_ROWS_UA - 2, HINT_ROWS_UA - 1

#: the blades' azimuth spacing [rad]
TWO_PI_3 = 2.0 * math.pi / 3.0

__all__ = ["evaluate_plant", "evaluate_plant_vw", "sample_wind", "sample_inplane", "sample_tower",
           "step_kernel"]

DENSE_STRIDES = (8,)                   # the strides of a 1-D C-contiguous float64 array

#: The u grid a wind without one passes to :func:`sample_wind`. Read-only, as every grid wind's
#: is: numba compiles a kernel for a writable array apart from one for a read-only array.
NO_GRID = np.zeros((1, 1, 1), dtype=np.float32)
NO_GRID.flags.writeable = False


# --------------------------------------------------------------------------------------------
# Kernels
# --------------------------------------------------------------------------------------------
_JIT = dict(cache=True, error_model="numpy")


@nb.njit(**_JIT)
def _clip(v, lo, hi):  # pragma: no cover - compiled
    return lo + 0.0 * v if v.real < lo else (hi + 0.0 * v if v.real > hi else v)


#: The rotor tip-speed ratios between which the BEM induction fades out (AeroDyn's BEMT:
#: none below the first, all above the second, a cosine blend between).
BEM_TSR_BOUNDS = (1.0, 2.0)


@nb.njit(**_JIT)
def _bem_weight(wr, wind, rtip, mode):  # pragma: no cover - compiled
    """The share of the BEM induction kept at the rotor's tip-speed ratio Omega R / U (U the
    mean free wind over the elements): 1 from :data:`BEM_TSR_BOUNDS`[1] up, 0 below [0], a
    cosine blend between (as AeroDyn 15's BEMT in OpenFAST: ``BEMT_lowerBoundTSR`` = 1,
    ``BEMT_upperBoundTSR`` = 2). Momentum theory has no meaning on a rotor that barely turns:
    a parked or stopping rotor's inflow is the geometric one. A frozen-wake or complex-step
    evaluation (linearization, at operating points) keeps all of it."""
    if mode & (MODE_FROZEN | MODE_CS):
        return 1.0
    u_mean = 0.0
    for i in range(wind.shape[0]):
        for j in range(wind.shape[1]):
            u_mean += wind[i, j].real
    u_mean /= wind.shape[0] * wind.shape[1]
    if u_mean <= 0.0:
        return 1.0
    tsr = abs(wr.real) * rtip / u_mean
    lo, hi = BEM_TSR_BOUNDS
    if tsr >= hi:
        return 1.0
    if tsr <= lo:
        return 0.0
    return 0.5 - 0.5 * math.cos(math.pi * (tsr - lo) / (hi - lo))


@nb.njit(**_JIT)
def evaluate_plant(x, u, wind, p, hint, mode):  # pragma: no cover - compiled
    """Derivatives, outputs and BEM state at one instant (generic over float and complex).

    ``wind``: (3, n_r) [m/s]. ``hint``: (4, 3, n_r) BEM state of a nearby earlier solve --
    inflow angle, residual slope, axial and tangential induced velocities (NaN: none); the same
    layout is returned.
    ``mode``: bits of :mod:`linearize.bem` (frozen wake, complex step, tight, no limits).
    The wind has no lateral or vertical component (:func:`evaluate_plant_vw` with them).
    """
    return evaluate_plant_vw(x, u, wind, (np.zeros((2, 3, p.r.size)), np.zeros((2, 0))), p,
                             hint, mode)


@nb.njit(**_JIT)
def evaluate_plant_vw(x, u, wind, ext, p, hint, mode):  # pragma: no cover - compiled
    """:func:`evaluate_plant` with more of the free wind, ``ext`` = (vw, tw): the lateral
    (+y, to the left looking downwind) and vertical (+z) components at each element, ``vw``
    (2, 3, n_r) [m/s], and u and v at the tower's drag points, ``tw`` (2, n_q) [m/s] (n_q = 0:
    no tower drag). The element components are
    projected on the coned, tilted blade element's normal and tangential directions:
    normal  u (cos t cos c + sin t sin c cos psi) + w (sin c cos t cos psi - sin t cos c)
    - v sin c sin psi, tangential (against the blade's motion) v cos psi + w cos t sin psi
    (and u sin t sin psi), with shaft tilt t, precone c and azimuth psi (Jonkman 2007,
    NREL/TP-500-41958, the hub and blade coordinate systems; AeroDyn's relative velocity);
    with ``deflected_blades`` (``opt[8]``) c is each element's local cone, the precone less
    its out-of-plane bending slope, and its distance from the shaft follows the deflection.
    """
    vw = ext[0]
    tw = ext[1]
    dof_fa, dof_ss, dof_dt, dof_gen, dof_flap, dof_pitch = (p.dof[0], p.dof[1], p.dof[2],
                                                            p.dof[3], p.dof[4], p.dof[5])
    dof_edge = p.dof[6]
    limits = (mode & MODE_NOLIMITS) == 0
    nr = p.r.size
    dx = np.zeros(n_x, dtype=x.dtype)
    z = np.zeros(31, dtype=x.dtype)
    bem = np.empty((hint.shape[0], 3, nr), dtype=x.dtype)
    for k in range(4, hint.shape[0]):
        for i in range(3):
            for j in range(nr):
                bem[k, i, j] = hint[k, i, j]
    ua_on = p.opt[4] != 0 and mode == 0 and hint.shape[0] >= HINT_ROWS_UA
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
    shadow = p.opt[3] != 0 and p.twr_h.size > 1
    defl = p.opt[8] != 0
    mflap_aero = np.zeros(3, dtype=x.dtype)
    mbody = np.zeros(3, dtype=x.dtype)
    medge_aero = np.zeros(3, dtype=x.dtype)
    gq = np.zeros(3, dtype=x.dtype)
    ge = np.zeros(3, dtype=x.dtype)
    w_bem = _bem_weight(wr, wind, p.rtip, mode)
    # the skewed wake (Pitt and Peters): the disk-averaged wind relative to the hub, its angle
    # to the shaft (chi_0) and the direction of its part in the rotor plane
    skew = p.opt[7] != 0 and mode == 0
    chi0 = 0.0
    dir_y = 0.0
    dir_up = 0.0
    if skew:
        chi0, dir_y, dir_up = _disk_skew(wind, vw, vhub_x.real, vhub_y.real, ct, st)
    # the element data as locals: an array field read from the parameter tuple in the loop
    # costs a reference count each time
    r_e, chord_e, twist_e, af_e, w_e = p.r, p.chord, p.twist, p.af, p.w
    phi_fl, phi_ed, dphi_fl, dphi_ed = p.phi_flap, p.phi_edge, p.dphi_flap, p.dphi_edge
    ax_fl, ax_ed, twist_se = p.ax_flap, p.ax_edge, p.twist_s
    table, alpha0, dalpha, flags, ua_par = p.table, p.alpha0, p.dalpha, p.flags, p.ua
    for i in range(3):
        psi_i = psi + i * TWO_PI_3
        sp = np.sin(psi_i)
        cp = np.cos(psi_i)
        qd = x[13 + i] if dof_flap else 0.0 * x[13 + i]
        ed = x[20 + i] if dof_edge else 0.0 * x[20 + i]
        qx = x[10 + i] if dof_flap else 0.0 * x[10 + i]
        ex = x[17 + i] if dof_edge else 0.0 * x[17 + i]
        tor_i = 0.0 * wr
        thr_i = 0.0 * wr
        mf = 0.0 * wr
        me = 0.0 * wr
        gqi = 0.0 * wr
        for j in range(nr):
            rj = r_e[j]
            uf = wind[i, j]
            v_tw = 0.0 * uf
            if shadow:
                fu, fv = _tower_potential_flow(rj, cp, sp, cc, sc, ct, st, p)
                v_tw = fv * uf
                uf = fu * uf
            vrel = uf - vhub_x - nod * rj * cc * cp
            vv = vw[0, i, j] + v_tw
            # the modes' directions: flapwise cos(th) x + sin(th) e, edgewise cos(th) e -
            # sin(th) x (x downwind, e the direction of rotation), th = pitch + twist
            if p.opt[5]:
                cs = np.cos(pitch[i] + twist_se[j])
                ss = np.sin(pitch[i] + twist_se[j])
            else:
                cs = 1.0 + 0.0 * pitch[i]
                ss = 0.0 * pitch[i]
            vq = qd * phi_fl[j]
            ve = ed * phi_ed[j]
            if defl:
                # the element's local cone, the precone less the out-of-plane bending slope,
                # and its distance from the shaft: the out-of-plane deflection along the coned
                # normal, less the blade's axial shortening (an inextensible blade)
                slope = qx * dphi_fl[j] * cs - ex * dphi_ed[j] * ss
                ccj = np.cos(p.cone - slope)
                scj = np.sin(p.cone - slope)
                rad = (rj * cc + (qx * phi_fl[j] * cs - ex * phi_ed[j] * ss) * sc
                       - (qx * qx * ax_fl[j] + ex * ex * ax_ed[j]) * cc)
                # the in-plane deflection turns with the rotor: its velocity, radially inward,
                # has a part along the coned normal
                v_ip = wr * (qx * phi_fl[j] * ss + ex * phi_ed[j] * cs) * scj
            else:
                ccj = cc + 0.0 * wr
                scj = sc + 0.0 * wr
                rad = rj * cc + 0.0 * wr
                v_ip = 0.0 * wr
            vx = (vrel * (ct * ccj + st * scj * cp) - vq * cs + ve * ss
                  + vw[1, i, j] * (scj * ct * cp - st * ccj) - vv * scj * sp + v_ip)
            vy = ((wr + roll) * rad + vrel * st * sp - vhub_y * cp + ve * cs + vq * ss
                  + vv * cp + vw[1, i, j] * ct * sp)
            if w_bem > 0.0:
                npr, tpr, ph, sl, u_ind, v_ind = element_kernel(
                    vx, vy, rj, chord_e[j], twist_e[j] + pitch[i], af_e[j], table, alpha0,
                    dalpha, p.nb, p.rtip, p.rhub, flags, p.rho, hint[0, i, j].real,
                    hint[1, i, j].real, hint[2, i, j].real, hint[3, i, j].real, mode)
            if w_bem < 1.0:     # low tip-speed ratio: the induction faded out
                u_ind = w_bem * u_ind if w_bem > 0.0 else 0.0 * vx
                v_ind = w_bem * v_ind if w_bem > 0.0 else 0.0 * vx
                npr, tpr, ph, sl, u_ind, v_ind = element_kernel(
                    vx, vy, rj, chord_e[j], twist_e[j] + pitch[i], af_e[j], table, alpha0,
                    dalpha, p.nb, p.rtip, p.rhub, flags, p.rho, math.nan, math.nan,
                    u_ind.real, v_ind.real, np.int64(MODE_FROZEN))
            bem[0, i, j] = ph
            bem[1, i, j] = sl
            bem[2, i, j] = u_ind
            bem[3, i, j] = v_ind
            if skew and chi0 > 0.0 and vx.real > 0.0:
                # the solved induction scaled as AeroDyn's BEM_Mod = 1 does, the loads from it
                # (the next solve starts from the uncorrected root kept above)
                a_ind = u_ind.real / vx.real
                chi = (0.6 * a_ind + 1.0) * chi0
                tn = math.tan(0.5 * chi) if abs(chi) <= 0.5 * math.pi else math.copysign(1.0, chi)
                corr = (SKEW_FACTOR * tn * rj * cc / p.rtip
                        * (cp.real * dir_up - sp.real * dir_y))
                u_ind = u_ind * (1.0 + corr)
                npr, tpr, ph, _, _, _ = element_kernel(
                    vx, vy, rj, chord_e[j], twist_e[j] + pitch[i], af_e[j], table, alpha0,
                    dalpha, p.nb, p.rtip, p.rhub, flags, p.rho, math.nan, math.nan,
                    u_ind.real, v_ind.real, np.int64(MODE_FROZEN))
            if ua_on and ua_par[af_e[j], 0] != 0.0:
                npr, tpr = _ua_loads(npr, tpr, ph, vx - u_ind, vy + v_ind, twist_e[j] + pitch[i],
                                     i, j, p, hint, bem)
            wj = w_e[j]
            tor_i += tpr * rad * wj
            thr_i += npr * ccj * wj
            mf += npr * (rj - p.rhub) * wj
            me += tpr * (rj - p.rhub) * wj
            gqi += (npr * cs + tpr * ss) * phi_fl[j] * wj
            ge[i] += (tpr * cs - npr * ss) * phi_ed[j] * wj
            fy += -tpr * cp * wj
        if p.w[nr] > 0.0:
            npr, tpr, rad_t, cs_t, ss_t = _tip_node(i, wr, roll, vhub_x, vhub_y, nod, qd, ed,
                                                    pitch[i], sp, cp, cc, ct, st, wind, vw, p)
            wt = p.w[nr]
            tor_i += tpr * rad_t * wt
            thr_i += npr * cc * wt
            mf += npr * (p.rtip - p.rhub) * wt
            me += tpr * (p.rtip - p.rhub) * wt
            gqi += (npr * cs_t + tpr * ss_t) * p.w[nr + 1] * wt
            ge[i] += (tpr * cs_t - npr * ss_t) * p.w[nr + 2] * wt
            fy += -tpr * cp * wt
        if p.opt[1]:
            # the blade's own forces normal to it (precone centrifugal, gravity along the
            # tilted shaft and across the coned blade), on the flap mode and the root moment
            fn_cf = wr * wr * sc * cc
            fn_g = p.grav * (st * cc - sc * ct * cp) if p.opt[0] else 0.0 * wr
            gqi += fn_cf * p.s_phi_r + fn_g * p.g_b
            mbody[i] = fn_cf * p.i_edge + fn_g * p.s1
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
    # drivetrain (Madsen eq 11), rotor inertia less what the edge modes carry; the gearbox's
    # loss brakes the high-speed side, as ElastoDyn's GBoxEff does while generating: the
    # generator torque tq asks tq / eta_gbx of the gearbox, and the electrical power is
    # eta_gen tq w_gen (ServoDyn's GenEff)
    if dof_gen:
        if dof_dt:
            qs = p.k_shaft * th + p.c_shaft * (wr - wg / p.ngear)
            dwr = (torque - qs - cpl) / (p.j_rot - j_cut)
            dwg = (qs / p.ngear - tq / p.eta_gbx) / p.j_gen
            dth = wr - wg / p.ngear
        else:
            jt = p.j_rot + p.ngear * p.ngear * p.j_gen
            dwr = (torque - p.ngear * tq / p.eta_gbx - cpl) / (jt - j_cut)
            dwg = p.ngear * dwr
            dth = 0.0 * dwr
    else:
        dwr = 0.0 * wr
        dwg = 0.0 * wr
        dth = 0.0 * wr
        qs = p.k_shaft * th if dof_dt else p.ngear * tq / p.eta_gbx
    edd = np.zeros(3, dtype=x.dtype)
    if dof_edge:
        for i in range(3):
            edd[i] = (fe[i] - p.s_e * dwr) / p.m_e
    if dof_gen and not dof_dt:
        # rotor side: J_r Omega' + S_e sum q'' = Q_aero - Q_shaft
        qs = torque - p.j_rot * dwr - p.s_e * (edd[0] + edd[1] + edd[2])
    # reaction torque on the nacelle about +x (rotor and generator spin the same way)
    m_react = tq + (1.0 - p.eta_gbx / p.ngear) * qs
    # tower fore-aft + blade flap (inertially coupled)
    omega2 = wr * wr
    kq = p.k_b + omega2 * p.k_cf
    fq = np.zeros(3, dtype=x.dtype)
    for i in range(3):
        if dof_flap:
            fq[i] = gq[i] - p.c_b * x[13 + i] - kq * x[10 + i]
    drag_fa, drag_ss, drag_my, drag_mx = _tower_drag(xd, yd, tw, p)
    xdd = 0.0 * wr
    if dof_fa:
        ft = (thrust * ct * p.hub_fa + mtilt * p.slope_fa - p.c_fa * xd - p.k_fa * x[0]
              + drag_fa)
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
        fss = fy * p.hub_ss - m_react * p.slope_ss - p.c_ss * yd - p.k_ss * x[8] + drag_ss
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
        # the modes' accelerations out of and in the plane (twisted directions)
        c_p = np.cos(pitch[i]) if p.opt[5] else 1.0 + 0.0 * pitch[i]
        s_p = np.sin(pitch[i]) if p.opt[5] else 0.0 * pitch[i]
        mf = (mflap_aero[i] + mbody[i] - p.hub_fa * xdd * p.s1
              - qdd[i] * (c_p * p.sfc - s_p * p.sfs) + edd[i] * (s_p * p.sec + c_p * p.ses)
              - omega2 * q * p.s_phi_r)
        me = (medge_aero[i] - dwr * p.i_edge - edd[i] * (c_p * p.sec - s_p * p.ses)
              - qdd[i] * (s_p * p.sfc + c_p * p.sfs))
        if p.opt[0]:
            me += p.grav * p.s1 * np.sin(psi_i) * ct
        z[10 + i] = mf
        z[13 + i] = me
    tl = 0.0 * wr
    yw = 0.0 * wr
    f_flap = 0.0 * wr
    for i in range(3):
        psi_i = psi + i * TWO_PI_3
        tl += np.cos(psi_i) * z[10 + i]
        yw += np.sin(psi_i) * z[10 + i]
        f_flap += qdd[i]
    # the tower base takes what the blade roots pass on: the thrust less the flap modes'
    # inertia relative to the hub, int m phi q'' (the same coupling as the tower's equation),
    # and the root moments' tilt (aerodynamic, inertial and body forces)
    z[16] = ((thrust - p.g_b * f_flap) * ct * p.zhub + tl + p.fa_static + p.fa_pdelta * x[0]
             - p.fa_inertia * xdd + drag_my)
    z[17] = m_react - fy * p.zhub - p.ss_pdelta * x[8] + p.ss_inertia * ydd - drag_mx
    z[18] = qs
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


@nb.njit(**_JIT)
def _tip_node(i, wr, roll, vhub_x, vhub_y, nod, qd, ed, pitch, sp, cp, cc, ct, st, wind, vw,
              p):  # pragma: no cover - compiled
    """Line loads (N', T') [N/m] at blade i's tip node as AeroDyn 15 has them with the tip
    loss on (its BEMT's ``FixedInductions``: where the Prandtl factor's constant vanishes the
    inductions are a = 1, a' = 0): the inflow lies in the rotor plane, phi = 0, alpha =
    -(pitch + twist), W = V_y, so N' = q C_l, T' = -q C_d with q = rho W^2 c / 2. The tip
    node has the last element's chord, twist, airfoil and free wind, its weight and the flap
    and edge modes' values there follow the elements' weights in ``p.w``; also returned: its
    distance from the shaft and the cosine and sine of its structural twist with the
    pitch."""
    jt = p.r.size - 1
    if p.opt[5]:
        cs = np.cos(pitch + p.twist_s[jt])
        ss = np.sin(pitch + p.twist_s[jt])
    else:
        cs = 1.0 + 0.0 * pitch
        ss = 0.0 * pitch
    rad = p.rtip * cc + 0.0 * wr
    vrel = wind[i, jt] - vhub_x - nod * p.rtip * cc * cp
    vy = ((wr + roll) * rad + vrel * st * sp - vhub_y * cp + ed * p.w[jt + 3] * cs
          + qd * p.w[jt + 2] * ss + vw[0, i, jt] * cp + vw[1, i, jt] * ct * sp)
    cl, cd = polar_lookup(p.table, p.af[jt], -(p.twist[jt] + pitch), p.alpha0, p.dalpha)
    q = 0.5 * p.rho * vy * vy * p.chord[jt]
    return q * cl, -q * cd, rad, cs, ss


#: Pitt and Peters' skewed-wake factor, 15 pi / 32 (AeroDyn's default ``SkewRedistrFactor``)
SKEW_FACTOR = 15.0 * math.pi / 32.0


@nb.njit(**_JIT)
def _disk_skew(wind, vw, vhub_x, vhub_y, ct, st):  # pragma: no cover - compiled
    """The wake's skew from the wind the elements meet: the mean over all elements of the free
    wind (u, v, w) less the hub's translation (AeroDyn's disk average ``V_diskAvg``), resolved
    along the tilted shaft (x_s = (cos t, 0, -sin t)) and in the rotor plane (lateral y and
    the plane's up, (sin t, 0, cos t)). Returns chi_0 = acos(V.x_s / |V|) [rad] and the unit
    direction of V's in-plane part (lateral, up); (0, 0, 0) when V has none."""
    su = 0.0
    sv = 0.0
    sw = 0.0
    for i in range(wind.shape[0]):
        for j in range(wind.shape[1]):
            su += wind[i, j].real
            sv += vw[0, i, j].real
            sw += vw[1, i, j].real
    n = wind.shape[0] * wind.shape[1]
    wx = su / n - vhub_x
    wy = sv / n - vhub_y
    wz = sw / n
    w_ax = wx * ct - wz * st
    w_up = wx * st + wz * ct
    w_ip = math.sqrt(wy * wy + w_up * w_up)
    if w_ip <= 0.0:
        return 0.0, 0.0, 0.0
    return math.atan2(w_ip, w_ax), wy / w_ip, w_up / w_ip


@nb.njit(**_JIT)
def _tower_drag(xd, yd, tw, p):  # pragma: no cover - compiled
    """Drag on the tower (AeroDyn's ``TwrAero``): per unit height 0.5 rho C_d D |V| V with V
    the free wind (u, v) at the tower's axis less the tower's velocity in its first modes.
    Returns the generalized forces on the fore-aft and side-side modes [N] and the base
    moments of the downwind and lateral forces, int f h dh [N m]."""
    gfa = 0.0 * xd
    gss = 0.0 * xd
    mfa = 0.0 * xd
    mss = 0.0 * xd
    if p.opt[6] == 0 or tw.shape[1] != p.tq_h.size:
        return gfa, gss, mfa, mss
    for k in range(p.tq_h.size):
        vx = tw[0, k] - xd * p.tq_fa[k]
        vy = tw[1, k] - yd * p.tq_ss[k]
        sp = np.sqrt(vx * vx + vy * vy)
        fx = p.tq_w[k] * sp * vx
        fy = p.tq_w[k] * sp * vy
        gfa += fx * p.tq_fa[k]
        gss += fy * p.tq_ss[k]
        mfa += fx * p.tq_h[k]
        mss += fy * p.tq_h[k]
    return gfa, gss, mfa, mss


@nb.njit(**_JIT)
def sample_tower(t, p, kind, wpar, grid):  # pragma: no cover - compiled
    """The free wind's u and v at the tower's drag points (on its axis), (2, n_q) [m/s];
    ``grid``: the u grid and the v-w grid."""
    nq = p.tq_h.size if p.opt[6] else 0
    out = np.zeros((2, nq))
    if nq == 0:
        return out
    if kind == 0:
        for k in range(nq):
            zz = max(p.tq_h[k], 1e-3)
            out[0, k] = wpar[0] * (zz / p.zhub) ** wpar[1] if wpar[1] != 0.0 else wpar[0]
        return out
    ys = np.zeros((1, nq))
    zs = np.empty((1, nq))
    zs[0] = p.tq_h
    _sample_grid(t, ys, zs, wpar, grid[0], out[0:1])
    if grid[1].shape[1] > 1 and p.opt[2]:
        _sample_grid(t, ys, zs, wpar, grid[1][0], out[1:2])
    return out


@nb.njit(**_JIT)
def _ua_loads(npr, tpr, phi, ua, ut, theta, i, j, p, hint, bem):  # pragma: no cover - compiled
    """Element (i, j)'s loads with the unsteady airfoil coefficients in place of the static
    ones: the BEM's inflow angle and induction stay (AeroDyn's coupling), the lift and drag
    follow the states. The static loads ``npr``, ``tpr`` are q (C_l cos phi + C_d sin phi),
    q (C_l sin phi - C_d cos phi) at this phi and W, so the model's increment
    (:func:`linearize.unsteady.ua_increment`) is added to them without a second polar lookup.
    Leaves the element's alpha and W in ``bem`` for the step's state update."""
    w2 = ua.real * ua.real + ut.real * ut.real
    w = math.sqrt(w2)
    bem[_ALPHA_ROW, i, j] = phi.real - theta.real
    bem[_W_ROW, i, j] = w
    dcl, dcd, valid = ua_increment(hint, i, j)
    if not valid or w2 <= 0.0:
        return npr, tpr
    q = 0.5 * p.rho * w2 * p.chord[j]
    s = ua.real / w         # sin and cos of the inflow angle
    c = ut.real / w
    return npr + q * (dcl * c + dcd * s), tpr + q * (dcl * s - dcd * c)


@nb.njit(**_JIT)
def _tower_potential_flow(r, cp, sp, cc, sc, ct, st, p):  # pragma: no cover - compiled
    """Potential flow around the tower at a blade element (AeroDyn's ``TwrPotent = 1``;
    Moriarty and Hansen 2005, NREL/EL-500-36881, sec. 7): with x downwind of and y across the
    tower's axis in units of the local tower radius R, the free wind U becomes
    u = U (1 - (x^2 - y^2) / (x^2 + y^2)^2) and v = -U 2 x y / (x^2 + y^2)^2. The element at
    radius ``r`` [m] and azimuth (cos, sin) = (``cp``, ``sp``) in its undeflected position (so
    that the loads stay independent of the displacements, as the trim needs; AeroDyn takes
    the deflected one); above the tower top or below its base the tower does not act.

    ``cc``, ``sc``, ``ct``, ``st``: cosine and sine of the precone and the shaft tilt.

    Returns the factors (u / U, v / U)."""
    z = p.zhub + r * cc * cp * ct
    if z.real > p.twr_h[-1] or z.real < p.twr_h[0]:
        return 1.0 + 0.0 * z, 0.0 * z
    k = 0
    while k < p.twr_h.size - 2 and z.real > p.twr_h[k + 1]:
        k += 1
    a = (z - p.twr_h[k]) / (p.twr_h[k + 1] - p.twr_h[k])
    rad = (1.0 - a) * p.twr_r[k] + a * p.twr_r[k + 1]
    xt = (p.x_apex + r * (cc * cp * st - sc * ct)) / rad
    yt = -r * cc * sp / rad
    d2 = xt * xt + yt * yt
    if d2.real < 1.0:
        d2 = 1.0 + 0.0 * d2
    return 1.0 - (xt * xt - yt * yt) / (d2 * d2), -2.0 * xt * yt / (d2 * d2)


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
    _sample_grid(t, ys, zs, wpar, grid, out)
    return out


@nb.njit(**_JIT)
def _sample_grid(t, ys, zs, wpar, grid, out):  # pragma: no cover - compiled
    """Trilinear interpolation of a (n_t, n_y, n_z) grid at each element into ``out``."""
    t0, dt, y0, dy, z0, dz = wpar[0], wpar[1], wpar[2], wpar[3], wpar[4], wpar[5]
    nt, ny, nz = grid.shape
    if nt == 1:
        it, at = 0, 0.0
    else:
        it, at = locate_cell((t - t0) / dt, nt)
    for i in range(ys.shape[0]):
        for j in range(ys.shape[1]):
            iy, ay = locate_cell((ys[i, j] - y0) / dy, ny)
            iz, az = locate_cell((zs[i, j] - z0) / dz, nz)
            acc = 0.0
            for kt in range(2):
                if nt == 1 and kt == 1:
                    break
                wt = (1.0 - at) if kt == 0 else at
                if nt == 1:
                    wt = 1.0
                m = it + kt         # indexed in place: a view per point costs its refcounts
                acc += wt * ((1 - ay) * (1 - az) * grid[m, iy, iz]
                             + ay * (1 - az) * grid[m, iy + 1, iz]
                             + (1 - ay) * az * grid[m, iy, iz + 1]
                             + ay * az * grid[m, iy + 1, iz + 1])
            out[i, j] = acc


@nb.njit(**_JIT)
def sample_inplane(t, psi, p, kind, wpar, vw_grid):  # pragma: no cover - compiled
    """The free wind's lateral and vertical components at each element, (2, 3, n_r) [m/s]:
    zero for a steady wind, a grid without them (``vw_grid`` of shape (2, 1, 1, 1)) or a
    plant without in-plane wind."""
    nr = p.r.size
    out = np.zeros((2, 3, nr))
    if kind != 1 or vw_grid.shape[1] == 1 or p.opt[2] == 0:
        return out
    ys, zs = _element_positions(psi, p)
    _sample_grid(t, ys, zs, wpar, vw_grid[0], out[0])
    _sample_grid(t, ys, zs, wpar, vw_grid[1], out[1])
    return out


@nb.njit(**_JIT)
def _sample_uvw(t, psi, p, kind, wpar, grid_u, grid_vw):  # pragma: no cover - compiled
    """:func:`sample_wind` and :func:`sample_inplane` together: with a grid wind that has v and
    w, the elements' positions and cells are found once for the three components."""
    nr = p.r.size
    if kind != 1 or grid_vw.shape[1] == 1 or p.opt[2] == 0:
        return (sample_wind(t, psi, p, kind, wpar, grid_u),
                sample_inplane(t, psi, p, kind, wpar, grid_vw))
    ys, zs = _element_positions(psi, p)
    out = np.empty((3, nr))
    vw = np.empty((2, 3, nr))
    t0, dt, y0, dy, z0, dz = wpar[0], wpar[1], wpar[2], wpar[3], wpar[4], wpar[5]
    nt, ny, nz = grid_u.shape
    it, at = (0, 0.0) if nt == 1 else locate_cell((t - t0) / dt, nt)
    nt2 = 1 if nt == 1 else 2
    for i in range(3):
        for j in range(nr):
            iy, ay = locate_cell((ys[i, j] - y0) / dy, ny)
            iz, az = locate_cell((zs[i, j] - z0) / dz, nz)
            w00 = (1 - ay) * (1 - az)
            w10 = ay * (1 - az)
            w01 = (1 - ay) * az
            w11 = ay * az
            su = 0.0
            sv = 0.0
            sw = 0.0
            for kt in range(nt2):
                wt = 1.0 if nt == 1 else ((1.0 - at) if kt == 0 else at)
                m = it + kt
                su += wt * (w00 * grid_u[m, iy, iz] + w10 * grid_u[m, iy + 1, iz]
                            + w01 * grid_u[m, iy, iz + 1] + w11 * grid_u[m, iy + 1, iz + 1])
                sv += wt * (w00 * grid_vw[0, m, iy, iz] + w10 * grid_vw[0, m, iy + 1, iz]
                            + w01 * grid_vw[0, m, iy, iz + 1]
                            + w11 * grid_vw[0, m, iy + 1, iz + 1])
                sw += wt * (w00 * grid_vw[1, m, iy, iz] + w10 * grid_vw[1, m, iy + 1, iz]
                            + w01 * grid_vw[1, m, iy, iz + 1]
                            + w11 * grid_vw[1, m, iy + 1, iz + 1])
            out[i, j] = su
            vw[0, i, j] = sv
            vw[1, i, j] = sw
    return out, vw


@nb.njit(**_JIT)
def _stage(t, x, u, p, kind, wpar, grid, hint):  # pragma: no cover - compiled
    """The plant at one RK4 stage: the wind at the elements (``grid``: the u grid and the
    (2, ...) v, w grid) and :func:`evaluate_plant_vw`."""
    w, vw = _sample_uvw(t, x[16], p, kind, wpar, grid[0], grid[1])
    tw = sample_tower(t, p, kind, wpar, grid)
    return evaluate_plant_vw(x, u, w, (vw, tw), p, hint, np.int64(0))


@nb.njit(**_JIT)
def _rk4(t, x, u, h, p, kind, wpar, grid, hint, dphi):  # pragma: no cover - compiled
    """One RK4 step. ``hint`` seeds the BEM solves; ``dphi`` is each element's change of
    inflow angle over the previous step, used to extrapolate the hints of stages 2 and 4.
    ``grid``: (u grid, v-w grid), see :func:`sample_wind` and :func:`sample_inplane`.

    Returns the new state, the outputs at t, the stage-4 BEM state and the new ``dphi``.
    """
    nx = x.size
    k1, z, ph1 = _stage(t, x, u, p, kind, wpar, grid, hint)
    phi1 = ph1[0].copy()
    xs = np.empty(nx)
    for m in range(nx):
        xs[m] = x[m] + 0.5 * h * k1[m]
    ph1[0] += 0.5 * dphi             # the stage-1 solution, extrapolated: stage 2's warm start
    k2, _, ph2 = _stage(t + 0.5 * h, xs, u, p, kind, wpar, grid, ph1)
    for m in range(nx):
        xs[m] = x[m] + 0.5 * h * k2[m]
    k3, _, ph3 = _stage(t + 0.5 * h, xs, u, p, kind, wpar, grid, ph2)
    for m in range(nx):
        xs[m] = x[m] + h * k3[m]
    ph3[0] += 0.5 * dphi
    k4, _, ph4 = _stage(t + h, xs, u, p, kind, wpar, grid, ph3)
    xn = np.empty(nx)
    for m in range(nx):
        xn[m] = x[m] + h / 6.0 * (k1[m] + 2.0 * k2[m] + 2.0 * k3[m] + k4[m])
    ua_update(ph4, p)
    new_dphi = ph4[0] - phi1
    for i in range(new_dphi.shape[0]):
        for j in range(new_dphi.shape[1]):
            if new_dphi[i, j] != new_dphi[i, j]:
                new_dphi[i, j] = 0.0
    return xn, z, ph4, new_dphi


@nb.njit(**_JIT)
def new_hint(p, dt):  # pragma: no cover - compiled
    """A fresh warm start for a run at plant step ``dt`` [s]: the BEM rows (NaN: no solve
    yet) and, with unsteady aerodynamics on, the UA state rows (NaN: first step) and dt."""
    rows = HINT_ROWS_UA if p.opt[4] != 0 else 4
    hint = np.full((rows, 3, p.r.size), np.nan)
    if rows > 4:
        hint[HINT_ROWS_UA - 3] = dt
        hint[HINT_ROWS_UA - 5:HINT_ROWS_UA - 3] = 0.0
    return hint


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
    hint = new_hint(p, h)
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
            _, z, _ = _stage(t, x, u, p, kind, wpar, grid, hint)
            zs[k] = z
            break
        xn, z, hint, dphi = _rk4(t, x, u, h, p, kind, wpar, grid, hint, dphi)
        zs[k] = z
        bad = bad_state(xn, lim)
        if bad >= 0:
            return xs[:k + 1], zs[:k + 1], us[:k + 1], k + 1, bad, xn[bad]
        x = xn
    return xs, zs, us, n_steps + 1, -1, 0.0


key_caches_on_callees(__name__)

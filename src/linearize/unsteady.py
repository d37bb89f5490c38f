"""Unsteady airfoil aerodynamics: a Beddoes-Leishman-type model in AeroDyn's discrete form,
acting on each blade element of the time-domain plant.

The model follows the incompressible core of the Beddoes-Leishman model as AeroDyn 15 runs it
with ``UA_Mod = 3`` (Minnema/Pierce) and ``FLookup = True`` (Damiani and Hayman 2019,
NREL/TP-5000-66347, "The Unsteady Aerodynamics Module for FAST 8", eqs 1.5-1.56; Leishman and
Beddoes 1989):

* the angle of attack low-pass filtered at a reduced frequency ``filt_cutoff``
  (eq 1.8), the attached-flow circulatory lag by Wagner's two-term indicial function with
  deficiency functions X1, X2 (eqs 1.14-1.15; A1, A2, b1, b2), in the semichords travelled
  ``ds = 2 W dt / c`` (eq 1.5b), with the Prandtl-Glauert factor beta = sqrt(1 - M^2) of the
  element's Mach number M = W / a (eqs 1.11-1.13);
* the non-circulatory (apparent-mass) normal force of the filtered angle-of-attack rate,
  4 T_alpha (K_alpha - K'_alpha) / M (eqs 1.7-1.11, 1.18), which leads the circulatory lag;
* the leading-edge pressure lag T_p on the potential normal force (eqs 1.34-1.35) giving the
  effective separation angle alpha_f;
* the trailing-edge separation point f' from the static polar by the inverse Kirchhoff
  relation, lagged by T_f0 (eqs 1.32-1.36), for the normal force and, with its own lookup, for
  the chordwise force (eq 1.40 with Gonzalez's offset 0.2);
* normal force C_n = C_n,nc + C_n,alpha alpha_e f'' + C_n,fs (1 - f'') with the fully
  separated C_n,fs from the static polar, chordwise force C_c = C_c,pot (sqrt(f''_c) - 0.2);
  lift and drag C_l = C_n cos(alpha) + C_c sin(alpha), C_d = C_n sin(alpha) - C_c cos(alpha)
  + C_d0 (eqs 1.2, 1.39-1.40);
* blended to the static polar within 5 deg below ``cutout`` and static above it.

Left out: the pitch-rate terms (the blade does not twist), the pitching moment, the
leading-edge vortex lift (eqs 1.47-1.55) and the time-constant switching of the full model
(sigma = 1). In steady flow the model returns the static polar wherever the static normal
force lies below the attached-flow line C_n,alpha / beta (alpha - alpha0), and that line
where it lies above: AeroDyn's steady behaviour with the same airfoil data (J. Jonkman, 2020,
"Incorrect Unsteady Airfoil Aerodynamic Input Parameters", OpenFAST r-test repository: the
NREL 5-MW's UA coefficients lower the mean lift of the DU21 and DU25 airfoils).

The states are discrete, updated once per plant step (as AeroDyn's), and kept beside the BEM
warm start: rows ``UA_ROW`` .. of the kernel's ``hint`` array.
"""
from __future__ import annotations

import math

import numba as nb
import numpy as np

from linearize.bem import polar_lookup
from linearize.jitcache import key_caches_on_callees

__all__ = ["UA_ROW", "N_UA", "HINT_ROWS_UA", "UA_PAR", "ua_increment", "ua_update",
           "ua_steady"]

#: first ``hint`` row of the UA states
UA_ROW = 4
#: states per element: filtered alpha, X1, X2, C_n,pot, D_p, f', D_f, f'_c, D_fc, K_alpha,f,
#: q_f, K'_alpha
N_UA = 12
#: the rows of the model's lift and drag less the static polar's (from the last update, held
#: over the next step), the plant step dt, then the last stage's alpha and W
_DCL, _DCD = UA_ROW + N_UA, UA_ROW + N_UA + 1
_DT, _ALPHA, _W = UA_ROW + N_UA + 2, UA_ROW + N_UA + 3, UA_ROW + N_UA + 4
#: rows of a ``hint`` that carries UA states
HINT_ROWS_UA = UA_ROW + N_UA + 5
#: columns of the per-airfoil parameter table: has UA, alpha0, C_n,alpha, C_d0, A1, A2, b1,
#: b2, T_p, T_f0, filt_cutoff, cutout, speed of sound
UA_PAR = ("on", "alpha0", "cn_alpha", "cd0", "a1", "a2", "b1", "b2", "t_p", "t_f0",
          "filt_cutoff", "cutout", "speed_of_sound")
_GONZALEZ = 0.2
_JIT = dict(cache=True, error_model="numpy")


@nb.njit(**_JIT)
def _separation(table, k, alpha, ua, kp, cna, a0, dalpha):  # pragma: no cover - compiled
    """From one lookup of the static polar at alpha: the separation point f' of the normal
    force (inverse Kirchhoff, eq 1.32a) with the attached-flow slope ``cna``, the fully
    separated normal force C_n,fs there, and the separation point f'_c of the chordwise force
    (eq 1.32b, Gonzalez offset). ``ua[kp]``: the airfoil's parameters (:data:`UA_PAR`)."""
    cl, cd = polar_lookup(table, k, alpha, a0, dalpha)
    s, c = math.sin(alpha), math.cos(alpha)
    cd0 = ua[kp, 3]
    cn = cl * c + (cd - cd0) * s
    cc = cl * s - (cd - cd0) * c
    lin = cna * (alpha - ua[kp, 1])
    x = 0.0
    if lin != 0.0 and cn != 0.0:
        x = cn / lin
        if x < 0.0:
            x = 0.0
    f = (2.0 * math.sqrt(x) - 1.0) ** 2
    cn_fs = 0.0
    if f >= 1.0:
        f = 1.0
    else:
        cn_fs = (cn - lin * f) / (1.0 - f)
    limit = (1.0 + _GONZALEZ) ** 2
    fc = limit
    if lin * s != 0.0:
        # cc / (lin tan(alpha))
        fc = min((cc * c / (lin * s) + _GONZALEZ) ** 2, limit)
    return f, cn_fs, fc


@nb.njit(**_JIT)
def _chain(alpha, w, chord, dt, ua, kp, st, r0, i, j, table, k, a0,
           dalpha):  # pragma: no cover - compiled
    """One step of the model: the coefficients (C_l, C_d) at the current alpha [rad] and
    relative speed w [m/s], from the previous step's states ``st[r0:r0 + N_UA, i, j]``, which
    it replaces with the new ones (in place: no views, no allocation in the plant's step).
    ``ua[kp]``: the airfoil's parameters (:data:`UA_PAR`); ``k``: its polar in ``table``."""
    w = max(w, 1e-3)
    mach = min(w / ua[kp, 12], 0.7)
    beta2 = 1.0 - mach * mach
    beta = math.sqrt(beta2)
    cna = ua[kp, 2] / beta
    ds = 2.0 * w * dt / chord
    cut = max(1.0, w) * ua[kp, 10] / (math.pi * chord)
    lp = math.exp(-2.0 * math.pi * dt * cut)
    a_prev = st[r0 + 0, i, j]
    a_filt = lp * a_prev + (1.0 - lp) * alpha
    da = a_filt - a_prev
    # non-circulatory normal force of the filtered rate (eqs 1.7-1.11, 1.18)
    q_cur = da / dt * chord / w
    q_f = lp * st[r0 + 10, i, j] + (1.0 - lp) * q_cur
    ka_f = q_f * w / chord
    k_alpha = 1.0 / ((1.0 - mach) + 0.5 * ua[kp, 2] * mach * mach * beta
                     * (ua[kp, 4] * ua[kp, 6] + ua[kp, 5] * ua[kp, 7]))
    t_alpha = 0.75 * k_alpha * chord / ua[kp, 12]
    het = math.exp(-0.5 * dt / t_alpha)     # sqrt of the decay, squared below
    et = het * het
    kp_alpha = st[r0 + 11, i, j] * et + (ka_f - st[r0 + 9, i, j]) * het
    cn_nc = 4.0 * t_alpha * (ka_f - kp_alpha) / mach
    # circulatory, Wagner (eqs 1.13-1.15)
    he1, he2 = math.exp(-0.5 * ua[kp, 6] * ds * beta2), math.exp(-0.5 * ua[kp, 7] * ds * beta2)
    x1 = st[r0 + 1, i, j] * he1 * he1 + ua[kp, 4] * da * he1
    x2 = st[r0 + 2, i, j] * he2 * he2 + ua[kp, 5] * da * he2
    a_e = a_filt - ua[kp, 1] - x1 - x2
    cn_circ = cna * a_e
    cn_pot = cn_circ + cn_nc
    hep = math.exp(-0.5 * ds / ua[kp, 8])
    dp = st[r0 + 4, i, j] * hep * hep + (cn_pot - st[r0 + 3, i, j]) * hep
    a_f = (cn_pot - dp) / cna + ua[kp, 1]
    fp, _, fpc = _separation(table, k, a_f, ua, kp, cna, a0, dalpha)
    hef = math.exp(-0.5 * ds / ua[kp, 9])
    df = st[r0 + 6, i, j] * hef * hef + (fp - st[r0 + 5, i, j]) * hef
    dfc = st[r0 + 8, i, j] * hef * hef + (fpc - st[r0 + 7, i, j]) * hef
    f2 = min(max(fp - df, 0.0), 1.0)
    f2c = min(max(fpc - dfc, 0.0), (1.0 + _GONZALEZ) ** 2)
    _, cn_fs, _ = _separation(table, k, a_e + ua[kp, 1], ua, kp, cna, a0, dalpha)
    cn = cn_nc + cn_circ * f2 + cn_fs * (1.0 - f2)
    cc = cn_circ * math.tan(a_e + ua[kp, 1]) * (math.sqrt(f2c) - _GONZALEZ)
    s, c = math.sin(alpha), math.cos(alpha)
    cl = cn * c + cc * s
    cd = cn * s - cc * c + ua[kp, 3]
    new = (a_filt, x1, x2, cn_pot, dp, fp, df, fpc, dfc, ka_f, q_f, kp_alpha)   # N_UA states
    for m in range(N_UA):
        st[r0 + m, i, j] = new[m]
    return cl, cd


@nb.njit(**_JIT)
def _blend(alpha, cl, cd, ua, kp, table, k, a0, dalpha):  # pragma: no cover - compiled
    """The model's coefficients blended to the static polar near and above the cut-out."""
    a = abs(alpha)
    if a <= ua[kp, 11] - math.radians(5.0):
        return cl, cd
    cls, cds = polar_lookup(table, k, alpha, a0, dalpha)
    if a >= ua[kp, 11]:
        return cls, cds
    w = 0.5 + 0.5 * math.cos(math.pi * (a - ua[kp, 11] + math.radians(5.0)) / math.radians(5.0))
    return w * cl + (1.0 - w) * cls, w * cd + (1.0 - w) * cds


@nb.njit(**_JIT)
def _initial(alpha, w, ua, kp, table, k, a0, dalpha):  # pragma: no cover - compiled
    """States of a steady flow at alpha and relative speed w [m/s] (the first step of a run),
    (N_UA,)."""
    mach = min(max(w, 1e-3) / ua[kp, 12], 0.7)
    cna = ua[kp, 2] / math.sqrt(1.0 - mach * mach)
    st = np.zeros(N_UA)
    st[0] = alpha
    st[3] = cna * (alpha - ua[kp, 1])
    st[5], _, st[7] = _separation(table, k, alpha, ua, kp, cna, a0, dalpha)
    return st


@nb.njit(**_JIT)
def ua_increment(hint, i, j):  # pragma: no cover - compiled
    """(dC_l, dC_d, valid) of element (i, j): the model's lift and drag less the static
    polar's at the last update, held over the step as the model's states are (the model runs
    once per element and step, in :func:`ua_update`); the element's unsteady coefficients
    are the static polar's at its current alpha plus these. ``valid`` False (and zeros)
    before the first update."""
    if hint[UA_ROW, i, j] != hint[UA_ROW, i, j]:
        return 0.0, 0.0, False
    return hint[_DCL, i, j], hint[_DCD, i, j], True


@nb.njit(**_JIT)
def ua_update(hint, p):  # pragma: no cover - compiled
    """Advance every element's states one step, from the alpha and W the last stage left in
    ``hint`` (in place); elements of airfoils without UA data keep NaN states."""
    if hint.shape[0] < HINT_ROWS_UA:
        return
    ua = p.ua
    for i in range(hint.shape[1]):
        for j in range(hint.shape[2]):
            k = p.af[j]
            alpha = hint[_ALPHA, i, j]
            if ua[k, 0] == 0.0 or alpha != alpha:
                continue
            if hint[UA_ROW, i, j] != hint[UA_ROW, i, j]:
                st = _initial(alpha, hint[_W, i, j], ua, k, p.table, k, p.alpha0, p.dalpha)
                for m in range(N_UA):
                    hint[UA_ROW + m, i, j] = st[m]
            cl, cd = _chain(alpha, hint[_W, i, j], p.chord[j], hint[_DT, i, j], ua, k, hint,
                            UA_ROW, i, j, p.table, k, p.alpha0, p.dalpha)
            cl, cd = _blend(alpha, cl, cd, ua, k, p.table, k, p.alpha0, p.dalpha)
            cls, cds = polar_lookup(p.table, k, alpha, p.alpha0, p.dalpha)
            hint[_DCL, i, j] = cl - cls
            hint[_DCD, i, j] = cd - cds


@nb.njit(**_JIT)
def ua_steady(alpha, w, par, table, k, a0, dalpha):  # pragma: no cover - compiled
    """The model's steady-flow coefficients (C_l, C_d) at alpha [rad] and relative speed w
    [m/s]: its fixed point. ``par``: the airfoil's parameters (:data:`UA_PAR`), contiguous;
    ``k``: its polar in ``table``."""
    ua = par.reshape((1, par.size))
    st = _initial(alpha, w, ua, 0, table, k, a0, dalpha).reshape((N_UA, 1, 1))
    cl, cd = _chain(alpha, w, 1.0, 0.01, ua, 0, st, 0, 0, 0, table, k, a0, dalpha)
    return _blend(alpha, cl, cd, ua, 0, table, k, a0, dalpha)


key_caches_on_callees(__name__)

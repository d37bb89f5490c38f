"""Blade-element-momentum aerodynamics (Madsen et al. 2012, eqs 1-7).

The inflow angle phi of each element is the root of one residual (Ning 2014), solved by Brent's
method inside a bracket that always holds a root, so the solve always converges:

    R(phi) = sin(phi) / (1 - a(phi)) - (V_x / V_y) cos(phi) / (1 + a'(phi))

with a, a' from Madsen eqs 5-7 (Prandtl tip and hub loss F) and, above a = 0.4, Buhl's
empirical high-induction relation. Forces per unit length follow Madsen eq 2; rotor torque,
thrust and root moments follow eq 3 (moments taken about the blade root).

Numerical kernels are numba-compiled pure functions; :func:`element_loads` is the public,
validated entry point here, and :func:`linearize.steady_coefficients` evaluates whole rotors
through the plant (one code path for surfaces, trim and simulation).

References
----------
Madsen, Filsoe, Soltani (2012), Preview-based asymmetric load reduction of wind turbines,
IEEE CCA, doi:10.1109/CCA.2012.6402671.
Ning (2014), A simple solution method for the blade element momentum equations with guaranteed
convergence, Wind Energy 17, doi:10.1002/we.1636.
Buhl (2005), A new empirical relationship between thrust coefficient and induction factor for
the turbulent windmill state, NREL/TP-500-36834.
Hansen (2015), Aerodynamics of Wind Turbines, 3rd ed., Routledge, ch. 6.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numba as nb
import numpy as np
from scipy.interpolate import Akima1DInterpolator

from linearize._typing import FloatArray
from linearize.turbine import Polar, Turbine
from linearize.validate import check_array

__all__ = ["AeroOptions", "PolarTable", "build_polar_table", "element_induction", "element_loads",
           "polar_table_of"]

_PI = math.pi
_EPS_PHI = 1e-6          # Ning's epsilon: bracket ends stay clear of the phi = 0 singularity
_XTOL = 1e-13            # absolute tolerance on phi, cold solves [rad]
_XTOL_WARM = 1e-7        # Newton correction at which a warm-started solve stops [rad]
_N_ALPHA = 1441          # polar grid: 0.25 deg from -180 to 180 deg


@dataclass(frozen=True)
class AeroOptions:
    """Switches of the aerodynamic model.

    Parameters
    ----------
    tip_loss, hub_loss : bool
        Prandtl tip and hub loss factors.
    tangential_induction : bool
        Solve for a' (else a' = 0).
    tilt, cone : bool
        Apply shaft tilt and precone in the element kinematics and loads.
    gravity : bool
        Add the blade's gravity moment to the edgewise root moment.
    induction_limits : bool
        AeroDyn 15's checks where momentum theory has no meaning (:func:`_limited`): a root
        whose loading factor has the wrong sign for its branch takes the geometric inflow, a
        and a' stay within [-1, 1.5] and [-1, 1]. CCBlade has none (off to compare with it);
        the windmill state never reaches them.
    """

    tip_loss: bool = True
    hub_loss: bool = True
    tangential_induction: bool = True
    tilt: bool = True
    cone: bool = True
    gravity: bool = True
    induction_limits: bool = True

    @property
    def azimuth_independent(self) -> "AeroOptions":
        """The same options with tilt, cone and gravity switched off."""
        from dataclasses import replace
        return replace(self, tilt=False, cone=False, gravity=False)


@dataclass(frozen=True)
class PolarTable:
    """Airfoil polars resampled for O(1) lookup: C^1 cubic Hermite on a uniform alpha grid.

    Parameters
    ----------
    table : (n_af, 4, n_alpha) ndarray
        cl, dcl/dalpha, cd, dcd/dalpha at the grid nodes [-, 1/rad].
    alpha0 : float
        First grid node [rad] (= -pi).
    dalpha : float
        Grid spacing [rad].
    """

    table: FloatArray
    alpha0: float
    dalpha: float


def build_polar_table(polars: tuple[Polar, ...], n_alpha: int = _N_ALPHA) -> PolarTable:
    """Fit each polar with a modified Akima spline (scipy) and sample value and slope on a grid.

    The Hermite cubic through the sampled values and slopes reproduces the Akima spline to
    O(h^3) and keeps the coefficients continuously differentiable in alpha, which the
    finite-difference linearization needs.

    Parameters
    ----------
    polars : tuple of Polar
        The airfoil polars.
    n_alpha : int
        Samples over -180..180 deg.

    Returns
    -------
    PolarTable
        Values and slopes of C_l, C_d on the grid.
    """
    grid = np.linspace(-_PI, _PI, n_alpha)
    out = np.empty((len(polars), 4, n_alpha))
    for k, p in enumerate(polars):
        for j, coef in enumerate((p.cl, p.cd)):
            if p.alpha_rad.size < 5:
                f = np.interp(grid, p.alpha_rad, coef)
                df = np.gradient(f, grid)
            else:
                spl = Akima1DInterpolator(p.alpha_rad, coef, method="makima")
                f = spl(grid)
                df = spl(grid, 1)
            out[k, 2 * j] = f
            out[k, 2 * j + 1] = df
    out.flags.writeable = False
    return PolarTable(table=out, alpha0=-_PI, dalpha=2 * _PI / (n_alpha - 1))


# --------------------------------------------------------------------------------------------
# Kernels
# --------------------------------------------------------------------------------------------
_JIT = dict(cache=True, error_model="numpy", fastmath=False)

# Mode bits of element_kernel (and of the plant kernel that passes them on).
MODE_FROZEN = 1    # frozen wake: induced velocities given, no solve
MODE_CS = 2        # complex step: implicit-function step around a tight real root
MODE_TIGHT = 4     # warm-started solves run to _XTOL instead of _XTOL_WARM
MODE_NOLIMITS = 8  # plant: no actuator position/rate clipping (linearization)

# The kernels below are generic over float64 and complex128 (for complex-step derivatives):
# branches test the real part, and abs() of a signed quantity is written as a sign flip.


@nb.njit(**_JIT)
def locate_cell(x, n):  # pragma: no cover - compiled
    """Cell of a uniform grid with n nodes holding the fractional index x: (i, x - i), i in
    [0, n - 2] (clamped, so points outside extrapolate the end cells)."""
    i = int(math.floor(x.real))
    if i < 0:
        i = 0
    elif i > n - 2:
        i = n - 2
    return i, x - i


@nb.njit(**_JIT)
def _atan2(y, x):  # pragma: no cover - compiled
    """atan2 that also differentiates under complex step (quadrant from the real parts)."""
    if x.real == 0.0:
        return 0.5 * _PI if y.real >= 0.0 else -0.5 * _PI
    a = np.arctan(y / x)
    if x.real < 0.0:
        a = a + _PI if y.real >= 0.0 else a - _PI
    return a


@nb.njit(**_JIT)
def _polar_lookup(table, k, alpha, alpha0, dalpha):  # pragma: no cover - compiled
    """cl, cd of airfoil k at alpha [rad], alpha wrapped into [-pi, pi)."""
    a = alpha - 2.0 * _PI * math.floor((alpha.real + _PI) / (2.0 * _PI))
    i, t = locate_cell((a - alpha0) / dalpha, table.shape[2])
    t2 = t * t
    t3 = t2 * t
    h00 = 2.0 * t3 - 3.0 * t2 + 1.0
    h10 = (t3 - 2.0 * t2 + t) * dalpha
    h01 = -2.0 * t3 + 3.0 * t2
    h11 = (t3 - t2) * dalpha
    cl = h00 * table[k, 0, i] + h10 * table[k, 1, i] + h01 * table[k, 0, i + 1] + h11 * table[k, 1, i + 1]
    cd = h00 * table[k, 2, i] + h10 * table[k, 3, i] + h01 * table[k, 2, i + 1] + h11 * table[k, 3, i + 1]
    return cl, cd


#: :func:`_polar_lookup` for the other compiled modules (unsteady aerodynamics): cl, cd of
#: airfoil k at alpha [rad] from the sampled table
polar_lookup = _polar_lookup


@nb.njit(**_JIT)
def _prandtl(r, rtip, rhub, nb_, sphi, tip, hub):  # pragma: no cover - compiled
    """Prandtl tip and hub loss factor F (Hansen 2015, eq 6.35), F >= 1e-10.

    Where the exponent exceeds 40, exp(-f) < 5e-18 and F = 1 to rounding: the acos is skipped.
    """
    F = 1.0 + 0.0 * sphi
    s = sphi if sphi.real >= 0.0 else -sphi
    if s.real < 1e-12:
        s = 1e-12 + 0.0 * sphi
    if tip:
        f = 0.5 * nb_ * (rtip - r) / (r * s)
        if f.real < 40.0:
            e = np.exp(-f)
            if e.real > 1.0:
                e = 1.0 + 0.0 * e
            F = F * (2.0 / _PI * np.arccos(e))
    if hub and rhub > 0.0:
        f = 0.5 * nb_ * (r - rhub) / (rhub * s)
        if f.real < 40.0:
            e = np.exp(-f)
            if e.real > 1.0:
                e = 1.0 + 0.0 * e
            F = F * (2.0 / _PI * np.arccos(e))
    if F.real < 1e-10:
        F = 1e-10 + 0.0 * F
    return F


@nb.njit(**_JIT)
def _induction(phi, vx, vy, r, chord, theta, k_af, table, alpha0, dalpha, nb_, rtip, rhub,
               flags):  # pragma: no cover - compiled
    """Residual R(phi) * V_y and the factors (1 - a), (1 + a'), cn, ct at phi.

    ``flags`` = (tip_loss, hub_loss, tangential_induction) as int64. Buhl's high-induction
    relation is always applied above a = 0.4 (k > 2/3): Ning's proof that the first bracket
    holds a root needs it (with pure momentum theory a -> 1 as phi -> 0 and R(0+) > 0).
    """
    s = np.sin(phi)
    c = np.cos(phi)
    cl, cd = _polar_lookup(table, k_af, phi - theta, alpha0, dalpha)
    cn = cl * c + cd * s
    ct = cl * s - cd * c
    F = _prandtl(r, rtip, rhub, nb_, s, flags[0] != 0, flags[1] != 0)
    sig = nb_ * chord / (2.0 * _PI * r)
    ss = s * s
    if ss.real < 1e-24:
        ss = 1e-24 + 0.0 * ss
    k = sig * cn / (4.0 * F * ss)
    sc = s * c
    if abs(sc.real) < 1e-24:
        sc = (1e-24 if sc.real >= 0.0 else -1e-24) + 0.0 * sc
    kp = sig * ct / (4.0 * F * sc) if flags[2] != 0 else 0.0 * ct
    if phi.real > 0.0:
        if k.real <= 2.0 / 3.0:
            # a = k/(1+k): 1 - a = 1/(1+k); written without the division
            res = vy * s * (1.0 + k) - vx * c * (1.0 - kp)
            den = 1.0 + k
            one_m_a = 1.0 / den if abs(den.real) > 1e-9 else 1e9 + 0.0 * den
        else:
            g1 = 2.0 * F * k - (10.0 / 9.0 - F)
            g2 = 2.0 * F * k - F * (4.0 / 3.0 - F)
            g3 = 2.0 * F * k - (25.0 / 9.0 - 2.0 * F)
            if g2.real < 1e-12:
                g2 = 1e-12 + 0.0 * g2
            if abs(g3.real) < 1e-6:
                a = 1.0 - 1.0 / (2.0 * np.sqrt(g2))
            else:
                a = (g1 - np.sqrt(g2)) / g3
            one_m_a = 1.0 - a
            if abs(one_m_a.real) < 1e-9:
                one_m_a = 1e-9 + 0.0 * one_m_a
            res = vy * s / one_m_a - vx * c * (1.0 - kp)
    else:
        # propeller-brake region (Ning 2014, sec. 3)
        res = vy * s * (1.0 - k) - vx * c * (1.0 - kp)
        one_m_a = 1.0 / (1.0 - k) if k.real > 1.0 else 1.0 + 0.0 * k
    den = 1.0 - kp
    one_p_ap = 1.0 / den if abs(den.real) > 1e-9 else 1e9 + 0.0 * den
    return res, one_m_a, one_p_ap, cn, ct


@nb.njit(**_JIT)
def _res(phi, vx, vy, r, chord, theta, k_af, table, alpha0, dalpha, nb_, rtip, rhub, flags):  # pragma: no cover
    return _induction(phi, vx, vy, r, chord, theta, k_af, table, alpha0, dalpha, nb_, rtip,
                      rhub, flags)[0]


@nb.njit(**_JIT)
def _brent(a, b, fa, fb, vx, vy, r, chord, theta, k_af, table, alpha0, dalpha, nb_, rtip, rhub,
           flags):  # pragma: no cover - compiled
    """Brent's root finder on [a, b] with fa * fb < 0 (Brent 1973, zeroin). Real only."""
    c = a
    fc = fa
    d = b - a
    e = d
    for _ in range(200):
        if fb * fc > 0.0:
            c = a
            fc = fa
            d = b - a
            e = d
        if abs(fc) < abs(fb):
            a = b
            b = c
            c = a
            fa = fb
            fb = fc
            fc = fa
        tol = 4.4e-16 * abs(b) + 0.5 * _XTOL
        m = 0.5 * (c - b)
        if abs(m) <= tol or fb == 0.0:
            return b
        if abs(e) >= tol and abs(fa) > abs(fb):
            s = fb / fa
            if a == c:
                p = 2.0 * m * s
                q = 1.0 - s
            else:
                q = fa / fc
                rr = fb / fc
                p = s * (2.0 * m * q * (q - rr) - (b - a) * (rr - 1.0))
                q = (q - 1.0) * (rr - 1.0) * (s - 1.0)
            if p > 0.0:
                q = -q
            else:
                p = -p
            if 2.0 * p < min(3.0 * m * q - abs(tol * q), abs(e * q)):
                e = d
                d = p / q
            else:
                d = m
                e = m
        else:
            d = m
            e = m
        a = b
        fa = fb
        if abs(d) > tol:
            b += d
        else:
            b += tol if m > 0.0 else -tol
        fb = _res(b, vx, vy, r, chord, theta, k_af, table, alpha0, dalpha, nb_, rtip, rhub, flags)
    return b


@nb.njit(**_JIT)
def _solve_phi(vx, vy, r, chord, theta, k_af, table, alpha0, dalpha, nb_, rtip, rhub, flags,
               hint, hint_slope, tol):  # pragma: no cover - compiled
    """Solve one element (real): (phi, dR/dphi, 1 - a, 1 + a', cn, ct) for V_x, V_y > 0.

    Without a hint (NaN) the root is found in Ning's (2014) global brackets by Brent's method
    to ``_XTOL`` (1e-13 rad); this always converges and is what trim uses. With a hint (an
    earlier solution nearby, as in time stepping) a secant iteration starts from it with the
    slope cached at that solve, confined to (0, pi), and stops at the evaluated point whose
    Newton correction is below ``tol``. With ``tol <= _XTOL``, as linearization asks, that last
    correction is applied too, which puts phi at rounding level (finite differences of a 1e7 N m
    rotor sum then resolve 1e-7 N m). Time stepping asks ``_XTOL_WARM`` (1e-7 rad, a relative
    load error of about 1e-6): at the first point the hint is returned as it is; after a
    secant step the last correction is taken and the factors there follow linearly from the
    last two points (errors of order the correction times the secant's step, without a further
    evaluation). If it does not get there in 8 steps it falls back to the global brackets.

    A hint in the propeller-brake region (phi < 0) is not used: Ning's procedure takes that
    region only when (0, pi/2) holds no root, and the residual jumps at phi = 0, where a secant
    confined to the negative region can "converge" on the jump with a huge slope. Tracking such
    a hint once kept a tip element at phi = -3e-5 while the root had come back to 0.106 rad, and
    the next step's loads threw the edgewise rates to 200 m/s (a campaign case that diverged).
    """
    args = (vx, vy, r, chord, theta, k_af, table, alpha0, dalpha, nb_, rtip, rhub, flags)
    if hint == hint and hint > 0.0:  # not NaN, not in the propeller-brake region
        lo_b, hi_b = _EPS_PHI, _PI - _EPS_PHI
        if lo_b < hint < hi_b:
            x0 = hint
            f0, oma, opa, cn, ct = _induction(x0, *args)
            slope = hint_slope
            if not (slope == slope) or slope == 0.0:
                x1 = x0 + 1e-6 if x0 + 1e-6 < hi_b else x0 - 1e-6
                slope = (_res(x1, *args) - f0) / (x1 - x0)
            dx_prev = math.inf
            oma_p, opa_p, cn_p, ct_p = oma, opa, cn, ct
            for _ in range(8):
                if slope == 0.0 or not (slope == slope):
                    break
                step = f0 / slope
                if abs(step) <= tol:
                    if tol <= _XTOL and step != 0.0 and lo_b < x0 - step < hi_b:
                        # tight: take the last correction too (superlinear: to rounding)
                        x0 = x0 - step
                        _, oma, opa, cn, ct = _induction(x0, *args)
                    elif dx_prev != math.inf and lo_b < x0 - step < hi_b:
                        # warm, after a secant step: take the last correction too, and the
                        # factors there by linear extrapolation from the last two points
                        # (both errors of order |step dx_prev|, no further evaluation)
                        g = -step / dx_prev
                        return (x0 - step, slope, oma + g * (oma - oma_p),
                                opa + g * (opa - opa_p), cn + g * (cn - cn_p),
                                ct + g * (ct - ct_p))
                    return x0, slope, oma, opa, cn, ct
                x1 = x0 - step
                if x1 <= lo_b or x1 >= hi_b:
                    break
                oma_p, opa_p, cn_p, ct_p = oma, opa, cn, ct
                f1, oma, opa, cn, ct = _induction(x1, *args)
                slope = (f1 - f0) / (x1 - x0)
                dx_prev = x1 - x0
                x0 = x1
                f0 = f1
    # Ning's brackets
    lo = _EPS_PHI
    hi = 0.5 * _PI
    flo = _res(lo, *args)
    fhi = _res(hi, *args)
    root = math.nan
    if flo * fhi > 0.0:
        fa = _res(-0.25 * _PI, *args)
        fb = _res(-_EPS_PHI, *args)
        if fa < 0.0 and fb > 0.0:
            lo, hi, flo, fhi = -0.25 * _PI, -_EPS_PHI, fa, fb
        else:
            lo = 0.5 * _PI
            hi = _PI - _EPS_PHI
            flo = fhi
            fhi = _res(hi, *args)
            if flo * fhi > 0.0:  # cannot happen for V_x, V_y > 0 (Ning 2014); stay finite
                root = math.atan2(vx, vy)
    if root != root:
        root = _brent(lo, hi, flo, fhi, *args)
    _, oma, opa, cn, ct = _induction(root, *args)
    return root, math.nan, oma, opa, cn, ct


@nb.njit(**_JIT)
def _loads_at(phi, vx, vy, one_m_a, one_p_ap, chord, theta, k_af, table, alpha0, dalpha,
              rho):  # pragma: no cover - compiled
    """N', T' from the inflow angle and induction: W^2 = (V_x (1-a))^2 + (V_y (1+a'))^2."""
    cl, cd = _polar_lookup(table, k_af, phi - theta, alpha0, dalpha)
    s = np.sin(phi)
    c = np.cos(phi)
    ua = vx * one_m_a
    ut = vy * one_p_ap
    q = 0.5 * rho * (ua * ua + ut * ut) * chord
    return q * (cl * c + cd * s), q * (cl * s - cd * c)


#: The induction factors' limits, a in [-1, 1.5] and a' in [-1, 1] (as AeroDyn's BEMT).
A_MIN, A_MAX, AP_MIN, AP_MAX = -1.0, 1.5, -1.0, 1.0


@nb.njit(**_JIT)
def _limited(phi, vx, vy, r, chord, theta, k_af, table, alpha0, dalpha, nb_, rtip, rhub, flags,
             one_m_a, one_p_ap, cn, ct):  # pragma: no cover - compiled
    """A root outside the windmill state checked and its induction limited (real).

    Momentum theory holds no solution where its loading factor k = sigma' c_n / (4 F sin^2 phi)
    has the wrong sign for the branch: k <= 1 in the propeller-brake region (phi < 0), k < -1
    in the momentum region. Such a root, which Ning's brackets return when the local speed
    ratio V_y / V_x is small (a feathered blade on a stopping rotor: phi = -3 deg for
    V_y = 0.05 m/s against V_x = 25 m/s, with 1 + a' in the thousands and a 25 m edgewise load
    of 440 MN m), is replaced by the geometric inflow without induction; otherwise a and a' are
    kept within [:data:`A_MIN`, :data:`A_MAX`] and [:data:`AP_MIN`, :data:`AP_MAX`]. Both
    follow AeroDyn 15's BEMT in OpenFAST (its invalid-solution test and
    ``BEMT_MinInduction``, ``BEMT_MaxInduction``). A
    changed root's phi, coefficients and inductions are returned with a flag; the normal
    windmill state (0 < phi, 0 <= a <= 1, 0 <= a' <= 1) never comes here.
    """
    s = math.sin(phi)
    ss = max(s * s, 1e-24)
    F = _prandtl(r, rtip, rhub, nb_, abs(s), flags[0] != 0, flags[1] != 0)
    k = nb_ * chord / (2.0 * _PI * r) * cn / (4.0 * F * ss)
    if (phi < 0.0 and k <= 1.0) or (phi > 0.0 and k < -1.0):
        oma, opa = 1.0, 1.0
    else:
        oma = min(max(one_m_a, 1.0 - A_MAX), 1.0 - A_MIN)
        opa = min(max(one_p_ap, 1.0 + AP_MIN), 1.0 + AP_MAX)
        if oma == one_m_a and opa == one_p_ap:
            return phi, one_m_a, one_p_ap, cn, ct, False
    ph = _atan2(vx * oma, vy * opa)
    cl, cd = _polar_lookup(table, k_af, ph - theta, alpha0, dalpha)
    sp, cp = math.sin(ph), math.cos(ph)
    return ph, oma, opa, cl * cp + cd * sp, cl * sp - cd * cp, True


@nb.njit(**_JIT)
def _element_frozen(vx, vy, chord, theta, k_af, table, alpha0, dalpha, rho, u_ind,
                    v_ind):  # pragma: no cover - compiled
    """Frozen wake as FAST/OpenFAST define it: the induced velocities are held, the axial
    u_ind = V_x a and the tangential v_ind = V_y a', so W_x = V_x - u_ind and
    W_y = V_y + v_ind follow the kinematics one for one; no solve."""
    ua = vx - u_ind
    ut = vy + v_ind
    phi = _atan2(ua, ut)
    cl, cd = _polar_lookup(table, k_af, phi - theta, alpha0, dalpha)
    w2 = ua * ua + ut * ut
    q = 0.5 * rho * w2 * chord
    # sin and cos of phi = atan2(W_x, W_y) from the velocities (q = 0 where they vanish)
    if w2.real > 0.0:
        w = np.sqrt(w2)
        s = ua / w
        c = ut / w
    else:
        s = 0.0 * phi
        c = 1.0 + 0.0 * phi
    return q * (cl * c + cd * s), q * (cl * s - cd * c), phi, math.nan, u_ind + 0.0 * phi, \
        v_ind + 0.0 * phi


@nb.njit(**_JIT)
def _element_cs(vx, vy, r, chord, theta, k_af, table, alpha0, dalpha, nb_, rtip, rhub, flags,
                rho):  # pragma: no cover - compiled
    """Complex-step sensitivity of the implicit solve (inputs complex).

    The real root phi_r is solved tightly; then phi = phi_r - R(phi_r; complex inputs) /
    R'(phi_r), whose imaginary part is the exact first-order sensitivity (implicit function
    theorem), with R'(phi_r) itself taken by a complex step in phi.
    """
    vxr, vyr, thr = vx.real, vy.real, theta.real
    phr = _solve_phi(vxr, vyr, r, chord, thr, k_af, table, alpha0, dalpha, nb_, rtip, rhub,
                     flags, math.nan, math.nan, _XTOL)[0]
    h = 1e-30
    dres = _res(phr + 1j * h, vxr, vyr, r, chord, thr, k_af, table, alpha0, dalpha, nb_, rtip,
                rhub, flags).imag / h
    f0 = _res(phr + 0.0 * vx, vx, vy, r, chord, theta, k_af, table, alpha0, dalpha, nb_, rtip,
              rhub, flags)
    phi = phr - f0 / dres
    _, oma, opa, _, _ = _induction(phi, vx, vy, r, chord, theta, k_af, table, alpha0, dalpha,
                                   nb_, rtip, rhub, flags)
    npr, tpr = _loads_at(phi, vx, vy, oma, opa, chord, theta, k_af, table, alpha0, dalpha, rho)
    return npr, tpr, phi, math.nan, vx * (1.0 - oma), vy * (opa - 1.0)


@nb.njit(**_JIT)
def element_kernel(vx, vy, r, chord, theta, k_af, table, alpha0, dalpha, nb_, rtip, rhub, flags, rho,
             hint, hint_slope, frozen_u, frozen_v, mode):  # pragma: no cover - compiled
    """Loads per unit length on one element: (N', T', phi, dR/dphi, u_ind, v_ind), the last two
    the axial and tangential induced velocities V_x a and V_y a' [m/s].

    N' is normal to the rotor plane (positive downwind) and T' in the plane (positive driving
    the rotor) [N/m]. Reversed or stalled kinematics (V_x <= 0 or V_y <= 0, where momentum
    theory has no meaning) use the geometric inflow without induction.

    ``mode`` bits: MODE_FROZEN holds the induced velocities at (frozen_u, frozen_v) (frozen
    wake, :func:`_element_frozen`); MODE_CS differentiates the implicit solve by complex step
    (:func:`_element_cs`); MODE_TIGHT makes warm solves converge to 1e-13 rad.
    """
    if mode & MODE_FROZEN:
        return _element_frozen(vx, vy, chord, theta, k_af, table, alpha0, dalpha, rho,
                               frozen_u, frozen_v)
    if vx.real > 1e-9 and vy.real > 1e-9 * max(1.0, vx.real):
        if mode & MODE_CS:
            return _element_cs(vx, vy, r, chord, theta, k_af, table, alpha0, dalpha, nb_, rtip,
                               rhub, flags, rho)
        tol = _XTOL if mode & MODE_TIGHT else _XTOL_WARM
        # real inputs here (complex ones take the MODE_CS branch); .real keeps typing real
        phi, slope, one_m_a, one_p_ap, cn, ct = _solve_phi(
            vx.real, vy.real, r, chord, theta.real, k_af, table, alpha0, dalpha, nb_, rtip,
            rhub, flags, hint, hint_slope, tol)
        if flags[3] != 0 and (phi < 0.0 or one_m_a < 0.0 or one_m_a > 1.0 or one_p_ap < 0.0
                              or one_p_ap > 2.0):
            # outside the normal windmill state: the induction is checked and limited
            phi, one_m_a, one_p_ap, cn, ct, lim = _limited(
                phi, vx.real, vy.real, r, chord, theta.real, k_af, table, alpha0, dalpha, nb_,
                rtip, rhub, flags, one_m_a, one_p_ap, cn, ct)
            if lim:
                slope = math.nan
        ua = vx * one_m_a
        ut = vy * one_p_ap
        q = 0.5 * rho * (ua * ua + ut * ut) * chord
        return q * cn, q * ct, phi + 0.0 * vx, slope, vx - ua, ut - vy
    phi = _atan2(vx, vy)
    one = 1.0 + 0.0 * phi
    npr, tpr = _loads_at(phi, vx, vy, one, one, chord, theta, k_af, table, alpha0, dalpha, rho)
    return npr, tpr, phi, math.nan, 0.0 * phi, 0.0 * phi


# --------------------------------------------------------------------------------------------
# Public entry points
# --------------------------------------------------------------------------------------------
def aero_flags(options: AeroOptions) -> np.ndarray:
    """Kernel flag vector (tip_loss, hub_loss, tangential_induction, induction_limits)."""
    return np.array([options.tip_loss, options.hub_loss, options.tangential_induction,
                     options.induction_limits], dtype=np.int64)


_TABLE_CACHE: dict[int, tuple[Turbine, PolarTable]] = {}


def polar_table_of(turbine: Turbine) -> PolarTable:
    """The turbine's :class:`PolarTable`, built once per turbine object.

    Parameters
    ----------
    turbine : Turbine
        The turbine.

    Returns
    -------
    PolarTable
        Its polars, sampled.
    """
    hit = _TABLE_CACHE.get(id(turbine))
    if hit is not None and hit[0] is turbine:
        return hit[1]
    tab = build_polar_table(turbine.polars)
    _TABLE_CACHE[id(turbine)] = (turbine, tab)
    return tab


def element_loads(turbine: Turbine, vx: FloatArray, vy: FloatArray, pitch_rad: float,
                  options: AeroOptions | None = None) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Loads on every element of one blade for given relative velocities.

    Parameters
    ----------
    turbine : Turbine
    vx : (n_r,) ndarray
        Velocity normal to the rotor plane seen by each element (before induction) [m/s].
    vy : (n_r,) ndarray
        In-plane velocity seen by each element (before induction) [m/s].
    pitch_rad : float
        Blade pitch [rad].
    options : AeroOptions, optional

    Returns
    -------
    normal, tangential : (n_r,) ndarray
        Force per unit length normal to the plane (positive downwind) and in the plane
        (positive driving the rotor) [N/m].
    phi_rad : (n_r,) ndarray
        Inflow angle [rad].
    """
    opts = options or AeroOptions()
    n = turbine.blade.r.size
    vx = check_array("vx", vx, (n,), shape_names="(n_r,)")
    vy = check_array("vy", vy, (n,), shape_names="(n_r,)")
    tab = polar_table_of(turbine)
    b = turbine.blade
    g = turbine.geometry
    flags = aero_flags(opts)
    out = np.empty((6, n))
    for j in range(n):
        out[:, j] = element_kernel(vx[j], vy[j], b.r[j], b.chord[j], b.twist_rad[j] + pitch_rad,
                             b.airfoil[j], tab.table, tab.alpha0, tab.dalpha,
                             float(g.number_of_blades), g.tip_radius, g.hub_radius, flags,
                             turbine.environment.air_density, math.nan, math.nan, 0.0, 0.0, 0)
    return out[0], out[1], out[2]


def element_induction(turbine: Turbine, vx: FloatArray, vy: FloatArray, pitch_rad: float,
                      options: AeroOptions | None = None) -> tuple[FloatArray, FloatArray]:
    """Induced velocities on every element of one blade for given free-stream velocities
    relative to the blade: what a frozen-wake linearization holds (FAST/OpenFAST).

    Parameters
    ----------
    turbine : Turbine
        The blade and its polars.
    vx : (n_r,) array_like
        Velocity normal to the rotor plane, before induction [m/s].
    vy : (n_r,) array_like
        In-plane velocity (rotation), before induction [m/s].
    pitch_rad : float
        Blade pitch [rad].
    options : AeroOptions, optional
        Loss models and tangential induction.

    Returns
    -------
    u_ind : (n_r,) ndarray
        Axial induced velocity V_x a [m/s]: the flow through the element is V_x - u_ind.
    v_ind : (n_r,) ndarray
        Tangential induced velocity V_y a' [m/s]: the in-plane flow is V_y + v_ind.
    """
    opts = options or AeroOptions()
    n = turbine.blade.r.size
    vx = check_array("vx", vx, (n,), shape_names="(n_r,)")
    vy = check_array("vy", vy, (n,), shape_names="(n_r,)")
    tab = polar_table_of(turbine)
    b, g = turbine.blade, turbine.geometry
    flags = aero_flags(opts)
    out = np.empty((2, n))
    for j in range(n):
        out[:, j] = element_kernel(vx[j], vy[j], b.r[j], b.chord[j], b.twist_rad[j] + pitch_rad,
                             b.airfoil[j], tab.table, tab.alpha0, tab.dalpha,
                             float(g.number_of_blades), g.tip_radius, g.hub_radius, flags,
                             turbine.environment.air_density, math.nan, math.nan, 0.0, 0.0,
                             0)[4:]
    return out[0], out[1]

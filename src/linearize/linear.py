"""Numerical linearization of the plant at trim points, parameterized by mean wind.

``linearize(turbine, wind_mps)`` returns the continuous model of Madsen et al. (2012) eqs 18-19,

    dx/dt = A x + B_u u + B_d d,      z = C_z x + D_u u + D_d d,

in perturbations from the trim point, with named states, inputs, disturbances and outputs.

Derivatives are central differences of :func:`linearize.plant_rhs` with a step per variable
scaled to that variable; warm-started BEM solves run to 1e-13 rad so the differences are not
noise. ``jacobian_check`` computes the same Jacobians by complex step through the same kernels
(the implicit BEM solve is differentiated by the implicit-function theorem), an independent
derivative used by the tests.

Wake assumption (``wake``):

* ``"quasi-steady"`` re-solves the induction at every perturbation, as Madsen's numerical
  linearization does and as OpenFAST linearizes unless its ``FrozenWake`` switch is set (our
  quasi-steady dQ/dV, dQ/dOmega and dT/dV follow the slopes of ROSCO's C_P/C_T tables to 3 %,
  tested). Use it to compare with OpenFAST's default ``.lin`` files and for controllers whose
  time scale is long compared with the wake's: baseline PI tuning of the speed loop, MPC at
  10 Hz on a quasi-steady BEM plant like ours.
* ``"frozen"`` holds the axial and tangential induced *velocities* (V_x a, V_y a') at their
  trim values, as FAST/OpenFAST do with ``FrozenWake = True``, and as the NREL 5-MW report's
  pitch sensitivities were computed (report sec. 7.4, hence the baseline's tuning). The
  kinematics then change the flow through the rotor one for one (tested against the element
  equations written out). Use it for the report's gain schedule and for fast pitch action
  (IPC, load control), where the wake has no time to respond within a control period; it
  predicts stronger immediate sensitivities (dP/dpitch 30 % and dT/dV 19 % above the
  quasi-steady ones at 18 m/s). The induced *velocities* are held, not the induction factors:
  held factors would make the induced velocities scale with V and Omega (dT/dV, dQ/dV 27-88 %
  off and a dQ/dOmega of the wrong sign near rated).

With tilt, cone, gravity or shear on, the plant is periodic in azimuth; the models are averaged
over azimuth in blade coordinates (Madsen's azimuth-independent models), or in multi-blade
coordinates (``coordinates="mbc"``: collective, cosine (tilt-like) and sine (yaw-like)
components, Bir 2008), which OpenFAST's MBC3 users know.

References
----------
Madsen, Filsoe, Soltani (2012), IEEE CCA, doi:10.1109/CCA.2012.6402671, sec. II-D.
Bir (2008), Multi-blade coordinate transformation and its application to wind turbine analysis,
AIAA 2008-1300. Do et al. (2020), Wind Energy, eq 6 (actuator augmentation).
Jonkman et al. (2009), NREL/TP-500-38060, sec. 7.4 (pitch sensitivity).
"""
from __future__ import annotations

import math
from typing import Any, Sequence

import numba as nb
import numpy as np

from linearize._typing import FloatArray
from linearize.bem import MODE_CS, MODE_FROZEN, MODE_NOLIMITS, MODE_TIGHT
from linearize.errors import LinearizationError
from linearize.jitcache import key_caches_on_callees
from linearize.kernel import NO_GRID, evaluate_plant, sample_wind
from linearize.models import LinearModel, LinearModelFamily, check_wind_grid
from linearize.params import (
    INPUT_NAMES,
    INPUT_UNITS,
    OUTPUT_NAMES,
    OUTPUT_UNITS,
    STATE_NAMES,
    STATE_UNITS,
    PlantConfig,
    PlantParams,
    n_x,
    n_z,
    plant_params,
)
from linearize.trim import OperatingPoint, trim
from linearize.turbine import Turbine
from linearize.validate import check_finite_scalar

__all__ = ["mbc_matrices", "linearize", "jacobian_check", "linearize_family"]

_OUT_IDX = [i for i, n in enumerate(OUTPUT_NAMES) if n != "azimuth"]


#: variables scales for the finite-difference steps (state, input, disturbance)
_X_SCALE = np.array([0.1, 0.1, 0.1, 10.0, 1e-3, 0.01, 0.01, 0.01, 0.1, 0.1, 0.1, 0.1, 0.1,
                     0.1, 0.1, 0.1, 1.0, 0.01, 0.01, 0.01, 0.1, 0.1, 0.1])


_U_SCALE = np.array([0.01, 0.01, 0.01, 1000.0])


_D_SCALE = np.array([1.0, 1.0, 1.0])


_REL_STEP = 2e-5


_BLADE_GROUPS_X = (("pitch_1", "pitch_2", "pitch_3"), ("flap_1", "flap_2", "flap_3"),
                   ("flap_rate_1", "flap_rate_2", "flap_rate_3"), ("edge_1", "edge_2", "edge_3"),
                   ("edge_rate_1", "edge_rate_2", "edge_rate_3"))


_BLADE_GROUPS_Z = (("pitch_1", "pitch_2", "pitch_3"),
                   ("pitch_rate_1", "pitch_rate_2", "pitch_rate_3"),
                   ("flap_moment_1", "flap_moment_2", "flap_moment_3"),
                   ("edge_moment_1", "edge_moment_2", "edge_moment_3"))


# --------------------------------------------------------------------------------------------
# Jacobian kernels
# --------------------------------------------------------------------------------------------
@nb.njit(cache=True, error_model="numpy")
def _perturbed(x0, u0, w0, j, delta):  # pragma: no cover - compiled
    """(x, u, wind) with variable j of the combined vector [x (23), u (4), blade winds (3)]
    moved by delta (a blade wind moves every element of that blade)."""
    x = x0.copy()
    u = u0.copy()
    w = w0.copy()
    if j < n_x:
        x[j] += delta
    elif j < n_x + 4:
        u[j - n_x] += delta
    else:
        w[j - n_x - 4] += delta
    return x, u, w


@nb.njit(cache=True, error_model="numpy")
def _jac_fd(x0, u0, w0, p, bem0, mode, h):  # pragma: no cover - compiled
    """Central-difference Jacobians of (dx/dt, z) w.r.t. the combined vector [x, u, blade
    winds], with step h[j] per variable: (n_x, n_x + 7) and (n_z, n_x + 7)."""
    jf = np.zeros((n_x, n_x + 7))
    jz = np.zeros((n_z, n_x + 7))
    for j in range(n_x + 7):
        xp, up, wp = _perturbed(x0, u0, w0, j, h[j])
        xm, um, wm = _perturbed(x0, u0, w0, j, -h[j])
        fp, zp, _ = evaluate_plant(xp, up, wp, p, bem0, mode)
        fm, zm, _ = evaluate_plant(xm, um, wm, p, bem0, mode)
        jf[:, j] = (fp - fm) / (2 * h[j])
        jz[:, j] = (zp - zm) / (2 * h[j])
    return jf, jz


@nb.njit(cache=True, error_model="numpy")
def _jac_cs(x0, u0, w0, p, bem0, mode):  # pragma: no cover - compiled
    """Complex-step Jacobians (step 1e-30 i): exact to rounding, no subtraction error."""
    h = 1e-30
    jf = np.zeros((n_x, n_x + 7))
    jz = np.zeros((n_z, n_x + 7))
    for j in range(n_x + 7):
        x, u, w = _perturbed(x0 + 0j, u0 + 0j, w0 + 0j, j, 1j * h)
        f, z, _ = evaluate_plant(x, u, w, p, bem0, mode)
        jf[:, j] = f.imag / h
        jz[:, j] = z.imag / h
    return jf, jz


def _split(jf: FloatArray, jz: FloatArray) -> tuple[FloatArray, ...]:
    """(df/dx, df/du, df/dd, dz/dx, dz/du, dz/dd) from the combined Jacobians."""
    return (jf[:, :n_x], jf[:, n_x:n_x + 4], jf[:, n_x + 4:], jz[:, :n_x], jz[:, n_x:n_x + 4],
            jz[:, n_x + 4:])


def _azimuths(params: PlantParams, shear: float, n_azimuth: int | None) -> FloatArray:
    a = params.config.aero
    if n_azimuth is None:
        periodic = (a.tilt or a.gravity or shear != 0.0 or params.dof("tower_fa")
                    or params.dof("tower_ss"))
        n_azimuth = 8 if periodic else 1
    if n_azimuth < 1:
        raise ValueError(f"n_azimuth must be >= 1, got {n_azimuth!r}")
    return 2 * math.pi * np.arange(n_azimuth) / n_azimuth


def _raw_jacobians(params: PlantParams, op: OperatingPoint, wake: str, shear: float,
                   psi: float, method: str = "fd") -> tuple[FloatArray, ...]:
    """Full (23-state, 4-input, 3-blade-wind, 31-output) Jacobians at one azimuth."""
    pk = params.pack
    x0 = op.x.copy()
    x0[16] = psi
    u0 = op.u.copy()
    w0 = sample_wind(0.0, psi, pk, 0, np.array([op.wind_mps, shear]), NO_GRID)
    bem0 = evaluate_plant(x0, u0, w0, pk, np.full((4, 3, pk.r.size), np.nan), MODE_NOLIMITS)[2]
    mode = MODE_NOLIMITS | (MODE_FROZEN if wake == "frozen" else 0)
    if method == "cs":
        mode |= 0 if wake == "frozen" else MODE_CS
        return _split(*_jac_cs(x0, u0, w0, pk, bem0, mode))
    mode |= MODE_TIGHT
    h = _REL_STEP * np.concatenate([np.maximum(np.abs(x0), _X_SCALE),
                                    np.maximum(np.abs(u0), _U_SCALE),
                                    np.maximum(np.abs(w0.mean(axis=1)), _D_SCALE)])
    return _split(*_jac_fd(x0, u0, w0, pk, bem0, mode, h))


# --------------------------------------------------------------------------------------------
# Linearization
# --------------------------------------------------------------------------------------------
_WAKES = ("quasi-steady", "frozen")


def _check_options(wake: str, disturbance: str, coordinates: str) -> None:
    if wake not in _WAKES:
        raise ValueError(f"wake must be one of {_WAKES}, got {wake!r}")
    if disturbance not in ("blade", "rotor"):
        raise ValueError(f"disturbance must be 'blade' or 'rotor', got {disturbance!r}")
    if coordinates not in ("blade", "mbc"):
        raise ValueError(f"coordinates must be 'blade' or 'mbc', got {coordinates!r}")


def mbc_matrices(psi: float, omega: float) -> tuple[FloatArray, FloatArray, FloatArray,
                                                      FloatArray]:
    """Bir's multi-blade coordinate transform (Bir 2008, NREL/CP-500-42553): T(psi) with rows
    [1, cos psi_i, sin psi_i] for the blades at psi_i = psi + 2 pi (i - 1) / 3, its inverse, and
    its first and second time derivatives at rotor speed omega.

    Parameters
    ----------
    psi : float
        Azimuth of blade 1 [rad].
    omega : float
        Rotor speed [rad/s].

    Returns
    -------
    t, t_inv, t_dot, t_ddot : (3, 3) ndarray
        T, T^-1, dT/dt and d2T/dt2.
    """
    ang = psi + 2 * math.pi * np.arange(3) / 3
    t = np.column_stack([np.ones(3), np.cos(ang), np.sin(ang)])
    dt = np.column_stack([np.zeros(3), -np.sin(ang), np.cos(ang)])
    ddt = np.column_stack([np.zeros(3), -np.cos(ang), -np.sin(ang)])
    tinv = np.vstack([np.ones(3) / 3, 2 / 3 * np.cos(ang), 2 / 3 * np.sin(ang)])
    return t, tinv, dt * omega, ddt * omega**2


def _assemble(jx: FloatArray, ju: FloatArray, jd: FloatArray, hx: FloatArray, hu: FloatArray,
              hd: FloatArray, si: list[int], psi: float, omega: float,
              coordinates: str, ngear: float) -> tuple[FloatArray, ...]:
    """Select active states, then (MBC) transform to non-rotating coordinates at psi."""
    ig, ir = STATE_NAMES.index("gen_speed"), STATE_NAMES.index("rotor_speed")
    if ig not in si and ir in si:       # rigid shaft: omega_g = N omega_r, fold the column in
        jx, hx = jx.copy(), hx.copy()
        jx[:, ir] += ngear * jx[:, ig]
        hx[:, ir] += ngear * hx[:, ig]
    a = jx[np.ix_(si, si)]
    b = ju[si]
    bd = jd[si]
    c = hx[np.ix_(_OUT_IDX, si)]
    du = hu[_OUT_IDX]
    dd = hd[_OUT_IDX]
    if coordinates == "blade":
        return a, b, bd, c, du, dd
    t, tinv, tdot, tddot = mbc_matrices(psi, omega)
    names = [STATE_NAMES[i] for i in si]
    n = len(si)
    tx = np.eye(n)          # x_blade = tx x_nr
    txdot = np.zeros((n, n))
    for grp in _BLADE_GROUPS_X:
        if grp[0] not in names:
            continue
        ix = [names.index(g) for g in grp]
        tx[np.ix_(ix, ix)] = t
        txdot[np.ix_(ix, ix)] = tdot
    for pos, vel in ((1, 2), (3, 4)):   # velocity states of the second-order groups
        if _BLADE_GROUPS_X[pos][0] not in names:
            continue
        ip = [names.index(g) for g in _BLADE_GROUPS_X[pos]]
        iv = [names.index(g) for g in _BLADE_GROUPS_X[vel]]
        tx[np.ix_(iv, ip)] = tdot
        txdot[np.ix_(iv, ip)] = tddot
        txdot[np.ix_(iv, iv)] = tdot
    tx_inv = np.linalg.inv(tx)
    tu = np.eye(4)
    tu[:3, :3] = t
    tz_inv = np.eye(len(_OUT_IDX))
    onames = [OUTPUT_NAMES[i] for i in _OUT_IDX]
    for grp in _BLADE_GROUPS_Z:
        iz = [onames.index(g) for g in grp]
        tz_inv[np.ix_(iz, iz)] = tinv
    a_nr = tx_inv @ (a @ tx - txdot)
    return (a_nr, tx_inv @ b @ tu, tx_inv @ bd @ t, tz_inv @ c @ tx, tz_inv @ du @ tu,
            tz_inv @ dd @ t)


def _mbc_name(name: str, k: int) -> str:
    stem = name.rsplit("_", 1)[0]
    return f"{stem}_{('coll', 'cos', 'sin')[k]}"


def _rename(names: Sequence[str], groups: Sequence[Sequence[str]]) -> tuple[str, ...]:
    out = list(names)
    for grp in groups:
        if grp[0] in out:
            for k, g in enumerate(grp):
                out[out.index(g)] = _mbc_name(g, k)
    return tuple(out)


def linearize(turbine: Turbine, wind_mps: float, *, config: PlantConfig | None = None,
              wake: str = "quasi-steady", disturbance: str = "blade",
              coordinates: str = "blade", power_W: float | None = None,
              shear_exponent: float = 0.0, n_azimuth: int | None = None,
              params: PlantParams | None = None,
              operating_point: OperatingPoint | None = None,
              azimuth_rad: float | None = None) -> LinearModel:
    """Linearize the plant at the trim point of a mean wind speed.

    Parameters
    ----------
    turbine : Turbine
    wind_mps : float
        Mean hub-height wind speed [m/s], within cut-in..cut-out.
    config : PlantConfig, optional
        Degrees of freedom and aerodynamic options; the states of the model are the active
        states of this configuration (``PlantConfig.madsen()`` gives Madsen's 8 states).
    wake : {"quasi-steady", "frozen"}
        Induction re-solved at each perturbation, or held at trim (see the module docstring).
    disturbance : {"blade", "rotor"}
        One wind speed per blade, uniform along it (Madsen's V_1..V_3), or one rotor-effective
        wind speed for all elements (the Takagi-Sugeno model and wind observer).
    coordinates : {"blade", "mbc"}
        Blade coordinates, or multi-blade (collective, cosine, sine) coordinates.
    power_W : float, optional
        Linearize at the trim point for a power reference below rated.
    shear_exponent : float
        Shear of the steady wind at the operating point [-].
    n_azimuth : int, optional
        Azimuth samples averaged over a revolution. Default 8 whenever the plant is periodic
        in azimuth: with tilt, gravity or shear, and also with a tower DOF on, since tower
        nodding and side-side motion reach each blade weighted by cos(psi_i); else 1.
    params : PlantParams, optional
        Prebuilt plant parameters (must match turbine and config).
    operating_point : OperatingPoint, optional
        Linearize here instead of at the trim: :func:`linearize.trim` with other settings, or
        :func:`linearize.operating_point` at a given rotor speed and pitch (an OpenFAST
        ``.lin`` file's point); its wind must be ``wind_mps``.
    azimuth_rad : float, optional
        Linearize at this rotor azimuth (blade 1) only, as one OpenFAST ``.lin`` file is,
        instead of averaging over ``n_azimuth`` azimuths [rad].

    Returns
    -------
    LinearModel

    Raises
    ------
    TrimError
        If the wind is outside cut-in..cut-out or the power reference is unreachable.
    LinearizationError
        If a Jacobian entry is not finite (the plant failed at the perturbed point); the
        message names the entry.
    """
    v = check_finite_scalar("wind_mps", wind_mps)
    _check_options(wake, disturbance, coordinates)
    if operating_point is not None and abs(operating_point.wind_mps - v) > 1e-9 * max(1.0, v):
        raise ValueError(f"wind_mps = {v:g} m/s differs from the operating point's "
                         f"{operating_point.wind_mps:g} m/s")
    p = params if params is not None else plant_params(turbine, config)
    op = operating_point if operating_point is not None else trim(
        turbine, v, power_W, params=p, shear_exponent=shear_exponent)
    psis = None if azimuth_rad is None else [check_finite_scalar("azimuth_rad", azimuth_rad)]
    jac = _averaged(p, op, wake, shear_exponent, n_azimuth, coordinates, "fd", psis)
    return _model(p, op, jac, wake, disturbance, coordinates, shear_exponent)


def _averaged(p: PlantParams, op: OperatingPoint, wake: str, shear: float,
              n_azimuth: int | None, coordinates: str, method: str,
              psis: Sequence[float] | None = None) -> tuple[FloatArray, ...]:
    si = [STATE_NAMES.index(n) for n in p.config.active_states()]
    acc: list[FloatArray] | None = None
    psis = _azimuths(p, shear, n_azimuth) if psis is None else np.asarray(psis, dtype=float)
    for psi in psis:
        raw = _raw_jacobians(p, op, wake, shear, float(psi), method)
        for name, m in zip(("A", "B_u", "B_d", "C", "D_u", "D_d"), raw):
            if not np.all(np.isfinite(m)):
                i = np.argwhere(~np.isfinite(m))[0]
                raise LinearizationError(
                    f"Jacobian {name}[{i[0]}, {i[1]}] is not finite at {op.wind_mps:g} m/s, "
                    f"azimuth {math.degrees(psi):.0f} deg: the plant failed at a perturbed point")
        mats = _assemble(*raw, si, float(psi), op.rotor_speed_rad_s, coordinates,
                         p.pack.ngear)
        acc = list(mats) if acc is None else [a + m for a, m in zip(acc, mats)]
    assert acc is not None
    return tuple(m / len(psis) for m in acc)


def _model(p: PlantParams, op: OperatingPoint, jac: tuple[FloatArray, ...], wake: str,
           disturbance: str, coordinates: str, shear: float) -> LinearModel:
    a, b, bd, c, du, dd = jac
    si = [STATE_NAMES.index(n) for n in p.config.active_states()]
    states = tuple(STATE_NAMES[i] for i in si)
    outputs = tuple(OUTPUT_NAMES[i] for i in _OUT_IDX)
    inputs = INPUT_NAMES
    dists = ("wind_1", "wind_2", "wind_3")
    x0 = op.x[si]
    u0 = op.u.copy()
    d0 = np.full(3, op.wind_mps)
    z0 = _z0(p, op, shear)[_OUT_IDX]
    if coordinates == "mbc":
        states = _rename(states, _BLADE_GROUPS_X)
        outputs = _rename(outputs, _BLADE_GROUPS_Z)
        inputs = _rename(inputs, (INPUT_NAMES[:3],))
        dists = _rename(dists, (dists,))
        t, tinv, _, _ = mbc_matrices(0.0, 0.0)
        x0 = _to_mbc_values(states, x0)
        u0 = np.concatenate([tinv @ u0[:3], u0[3:]])
        d0 = tinv @ d0
        z0 = _to_mbc_values(outputs, z0)
    if disturbance == "rotor":
        bd = bd.sum(axis=1, keepdims=True) if coordinates == "blade" else bd[:, :1]
        dd = dd.sum(axis=1, keepdims=True) if coordinates == "blade" else dd[:, :1]
        dists = ("wind",)
        d0 = np.array([op.wind_mps])
    unit = dict(zip(STATE_NAMES, STATE_UNITS))
    ounit = dict(zip(OUTPUT_NAMES, OUTPUT_UNITS))
    iunit = dict(zip(INPUT_NAMES, INPUT_UNITS))
    return LinearModel(
        A=a, B_u=b, B_d=bd, C_z=c, D_u=du, D_d=dd, states=states, inputs=inputs,
        disturbances=dists, outputs=outputs,
        state_units=tuple(unit[STATE_NAMES[i]] for i in si),
        input_units=tuple(iunit[n] for n in INPUT_NAMES),
        disturbance_units=tuple("m/s" for _ in dists),
        output_units=tuple(ounit[OUTPUT_NAMES[i]] for i in _OUT_IDX),
        x0=x0, u0=u0, d0=d0, z0=z0, wind_mps=op.wind_mps, wake=wake,
        coordinates=coordinates,
        info={"region": op.region, "pitch_deg": op.pitch_deg,
              "rotor_speed_rpm": op.rotor_speed_rpm, "gen_torque_Nm": op.gen_torque,
              "power_W": op.power, "thrust_N": op.thrust, "shear_exponent": shear,
              "power_reference_W": op.power_reference,
              "dofs": sorted(p.config.dofs), "turbine": p.turbine.name})


def _z0(p: PlantParams, op: OperatingPoint, shear: float, n_azimuth: int = 24) -> FloatArray:
    """The outputs at the operating point with the inflow the trim used -- the sheared power-law
    wind at every element -- averaged over a revolution (every blade equally; the rotor totals
    then equal the trim's, which averages over azimuth too)."""
    pk = p.pack
    wpar = np.array([op.wind_mps, shear])
    z = np.zeros(len(OUTPUT_NAMES))
    x, u = op.x.copy(), op.u.copy()      # writable: the kernel compiled for every caller
    for psi in 2 * math.pi * np.arange(n_azimuth) / n_azimuth:
        x[16] = psi
        w = sample_wind(0.0, float(psi), pk, 0, wpar, NO_GRID)
        z += evaluate_plant(x, u, w, pk, np.full((4, 3, pk.r.size), np.nan), 0)[1]
    return z / n_azimuth


def _to_mbc_values(names: Sequence[str], vals: FloatArray) -> FloatArray:
    """Operating-point values in MBC: equal blade values -> collective = value, cos = sin = 0."""
    out = np.array(vals, dtype=float)
    for k, n in enumerate(names):
        if n.endswith(("_cos", "_sin")):
            out[k] = 0.0
    return out


def jacobian_check(turbine: Turbine, wind_mps: float, *, config: PlantConfig | None = None,
                   wake: str = "quasi-steady", shear_exponent: float = 0.0,
                   params: PlantParams | None = None) -> tuple[tuple[FloatArray, ...],
                                                                tuple[FloatArray, ...]]:
    """Full Jacobians at azimuth 0 by central differences and by complex step.

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    wind_mps : float
        Mean wind speed of the trim [m/s].
    config : PlantConfig, optional
        Plant configuration (default all DOFs).
    wake : {"quasi-steady", "frozen"}
        Wake model of the derivatives.
    shear_exponent : float
        Power-law shear exponent [-].
    params : PlantParams, optional
        Precomputed plant parameters.

    Returns
    -------
    fd, cs : tuple of 6 ndarray
        (df/dx, df/du, df/dd, dz/dx, dz/du, dz/dd) on all 23 states, 4 inputs, 3 blade winds
        and 31 outputs, from each method.
    """
    p = params if params is not None else plant_params(turbine, config)
    op = trim(turbine, wind_mps, params=p, shear_exponent=shear_exponent)
    return (_raw_jacobians(p, op, wake, shear_exponent, 0.0, "fd"),
            _raw_jacobians(p, op, wake, shear_exponent, 0.0, "cs"))


def linearize_family(turbine: Turbine, wind_mps: Sequence[float] | FloatArray | None = None,
                     *, progress: bool = False, **kwargs: Any) -> LinearModelFamily:
    """Linear models over a grid of mean wind speeds (default 4..25 m/s, step 1).

    ``kwargs`` are those of :func:`linearize` (config, wake, disturbance, coordinates,
    power_W, shear_exponent, n_azimuth).

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    wind_mps : sequence of float, optional
        Mean wind speeds [m/s] (default 4..25 step 1).
    progress : bool
        Show a progress bar.
    **kwargs
        Options of :func:`linearize`.

    Returns
    -------
    LinearModelFamily
        One model per wind speed.

    Raises
    ------
    ValueError
        If the grid is not strictly increasing and finite.
    TrimError
        If a wind speed is outside cut-in..cut-out (the message names it).
    """
    v = np.asarray(np.arange(4.0, 25.5, 1.0) if wind_mps is None else wind_mps,
                   dtype=float)
    check_wind_grid(v)
    p = kwargs.pop("params", None) or plant_params(turbine, kwargs.pop("config", None))
    from linearize.progress import progress as bar

    models = tuple(linearize(turbine, float(w), params=p, **kwargs)
                   for w in bar(v, "linearize", "op", enabled=progress))
    return LinearModelFamily(v, models)


key_caches_on_callees(__name__)

"""Gain synthesis: LQR full-state feedback and the PI observer of Do et al. (2020).

LQR (Do et al. eqs 9-10): on the actuator-augmented linear model (eq 6; our models carry the
pitch servo as states, so ``linearize.PlantConfig.do()`` gives it directly), minimise
integral x'Qx + u'Ru (continuous) or sum x'Qx + u'Ru (discrete); u = -K x with K from
python-control's ``lqr`` / ``dlqr`` (the Riccati solution P of eq 10 is returned too). Q is built
from weights per named state and per named output, R from weights per input; an output
z_i = C_i x + D_i u weighted by w adds w (C_i x + D_i u)^2 (Q, R and the cross term N of
x'Qx + 2 x'Nu + u'Ru), so a blade-root moment or a pitch rate can be weighted directly; weights
are divided by the squares of optional typical magnitudes (``scales``) so that they are
dimensionless.

PI observer (Do et al. eqs 11-16): the model extended with unknown inputs f that act through N
(by default the disturbance matrix B_d: the blade-effective wind deviations) as constants,
A_e = [[A, N], [0, 0]], C_e = [C, 0] (eq 13), observer gains [L1; L2] by LQR on the dual pair
(A_e', C_e') with Q_obs = diag(I_n, q I_r), R_obs = I_m (eq 16). The design checks that A_e - L C_e
is stable (eq 15) and reports ||L2||_F / ||L1||_F, which q >> 1 makes large ("high gain").

:class:`LQRPIOController` holds both as the kind's shipped C law runs them: the observer
discretized (zero-order hold on its input u and measurement y) at the controller period, the
pitch commands
u = u0 - K x_hat - K_f f_hat (the unknown-input feedforward K_f cancels the steady effect of the
estimated wind on the regulated outputs, a disturbance-accommodating term; ``feedforward=False``
drops it), generator torque constant at its operating-point value (Do's region III strategy) or
the region-II torque law K_opt Omega^2 (Do eq 7) with the LQR pitch added around fine pitch.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Mapping, Sequence

import numpy as np
import scipy.linalg

import linearize
from linearize.validate import check_number
from mpc_wt.controllers.base import DesignBase
from mpc_wt.controllers.baseline import LawTorque
from mpc_wt.errors import SynthesisError

__all__ = ["LQRDesign", "PIObserver", "design_lqr", "design_lqr_family", "design_pi_observer",
           "LQRPIOController", "ScheduledLQRPIO", "SynthesisError", "REGION3_WEIGHTS",
           "REGION3_SCALES", "PAPER_MEASURED", "TURBINE_MEASURED", "turbine_scales"]

#: Region-III LQR weights that hold the loop stable with the PI observer (q = 1e3) on the
#: nonlinear plant: rotor-speed regulation and tower fore-aft damping (``state_weights``).
REGION3_WEIGHTS = {"rotor_speed": 5.0, "tower_fa_velocity": 1.0}
#: Their typical magnitudes (``scales``): 0.05 rad/s, 0.1 m/s, 1 deg of pitch per blade.
REGION3_SCALES = {"rotor_speed": 0.05, "tower_fa_velocity": 0.1,
                  **{f"pitch_ref_{i}": math.radians(1.0) for i in (1, 2, 3)}}
#: Region II (Do et al. sec. 4.2): the torque law keeps the speed; the pitch, moved around its
#: operating point, adds damping to the tower fore-aft and blade flap modes only.
REGION2_WEIGHTS = {"tower_fa_velocity": 1.0, **{f"flap_rate_{i}": 0.2 for i in (1, 2, 3)}}
#: Their magnitudes: 0.1 m/s tower-top velocity, 1 m/s flap tip rate, 1 deg of pitch per blade.
REGION2_SCALES = {"tower_fa_velocity": 0.1, **{f"flap_rate_{i}": 1.0 for i in (1, 2, 3)},
                  **{f"pitch_ref_{i}": math.radians(1.0) for i in (1, 2, 3)}}


#: Do et al.'s measured signals (sec. 3.2): generator speed, tower-top fore-aft displacement
#: and the blades' flap tip displacements (modal states a turbine's controller is not given).
PAPER_MEASURED = ("gen_speed", "tower_fa_displacement", "flap_1", "flap_2", "flap_3")
#: What a turbine's controller is given (the Bladed interface's records 20, 53 and 30-32):
#: generator speed, tower-top fore-aft acceleration and the blade root out-of-plane moments.
TURBINE_MEASURED = ("gen_speed", "tower_fa_acceleration", "flap_moment_1", "flap_moment_2",
                    "flap_moment_3")


def turbine_scales(model: linearize.LinearModel) -> dict[str, float]:
    """Scales of :data:`TURBINE_MEASURED` for the observer's R = I (``scales`` of
    :func:`design_pi_observer`): what one metre of tower-top or flap tip displacement gives in
    the model (the NREL 5-MW: 4.4 m/s^2 of tower-top acceleration, 1.7 MN m of root moment), so
    that they weigh the structure as :data:`PAPER_MEASURED`'s displacements (scale 1 m) do.

    Parameters
    ----------
    model : LinearModel
        The model the observer is designed on.

    Returns
    -------
    dict of str to float
        Generator speed 1 rad/s, the acceleration [m/s^2] and the moments [N m].
    """
    def gain(output: str, state: str) -> float:
        return abs(float(model.C_z[model.outputs.index(output), model.states.index(state)]))

    out = {"gen_speed": 1.0,
           "tower_fa_acceleration": gain("tower_fa_acceleration", "tower_fa_displacement")}
    out.update({f"flap_moment_{i}": gain(f"flap_moment_{i}", f"flap_{i}") for i in (1, 2, 3)})
    bad = {k: v for k, v in out.items() if not (math.isfinite(v) and v > 0)}
    if bad:
        raise ValueError(f"the model gives no scale for {sorted(bad)} (zero or non-finite "
                         f"sensitivity to the displacement)")
    return out


def _names(model: linearize.LinearModel) -> dict[str, tuple[np.ndarray, str]]:
    """Name -> (row over the states, kind) for states and outputs (outputs as C rows)."""
    out: dict[str, tuple[np.ndarray, str]] = {}
    for i, n in enumerate(model.outputs):
        out[n] = (model.C_z[i], "output")
    for i, n in enumerate(model.states):
        out[n] = (np.eye(len(model.states))[i], "state")
    return out


def _check_weight(name: str, v: Any) -> float:
    return check_number(f"weight {name!r}", v, lo=0.0, reason="Q must be positive semidefinite")


def uncontrollable_modes(a: np.ndarray, b: np.ndarray, discrete: bool) -> list[complex]:
    """Eigenvalues of A that are not stable and not controllable (PBH test)."""
    bad = []
    n = a.shape[0]
    for lam in np.linalg.eigvals(a):
        unstable = abs(lam) >= 1.0 - 1e-9 if discrete else lam.real >= -1e-9
        if not unstable:
            continue
        m = np.hstack([lam * np.eye(n) - a, b])
        s = np.linalg.svd(m, compute_uv=False)
        if s[-1] < 1e-9 * max(1.0, s[0]):
            bad.append(complex(lam))
    return bad


@dataclass
class LQRDesign:
    """An LQR gain at one operating point: u - u0 = -K (x - x0).

    Parameters
    ----------
    K : ndarray (n_u, n_x)
        Gain on the state deviations, for the inputs ``inputs``.
    P : ndarray (n_x, n_x)
        Riccati solution (Do et al. eq 10).
    Q, R : ndarray
        The weights used (after scaling).
    closed_loop_eigs : ndarray
        Eigenvalues of A - B K.
    """

    K: np.ndarray
    P: np.ndarray
    Q: np.ndarray
    R: np.ndarray
    closed_loop_eigs: np.ndarray
    states: tuple[str, ...]
    inputs: tuple[str, ...]
    x0: np.ndarray
    u0: np.ndarray
    wind_mps: float
    dt: float | None
    weights: dict[str, Any] = field(default_factory=dict)


def design_lqr(model: linearize.LinearModel, *,
               state_weights: Mapping[str, float] | None = None,
               output_weights: Mapping[str, float] | None = None,
               input_weights: Mapping[str, float] | None = None,
               inputs: Sequence[str] = ("pitch_ref_1", "pitch_ref_2", "pitch_ref_3"),
               scales: Mapping[str, float] | None = None) -> LQRDesign:
    """LQR full-state feedback on ``model`` (continuous, or discrete when ``model.dt`` is set).

    Parameters
    ----------
    state_weights, output_weights : dict of name to weight >= 0
        Weights on named states and on named outputs (an output z_i = C_i x + D_i u adds
        w (C_i x + D_i u)^2 to the cost: Q, R and the cross term N). Default: rotor speed 1
        (speed regulation, Do's region III).
    input_weights : dict of input name to weight > 0
        Default 1 for every input used (Do: R = I).
    inputs : names of the inputs the gain acts on (default the three pitch references; the
        others are held at the operating point).
    scales : dict of name to typical magnitude > 0
        Each weight is divided by the square of its signal's scale (default 1).

    Returns
    -------
    LQRDesign
        Gain K, Riccati solution P, weights Q and R, closed-loop eigenvalues and the
        operating point.

    Raises
    ------
    ValueError
        A weight negative or non-finite, an unknown name, an input weight not > 0.
    SynthesisError
        (A, B) not stabilizable: the message lists the unstable uncontrollable modes.
    """
    import control

    scales = _check_scales(scales)
    sw = dict(state_weights or {})
    ow = dict(output_weights or {})
    if not sw and not ow:
        sw = {"rotor_speed": 1.0}
    inputs = tuple(inputs)
    r, iw = _input_weight_matrix(model, inputs, input_weights, scales)
    iu = [model.inputs.index(n) for n in inputs]
    q, r_out, n_cross = _weight_matrices(model, sw, ow, scales, iu)
    r = r + r_out
    a, b = model.A, model.B_u[:, iu]
    discrete = model.dt is not None
    modes = uncontrollable_modes(a, b, discrete)
    if modes:
        raise SynthesisError(
            f"(A, B) is not stabilizable with inputs {list(inputs)}: the modes "
            f"{', '.join(f'{m.real:.4g}{m.imag:+.4g}j' for m in modes)} are "
            f"{'outside the unit circle' if discrete else 'not in the open left half-plane'} and "
            f"cannot be moved; add an input that acts on them or a model DOF that damps them")
    try:
        k, p, eig = (control.dlqr if discrete else control.lqr)(a, b, q, r, n_cross)
    except Exception as err:  # python-control raises ControlArgument / LinAlgError
        raise SynthesisError(f"the Riccati equation has no stabilizing solution: {err}; "
                             f"check that every unstable mode is seen by Q (detectability)") \
            from err
    k, p = np.asarray(k), np.asarray(p)
    return LQRDesign(K=k, P=p, Q=q, R=r, closed_loop_eigs=np.asarray(eig),
                     states=model.states, inputs=inputs, x0=model.x0.copy(),
                     u0=model.u0[iu].copy(), wind_mps=float(model.wind_mps), dt=model.dt,
                     weights={"state": sw, "output": ow, "input": iw, "scales": scales})


def _check_scales(scales: Mapping[str, float] | None) -> dict[str, float]:
    out = dict(scales or {})
    return {k: check_number(f"scale {k!r}", v, lo=0.0, lo_open=True) for k, v in out.items()}


def _weight_matrices(model: linearize.LinearModel, sw: Mapping[str, float],
                     ow: Mapping[str, float], scales: Mapping[str, float], iu: Sequence[int]
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Q, the inputs' share R_z and the cross term N of the cost from weights on named states
    and outputs, each divided by its scale^2: an output z_i = C_i x + D_i u weighted by w adds
    w (C_i x + D_i u)^2, i.e. w C_i' C_i to Q, w D_i' D_i to R and w C_i' D_i to N (a pitch
    rate, (u - x_pitch) / tau, is weighted as the rate it is)."""
    nx = len(model.states)
    q = np.zeros((nx, nx))
    r = np.zeros((len(iu), len(iu)))
    n_cross = np.zeros((nx, len(iu)))
    for group, kind in ((sw, "state"), (ow, "output")):
        pool = model.states if kind == "state" else model.outputs
        for n, w in group.items():
            if n not in pool:
                raise ValueError(f"{kind}_weights: unknown {kind} {n!r}; the model's {kind}s are "
                                 f"{list(pool)}")
            w = _check_weight(n, w) / scales.get(n, 1.0) ** 2
            if kind == "output":
                row = model.C_z[model.outputs.index(n)]
                d = model.D_u[model.outputs.index(n), iu]
                r += w * np.outer(d, d)
                n_cross += w * np.outer(row, d)
            else:
                row = np.eye(nx)[model.states.index(n)]
            q += w * np.outer(row, row)
    q = 0.5 * (q + q.T)
    lam = np.linalg.eigvalsh(q)
    if lam[0] < -1e-10 * max(1.0, lam[-1]):
        raise ValueError(f"Q is not positive semidefinite (smallest eigenvalue {lam[0]:g})")
    return q, r, n_cross


def _input_weight_matrix(model: linearize.LinearModel, inputs: tuple[str, ...],
                         input_weights: Mapping[str, float] | None,
                         scales: Mapping[str, float]) -> tuple[np.ndarray, dict[str, float]]:
    """R (diagonal, default 1 per input) and the weights by name."""
    bad = [n for n in inputs if n not in model.inputs]
    if bad or not inputs:
        raise ValueError(f"inputs {bad or inputs!r} not among the model's inputs "
                         f"{list(model.inputs)}")
    iw = {n: 1.0 for n in inputs}
    for n, w in (input_weights or {}).items():
        if n not in inputs:
            raise ValueError(f"input_weights: {n!r} is not one of the inputs {list(inputs)}")
        iw[n] = check_number(f"input weight {n!r}", w, lo=0.0, lo_open=True,
                             reason="R must be positive definite")
    return np.diag([iw[n] / scales.get(n, 1.0) ** 2 for n in inputs]), iw


def design_lqr_family(family: linearize.LinearModelFamily, **kwargs: Any) -> list[LQRDesign]:
    """:func:`design_lqr` at every model of ``family`` (same weights); a gain table over wind.

    Parameters
    ----------
    family : LinearModelFamily
        Models over mean wind.
    **kwargs
        Passed to :func:`design_lqr`.

    Returns
    -------
    list of LQRDesign
        One per model.
    """
    return [design_lqr(m, **kwargs) for m in family.models]


@dataclass
class PIObserver:
    """PI observer gains (Do et al. eqs 13-16) on a continuous model.

    Parameters
    ----------
    L1, L2 : ndarray
        Proportional (n_x, n_y) and integral (n_f, n_y) gains.
    A_e, B_e, C_e : ndarray
        The extended model (eq 13).
    error_eigs : ndarray
        Eigenvalues of A_e - L C_e (eq 15); all have negative real parts.
    gain_ratio : float
        ||L2||_F / ||L1||_F (Do et al.: >> 1).
    """

    L1: np.ndarray
    L2: np.ndarray
    A_e: np.ndarray
    B_e: np.ndarray
    C_e: np.ndarray
    D_e: np.ndarray
    error_eigs: np.ndarray
    gain_ratio: float
    measured: tuple[str, ...]
    y0: np.ndarray
    q: float

    @property
    def L(self) -> np.ndarray:
        return np.vstack([self.L1, self.L2])


def _measurement_rows(model: linearize.LinearModel, measured: Sequence[str], nf: int,
                      wind_feedthrough: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """C_e, D_e and y0 of the measured names over [x; f]: a state's unit row, an output's
    model rows; an output the wind moves directly (a root moment, an acceleration) sees the
    unknown inputs through D_d when they are the model's disturbances (``wind_feedthrough``)."""
    names = _names(model)
    out = [names[n][1] == "output" for n in measured]
    rows = [model.outputs.index(n) if o else -1 for n, o in zip(measured, out)]
    c = np.array([names[n][0] for n in measured])
    nu = model.B_u.shape[1]
    du = np.array([model.D_u[r] if o else np.zeros(nu) for r, o in zip(rows, out)])
    y0 = np.array([model.z0[r] if o else model.x0[model.states.index(n)]
                   for n, r, o in zip(measured, rows, out)])
    cf = np.array([model.D_d[r] if o and wind_feedthrough else np.zeros(nf)
                   for r, o in zip(rows, out)]).reshape(len(measured), nf)
    return np.hstack([c, cf]), du, y0


def design_pi_observer(model: linearize.LinearModel, *,
                       measured: Sequence[str] = PAPER_MEASURED,
                       unknown_inputs: np.ndarray | None = None, q: float = 1e3,
                       scales: Mapping[str, float] | None = None) -> PIObserver:
    """PI observer for ``model`` (continuous) from the named measured signals.

    Parameters
    ----------
    measured : names of outputs or states that are measured (Do et al.: generator speed, tower
        fore-aft displacement, blade flap displacements).
    unknown_inputs : ndarray (n_x, n_f), optional
        N of eq 11; default the model's B_d (the unknown inputs are the blade-wind deviations,
        and a measured output sees them through the model's D_d: root moments and the
        tower-top acceleration respond to the wind without delay).
    q : float
        Weight of the unknown-input block of Q_obs (eq 16), > 0; q >> 1 gives the high-gain PIO.
    scales : dict of measured name to typical magnitude
        Measurements are divided by these before the design (R_obs = I on the scaled outputs).


    Returns
    -------
    PIObserver
        The gains L1, L2, the extended model and the error eigenvalues.

    Raises
    ------
    SynthesisError
        (A_e, C_e) not detectable: the message lists the unobservable unstable modes.
    """
    import control

    if model.dt is not None:
        raise ValueError("design_pi_observer needs a continuous model (Do et al. eqs 13-16); "
                         "it is discretized for the controller by LQRPIOController")
    check_number("q", q, lo=0.0, lo_open=True)
    names = _names(model)
    bad = [n for n in measured if n not in names]
    if bad or not measured:
        raise ValueError(f"measured signals {bad or list(measured)!r} are neither outputs nor "
                         f"states of the model")
    scales = dict(scales or {})
    sy = np.array([scales.get(n, 1.0) for n in measured])
    if not np.all(np.isfinite(sy) & (sy > 0)):
        raise ValueError(f"scales must be finite and > 0, got {scales!r}")
    nmat = model.B_d if unknown_inputs is None else np.asarray(unknown_inputs, float)
    nx = model.A.shape[0]
    if nmat.ndim != 2 or nmat.shape[0] != nx:
        raise ValueError(f"unknown_inputs must have shape (n_x, n_f) = ({nx}, n_f), got "
                         f"{nmat.shape}")
    nf = nmat.shape[1]
    ae = np.block([[model.A, nmat], [np.zeros((nf, nx + nf))]])
    be = np.vstack([model.B_u, np.zeros((nf, model.B_u.shape[1]))])
    ce, du, y0 = _measurement_rows(model, measured, nf, unknown_inputs is None)
    ces = ce / sy[:, None]
    modes = uncontrollable_modes(ae.T, ces.T, discrete=False)
    if modes:
        raise SynthesisError(
            f"(A_e, C_e) is not detectable from {list(measured)}: the modes "
            f"{', '.join(f'{m.real:.4g}{m.imag:+.4g}j' for m in modes)} (including the unknown "
            f"inputs' integrators) are not seen; measure more signals or use fewer unknown "
            f"inputs")
    qobs = np.diag(np.r_[np.ones(nx), np.full(nf, float(q))])
    k, _, _ = control.lqr(ae.T, ces.T, qobs, np.eye(len(measured)))
    lmat = np.asarray(k).T / sy[None, :]
    eig = np.linalg.eigvals(ae - lmat @ ce)
    if eig.real.max() >= 0:
        raise SynthesisError(f"the PI observer is not stable (max real part {eig.real.max():g})")
    l1, l2 = lmat[:nx], lmat[nx:]
    ratio = float(np.linalg.norm(l2) / max(np.linalg.norm(l1), 1e-300))
    return PIObserver(L1=l1, L2=l2, A_e=ae, B_e=be, C_e=ce, D_e=du, error_eigs=eig,
                      gain_ratio=ratio, measured=tuple(measured), y0=y0, q=float(q))


class LQRPIOController(DesignBase):
    """The design of LQR state feedback on PI-observer estimates (Do et al. Fig. 2) at one
    operating point, run by its shipped law (the ``lqr-pio`` kind's C law,
    ``mpc_wt/io/discon_c/lqr.c``, as a schedule of this one design;
    :func:`mpc_wt.run.law_controller` runs it).

    The law updates the observer over each period (its zero-order hold at ``dt``, eq 13 with
    the measurements' deviations from the operating point), commands u = u0 - K (x_hat - x0)
    - K_f f_hat on the gain's inputs, each pitch within the actuator's limits and within its
    rate times its time constant of that blade's measured pitch (the command the actuator can
    follow; the observer is fed this command, not one whose gap it would read as wind), the
    torque by the region.

    Parameters
    ----------
    model : LinearModel
        Continuous actuator-augmented model (e.g. ``PlantConfig.do()``) at the mean wind.
    turbine : Turbine
    lqr : LQRDesign
        From :func:`design_lqr` on ``model`` (continuous) -- the gain acts on the pitch inputs.
    observer : PIObserver
        From :func:`design_pi_observer` on ``model``.
    dt : float
        Controller period [s] (default 0.0125, the plant rate).
    region : {"III", "II"}
        III: generator torque held at the operating point (Do's constant-torque region III);
        II: the torque law K_opt Omega_g^2 (eq 7, ``k_opt`` [N m/(rad/s)^2] on generator speed),
        the LQR pitch added around the operating-point pitch.
    torque_law : BaselineController, optional
        Region II only: take the generator torque from this baseline's schedule (regions 1.5,
        2 and 2.5, :meth:`BaselineController.torque`) on the generator speed low-passed at its
        filter corner, instead of K_opt Omega_g^2 on the raw speed. Do et al.'s PI and FSF share
        one torque law in region II (sec. 4.2: only the pitch loop differs), so a comparison
        with our baseline needs ours.
    feedforward : bool
        Add the unknown-input feedforward -K_f f_hat (default True).
    regulated : names of states whose steady deviation the feedforward cancels (least squares;
        default rotor speed).

    Notes
    -----
    The torque by region: region III holds the operating point's torque (Do et al.'s constant
    torque), capped by the torque law where one is given (below rated speed at fine pitch the
    law asks less: a rotor slowed by a lull is not braked into a stall); region II follows the
    law (or K_opt Omega_g^2 on the raw generator speed). The pitch commands stay above the
    turbine's region-2 pitch (a deck's minimum-pitch table, else the fine pitch): with a torque
    law, the law's minimum-pitch schedule on its filtered generator speed (the baseline's and
    the TS law's); without one, ``pitch_floor``, :func:`linearize.region2_pitch` at the
    design's wind (never above the operating point's), which the schedule's nearest design
    makes a minimum pitch scheduled on the estimated wind.
    """

    kind = "lqr-pio"

    def __init__(self, model: linearize.LinearModel, turbine: linearize.Turbine,
                 lqr: LQRDesign, observer: PIObserver, *, dt: float = 1.0 / 80.0,
                 region: str = "III", k_opt: float | None = None, feedforward: bool = True,
                 regulated: Sequence[str] = ("rotor_speed",),
                 torque_law: Any = None) -> None:
        if model.dt is not None:
            raise ValueError("model must be continuous (the observer is discretized here)")
        if lqr.dt is not None:
            raise ValueError("lqr must be designed on the continuous model")
        if region not in ("II", "III"):
            raise ValueError(f"region must be 'II' or 'III', got {region!r}")
        if region == "II" and torque_law is None and not (k_opt and k_opt > 0):
            raise ValueError("region 'II' needs k_opt > 0 [N m/(rad/s)^2] or a torque_law")
        self.torque_law = torque_law
        check_number("dt", dt, lo=0.0, lo_open=True, unit="s")
        # the torque law's speed filter pole at our period
        self._law = LawTorque(torque_law, dt) if torque_law is not None else None
        self.model, self.turbine, self.lqr, self.obs = model, turbine, lqr, observer
        self.dt, self.region, self.k_opt = float(dt), region, k_opt
        nx, nf = model.A.shape[0], observer.L2.shape[0]
        nu_all = model.B_u.shape[1]
        # observer ODE: xe' = (Ae - L Ce) xe + (Be - L De) u + L y  -> ZOH at dt
        lmat = observer.L
        ao = observer.A_e - lmat @ observer.C_e
        bo = np.hstack([observer.B_e - lmat @ observer.D_e, lmat])
        n = ao.shape[0]
        m = scipy.linalg.expm(np.block([[ao, bo], [np.zeros((bo.shape[1], n + bo.shape[1]))]])
                              * dt)
        self._ad, self._bd = m[:n, :n], m[:n, n:]
        self._iu = [model.inputs.index(nm) for nm in lqr.inputs]
        self._nu_all, self._nx, self._nf = nu_all, nx, nf
        # feedforward: choose K_f so that at steady state (A x + B K_f... ) the regulated states
        # do not move with f: 0 = A x + B_sel u + N f, u = -K x - K_f f, x_reg = 0
        kf = np.zeros((len(self._iu), nf))
        if feedforward:
            bsel = model.B_u[:, self._iu]
            acl = model.A - bsel @ lqr.K
            nmat = observer.A_e[:nx, nx:]
            sel = np.array([model.states.index(r) for r in regulated])
            # x = -acl^-1 (N - B K_f) f ; regulated rows zero: S acl^-1 B K_f = S acl^-1 N
            ainv = np.linalg.solve(acl, np.eye(nx))
            kf = np.linalg.lstsq(ainv[sel] @ bsel, ainv[sel] @ nmat, rcond=None)[0]
        self.K_f = kf
        # the compiled step's data: the gains side by side, the inputs' columns, the limits
        self._gain = np.ascontiguousarray(np.hstack([lqr.K, kf]))
        self._iu_arr = np.asarray(self._iu, dtype=np.int64)
        pa = turbine.pitch_actuator
        self._pitch_lim = np.array([pa.min_pitch_rad, pa.max_pitch_rad])
        # the lowest pitch command: the turbine's region-2 pitch at the design's wind (a deck's
        # minimum-pitch table, else fine pitch), never above the operating point's
        self.pitch_floor = float(min(max(pa.min_pitch_rad,
                                         linearize.region2_pitch(turbine, model.wind_mps)),
                                     np.min(np.asarray(model.u0)[:3])))
        # how far a command may lead the measured pitch: a first-order actuator (time
        # constant tau) then moves at most at its rate
        self._reach = pa.max_rate_rad_s * pa.time_constant if pa.time_constant > 0 else math.inf


class ScheduledLQRPIO(DesignBase):
    """The design of LQR-PIO over a grid of mean winds, run by its shipped law (the
    ``lqr-pio`` kind's C law; :func:`mpc_wt.run.law_controller` runs a design made by hand):
    one design acting at a time, chosen on a measured mean wind
    (:class:`~mpc_wt.controllers.scheduling.WindSchedule`: the rotor-effective wind
    estimated from rotor speed, pitch and generator torque, low-passed, with hysteresis).

    Below the rated wind each design is Do et al.'s region II (the torque law, the LQR on the
    pitch around fine pitch), above it region III (torque held at rated, the LQR with the
    unknown-input feedforward). On a switch the observer's estimate, the last command and the
    torque law's filtered speed are carried over in absolute units (bumpless): the new design
    continues from where the old one left the turbine.

    Parameters
    ----------
    controllers : sequence of LQRPIOController
        One per grid wind, all at the same ``dt``.
    winds : (n,) array
        Their mean winds [m/s], increasing.
    turbine : Turbine
        For the wind estimator.
    time_constant : float
        Low-pass of the scheduling wind [s].
    hysteresis : float
        Beyond the midpoint between grid winds [m/s].
    wind_estimator : WindSpeedEstimator, optional
        The scheduling wind's estimator at the controllers' ``dt`` (default: made here).

    Notes
    -----
    The law logs ``region`` (2 or 3), ``schedule_wind`` and ``schedule_grid_wind`` [m/s].
    """

    kind = "lqr-pio"

    def __init__(self, controllers: Sequence[LQRPIOController], winds: Any,
                 turbine: linearize.Turbine, *, time_constant: float = 30.0,
                 hysteresis: float = 0.25, wind_estimator: Any = None) -> None:
        from mpc_wt.controllers.scheduling import WindSchedule

        self.controllers = list(controllers)
        w = np.asarray(winds, dtype=float)
        if len(self.controllers) != w.size or w.size == 0:
            raise ValueError(f"need one controller per wind: {len(self.controllers)} "
                             f"controllers, {w.size} winds")
        dts = {c.dt for c in self.controllers}
        if len(dts) != 1:
            raise ValueError(f"every controller must run at one dt, got {sorted(dts)}")
        self.dt = dts.pop()
        self.winds = w
        self.schedule = WindSchedule(w, turbine, self.dt, time_constant=time_constant,
                                     hysteresis=hysteresis, estimator=wind_estimator)

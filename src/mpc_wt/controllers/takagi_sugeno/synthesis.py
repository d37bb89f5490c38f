"""LMI synthesis of the Takagi-Sugeno controller and wind observer (Clemens et al. eqs 7-10), and
the certificates checked with numpy alone after every solve.
"""
from __future__ import annotations

import itertools
import logging
import time
import warnings
from dataclasses import dataclass
from typing import Any, Mapping, Sequence

import numpy as np

from linearize.validate import check_number
from mpc_wt.controllers.takagi_sugeno.model import DEFAULT_SCALES, TSModel
from mpc_wt.errors import SynthesisError

__all__ = ["Certificate", "TSControllerDesign", "TSObserverDesign", "design_ts_controller",
           "verify_controller", "design_ts_observer", "verify_observer"]

log = logging.getLogger(__name__)


# --------------------------------------------------------------------------------------------
# LMI synthesis
# --------------------------------------------------------------------------------------------
@dataclass
class Certificate:
    """The result of checking an LMI design with numpy alone.

    Parameters
    ----------
    ok : bool
    worst_lmi : float
        Largest eigenvalue over the strict LMIs (scaled coordinates), must be
        <= -margin.
    worst_decay : float
        Largest real part of the closed-loop eigenvalues over the premise grid plus the
        required decay rate: must be <= 0.
    worst_lyapunov : float
        Largest eigenvalue of Acl' P + P Acl + 2 alpha P (normalised) over the premise grid.
    n_grid : int
        Premise points checked.
    failures : list of str
    """

    ok: bool
    worst_lmi: float
    worst_decay: float
    worst_lyapunov: float
    n_grid: int
    failures: list[str]


@dataclass
class TSControllerDesign:
    """PDC gains K_i [SI] on x - x0_i with common Lyapunov matrix P (in scaled coordinates).

    Parameters
    ----------
    K : (N, n_u, n_x [+ 1]) ndarray
        The last column acts on the integral of ``integral_of``'s deviation [unit s] when set.
    P : (n_x [+ 1], n_x [+ 1]) ndarray   P = X^-1 of the scaled problem.
    decay_rate : float [1/s]
    disk_radius : float or None [1/s]
    input_bounds : (n_u,) ndarray  mu_j [SI input units] on the ellipsoid: the largest of
        the vertices' bounds.
    uncontrolled : tuple of str  the states K does not act on (zero columns); P is
        the Lyapunov matrix of the model without them.
    solver, solve_time_s, certificate
    """

    K: np.ndarray
    P: np.ndarray
    scale_x: np.ndarray
    scale_u: np.ndarray
    decay_rate: float
    disk_radius: float | None
    input_bounds: np.ndarray
    integral_of: str | None
    solver: str
    solve_time_s: float
    certificate: Certificate
    margin: float
    uncontrolled: tuple[str, ...] = ()


@dataclass
class TSObserverDesign:
    """TS observer gains L_i [SI] for xi = [x; v] (Clemens eq 10) from the measured outputs.

    Parameters
    ----------
    L : (N, n_xi, n_y) ndarray
        Observer gains per vertex [SI].
    P : ndarray
        Common Lyapunov matrix (scaled coordinates).
    A_aug, B_aug, C_aug : ndarray
        The augmented model of eq 10.
    scale_xi, scale_y : ndarray
        Scales of the augmented state and the outputs.
    tau_v : float
        Wind time constant of the augmentation [s].
    decay_rate : float
        Guaranteed decay rate [1/s].
    disk_radius : float or None
        Pole disk radius [1/s].
    solver : str
        The SDP solver used.
    solve_time_s : float
        Solve time [s].
    certificate : Certificate
        The numpy check.
    margin : float
        LMI margin.
    """

    L: np.ndarray
    P: np.ndarray
    A_aug: np.ndarray
    B_aug: np.ndarray
    C_aug: np.ndarray
    scale_xi: np.ndarray
    scale_y: np.ndarray
    tau_v: float
    decay_rate: float
    disk_radius: float | None
    solver: str
    solve_time_s: float
    certificate: Certificate
    margin: float


def _scales(ts: TSModel, names: Sequence[str], scales: Mapping[str, float] | None
            ) -> np.ndarray:
    """The typical magnitudes of ``names``: ``scales``, else the model's, else the defaults."""
    s = dict(DEFAULT_SCALES)
    s.update(ts.scales or {})
    s.update(scales or {})
    out = []
    for n in names:
        out.append(check_number(f"scale {n!r}", s.get(n, 1.0), lo=0.0, lo_open=True))
    return np.array(out)


def _check_rate(name: str, v: Any, allow_none: bool = False) -> float | None:
    if v is None and allow_none:
        return None
    return check_number(name, v, lo=0.0, unit="[1/s]")


def _solve(prob: Any, solver: str | None) -> tuple[str, str]:
    """Solve with ``solver`` or the first installed of MOSEK, Clarabel, SCS that returns a
    status; a solver that fails numerically is logged and the next one tried. Returns the
    solver's name and the status, "solver_error" when none gave one (treated as infeasible by
    the callers, who then say what to relax)."""
    import cvxpy as cp

    installed = cp.installed_solvers()
    if solver and solver not in installed:
        raise ValueError(f"solver {solver!r} is not installed; installed: {installed}")
    names = [solver] if solver else [s for s in ("MOSEK", "CLARABEL", "SCS") if s in installed]
    for s in names:
        try:
            with warnings.catch_warnings():
                # "optimal_inaccurate" is kept: the numpy certificate decides, not the status
                warnings.filterwarnings("ignore", message="Solution may be inaccurate")
                prob.solve(solver=s)
        except (KeyboardInterrupt, SystemExit):
            raise
        except BaseException as err:  # cvxpy.SolverError; Clarabel's Rust panics are
            log.warning("SDP solver %s failed (%s); trying the next", s, err)
            continue
        if prob.status in ("optimal", "optimal_inaccurate", "infeasible",
                           "infeasible_inaccurate"):
            return s, prob.status
    return (names[-1] if names else "none"), "solver_error"


def _sym(m: Any) -> Any:
    return 0.5 * (m + m.T)


def _controller_mats(ts: TSModel, integral_of: str | None, sx: np.ndarray, su: np.ndarray
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Scaled A_i, B_i of the controller design, augmented by the integral of a state's
    deviation from its vertex value (dq/dt = x_k - x_0,i,k) when ``integral_of`` is set."""
    a, b = ts.A, ts.B
    if integral_of is not None:
        k = ts.states.index(integral_of)
        nv, nx = a.shape[:2]
        aa = np.zeros((nv, nx + 1, nx + 1))
        aa[:, :nx, :nx] = a
        aa[:, nx, k] = 1.0
        a = aa
        b = np.concatenate([b, np.zeros((nv, 1, b.shape[2]))], axis=1)
    return (np.array([np.diag(1 / sx) @ ai @ np.diag(sx) for ai in a]),
            np.array([np.diag(1 / sx) @ bi @ np.diag(su) for bi in b]))


def _controller_problem(a: np.ndarray, b: np.ndarray, cells: list[tuple[int, ...]],
                        alpha: float, radius: float | None, mu: np.ndarray | None,
                        eps: float, use_bound: bool = True) -> tuple[Any, Any, list[Any], Any]:
    import cvxpy as cp

    nv, nx, nu = b.shape
    x = cp.Variable((nx, nx), symmetric=True)
    y = [cp.Variable((nu, nx)) for _ in range(nv)]
    cons: list[Any] = []
    ix = np.eye(nx)

    def g(i: int, j: int) -> Any:
        return a[i] @ x - b[i] @ y[j]

    pairs = sorted({(i, j) for c in cells for i in c for j in c if i < j})
    for i in range(nv):
        cons.append(_sym(g(i, i) + g(i, i).T + 2 * alpha * x) << -eps * ix)
    for i, j in pairs:
        s = g(i, j) + g(j, i)
        cons.append(_sym(s + s.T + 4 * alpha * x) << 0)
    if radius is not None:
        for i in range(nv):
            gi = g(i, i)
            cons.append(_sym(cp.bmat([[-radius * x, gi], [gi.T, -radius * x]]))
                        << -eps * np.eye(2 * nx))
        for i, j in pairs:
            s = g(i, j) + g(j, i)
            cons.append(_sym(cp.bmat([[-2 * radius * x, s], [s.T, -2 * radius * x]])) << 0)
    for k in range(nx):
        e = ix[:, k:k + 1]
        cons.append(_sym(cp.bmat([[np.ones((1, 1)), e.T], [e, x]])) >> 0)
    # each vertex's own bound t_ij on input j (one bound shared by the vertices, as before,
    # left the gains of every vertex but the one that set it free up to that bound: on the
    # IEA-15-240-RWT the high-wind vertices then pitched on the tower's motion)
    t = cp.Variable((nv, nu))
    if use_bound:
        for i in range(nv):
            for j in range(nu):
                row = y[i][j:j + 1, :]
                tj = cp.reshape(t[i, j], (1, 1), order="C")
                cons.append(_sym(cp.bmat([[x, row.T], [row, tj]])) >> 0)
        if mu is not None:
            for j in np.nonzero(np.isfinite(mu))[0]:
                cons.append(t[:, j] <= mu[j] ** 2)
    obj = cp.Minimize(cp.sum(t)) if use_bound else cp.Minimize(cp.trace(x))
    return cp.Problem(obj, cons), x, y, t


def design_ts_controller(ts: TSModel, *, decay_rate: float = 0.2,
                         disk_radius: float | None = None,
                         input_bounds: Mapping[str, float] | None = None,
                         scales: Mapping[str, float] | None = None, margin: float = 1e-4,
                         integral_of: str | None = "rotor_speed",
                         solver: str | None = None, grid_points: int = 6,
                         uncontrolled: Sequence[str] = ()) -> TSControllerDesign:
    """PDC gains K_i for the TS model by LMIs (Clemens et al. eq 7); certificate checked.

    Parameters
    ----------
    decay_rate : float
        alpha [1/s]: every trajectory decays at least as exp(-alpha t) (Re lambda <= -alpha).
    disk_radius : float or None
        D-stability: closed-loop eigenvalues within abs(lambda) < r [1/s] (keeps the gains from
        outrunning the controller rate and the unmodelled dynamics); None drops it.
    input_bounds : dict of input name to bound, optional
        abs(u_j - u_0,j) <= mu_j [SI] for states in the Lyapunov ellipsoid that holds the typical
        deviations (``scales``). Default: the bounds are minimised instead.
    scales : dict of name to typical magnitude [SI]
        Scaling of states and inputs (default: the model's ``scales``, the turbine's typical
        magnitudes, else :data:`DEFAULT_SCALES`).
    margin : float
        Strictness of the LMIs in scaled units (verified to half of it).
    integral_of : str or None
        Add integral action on this state's deviation from its equilibrium (default rotor
        speed: removes the steady speed offset that model mismatch leaves with eq 7 alone;
        None gives Clemens' eq 7 exactly). Its scale is that of the state times 1 s.
    uncontrolled : sequence of str
        States the law does not act on (zero columns of K_i) and whose decay is not required:
        the LMIs and the certificate are those of the model without them (:func:`_kept`).

    Returns
    -------
    TSControllerDesign
        Gains K_i, P, scales, the solver and the certificate.

    Raises
    ------
    SynthesisError
        LMIs infeasible: the message says which constraint to relax (the input bound, the
        disk, or the decay rate, with the largest feasible decay rate found).
    """

    alpha = _check_rate("decay_rate", decay_rate)
    radius = _check_rate("disk_radius", disk_radius, allow_none=True)
    if radius is not None and radius <= alpha:
        raise ValueError(f"disk_radius ({radius:g} 1/s) must exceed decay_rate ({alpha:g} 1/s)")
    if integral_of is not None and integral_of not in ts.states:
        raise ValueError(f"integral_of must be a state of the TS model {list(ts.states)}, got "
                         f"{integral_of!r}")
    uncontrolled = _check_uncontrolled(ts, uncontrolled, integral_of)
    sx, su = _scales(ts, ts.states, scales), _scales(ts, ts.inputs, scales)
    if integral_of is not None:
        sx = np.append(sx, sx[ts.states.index(integral_of)] * 1.0)
    mu = _input_bounds(ts, input_bounds, su)
    a, b = _controller_mats(ts, integral_of, sx, su)
    keep = _kept(ts, uncontrolled, sx.size)
    a, b = a[:, keep][:, :, keep], b[:, keep]
    cells = ts.cells()
    t0 = time.perf_counter()
    prob, xv, yv, tv = _controller_problem(a, b, cells, alpha, radius, mu, margin)
    used, status = _solve(prob, solver)
    dt = time.perf_counter() - t0
    if status not in ("optimal", "optimal_inaccurate"):
        raise SynthesisError(_diagnose_controller(a, b, cells, alpha, radius, mu, margin, used))
    k, p = _gains(xv.value, [y.value for y in yv], keep, sx, su)
    cert = verify_controller(ts, k, p, sx, su, alpha, radius, margin=0.5 * margin,
                             grid_points=grid_points, integral_of=integral_of,
                             uncontrolled=uncontrolled)
    if not cert.ok:
        raise SynthesisError(_certificate_failed(used, status, cert.failures))
    bounds = np.sqrt(np.maximum(tv.value.max(axis=0), 0)) * su if tv.value is not None \
        else np.full(len(ts.inputs), np.nan)
    return TSControllerDesign(K=k, P=p, scale_x=sx, scale_u=su, decay_rate=alpha,
                              disk_radius=radius, input_bounds=bounds, integral_of=integral_of,
                              solver=used, solve_time_s=dt, certificate=cert, margin=margin,
                              uncontrolled=uncontrolled)


def _certificate_failed(used: str, status: str, failures: list[str]) -> str:
    """What to do when the solver's gains fail the certificate: an inaccurate solve of LMIs that
    may be infeasible says what to relax."""
    hint = ("the LMIs may be infeasible: relax input_bounds, disk_radius or decay_rate, or "
            "tighten the solver tolerance" if status == "optimal_inaccurate" else
            "tighten the solver tolerance or scale the model")
    return (f"the solver ({used}, status {status}) returned gains whose certificate fails: "
            f"{'; '.join(failures[:3])}; {hint}")


def _gains(x: np.ndarray, y: list[np.ndarray], keep: np.ndarray, sx: np.ndarray,
           su: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """K_i [SI] (zero columns on the states not kept) and P from the scaled solution X, Y_i."""
    xs = 0.5 * (x + x.T)
    ks = np.zeros((len(y), su.size, sx.size))
    ks[:, :, keep] = [yi @ np.linalg.inv(xs) for yi in y]
    return np.array([np.diag(su) @ ki @ np.diag(1 / sx) for ki in ks]), np.linalg.inv(xs)


def _check_uncontrolled(ts: TSModel, uncontrolled: Sequence[str], integral_of: str | None
                        ) -> tuple[str, ...]:
    """``uncontrolled`` as a tuple of the model's states, checked."""
    if isinstance(uncontrolled, str):
        raise TypeError(f"uncontrolled must be a sequence of state names, got the string "
                        f"{uncontrolled!r}")
    out = tuple(str(n) for n in uncontrolled)
    bad = [n for n in out if n not in ts.states]
    if bad:
        raise ValueError(f"uncontrolled: {bad} are not states of the TS model "
                         f"{list(ts.states)}")
    if integral_of is not None and integral_of in out:
        raise ValueError(f"uncontrolled: {integral_of!r} is integral_of, the state the law "
                         f"integrates; it cannot be left out")
    if len(set(out)) == len(ts.states):
        raise ValueError("uncontrolled names every state of the TS model: the law would act "
                         "on none")
    return out


def _kept(ts: TSModel, uncontrolled: Sequence[str], n: int) -> np.ndarray:
    """Indices of the design's states (the model's and the integral, if any) the law acts on.

    ``uncontrolled`` is for a mode the inputs barely reach and that keeps its own (structural)
    damping: the tower's side-side (:data:`~mpc_wt.controllers.takagi_sugeno.model.
    SIDE_SIDE_STATES`). Its open-loop decay is 0.027 1/s on the NREL 5-MW and 0.020 1/s on the
    IEA-15-240-RWT; required to decay at the controller's rate it is damped by whatever input
    reaches it (the torque through the shaft's torsion, or on a direct drive the collective
    pitch through the rotor's in-plane force), which couples it into the rotor's thrust. Its
    couplings to the other states (the tower-top velocities' 0.05-0.06 1/s terms) are left out
    of the certificate; the scheduled loop on the whole plant
    (:func:`~mpc_wt.controllers.takagi_sugeno.robustness.design_for_loop`) checks them.
    """
    drop = {ts.states.index(s) for s in uncontrolled}
    return np.array([i for i in range(n) if i not in drop], dtype=int)


def _input_bounds(ts: TSModel, input_bounds: Mapping[str, float] | None, su: np.ndarray
                  ) -> np.ndarray | None:
    """Scaled input bounds mu_j on the ellipsoid, or None."""
    if not input_bounds:
        return None
    unknown = set(input_bounds) - set(ts.inputs)
    if unknown:
        raise ValueError(f"input_bounds: unknown inputs {sorted(unknown)}; inputs are "
                         f"{list(ts.inputs)}")
    mu = np.array([float(input_bounds.get(n, np.inf)) for n in ts.inputs]) / su
    if np.any(~(mu > 0)):
        raise ValueError(f"input_bounds must be > 0, got {dict(input_bounds)}")
    return mu


def _diagnose_controller(a, b, cells, alpha, radius, mu, margin, solver) -> str:
    """Find which constraint makes the controller LMIs infeasible."""
    what = []
    if mu is not None:
        p, *_ = _controller_problem(a, b, cells, alpha, radius, None, margin)
        if _solve(p, solver)[1] in ("optimal", "optimal_inaccurate"):
            return ("the controller LMIs are infeasible with the input bounds given: relax "
                    "input_bounds (feasible without them)")
        what.append("input_bounds")
    if radius is not None:
        p, *_ = _controller_problem(a, b, cells, alpha, None, None, margin, use_bound=False)
        if _solve(p, solver)[1] in ("optimal", "optimal_inaccurate"):
            return (f"the controller LMIs are infeasible with disk_radius = {radius:g} 1/s: "
                    f"relax (increase) disk_radius")
    lo, hi = 0.0, alpha
    for _ in range(8):
        mid = 0.5 * (lo + hi)
        p, *_ = _controller_problem(a, b, cells, mid, None, None, margin, use_bound=False)
        if _solve(p, solver)[1] in ("optimal", "optimal_inaccurate"):
            lo = mid
        else:
            hi = mid
    return (f"the controller LMIs are infeasible at decay_rate = {alpha:g} 1/s even without "
            f"the disk and input bounds: relax (lower) decay_rate; the largest feasible found is "
            f"about {lo:.4g} 1/s" if lo > 0 else
            "the controller LMIs are infeasible at any decay rate: the TS model is not "
            "stabilizable with a common Lyapunov function; add inputs or split the premise grid")


def _premise_grid(ts: TSModel, n: int) -> list[tuple[float, float]]:
    def fine(g: np.ndarray) -> np.ndarray:
        if g.size == 1:
            return g
        return np.unique(np.concatenate([np.linspace(g[k], g[k + 1], n + 1)
                                         for k in range(g.size - 1)]))
    return list(itertools.product(fine(ts.wind_grid), fine(ts.reduction_grid)))


def verify_controller(ts: TSModel, K: np.ndarray, P: np.ndarray, scale_x: np.ndarray,
                      scale_u: np.ndarray, decay_rate: float, disk_radius: float | None = None,
                      *, margin: float = 5e-5, grid_points: int = 6,
                      integral_of: str | None = None,
                      uncontrolled: Sequence[str] = ()) -> Certificate:
    """Check a PDC design with numpy: the LMIs at X = P^-1, Y_i = K_i X hold with ``margin``
    (scaled units, normalised by ||X||), and on a premise grid with ``grid_points`` intervals
    per cell edge the closed loop sum_ij h_i h_j (A_i - B_i K_j) has Re lambda <= -alpha and
    Acl' P + P Acl + 2 alpha P <= 0 (all in the scaled coordinates of the design).

    Parameters
    ----------
    ts : TSModel
        The model.
    K : ndarray
        Gains per vertex.
    P : ndarray
        Lyapunov matrix (scaled).
    scale_x, scale_u : ndarray
        Scales of states and inputs.
    decay_rate : float
        Required decay rate [1/s].
    disk_radius : float, optional
        Pole disk radius [1/s].
    margin : float
        LMI margin.
    grid_points : int
        Premise grid intervals per cell edge.
    integral_of : str, optional
        The integrated state.
    uncontrolled : sequence of str
        States left out of the design (:func:`design_ts_controller`): the checks are those of
        the model without them, ``P`` is of that size, and K's columns on them must be zero.

    Returns
    -------
    Certificate
        Whether every check holds, the worst margins and the failures.
    """
    fails: list[str] = []
    a, b, k, p = _scaled_design(ts, K, P, scale_x, scale_u, integral_of, uncontrolled, fails)
    lam_p = np.linalg.eigvalsh(p)
    if lam_p[0] <= 0:
        fails.append(f"P is not positive definite (smallest eigenvalue {lam_p[0]:g})")
    x = np.linalg.inv(p)
    nrm = np.linalg.norm(x, 2)
    alpha = float(decay_rate)
    worst = -np.inf

    def g(i: int, j: int) -> np.ndarray:
        return a[i] @ x - b[i] @ (k[j] @ x)

    pairs = sorted({(i, j) for c in ts.cells() for i in c for j in c if i < j})
    for i in range(len(a)):
        h = g(i, i)
        e = np.linalg.eigvalsh(h + h.T + 2 * alpha * x).max()
        worst = max(worst, e)
        if e > -margin:
            fails.append(f"decay LMI of vertex {i} has eigenvalue {e:.3g} > -{margin:g}")
        if disk_radius is not None:
            m = np.block([[-disk_radius * x, h], [h.T, -disk_radius * x]])
            e = np.linalg.eigvalsh(m).max()
            worst = max(worst, e)
            if e > -margin:
                fails.append(f"disk LMI of vertex {i} has eigenvalue {e:.3g} > -{margin:g}")
    for i, j in pairs:
        s = g(i, j) + g(j, i)
        e = np.linalg.eigvalsh(s + s.T + 4 * alpha * x).max()
        if e > 1e-8 * nrm:
            fails.append(f"decay LMI of the pair ({i}, {j}) has eigenvalue {e:.3g} > 0")
    pts = _premise_grid(ts, grid_points)
    worst_decay, worst_lyap = _check_grid(ts, pts, a, b, k, p, alpha, fails)
    return Certificate(ok=not fails, worst_lmi=float(worst), worst_decay=float(worst_decay),
                       worst_lyapunov=float(worst_lyap), n_grid=len(pts), failures=fails)


def _scaled_design(ts: TSModel, K: np.ndarray, P: np.ndarray, scale_x: np.ndarray,
                   scale_u: np.ndarray, integral_of: str | None, uncontrolled: Sequence[str],
                   fails: list[str]) -> tuple[np.ndarray, ...]:
    """A_i, B_i, K_i and P of a design in its scaled coordinates, without the uncontrolled
    states (a gain on them is added to ``fails``)."""
    uncontrolled = _check_uncontrolled(ts, uncontrolled, integral_of)
    sx, su = np.asarray(scale_x, float), np.asarray(scale_u, float)
    a, b = _controller_mats(ts, integral_of, sx, su)
    k = np.array([np.diag(1 / su) @ ki @ np.diag(sx) for ki in np.asarray(K, float)])
    keep = _kept(ts, uncontrolled, sx.size)
    dropped = np.setdiff1d(np.arange(sx.size), keep)
    if dropped.size and np.any(k[:, :, dropped] != 0.0):
        fails.append(f"K acts on the uncontrolled states {list(uncontrolled)}")
    p = 0.5 * (np.asarray(P, float) + np.asarray(P, float).T)
    if p.shape != (keep.size, keep.size):
        raise ValueError(f"P has shape {p.shape}; the design without {list(uncontrolled)} "
                         f"has {keep.size} states")
    return a[:, keep][:, :, keep], b[:, keep], k[:, :, keep], p


def _check_grid(ts: TSModel, pts: list[tuple[float, float]], a: np.ndarray, b: np.ndarray,
                k: np.ndarray, p: np.ndarray, alpha: float, fails: list[str]
                ) -> tuple[float, float]:
    """Closed loop sum_ij h_i h_j (A_i - B_i K_j) on the premise grid: Re lambda <= -alpha and
    a decreasing Lyapunov function; failures appended to ``fails``; the worst of each."""
    worst_decay, worst_lyap = -np.inf, -np.inf
    for v, dp in pts:
        h = ts.membership(v, dp)
        act = np.nonzero(h)[0]
        acl = sum(h[i] * h[j] * (a[i] - b[i] @ k[j]) for i in act for j in act)
        ev = np.linalg.eigvals(acl)
        d = ev.real.max() + alpha
        ly = np.linalg.eigvalsh(acl.T @ p + p @ acl + 2 * alpha * p).max() / np.linalg.norm(p, 2)
        worst_decay, worst_lyap = max(worst_decay, d), max(worst_lyap, ly)
        if d > 1e-9 * max(1.0, alpha):
            fails.append(f"closed loop at v = {v:g} m/s, dP = {dp:g} has Re lambda = "
                         f"{ev.real.max():.4g} > -alpha = {-alpha:g}")
        if ly > 1e-9:
            fails.append(f"Lyapunov decrease fails at v = {v:g} m/s, dP = {dp:g} ({ly:.3g})")
    return worst_decay, worst_lyap


def _augmented(ts: TSModel, tau_v: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A~_i, B~_i (eq 9 appended) and C~_i of xi = [x; v] (stacked over the vertices)."""
    nv, nx = ts.A.shape[:2]
    aa = np.zeros((nv, nx + 1, nx + 1))
    aa[:, :nx, :nx] = ts.A
    aa[:, :nx, nx] = ts.B_d
    aa[:, nx, nx] = -1.0 / tau_v
    bb = np.concatenate([ts.B, np.zeros((nv, 1, ts.B.shape[2]))], axis=1)
    cc = np.concatenate([ts.C, ts.E[:, :, None]], axis=2)
    return aa, bb, cc


def _observer_mats(ts: TSModel, tau_v: float, sxi: np.ndarray, sy: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Scaled A~_i and C~_i of the observer design (states and wind by ``sxi``, outputs by
    ``sy``)."""
    aa, _, cc = _augmented(ts, tau_v)
    return (np.array([np.diag(1 / sxi) @ ai @ np.diag(sxi) for ai in aa]),
            np.array([np.diag(1 / sy) @ ci @ np.diag(sxi) for ci in cc]))



def design_ts_observer(ts: TSModel, *, tau_v: float = 4.0, decay_rate: float = 1.0,
                       disk_radius: float | None = 60.0,
                       scales: Mapping[str, float] | None = None, margin: float = 1e-4,
                       solver: str | None = None, grid_points: int = 6) -> TSObserverDesign:
    """TS state and wind observer gains L_i (Clemens et al. eqs 8-10) by LMIs; certified.

    Parameters
    ----------
    tau_v : float
        Time constant of the inflow model of eq 9 [s] (Clemens: 4 s).
    decay_rate : float
        alpha_o [1/s] of the estimation error.
    disk_radius : float or None
        Error eigenvalues within abs(lambda) < r_o [1/s].


    Returns
    -------
    TSObserverDesign
        Gains L_i, P, the augmented model, the solver and the certificate.

    Raises
    ------
    SynthesisError
        The pair (A~_i, C~) not detectable at a vertex, or the LMIs infeasible (the message says
        what to relax).
    """
    check_number("tau_v", tau_v, lo=0.0, lo_open=True, unit="s")
    alpha = _check_rate("decay_rate", decay_rate)
    radius = _check_rate("disk_radius", disk_radius, allow_none=True)
    if radius is not None and radius <= alpha:
        raise ValueError(f"disk_radius ({radius:g} 1/s) must exceed decay_rate ({alpha:g} 1/s)")
    aa, bb, cc = _augmented(ts, float(tau_v))
    sxi = _scales(ts, ts.states + ("wind",), scales)
    sy = _scales(ts, ts.measured, scales)
    a, c = _observer_mats(ts, float(tau_v), sxi, sy)
    _check_detectable(ts, a, c, alpha)
    prob, pv, nvar = _observer_problem(a, c, alpha, radius, margin,
                                       [] if ts.common_output else
                                       [(i, j) for i, j in ts.active_pairs() if i < j])
    t0 = time.perf_counter()
    used, status = _solve(prob, solver)
    dt = time.perf_counter() - t0
    if status not in ("optimal", "optimal_inaccurate"):
        hint = ("relax (increase) disk_radius or lower decay_rate" if radius is not None
                else "lower decay_rate")
        raise SynthesisError(f"the observer LMIs are infeasible at decay_rate = {alpha:g} 1/s"
                             f"{'' if radius is None else f', disk_radius = {radius:g} 1/s'}: "
                             f"{hint}")
    p = 0.5 * (pv.value + pv.value.T)
    ls = np.array([np.linalg.solve(p, ni.value) for ni in nvar])
    lmat = np.array([np.diag(sxi) @ li @ np.diag(1 / sy) for li in ls])
    cert = verify_observer(ts, lmat, p, sxi, sy, alpha, radius, tau_v=float(tau_v),
                           margin=0.5 * margin)
    if not cert.ok:
        raise SynthesisError(f"the observer certificate fails: {'; '.join(cert.failures[:3])}")
    return TSObserverDesign(L=lmat, P=p, A_aug=aa, B_aug=bb, C_aug=cc, scale_xi=sxi,
                            scale_y=sy, tau_v=float(tau_v), decay_rate=alpha,
                            disk_radius=radius, solver=used, solve_time_s=dt,
                            certificate=cert, margin=margin)


def _check_detectable(ts: TSModel, a: np.ndarray, c: np.ndarray, alpha: float) -> None:
    """Modes slower than the required decay must be observable (PBH on A~ + alpha I)."""
    from mpc_wt.controllers.lqr import uncontrollable_modes

    for i, ai in enumerate(a):
        modes = uncontrollable_modes(ai.T + alpha * np.eye(ai.shape[0]), c[i].T, discrete=False)
        if modes:
            raise SynthesisError(
                f"(A~, C~) is not detectable with decay rate {alpha:g} 1/s at vertex {i} "
                f"(v = {ts.vertices[i, 0]:g} m/s, dP = {ts.vertices[i, 1]:g}) from "
                f"{list(ts.measured)}: the modes "
                f"{', '.join(f'{m.real - alpha:.4g}{m.imag:+.4g}j' for m in modes)} are not "
                f"seen; measure more signals or lower decay_rate")


def _observer_problem(a: np.ndarray, c: np.ndarray, alpha: float, radius: float | None,
                      margin: float, pairs: Sequence[tuple[int, int]] = ()
                      ) -> tuple[Any, Any, list[Any]]:
    """The observer LMIs (Clemens eq 10) with the decay rate and the optional pole disk; the
    objective bounds the gains' norm. With measurements that differ between vertices (C~_i),
    the error e' = sum_i sum_j h_i h_j (A~_i - L_i C~_j) e also needs, for every ``pairs``
    (i, j) active together, M_ij + M_ji < -4 alpha P (Tanaka and Wang 2001, thm 2.2)."""
    import cvxpy as cp

    nv, n = a.shape[:2]
    ny = c.shape[1]
    pv = cp.Variable((n, n), symmetric=True)
    nvar = [cp.Variable((n, ny)) for _ in range(nv)]
    t = cp.Variable()
    cons = [pv >> np.eye(n)]

    def lyap(i: int, j: int) -> Any:
        return a[i].T @ pv + pv @ a[i] - c[j].T @ nvar[i].T - nvar[i] @ c[j]

    for i in range(nv):
        m = lyap(i, i) + 2 * alpha * pv
        cons.append(_sym(m) << -margin * np.eye(n))
        if radius is not None:
            g = pv @ a[i] - nvar[i] @ c[i]
            cons.append(_sym(cp.bmat([[-radius * pv, g], [g.T, -radius * pv]]))
                        << -margin * np.eye(2 * n))
        cons.append(_sym(cp.bmat([[t * np.eye(n), nvar[i]], [nvar[i].T, t * np.eye(ny)]])) >> 0)
    for i, j in pairs:
        m = 0.5 * (lyap(i, j) + lyap(j, i)) + 2 * alpha * pv
        cons.append(_sym(m) << -margin * np.eye(n))
    return cp.Problem(cp.Minimize(t), cons), pv, nvar


def verify_observer(ts: TSModel, L: np.ndarray, P: np.ndarray, scale_xi: np.ndarray,
                    scale_y: np.ndarray, decay_rate: float, disk_radius: float | None = None,
                    *, tau_v: float = 4.0, margin: float = 5e-5,
                    grid_points: int = 6) -> Certificate:
    """Check TS observer gains with numpy: vertex LMIs at P with ``margin`` and, on a premise
    grid, sum_i h_i (A~_i - L_i C~) Hurwitz with the decay rate and decreasing e' P e.

    Parameters
    ----------
    ts : TSModel
        The model.
    L : ndarray
        Gains per vertex.
    P : ndarray
        Lyapunov matrix (scaled).
    scale_xi, scale_y : ndarray
        Scales of the augmented state and outputs.
    decay_rate : float
        Required decay rate [1/s].
    disk_radius : float, optional
        Pole disk radius [1/s].
    tau_v : float
        Wind time constant [s].
    margin : float
        LMI margin.
    grid_points : int
        Premise grid intervals per cell edge.

    Returns
    -------
    Certificate
        Whether every check holds, the worst margins and the failures.
    """
    sxi, sy = np.asarray(scale_xi, float), np.asarray(scale_y, float)
    a, c = _observer_mats(ts, tau_v, sxi, sy)
    ls = np.array([np.diag(1 / sxi) @ li @ np.diag(sy) for li in np.asarray(L, float)])
    p = 0.5 * (np.asarray(P, float) + np.asarray(P, float).T)
    fails: list[str] = []
    if np.linalg.eigvalsh(p)[0] <= 0:
        fails.append("P is not positive definite")
    alpha = float(decay_rate)
    nrm = np.linalg.norm(p, 2)
    worst = -np.inf
    for i in range(len(a)):
        f = a[i] - ls[i] @ c[i]
        e = np.linalg.eigvalsh(f.T @ p + p @ f + 2 * alpha * p).max()
        worst = max(worst, e)
        if e > -margin:
            fails.append(f"observer decay LMI of vertex {i} has eigenvalue {e:.3g} > -{margin:g}")
        if disk_radius is not None:
            g = p @ f
            e = np.linalg.eigvalsh(np.block([[-disk_radius * p, g], [g.T, -disk_radius * p]])
                                   ).max()
            worst = max(worst, e)
            if e > -margin:
                fails.append(f"observer disk LMI of vertex {i} has eigenvalue {e:.3g}")
    wd, wl = -np.inf, -np.inf
    pts = _premise_grid(ts, grid_points)
    for v, dp in pts:
        h = ts.membership(v, dp)
        f = np.tensordot(h, a, axes=1) - np.tensordot(h, ls, axes=1) @ np.tensordot(h, c, axes=1)
        d = np.linalg.eigvals(f).real.max() + alpha
        ly = np.linalg.eigvalsh(f.T @ p + p @ f + 2 * alpha * p).max() / nrm
        wd, wl = max(wd, d), max(wl, ly)
        if d > 1e-9 * max(1.0, alpha) or ly > 1e-9:
            fails.append(f"observer error at v = {v:g} m/s, dP = {dp:g}: decay margin {d:.3g}, "
                         f"Lyapunov {ly:.3g}")
    return Certificate(ok=not fails, worst_lmi=float(worst), worst_decay=float(wd),
                       worst_lyapunov=float(wl), n_grid=len(pts), failures=fails)

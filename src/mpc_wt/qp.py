"""QP backends of the MPC: one adapter per solver with one interface (cvxpy's
``qp_solvers/*_qpif.py`` are the model).

Each adapter declares the module it needs and a status map from the solver's codes to ours,
and offers ``setup`` (once per operating point), ``update_bounds`` and ``solve`` (each step).
The problem is ``min 0.5 v' H v + q' v  s.t.  lo <= A v <= hi`` where the first ``n_box`` rows
of ``A`` are the identity (simple bounds on v); ``q`` is fixed at setup (the MPC shifts its
variables so that a step changes the bounds only).
"""
from __future__ import annotations

import importlib
import logging
from typing import Any, ClassVar

import numpy as np
import scipy.sparse as sp

from .errors import QPSetupError

__all__ = ["QPBackend", "OSQPBackend", "DAQPBackend", "BACKENDS", "SOLVED", "default_backend",
           "make_backend", "backend_installed"]

#: Our status of a usable solution; any other status means the step needs a fallback.
SOLVED = ("solved", "solved inaccurate")
log = logging.getLogger(__name__)


class QPBackend:
    """The interface of a QP adapter.

    Parameters
    ----------
    options : dict, optional
        Solver settings, passed to the solver as they are.
    """

    name: ClassVar[str] = ""
    module: ClassVar[str] = ""
    extra: ClassVar[str] = ""
    dense_only: ClassVar[bool] = False
    STATUS_MAP: ClassVar[dict[Any, str]] = {}

    def __init__(self, options: dict[str, Any] | None = None) -> None:
        self.options = dict(options or {})
        self.info: Any = None

    @classmethod
    def import_solver(cls) -> Any:
        """The solver's module.

        Returns
        -------
        module
            The imported solver package.

        Raises
        ------
        QPSetupError
            If it is not installed (naming the extra that installs it).
        """
        try:
            return importlib.import_module(cls.module)
        except ImportError as err:
            raise QPSetupError(f"backend={cls.name!r} needs {cls.module}: pip install "
                               f"'mpc-wt[{cls.extra or cls.module}]'") from err

    def setup(self, h: np.ndarray, q: np.ndarray, a: np.ndarray, n_box: int) -> None:
        """Set the problem up once (bounds free until :meth:`update_bounds`).

        Parameters
        ----------
        h : (n_v, n_v) ndarray or sparse
            Hessian, symmetric positive (semi)definite.
        q : (n_v,) ndarray
            Linear term.
        a : (n_c, n_v) ndarray or sparse
            Constraint rows; the first ``n_box`` are the identity.
        n_box : int
            Number of simple-bound rows.
        """
        raise NotImplementedError

    def update_bounds(self, lo: np.ndarray, hi: np.ndarray) -> None:
        """New bounds of all rows, (n_c,) each.

        Parameters
        ----------
        lo, hi : (n_c,) ndarray
            Lower and upper bounds of every row.
        """
        raise NotImplementedError

    def solve(self) -> tuple[np.ndarray | None, str]:
        """Solve with the current bounds.

        Returns
        -------
        x : (n_v,) ndarray or None
            The solution, None when the status is not one of :data:`SOLVED`.
        status : str
            Our status (the solver's code mapped by ``STATUS_MAP``).
        """
        raise NotImplementedError

    @property
    def iterations(self) -> int:
        """Iterations of the last solve."""
        raise NotImplementedError


class OSQPBackend(QPBackend):
    """OSQP (operator splitting; dense or sparse problems).

    OSQP's compiled solver object is used directly when it offers the calls we need (osqp >=
    1.0): its Python wrapper costs some 30 us per step (result namespaces, bound clipping),
    and our bounds are finite (|b| <= 1e20 < OSQP_INFTY). ``fast = False`` uses the public
    interface. The warm start is rounded to 2^-52 absolute: the shifted iterates sit at zero
    when no constraint binds, and without rounding they decay into subnormal numbers that make
    every iteration some 50 times slower.

    When OSQP stops without an answer to its tolerance (iteration limit, "solved inaccurate",
    or an infeasibility it cannot certify), the same QP is solved again by Clarabel (interior
    point, exact to its tolerances; a dependency of cvxpy) and its answer is returned, with a
    logged warning: ADMM converges slowly on the ill-conditioned QPs of far-off states, and
    there a feasible QP otherwise counts as failed and an infeasible one is not reported as
    such.

    Parameters
    ----------
    options : dict, optional
        OSQP settings (``eps_abs``, ``max_iter``, ...).
    """

    name, module, extra = "osqp", "osqp", "osqp"
    STATUS_MAP = {1: "solved", 2: "solved inaccurate", 3: "primal infeasible",
                  4: "primal infeasible inaccurate", 5: "dual infeasible",
                  6: "dual infeasible inaccurate", 7: "maximum iterations reached",
                  8: "run time limit reached", -3: "non-convex", -4: "interrupted",
                  -5: "unsolved"}

    def setup(self, h: Any, q: np.ndarray, a: Any, n_box: int) -> None:
        osqp = self.import_solver()
        n_c = a.shape[0]
        self.problem = [sp.csc_matrix(h), np.asarray(q, float), sp.csc_matrix(a), None, None]
        self.solver = osqp.OSQP()
        self.solver.setup(P=sp.triu(sp.csc_matrix(h)).tocsc(), q=np.asarray(q, float),
                          A=sp.csc_matrix(a), l=np.full(n_c, -np.inf), u=np.full(n_c, np.inf),
                          **self.options)
        ext = getattr(self.solver, "_solver", None)
        self.ext = ext if all(hasattr(ext, n) for n in ("update_data_vec", "warm_start",
                                                          "solve", "info", "solution")) else None
        self.warm: tuple[np.ndarray, np.ndarray] | None = None

    @property
    def fast(self) -> bool:
        """Whether the compiled object is called directly."""
        return self.ext is not None

    @fast.setter
    def fast(self, on: bool) -> None:
        if not on:
            self.ext = None

    def update_bounds(self, lo: np.ndarray, hi: np.ndarray) -> None:
        self.problem[3:] = [np.asarray(lo, float), np.asarray(hi, float)]
        if self.ext is not None:
            self.ext.update_data_vec(q=None, l=lo, u=hi)
        else:
            self.solver.update(l=lo, u=hi)

    def solve(self) -> tuple[np.ndarray | None, str]:
        x, status = self._solve_osqp()
        if status in _UNANSWERED and self.problem[3] is not None:
            x2, status2 = _clarabel_solve(*self.problem,
                                          eps=float(self.options.get("eps_abs", 1e-3)))
            if status2 != "unavailable":
                log.warning("OSQP: %s; the same QP re-solved by Clarabel: %s", status, status2)
                return x2, status2
        return x, status

    def _solve_osqp(self) -> tuple[np.ndarray | None, str]:
        ext = self.ext
        if ext is None:
            res = self.solver.solve(raise_error=False)
            self.info = res.info
            if res.x is None or res.info.status not in SOLVED:
                return None, res.info.status
            return res.x, res.info.status
        if self.warm is not None:
            ext.warm_start(*self.warm)
        ext.solve()
        info = self.info = ext.info
        status = self.STATUS_MAP.get(info.status_val, str(info.status))
        if status not in SOLVED:
            self.warm = None
            return None, status
        xs, ys = ext.solution.x, ext.solution.y
        self.warm = ((xs + 1.0) - 1.0, (ys + 1.0) - 1.0)
        return xs, status

    def reset(self) -> None:
        """Drop the warm start."""
        self.warm = None

    @property
    def iterations(self) -> int:
        return int(self.info.iter)


_UNANSWERED = ("solved inaccurate", "maximum iterations reached", "primal infeasible inaccurate",
               "dual infeasible inaccurate", "run time limit reached")


def _clarabel_solve(h: Any, q: np.ndarray, a: Any, lo: np.ndarray, hi: np.ndarray, *,
                    eps: float) -> tuple[np.ndarray | None, str]:
    """min 1/2 x'Hx + q'x s.t. lo <= Ax <= hi by Clarabel: rows with lo == hi as equalities,
    the others as A x <= hi and -A x <= -lo (infinite bounds dropped). Status in OSQP's words
    ("solved", "primal infeasible", ...), or "unavailable" without the package. Clarabel's
    "almost solved" counts as "solved" when the primal and dual residuals are within ``eps``,
    OSQP's own absolute criterion."""
    try:
        import clarabel
    except ImportError:
        return None, "unavailable"
    eq = lo == hi
    up = ~eq & np.isfinite(hi) & (hi < 1e19)
    dn = ~eq & np.isfinite(lo) & (lo > -1e19)
    a = sp.csr_matrix(a)
    big = sp.vstack([a[eq], a[up], -a[dn]]).tocsc()
    b = np.concatenate([hi[eq], hi[up], -lo[dn]])
    cones = ([clarabel.ZeroConeT(int(eq.sum()))] if eq.any() else []) + \
        [clarabel.NonnegativeConeT(int(up.sum() + dn.sum()))]
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    sol = clarabel.DefaultSolver(sp.triu(sp.csc_matrix(h)).tocsc(), q, big, b, cones,
                                 settings).solve()
    name = str(sol.status)
    if name in ("Solved", "AlmostSolved"):
        x, z = np.asarray(sol.x), np.asarray(sol.z)
        primal = max(float(np.max(np.maximum(big @ x - b, 0.0), initial=0.0)),
                     float(np.max(np.abs((big @ x - b)[:int(eq.sum())]), initial=0.0)))
        dual = float(np.max(np.abs(sp.csc_matrix(h) @ x + q + big.T @ z)))
        exact = name == "Solved" or max(primal, dual) <= eps
        return x, "solved" if exact else "solved inaccurate"
    if "PrimalInfeasible" in name:
        return None, "primal infeasible"
    if "DualInfeasible" in name:
        return None, "dual infeasible"
    return None, f"clarabel: {name}"


class DAQPBackend(QPBackend):
    """DAQP (dual active set; dense problems, exact to its tolerances on these small QPs).

    Parameters
    ----------
    options : dict, optional
        Unused (DAQP's defaults are kept).
    """

    name, module, extra, dense_only = "daqp", "daqp", "daqp", True
    STATUS_MAP = {1: "solved", 2: "solved", -1: "primal infeasible", -2: "cycling detected",
                  -3: "unbounded", -4: "maximum iterations reached", -5: "nonconvex",
                  -6: "initial working set overdetermined"}

    def setup(self, h: Any, q: np.ndarray, a: Any, n_box: int) -> None:
        daqp = self.import_solver()
        a = np.asarray(a.toarray() if sp.issparse(a) else a, float)
        free = np.full(a.shape[0], 1e30)               # the bounds are set every step
        self.model = daqp.Model()
        self.model.setup(np.ascontiguousarray(h), np.asarray(q, float),
                         np.ascontiguousarray(a[n_box:]), free, -free)

    def update_bounds(self, lo: np.ndarray, hi: np.ndarray) -> None:
        self.model.update(bupper=hi, blower=lo)

    def solve(self) -> tuple[np.ndarray | None, str]:
        xs, _, flag, self.info = self.model.solve()
        if flag != 1:
            return None, f"daqp exitflag {flag} ({self.STATUS_MAP.get(flag, 'unknown')})"
        return xs, "solved"

    def reset(self) -> None:
        """Nothing to forget: DAQP keeps its working set."""

    @property
    def iterations(self) -> int:
        return int(self.info["iterations"])


#: Backend name -> adapter class.
BACKENDS: dict[str, type[QPBackend]] = {"osqp": OSQPBackend, "daqp": DAQPBackend}


def backend_installed(name: str) -> bool:
    """Whether the solver of backend ``name`` imports.

    Parameters
    ----------
    name : str
        A key of :data:`BACKENDS`.

    Returns
    -------
    bool
        True when its module imports.
    """
    try:
        importlib.import_module(BACKENDS[name].module)
    except ImportError:
        return False
    return True


def default_backend(formulation: str = "condensed") -> str:
    """The backend used when none is named: DAQP for the condensed (dense) QP when installed,
    else OSQP.

    Parameters
    ----------
    formulation : {"condensed", "sparse"}
        The QP's formulation.

    Returns
    -------
    str
        A key of :data:`BACKENDS`.
    """
    if formulation == "condensed" and backend_installed("daqp"):
        return "daqp"
    return "osqp"


def check_backend(name: str, formulation: str) -> None:
    """Raise unless ``name`` is a backend that can take ``formulation``.

    Parameters
    ----------
    name : str
        Backend name.
    formulation : str
        "condensed" or "sparse".

    Raises
    ------
    QPSetupError
        Naming the backends, or the formulation the backend cannot take.
    """
    if name not in BACKENDS:
        allowed = " or ".join(repr(k) for k in BACKENDS)
        raise QPSetupError(f"backend must be {allowed}, got {name!r}")
    if formulation == "sparse" and BACKENDS[name].dense_only:
        raise QPSetupError(f"formulation='sparse' needs backend='osqp' ({name} is dense), got "
                           f"backend={name!r}")


def make_backend(name: str, formulation: str = "condensed",
                 options: dict[str, Any] | None = None) -> QPBackend:
    """A new adapter of backend ``name``.

    Parameters
    ----------
    name : str
        A key of :data:`BACKENDS`.
    formulation : str
        "condensed" or "sparse".
    options : dict, optional
        Solver settings.

    Returns
    -------
    QPBackend
        Not yet set up.

    Raises
    ------
    QPSetupError
        Unknown backend, not installed, or unable to take the formulation.
    """
    check_backend(name, formulation)
    cls = BACKENDS[name]
    cls.import_solver()
    return cls(options)

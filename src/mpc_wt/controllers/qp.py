"""QP backends of the MPC: one adapter per solver with one interface (cvxpy's
``qp_solvers/*_qpif.py`` are the model).

Each adapter declares the module it needs and a status map from the solver's codes to ours,
and offers ``setup`` (once per operating point), ``update_bounds`` and ``solve`` (each step).
The problem is ``min 0.5 v' H v + q' v  s.t.  lo <= A v <= hi`` where the first ``n_box`` rows
of ``A`` are the identity (simple bounds on v); ``q`` is fixed at setup (the MPC shifts its
variables so that a step changes the bounds only).
"""
from __future__ import annotations

import ctypes
import importlib
import importlib.metadata
import logging
import weakref
from typing import Any, ClassVar

import numba as nb
import numpy as np
import scipy.sparse as sp
from llvmlite import ir
from numba.core import types as nbtypes
from numba.extending import intrinsic

from mpc_wt.errors import QPSetupError

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
    and our bounds are finite (abs(b) <= 1e20 < OSQP_INFTY). ``fast = False`` uses the public
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


class _DAQPProblem(ctypes.Structure):
    """DAQP's ``DAQPProblem`` (include/types.h, unchanged since v0.8): the problem's sizes and
    pointers to its data, which stay ours."""

    _fields_ = [("n", ctypes.c_int), ("m", ctypes.c_int), ("ms", ctypes.c_int),
                ("H", ctypes.c_void_p), ("f", ctypes.c_void_p), ("A", ctypes.c_void_p),
                ("bupper", ctypes.c_void_p), ("blower", ctypes.c_void_p),
                ("sense", ctypes.c_void_p), ("break_points", ctypes.c_void_p),
                ("nh", ctypes.c_int), ("problem_type", ctypes.c_int)]


class _DAQPResult(ctypes.Structure):
    """DAQP's ``DAQPResult`` (include/api.h): pointers to our solution and multiplier
    buffers, the solver's flag and counts."""

    _fields_ = [("x", ctypes.c_void_p), ("lam", ctypes.c_void_p), ("fval", ctypes.c_double),
                ("soft_slack", ctypes.c_double), ("exitflag", ctypes.c_int),
                ("iter", ctypes.c_int), ("nodes", ctypes.c_int),
                ("solve_time", ctypes.c_double), ("setup_time", ctypes.c_double)]


#: DAQP releases whose C interface (struct layouts above, ``daqp_update_ldp``) the direct path
#: was checked against; others go through DAQP's Python ``Model``.
_DAQP_C_VERSIONS = ("0.10.", "0.11.")
_DAQP_UPDATE_D = 8                     # DAQP_UPDATE_d: new bounds (include/constants.h)
_DAQP_WORKSPACE_BYTES = 1 << 14        # a DAQPWorkspace is < 1 kB; the rest is margin


def _daqp_library(module: Any) -> Any:
    """DAQP's C functions from its Python extension (the wheel exports them), or None when the
    installed release is not one the direct path knows."""
    try:
        version = importlib.metadata.version("daqp")
    except importlib.metadata.PackageNotFoundError:
        return None
    if not version.startswith(_DAQP_C_VERSIONS):
        return None
    try:
        lib = ctypes.CDLL(module.__file__)
        fns = {n: getattr(lib, n) for n in ("allocate_daqp_settings", "setup_daqp",
                                            "daqp_update_ldp", "daqp_solve",
                                            "free_daqp_workspace", "free_daqp_ldp")}
    except (OSError, AttributeError):
        return None
    vp = ctypes.c_void_p
    for n in ("allocate_daqp_settings", "free_daqp_workspace", "free_daqp_ldp"):
        fns[n].argtypes, fns[n].restype = [vp], None
    fns["setup_daqp"].argtypes, fns["setup_daqp"].restype = [vp, vp, vp], ctypes.c_int
    fns["daqp_update_ldp"].argtypes = [ctypes.c_int, vp, vp]
    fns["daqp_update_ldp"].restype = ctypes.c_int
    fns["daqp_solve"].argtypes, fns["daqp_solve"].restype = [vp, vp], None
    return fns


def _free_workspace(fns: dict[str, Any], work_mem: np.ndarray) -> None:
    # the finalizer holds the workspace's memory itself, so it is still ours when DAQP frees
    # what it allocated inside it
    work = work_mem.ctypes.data
    fns["free_daqp_workspace"](work)
    fns["free_daqp_ldp"](work)


class _DAQPDirect:
    """A DAQP workspace driven through DAQP's C functions (``setup_daqp``, ``daqp_update_ldp``,
    ``daqp_solve``), the bounds read from the caller's arrays in place and the solution written
    into a buffer of ours: a step costs two foreign calls instead of the Python wrapper's
    argument handling, dict and copies (about 9 us of the MPC's step).

    Parameters
    ----------
    fns : dict
        The C functions (:func:`_daqp_library`).
    h : (n, n) ndarray
        Hessian.
    q : (n,) ndarray
        Linear term.
    a : (m - ms, n) ndarray
        General constraint rows.
    m, ms : int
        Number of bounds and of simple bounds.
    """

    #: a solver workspace (addresses, C memory): no design data (its data are the QP's
    #: arrays, which the MPC holds)
    __design__ = False

    def __init__(self, fns: dict[str, Any], h: np.ndarray, q: np.ndarray, a: np.ndarray,
                 m: int, ms: int) -> None:
        n = h.shape[0]
        self._keep = [np.ascontiguousarray(h, float), np.array(q, float).reshape(n),
                      np.ascontiguousarray(a, float), np.zeros(m, dtype=np.intc)]
        self.x, self.lam = np.zeros(n), np.zeros(m)
        self._lo_arr: Any = None
        self._hi_arr: Any = None
        # no linear term: f = NULL, so that DAQP keeps no v and a bounds update is O(m) (with
        # f given, every update forms M v, about 6 us here, for v = 0)
        f = self._keep[1].ctypes.data if np.any(self._keep[1]) else None
        self._prob = _DAQPProblem(n, m, ms, self._keep[0].ctypes.data, f,
                                  self._keep[2].ctypes.data, None, None,
                                  self._keep[3].ctypes.data, None, 0, 0)
        self._res = _DAQPResult(self.x.ctypes.data, self.lam.ctypes.data)
        self._work_mem = np.zeros(_DAQP_WORKSPACE_BYTES, np.uint8)
        self._work = self._work_mem.ctypes.data
        self._prob_p = ctypes.addressof(self._prob)
        self._res_p = ctypes.addressof(self._res)
        free = np.full(m, 1e30)
        self.bind(-free, free)
        fns["allocate_daqp_settings"](self._work)
        flag = fns["setup_daqp"](self._prob_p, self._work, None)
        weakref.finalize(self, _free_workspace, fns, self._work_mem)
        if flag < 0:
            raise QPSetupError(f"daqp setup failed with exitflag {flag}")
        self._update, self._solve = fns["daqp_update_ldp"], fns["daqp_solve"]

    def bind(self, lo: np.ndarray, hi: np.ndarray) -> None:
        """Point the problem's bounds at ``lo`` and ``hi`` (kept alive here; DAQP reads them
        at every :meth:`update_bounds` or :func:`daqp_update_solve`).

        Parameters
        ----------
        lo, hi : (m,) ndarray
            Bounds.

        Raises
        ------
        ValueError
            Naming the shapes, when they are not (m,).
        """
        m = self._prob.m
        lo = np.ascontiguousarray(lo, dtype=float)
        hi = np.ascontiguousarray(hi, dtype=float)
        if lo.shape != (m,) or hi.shape != (m,):
            raise ValueError(f"bounds have shapes {lo.shape}, {hi.shape}; expected ({m},)")
        self._lo_arr, self._hi_arr = lo, hi
        self._prob.blower, self._prob.bupper = lo.ctypes.data, hi.ctypes.data

    def update_bounds(self, lo: np.ndarray, hi: np.ndarray) -> int:
        """Point the problem at ``lo``/``hi`` (kept; a caller that passes the same arrays
        again, rewritten in place, costs no re-binding) and refresh DAQP's internal form.

        Parameters
        ----------
        lo, hi : (m,) ndarray
            Bounds.

        Returns
        -------
        int
            DAQP's update flag (negative on failure).
        """
        if lo is not self._lo_arr or hi is not self._hi_arr:
            self.bind(lo, hi)
        return int(self._update(_DAQP_UPDATE_D, self._work, self._prob_p))

    def handles(self) -> tuple[np.ndarray, np.ndarray]:
        """What compiled code needs to update and solve this workspace itself
        (:func:`daqp_update_solve`).

        Returns
        -------
        addresses : (5,) int64 ndarray
            ``daqp_update_ldp``, ``daqp_solve``, the workspace, the problem, the result.
        result : (k,) int32 ndarray
            The result struct's memory as int32 (``exitflag`` at
            ``_DAQPResult.exitflag.offset // 4``, ``iter`` after it).
        """
        addr = [ctypes.cast(self._update, ctypes.c_void_p).value,
                ctypes.cast(self._solve, ctypes.c_void_p).value, self._work, self._prob_p,
                self._res_p]
        words = ctypes.sizeof(_DAQPResult) // 4
        view = np.ctypeslib.as_array((ctypes.c_int32 * words).from_address(self._res_p))
        return np.array(addr, dtype=np.int64), view

    def solve(self) -> int:
        """Solve; the solution is in :attr:`x` (overwritten by the next solve).

        Returns
        -------
        int
            DAQP's exit flag.
        """
        self._solve(self._res_p, self._work)
        return self._res.exitflag

    @property
    def iterations(self) -> int:
        """Iterations of the last solve (also one run from compiled code)."""
        return int(self._res.iter)


@intrinsic
def _c_int_call(typingctx: Any, fn: Any, a: Any, p: Any, q: Any) -> Any:  # pragma: no cover
    """int fn(int a, void *p, void *q) at the address ``fn`` (numba intrinsic)."""
    sig = nbtypes.int32(nbtypes.int64, nbtypes.int32, nbtypes.int64, nbtypes.int64)

    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        vp = ir.IntType(8).as_pointer()
        fty = ir.FunctionType(ir.IntType(32), [ir.IntType(32), vp, vp])
        f = builder.inttoptr(args[0], fty.as_pointer())
        return builder.call(f, [args[1], builder.inttoptr(args[2], vp),
                                builder.inttoptr(args[3], vp)])
    return sig, codegen


@intrinsic
def _c_void_call(typingctx: Any, fn: Any, p: Any, q: Any) -> Any:  # pragma: no cover
    """void fn(void *p, void *q) at the address ``fn`` (numba intrinsic); returns 0."""
    sig = nbtypes.int32(nbtypes.int64, nbtypes.int64, nbtypes.int64)

    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        vp = ir.IntType(8).as_pointer()
        fty = ir.FunctionType(ir.VoidType(), [vp, vp])
        f = builder.inttoptr(args[0], fty.as_pointer())
        builder.call(f, [builder.inttoptr(args[1], vp), builder.inttoptr(args[2], vp)])
        return ir.Constant(ir.IntType(32), 0)
    return sig, codegen


_RES_FLAG = _DAQPResult.exitflag.offset // 4


@nb.njit(cache=True, nogil=True)
def daqp_update_solve(addr: np.ndarray, res: np.ndarray) -> int:  # pragma: no cover
    """New bounds into a :class:`_DAQPDirect` workspace and solve, from compiled code
    (``addr``, ``res``: :meth:`_DAQPDirect.handles`). Returns DAQP's update flag when it is
    negative (bounds infeasible), else its exit flag (1: solved)."""
    flag = _c_int_call(addr[0], _DAQP_UPDATE_D, addr[2], addr[3])
    if flag < 0:
        return flag
    _c_void_call(addr[1], addr[4], addr[2])
    return res[_RES_FLAG]


class DAQPBackend(QPBackend):
    """DAQP (dual active set; dense problems, exact to its tolerances on these small QPs).

    Through DAQP's C functions on a workspace of ours when the installed release is one whose
    interface we know (0.10, 0.11: :class:`_DAQPDirect`), else through its Python ``Model``;
    the two give the same iterates (tested).

    Parameters
    ----------
    options : dict, optional
        ``{"interface": "python"}`` forces DAQP's Python ``Model``; DAQP's own settings are
        kept at their defaults.
    """

    name, module, extra, dense_only = "daqp", "daqp", "daqp", True
    STATUS_MAP = {1: "solved", 2: "solved", -1: "primal infeasible", -2: "cycling detected",
                  -3: "unbounded", -4: "maximum iterations reached", -5: "nonconvex",
                  -6: "initial working set overdetermined"}

    def setup(self, h: Any, q: np.ndarray, a: Any, n_box: int) -> None:
        daqp = self.import_solver()
        a = np.asarray(a.toarray() if sp.issparse(a) else a, float)
        interface = self.options.get("interface", "c")
        if interface not in ("c", "python"):
            raise QPSetupError(f"daqp option interface must be 'c' or 'python', got "
                               f"{interface!r}")
        fns = _daqp_library(daqp) if interface == "c" else None
        self.direct = None if fns is None else _DAQPDirect(
            fns, np.asarray(h, float), np.asarray(q, float), a[n_box:], a.shape[0], n_box)
        self._iter = self._update_flag = 0
        if self.direct is None:
            free = np.full(a.shape[0], 1e30)           # the bounds are set every step
            self.model = daqp.Model()
            self.model.setup(np.ascontiguousarray(h), np.asarray(q, float),
                             np.ascontiguousarray(a[n_box:]), free, -free)

    def update_bounds(self, lo: np.ndarray, hi: np.ndarray) -> None:
        # DAQP checks the bounds here (lo > hi is infeasible at once); its flag is kept, so
        # that solve() reports it instead of solving the previous problem
        if self.direct is not None:
            self._update_flag = self.direct.update_bounds(lo, hi)
        else:
            self._update_flag = int(self.model.update(bupper=hi, blower=lo))

    def status(self, flag: int) -> str:
        """Our status of a DAQP flag.

        Parameters
        ----------
        flag : int
            DAQP's exit (or bounds-update) flag.

        Returns
        -------
        str
            "solved", or the flag and its meaning.
        """
        if flag == 1:
            return "solved"
        return f"daqp exitflag {flag} ({self.STATUS_MAP.get(flag, 'unknown')})"

    def solve(self) -> tuple[np.ndarray | None, str]:
        """Solve with the current bounds (the direct path returns its solution buffer,
        overwritten by the next solve).

        Returns
        -------
        x : (n_v,) ndarray or None
            The solution, None when DAQP did not solve.
        status : str
            Our status.
        """
        if self._update_flag < 0:
            flag, self._iter, xs = self._update_flag, 0, None
        elif self.direct is not None:
            flag, xs = self.direct.solve(), self.direct.x
        else:
            xs, _, flag, self.info = self.model.solve()
            self._iter = int(self.info["iterations"])
        if flag != 1:
            return None, self.status(flag)
        return xs, "solved"

    def reset(self) -> None:
        """Nothing to forget: DAQP keeps its working set."""

    @property
    def iterations(self) -> int:
        if self.direct is not None and self._update_flag >= 0:
            return self.direct.iterations
        return self._iter


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

"""MPC solver comparison: the QPs of one closed-loop run, solved by several solvers.

A closed loop of ``steps`` steps at 10 Hz of Madsen's individual-pitch MPC (8-state model at
18 m/s, H_p = H_u = 15, 3 pitch + torque, pitch/torque/rate constraints), run by its shipped
law, on our nonlinear plant in IEC class-A turbulence at 18 m/s mean. At every step the QP of
the plant's state deviation and the law's previous command is recorded (the QP a design on
the true states solves along that trajectory), then the same sequence of QPs is solved by

- ``osqp-condensed``, ``osqp-sparse`` and ``daqp-condensed``: the design's QP
  (:meth:`~mpc_wt.controllers.mpc.MPC.solve`), scaled, warm-started, factorization kept
  (timed: the solver call alone, and the whole ``solve`` including the per-step vectors);
- ``cvxpy-params (OSQP)``: cvxpy with parameters for q and the bounds, re-solved each step;
- ``clarabel``: the condensed QP handed to Clarabel each step (interior point, no warm start);
- ``qpoases-casadi``: qpOASES through CasADi's ``conic`` interface;

against a reference solution (Clarabel, tolerances 1e-10). ``max_move_error`` is the largest
error of the applied first move relative to the acceptance tolerance (0.01 deg pitch,
0.1 % of rated torque): <= 1 passes. The shipped law's whole step (the library's call:
estimator, schedule, QP with DAQP, fallback logic) is timed in the closed loop itself.

Used by ``benchmarks/bench_mpc.py`` and ``mpcwt bench mpc [--json]``.
"""
from __future__ import annotations

import contextlib
import io
import platform
import time
from typing import Any, Callable

import numpy as np
import scipy.sparse as sp

import linearize
from mpc_wt.controllers.mpc import MPC, MPCSettings
from mpc_wt.controllers.qp import backend_installed, default_backend
from mpc_wt.simulation.loop import simulate_closed_loop
from mpc_wt.simulation.scenario import Scenario, make_wind


class _Timed:
    """Proxy timing one method of a solver object."""

    def __init__(self, obj: Any, method: str) -> None:
        self._obj, self._method, self.times = obj, method, []

    def __getattr__(self, name: str) -> Any:
        attr = getattr(self._obj, name)
        if name != self._method:
            return attr

        def timed(*a: Any, **k: Any) -> Any:
            t0 = time.perf_counter()
            out = attr(*a, **k)
            self.times.append(time.perf_counter() - t0)
            self.last = out
            return out
        return timed


def _stats(ts: list[float] | np.ndarray) -> dict[str, float]:
    a = np.asarray(ts) * 1e6
    return {"median_us": float(np.median(a)), "p95_us": float(np.percentile(a, 95)),
            "p99_us": float(np.percentile(a, 99)), "max_us": float(a.max())}


def _clarabel(qp: dict[str, np.ndarray], tol: float | None = None) -> tuple[np.ndarray, int]:
    import clarabel

    n = qp["H"].shape[0]
    eye = sp.identity(n, format="csc")
    a = sp.vstack([eye, -eye, sp.csc_matrix(qp["A"]), -sp.csc_matrix(qp["A"])]).tocsc()
    b = np.concatenate([qp["hi_box"], -qp["lo_box"], qp["hi"], -qp["lo"]])
    s = clarabel.DefaultSettings()
    s.verbose = False
    if tol is not None:
        s.tol_gap_abs = s.tol_gap_rel = s.tol_feas = tol
        s.tol_ktratio = 1e-8
    sol = clarabel.DefaultSolver(sp.triu(sp.csc_matrix(qp["H"])).tocsc(), qp["q"], a, b,
                                 [clarabel.NonnegativeConeT(a.shape[0])], s).solve()
    if str(sol.status) not in ("Solved", "AlmostSolved"):
        raise RuntimeError(f"clarabel: {sol.status}")
    return np.asarray(sol.x), int(sol.iterations)


def run_solver_benchmark(law: Callable[..., Any], steps: int = 3000,
                         progress: bool = True) -> dict[str, Any]:
    """Run the comparison on one closed loop at 18 m/s, class A.

    Parameters
    ----------
    law : callable
        ``law(design, kind, turbine)``: the design run by its shipped law
        (:func:`mpc_wt.run.law_controller`).
    steps : int
        Controller steps of the closed loop (10 Hz), >= 10.
    progress : bool
        Show a progress bar.

    Returns
    -------
    dict
        The figures: per solver ``solver``, ``median_us``, ``p95_us``, ``p99_us``, ``max_us``,
        ``max_move_error`` ...; the closed loop's whole-step times and run time.

    Raises
    ------
    ValueError
        If ``steps`` < 10.
    """
    if steps < 10:
        raise ValueError(f"steps must be >= 10, got {steps}")
    t = linearize.load_turbine()
    wind_mps = 18.0
    model = linearize.linearize(t, wind_mps, config=linearize.PlantConfig.madsen())
    res: dict[str, Any] = {"date": time.strftime("%Y-%m-%d"), "machine": platform.machine(),
                           "python": platform.python_version(), "steps": steps,
                           "wind_mps": wind_mps, "turbulence": "A", "horizon": 15,
                           "solvers": []}
    backends = ["osqp"] + ["daqp"] * backend_installed("daqp")
    if "daqp" not in backends:
        res["daqp"] = "not installed (pip install 'daqp>=0.11')"
    res["closed_loop_backend"] = default_backend()
    rec = _record_closed_loop(t, model, steps, res, progress, law)
    ctl = rec["controller"]
    qps = []
    for zz, has_preview in rec["z"]:
        ctl._z[:] = zz
        ctl._has_preview = has_preview
        qps.append(ctl.qp())
    nu = ctl._nu
    su = qps[0]["scale"]
    vref = [_clarabel(qp, 1e-10)[0] for qp in qps]
    ref = np.array([v[:nu] * su[:nu] for v in vref])
    res["constraints_active_fraction"] = _active_fraction(qps, vref)
    err = _MoveAccuracy(ref, t.rated_generator_torque)
    for backend, form in [("osqp", "condensed"), ("osqp", "sparse")] + \
            [("daqp", "condensed")] * ("daqp" in backends):
        res["solvers"].append(_replay(model, t, backend, form, rec, su, err))
    res["solvers"] += [_cvxpy(qps, su, err), _clarabel_all(qps, su, err),
                       _qpoases(qps, su, err)]
    return res


def _record_closed_loop(t: Any, model: Any, steps: int, res: dict[str, Any],
                        progress: bool, law: Callable[..., Any]) -> dict[str, Any]:
    """The closed loop of the design run by its shipped law, timing each call of the library;
    at each step the QP data of the plant's state deviation and the law's previous command
    (recorded from a design on the true states)."""
    dt = 0.1
    host = law(MPC(model, t, MPCSettings(dt=dt)), "mpc", t)
    ctl = MPC(model, t, MPCSettings(estimator="full-state", dt=dt))
    rec: dict[str, Any] = {"z": [], "qp_in": [], "controller": ctl}
    step_times: list[float] = []
    idx = [linearize.STATE_NAMES.index(n) for n in ctl.model.states]
    last = np.zeros(4)
    step0 = host.step

    def timed_step(tt: float, meas: dict[str, Any]) -> Any:
        x = np.asarray(meas["state"])[idx] - ctl.model.x0
        ctl.solve(x, None, last.copy())
        rec["z"].append((ctl._z.copy(), False))
        rec["qp_in"].append((x, last.copy()))
        t0 = time.perf_counter()
        pitch, torque = step0(tt, meas)
        step_times.append(time.perf_counter() - t0)
        last[:3], last[3] = np.asarray(pitch) - ctl.model.u0[:3], torque - ctl.model.u0[3]
        return pitch, torque
    host.step = timed_step  # type: ignore[method-assign]
    duration = steps * dt
    wind, _ = make_wind(t, Scenario(res["wind_mps"], "A", 1, duration, 0.2))
    op = linearize.trim(t, res["wind_mps"])
    t0 = time.perf_counter()
    simulate_closed_loop(linearize.plant_params(t), host, wind, duration, x0=op.x, u0=op.u,
                         controller_dt=dt, progress=progress, compiled=False)
    res["closed_loop_s"] = time.perf_counter() - t0
    res["whole_step_closed_loop"] = _stats(step_times)
    return rec


def _active_fraction(qps: list[dict[str, np.ndarray]], vref: list[np.ndarray]) -> float:
    active = 0
    tol = 1e-6
    for qp, v in zip(qps, vref):
        av = qp["A"] @ v
        if (np.any(v <= qp["lo_box"] + tol) or np.any(v >= qp["hi_box"] - tol)
                or np.any(av <= qp["lo"] + tol) or np.any(av >= qp["hi"] - tol)):
            active += 1
    return active / len(qps)


class _MoveAccuracy:
    """The largest first-move error against the reference solution, in units of the
    tolerances (0.01 deg pitch, 0.1 % of rated torque)."""

    def __init__(self, ref: np.ndarray, rated_torque: float) -> None:
        self.ref, self.rated_torque = ref, rated_torque

    def __call__(self, first: np.ndarray) -> dict[str, float]:
        err = np.abs(np.asarray(first) - self.ref)
        pitch = float(np.degrees(err[:, :3].max()))
        torque = float(100.0 * err[:, 3].max() / self.rated_torque)
        return {"max_move_error_pitch_deg": pitch, "max_move_error_torque_pct": torque,
                "max_move_error": max(pitch / 0.01, torque / 0.1)}


def _replay(model: Any, t: Any, backend: str, form: str, rec: dict[str, Any],
            su: np.ndarray, err: _MoveAccuracy) -> dict[str, Any]:
    """Our backend: the design's whole ``solve`` on the recorded QP data in order (its own
    warm starts), timed, with the solver call alone timed on a twin; the first moves for the
    move error."""
    c = MPC(model, t, MPCSettings(estimator="full-state", backend=backend, formulation=form))
    be = c.qp_backend
    # DAQP through its C interface runs inside the compiled step: its solve alone is timed
    # through DAQP's Python Model on a twin controller (the same iterates, tested)
    twin = c if getattr(be, "direct", None) is None else \
        MPC(model, t, MPCSettings(estimator="full-state", backend=backend, formulation=form,
                                  solver_options={"interface": "python"}))
    attr = "ext" if backend == "osqp" else "model"
    timer = _Timed(getattr(twin.qp_backend, attr), "solve")
    setattr(twin.qp_backend, attr, timer)
    whole, iters = [], []
    for x, up in rec["qp_in"]:
        t0 = time.perf_counter()
        c.solve(x, None, up)
        whole.append(time.perf_counter() - t0)
        iters.append(be.iterations)
        if twin is not c:
            twin.solve(x, None, up)
    solve_times = list(timer.times)
    nu = c._nu
    first = []
    for zz, has_preview in rec["z"]:
        c._z[:] = zz
        v, _ = c._solve_z(has_preview)
        first.append(v[:nu] * su[:nu] if v is not None else np.full(nu, np.nan))
    return {"solver": f"{backend}-{form}", **_stats(solve_times),
            "iter_median": float(np.median(iters)), "iter_max": int(np.max(iters)),
            "whole_step": _stats(whole), **err(np.array(first))}


def _cvxpy(qps: list[dict[str, np.ndarray]], su: np.ndarray, err: _MoveAccuracy
           ) -> dict[str, Any]:
    """cvxpy with parameters (OSQP underneath), re-solved each step."""
    import cvxpy as cp

    nu = len(err.ref[0])
    nv = qps[0]["H"].shape[0]
    lchol = np.linalg.cholesky(qps[0]["H"])
    v = cp.Variable(nv)
    q_p, lo_p, hi_p = cp.Parameter(nv), cp.Parameter(len(qps[0]["lo"])), \
        cp.Parameter(len(qps[0]["lo"]))
    lb_p, ub_p = cp.Parameter(nv), cp.Parameter(nv)
    av = qps[0]["A"] @ v
    prob = cp.Problem(cp.Minimize(0.5 * cp.sum_squares(lchol.T @ v) + q_p @ v),
                      [v >= lb_p, v <= ub_p, av >= lo_p, av <= hi_p])
    ts, first = [], []
    for qp in qps:
        q_p.value, lo_p.value, hi_p.value = qp["q"], qp["lo"], qp["hi"]
        lb_p.value, ub_p.value = qp["lo_box"], qp["hi_box"]
        t0 = time.perf_counter()
        prob.solve(solver=cp.OSQP, warm_start=True, eps_abs=1e-6, eps_rel=1e-6)
        ts.append(time.perf_counter() - t0)
        first.append(v.value[:nu] * su[:nu])
    return {"solver": "cvxpy-params (OSQP)", **_stats(ts), **err(np.array(first))}


def _clarabel_all(qps: list[dict[str, np.ndarray]], su: np.ndarray, err: _MoveAccuracy
                  ) -> dict[str, Any]:
    """Clarabel (interior point, rebuilt each step)."""
    nu = len(err.ref[0])
    ts, first, its = [], [], []
    for qp in qps:
        t0 = time.perf_counter()
        xs, it = _clarabel(qp)
        ts.append(time.perf_counter() - t0)
        first.append(xs[:nu] * su[:nu])
        its.append(it)
    return {"solver": "clarabel", **_stats(ts), "iter_median": float(np.median(its)),
            **err(np.array(first))}


def _qpoases(qps: list[dict[str, np.ndarray]], su: np.ndarray, err: _MoveAccuracy
             ) -> dict[str, Any]:
    """qpOASES through CasADi."""
    import casadi as ca

    nu = len(err.ref[0])
    nv = qps[0]["H"].shape[0]
    with contextlib.redirect_stdout(io.StringIO()):     # qpOASES prints a licence banner
        s = ca.conic("S", "qpoases", {"h": ca.Sparsity.dense(nv, nv),
                                      "a": ca.Sparsity.dense(*qps[0]["A"].shape)},
                     {"printLevel": "none", "error_on_fail": False})
        qp0 = qps[0]
        s(h=qp0["H"], g=qp0["q"], a=qp0["A"], lba=qp0["lo"], uba=qp0["hi"],
          lbx=qp0["lo_box"], ubx=qp0["hi_box"])
    ts, first, its = [], [], []
    for qp in qps:
        t0 = time.perf_counter()
        r = s(h=qp["H"], g=qp["q"], a=qp["A"], lba=qp["lo"], uba=qp["hi"], lbx=qp["lo_box"],
              ubx=qp["hi_box"])
        ts.append(time.perf_counter() - t0)
        first.append(np.asarray(r["x"]).ravel()[:nu] * su[:nu])
        its.append(s.stats()["iter_count"])
    return {"solver": "qpoases-casadi", **_stats(ts), "iter_median": float(np.median(its)),
            **err(np.array(first))}


def format_table(res: dict[str, Any]) -> str:
    """The figures as a text table."""
    w = res["whole_step_closed_loop"]
    lines = [f"closed loop: {res['steps']} steps at {res['wind_mps']:g} m/s, "
             f"{res['closed_loop_s']:.1f} s, constraints active in "
             f"{100 * res['constraints_active_fraction']:.1f} % of the QPs",
             f"whole controller step in the loop ({res['closed_loop_backend']}): median "
             f"{w['median_us']:.1f} us, p99 {w['p99_us']:.1f} us, max {w['max_us']:.1f} us",
             f"{'solver':22s} {'median':>8s} {'p95':>8s} {'p99':>8s} {'max':>8s} {'iter':>5s} "
             f"{'pitch err deg':>13s} {'torque err %':>12s}  whole step median/p99 [us]"]
    for e in res["solvers"]:
        ws = e.get("whole_step")
        extra = f"{ws['median_us']:.1f} / {ws['p99_us']:.1f}" if ws else ""
        it = e.get("iter_median")
        its = f"{it:5.0f}" if it is not None else "    -"
        lines.append(f"{e['solver']:22s} {e['median_us']:8.1f} {e['p95_us']:8.1f} "
                     f"{e['p99_us']:8.1f} {e['max_us']:8.1f} {its} "
                     f"{e['max_move_error_pitch_deg']:13.2e} "
                     f"{e['max_move_error_torque_pct']:12.2e}  {extra}")
    return "\n".join(lines)


def plot_solver_times(res: dict[str, Any], path: str) -> Any:
    """Bar chart (log scale) of the median, p99 and max solve time per solver (PNG)."""
    from mpc_wt.plotting import pyplot, save_figure

    plt = pyplot()
    names = [e["solver"] for e in res["solvers"]]
    x = np.arange(len(names))
    fig, ax = plt.subplots(figsize=(8, 4))
    for k, (key, lab) in enumerate((("median_us", "median"), ("p99_us", "p99"),
                                    ("max_us", "max"))):
        ax.bar(x + (k - 1) * 0.27, [e[key] for e in res["solvers"]], 0.27, label=lab)
    ax.axhline(1e5, color="k", ls="--", lw=0.8, label="10 Hz budget (100 ms)")
    ax.set_yscale("log")
    ax.set_xticks(x, names, rotation=15)
    ax.set_ylabel("solve time per step [us]")
    ax.set_title(f"MPC QP solve time, {res['steps']} closed-loop steps at {res['wind_mps']:g} m/s")
    ax.legend()
    return save_figure(fig, path)

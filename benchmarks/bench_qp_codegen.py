"""The exported MPC's QP solver, two ways: DAQP built from its published source distribution
(what ``export --format discon`` ships) against OSQP's code generation from the installed wheel
(``osqp.OSQP.codegen``, offline), on the QPs the scheduled MPC solves in closed loop.

Run:  python benchmarks/bench_qp_codegen.py [--kind mpc-lidar] [--wind 18] [--seed 31]
                                            [--duration 120] [--repeat 5] [--json]

The kind's shipped law runs once on mpc-wt's plant (class A; the seed is one no design or
tuning saw); at each controller step the QP of the acting grid design at the plant's state
and the law's previous command is recorded (:meth:`mpc_wt.MPC.qp`: Hessian, constraint rows,
the step's linear term and bounds) with the design's own solution. Both solvers are then
compiled in C (``cc -O2``) and replay the same QPs in the order the run solved them, each grid
design on a workspace set up once, warm-started from its last solve:

* DAQP 0.11 from the cached source distribution (:func:`mpc_wt.io.solver_sources.daqp_sources`),
  the linear term shifted into the bounds and only the bounds updated per step, as the shipped
  library does (``mpc.c``);
* OSQP 1.x's embedded code (``parameters="vectors"``: the linear term and the bounds updated per
  step), one generated workspace per grid design, with the design's solver settings
  (eps_abs = eps_rel = 1e-5, no polishing, warm start) and a fixed step size rho per design
  (:func:`best_rho`, chosen on its first QPs of the same run: in OSQP's favour).

Prints, per solver: the solve's median / p99 / largest time [us] over every step and repeat,
the failed solves, and the first move's largest difference from the design's own solution
(pitch [deg], torque [% of rated]). The DISCON call of the shipped library (measured in the
same run: the whole call, and its logged QP time) gives the call with OSQP as the call less
DAQP's solve plus OSQP's (medians).
"""
from __future__ import annotations

import argparse
import json
import platform
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np
import scipy.sparse as sp

import linearize
from mpc_wt.io.discon_export import find_compiler
from mpc_wt.io.solver_sources import daqp_sources
from mpc_wt.simulation.scenario import Scenario

HARNESS = r"""
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
%(includes)s

static double now_us(void) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e6 + ts.tv_nsec * 1e-3;
}

static double *read_doubles(const char *path, long *n) {
    FILE *f = fopen(path, "rb");
    long size;
    double *v;
    if (!f) { fprintf(stderr, "cannot open %%s\n", path); exit(2); }
    fseek(f, 0, SEEK_END);
    size = ftell(f);
    fseek(f, 0, SEEK_SET);
    v = (double *)malloc((size_t)size);
    if (fread(v, 1, (size_t)size, f) != (size_t)size) exit(2);
    fclose(f);
    *n = size / (long)sizeof(double);
    return v;
}

int main(int argc, char **argv) {
    /* argv: design file, steps file (per step: m lo, m hi [, n q]), repeat, out file */
    long nd, ns, k, i;
    double *d = read_doubles(argv[1], &nd);
    double *s = read_doubles(argv[2], &ns);
    int repeat = atoi(argv[4]);
    FILE *out = fopen(argv[3], "wb");
%(body)s
    fclose(out);
    return 0;
}
"""

DAQP_BODY = r"""
    /* design file: n, m, ms, H (n n), A ((m - ms) n) */
    int n = (int)d[0], m = (int)d[1], ms = (int)d[2], r;
    long per = 2 * m, nsteps = ns / per;
    double *H = d + 3, *A = H + (long)n * n;
    double *lo = calloc(m, sizeof(double)), *hi = calloc(m, sizeof(double));
    double *x = calloc(n, sizeof(double)), *lam = calloc(m, sizeof(double));
    int *sense = calloc(m, sizeof(int));
    DAQPProblem prob = {0};
    DAQPWorkspace work = {0};
    DAQPResult res = {0};
    for (i = 0; i < m; i++) { lo[i] = -1e30; hi[i] = 1e30; }
    prob.n = n; prob.m = m; prob.ms = ms; prob.H = H; prob.f = NULL; prob.A = A;
    prob.bupper = hi; prob.blower = lo; prob.sense = sense;
    allocate_daqp_settings(&work);
    if (setup_daqp(&prob, &work, NULL) < 0) { fprintf(stderr, "setup failed\n"); return 3; }
    res.x = x; res.lam = lam;
    for (r = 0; r < repeat; r++) {
        for (k = 0; k < nsteps; k++) {
            double t0, t1, flag;
            for (i = 0; i < m; i++) { lo[i] = s[k * per + i]; hi[i] = s[k * per + m + i]; }
            t0 = now_us();
            daqp_update_ldp(DAQP_UPDATE_d, &work, &prob);
            daqp_solve(&res, &work);
            t1 = now_us();
            flag = (double)res.exitflag;
            fwrite(&flag, sizeof(double), 1, out);
            t1 -= t0;
            fwrite(&t1, sizeof(double), 1, out);
            fwrite(x, sizeof(double), (size_t)n, out);
        }
    }
"""

OSQP_BODY = r"""
    /* design file: n, m (of OSQP's rows, box rows included) */
    int n = (int)d[0], m = (int)d[1], r;
    long per = 2 * m + n, nsteps = ns / per;
    OSQPSolver *solver = &%(prefix)ssolver;
    double *iters = calloc((size_t)nsteps, sizeof(double));
    FILE *fi = fopen("iters.bin", "wb");
    for (r = 0; r < repeat; r++) {
        for (k = 0; k < nsteps; k++) {
            double t0, t1, flag;
            double *q = s + k * per, *l = q + n, *u = l + m;
            t0 = now_us();
            osqp_update_data_vec(solver, q, l, u);
            osqp_solve(solver);
            t1 = now_us();
            flag = (double)solver->info->status_val;
            fwrite(&flag, sizeof(double), 1, out);
            iters[k] = (double)solver->info->iter;
            t1 -= t0;
            fwrite(&t1, sizeof(double), 1, out);
            fwrite(solver->solution->x, sizeof(double), (size_t)n, out);
        }
    }
    fwrite(iters, sizeof(double), (size_t)nsteps, fi);
    fclose(fi);
"""


def record_qps(kind: str, scenario: Scenario) -> tuple[list[dict], dict]:
    """The QPs of the kind's design along the shipped law's run of the scenario: at each
    controller step the QP of the acting grid design (the law's logged grid wind) at the
    plant's state deviation and the law's previous command (the disturbance at the operating
    point), with the design's solution.

    Parameters
    ----------
    kind : str
        An MPC kind.
    scenario : Scenario
        The case.

    Returns
    -------
    list of dict
        Per solve: the design's id, its QP (:meth:`MPC.qp`) and its scaled solution.
    dict
        The shipped library's run of the same case: its logged QP times.
    """
    from mpc_wt.run import build_controller
    from mpc_wt.simulation.loop import simulate_closed_loop

    turbine = linearize.load_turbine()
    built, op, field = build_controller(turbine, kind, scenario)
    design, host = built.design, built.controller
    grid = list(design._grid)
    records: list[dict] = []
    last: dict[int, np.ndarray] = {}
    step0 = host.step

    def step(t, meas):
        k = grid.index(host.signals["schedule_grid_wind"]) if host.signals else 0
        m = design.controller(k)
        idx = [linearize.STATE_NAMES.index(n) for n in m.model.states]
        x = np.asarray(meas["state"])[idx] - m.model.x0
        up = last.get(k, np.zeros(m._nu))
        plan, _ = m.solve(x, None, up)
        if plan is not None:                     # the scaled solution: the solver's vector
            records.append({"design": id(m), "qp": {k2: np.array(v2) for k2, v2 in
                                                    m.qp().items()},
                            "v": np.array(m._vbuf)})
        pitch, torque = step0(t, meas)
        u = np.r_[pitch, torque] - m.model.u0
        last[k] = np.array([u[0], u[3]]) if m.collective else u
        return pitch, torque
    host.step = step
    res = simulate_closed_loop(linearize.plant_params(turbine), host, field, scenario.duration,
                               x0=op.x, u0=op.u, controller_dt=built.controller_dt,
                               compiled=False)
    qp_ms = np.asarray(res.channel("qp_solve_ms"), float)
    return records, {"qp_solve_us": qp_ms[np.isfinite(qp_ms) & (qp_ms > 0)] * 1e3,
                     "rated_torque": turbine.rated_generator_torque}


def _write(path: Path, *arrays: np.ndarray) -> None:
    np.concatenate([np.ravel(np.asarray(a, float)) for a in arrays]).tofile(path)


def _compile(cc: str, sources: list[Path], includes: list[Path], exe: Path) -> None:
    cmd = [cc, "-O2", "-std=c99", *[f"-I{p}" for p in includes], *map(str, sources), "-lm",
           "-o", str(exe)]
    subprocess.run(cmd, check=True, capture_output=True, text=True)


def _read_out(path: Path, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    raw = np.fromfile(path, dtype=float).reshape(-1, 2 + n)
    return raw[:, 0], raw[:, 1], raw[:, 2:]


def daqp_replay(cc: str, work: Path, qp: dict, steps: list[dict], repeat: int
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """DAQP (its published C sources) on one design's QPs; flags, times [us], solutions."""
    src = work / "daqp"
    daqp_sources().write(src)
    h, a = qp["H"], qp["A"]
    n, mg, ms = h.shape[0], a.shape[0], len(qp["lo_box"])
    m = ms + mg
    hinv = np.linalg.inv(h)
    rows = []
    for st in steps:
        c = -hinv @ st["q"]                               # v = w + c: the linear term gone
        lo = np.r_[st["lo_box"] - c[:ms], st["lo"] - a @ c]
        hi = np.r_[st["hi_box"] - c[:ms], st["hi"] - a @ c]
        rows.append((lo, hi, c))
    _write(work / "daqp_design.bin", [n, m, ms], h, a)
    _write(work / "daqp_steps.bin", *[np.r_[lo, hi] for lo, hi, _ in rows])
    (work / "daqp_main.c").write_text(HARNESS % {"includes": '#include "api.h"',
                                                 "body": DAQP_BODY})
    exe = work / "daqp_replay"
    _compile(cc, [work / "daqp_main.c", *sorted((src).glob("*.c"))], [src], exe)
    subprocess.run([str(exe), str(work / "daqp_design.bin"), str(work / "daqp_steps.bin"),
                    str(work / "daqp_out.bin"), str(repeat)], check=True)
    flag, us, x = _read_out(work / "daqp_out.bin", n)
    shift = np.tile(np.array([c for _, _, c in rows]), (repeat, 1))
    return flag, us, x + shift


#: Embedded OSQP keeps its step size rho (no refactorisation at run time): each design's is
#: the one of RHO_GRID with the fewest iterations (median) over its first RHO_TUNING_QPS QPs
#: (OSQP's adaptive rho estimate of the first QP was tried: 1700-2950 iterations on a third of
#: the designs against 210-380 on the others).
RHO_GRID = np.logspace(-4, -1, 13)
RHO_TUNING_QPS = 20


def best_rho(data: dict, settings: dict, steps: list[dict]) -> float:
    """The rho of :data:`RHO_GRID` with the fewest median iterations on ``steps`` (fixed rho).

    Parameters
    ----------
    data : dict
        OSQP's problem data (P, q, A, l, u).
    settings : dict
        Its settings.
    steps : list of dict
        QPs of the design (:meth:`mpc_wt.MPC.qp`).

    Returns
    -------
    float
        rho.
    """
    import osqp

    cost = []
    for rho in RHO_GRID:
        prob = osqp.OSQP()
        prob.setup(**data, **settings, rho=float(rho), adaptive_rho=False)
        its = []
        for st in steps:
            prob.update(q=st["q"], l=np.r_[st["lo_box"], st["lo"]],
                        u=np.r_[st["hi_box"], st["hi"]])
            its.append(prob.solve().info.iter)
        cost.append(np.median(its))
    return float(RHO_GRID[int(np.argmin(cost))])


def osqp_replay(cc: str, work: Path, qp: dict, steps: list[dict], repeat: int
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """OSQP's generated code on one design's QPs; status, times [us], solutions."""
    import osqp

    h, a = qp["H"], qp["A"]
    n = h.shape[0]
    big = np.vstack([np.eye(n)[:len(qp["lo_box"])], a])
    m = big.shape[0]
    s0 = steps[0]
    data = dict(P=sp.triu(sp.csc_matrix(h), format="csc"), q=s0["q"], A=sp.csc_matrix(big),
                l=np.r_[s0["lo_box"], s0["lo"]], u=np.r_[s0["hi_box"], s0["hi"]])
    settings = dict(verbose=False, eps_abs=1e-5, eps_rel=1e-5, polishing=False,
                    warm_starting=True, check_termination=2)
    rho = best_rho(data, settings, steps[:RHO_TUNING_QPS])
    prob = osqp.OSQP()
    prob.setup(**data, **settings, rho=rho, adaptive_rho=False)
    gen = work / "osqp"
    prob.codegen(str(gen), parameters="vectors", extension_name=None, prefix="mw_",
                 force_rewrite=True)
    _write(work / "osqp_design.bin", [n, m])
    lim = 1e30
    _write(work / "osqp_steps.bin", *[np.r_[st["q"], np.clip(np.r_[st["lo_box"], st["lo"]],
                                                               -lim, lim),
                                             np.clip(np.r_[st["hi_box"], st["hi"]], -lim,
                                                     lim)] for st in steps])
    (work / "osqp_main.c").write_text(HARNESS % {
        "includes": '#include "osqp.h"\n#include "mw_workspace.h"',
        "body": OSQP_BODY % {"prefix": "mw_"}})
    exe = work / "osqp_replay"
    _compile(cc, [work / "osqp_main.c", gen / "mw_workspace.c", *sorted((gen / "src").glob("*.c"))],
             [gen, gen / "inc" / "public", gen / "inc" / "private"], exe)
    subprocess.run([str(exe), str(work / "osqp_design.bin"), str(work / "osqp_steps.bin"),
                    str(work / "osqp_out.bin"), str(repeat)], check=True, cwd=work)
    iters = np.fromfile(work / "iters.bin")
    print(f"  OSQP codegen, design of {n} variables, {m} rows: rho {rho:.3g}, iterations "
          f"median {np.median(iters):.0f}, largest {iters.max():.0f}")
    return _read_out(work / "osqp_out.bin", n)


def first_move_error(x: np.ndarray, ref: np.ndarray, scale: np.ndarray, rated_torque: float
                     ) -> tuple[float, float]:
    """The largest first-move difference: pitch [deg], torque [% of rated]."""
    d = (x[:, :4] - ref[:, :4]) * scale[:4]
    return (float(np.degrees(np.abs(d[:, :3]).max())),
            float(100.0 * np.abs(d[:, 3]).max() / rated_torque))


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--kind", default="mpc-lidar")
    ap.add_argument("--wind", type=float, default=18.0)
    ap.add_argument("--seed", type=int, default=31)
    ap.add_argument("--duration", type=float, default=120.0)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    cc = find_compiler()
    if cc is None:
        print("no C compiler found: this benchmark compiles both solvers")
        return 2
    sc = Scenario(args.wind, turbulence="A", seed=args.seed, duration=args.duration)
    records, shipped = record_qps(args.kind, sc)
    rated_torque = float(shipped["rated_torque"])
    by_design: dict[int, list[dict]] = {}
    for r in records:
        by_design.setdefault(r["design"], []).append(r)
    out = {"date": time.strftime("%Y-%m-%d %H:%M"), "machine": platform.node(),
           "python": platform.python_version(), "kind": args.kind, "wind_mps": args.wind,
           "seed": args.seed, "duration_s": args.duration, "solves": len(records),
           "designs": len(by_design), "repeat": args.repeat}
    acc: dict[str, dict[str, list]] = {s: {"us": [], "fail": [], "pitch": [], "torque": []}
                                       for s in ("daqp", "osqp")}
    tmp = Path(tempfile.mkdtemp(prefix="mpcwt_qp_codegen_"))
    try:
        for k, recs in enumerate(by_design.values()):
            qp = recs[0]["qp"]
            steps = [r["qp"] for r in recs]
            ref = np.tile(np.array([r["v"] for r in recs]), (args.repeat, 1))
            for name, replay in (("daqp", daqp_replay), ("osqp", osqp_replay)):
                work = tmp / f"{name}_{k}"
                work.mkdir()
                flag, us, x = replay(cc, work, qp, steps, args.repeat)
                ok = flag == 1
                acc[name]["us"].append(us)
                acc[name]["fail"].append(int((~ok).sum()))
                if ok.any():
                    p, q = first_move_error(x[ok], ref[ok], qp["scale"], rated_torque)
                    acc[name]["pitch"].append(p)
                    acc[name]["torque"].append(q)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    for name, a in acc.items():
        us = np.concatenate(a["us"])
        out[name] = {"median_us": float(np.median(us)), "p99_us": float(np.percentile(us, 99)),
                     "max_us": float(us.max()), "failed": int(sum(a["fail"])),
                     "first_move_pitch_deg": max(a["pitch"], default=float("nan")),
                     "first_move_torque_pct_rated": max(a["torque"], default=float("nan"))}
    lib = shipped["qp_solve_us"]
    out["shipped_library_qp_us"] = {"median": float(np.median(lib)),
                                    "p99": float(np.percentile(lib, 99))}
    out["osqp_over_daqp_median"] = out["osqp"]["median_us"] / out["daqp"]["median_us"]
    if args.json:
        print(json.dumps(out, indent=1))
        return 0
    print(f"{args.kind} at {args.wind:g} m/s, class A, seed {args.seed}, {args.duration:g} s: "
          f"{len(records)} QPs on {len(by_design)} grid designs, replayed {args.repeat}x "
          f"({out['date']}, {out['machine']})")
    print(f"{'solver':<28} {'median':>8} {'p99':>8} {'max':>8} {'failed':>7} "
          f"{'pitch':>9} {'torque':>9}")
    print(f"{'':<28} {'[us]':>8} {'[us]':>8} {'[us]':>8} {'':>7} {'[deg]':>9} {'[% rated]':>9}")
    for name, label in (("daqp", "DAQP 0.11 (sdist, shipped)"), ("osqp", "OSQP codegen (wheel)")):
        r = out[name]
        print(f"{label:<28} {r['median_us']:8.1f} {r['p99_us']:8.1f} {r['max_us']:8.1f} "
              f"{r['failed']:7d} {r['first_move_pitch_deg']:9.2e} "
              f"{r['first_move_torque_pct_rated']:9.2e}")
    s = out["shipped_library_qp_us"]
    print(f"the shipped library's own QP time in closed loop (map + DAQP): median "
          f"{s['median']:.1f} us, p99 {s['p99']:.1f} us; OSQP / DAQP solve, medians: "
          f"{out['osqp_over_daqp_median']:.2f}x")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

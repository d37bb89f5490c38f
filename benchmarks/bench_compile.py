"""What a fresh install pays before its first result: numba compiling the kernels.

Run:  python benchmarks/bench_compile.py

Each job runs in a new process with an empty numba cache (``NUMBA_CACHE_DIR`` in a temporary
folder), then once more on the cache it filled. Jobs: a 2 s closed loop of the baseline in
turbulence (trim, field, plant, compiled loop); the same for ``mpc``, ``lqr-pio`` and ``ts``
after it; the baseline in steady wind, then in turbulence; the NREL 5-MW's Jacobian by finite
differences and by complex step. Prints each job's time on the empty and on the filled cache
[s], how many versions of the plant kernel (``evaluate_plant_vw``) numba compiled (one for real
states, one for the complex step) and how many of the plant's time step (``_rk4``): numba
compiles a kernel again for each new set of argument types, read-only arrays apart from
writable ones, so a steady wind and a turbulent one must pass the same types.
"""
from __future__ import annotations

import datetime
import os
import platform
import subprocess
import sys
import tempfile

CHILD = """
import time
from numba.core import event
import linearize
from linearize import kernel
t0 = time.perf_counter()
with event.install_recorder("numba:compile") as rec:
    tb = linearize.load_turbine("nrel5mw")
    JOB
real = sum(1 for _, e in rec.buffer if e.is_start and e.data["dispatcher"].py_func is
           kernel.evaluate_plant_vw.py_func and "float64" in str(e.data["args"][0]))
cplx = sum(1 for _, e in rec.buffer if e.is_start and e.data["dispatcher"].py_func is
           kernel.evaluate_plant_vw.py_func and "complex128" in str(e.data["args"][0]))
steps = sum(1 for _, e in rec.buffer if e.is_start and e.data["dispatcher"].py_func is
            kernel._rk4.py_func and "complex" not in str(e.data["args"]))
print(f"{time.perf_counter() - t0:.1f} {real} {cplx} {steps}")
"""

JOBS = {
    "closed loop, baseline": "from mpc_wt.run import run_controller\n"
                             "    run_controller(tb, 'baseline', 12.0, turbulence='A', "
                             "duration=2.0)",
    "closed loops, baseline then mpc, lqr-pio, ts":
        "from mpc_wt.run import run_controller\n"
        "    for k in ('baseline', 'mpc', 'lqr-pio', 'ts'):\n"
        "        run_controller(tb, k, 12.0, turbulence='A', duration=2.0)",
    "baseline in steady wind, then in turbulence":
        "from mpc_wt.run import run_controller\n"
        "    run_controller(tb, 'baseline', 12.0, turbulence='steady', duration=2.0)\n"
        "    run_controller(tb, 'baseline', 12.0, turbulence='A', duration=2.0)",
    "Jacobian, finite differences and complex step":
        "from linearize.linear import jacobian_check\n"
        "    jacobian_check(tb, 12.0, wake='quasi-steady', shear_exponent=0.2)",
}


def _run(job: str, cache: str) -> tuple[float, int, int, int]:
    code = CHILD.replace("JOB", job)
    env = dict(os.environ, NUMBA_CACHE_DIR=cache)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         check=True).stdout.split()
    return float(out[-4]), int(out[-3]), int(out[-2]), int(out[-1])


def main() -> None:
    """Time each job on an empty and on a filled numba cache; print the table."""
    print(f"{'job':<48} {'empty cache [s]':>16} {'filled [s]':>11} {'plant kernels':>19} "
          f"{'step kernels':>13}")
    for name, job in JOBS.items():
        with tempfile.TemporaryDirectory() as cache:
            cold, real, cplx, steps = _run(job, cache)
            warm, *_ = _run(job, cache)
        print(f"{name:<48} {cold:16.1f} {warm:11.1f} {f'{real} real, {cplx} complex':>19} "
              f"{steps:13d}")
    print(f"{datetime.date.today()}; {platform.node()} ({platform.machine()}), "
          f"Python {platform.python_version()}")


if __name__ == "__main__":
    main()

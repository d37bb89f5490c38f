"""Plant speed: right-hand side, steady rotor evaluation (vs CCBlade), 600 s open loop.

Run:  python benchmarks/bench_plant.py [--peer-python PATH] [--json]

``--peer-python`` names an interpreter that has WISDEM installed (CCBlade ships inside it as
``wisdem.ccblade``); the same steady rotor evaluation is then timed there in the same run and
its C_P is printed next to ours. Nothing from WISDEM is imported into this process.

Figures printed (all on one core; the machine has 2):
* rhs_python_us: one full-plant RHS from Python: validation, dispatch and a cold BEM solve of
  every element (a stateless call has no earlier solution to start from)
* rhs_kernel_us: one full-plant RHS inside compiled code (what the stepper pays)
* steady_eval_us: one azimuth-averaged (4 sectors) steady rotor evaluation, ours vs CCBlade
* sim600_*: 600 s open loop at 80 Hz with RK4, all DOFs on, wind sampled at every blade
  element at every stage (IEC class-A field, 32 x 32 over 150 m at 20 Hz, shear 0.2; and
  steady sheared wind)
"""
from __future__ import annotations

import argparse
import json
import math
import platform
import subprocess
import sys
import time
from pathlib import Path

import numba as nb
import numpy as np

import linearize
from linearize.kernel import evaluate_plant
from linearize.steady import _avg_eval


@nb.njit(cache=False)
def _loop_rhs(x, u, w, pk, hint, n):  # pragma: no cover - compiled
    acc = 0.0
    for _ in range(n):
        dx, z, ph = evaluate_plant(x, u, w, pk, hint, 0)
        hint = ph
        acc += dx[2]
    return acc


@nb.njit(cache=False)
def _loop_steady(x, u, v, shear, pk, n_az, n):  # pragma: no cover - compiled
    acc = 0.0
    for _ in range(n):
        _, z = _avg_eval(x, u, v, shear, pk, n_az)
        acc += z[22]
    return acc


def _timeit(fn, repeat: int) -> list[float]:
    out = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t0)
    return out


def _iec_field(v_hub: float, duration: float, seed: int) -> linearize.GridWind:
    """IEC 61400-1 class-A Kaimal field (lidar package), 32 x 32 points over 150 m, 20 Hz,
    shear 0.2, as the plant's gridded wind."""
    import lidar

    f = lidar.generate_field(lidar.TurbulenceSpec(v_hub, "A", duration=duration), seed)
    return linearize.GridWind(t=f.t, y=f.y, z=f.z, u=np.maximum(f.u, 0.0))


_PEER = r"""
import json, math, sys, time, csv
import numpy as np
from wisdem.ccblade.ccblade import CCBlade, CCAirfoil
d = sys.argv[1]
rows = list(csv.DictReader(open(d + "/blade_aero_elements_17.csv")))
idx = list(csv.DictReader(open(d + "/airfoils/airfoil_index.csv")))
afs = {}
for row in idx:
    tab = np.loadtxt(d + "/" + row["file"], delimiter=",", skiprows=1)
    afs[row["af_id"]] = CCAirfoil(tab[:, 0], [0.75e6], tab[:, 1:2], tab[:, 2:3], tab[:, 3:4])
r = [float(x["RNodes_m_from_apex"]) for x in rows]
chord = [float(x["Chord_m"]) for x in rows]
theta = [float(x["AeroTwst_deg"]) for x in rows]
af = [afs[x["af_id"]] for x in rows]
rot = CCBlade(r, chord, theta, af, 1.5, 63.0, 3, 1.225, 1.81206e-5, 2.5, 5.0, 0.0, 0.2, 90.0,
              nSector=4)
v = 10.0
def cp_at(tsr):
    om = tsr * v / (63.0 * math.cos(math.radians(2.5))) * 30 / math.pi
    out = rot.evaluate([v], [om], [0.0], coefficients=True)
    out = out[0] if isinstance(out, tuple) else out
    return float(out["CP"][0])
cp_at(7.5)
n = 200
t0 = time.perf_counter()
for _ in range(n):
    cp_at(7.5)
dt = (time.perf_counter() - t0) / n
grid = np.arange(6.5, 9.0, 0.05)
cps = [cp_at(x) for x in grid]
i = int(np.argmax(cps))
print(json.dumps({"eval_us": dt * 1e6, "cp_75": cp_at(7.5), "cp_max": cps[i],
                  "tsr_max": float(grid[i])}))
"""


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--peer-python", help="interpreter with WISDEM (CCBlade) installed")
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()

    turbine = linearize.load_turbine("nrel5mw")
    params = linearize.plant_params(turbine)
    op = linearize.trim(turbine, 18.0, shear_exponent=0.2)
    res: dict[str, object] = {"date": time.strftime("%Y-%m-%d"), "machine": platform.machine(),
                              "python": platform.python_version(), "numba": nb.__version__,
                              "cpu": platform.processor() or "unknown"}

    # --- right-hand side
    d = linearize.element_wind(params, 0.3, 18.0, 0.2)
    linearize.plant_rhs(0.0, op.x, op.u, d, params)
    n = 2000
    t = min(_timeit(lambda: [linearize.plant_rhs(0.0, op.x, op.u, d, params) for _ in range(n)],
                    args.repeat))
    res["rhs_python_us"] = t / n * 1e6
    hint = np.full((4, 3, 17), np.nan)
    _loop_rhs(op.x, op.u, d, params.pack, hint, 2)
    n = 20000
    t = min(_timeit(lambda: _loop_rhs(op.x, op.u, d, params.pack, hint, n), args.repeat))
    res["rhs_kernel_us"] = t / n * 1e6

    # --- steady rotor evaluation, CCBlade setup (4 sectors, tilt, cone, shear 0.2)
    sp = linearize.plant_params(turbine, linearize.PlantConfig(frozenset({"generator"}),
                                                               integration="trapezoid"))
    om = 7.5 * 10.0 / (63.0 * math.cos(math.radians(2.5)))
    x = np.zeros(17)
    x[2], x[3] = om, om * 97
    u = np.zeros(4)
    _loop_steady(x, u, 10.0, 0.2, sp.pack, 4, 2)
    n = 2000
    t = min(_timeit(lambda: _loop_steady(x, u, 10.0, 0.2, sp.pack, 4, n), args.repeat))
    res["steady_eval_us"] = t / n * 1e6
    cp75, _ = linearize.steady_coefficients(turbine, 7.5, 0.0, shear_exponent=0.2,
                                            integration="trapezoid")
    lam, cpm = linearize.optimal_tsr(turbine, 0.0, shear_exponent=0.2, integration="trapezoid")
    res["cp_75_ours"] = float(cp75)
    res["cp_max_ours"], res["tsr_max_ours"] = cpm, lam
    if args.peer_python:
        data = Path(linearize.__file__).parent / "data" / "nrel5mw"
        out = subprocess.run([args.peer_python, "-c", _PEER, str(data)], capture_output=True,
                             text=True, timeout=600)
        if out.returncode == 0:
            peer = json.loads(out.stdout.strip().splitlines()[-1])
            res["steady_eval_us_ccblade"] = peer["eval_us"]
            res["steady_eval_ratio_ccblade_over_ours"] = peer["eval_us"] / res["steady_eval_us"]
            res["cp_75_ccblade"] = peer["cp_75"]
            res["cp_max_ccblade"], res["tsr_max_ccblade"] = peer["cp_max"], peer["tsr_max"]
        else:
            res["ccblade_error"] = out.stderr.strip().splitlines()[-1:]

    # --- 600 s open loop, all DOFs
    field = _iec_field(18.0, 601.0, seed=1)
    linearize.rk4_simulate(params, op.x, op.u, field, 1.0)
    times = _timeit(lambda: linearize.rk4_simulate(params, op.x, op.u, field, 600.0),
                    args.repeat)
    res["sim600_grid_best_s"] = min(times)
    res["sim600_grid_median_s"] = float(np.median(times))
    res["sim600_grid_realtime_factor"] = 600.0 / min(times)
    times = _timeit(lambda: linearize.rk4_simulate(params, op.x, op.u,
                                                   linearize.SteadyWind(18.0, 0.2), 600.0),
                    args.repeat)
    res["sim600_steady_sheared_best_s"] = min(times)
    res["sim600_steady_sheared_median_s"] = float(np.median(times))

    if args.json:
        print(json.dumps(res, indent=1))
    else:
        for k, v in res.items():
            print(f"{k:40s} {v:.4g}" if isinstance(v, float) else f"{k:40s} {v}")
    floor_ok = res["sim600_grid_best_s"] <= 6.0
    print(f"# floor (600 s in <= 6 s on one core): {'met' if floor_ok else 'NOT met'}",
          file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Linearization speed: the default family (4..25 m/s, 22 wind speeds) on one core.

Run:  python benchmarks/bench_linearize.py [--json]

Prints the wall time of ``linearize_family`` with the default options (all DOFs, all
aerodynamic effects, quasi-steady wake, 8 azimuth samples per wind speed, trim included),
best of 3 after a warm-up that compiles the kernels, and the same for frozen wake and MBC.
"""
from __future__ import annotations

import argparse
import json
import platform
import sys
import time

import numpy as np

import linearize


def _best(fn, repeat: int = 3) -> float:
    out = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t0)
    return min(out)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    t = linearize.load_turbine("nrel5mw")
    linearize.linearize_family(t, [10.0, 18.0])                        # compile
    linearize.linearize_family(t, [10.0, 18.0], wake="frozen", coordinates="mbc")
    res = {"date": time.strftime("%Y-%m-%d"), "machine": platform.machine(),
           "python": platform.python_version()}
    grid = np.arange(4.0, 25.5, 1.0)
    res["family22_quasi_steady_s"] = _best(lambda: linearize.linearize_family(t, grid))
    res["family22_frozen_s"] = _best(lambda: linearize.linearize_family(t, grid, wake="frozen"))
    res["family22_mbc_s"] = _best(lambda: linearize.linearize_family(t, grid,
                                                                     coordinates="mbc"))
    res["family22_madsen8_s"] = _best(lambda: linearize.linearize_family(
        t, grid, config=linearize.PlantConfig.madsen()))
    if args.json:
        print(json.dumps(res, indent=1))
    else:
        for k, v in res.items():
            print(f"{k:32s} {v:.4g}" if isinstance(v, float) else f"{k:32s} {v}")
    print(f"# floor (22 models in < 2 s on one core): "
          f"{'met' if res['family22_quasi_steady_s'] < 2.0 else 'NOT met'}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())

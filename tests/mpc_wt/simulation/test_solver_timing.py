"""``mpcwt bench mpc``: the solver comparison on a short closed loop -- JSON keys, the first moves
of every solver against the tight-tolerance reference, and bad arguments."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from mpc_wt.cli import main
from mpc_wt.simulation.solver_timing import run_solver_benchmark


def test_bench_mpc_json_and_move_errors(capsys: pytest.CaptureFixture[str],
                                        tmp_path: Path) -> None:
    png = tmp_path / "times.png"
    assert main(["bench", "mpc", "--steps", "40", "--json", "--plot", str(png)]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["steps"] == 40
    names = [e["solver"] for e in res["solvers"]]
    assert {"osqp-condensed", "cvxpy-params (OSQP)", "clarabel", "qpoases-casadi"} <= set(names)
    for e in res["solvers"]:
        for key in ("solver", "median_us", "p95_us", "p99_us", "max_us", "max_move_error"):
            assert key in e, (e["solver"], key)
        assert 0 < e["median_us"] <= e["p99_us"] <= e["max_us"]
        # acceptance: the applied first move within 0.01 deg pitch and 0.1 % of rated
        # torque of the reference, i.e. max_move_error <= 1
        assert e["max_move_error"] <= 1.0, e
    assert png.stat().st_size > 10_000


def test_bench_rejects_too_few_steps() -> None:
    with pytest.raises(ValueError, match="steps must be >= 10, got 3"):
        run_solver_benchmark(None, 3, progress=False)

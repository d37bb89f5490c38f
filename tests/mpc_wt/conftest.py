"""Fixtures shared by the mpc_wt tests: the tuned baseline and one 600 s run of it at 18 m/s.
"""
from __future__ import annotations

import numpy as np
import pytest

import lidar
import linearize
from mpc_wt.controllers.baseline import BaselineController, tune_baseline
from mpc_wt.run import law_controller
from mpc_wt.simulation.loop import simulate_closed_loop


@pytest.fixture(scope="session")
def gains(turbine: linearize.Turbine):
    return tune_baseline(turbine)


def _field(v: float, turb, seed: int) -> tuple[linearize.GridWind, lidar.WindField]:
    f = lidar.generate_field(lidar.TurbulenceSpec(v, turb, duration=610.0), seed)
    return linearize.GridWind(t=f.t, y=f.y, z=f.z, u=np.maximum(f.u, 0.0)), f


@pytest.fixture(scope="session")
def run18(turbine: linearize.Turbine, params: linearize.PlantParams, gains):
    gw, _ = _field(18.0, "A", 1)
    op = linearize.trim(turbine, 18.0)
    ctl = law_controller(BaselineController(turbine, gains), "baseline", turbine)
    return simulate_closed_loop(params, ctl, gw, 600.0,
                                x0=op.x, u0=op.u)

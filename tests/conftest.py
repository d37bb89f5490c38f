"""Shared fixtures: the reference turbine (session scope), its plant parameters, a seeded rng."""
from __future__ import annotations

import numpy as np
import pytest

import linearize


@pytest.fixture(scope="session")
def turbine() -> linearize.Turbine:
    return linearize.load_turbine("nrel5mw")


@pytest.fixture(scope="session")
def params(turbine: linearize.Turbine) -> linearize.PlantParams:
    return linearize.plant_params(turbine)


@pytest.fixture(scope="session")
def params_axisym(turbine: linearize.Turbine) -> linearize.PlantParams:
    """All DOFs, azimuth-dependent effects (tilt, cone, gravity) off."""
    cfg = linearize.PlantConfig(aero=linearize.AeroOptions().azimuth_independent)
    return linearize.plant_params(turbine, cfg)


@pytest.fixture()
def rng() -> np.random.Generator:
    return np.random.default_rng(20261122)

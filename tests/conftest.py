"""Shared fixtures: the reference turbine (session scope), its plant parameters, a seeded rng."""
from __future__ import annotations

from pathlib import Path

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


@pytest.fixture(scope="session")
def rosco_nrel5mw() -> tuple[np.ndarray, ...]:
    """ROSCO's NREL 5-MW performance tables (tests/data/Cp_Ct_Cq.NREL5MW.txt, CCBlade; see
    tests/data/README.md): (pitch [deg], tsr [-], C_P, C_T), rows TSR, columns pitch."""
    lines = (Path(__file__).parent / "data" / "Cp_Ct_Cq.NREL5MW.txt").read_text().splitlines()
    pitch = np.array(lines[4].split(), float)
    tsr = np.array(lines[6].split(), float)
    cp = np.array([ln.split() for ln in lines[12:12 + tsr.size]], float)
    ct = np.array([ln.split() for ln in lines[42:42 + tsr.size]], float)
    return pitch, tsr, cp, ct

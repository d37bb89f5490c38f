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


@pytest.fixture(scope="session")
def rosco_utilities():
    """ROSCO's Python readers of ``DISCON.IN`` and ``Cp_Ct_Cq.txt`` (``rosco.toolbox.utilities``),
    a peer of ours. They import WISDEM, which the test extras leave out (about 110 packages):
    the README's test command installs the rosco wheel without its dependencies, for its
    compiled library and decks, so tests reading with these are skipped there and run with
    ``pip install ".[test,rosco]"``. Each such test has a check through ROSCO's compiled
    library or a fixed-layout parse beside it that always runs."""
    return pytest.importorskip("rosco.toolbox.utilities",
                               reason="ROSCO's Python toolbox needs WISDEM: "
                                      "pip install '.[test,rosco]'")

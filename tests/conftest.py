"""Shared fixtures: the reference turbine (session scope), its plant parameters, a seeded rng;
and the compiled kernels shared out between the test workers at the start."""
from __future__ import annotations

import os
import shutil
import sys
import tempfile
import traceback
from pathlib import Path

import numpy as np
import pytest

import linearize


def _compile_closed_loop() -> None:
    from mpc_wt.run import run_controller

    run_controller(linearize.load_turbine("nrel5mw"), "baseline", 12.0, turbulence="A",
                   duration=0.5)


def _compile_linearization() -> None:
    from linearize.linear import jacobian_check

    jacobian_check(linearize.load_turbine("nrel5mw"), 12.0, wake="quasi-steady",
                   shear_exponent=0.2)


_CACHE = pytest.StashKey[str]()


def pytest_configure(config: pytest.Config) -> None:
    """The suite keeps mpc-wt's per-user cache (the MPC exports' solver sources) in a folder of
    its own, made by the main process and shared with its workers, so that no test writes to
    the user's cache."""
    if "PYTEST_XDIST_WORKER" not in os.environ and "MPCWT_CACHE_DIR" not in os.environ:
        path = tempfile.mkdtemp(prefix="mpcwt-test-cache-")
        os.environ["MPCWT_CACHE_DIR"] = path
        config.stash[_CACHE] = path


def pytest_unconfigure(config: pytest.Config) -> None:
    path = config.stash.get(_CACHE, None)
    if path is not None:
        shutil.rmtree(path, ignore_errors=True)
        os.environ.pop("MPCWT_CACHE_DIR", None)


def pytest_sessionstart(session: pytest.Session) -> None:
    """On a fresh install every test worker would compile the same numba kernels at once
    (about a minute each on 2 cores). The first two workers share the work out instead: each
    first compiles one half (the closed loop; the real and complex-step linearization), then
    asks for the other, which by then the other worker has put in numba's disk cache. With the
    kernels cached this takes a second or two."""
    order = {"gw0": (_compile_closed_loop, _compile_linearization),
             "gw1": (_compile_linearization, _compile_closed_loop)}
    for step in order.get(os.environ.get("PYTEST_XDIST_WORKER", ""), ()):
        try:
            step()
        except Exception:              # the tests that need these kernels report it
            print(f"warming the kernels failed:\n{traceback.format_exc()}", file=sys.stderr)


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

"""One run from a controller name: the scenario given whole or as its mean wind and fields,
and bad scenarios named by their field (or flag, on the command line)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import linearize
from mpc_wt.cli import main
from mpc_wt.run import run_controller
from mpc_wt.simulation.scenario import Scenario


@pytest.fixture(scope="module")
def turbine() -> linearize.Turbine:
    return linearize.load_turbine("nrel5mw")


def test_a_whole_scenario_and_its_shorthand_run_the_same_case(turbine) -> None:
    whole = run_controller(turbine, "baseline", Scenario(14.0, "steady", 1, 3.0, 0.1))
    short = run_controller(turbine, "baseline", 14.0, turbulence="steady", seed=1, duration=3.0,
                           shear_exponent=0.1)
    assert whole.meta["wind_mps"] == 14.0 and whole.meta["shear_exponent"] == 0.1
    assert {k: whole.meta[k] for k in ("wind_mps", "turbulence", "seed", "duration_s")} == \
        {k: short.meta[k] for k in ("wind_mps", "turbulence", "seed", "duration_s")}
    # the same inputs, the same deterministic simulation: equal to the last bit
    assert np.array_equal(whole.channel("rotor_speed"), short.channel("rotor_speed"))


def test_scenario_fields_beside_a_whole_scenario_are_refused(turbine) -> None:
    with pytest.raises(TypeError, match=r"\['seed'\] apply only with a mean wind"):
        run_controller(turbine, "baseline", Scenario(14.0), seed=3)
    with pytest.raises(TypeError, match="scenario must be a Scenario or a mean wind speed"):
        run_controller(turbine, "baseline", "14")


@pytest.mark.parametrize("fields, match", [
    ({"seed": -1}, "seed must be an integer >= 0"),
    ({"turbulence": "D"}, "turbulence must be 'A', 'B', 'C', 'steady'"),
    ({"turbulence": 1.5}, r"turbulence intensity must be in \(0, 1\)"),
    ({"duration": 0.0}, "duration"),
    ({"condition": {"condition": "eog"}, "turbulence": 0.1},
     "condition 'eog' needs an IEC turbulence category"),
])
def test_a_bad_scenario_names_its_field(turbine, fields, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        run_controller(turbine, "baseline", 14.0, **fields)


@pytest.mark.parametrize("argv, flag", [
    (["--seed", "-1"], "--seed: seed must be an integer >= 0"),
    (["--duration", "-5"], "--duration: duration"),
])
def test_the_command_line_names_the_flag_of_a_bad_scenario(argv, flag: str, tmp_path: Path,
                                                            capsys) -> None:
    assert main(["simulate", "--wind", "13", *argv, "--out", str(tmp_path / "x.nc")]) == 2
    assert flag in capsys.readouterr().err

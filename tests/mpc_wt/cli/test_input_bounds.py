"""Arguments checked before any work, bounds that refuse runs which would fail on memory or
run for days, a diverged run's samples written where the user looks, and the exit codes:
2 for input, 1 for a failed run."""
from __future__ import annotations

import pytest

import linearize
from mpc_wt.campaign import SpecError, spec_from_dict
from mpc_wt.cli.main import main

BASE = {"name": "t", "duration": 20, "transient": 5, "winds": [14], "seeds": 1,
        "controllers": ["baseline"]}


@pytest.fixture()
def no_simulation(monkeypatch):
    """Fails the test if a simulation starts: the checks must come first."""
    import mpc_wt.run

    def refuse(*a, **k):
        raise AssertionError("the simulation started before the arguments were checked")
    monkeypatch.setattr(mpc_wt.run, "run_controller", refuse)


@pytest.mark.parametrize("out, match", [
    ("no/such/folder/x.nc", r"--out no/such/folder/x.nc: the folder no/such/folder does not "
                            r"exist"),
    ("x.csv", r"--out must end in .nc; got 'x.csv'"),
])
def test_simulate_checks_its_output_before_simulating(capsys, no_simulation, out, match) -> None:
    assert main(["simulate", "--wind", "12", "--duration", "5", "--out", out]) == 2
    assert match.replace("\\", "") in capsys.readouterr().err


def test_simulate_refuses_a_folder_as_output(capsys, no_simulation, tmp_path) -> None:
    (tmp_path / "r.nc").mkdir()
    assert main(["simulate", "--wind", "12", "--out", str(tmp_path / "r.nc")]) == 2
    assert "is a folder" in capsys.readouterr().err


@pytest.mark.parametrize("argv, match", [
    (["--duration", "1e12"], "--duration: duration must be at most 10800 s"),
    (["--controller", "mpc", "--horizon", "100000"], "200"),
])
def test_simulate_bounds(capsys, no_simulation, tmp_path, argv, match) -> None:
    assert main(["simulate", "--wind", "12", "--out", str(tmp_path / "r.nc"), *argv]) == 2
    err = capsys.readouterr().err
    assert match in err, err
    assert "horizon" in err or "duration" in err


@pytest.mark.parametrize("over, match", [
    ({"seeds": 10_000_000}, r"seeds: a seed count must be between 1 and 1000, got 10000000"),
    ({"seeds": list(range(1001))}, r"seeds: at most 1000 seeds, got 1001"),
    ({"winds": list(range(4, 25)), "seeds": 1000,
      "controllers": [f"derate{p}" for p in range(50, 100, 5)]},
     r"the spec makes 210000 cases, more than 100000"),
    ({"duration": 1e9}, r"duration: must be .*10800"),
])
def test_campaign_bounds(over, match) -> None:
    with pytest.raises(SpecError, match=match):
        spec_from_dict({**BASE, **over})


def test_a_diverged_simulate_writes_its_samples_and_exits_1(capsys, monkeypatch,
                                                            tmp_path) -> None:
    """The run's samples before the divergence go to OUT.partial.nc, and the message says
    where (it said "kept in .partial" and wrote nothing)."""
    import mpc_wt.run
    from mpc_wt import ClosedLoopResult
    from mpc_wt.simulation.scenario import Scenario

    turbine = linearize.load_turbine()
    before = mpc_wt.run.run_controller(turbine, "baseline", Scenario(12.0, "steady", 1, 2.0))

    def diverge(*a, **k):
        raise linearize.SimulationDivergedError(
            "simulation diverged at t = 2.0000 s: state 'rotor_speed' = 9.9 rad/s left its "
            "envelope; the 161 samples before are kept in .partial", before)
    monkeypatch.setattr(mpc_wt.run, "run_controller", diverge)
    out = tmp_path / "r.nc"
    assert main(["simulate", "--wind", "12", "--duration", "5", "--out", str(out)]) == 1
    err = capsys.readouterr().err
    kept = tmp_path / "r.partial.nc"
    assert "run failed: simulation diverged" in err and str(kept) in err
    assert ClosedLoopResult.load(kept).t.size == before.t.size
    assert not out.exists()

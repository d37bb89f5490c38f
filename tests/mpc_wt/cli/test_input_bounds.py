"""Arguments checked before any work, bounds that refuse runs which would fail on memory or
run for days, a diverged run's samples written where the user looks, and the exit codes:
2 for input, 1 for a failed run."""
from __future__ import annotations

import pytest

import linearize
from mpc_wt.campaign import SpecError, spec_from_dict
from mpc_wt.cli import main

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
    # checked only after the simulation, with a raw errno on the temporary name
    ("/proc/x.nc", r"--out /proc/x.nc: the folder /proc is not writable"),
])
def test_simulate_checks_its_output_before_simulating(capsys, no_simulation, out, match) -> None:
    assert main(["simulate", "--wind", "12", "--duration", "5", "--out", out]) == 2
    assert match.replace("\\", "") in capsys.readouterr().err


def test_simulate_refuses_a_folder_as_output(capsys, no_simulation, tmp_path) -> None:
    """A folder named as the output file, with or without its suffix or a trailing slash, is
    refused (``--out o/`` wrote ``o.nc`` beside the folder)."""
    (tmp_path / "r.nc").mkdir()
    (tmp_path / "o").mkdir()
    for out in (str(tmp_path / "r.nc"), str(tmp_path / "o"), f"{tmp_path / 'o'}/"):
        assert main(["simulate", "--wind", "12", "--out", out]) == 2
        assert "is a folder" in capsys.readouterr().err
    assert not (tmp_path / "o.nc").exists()


@pytest.mark.parametrize("argv, match", [
    (["--n", "100000"], "--n must be between 2 and 256 grid points per side, got 100000"),
    (["--duration", "1e9"], "--duration must be in (0, 10800] s (3 h), got 1e+09"),
    (["--n", "200", "--duration", "10800"], "10800 s field of 200 x 200 points every 0.05 s "
                                            "needs about 207.81 GB of memory"),
])
def test_wind_generate_bounds(capsys, monkeypatch, tmp_path, argv, match) -> None:
    """Refused before any field is made, exit 2 (tracebacks asking numpy for 218 TiB and
    149 GiB)."""
    import lidar

    monkeypatch.setattr(lidar, "generate_field", lambda *a, **k: pytest.fail("generated"))
    monkeypatch.setattr("mpc_wt.simulation.memory.available_memory", lambda: 24e9)
    assert main(["wind", "generate", "--mean", "12", "--out", str(tmp_path / "w.npz"),
                 *argv]) == 2
    assert match in capsys.readouterr().err


def test_an_event_after_the_runs_end_is_refused(capsys, tmp_path) -> None:
    """``--grid-loss-at 500`` in a 5 s run: refused naming the event and the run's end (it
    ran, with no event and no warning)."""
    out = tmp_path / "g.nc"
    assert main(["simulate", "--wind", "12", "--duration", "5", "--grid-loss-at", "500",
                 "--out", str(out)]) == 2
    assert ("supervisor grid_loss_at = 500 s is at or after the run's end (5 s)"
            in capsys.readouterr().err)
    assert not out.exists()


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
    # refused after 89.5 s and 1.56 GB, naming the seeds
    ({"winds": {"start": 5, "stop": 25, "step": 1e-6}},
     r"winds.step: 1e-06 m/s from 5 to 25 m/s makes 20000001 mean winds, more than 1000"),
    ({"winds": {"start": 5, "stop": 600}}, r"winds.stop: must be .*60"),
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


def test_a_garbage_index_and_a_cut_field_file_are_one_line_errors(capsys, tmp_path) -> None:
    """They were tracebacks (sqlite3.DatabaseError, zipfile.BadZipFile)."""
    import numpy as np

    camp = tmp_path / "camp"
    camp.mkdir()
    (camp / "index.sqlite").write_text("garbage, not a database\n")
    for cmd in ("status", "report"):
        assert main(["campaign", cmd, str(camp)]) == 2
        assert (f"{camp / 'index.sqlite'}: cannot be used as a campaign index: file is not a "
                f"database") in capsys.readouterr().err
    np.savez(tmp_path / "f.npz", a=np.zeros(1000))
    cut = tmp_path / "cut.npz"
    cut.write_bytes((tmp_path / "f.npz").read_bytes()[:300])
    assert main(["lidar", "evaluate", "--field", str(cut)]) == 2
    assert f"{cut}: not a complete .npz file" in capsys.readouterr().err


def test_ctrl_c_exits_130_with_how_to_resume(capsys, monkeypatch, tmp_path) -> None:
    import mpc_wt.campaign.runner

    def interrupted(*a, **k):
        raise KeyboardInterrupt
    monkeypatch.setattr(mpc_wt.campaign.runner, "run_campaign", interrupted)
    spec = tmp_path / "s.yaml"
    spec.write_text("name: s\nduration: 10\nwinds: [12]\nseeds: 1\ncontrollers: [baseline]\n")
    assert main(["campaign", "run", str(spec), "--out", str(tmp_path / "c"), "--engine",
                 "serial"]) == 130
    assert ("interrupted; run the same command again to resume: finished cases are kept"
            in capsys.readouterr().err)


def test_a_run_outside_its_validity_says_so(capsys, tmp_path) -> None:
    """TS at cut-out in class-A turbulence: its premise leaves the vertex grid (the estimated
    wind above 25 m/s) in a share of the steps; the run's result counts it, the command line
    prints it. A baseline run at 12 m/s has no such line."""
    from mpc_wt import ClosedLoopResult

    out = tmp_path / "ts.nc"
    assert main(["simulate", "--controller", "ts", "--wind", "25", "--duration", "30",
                 "--out", str(out)]) == 0
    text = capsys.readouterr().out
    warns = ClosedLoopResult.load(out).meta["run_warnings"]
    assert len(warns) == 1 and "TS premise" in warns[0] and "steps (" in warns[0]
    assert f"warning: {warns[0]}" in text
    assert main(["simulate", "--wind", "12", "--duration", "10", "--out",
                 str(tmp_path / "b.nc")]) == 0
    assert "warning:" not in capsys.readouterr().out


def test_ctrl_c_in_tune_exits_130_with_how_to_resume(capsys, monkeypatch, tmp_path) -> None:
    import yaml

    import mpc_wt.tuning.run

    def interrupted(*a, **k):
        raise KeyboardInterrupt
    monkeypatch.setattr(mpc_wt.tuning.run, "tune", interrupted)
    spec = tmp_path / "t.yaml"
    spec.write_text(yaml.safe_dump({
        "name": "t", "duration": 40, "transient": 10, "turbulence": "A", "winds": [18],
        "seeds": [1], "holdout_seeds": [2], "channels": {"tower_base_fa_moment": 4},
        "controller": {"controller": "baseline"},
        "reference": {"name": "ref", "controller": "baseline"},
        "parameters": {"omega_n_rad_s": {"low": 0.3, "high": 1.0}},
        "objective": [{"metric": "del:tower_base_fa_moment", "weight": 1}], "trials": 3}))
    assert main(["tune", str(spec), "--out", str(tmp_path / "tn"), "--engine", "serial"]) == 130
    assert ("mpcwt tune: interrupted; run the same command again to resume: finished trials "
            "are kept" in capsys.readouterr().err)


def test_memory_is_estimated_before_a_run(capsys, monkeypatch, tmp_path) -> None:
    """A 3 h turbulent run on the IEA-15 (a 56 x 56 field every 0.05 s: 3.6 GB stored, by hand
    216001 x 56 x 56 x 4 B) on a machine with 2 GB available is refused before the field is
    made, naming the estimate, its parts and what is available (exit 2); a 2 s run passes."""
    import mpc_wt.simulation.memory as memory
    import mpc_wt.simulation.scenario as scenario

    monkeypatch.setattr(memory, "available_memory", lambda: 2e9)

    def refuse(*a, **k):
        raise AssertionError("the wind field was made before memory was checked")
    monkeypatch.setattr(scenario, "make_wind", refuse)
    import mpc_wt.run
    monkeypatch.setattr(mpc_wt.run, "make_wind", refuse)
    assert main(["simulate", "--turbine", "iea15mw", "--wind", "12", "--duration", "10800",
                 "--out", str(tmp_path / "x.nc")]) == 2
    err = capsys.readouterr().err
    assert "a 10800 s run of baseline needs about" in err and "more than the 2.00 GB available" \
        in err and "shorten the duration" in err
    m = memory.estimate_run_memory(linearize.load_turbine("iea15mw"),
                                   scenario.Scenario(12.0, "A", 1, 10800.0))
    assert m.field >= 216001 * 56 * 56 * 4
    monkeypatch.undo()
    monkeypatch.setattr(memory, "available_memory", lambda: 2e9)
    assert main(["simulate", "--wind", "12", "--duration", "2", "--out",
                 str(tmp_path / "y.nc")]) == 0


def test_a_campaign_that_would_not_fit_is_refused(monkeypatch, tmp_path) -> None:
    """A campaign of 1 h cases on 2 workers with 1 GB available: refused before any case
    runs, naming the largest case and the worker count; nothing is recorded as failed."""
    import mpc_wt.simulation.memory as memory
    from mpc_wt.campaign import run_campaign
    from mpc_wt.campaign.store import CampaignStore

    monkeypatch.setattr(memory, "available_memory", lambda: 1e9)
    spec = spec_from_dict({**BASE, "duration": 3600})
    with pytest.raises(memory.RunTooLargeError, match=r"the campaign's largest case "
                                                      r"\(baseline__A__v14__s1\) needs about "
                                                      r"2 x .* run fewer workers"):
        run_campaign(spec, tmp_path / "c", workers=2, engine="processes", progress=False)
    with CampaignStore(tmp_path / "c") as store:
        assert store.counts().get("failed", 0) == 0 and store.counts().get("done", 0) == 0


@pytest.mark.parametrize("argv", [
    ["campaign", "run", "SPEC", "--out", "FILE", "--engine", "serial"],
    ["design", "baseline", "--out", "FILE"],
    ["run", "--out", "FILE"],
    ["run", "--out", "FILE/sub"],
    ["export", "DESIGN", "--format", "csv", "--to", "FILE"],
    ["tune", "SPEC", "--out", "FILE"],
])
def test_an_output_folder_that_is_a_file_is_refused_first(capsys, no_simulation, tmp_path,
                                                          argv) -> None:
    """Every command that writes a folder, given an existing file as it: one line naming the
    option and the path, exit 2, before any work (formerly a FileExistsError or
    NotADirectoryError traceback after the design)."""
    (tmp_path / "f").write_text("mine\n")
    spec = tmp_path / "s.yaml"
    spec.write_text("name: s\nduration: 10\nwinds: [12]\nseeds: 1\ncontrollers: [baseline]\n")
    sub = {"FILE": str(tmp_path / "f"), "SPEC": str(spec), "DESIGN": str(tmp_path)}
    args = [next((a.replace(k, v) for k, v in sub.items() if a.startswith(k)), a) for a in argv]
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(tmp_path / "f") in err[0]
    assert "is a file" in err[0]
    assert (tmp_path / "f").read_text() == "mine\n"


def test_a_range_flag_that_makes_millions_of_values_is_refused(capsys, tmp_path) -> None:
    """``--wind 5:25:0.000001`` makes 2e7 winds: refused at once, naming the flag."""
    assert main(["design", "lqr", "--wind", "5:25:0.000001", "--out",
                 str(tmp_path / "d")]) == 2
    assert ("--wind 5:25:0.000001: makes 20000001 values, more than 1000"
            in capsys.readouterr().err)


@pytest.mark.parametrize("source, match", [
    ("def f(:\n", r"does not import: a syntax error at .*broken_plugin.py:1: invalid syntax"),
    ("raise SystemExit(0)\n", r"does not import: it raised SystemExit\(0\) while imported"),
    ("raise RuntimeError('no licence')\n", r"it raised RuntimeError: no licence"),
    (None, r"does not import: No module named 'broken_plugin'"),
])
def test_a_plugin_that_does_not_import_is_one_line(capsys, monkeypatch, tmp_path, source,
                                                   match) -> None:
    """``--plugin MODULE`` is found in the folder the command runs in (it needed
    ``PYTHONPATH=.``); one that does not import exits 2 with one line (a syntax error was a
    traceback; ``SystemExit(0)`` made ``simulate`` exit 0 with no output and no file)."""
    import re
    import sys

    monkeypatch.chdir(tmp_path)
    monkeypatch.delitem(sys.modules, "broken_plugin", raising=False)
    if source is not None:
        (tmp_path / "broken_plugin.py").write_text(source)
    assert main(["--plugin", "broken_plugin", "simulate", "--wind", "12", "--duration", "2",
                 "--out", str(tmp_path / "x.nc")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and re.search(match, err), err
    assert not (tmp_path / "x.nc").exists()


def test_a_plugin_in_the_commands_folder_registers(capsys, monkeypatch, tmp_path) -> None:
    """A plugin module beside the user, given by name, registers its kind for the command."""
    import json
    import sys

    monkeypatch.chdir(tmp_path)
    monkeypatch.delitem(sys.modules, "here_plugin", raising=False)
    (tmp_path / "here_plugin.py").write_text(
        "from dataclasses import dataclass\n"
        "from mpc_wt.registry import Built, Options, register\n\n"
        "@dataclass(frozen=True)\nclass HereOptions(Options):\n    pass\n\n"
        "@register('here-plugin-kind', HereOptions, summary='a kind from the current folder')\n"
        "def build(ctx, opts):\n    raise NotImplementedError\n")
    try:
        assert main(["--plugin", "here_plugin", "controllers", "--json"]) == 0
        assert "here-plugin-kind" in [k["name"] for k in json.loads(capsys.readouterr().out)]
    finally:
        from mpc_wt.registry import registry

        registry._KINDS.pop("here-plugin-kind", None)
        registry._PLUGINS_LOADED.discard("here_plugin")

"""Campaigns on the user's own wind: a load case of TurbSim files runs one case per file and
controller, the plant meets the file's wind, the lifetime tables bin each file by its mean
wind, an edited file reruns only its own cases, and a bad entry is named."""
from __future__ import annotations

import dataclasses
import shutil
from pathlib import Path

import numpy as np
import pytest

import lidar
import linearize
from mpc_wt.campaign import SpecError, load_spec, run_campaign, spec_from_dict
from mpc_wt.cli import main
from mpc_wt.simulation.results import ClosedLoopResult
from mpc_wt.simulation.scenario import Scenario, field_spec


@pytest.fixture(scope="module")
def files(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Two TurbSim files, class B at 13.2 and 19.0 m/s (about 36 s each)."""
    tb = linearize.load_turbine()
    d = tmp_path_factory.mktemp("winds")
    for name, v, seed in (("low", 13.2, 5), ("high", 19.0, 6)):
        f = lidar.generate_field(field_spec(tb, Scenario(v, "B", seed, duration=16.0)), seed)
        f.save(d / f"{name}.bts")
    return d


def _raw(files: Path, **lc) -> dict:
    return {"name": "files", "transient": 2, "turbine": "nrel5mw",
            "controllers": ["baseline", "coleman-ipc"],
            "wind_distribution": {"kind": "rayleigh", "mean": 10},
            "load_cases": [{"dlc": "1.2", "duration": 12,
                            "wind_files": ["low.bts", {"file": "high.bts", "wind": 20}],
                            **lc}]}


def _load(files: Path, tmp_path: Path, **lc):
    import yaml

    p = files / f"spec-{tmp_path.name}.yaml"
    p.write_text(yaml.safe_dump(_raw(files, **lc)))
    return load_spec(p)


def test_a_campaign_runs_each_file_once_per_controller(files: Path, tmp_path: Path) -> None:
    from mpc_wt.campaign.aggregate import aggregate
    from mpc_wt.campaign.report import make_report

    spec = _load(files, tmp_path)
    cases = spec.cases()
    assert sorted(c.case_id for c in cases) == [
        "baseline__dlc1.2__file-high__v20", "baseline__dlc1.2__file-low__v13",
        "coleman-ipc__dlc1.2__file-high__v20", "coleman-ipc__dlc1.2__file-low__v13"]
    # the bin of a file without one is its header's mean hub-height wind, rounded
    low = next(c for c in cases if "low" in c.case_id)
    assert low.wind_mps == 13.0 and low.scenario.wind_mps is None
    assert low.scenario.wind_file == str((files / "low.bts").resolve())
    assert low.scenario.duration == 14.0 and low.duration == 12.0
    s = run_campaign(spec, tmp_path / "run", engine="serial", progress=False)
    assert (s.done, s.failed) == (4, 0)
    # the plant met the file's wind: the case is the run `mpcwt simulate --wind-file` makes
    res = ClosedLoopResult.load(tmp_path / "run" / "cases" / f"{low.case_id}.nc")
    assert res.meta["wind_file"] == low.scenario.wind_file
    assert main(["simulate", "--wind-file", str(files / "low.bts"), "--duration", "14",
                 "--out", str(tmp_path / "alone.nc")]) == 0
    alone = ClosedLoopResult.load(tmp_path / "alone.nc")
    for ch in ("rotor_speed", "pitch_1", "flap_moment_1"):
        assert np.array_equal(res.channel(ch), alone.channel(ch)), ch
    agg = aggregate(tmp_path / "run")
    assert sorted({r["wind_mps"] for r in agg["per_wind"]}) == [13.0, 20.0]
    assert not agg["incomplete"]
    text = make_report(tmp_path / "run").read_text()
    assert "2 wind files" in text


def test_an_edited_file_reruns_only_its_cases(files: Path, tmp_path: Path) -> None:
    d = tmp_path / "w"
    shutil.copytree(files, d, ignore=shutil.ignore_patterns("*.yaml"))
    before = {c.case_id: c.case_hash for c in _load(d, tmp_path).cases()}
    f = lidar.WindField.load(d / "high.bts")
    dataclasses.replace(f, u=f.u * 1.01).save(d / "high.bts")
    after = {c.case_id: c.case_hash for c in _load(d, tmp_path).cases()}
    changed = sorted(k for k in before if before[k] != after[k])
    assert changed == ["baseline__dlc1.2__file-high__v20", "coleman-ipc__dlc1.2__file-high__v20"]


@pytest.mark.parametrize("over, key, words", [
    ({"winds": [12]}, "load_cases[0].winds", "not with wind_files"),
    ({"seeds": 3}, "load_cases[0].seeds", "not with wind_files"),
    ({"condition": "etm"}, "load_cases[0].condition", "not with wind_files"),
    ({"turbulence": ["A", "B"]}, "load_cases[0].turbulence", "one class"),
    ({"wind_files": []}, "load_cases[0].wind_files", "non-empty list"),
    ({"wind_files": ["nowhere.bts"]}, "load_cases[0].wind_files[0]", "no such file"),
    ({"wind_files": ["low.txt"]}, "load_cases[0].wind_files[0]", ".bts"),
    ({"wind_files": [{"wind": 12}]}, "load_cases[0].wind_files[0].file", "missing"),
    ({"wind_files": [{"file": "low.bts", "wind": -3}]}, "load_cases[0].wind_files[0].wind",
     "> 0"),
    ({"wind_files": ["low.bts"], "duration": 60}, "load_cases[0].wind_files[0]",
     "holds"),
    ({"wind_files": ["low.bts", "low.bts"]}, "load_cases[0].wind_files", "same name"),
])
def test_bad_wind_file_entries_name_the_key(files: Path, over: dict, key: str,
                                            words: str) -> None:
    raw = _raw(files)
    raw["load_cases"][0].update(over)
    with pytest.raises(SpecError) as err:
        spec_from_dict(raw, base=files)
    assert f"{key}:" in str(err.value) and words in str(err.value), str(err.value)


def test_a_broken_file_is_named(files: Path, tmp_path: Path) -> None:
    bad = tmp_path / "broken.bts"
    bad.write_bytes((files / "low.bts").read_bytes()[:100])
    raw = _raw(files)
    raw["load_cases"][0]["wind_files"] = [str(bad)]
    with pytest.raises(SpecError, match=r"wind_files\[0\]: .*broken\.bts"):
        spec_from_dict(raw, base=files)


def test_a_store_keeps_a_file_case(files: Path) -> None:
    """A file case's plain data goes through the store's JSON and back unchanged."""
    import json

    from mpc_wt.campaign.spec import Case

    spec = spec_from_dict(_raw(files), base=files)
    c = spec.cases()[0]
    back = Case.from_dict(json.loads(json.dumps(c.to_dict())))
    assert back == c and back.wind_mps == c.wind_mps
    with pytest.raises(ValueError, match="wind_mps must be None"):
        Scenario(12.0, wind_file=c.scenario.wind_file)

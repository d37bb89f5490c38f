"""Gain-table export (issue 7, item 6): every format read back, ROSCO DISCON lines, the CLI,
bad tables."""
from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest
import scipy.io

import linearize
from mpc_wt.baseline import tune_baseline
from mpc_wt.cli import main
from mpc_wt.export import (GainTableError, baseline_table, export, load_design, lqr_table,
                           read_rosco, save_design)
from mpc_wt.synthesis import design_lqr_family, design_pi_observer


@pytest.fixture(scope="module")
def base_doc(turbine: linearize.Turbine):
    return baseline_table(turbine, tune_baseline(turbine))


@pytest.fixture(scope="module")
def lqr_doc(turbine: linearize.Turbine):
    fam = linearize.linearize_family(turbine, [14.0, 18.0], config=linearize.PlantConfig.do())
    d = design_lqr_family(fam, state_weights={"rotor_speed": 5.0})
    return lqr_table(turbine, d, [design_pi_observer(m) for m in fam.models]), d


def test_rosco_lines_read_back(turbine, base_doc, tmp_path) -> None:
    g = tune_baseline(turbine)
    (path,) = export(base_doc, "rosco", tmp_path)
    r = read_rosco(path)
    ang = np.array(r["PC_GS_angles"])
    assert r["PC_GS_n"] == len(ang) and np.all(np.diff(ang) > 0)
    # ROSCO's gains act on (reference - measured): negative, and kp GK(theta) of ours
    np.testing.assert_allclose(r["PC_GS_KP"], -g.kp / (1 + ang / g.theta_k_rad), rtol=1e-7)
    np.testing.assert_allclose(r["PC_GS_KI"], -g.ki / (1 + ang / g.theta_k_rad), rtol=1e-7)
    assert r["VS_Rgn2K"] == pytest.approx(g.k_opt, rel=1e-7)
    assert r["VS_RtTq"] == pytest.approx(g.rated_torque, rel=1e-7)
    assert r["VS_RefSpd"] == pytest.approx(g.rated_gen_speed_rad_s, rel=1e-7)
    assert r["PC_RefSpd"] == r["VS_RefSpd"]
    # NREL 5-MW (Jonkman et al. 2009, table 1-1 / 7-1): 94.4 % efficiency, 43 093.55 N m
    # rated torque, 1173.7 rpm rated generator speed, 8 deg/s pitch rate
    assert r["VS_GenEff"] == pytest.approx(94.4, abs=1e-6)
    assert r["VS_RtTq"] == pytest.approx(43093.55, rel=1e-5)
    assert r["VS_RefSpd"] == pytest.approx(1173.7 * math.pi / 30, rel=1e-4)
    assert r["PC_MaxRat"] == pytest.approx(math.radians(8.0), rel=1e-7)
    assert r["PC_MinRat"] == -r["PC_MaxRat"]


def test_json_csv_mat_read_back(lqr_doc, tmp_path) -> None:
    doc, designs = lqr_doc
    (pj,) = export(doc, "json", tmp_path)
    assert json.loads(pj.read_text()) == json.loads(json.dumps(doc))
    sched, mats = export(doc, "csv", tmp_path)
    lines = sched.read_text().splitlines()
    assert lines[0].startswith("# mpc-wt gain table, schema_version 1, kind lqr")
    rows = list(csv.reader(lines[1:]))
    assert rows[0][0] == "wind_speed [m/s]" and "x0_rotor_speed [rad/s]" in rows[0]
    np.testing.assert_array_equal(np.array(rows[1:], dtype=float),
                                  np.array(doc["schedule"]["rows"]))
    long = list(csv.DictReader(mats.read_text().splitlines()[1:]))
    k = [r for r in long if r["matrix"] == "K" and r["point"] == "1"
         and r["row"] == "pitch_ref_2" and r["col"] == "rotor_speed"]
    assert len(k) == 1 and float(k[0]["value"]) == designs[1].K[1, designs[1].states.index(
        "rotor_speed")]
    assert k[0]["unit"] == "rad/(rad/s)"
    (pm,) = export(doc, "mat", tmp_path)
    m = scipy.io.loadmat(pm)
    np.testing.assert_array_equal(m["K"], np.array([d.K for d in designs]))
    np.testing.assert_array_equal(m["s_wind_speed"].ravel(), [14.0, 18.0])
    assert int(m["schema_version"][0, 0]) == 1 and m["L2"].shape[0] == 2


def test_bad_tables_are_refused(base_doc, lqr_doc, tmp_path) -> None:
    with pytest.raises(GainTableError, match="does not exist"):
        load_design(tmp_path / "nothing")
    (tmp_path / "bad").mkdir()
    (tmp_path / "bad" / "design.json").write_text("{not json")
    with pytest.raises(GainTableError, match="not valid JSON"):
        load_design(tmp_path / "bad")
    future = dict(base_doc, schema_version=99)
    (tmp_path / "bad" / "design.json").write_text(json.dumps(future))
    with pytest.raises(GainTableError, match="schema_version 99"):
        load_design(tmp_path / "bad")
    short = json.loads(json.dumps(base_doc))
    short["schedule"]["rows"][0].pop()
    with pytest.raises(GainTableError, match="differ in length"):
        save_design(short, tmp_path / "x")
    with pytest.raises(GainTableError, match="rosco format holds a PI pitch schedule"):
        export(lqr_doc[0], "rosco", tmp_path)
    with pytest.raises(ValueError, match="format must be one of"):
        export(base_doc, "xlsx", tmp_path)


def test_cli_design_and_export(tmp_path, capsys) -> None:
    out = tmp_path / "ts"
    assert main(["design", "ts", "--wind", "14,20", "--reductions", "0,0.5",
                 "--out", str(out)]) == 0
    assert (out / "design.json").exists() and (out / "gains.png").stat().st_size > 1000
    doc = load_design(out)
    assert doc["kind"] == "ts" and doc["settings"]["certificate_ok"]
    assert doc["settings"]["wind_grid"] == [14.0, 20.0]
    assert np.asarray(doc["matrices"]["K"]["data"]).shape == (4, 2, 8)
    assert np.asarray(doc["matrices"]["L"]["data"]).shape == (4, 8, 4)
    for fmt in ("csv", "json", "mat"):
        assert main(["export", str(out), "--format", fmt]) == 0
    assert main(["export", str(out), "--format", "rosco"]) == 2
    assert "rosco format holds a PI pitch schedule" in capsys.readouterr().err
    assert main(["design", "lqr", "--wind", "14:15:1", "--weight", "rotor_speed",
                 "--out", str(tmp_path / "l")]) == 2
    assert "--weight takes NAME=VALUE" in capsys.readouterr().err
    assert main(["design", "ts", "--wind", "14,30", "--out", str(tmp_path / "t2")]) == 2
    assert "30" in capsys.readouterr().err
    assert main(["export", str(tmp_path / "none"), "--format", "csv"]) == 2

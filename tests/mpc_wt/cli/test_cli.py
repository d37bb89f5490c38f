"""The mpcwt command line: output formats, files written, errors on bad arguments."""
from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

from mpc_wt.cli import UsageError, main, parse_range


def test_trim_json_keys(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["trim", "--wind", "10:12:1", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [r["wind_mps"] for r in rows] == [10.0, 11.0, 12.0]
    for key in ("wind_mps", "pitch_deg", "rotor_speed_rpm", "gen_torque_Nm", "power_W",
                "thrust_N"):
        assert all(isinstance(r[key], float) for r in rows), key
    assert rows[2]["power_W"] == pytest.approx(5e6, rel=1e-9)


def test_trim_table_and_power_reference(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["trim", "--wind", "16", "--power-W", "4e6", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert rows[0]["power_W"] == pytest.approx(4e6, rel=1e-9)
    assert main(["trim", "--wind", "8,16"]) == 0
    out = capsys.readouterr().out
    assert "pitch [deg]" in out and len(out.strip().splitlines()) == 4


def test_cp_surface_csv_and_plot(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    csv_path, png = tmp_path / "cp.csv", tmp_path / "cp.png"
    assert main(["aero", "cp-surface", "--tsr", "6:9:0.5", "--pitch=-1:2:1", "--out",
                 str(csv_path), "--plot", str(png)]) == 0
    rows = list(csv.reader(csv_path.open()))
    assert len(rows) == 1 + 4 and len(rows[0]) == 1 + 7
    cp = np.array([[float(c) for c in r[1:]] for r in rows[1:]])
    assert 0.45 < cp.max() < 0.5
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "C_P max" in capsys.readouterr().out


def test_run_writes_table_and_plots(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The main job: steady outputs, the linear models, the baseline's gain tables
    (CSV, JSON, ROSCO), and baseline, baseline + LIDAR feedforward and MPC with LIDAR preview
    on one field, compared in one table (the MPC's QP times in it) and plots."""
    assert main(["run", "--out", str(tmp_path), "--duration", "30"]) == 0
    out = capsys.readouterr().out
    assert "rated wind speed" in out and out.count("\n") > 20
    for name in ("operating_points.csv", "operating_points.json", "cp_surface.csv",
                 "cp_surface.png", "operating_schedule.png", "linear_models.mat",
                 "gains/gains.json", "gains/gains_schedule.csv", "gains/DISCON.IN",
                 "baseline_run.nc", "baseline_lidar-ff_run.nc", "mpc-lidar_run.nc",
                 "comparison.json", "comparison.png", "cs_ellipses.png",
                 "psd_flap_moment_1.png"):
        assert (tmp_path / name).stat().st_size > 100, name
    rows = json.loads((tmp_path / "comparison.json").read_text())
    assert [r["controller"] for r in rows] == ["baseline", "baseline+lidar-ff", "mpc-lidar"]
    assert rows[2]["qp_median_ms"] > 0 and rows[0]["qp_median_ms"] is None
    # the largest power, rotor speed and torque over the window each row states, read back
    # from the run it names
    from mpc_wt.simulation.results import ClosedLoopResult

    for r in rows:
        res = ClosedLoopResult.load(tmp_path / r["file"])
        k = (res.t >= r["window_s"][0]) & (res.t <= r["window_s"][1])
        assert r["window_s"] == [3.0, 30.0]                 # a tenth of a 30 s run
        assert r["power_max_MW"] == pytest.approx(res.channel("gen_power")[k].max() / 1e6)
        assert r["rotor_speed_max_rpm"] == pytest.approx(
            res.channel("rotor_speed")[k].max() * 30 / np.pi)
        assert r["gen_torque_max_kNm"] == pytest.approx(res.channel("gen_torque")[k].max() / 1e3)
    assert "statistics over 3-30 s" in out and "P max" in out
    assert "mpc-lidar" in out and "QP med/p99" in out
    # the MPC line names its solver: DAQP, the default, is a core dependency
    assert rows[2]["qp_solver"] == "daqp"
    assert next(ln for ln in out.splitlines() if ln.startswith("mpc-lidar ")).endswith(" daqp")
    assert "main job's weights.pitch_rate=0.035" in out
    # every JSON file it wrote is standard JSON (no NaN or Infinity)
    def refuse(name):
        raise ValueError(f"not JSON: {name}")
    written = sorted(tmp_path.rglob("*.json"))
    assert len(written) >= 3
    for f in written:
        json.loads(f.read_text(), parse_constant=refuse)
    pts = json.loads((tmp_path / "operating_points.json").read_text())
    assert pts[0]["wind_mps"] == 3.0 and pts[-1]["wind_mps"] == 25.0


@pytest.mark.parametrize("argv, match", [
    (["trim", "--wind", "12:4:1"], "--wind must be START:STOP:STEP"),
    (["trim", "--wind", "1:4:1"], "wind_mps = 1 m/s is outside the operating range"),
    (["trim", "--wind", "abc"], "--wind must be"),
    (["trim", "--turbine", "/no/such/turbine.yaml"], "neither a packaged turbine"),
    (["trim", "--wind", "8", "--power-W", "9e6"], "power_W = 9e\\+06 W must be in"),
    (["aero", "cp-surface", "--tsr", "6:9:1"], "give --out FILE.csv and/or --plot"),
])
def test_errors_exit_2_with_a_message(argv: list[str], match: str,
                                      capsys: pytest.CaptureFixture[str]) -> None:
    assert main(argv) == 2
    import re

    assert re.search(match, capsys.readouterr().err)


def test_parse_range() -> None:
    np.testing.assert_allclose(parse_range("4:25:1", "--wind"), np.arange(4.0, 26.0))
    np.testing.assert_allclose(parse_range("0.1:0.3:0.1", "x"), [0.1, 0.2, 0.3])
    np.testing.assert_allclose(parse_range("3,5", "x"), [3.0, 5.0])
    with pytest.raises(UsageError, match="STEP > 0"):
        parse_range("1:2:0", "x")
    with pytest.raises(UsageError, match="finite"):
        parse_range("nan", "x")


def test_linearize_json_and_mat(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "models.mat"
    assert main(["linearize", "--wind", "12:13:1", "--frozen-wake", "--out", str(out),
                 "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [r["wind_mps"] for r in rows] == [12.0, 13.0]
    for key in ("wind_mps", "pitch_deg", "dP_dpitch_W_per_rad", "dQ_domega", "dT_dV", "modes"):
        assert key in rows[0], key
    names = {m["name"] for m in rows[0]["modes"]}
    assert {"tower fore-aft", "drivetrain torsion"} <= names
    assert all({"frequency_Hz", "damping_ratio"} <= set(m) for m in rows[0]["modes"])
    assert rows[0]["dP_dpitch_W_per_rad"] < 0 and rows[0]["dT_dV"] > 0
    import linearize

    fam = linearize.LinearModelFamily.load(out)
    assert fam.models[0].wake == "frozen" and fam.wind_mps.tolist() == [12.0, 13.0]


def test_linearize_bad_grid(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["linearize", "--wind", "12,11"]) == 2
    assert "strictly increasing" in capsys.readouterr().err
    assert main(["linearize", "--wind", "26"]) == 2
    assert "outside the operating range" in capsys.readouterr().err


def test_wind_generate_and_lidar_evaluate(tmp_path: Path,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    field = tmp_path / "f.bts"
    assert main(["wind", "generate", "--mean", "18", "--class", "A", "--seed", "1",
                 "--duration", "120", "--n", "16", "--out", str(field)]) == 0
    assert "wrote" in capsys.readouterr().out
    assert main(["lidar", "evaluate", "--field", str(field), "--json", "--plots",
                 str(tmp_path / "plots")]) == 0
    res = json.loads(capsys.readouterr().out)
    for key in ("coherence_bandwidth_Hz", "rms_preview_error_mps", "focus_m", "preview_time_s"):
        assert isinstance(res[key], float), key
    assert res["focus_m"] == 54.0 and res["preview_time_s"] == pytest.approx(3.0)
    assert res["lead_angle_deg"] == pytest.approx(217.8, abs=0.1)
    for png in ("lidar_coherence.png", "lidar_scan.png"):
        assert (tmp_path / "plots" / png).read_bytes()[:4] == b"\x89PNG"
    # idealized: the preview is the later blade wind
    assert main(["lidar", "evaluate", "--field", str(field), "--json", "--point",
                 "--no-los-error"]) == 0
    assert json.loads(capsys.readouterr().out)["rms_preview_error_mps"] < 1e-6
    # with wind evolution over the 54 m (a .bts carries no class: the intensity is measured)
    # even the idealized preview misses: sigma_u is 3.06 m/s and the evolution coherence at
    # 0.1 Hz is 0.55 (Simley and Pao), so the error is a good part of sigma_u (1.35 m/s on a
    # 1220 s field)
    assert main(["lidar", "evaluate", "--field", str(field), "--json", "--point",
                 "--no-los-error", "--evolution"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["evolution"] is True and 0.5 < res["rms_preview_error_mps"] < 3.06


def test_lidar_evaluate_bad_field(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "f.bts"
    bad.write_bytes(b"\x07\x00" + b"\x00" * 10)
    assert main(["lidar", "evaluate", "--field", str(bad)]) == 2
    assert "truncated .bts header" in capsys.readouterr().err


def test_simulate_and_assess(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    run = tmp_path / "run"
    assert main(["simulate", "--controller", "baseline", "--wind", "16", "--turbulence", "B",
                 "--duration", "60", "--out", str(run)]) == 0
    assert "mean power" in capsys.readouterr().out
    assert (tmp_path / "run.nc").is_file()
    assert main(["assess", str(tmp_path / "run.nc"), "--json", "--t-start", "10",
                 "--plots", str(tmp_path / "p")]) == 0
    rows = json.loads(capsys.readouterr().out)
    r = rows[0]
    for key in ("cs1", "cs2", "cs3", "cs4", "cs5", "pitch_travel_deg", "power_std_W",
                "energy_Wh"):
        assert isinstance(r[key], float), key
    assert r["channels"]["flap_moment_1"]["m"] == 10.0
    assert r["channels"]["tower_base_fa_moment"]["m"] == 4.0
    assert r["channels"]["tower_base_fa_moment"]["del"] > 0
    assert (tmp_path / "p" / "cs_ellipses.png").read_bytes()[:4] == b"\x89PNG"


def test_assess_csv_from_another_tool(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    t = np.arange(0, 100, 0.05)
    x = 1e6 * np.sin(2 * np.pi * 0.5 * t)
    p = tmp_path / "field.csv"
    p.write_text("Time,RootMyc1_[N-m]\n" + "\n".join(f"{a},{b}" for a, b in zip(t, x)))
    assert main(["assess", str(p), "--time-column", "Time", "--channels", "flap_moment_1",
                 "--m", "4", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)[0]["channels"]["flap_moment_1"]
    # analytic: 50 cycles of range 2e6 over 100 s, N_eq = 100: DEL = 2e6 (0.5)^(1/4)
    assert d["del"] == pytest.approx(2e6 * 0.5 ** 0.25, rel=0.01)
    # An OpenFAST name without a unit is taken in OpenFAST's (kN-m)
    p.write_text("Time,RootMyc1\n" + "\n".join(f"{a},{b}" for a, b in zip(t, x)))
    assert main(["assess", str(p), "--channels", "flap_moment_1", "--m", "4", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)[0]["channels"]["flap_moment_1"]
    assert d["del"] == pytest.approx(2e9 * 0.5 ** 0.25, rel=0.01)


@pytest.mark.parametrize("argv, match", [
    (["assess", "/no/run.nc"], "file not found"),
    (["simulate", "--controller", "lqr", "--wind", "18", "--out", "x"],
     "--controller: controller must be one of"),
    (["simulate", "--controller", "derate0", "--wind", "18", "--out", "x"],
     "derating in 'derate0' is 0 % of rated power; allowed: (0, 100] %"),
    (["simulate", "--controller", "apc", "--wind", "18", "--out", "x"],
     "--controller apc needs --apc-frequency"),
    (["simulate", "--controller", "apc", "--apc-frequency", "0.1", "--wind", "8",
      "--duration", "1", "--out", "x"], "above the power available at the mean wind 8"),
    (["simulate", "--controller", "apc", "--apc-frequency", "0.1", "--apc-offset", "0",
      "--wind", "18", "--duration", "1", "--out", "x"], "need offset >= amplitude"),
    (["simulate", "--controller", "baseline", "--loop-gain", "2", "--wind", "18", "--out", "x"],
     "--loop-gain/--keep-collective apply to the ibc controllers only"),
    (["design", "ibc", "--power-fraction", "1.5", "--out", "x"],
     "--power-fraction must be in (0, 1]"),
    (["simulate", "--controller", "baseline", "--horizon", "5", "--wind", "18", "--out", "x"],
     "not to --controller baseline"),
    (["simulate", "--controller", "mpc", "--design-wind-mps", "30", "--wind", "8",
      "--duration", "1", "--out", "x"], "design_wind_mps = 30 m/s is outside the turbine's "
                                         "operating range 3..25 m/s"),
    (["simulate", "--controller", "lqr-pio", "--apc-frequency", "0.1", "--wind", "18",
      "--out", "x"], "--apc-frequency applies to --controller ts and apc only"),
    (["simulate", "--controller", "ts", "--horizon", "5", "--wind", "18", "--out", "x"],
     "not to --controller ts"),
])
def test_simulate_assess_errors(argv, match: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(argv) == 2
    assert match in capsys.readouterr().err


def test_the_mpc_state_source_is_no_flag(capsys: pytest.CaptureFixture[str]) -> None:
    """The MPC's law estimates its state: there is no flag for the plant's true states."""
    with pytest.raises(SystemExit):
        main(["simulate", "--controller", "mpc", "--estimator", "full-state", "--wind", "18",
              "--out", "x"])
    assert "--estimator" in capsys.readouterr().err


def test_assess_unknown_channel(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    p = tmp_path / "a.csv"
    p.write_text("time,x\n0,1\n1,2\n2,1\n3,2\n")
    assert main(["assess", str(p), "--channels", "y"]) == 2
    assert "no channel 'y'" in capsys.readouterr().err


@pytest.mark.parametrize("controller", ["mpc", "mpc-lidar", "mpc-collective"])
def test_simulate_mpc_controllers(controller: str, tmp_path: Path,
                                  capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / f"{controller}.nc"
    assert main(["simulate", "--controller", controller, "--wind", "18", "--turbulence", "B",
                 "--duration", "20", "--out", str(out)]) == 0
    assert "mean power" in capsys.readouterr().out
    from mpc_wt.simulation.results import ClosedLoopResult

    r = ClosedLoopResult.load(out)
    assert r.meta["controller"] == controller and r.meta["mpc"]["horizon"] == 15
    assert np.all(r.controller["qp_fallback"] == 0)
    if controller == "mpc-collective":
        assert np.allclose(r.u[:, 0], r.u[:, 2])


@pytest.mark.parametrize("extra, meta", [
    (["--design-wind-mps", "17", "--horizon", "10"],
     {"estimator": "kalman", "design_winds_mps": [17.0, 17.0], "horizon": 10,
      "backend": "daqp", "formulation": "condensed"}),
    (["--horizon", "10"], {"estimator": "kalman", "design_winds_mps": [3.0, 25.0],
                           "horizon": 10}),
])
def test_simulate_mpc_options(extra: list[str], meta: dict, tmp_path: Path,
                              capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "run.nc"
    assert main(["simulate", "--controller", "mpc", "--wind", "17", "--turbulence", "B",
                 "--duration", "20", "--out", str(out), *extra]) == 0
    from mpc_wt.simulation.results import ClosedLoopResult

    r = ClosedLoopResult.load(out)
    for k, v in meta.items():
        assert r.meta["mpc"][k] == v, k
    assert np.all(r.controller["qp_fallback"] == 0)
    # the controller holds the rotor near rated speed (1.267 rad/s) through the gusts
    assert abs(r.x[r.t > 10, 2].mean() - 1.267) < 0.05


@pytest.mark.parametrize("controller, extra", [("lqr-pio", []),
                                               ("ts", ["--apc-frequency", "0.1"])])
def test_simulate_gain_controllers(controller: str, extra: list[str], tmp_path: Path,
                                   capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / f"{controller}.nc"
    assert main(["simulate", "--controller", controller, "--wind", "16", "--turbulence", "B",
                 "--duration", "20", "--out", str(out), *extra]) == 0
    from mpc_wt.simulation.results import ClosedLoopResult

    r = ClosedLoopResult.load(out)
    assert r.meta["controller"] == controller
    w = r.channel("rotor_speed")
    assert abs(w.mean() / 1.2671 - 1) < 0.03
    if controller == "ts":
        assert r.meta["ts"]["apc_frequency_Hz"] == 0.1
        assert r.channel("power_ref").min() < 0.4 * r.channel("power_ref").max()


@pytest.mark.parametrize("controller, extra", [("derate90+ibc", ["--loop-gain", "0.5"]),
                                               ("coleman-ipc", []),
                                               ("apc", ["--apc-frequency", "0.1"])])
def test_simulate_retrofit_controllers(controller: str, extra: list[str], tmp_path: Path,
                                       capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "run.nc"
    assert main(["simulate", "--controller", controller, "--wind", "16", "--turbulence", "B",
                 "--duration", "20", "--out", str(out), *extra]) == 0
    from mpc_wt.simulation.results import ClosedLoopResult

    r = ClosedLoopResult.load(out)
    assert r.meta["controller"] == controller
    assert abs(r.channel("rotor_speed").mean() / 1.2671 - 1) < 0.03
    if controller == "derate90+ibc":
        assert r.meta["ibc"]["loop_gain_1p"] == 0.5 and r.meta["gains"]["power_fraction"] == 0.9
        assert abs(r.channel("gen_power").mean() / 4.5e6 - 1) < 0.03
        assert np.abs(r.channel("ibc_pitch_1")).max() > 0
    if controller == "apc":
        assert r.meta["apc"]["frequency_Hz"] == 0.1
        assert r.channel("power_reference").min() < 0.4 * 5e6


def test_design_ibc_and_export(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    d = tmp_path / "ibc"
    assert main(["design", "ibc", "--power-fraction", "0.9", "--out", str(d)]) == 0
    assert (d / "gains.png").stat().st_size > 0
    assert main(["export", str(d), "--format", "csv"]) == 0
    rows = list(csv.reader((d / "gains_schedule.csv").open()))
    assert rows[1][:3] == ["wind_speed [m/s]", "pitch [rad]", "gain [rad/(N m)]"]
    assert all(float(r[2]) > 0 for r in rows[2:])
    doc = json.loads((d / "design.json").read_text())
    assert doc["settings"]["power_fraction"] == 0.9


def test_cp_surface_has_distinct_rows_below_zero_pitch(tmp_path: Path,
                                                      capsys: pytest.CaptureFixture[str]) -> None:
    """A past defect: the rows below the actuator's 0 deg were copies of the 0 deg row."""
    out = tmp_path / "cp.csv"
    assert main(["aero", "cp-surface", "--pitch=-4:20:1", "--tsr", "6:10:1", "--out",
                 str(out)]) == 0
    rows = list(csv.reader(out.open()))[1:]
    cp = {float(r[0]): np.array(r[1:], float) for r in rows}
    below = [cp[b] for b in (-4.0, -3.0, -2.0, -1.0, 0.0)]
    for a, b in zip(below, below[1:]):
        assert np.abs(a - b).max() > 1e-3
    # the reported maximum is a real row, near 0 deg (ROSCO's table: 0.4659 at TSR 7.5, 0 deg)
    text = capsys.readouterr().out
    assert "pitch -4.00 deg" not in text and "pitch 0.00 deg" in text


def test_assess_csv_without_known_channels_names_what_it_found(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A past defect: exit 0 with an empty assessment before; now exit 2 naming the
    columns found and the channels expected, and --channels takes any numeric column.
    OpenFAST names are channels we know (TwrBsMyt -> tower_base_fa_moment, kN-m -> N m)."""
    p = tmp_path / "field.csv"
    t = np.arange(0, 50, 0.1)
    p.write_text("time,strain_gauge_3,power_kw\n" + "\n".join(
        f"{a},{1e3 * np.sin(a)},{5e3}" for a in t))
    assert main(["assess", str(p)]) == 2
    err = capsys.readouterr().err
    assert "no column is a load channel we know" in err and "'strain_gauge_3'" in err
    assert "tower_base_fa_moment" in err
    assert main(["assess", str(p), "--channels", "strain_gauge_3", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)[0]["channels"]["strain_gauge_3"]
    assert d["m"] == 4.0 and d["del"] > 0
    p.write_text("time,TwrBsMyt,GenPwr\n" + "\n".join(
        f"{a},{1e3 * np.sin(a)},{5e3}" for a in t))
    assert main(["assess", str(p), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)[0]
    assert out["channels"]["tower_base_fa_moment"]["m"] == 4.0
    assert out["power_mean_W"] == pytest.approx(5e6)


def test_linearize_at_a_given_operating_point(capsys: pytest.CaptureFixture[str]) -> None:
    # OpenFAST's FASTLin.lin point: 11 m/s, 11.81 rpm, pitch 0
    assert main(["linearize", "--wind", "11", "--rotor-speed-rpm", "11.81", "--pitch-deg", "0",
                 "--json"]) == 0
    row = json.loads(capsys.readouterr().out)[0]
    assert row["rotor_speed_rpm"] == pytest.approx(11.81, rel=1e-12)
    assert row["pitch_deg"] == 0.0
    assert main(["linearize", "--wind", "11:12:1", "--rotor-speed-rpm", "11.81",
                 "--pitch-deg", "0"]) == 2
    assert "go together, with a single --wind" in capsys.readouterr().err


def test_wind_generate_iec_condition(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``mpcwt wind generate --condition eog --mean 13`` writes the deterministic
    field and its plot; the EOG magnitude printed is eq 16's (class I A, z_hub 90 m, D 126 m:
    3.3 * 0.16 (0.75 * 13 + 5.6) / 1.3 = 6.2345 m/s); the field loads back with the gust."""
    import lidar

    out, png = tmp_path / "eog.npz", tmp_path / "eog.png"
    assert main(["wind", "generate", "--condition", "eog", "--mean", "13", "--cut-in", "3",
                 "--cut-out", "25", "--n", "8", "--out", str(out), "--plot", str(png)]) == 0
    assert "gust_mps 6.234" in capsys.readouterr().out
    assert png.read_bytes()[:4] == b"\x89PNG"
    f = lidar.WindField.load(out)
    assert f.meta["condition"] == "eog"
    hub = f.sample(f.t, np.zeros_like(f.t), np.full_like(f.t, 90.0))
    assert (hub - hub[0]).max() == pytest.approx(0.74 * 6.2345, abs=5e-4)   # the same at
    # every height; the grid's hub point is interpolated on the power-law profile
    assert main(["wind", "generate", "--condition", "eog", "--mean", "26", "--cut-out", "25",
                 "--out", str(out)]) == 2
    assert ("--condition eog: mean_speed 26 m/s is above the turbine's cut-out 25 m/s"
            in capsys.readouterr().err)
    assert main(["wind", "generate", "--condition", "ecd", "--mean", "13", "--iec-class", "IV",
                 "--out", str(out)]) == 2
    assert "turbine_class must be one of ['I', 'II', 'III']" in capsys.readouterr().err


def test_simulate_iec_event_with_supervisor(tmp_path: Path,
                                            capsys: pytest.CaptureFixture[str]) -> None:
    """``mpcwt simulate --condition eog --grid-loss-at`` runs a gust with a grid loss
    under the supervisor: the result records the condition, the trip (state 3, grid loss) at
    the first controller step from 40 s, and zero generator torque after it."""
    from mpc_wt.simulation.results import ClosedLoopResult

    out = tmp_path / "eog.nc"
    assert main(["simulate", "--wind", "13.4", "--condition", "eog", "--event-at", "35",
                 "--duration", "50", "--overspeed", "1.25", "--grid-loss-at", "40",
                 "--out", str(out)]) == 0
    res = ClosedLoopResult.load(out)
    assert res.meta["condition"] == "eog" and res.meta["event_at_s"] == 35.0
    state = res.channel("supervisor_state")
    trip = res.t[np.flatnonzero(state > 0)[0]]
    assert state.max() == 3 and 40.0 - 1e-9 <= trip <= 40.1 + 1e-9
    assert np.all(res.channel("gen_torque")[res.t > trip + 0.05] == 0.0)
    capsys.readouterr()
    assert main(["simulate", "--wind", "26", "--condition", "eog", "--out", str(out)]) == 2
    assert ("--condition eog: mean_speed 26 m/s is above the turbine's cut-out 25 m/s"
            in capsys.readouterr().err)
    assert main(["simulate", "--wind", "13", "--condition", "eog", "--turbulence", "steady",
                 "--out", str(out)]) == 2
    assert "needs an IEC turbulence category" in capsys.readouterr().err
    assert main(["simulate", "--wind", "13", "--overspeed", "0.8", "--out", str(out)]) == 2
    assert "--overspeed: overspeed must be a fraction of rated" in capsys.readouterr().err
    assert main(["simulate", "--wind", "13", "--shutdown-at", "-1", "--out", str(out)]) == 2
    assert "--shutdown-at: shutdown_at must be a finite time >= 0 s" in capsys.readouterr().err

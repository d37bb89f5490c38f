"""The other turbines everywhere a turbine is taken: the IEA-15-240-RWT in the main job
and a closed loop, OpenFAST decks on the command line, ROSCO tables written by the CLI."""
from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest
import rosco  # in the test extras

import linearize
from mpc_wt.cli import main
from mpc_wt.run import run_controller
from mpc_wt.simulation.scenario import Scenario

CASES = Path(rosco.__file__).parents[1] / "Examples" / "Test_Cases"


@pytest.mark.parametrize("duration", [200.0, pytest.param(600.0, marks=pytest.mark.slow)])
def test_iea15mw_baseline_regulates(duration: float) -> None:
    """600 s (200 s in the quick suite) at 18 m/s, IEC class A turbulence, seed 1, the tuned
    baseline on the IEA-15 (direct drive, rotor 242 m: the turbulence grid grows to 266 m, 56
    points): mean electrical power within 1 % of 15 MW after the first 60 s (measured +0.01 %
    over 600 s and over 200 s), and no actuator limit exceeded: pitch inside [PC_MinPit,
    PC_MaxPit], pitch rate <= PC_MaxRat = 2.0 deg/s (measured 1.72 over 600 s), generator
    torque <= VS_MaxTq = 21.77 MN m (21.35), torque rate <= VS_MaxRat = 4.5 MN m/s (1.05)."""
    t = linearize.load_turbine("iea15mw")
    res = run_controller(t, "baseline", Scenario(18.0, "A", 1, duration))
    keep = res.t >= 60.0
    assert abs(res.channel("gen_power")[keep].mean() / 15e6 - 1) <= 0.01
    pa, gen = t.pitch_actuator, t.generator
    for b in (1, 2, 3):
        pitch = res.channel(f"pitch_{b}")
        assert pa.min_pitch_rad - 1e-9 <= pitch.min() and pitch.max() <= pa.max_pitch_rad
        assert np.abs(res.channel(f"pitch_rate_{b}")).max() <= pa.max_rate_rad_s * (1 + 1e-9)
    tq = res.channel("gen_torque")
    assert tq.max() <= gen.max_torque * (1 + 1e-9) and tq.min() >= gen.min_torque - 1e-6
    assert np.abs(np.diff(tq) / np.diff(res.t)).max() <= gen.max_torque_rate * (1 + 1e-6)


def test_trim_of_a_deck_from_the_cli(capsys: pytest.CaptureFixture[str]) -> None:
    """``mpcwt trim --turbine PATH.fst --json`` on the BAR_10 deck: 5 MW in region 3, the
    region-3 pitch of test_openfast.py's Cp-table reference (15 m/s: 14.22 deg +- 1)."""
    fst = CASES / "BAR_10" / "BAR_10.fst"
    assert main(["trim", "--turbine", str(fst), "--wind", "15", "--json"]) == 0
    row = json.loads(capsys.readouterr().out)[0]
    assert row["power_W"] == pytest.approx(5e6, rel=1e-9)
    assert abs(row["pitch_deg"] - 14.22) <= 1.0
    assert main(["trim", "--turbine", str(fst), "--wind", "15", "--report"]) == 0
    out = capsys.readouterr().out
    assert "BAR_10_ElastoDyn.dat:" in out and "default:" in out


def test_main_job_steady_part_on_iea15mw(tmp_path: Path, capsys) -> None:
    """``mpcwt run --turbine iea15mw`` (steady part; the closed loop is the test above):
    the operating table from cut-in to cut-out, 15 MW in region 3, the plots."""
    assert main(["run", "--turbine", "iea15mw", "--duration", "0", "--out", str(tmp_path)]) == 0
    rows = json.loads((tmp_path / "operating_points.json").read_text())
    assert [r["wind_mps"] for r in rows] == list(np.arange(3.0, 25.5, 1.0))
    assert rows[-1]["power_W"] == pytest.approx(15e6, rel=1e-9)
    assert rows[0]["region"] == "1.5" and rows[0]["rotor_speed_rpm"] == pytest.approx(5.0, abs=1e-4)
    assert (tmp_path / "operating_schedule.png").stat().st_size > 10_000
    assert "rated wind speed 10.4" in capsys.readouterr().out


def test_cp_surface_rosco_format_is_read_by_rosco(tmp_path: Path, rosco_utilities) -> None:
    """``mpcwt aero cp-surface --format rosco``: ROSCO's reader takes it; C_P max of the
    IEA-15 at shear 0.2 within 0.02 of the ROSCO table's 0.4704."""
    load_from_txt = rosco_utilities.load_from_txt
    out = tmp_path / "Cp_Ct_Cq.txt"
    assert main(["aero", "cp-surface", "--turbine", "iea15mw", "--format", "rosco", "--out",
                 str(out), "--tsr", "3:12:0.5", "--pitch=-2:10:1", "--shear", "0.2"]) == 0
    pitch, tsr, cp, ct, cq = load_from_txt(str(out))
    assert cp.shape == (tsr.size, pitch.size) == (19, 13)
    assert abs(cp.max() - 0.4704) <= 0.02
    np.testing.assert_allclose(np.degrees(pitch), np.arange(-2.0, 10.5, 1.0), atol=1e-12)


def test_cp_surface_rosco_format_has_roscos_layout(tmp_path: Path) -> None:
    """``mpcwt aero cp-surface --format rosco`` at the line positions of ROSCO's shipped
    NREL-5MW table (tests/data/Cp_Ct_Cq.NREL5MW.txt: pitch vector on line 5, TSR on line 7,
    the C_P block from line 13, C_T four lines after C_P's end); C_P max of the IEA-15 at
    shear 0.2 within 0.02 of the ROSCO table's 0.4704."""
    out = tmp_path / "Cp_Ct_Cq.txt"
    assert main(["aero", "cp-surface", "--turbine", "iea15mw", "--format", "rosco", "--out",
                 str(out), "--tsr", "3:12:0.5", "--pitch=-2:10:1", "--shear", "0.2"]) == 0
    lines = out.read_text().splitlines()
    ref = (Path(__file__).parents[1] / "data" / "Cp_Ct_Cq.NREL5MW.txt").read_text().splitlines()
    assert [ln.startswith("#") for ln in lines[:13]] == [ln.startswith("#") for ln in ref[:13]]
    np.testing.assert_allclose(np.array(lines[4].split(), float), np.arange(-2.0, 10.5, 1.0))
    np.testing.assert_allclose(np.array(lines[6].split(), float), np.arange(3.0, 12.25, 0.5))
    cp = np.array([ln.split() for ln in lines[12:31]], float)
    assert cp.shape == (19, 13) and abs(cp.max() - 0.4704) <= 0.02
    assert [ln.strip() for ln in lines[31:35]] == ["", "", lines[33].strip(), ""]
    assert "Thrust" in lines[33] and "Thrust" in ref[40]
    ct = np.array([ln.split() for ln in lines[35:54]], float)
    assert ct.shape == (19, 13) and 0.0 < ct.max() < 1.5


def test_cp_surface_rosco_format_needs_out(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["aero", "cp-surface", "--format", "rosco", "--plot", "x.png"]) == 2
    assert "--format rosco needs --out FILE.txt" in capsys.readouterr().err


def test_campaign_hash_of_a_deck_follows_what_was_read(tmp_path: Path) -> None:
    """A campaign names its turbine by a hash; for a deck that is the content of what the
    loader read (the IEA-15 deck reads files outside its folder): two copies hash alike, a
    changed nacelle mass does not."""
    import shutil

    from mpc_wt.campaign.spec import turbine_files_hash

    src = CASES / "NREL-5MW"
    a, b = tmp_path / "a", tmp_path / "b"
    for d in (a, b):
        shutil.copytree(src, d, ignore=shutil.ignore_patterns("*.inp", "Ice*", "*BeamDyn*"))
    assert turbine_files_hash(str(a / "NREL-5MW.fst"))[1] == \
        turbine_files_hash(str(b / "NREL-5MW.fst"))[1]
    ed = b / "NRELOffshrBsline5MW_Onshore_ElastoDyn.dat"
    ed.write_text(ed.read_text().replace("     240000   NacMass", "     242000   NacMass"))
    assert turbine_files_hash(str(a / "NREL-5MW.fst"))[1] != \
        turbine_files_hash(str(b / "NREL-5MW.fst"))[1]


def test_a_geared_deck_holds_its_electrical_rated_power() -> None:
    """The rosco wheel's NREL-2.8-127 deck: gearbox efficiency 95.5 % (ElastoDyn GBoxEff),
    generator 93.95 % (ServoDyn GenEff). OpenFAST's electrical power is GenEff x generator
    torque x generator speed, and the gearbox's loss brakes the rotor; the deck's own ROSCO
    file holds VS_RtPwr = 2.8 MW with VS_RtTq = VS_RtPwr / (VS_GenEff omega_g) = 24248.5 N m.
    mpc-wt's trim and the baseline it ships hold the same: the region-3 torque within 1 N m of
    the file's VS_RtTq, and 2.8 MW electrical within 0.5 % over 30-60 s of steady 16 m/s (it
    made 95.5 % of it, silently, when the gearbox's loss was counted in the generator)."""
    fst = CASES / "NREL_2p8_127" / "NREL-2p8-127.fst"
    t = linearize.load_turbine(fst)
    op = linearize.trim(t, 16.0)
    assert op.gen_torque == pytest.approx(2.42485e4, abs=1.0)        # the deck's VS_RtTq
    assert op.power == pytest.approx(2.8e6, rel=1e-9)
    res = run_controller(t, "baseline", 16.0, duration=60.0, turbulence="steady")
    late = res.t >= 30.0
    assert res.channel("gen_power")[late].mean() == pytest.approx(2.8e6, rel=0.005)
    assert res.channel("gen_torque")[late].mean() == pytest.approx(2.42485e4, rel=0.005)


def test_a_main_job_that_cannot_trim_says_why_and_leaves_no_folder(tmp_path, capsys) -> None:
    """``mpcwt run`` on a deck whose trim the torque limit blocks (the IEA-15 with fine and
    minimum pitch at -4 deg and no minimum-pitch schedule in a copy): exit 2, the error names
    VS_MaxTq's file, line and key,
    and the output folder it would have made is not left behind empty."""
    import shutil

    src = Path(linearize.__file__).parent / "data" / "iea15mw"
    shutil.copytree(src, tmp_path / "iea15")
    dis = tmp_path / "iea15" / "IEA-15-240-RWT-Monopile" / "IEA-15-240-RWT-Monopile_DISCON.IN"
    text = dis.read_text()
    for key in ("PC_FinePit", "PC_MinPit"):
        text = text.replace(f"0.000000000000      ! {key}", f"-0.069813170080     ! {key}")
    text = text.replace("1                   ! PS_Mode", "0                   ! PS_Mode")
    dis.write_text(text)
    out = tmp_path / "job"
    assert main(["run", "--turbine", str(tmp_path / "iea15" / "turbine.yaml"), "--duration",
                 "0", "--out", str(out)]) == 2
    assert "DISCON.IN:84 VS_MaxTq" in capsys.readouterr().err
    assert not out.exists()


IEA22 = (Path(__file__).parents[1] / "data" / "iea22" / "OpenFAST" / "IEA-22-280-RWT-Monopile"
         / "IEA-22-280-RWT-Monopile.fst")


def test_the_iea22_deck_as_published_loads_and_says_what_blocks_its_trim() -> None:
    """The IEA-22-280-RWT monopile deck as published (tests/data/iea22): it loads (22 MW,
    the monopile clamped at the tower base, BeamDyn blades read from ElastoDyn's blade file,
    each said in the report's notes). Without its minimum-pitch schedule, at the deck's fine
    pitch of -4.01 deg, its trim above rated wind stops on the generator's torque limit, and
    the error names VS_MaxTq's and PC_FinePit's file, line and key and the torque that would
    trim it."""
    t = linearize.load_turbine(IEA22)
    assert t.operation.rated_power == 22e6
    notes = " ".join(t.report.notes)
    assert "clamped at its base" in notes and "BeamDyn" in notes
    with pytest.raises(linearize.TrimError) as err:
        linearize.trim(dataclasses.replace(t, min_pitch=None), 11.0)
    msg = str(err.value)
    assert "IEA-22-280-RWT_DISCON.IN:84 VS_MaxTq" in msg
    assert "fine pitch -4.01 deg (IEA-22-280-RWT_DISCON.IN:68 PC_FinePit)" in msg
    assert "a torque limit of at least" in msg


def _discon_row(path: Path, key: str) -> np.ndarray:
    """The numbers of a DISCON.IN line, found by its key (read here, not by the loader)."""
    line = next(ln for ln in path.read_text().splitlines() if f"! {key} " in ln
                or ln.split("!")[-1].split()[:1] == [key])
    return np.array([float(x) for x in line.split("!")[0].split()])


#: IEA-22-280-RWT_tabular.xlsx, sheet "Rotor Performance - WISDEM" (IEAWindSystems/IEA-22-280-RWT
#: @ 57979ec, Documentation/): wind [m/s] and collective pitch [deg] above rated (the rigid
#: rotor at 6.854 rpm); the sheet "Rotor Performance - OpenFAST" (elastic blades, 7.061 rpm)
#: gives 14.42 deg at 18 m/s
IEA22_WISDEM_REGION3 = ((12.848, 9.085), (14.778, 12.392), (16.921, 15.351),
                        (19.231, 18.132), (21.661, 20.775), (24.16, 23.281))


def test_the_iea22_deck_as_published_trims_on_its_minimum_pitch_table() -> None:
    """The IEA-22 deck as published trims from cut-in to cut-out on its minimum-pitch
    schedule (ROSCO's PS_BldPitchMin over PS_WindSpeeds, PS_Mode 1; the report names the
    lines): below rated the trim's pitch is the table's at each of its own points (the file
    read here), never the fine pitch of -4.01 deg; above rated every pitch lies within 1 deg
    of the repository's published WISDEM table (measured: at most 0.4 deg); the electrical
    power is rated (22 MW, ROSCO's VS_RtPwr) through the generator's efficiency of 0.954; no
    generator torque above VS_MaxTq."""
    t = linearize.load_turbine(IEA22)
    dis = IEA22.parent / "IEA-22-280-RWT_DISCON.IN"
    assert "IEA-22-280-RWT_DISCON.IN:153 PS_BldPitchMin" in t.report.source(
        "minimum-pitch schedule")
    winds, pitches = _discon_row(dis, "PS_WindSpeeds"), _discon_row(dis, "PS_BldPitchMin")
    rated = linearize.rated_wind_speed(t)
    for v, b in zip(winds, pitches):
        if v < rated - 0.3:
            op = linearize.trim(t, float(v))
            assert op.pitch_rad == pytest.approx(b, abs=1e-12)
            assert op.region in ("1.5", "2", "2.5")
    for v, b_deg in IEA22_WISDEM_REGION3:
        op = linearize.trim(t, v)
        assert op.region == "3"
        assert abs(op.pitch_deg - b_deg) < 1.0
        assert op.power == pytest.approx(22e6, rel=1e-9)
        assert op.gen_torque <= 3.43057e7
    for v in np.arange(3.0, 25.5, 1.0):
        op = linearize.trim(t, float(v))
        assert op.pitch_rad >= linearize.region2_pitch(t, float(v)) - 1e-12 > -0.06


def test_a_minimum_pitch_table_is_checked() -> None:
    """A minimum-pitch table of too few points, of winds not increasing or of pitches past
    90 deg is refused naming what is allowed; between its points it interpolates linearly
    and beyond them it holds its end values (hand-worked)."""
    table = linearize.MinPitchTable((4.0, 8.0), (0.02, 0.06))
    assert table.at(6.0) == pytest.approx(0.04)
    assert table.at(2.0) == 0.02 and table.at(30.0) == 0.06
    for winds, pitches in (((4.0,), (0.0,)), ((8.0, 4.0), (0.0, 0.0)),
                           ((4.0, 8.0), (0.0,)), ((4.0, 8.0), (0.0, 2.0)),
                           ((4.0, math.nan), (0.0, 0.0))):
        with pytest.raises(ValueError, match="MinPitchTable"):
            linearize.MinPitchTable(winds, pitches)


def test_the_dofs_a_deck_switches_off_are_rigid_in_the_plant() -> None:
    """ElastoDyn's drivetrain switch is the plant's: the IEA-22 deck's drivetrain (DrTrDOF
    False with DTTorSpr 1e12 N m/rad, a 117 Hz spring the plant's step cannot integrate) is
    one inertia, so its plant passes the step check; the NREL-2.8-127 deck's drivetrain is
    rigid and its tower switches (TwFADOF1, TwSSDOF1 False) are noted, the tower left
    flexible; the rosco wheel's NREL 5-MW deck's DOFs all flexible. The report names each
    switch's file and line. In a closed loop on the NREL-2.8-127 the generator turns at
    exactly GBRatio = 97 times the rotor."""
    t22 = linearize.load_turbine(IEA22)
    assert t22.rigid_dofs == ("drivetrain",)
    assert "IEA-22-280-RWT_ElastoDyn.dat:12 DrTrDOF" in t22.report.source(
        "rigid degrees of freedom")
    p22 = linearize.plant_params(t22)
    assert not p22.dof("drivetrain") and p22.dof("generator")
    linearize.check_plant_step(p22, 1 / 80)
    t28 = linearize.load_turbine(CASES / "NREL_2p8_127" / "NREL-2p8-127.fst")
    assert t28.rigid_dofs == ("drivetrain",)
    assert any("TwFADOF1" in n and "TwSSDOF1" in n and "stay flexible" in n
               for n in t28.report.notes)
    assert linearize.load_turbine(CASES / "NREL-5MW" / "NREL-5MW.fst").rigid_dofs == ()
    res = run_controller(t28, "baseline", 8.0, duration=10.0, turbulence="steady")
    assert t28.drivetrain.gearbox_ratio == 97.0                      # the deck's GBRatio
    names = linearize.STATE_NAMES
    rotor, gen = res.x[:, names.index("rotor_speed")], res.x[:, names.index("gen_speed")]
    np.testing.assert_allclose(gen, 97.0 * rotor, rtol=1e-12)


def _deck_values(path: Path, key: str) -> list[float]:
    """A ``values ! key`` line's values, read from the file as published."""
    for line in path.read_text().splitlines():
        head, bang, tail = line.partition("!")
        if bang and tail.split()[:1] == [key]:
            return [float(w) for w in head.split()]
    raise AssertionError(f"no {key} in {path}")


def test_lqr_pio_on_the_iea22_pitches_no_lower_than_its_minimum_pitch_table() -> None:
    """LQR-PIO designed from the IEA-22 deck as published, 200 s at 12 m/s, class IA, shear
    0.2, seed 2: the blades never pitch below the deck's lowest ``PS_BldPitchMin`` (-1.28 deg,
    read from the file), the law's lowest pitch being the baseline's minimum-pitch schedule on
    its filtered speed. Its gains alone took the pitch to the actuator's limit, the deck's fine
    pitch -4.01 deg, in the lulls near rated: in the 300-s case of the IEA-22 table it reached
    -4.01 deg at 171 s and the rotor 1.36 x rated speed at 286 s (the supervisor's stop), with
    the floor 0.62 deg and 1.09 x rated."""
    t = linearize.load_turbine(IEA22)
    res = run_controller(t, "lqr-pio", Scenario(12.0, "A", 2, 200.0, shear_exponent=0.2,
                                                iec_class="I"))
    pitch = np.column_stack([res.channel(f"pitch_{i}") for i in (1, 2, 3)])
    lowest = min(_deck_values(IEA22.parent / "IEA-22-280-RWT_DISCON.IN", "PS_BldPitchMin"))
    assert pitch.min() >= lowest - math.radians(0.01)
    assert res.channel("rotor_speed").max() <= 1.1 * t.operation.rated_rotor_speed_rad_s


@pytest.mark.parametrize("kind", ["ts", "lqr-pio"])
def test_the_model_based_kinds_pitch_no_lower_than_fine_on_a_deck_whose_actuator_goes_lower(
        kind: str) -> None:
    """The rosco wheel's NREL-2.8-127: fine pitch 0 deg (its ``PC_FinePit``), the actuator's
    limit -10 deg (``PC_MinPit``), so a law's lowest pitch must be the fine pitch, not the
    actuator's. 90 s at 8 m/s (region 2, class A, seed 1): TS's and LQR-PIO's blades never
    below the file's fine pitch. The laws took the actuator's limit where the baseline's
    minimum-pitch schedule has no offset: TS's region-2 pitch stood 10 deg below fine in the
    table of every kind on this deck."""
    fst = CASES / "NREL_2p8_127" / "NREL-2p8-127.fst"
    dis = fst.parent / "NREL-2p8-127_DISCON.IN"
    (fine,), (lowest,) = _deck_values(dis, "PC_FinePit"), _deck_values(dis, "PC_MinPit")
    assert lowest < fine - math.radians(5.0)
    t = linearize.load_turbine(fst)
    res = run_controller(t, kind, Scenario(8.0, "A", 1, 90.0))
    pitch = np.column_stack([res.channel(f"pitch_{i}") for i in (1, 2, 3)])
    assert pitch.min() >= fine - math.radians(0.01)

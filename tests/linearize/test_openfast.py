"""OpenFAST decks as turbines, checked against openfast-io (a peer reader), the
packaged NREL 5-MW, each deck's ROSCO performance table and the turbines' published schedules
(``shared/validation/iea15mw/README.md`` gives the sources and the suggested tolerances)."""
from __future__ import annotations

import dataclasses
import math
import os
import shutil
from pathlib import Path

import numpy as np
import pytest
import rosco  # in the test extras: the decks and ROSCO's tables are the outside reference

import linearize
from linearize import TurbineFileError, load_openfast, read_rotor_performance

CASES = Path(rosco.__file__).parents[1] / "Examples" / "Test_Cases"
DECKS = {
    "nrel5mw": ("NREL-5MW/NREL-5MW.fst", "NREL-5MW/Cp_Ct_Cq.NREL5MW.txt"),
    "iea15mw": ("IEA-15-240-RWT/IEA-15-240-RWT-Monopile/IEA-15-240-RWT-Monopile.fst",
                "IEA-15-240-RWT/IEA-15-240-RWT/Cp_Ct_Cq.IEA15MW.txt"),
    "bar10": ("BAR_10/BAR_10.fst", "BAR_10/Cp_Ct_Cq.BAR_10.txt"),
    "nrel2p8": ("NREL_2p8_127/NREL-2p8-127.fst", "NREL_2p8_127/NREL-2p8-127_Cp_Ct_Cq.txt"),
}
VALIDATION = Path(__file__).parents[1] / "data" / "iea15mw_steady_state_tabular.csv"


@pytest.fixture(scope="module")
def decks() -> dict[str, linearize.Turbine]:
    return {k: load_openfast(CASES / fst) for k, (fst, _) in DECKS.items()}


def _of_reader(fst: Path):  # openfast-io's reader of the same deck
    from openfast_io.FAST_reader import InputReader_OpenFAST

    r = InputReader_OpenFAST()
    r.FAST_InputFile = fst.name
    r.FAST_directory = str(fst.parent)
    r.read_MainInput()
    r.read_ElastoDyn(os.path.join(r.FAST_directory, r.fst_vt["Fst"]["EDFile"]))
    r.read_AeroDyn()
    r.read_ServoDyn()
    return r.fst_vt


@pytest.mark.parametrize("key", ["nrel5mw", "iea15mw"])
def test_deck_values_equal_openfast_io(decks, key) -> None:
    """Our line parser against openfast-io's reader, value by value: geometry (with our sign
    conventions), masses, drivetrain, efficiencies, the AeroDyn blade nodes and every airfoil
    table. Exact equality: both parse the same decimal text."""
    t = decks[key]
    v = _of_reader(CASES / DECKS[key][0])
    ed = v["ElastoDyn"]
    g = t.geometry
    assert g.tip_radius == ed["TipRad"] and g.hub_radius == ed["HubRad"]
    assert math.degrees(g.precone_rad) == pytest.approx(-ed["PreCone(1)"], rel=1e-15)
    assert math.degrees(g.shaft_tilt_rad) == pytest.approx(-ed["ShftTilt"], rel=1e-15)
    assert g.overhang == -ed["OverHang"] and g.twr2shft == ed["Twr2Shft"]
    assert g.tower_height == ed["TowerHt"] and g.tower_base_height == ed["TowerBsHt"]
    assert t.rotor.hub_mass == ed["HubMass"] and t.rotor.hub_inertia == ed["HubIner"]
    assert t.nacelle.mass == ed["NacMass"] + ed["YawBrMass"]
    d = t.drivetrain
    assert (d.gearbox_ratio, d.generator_inertia, d.shaft_stiffness, d.shaft_damping) == (
        ed["GBRatio"], ed["GenIner"], ed["DTTorSpr"], ed["DTTorDmp"])
    assert d.generator_efficiency == pytest.approx(v["ServoDyn"]["GenEff"] / 100, rel=1e-15)
    bl = v["AeroDynBlade"]
    bl = bl[0] if isinstance(bl, list) else bl
    r = g.hub_radius + np.asarray(bl["BlSpn"], dtype=float)
    inside = (r > g.hub_radius + 1e-6) & (r < g.tip_radius - 1e-6)
    np.testing.assert_array_equal(t.blade.r, r[inside])
    np.testing.assert_array_equal(t.blade.chord, np.asarray(bl["BlChord"], float)[inside])
    np.testing.assert_allclose(np.degrees(t.blade.twist_rad),
                               np.asarray(bl["BlTwist"], float)[inside], rtol=1e-14)
    np.testing.assert_array_equal(t.blade.airfoil + 1, np.asarray(bl["BlAFID"], int)[inside])
    assert len(t.polars) == len(v["AeroDyn"]["af_data"])
    for polar, af in zip(t.polars, v["AeroDyn"]["af_data"]):
        tab = af[0]
        np.testing.assert_allclose(np.degrees(polar.alpha_rad), np.asarray(tab["Alpha"], float),
                                   rtol=1e-14, atol=1e-12)
        np.testing.assert_array_equal(polar.cl, np.asarray(tab["Cl"], float))
        np.testing.assert_array_equal(polar.cd, np.asarray(tab["Cd"], float))


@pytest.mark.parametrize("key", ["nrel5mw", "iea15mw"])
def test_deck_discon_limits_equal_roscos_reader(decks, key, rosco_utilities) -> None:
    """The DISCON limits as ROSCO's own reader reads them from the deck's ``DISCON.IN``."""
    t = decks[key]
    fst = CASES / DECKS[key][0]
    v = _of_reader(fst)
    dis = rosco_utilities.read_DISCON(str(fst.parent / v["ServoDyn"]["DLL_InFile"]))
    assert t.operation.rated_power == dis["VS_RtPwr"]
    assert t.operation.rated_rotor_speed_rad_s == pytest.approx(
        dis["PC_RefSpd"] / v["ElastoDyn"]["GBRatio"], rel=1e-15)
    assert t.generator.max_torque == dis["VS_MaxTq"]
    assert t.pitch_actuator.max_rate_rad_s == dis["PC_MaxRat"]


def test_deck_discon_limits_equal_the_published_nrel5mw(decks) -> None:
    """The NREL 5-MW deck's DISCON limits against NREL/TP-500-38060 (table 1-1 and sec. 7):
    rated power 5 MW, rated generator speed 1173.7 rpm (rotor 12.1 rpm; the deck's
    PC_RefSpd 122.9096 rad/s), maximum generator torque 47,402.91 N m (the deck's 47402.9). Its
    pitch-rate limit, 0.1745 rad/s (10 deg/s), is ROSCO's choice, not the report's 8 deg/s."""
    t = decks["nrel5mw"]
    assert t.operation.rated_power == 5e6
    gen_rpm = t.operation.rated_rotor_speed_rad_s * t.drivetrain.gearbox_ratio * 30 / math.pi
    assert gen_rpm == pytest.approx(1173.7, abs=0.05)
    assert t.generator.max_torque == pytest.approx(47402.91, abs=0.05)   # deck: 47402.9


def test_deck_report_names_files_keys_and_defaults(decks) -> None:
    t = decks["iea15mw"]
    text = str(t.report)
    assert "IEA-15-240-RWT-Monopile_ElastoDyn.dat:" in text and "TipRad" in text
    assert "IEA-15-240-RWT-Monopile_DISCON.IN:" in text and "PC_RefSpd" in text
    assert {e.quantity for e in t.report.defaulted} == {"cut-in wind", "cut-out wind",
                                                        "pitch servo time constant"}
    assert any("clamped at its base" in n for n in t.report.notes)
    assert t.drivetrain.gearbox_ratio == 1.0          # direct drive
    assert t.geometry.tower_base_height == 15.0


def test_packaged_iea15mw_is_the_deck(decks) -> None:
    """``load_turbine("iea15mw")`` reads the packaged copy of the rosco wheel's deck."""
    assert "iea15mw" in linearize.available_turbines()
    t = linearize.load_turbine("iea15mw")
    d = decks["iea15mw"]
    np.testing.assert_array_equal(t.blade.r, d.blade.r)
    assert t.operation == d.operation and t.geometry == d.geometry
    assert t.mode_shapes.blade_edge1 is not None


def test_nrel5mw_deck_agrees_with_packaged_turbine(turbine, decks) -> None:
    """ROSCO's NREL-5MW deck against our packaged NREL 5-MW (same ElastoDyn data; aerodynamics
    on AeroDyn 15's 19 nodes by trapezoid instead of AeroDyn v13's 17 elements).

    Measured: C_P max 0.4820 vs 0.4870 (the element layout), rated wind 11.329 vs 11.289 m/s,
    region-3 pitch within 0.06 deg at 12-25 m/s, structural frequencies equal to 1e-4.
    Asserted: |dC_P max| <= 0.006, |d rated wind| <= 0.1 m/s, pitch within 0.2 deg, frequencies
    within 0.1 %. The rotor's data compared, the deck's controller set aside: its DISCON.IN
    adds ROSCO's peak shaving (PS_BldPitchMin, from 10.2 m/s), which the deck's own trim
    follows (its rated wind 12.04 m/s, below it the table's pitch: 3.15 deg at 11.5 m/s)."""
    deck_with_table = decks["nrel5mw"]
    assert deck_with_table.min_pitch is not None
    op = linearize.trim(deck_with_table, 11.5)
    assert op.region == "2.5"
    assert op.pitch_rad == pytest.approx(deck_with_table.min_pitch.at(11.5), abs=1e-12)
    assert math.degrees(op.pitch_rad) > 2.0
    deck = dataclasses.replace(deck_with_table, min_pitch=None)
    cp_pack = linearize.optimal_tsr(turbine)[1]
    cp_deck = linearize.optimal_tsr(deck)[1]
    assert abs(cp_deck - cp_pack) <= 0.006
    assert abs(linearize.rated_wind_speed(deck) - linearize.rated_wind_speed(turbine)) <= 0.1
    for v in (12.0, 18.0, 25.0):
        dp = linearize.trim(deck, v).pitch_rad - linearize.trim(turbine, v).pitch_rad
        assert abs(math.degrees(dp)) <= 0.2
    fp = linearize.structural_frequencies(linearize.plant_params(turbine))
    fd = linearize.structural_frequencies(linearize.plant_params(deck))
    for k in fp:
        assert fd[k] == pytest.approx(fp[k], rel=1e-3), k
    assert deck.operation.rated_rotor_speed_rad_s == pytest.approx(
        turbine.operation.rated_rotor_speed_rad_s, rel=2e-3)


@pytest.mark.parametrize("key", list(DECKS))
def test_cp_ct_surface_matches_rosco_table(decks, key) -> None:
    """Each deck's C_P and C_T against its own ROSCO table (CCBlade on the same AeroDyn
    nodes and polars, shear 0.2 as ROSCO's tuning default) over TSR 3-12, pitch -2..20 deg
    where the table's C_P > 0.

    The remaining difference is CCBlade's smoothing of the polars (shown for the NREL 5-MW in
    test_steady.py: it alone accounts for 0.0135 in C_P) and its 8 azimuth sectors. Measured
    RMS / max |dC_P|: NREL 5-MW 0.0051 / 0.0129, IEA-15 0.0047 / 0.0156, BAR_10 0.0011 /
    0.0042, NREL-2.8-127 0.0053 / 0.0231; |dC_T| max 0.0217, 0.0130, 0.0032, 0.0153.
    Asserted for all four: RMS <= 0.008, max <= 0.025 in both."""
    ref = read_rotor_performance(CASES / DECKS[key][1])
    rows = (ref.tsr >= 3.0) & (ref.tsr <= 12.0)
    cols = (ref.pitch_deg >= -2.0) & (ref.pitch_deg <= 20.0)
    mine = linearize.rotor_performance(decks[key], ref.tsr[rows], ref.pitch_deg[cols],
                                       shear_exponent=0.2)
    cp_r, ct_r = ref.cp[np.ix_(rows, cols)], ref.ct[np.ix_(rows, cols)]
    on = cp_r > 0
    dcp, dct = (mine.cp - cp_r)[on], (mine.ct - ct_r)[on]
    assert np.sqrt(np.mean(dcp**2)) <= 0.008 and np.abs(dcp).max() <= 0.025
    assert np.sqrt(np.mean(dct**2)) <= 0.008 and np.abs(dct).max() <= 0.025


def test_iea15mw_schedule_against_published(decks) -> None:
    """IEA-15-240-RWT, rigid rotor, no shear, against the references and tolerances of
    ``shared/validation/iea15mw/README.md``: C_P max 0.470 +- 0.02 (ROSCO table; not the 0.489
    normalized by 118 m), optimal TSR 9.0 +- 0.5, rated wind 10.6 +- 0.3 m/s, rated speed the
    deck's 7.56 rpm, 5.0 rpm held in region 1.5 with WISDEM's pitch +- 1.5 deg (the trim
    maximizes power at minimum speed, as WISDEM does: measured within 0.1 deg), region-3 pitch +- 1 deg and thrust +- 8 % of
    WISDEM's 2024 table (12-25 m/s), 15 MW in region 3.

    Measured: C_P max 0.4832 (with the deck's projected radius 120.68 m), TSR 9.04, rated
    10.50 m/s, pitch 6.52 / 11.69 / 17.84 / 22.91 deg at 12 / 15 / 20 / 25 m/s against 6.13 /
    11.56 / 17.79 / 22.88, thrust within -1.8..+2.5 %."""
    t = decks["iea15mw"]
    lam, cp = linearize.optimal_tsr(t)
    assert abs(cp - 0.470) <= 0.02 and abs(lam - 9.0) <= 0.5
    assert abs(linearize.rated_wind_speed(t) - 10.6) <= 0.3
    assert t.operation.rated_rotor_speed_rad_s * 30 / math.pi == pytest.approx(7.56, abs=0.01)
    ref = np.genfromtxt(VALIDATION, delimiter=",", names=True)
    for row in ref[ref["wind_speed_mps"] < 6.9]:       # region 1.5: pitch maximizing power
        low = linearize.trim(t, float(row["wind_speed_mps"]))
        assert low.region == "1.5"
        assert low.rotor_speed_rad_s * 30 / math.pi == pytest.approx(5.0, abs=0.05)
        assert abs(math.degrees(low.pitch_rad) - row["pitch_deg"]) <= 1.5
    for v in (12.0, 15.0, 20.0, 25.0):
        op = linearize.trim(t, v)
        pitch_ref = np.interp(v, ref["wind_speed_mps"], ref["pitch_deg"])
        thrust_ref = np.interp(v, ref["wind_speed_mps"], ref["thrust_MN"]) * 1e6
        assert abs(math.degrees(op.pitch_rad) - pitch_ref) <= 1.0, v
        assert abs(op.thrust / thrust_ref - 1) <= 0.08, v
        assert op.power == pytest.approx(15e6, rel=5e-3)


def test_bar10_and_nrel2p8_schedules(decks) -> None:
    """Secondary turbines (``shared/validation/iea15mw/README.md``, end).

    BAR_10: rated wind 8.27 +- 0.3 m/s (ROSCO's v_rated 8.274), region-3 pitch within 1 deg of
    the Cp-table trim 10.00 / 14.22 / 20.16 / 25.35 deg (12 / 15 / 20 / 25 m/s); measured 8.268
    m/s and 9.82 / 14.11 / 20.12 / 25.35 deg.

    NREL-2.8-127 (ROSCO's retuned deck): region-3 pitch within 1.5 deg of the Cp-table trim
    10.51 / 15.37 / 21.78 / 27.21 deg; measured 10.25 / 15.24 / 21.74 / 27.19. Its rated wind is
    checked against the one implied by its own ROSCO table (C_P max 0.4767, the deck's
    efficiencies 0.9395 x 0.955 and rated power): 9.45 m/s; measured 9.47 (+- 0.2 asserted).
    The WISDEM / OpenFAST 10.68 m/s of the legacy model include a 67.5 % thrust cap (peak
    shaving), which the trim does not apply."""
    bar = decks["bar10"]
    assert abs(linearize.rated_wind_speed(bar) - 8.27) <= 0.3
    for v, ref in ((12.0, 10.00), (15.0, 14.22), (20.0, 20.16), (25.0, 25.35)):
        assert abs(math.degrees(linearize.trim(bar, v).pitch_rad) - ref) <= 1.0, v
    t = decks["nrel2p8"]
    for v, ref in ((12.0, 10.51), (15.0, 15.37), (20.0, 21.78), (25.0, 27.21)):
        assert abs(math.degrees(linearize.trim(t, v).pitch_rad) - ref) <= 1.5, v
    table = read_rotor_performance(CASES / DECKS["nrel2p8"][1])
    eta = t.drivetrain.generator_efficiency * t.drivetrain.gearbox_efficiency
    area = math.pi * (t.geometry.tip_radius * math.cos(t.geometry.precone_rad)) ** 2
    v_table = (t.operation.rated_power / (eta * 0.5 * 1.225 * area * table.cp.max())) ** (1 / 3)
    assert abs(linearize.rated_wind_speed(t) - v_table) <= 0.2


# --------------------------------------------------------------------------------------------
# Bad decks
# --------------------------------------------------------------------------------------------
@pytest.fixture()
def deck_copy(tmp_path) -> Path:
    src = CASES / "NREL-5MW"
    dst = tmp_path / "NREL-5MW"
    shutil.copytree(src, dst, ignore=shutil.ignore_patterns("*.inp", "Ice*", "*BeamDyn*"))
    return dst


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert old in text, old
    path.write_text(text.replace(old, new, 1))


ED = "NRELOffshrBsline5MW_Onshore_ElastoDyn.dat"
AD = "NRELOffshrBsline5MW_Onshore_AeroDyn15.dat"


@pytest.mark.parametrize("file, old, new, match", [
    (ED, "         63   TipRad", "       abc   TipRad", r"ElastoDyn.dat:\d+ TipRad = 'abc' is not a number"),
    (ED, "         63   TipRad", "         63   TipRadius", r"key 'TipRad' not found"),
    (ED, "          3   NumBl", "          2   NumBl", r"NumBl = 2; the plant supports 3 blades"),
    (ED, '"NRELOffshrBsline5MW_Blade.dat"    BldFile(1)', '"missing_blade.dat"    BldFile(1)',
     r"BldFile1: ElastoDyn blade file .*missing_blade.dat not found; BeamDyn-only blades"),
    (ED, "False         PtfmSgDOF", "True          PtfmSgDOF",
     r"PtfmSgDOF = True without SubDyn: platform degrees of freedom"),
    (AD, "          1   Wake_Mod", "          3   Wake_Mod", r"Wake_Mod = 3 \(OLAF"),
    ("NREL-5MW.fst", "          0   CompMooring", "          3   CompMooring",
     r"CompMooring = 3: floating platforms are not supported"),
    ("NREL-5MW.fst", "          0   MHK ", "          1   MHK ", r"MHK = 1; only wind turbines"),
    ("NRELOffshrBsline5MW_AeroDyn_blade.dat", "1.3667000E+00 -8.1531745E-04", "1.3667000E+00 xyz",
     r"AeroDyn_blade.dat: line \d+: .* is not a row of numbers"),
    ("DISCON.IN", "VS_RtPwr", "VS_RatedPower", r"DISCON.IN: key 'VS_RtPwr' not found"),
    ("DISCON.IN", "0.000000000000      ! PC_FinePit", "-0.05000000000      ! PC_FinePit",
     r"DISCON.IN:68 PC_FinePit: the fine pitch -2.865 deg is below the minimum pitch 0 deg "
     r"\(.*DISCON.IN:64 PC_MinPit\)"),
    ("Airfoils/DU21_A17.dat", "NumAlf", "NumAlpha", r"DU21_A17.dat: key 'NumAlf' not found"),
])
def test_bad_deck_names_file_and_key(deck_copy, file, old, new, match) -> None:
    _edit(deck_copy / file, old, new)
    with pytest.raises(TurbineFileError, match=match):
        load_openfast(deck_copy / "NREL-5MW.fst")


def test_missing_deck_and_pair_without_aerodyn(tmp_path, deck_copy) -> None:
    with pytest.raises(FileNotFoundError, match="nor an existing turbine file"):
        linearize.load_turbine(tmp_path / "nothing.fst")
    with pytest.raises(TurbineFileError, match="give fst, or both elastodyn and aerodyn"):
        load_openfast(elastodyn=deck_copy / ED)
    with pytest.raises(TurbineFileError, match="no ServoDyn GenEff nor DISCON VS_GenEff"):
        load_openfast(elastodyn=deck_copy / ED, aerodyn=deck_copy / AD)


def test_elastodyn_aerodyn_pair_loads_with_discon(deck_copy) -> None:
    t = load_openfast(elastodyn=deck_copy / ED, aerodyn=deck_copy / AD,
                      servodyn=deck_copy / "NRELOffshrBsline5MW_Onshore_ServoDyn.dat",
                      discon=deck_copy / "DISCON.IN")
    assert t.operation.rated_power == 5e6 and t.blade.layout == "nodes"
    assert any("AirDens" in e.source for e in t.report.entries)


DISCON = {"nrel5mw": "NREL-5MW/DISCON.IN",
          "iea15mw": "IEA-15-240-RWT/IEA-15-240-RWT-Monopile/IEA-15-240-RWT-Monopile_DISCON.IN",
          "bar10": "BAR_10/BAR_10_DISCON.IN",
          "nrel2p8": "NREL_2p8_127/NREL-2p8-127_DISCON.IN"}


@pytest.mark.parametrize("key", list(DECKS))
def test_optimal_tsr_and_region2_gain_against_discon(decks, key) -> None:
    """Each deck's ROSCO tuning against our C_P (shear 0.2 and fine pitch, as ROSCO tunes):
    the C_P-optimal TSR within 0.3 of ``VS_TSRopt`` (measured 7.7 / 9.0 / 9.8 / 8.0 against
    7.5 / 9.0 / 10.0 / 8.207), and ``VS_Rgn2K`` = rho pi R^5 C_P / (2 lambda^3 N^3) from our
    C_P within 2 % where the TSR ROSCO used is known: at ``VS_TSRopt`` for the NREL 5-MW
    (+1.2 %) and the NREL-2.8-127 (+1.1 %); for the IEA-15 ROSCO took its table's optimum,
    TSR 8.5 (-1.3 % there; -16 % at VS_TSRopt = 9.0). BAR_10's gain is not asserted: ours at
    VS_TSRopt is +5.3 %, and we could not tell which TSR its tuning used."""
    from linearize.openfast import OpenFASTFile

    t = decks[key]
    dis = OpenFASTFile(CASES / DISCON[key])
    fine = math.degrees(t.operation.fine_pitch_rad)
    assert dis.number("PC_FinePit" if dis.has("PC_FinePit") else "PC_MinPit") == \
        pytest.approx(t.operation.fine_pitch_rad, abs=1e-12)
    lam = np.linspace(6.0, 12.0, 121)
    cp, _ = linearize.steady_coefficients(t, lam, np.full(lam.size, fine), shear_exponent=0.2)
    assert abs(lam[np.argmax(cp)] - dis.number("VS_TSRopt")) <= 0.3
    if key == "bar10":
        return
    lam_k = 8.5 if key == "iea15mw" else dis.number("VS_TSRopt")
    cp_k, _ = linearize.steady_coefficients(t, lam_k, fine, shear_exponent=0.2)
    r, n = t.geometry.tip_radius, t.drivetrain.gearbox_ratio
    k = 0.5 * t.environment.air_density * math.pi * r**5 * float(cp_k) / lam_k**3 / n**3
    assert k == pytest.approx(dis.number("VS_Rgn2K"), rel=0.02)

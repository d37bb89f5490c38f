"""Running the user's OpenFAST: finding it, the deck's copies pointed at a library, OpenFAST's
failures reported with its own lines, and ``verify-openfast`` end to end where OpenFAST is
installed (``$MPCWT_OPENFAST``, ``PATH`` or the binary beside the checkout; skipped without
one)."""
from __future__ import annotations

import json
import re
import stat
from pathlib import Path

import numpy as np
import pytest

import linearize
from mpc_wt.cli import main
from mpc_wt.errors import OpenFASTRunError
from mpc_wt.io.discon_export import find_compiler
from mpc_wt.io.openfast_case import read_openfast_case
from mpc_wt.io.openfast_run import (OPENFAST_ENV, find_openfast, prepare_deck, run_openfast,
                                    write_wind_deck)
from openfast_here import SHARED, installed_openfast

_V5 = SHARED / "validation" / "nrel5mw" / "openfast_rtest" / "5MW_Land_DLL_WTurb_v5"
_FST = _V5 / "5MW_Land_DLL_WTurb.fst"


def _script(path: Path, body: str) -> Path:
    path.write_text("#!/bin/sh\n" + body)
    path.chmod(path.stat().st_mode | stat.S_IXUSR)
    return path


def test_no_openfast_is_one_message_naming_each_place(tmp_path, monkeypatch):
    monkeypatch.delenv(OPENFAST_ENV, raising=False)
    monkeypatch.setenv("PATH", str(tmp_path))
    with pytest.raises(OpenFASTRunError, match=rf"no OpenFAST executable.*\${OPENFAST_ENV}: "
                                               r"not set; PATH: no 'openfast'.*--openfast") as e:
        find_openfast()
    assert not e.value.ran
    with pytest.raises(OpenFASTRunError, match="is not an executable file"):
        find_openfast(tmp_path / "missing")
    exe = _script(tmp_path / "openfast", "exit 0\n")
    assert find_openfast() == exe.resolve()                    # found on PATH
    monkeypatch.setenv(OPENFAST_ENV, str(exe))
    assert find_openfast() == exe.resolve()


def _library(tmp_path: Path) -> tuple[Path, Path]:
    lib, inp = tmp_path / "libx.so", tmp_path / "x.in"
    lib.write_bytes(b"\0")
    inp.write_text("kind baseline\n")
    return lib, inp


@pytest.mark.skipif(not _FST.is_file(), reason="OpenFAST's v5 regression case is not here")
def test_the_deck_copy_runs_the_library_and_reads_every_other_file_in_place(tmp_path):
    """The copies of the main and ServoDyn files: every file they name absolute and existing
    (the ElastoDyn, AeroDyn and InflowWind files read where they are), ServoDyn's Bladed
    interface at the library (``DLL_FileName``, ``DLL_InFile``, ``DLL_DT``, ``Ptch_Cntrl`` 1,
    ``PCMode`` and ``VSContrl`` 5), ``TMax`` the given one; the deck itself unchanged."""
    before = {p: p.read_bytes() for p in _V5.iterdir()}
    lib, inp = _library(tmp_path)
    copy = prepare_deck(_FST, tmp_path / "run", lib, inp, 0.1, tmax=12.5)
    main_text = copy.read_text()
    assert re.search(r"^\s*12\.5\s+TMax", main_text, re.M)
    names = dict(re.findall(r'^\s*"([^"]+)"\s+(\w+File)\b', main_text, re.M))
    named = {k: v for v, k in names.items()}
    for key in ("EDFile", "InflowFile", "AeroFile", "ServoFile"):
        assert Path(named[key]).is_absolute() and Path(named[key]).is_file(), key
    assert Path(named["ServoFile"]).parent == tmp_path / "run"
    srv = Path(named["ServoFile"]).read_text()
    assert re.search(rf'^"{re.escape(str(lib.resolve()))}"\s+DLL_FileName', srv, re.M)
    assert re.search(rf'^"{re.escape(str(inp.resolve()))}"\s+DLL_InFile', srv, re.M)
    for key, val in (("DLL_DT", "0.1"), ("Ptch_Cntrl", "1"), ("PCMode", "5"),
                     ("VSContrl", "5")):
        assert re.search(rf"^\s*{re.escape(val)}\s+{key}\b", srv, re.M), key
    assert {p: p.read_bytes() for p in _V5.iterdir()} == before
    # as the case reader sees the two: the library's interval and individual pitch, against
    # the deck's "default" (ServoDyn's DT "default": the main file's 0.00625 s) and Ptch_Cntrl 0
    t = linearize.load_turbine("nrel5mw")
    ours, deck = read_openfast_case(copy, turbine=t), read_openfast_case(_FST, turbine=t)
    assert (ours.dll_dt, ours.individual_pitch) == (0.1, True)
    assert (deck.dll_dt, deck.individual_pitch) == (0.00625, False)


@pytest.mark.skipif(not _FST.is_file(), reason="OpenFAST's v5 regression case is not here")
def test_a_wind_deck_runs_in_our_field_from_the_trim(tmp_path):
    """``write_wind_deck``: the case reader sees the new field, ``TMax`` and ElastoDyn's
    initial rotor speed, pitch and tower-top and blade-tip deflections of the trim (to the 6
    digits written); the AeroDyn file is the deck's own, the deck is unchanged; a missing field
    is named. Where OpenFAST is installed, 3 s of it run in the field."""
    import lidar

    before = {p: p.read_bytes() for p in _V5.iterdir()}
    spec = lidar.TurbulenceSpec(mean_speed=16.0, turbulence="A", duration=40.0, dt=0.05,
                                width=150.0, height=35 * 150.0 / 31, n_y=8, n_z=9)
    bts = lidar.generate_field(spec, 3).save(tmp_path / "f.bts")
    t = linearize.load_turbine("nrel5mw")
    op = linearize.trim(t, 16.0)
    copy = write_wind_deck(_FST, tmp_path / "deck", bts, tmax=3.0, start=op)
    case = read_openfast_case(copy, turbine=t)
    assert case.wind_file == Path(bts).resolve() and case.duration == 3.0
    assert case.x0[2] == pytest.approx(op.rotor_speed_rad_s, rel=1e-5)
    assert case.x0[5:8] == pytest.approx(np.full(3, op.pitch_rad), rel=1e-5)
    assert case.x0[0] == pytest.approx(op.x[0], rel=1e-5)
    assert case.x0[10:13] == pytest.approx(np.full(3, np.mean(op.x[10:13])), rel=1e-5)
    named = dict((k, v) for v, k in re.findall(r'^\s*"([^"]+)"\s+(\w+File)\b',
                                              copy.read_text(), re.M))
    assert Path(named["AeroFile"]) == (_V5 / "NRELOffshrBsline5MW_Onshore_AeroDyn.dat").resolve()
    assert {p: p.read_bytes() for p in _V5.iterdir()} == before
    with pytest.raises(FileNotFoundError, match="wind field .*nothing.bts"):
        write_wind_deck(_FST, tmp_path / "deck2", tmp_path / "nothing.bts")
    exe = installed_openfast()
    if exe is not None and find_compiler() is not None:
        from mpc_wt.io.openfast_output import read_openfast_output
        from mpc_wt.run import export_discon

        ex = export_discon(t, "baseline", tmp_path / "lib")
        run = prepare_deck(copy, tmp_path / "run", ex.library, ex.input_file, ex.dt)
        series = read_openfast_output(run_openfast(exe, run))
        assert series.t[-1] == pytest.approx(3.0)


@pytest.mark.skipif(not _FST.is_file(), reason="OpenFAST's v5 regression case is not here")
def test_the_copies_take_values_and_a_step_that_divides_the_librarys(tmp_path, caplog):
    """``values``: a main-file key and ``EDFile:RotSpeed`` (the ElastoDyn file copied, the
    case reader sees 10 rpm); a library interval of 0.015 s against the deck's DT 0.00625 s
    (2.4 steps, which ServoDyn refuses): the copy's DT is 0.015 / 3 = 0.005 s by hand, with a
    warning; 0.1 s (16 steps) leaves it. An unknown key is named."""
    lib, inp = _library(tmp_path)
    with caplog.at_level("WARNING", logger="mpc_wt.io.openfast_run"):
        copy = prepare_deck(_FST, tmp_path / "a", lib, inp, 0.015,
                            values={"CompHydro": 0, "EDFile:RotSpeed": 10})
    text = copy.read_text()
    assert re.search(r"^\s*0\.005\s+DT\s", text, re.M)
    assert any("DT 0.00625 s" in r.getMessage() for r in caplog.records)
    ed = dict((k, v) for v, k in re.findall(r'^\s*"([^"]+)"\s+(\w+File)\b', text, re.M))
    assert Path(ed["EDFile"]).parent == tmp_path / "a"
    case = read_openfast_case(copy, turbine=linearize.load_turbine("nrel5mw"))
    assert case.x0[2] * 30 / np.pi == pytest.approx(10.0)
    same = prepare_deck(_FST, tmp_path / "b", lib, inp, 0.1).read_text()
    assert re.search(r"^\s*0\.00625\s+DT\s", same, re.M)
    with pytest.raises(ValueError, match="'NoSuchKey'"):
        prepare_deck(_FST, tmp_path / "c", lib, inp, 0.1, values={"EDFile:NoSuchKey": 1})


def test_a_deck_without_servodyn_or_library_is_named(tmp_path):
    lib, inp = _library(tmp_path)
    fst = tmp_path / "case.fst"
    fst.write_text('"ed.dat"    EDFile   - ElastoDyn\n')
    with pytest.raises(ValueError, match="no ServoFile line"):
        prepare_deck(fst, tmp_path / "run", lib, inp, 0.0125)
    with pytest.raises(FileNotFoundError, match="library .*nolib.so does not exist"):
        prepare_deck(fst, tmp_path / "run", tmp_path / "nolib.so", inp, 0.0125)


def test_openfast_that_fails_or_writes_nothing_is_reported_with_its_lines(tmp_path):
    fst = tmp_path / "case.fst"
    fst.write_text("x\n")
    bad = _script(tmp_path / "of_bad", "echo ' Time: 0 of 10 seconds.'\n"
                                       "echo ' FAST_InitializeAll: Lidar_Init: no beams'\nexit 1\n")
    seen = []
    with pytest.raises(OpenFASTRunError, match=r"(?s)stopped \(exit 1\).*Lidar_Init: no beams") as e:
        run_openfast(bad, fst, progress=seen.append)
    assert e.value.ran and seen == [0.0]
    quiet = _script(tmp_path / "of_quiet", "exit 0\n")
    with pytest.raises(OpenFASTRunError, match="wrote no output file"):
        run_openfast(quiet, fst)


def test_verify_openfast_without_openfast_exits_2_before_any_work(tmp_path, monkeypatch,
                                                                   capsys):
    monkeypatch.delenv(OPENFAST_ENV, raising=False)
    monkeypatch.setenv("PATH", str(tmp_path))
    fst = tmp_path / "case.fst"
    fst.write_text("x\n")
    assert main(["verify-openfast", "baseline", str(fst), "--out", str(tmp_path / "v")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("mpcwt verify-openfast: error: no OpenFAST executable")
    assert len(err.splitlines()) == 1 and not (tmp_path / "v").exists()


@pytest.mark.skipif(installed_openfast() is None or find_compiler() is None or not _FST.is_file(),
                    reason="needs OpenFAST ($MPCWT_OPENFAST or openfast on PATH), a C "
                           "compiler and OpenFAST's v5 regression case")
def test_verify_openfast_on_the_regression_case(tmp_path, capsys):
    """``mpcwt verify-openfast baseline`` on OpenFAST's own case, 20 s: OpenFAST and mpc-wt's
    plant run the same library; over 5-20 s mean power and rotor speed agree within 1 % (the
    verification's own bounds; over 10-60 s they agree within 0.25 %), the JSON and the plot
    are written, and the table prints each channel."""
    code = main(["verify-openfast", "baseline", str(_FST), "--out", str(tmp_path / "v"),
                 "--openfast", installed_openfast(), "--tmax", "20", "--window", "5", "20"])
    assert code in (0, 3)
    out = capsys.readouterr().out
    assert "gen_power" in out and "pitch travel" in out
    doc = json.loads((tmp_path / "v" / "verify.json").read_text())
    rows = {r["channel"]: r for r in doc["rows"]}
    for ch in ("gen_power", "rotor_speed"):
        assert abs(rows[ch]["mean_diff_pct"]) <= 1.0, rows[ch]
    assert not any(f.startswith(("mean power", "mean rotor speed")) for f in doc["flags"])
    assert (tmp_path / "v" / "verify.png").stat().st_size > 10_000
    t = linearize.load_turbine("nrel5mw")
    assert rows["gen_power"]["max_ref"] <= 1.1 * t.operation.rated_power
    assert np.isfinite(doc["pitch_travel_deg"]).all()


def _rosco_iea15_deck() -> Path | None:
    """The rosco wheel's IEA-15-240-RWT monopile deck, where the wheel ships its examples."""
    import importlib.util

    spec = importlib.util.find_spec("rosco")
    if spec is None or spec.origin is None:
        return None
    fst = (Path(spec.origin).parents[1] / "Examples" / "Test_Cases" / "IEA-15-240-RWT"
           / "IEA-15-240-RWT-Monopile" / "IEA-15-240-RWT-Monopile.fst")
    return fst if fst.is_file() else None


_FIXED_BASE = ["--set", "CompSeaSt=0", "--set", "CompHydro=0", "--set", "CompSub=0"] + [
    a for dof in ("Sg", "Sw", "Hv", "R", "P", "Y") for a in ("--set", f"EDFile:Ptfm{dof}DOF=False")]


@pytest.mark.slow
@pytest.mark.skipif(installed_openfast() is None or find_compiler() is None
                    or _rosco_iea15_deck() is None,
                    reason="needs OpenFAST, a C compiler and the rosco wheel's IEA-15 deck")
def test_verify_openfast_on_the_rosco_iea15_deck_fixed_at_its_base(tmp_path):
    """The rosco wheel's IEA-15-240-RWT monopile deck (OpenFAST v4.x offshore inputs) runs
    fixed at its tower base with ``--set``, at a DT that divides the library's 0.0125 s; past
    the start (40-60 s, steady 15 m/s) mean power and rotor speed agree within 1 % (measured
    0.01 and 0.11 % over 40-100 s)."""
    code = main(["verify-openfast", "baseline", str(_rosco_iea15_deck()), "--turbine",
                 "iea15mw", "--out", str(tmp_path / "v"), "--openfast", installed_openfast(),
                 "--tmax", "60", "--window", "40", "60", *_FIXED_BASE])
    assert code in (0, 3)
    doc = json.loads((tmp_path / "v" / "verify.json").read_text())
    rows = {r["channel"]: r for r in doc["rows"]}
    for ch in ("gen_power", "rotor_speed"):
        assert abs(rows[ch]["mean_diff_pct"]) <= 1.0, rows[ch]
    main_copy = next((tmp_path / "v" / "openfast").glob("*.fst")).read_text()
    assert re.search(r"^\s*0\.004166666666666\d*\s+DT\s", main_copy, re.M)

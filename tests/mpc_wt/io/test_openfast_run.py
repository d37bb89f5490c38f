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
from mpc_wt.io.openfast_run import OPENFAST_ENV, find_openfast, prepare_deck, run_openfast
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

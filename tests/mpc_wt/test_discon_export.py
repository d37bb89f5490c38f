"""Controllers exported as Bladed-style libraries (DISCON): built with the system's C compiler,
run through our DisconController host and compared step by step with the Python controller
they came from; sanitizers, two instances, bad input files and measurements."""
from __future__ import annotations

import ctypes
import json
import math
import os
import re
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import linearize
from mpc_wt.controllers.discon import DisconController
from mpc_wt.errors import ControllerLibraryError
from mpc_wt.io.discon_export import build_library, find_compiler, library_name, servodyn_input
from mpc_wt.registry import exportable, law_export
from mpc_wt.run import export_discon, run_controller
from mpc_wt.simulation.scenario import FieldMemo

pytestmark = pytest.mark.skipif(find_compiler() is None,
                                reason="no C compiler ($CC, cc, gcc, clang) to build the "
                                       "exported library")



@pytest.fixture(scope="module")
def nrel5mw():
    return linearize.load_turbine("nrel5mw")


def _export_fixture(kind: str, folder: str, options: dict | None = None):
    """A module-scoped fixture: ``kind`` exported (and built) for the NREL 5-MW."""
    @pytest.fixture(scope="module")
    def exported(nrel5mw, tmp_path_factory):
        return export_discon(nrel5mw, kind, tmp_path_factory.mktemp(folder), options)
    return exported


baseline_export = _export_fixture("baseline", "baseline")
mpc_export = _export_fixture("mpc", "mpc")
mpc_lidar_export = _export_fixture("mpc-lidar", "mpc_lidar")
lqr_export = _export_fixture("lqr-pio", "lqr")
ibc_export = _export_fixture("ibc", "ibc")
ts_export = _export_fixture("ts", "ts")
coleman_export = _export_fixture("coleman-ipc", "coleman")
apc_export = _export_fixture("apc", "apc", {"apc_frequency": 0.05})
ts_apc_export = _export_fixture("ts", "ts_apc", {"apc_frequency": 0.05})


def _discon(ex):
    opts = {"discon_library": str(ex.library), "discon_in": str(ex.input_file),
            "discon_dt": ex.dt}
    if ex.kind in ("mpc-lidar", "baseline+lidar-ff"):
        opts["lidar_records"] = True
    return opts


#: the cases' fields, made once for both runs of a comparison (bit for bit the same fields)
_FIELDS = FieldMemo()


def test_mpc_lidar_library_without_lidar_records_stops(nrel5mw, mpc_lidar_export):
    """Without the lidar records (a host that gives none) the library stops at its first
    call and says which records it needs."""
    opts = dict(_discon(mpc_lidar_export), lidar_records=False)
    with pytest.raises(ControllerLibraryError, match=r"avrSWAP 2001-2003: type 0, 0 beams, 0 "
                                                     r"pulse gates\) are no lidar it reads"):
        run_controller(nrel5mw, "discon", 12.0, opts, duration=1.0)


def test_ts_library_holds_a_minimum_pitch_schedule(nrel5mw, tmp_path):
    """TS on a torque law with a minimum-pitch schedule (0.8 deg above fine pitch over the
    whole speed range, so that it acts on the NREL 5-MW at 7 m/s, where the trim is at fine
    pitch; below the 1 deg at which the torque schedule reads region 3): the library's pitch
    rises from the trim's to the schedule's, within 0.05 deg after 30 s, never below fine
    pitch, at most at the drives' rate."""
    import dataclasses

    from mpc_wt.controllers.baseline import BaselineController, LawTorque
    from mpc_wt.run import design_controller, export_controller
    from mpc_wt.simulation.loop import simulate_closed_loop

    ctl = design_controller(nrel5mw, "ts")[0].designed
    law = ctl.torque_law
    g = dataclasses.replace(law.gains, min_pitch_speeds=(law.w_cutin, law.w_rated),
                            min_pitch_offsets=(math.radians(0.8), math.radians(0.8)))
    ctl.torque_law = BaselineController(nrel5mw, g)
    ctl._law = LawTorque(ctl.torque_law, ctl.dt)
    ex = export_controller(ctl, "ts", nrel5mw, tmp_path / "ts_min_pitch")
    lib = DisconController(ex.library, ex.input_file, nrel5mw)
    op = linearize.trim(nrel5mw, 7.0)
    r = simulate_closed_loop(linearize.plant_params(nrel5mw), lib, linearize.SteadyWind(7.0),
                             30.0, x0=op.x, u0=op.u)
    lib.finalize()
    pitch = np.degrees(r.u[:, 0])
    assert abs(pitch[-1] - 0.8) < 0.05 and pitch.min() >= -1e-6


def test_ibc_library_holds_the_amplitude(nrel5mw, tmp_path):
    """IBC with its largest pitch per blade at 0.3 deg, its library in the loop (class A, 120
    s, 18 m/s): no blade's IBC part beyond 0.3 deg, and the clamp acting (the part at the
    bound) more than a fifth of the time."""
    lib = run_controller(nrel5mw, "ibc", 18.0, {"max_amplitude_deg": 0.3}, duration=120.0,
                         turbulence="A", seed=11, fields=_FIELDS)
    ibc = np.degrees(np.abs([lib.channel(f"ibc_pitch_{b}") for b in (1, 2, 3)]))
    assert ibc.max() <= 0.3 + 1e-6 and np.mean(ibc > 0.3 - 1e-5) > 0.2


def test_cli_design_ibc_then_export_discon(tmp_path, capsys):
    """``mpcwt design ibc`` then ``mpcwt export --format discon`` builds IBC again with the
    design's loop gain; a design on a derated baseline is refused with its power fraction."""
    from mpc_wt.cli import main

    d = tmp_path / "ibc"
    assert main(["design", "ibc", "--loop-gain", "0.8", "--out", str(d)]) == 0
    assert main(["export", str(d), "--format", "discon"]) == 0
    text = (d / "mpcwt_ibc.in").read_text()
    gains = json.loads((d / "design.json").read_text())["schedule"]["rows"]
    lib = next(line for line in text.splitlines() if line.startswith("ibc_gain "))
    assert [float(v) for v in lib.split()[1:]] == pytest.approx([r[2] for r in gains],
                                                                 rel=1e-12)
    e = tmp_path / "derated"
    assert main(["design", "ibc", "--power-fraction", "0.8", "--out", str(e)]) == 0
    capsys.readouterr()
    assert main(["export", str(e), "--format", "discon"]) != 0
    assert "power fraction 0.8" in capsys.readouterr().err


def test_designs_that_know_more_than_measurements_do_not_export(nrel5mw, tmp_path):
    """Observers on the papers' measurement sets (Do et al.'s flap displacements, Clemens et
    al.'s tower-top displacements: no swap record carries them) are refused naming the
    signals; the paper-set options are gone ('observer_signals' is no option)."""
    from mpc_wt.controllers.lqr import LQRPIOController, design_lqr, design_pi_observer
    from mpc_wt.controllers.takagi_sugeno import (TSController, build_ts_model,
                                                  design_ts_controller, design_ts_observer)
    from mpc_wt.errors import OptionsError
    from mpc_wt.run import law_controller

    m = linearize.linearize(nrel5mw, 18.0, config=linearize.PlantConfig.do())
    lq = design_lqr(m, state_weights={"rotor_speed": 5.0})
    pio = LQRPIOController(m, nrel5mw, lq, design_pi_observer(m))     # the paper's signals
    with pytest.raises(ValueError, match="flap_1"):
        law_controller(pio, "lqr-pio", nrel5mw)
    ts = build_ts_model(nrel5mw, wind_grid=(12.0, 18.0, 25.0), reduction_grid=(0.0,))
    tsc = TSController(ts, design_ts_controller(ts), design_ts_observer(ts), nrel5mw)
    with pytest.raises(ValueError, match="tower_fa_displacement"):
        law_controller(tsc, "ts", nrel5mw)
    for kind in ("lqr-pio", "ts"):
        with pytest.raises(OptionsError, match="observer_signals"):
            export_discon(nrel5mw, kind, tmp_path / kind, {"observer_signals": "paper"},
                          build=False)


def test_a_single_point_lqr_pio_exports_as_a_schedule_of_one(nrel5mw, tmp_path):
    """Do et al.'s single design (``design_wind_mps``) exports as a schedule of one point:
    the input file holds one design at that wind."""
    ex = export_discon(nrel5mw, "lqr-pio", tmp_path / "one", {"design_wind_mps": 18.0},
                       build=False)
    text = ex.input_file.read_text()
    assert re.search(r"^n_points\s+1\b", text, re.M)
    assert re.search(r"^schedule\.grid\s+18\b", text, re.M)
    assert "point.1." not in text


def test_mpc_qp_over_budget_takes_the_logged_fallback(nrel5mw, mpc_export, tmp_path, caplog):
    """A QP time budget no solve can meet: every step takes the fallback (the last plan's
    rest, then the held command), the library reports it as a warning (aviFAIL = 1) that the
    host logs, and the run goes on to its end."""
    text = mpc_export.input_file.read_text().replace("\nqp_time_budget_ms ",
                                                     "\nqp_time_budget_ms 1e-9 # ")
    inp = tmp_path / "budget.in"
    inp.write_text(text)
    opts = dict(_discon(mpc_export), discon_in=str(inp))
    with caplog.at_level("WARNING"):
        r = run_controller(nrel5mw, "discon", 14.0, opts, duration=5.0, turbulence="A", seed=1)
    assert r.u.shape[0] == 401 and np.all(np.isfinite(r.u))
    msgs = [rec.getMessage() for rec in caplog.records
            if rec.name == "mpc_wt.controllers.discon"]
    assert len(msgs) >= 50 and all("fallback" in m and "budget" in m for m in msgs)
    assert "fallback 2 (1 so far)" in msgs[0] and "fallback 1 (2 so far)" in msgs[1]
    assert np.all(r.controller["library_warning"] == 1.0)


def test_export_writes_sources_makefile_input_and_servodyn(baseline_export, mpc_export):
    """The folder holds the sources, a Makefile that builds the same library, the input file
    with every key the library reads, and a ServoDyn file that openfast-io reads with the
    library, its input file and the interval set."""
    ex = baseline_export
    names = {p.name for p in ex.directory.iterdir()}
    assert {"discon.c", "input.c", "baseline.c", "mpcwt_discon.h", "Makefile"} <= names
    assert ex.library is not None and ex.library.is_file()
    text = ex.input_file.read_text()
    assert "kind baseline" in text and "format_version 1" in text
    from openfast_io.FAST_reader import InputReader_OpenFAST

    r = InputReader_OpenFAST()
    r.FAST_directory = str(ex.servodyn.parent)
    r.fst_vt["Fst"]["ServoFile"] = ex.servodyn.name
    r.read_ServoDyn()
    sd = r.fst_vt["ServoDyn"]
    assert (sd["PCMode"], sd["VSContrl"], sd["DLL_ProcName"]) == (5, 5, "DISCON")
    assert Path(sd["DLL_FileName"]) == ex.library.resolve()
    assert Path(sd["DLL_InFile"]) == ex.input_file.resolve()
    assert sd["DLL_DT"] == pytest.approx(0.0125)
    assert "DLL_DT" in mpc_export.servodyn.read_text() and mpc_export.dt == pytest.approx(0.1)
    assert (mpc_export.directory / "daqp" / "LICENSE").is_file()


@pytest.mark.skipif(shutil.which("make") is None, reason="no make")
def test_makefile_builds_the_library(baseline_export, tmp_path):
    (tmp_path / "daqp").mkdir()
    for p in baseline_export.sources + (baseline_export.makefile,):
        shutil.copy(p, tmp_path / p.relative_to(baseline_export.directory))
    out = subprocess.run(["make", "-s"], cwd=tmp_path, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert (tmp_path / baseline_export.library.name).is_file()


def test_the_same_sources_are_compiled_once_a_changed_one_again(baseline_export, tmp_path,
                                                                 caplog):
    """Exports of the same sources with the same compiler and flags share one compilation: the
    second library is a file of its own with the first one's bytes. A changed source is
    compiled again, and so are the same sources once the library compiled first is gone; each
    library loads and answers."""
    def build(name: str, edit: bool) -> tuple[Path, bool]:
        d = tmp_path / name
        (d / "daqp").mkdir(parents=True)
        for p in baseline_export.sources:
            shutil.copy(p, d / p.relative_to(baseline_export.directory))
        if edit:
            c_file = sorted(d.glob("*.c"))[0]
            c_file.write_text(c_file.read_text() + "\n/* another source */\n")
        caplog.clear()
        with caplog.at_level("DEBUG", logger="mpc_wt.io.discon_export"):
            lib = build_library(d, "baseline")
        assert ctypes.CDLL(str(lib)).DISCON is not None
        return lib, "copied" in caplog.text

    same, copied = build("same", False)
    assert copied and same.read_bytes() == baseline_export.library.read_bytes()
    assert not same.samefile(baseline_export.library)
    first, copied = build("changed", True)
    assert not copied
    second, copied = build("changed_too", True)
    assert copied and second.read_bytes() == first.read_bytes()
    first.unlink()
    _, copied = build("changed_again", True)
    assert not copied


def test_iea15_baseline_library_holds_the_minimum_pitch_schedule(tmp_path):
    """The IEA-15's baseline exported and run at 5 m/s (class A, 120 s): the minimum-pitch
    schedule holds the mean pitch more than 2 deg above fine (the published schedule: 2.5-3.9
    deg at the rotor speeds of 5 m/s)."""
    iea = linearize.load_turbine("iea15mw")
    ex = export_discon(iea, "baseline", tmp_path / "iea")
    lib = run_controller(iea, "discon", 5.0, _discon(ex), duration=120.0, turbulence="A",
                         seed=11, fields=_FIELDS)
    assert math.degrees(float(np.mean(lib.u[:, 0]))) > 2.0


def test_iea15_export_has_its_deck_servodyn(tmp_path):
    iea = linearize.load_turbine("iea15mw")
    ex = export_discon(iea, "baseline", tmp_path, build=False)
    assert ex.library is None and ex.servodyn is not None
    text = ex.servodyn.read_text()
    assert '"DISCON"' in text and "PCMode" in text


# -- the library alone, through ctypes ------------------------------------------------------
class _Lib:
    """The DISCON entry of a library loaded with ctypes (one copy: instances share it)."""

    def __init__(self, path):
        self.lib = ctypes.CDLL(str(path))
        self.fn = self.lib.DISCON
        self.fn.restype = None

    def call(self, swap, infile, outname):
        fail = ctypes.c_int(0)
        msg = ctypes.create_string_buffer(1025)
        out = ctypes.create_string_buffer(outname.encode(), 1025)
        self.fn(swap.ctypes.data_as(ctypes.POINTER(ctypes.c_float)), ctypes.byref(fail),
                str(infile).encode(), out, msg)
        return fail.value, msg.value.decode()


def _swap(status, t, gen_speed, pitch=0.05, dt=0.0125, infile="x"):
    s = np.zeros(3300, np.float32)
    s[[0, 1, 2, 3, 32, 33, 19, 20]] = (status, t, dt, pitch, pitch, pitch, gen_speed,
                                       gen_speed / 97.0)
    s[48], s[49], s[50] = 1025, len(str(infile)) + 1, 1025
    return s


def _copy(lib_path, tmp_path, name):
    p = tmp_path / name
    shutil.copy(lib_path, p)
    return p


def test_two_turbines_on_one_copy_keep_their_own_state(baseline_export, tmp_path):
    """One loaded copy, two root names called in turn, against each run alone on a fresh copy
    of its own: the demands agree bit for bit."""
    inp = baseline_export.input_file
    speeds = {"a": 120.0 + 3.0 * np.sin(np.arange(200) * 0.1),
              "b": 126.0 + 2.0 * np.cos(np.arange(200) * 0.07)}

    def run(lib, names):
        out = {n: [] for n in names}
        for k in range(200):
            for n in names:
                s = _swap(0 if k == 0 else 1, k * 0.0125, speeds[n][k], infile=inp)
                fail, msg = lib.call(s, inp, n)
                assert fail == 0, msg
                out[n].append(s[[41, 46]].copy())
        return {n: np.array(v) for n, v in out.items()}

    both = run(_Lib(_copy(baseline_export.library, tmp_path, "both.so")), ["a", "b"])
    alone_a = run(_Lib(_copy(baseline_export.library, tmp_path, "a.so")), ["a"])
    alone_b = run(_Lib(_copy(baseline_export.library, tmp_path, "b.so")), ["b"])
    assert np.array_equal(both["a"], alone_a["a"])
    assert np.array_equal(both["b"], alone_b["b"])
    assert not np.array_equal(both["a"], both["b"])


def test_two_hosts_side_by_side(nrel5mw, baseline_export):
    """Two DisconController hosts (each its own copy) stepped in turn give what each gives
    alone."""
    def meas(w):
        return {"gen_speed": w, "rotor_speed": w / 97.0, "pitch": np.full(3, 0.05),
                "flap_moment": np.zeros(3), "edge_moment": np.zeros(3)}

    def host():
        c = DisconController(baseline_export.library, baseline_export.input_file, nrel5mw)
        c.reset()
        return c

    a, b = host(), host()
    wa = 121.0 + np.sin(np.arange(100) * 0.2)
    wb = 125.0 + np.cos(np.arange(100) * 0.3)
    pair = [(a.step(k * 0.0125, meas(wa[k]))[0][0], b.step(k * 0.0125, meas(wb[k]))[0][0])
            for k in range(100)]
    a.finalize(), b.finalize()
    solo = host()
    alone = [solo.step(k * 0.0125, meas(wa[k]))[0][0] for k in range(100)]
    solo.finalize()
    assert [p[0] for p in pair] == alone


@pytest.mark.parametrize("edit, words", [
    (lambda t: None, ["cannot open", "missing.in"]),
    (lambda t: "\n".join(l for l in t.splitlines() if not l.startswith("kp ")),
     ["'kp'", "missing"]),
    (lambda t: t.replace("\nki ", "\nki x1.5 # "), ["'ki'", "'x1.5'", "not a finite number"]),
    (lambda t: t.replace("\nki ", "\nki nan # "), ["'ki'", "'nan'"]),
    (lambda t: t.replace("kind baseline", "kind turbo"), ["'turbo'", "baseline"]),
    (lambda t: t.replace("format_version 1", "format_version 7"), ["format_version", "7"]),
    (lambda t: t.replace("\ndt ", "\ndt 0.05 # "), ["DLL_DT", "0.05", "0.0125"]),
    (lambda t: t + "kp 1.0\n", ["'kp'", "twice"]),
    (lambda t: t.replace("\npitch_max ", "\npitch_max -1 # "), ["pitch_max >= pitch_min"]),
    (lambda t: t.replace("\nmin_pitch_offsets ", "\nmin_pitch_offsets 0 -0.1 # "),
     ["min_pitch_offsets", "increasing", ">= 0 rad"]),
    (lambda t: t.replace("\nmin_pitch_offsets ", "\nmin_pitch_offsets 0.1 0 0 # "),
     ["min_pitch_offsets", "as many values", "got 2 and 3"]),
])
def test_bad_input_file_fails_with_the_file_and_key(nrel5mw, baseline_export, tmp_path, edit,
                                                     words):
    """A missing or corrupt input file stops the first call with aviFAIL < 0 and a message
    that names the file and the key."""
    text = edit(baseline_export.input_file.read_text())
    path = tmp_path / "missing.in"
    if text is not None:
        path = tmp_path / "bad.in"
        path.write_text(text)
    ctl = DisconController(baseline_export.library, baseline_export.input_file, nrel5mw)
    ctl.discon_in = path                      # the host checks the file exists: bypass it
    msg = _first_call_error(ctl)
    assert "aviFAIL = -1" in msg
    for w in words:
        assert w in msg, (w, msg)
    if text is not None:
        assert "bad.in" in msg


def _first_call_error(ctl):
    """The message of the ControllerLibraryError the library's first call raises."""
    ctl.reset()
    with pytest.raises(ControllerLibraryError) as err:
        ctl.step(0.0, {"gen_speed": 120.0, "rotor_speed": 1.2, "pitch": np.zeros(3),
                       "flap_moment": np.zeros(3), "edge_moment": np.zeros(3)})
    ctl.finalize()
    return str(err.value)


def _first_call_names_the_key(turbine, ex, edit, words, tmp_path):
    """The export's input file edited by ``edit``: the library's first call stops with
    aviFAIL < 0 and a message naming the file and each of ``words``."""
    text = edit(ex.input_file.read_text())
    assert text != ex.input_file.read_text()
    path = tmp_path / "bad.in"
    path.write_text(text)
    ctl = DisconController(ex.library, path, turbine, dt=ex.dt)
    msg = _first_call_error(ctl)
    assert "aviFAIL = -1" in msg and "bad.in" in msg
    for w in words:
        assert w in msg, (w, msg)


@pytest.mark.parametrize("kind, edit, words", [
    ("lqr-pio", lambda t: t.replace("\npoint.3.sizes ", "\npoint.3.sizes 14 3 5 4 3 7 1 # "),
     ["'point.3.sizes'", "region 2 or 3"]),
    ("lqr-pio", lambda t: t.replace("\nsignals ", "\nsignals 1 8 5 6 12 # "),
     ["'signals'", "value 5 is 12"]),
    ("lqr-pio", lambda t: "\n".join(l for l in t.splitlines()
                                     if not l.startswith("point.20.bd ")), ["'point.20.bd'"]),
    ("ts", lambda t: t.replace("\nterms ", "\nterms 0 # "), ["'terms'", "pairs"]),
    ("ts", lambda t: t.replace("\nstart_pitch ", "\nstart_pitch 0.3 0.2 0.1 0 0 0 # "),
     ["'start_pitch'", "must not decrease"]),
    ("ts", lambda t: t.replace("\nsizes ", "\nsizes 6 3 8 2 4 7 2 0 # "),
     ["'sizes'", "gain columns"]),
])
def test_bad_lqr_and_ts_input_files_name_the_key(nrel5mw, lqr_export, ts_export, tmp_path,
                                                  kind, edit, words):
    """A corrupt LQR-PIO or TS input file stops the first call with aviFAIL < 0 and a message
    naming the file and the key."""
    ex = lqr_export if kind == "lqr-pio" else ts_export
    _first_call_names_the_key(nrel5mw, ex, edit, words, tmp_path)


@pytest.mark.parametrize("kind, edit, words", [
    ("coleman-ipc", lambda t: re.sub(r"\ncoleman_pitch +\S+", "\ncoleman_pitch 9", t),
     ["'coleman_pitch'", "must increase"]),
    ("coleman-ipc", lambda t: t.replace("\ncoleman_settings ",
                                        "\ncoleman_settings 0.95 0.8 5e6 0.9 0 1.5 0.1 0.03 # "),
     ["'coleman_settings'", "power fractions increasing"]),
    ("coleman-ipc", lambda t: re.sub(r"\nibc +0", "\nibc 1\nibc_settings 0.8 0.95 5e6 0.9 0 "
                                        "1.5 0.1 1 0.03\nibc_gain_pitch 0 0.3\nibc_gain 1e-8 "
                                        "1e-8\nibc_input_sos 1 0 0 1 0 0\nibc_input_zi 0 0\n"
                                        "ibc_output_sos 1 0 0 1 0 0\nibc_output_zi 0 0\n#", t),
     ["'ibc' and 'coleman_ipc' are both 1"]),
    ("apc", lambda t: t.replace("\napc_schedule ", "\napc_schedule 1 2 3 # "),
     ["'apc_schedule'", "designs of 5 values"]),
    ("apc", lambda t: t.replace("\napc ", "\napc -0.1 0.375 0.375 5e6 # "),
     ["'apc'", "frequency >= 0 Hz"]),
])
def test_bad_coleman_and_apc_input_files_name_the_key(nrel5mw, coleman_export, apc_export,
                                                       tmp_path, kind, edit, words):
    """A corrupt Coleman IPC or APC input file (a schedule that does not increase, settings out
    of range, IBC and Coleman IPC both on, a schedule of the wrong length, a negative
    frequency) stops the first call with aviFAIL < 0 and a message naming the file and the
    key."""
    ex = coleman_export if kind == "coleman-ipc" else apc_export
    _first_call_names_the_key(nrel5mw, ex, edit, words, tmp_path)


def test_non_finite_speed_stops_with_the_record(baseline_export, tmp_path):
    lib = _Lib(_copy(baseline_export.library, tmp_path, "nan.so"))
    inp = baseline_export.input_file
    assert lib.call(_swap(0, 0.0, 120.0, infile=inp), inp, "r")[0] == 0
    fail, msg = lib.call(_swap(1, 0.0125, math.nan, infile=inp), inp, "r")
    assert fail < 0 and "record 20" in msg and "0.0125" in msg
    fail, msg = lib.call(_swap(1, 0.0, 120.0, infile=inp), inp, "never-started")
    assert fail < 0 and "status 0" in msg
    assert lib.call(_swap(-1, 0.025, 120.0, infile=inp), inp, "r")[0] == 0


def _asan_runtime() -> str | None:
    cc = find_compiler()
    if cc is None or sys.platform != "linux":
        return None
    out = subprocess.run([cc, "-print-file-name=libasan.so"], capture_output=True, text=True)
    path = out.stdout.strip()
    return path if os.path.isabs(path) and os.path.isfile(path) else None


@pytest.mark.skipif(_asan_runtime() is None, reason="no AddressSanitizer runtime (libasan)")
def test_sanitized_libraries_run_60_s_clean(baseline_export, mpc_export, mpc_lidar_export,
                                             lqr_export, ts_export, ibc_export, coleman_export,
                                             apc_export, ts_apc_export, tmp_path):
    """The baseline, the MPC, the MPC with LIDAR preview, the LQR-PIO, the TS controller (also
    with its power reduction), IBC, Coleman IPC and active power control built with
    -fsanitize=address,undefined (any report aborts), 60 s of turbulent closed loop each in a
    process that loads the sanitizer runtime first: exit 0, no report, no warning from the
    library."""
    # each law's library (the kinds of one law share it) built with the sanitizers
    libs = {}
    for ex in (baseline_export, mpc_export, lqr_export, ts_export):
        d = tmp_path / f"asan_{ex.kind}"
        (d / "daqp").mkdir(parents=True)
        for p in ex.sources:
            shutil.copy(p, d / p.relative_to(ex.directory))
        libs[ex.kind] = build_library(d, ex.kind, sanitize=True, name="libasan_mpcwt.so")
    law = {"mpc-lidar": "mpc", "ibc": "baseline", "coleman-ipc": "baseline",
           "apc": "baseline"}
    exports = (baseline_export, mpc_export, mpc_lidar_export, lqr_export, ts_export,
               ibc_export, coleman_export, apc_export, ts_apc_export)
    runs = [dict(_discon(ex), discon_library=str(libs[law.get(ex.kind, ex.kind)]))
            for ex in exports]
    script = textwrap.dedent(f"""
        import linearize
        from mpc_wt.run import run_controller
        t = linearize.load_turbine("nrel5mw")
        for opts in {runs!r}:
            r = run_controller(t, "discon", 15.0, opts, duration=60.0, turbulence="A", seed=2)
            print("steps", r.u.shape[0], "warnings", int(r.controller["library_warning"].sum()))
    """)
    env = dict(os.environ, LD_PRELOAD=_asan_runtime(),
               ASAN_OPTIONS="detect_leaks=0:abort_on_error=1",
               UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1")
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         env=env, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    assert "AddressSanitizer" not in out.stderr and "runtime error" not in out.stderr
    assert out.stdout.count("steps 4801 warnings 0") == len(exports), out.stdout


def test_kinds_that_do_not_export_are_named(nrel5mw, tmp_path):
    with pytest.raises(ValueError, match="does not export.*'coleman-ipc'"):
        export_discon(nrel5mw, "rosco", tmp_path)
    with pytest.raises(ValueError, match="LIDAR"):
        from mpc_wt.io.discon_export import controller_input
        from mpc_wt.run import design_controller
        controller_input(design_controller(nrel5mw, "mpc-lidar")[0].controller,
                         law_export("mpc"), nrel5mw)
    assert {"baseline", "derate", "ibc", "coleman-ipc", "apc"} <= set(exportable())
    assert law_export("derate80+ibc") is law_export("ibc")     # on a derated baseline too
    with pytest.raises(ValueError, match="the kinds that do: .*'ibc'"):
        law_export("mpc+ibc")


def test_servodyn_template_without_the_keys(tmp_path, baseline_export):
    bad = tmp_path / "sd.dat"
    bad.write_text("ServoDyn\n5 PCMode - x\n")
    with pytest.raises(ValueError, match="DLL_FileName"):
        servodyn_input(bad, tmp_path / "o.dat", baseline_export.library,
                       baseline_export.input_file, 0.0125)


def test_cli_design_then_export_discon(tmp_path, capsys):
    """``mpcwt design baseline`` then ``mpcwt export --format discon``: the library of the
    saved gains (a derated design keeps its derated rated power); a Coleman IPC design
    exports, but not one on a derated baseline (the saved design cannot say its base)."""
    from mpc_wt.cli import main

    d = tmp_path / "design"
    assert main(["design", "baseline", "--power-fraction", "0.8", "--out", str(d)]) == 0
    assert main(["export", str(d), "--format", "discon", "--out", str(d / "lib")]) == 0
    assert "libmpcwt_baseline" in capsys.readouterr().out
    text = (d / "lib" / "mpcwt_baseline.in").read_text()
    rated = next(float(line.split()[1]) for line in text.splitlines()
                 if line.startswith("rated_power "))
    assert rated == pytest.approx(0.8 * 5e6)
    assert (d / "lib" / "ServoDyn_mpcwt_baseline.dat").is_file()
    i = tmp_path / "coleman"
    assert main(["design", "coleman-ipc", "--out", str(i)]) == 0
    assert main(["export", str(i), "--format", "discon"]) == 0
    assert re.search(r"^coleman_ipc\s+1", (i / "mpcwt_coleman_ipc.in").read_text(), re.M)
    assert main(["design", "coleman-ipc", "--power-fraction", "0.8", "--out", str(i)]) == 0
    assert main(["export", str(i), "--format", "discon"]) != 0
    err = capsys.readouterr().err
    assert "derated baseline (power fraction 0.8)" in err and "derate80+coleman-ipc" in err


def test_cli_design_mpc_then_export_discon(tmp_path, capsys):
    """``mpcwt design mpc`` writes the grid's trim table and plot, and the torque notch;
    ``mpcwt export --format discon`` builds the MPC again from the design's options and
    exports it, notch included."""
    from mpc_wt.cli import main

    d = tmp_path / "mpc"
    assert main(["design", "mpc", "--out", str(d)]) == 0
    assert (d / "gains.png").stat().st_size > 0
    doc = json.loads((d / "design.json").read_text())
    rows = np.array(doc["schedule"]["rows"])
    assert doc["kind"] == "mpc" and rows[0, 0] == 3.0 and rows[-1, 0] == 25.0
    assert np.all(rows[:, 5] < 1.0)                  # every Kalman filter stable
    # the notch on the torque command at the drivetrain mode (1.76 Hz on the NREL 5-MW)
    assert 1.6 < doc["settings"]["torque_notch_hz"] < 1.9
    assert doc["settings"]["torque_notch_q"] == 2.0
    assert main(["export", str(d), "--format", "discon"]) == 0
    assert "libmpcwt_mpc" in capsys.readouterr().out
    text = (d / "mpcwt_mpc.in").read_text()
    assert "kind mpc" in text
    assert re.search(r"^torque_notch\s+1(\.0)?\s", text, re.M)
    assert (d / library_name("mpc")).is_file()


def test_cli_design_lidar_ff_then_export_discon(tmp_path, capsys):
    """``mpcwt design baseline+lidar-ff``: the filter corner over wind (rising with the wind,
    as the LIDAR-rotor coherence bandwidth does) and the static pitch curve; the export builds
    the feedforward again from the design's options."""
    from mpc_wt.cli import main

    d = tmp_path / "ff"
    assert main(["design", "baseline+lidar-ff", "--out", str(d)]) == 0
    rows = np.array(json.loads((d / "design.json").read_text())["schedule"]["rows"])
    assert rows[-1, 1] > rows[0, 1] > 0 and rows[-1, 2] > rows[0, 2]
    assert main(["export", str(d), "--format", "discon"]) == 0
    assert "kind baseline" in (d / "mpcwt_baseline_lidar_ff.in").read_text()
    assert "feedforward" in (d / "mpcwt_baseline_lidar_ff.in").read_text()


def test_cli_design_lqr_pio_and_ts_then_export_discon(tmp_path, capsys):
    """``mpcwt design lqr-pio`` tabulates the scheduled designs from cut-in to cut-out (region
    II below the rated wind, III above) and exports as a library built again from the design's
    options (the TS kind's export is the ``ts_export`` fixture's). A ``mpcwt design ts`` on
    another vertex grid than the kind's is refused with both grids named."""
    from mpc_wt.cli import main

    d = tmp_path / "lqr"
    assert main(["design", "lqr-pio", "--out", str(d)]) == 0
    doc = json.loads((d / "design.json").read_text())
    rows = np.array(doc["schedule"]["rows"])
    rated = linearize.rated_wind_speed(linearize.load_turbine("nrel5mw"))
    assert doc["kind"] == "lqr-pio" and rows[0, 0] == 3.0 and rows[-1, 0] == 25.0
    assert np.all((rows[:, -1] == 2) == (rows[:, 0] < rated))
    assert doc["settings"]["measured"][1] == "tower_fa_acceleration"
    assert main(["export", str(d), "--format", "discon"]) == 0
    assert "libmpcwt_lqr_pio" in capsys.readouterr().out
    assert "kind lqr" in (d / "mpcwt_lqr_pio.in").read_text()
    t = tmp_path / "ts"
    assert main(["design", "ts", "--wind", "12:25:13", "--reductions", "0", "--out",
                 str(t)]) == 0
    doc = json.loads((t / "design.json").read_text())
    assert doc["settings"]["measured"][0] == "tower_fa_acceleration"
    capsys.readouterr()
    assert main(["export", str(t), "--format", "discon"]) != 0
    err = capsys.readouterr().err
    assert "[12.0, 25.0]" in err and "[12.0, 14.0, 16.0, 19.0, 22.0, 25.0]" in err


def test_export_for_a_users_deck_writes_its_servodyn_and_inflowwind_files(tmp_path):
    """A turbine read from an OpenFAST deck (the rosco package's NREL-5MW): the export writes a
    copy of that deck's ServoDyn file pointed at the library, and for a LIDAR kind a copy of its
    InflowWind file with five single points 54 m upwind on the CW lidar's ring (r = 54
    tan(cone)); a turbine without a deck gets the note instead."""
    pytest.importorskip("rosco")
    from linearize.openfast import OpenFASTFile
    from mpc_wt.controllers.discon import rosco_discon

    fst = next(rosco_discon("NREL-5MW").parent.glob("*.fst"))
    t = linearize.load_openfast(fst)
    ex = export_discon(t, "baseline+lidar-ff", tmp_path / "ff", build=False)
    srv = OpenFASTFile(ex.servodyn)
    assert Path(srv.text("DLL_FileName")) == (tmp_path / "ff" / library_name(
        "baseline+lidar-ff")).resolve()
    assert srv.text("DLL_InFile") == str(ex.input_file.resolve())
    iw = OpenFASTFile(ex.inflow)
    assert iw.integer("SensorType") == 1 and iw.integer("NumBeam") == 5
    x, y, z = (iw.numbers(f"FocalDistance{c}") for c in "XYZ")
    np.testing.assert_allclose(x, -54.0, atol=1e-4)
    np.testing.assert_allclose(np.hypot(y, z), 54.0 * math.tan(math.radians(41.19)), rtol=1e-3)
    assert ex.inflow in ex.files()
    plain = export_discon(linearize.load_turbine("nrel5mw"), "baseline", tmp_path / "b",
                          build=False)
    assert plain.inflow is None


def test_a_design_with_nan_gains_is_refused_at_export_naming_the_key(tmp_path, capsys):
    """A saved baseline design whose kp was made NaN (``design.json`` edited): ``mpcwt export
    --format discon`` stops with exit 2 naming the key, before writing or compiling anything
    (it wrote ``kp nan`` and compiled a library its own reader then refused)."""
    import json

    from mpc_wt.cli import main

    d = tmp_path / "design"
    assert main(["design", "baseline", "--out", str(d)]) == 0
    doc = json.loads((d / "design.json").read_text())
    doc["settings"]["kp"] = float("nan")
    (d / "design.json").write_text(json.dumps(doc))
    capsys.readouterr()
    assert main(["export", str(d), "--format", "discon", "--out", str(d / "lib")]) == 2
    err = capsys.readouterr().err
    assert "'kp'" in err and "not finite" in err
    assert not (d / "lib" / "mpcwt_baseline.in").exists()

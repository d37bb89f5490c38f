"""OpenFAST outputs (.out, .outb, CSV with OpenFAST names) read into assessment, checked
against openfast-io's reader (a peer) and against our own run written in OpenFAST's layout."""
from __future__ import annotations

import json

import numpy as np
import pytest
from openfast_io.FAST_output_reader import FASTOutputFile

from mpc_wt.cli import main
from mpc_wt.errors import ResultFileError
from mpc_wt.io.openfast_output import (
    from_mpcwt_channels,
    read_openfast_output,
    write_openfast_output,
)
from mpc_wt.simulation.results import load_series
from mpc_wt.simulation.scenario import Scenario


@pytest.fixture(scope="module")
def series() -> tuple[np.ndarray, dict[str, np.ndarray], dict[str, str]]:
    rng = np.random.default_rng(19)
    t = np.arange(0.0, 100.0, 0.05)
    ch = {"RootMyb1": 8000 + 1500 * np.sin(1.27 * t) + 300 * rng.standard_normal(t.size),
          "BldPitch1": 10 + 2 * np.sin(0.1 * t), "GenSpeed": 1173.7 + 20 * np.sin(0.3 * t),
          "GenPwr": 5000 + 50 * rng.standard_normal(t.size),
          "TwrBsMyt": 60000 + 9000 * np.sin(0.33 * 2 * np.pi * t),
          "OoPDefl1": 4 + 0.2 * np.sin(t)}
    units = {"RootMyb1": "kN-m", "BldPitch1": "deg", "GenSpeed": "rpm", "GenPwr": "kW",
             "TwrBsMyt": "kN-m", "OoPDefl1": "m"}
    return t, ch, units


@pytest.mark.parametrize("suffix, fmt", [(".out", 3), (".outb", 3), (".outb", 1), (".outb", 2),
                                         (".outb", 4)])
def test_reader_agrees_with_openfast_io(tmp_path, series, suffix, fmt) -> None:
    """Each OpenFAST output format read by us and by openfast-io's FASTOutputFile: the same
    names, units, time and values (to float32 scaling round-off for the 16-bit formats; the
    values themselves keep 16 bits, 1/65535 of each channel's range, as OpenFAST writes)."""
    t, ch, units = series
    p = write_openfast_output(tmp_path / f"run{suffix}", t, ch, units, binary_format=fmt)
    ours = read_openfast_output(p)
    peer = FASTOutputFile(str(p))
    assert list(ours.names) == peer.info["attribute_names"][1:]
    assert list(ours.units) == peer.info["attribute_units"][1:]
    np.testing.assert_allclose(ours.t, peer.data[:, 0] if peer.data.shape[1] == len(ch) + 1
                               else t, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(ours.data, peer.data[:, -len(ch):], rtol=1e-12, atol=1e-9)
    written = np.column_stack(list(ch.values()))
    if fmt == 3:                          # text with repr() and float64 binary are exact
        np.testing.assert_array_equal(ours.data, written)
    else:                                 # half a 16-bit step of each channel's range
        span = np.ptp(written, axis=0)
        assert np.all(np.abs(ours.data - written) <= 0.5 * span / 65535 * (1 + 1e-5))


def test_channels_mapped_to_ours_in_si(tmp_path, series) -> None:
    """kN-m -> N m, deg -> rad, rpm -> rad/s, kW -> W; unmapped channels keep their names;
    ElastoDyn's blade-frame root moment (``RootMyb``) is ours flapwise, not out-of-plane."""
    t, ch, units = series
    p = write_openfast_output(tmp_path / "run.outb", t, ch, units)
    tt, cols = load_series(p)
    np.testing.assert_array_equal(tt, t)
    np.testing.assert_allclose(cols["flapwise_moment_1"], ch["RootMyb1"] * 1e3, rtol=1e-15)
    assert "flap_moment_1" not in cols
    np.testing.assert_allclose(cols["pitch_1"], np.radians(ch["BldPitch1"]), rtol=1e-15)
    np.testing.assert_allclose(cols["gen_speed"], ch["GenSpeed"] * np.pi / 30, rtol=1e-15)
    np.testing.assert_allclose(cols["gen_power"], ch["GenPwr"] * 1e3, rtol=1e-15)
    np.testing.assert_array_equal(cols["OoPDefl1"], ch["OoPDefl1"])


def test_assess_openfast_run_beside_ours(tmp_path, capsys) -> None:
    """One of our runs, written as an OpenFAST .outb (our channels in OpenFAST names and units)
    and as CSV with OpenFAST headers, assessed beside the original: the same DELs (exactly for
    the float64 format, to the 16-bit quantization for FileFmtID 2) and ``relative_to_first``
    near zero."""
    import linearize
    from mpc_wt.run import run_controller

    res = run_controller(linearize.load_turbine("nrel5mw"), "baseline", Scenario(14.0, "B", 3, 120.0))
    nc = res.save(tmp_path / "ours.nc")
    cols = {n: res.channel(n) for n in res.channels()}
    of, units = from_mpcwt_channels(cols)
    assert {"RootMyc1", "RootMyb1", "TwrBsMyt", "GenPwr", "BldPitch1"} <= set(of)
    exact = write_openfast_output(tmp_path / "openfast.outb", res.t, of, units)
    packed = write_openfast_output(tmp_path / "packed.outb", res.t, of, units, binary_format=2)
    csv_path = tmp_path / "openfast.csv"
    header = ["Time_[s]"] + [f"{n}_[{units[n]}]" for n in of]
    rows = np.column_stack([res.t] + list(of.values()))
    csv_path.write_text(",".join(header) + "\n"
                        + "\n".join(",".join(repr(float(v)) for v in r) for r in rows) + "\n")
    assert main(["assess", str(nc), str(exact), str(packed), str(csv_path), "--t-start", "20",
                 "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    base = out[0]["channels"]
    for run, tol in ((out[1], 1e-9), (out[3], 1e-9), (out[2], 2e-3)):
        for name in ("flap_moment_1", "tower_base_fa_moment", "lss_torque"):
            assert run["channels"][name]["del"] == pytest.approx(base[name]["del"], rel=tol)
    assert out[1]["power_std_W"] == pytest.approx(out[0]["power_std_W"], rel=1e-9)


def test_bad_openfast_files_are_named(tmp_path, series) -> None:
    t, ch, units = series
    bad_unit = write_openfast_output(tmp_path / "u.out", t, {"RootMyb1": ch["RootMyb1"]},
                                     {"RootMyb1": "deg"})
    with pytest.raises(ResultFileError, match=r"channel 'RootMyb1' has unit 'deg'; allowed"):
        load_series(bad_unit)
    good = write_openfast_output(tmp_path / "g.outb", t, ch, units)
    trunc = tmp_path / "t.outb"
    trunc.write_bytes(good.read_bytes()[:-100])
    with pytest.raises(ResultFileError, match=r"t.outb: truncated at byte"):
        load_series(trunc)
    junk = tmp_path / "j.outb"
    junk.write_bytes(b"\x07\x00" + good.read_bytes()[2:])
    with pytest.raises(ResultFileError, match=r"FileFmtID 7 is not an OpenFAST binary"):
        load_series(junk)
    with pytest.raises(ResultFileError, match=r"no header line starting with 'Time'"):
        (tmp_path / "x.out").write_text("nothing here\n1 2 3\n")
        load_series(tmp_path / "x.out")
    with pytest.raises(ResultFileError, match=r"suffix '\.txt' is not a run file"):
        (tmp_path / "r.txt").write_text("")
        load_series(tmp_path / "r.txt")


def test_files_cut_or_mislabelled_are_refused(tmp_path, series) -> None:
    """A text output or CSV cut in the middle of a number (its last line without a line end:
    the last RotTorq was read as 4 instead of about 4100), a CSV with two columns of one
    name, a CSV whose time steps by 50 per sample without a unit (ms: energy 1000x) are
    refused naming the file and what is wrong; the same CSV with ``time [ms]`` in its header
    is read in seconds."""
    t, ch, units = series
    good = write_openfast_output(tmp_path / "g.out", t, ch, units)
    text = good.read_text()
    cut = tmp_path / "cut.out"
    cut.write_text(text.rstrip("\n")[:-3])
    with pytest.raises(ResultFileError, match=r"cut.out: line \d+ ends without a line end"):
        load_series(cut)
    rows = "\n".join(f"{a:.2f},{b:.1f},{5e6:.1f}" for a, b in zip(t, ch["RootMyb1"] * 1e3))
    (tmp_path / "cut.csv").write_text("time,flap_moment_1,gen_power\n" + rows[:-4])
    with pytest.raises(ResultFileError, match=r"cut.csv: line 2001 ends without a line end"):
        load_series(tmp_path / "cut.csv")
    (tmp_path / "two.csv").write_text("time,flap_moment_1,flap_moment_1\n" + rows + "\n")
    with pytest.raises(ResultFileError, match=r"the columns \['flap_moment_1'\] appear more "
                                              r"than once"):
        load_series(tmp_path / "two.csv")
    ms = "\n".join(f"{1000 * a:.1f},{b:.1f},{5e6:.1f}" for a, b in zip(t, ch["RootMyb1"]))
    (tmp_path / "ms.csv").write_text("time,flap_moment_1,gen_power\n" + ms + "\n")
    with pytest.raises(ResultFileError, match=r"time column 'time' steps by 50 per sample, more "
                                              r"than 1 s: if it is in ms"):
        load_series(tmp_path / "ms.csv")
    (tmp_path / "ms2.csv").write_text("time [ms],flap_moment_1,gen_power\n" + ms + "\n")
    t2, cols = load_series(tmp_path / "ms2.csv")
    np.testing.assert_allclose(t2, t, atol=1e-9)
    assert set(cols) == {"flap_moment_1", "gen_power"}


def test_assess_cli_names_unknown_channel_of_openfast_run(tmp_path, series, capsys) -> None:
    t, ch, units = series
    p = write_openfast_output(tmp_path / "run.out", t, ch, units)
    assert main(["assess", str(p), "--channels", "RootMyb9"]) == 2
    assert "RootMyb9" in capsys.readouterr().err

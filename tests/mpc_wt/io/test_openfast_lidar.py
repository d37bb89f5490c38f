"""OpenFAST v5.0.0's lidar as the exported LIDAR kinds meet it.

InflowWind v5.0.0 gives a controller a single-point lidar (``SensorType 1``, up to 5 beams at
points fixed relative to the hub, the wind's magnitude |V| at each) or one CW or pulsed beam;
ServoDyn writes them to records 2001-2500 (``Lidar.f90``, ``BladedInterface_EX.f90``). The
libraries fit the single points' 1P over the rotor's azimuth and read each blade's wind at its
own azimuth; mpc-wt's host fills the records as OpenFAST does (:class:`lidar.PointLidar`),
checked record by record against a logging library run inside OpenFAST (skipped without it).
"""
from __future__ import annotations

import csv
import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import linearize
import lidar
from mpc_wt.controllers.discon import DisconController
from mpc_wt.io.discon_export import find_compiler
from mpc_wt.io.openfast_case import read_openfast_case
from mpc_wt.io.openfast_run import prepare_deck, run_openfast
from mpc_wt.run import run_openfast_case
from mpc_wt.simulation.loop import simulate_closed_loop
from openfast_here import SHARED, exported, installed_openfast

_RTEST = SHARED / "validation" / "nrel5mw" / "openfast_rtest"
_FST = _RTEST / "5MW_Land_DLL_WTurb_v5" / "5MW_Land_DLL_WTurb.fst"
#: three single points 54 m upwind, r = 47.25 m at azimuths 0 / 120 / 240 deg (the docs' file)
_LIDAR3 = _RTEST / "5MW_Baseline" / "NRELOffshrBsline5MW_InflowWind_12mps_lidar3.dat"
_PROBE_C = Path(__file__).resolve().parents[2] / "data" / "discon_probe.c"
_R = 47.25


def _ring(n: int) -> np.ndarray:
    """n points 54 m upwind at r = 47.25 m, blade-1-up azimuths 0, 360/n, ... (y = -r sin,
    z = r cos: OpenFAST's frame, the rotor turning from up toward -y)."""
    psi = 2.0 * np.pi * np.arange(n) / n
    return np.stack([np.full(n, -54.0), -_R * np.sin(psi), _R * np.cos(psi)], axis=1)


def _field(u, v=0.0, w=0.0, hub=90.0) -> lidar.WindField:
    """A steady field on a 200 m square around the hub: u(z) given, v and w uniform."""
    t, y, z = np.arange(0.0, 20.01, 1.0), np.linspace(-100, 100, 41), np.linspace(0, 200, 81)
    uu = np.broadcast_to(np.asarray(u(z), float), (t.size, y.size, z.size))
    return lidar.WindField(t=t, y=y, z=z, u=uu, v=np.full(uu.shape, v), w=np.full(uu.shape, w),
                           mean_speed=12.0, hub_height=hub)


def test_point_lidar_records_hand_worked():
    """A uniform wind (12, 3, 4) m/s: every speed is |V| = 13 m/s (InflowWind's single point,
    not a line-of-sight speed), the positions are the hub's plus the points', and a sample is
    due where interval * int(t / interval) == t in floating point: at 0.2 s but not at 0.3 s
    (0.3 / 0.1 = 2.9999999999999996), as InflowWind skips it."""
    pl = lidar.PointLidar(_ring(3), 0.1, hub=(-5.0, 0.0, 90.0)).bind(
        _field(lambda z: np.full_like(z, 12.0), v=3.0, w=4.0))
    rec = pl.records(1.0)
    np.testing.assert_allclose(rec[:4], [1.0, 3.0, 1.0, 0.0])
    np.testing.assert_allclose(rec[4:7], 13.0, rtol=1e-6)
    np.testing.assert_allclose(rec[7:10], -59.0)
    np.testing.assert_allclose(rec[10:13], [0.0, -_R * math.sin(2 * math.pi / 3),
                                            _R * math.sin(2 * math.pi / 3)], atol=1e-9)
    np.testing.assert_allclose(rec[13:16], [90.0 + _R, 90.0 - _R / 2, 90.0 - _R / 2])
    assert pl.due(0.2) and not pl.due(0.3) and pl.due(0.0)


def test_a_cw_beam_gives_the_wind_along_x_hand_worked():
    """InflowWind's CW lidar with LidRadialVel False (SensorType 2, one beam): its estimate of
    the wind along x, here the focus point's u (12 m/s in a uniform (12, 3, 4) m/s wind, not
    |V| = 13); more than one point is refused, as InflowWind does for a CW lidar."""
    pl = lidar.PointLidar([[-54.0, 0.0, 0.0]], 0.1, hub=(-5.0, 0.0, 90.0), sensor_type=2).bind(
        _field(lambda z: np.full_like(z, 12.0), v=3.0, w=4.0))
    np.testing.assert_allclose(pl.records(1.0), [2, 1, 1, 0, 12.0, -59.0, 0.0, 90.0],
                               rtol=1e-6)
    with pytest.raises(ValueError, match="one CW beam"):
        lidar.PointLidar(_ring(3), 0.1, sensor_type=2)


@pytest.mark.parametrize("bad, match", [
    (np.zeros((0, 3)), "1 <= n <= 5"), (np.zeros((6, 3)), "1 <= n <= 5"),
    (np.zeros((3, 2)), r"\(n, 3\)"), ([[54.0, 0.0, 0.0]], "upwind"),
    ([[-54.0, np.nan, 0.0]], "finite")])
def test_point_lidar_refuses_bad_points(bad, match):
    with pytest.raises(ValueError, match=match):
        lidar.PointLidar(bad, 0.1)


@pytest.fixture(scope="module")
def mpc_lidar(tmp_path_factory):
    return exported("mpc-lidar", tmp_path_factory.mktemp("mpcl") / "lib")


@pytest.mark.parametrize("n, kind", [(1, 1), (2, 1), (3, 1), (5, 1), (1, 2)])
def test_the_library_reads_each_blade_at_its_azimuth(mpc_lidar, n, kind):
    """A linear shear u = 10 + 0.1 (z - 90) m/s and no v, w, measured at n fixed points: with
    3 or more around the rotor the MPC's blade winds (its logging channels lidar_wind_1..3) are
    the 1P fit at the azimuth each blade will have when that wind reaches it, 10 + 4.725
    cos(psi + omega (T_p - age) + (k - 1) 120 deg) m/s with T_p = 54 m / 10 m/s, exact for a
    linear shear; with fewer, every blade gets the points' mean (a CW beam, SensorType 2: its
    speed). The records at a call hold the
    sample of the call before (as OpenFAST hands them over), the first call's its own; the
    blade's azimuth is the call's."""
    t = linearize.load_turbine("nrel5mw")
    pl = lidar.PointLidar(_ring(n), 0.1, hub=(-5.0, 0.0, 90.0), sensor_type=kind).bind(
        _field(lambda z: 10.0 + 0.1 * (z - 90.0)))
    ctl = DisconController(mpc_lidar.library, mpc_lidar.input_file, t, dt=0.1, lidar=pl,
                           isolate=False, log_names=("qp_fallback", "qp_solve_ms",
                                                     "schedule_wind", "schedule_grid_wind",
                                                     "lidar_wind_1", "lidar_wind_2",
                                                     "lidar_wind_3"))
    p = linearize.plant_params(t)
    op = linearize.trim(t, 10.0, params=p)
    res = simulate_closed_loop(p, ctl, linearize.SteadyWind(10.0, 0.0), 3.0, x0=op.x, u0=op.u,
                               controller_dt=0.1)
    calls = np.arange(0, res.t.size - 1, 8)                   # the library's calls at 10 Hz
    # where each blade will be when the wind measured 54 m upwind reaches it: 54 m / 10 m/s
    # (the points' mean) = 5.4 s on, less the sample's age (one call, 0.1 s; 0 at the first)
    age = np.where(np.arange(calls.size) == 0, 0.0, 0.1)
    psi = res.channel("azimuth")[calls] + res.channel("rotor_speed")[calls] * (5.4 - age)
    speeds = pl.records(0.0)[4:4 + n]
    for k in range(3):
        got = res.controller[f"lidar_wind_{k + 1}"][calls]
        want = (10.0 + 0.1 * _R * np.cos(psi + 2.0 * np.pi * k / 3.0) if n >= 3
                else np.full(calls.size, speeds.mean()))
        want[1] = want[0]        # the second call holds the first sample (taken at t = 0)
        np.testing.assert_allclose(got, want, atol=2e-4, err_msg=f"blade {k + 1}")


needs_openfast = pytest.mark.skipif(
    installed_openfast() is None or find_compiler() is None or not _FST.is_file(),
    reason="needs OpenFAST ($MPCWT_OPENFAST or openfast on PATH), a C compiler and "
           "OpenFAST's regression case")


def _lidar_rows(path: Path) -> np.ndarray:
    with path.open() as fh:
        return np.array([[float(v) for v in r] for r in csv.reader(fh)])


@needs_openfast
def test_the_lidar_records_are_openfasts(tmp_path):
    """A library that logs records 2001-2016 at every call, run 1 s in OpenFAST on its
    regression case with the three single points and on mpc-wt's plant through the same deck:
    type, beams and gates equal, the speeds within 0.1 m/s at each call, OpenFAST's sample of
    the call before included; the points' y and z within 0.05 m and x within 0.25 m: OpenFAST
    moves them with the hub (``ConsiderHubMotion 1``; the tower top's fore-aft motion, 0.16 m
    in the first second), mpc-wt's host keeps them where the hub is at rest."""
    cc = shutil.which("gcc") or shutil.which("cc")
    probe = tmp_path / "libprobe.so"
    subprocess.run([cc, "-shared", "-fPIC", "-O1", "-o", str(probe), str(_PROBE_C)], check=True)
    (tmp_path / "PROBE.IN").write_text("probe input\n")
    deck = prepare_deck(_FST, tmp_path / "of", probe, tmp_path / "PROBE.IN", 0.1, tmax=1.0,
                        inflow=_LIDAR3)
    run_openfast(installed_openfast(), deck)
    of = _lidar_rows(next((tmp_path / "of").glob("*.lidar.csv")))
    case = read_openfast_case(deck, turbine=linearize.load_turbine("nrel5mw"))
    run_openfast_case(case, "discon", library=probe, discon_in=tmp_path / "PROBE.IN",
                      workdir=tmp_path / "ours")
    ours = _lidar_rows(tmp_path / "ours" / "mpcwt_discon.SrvD.lidar.csv")
    n = min(len(of), len(ours)) - 1                   # OpenFAST's last call repeats its time
    np.testing.assert_allclose(ours[:n, 1], of[:n, 1], atol=1e-6)          # the calls' times
    np.testing.assert_array_equal(ours[:n, 2:6], of[:n, 2:6])
    np.testing.assert_allclose(ours[:n, 6:9], of[:n, 6:9], atol=0.1)       # speeds
    np.testing.assert_allclose(ours[:n, 9:12], of[:n, 9:12], atol=0.25)    # x
    np.testing.assert_allclose(ours[:n, 12:18], of[:n, 12:18], atol=0.05)  # y, z


@pytest.fixture(scope="module")
def mpc_lidar_verified(tmp_path_factory):
    """``verify_openfast`` of mpc-lidar on OpenFAST's case as published: it gives the deck five
    single points on the design's ring and runs OpenFAST's 60 s; its rows by channel."""
    from mpc_wt.run import verify_openfast

    out = tmp_path_factory.mktemp("verify") / "v"
    doc = verify_openfast(linearize.load_turbine("nrel5mw"), "mpc-lidar", _FST, out,
                          openfast=installed_openfast())
    assert (out / "openfast" / "inflow.dat").is_file()
    return {x["channel"]: x for x in doc["rows"]}


@pytest.mark.slow
@needs_openfast
def test_mpc_lidar_in_openfast_cuts_the_blade_and_shaft_loads(mpc_lidar_verified):
    """Against the published run (Jonkman's baseline in the same case, 10-60 s): blade 1's
    flapwise root moment (RootMyb1, the published output's) and the shaft torque DELs below it
    (measured 3.47 against 4.28 MN m, 428 against 605 kN m) and the largest power within
    1.1 x rated (measured 5177 kW)."""
    r, ref = mpc_lidar_verified, _published_dels()
    assert r["flapwise_moment_1"]["del_ref"] < ref["flap"] * 1e3, (r["flapwise_moment_1"], ref)
    assert r["lss_torque"]["del_ref"] < ref["shaft"] * 1e3, (r["lss_torque"], ref)
    assert r["gen_power"]["max_ref"] <= 1.1 * 5e6


@pytest.mark.slow
@needs_openfast
@pytest.mark.xfail(strict=True, reason="measured 4974 kW against the published run's 4921.6: "
                   "+1.06 %, the MPC makes more power than the baseline in this case")
def test_mpc_lidar_in_openfast_mean_power_within_1_percent(mpc_lidar_verified):
    """The mean power over 10-60 s within 1 % of the published run's."""
    p = mpc_lidar_verified["gen_power"]["mean_ref"] / 1e3
    assert abs(p / _published_dels()["power"] - 1.0) <= 0.01, p


_V5_INFLOW = _RTEST / "5MW_Baseline" / "NRELOffshrBsline5MW_InflowWind_12mps_v5.dat"


@pytest.mark.skipif(not _V5_INFLOW.is_file(), reason="needs OpenFAST's regression case")
def test_the_lidar_inflowwind_file_for_a_deck(tmp_path):
    """The case's own InflowWind file (no lidar) given five points on the CW lidar's ring
    (54 m upwind, r = 54 tan(41.2 deg) = 47.25 m): SensorType 1, NumBeam 5, the points' x, y,
    z as written, 0.1 s, the wind file's path made absolute; read back as the case's lidar."""
    from linearize.openfast import OpenFASTFile
    from mpc_wt.io.openfast_run import lidar_points, write_lidar_inflow

    pts = lidar_points(54.0, _R)
    np.testing.assert_allclose(pts[1], [-54.0, -_R * math.sin(0.4 * math.pi),
                                        _R * math.cos(0.4 * math.pi)])
    out = write_lidar_inflow(_V5_INFLOW, tmp_path / "inflow.dat", pts, 0.1)
    f = OpenFASTFile(out)
    assert f.integer("SensorType") == 1 and f.integer("NumBeam") == 5
    for i, c in enumerate("XYZ"):
        np.testing.assert_allclose(f.numbers(f"FocalDistance{c}"), pts[:, i], atol=1e-4)
    assert f.number("MeasurementInterval") == 0.1 and f.file("FileName_BTS").is_file()
    deck = prepare_deck(_FST, tmp_path / "deck", _V5_INFLOW, _V5_INFLOW, 0.1, inflow=out)
    case = read_openfast_case(deck, turbine=linearize.load_turbine("nrel5mw"))
    np.testing.assert_allclose(case.lidar["points"], pts, atol=1e-4)
    with pytest.raises(ValueError, match="1 <= n <= 5"):
        write_lidar_inflow(_V5_INFLOW, tmp_path / "x.dat", np.zeros((6, 3)) - 1.0, 0.1)


def _published_dels() -> dict[str, float]:
    """Power mean [kW] and DELs [kN m] (blade 1 flapwise, shaft torque) over 10-60 s of the
    published run (Jonkman's baseline in OpenFAST's regression case, its reference output)."""
    from mpc_wt.assessment.fatigue import damage_equivalent_load
    from mpc_wt.io.openfast_output import read_openfast_output

    s = read_openfast_output(_RTEST / "5MW_Land_DLL_WTurb" / "5MW_Land_DLL_WTurb.outb")
    m = s.t >= 10.0
    col = lambda n: s.data[m, s.names.index(n)]  # noqa: E731
    return {"power": float(col("GenPwr").mean()),
            "flap": damage_equivalent_load(col("RootMyb1"), 10.0, duration=50.0),
            "shaft": damage_equivalent_load(col("RotTorq"), 4.0, duration=50.0)}

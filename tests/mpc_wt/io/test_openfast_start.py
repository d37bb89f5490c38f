"""Exported libraries started as OpenFAST v5.0.0 starts them: ServoDyn's first call sends no
generator torque or electrical power (records 23 and 15 hold the previous step's, 0 at the
first; BladedInterface.f90, Fill_avrSWAP), and the demanded pitch of record 11 is the initial
pitch. mpc-wt's host calls a library the same way, so the start is the same on both plants;
in OpenFAST itself (the binary given by ``$MPCWT_OPENFAST``, on ``PATH``, or the one beside the
checkout; skipped without one) on its regression case ``5MW_Land_DLL_WTurb``."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import linearize
from mpc_wt.io.discon_export import find_compiler
from mpc_wt.io.openfast_output import read_openfast_output
from mpc_wt.io.openfast_run import prepare_deck, run_openfast
from mpc_wt.run import export_discon, run_controller
from openfast_here import SHARED, installed_openfast

_CASE = SHARED / "validation" / "nrel5mw" / "openfast_rtest"


@pytest.mark.parametrize("kind, wind", [("mpc", 7.0), ("mpc", 12.0), ("mpc", 20.0),
                                        ("lqr-pio", 12.0), ("lqr-pio", 20.0)])
def test_the_schedule_starts_at_the_wind_of_the_torque_schedule(kind, wind):
    """The shipped MPC and LQR-PIO, started from the trim as ServoDyn starts a library (no
    torque yet): their wind schedule's first estimate is within 0.15 m/s of the trim's mean
    wind (with the first call's torque taken as 0 it would be the wind at which the rotor
    makes no torque), and the power over the first 10 s stays within 5 % of rated above rated
    wind."""
    t = linearize.load_turbine("nrel5mw")
    r = run_controller(t, kind, wind, duration=10.0, seed=5)
    assert abs(r.controller["schedule_wind"][0] - wind) <= 0.15
    if wind > 11.4:
        p = r.channel("gen_power") / t.operation.rated_power
        assert 0.95 <= p.min() and p.max() <= 1.05, (p.min(), p.max())


def _run_openfast(exe: str, lib, work: Path, tmax: float) -> dict[str, np.ndarray]:
    deck = prepare_deck(_CASE / "5MW_Land_DLL_WTurb_v5" / "5MW_Land_DLL_WTurb.fst", work,
                        lib.library, lib.input_file, lib.dt, tmax=tmax)
    s = read_openfast_output(run_openfast(exe, deck))
    return {"Time": s.t, **{n: s.data[:, i] for i, n in enumerate(s.names)}}


@pytest.mark.skipif(installed_openfast() is None or find_compiler() is None or not _CASE.is_dir(),
                    reason="needs OpenFAST ($MPCWT_OPENFAST or openfast on PATH), a C "
                           "compiler and OpenFAST's regression case")
def test_the_mpc_library_starts_in_openfast_at_its_torque_schedule(tmp_path):
    """The exported MPC in OpenFAST's own case (12.1 rpm, pitch 0, 12 m/s turbulent wind),
    10 s: its first torque within 5 % of the rated 43.09 kN m (Jonkman et al. 2009, table 7-1;
    the rotor at rated speed), the rotor below 12.7 rpm (5 % over rated) and the power below
    1.05 x rated 5 MW throughout (it started at 4.3 kN m when it took the first call's 0 as
    the measured torque, reached 13.04 rpm at 3 s and 5.88 MW)."""
    t = linearize.load_turbine("nrel5mw")
    lib = export_discon(t, "mpc", tmp_path / "lib")
    out = _run_openfast(installed_openfast(), lib, tmp_path, 10.0)
    assert abs(out["GenTq"][0] - 43.09) <= 0.05 * 43.09, out["GenTq"][:3]
    assert out["RotSpeed"].max() <= 12.7 and out["GenPwr"].max() <= 1.05 * 5000.0

"""A kind that exports runs, on request, as it is shipped: its design's numbers in the input file
of its compiled C law, called through the host. The peer is the user's own path: the same
design exported with ``export_discon`` (a folder of sources built by itself) and run as any
Bladed-style library (the ``discon`` kind); the shipped run must be that run, step for step."""
from __future__ import annotations

import numpy as np
import pytest

from mpc_wt.io.discon_export import EXPORTABLE, find_compiler, shipped_library
from mpc_wt.io.solver_sources import cache_dir
from mpc_wt.run import export_discon, run_controller
from mpc_wt.simulation.scenario import FieldMemo

pytestmark = pytest.mark.skipif(find_compiler() is None,
                                reason="no C compiler ($CC, cc, gcc, clang) to build the law")

_FIELDS = FieldMemo()
_KW = dict(duration=30.0, turbulence="A", seed=23, fields=_FIELDS)


@pytest.mark.parametrize("kind", sorted(EXPORTABLE))
def test_the_shipped_run_is_the_users_export_run(turbine, kind, tmp_path):
    """Every exportable kind, 30 s of class-A turbulence at 14 m/s: the shipped run and the run
    of the user's export of the same design give the same demands to the last bit, and both
    say which law ran."""
    shipped = run_controller(turbine, kind, 14.0, shipped=True, **_KW)
    assert shipped.meta["law"] == "shipped"
    ex = export_discon(turbine, kind, tmp_path / "export")
    opts = {"discon_library": str(ex.library), "discon_in": str(ex.input_file),
            "discon_dt": ex.dt, "isolate": False}
    if kind in ("mpc-lidar", "baseline+lidar-ff"):
        opts["lidar_records"] = True
    user = run_controller(turbine, "discon", 14.0, opts, **_KW)
    np.testing.assert_array_equal(shipped.u, user.u)        # the same law on the same inputs


def test_the_python_step_stays_where_the_library_takes_no_such_design(turbine):
    """An MPC on OSQP (the library solves with DAQP) and IBC on a derated baseline (the
    library's IBC is on the full-power baseline) keep their Python step, and say so."""
    r = run_controller(turbine, "mpc", 14.0, {"backend": "osqp"}, shipped=True, duration=2.0,
                       turbulence="A", seed=23)
    assert r.meta["law"] == "python"
    r = run_controller(turbine, "derate80+ibc", 14.0, shipped=True, duration=2.0,
                       turbulence="A", seed=23)
    assert "law" not in r.meta                 # no shipped law for this composition
    r = run_controller(turbine, "baseline", 14.0, duration=2.0, turbulence="A", seed=23)
    assert "law" not in r.meta                 # the Python step unless asked


def test_the_library_is_built_once_into_the_users_cache():
    """Both libraries sit in the per-user cache under a key of their sources, compiler and
    flags; asking again gives the same file."""
    core, mpc = shipped_library("baseline"), shipped_library("mpc")
    assert core != mpc and core.parent.parent == mpc.parent.parent == cache_dir() / "libraries"
    assert shipped_library("ts") == core and shipped_library("mpc-lidar") == mpc


def test_the_guides_python_examples_run(tmp_path, monkeypatch):
    """The Python blocks of the guide "Run your mpc-wt controller in OpenFAST" run as written
    (in a folder of their own)."""
    import re
    from pathlib import Path

    guide = Path(__file__).resolve().parents[2] / "docs" / "guide" / "openfast-discon.md"
    blocks = re.findall(r"```python\n(.*?)```", guide.read_text(), flags=re.S)
    assert len(blocks) >= 2
    monkeypatch.chdir(tmp_path)
    for code in blocks:
        exec(compile(code, str(guide), "exec"), {"__name__": "__guide__"})

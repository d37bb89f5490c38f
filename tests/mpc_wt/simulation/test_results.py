"""Closed-loop results: the netCDF round trip, broken and foreign files, derived channels.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from mpc_wt.errors import ResultFileError
from mpc_wt.simulation.results import ClosedLoopResult, shaft_bending_resultant


def test_result_round_trip(run18: ClosedLoopResult, tmp_path: Path) -> None:
    p = run18.save(tmp_path / "run.nc")
    back = ClosedLoopResult.load(p)
    assert_allclose(back.z, run18.z, rtol=0, atol=0)
    assert_allclose(back.channel("pitch_integral"), run18.channel("pitch_integral"), rtol=0)
    assert back.meta["software_version"] == run18.meta["software_version"]
    import xarray as xr  # self-describing: readable without mpc-wt

    with xr.open_dataset(p, engine="scipy") as ds:
        assert ds["gen_power"].attrs["units"] == "W" and ds["time"].attrs["units"] == "s"


def test_a_stale_dask_scheduler_does_not_stop_a_save(run18: ClosedLoopResult,
                                                      tmp_path: Path) -> None:
    """A ``distributed.Client`` that failed to connect leaves Dask's config naming the
    distributed scheduler with no client; xarray asks for it even for NumPy data. A result is
    still written (it failed every later case of a serial campaign in that process)."""
    import dask

    with dask.config.set(scheduler="dask.distributed"):
        p = run18.save(tmp_path / "run.nc")
    assert_allclose(ClosedLoopResult.load(p).z, run18.z, rtol=0, atol=0)


def test_broken_result_files(run18: ClosedLoopResult, tmp_path: Path) -> None:
    p = run18.save(tmp_path / "run.nc")
    raw = p.read_bytes()
    (tmp_path / "cut.nc").write_bytes(raw[: len(raw) // 3])
    with pytest.raises(ResultFileError, match="not a readable result file"):
        ClosedLoopResult.load(tmp_path / "cut.nc")
    with pytest.raises(ResultFileError, match="file not found"):
        ClosedLoopResult.load(tmp_path / "none.nc")
    # a garbage header: one line (it was several ending in a hint to install netCDF4)
    (tmp_path / "junk.nc").write_bytes(b"GARBAGEHEADER" + raw[13:])
    with pytest.raises(ResultFileError) as err:
        ClosedLoopResult.load(tmp_path / "junk.nc")
    assert "\n" not in str(err.value) and "netcdf4" not in str(err.value).lower()
    assert "junk.nc: not an mpc-wt result file: it does not begin as a netCDF-3 file" \
        in str(err.value)
    with pytest.raises(ResultFileError) as err:
        ClosedLoopResult.load(tmp_path / "cut.nc")
    assert "\n" not in str(err.value)
    with pytest.raises(KeyError, match=r"no channel 'gen_powr'"):
        run18.channel("gen_powr")


def test_shaft_bending_channel(run18: ClosedLoopResult) -> None:
    f = run18.z[:, 10:13]
    assert_allclose(run18.channel("shaft_bending_blade1"), f[:, 0] - 0.5 * (f[:, 1] + f[:, 2]),
                    rtol=0, atol=0)


@pytest.mark.parametrize("m, want", [
    ((1.0, 0.0, 0.0), 1.0),             # one blade loaded: its own moment
    ((1.0, 1.0, 1.0), 0.0),             # a symmetric rotor bends no shaft
    ((2.0, -1.0, -1.0), 3.0),           # vector toward blade 1: M1 - (M2 + M3) / 2 = 3
    ((0.0, 1.0, -1.0), 3.0 ** 0.5),     # toward the 90 deg point: sqrt(3) sin 60 deg x 2
])
def test_shaft_bending_resultant_hand_worked(m, want) -> None:
    assert float(shaft_bending_resultant(*m)) == pytest.approx(want, abs=1e-12)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(-1e7, 1e7), min_size=3, max_size=3), st.floats(0.0, 2 * np.pi))
def test_shaft_bending_resultant_is_the_largest_fiber_moment(m, psi) -> None:
    """Invariant: the resultant is the largest over the section's fibers of the projected
    moment sum_k M_k cos(psi_k - phi) (blades 120 deg apart from any azimuth ``psi``), and
    the fiber toward blade 1 never exceeds it."""
    psis = psi + np.arange(3) * 2 * np.pi / 3
    phi = np.linspace(0.0, 2 * np.pi, 7201)
    fibers = np.asarray(m) @ np.cos(psis[:, None] - phi[None, :])
    r = float(shaft_bending_resultant(*m))
    scale = max(1.0, max(map(abs, m)))
    assert r >= 0.0
    assert fibers.max() <= r + 1e-9 * scale
    assert fibers.max() == pytest.approx(r, rel=1e-6, abs=1e-9 * scale)
    assert abs(m[0] - 0.5 * (m[1] + m[2])) <= r + 1e-9 * scale


def test_shaft_bending_resultant_channel(run18: ClosedLoopResult, tmp_path: Path) -> None:
    """The channel is the magnitude of the flap moments' sum along their azimuths (the plant's
    blade 1 azimuth, the others 120 and 240 deg on), and it is written with its unit."""
    f = run18.channel("flap_moment_1"), run18.channel("flap_moment_2"), \
        run18.channel("flap_moment_3")
    psi = run18.channel("azimuth")
    vec = sum(fk * np.exp(1j * (psi + k * 2 * np.pi / 3)) for k, fk in enumerate(f))
    assert_allclose(run18.channel("shaft_bending_resultant"), np.abs(vec), rtol=1e-9,
                    atol=1e-6)
    import xarray as xr

    with xr.open_dataset(run18.save(tmp_path / "r.nc"), engine="scipy") as ds:
        assert ds["shaft_bending_resultant"].attrs["units"] == "N m"
        assert ds["shaft_bending_blade1"].attrs["units"] == "N m"


def test_result_from_another_version(run18: ClosedLoopResult, tmp_path: Path) -> None:
    import xarray as xr

    p = run18.save(tmp_path / "run.nc")
    with xr.open_dataset(p, engine="scipy") as ds:
        ds = ds.load()
    ds.attrs["schema_version"] = 99
    ds.to_netcdf(tmp_path / "v99.nc", engine="scipy")
    with pytest.raises(ResultFileError, match=r"schema_version must be 1, got 99"):
        ClosedLoopResult.load(tmp_path / "v99.nc")

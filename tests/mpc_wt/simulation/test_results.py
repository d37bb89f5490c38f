"""Closed-loop results: the netCDF round trip, broken and foreign files, derived channels.
"""
from __future__ import annotations

from pathlib import Path

import pytest
from numpy.testing import assert_allclose

from mpc_wt.errors import ResultFileError
from mpc_wt.simulation.results import ClosedLoopResult


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
    with pytest.raises(KeyError, match=r"no channel 'gen_powr'"):
        run18.channel("gen_powr")


def test_shaft_bending_channel(run18: ClosedLoopResult) -> None:
    f = run18.z[:, 10:13]
    assert_allclose(run18.channel("shaft_bending_blade1"), f[:, 0] - 0.5 * (f[:, 1] + f[:, 2]),
                    rtol=0, atol=0)


def test_result_from_another_version(run18: ClosedLoopResult, tmp_path: Path) -> None:
    import xarray as xr

    p = run18.save(tmp_path / "run.nc")
    with xr.open_dataset(p, engine="scipy") as ds:
        ds = ds.load()
    ds.attrs["schema_version"] = 99
    ds.to_netcdf(tmp_path / "v99.nc", engine="scipy")
    with pytest.raises(ResultFileError, match=r"schema_version must be 1, got 99"):
        ClosedLoopResult.load(tmp_path / "v99.nc")

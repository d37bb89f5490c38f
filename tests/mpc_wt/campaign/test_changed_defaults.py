"""A campaign resumed after the software changed a controller kind's defaults computes that
kind's cases again (a case's design hash covers every option as the kind resolves it, defaults
included), says so in the log, and leaves the other kinds' cases alone; an index written before
designs were hashed takes the current hash without computing anything again, and says so."""
from __future__ import annotations

import json
import logging
from dataclasses import dataclass

import numpy as np
import pytest

from mpc_wt.campaign import CampaignStore, run_campaign, spec_from_dict
from mpc_wt.registry import Built, Options, option, register
from mpc_wt.registry.registry import _KINDS
from mpc_wt.simulation.results import ClosedLoopResult


class _Hold:
    """Holds the first measured pitch plus an offset, and the first torque."""

    def __init__(self, extra: float) -> None:
        self.extra = extra
        self.reset()

    def reset(self) -> None:
        self.cmd = None

    def step(self, t, meas):
        if self.cmd is None:
            self.cmd = (np.asarray(meas["pitch"], float) + self.extra, float(meas["gen_torque"]))
        return self.cmd[0].copy(), self.cmd[1]


def _register(default_deg: float) -> None:
    @dataclass(frozen=True)
    class HoldOptions(Options):
        extra_pitch_deg: float = option(default_deg, help="pitch added", unit="deg")

    @register("hold-defaults", HoldOptions, replace=True, summary="held pitch and torque")
    def build(ctx, opts):
        return Built(_Hold(np.radians(opts.extra_pitch_deg)), controller_dt=0.1)


@pytest.fixture()
def probe_kind():
    yield _register
    _KINDS.pop("hold-defaults", None)


RAW = {"name": "defaults", "duration": 10, "transient": 0, "winds": [18], "seeds": 1,
       "turbulence": "steady", "controllers": ["baseline", "hold-defaults"]}


def test_changed_defaults_compute_the_kinds_cases_again(probe_kind, tmp_path, caplog) -> None:
    probe_kind(0.0)
    out = tmp_path / "c"
    first = run_campaign(spec_from_dict(RAW), out, engine="serial", progress=False)
    assert first.done == 2
    pitch0 = ClosedLoopResult.load(out / "cases" / "hold-defaults__steady__v18__s1.nc")
    probe_kind(1.0)                       # the next version's default: 1 deg more pitch
    with caplog.at_level(logging.WARNING):
        second = run_campaign(spec_from_dict(RAW), out, engine="serial", progress=False)
    assert second.done == 1 and second.skipped == 1 and second.reused == 0
    assert "1 cases were computed under other defaults" in caplog.text
    again = ClosedLoopResult.load(out / "cases" / "hold-defaults__steady__v18__s1.nc")
    # the held pitch is now the trim's plus 1 deg (by hand: the case ran with the new default)
    assert np.degrees(again.channel("pitch_ref_1")[-1] - pitch0.channel("pitch_ref_1")[-1]) \
        == pytest.approx(1.0, abs=1e-9)
    third = run_campaign(spec_from_dict(RAW), out, engine="serial", progress=False)
    assert third.submitted == 0


def test_an_index_without_design_hashes_takes_them_without_recomputing(probe_kind, tmp_path,
                                                                       caplog) -> None:
    """Cases from a version that recorded no design are kept (their defaults are unknown) and
    the log says how many, and how to compute them again."""
    probe_kind(0.0)
    out = tmp_path / "c"
    run_campaign(spec_from_dict(RAW), out, engine="serial", progress=False)
    with CampaignStore(out, lock=True) as st:     # as written before designs were hashed
        for cid, cj in st.db.execute("SELECT case_id, case_json FROM cases").fetchall():
            d = json.loads(cj)
            d.pop("design_hash", None)
            st.db.execute("UPDATE cases SET case_json=? WHERE case_id=?", (json.dumps(d), cid))
    with caplog.at_level(logging.WARNING):
        again = run_campaign(spec_from_dict(RAW), out, engine="serial", progress=False)
    assert again.submitted == 0
    assert "2 finished cases carry no record of the defaults" in caplog.text
    assert "remove their files from cases/" in caplog.text
    with CampaignStore(out) as st:
        hashes = [json.loads(cj).get("design_hash")
                  for (cj,) in st.db.execute("SELECT case_json FROM cases")]
    assert all(isinstance(h, str) and len(h) == 64 for h in hashes)

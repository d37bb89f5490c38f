"""Campaigns: spec validation, case hashing, the results store, the Dask runner under a killed
worker and a killed client, aggregation and the report."""
from __future__ import annotations

import json
import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from mpc_wt.campaign import (
    CampaignLockedError,
    CampaignStore,
    SpecError,
    load_spec,
    run_campaign,
    spec_from_dict,
)
from mpc_wt.campaign.spec import Case
from mpc_wt.simulation.results import ClosedLoopResult
from mpc_wt.simulation.scenario import Scenario

BASE = {"name": "t", "duration": 20, "transient": 5, "winds": [14],
        "seeds": 1, "controllers": ["baseline"]}


def _spec(**over):
    return spec_from_dict({**BASE, **over})


# -- spec -------------------------------------------------------------------------------------
@pytest.mark.parametrize("over, key", [
    ({"windz": [3]}, "windz"),
    ({"winds": [3, -1]}, "winds[1]"),
    ({"winds": {"start": 4, "stop": 2}}, "winds.stop"),
    ({"winds": [8, 8]}, "winds"),
    ({"seeds": 0}, "seeds"),
    ({"seeds": [1, 1]}, "seeds"),
    ({"duration": float("nan")}, "duration"),
    # every case then failed at run time, "transient 60 s leaves 6 s" (exit 1, not 2)
    ({"duration": 6}, "duration: the time assessed after the transient must be at least 10 s"),
    # accepted, and the grid loss never happened
    ({"supervisor": {"grid_loss_at": 500}}, "supervisor.grid_loss_at: 500 s is at or after"),
    ({"load_cases": [{"dlc": "4.2", "condition": "eog", "winds": [12],
                      "supervisor": {"shutdown_at": 60}}]},
     "load_cases[0].supervisor.shutdown_at: 60 s is at or after the case's end"),
    # an OverflowError from SQLite after the designs
    ({"seeds": [1, 99999999999999999999999]}, "seeds: seeds must be at most 2\\*\\*63 - 1"),
    ({"turbulence": "D"}, "turbulence"),
    ({"turbulence": [0.12, 1.5]}, "turbulence[1]"),
    ({"controllers": ["baseline", "fuzzy"]}, "controllers[1].controller"),
    ({"controllers": ["baseline", "baseline"]}, "controllers"),
    ({"controllers": [{"name": "x", "controller": "baseline", "gain": 2}]},
     "controllers[0].gain"),
    ({"controllers": [{"name": "a b", "controller": "baseline"}]}, "controllers[0].name"),
    ({"controllers": [{"name": "p", "controller": "apc"}]}, "controllers[0].apc_frequency"),
    ({"controllers": [{"name": "b", "controller": "baseline", "apc_frequency": 0.1}]},
     "controllers[0].apc_frequency"),
    ({"controllers": [{"name": "m", "controller": "mpc-lidar", "lidar": {"focus": 3}}]},
     "controllers[0].lidar.focus"),
    ({"channels": {"flap_moment_9": 10}}, "channels.flap_moment_9"),
    ({"channels": {"flap_moment_1": -1}}, "channels.flap_moment_1"),
    ({"reference": "mpc"}, "reference"),
    ({"ultimate_channels": ["flap_moment_9"]}, "ultimate_channels[0]"),
    ({"ultimate_channels": "lss_torque"}, "ultimate_channels"),
    ({"ultimate_channels": ["lss_torque", "lss_torque"]}, "ultimate_channels"),
    ({"plant": {"twisted": True}}, "plant"),
    ({"plant": {"twisted_modes": "yes"}}, "plant"),
    ({"plant": ["twisted_modes"]}, "plant"),
    ({"wind_distribution": {"kind": "weibull"}}, "wind_distribution.scale"),
    ({"wind_distribution": {"kind": "gamma"}}, "wind_distribution.kind"),
    ({"turbine": "no/such/turbine.yaml"}, "turbine"),
    ({"report": {"paper": [{"metric": "del_change_pct", "controller": "baseline",
                            "value": "x"}]}}, "report.paper[0].value"),
])
def test_spec_errors_name_the_key(over, key):
    with pytest.raises(SpecError, match=key.replace("[", r"\[").replace("]", r"\]")):
        _spec(**over)


def test_spec_missing_keys_listed_and_bad_yaml(tmp_path):
    with pytest.raises(SpecError, match="missing"):
        spec_from_dict({"name": "x"})
    p = tmp_path / "bad.yaml"
    p.write_text("name: [unclosed\n")
    with pytest.raises(SpecError, match="not valid YAML"):
        load_spec(p)
    with pytest.raises(FileNotFoundError):
        load_spec(tmp_path / "none.yaml")


def test_spec_grid_and_ranges():
    s = _spec(winds={"start": 3, "stop": 25, "step": 2}, seeds=6,
              turbulence=["A", 0.12], controllers=["baseline", {"name": "ts",
                                                                "controller": "ts",
                                                                "winds": [15]}])
    assert s.winds == tuple(range(3, 26, 2))
    cases = s.cases()
    assert len(cases) == 12 * 6 * 2 + 1 * 6 * 2
    assert len({c.case_id for c in cases}) == len(cases)
    assert {c.turbulence for c in cases} == {"A", 0.12}


@settings(max_examples=30, deadline=None)
@given(st.lists(st.integers(3, 25), min_size=1, max_size=6, unique=True),
       st.integers(1, 4), st.sampled_from(["baseline", "ibc", "derate90"]),
       st.floats(0.0, 0.5))
def test_case_hash_changes_only_for_touched_cases(winds, seeds, ctl, shear):
    """Invariant: editing one controller's options changes the case hash of its cases only;
    editing the channels changes only assessment hashes; the case ids are unique."""
    raw = {**BASE, "winds": winds, "seeds": seeds, "shear_exponent": shear,
           "controllers": ["baseline", {"name": "other", "controller": ctl}]}
    a = spec_from_dict(raw).cases()
    # an option the kind takes (the registry rejects others when the spec loads)
    opt = {"baseline": {"zeta": 0.6}, "ibc": {"loop_gain_1p": 0.5}}.get(ctl, {})
    raw2 = {**raw, "controllers": ["baseline", {"name": "other", "controller": ctl,
                                                "options": opt}]}
    if ctl == "derate90":
        raw2["controllers"][1] = {"name": "other", "controller": "derate80"}
    b = spec_from_dict(raw2).cases()
    assert len({c.case_id for c in a}) == len(a) == 2 * len(winds) * seeds
    for x, y in zip(a, b):
        assert x.case_id == y.case_id
        assert (x.case_hash == y.case_hash) == (x.controller == "baseline")
    c = spec_from_dict({**raw, "channels": {"lss_torque": 4}}).cases()
    for x, y in zip(a, c):
        assert x.case_hash == y.case_hash and x.assess_hash != y.assess_hash
    d = spec_from_dict({**raw, "ultimate_channels": ["shaft_bending_resultant"]}).cases()
    for x, y in zip(a, d):
        assert x.case_hash == y.case_hash and x.assess_hash != y.assess_hash
        assert y.extremes_of == ("shaft_bending_resultant",) and x.extremes_of == ()
    e = spec_from_dict({**raw, "plant": {"twisted_modes": True}}).cases()
    for x, y in zip(a, e):
        assert x.case_hash != y.case_hash and x.assess_hash == y.assess_hash
        assert y.plant == {"twisted_modes": True} and x.plant is None


# -- store and runner (in this process) -------------------------------------------------------
def test_rerun_skips_finished_reruns_failed_and_invalidates_only_touched(tmp_path):
    # apc asks for more power than 8 m/s gives: that case raises, the others run
    spec = _spec(winds=[8, 16], controllers=[
        "baseline", {"name": "apc", "controller": "apc", "apc_frequency": 0.1, "winds": [8]}])
    s1 = run_campaign(spec, tmp_path, engine="serial", progress=False)
    assert (s1.done, s1.failed, s1.total) == (2, 1, 3)
    with CampaignStore(tmp_path) as st_:
        rows = {r.case_id: r for r in st_.rows()}
    bad = rows["apc__A__v8__s1"]
    assert bad.status == "failed" and "power" in bad.error and "Traceback" in bad.traceback
    ok = rows["baseline__A__v16__s1"]
    assert ok.status == "done" and ok.metrics["channels"]["flap_moment_1"]["del"] > 0
    mtime = (tmp_path / ok.file).stat().st_mtime_ns
    # rerun: finished cases skipped, the failed one retried (and fails again, recorded again)
    s2 = run_campaign(spec, tmp_path, engine="serial", progress=False)
    assert (s2.skipped, s2.submitted, s2.failed) == (2, 1, 1)
    assert (tmp_path / ok.file).stat().st_mtime_ns == mtime
    # channels changed: re-assessed from the files, no simulation
    spec3 = _spec(winds=[8, 16], controllers=["baseline"], channels={"lss_torque": 4})
    s3 = run_campaign(spec3, tmp_path, engine="serial", progress=False)
    assert (s3.done, s3.reused) == (2, 2)
    assert (tmp_path / ok.file).stat().st_mtime_ns == mtime
    with CampaignStore(tmp_path) as st_:
        rows = {r.case_id: r for r in st_.rows(include_stale=True)}
    assert set(rows["baseline__A__v16__s1"].metrics["channels"]) == {"lss_torque"}
    assert rows["apc__A__v8__s1"].status == "stale"
    # one wind changed: only that wind's case runs
    spec4 = _spec(winds=[8, 18], controllers=["baseline"], channels={"lss_torque": 4})
    s4 = run_campaign(spec4, tmp_path, engine="serial", progress=False)
    assert (s4.skipped, s4.done, s4.reused) == (1, 1, 0)


def test_lost_file_is_rerun_and_lock_refuses_second_client(tmp_path):
    spec = _spec()
    run_campaign(spec, tmp_path, engine="serial", progress=False)
    with CampaignStore(tmp_path) as st_:
        (row,) = st_.rows()
    (tmp_path / row.file).unlink()
    s = run_campaign(spec, tmp_path, engine="serial", progress=False)
    assert (s.submitted, s.done, s.reused) == (1, 1, 0)
    with CampaignStore(tmp_path, lock=True):
        with pytest.raises(CampaignLockedError, match="another client"):
            run_campaign(spec, tmp_path, engine="serial", progress=False)


def test_bad_runner_arguments(tmp_path):
    spec = _spec()
    with pytest.raises(ValueError, match="engine"):
        run_campaign(spec, tmp_path, engine="mpi")
    with pytest.raises(ValueError, match="workers"):
        run_campaign(spec, tmp_path, engine="processes", workers=0)
    with pytest.raises(ValueError, match="scheduler"):
        run_campaign(spec, tmp_path, scheduler="localhost:8786")
    with pytest.raises(FileNotFoundError, match="not a campaign"):
        CampaignStore(tmp_path / "nothing")


# -- Dask: a killed worker and a killed client ------------------------------------------------
def _done(db: Path) -> int:
    if not db.is_file():
        return 0
    con = sqlite3.connect(f"file:{db}?mode=ro", uri=True, timeout=10)
    try:
        return con.execute("SELECT count(*) FROM cases WHERE status='done'").fetchone()[0]
    except sqlite3.OperationalError:
        return 0
    finally:
        con.close()


def _wait(pred, timeout: float, what: str) -> None:
    t0 = time.monotonic()
    while not pred():
        if time.monotonic() - t0 > timeout:
            raise AssertionError(f"timed out waiting for {what}")
        time.sleep(0.2)


def _campaign_cli(tmp_path: Path, raw: dict) -> tuple[Path, Path, Path, list[str]]:
    """The spec written to a file, the campaign folder, its index and the client's command."""
    spec_path = tmp_path / f"{raw['name']}.yaml"
    spec_path.write_text(yaml.safe_dump(raw))
    out = tmp_path / "camp"
    return spec_path, out, out / "index.sqlite", [
        sys.executable, "-m", "mpc_wt.cli", "campaign", "run", str(spec_path), "--out",
        str(out), "--quiet"]


def _kill_a_worker_then_the_client(cmd: list[str], client, db: Path, after: int) -> None:
    """Start the campaign client ``cmd``; once a case is done SIGKILL one worker of
    ``client``'s cluster, once ``after`` are done SIGKILL the client."""
    first = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    try:
        _wait(lambda: _done(db) >= 1, 240, "the first case")
        pids = client.run(os.getpid)
        os.kill(next(iter(pids.values())), signal.SIGKILL)     # a worker, mid-case
        _wait(lambda: _done(db) >= after, 240, f"{after} cases after the worker kill")
    finally:
        first.kill()                                            # the client, mid-campaign
        first.wait()


@pytest.mark.slow
def test_killed_worker_and_killed_client_lose_nothing_duplicate_nothing(tmp_path):
    """A real LocalCluster (2 worker processes, loopback); the campaign client is a separate
    process. One worker is killed (SIGKILL) mid-campaign, then the client is killed and
    restarted: every case is in the index exactly once, done, with a valid file. (A long
    study: the fault-injection test, in every run of the suite, kills a worker and the client
    among failing libraries and cut files.)"""
    from distributed import Client, LocalCluster

    winds = [6, 9, 12, 15, 18, 21]
    raw = {**BASE, "name": "kill", "duration": 60, "winds": winds, "seeds": 2}
    spec_path, out, db, cmd = _campaign_cli(tmp_path, raw)
    n_cases = len(winds) * 2
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None) as cluster, Client(cluster) as client:
        cmd += ["--scheduler", cluster.scheduler_address]
        _kill_a_worker_then_the_client(cmd, client, db, 4)
        before = _done(db)
        assert before < n_cases, "the client finished before it was killed: lengthen the cases"
        second = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        assert second.returncode == 0, second.stdout + second.stderr
    con = sqlite3.connect(db)
    attempts = [a for (a,) in con.execute("SELECT attempts FROM cases")]
    assert max(attempts) == 2 and min(attempts) == 1    # the second client resubmitted the rest
    rows = con.execute("SELECT case_id, status, file FROM cases").fetchall()
    ids = [r[0] for r in rows]
    assert len(ids) == len(set(ids)) == n_cases
    assert {r[1] for r in rows} == {"done"}
    expected = {c.case_id: c.case_hash for c in load_spec(spec_path).cases()}
    assert set(ids) == set(expected)
    files = sorted(p.name for p in (out / "cases").glob("*.nc"))
    assert len(files) == n_cases
    for cid, _, f in rows:
        r = ClosedLoopResult.load(out / f)
        assert r.meta["campaign_case"]["case_hash"] == expected[cid]
        assert r.t[-1] == pytest.approx(65.0, abs=0.05)
        assert np.all(np.isfinite(r.z))


# -- aggregation and report -------------------------------------------------------------------
def test_report_tables_and_plots(tmp_path):
    from mpc_wt.campaign.aggregate import aggregate
    from mpc_wt.campaign.report import make_report

    spec = _spec(winds=[10, 14], seeds=2, controllers=["baseline", "derate80"],
                 duration=30, wind_distribution={"kind": "rayleigh", "mean": 10},
                 report={"paper": [{"metric": "lifetime_del_change_pct",
                                    "controller": "derate80", "channel": "lss_torque",
                                    "value": -11.0, "source": "Pettas fig. 5"}]})
    run_campaign(spec, tmp_path, engine="serial", progress=False)
    agg = aggregate(tmp_path)
    life = agg["lifetime"]
    lss = {r["controller"]: r for r in life if r["channel"] == "lss_torque"}
    # the m-power mean lies between the bins' DELs; derating lowers the shaft load
    dels = [r["del"] for r in agg["short_term"] if r["controller"] == "baseline"
            and r["channel"] == "lss_torque"]
    assert min(dels) <= lss["baseline"]["lifetime_del"] <= max(dels)
    assert lss["baseline"]["change_pct"] == 0.0
    assert lss["derate80"]["change_pct"] < 0
    aep = {r["controller"]: r for r in agg["aep"]}
    assert aep["derate80"]["change_pct"] < -3
    # regulation: the rotor-speed std of each case from its own result file,
    # averaged over seeds and weighted over the two winds as the report says
    from mpc_wt.simulation.results import ClosedLoopResult
    reg = {r["controller"]: r for r in agg["regulation"]}
    assert reg["baseline"]["rotor_speed_std_rad_s_change_pct"] == 0.0
    p = _probs_rayleigh([10.0, 14.0], 10.0)
    by_wind = {10.0: [], 14.0: []}
    for row in agg["rows"]:
        if row.controller == "baseline":
            res = ClosedLoopResult.load(tmp_path / row.file)
            k = res.t >= res.t[0] + spec.transient
            by_wind[row.wind_mps].append(res.channel("rotor_speed")[k].std())
    want = sum(pw * np.mean(by_wind[v]) for pw, v in zip(p, (10.0, 14.0))) / p.sum()
    assert reg["baseline"]["rotor_speed_std_rad_s"] == pytest.approx(want, rel=1e-9)
    rep = make_report(tmp_path)
    text = Path(rep).read_text()
    assert "Pettas fig. 5" in text and "lss_torque" in text
    assert "## Regulation and 1P content" in text
    for f in ("lifetime_del.csv", "short_term_del.csv", "aep.csv", "del_vs_wind.png",
              "lifetime_del.png", "cs_ellipses.png", "psd.png", "ultimate.csv"):
        assert (Path(rep).parent / f).is_file(), f
    # ultimate loads: the campaign's largest shaft torque and its case, found here
    # from the result files themselves; the characteristic value is the larger of the two
    # winds' seed means of the maxima; the design value 1.35 x that
    assert "## Ultimate loads" in text
    ult = {r["controller"]: r for r in agg["ultimate"] if r["channel"] == "lss_torque"}
    peaks: dict = {}
    for row in agg["rows"]:
        if row.controller == "derate80":
            res = ClosedLoopResult.load(tmp_path / row.file)
            k = res.t >= res.t[0] + spec.transient
            peaks[row.case_id] = (row.wind_mps, float(res.channel("lss_torque")[k].max()))
    top = max(peaks, key=lambda c: peaks[c][1])
    u = ult["derate80"]
    assert u["max_case"] == top and u["max"] == pytest.approx(peaks[top][1], rel=1e-12)
    means = [np.mean([m for w, m in peaks.values() if w == v]) for v in (10.0, 14.0)]
    assert u["characteristic_max"] == pytest.approx(max(means), rel=1e-12)
    assert u["design_max"] == pytest.approx(1.35 * max(means), rel=1e-12)


def test_ultimate_loads_on_their_own_channels(tmp_path):
    """``ultimate_channels``: the design loads are read on those channels (the shaft's
    resultant, whose largest value is found here from the result files' flap moments), the
    fatigue tables keep ``channels``, and the report shows both."""
    from mpc_wt.campaign.aggregate import aggregate
    from mpc_wt.campaign.report import make_report

    raw = {k: v for k, v in BASE.items() if k not in ("winds", "seeds")}
    spec = spec_from_dict({
        **raw, "duration": 30,
        "load_cases": [{"dlc": "1.2", "condition": "ntm", "winds": [14], "seeds": 2}],
        "channels": {"shaft_bending_blade1": 4, "lss_torque": 4},
        "ultimate_channels": ["shaft_bending_resultant", "lss_torque"]})
    run_campaign(spec, tmp_path, engine="serial", progress=False)
    agg = aggregate(tmp_path)
    assert {r["channel"] for r in agg["ultimate"]} == {"shaft_bending_resultant",
                                                      "lss_torque", "rotor_speed"}
    assert {r["channel"] for r in agg["lifetime"]} == {"shaft_bending_blade1", "lss_torque"}
    peaks = []
    for row in agg["rows"]:
        res = ClosedLoopResult.load(tmp_path / row.file)
        k = res.t >= res.t[0] + spec.transient
        f = [res.channel(f"flap_moment_{b}")[k] for b in (1, 2, 3)]
        vec = sum(fb * np.exp(2j * np.pi * b / 3) for b, fb in enumerate(f))
        peaks.append(float(np.abs(vec).max()))
        assert np.abs(res.channel("shaft_bending_blade1")[k]).max() <= peaks[-1] * (1 + 1e-9)
    u = next(r for r in agg["ultimate"] if r["channel"] == "shaft_bending_resultant")
    assert u["max"] == pytest.approx(max(peaks), rel=1e-9)
    assert u["design_max"] == pytest.approx(1.35 * np.mean(peaks), rel=1e-9)
    text = Path(make_report(tmp_path)).read_text()
    assert "shaft_bending_resultant design load [%]" in text
    assert "shaft_bending_blade1 lifetime DEL [%]" in text
    assert "shaft_bending_blade1 design load" not in text


def test_a_campaign_runs_the_plant_its_spec_names(tmp_path):
    """``plant``: the cases run on the plant with those effects (recorded in each result's
    meta); the same case on the default plant differs in its loads, and a stored case read
    back keeps the switches."""
    raw = {**BASE, "duration": 10, "transient": 2, "winds": [14]}
    twisted = spec_from_dict({**raw, "plant": {"twisted_modes": True}})
    run_campaign(twisted, tmp_path / "tw", engine="serial", progress=False)
    run_campaign(spec_from_dict(raw), tmp_path / "plain", engine="serial", progress=False)
    (ft,) = (tmp_path / "tw" / "cases").glob("*.nc")
    (fp,) = (tmp_path / "plain" / "cases").glob("*.nc")
    rt, rp = ClosedLoopResult.load(ft), ClosedLoopResult.load(fp)
    assert rt.meta["plant"] == {"twisted_modes": True} and "plant" not in rp.meta
    assert not np.allclose(rt.channel("edge_moment_1"), rp.channel("edge_moment_1"), rtol=1e-3)
    case = twisted.cases()[0]
    assert Case.from_dict(json.loads(json.dumps(case.to_dict()))).plant == case.plant


def _probs_rayleigh(winds, mean):
    """Rayleigh probabilities of bins centred on ``winds`` (edges halfway), as IEC 61400-1."""
    w = np.asarray(winds, float)
    edges = np.r_[w[0] - (w[1] - w[0]) / 2, (w[1:] + w[:-1]) / 2, w[-1] + (w[-1] - w[-2]) / 2]
    cdf = 1 - np.exp(-np.pi / 4 * (edges / mean) ** 2)
    return np.diff(cdf)


def test_report_refuses_empty_campaign(tmp_path):
    from mpc_wt.campaign.report import make_report

    with CampaignStore(tmp_path, lock=True) as st_:
        st_.sync(_spec())
        with pytest.raises(ValueError, match="holds no spec"):
            make_report(tmp_path)
        st_.set_meta(name="t", reference="baseline", spec_raw=BASE)
    with pytest.raises(ValueError, match="no finished case"):
        make_report(tmp_path)


# -- controllers the studies added -------------------------------------------------------------
def test_do_controllers_pick_their_region():
    """lqr-pio, scheduled on its own wind estimate, runs Do's region II below the rated wind
    (torque law, pitch only damps: the mean power stays that of the baseline within 2 %) and
    region III above it; baseline-ct holds torque constant above rated
    (torque std below 0.5 % of rated torque, the constant-power baseline's is larger)."""
    import linearize
    from mpc_wt import run_controller

    tb = linearize.load_turbine()
    r2 = run_controller(tb, "lqr-pio", Scenario(8.0, 0.12, 1, 60.0))
    b2 = run_controller(tb, "baseline", Scenario(8.0, 0.12, 1, 60.0))
    k = r2.t > 20
    assert np.all(r2.channel("region")[k] == 2.0)
    assert r2.channel("gen_power")[k].mean() == pytest.approx(
        b2.channel("gen_power")[k].mean(), rel=0.02)
    assert np.all(run_controller(tb, "lqr-pio", Scenario(18.0, 0.12, 1, 5.0)).channel("region")
                  == 3.0)
    ct = run_controller(tb, "baseline-ct", Scenario(18.0, 0.12, 1, 60.0))
    cp = run_controller(tb, "baseline", Scenario(18.0, 0.12, 1, 60.0))
    q_rated = tb.operation.rated_power / tb.operation.rated_rotor_speed_rad_s / \
        tb.drivetrain.gearbox_ratio
    assert ct.channel("gen_torque")[k].std() < 0.005 * q_rated
    assert cp.channel("gen_torque")[k].std() > ct.channel("gen_torque")[k].std()


def test_aggregate_flags_a_seed_far_above_its_bin_and_weights_lifetime(tmp_path):
    """Synthetic index (no simulation): the lifetime DEL is the eq-18 m-power mean, and a seed
    with 10x its bin's median DEL is listed as suspect (kept in the tables)."""
    from mpc_wt.assessment.fatigue import lifetime_del, wind_bin_probabilities
    from mpc_wt.campaign.aggregate import aggregate

    raw = {**BASE, "winds": [8, 12], "seeds": 3, "channels": {"lss_torque": 4}}
    spec = spec_from_dict(raw)
    dels = {(8.0, 1): 1.0, (8.0, 2): 1.1, (8.0, 3): 11.0, (12.0, 1): 2.0, (12.0, 2): 2.0,
            (12.0, 3): 2.0}
    with CampaignStore(tmp_path, lock=True) as st_:
        st_.sync(spec)
        st_.set_meta(name="t", reference="baseline", spec_raw=raw)
        for c in spec.cases():
            d = dels[(c.wind_mps, c.seed)]
            st_.record(c.case_id, {"status": "done", "file": None, "metrics": {
                "channels": {"lss_torque": {"del": d, "m": 4.0}}, "power_mean_W": 1e6}},
                spec.spec_hash)
    agg = aggregate(tmp_path)
    (out,) = agg["outliers"]
    assert (out["wind_mps"], out["seed"]) == (8.0, 3)
    assert out["ratio_to_median"] == pytest.approx(10.0)
    bin8 = np.mean(np.array([1.0, 1.1, 11.0]) ** 4) ** 0.25
    p = wind_bin_probabilities(np.array([8.0, 12.0]), "rayleigh", mean=10.0)
    (life,) = agg["lifetime"]
    assert life["lifetime_del"] == pytest.approx(lifetime_del([bin8, 2.0], 4.0, p))


def test_clemens_convention_weights_bins_by_counted_cycles(tmp_path):
    """A past defect: with ``del_convention: clemens`` the per-case DEL is an amplitude
    over the counted cycles (eq 17) and the lifetime DEL weights each bin by its counted cycles
    (eq 18). Independent check: eq 18 equals the DEL of all bins' cycles pooled with the wind
    probabilities, computed here from the stored series' rainflow cycles."""
    from mpc_wt.assessment.fatigue import rainflow, wind_bin_probabilities
    from mpc_wt.campaign.aggregate import aggregate

    spec = _spec(winds=[12, 18], duration=20, transient=5, turbulence="steady",
                 channels={"flap_moment_1": 10}, del_convention="clemens")
    assert run_campaign(spec, tmp_path / "c", engine="serial", progress=False).failed == 0
    agg = aggregate(tmp_path / "c")
    row = next(r for r in agg["lifetime"] if r["channel"] == "flap_moment_1")
    p = wind_bin_probabilities(np.array([12.0, 18.0]), "rayleigh", mean=10.0)
    num = den = 0.0
    for pj, v in zip(p, (12, 18)):
        res = ClosedLoopResult.load(tmp_path / "c" / "cases" / f"baseline__steady__v{v}__s1.nc")
        x = res.channel("flap_moment_1")[res.t >= res.t[0] + 5.0]
        r, _, n = rainflow(x)
        num += pj * np.sum(n * (r / 2) ** 10)
        den += pj * np.sum(n)
    np.testing.assert_allclose(row["lifetime_del"], (num / den) ** 0.1, rtol=1e-9)
    with pytest.raises(SpecError, match="del_convention"):
        _spec(del_convention="mlife")


# A spec and two of its cases as the store kept them before a case held its Scenario (flat
# wind, seed, turbulence, duration, shear, condition and sign; written by the code of that
# time): their simulation hashes must not change, or every stored case would be re-run.
LEGACY_SPEC = {"name": "h", "turbine": "nrel5mw", "duration": 60, "transient": 10, "winds": [8, 18],
       "seeds": [1, 2], "turbulence": ["A", 0.12],
       "controllers": ["baseline", {"name": "mpc-s", "controller": "mpc", "horizon": 12}],
       "load_cases": [{"dlc": "1.2"},
                      {"dlc": "1.4", "condition": "ecd", "turbulence": "A", "winds": [11.4],
                       "signs": [1, -1]},
                      {"dlc": "2.3", "condition": "eog", "turbulence": "B", "winds": [13.4],
                       "supervisor": {"grid_loss_at": 8.0}}]}
LEGACY_CASES = {
 "baseline__dlc1.4__ecd__v11.4__neg": {
  "assess_hash": "4a724c3b7b4c6473f3c1a7a1e8eca75576c792cef24e512bef16bb10d499c1ff",
  "case_hash": "e4d9eacf2a32d02e73ce26bf56546d04c52ed0fc5201767a4c1a99c61881c970",
  "case_id": "baseline__dlc1.4__ecd__v11.4__neg",
  "channels": {
   "edge_moment_1": 10.0,
   "edge_moment_2": 10.0,
   "edge_moment_3": 10.0,
   "flap_moment_1": 10.0,
   "flap_moment_2": 10.0,
   "flap_moment_3": 10.0,
   "lss_torque": 4.0,
   "shaft_bending_blade1": 4.0,
   "tilt_moment": 4.0,
   "tower_base_fa_moment": 4.0,
   "tower_base_ss_moment": 4.0,
   "yaw_moment": 4.0
  },
  "condition": {
   "condition": "ecd",
   "event_at": 20.0,
   "iec_class": "I",
   "sign": -1
  },
  "controller": "baseline",
  "del_convention": "range-1hz",
  "dlc": "1.4",
  "duration": 60.0,
  "family": "N",
  "fatigue": False,
  "options": {},
  "plugins": [],
  "run_name": "baseline",
  "seed": 0,
  "shear_exponent": 0.2,
  "sign": -1,
  "supervisor": None,
  "transient": 10.0,
  "turbine": "nrel5mw",
  "turbine_hash": "c03e0c22fc8a8937a060db014bd341ccc146b93dc00fe02e8859bfa65be73495",
  "turbulence": "A",
  "wind_mps": 11.4
 },
 "mpc-s__dlc1.2__ti12__v18__s2": {
  "assess_hash": "4a724c3b7b4c6473f3c1a7a1e8eca75576c792cef24e512bef16bb10d499c1ff",
  "case_hash": "f958a637e87eb02bc949c95b1a290c5a82ffb6b081904844d77c89f4bba444bd",
  "case_id": "mpc-s__dlc1.2__ti12__v18__s2",
  "channels": {
   "edge_moment_1": 10.0,
   "edge_moment_2": 10.0,
   "edge_moment_3": 10.0,
   "flap_moment_1": 10.0,
   "flap_moment_2": 10.0,
   "flap_moment_3": 10.0,
   "lss_torque": 4.0,
   "shaft_bending_blade1": 4.0,
   "tilt_moment": 4.0,
   "tower_base_fa_moment": 4.0,
   "tower_base_ss_moment": 4.0,
   "yaw_moment": 4.0
  },
  "condition": None,
  "controller": "mpc-s",
  "del_convention": "range-1hz",
  "dlc": "1.2",
  "duration": 60.0,
  "family": "N",
  "fatigue": True,
  "options": {
   "horizon": 12
  },
  "plugins": [],
  "run_name": "mpc",
  "seed": 2,
  "shear_exponent": 0.2,
  "sign": 1,
  "supervisor": None,
  "transient": 10.0,
  "turbine": "nrel5mw",
  "turbine_hash": "c03e0c22fc8a8937a060db014bd341ccc146b93dc00fe02e8859bfa65be73495",
  "turbulence": 0.12,
  "wind_mps": 18.0
 }
}


def test_cases_of_an_older_store_read_back_with_their_hashes() -> None:
    """The hashes of an older store's cases come back from its spec: with the turbine data it
    was run on (its folder's hash, recorded in each case), the case hashes are the recorded
    ones; the spec's own turbine hash follows the packaged data of this release."""
    import dataclasses

    from mpc_wt.campaign.spec import Case

    spec = spec_from_dict(LEGACY_SPEC)
    old_turbine = {c["turbine_hash"] for c in LEGACY_CASES.values()}
    assert len(old_turbine) == 1
    spec = dataclasses.replace(spec, turbine_hash=old_turbine.pop())
    new = {c.case_id: c for c in spec.cases()}
    for case_id, old in LEGACY_CASES.items():
        assert new[case_id].case_hash == old["case_hash"]
        # an older store knows no design hash; everything else comes back as it was
        assert Case.from_dict(old) == dataclasses.replace(new[case_id], design_hash=None)
        assert Case.from_dict(json.loads(json.dumps(new[case_id].to_dict()))) == new[case_id]
    ecd = new["baseline__dlc1.4__ecd__v11.4__neg"]
    assert (ecd.scenario.condition, ecd.scenario.sign, ecd.scenario.event_at) == ("ecd", -1, 20.0)
    assert ecd.scenario.duration == 70.0 and ecd.duration == 60.0


def test_a_worker_designs_each_controller_once(tmp_path):
    """One design per controller per worker, whatever the number of cases: 2 controllers x
    3 winds x 2 seeds on 2 process workers; each case's file says whether its design was made
    for it, and every (worker, controller) made exactly one, with one digest per controller."""
    spec = _spec(winds=[6, 13, 20], seeds=2, duration=10, transient=1,
                 controllers=["baseline", "coleman-ipc"])
    s = run_campaign(spec, tmp_path, engine="processes", workers=2, progress=False)
    assert (s.done, s.failed) == (12, 0)
    made: dict = {}
    digests: dict = {}
    for f in sorted((tmp_path / "cases").glob("*.nc")):
        meta = ClosedLoopResult.load(f).meta
        key = (meta["campaign_case"]["worker"], meta["controller"])
        made.setdefault(key, []).append(meta["design"]["new"])
        digests.setdefault(meta["controller"], set()).add(meta["design"]["digest"])
    assert sum(len(v) for v in made.values()) == 12
    assert all(sum(v) == 1 for v in made.values()), made
    assert {len(d) for d in digests.values()} == {1}


def test_the_runner_hands_out_long_cases_first_and_a_scenarios_controllers_together():
    """Submission order: the 60 s cases before the 20 s ones, and within a length the
    controllers of one (wind, seed) one after another, so a worker meets the field it has just
    made; the spec's own order is controller-major."""
    from mpc_wt.campaign.runner import submission_order

    raw = {k: v for k, v in BASE.items() if k not in ("winds", "seeds")}
    spec = spec_from_dict({**raw, "controllers": ["baseline", "coleman-ipc"], "load_cases": [
        {"dlc": "1.2", "winds": [6, 13], "seeds": 2},
        {"dlc": "1.3", "condition": "etm", "winds": [13], "seeds": 1, "duration": 60}]})
    cases = spec.cases()
    assert [c.controller for c in cases[:5]] == ["baseline"] * 5
    order = submission_order(cases)
    assert sorted(c.case_id for c in order) == sorted(c.case_id for c in cases)
    assert [c.scenario.duration for c in order] == [65.0] * 2 + [25.0] * 8
    pairs = [(c.scenario.wind_mps, c.scenario.seed, c.controller) for c in order[2:]]
    assert pairs == [(v, s, k) for v in (6.0, 13.0) for s in (1, 2)
                     for k in ("baseline", "coleman-ipc")]


def test_changed_or_cut_files_are_found_by_checksum_and_computed_again(tmp_path, caplog):
    """Two finished cases: one file's flap moment scaled by 3 in place (still a valid file),
    the other cut to 800 kB. The report refuses, naming both; resuming computes both again
    (logged), moves the changed files aside, and the report then equals the first one's DELs
    (the simulation is deterministic)."""
    import logging

    from mpc_wt.campaign.report import make_report
    from mpc_wt.errors import ResultFileError

    spec = _spec(winds=[12, 16])
    run_campaign(spec, tmp_path, engine="serial", progress=False)
    with CampaignStore(tmp_path) as st_:
        rows = {r.case_id: r for r in st_.rows()}
    assert all(r.sha256 and len(r.sha256) == 64 for r in rows.values())
    before = {k: r.metrics["channels"]["flap_moment_1"]["del"] for k, r in rows.items()}
    scaled, cut = (tmp_path / rows[k].file for k in sorted(rows))
    import linearize

    res = ClosedLoopResult.load(scaled)
    res.z[:, linearize.OUTPUT_NAMES.index("flap_moment_1")] *= 3.0
    res.save(scaled)
    data = cut.read_bytes()
    cut.write_bytes(data[:800_000] if len(data) > 800_000 else data[: len(data) // 2])
    with pytest.raises(ResultFileError, match=r"2 case\(s\) do not match the checksum") as e:
        make_report(tmp_path)
    assert all(k in str(e.value) for k in rows)
    with caplog.at_level(logging.WARNING, logger="mpc_wt.campaign.store"):
        s = run_campaign(spec, tmp_path, engine="serial", progress=False)
    assert (s.submitted, s.done, s.reused) == (2, 2, 0)
    assert sum("does not match the checksum" in m for m in caplog.messages) == 2
    assert scaled.with_suffix(".changed.nc").is_file() and cut.with_suffix(".changed.nc").is_file()
    with CampaignStore(tmp_path) as st_:
        again = {r.case_id: r.metrics["channels"]["flap_moment_1"]["del"] for r in st_.rows()}
    assert again == before
    make_report(tmp_path)


def test_metrics_edited_in_the_index_are_found_by_checksum(tmp_path, caplog):
    """A finished case's DEL edited in index.sqlite (its file untouched): the report refuses,
    naming the case and its metrics; resuming computes the case again (logged) and the report
    then holds the computed DEL, not the edited one (the edited number went into the report)."""
    import logging
    import sqlite3

    from mpc_wt.campaign.report import make_report
    from mpc_wt.errors import ResultFileError

    spec = _spec(winds=[12])
    run_campaign(spec, tmp_path, engine="serial", progress=False)
    with CampaignStore(tmp_path) as st_:
        (row,) = st_.rows()
    true_del = row.metrics["channels"]["flap_moment_1"]["del"]
    edited = json.loads(json.dumps(row.metrics))
    edited["channels"]["flap_moment_1"]["del"] = 0.5 * true_del
    with sqlite3.connect(tmp_path / "index.sqlite") as db:
        db.execute("UPDATE cases SET metrics=? WHERE case_id=?",
                   (json.dumps(edited), row.case_id))
    with pytest.raises(ResultFileError, match=rf"1 case\(s\) do not match the checksum .*"
                                              rf"{row.case_id} \(its metrics in index.sqlite: "
                                              rf"edited"):
        make_report(tmp_path)
    with caplog.at_level(logging.WARNING, logger="mpc_wt.campaign.store"):
        s = run_campaign(spec, tmp_path, engine="serial", progress=False)
    assert (s.submitted, s.done) == (1, 1)
    assert any("its metrics in the index" in m for m in caplog.messages)
    with CampaignStore(tmp_path) as st_:
        (again,) = st_.rows()
    assert again.metrics["channels"]["flap_moment_1"]["del"] == true_del
    make_report(tmp_path)


def test_fault_injection_campaign(tmp_path):
    """Twelve short cases on a real LocalCluster (2 workers) with a separate client process:
    one case's library calls exit(3), one's crashes (SIGSEGV); a worker is killed (SIGKILL)
    mid-campaign, then the client, which is started again; then one finished file is cut to
    half and another's flap moment tripled in place, and the campaign resumed. Every case is in
    the index exactly once; the two library cases failed, named with their exit status or
    signal and their last output, and nothing else failed; the two changed files were computed
    again (equal to the first results); the report is made and lists the failed cases."""
    import shutil as sh

    from distributed import Client, LocalCluster

    import linearize
    from mpc_wt.campaign.report import make_report

    cc = sh.which("gcc") or sh.which("cc")
    if cc is None:
        pytest.skip("no C compiler")
    probe = tmp_path / "libprobe.so"
    subprocess.run([cc, "-shared", "-fPIC", "-O1", "-o", str(probe),
                    str(Path(__file__).parents[2] / "data" / "discon_probe.c")], check=True)
    for name in ("PROBE_EXIT.IN", "PROBE_CRASH.IN"):
        (tmp_path / name).write_text("x\n")
    libs = [{"name": n, "controller": "discon", "discon_library": str(probe),
             "discon_in": str(tmp_path / f), "winds": [12], "seeds": [1]}
            for n, f in (("exits", "PROBE_EXIT.IN"), ("crashes", "PROBE_CRASH.IN"))]
    raw = {**BASE, "name": "faults", "duration": 45, "winds": [8, 11, 14, 17, 20],
           "seeds": 2, "controllers": ["baseline", *libs]}
    spec_path, out, db, cmd = _campaign_cli(tmp_path, raw)
    n_cases = 12
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None) as cluster, Client(cluster) as client:
        cmd += ["--scheduler", cluster.scheduler_address]
        _kill_a_worker_then_the_client(cmd, client, db, 3)
        assert _done(db) < n_cases - 2, "the client finished before it was killed"
        second = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        assert second.returncode == 1, second.stdout + second.stderr   # two failed cases
        con = sqlite3.connect(db)
        done = dict(con.execute("SELECT case_id, file FROM cases WHERE status='done'"))
        before = {cid: ClosedLoopResult.load(out / f).channel("flap_moment_1")
                  for cid, f in done.items()}
        cut, scaled = sorted(done)[:2]
        data = (out / done[cut]).read_bytes()
        (out / done[cut]).write_bytes(data[: len(data) // 2])
        res = ClosedLoopResult.load(out / done[scaled])
        res.z[:, linearize.OUTPUT_NAMES.index("flap_moment_1")] *= 3.0
        res.save(out / done[scaled])
        third = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
        assert third.returncode == 1, third.stdout + third.stderr
    rows = con.execute("SELECT case_id, status, error, file FROM cases").fetchall()
    ids = [r[0] for r in rows]
    assert len(ids) == len(set(ids)) == n_cases
    assert set(ids) == {c.case_id for c in load_spec(spec_path).cases()}
    failed = {r[0]: r[2] for r in rows if r[1] == "failed"}
    assert sorted(failed) == ["crashes__A__v12__s1", "exits__A__v12__s1"]
    assert "exit status 3" in failed["exits__A__v12__s1"]
    assert "probe: giving up at t = 0.50 s" in failed["exits__A__v12__s1"]
    assert "killed by signal 11 (SIGSEGV)" in failed["crashes__A__v12__s1"]
    assert "probe: about to crash" in failed["crashes__A__v12__s1"]
    for cid, status, _, f in rows:
        if status == "done":
            again = ClosedLoopResult.load(out / f).channel("flap_moment_1")
            np.testing.assert_array_equal(again, before[cid])
    assert (out / done[cut]).with_suffix(".changed.nc").is_file()
    text = (Path(make_report(out)).parent / "report.md").read_text()
    section = text[text.index("## Failed cases"):]
    assert "exits__A__v12__s1" in section and "exit status 3" in section
    assert "crashes__A__v12__s1" in section and "SIGSEGV" in section


KIND_WITH_A_CODE_DEFAULT = '''
import dataclasses
from mpc_wt.registry import Built, Options, register
from mpc_wt.controllers.baseline import BaselineController, tune_baseline
from mpc_wt.run import law_controller

#: a default that lives in code, not in an option: no case hash covers it
GAIN_SCALE = 1.0

@dataclasses.dataclass(frozen=True)
class NoOptions(Options):
    pass

@register("pi-code-default", NoOptions, summary="the baseline PI, its gains x GAIN_SCALE")
def build(ctx, opts):
    g = tune_baseline(ctx.turbine)
    g = dataclasses.replace(g, kp=g.kp * GAIN_SCALE, ki=g.ki * GAIN_SCALE)
    return Built(law_controller(BaselineController(ctx.turbine, g), "baseline", ctx.turbine))
'''


def test_a_default_changed_in_code_computes_the_cases_again(tmp_path, monkeypatch, caplog):
    """A kind whose design takes a default from code (its PI gains x GAIN_SCALE): after that
    default changes (as a new version would change it), resuming the campaign designs the
    controller, finds that its digest differs from the one the finished cases' files record,
    and computes them again, the old files kept as ID.redesigned.nc; the new files record the
    new design and their pitch differs. With the default as it was, a resume computes
    nothing."""
    import importlib
    import logging

    from mpc_wt.registry import registry
    from mpc_wt.registry.context import DEFAULT_CACHE

    (tmp_path / "code_default_kind.py").write_text(KIND_WITH_A_CODE_DEFAULT)
    monkeypatch.syspath_prepend(str(tmp_path))
    try:
        spec = spec_from_dict({"name": "code-default", "duration": 10, "transient": 0,
                               "winds": [18], "seeds": [1, 2], "turbulence": "A",
                               "plugins": ["code_default_kind"],
                               "controllers": [{"name": "pi", "controller": "pi-code-default"}],
                               "channels": {"tower_base_fa_moment": 4}})
        out = tmp_path / "c"
        s = run_campaign(spec, out, engine="serial", progress=False)
        assert (s.done, s.failed) == (2, 0)
        s = run_campaign(spec, out, engine="serial", progress=False)
        assert (s.submitted, s.sync["redesigned"]) == (0, 0)
        assert s.wall_s > 0.0          # the resume's own work (designing, reading headers)
        monkeypatch.setattr(importlib.import_module("code_default_kind"), "GAIN_SCALE", 2.0)
        DEFAULT_CACHE.clear()                   # as in the new version's fresh process
        with caplog.at_level(logging.WARNING, logger="mpc_wt.campaign.runner"):
            s = run_campaign(spec, out, engine="serial", progress=False)
        assert (s.submitted, s.done, s.sync["redesigned"]) == (2, 2, 2)
        assert "computed with another design" in caplog.text
        kept = sorted((out / "cases").glob("*.redesigned.nc"))
        assert len(kept) == 2
        for old_file in kept:
            old = ClosedLoopResult.load(old_file)
            new = ClosedLoopResult.load(old_file.with_name(
                old_file.name.replace(".redesigned.nc", ".nc")))
            assert new.meta["design"]["digest"] != old.meta["design"]["digest"]
            assert np.max(np.abs(new.u[:, 0] - old.u[:, 0])) > 1e-6
    finally:
        registry._KINDS.pop("pi-code-default", None)
        registry._PLUGINS_LOADED.discard("code_default_kind")
        sys.modules.pop("code_default_kind", None)
        DEFAULT_CACHE.clear()


def test_a_law_built_otherwise_computes_the_cases_again(tmp_path, monkeypatch) -> None:
    """The same design run by another build of its law (here another compiler flag, as a fixed
    C source would be): the files record the law's build key, a resume finds it changed and
    computes the cases again; with the law as it was a resume computes nothing. A file that
    records no law (an older version's) keeps."""
    from mpc_wt.io import discon_export
    from mpc_wt.registry.context import DEFAULT_CACHE

    spec = spec_from_dict({"name": "law-build", "duration": 10, "transient": 0,
                           "winds": [18], "seeds": [1, 2], "turbulence": "A",
                           "controllers": [{"name": "b", "controller": "baseline"}],
                           "channels": {"tower_base_fa_moment": 4}})
    out = tmp_path / "c"
    s = run_campaign(spec, out, engine="serial", progress=False)
    assert (s.done, s.failed) == (2, 0)
    first = ClosedLoopResult.read_meta(next((out / "cases").glob("*.nc")))
    assert len(first["design"]["law"]) == 24
    s = run_campaign(spec, out, engine="serial", progress=False)
    assert (s.submitted, s.sync["redesigned"]) == (0, 0)
    monkeypatch.setattr(discon_export, "_CFLAGS", discon_export._CFLAGS + " -DMPCWT_REBUILT=1")
    monkeypatch.setattr(discon_export, "_SHIPPED", {})
    DEFAULT_CACHE.clear()
    try:
        s = run_campaign(spec, out, engine="serial", progress=False)
        assert (s.submitted, s.done, s.sync["redesigned"]) == (2, 2, 2)
        again = ClosedLoopResult.read_meta(next((out / "cases").glob("*s1.nc")))
        assert again["design"]["law"] != first["design"]["law"]
        assert again["design"]["digest"] == first["design"]["digest"]
    finally:
        DEFAULT_CACHE.clear()
    from mpc_wt.campaign.runner import _differs

    assert not _differs({"digest": "d"}, {"digest": "d", "law": "k"})      # no law recorded
    assert _differs({"digest": "d", "law": "j"}, {"digest": "d", "law": "k"})

"""Controller tuning as a constrained, resumable optimization (mpc_wt.tuning)."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from mpc_wt.tuning import Constraint, Parameter, TrialFailed, optimize

# scalar plant x' = a x + b u + w, w white with intensity W; full-state LQR u = -k x designed
# with Q = 1, R = r; the true cost E[x^2 + rho u^2]
A, B, W, RHO = 0.3, 1.0, 1.0, 0.5


def _scalar_lqr(r: float) -> dict[str, float]:
    """Closed form: k = (a + sqrt(a^2 + b^2 / r)) / b, a_cl = a - b k < 0, and the stationary
    variance of x is W / (2 |a_cl|)."""
    k = (A + math.sqrt(A * A + B * B / r)) / B
    var_x = W / (2.0 * abs(A - B * k))
    return {"cost": var_x * (1.0 + RHO * k * k), "u2": k * k * var_x, "gain": k}


def _riccati_cost(rho: float) -> float:
    """LQR theory: with white noise the optimal E[x^2 + rho u^2] is P W, P the Riccati
    solution for Q = 1, R = rho, reached by r = rho (a fact independent of the search)."""
    p = rho * (A + math.sqrt(A * A + B * B / rho)) / (B * B)
    return p * W


def test_scalar_lqr_weight_recovers_the_known_optimum(tmp_path: Path) -> None:
    """TPE over r in [1e-3, 1e3] (log), 30 trials: the best r lies within 25 % of rho = 0.5
    and its cost within 0.2 % of the Riccati optimum P W (the cost is flat: 25 % off in r is
    about 1 % in cost)."""
    res = optimize(lambda p: _scalar_lqr(p["r"]), [Parameter("r", 1e-3, 1e3, log=True)],
                   storage=tmp_path / "s.sqlite", objective="cost", n_trials=30, seed=3,
                   progress=False)
    assert res.best is not None and len(res.trials) == 30
    assert abs(math.log(res.best.params["r"] / RHO)) < math.log(1.25)
    assert res.best.value <= _riccati_cost(RHO) * 1.002
    assert res.best.value >= _riccati_cost(RHO) * (1 - 1e-12)    # nothing beats the optimum


def test_constraints_are_honoured(tmp_path: Path) -> None:
    """E[u^2] <= 0.95 cuts off the unconstrained optimum (E[u^2] = 1.054 at r = rho): the
    returned design meets it, and sits at the boundary r_c (solved by brentq) within 1 % of its
    cost; every trial marked feasible meets it too."""
    cap = 0.95
    res = optimize(lambda p: _scalar_lqr(p["r"]), [Parameter("r", 1e-3, 1e3, log=True)],
                   storage=tmp_path / "s.sqlite", objective="cost",
                   constraints=[Constraint("u2", cap)], n_trials=40, seed=1, progress=False)
    assert _scalar_lqr(RHO)["u2"] > cap
    assert res.best is not None and res.best.metrics["u2"] <= cap
    r_c = brentq(lambda r: _scalar_lqr(r)["u2"] - cap, RHO, 100.0)
    assert res.best.value == pytest.approx(_scalar_lqr(r_c)["cost"], rel=0.01)
    assert all(t.metrics["u2"] <= cap for t in res.trials if t.feasible)
    assert any(not t.feasible for t in res.trials)


def test_a_lower_bound_is_honoured(tmp_path: Path) -> None:
    """E[u^2] >= 1.2 (a lower bound) cuts off the unconstrained optimum from the other side
    (E[u^2] = 1.054 at r = rho, growing as r falls): the returned design meets it and sits at
    the boundary r_c (brentq) within 1 % of its cost; every trial marked feasible meets it."""
    floor = 1.2
    res = optimize(lambda p: _scalar_lqr(p["r"]), [Parameter("r", 1e-3, 1e3, log=True)],
                   storage=tmp_path / "s.sqlite", objective="cost",
                   constraints=[Constraint("u2", floor, lower=True)], n_trials=40, seed=1,
                   progress=False)
    assert _scalar_lqr(RHO)["u2"] < floor
    assert res.best is not None and res.best.metrics["u2"] >= floor
    r_c = brentq(lambda r: _scalar_lqr(r)["u2"] - floor, 1e-3, RHO)
    assert res.best.value == pytest.approx(_scalar_lqr(r_c)["cost"], rel=0.01)
    assert all(t.metrics["u2"] >= floor for t in res.trials if t.feasible)
    assert str(Constraint("power_mean", 0.995, lower=True)) == "power_mean >= 0.995"


def test_min_ratio_in_a_spec_is_a_lower_bound() -> None:
    """``min_ratio`` and ``min_change_pct`` give lower bounds; ``max_ratio`` an upper one."""
    from mpc_wt.tuning.spec import _constraints

    c = _constraints([{"metric": "power_mean", "min_ratio": 0.995},
                      {"metric": "power_mean", "min_change_pct": -0.5},
                      {"metric": "pitch_travel", "max_ratio": 3}], {})
    assert [(x.metric, x.upper, x.lower) for x in c] == [
        ("power_mean", 0.995, True), ("power_mean", pytest.approx(0.995), True),
        ("pitch_travel", 3.0, False)]
    assert c[0].violation({"power_mean": 0.99}) == pytest.approx(0.005)
    assert c[0].violation({"power_mean": 1.01}) < 0


def test_no_feasible_design_gives_none(tmp_path: Path) -> None:
    res = optimize(lambda p: _scalar_lqr(p["r"]), [Parameter("r", 1e-2, 1e2, log=True)],
                   storage=tmp_path / "s.sqlite", objective="cost",
                   constraints=[Constraint("u2", 0.01)], n_trials=6, progress=False)
    assert res.best is None and len(res.completed) == 6


def test_interrupted_tuning_resumes_without_rerunning(tmp_path: Path) -> None:
    """A Ctrl-C in the third evaluation, then a resume to 6 trials: the two finished trials
    are not evaluated again, the interrupted one's parameters are evaluated first, and the
    study ends with 6 counted trials (plus the interrupted record)."""
    store = tmp_path / "s.sqlite"
    calls: list[float] = []

    def evaluate(p: dict[str, float]) -> dict[str, float]:
        if len(calls) == 2 and not getattr(evaluate, "resumed", False):
            raise KeyboardInterrupt
        calls.append(p["r"])
        return _scalar_lqr(p["r"])

    space = [Parameter("r", 1e-3, 1e3, log=True)]
    with pytest.raises(KeyboardInterrupt):
        optimize(evaluate, space, storage=store, objective="cost", n_trials=6, progress=False)
    first = list(calls)
    assert len(first) == 2
    evaluate.resumed = True  # type: ignore[attr-defined]
    res = optimize(evaluate, space, storage=store, objective="cost", n_trials=6, progress=False)
    assert calls[:2] == first and len(calls) == 6          # 2 before + 4 now, none repeated
    interrupted = [t for t in res.trials if t.state == "FAIL"]
    assert len(interrupted) == 1 and calls[2] == interrupted[0].params["r"]
    assert res.evaluated == 4 and len(res.completed) == 6
    assert len(set(calls)) == 6                 # the resumed sampler repeats no earlier point
    # a third call with the same target evaluates nothing
    again = optimize(evaluate, space, storage=store, objective="cost", n_trials=6,
                     progress=False)
    assert again.evaluated == 0 and len(calls) == 6


def test_killed_process_leaves_a_running_trial_that_is_retried(tmp_path: Path) -> None:
    """A trial left RUNNING (the process was killed: asked, never told) is marked failed and its
    parameters are the first evaluated on resume."""
    import optuna

    store = tmp_path / "s.sqlite"
    space = [Parameter("r", 1e-3, 1e3, log=True)]
    optimize(lambda p: _scalar_lqr(p["r"]), space, storage=store, objective="cost",
             n_trials=2, progress=False)
    study = optuna.load_study(study_name="tune", storage=f"sqlite:///{store}")
    orphan = study.ask()
    r_orphan = orphan.suggest_float("r", 1e-3, 1e3, log=True)
    seen: list[float] = []
    res = optimize(lambda p: seen.append(p["r"]) or _scalar_lqr(p["r"]), space, storage=store,
                   objective="cost", n_trials=3, progress=False)
    assert seen == [r_orphan]
    assert [t.state for t in res.trials].count("FAIL") == 1 and len(res.completed) == 3


def test_failed_evaluations_are_recorded(tmp_path: Path) -> None:
    def evaluate(p: dict[str, float]) -> dict[str, float]:
        if p["r"] > 1.0:
            raise TrialFailed(f"diverged at r = {p['r']:.3g}")
        return _scalar_lqr(p["r"])

    res = optimize(evaluate, [Parameter("r", 1e-2, 1e2, log=True)],
                   storage=tmp_path / "s.sqlite", objective="cost", n_trials=12, seed=0,
                   progress=False)
    failed = [t for t in res.trials if t.state == "FAIL"]
    assert failed and all(t.error.startswith("diverged at r = ") for t in failed)
    assert res.best is not None and res.best.params["r"] <= 1.0


@pytest.mark.parametrize("kwargs, match", [
    ({"low": 1.0, "high": 1.0}, "low 1.0 must be below high 1.0"),
    ({"low": 0.0, "high": 1.0, "log": True}, "a log range needs low > 0, got 0.0"),
    ({"low": float("nan"), "high": 1.0}, "parameter 'r' low"),
])
def test_bad_parameters_are_named(kwargs: dict, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        Parameter("r", **kwargs)


def test_bad_calls_are_named(tmp_path: Path) -> None:
    space = [Parameter("r", 1e-3, 1e3, log=True)]
    with pytest.raises(ValueError, match="n_trials must be an integer >= 1, got 0"):
        optimize(_scalar_lqr, space, storage=tmp_path / "s.sqlite", n_trials=0)
    with pytest.raises(ValueError, match="sampler must be one of"):
        optimize(_scalar_lqr, space, storage=tmp_path / "s.sqlite", sampler="grid")
    with pytest.raises(ValueError, match=r"initial point .* r=5000.0 is outside"):
        optimize(_scalar_lqr, space, storage=tmp_path / "t.sqlite", initial=[{"r": 5e3}])
    with pytest.raises(ValueError, match=r"repeated names"):
        optimize(_scalar_lqr, space * 2, storage=tmp_path / "u.sqlite")
    assert np.isfinite(_scalar_lqr(1.0)["cost"])


# -- the campaign-backed tuning (mpcwt tune) ------------------------------------------------
def _spec_raw(**over: object) -> dict:
    raw = {"name": "t", "turbine": "nrel5mw", "duration": 40, "transient": 10,
           "turbulence": "A", "winds": [18], "seeds": [1], "holdout_seeds": [2],
           "channels": {"tower_base_fa_moment": 4},
           "controller": {"controller": "baseline"},
           "reference": {"name": "ref", "controller": "baseline"},
           "parameters": {"omega_n_rad_s": {"low": 0.3, "high": 1.0}},
           "objective": [{"metric": "del:tower_base_fa_moment", "weight": 1}],
           "constraints": [{"metric": "rotor_speed_std", "max_ratio": 1.3}],
           "trials": 3, "seed": 2}
    raw.update(over)
    return raw


@pytest.mark.parametrize("over, key, match", [
    ({"bogus": 1}, "bogus", "unknown key"),
    ({"parameters": {"omega_n": {"low": 0.3, "high": 1}}}, "parameters.omega_n",
     "unknown option of controller 'baseline'"),
    ({"parameters": {"omega_n_rad_s": {"low": -1, "high": 1}}}, "parameters.omega_n_rad_s",
     "omega_n_rad_s must be > 0"),
    ({"parameters": {"omega_n_rad_s": {"low": 0.3}}}, "parameters.omega_n_rad_s.high",
     "missing"),
    ({"objective": [{"metric": "del:flap_moment_1"}]}, "objective[0].metric",
     "unknown measure 'del:flap_moment_1'"),
    ({"constraints": [{"metric": "cs1", "max_ratio": 1, "max_change_pct": 0}]},
     "constraints[0]", "must be {metric, max_ratio}, {metric, max_change_pct}, "),
    ({"constraints": [{"metric": "cs1", "max_value": 3}]}, "constraints[0].metric",
     "max_value bounds a measure per case"),
    ({"controller": {"controller": "baseline", "zeta": 0}}, "controller.zeta",
     "zeta must be > 0"),
    ({"reference": {"controller": "baseline"}}, "reference", "must be a mapping with `name`"),
    ({"sampler": "grid"}, "sampler", "must be one of"),
    ({"trials": 0}, "trials", "must be an integer >= 1, got 0"),
    ({"winds": [99]}, "winds[0]", "must be finite and > 0 and <= 60, got 99"),
])
def test_bad_tuning_spec_keys_are_named(over: dict, key: str, match: str) -> None:
    from mpc_wt.errors import SpecError
    from mpc_wt.tuning.spec import tune_spec_from_dict

    with pytest.raises(SpecError, match=match) as info:
        tune_spec_from_dict(_spec_raw(**over))
    assert info.value.key == key and str(info.value).startswith(f"tuning spec: {key}: ")


def test_tune_over_load_cases_end_to_end_and_resume(tmp_path: Path) -> None:
    """Three trials of the baseline's PI frequency on 40 s cases (serial engine): the outputs
    are written, the returned design meets its constraint on the tuning seeds, and a resume to
    four trials runs only the new trial's case (the reference's and the finished designs' cases
    are reused from the campaign store)."""
    from mpc_wt.campaign import CampaignStore
    from mpc_wt.tuning.run import tune
    from mpc_wt.tuning.spec import tune_spec_from_dict

    spec = tune_spec_from_dict(_spec_raw(constraints=[
        {"metric": "rotor_speed_std", "max_ratio": 1.3},
        {"metric": "pitch_rate_limit_hits", "max_value": 50}]))
    out = tmp_path / "tune"
    res = tune(spec, out, engine="serial", progress=False)
    assert len(res.result.completed) == 3 and res.result.best is not None
    assert res.result.best.metrics["rotor_speed_std"] <= 1.3
    assert 0 <= res.result.best.metrics["pitch_rate_limit_hits"] <= 50
    assert res.tuning["tuned"]["objective"] == pytest.approx(res.result.best.value, rel=1e-9)
    assert set(res.holdout) == {"hand-set", "tuned"}
    for f in ("best.json", "trials.csv", "report.md", "pareto.png", "best/design.json",
              "best/DISCON.IN"):
        assert (out / f).is_file(), f
    assert (out / "pareto.png").read_bytes()[:4] == b"\x89PNG"
    with CampaignStore(out / "campaign") as st:
        before = {r.case_id for r in st.rows(include_stale=True) if r.status == "done"}
    again = tune(spec, out, engine="serial", n_trials=4, progress=False)
    assert again.result.evaluated == 1 and len(again.result.completed) == 4
    with CampaignStore(out / "campaign") as st:
        after = {r.case_id for r in st.rows(include_stale=True) if r.status == "done"}
    new = after - before
    assert len(new) <= 1 and all(c.startswith("c-") for c in new)


def test_tune_cli_names_bad_arguments(tmp_path: Path, capsys: pytest.CaptureFixture[str]
                                      ) -> None:
    import yaml

    from mpc_wt.cli import main

    f = tmp_path / "t.yaml"
    f.write_text(yaml.safe_dump(_spec_raw(parameters={"nope": {"low": 0, "high": 1}})))
    assert main(["tune", str(f), "--out", str(tmp_path / "o")]) == 2
    assert "parameters.nope" in capsys.readouterr().err
    f.write_text(yaml.safe_dump(_spec_raw()))
    assert main(["tune", str(f), "--trials", "0"]) == 2
    assert "--trials must be >= 1, got 0" in capsys.readouterr().err


def test_actuator_limit_hits_hand_worked() -> None:
    """Blade 1 ramps at the 8 deg/s limit during 1-2 s and 5-5.5 s, blade 2 at 4 deg/s
    throughout (half the limit); 10 s at 0.05 s after a 0.5 s transient: two hits, 1.5 s at the
    limit, largest rate 8 deg/s."""
    from mpc_wt.campaign.task import actuator_limit_metrics

    dt, lim = 0.05, math.radians(8.0)
    t = np.arange(0.0, 10.0 + dt / 2, dt)
    rate1 = np.where(((t >= 1.0) & (t < 2.0)) | ((t >= 5.0) & (t < 5.5)), lim, 0.0)
    p1 = np.concatenate([[0.0], np.cumsum(rate1[:-1] * dt)])
    p2 = 0.5 * lim * t
    m = actuator_limit_metrics(t, {"pitch_1": p1, "pitch_2": p2, "pitch_3": 0 * t}, lim, 0.5)
    assert m["pitch_rate_limit_hits"] == 2
    assert m["pitch_rate_limit_s"] == pytest.approx(1.5, abs=1e-9)
    assert m["pitch_rate_max_degps"] == pytest.approx(8.0, rel=1e-9)
    assert actuator_limit_metrics(t, {"rotor_speed": t}, lim, 0.5) == {}


def test_relative_and_absolute_metrics_hand_worked() -> None:
    """Hand-worked ratios: one wind, two seeds. The candidate's tower DELs 2 and 2 MN m against
    the reference's 1 and 1 (m = 4, equal cycle counts: the bin DEL is the m-power mean) give 2;
    DELs 1 and 3 against 1 and 1 give ((1 + 81) / 2)^(1/4) = 2.530; power std 3 and 5 kW
    against 2 and 2 give 2; the per-case limit hits 1 and 4 give 2.5 (no ratio: the reference
    has none)."""
    from mpc_wt.campaign import spec_from_dict
    from mpc_wt.campaign.aggregate import absolute_metrics, relative_metrics
    from mpc_wt.campaign.store import CaseRow

    spec = spec_from_dict({"name": "h", "winds": [18], "seeds": 2,
                           "channels": {"tower_base_fa_moment": 4},
                           "controllers": ["baseline", {"name": "c", "controller": "baseline"}],
                           "reference": "baseline"})

    def row(ctl: str, seed: int, d: float, p: float, hits: int) -> CaseRow:
        m = {"channels": {"tower_base_fa_moment": {"del": d * 1e6, "m": 4.0, "n_eq": 600.0}},
             "power_std_W": p * 1e3, "pitch_rate_limit_hits": hits}
        return CaseRow(f"{ctl}{seed}", ctl, "baseline", 18.0, seed, "A", "", "", "done", None,
                       m, None, None, None, None, 1, None, None)

    ref = [row("baseline", 1, 1.0, 2.0, 0), row("baseline", 2, 1.0, 2.0, 0)]
    got = relative_metrics(spec, ref + [row("c", 1, 2.0, 3.0, 1), row("c", 2, 2.0, 5.0, 4)], "c")
    assert got["del:tower_base_fa_moment"] == pytest.approx(2.0, rel=1e-12)
    assert got["power_std"] == pytest.approx(2.0, rel=1e-12)
    assert "cs1" not in got                                      # neither has it
    got = relative_metrics(spec, ref + [row("c", 1, 1.0, 2.0, 0), row("c", 2, 3.0, 2.0, 0)], "c")
    assert got["del:tower_base_fa_moment"] == pytest.approx(41.0 ** 0.25, rel=1e-12)
    ab = absolute_metrics(spec, ref + [row("c", 1, 2.0, 3.0, 1), row("c", 2, 2.0, 5.0, 4)], "c")
    assert ab["pitch_rate_limit_hits"] == pytest.approx(2.5, rel=1e-12)
    with pytest.raises(ValueError, match="share no wind with finished cases"):
        relative_metrics(spec, [row("c", 1, 2.0, 3.0, 1)], "c")


def test_tune_on_its_own_local_cluster(tmp_path: Path) -> None:
    """The default engine: the tuning starts one local Dask cluster (TLS, closed to other
    processes) for all its trials, and its client connects with that cluster's credentials
    (a plain client was refused: "TLS expects a ssl_context"). Two trials on one worker."""
    from mpc_wt.tuning.run import tune
    from mpc_wt.tuning.spec import tune_spec_from_dict

    spec = tune_spec_from_dict(_spec_raw(trials=2, holdout_seeds=[]))
    res = tune(spec, tmp_path / "tune", engine="dask", workers=1, progress=False)
    assert len(res.result.completed) == 2 and res.result.best is not None

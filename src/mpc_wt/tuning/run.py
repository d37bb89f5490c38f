"""Tune a controller kind over load cases: every trial a small campaign (``mpcwt tune``).

A trial's design runs the tuning spec's load cases (winds x tuning seeds) next to the reference
in one campaign directory, ``OUT/campaign``, on the campaigns' engines (one Dask cluster for
the whole tuning, so workers keep their caches); cases are keyed by the design's parameters, so
a design met again -- a resumed trial, the best one on its re-evaluation -- reuses them. The
Optuna study is ``OUT/study.sqlite``: an interrupted tuning continues where it stopped. After the
search the best feasible design and the hand-set one (the kind's defaults) are run on the
held-out seeds. Written to ``OUT``: ``best.json``, ``trials.csv``, ``pareto.png``,
``report.md`` and, for kinds with a gain synthesis, ``best/`` with the gain table (design.json,
CSV, JSON, and ROSCO's DISCON.IN for a baseline).
"""
from __future__ import annotations

import contextlib
import fcntl
import logging
import time
from pathlib import Path
from typing import Any, Iterator, Mapping

from mpc_wt.campaign.aggregate import absolute_metrics, relative_metrics
from mpc_wt.campaign.runner import run_campaign
from mpc_wt.campaign.store import CampaignStore
from mpc_wt.errors import CampaignLockedError, TrialFailed
from mpc_wt.io.json_text import write_json
from mpc_wt.tuning.optimizer import optimize
from mpc_wt.tuning.outcome import TuneOutcome
from mpc_wt.tuning.spec import TuneSpec, load_tune_spec

__all__ = ["tune"]

log = logging.getLogger(__name__)


@contextlib.contextmanager
def _lock(out: Path) -> Iterator[None]:
    out.mkdir(parents=True, exist_ok=True)
    f = open(out / ".tune.lock", "w")
    try:
        try:
            fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            raise CampaignLockedError(f"{out}: another `mpcwt tune` runs this directory") \
                from None
        yield
    finally:
        f.close()


@contextlib.contextmanager
def _engine(engine: str, workers: int | None, scheduler: str | None
            ) -> Iterator[dict[str, Any]]:
    """run_campaign's engine arguments; for Dask without a scheduler, one local cluster for
    every trial (its workers keep their design caches and compiled kernels)."""
    if engine != "dask" or scheduler is not None:
        yield {"engine": engine, "workers": workers, "scheduler": scheduler}
        return
    from mpc_wt.campaign.runner import local_cluster, worker_count

    cluster = local_cluster(worker_count(workers))
    try:
        yield {"engine": "dask", "workers": None, "scheduler": cluster}
    finally:
        cluster.close()


def _ratios(spec: TuneSpec, root: Path, designs: Mapping[str, Mapping[str, float] | None],
            run: dict[str, Any], seeds: Any = None) -> dict[str, dict[str, float]]:
    """Run the designs (and the reference) on the spec's cases and return their ratios."""
    cspec = spec.campaign(designs, seeds=seeds)
    summary = run_campaign(cspec, root, progress=False, **run)
    if summary.failed:
        cid, err = summary.failures[0]
        raise TrialFailed(f"{summary.failed} case(s) failed, e.g. {cid}: {err}")
    with CampaignStore(root) as st:
        rows = st.rows()
    return {name: spec.metrics({**relative_metrics(cspec, rows, name),
                                **absolute_metrics(cspec, rows, name)}) for name in designs}


def tune(spec: TuneSpec | str | Path, out: str | Path, *, engine: str = "dask",
         workers: int | None = None, scheduler: str | None = None, n_trials: int | None = None,
         progress: bool = True) -> TuneOutcome:
    """Search the spec's parameters, then assess the best design on the held-out seeds.

    Parameters
    ----------
    spec : TuneSpec, str or Path
        A validated spec (:func:`mpc_wt.tuning.spec.load_tune_spec`) or a tuning YAML file.
    out : path
        The tuning directory (created; an existing one is continued).
    engine : {"dask", "processes", "serial"}
        How a trial's cases run (:func:`mpc_wt.campaign.run_campaign`).
    workers : int, optional
        Local worker processes (default one per core).
    scheduler : str, optional
        A running Dask scheduler's address.
    n_trials : int, optional
        Total trials (default the spec's ``trials``).
    progress : bool
        Progress bar over the trials.

    Returns
    -------
    TuneOutcome

    Raises
    ------
    CampaignLockedError
        Another tuning runs the directory.
    """
    if not isinstance(spec, TuneSpec):
        spec = load_tune_spec(spec)
    out = Path(out)
    t0 = time.perf_counter()
    with _lock(out), _engine(engine, workers, scheduler) as run:
        write_json(out / "spec.json", spec.raw)
        root = out / "campaign"

        def evaluate(params: dict[str, Any]) -> dict[str, float]:
            name = spec.candidate_name(params)
            return _ratios(spec, root, {name: params}, run)[name]

        result = optimize(evaluate, spec.parameters, storage=out / "study.sqlite",
                          objective="objective", constraints=spec.constraints,
                          n_trials=n_trials or spec.trials, study_name=spec.name,
                          sampler=spec.sampler, seed=spec.seed, initial=spec.initial,
                          progress=progress)
        outcome = TuneOutcome(result=result)
        designs: dict[str, Mapping[str, float] | None] = {"hand-set": None}
        if result.best is not None:
            designs[spec.candidate_name(result.best.params)] = result.best.params
        for label, seeds, target in (("tuning", None, outcome.tuning),
                                     ("holdout", spec.holdout_seeds, outcome.holdout)):
            if label == "holdout" and not seeds:
                continue
            try:
                got = _ratios(spec, root, designs, run, seeds=seeds)
            except TrialFailed as err:
                log.warning("tuning: the %s evaluation failed: %s", label, err)
                continue
            target.update({("hand-set" if k == "hand-set" else "tuned"): v
                           for k, v in got.items()})
    outcome.wall_s = time.perf_counter() - t0
    from mpc_wt.tuning.report import write_outputs

    outcome.files = write_outputs(spec, outcome, out)
    return outcome



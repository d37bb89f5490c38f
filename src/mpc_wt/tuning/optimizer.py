"""Constrained optimization of design parameters with Optuna, resumable from SQLite.

:func:`optimize` minimizes one measure returned by an ``evaluate(params) -> metrics`` callable,
subject to upper bounds on others, with Optuna's TPE sampler (constraint-aware: each trial's
constraint values go to ``Trial.set_constraint``, feasible when every value <= 0). The study lives in an SQLite file: a
second call with the same file and study name continues it -- finished trials are never run
again, and a trial that was running when the process died is marked failed and its parameters
are tried again first (a campaign-backed ``evaluate`` then reuses the cases that trial
finished). The best design is the feasible trial with the lowest objective.

References
----------
Akiba et al. (2019), Optuna: a next-generation hyperparameter optimization framework, KDD.
Watanabe (2023), Tree-structured Parzen estimator: understanding its algorithm components.
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

from linearize.validate import check_number
from mpc_wt.errors import TrialFailed

__all__ = ["Parameter", "Constraint", "TrialRecord", "TuneResult", "TrialFailed", "optimize",
           "SAMPLERS"]

log = logging.getLogger(__name__)

#: Samplers by name: TPE (default, constraint-aware), random search, and NSGA-II.
SAMPLERS = ("tpe", "random", "nsga2")


@dataclass(frozen=True)
class Parameter:
    """One design parameter and its search range.

    Parameters
    ----------
    name : str
        The option it sets (dotted for nested options: ``weights.rotor_speed``).
    low, high : float
        Range, low < high (both > 0 with ``log``).
    log : bool
        Search on a log scale (weights, gains).
    integer : bool
        An integer parameter.
    """

    name: str
    low: float
    high: float
    log: bool = False
    integer: bool = False

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name:
            raise ValueError(f"parameter name must be a non-empty string, got {self.name!r}")
        check_number(f"parameter {self.name!r} low", self.low)
        check_number(f"parameter {self.name!r} high", self.high)
        if not self.low < self.high:
            raise ValueError(f"parameter {self.name!r}: low {self.low!r} must be below high "
                             f"{self.high!r}")
        if self.log and self.low <= 0:
            raise ValueError(f"parameter {self.name!r}: a log range needs low > 0, got "
                             f"{self.low!r}")

    def suggest(self, trial: Any) -> float | int:
        """The trial's value of this parameter.

        Parameters
        ----------
        trial : optuna.Trial

        Returns
        -------
        float or int
        """
        if self.integer:
            return int(trial.suggest_int(self.name, int(self.low), int(self.high), log=self.log))
        return float(trial.suggest_float(self.name, self.low, self.high, log=self.log))


@dataclass(frozen=True)
class Constraint:
    """A bound on one measure: feasible when ``metrics[metric] <= upper`` (or, with
    ``lower``, ``>= upper``).

    Parameters
    ----------
    metric : str
        A key of the metrics ``evaluate`` returns.
    upper : float
        The bound: the largest allowed value (the smallest with ``lower``).
    lower : bool
        The bound is a lower one (e.g. a power ratio that must not fall below 0.995).
    """

    metric: str
    upper: float
    lower: bool = False

    def __post_init__(self) -> None:
        check_number(f"constraint {self.metric!r} upper", self.upper)

    def violation(self, metrics: Mapping[str, float]) -> float:
        """How far a design is from meeting the bound.

        Parameters
        ----------
        metrics : mapping of str to float

        Returns
        -------
        float
            metrics[metric] - upper (upper - metrics[metric] for a lower bound; <= 0: met);
            +inf when the measure is missing.
        """
        v = metrics.get(self.metric)
        if v is None or not math.isfinite(v):
            return math.inf
        return self.upper - float(v) if self.lower else float(v) - self.upper

    def __str__(self) -> str:
        return f"{self.metric} {'>=' if self.lower else '<='} {self.upper:g}"


@dataclass
class TrialRecord:
    """One trial as stored.

    Parameters
    ----------
    number : int
    state : str
        COMPLETE, FAIL, RUNNING, WAITING.
    params : dict of str to float
    value : float or None
        The objective (None unless complete).
    metrics : dict of str to float
    feasible : bool
        Complete and every constraint met.
    error : str or None
        Why it failed.
    """

    number: int
    state: str
    params: dict[str, float]
    value: float | None
    metrics: dict[str, float]
    feasible: bool
    error: str | None = None


@dataclass
class TuneResult:
    """What :func:`optimize` found.

    Parameters
    ----------
    best : TrialRecord or None
        The feasible trial with the lowest objective (None: no trial feasible).
    trials : list of TrialRecord
        Every trial of the study, in order.
    evaluated : int
        Trials evaluated by this call (the rest were finished before).
    storage : Path
        The SQLite file.
    """

    best: TrialRecord | None
    trials: list[TrialRecord]
    evaluated: int
    storage: Path
    objective: str = "objective"
    constraints: tuple[Constraint, ...] = field(default_factory=tuple)

    @property
    def completed(self) -> list[TrialRecord]:
        """The trials that returned metrics."""
        return [t for t in self.trials if t.state == "COMPLETE"]


def _sampler(name: str, seed: int, n_startup: int) -> Any:
    """The sampler; the constraint values reach it through ``Trial.set_constraint``."""
    import optuna

    if name == "tpe":
        return optuna.samplers.TPESampler(seed=seed, n_startup_trials=n_startup,
                                          multivariate=True)
    if name == "random":
        return optuna.samplers.RandomSampler(seed=seed)
    if name == "nsga2":
        return optuna.samplers.NSGAIISampler(seed=seed)
    raise ValueError(f"sampler must be one of {list(SAMPLERS)}, got {name!r}")


def _record(t: Any, objective: str) -> TrialRecord:
    metrics = dict(t.user_attrs.get("metrics", {}))
    cons = t.user_attrs.get("constraints")
    feasible = t.state.name == "COMPLETE" and cons is not None and all(c <= 0 for c in cons)
    return TrialRecord(number=t.number, state=t.state.name, params=dict(t.params),
                       value=t.value if t.state.name == "COMPLETE" else None, metrics=metrics,
                       feasible=feasible, error=t.user_attrs.get("error"))


#: The error recorded on a trial that a stopped process left unfinished.
INTERRUPTED = "interrupted; tried again on resume"


def _recover(study: Any) -> int:
    """Trials a stopped process left running (killed) or failed by an interrupt (Ctrl-C): the
    running ones are marked failed, and the parameters of each are enqueued to be tried first
    unless a later trial already holds them. Returns how many were enqueued."""
    from optuna.trial import TrialState

    trials = study.get_trials(deepcopy=False)
    n = 0
    for t in trials:
        if t.state == TrialState.RUNNING:
            study._storage.set_trial_user_attr(t._trial_id, "error", INTERRUPTED)
            study._storage.set_trial_state_values(t._trial_id, TrialState.FAIL)
        elif not (t.state == TrialState.FAIL and t.user_attrs.get("error") == INTERRUPTED):
            continue
        later = [u.params or u.system_attrs.get("fixed_params", {}) for u in trials
                 if u.number > t.number]
        if t.params and dict(t.params) not in later:
            study.enqueue_trial(dict(t.params), skip_if_exists=False)
            n += 1
    if n:
        log.warning("tuning: %d trial(s) were unfinished when the last process stopped; their "
                    "parameters are tried again first", n)
    return n


def optimize(evaluate: Callable[[dict[str, Any]], Mapping[str, float]],
             parameters: Sequence[Parameter], *, storage: str | Path,
             objective: str = "objective", constraints: Sequence[Constraint] = (),
             n_trials: int = 40, study_name: str = "tune", sampler: str = "tpe", seed: int = 0,
             initial: Sequence[Mapping[str, Any]] = (), progress: bool = True) -> TuneResult:
    """Minimize ``evaluate(params)[objective]`` subject to ``constraints`` (resumable).

    Parameters
    ----------
    evaluate : callable(params) -> mapping
        Metrics of one design; raise :class:`TrialFailed` for a design that cannot be assessed.
    parameters : sequence of Parameter
        The search space.
    storage : path
        SQLite file of the study (created; an existing study of ``study_name`` is continued).
    objective : str
        The metric to minimize.
    constraints : sequence of Constraint
        Upper bounds on metrics.
    n_trials : int
        Total trials the study should hold when done (finished ones count; failed too).
    study_name : str
    sampler : {"tpe", "random", "nsga2"}
    seed : int
        Sampler seed.
    initial : sequence of mapping
        Parameter sets tried first in a new study (e.g. the hand-set design).
    progress : bool
        A progress bar over the trials.

    Returns
    -------
    TuneResult

    Raises
    ------
    ValueError
        Bad parameters, n_trials < 1, an unknown sampler, an initial point outside the space.
    """
    import optuna
    from optuna.trial import TrialState

    params = list(parameters)
    _check(params, n_trials, initial)
    cons = tuple(constraints)
    path = Path(storage)
    path.parent.mkdir(parents=True, exist_ok=True)
    optuna.logging.set_verbosity(optuna.logging.ERROR)     # failed trials: logged below
    study = optuna.create_study(
        storage=f"sqlite:///{path.resolve()}", study_name=study_name, direction="minimize",
        sampler=_sampler(sampler, seed, n_startup=max(5, min(10, n_trials // 4))),
        load_if_exists=True)
    # a resumed study draws on from a seed of its own: the same seed would replay the first
    # trials' start-up samples (TPE samples at random for its first n_startup trials)
    n_before = len(study.trials)
    if n_before:
        study.sampler = _sampler(sampler, seed + n_before,
                                 n_startup=max(5, min(10, n_trials // 4)))
    _recover(study)
    if not study.trials:
        for point in initial:
            study.enqueue_trial(dict(point))
    ended = (TrialState.COMPLETE, TrialState.FAIL)
    done = sum(t.state in ended for t in study.get_trials(deepcopy=False)
               if t.user_attrs.get("error") != INTERRUPTED)
    todo = max(0, n_trials - done)
    if todo:
        study.optimize(_trial_function(evaluate, params, objective, cons), n_trials=todo,
                       catch=(TrialFailed,), show_progress_bar=progress)
    records = [_record(t, objective) for t in study.get_trials(deepcopy=False)]
    feasible = [r for r in records if r.feasible and r.value is not None]
    best = min(feasible, key=lambda r: r.value) if feasible else None  # type: ignore[arg-type]
    return TuneResult(best=best, trials=records, evaluated=todo, storage=path,
                      objective=objective, constraints=cons)


def _check(params: list[Parameter], n_trials: Any, initial: Sequence[Mapping[str, Any]]
           ) -> None:
    if not params:
        raise ValueError("parameters: at least one is needed")
    names = [p.name for p in params]
    if len(set(names)) != len(names):
        raise ValueError(f"parameters: repeated names in {names}")
    if isinstance(n_trials, bool) or not isinstance(n_trials, int) or n_trials < 1:
        raise ValueError(f"n_trials must be an integer >= 1, got {n_trials!r}")
    space = {p.name: p for p in params}
    for point in initial:
        for k, v in point.items():
            p = space.get(k)
            if p is None or not p.low <= v <= p.high:
                raise ValueError(f"initial point {dict(point)}: {k}={v!r} is outside the "
                                 f"search space {[(q.name, q.low, q.high) for q in params]}")


def _trial_function(evaluate: Callable[[dict[str, Any]], Mapping[str, float]],
                    params: list[Parameter], objective: str, cons: tuple[Constraint, ...]
                    ) -> Callable[[Any], float]:
    """Optuna's objective: suggest, evaluate, store metrics and constraint values."""
    def run(trial: Any) -> float:
        p = {q.name: q.suggest(trial) for q in params}
        try:
            m = {k: float(v) for k, v in evaluate(p).items()}
        except KeyboardInterrupt:
            trial.set_user_attr("error", INTERRUPTED)
            raise
        except TrialFailed as err:
            log.warning("trial %d failed (%s): %s", trial.number,
                        ", ".join(f"{k}={v:.4g}" for k, v in p.items()), err)
            trial.set_user_attr("error", str(err))
            trial.set_user_attr("constraints", [math.inf] * max(1, len(cons)))
            raise
        trial.set_user_attr("metrics", m)
        viol = [c.violation(m) for c in cons]
        trial.set_user_attr("constraints", viol or [0.0])
        for i, (c, v) in enumerate(zip(cons, viol)):
            trial.set_constraint(f"{i}:{c.metric}", v if math.isfinite(v) else 1e300)
        value = m.get(objective)
        if value is None or not math.isfinite(value):
            trial.set_user_attr("error", f"objective {objective!r} missing or not finite in "
                                         f"the metrics {sorted(m)}")
            raise TrialFailed(trial.user_attrs["error"])
        return value
    return run

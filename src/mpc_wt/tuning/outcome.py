"""What a tuning run found: its outcome, the Pareto front and the trials' table.
"""
from __future__ import annotations

import csv
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from mpc_wt.tuning.optimizer import TuneResult

__all__ = ["REPORT_METRICS", "TuneOutcome", "write_trials_csv", "pareto_front"]

#: Measures the report always shows (besides the objective's and the constraints').
REPORT_METRICS = ("rotor_speed_std", "power_std", "pitch_travel", "cs1", "cs2")


@dataclass
class TuneOutcome:
    """What :func:`tune` found and wrote.

    Parameters
    ----------
    result : TuneResult
        The search (best trial, every trial).
    tuning : dict
        Ratios to the reference on the tuning seeds: ``tuned`` and ``hand-set``.
    holdout : dict
        The same on the held-out seeds (empty without ``holdout_seeds``).
    files : list of Path
        What was written.
    wall_s : float
    """

    result: TuneResult
    tuning: dict[str, dict[str, float]] = field(default_factory=dict)
    holdout: dict[str, dict[str, float]] = field(default_factory=dict)
    files: list[Path] = field(default_factory=list)
    wall_s: float = 0.0


def write_trials_csv(result: TuneResult, path: Path) -> Path:
    """Write ``trials.csv``: one row per trial (:func:`trials_table`).

    Parameters
    ----------
    result : TuneResult
        The tuning's trials.
    path : Path
        The file to write.

    Returns
    -------
    Path
        The file written.
    """
    rows = trials_table(result)
    with open(path, "w", newline="") as f:
        if rows:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            for r in rows:
                w.writerow({k: ("" if v is None else f"{v:.6g}" if isinstance(v, float)
                                and math.isfinite(v) else v) for k, v in r.items()})
    return path


def pareto_front(points: np.ndarray) -> np.ndarray:
    """Indices of the non-dominated rows of ``points`` (every column minimized), in order of
    the first column.

    Parameters
    ----------
    points : (n, k) ndarray
        One row per design, one column per objective.

    Returns
    -------
    (n_front,) ndarray of int
        The rows on the Pareto front.
    """
    idx = []
    for i, p in enumerate(points):
        dominated = np.any(np.all(points <= p, axis=1) & np.any(points < p, axis=1))
        if not dominated:
            idx.append(i)
    return np.array(sorted(idx, key=lambda i: points[i, 0]), dtype=int)


def trials_table(result: TuneResult) -> list[dict[str, Any]]:
    """One row per trial: number, state, feasible, objective, parameters, measures, error."""
    keys = sorted({k for t in result.trials for k in t.metrics} - {"objective"})
    pnames = sorted({k for t in result.trials for k in t.params})
    return [{"trial": t.number, "state": t.state, "feasible": t.feasible, "objective": t.value,
             **{f"param:{k}": t.params.get(k) for k in pnames},
             **{k: t.metrics.get(k) for k in keys}, "error": t.error or ""}
            for t in result.trials]

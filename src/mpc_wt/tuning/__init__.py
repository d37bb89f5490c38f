"""Controller tuning as an optimization over load cases.

:mod:`.optimizer` is the generic, resumable, constrained search (Optuna, SQLite);
:mod:`.spec` the tuning spec (a campaign spec plus the search space, objective and
constraints); :mod:`.run` evaluates a design as a small campaign on the campaigns' engines and
writes the best design, its gain tables, the Pareto front and a report.
"""
from mpc_wt.errors import TrialFailed
from mpc_wt.tuning.optimizer import (
           SAMPLERS,
           Constraint,
           Parameter,
           TrialRecord,
           TuneResult,
           optimize,
)

__all__ = ["SAMPLERS", "Constraint", "Parameter", "TrialFailed", "TrialRecord", "TuneResult",
           "optimize"]

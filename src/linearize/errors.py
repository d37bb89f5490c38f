"""Exceptions of ``linearize``, each a subclass of a built-in (python-control's
``exception.py`` is the model): catch the built-in, or the specific class."""
from __future__ import annotations

from typing import Any

__all__ = ["TurbineFileError", "TrimError", "LinearizationError", "SimulationDivergedError",
           "LinFileError"]


class TurbineFileError(ValueError):
    """A turbine file is missing, malformed or holds a value out of range."""


class LinFileError(ValueError):
    """An OpenFAST ``.lin`` file is missing, malformed, or not a set that MBC3 can take."""


class TrimError(RuntimeError):
    """The requested operating point cannot be reached."""


class LinearizationError(RuntimeError):
    """The plant could not be linearized (e.g. a Jacobian entry is not finite)."""


class SimulationDivergedError(RuntimeError):
    """A simulation left the physical envelope.

    Parameters
    ----------
    message : str
        Names the time, the state and its value.
    partial : object
        What was simulated before: a :class:`linearize.SimulationResult` for open-loop runs, an
        ``mpc_wt.ClosedLoopResult`` for closed loops. Nothing computed is lost.
    """

    def __init__(self, message: str, partial: Any) -> None:
        super().__init__(message)
        self.partial = partial

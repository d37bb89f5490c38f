"""Exceptions of ``mpc_wt``, one class per kind of failure, each a subclass of a built-in
(python-control's ``exception.py`` is the model). :class:`SimulationDivergedError` is
``linearize``'s own class: open and closed loops raise the same one."""
from __future__ import annotations

from linearize import SimulationDivergedError

__all__ = ["RunTooLargeError", "UsageError", "OptionsError", "SpecError", "CampaignLockedError", "CampaignIndexError",
           "GainTableError", "ResultFileError", "PremiseError", "SynthesisError",
           "SimulationDivergedError", "QPSetupError", "ControllerLibraryError", "SolverSourceError", "TrialFailed",
           "CaseDataError", "OpenFASTRunError"]


class UsageError(ValueError):
    """A command-line value that is not allowed."""


class OptionsError(ValueError):
    """Controller options that a kind does not take, or values out of range.

    Parameters
    ----------
    message : str
        Names the option, the value and what is allowed.
    key : str
        The option's name (nested options joined by dots, ``lidar.focus``), so that a campaign
        spec can prefix its own path (``controllers[0].lidar.focus``).
    """

    def __init__(self, message: str, key: str = "") -> None:
        super().__init__(message)
        self.key = key


class SpecError(ValueError):
    """A campaign spec that cannot be used; the message names the key and what is allowed."""


class CampaignLockedError(RuntimeError):
    """Another client is running the same campaign directory."""


class CampaignIndexError(ValueError):
    """A campaign's ``index.sqlite`` that is not an SQLite database (``storage`` False: the
    command line exits 2), or that cannot be written (a full disk, a read-only folder;
    ``storage`` True: exit 1, the run failed)."""

    def __init__(self, message: str, *, storage: bool = False) -> None:
        super().__init__(message)
        self.storage = storage


class RunTooLargeError(ValueError):
    """A run or campaign whose estimated memory exceeds what the machine has available."""


class GainTableError(ValueError):
    """A gain table that is missing, of another schema, or inconsistent."""


class ResultFileError(ValueError):
    """A result file is missing, truncated, of another schema, or misses a channel."""


class PremiseError(ValueError):
    """A premise value outside the TS model's vertex grid."""


class SynthesisError(ValueError):
    """A design problem that has no solution as posed (the message says what to change)."""


class QPSetupError(ValueError):
    """A QP backend that is unknown, not installed, or cannot take the formulation asked for."""


class ControllerLibraryError(RuntimeError):
    """A Bladed-style controller library that cannot be loaded, or that stopped the run
    (``aviFAIL < 0``) with its message.

    Parameters
    ----------
    message : str
        Names the library and file, or the time and the library's own message.
    partial : object, optional
        The :class:`mpc_wt.ClosedLoopResult` simulated before the library stopped the run (set
        by :func:`mpc_wt.simulate_closed_loop`); nothing computed is lost.
    """

    def __init__(self, message: str, partial: object = None) -> None:
        super().__init__(message)
        self.partial = partial


class SolverSourceError(ControllerLibraryError):
    """The C sources of a QP solver that an export needs cannot be had: not in the cache and
    not downloadable, or an archive whose digest is not the recorded one. The message gives the
    command that fixes it."""


class OpenFASTRunError(RuntimeError):
    """OpenFAST could not be found, or did not finish: the message says which, with OpenFAST's
    last lines where it ran.

    Parameters
    ----------
    message : str
        What was tried, or OpenFAST's last lines.
    ran : bool
        Whether OpenFAST was started (False: no executable found).
    """

    def __init__(self, message: str, ran: bool = True) -> None:
        super().__init__(message)
        self.ran = ran


class TrialFailed(RuntimeError):
    """A tuning trial's design that could not be assessed (a diverged case, a synthesis error):
    the trial is recorded as failed with this message, and the search goes on."""


class CaseDataError(RuntimeError):
    """A controller's design asked for what only the simulator knows (the case's mean wind,
    seed, turbulence or wind field)."""

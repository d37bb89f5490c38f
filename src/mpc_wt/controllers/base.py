"""What a controller is to the closed loop: the protocol and the base class.
"""
from __future__ import annotations

from typing import Any, Protocol

import numpy as np

__all__ = ["ControllerBase", "Controller"]


class ControllerBase:
    """Base of the controllers mpc-wt ships; a user's controller need not subclass it (any
    object with ``reset`` and ``step`` runs, see :class:`Controller`).

    ``signals`` holds the controller's internal signals of the last step, recorded by the
    harness at every plant step.
    """

    signals: dict[str, float]

    def reset(self) -> None:
        """Forget everything of a previous run."""
        raise NotImplementedError

    def step(self, t: float, meas: dict[str, Any]) -> tuple[np.ndarray, float]:
        """Commands for the measurements at time ``t``.

        Parameters
        ----------
        t : float
            Time [s].
        meas : dict
            The harness's measurements (this module's docstring lists them).

        Returns
        -------
        pitch_ref : (3,) ndarray
            Blade pitch commands [rad].
        gen_torque_ref : float
            Generator torque command [N m].
        """
        raise NotImplementedError


class Controller(Protocol):
    """What the harness needs from a controller: ``reset()`` before a run and
    ``step(t, meas) -> (pitch_ref (3,) [rad], gen_torque_ref [N m])`` at its rate."""

    def reset(self) -> None:
        """Forget everything of a previous run."""

    def step(self, t: float, meas: dict[str, Any]) -> tuple[np.ndarray, float]:
        ...


Controller.step.__doc__ = ControllerBase.step.__doc__

"""What a controller is to the closed loop: the protocol and the base class.
"""
from __future__ import annotations

from typing import Any, Protocol

import numpy as np

__all__ = ["ControllerBase", "Controller", "DesignBase"]


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


class DesignBase:
    """Base of the designs whose law runs as it is shipped: their numbers are the input of a
    compiled C law (the kind's export), which the host calls as OpenFAST's ServoDyn does; the
    design itself has no step. :func:`mpc_wt.run.law_controller` (or ``run_controller``,
    campaigns, the command line) runs it.

    ``kind`` names the controller kind whose law runs the design.
    """

    kind: str = ""

    def _not_a_controller(self) -> TypeError:
        return TypeError(
            f"{type(self).__name__} is a design: its law is the compiled C law its kind "
            f"exports; run it with mpc_wt.run.law_controller(design, {self.kind!r}, turbine) "
            f"(or mpc_wt.run.run_controller)")

    def reset(self) -> None:
        """A design has no state; raises :class:`TypeError` naming the way to run it."""
        raise self._not_a_controller()

    def step(self, t: float, meas: dict[str, Any]) -> tuple[np.ndarray, float]:
        """A design has no step; raises :class:`TypeError` naming the way to run it.

        Parameters
        ----------
        t : float
            Time [s].
        meas : dict
            Measurements.

        Returns
        -------
        tuple
            Never.
        """
        raise self._not_a_controller()


class Controller(Protocol):
    """What the harness needs from a controller: ``reset()`` before a run and
    ``step(t, meas) -> (pitch_ref (3,) [rad], gen_torque_ref [N m])`` at its rate."""

    def reset(self) -> None:
        """Forget everything of a previous run."""

    def step(self, t: float, meas: dict[str, Any]) -> tuple[np.ndarray, float]:
        ...


Controller.step.__doc__ = ControllerBase.step.__doc__

"""The supervisory layer: a normal shutdown and emergency stops around any controller.

IEC 61400-1 ed. 3's load cases 2.x (a fault or a loss of the electrical network while
producing), 4.x (normal shutdown) and 5.1 (emergency shutdown) need the turbine's protection
and shutdown sequence in the loop. :class:`Supervisor` wraps any controller (``reset``/
``step``) and, once an event has tripped, replaces its commands for the rest of the run:

* **normal shutdown** at ``shutdown_at``: every blade pitches from where it is towards feather
  (the actuator's maximum pitch) at ``pitch_rate`` (default the actuator's maximum rate), and
  the generator torque ramps from its value at the trip to zero over ``torque_ramp_s``;
* **emergency stop on overspeed**: the same sequence, started at the first controller step at
  which the measured rotor speed exceeds ``overspeed`` times rated (the protection system's
  limit);
* **grid loss** at ``grid_loss_at``: the generator torque drops to zero at once (the harness
  applies no torque-rate limit to it: :attr:`grid_connected` is False) and the blades pitch to
  feather at ``pitch_rate``;
* **a pitch fault on one blade** at ``pitch_fault_at`` (IEC 61400-1 ed. 3 DLC 2.1/2.2: a
  control or protection system fault while producing): blade ``pitch_fault_blade``'s drive
  either seizes (``pitch_fault="seized"``: the blade holds the pitch it had when the fault
  came) or runs away towards fine pitch at the actuator's maximum rate (``"runaway"``, the
  direction that adds aerodynamic torque). The controller keeps running on the other blades
  until the protection detects the fault ``fault_detect_s`` later (a command-versus-measured
  pitch deviation check; our assumed delay); the protection then stops the turbine as in a
  normal shutdown, with the healthy blades to feather and the faulty one held where it is.
  With ``pitch_fault_azimuth_deg`` the fault comes at the first step from ``pitch_fault_at`` on
  at which the faulty blade reaches that azimuth (0 = up, in the direction of rotation): the
  loads of the stop depend on where the faulty blade is when it comes (the edgewise gravity
  load adds to the unbalanced rotor's), so a comparison of controllers fixes it rather than
  leaving it to each rotor's phase at a fixed time. A rotor that has not brought the blade there
  within :data:`AZIMUTH_WAIT_S` (a rotor nearly at rest) takes the fault then (logged).

The state and the trip time are recorded (signals ``supervisor_state``: 0 running, 1
shutdown, 2 overspeed stop, 3 grid loss, 4 pitch-fault stop; ``supervisor_trip_time``); the
wrapped controller's signals are held at their last values after the trip.
"""
from __future__ import annotations

import logging
import math
from typing import Any

import numpy as np

import linearize
from mpc_wt.controllers.base import ControllerBase
from mpc_wt.controllers.baseline_law import REGION3_PITCH_MARGIN

_log = logging.getLogger(__name__)

__all__ = ["Supervisor", "STATES", "TorqueLawGuard", "AZIMUTH_WAIT_S"]

#: Supervisor states and their codes in the signal ``supervisor_state``.
STATES = {"running": 0, "shutdown": 1, "overspeed": 2, "grid_loss": 3, "pitch_fault": 4}

#: The kinds of pitch fault on one blade.
PITCH_FAULTS = ("seized", "runaway")

#: The longest wait for the faulty blade to reach ``pitch_fault_azimuth_deg`` [s]: three
#: revolutions at a fifth of the NREL 5-MW's rated speed.
AZIMUTH_WAIT_S = 30.0


def _opt_time(name: str, value: Any) -> float | None:
    if value is None:
        return None
    v = float(value)
    if not (math.isfinite(v) and v >= 0.0):
        raise ValueError(f"{name} must be a finite time >= 0 s (or None: never), got "
                         f"{value!r}")
    return v


class Supervisor(ControllerBase):
    """Shutdown and emergency stops around a controller (module docstring).

    Parameters
    ----------
    controller : Controller
        The operating controller.
    turbine : linearize.Turbine
        For rated rotor speed and the pitch actuator's limits.
    overspeed : float, optional
        Emergency stop when the rotor speed exceeds this fraction of rated (e.g. 1.2; None:
        no overspeed protection) [-].
    shutdown_at, grid_loss_at : float, optional
        Times of a normal shutdown and of a grid loss [s] (None: none).
    pitch_rate : float, optional
        Pitch rate towards feather [rad/s] (default the actuator's maximum).
    torque_ramp_s : float
        Time in which a shutdown ramps the generator torque to zero [s].
    pitch_fault_at : float, optional
        Time of a pitch fault on one blade [s] (None: none).
    pitch_fault : {"seized", "runaway"}
        The fault: the blade's drive holds its pitch, or runs towards fine pitch at the
        actuator's maximum rate.
    pitch_fault_blade : int
        The faulty blade, 1-3.
    fault_detect_s : float
        Time from the fault to the protection's stop [s] (default 1 s, our assumption).
    pitch_fault_azimuth_deg : float, optional
        The faulty blade's azimuth at which the fault comes, the first time from
        ``pitch_fault_at`` on [deg, 0 = up, in the direction of rotation, 0-360) (None: at
        ``pitch_fault_at`` itself).
    """

    def __init__(self, controller: Any, turbine: linearize.Turbine, *,
                 overspeed: float | None = None, shutdown_at: float | None = None,
                 grid_loss_at: float | None = None, pitch_rate: float | None = None,
                 torque_ramp_s: float = 5.0, pitch_fault_at: float | None = None,
                 pitch_fault: str = "seized", pitch_fault_blade: int = 1,
                 fault_detect_s: float = 1.0,
                 pitch_fault_azimuth_deg: float | None = None) -> None:
        self.controller = controller
        pa = turbine.pitch_actuator
        if overspeed is not None and not (math.isfinite(float(overspeed))
                                          and float(overspeed) > 1.0):
            raise ValueError(f"overspeed must be a fraction of rated rotor speed > 1 (e.g. "
                             f"1.2), got {overspeed!r}")
        self.overspeed = None if overspeed is None else float(overspeed)
        self.limit = (math.inf if overspeed is None
                      else float(overspeed) * turbine.operation.rated_rotor_speed_rad_s)
        self.shutdown_at = _opt_time("shutdown_at", shutdown_at)
        self.grid_loss_at = _opt_time("grid_loss_at", grid_loss_at)
        rate = pa.max_rate_rad_s if pitch_rate is None else float(pitch_rate)
        if not (math.isfinite(rate) and 0.0 < rate <= pa.max_rate_rad_s * (1 + 1e-9)):
            raise ValueError(f"pitch_rate must be in (0, {pa.max_rate_rad_s:g}] rad/s (the "
                             f"actuator's maximum), got {pitch_rate!r}")
        self.pitch_rate = rate
        ramp = float(torque_ramp_s)
        if not (math.isfinite(ramp) and ramp > 0.0):
            raise ValueError(f"torque_ramp_s must be > 0 s, got {torque_ramp_s!r}")
        self.torque_ramp_s = ramp
        self.pitch_fault_at = _opt_time("pitch_fault_at", pitch_fault_at)
        if pitch_fault not in PITCH_FAULTS:
            raise ValueError(f"pitch_fault must be one of {PITCH_FAULTS}, got {pitch_fault!r}")
        self.pitch_fault = pitch_fault
        if pitch_fault_blade not in (1, 2, 3) or isinstance(pitch_fault_blade, bool):
            raise ValueError(f"pitch_fault_blade must be 1, 2 or 3, got {pitch_fault_blade!r}")
        self.fault_blade = int(pitch_fault_blade) - 1
        det = float(fault_detect_s)
        if not (math.isfinite(det) and det >= 0.0):
            raise ValueError(f"fault_detect_s must be a finite time >= 0 s, got "
                             f"{fault_detect_s!r}")
        self.fault_detect_s = det
        az = pitch_fault_azimuth_deg
        if az is not None:
            try:
                az = float(az)
            except (TypeError, ValueError):
                az = math.nan
            if not (math.isfinite(az) and 0.0 <= az < 360.0):
                raise ValueError(f"pitch_fault_azimuth_deg must be an azimuth in [0, 360) deg "
                                 f"(or None: at pitch_fault_at), got "
                                 f"{pitch_fault_azimuth_deg!r}")
        self.fault_azimuth = None if az is None else math.radians(az)
        self.fine = pa.min_pitch_rad
        self.max_rate = pa.max_rate_rad_s
        self.feather = pa.max_pitch_rad
        self.reset()

    @classmethod
    def check_settings(cls, turbine: linearize.Turbine, **settings: Any) -> None:
        """Check supervisor settings without a controller (a spec or the command line).

        Parameters
        ----------
        turbine : linearize.Turbine
            For rated rotor speed and the pitch actuator's limits.
        **settings
            The keyword arguments of :class:`Supervisor` but the controller.

        Raises
        ------
        ValueError
            Naming the setting, its value and what is allowed.
        TypeError
            An unknown setting.
        """
        cls(_Idle(), turbine, **settings)

    def reset(self) -> None:
        """Back to running; reset the wrapped controller."""
        self.controller.reset()
        self.state = "running"
        self.trip_time: float | None = None
        #: False after a grid loss: the harness then applies zero generator torque at once
        self.grid_connected = True
        self._pitch0 = np.zeros(3)
        self._torque0 = 0.0
        self._inner: dict[str, float] = {}
        self._fault_pitch: float | None = None      # the faulty blade's pitch at the fault
        #: when the fault came [s] (None: not yet)
        self.fault_time: float | None = (self.pitch_fault_at if self.fault_azimuth is None
                                         else None)
        self._az_left: float | None = None          # azimuth still to go to the fault [rad]
        self._az_prev = 0.0
        self.signals: dict[str, float] = {"supervisor_state": 0.0,
                                          "supervisor_trip_time": math.nan}

    def _trip(self, t: float, meas: dict[str, Any]) -> None:
        """Latch the first event due at ``t``."""
        if self.grid_loss_at is not None and t >= self.grid_loss_at:
            self.state = "grid_loss"
            self.grid_connected = False
        elif float(meas["rotor_speed"]) > self.limit:
            self.state = "overspeed"
        elif self.shutdown_at is not None and t >= self.shutdown_at:
            self.state = "shutdown"
        elif self.fault_time is not None and t >= self.fault_time + self.fault_detect_s:
            self.state = "pitch_fault"
        else:
            return
        self.trip_time = t
        self._pitch0 = np.asarray(meas["pitch"], float).copy()
        self._torque0 = float(meas["gen_torque"])

    def step(self, t: float, meas: dict[str, Any]) -> tuple[np.ndarray, float]:
        # the wrapped controller's commands while running, the stop sequence after a trip
        # (parameters and returns: ControllerBase.step)
        if self.state == "running" and self.fault_time is None and \
                self.pitch_fault_at is not None and t >= self.pitch_fault_at:
            self._await_azimuth(t, meas)
        if self.state == "running":
            self._trip(t, meas)
        if self.state == "running":
            pitch, tq = self.controller.step(t, meas)
            self._inner = dict(getattr(self.controller, "signals", {}))
            self.signals = {**self._inner, "supervisor_state": 0.0,
                            "supervisor_trip_time": math.nan}
            if self.fault_time is not None and t >= self.fault_time:
                pitch = np.array(pitch, dtype=float)
                pitch[self.fault_blade] = self._faulty(t, meas)
            return pitch, tq
        assert self.trip_time is not None
        el = t - self.trip_time
        pitch = np.minimum(self._pitch0 + self.pitch_rate * el, self.feather)
        pitch = np.maximum(pitch, self._pitch0)
        if self.state == "pitch_fault":     # the faulty drive stays where it is
            pitch[self.fault_blade] = self._pitch0[self.fault_blade]
        tq = 0.0 if self.state == "grid_loss" else \
            self._torque0 * max(0.0, 1.0 - el / self.torque_ramp_s)
        self.signals = {**self._inner,                       # held at their last values
                        "supervisor_state": float(STATES[self.state]),
                        "supervisor_trip_time": self.trip_time}
        return pitch, tq

    def compiled_gate(self, dt: float, ratio: int, n: int) -> tuple[float, int] | None:
        """Where a closed loop compiled around the wrapped controller must hand its call steps
        to :meth:`step`: the rotor speed above which it trips (the overspeed limit) and the
        first call step at which a timed event can come (a shutdown, a grid loss, a pitch
        fault's time). None once it has left the running state.

        Parameters
        ----------
        dt : float
            The plant's step [s]; call step ``k`` is at ``k * dt``.
        ratio : int
            Plant steps per call.
        n : int
            The run's plant steps.

        Returns
        -------
        (float, int) or None
            Rotor speed limit [rad/s] (inf: none), the first plant step that is the
            supervisor's (``n + 1``: none).
        """
        if self.state != "running" or self.fault_time is not None and \
                self.fault_time != self.pitch_fault_at:
            return None
        due = [v for v in (self.grid_loss_at, self.shutdown_at, self.pitch_fault_at)
               if v is not None]
        if not due:
            return self.limit, n + 1
        first = min(due)
        k = max(0, (int(first / dt) // ratio - 1) * ratio)
        while k * dt < first:             # the step's own test: t >= the event's time
            k += ratio
        return self.limit, min(k, n + 1)

    def adopt_running(self) -> None:
        """The signals after call steps a compiled loop made in the running state: the wrapped
        controller's, the state 0."""
        self._inner = dict(getattr(self.controller, "signals", {}))
        self.signals = {**self._inner, "supervisor_state": 0.0,
                        "supervisor_trip_time": math.nan}

    def _await_azimuth(self, t: float, meas: dict[str, Any]) -> None:
        """Count the faulty blade's way to ``pitch_fault_azimuth_deg``; set
        :attr:`fault_time` when it gets there (or when the wait runs out)."""
        assert self.fault_azimuth is not None and self.pitch_fault_at is not None
        psi = float(meas["azimuth"]) + self.fault_blade * 2.0 * math.pi / 3.0
        if self._az_left is None:
            self._az_left = (self.fault_azimuth - psi) % (2.0 * math.pi)
        else:
            step = (psi - self._az_prev + math.pi) % (2.0 * math.pi) - math.pi
            self._az_left -= step
        self._az_prev = psi
        if self._az_left <= 0.0:
            self.fault_time = t
        elif t - self.pitch_fault_at >= AZIMUTH_WAIT_S:
            self.fault_time = t
            _log.warning("pitch fault: blade %d did not reach %.0f deg azimuth within %.0f s "
                         "of pitch_fault_at; the fault comes at t = %.2f s",
                         self.fault_blade + 1, math.degrees(self.fault_azimuth),
                         AZIMUTH_WAIT_S, t)

    def _faulty(self, t: float, meas: dict[str, Any]) -> float:
        """The faulty blade's pitch command after the fault (before the protection acts)."""
        assert self.fault_time is not None
        if self._fault_pitch is None:
            self._fault_pitch = float(meas["pitch"][self.fault_blade])
        if self.pitch_fault == "seized":
            return self._fault_pitch
        return max(self.fine, self._fault_pitch - self.max_rate * (t - self.fault_time))

    def finalize(self) -> None:
        """Pass the harness's last call on to the wrapped controller."""
        fin = getattr(self.controller, "finalize", None)
        if callable(fin):
            fin()


class _Idle:
    """Stands in for the controller while settings are checked."""

    def reset(self) -> None:
        """Nothing to reset."""


class TorqueLawGuard(ControllerBase):
    """Caps a controller's generator torque at the baseline's torque-speed law in a lull: at
    fine pitch below rated speed (the ``+torque-law`` add-on of the MPC kinds).

    An above-rated design that regulates power and speed with pitch and torque together (Madsen
    et al.'s MPC, linearized at the case's mean wind) has, in a lull that brings the pitch to
    fine, only the torque left; holding power with it is the unstable constant-power law below
    rated: the torque rises as the rotor slows, and the rotor stalls (the sign-off campaign:
    13 of 65 MPC cases, from 9 to 17 m/s). With the guard, while the measured collective pitch
    is within ``fine_band`` of the law's minimum pitch at the measured generator speed (fine
    pitch plus the baseline's minimum-pitch schedule,
    :meth:`~mpc_wt.controllers.baseline.BaselineController.min_pitch`: a deck's ROSCO table
    where it has one; from the fine pitch alone the guard never acted on the
    IEA-22-280-RWT, whose region 2 lies 3-5 deg above its fine pitch) and the generator speed
    below the law's rated speed, the
    torque is at most the baseline's law at that speed (K omega^2 in region 2, the region 2.5
    line up to rated torque: :meth:`mpc_wt.controllers.baseline.BaselineController.torque`); otherwise the
    guarded controller's torque passes unchanged.

    Parameters
    ----------
    controller : Controller
        The controller guarded.
    turbine : linearize.Turbine
        For the torque law and fine pitch.
    fine_band : float
        Pitch above fine within which the guard acts [rad] (default 1 deg, the baseline's own
        switch to region 3).
    """

    def __init__(self, controller: Any, turbine: linearize.Turbine, *,
                 fine_band: float = REGION3_PITCH_MARGIN) -> None:
        from mpc_wt.controllers.baseline import BaselineController

        band = float(fine_band)
        if not (math.isfinite(band) and band >= 0.0):
            raise ValueError(f"fine_band must be a finite pitch >= 0 rad, got {fine_band!r}")
        self.controller = controller
        self.law = BaselineController(turbine)
        self.band = band
        self.signals: dict[str, float] = {"torque_law_active": 0.0}

    def reset(self) -> None:
        """Reset the guarded controller."""
        self.controller.reset()
        self.signals: dict[str, float] = {"torque_law_active": 0.0}

    def step(self, t: float, meas: dict[str, Any]) -> tuple[np.ndarray, float]:
        # the guarded controller's commands, the torque capped in a lull (parameters and
        # returns: ControllerBase.step)
        pitch, tq = self.controller.step(t, meas)
        w, p = float(meas["gen_speed"]), meas["pitch"]
        active = 0.0
        floor = self.law.min_pitch(w)         # the law's region-2 pitch at this speed
        if w < self.law.w_rated and float(p[0] + p[1] + p[2]) / 3.0 <= floor + self.band:
            cap = self.law.torque(w, self.law.pitch_min)   # the law's region-2 torque
            if tq > cap:
                tq, active = cap, 1.0
        self.signals = {**getattr(self.controller, "signals", {}), "torque_law_active": active}
        return pitch, tq

    def finalize(self) -> None:
        """Pass the harness's last call on to the guarded controller."""
        fin = getattr(self.controller, "finalize", None)
        if callable(fin):
            fin()

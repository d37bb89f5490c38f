"""Retrofit load control: individual blade control and Coleman-frame IPC, added to a baseline
(down-regulation and active power control are in :mod:`mpc_wt.controllers.derating` and :mod:`mpc_wt.controllers.apc`).

Individual blade control (Pettas and Cheng 2018, sec. 3.1, fig. 3): three decoupled
proportional loops, one per blade, on the blade-root flap moment M_i. A high-pass filter on the
input keeps the loops out of the collective pitch controller's band, band-stop (notch) filters
on the output keep them out of 3P (and any further harmonics given), and the gain is scheduled
on the mean pitch. The IBC pitch is weighted by a factor rising linearly from 0 to 1 with the
electrical power between two fractions of rated (partial to full load):

    theta_i = theta_CPC + w(P) BS(K(theta_mean) HP(M_i)),     i = 1, 2, 3.

The paper tunes K on identified blade models; here K comes from our linear models: at each
region-III wind, the single-blade loop L = K F(z) (-G(z)) (G: pitch_ref_1 -> flap_moment_1 of
the blade-coordinate model discretized at the controller rate, F: the filters) gets the loop
gain ``loop_gain_1p`` at 1P, lowered if needed so that the gain margin is at least
``min_gain_margin`` (python-control's stability margins), and the closed loop is checked
stable.

Coleman-frame IPC (Bossanyi 2003, the scheme ROSCO's IPC implements): the tilt and yaw
components M_cs = 2/3 sum_i M_i [cos psi_i, sin psi_i] are driven to zero by integral control,
theta_cs = -K_I R(-phi) int M_cs dt, and returned to the blades by the inverse transform. K_I
and the azimuth offset phi come from the static gain of the MBC linear model (the 2x2 map
pitch_ref_cos/sin -> flap_moment_cos/sin is close to a gain times a rotation R(phi)): K_I sets
the crossover ``crossover_rad_s`` and phi cancels the rotation.

Down-regulation (Pettas and Cheng sec. 3.2) is :func:`mpc_wt.controllers.baseline.tune_baseline` with
``power_fraction``; :func:`steady_power_curve` and :func:`aep_change` give the steady power
curve of a torque law and the Weibull/Rayleigh-weighted AEP loss.

Active power control (Clemens et al. sec. 3.2, eq 11): :func:`apc_reference` is the test
signal; :class:`mpc_wt.controllers.baseline.BaselineController` follows it with ``power_reference`` and a
pitch loop scheduled on the reference.

Metrics (Pettas and Cheng sec. 4, eq 1): :func:`lifetime_comparison`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np
from scipy import signal

import linearize
from linearize.validate import check_number
from mpc_wt.controllers.apc import check_weight_range
from mpc_wt.controllers.base import DesignBase
from mpc_wt.controllers.baseline import BaselineController, check_power_fraction
from mpc_wt.controllers.filters import filter_sos

__all__ = ["IBC_LOOP_GAIN", "COLEMAN_MAX_AMPLITUDE_DEG", "CYCLIC_RATE_FRACTION",
           "cyclic_amplitude_limit_deg", "ibc_loop_gain", "IBCGains", "tune_ibc",
           "IBCController", "ColemanIPCGains", "tune_coleman_ipc", "ColemanIPCController"]

#: The default loop gain at 1P of each IBC blade loop where the pitch drives are fast enough:
#: chosen so that IBC's pitch travel over the sign-off's DLC 1.2 stays within 3x the
#: baseline's on the NREL 5-MW (1.0 cut the lifetime flap DEL by 16 % at 3.7x the travel; 0.6
#: by about 11 % at about 2.7x; benchmarks/RESULTS.md). On slower drives it falls with the
#: cyclic amplitude they allow (:func:`ibc_loop_gain`).
IBC_LOOP_GAIN = 0.6
#: The largest cyclic pitch amplitude of the Coleman IPC by default [deg]: it bounds the cyclic
#: pitch's travel to keep it within 3x the baseline's over the sign-off's DLC 1.2 on the NREL
#: 5-MW (5 deg left the integrators free: 3.5x). A turbine with slow pitch drives gets less
#: (:func:`cyclic_amplitude_limit_deg`).
COLEMAN_MAX_AMPLITUDE_DEG = 2.0
#: The fraction of the pitch actuator's largest rate a cyclic pitch at rated 1P may take by
#: default: a cyclic of amplitude A at 1P moves at up to A Omega.
CYCLIC_RATE_FRACTION = 0.5


def ibc_loop_gain(turbine: linearize.Turbine) -> float:
    """The default 1P loop gain of IBC's blade loops on a turbine: :data:`IBC_LOOP_GAIN` times
    the fraction of the 2 deg cyclic amplitude its pitch drives allow
    (:func:`cyclic_amplitude_limit_deg`). The proportional loops pass the flap moment's
    turbulence above 1P to the pitch as well, and most of their travel is there (on the
    IEA-15 at 17 m/s the IBC pitch's travel above 1.3P was 3.5x that at 1P): the amplitude's
    clamp alone took 5 % off it. 0.6 on the NREL 5-MW; 0.38 on the IEA-15-240-RWT.

    Parameters
    ----------
    turbine : Turbine

    Returns
    -------
    float
        [-]
    """
    return IBC_LOOP_GAIN * cyclic_amplitude_limit_deg(turbine) / COLEMAN_MAX_AMPLITUDE_DEG


def cyclic_amplitude_limit_deg(turbine: linearize.Turbine,
                               rate_fraction: float = CYCLIC_RATE_FRACTION,
                               cap_deg: float = COLEMAN_MAX_AMPLITUDE_DEG) -> float:
    """The default largest cyclic pitch amplitude of a turbine [deg]: ``cap_deg``, or less
    where a cyclic of that amplitude at rated 1P would take more than ``rate_fraction`` of the
    pitch actuator's largest rate (its rate is A Omega).

    On the NREL 5-MW (8 deg/s, 1.27 rad/s) half the rate allows 3.2 deg and the cap of 2 deg
    holds; on the IEA-15-240-RWT (2 deg/s, 0.79 rad/s) it allows 1.26 deg. With 2 deg there the
    Coleman IPC moved its blades 3.9x as far as the baseline over the sign-off's DLC 1.2 (the
    bound is 3x), and a cyclic of 2.5 deg needs all of the drive's rate.

    Parameters
    ----------
    turbine : Turbine
    rate_fraction : float
        Fraction of the actuator's largest rate, in (0, 1].
    cap_deg : float
        The amplitude where the actuator is fast enough [deg], > 0.

    Returns
    -------
    float
        [deg]
    """
    check_number("rate_fraction", rate_fraction, lo=0.0, lo_open=True, hi=1.0)
    check_number("cap_deg", cap_deg, lo=0.0, lo_open=True, unit="deg")
    rate = turbine.pitch_actuator.max_rate_rad_s
    return min(float(cap_deg),
               math.degrees(rate_fraction * rate / turbine.operation.rated_rotor_speed_rad_s))


def _region3_winds(turbine: linearize.Turbine, step: float = 2.0) -> np.ndarray:
    lo = float(np.floor(linearize.rated_wind_speed(turbine))) + 1.0
    hi = min(25.0, turbine.operation.cut_out_wind)
    return np.unique(np.r_[np.arange(lo, hi, step), hi])


def _freq_resp(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray,
               z: complex) -> np.ndarray:
    """C (z I - A)^-1 B + D of a discrete model."""
    return c @ np.linalg.solve(z * np.eye(a.shape[0]) - a, b) + d


# --------------------------------------------------------------------------------------------
# Individual blade control
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class IBCGains:
    """Gain schedule and filters of the individual blade controller.

    Parameters
    ----------
    pitch_rad : (n_op,) ndarray
        Mean-pitch breakpoints of the schedule (trim pitch at ``wind_mps``) [rad].
    gain : (n_op,) ndarray
        Proportional gain per breakpoint [rad/(N m)]: pitch per unit flap moment.
    wind_mps : (n_op,) ndarray
        Wind speeds of the operating points [m/s].
    gain_margin : (n_op,) ndarray
        Gain margin of the single-blade loop at each point [-] (inf: none).
    loop_gain_1p : (n_op,) ndarray
        Achieved loop gain abs(L) at 1P [-].
    dt : float
        Controller period the filters are designed for [s].
    rotor_speed_rad_s : float
        Rotor speed of the filter frequencies (rated) [rad/s].
    highpass_hz : float
        Input high-pass corner [Hz].
    notch_harmonics : tuple of int
        Output band-stop filters at these multiples of 1P.
    notch_q : float
        Quality factor of the band-stop filters [-].
    weight_range : (float, float)
        Power fractions of rated between which the IBC output rises from 0 to 1 [-].
    rated_power : float
        The rated (or derated) power the weight refers to [W].
    power_fraction : float
        Derating fraction the gains were tuned at [-].
    lowpass_hz : float or None
        Corner of a second-order Butterworth low-pass on the output [Hz] (None: none).
    max_amplitude_rad : float
        Largest IBC pitch of each blade, either way [rad] (inf: none); the controller clamps
        each blade's IBC pitch to it after the blades' mean is taken out.
    """

    pitch_rad: np.ndarray
    gain: np.ndarray
    wind_mps: np.ndarray
    gain_margin: np.ndarray
    loop_gain_1p: np.ndarray
    dt: float
    rotor_speed_rad_s: float
    highpass_hz: float
    notch_harmonics: tuple[float, ...]
    notch_q: float
    weight_range: tuple[float, float]
    rated_power: float
    power_fraction: float = 1.0
    lowpass_hz: float | None = None
    max_amplitude_rad: float = math.inf
    info: dict[str, Any] = field(default_factory=dict, compare=False)

    def __post_init__(self) -> None:
        if not self.max_amplitude_rad > 0:
            raise ValueError(f"max_amplitude_rad must be > 0 rad (inf: none), got "
                             f"{self.max_amplitude_rad!r}")
        for n in ("pitch_rad", "gain", "wind_mps", "gain_margin", "loop_gain_1p"):
            arr = np.array(getattr(self, n), dtype=float)
            arr.flags.writeable = False
            object.__setattr__(self, n, arr)
        if not (self.pitch_rad.shape == self.gain.shape == self.wind_mps.shape
                and self.pitch_rad.ndim == 1 and self.pitch_rad.size >= 1):
            raise ValueError(f"pitch_rad {self.pitch_rad.shape}, gain {self.gain.shape} and "
                             f"wind_mps {self.wind_mps.shape} must be 1-D of equal length")
        if np.any(np.diff(self.pitch_rad) <= 0):
            raise ValueError("pitch_rad must be strictly increasing")

    @property
    def fs(self) -> float:
        """Controller rate [Hz]."""
        return 1.0 / self.dt

    @property
    def one_p_hz(self) -> float:
        """Rotor frequency of the filters [Hz]."""
        return self.rotor_speed_rad_s / (2 * math.pi)

    def input_sos(self) -> np.ndarray:
        """Second-order sections of the input (high-pass) filter.

        Returns
        -------
        (n_sections, 6) ndarray
            The sections.
        """
        return _ibc_sos(self.fs, self.one_p_hz, self.highpass_hz, self.notch_harmonics,
                        self.notch_q, self.lowpass_hz)[0]

    def output_sos(self) -> np.ndarray:
        """Second-order sections of the output (band-stop, optional low-pass) filters.

        Returns
        -------
        (n_sections, 6) ndarray
            The sections.
        """
        return _ibc_sos(self.fs, self.one_p_hz, self.highpass_hz, self.notch_harmonics,
                        self.notch_q, self.lowpass_hz)[1]

    def gain_at(self, pitch_rad: float) -> float:
        """Scheduled gain at a mean pitch (held at the ends of the table) [rad/(N m)].

        Parameters
        ----------
        pitch_rad : float
            Mean pitch [rad].

        Returns
        -------
        float
            Gain [rad/(N m)].
        """
        return float(np.interp(pitch_rad, self.pitch_rad, self.gain))


def _ibc_sos(fs: float, one_p_hz: float, highpass_hz: float, harmonics: Sequence[float],
             notch_q: float, lowpass_hz: float | None) -> tuple[np.ndarray, np.ndarray]:
    """(input, output) second-order sections of the IBC filters."""
    return (filter_sos(fs, highpass_hz=highpass_hz),
            filter_sos(fs, notch_hz=[h * one_p_hz for h in harmonics], notch_q=notch_q,
                       lowpass_hz=lowpass_hz))


def _blade_model(turbine: linearize.Turbine, v: float, p_w: float | None,
                 params: linearize.PlantParams, coordinates: str = "blade"
                 ) -> linearize.LinearModel:
    return linearize.linearize(turbine, v, params=params, power_W=p_w, coordinates=coordinates)


def tune_ibc(turbine: linearize.Turbine, *, winds: Any = None, dt: float = 1.0 / 80.0,
             loop_gain_1p: float | None = None, min_gain_margin: float = 2.0,
             highpass_hz: float | None = None, notch_harmonics: Sequence[int] = (3,),
             notch_q: float = 1.0, weight_range: tuple[float, float] = (0.8, 0.95),
             power_fraction: float = 1.0, lowpass_hz: float | None = None,
             max_amplitude_deg: float | None = None) -> IBCGains:
    """Tune the individual blade controller on our linear models (Pettas and Cheng sec. 3.1).

    Parameters
    ----------
    winds : array_like, optional
        Region-III wind speeds of the schedule [m/s]; default every 2 m/s from the first whole
        m/s above rated to cut-out.
    dt : float
        Controller period [s] (the harness runs the baseline at the plant rate, 1/80 s).
    loop_gain_1p : float, optional
        Target loop gain abs(L(1P)) of each blade loop [-]; default :func:`ibc_loop_gain`.
    min_gain_margin : float
        Smallest gain margin allowed (the gain is lowered to meet it) [-] (2 = 6 dB).
    highpass_hz : float, optional
        Input high-pass corner [Hz]; default half the rated 1P frequency.
    notch_harmonics : sequence of int
        Output band-stop filters at these multiples of rated 1P (paper: 3P).
    notch_q : float
        Quality factor of the band-stop filters [-].
    weight_range : (float, float)
        Power fractions between which the IBC fades in [-].
    power_fraction : float
        Tune on the operating points derated to this fraction of rated power [-].
    lowpass_hz : float, optional
        Second-order low-pass corner on the output [Hz] (not in the paper; it limits the pitch
        acceleration the loops ask for above 3P).
    max_amplitude_deg : float, optional
        Largest IBC pitch of each blade either way [deg] (not in the paper); default
        :func:`cyclic_amplitude_limit_deg` (less on slow pitch drives).

    Returns
    -------
    IBCGains
        The gain schedule over pitch with the filters, margins and the reached 1P loop gain.

    Raises
    ------
    ValueError
        For a filter corner at or above Nyquist, a derating fraction outside (0, 1], or
        non-positive targets.
    RuntimeError
        If a blade loop is unstable even at the smallest gain tried.
    """
    frac = check_power_fraction(power_fraction)
    loop_gain_1p, amp = _ibc_drive_defaults(turbine, loop_gain_1p, max_amplitude_deg)
    harm = _check_ibc_args(dt, loop_gain_1p, min_gain_margin, notch_harmonics)
    wr = check_weight_range(weight_range)
    om = turbine.operation.rated_rotor_speed_rad_s
    f1p = om / (2 * math.pi)
    fs = 1.0 / dt
    hp = 0.5 * f1p if highpass_hz is None else highpass_hz
    v = _region3_winds(turbine) if winds is None else np.asarray(winds, float)
    p_rated = frac * turbine.operation.rated_power
    p_w = None if frac == 1.0 else p_rated
    filt = np.vstack(_ibc_sos(fs, f1p, hp, harm, notch_q, lowpass_hz))
    f_sys = _sos_ss(filt, dt)
    zf = np.exp(1j * om * dt)
    f1 = complex(signal.sosfreqz(filt, worN=[f1p], fs=fs)[1][0])
    params = linearize.plant_params(turbine)
    rows = []                                  # (pitch, gain, gain margin, 1P loop gain)
    for w in v:
        m = _blade_model(turbine, float(w), p_w, params)
        rows.append((math.radians(m.info["pitch_deg"]),
                     *_ibc_gain(m, dt, zf, f1, f_sys, loop_gain_1p, min_gain_margin)))
    pitch, k_out, gm_out, l1p = (np.asarray(c, float) for c in zip(*rows))
    order = np.argsort(pitch)
    return IBCGains(pitch_rad=pitch[order], gain=k_out[order], wind_mps=v[order],
                    gain_margin=gm_out[order], loop_gain_1p=l1p[order], dt=dt,
                    rotor_speed_rad_s=om,
                    highpass_hz=hp, notch_harmonics=harm, notch_q=notch_q,
                    weight_range=wr, rated_power=p_rated, power_fraction=frac,
                    lowpass_hz=lowpass_hz, max_amplitude_rad=math.radians(amp),
                    info={"target_loop_gain_1p": loop_gain_1p,
                          "min_gain_margin": min_gain_margin})


def _ibc_drive_defaults(turbine: linearize.Turbine, loop_gain_1p: float | None,
                        max_amplitude_deg: float | None) -> tuple[float, float]:
    """The loop gain and the largest IBC pitch [deg], each given or the turbine's default."""
    gain = ibc_loop_gain(turbine) if loop_gain_1p is None else loop_gain_1p
    amp = (cyclic_amplitude_limit_deg(turbine) if max_amplitude_deg is None
           else check_number("max_amplitude_deg", max_amplitude_deg, lo=0.0, lo_open=True,
                             hi=20.0, unit="deg"))
    return gain, amp


def _check_ibc_args(dt: float, loop_gain_1p: float, min_gain_margin: float,
                    notch_harmonics: Sequence[int]) -> tuple[float, ...]:
    """Check tune_ibc's numbers; the notch harmonics as floats."""
    check_number("dt", dt, lo=0.0, lo_open=True, unit="s")
    if not (loop_gain_1p > 0 and min_gain_margin > 1):
        raise ValueError(f"loop_gain_1p must be > 0 and min_gain_margin > 1, got "
                         f"{loop_gain_1p!r}, {min_gain_margin!r}")
    harm = tuple(float(h) for h in notch_harmonics)
    if any(not h > 0 for h in harm):
        raise ValueError(f"notch_harmonics must be positive multiples of 1P, got "
                         f"{notch_harmonics!r}")
    return harm


def _ibc_gain(m: linearize.LinearModel, dt: float, zf: complex, f1: complex, f_sys: Any,
              loop_gain_1p: float, min_gain_margin: float) -> tuple[float, float, float]:
    """One blade loop's gain at one operating point: abs(k F G) = target at 1P, lowered until the
    gain margin is met; returns (gain, gain margin, loop gain at 1P)."""
    import control

    s = m.select(inputs=["pitch_ref_1"], outputs=["flap_moment_1"]).discretize(dt)
    g1 = complex(_freq_resp(s.A, s.B_u, s.C_z, s.D_u, zf)[0, 0])
    k = loop_gain_1p / abs(f1 * g1)
    plant = control.ss(s.A, s.B_u, -s.C_z, -s.D_u, dt)     # -G: pitch up lowers the moment
    loop = plant * f_sys
    gm = _gain_margin(loop, k)
    if gm < min_gain_margin:
        k *= gm / min_gain_margin
        gm = _gain_margin(loop, k)
    if not gm > 1.0:
        raise RuntimeError(f"IBC blade loop at {m.wind_mps:g} m/s is unstable at gain {k:g} "
                           f"rad/(N m); check the filters")
    return k, gm, k * abs(f1 * g1)


def _sos_ss(sos: np.ndarray, dt: float) -> Any:
    """A discrete filter in second-order sections as a python-control state-space system (a
    cascade of the sections' state-space forms: no high-order polynomial in between)."""
    import control

    sys = control.ss([], [], [], [[1.0]], dt)
    for sec in np.atleast_2d(sos):
        a, b, c, d = signal.tf2ss(sec[:3], sec[3:])
        sys = control.ss(a, b, c, d, dt) * sys if a.size else sys * float(d[0, 0])
    return sys


def _gain_margin(loop: Any, k: float) -> float:
    """Gain margin of the negative-feedback loop k * loop (discrete): the factor by which k can
    grow before the closed loop turns unstable, found on the closed-loop poles (exact, unlike a
    margin read off a frequency grid); inf if none up to 1e3."""
    import control

    def stable(kk: float) -> bool:
        cl = control.feedback(kk * loop, 1)
        return bool(np.all(np.abs(control.poles(cl)) < 1.0 - 1e-9))

    if not stable(k):
        lo, hi = 0.0, 1.0
        for _ in range(40):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if stable(mid * k) else (lo, mid)
        return lo
    lo, hi = 1.0, 2.0
    while stable(hi * k):
        lo, hi = hi, hi * 2
        if hi > 1e3:
            return math.inf
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if stable(mid * k) else (lo, mid)
    return lo


class _PitchAddOn(DesignBase):
    """What the IBC and Coleman IPC designs share: the collective controller's design
    underneath, the power fade-in weight (power low-passed over ``power_tau`` = 1 s; no seed
    while the measured power is 0, as at ServoDyn's first call), and the pitch limits and
    rate on the summed command."""

    power_tau = 1.0

    def __init__(self, collective: BaselineController, gains: Any) -> None:
        self.collective = collective
        self.gains = gains
        self.dt = collective.dt
        pa = collective.turbine.pitch_actuator
        self.pitch_min, self.pitch_max = collective.pitch_min, pa.max_pitch_rad
        self.step_max = pa.max_rate_rad_s * self.dt


class IBCController(_PitchAddOn):
    """The design of individual blade control on top of a collective controller (Pettas and
    Cheng fig. 3), run by its shipped law (the ``ibc`` kind).

    ``collective`` is the baseline (or derated baseline) that regulates rotor speed and power;
    the law adds the per-blade pitch w(P) BS(K(theta_mean) HP(M_i)) (less its mean over the
    blades, see below; each blade's within ``max_amplitude_rad``) to its collective command
    and enforces the pitch limits and rate on the sum, the collective's part first (the
    blades' own moves within the rate it leaves, as Coleman IPC's: a collective at its rate in
    a gust is never slowed by the blades' loops). The filters start at the steady state of
    their first input. Signals: ``ibc_weight``, ``ibc_gain`` and ``ibc_pitch_1..3`` [rad].

    ``remove_collective=True`` (default) subtracts the blades' mean IBC pitch: the loops act on
    the cyclic content only and leave thrust and torque to the collective controller. The
    paper's fully independent loops (False) rely on the high-pass alone to stay out of the
    collective loop's way; on our plant at 18 m/s (600 s, shear 0.2) that raised the flap DEL
    by 3 %, the tower fore-aft DEL by 21 % and the shaft-torque DEL by 28 %, while the mean
    removal gave -21 %, +0.6 % and -0.1 % for the same 1P reduction (benchmarks/RESULTS.md).

    Parameters
    ----------
    collective : BaselineController
        The collective controller's design.
    gains : IBCGains
        From :func:`tune_ibc` at the collective's dt.
    remove_collective : bool
        Subtract the blades' mean IBC pitch (cyclic action only).
    """

    kind = "ibc"

    def __init__(self, collective: BaselineController, gains: IBCGains, *,
                 remove_collective: bool = True) -> None:
        from scipy.signal import sosfilt_zi

        self.remove_collective = bool(remove_collective)
        if abs(collective.dt - gains.dt) > 1e-12:
            raise ValueError(f"IBC gains were designed for dt = {gains.dt:g} s, the collective "
                             f"controller runs at {collective.dt:g} s")
        #: the input high-pass's and output band-stop's sections (n, 6) and their state at a
        #: unit input's steady state (n, 2)
        self.input_sos, self.output_sos = gains.input_sos(), gains.output_sos()
        self.input_zi, self.output_zi = sosfilt_zi(self.input_sos), sosfilt_zi(self.output_sos)
        super().__init__(collective, gains)


# --------------------------------------------------------------------------------------------
# Coleman-frame IPC
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class ColemanIPCGains:
    """Gain schedule of the Coleman-frame (tilt/yaw) integral IPC.

    Parameters
    ----------
    pitch_rad : (n_op,) ndarray
        Mean-pitch breakpoints [rad].
    ki : (n_op,) ndarray
        Integral gain [rad/(N m s)].
    azimuth_offset_rad : (n_op,) ndarray
        Rotation phi that decouples tilt and yaw [rad].
    wind_mps : (n_op,) ndarray
        [m/s]
    gain_margin : (n_op,) ndarray
        Factor on K_I at which the MBC closed loop turns unstable [-].
    crossover_rad_s : float
        Design crossover of the tilt and yaw loops [rad/s].
    max_amplitude_rad : float
        Limit of the cyclic pitch amplitude (anti-windup) [rad].
    weight_range : (float, float)
        Power fractions of the fade-in [-].
    rated_power : float
        [W]
    power_fraction : float
        [-]
    """

    pitch_rad: np.ndarray
    ki: np.ndarray
    azimuth_offset_rad: np.ndarray
    wind_mps: np.ndarray
    gain_margin: np.ndarray
    crossover_rad_s: float
    max_amplitude_rad: float
    weight_range: tuple[float, float]
    rated_power: float
    power_fraction: float = 1.0

    def __post_init__(self) -> None:
        for n in ("pitch_rad", "ki", "azimuth_offset_rad", "wind_mps", "gain_margin"):
            arr = np.array(getattr(self, n), dtype=float)
            arr.flags.writeable = False
            object.__setattr__(self, n, arr)
        if np.any(np.diff(self.pitch_rad) <= 0):
            raise ValueError("pitch_rad must be strictly increasing")

    def at(self, pitch_rad: float) -> tuple[float, float]:
        """(K_I, phi) at a mean pitch.

        Parameters
        ----------
        pitch_rad : float
            Mean pitch [rad].

        Returns
        -------
        ki : float
            Integral gain [rad/(N m s)].
        phi : float
            Azimuth offset [rad].
        """
        return (float(np.interp(pitch_rad, self.pitch_rad, self.ki)),
                float(np.interp(pitch_rad, self.pitch_rad, self.azimuth_offset_rad)))


def _rot(phi: float) -> np.ndarray:
    c, s = math.cos(phi), math.sin(phi)
    return np.array([[c, -s], [s, c]])


def tune_coleman_ipc(turbine: linearize.Turbine, *, winds: Any = None,
                     crossover_rad_s: float = 0.2,
                     max_amplitude_deg: float | None = None,
                     weight_range: tuple[float, float] = (0.8, 0.95),
                     power_fraction: float = 1.0) -> ColemanIPCGains:
    """Tune the Coleman-frame integral IPC on the MBC linear models.

    At each wind the static MBC gain G0 (pitch_ref_cos/sin -> flap_moment_cos/sin) is fitted as
    g R(phi); K_I = crossover / g makes both loops integrators crossing over at
    ``crossover_rad_s``, and phi is the azimuth offset. The 2x2 closed loop of the MBC model
    with the integral controller is checked stable and its gain margin reported.

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    winds : array_like, optional
        Region-III winds of the schedule [m/s] (default every 2 m/s above rated).
    crossover_rad_s : float
        Crossover of the integral loops [rad/s].
    max_amplitude_deg : float, optional
        Largest cyclic pitch amplitude [deg]; default :func:`cyclic_amplitude_limit_deg`.
    weight_range : (float, float)
        Power fractions of the fade-in [-].
    power_fraction : float
        Tune on the operating points derated to this fraction [-].

    Returns
    -------
    ColemanIPCGains
        K_I and the azimuth offset over pitch, with the gain margins.
    """
    frac = check_power_fraction(power_fraction)
    if not crossover_rad_s > 0:
        raise ValueError(f"crossover_rad_s must be > 0, got {crossover_rad_s!r}")
    if max_amplitude_deg is None:
        max_amplitude_deg = cyclic_amplitude_limit_deg(turbine)
    if not 0 < max_amplitude_deg <= 20:
        raise ValueError(f"max_amplitude_deg must be in (0, 20] deg, got {max_amplitude_deg!r}")
    wr = check_weight_range(weight_range)
    v = _region3_winds(turbine) if winds is None else np.asarray(winds, float)
    p_rated = frac * turbine.operation.rated_power
    p_w = None if frac == 1.0 else p_rated
    params = linearize.plant_params(turbine)
    rows = []
    for w in v:
        m = _blade_model(turbine, float(w), p_w, params, coordinates="mbc")
        s = m.select(inputs=["pitch_ref_cos", "pitch_ref_sin"],
                     outputs=["flap_moment_cos", "flap_moment_sin"])
        g0 = s.D_u - s.C_z @ np.linalg.solve(s.A, s.B_u)
        a, b = 0.5 * (g0[0, 0] + g0[1, 1]), 0.5 * (g0[1, 0] - g0[0, 1])
        g, phi = math.hypot(a, b), math.atan2(b, a)
        ki = crossover_rad_s / g

        def stable(kk: float) -> bool:
            # x' = A x + B theta, e' = C x + D theta, theta = -kk R(-phi) e
            kc = -kk * _rot(-phi)
            n = s.A.shape[0]
            acl = np.block([[s.A, s.B_u @ kc], [s.C_z, s.D_u @ kc]])
            return bool(np.max(np.linalg.eigvals(acl).real) < -1e-9) and n > 0

        if not stable(ki):
            raise RuntimeError(f"Coleman IPC at {w:g} m/s is unstable at K_I = {ki:g}; lower "
                               f"crossover_rad_s")
        lo, hi = 1.0, 2.0
        while stable(hi * ki) and hi < 1e3:
            lo, hi = hi, 2 * hi
        for _ in range(30):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if stable(mid * ki) else (lo, mid)
        rows.append((m.info["pitch_deg"] * math.pi / 180, ki, phi, float(w), lo))
    rows.sort()
    arr = np.array(rows)
    return ColemanIPCGains(pitch_rad=arr[:, 0], ki=arr[:, 1], azimuth_offset_rad=arr[:, 2],
                           wind_mps=arr[:, 3], gain_margin=arr[:, 4],
                           crossover_rad_s=crossover_rad_s,
                           max_amplitude_rad=math.radians(max_amplitude_deg), weight_range=wr,
                           rated_power=p_rated, power_fraction=frac)


class ColemanIPCController(_PitchAddOn):
    """The design of Coleman-frame integral IPC (tilt and yaw to zero) on top of a collective
    controller, run by its shipped law (the ``coleman-ipc`` kind): the blades' root moments to
    tilt and yaw (M_tilt, M_yaw = 2/3 sum M_i (cos, sin) psi_i, Bossanyi 2003), rotated by the
    scheduled azimuth offset phi, integrated with the scheduled gain K_I (the amplitude
    clamped at ``max_amplitude_rad``: anti-windup), faded in with the power and sent back to
    the blades. The collective part moves towards its command within the rate step first, the
    cyclic within what that leaves: a cyclic pitch at 1P of amplitude A needs A Omega of the
    rate, and on the IEA-15 (2 deg/s, 0.79 rad/s) a 2.5 deg cyclic needs all of it (a gust
    found the collective without rate: 1.44 x rated at 13 m/s).

    Signals: ``ipc_weight``, ``ipc_tilt_moment``, ``ipc_yaw_moment`` [N m] and
    ``ipc_pitch_cos``, ``ipc_pitch_sin`` [rad].

    Parameters
    ----------
    collective : BaselineController
        The collective controller's design.
    gains : ColemanIPCGains
        From :func:`tune_coleman_ipc`.
    """

    kind = "coleman-ipc"

"""The baseline controller: NREL 5-MW style variable-speed, variable-pitch control, tuned by
mpc-wt from its own linear models.

* Generator torque (Jonkman et al. 2009, sec. 7.3): region 1 (no torque), 1.5 (linear from
  cut-in speed), 2 (K omega_g^2 with K from the optimal C_P), 2.5 (straight line to rated
  torque at rated speed with a slip), 3 (constant power, or constant torque), on the filtered
  generator speed; torque rate limited.
* Minimum pitch: on a turbine whose rotor would brake at fine pitch at its minimum speed (the
  trim's region 1.5 pitch, :func:`linearize.trim`; the IEA-15-240-RWT), the PI's lower limit
  is the pitch that maximizes the aerodynamic torque at the steady point of region 1.5's torque
  line, scheduled on the filtered generator speed (:func:`min_pitch_schedule`), as ROSCO's
  minimum-pitch table does on its wind estimate. The NREL 5-MW keeps fine pitch (Jonkman's
  baseline).
* Collective pitch: PI on the filtered generator-speed error, gain-scheduled
  GK(theta) = 1 / (1 + theta / theta_K), with anti-windup (the integral is held so that the
  command stays within the pitch limits), rate-limited command.
* Tuning (report sec. 7.4; Do et al. 2020 eq 8, the method of Wright and Fingersh): the rotor as
  one rigid inertia J (rotor plus generator on the low-speed shaft) with the aerodynamic power
  sensitivity dP/dtheta, linear in pitch: dP/dtheta = (dP/dtheta)_0 (1 + theta / theta_K).
  Placing the closed-loop poles at omega_n, zeta (aerodynamic damping neglected, as the report
  does) gives KP = 2 J Omega_0 zeta omega_n / (N (-dP/dtheta)_0) and
  KI = J Omega_0 omega_n^2 / (N (-dP/dtheta)_0), on the generator speed.
* Down-regulation (Pettas and Cheng 2018, sec. 3.2): ``power_fraction`` f < 1 lowers the rated
  power to f P_r by the generator torque (rated torque f T_r at the same rated speed) and
  re-tunes the PI on the derated operating points (trim to the power reference).
* Active power control (Clemens et al. sec. 3.2, eq 11): a power reference P_ref(t) replaces
  rated power in the constant-power torque law, and the PI gains are interpolated between
  designs at several power fractions (the pitch loop scheduled on the power reference).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Sequence

import numpy as np
from scipy.optimize import brentq

import linearize
from mpc_wt.controllers.base import DesignBase
from mpc_wt.controllers.baseline_law import law_parameters, min_pitch_offset
from mpc_wt.controllers.baseline_law import torque as law_torque

__all__ = ["BaselineGains", "tune_baseline", "tune_baseline_schedule", "BaselineController",
           "LawTorque", "check_power_fraction", "effective_pi_gains", "jonkman_gains",
           "min_pitch_schedule"]

#: Region 1.5 of the torque law runs from the minimum rotor speed to this factor above it on
#: the generator (the NREL 5-MW's 670 to 871 rpm; Jonkman et al. 2009, sec. 7.3).
REGION15_SPAN = 1.3
#: Breakpoints of the minimum-pitch schedule over region 1.5's speeds.
MIN_PITCH_POINTS = 9


def check_power_fraction(value: Any, name: str = "power_fraction") -> float:
    """A derating fraction of rated power: finite and in (0, 1].

    Parameters
    ----------
    value : float
        The fraction [-].
    name : str
        The argument's name, for the message.

    Returns
    -------
    float
        The fraction.

    Raises
    ------
    ValueError
        Naming the argument and the value.
    """
    f = float(value)
    if not (math.isfinite(f) and 0.0 < f <= 1.0):
        raise ValueError(f"{name} must be in (0, 1] (a fraction of rated power), got {value!r}")
    return f


def effective_pi_gains(kp: float, ki: float, theta_k_rad: float, pitch_rad: Any
                       ) -> tuple[np.ndarray, np.ndarray]:
    """Small-signal PI gains of the DISCON-form pitch loop at collective pitch theta.

    :class:`BaselineController` (as Jonkman's DISCON, report sec. 7.4) commands
    theta_k = GK(theta_{k-1}) (kp e_k + ki sum e dt), GK(theta) = 1 / (1 + theta / theta_K),
    with GK taken at the previous command and the integral of the raw speed error. Holding
    theta = GK(theta) X with X = kp e + ki int e makes a small change obey
    d theta (1 + theta GK / theta_K) = GK dX, i.e. d theta = dX / (1 + 2 theta / theta_K) in the
    control band. The loop therefore acts with kp / (1 + 2 theta / theta_K) and
    ki / (1 + 2 theta / theta_K), not with kp GK(theta): 0.62x of it at 0.15 rad for the
    NREL 5-MW. A PI that holds its integral in pitch units and applies its table's gains
    directly (ROSCO) regulates as ours with these gains.

    Parameters
    ----------
    kp, ki : float
        The design's gains at zero pitch [s], [-].
    theta_k_rad : float
        Gain-schedule corner [rad].
    pitch_rad : array_like
        Collective pitch [rad].

    Returns
    -------
    kp_eff, ki_eff : ndarray
        Effective proportional [s] and integral [-] gains at each pitch.
    """
    f = 1.0 / (1.0 + 2.0 * np.asarray(pitch_rad, float) / theta_k_rad)
    return kp * f, ki * f


@dataclass(frozen=True)
class BaselineGains:
    """Gains and set points of the baseline controller (high-speed-shaft quantities).

    Parameters
    ----------
    kp : float
        Proportional gain at zero pitch [rad pitch / (rad/s generator speed)] (= [s]).
    ki : float
        Integral gain at zero pitch [rad pitch / rad generator-speed integral] (= [-]).
    theta_k_rad : float
        Pitch at which the pitch sensitivity doubles (gain-schedule corner) [rad].
    k_opt : float
        Region-2 torque gain [N m / (rad/s)^2].
    rated_gen_speed_rad_s, rated_torque, rated_power : float
        Set points [rad/s, N m, W (electrical)].
    dpdtheta_0 : float
        Aerodynamic power sensitivity extrapolated to zero pitch [W/rad].
    omega_n_rad_s, zeta : float
        Design natural frequency [rad/s] and damping ratio [-].
    power_fraction : float
        Fraction of the turbine's rated power this design was tuned for (1: normal operation;
        < 1: derated, ``rated_power`` and ``rated_torque`` already lowered) [-].
    min_pitch_speeds, min_pitch_offsets : tuple of float
        The minimum-pitch schedule: filtered generator speeds [rad/s] (increasing) and the
        pitch above fine pitch that the PI may not go below there [rad], interpolated, held
        beyond the ends (:func:`min_pitch_schedule`); empty: fine pitch throughout.
    """

    kp: float
    ki: float
    theta_k_rad: float
    k_opt: float
    rated_gen_speed_rad_s: float
    rated_torque: float
    rated_power: float
    dpdtheta_0: float
    omega_n_rad_s: float = 0.6
    zeta: float = 0.7
    power_fraction: float = 1.0
    info: dict[str, Any] = field(default_factory=dict, compare=False)
    min_pitch_speeds: tuple[float, ...] = ()
    min_pitch_offsets: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        sp = tuple(float(x) for x in self.min_pitch_speeds)
        off = tuple(float(x) for x in self.min_pitch_offsets)
        if len(sp) != len(off) or (sp and (len(sp) < 2 or not all(math.isfinite(x) for x in sp + off)
                                           or any(b <= a for a, b in zip(sp, sp[1:]))
                                           or min(off) < 0.0)):
            raise ValueError(f"min_pitch_speeds and min_pitch_offsets must be equally long (0 or "
                             f">= 2 points), the speeds finite and increasing, the offsets finite "
                             f"and >= 0 rad; got {sp!r} and {off!r}")
        object.__setattr__(self, "min_pitch_speeds", sp)
        object.__setattr__(self, "min_pitch_offsets", off)


#: The NREL 5-MW's rated rotor speed, 12.1 rpm [rad/s]: the report's PI design (0.6 rad/s)
#: belongs to it.
NREL5MW_RATED_ROTOR_SPEED = 12.1 * math.pi / 30.0


def default_omega_n(turbine: linearize.Turbine) -> float:
    """The PI pitch loop's default natural frequency for a turbine [rad/s]: the NREL 5-MW
    report's 0.6 rad/s (Jonkman et al. 2009, sec. 7.2) in proportion to the turbine's rated
    rotor speed (exactly 0.6 for the NREL 5-MW).

    A larger rotor turns, and its tower and pitch drives move, more slowly. On the IEA-15
    (7.56 rpm, pitch drives of 2 deg/s against the NREL 5-MW's 8) the report's 0.6 rad/s held
    the pitch at its rate limit 38 % of the time at 13 m/s (class B) and the rotor reached
    1.30 x rated (seeds 1 and 2 tripped the protection); the scaled 0.37 rad/s held it to
    1.08-1.13 x at 11-17 m/s.

    Parameters
    ----------
    turbine : Turbine

    Returns
    -------
    float
        [rad/s]
    """
    return 0.6 * turbine.operation.rated_rotor_speed_rad_s / NREL5MW_RATED_ROTOR_SPEED


def jonkman_gains() -> BaselineGains:
    """Jonkman's baseline controller for the NREL 5-MW as published, its parameter block in
    DISCON.F90 (OpenFAST r-test ``5MW_Baseline/ServoData/DISCON``; Jonkman et al. 2009,
    NREL/TP-500-38060, sec. 7): PC_KP = 0.01882681 s, PC_KI = 0.008068634, PC_KK = 0.1099965
    rad, VS_Rgn2K = 2.332287 N m/(rad/s)^2, PC_RefSpd = 122.9096 rad/s, VS_RtPwr =
    5,296,610 W mechanical (5 MW electrical at 94.4 %), VS_RtTq = 43,093.55 N m; the
    report's dP/dtheta = -25.52e6 W/rad behind the gains. The case's controller when an
    OpenFAST deck runs Jonkman's compiled DLL (which has no input file).

    Returns
    -------
    BaselineGains
    """
    return BaselineGains(kp=0.01882681, ki=0.008068634, theta_k_rad=0.1099965,
                         k_opt=2.332287, rated_gen_speed_rad_s=122.9096, rated_torque=43093.55,
                         rated_power=5.0e6, dpdtheta_0=-25.52e6, omega_n_rad_s=0.6, zeta=0.7,
                         info={"source": "Jonkman et al. 2009, DISCON.F90 parameter block"})


def tune_baseline(turbine: linearize.Turbine, *, omega_n_rad_s: float | None = None,
                  zeta: float = 0.7,
                  wake: str = "frozen", winds: Any = None,
                  inertia: float | None = None, power_fraction: float = 1.0) -> BaselineGains:
    """Tune the baseline from the turbine's own linear models.

    With ``power_fraction`` f < 1 (down-regulation, Pettas and Cheng sec. 3.2) the pitch
    sensitivities come from the operating points trimmed to f P_r at rated rotor speed, and the
    set points become f P_r and f T_r (the same rated speed, so the same tip-speed ratio).

    Parameters
    ----------
    omega_n_rad_s : float, optional
        Closed-loop natural frequency [rad/s] (default :func:`default_omega_n`: the report's
        0.6 rad/s for the NREL 5-MW, scaled by rated rotor speed for others).
    zeta : float
        Closed-loop damping ratio (report: 0.7).
    wake : {"frozen", "quasi-steady"}
        Wake assumption of the pitch sensitivities (the report's are frozen-wake).
    winds : array_like, optional
        Wind speeds for the linear fit of dP/dtheta against pitch; default rated (zero pitch),
        then 12-25 m/s, the range of the report's fit (its Table 7-2 starts at 11.4 m/s).
    inertia : float, optional
        Drivetrain inertia on the low-speed shaft [kg m^2]; default rotor (from the blade data)
        plus N^2 times the generator inertia.
    power_fraction : float
        Derating fraction in (0, 1] [-].


    Returns
    -------
    BaselineGains
        KP, KI, the gain-scheduling angle theta_K, the torque constant and the set points.

    Raises
    ------
    ValueError
        If ``power_fraction`` is outside (0, 1] or a gain parameter is not positive.
    """
    frac = check_power_fraction(power_fraction)
    if omega_n_rad_s is None:
        omega_n_rad_s = default_omega_n(turbine)
    if not (omega_n_rad_s > 0 and zeta > 0):
        raise ValueError(f"omega_n_rad_s and zeta must be > 0, got {omega_n_rad_s!r}, {zeta!r}")
    if winds is None:
        v_rated = linearize.rated_wind_speed(turbine)
        grid = np.arange(12.0, 25.5, 1.0)
        v = np.r_[v_rated + 1e-6, grid[grid > v_rated + 0.1]]    # rated may lie above 12 m/s
    else:
        v = np.asarray(winds, float)
    params = linearize.plant_params(turbine)
    p_w = None if frac == 1.0 else frac * turbine.operation.rated_power
    fam = linearize.linearize_family(turbine, v, wake=wake, params=params, power_W=p_w)
    theta = np.array([m.info["pitch_deg"] for m in fam.models]) * math.pi / 180
    dpdt = np.array([linearize.sensitivities(m)["dP_dpitch_W_per_rad"] for m in fam.models])
    slope, intercept = np.polyfit(theta, dpdt, 1)
    theta_k = intercept / slope
    n = turbine.drivetrain.gearbox_ratio
    j = (params.rotor_inertia + n**2 * turbine.drivetrain.generator_inertia
         if inertia is None else float(inertia))
    om0 = turbine.operation.rated_rotor_speed_rad_s
    kp = 2 * j * om0 * zeta * omega_n_rad_s / (n * -intercept)
    ki = j * om0 * omega_n_rad_s**2 / (n * -intercept)
    lam, cp = linearize.optimal_tsr(turbine, math.degrees(turbine.operation.fine_pitch_rad))
    r = turbine.geometry.tip_radius * math.cos(turbine.geometry.precone_rad)
    rho = turbine.environment.air_density
    k_opt = 0.5 * rho * math.pi * r**5 * cp / lam**3 / n**3
    if turbine.min_pitch is not None:
        trims2 = _region2_trims(turbine, params)
        if _pitches_in_region2(turbine, trims2):
            k_opt = region2_torque_gain(turbine, params=params, trims=trims2)
    sp, off = min_pitch_schedule(turbine, k_opt, params=params, tsr_opt=lam)
    return BaselineGains(kp=kp, ki=ki, theta_k_rad=theta_k, k_opt=k_opt,
                         rated_gen_speed_rad_s=turbine.rated_generator_speed_rad_s,
                         rated_torque=frac * turbine.rated_generator_torque,
                         rated_power=frac * turbine.operation.rated_power, dpdtheta_0=intercept,
                         omega_n_rad_s=omega_n_rad_s, zeta=zeta, power_fraction=frac,
                         info={"wake": wake, "inertia_lss": j, "tsr_opt": lam, "cp_max": cp,
                               "fit_winds": v.tolist()},
                         min_pitch_speeds=sp, min_pitch_offsets=off)


def min_pitch_schedule(turbine: linearize.Turbine, k_opt: float, *,
                       n_points: int = MIN_PITCH_POINTS,
                       params: linearize.PlantParams | None = None,
                       tsr_opt: float | None = None
                       ) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """The baseline's minimum-pitch schedule over region 1.5 of its torque law.

    Only where the trim pitches at cut-in (:func:`linearize.trim`: the rotor at its minimum
    speed and fine pitch would brake, as the IEA-15-240-RWT's at 5 rpm and 3 m/s); otherwise
    empty (fine pitch, Jonkman's NREL 5-MW baseline). Region 1.5's torque line
    T(w) = K w_2^2 (w - w_1) / (w_2 - w_1) between the minimum generator speed w_1 and
    w_2 = 1.3 w_1 (Jonkman et al. 2009, sec. 7.3) holds the rotor where the aerodynamic torque
    equals N T(w). At each of ``n_points`` speeds on the line the schedule's pitch is the one
    that maximizes the aerodynamic torque (:func:`linearize.max_torque_pitch`) at the wind where
    that largest torque equals N T(w); the steady torque scales with V^2 at a given tip-speed
    ratio and pitch, so one table over the tip-speed ratio serves every speed. The last point,
    w_2, is fine pitch, where region 2's optimal tip-speed ratio begins. At the torque-maximizing
    pitch the torque's pitch sensitivity is zero, so the schedule feeds nothing back through
    the speed to first order.

    Parameters
    ----------
    turbine : Turbine
    k_opt : float
        The region-2 torque gain [N m/(rad/s)^2].
    n_points : int
        Breakpoints, >= 3.
    params : PlantParams, optional
        Prebuilt plant parameters of ``turbine``.
    tsr_opt : float, optional
        The optimal tip-speed ratio at fine pitch (default :func:`linearize.optimal_tsr`).

    Returns
    -------
    speeds, offsets : tuple of float
        Filtered generator speeds [rad/s] and the pitch above fine pitch [rad]; both empty
        where the trim keeps fine pitch.
    """
    if int(n_points) < 3:
        raise ValueError(f"n_points must be >= 3, got {n_points!r}")
    if not (math.isfinite(k_opt) and k_opt > 0):
        raise ValueError(f"k_opt must be finite and > 0 N m/(rad/s)^2, got {k_opt!r}")
    op = turbine.operation
    p = params if params is not None else linearize.plant_params(turbine)
    fine = op.fine_pitch_rad
    n = turbine.drivetrain.gearbox_ratio
    if turbine.min_pitch is not None:
        brakes = (linearize.aero_torque(turbine, op.cut_in_wind, op.min_rotor_speed_rad_s, fine,
                                        params=p) * turbine.drivetrain.gearbox_efficiency / n
                  < turbine.generator.min_torque)
        line = _max_torque_line(turbine, k_opt, int(n_points), p, tsr_opt) if brakes else None
        return _table_schedule(turbine, k_opt, int(n_points), p, line)
    if not linearize.trim(turbine, op.cut_in_wind, params=p).pitch_rad > fine + 1e-9:
        return (), ()                               # the trim keeps fine pitch at cut-in
    speeds, offsets = _max_torque_line(turbine, k_opt, int(n_points), p, tsr_opt)
    return tuple(float(x) for x in speeds), tuple(offsets)


def _max_torque_line(turbine: linearize.Turbine, k_opt: float, n_points: int,
                     p: linearize.PlantParams, tsr_opt: float | None
                     ) -> tuple[np.ndarray, list[float]]:
    """The torque-maximizing pitch above fine pitch at ``n_points`` speeds on region 1.5's
    torque line (:func:`min_pitch_schedule`), the last (region 2's start) at fine pitch."""
    op = turbine.operation
    fine = op.fine_pitch_rad
    n = turbine.drivetrain.gearbox_ratio
    w1 = op.min_rotor_speed_rad_s * n
    w2 = REGION15_SPAN * w1
    slope = k_opt * w2**2 / (w2 - w1)
    r = turbine.geometry.tip_radius * math.cos(turbine.geometry.precone_rad)
    q_ref = 0.5 * turbine.environment.air_density * math.pi * r**5
    # the steady aerodynamic torque scales with V^2 at a given tip-speed ratio and pitch, so
    # the largest torque over pitch is Q* = q_ref Omega^2 g(lambda) with one g for all speeds
    om = op.min_rotor_speed_rad_s
    lam_opt = (linearize.optimal_tsr(turbine, math.degrees(fine))[0] if tsr_opt is None
               else float(tsr_opt))
    lam = np.geomspace(0.8 * lam_opt, om * r / (0.5 * op.cut_in_wind), 24)
    best = [linearize.max_torque_pitch(turbine, om * r / x, om, params=p) for x in lam]
    g = np.array([q for _, q in best]) / (q_ref * om**2)
    theta = np.array([b for b, _ in best])
    keep = np.r_[True, np.diff(g) < 0]                 # decreasing in lambda
    lam, g, theta = lam[keep], g[keep], theta[keep]
    speeds = np.linspace(w1, w2, n_points)
    offsets = []
    for w in speeds[:-1]:
        c = n * slope * (w - w1) / (q_ref * (w / n) ** 2)
        x = float(np.interp(c, g[::-1], lam[::-1]))     # clamped at the table's ends
        offsets.append(max(0.0, float(np.interp(x, lam, theta)) - fine))
    offsets.append(0.0)
    return speeds, offsets


def _region2_trims(turbine: linearize.Turbine, params: linearize.PlantParams,
                   n: int = 24) -> list[linearize.OperatingPoint]:
    """The trims in region 2 (maximum-C_P tracking below rated speed) over ``n`` winds from
    cut-in to rated wind."""
    op = turbine.operation
    winds = np.linspace(op.cut_in_wind, linearize.rated_wind_speed(turbine), n + 1)[:-1]
    trims = [linearize.trim(turbine, float(v), params=params) for v in winds]
    return [t for t in trims if t.region == "2"]


def _pitches_in_region2(turbine: linearize.Turbine,
                        trims: Sequence[linearize.OperatingPoint]) -> bool:
    """Whether the turbine's minimum-pitch schedule holds most of its region 2 off fine pitch
    (the IEA-22-280-RWT's; the IEA-15-240-RWT's leaves fine pitch only at region 2's ends, and
    its torque gain stays the fine pitch's optimum)."""
    fine = turbine.operation.fine_pitch_rad
    off = [abs(t.pitch_rad - fine) > 1e-9 for t in trims]
    return sum(off) > len(off) / 2


def region2_torque_gain(turbine: linearize.Turbine, *,
                        params: linearize.PlantParams | None = None,
                        trims: Sequence[linearize.OperatingPoint] | None = None) -> float:
    """The region-2 torque gain K of T = K w_g^2 [N m/(rad/s)^2] that holds the trim's region-2
    schedule in the least-squares sense: for a turbine whose minimum-pitch schedule
    (:attr:`linearize.Turbine.min_pitch`) moves the region-2 pitch with the wind, no single
    pitch's optimal C_P and tip-speed ratio (Jonkman et al. 2009, sec. 7.3, eq of K) describes
    the schedule, so K is fitted to the trims' generator torques against their generator speeds,
    K = sum T w^2 / sum w^4.

    Parameters
    ----------
    turbine : Turbine
    params : PlantParams, optional
    trims : sequence of OperatingPoint, optional
        The region-2 trims to fit (default: 24 winds from cut-in to rated wind).

    Returns
    -------
    float

    Raises
    ------
    ValueError
        If no trim between cut-in and rated wind is in region 2.
    """
    if trims is None:
        p = params if params is not None else linearize.plant_params(turbine)
        trims = _region2_trims(turbine, p)
    if not trims:
        raise ValueError(f"{turbine.name}: no trim between cut-in and rated wind is in region 2; "
                         f"no region-2 torque gain to fit")
    w = np.array([t.gen_speed_rad_s for t in trims])
    tq = np.array([t.gen_torque for t in trims])
    return float(np.sum(tq * w**2) / np.sum(w**4))


def _table_schedule(turbine: linearize.Turbine, k_opt: float, n_points: int,
                    p: linearize.PlantParams, line: tuple[np.ndarray, list[float]] | None
                    ) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """The baseline's minimum pitch over its filtered generator speed from the turbine's
    minimum-pitch table: on region 1.5's torque line (as :func:`min_pitch_schedule`) the
    table's pitch at the wind where the rotor at that speed and pitch balances the line's torque;
    above it the region-2 trims' pitch at their generator speeds, up to the last trim below
    rated speed (at rated speed the pitch loop takes over). Where the rotor would brake at
    fine pitch (``line``: :func:`_max_torque_line`), the line's pitch is the larger of the
    table's and the torque-maximizing one, as the trim's."""
    op, n = turbine.operation, turbine.drivetrain.gearbox_ratio
    fine, egb = op.fine_pitch_rad, turbine.drivetrain.gearbox_efficiency
    w1 = op.min_rotor_speed_rad_s * n
    w2 = REGION15_SPAN * w1
    slope = k_opt * w2**2 / (w2 - w1)
    speeds, offsets = [], []
    v_hi = linearize.rated_wind_speed(turbine)
    for w in np.linspace(w1, w2, n_points)[1:]:
        need = n * slope * (w - w1) / egb                       # low-speed shaft torque

        def surplus(v: float, w: float = w, need: float = need) -> float:
            b = linearize.region2_pitch(turbine, v)
            return linearize.aero_torque(turbine, v, w / n, b, params=p) - need

        v = brentq(surplus, 0.3 * op.cut_in_wind, v_hi, xtol=1e-6)
        speeds.append(float(w))
        offsets.append(max(0.0, linearize.region2_pitch(turbine, v) - fine))
    for t in _region2_trims(turbine, p, n=48):
        if t.gen_speed_rad_s > speeds[-1] * (1 + 1e-6) and len(speeds) < MIN_PITCH_TABLE_MAX:
            speeds.append(t.gen_speed_rad_s)
            offsets.append(max(0.0, t.pitch_rad - fine))
    speeds.insert(0, float(w1))
    offsets.insert(0, offsets[0])
    if line is not None:
        offsets[:n_points] = [max(a, b) for a, b in zip(offsets[:n_points], line[1])]
    while len(speeds) > 2 and offsets[-1] == offsets[-2] == 0.0:   # fine pitch held beyond
        speeds.pop()
        offsets.pop()
    return tuple(speeds), tuple(offsets)


#: the most points the exported law's minimum-pitch schedule holds (``MW_MIN_PITCH_MAX``)
MIN_PITCH_TABLE_MAX = 64


def tune_baseline_schedule(turbine: linearize.Turbine,
                           fractions: Sequence[float] = (1.0, 0.75, 0.5, 0.25),
                           **kwargs: Any) -> tuple[BaselineGains, ...]:
    """PI designs at several power fractions, for a pitch loop scheduled on the power reference
    (active power control). ``kwargs`` go to :func:`tune_baseline`; sorted by fraction.

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    fractions : sequence of float
        Power fractions in (0, 1].
    **kwargs
        Passed to :func:`tune_baseline`.

    Returns
    -------
    tuple of BaselineGains
        One design per fraction, by increasing fraction.
    """
    fr = sorted({check_power_fraction(f, "fractions") for f in fractions})
    if len(fr) < 1:
        raise ValueError("fractions must hold at least one power fraction")
    return tuple(tune_baseline(turbine, power_fraction=f, **kwargs) for f in fr)


class BaselineController(DesignBase):
    """The NREL 5-MW style baseline's design (torque law + gain-scheduled PI pitch): its gains,
    the torque law's breakpoints, limits and period, as its compiled law reads them. The law
    runs as it is shipped (:func:`mpc_wt.run.law_controller`, ``run_controller``): a
    first-order low-pass on the generator speed, the PI on the filtered speed error with
    GK(theta) at the previous command, anti-windup and a bumpless start at the measured pitch,
    the pitch-rate limit, the torque law of regions 1.5, 2, 2.5 and 3 with its rate limit.

    Derated gains (``gains.power_fraction`` < 1) cap the torque law at the derated rated torque
    at rated speed. Region 2.5 is the NREL line from the synchronous speed to (rated speed,
    rated torque); when K omega^2 meets no such line below rated speed (deep derating), the
    region-2 torque is capped at the rated torque instead (a constant-torque region 2.5 in which
    the rotor speeds up to rated, as in Pettas and Cheng fig. 5).

    Active power control (the ``apc`` kind): ``power_reference(t)`` [W] replaces rated power in
    region 3, and with ``gain_schedule`` (designs at several power fractions,
    :func:`tune_baseline_schedule`) the effective gains KP GK(theta), KI GK(theta) of the designs
    are interpolated on P_ref / P_r (integral kept in pitch units, so a gain change moves no
    command), and each change of the reference moves the pitch by dP_ref / (eta dP/dtheta),
    dP/dtheta from the same designs at the present pitch (the pitch loop then only corrects).
    A reference outside (0, rated power] stops the run naming it; while the rotor is below
    rated speed at fine pitch the wind cannot give the reference (signal ``apc_saturated`` = 1).

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    gains : BaselineGains, optional
        The design (default :func:`tune_baseline`).
    dt : float
        Controller period [s] (default the plant's 1/80 s).
    region3 : {"constant_power", "constant_torque"}
        Torque law above rated.
    filter_hz : float
        Corner of the generator-speed low-pass [Hz].
    slip_pct : float
        Region 2.5 width, in percent of rated generator speed.
    power_reference : PowerReference, optional
        t [s] -> power reference [W] (active power control,
        :class:`mpc_wt.controllers.apc.PowerReference`).
    gain_schedule : sequence of BaselineGains, optional
        Designs at several power fractions, interpolated on the reference.
    """

    kind = "baseline"

    def __init__(self, turbine: linearize.Turbine, gains: BaselineGains | None = None, *,
                 dt: float = 1.0 / 80.0, region3: str = "constant_power",
                 filter_hz: float = 0.25, slip_pct: float = 10.0,
                 power_reference: Callable[[float], float] | None = None,
                 gain_schedule: Sequence[BaselineGains] | None = None) -> None:
        if region3 not in ("constant_power", "constant_torque"):
            raise ValueError(f"region3 must be 'constant_power' or 'constant_torque', got "
                             f"{region3!r}")
        if not dt > 0:
            raise ValueError(f"dt must be > 0 s, got {dt!r}")
        if not 0 < filter_hz < 0.5 / dt:
            raise ValueError(f"filter_hz must be in (0, Nyquist = {0.5 / dt:g} Hz) at dt = "
                             f"{dt:g} s, got {filter_hz!r}")
        self.turbine = turbine
        self.power_reference = power_reference
        sched = sorted(gain_schedule or (), key=lambda g: g.power_fraction)
        if gain_schedule is not None and not sched:
            raise ValueError("gain_schedule must hold at least one BaselineGains")
        #: the designs the gains are scheduled over (active power control), by fraction
        self.gain_schedule: tuple[BaselineGains, ...] = tuple(sched)
        self.gains = gains or (sched[-1] if sched else tune_baseline(turbine))
        if power_reference is not None or sched:
            self.kind = "apc"
        self.dt = float(dt)
        self.region3 = region3
        self.wc = 2 * math.pi * filter_hz
        #: the speed low-pass's pole at dt [-]
        self.filter_pole = math.exp(-self.wc * self.dt)
        self.pitch_min = turbine.operation.fine_pitch_rad
        self.pitch_max = turbine.pitch_actuator.max_pitch_rad
        self.rate = turbine.pitch_actuator.max_rate_rad_s
        self.tq_rate = turbine.generator.max_torque_rate
        self.tq_max = turbine.generator.max_torque
        #: the largest below-rated trim pitch [rad], set by :meth:`largest_region2_pitch`
        self.below_rated_pitch: float | None = None
        self._breakpoints(slip_pct)
        self._par = law_parameters(self)

    def _breakpoints(self, slip_pct: float) -> None:
        """The torque law's breakpoints (report sec. 7.3, DISCON): rated speed 99 % of the set
        point, region 1.5 from the minimum rotor speed to 30 % above it on the generator (the
        NREL 5-MW's 670 and 871 rpm), and the minimum-pitch schedule."""
        g, turbine = self.gains, self.turbine
        n = turbine.drivetrain.gearbox_ratio
        self.w_cutin = turbine.operation.min_rotor_speed_rad_s * n
        self.w_rgn2 = REGION15_SPAN * self.w_cutin
        self.w_rated = 0.99 * g.rated_gen_speed_rad_s
        self.w_sync = self.w_rated / (1.0 + 0.01 * slip_pct)
        self.slope25 = g.rated_power / turbine.drivetrain.generator_efficiency / self.w_rated \
            / (self.w_rated - self.w_sync)
        self.slope15 = g.k_opt * self.w_rgn2**2 / (self.w_rgn2 - self.w_cutin)
        # region 2 -> 2.5 where K w^2 meets the 2.5 line (DISCON's VS_TrGnSp), so the torque is
        # continuous; without an intersection the line starts at the synchronous speed
        disc = self.slope25**2 - 4.0 * g.k_opt * self.slope25 * self.w_sync
        self.w_trans = ((self.slope25 - math.sqrt(disc)) / (2.0 * g.k_opt) if disc >= 0
                        else math.inf)
        # no crossing below rated speed: region 2 runs up to rated, capped at rated torque
        self.tq_cap = g.rated_power / turbine.drivetrain.generator_efficiency / self.w_rated
        if self.w_trans > self.w_rated:
            self.w_trans = self.w_rated
        #: the minimum-pitch schedule: filtered generator speeds [rad/s] and pitch above fine
        #: pitch [rad] (the design's; two zero offsets over region 1.5 where it has none)
        self.min_pitch_speeds: tuple[float, ...] = (g.min_pitch_speeds or
                                                    (self.w_cutin, self.w_rgn2))
        self.min_pitch_offsets: tuple[float, ...] = g.min_pitch_offsets or (0.0, 0.0)

    def min_pitch(self, w_filt: float) -> float:
        """The PI's lower pitch limit at a filtered generator speed: fine pitch plus the
        minimum-pitch schedule's offset (:func:`min_pitch_schedule`) [rad].

        Parameters
        ----------
        w_filt : float
            Filtered generator speed [rad/s].

        Returns
        -------
        float
            [rad]
        """
        return self.pitch_min + float(min_pitch_offset(float(w_filt), self._par))

    def largest_region2_pitch(self) -> float:
        """:func:`below_rated_pitch` of this law's turbine [rad], one trim sweep per law.

        Returns
        -------
        float
            [rad] above fine pitch, >= 0.
        """
        if self.below_rated_pitch is None:
            self.below_rated_pitch = below_rated_pitch(self.turbine)
        return self.below_rated_pitch

    def torque(self, w: float, pitch: float, power: float | None = None) -> float:
        """The torque law: generator torque demand for a filtered generator speed and the
        collective pitch; ``power`` replaces rated power in region 3 (active power control)
        [W]. The steady curves of a design (:mod:`mpc_wt.controllers.derating`) and other
        designs' torque schedules (:class:`LawTorque`) read it.

        Parameters
        ----------
        w : float
            Filtered generator speed [rad/s].
        pitch : float
            Collective pitch [rad].
        power : float, optional
            Power reference [W] (default rated).

        Returns
        -------
        float
            Generator torque demand [N m].
        """
        p3 = self.gains.rated_power if power is None else power
        return float(law_torque(float(w), float(pitch), float(p3), self._par))


class LawTorque:
    """The design of the baseline's torque schedule as another controller's generator torque
    (the region-II law of the scheduled LQR-PIO, MPC and TS, which their shipped C laws run):
    the generator speed low-passed at the law's filter corner (pole ``_a`` at the calling
    controller's period), then :meth:`BaselineController.torque`, within the generator's limits.

    The schedule tells region 3 from a pitch 1 deg above fine (the NREL 5-MW controller's
    switch). A controller that tracks the trim holds a turbine with a minimum-pitch schedule
    (the IEA-15: 3.8 deg at 3 m/s, 1.7 deg at 5.9 m/s) above that at its minimum rotor speed,
    where the schedule would then ask for rated power and stall the rotor; below region 2's
    speed the pitch is therefore counted from the largest below-rated trim pitch
    (:func:`below_rated_pitch`; 0 for the NREL 5-MW, where nothing changes), and above it from
    the baseline's minimum-pitch schedule at the filtered speed (0 where that schedule is fine
    pitch; the IEA-22-280-RWT's region 2 runs 3-5 deg above its fine pitch of -4 deg).

    Parameters
    ----------
    law : BaselineController
        The schedule (its gains and filter corner).
    dt : float
        The calling controller's period [s].
    """

    def __init__(self, law: BaselineController, dt: float) -> None:
        self.law = law
        self._a = math.exp(-law.wc * float(dt))
        g = law.turbine.generator
        self._lo, self._hi = g.min_torque, g.max_torque
        self._offset = law.largest_region2_pitch()
        self._has_min_pitch = any(o > 0.0 for o in law.min_pitch_offsets)


def below_rated_pitch(turbine: linearize.Turbine, n: int = 6) -> float:
    """The largest trim pitch between cut-in and rated wind (``n`` winds up to 97 % of rated)
    [rad]: a minimum-pitch schedule's largest pitch, 0 for a turbine at fine pitch there.

    Parameters
    ----------
    turbine : Turbine
    n : int
        Winds trimmed.

    Returns
    -------
    float
        [rad], >= 0.
    """
    vr = linearize.rated_wind_speed(turbine)
    winds = np.linspace(turbine.operation.cut_in_wind, 0.97 * vr, n)
    pitch = [float(np.mean(linearize.trim(turbine, float(v)).u[:3])) for v in winds]
    return max(0.0, max(pitch) - turbine.operation.fine_pitch_rad)

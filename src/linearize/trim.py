"""Steady operating points against mean wind speed (trim).

Schedule (Madsen et al. 2012, sec. II-D: "maximizing the power output at low wind speeds ...
limiting the power to the rated level"; Jonkman et al. 2009, sec. 7):

* region 1.5: rotor speed held at its minimum, fine pitch. If at cut-in the rotor at its
  minimum speed and fine pitch would brake (aerodynamic torque below the generator's minimum,
  e.g. the IEA-15-240-RWT at 3 m/s and 5 rpm, tip-speed ratio 21), the whole of region 1.5
  takes the pitch (>= fine) that maximizes the aerodynamic torque at that speed, as WISDEM's
  schedule and ROSCO's minimum-pitch table do (or the turbine's own minimum-pitch schedule where
  that is higher); deciding once per turbine keeps the schedule continuous. The NREL 5-MW
  (6.9 rpm) stays at fine pitch, as Jonkman's baseline;
* region 2: maximum C_P tracking, omega = lambda_opt V / R, fine pitch;
* region 2.5: rotor speed held at rated, fine pitch, power still below the cap;
* region 3: power held at the cap (rated, or a power reference below rated) by pitching to
  feather at the scheduled rotor speed.

A turbine with a minimum-pitch schedule over wind (:attr:`Turbine.min_pitch`, ROSCO's
``PS_BldPitchMin``) pitches at least that schedule everywhere (:func:`region2_pitch`, never
below fine pitch): in regions 1.5 to 2.5 at the schedule's pitch, tracking the tip-speed ratio
of maximum C_P at that pitch, or the fine pitch's where that is larger (as the deck's controller
keeps its optimal tip-speed ratio on the estimated wind whatever the pitch's floor), and in
region 3 pitching up from it. The IEA-22-280-RWT, whose fine pitch of
-4 deg reaches rated power below rated speed, trims only on its schedule.

The structural equilibrium (tower deflections, shaft torsion, blade flap) follows exactly from
the rotor loads, so that the trim point is an equilibrium of :func:`linearize.plant_rhs` (with
tilt, gravity or shear on, of its azimuth average).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from linearize._typing import FloatArray
from linearize.errors import TrimError
from linearize.params import STATE_NAMES, PlantConfig, PlantParams, n_x, plant_params
from linearize.steady import optimal_tsr, rotor_average
from linearize.turbine import Turbine
from linearize.validate import check_finite_scalar

__all__ = ["TrimError", "OperatingPoint", "trim", "operating_point", "operating_schedule",
           "rated_wind_speed", "max_torque_pitch", "region2_pitch", "aero_torque"]


@dataclass(frozen=True)
class OperatingPoint:
    """A trimmed steady operating point.

    Parameters
    ----------
    wind_mps : float
        Hub-height mean wind speed [m/s].
    region : str
        "1.5", "2", "2.5" or "3" (:func:`trim`), or "given" (:func:`operating_point`).
    pitch_rad : float
        Collective pitch [rad].
    rotor_speed_rad_s, gen_speed_rad_s : float
        [rad/s].
    gen_torque : float
        Generator torque (high-speed shaft) [N m].
    power : float
        Electrical power [W].
    aero_power : float
        Rotor aerodynamic power, torque times rotor speed [W].
    aero_torque : float
        [N m].
    thrust : float
        Rotor thrust along the shaft [N].
    tsr : float
        Tip-speed ratio on the projected radius [-].
    cp, ct : float
        Power and thrust coefficients [-].
    x : (n_x,) ndarray
        Equilibrium state (:data:`linearize.STATE_NAMES`).
    u : (n_u,) ndarray
        Equilibrium inputs (:data:`linearize.INPUT_NAMES`).
    power_reference : float or None
        The power cap the point was trimmed to, if a reference below rated was asked [W].
    shear_exponent : float
        Shear of the steady wind the point was trimmed in [-].
    """

    wind_mps: float
    region: str
    pitch_rad: float
    rotor_speed_rad_s: float
    gen_speed_rad_s: float
    gen_torque: float
    power: float
    aero_power: float
    aero_torque: float
    thrust: float
    tsr: float
    cp: float
    ct: float
    x: FloatArray = field(repr=False)
    u: FloatArray = field(repr=False)
    power_reference: float | None = None
    shear_exponent: float = 0.0

    def __post_init__(self) -> None:
        for name in ("x", "u"):
            a = np.array(getattr(self, name), dtype=float)
            a.flags.writeable = False
            object.__setattr__(self, name, a)

    @property
    def pitch_deg(self) -> float:
        """Collective pitch [deg] (I/O convenience)."""
        return math.degrees(self.pitch_rad)

    @property
    def rotor_speed_rpm(self) -> float:
        """Rotor speed [rpm] (I/O convenience)."""
        return self.rotor_speed_rad_s * 30.0 / math.pi

    def state(self, name: str) -> float:
        """One equilibrium state by name.

        Parameters
        ----------
        name : str
            A name of :data:`STATE_NAMES`.

        Returns
        -------
        float
            Its equilibrium value (SI).
        """
        return float(self.x[STATE_NAMES.index(name)])

    def as_dict(self) -> dict[str, Any]:
        """Plain dict with unit-suffixed keys, for JSON and tables.

        Returns
        -------
        dict
            Wind, region, pitch, rotor and generator speed, torques, powers, thrust, TSR,
            C_P, C_T and the structure's deflections, each key with its unit.
        """
        return {
            "wind_mps": self.wind_mps, "region": self.region, "pitch_deg": self.pitch_deg,
            "rotor_speed_rpm": self.rotor_speed_rpm,
            "gen_speed_rpm": self.gen_speed_rad_s * 30.0 / math.pi,
            "gen_torque_Nm": self.gen_torque, "power_W": self.power,
            "aero_power_W": self.aero_power, "aero_torque_Nm": self.aero_torque,
            "thrust_N": self.thrust, "tsr": self.tsr, "cp": self.cp, "ct": self.ct,
            "tower_fa_deflection_m": self.state("tower_fa_displacement"),
            "tower_ss_deflection_m": self.state("tower_ss_displacement"),
            "shaft_torsion_rad": self.state("shaft_torsion"),
            "flap_deflection_m": self.state("flap_1"),
        }


_TSR_CACHE: dict[tuple[int, PlantConfig, float, float], tuple[Turbine, float]] = {}


def _tsr_opt(params: PlantParams, shear: float, pitch: float | None = None) -> float:
    """The tip-speed ratio of maximum C_P at a pitch [rad] (default: fine pitch)."""
    t = params.turbine
    b = t.operation.fine_pitch_rad if pitch is None else float(pitch)
    key = (id(t), params.config, shear, b)
    hit = _TSR_CACHE.get(key)
    if hit is not None and hit[0] is t:
        return hit[1]
    lam, _ = optimal_tsr(t, math.degrees(b), params.config.aero,
                         shear_exponent=shear, integration=params.config.integration)
    _TSR_CACHE[key] = (t, lam)
    return lam


def region2_pitch(turbine: Turbine, wind_mps: float) -> float:
    """The least pitch [rad] the turbine operates at in a mean wind: its minimum-pitch schedule
    there (:attr:`Turbine.min_pitch`), never below fine pitch; the fine pitch for a turbine
    without a schedule. :func:`trim` holds it below rated and pitches up from it above.

    Parameters
    ----------
    turbine : Turbine
    wind_mps : float
        Mean hub-height wind [m/s].

    Returns
    -------
    float
    """
    fine = turbine.operation.fine_pitch_rad
    table = turbine.min_pitch
    return fine if table is None else max(fine, table.at(float(wind_mps)))


def _region2(p: PlantParams, v: float, shear: float) -> tuple[float, float, float]:
    """Rotor speed, pitch and unclamped maximum-C_P rotor speed [rad/s, rad, rad/s] of the
    below-rated schedule at wind ``v``: the region-2 pitch and the optimal tip-speed ratio at
    it, or at fine pitch where that is larger (a minimum-pitch schedule sheds thrust, it does
    not slow the rotor: ROSCO keeps its ``VS_TSRopt`` whatever the pitch's floor), the speed
    clamped to the operating range."""
    t = p.turbine
    op = t.operation
    pitch = region2_pitch(t, v)
    cone = t.geometry.precone_rad if p.config.aero.cone else 0.0
    lam = _tsr_opt(p, shear)
    if pitch != op.fine_pitch_rad:      # never slower than the fine pitch's optimum
        lam = max(lam, _tsr_opt(p, shear, pitch))
    w_opt = lam * v / (t.geometry.tip_radius * math.cos(cone))
    return min(max(w_opt, op.min_rotor_speed_rad_s), op.rated_rotor_speed_rad_s), pitch, w_opt


def _state(params: PlantParams, omega: float, pitch: float) -> FloatArray:
    x = np.zeros(n_x)
    x[2] = omega
    x[3] = omega * params.turbine.drivetrain.gearbox_ratio
    x[5:8] = pitch
    return x


def _aero(params: PlantParams, v: float, omega: float, pitch: float,
          shear: float) -> tuple[float, float]:
    """Azimuth-averaged aerodynamic torque [N m] and thrust [N]; with ``deflected_blades`` at the
    structure's static deflection under those loads (found by :func:`_displacement_step` with
    the generator balancing the rotor: the loads then depend on the deflection, a fixed point
    that converges in a few steps, the blades' aeroelastic stiffness being small)."""
    x = _state(params, omega, pitch)
    u = np.array([pitch, pitch, pitch, 0.0])
    _, z = rotor_average(params, x, u, v, shear)
    if _deflection_matters(params):
        ngear = params.turbine.drivetrain.gearbox_ratio
        for _ in range(_DEFLECTION_STEPS):
            u[3] = params.turbine.drivetrain.gearbox_efficiency * z[22] / ngear
            if params.dof("drivetrain"):
                x[4] = z[22] / params.pack.k_shaft
            x, _, z = _displacement_step(params, x, u, v, omega, shear)
    return float(z[22]), float(z[23])


#: fixed-point steps of the aerodynamic loads at the blades' own deflection
_DEFLECTION_STEPS = 8


def _source(turbine: Turbine, quantity: str) -> str:
    """`` (file:line key)`` of a quantity the turbine's loader read, or "" (YAML turbines)."""
    src = turbine.report.source(quantity)
    return f" ({src})" if src else ""


def _torque_limit_message(turbine: Turbine, v: float, omega: float, pitch: float,
                          tg: float) -> str:
    """Why a trim needs more generator torque than the turbine allows, where the limit and
    the region's pitch came from, and what would trim it."""
    op = turbine.operation
    rpm = 30.0 / math.pi
    msg = (f"trim at {v:g} m/s needs generator torque {tg:g} N m, above the limit "
           f"{turbine.generator.max_torque:g} N m{_source(turbine, 'maximum generator torque')}")
    if omega < op.rated_rotor_speed_rad_s * (1 - 1e-9):
        msg += (f": on the optimal tip-speed ratio of its fine pitch "
                f"{math.degrees(op.fine_pitch_rad):.3g} deg{_source(turbine, 'fine pitch')} "
                f"the rotor runs at {omega * rpm:.4g} rpm (pitch {math.degrees(pitch):.3g} deg), "
                f"below its rated speed {op.rated_rotor_speed_rad_s * rpm:.4g} rpm, when rated "
                f"power comes; a region-2 pitch whose optimal tip-speed ratio reaches rated "
                f"speed first, or a torque limit of at least {tg:.6g} N m, trims it")
    else:
        msg += f"; a torque limit of at least {tg:.6g} N m trims it"
    return msg


def _deflection_matters(params: PlantParams) -> bool:
    """Whether the loads depend on the blades' deflection (``deflected_blades`` with a blade
    DOF)."""
    return bool(params.config.deflected_blades
                and (params.dof("blade_flap") or params.dof("blade_edge")))


def _best_pitch(p: PlantParams, v: float, omega: float, fine: float, shear: float) -> float:
    """Pitch in [fine, fine + 30 deg] that maximizes the aerodynamic torque at ``omega``."""
    res = minimize_scalar(lambda b: -_aero(p, v, omega, b, shear)[0],
                          bounds=(fine, fine + math.radians(30.0)), method="bounded",
                          options={"xatol": 1e-9})
    return float(res.x)


def _wind_and_speed(wind_mps: Any, rotor_speed_rad_s: Any) -> tuple[float, float]:
    """A steady wind and rotor speed, both finite and > 0 (else ValueError naming them)."""
    v = check_finite_scalar("wind_mps", wind_mps)
    om = check_finite_scalar("rotor_speed_rad_s", rotor_speed_rad_s)
    if not (v > 0 and om > 0):
        raise ValueError(f"wind_mps and rotor_speed_rad_s must be > 0, got {v!r} m/s and "
                         f"{om!r} rad/s")
    return v, om


def max_torque_pitch(turbine: Turbine, wind_mps: float, rotor_speed_rad_s: float, *,
                     config: PlantConfig | None = None, shear_exponent: float = 0.0,
                     params: PlantParams | None = None) -> tuple[float, float]:
    """The pitch between fine pitch and 30 deg above it that maximizes the rigid rotor's
    azimuth-averaged aerodynamic torque at a steady wind and rotor speed, and that torque: the
    pitch :func:`trim` holds in region 1.5 of a turbine whose rotor would brake at fine pitch,
    at any rotor speed (a minimum-pitch schedule's point).

    Parameters
    ----------
    turbine : Turbine
    wind_mps : float
        Hub-height wind [m/s], > 0.
    rotor_speed_rad_s : float
        Rotor speed [rad/s], > 0.
    config, shear_exponent, params
        As :func:`trim`.

    Returns
    -------
    pitch_rad, aero_torque : float
        [rad], [N m] (low-speed shaft).
    """
    v, om = _wind_and_speed(wind_mps, rotor_speed_rad_s)
    p = params if params is not None else plant_params(turbine, config)
    fine = turbine.operation.fine_pitch_rad
    b = _best_pitch(p, v, om, fine, float(shear_exponent))
    return b, _aero(p, v, om, b, float(shear_exponent))[0]


def aero_torque(turbine: Turbine, wind_mps: float, rotor_speed_rad_s: float,
                pitch_rad: float, *, config: PlantConfig | None = None,
                shear_exponent: float = 0.0, params: PlantParams | None = None) -> float:
    """The rotor's azimuth-averaged aerodynamic torque [N m] (low-speed shaft) at a steady
    wind, rotor speed and collective pitch, the structure at its static deflection (as
    :func:`trim` computes it), whatever torque the generator could hold.

    Parameters
    ----------
    turbine : Turbine
    wind_mps : float
        Hub-height wind [m/s], > 0.
    rotor_speed_rad_s : float
        Rotor speed [rad/s], > 0.
    pitch_rad : float
        Collective pitch [rad].
    config, shear_exponent, params
        As :func:`trim`.

    Returns
    -------
    float
    """
    v, om = _wind_and_speed(wind_mps, rotor_speed_rad_s)
    b = check_finite_scalar("pitch_rad", pitch_rad)
    p = params if params is not None else plant_params(turbine, config)
    return _aero(p, v, om, b, float(shear_exponent))[0]


def trim(turbine: Turbine, wind_mps: float, power_W: float | None = None, *,
         config: PlantConfig | None = None, shear_exponent: float = 0.0,
         params: PlantParams | None = None) -> OperatingPoint:
    """Trim the plant at a mean wind speed.

    Parameters
    ----------
    turbine : Turbine
    wind_mps : float
        Hub-height wind speed [m/s], within cut-in..cut-out.
    power_W : float, optional
        Electrical power reference below rated [W] (down-regulation, active power control).
        ``None`` trims to the normal schedule with rated power as the cap.
    config : PlantConfig, optional
        Degrees of freedom and aerodynamic options (default: all on).
    shear_exponent : float
        Power-law shear of the steady wind [-] (default 0: uniform).
    params : PlantParams, optional
        Prebuilt parameters (skips :func:`plant_params`); must match ``turbine``.

    Returns
    -------
    OperatingPoint

    Raises
    ------
    TrimError
        If the wind is outside cut-in..cut-out, the power reference is above rated or above the
        power available in this wind, or the generator torque would exceed its limit.
    ValueError
        If an argument is not finite.
    """
    v = check_finite_scalar("wind_mps", wind_mps)
    op = turbine.operation
    if not op.cut_in_wind <= v <= op.cut_out_wind:
        raise TrimError(f"wind_mps = {v:g} m/s is outside the operating range cut-in.."
                        f"cut-out = {op.cut_in_wind:g}..{op.cut_out_wind:g} m/s")
    if power_W is not None:
        pref = check_finite_scalar("power_W", power_W)
        if not 0.0 < pref <= op.rated_power * (1 + 1e-12):
            raise TrimError(f"power_W = {pref:g} W must be in (0, rated power "
                            f"{op.rated_power:g} W]")
    else:
        pref = None
    cap = op.rated_power if pref is None else pref
    p = params if params is not None else plant_params(turbine, config)
    shear = float(shear_exponent)
    dt = turbine.drivetrain
    ngear = dt.gearbox_ratio
    eta = dt.generator_efficiency * dt.gearbox_efficiency
    # the generator torque that holds an aerodynamic torque q: eta_gbx q / N (the gearbox's
    # loss on the high-speed side, :mod:`linearize.kernel`)
    egb = dt.gearbox_efficiency
    cone = turbine.geometry.precone_rad if p.config.aero.cone else 0.0
    rproj = turbine.geometry.tip_radius * math.cos(cone)
    if op.fine_pitch_rad < turbine.pitch_actuator.min_pitch_rad - 1e-12:
        raise TrimError(f"the fine pitch {math.degrees(op.fine_pitch_rad):.4g} deg"
                        f"{_source(turbine, 'fine pitch')} is below the pitch actuator's "
                        f"minimum {math.degrees(turbine.pitch_actuator.min_pitch_rad):.4g} deg"
                        f"{_source(turbine, 'minimum pitch')}: the region-2 pitch must be one "
                        f"the actuator can reach")

    omega, fine, w_opt = _region2(p, v, shear)
    q_fine, _ = _aero(p, v, omega, fine, shear)
    f0 = op.fine_pitch_rad
    if (omega <= op.min_rotor_speed_rad_s * (1 + 1e-12) and w_opt < omega
            and _aero(p, op.cut_in_wind, op.min_rotor_speed_rad_s, f0, shear)[0] * egb / ngear
            < turbine.generator.min_torque):
        # the torque-maximizing pitch, or the minimum-pitch schedule's where that is above it
        fine = max(fine, _best_pitch(p, v, omega, f0, shear))
        q_fine, _ = _aero(p, v, omega, fine, shear)
        if egb * q_fine / ngear < turbine.generator.min_torque:
            raise TrimError(
                f"at {v:g} m/s the rotor cannot run at its minimum speed "
                f"{omega * 30 / math.pi:.3g} rpm: the aerodynamic torque is at most "
                f"{q_fine:.4g} N m (pitch {math.degrees(fine):.2f} deg), below the generator's "
                f"minimum {turbine.generator.min_torque * ngear / egb:.4g} N m (low-speed shaft); "
                f"raise cut-in above {v:g} m/s")
    if egb * q_fine / ngear < turbine.generator.min_torque - 1e-9:
        raise TrimError(
            f"at {v:g} m/s the rotor at {omega * 30 / math.pi:.4g} rpm and the minimum-pitch "
            f"schedule's {math.degrees(fine):.3g} deg{_source(turbine, 'minimum-pitch schedule')} "
            f"makes an aerodynamic torque of {q_fine:.4g} N m, below the generator's minimum "
            f"{turbine.generator.min_torque * ngear / egb:.4g} N m (low-speed shaft)")
    p_fine = eta * q_fine * omega
    if p_fine <= cap * (1 + 1e-12):
        if pref is not None and p_fine < pref * (1 - 1e-9):
            raise TrimError(f"power_W = {pref:g} W is above the power available at "
                            f"{v:g} m/s ({p_fine:g} W)")
        pitch = fine
        if omega <= op.min_rotor_speed_rad_s * (1 + 1e-12) and w_opt < omega:
            region = "1.5"
        elif omega >= op.rated_rotor_speed_rad_s * (1 - 1e-12) and w_opt > omega:
            region = "2.5"
        else:
            region = "2"
        q_target = q_fine
    else:
        region = "3"
        q_target = cap / (eta * omega)

        def resid(b: float) -> float:
            return _aero(p, v, omega, b, shear)[0] - q_target

        hi = turbine.pitch_actuator.max_pitch_rad
        if resid(hi) > 0:
            raise TrimError(f"cannot shed enough power at {v:g} m/s even at maximum pitch")
        pitch = brentq(resid, fine, hi, xtol=1e-14, rtol=4 * np.finfo(float).eps, maxiter=200)
    tg = egb * q_target / ngear
    if tg > turbine.generator.max_torque * (1 + 1e-9):
        raise TrimError(_torque_limit_message(turbine, v, omega, pitch, tg))
    x, u, z = _equilibrium(p, v, omega, pitch, tg, shear)
    q, thrust = float(z[22]), float(z[23])
    area = math.pi * rproj**2
    return OperatingPoint(
        wind_mps=v, region=region, pitch_rad=float(pitch), rotor_speed_rad_s=omega,
        gen_speed_rad_s=omega * ngear, gen_torque=tg,
        power=dt.generator_efficiency * tg * omega * ngear, aero_power=q * omega,
        aero_torque=q, thrust=thrust, tsr=omega * rproj / v if v > 0 else 0,
        cp=q * omega / (0.5 * turbine.environment.air_density * area * v**3),
        ct=thrust / (0.5 * turbine.environment.air_density * area * v**2),
        x=x, u=u, power_reference=pref, shear_exponent=shear)


def operating_point(turbine: Turbine, wind_mps: float, rotor_speed_rad_s: float,
                    pitch_rad: float, *, config: PlantConfig | None = None,
                    shear_exponent: float = 0.0, params: PlantParams | None = None
                    ) -> OperatingPoint:
    """The operating point at a given wind, rotor speed and pitch: the structure in
    equilibrium and the generator torque balancing the aerodynamic torque.

    Where :func:`trim` follows the turbine's own schedule, this takes the point from elsewhere
    -- an OpenFAST ``.lin`` file's operating point, a measurement -- so a linear model can be
    made at exactly that point (``linearize(..., operating_point=op)``).

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    wind_mps : float
        Mean hub-height wind [m/s], >= 0.
    rotor_speed_rad_s : float
        Rotor speed [rad/s], > 0.
    pitch_rad : float
        Collective pitch [rad], within the actuator's range.
    config : PlantConfig, optional
        Degrees of freedom and aerodynamic options (default: all on).
    shear_exponent : float
        Power-law shear of the steady wind [-].
    params : PlantParams, optional
        Prebuilt parameters; must match ``turbine`` and ``config``.

    Returns
    -------
    OperatingPoint
        With region ``"given"``; power is the electrical power of the balancing torque.

    Raises
    ------
    ValueError
        A non-finite or out-of-range argument (names it and the allowed range).
    TrimError
        If the balancing generator torque is negative (the rotor would be motored) or above the
        generator's limit, or the structure finds no equilibrium.
    """
    v = check_finite_scalar("wind_mps", wind_mps)
    if v < 0:
        raise ValueError(f"wind_mps must be >= 0 m/s, got {wind_mps!r}")
    omega = check_finite_scalar("rotor_speed_rad_s", rotor_speed_rad_s)
    if omega <= 0:
        raise ValueError(f"rotor_speed_rad_s must be > 0, got {rotor_speed_rad_s!r}")
    pitch = check_finite_scalar("pitch_rad", pitch_rad)
    pa = turbine.pitch_actuator
    if not pa.min_pitch_rad - 1e-12 <= pitch <= pa.max_pitch_rad + 1e-12:
        raise ValueError(f"pitch_rad = {pitch:g} rad is outside the actuator's range "
                         f"{pa.min_pitch_rad:g}..{pa.max_pitch_rad:g} rad")
    p = params if params is not None else plant_params(turbine, config)
    shear = float(shear_exponent)
    dt = turbine.drivetrain
    ngear = dt.gearbox_ratio
    q, _ = _aero(p, v, omega, pitch, shear)
    tg = dt.gearbox_efficiency * q / ngear
    if not 0.0 <= tg <= turbine.generator.max_torque * (1 + 1e-9):
        raise TrimError(f"at {v:g} m/s, {omega:g} rad/s and pitch {pitch:g} rad the generator "
                        f"torque balancing the rotor would be {tg:g} N m; allowed: 0.."
                        f"{turbine.generator.max_torque:g} N m")
    x, u, z = _equilibrium(p, v, omega, pitch, tg, shear)
    cone = turbine.geometry.precone_rad if p.config.aero.cone else 0.0
    rproj = turbine.geometry.tip_radius * math.cos(cone)
    area = math.pi * rproj**2
    qa, thrust = float(z[22]), float(z[23])
    qdyn = 0.5 * turbine.environment.air_density * area
    return OperatingPoint(
        wind_mps=v, region="given", pitch_rad=pitch, rotor_speed_rad_s=omega,
        gen_speed_rad_s=omega * ngear, gen_torque=tg,
        power=dt.generator_efficiency * tg * omega * ngear, aero_power=qa * omega,
        aero_torque=qa, thrust=thrust,
        tsr=omega * rproj / v if v > 0 else 0.0,
        cp=qa * omega / (qdyn * v**3) if v > 0 else 0.0,
        ct=thrust / (qdyn * v**2) if v > 0 else 0.0,
        x=x, u=u, power_reference=None, shear_exponent=shear)


def _equilibrium(p: PlantParams, v: float, omega: float, pitch: float, tg: float,
                 shear: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Structural displacements that null the (azimuth-averaged) accelerations.

    The loads do not depend on displacements, so the accelerations are affine in them and
    one solve of K delta = M a is exact; a second one from the displacements found checks it
    (and removes round-off). With ``deflected_blades`` they do, and the steps are a fixed-point
    iteration (a few more).
    """
    pk = p.pack
    x = _state(p, omega, pitch)
    u = np.array([pitch, pitch, pitch, tg])
    # shaft torsion: K theta = Q_aero (with the rigid-shaft torque as the reference)
    if p.dof("drivetrain"):
        q, _ = _aero(p, v, omega, pitch, shear)
        x[4] = q / pk.k_shaft
    for _ in range(8 + 12 * _deflection_matters(p)):
        x, dx, z = _displacement_step(p, x, u, v, omega, shear)
        resid = _residual(dx)
        if np.all(np.isfinite(dx)) and resid.max() <= 1e-6:
            return x, u, z
    k = int(np.argmax(resid)) if np.all(np.isfinite(resid)) else int(np.argmax(~np.isfinite(dx)))
    raise TrimError(f"trim did not reach equilibrium: d({STATE_NAMES[k]})/dt = {dx[k]!r}")


def _residual(dx: FloatArray) -> FloatArray:
    """Scaled equilibrium residual of the azimuth-averaged derivatives (displacement rates,
    zero by construction, and the azimuth's rate, the speed, left out)."""
    scale = np.array([1.0, 1e-2, 1e-3, 1e-1, 1e-3, 1e-3, 1e-3, 1e-3, 1.0, 1e-2, 1.0, 1.0, 1.0,
                      1e-2, 1e-2, 1e-2, 1.0, 1.0, 1.0, 1.0, 1e-2, 1e-2, 1e-2])
    resid = np.abs(dx) / scale
    resid[[0, 8, 10, 11, 12, 16, 17, 18, 19]] = 0.0
    return resid


def _displacement_step(p: PlantParams, x: FloatArray, u: FloatArray, v: float, omega: float,
                       shear: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    """One Newton-like step of the displacements from ``x`` (K delta = M a at x), and the
    azimuth-averaged derivatives and outputs at the new displacements."""
    pk = p.pack
    x = x.copy()
    dx0, _ = rotor_average(p, x, u, v, shear)
    if p.dof("tower_fa") or p.dof("blade_flap"):
        kq = pk.k_b + omega**2 * pk.k_cf
        m = np.array([[pk.m_fa, pk.m_c, pk.m_c, pk.m_c],
                      [pk.m_c, pk.m_b, 0.0, 0.0],
                      [pk.m_c, 0.0, pk.m_b, 0.0],
                      [pk.m_c, 0.0, 0.0, pk.m_b]])
        k = np.diag([pk.k_fa, kq, kq, kq])
        # rotor_average samples a third of a revolution (rotor totals repeat every 120 deg);
        # a blade's full-revolution mean is the mean over the three blades
        a0 = np.array([dx0[1]] + [dx0[13:16].mean()] * 3)
        on = np.array([p.dof("tower_fa")] + [p.dof("blade_flap")] * 3)
        idx = np.flatnonzero(on)
        delta = np.zeros(4)
        delta[idx] = np.linalg.solve(k[np.ix_(idx, idx)], m[np.ix_(idx, idx)] @ a0[idx])
        x[0] += delta[0]
        x[10:13] += delta[1:]
    if p.dof("tower_ss"):
        x[8] += pk.m_ss * dx0[9] / pk.k_ss
    if p.dof("blade_edge"):
        # edge force per blade (mean over a revolution) from the accelerations:
        # M_e q'' + S_e Omega' = F - K q  =>  K delta = M_e q'' + S_e Omega'
        force = pk.m_e * dx0[20:23].mean() + pk.s_e * dx0[2]
        x[17:20] += force / (pk.k_e + omega**2 * (pk.k_cf_e - pk.m_e))
    dx, z = rotor_average(p, x, u, v, shear)
    dx[13:16] = dx[13:16].mean()   # rotor_average returns a new array
    dx[20:23] = dx[20:23].mean()
    return x, dx, z


def operating_schedule(turbine: Turbine, wind_mps: FloatArray, power_W: float | None = None,
                       *, config: PlantConfig | None = None,
                       shear_exponent: float = 0.0) -> list[OperatingPoint]:
    """Trim at each wind speed; with ``power_W``, cap the power at min(available, power_W).

    Unlike :func:`trim`, a power reference above what the wind offers is not an error here:
    those points follow the normal schedule (the derated turbine's partial-load region).

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    wind_mps : (n_op,) array_like
        Mean wind speeds [m/s].
    power_W : float, optional
        Power reference [W] (default rated).
    config : PlantConfig, optional
        Plant configuration.
    shear_exponent : float
        Power-law shear exponent [-].

    Returns
    -------
    list of OperatingPoint
        One per wind speed.
    """
    p = plant_params(turbine, config)
    out = []
    for v in np.asarray(wind_mps, dtype=float).ravel():
        if power_W is None:
            out.append(trim(turbine, float(v), params=p, shear_exponent=shear_exponent))
            continue
        try:
            out.append(trim(turbine, float(v), power_W, params=p, shear_exponent=shear_exponent))
        except TrimError as err:
            if "above the power available" not in str(err):
                raise
            out.append(trim(turbine, float(v), params=p, shear_exponent=shear_exponent))
    return out


def rated_wind_speed(turbine: Turbine, *, config: PlantConfig | None = None,
                     shear_exponent: float = 0.0) -> float:
    """Lowest wind speed at which rated power is reached at the region-2 pitch
    (:func:`region2_pitch`) [m/s].

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    config : PlantConfig, optional
        Plant configuration.
    shear_exponent : float
        Power-law shear exponent [-].

    Returns
    -------
    float
        Rated wind speed [m/s].

    Raises
    ------
    TrimError
        If rated power is not reached below cut-out.
    """
    p = plant_params(turbine, config)
    op = turbine.operation
    dt = turbine.drivetrain
    eta = dt.generator_efficiency * dt.gearbox_efficiency

    def surplus(v: float) -> float:
        w, pitch, _ = _region2(p, v, float(shear_exponent))
        q, _ = _aero(p, v, w, pitch, float(shear_exponent))
        return eta * q * w - op.rated_power

    if surplus(op.cut_out_wind) < 0:
        raise TrimError("rated power is not reached below cut-out")
    return float(brentq(surplus, op.cut_in_wind, op.cut_out_wind, xtol=1e-10))

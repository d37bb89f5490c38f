"""Reference-turbine data: typed, frozen, validated on loading.

A turbine is a YAML file of scalar parameters plus CSV tables (blade aerodynamics, airfoil polars,
distributed blade and tower structure, mode shapes). The format is documented in
``docs/turbine-format.md``; :func:`load_turbine` reads it and names the file, field and allowed
range on any error. Everything held by :class:`Turbine` is SI (angles in rad).
"""
from __future__ import annotations

import csv
import hashlib
import math
from dataclasses import dataclass, field, fields, is_dataclass
from importlib import resources
from pathlib import Path
from typing import Any, Callable

import numpy as np
import yaml

from linearize._typing import FloatArray, IntArray
from linearize.errors import TurbineFileError
from linearize.validate import frozen_array

__all__ = [
    "TurbineFileError", "Geometry", "Operation", "Environment", "RotorMass", "Nacelle",
    "Drivetrain", "Generator", "PitchActuator", "Damping", "BladeAero", "Polar", "UAParams",
    "BladeStructure", "TowerStructure", "ModeShapes", "MinPitchTable", "Turbine",
    "available_turbines", "LoadReport", "ReportEntry", "content_digest",
]

SCHEMA_VERSION = 1
_DEG = math.pi / 180.0
_RPM = math.pi / 30.0


def _pos(v: float) -> bool:
    return v > 0.0


# --------------------------------------------------------------------------------------------
# Scalar sections. Each field's metadata: yaml key, unit factor to SI, allowed closed range.
# --------------------------------------------------------------------------------------------
def _f(key: str, lo: float, hi: float, scale: float = 1.0, *, lo_open: bool = False) -> Any:
    return field(metadata={"key": key, "lo": lo, "hi": hi, "scale": scale, "lo_open": lo_open})


def _check_section(obj: Any) -> None:
    for f in fields(obj):
        meta = f.metadata
        if "key" not in meta:
            continue
        v = getattr(obj, f.name)
        lo, hi = meta["lo"] * meta["scale"], meta["hi"] * meta["scale"]
        bad_lo = v <= lo if meta["lo_open"] else v < lo
        if not math.isfinite(v) or bad_lo or v > hi:
            lb = "(" if meta["lo_open"] else "["
            raise ValueError(
                f"{type(obj).__name__}.{f.name} ({meta['key']}) must be in "
                f"{lb}{meta['lo']:g}, {meta['hi']:g}], got {v / meta['scale']!r}")


class _Section:
    """Base of the scalar sections: each field is checked against its allowed range."""

    def __post_init__(self) -> None:
        _check_section(self)


@dataclass(frozen=True)
class Geometry(_Section):
    """Rotor and nacelle geometry.

    Parameters
    ----------
    number_of_blades : int
        Blade count [-] (the plant supports 3).
    tip_radius : float
        Rotor apex to blade tip along the blade [m].
    hub_radius : float
        Rotor apex to blade root [m].
    hub_height : float
        Hub centre above ground [m].
    tower_height : float
        Tower top (yaw bearing) above ground [m].
    tower_base_height : float
        Tower base above ground, where the tower is clamped [m] (ElastoDyn ``TowerBsHt``; 0
        for a land-based tower, the transition piece of a monopile). Optional in the YAML
        (``tower_base_height_m``, default 0).
    twr2shft : float
        Tower top to shaft axis, vertical [m].
    overhang : float
        Yaw axis to rotor apex, positive upwind [m].
    precone_rad : float
        Blade cone angle, positive coned upwind [rad].
    shaft_tilt_rad : float
        Shaft tilt, positive nose up [rad].
    nacelle_cm_downwind, nacelle_cm_vertical : float
        Nacelle centre of mass from the tower top [m].
    """

    number_of_blades: int = _f("number_of_blades", 3, 3)
    tip_radius: float = _f("tip_radius_m", 0.0, 300.0, lo_open=True)
    hub_radius: float = _f("hub_radius_m", 0.0, 50.0)
    hub_height: float = _f("hub_height_m", 0.0, 400.0, lo_open=True)
    tower_height: float = _f("tower_height_m", 0.0, 400.0, lo_open=True)
    twr2shft: float = _f("twr2shft_m", -20.0, 20.0)
    overhang: float = _f("overhang_m", -30.0, 30.0)
    precone_rad: float = _f("precone_deg", -20.0, 20.0, _DEG)
    shaft_tilt_rad: float = _f("shaft_tilt_deg", -20.0, 20.0, _DEG)
    nacelle_cm_downwind: float = _f("nacelle_cm_downwind_m", -30.0, 30.0)
    nacelle_cm_vertical: float = _f("nacelle_cm_vertical_m", -30.0, 30.0)
    tower_base_height: float = field(default=0.0, metadata={
        "key": "tower_base_height_m", "lo": 0.0, "hi": 400.0, "scale": 1.0, "lo_open": False,
        "optional": True})

    def __post_init__(self) -> None:
        super().__post_init__()
        if not self.tower_base_height < self.tower_height:
            raise ValueError(f"Geometry.tower_base_height ({self.tower_base_height} m) must be "
                             f"below tower_height ({self.tower_height} m)")
        if not self.hub_radius < self.tip_radius:
            raise ValueError(f"Geometry.hub_radius ({self.hub_radius} m) must be smaller than "
                             f"tip_radius ({self.tip_radius} m)")
        if self.tip_radius >= self.hub_height:
            raise ValueError(f"Geometry.tip_radius ({self.tip_radius} m) must be smaller than "
                             f"hub_height ({self.hub_height} m): the blade would hit the ground")


@dataclass(frozen=True)
class Operation(_Section):
    """Operating envelope.

    Parameters
    ----------
    rated_power : float
        Rated electrical power [W].
    cut_in_wind, cut_out_wind : float
        Wind-speed envelope [m/s].
    min_rotor_speed_rad_s, rated_rotor_speed_rad_s : float
        Rotor-speed envelope [rad/s].
    fine_pitch_rad : float
        Fine (minimum operating) pitch [rad].
    """

    rated_power: float = _f("rated_power_W", 0.0, 1e9, lo_open=True)
    cut_in_wind: float = _f("cut_in_wind_mps", 0.0, 15.0, lo_open=True)
    cut_out_wind: float = _f("cut_out_wind_mps", 5.0, 60.0)
    min_rotor_speed_rad_s: float = _f("min_rotor_speed_rpm", 0.0, 100.0, _RPM)
    rated_rotor_speed_rad_s: float = _f("rated_rotor_speed_rpm", 0.0, 100.0, _RPM, lo_open=True)
    fine_pitch_rad: float = _f("fine_pitch_deg", -10.0, 30.0, _DEG)

    def __post_init__(self) -> None:
        super().__post_init__()
        if not self.cut_in_wind < self.cut_out_wind:
            raise ValueError(f"Operation.cut_in_wind ({self.cut_in_wind}) must be below "
                             f"cut_out_wind ({self.cut_out_wind}) m/s")
        if not self.min_rotor_speed_rad_s < self.rated_rotor_speed_rad_s:
            raise ValueError("Operation.min_rotor_speed_rpm must be below rated_rotor_speed_rpm")


@dataclass(frozen=True)
class Environment(_Section):
    """Air and gravity: ``air_density`` [kg/m^3], ``gravity`` [m/s^2].

    Parameters
    ----------
    air_density : float
        [kg/m^3].
    gravity : float
        [m/s^2].
    """

    air_density: float = _f("air_density_kgpm3", 0.5, 1.6)
    gravity: float = _f("gravity_mps2", 0.0, 20.0)


@dataclass(frozen=True)
class RotorMass(_Section):
    """Hub mass [kg], hub inertia about the shaft [kg m^2], blade mass scale factor [-].

    Parameters
    ----------
    hub_mass : float
        [kg].
    hub_inertia : float
        About the shaft [kg m^2].
    blade_mass_scale : float
        Factor on the blade's mass per length [-].
    """

    hub_mass: float = _f("hub_mass_kg", 0.0, 1e7, lo_open=True)
    hub_inertia: float = _f("hub_inertia_kgm2", 0.0, 1e10, lo_open=True)
    blade_mass_scale: float = _f("blade_mass_scale", 0.5, 2.0)


@dataclass(frozen=True)
class Nacelle(_Section):
    """Nacelle mass [kg] and yaw inertia [kg m^2].

    Parameters
    ----------
    mass : float
        [kg].
    yaw_inertia : float
        [kg m^2].
    """

    mass: float = _f("mass_kg", 0.0, 1e8, lo_open=True)
    yaw_inertia: float = _f("yaw_inertia_kgm2", 0.0, 1e10, lo_open=True)


@dataclass(frozen=True)
class Drivetrain(_Section):
    """Two-mass drivetrain (Madsen et al. 2012, eq 11).

    Parameters
    ----------
    gearbox_ratio : float
        High-speed over low-speed shaft speed [-].
    gearbox_efficiency, generator_efficiency : float
        [-], in (0, 1].
    generator_inertia : float
        Generator inertia about the high-speed shaft [kg m^2].
    shaft_stiffness : float
        Equivalent low-speed-shaft torsional stiffness [N m/rad].
    shaft_damping : float
        Equivalent low-speed-shaft torsional damping [N m s/rad].
    """

    gearbox_ratio: float = _f("gearbox_ratio", 1.0, 1000.0)
    gearbox_efficiency: float = _f("gearbox_efficiency", 0.0, 1.0, lo_open=True)
    generator_efficiency: float = _f("generator_efficiency", 0.0, 1.0, lo_open=True)
    generator_inertia: float = _f("generator_inertia_kgm2", 0.0, 1e9, lo_open=True)
    shaft_stiffness: float = _f("shaft_stiffness_Nm_per_rad", 0.0, 1e13, lo_open=True)
    shaft_damping: float = _f("shaft_damping_Nms_per_rad", 0.0, 1e12)


@dataclass(frozen=True)
class Generator(_Section):
    """Generator torque limits on the high-speed shaft [N m] and rate limit [N m/s].

    Parameters
    ----------
    min_torque, max_torque : float
        Torque limits on the high-speed shaft [N m].
    max_torque_rate : float
        Torque rate limit [N m/s].
    """

    min_torque: float = _f("min_torque_Nm", -1e8, 1e8)
    max_torque: float = _f("max_torque_Nm", 0.0, 1e8, lo_open=True)
    max_torque_rate: float = _f("max_torque_rate_Nmps", 0.0, 1e9, lo_open=True)

    def __post_init__(self) -> None:
        super().__post_init__()
        if not self.min_torque < self.max_torque:
            raise ValueError("Generator.min_torque_Nm must be below max_torque_Nm")


@dataclass(frozen=True)
class PitchActuator(_Section):
    """First-order pitch servo with limits (Madsen et al. 2012, eqs 14-15).

    Parameters
    ----------
    min_pitch_rad, max_pitch_rad : float
        Position limits [rad].
    max_rate_rad_s : float
        Rate limit [rad/s].
    time_constant : float
        Servo time constant tau_beta [s].
    """

    min_pitch_rad: float = _f("min_pitch_deg", -30.0, 30.0, _DEG)
    max_pitch_rad: float = _f("max_pitch_deg", 0.0, 95.0, _DEG)
    max_rate_rad_s: float = _f("max_rate_degps", 0.0, 180.0, _DEG, lo_open=True)
    time_constant: float = _f("time_constant_s", 0.0, 5.0, lo_open=True)

    def __post_init__(self) -> None:
        super().__post_init__()
        if not self.min_pitch_rad < self.max_pitch_rad:
            raise ValueError("PitchActuator.min_pitch_deg must be below max_pitch_deg")


@dataclass(frozen=True)
class Damping(_Section):
    """Structural damping ratios of the first modes [-].

    Parameters
    ----------
    blade : float
        Blade modes' damping ratio [-], of the isolated blade (no centrifugal stiffening), as
        ElastoDyn's ``BldFlDmp``.
    tower_fa, tower_ss : float
        Tower fore-aft and side-side damping ratios [-] of the isolated tower's first modes
        (without the nacelle and rotor), as ElastoDyn's ``TwrFADmp(1)`` and ``TwrSSDmp(1)``
        and the NREL 5-MW's 1 %: the plant's damping is stiffness-proportional,
        c = zeta K / (pi f) with the isolated tower's elastic stiffness K and frequency f
        (J. Jonkman, NREL forum, "Natural frequency and damping ratio calculation", 2013). With
        the nacelle and rotor on top the mode keeps about a third of it (0.36 % of critical on
        the NREL 5-MW).
    """

    blade: float = _f("blade_damping_ratio", 0.0, 0.5)
    tower_fa: float = _f("tower_fa_damping_ratio", 0.0, 0.5)
    tower_ss: float = _f("tower_ss_damping_ratio", 0.0, 0.5)


# --------------------------------------------------------------------------------------------
# Tables
# --------------------------------------------------------------------------------------------
def _freeze(obj: Any, names: tuple[str, ...]) -> None:
    for n in names:
        object.__setattr__(obj, n, frozen_array(getattr(obj, n)))


@dataclass(frozen=True)
class BladeAero:
    """Blade elements for BEM.

    Parameters
    ----------
    r : (n_r,) ndarray
        Element centre from the rotor apex, along the blade [m].
    dr : (n_r,) ndarray
        Element length [m].
    chord : (n_r,) ndarray
        [m].
    twist_rad : (n_r,) ndarray
        Aerodynamic twist, positive toward feather [rad].
    airfoil : (n_r,) ndarray of int
        Index into :attr:`Turbine.polars`.
    layout : {"elements", "nodes"}
        ``"elements"``: ``r`` is the centre of an element ``dr`` long (AeroDyn v13, our YAML
        files). ``"nodes"``: ``r`` are AeroDyn 15 nodes strictly inside the rotor and ``dr``
        their trapezoid weights with zero load at hub and tip (OpenFAST decks); the midpoint
        sum is then the trapezoid rule over the nodes.
    """

    r: FloatArray
    dr: FloatArray
    chord: FloatArray
    twist_rad: FloatArray
    airfoil: IntArray
    layout: str = "elements"

    def __post_init__(self) -> None:
        _freeze(self, ("r", "dr", "chord", "twist_rad"))
        a = np.array(self.airfoil, dtype=np.int64)
        a.flags.writeable = False
        object.__setattr__(self, "airfoil", a)
        n = self.r.shape
        for name in ("dr", "chord", "twist_rad", "airfoil"):
            if getattr(self, name).shape != n:
                raise ValueError(f"BladeAero.{name} has shape {getattr(self, name).shape}; "
                                 f"expected (n_r,) = {n}")
        if self.r.size < 2 or np.any(np.diff(self.r) <= 0):
            raise ValueError("BladeAero.r (element radius) must be strictly increasing")
        if np.any(self.dr <= 0) or np.any(self.chord <= 0):
            raise ValueError("BladeAero.dr and chord must be > 0")
        if self.layout not in ("elements", "nodes"):
            raise ValueError(f"BladeAero.layout must be 'elements' or 'nodes', "
                             f"got {self.layout!r}")


@dataclass(frozen=True)
class UAParams:
    """An airfoil's unsteady-aerodynamics coefficients, AeroDyn's names and defaults
    (AirfoilInfo ``alpha0``, ``C_nalpha``, ``Cd0``, ``A1``, ``A2``, ``b1``, ``b2``, ``T_p``,
    ``T_f0``, ``filtCutOff``, ``UACutout``; :mod:`linearize.unsteady`).

    Parameters
    ----------
    alpha0_rad : float
        Zero-lift angle of attack [rad].
    cn_alpha : float
        Slope of the attached-flow normal-force line [1/rad], > 0.
    cd0 : float
        Drag coefficient at zero lift [-].
    a1, a2, b1, b2 : float
        Wagner's indicial-function constants [-] (0.3, 0.7, 0.14, 0.53).
    t_p, t_f0 : float
        Leading-edge pressure and trailing-edge separation time constants in semichords [-]
        (1.7, 3).
    filt_cutoff : float
        Reduced frequency of the angle-of-attack low-pass filter [-] (0.5).
    cutout_rad : float
        Angle of attack above which the static polar acts [rad] (45 deg).
    speed_of_sound : float
        [m/s] (AeroDyn's ``SpdSound``, 335), for the element's Mach number.
    """

    alpha0_rad: float
    cn_alpha: float
    cd0: float
    a1: float = 0.3
    a2: float = 0.7
    b1: float = 0.14
    b2: float = 0.53
    t_p: float = 1.7
    t_f0: float = 3.0
    filt_cutoff: float = 0.5
    cutout_rad: float = math.radians(45.0)
    speed_of_sound: float = 335.0

    def __post_init__(self) -> None:
        for name in ("alpha0_rad", "cn_alpha", "cd0", "a1", "a2", "b1", "b2", "t_p", "t_f0",
                     "filt_cutoff", "cutout_rad", "speed_of_sound"):
            v = float(getattr(self, name))
            if not math.isfinite(v):
                raise ValueError(f"UAParams.{name} must be finite, got {v!r}")
            object.__setattr__(self, name, v)
        for name in ("cn_alpha", "b1", "b2", "t_p", "t_f0", "filt_cutoff", "cutout_rad",
                     "speed_of_sound"):
            if not getattr(self, name) > 0:
                raise ValueError(f"UAParams.{name} must be > 0, got {getattr(self, name)!r}")
        if abs(self.alpha0_rad) > math.radians(30.0):
            raise ValueError(f"UAParams.alpha0_rad must be within +-30 deg, got "
                             f"{math.degrees(self.alpha0_rad):.3g} deg")

    def row(self) -> tuple[float, ...]:
        """The kernel's parameter row.

        Returns
        -------
        tuple of float
            In the order of :data:`linearize.unsteady.UA_PAR`, the first 1.0 (UA on).
        """
        return (1.0, self.alpha0_rad, self.cn_alpha, self.cd0, self.a1, self.a2, self.b1,
                self.b2, self.t_p, self.t_f0, self.filt_cutoff, self.cutout_rad,
                self.speed_of_sound)


@dataclass(frozen=True)
class Polar:
    """Static airfoil polar covering -180..180 deg.

    Parameters
    ----------
    name : str
    alpha_rad : (n_alpha,) ndarray
        Angle of attack, strictly increasing, from -pi to pi [rad].
    cl, cd : (n_alpha,) ndarray
        Lift and drag coefficients [-].
    ua : UAParams, optional
        Unsteady-aerodynamics coefficients; None: the airfoil acts by its static polar alone.
    """

    name: str
    alpha_rad: FloatArray
    cl: FloatArray
    cd: FloatArray
    ua: UAParams | None = None

    def __post_init__(self) -> None:
        _freeze(self, ("alpha_rad", "cl", "cd"))
        a = self.alpha_rad
        if a.ndim != 1 or a.size < 2 or self.cl.shape != a.shape or self.cd.shape != a.shape:
            raise ValueError(f"Polar {self.name}: alpha, cl, cd must be 1-D of equal length")
        if np.any(np.diff(a) <= 0):
            raise ValueError(f"Polar {self.name}: alpha must be strictly increasing")
        if a[0] > -math.pi + 1e-9 or a[-1] < math.pi - 1e-9:
            raise ValueError(f"Polar {self.name}: alpha must cover -180..180 deg, got "
                             f"{math.degrees(a[0]):.2f}..{math.degrees(a[-1]):.2f} deg")
        if not (np.all(np.isfinite(self.cl)) and np.all(np.isfinite(self.cd))):
            raise ValueError(f"Polar {self.name}: cl and cd must be finite")


@dataclass(frozen=True)
class BladeStructure:
    """Distributed blade properties at span fractions 0..1 from the root.

    ``mass_per_length`` [kg/m] (already scaled), ``flap_stiffness``, ``edge_stiffness`` [N m^2].

    Parameters
    ----------
    span_fraction : (n,) ndarray
        Span fractions from the root, 0..1 [-].
    mass_per_length : (n,) ndarray
        Mass per unit length, scaled [kg/m].
    flap_stiffness, edge_stiffness : (n,) ndarray
        Bending stiffness [N m^2].
    structural_twist_rad : (n,) ndarray, optional
        Twist of the principal axes [rad] (ElastoDyn's ``StrcTwst``): the flap and edge modes
        vibrate along them, pitched with the blade. None: in and out of the rotor plane.
    """

    span_fraction: FloatArray
    mass_per_length: FloatArray
    flap_stiffness: FloatArray
    edge_stiffness: FloatArray
    structural_twist_rad: FloatArray | None = None

    def __post_init__(self) -> None:
        _freeze(self, ("span_fraction", "mass_per_length", "flap_stiffness", "edge_stiffness"))
        _check_stations("BladeStructure", self.span_fraction)
        if self.structural_twist_rad is not None:
            _freeze(self, ("structural_twist_rad",))
            tw = self.structural_twist_rad
            if tw.shape != self.span_fraction.shape or not np.all(np.abs(tw) <= math.pi / 2):
                raise ValueError(f"BladeStructure.structural_twist_rad must be within +-90 deg at "
                                 f"each of the {self.span_fraction.size} stations")


@dataclass(frozen=True)
class TowerStructure:
    """Distributed tower properties at height fractions 0..1 of the flexible tower.

    ``mass_per_length`` [kg/m], ``fa_stiffness``, ``ss_stiffness`` [N m^2].

    Parameters
    ----------
    height_fraction : (n,) ndarray
        Fractions of the flexible tower's height, 0..1 [-].
    mass_per_length : (n,) ndarray
        [kg/m].
    fa_stiffness, ss_stiffness : (n,) ndarray
        Fore-aft and side-side bending stiffness [N m^2].
    outer_diameter : (n,) ndarray, optional
        Outer diameter [m] (AeroDyn's ``TwrDiam``), for the tower's potential flow and drag;
        None when the data have none (the plant then has no tower shadow and no tower drag).
    drag_coefficient : (n,) ndarray, optional
        Drag coefficient of the tower's section [-] (AeroDyn's ``TwrCd``); None: no tower drag.
    """

    height_fraction: FloatArray
    mass_per_length: FloatArray
    fa_stiffness: FloatArray
    ss_stiffness: FloatArray
    outer_diameter: FloatArray | None = None
    drag_coefficient: FloatArray | None = None

    def __post_init__(self) -> None:
        _freeze(self, ("height_fraction", "mass_per_length", "fa_stiffness", "ss_stiffness"))
        _check_stations("TowerStructure", self.height_fraction)
        if self.drag_coefficient is not None:
            _freeze(self, ("drag_coefficient",))
            c = self.drag_coefficient
            if c.shape != self.height_fraction.shape or not np.all(np.isfinite(c)) \
                    or np.any(c < 0) or np.any(c > 5):
                raise ValueError(f"TowerStructure.drag_coefficient must be within 0..5 at each "
                                 f"of the {self.height_fraction.size} stations, got {c!r}")
        if self.outer_diameter is not None:
            _freeze(self, ("outer_diameter",))
            d = self.outer_diameter
            if d.shape != self.height_fraction.shape or not np.all(np.isfinite(d)) \
                    or np.any(d <= 0):
                raise ValueError(f"TowerStructure.outer_diameter must be finite and > 0 m at "
                                 f"each of the {self.height_fraction.size} stations, got {d!r}")


def _check_stations(owner: str, x: FloatArray) -> None:
    if x.ndim != 1 or x.size < 2 or np.any(np.diff(x) <= 0):
        raise ValueError(f"{owner}: station fractions must be strictly increasing")
    if abs(x[0]) > 1e-9 or abs(x[-1] - 1.0) > 1e-9:
        raise ValueError(f"{owner}: station fractions must run from 0 to 1, got "
                         f"{x[0]:g}..{x[-1]:g}")


@dataclass(frozen=True)
class ModeShapes:
    """Polynomial mode shapes phi(x) = sum_k c_k x^k, k = 2..6, with phi(1) = 1.

    Each field is a (5,) ndarray of coefficients for x^2..x^6 (x = fraction of height/span).
    ``blade_edge1`` (ElastoDyn's first edgewise blade mode) is optional: without it the
    edgewise modal properties of :class:`~linearize.PlantParams` are NaN.

    Parameters
    ----------
    tower_fa1, tower_ss1, blade_flap1 : (5,) ndarray
        Coefficients of x^2..x^6 of the first tower fore-aft, side-side and blade flap modes.
    blade_edge1 : (5,) ndarray, optional
        The first edgewise blade mode's.
    """

    tower_fa1: FloatArray
    tower_ss1: FloatArray
    blade_flap1: FloatArray
    blade_edge1: FloatArray | None = None

    def __post_init__(self) -> None:
        names = ("tower_fa1", "tower_ss1", "blade_flap1")
        _freeze(self, names + (("blade_edge1",) if self.blade_edge1 is not None else ()))
        for f in fields(self):
            c = getattr(self, f.name)
            if c is None:
                continue
            if c.shape != (5,):
                raise ValueError(f"ModeShapes.{f.name} has shape {c.shape}; expected (5,)")
            if abs(c.sum() - 1.0) > 2e-3:
                raise ValueError(f"ModeShapes.{f.name}: phi(1) = {c.sum():.4f}; must be 1")


def mode_shape(coeffs: FloatArray, x: FloatArray, derivative: int = 0) -> FloatArray:
    """Evaluate a polynomial mode shape or its first/second derivative w.r.t. ``x`` [-]."""
    x = np.asarray(x, dtype=float)
    out = np.zeros_like(x)
    for i, c in enumerate(coeffs):
        k = i + 2
        if derivative == 0:
            out = out + c * x**k
        elif derivative == 1:
            out = out + c * k * x ** (k - 1)
        elif derivative == 2:
            out = out + c * k * (k - 1) * x ** (k - 2)
        else:
            raise ValueError(f"derivative must be 0, 1 or 2, got {derivative!r}")
    return out


@dataclass(frozen=True)
class ReportEntry:
    """One line of a :class:`LoadReport`: a quantity, its value with unit, and where it came
    from (``file:line key`` or ``default: why``).

    Parameters
    ----------
    quantity : str
        What was read.
    value : str
        Its value with unit.
    source : str
        ``file:line key`` or ``default: why``.
    """

    quantity: str
    value: str
    source: str


@dataclass(frozen=True)
class LoadReport:
    """What a turbine loader read from where and what it defaulted.

    Parameters
    ----------
    entries : tuple of ReportEntry
        One per quantity.
    notes : tuple of str
        What was read but not modelled, or modelled differently (e.g. a monopile clamped at
        the tower base).
    """

    entries: tuple[ReportEntry, ...] = ()
    notes: tuple[str, ...] = ()

    def source(self, quantity: str) -> str:
        """Where a quantity came from (``file:line key``), or "" when it was not read from a
        file (a default, or a YAML turbine's report, which is empty).

        Parameters
        ----------
        quantity : str
            The entry's quantity, e.g. ``"shaft stiffness"``.

        Returns
        -------
        str
        """
        for e in self.entries:
            if e.quantity == quantity and not e.source.startswith("default"):
                return e.source
        return ""

    @property
    def defaulted(self) -> tuple[ReportEntry, ...]:
        """The entries that were not in the files."""
        return tuple(e for e in self.entries if e.source.startswith("default"))

    def __str__(self) -> str:
        w = max([len(e.quantity) for e in self.entries] + [8])
        v = max([len(e.value) for e in self.entries] + [5])
        lines = [f"{e.quantity:<{w}}  {e.value:>{v}}  {e.source}" for e in self.entries]
        lines += [f"note: {n}" for n in self.notes]
        return "\n".join(lines)


@dataclass(frozen=True)
class MinPitchTable:
    """A minimum-pitch schedule over mean wind: the least collective pitch the turbine's own
    controller holds at each wind (ROSCO's ``PS_BldPitchMin`` over ``PS_WindSpeeds`` with
    ``PS_Mode`` 1: the region-1.5 pitch at low wind and the peak shaving of thrust near rated),
    linear between its points and held at its end values beyond them. Every operating point
    of :func:`linearize.trim` pitches at least this, and at least the fine pitch.

    Parameters
    ----------
    wind_mps : tuple of float
        Mean winds [m/s], at least two, finite, strictly increasing.
    pitch_rad : tuple of float
        The minimum pitch at each wind [rad], finite.
    """

    wind_mps: tuple[float, ...]
    pitch_rad: tuple[float, ...]

    def __post_init__(self) -> None:
        w = tuple(float(x) for x in np.ravel(self.wind_mps))
        b = tuple(float(x) for x in np.ravel(self.pitch_rad))
        if (len(w) < 2 or len(w) != len(b) or not all(map(math.isfinite, w + b))
                or any(w1 <= w0 for w0, w1 in zip(w, w[1:])) or w[0] <= 0.0):
            raise ValueError(f"MinPitchTable: wind_mps and pitch_rad must hold as many finite "
                             f"values, at least 2, the winds > 0 and strictly increasing; got "
                             f"{len(w)} winds {list(w)[:4]}... and {len(b)} pitches")
        if not all(-math.pi / 2 <= x <= math.pi / 2 for x in b):
            raise ValueError(f"MinPitchTable: pitch_rad must lie in [-pi/2, pi/2] rad, got "
                             f"{min(b):g}..{max(b):g}")
        object.__setattr__(self, "wind_mps", w)
        object.__setattr__(self, "pitch_rad", b)

    def at(self, wind_mps: float) -> float:
        """The minimum pitch [rad] at a mean wind [m/s] (held at the end values beyond the
        table).

        Parameters
        ----------
        wind_mps : float
            [m/s].

        Returns
        -------
        float
        """
        return float(np.interp(wind_mps, self.wind_mps, self.pitch_rad))


@dataclass(frozen=True)
class Turbine:
    """A reference turbine as the BEM plant sees it. All quantities SI, angles in rad.

    ``report`` says what was read from where (OpenFAST decks) or holds nothing (YAML files,
    whose comments carry the sources).

    Parameters
    ----------
    name : str
        The turbine's name.
    source : str
        The file it was read from.
    geometry, operation, environment, rotor, nacelle, drivetrain, generator, pitch_actuator, damping
        The sections of the turbine file (:class:`Geometry` ... :class:`Damping`).
    blade : BladeAero
        The blade's aerodynamic layout.
    polars : tuple of Polar
        The airfoil polars.
    blade_structure : BladeStructure
        Distributed blade properties.
    tower_structure : TowerStructure
        Distributed tower properties.
    mode_shapes : ModeShapes
        The assumed modes.
    rigid_dofs : tuple of str
        The plant's degrees of freedom the turbine's data holds rigid, sorted (names of
        :data:`linearize.DOF_NAMES`; an OpenFAST deck's ElastoDyn switches, e.g.
        ``("drivetrain",)`` for ``DrTrDOF False``): :func:`linearize.plant_params` leaves them
        out of every configuration. Empty for a turbine whose every DOF is flexible.
    min_pitch : MinPitchTable or None
        The turbine's minimum-pitch schedule over mean wind (an OpenFAST deck's ROSCO
        ``PS_BldPitchMin`` with ``PS_Mode`` 1); None: the fine pitch everywhere.
    report : LoadReport
        What was read from where.
    """

    name: str
    source: str = field(compare=False)
    geometry: Geometry
    operation: Operation
    environment: Environment
    rotor: RotorMass
    nacelle: Nacelle
    drivetrain: Drivetrain
    generator: Generator
    pitch_actuator: PitchActuator
    damping: Damping
    blade: BladeAero
    polars: tuple[Polar, ...]
    blade_structure: BladeStructure
    tower_structure: TowerStructure
    mode_shapes: ModeShapes
    rigid_dofs: tuple[str, ...] = field(default=(), metadata={"digest_at_default": False})
    min_pitch: MinPitchTable | None = field(default=None, metadata={"digest_at_default": False})
    report: LoadReport = field(default_factory=LoadReport, compare=False)

    def __post_init__(self) -> None:
        rigid = tuple(self.rigid_dofs)
        if any(not isinstance(d, str) for d in rigid) or list(rigid) != sorted(set(rigid)):
            raise ValueError(f"rigid_dofs must be a sorted tuple of distinct DOF names, got "
                             f"{self.rigid_dofs!r}")
        object.__setattr__(self, "rigid_dofs", rigid)
        g = self.geometry
        b = self.blade
        if b.layout == "nodes":
            rr = np.concatenate(([g.hub_radius], b.r, [g.tip_radius]))
            if b.r[0] <= g.hub_radius or b.r[-1] >= g.tip_radius:
                raise ValueError(f"blade nodes span {b.r[0]:.4g}..{b.r[-1]:.4g} m; they must "
                                 f"lie strictly within hub_radius..tip_radius = "
                                 f"{g.hub_radius:g}..{g.tip_radius:g} m")
            if not np.allclose(b.dr, 0.5 * (rr[2:] - rr[:-2]), rtol=1e-9, atol=1e-12):
                raise ValueError("blade node weights dr must be the trapezoid weights of the "
                                 "nodes between hub and tip")
        lo = b.r - 0.5 * b.dr if b.layout == "elements" else np.array([g.hub_radius])
        hi = b.r + 0.5 * b.dr if b.layout == "elements" else np.array([g.tip_radius])
        if lo[0] < g.hub_radius - 1e-3 or hi[-1] > g.tip_radius + 1e-3:
            raise ValueError(
                f"blade elements span {lo[0]:.4g}..{hi[-1]:.4g} m; they must lie within "
                f"hub_radius..tip_radius = {g.hub_radius:g}..{g.tip_radius:g} m")
        if np.any(b.chord > 0.5 * g.tip_radius):
            raise ValueError(f"blade chord must be below half the tip radius "
                             f"({0.5 * g.tip_radius:g} m), got max {b.chord.max():g} m")
        if b.airfoil.min() < 0 or b.airfoil.max() >= len(self.polars):
            raise ValueError(f"blade airfoil index out of range 0..{len(self.polars) - 1}")

    @property
    def rated_generator_speed_rad_s(self) -> float:
        """Rated generator speed [rad/s]."""
        return self.operation.rated_rotor_speed_rad_s * self.drivetrain.gearbox_ratio

    @property
    def rated_mechanical_power(self) -> float:
        """Rated rotor (mechanical) power: rated electrical power over the efficiencies [W]."""
        d = self.drivetrain
        return self.operation.rated_power / (d.generator_efficiency * d.gearbox_efficiency)

    @property
    def rated_generator_torque(self) -> float:
        """Generator torque at rated power and rated speed [N m]."""
        return self.operation.rated_power / (
            self.drivetrain.generator_efficiency * self.rated_generator_speed_rad_s)


def content_digest(obj: Any) -> str:
    """A digest of a turbine's content (every field and array; not where it was read from),
    for keeping what is computed from a turbine (designs, tables) and naming it.

    Walks dataclasses (fields with ``compare=False``, such as a turbine's source path and load
    report, are left out), arrays (shape and float64 bytes), mappings, sequences and scalars.

    Parameters
    ----------
    obj : Turbine or any dataclass, array, mapping, sequence or scalar
        What to digest.

    Returns
    -------
    str
        SHA-256 hex digest; equal content gives equal digests whatever the objects' identity.

    Examples
    --------
    >>> from linearize import load_turbine
    >>> content_digest(load_turbine("nrel5mw")) == content_digest(load_turbine("nrel5mw"))
    True
    """
    h = hashlib.sha256()
    _feed(h, obj)
    return h.hexdigest()


def _feed(h: Any, obj: Any) -> None:
    if is_dataclass(obj) and not isinstance(obj, type):
        h.update(type(obj).__name__.encode())
        for f in fields(obj):
            if not f.compare:           # provenance (a turbine's source path, its load report)
                continue
            if (f.metadata.get("digest_at_default") is False
                    and getattr(obj, f.name) == f.default):
                continue                # a field added later, at its default: the digest of before
            h.update(f.name.encode())
            _feed(h, getattr(obj, f.name))
    elif isinstance(obj, np.ndarray):
        h.update(str(obj.shape).encode())
        h.update(np.ascontiguousarray(obj, dtype=float).tobytes())
    elif isinstance(obj, dict):
        for k in sorted(obj, key=str):
            h.update(str(k).encode())
            _feed(h, obj[k])
    elif isinstance(obj, (list, tuple)):
        for v in obj:
            _feed(h, v)
    elif isinstance(obj, float) and math.isnan(obj):
        h.update(b"nan")
    else:
        h.update(repr(obj).encode())


# --------------------------------------------------------------------------------------------
# Loading
# --------------------------------------------------------------------------------------------
_SECTIONS: dict[str, type] = {
    "geometry": Geometry, "operation": Operation, "environment": Environment,
    "rotor": RotorMass, "nacelle": Nacelle, "drivetrain": Drivetrain, "generator": Generator,
    "pitch_actuator": PitchActuator, "structure": Damping,
}
_TOP_KEYS = {"schema_version", "name", "files", *_SECTIONS}
_FILE_KEYS = {"blade_aero", "airfoil_index", "blade_structure", "tower_structure", "mode_shapes"}


def available_turbines() -> list[str]:
    """Names of the turbines shipped as package data (``nrel5mw``, ``iea15mw``).

    Returns
    -------
    list of str
        The packaged turbines' names.
    """
    root = resources.files("linearize") / "data"
    return sorted(p.name for p in root.iterdir() if (p / "turbine.yaml").is_file())


def read_turbine_mapping(path: Path) -> dict[str, Any]:
    """The top-level mapping of a ``turbine.yaml`` file.

    Parameters
    ----------
    path : Path
        The file.

    Returns
    -------
    dict
        Its parsed YAML.

    Raises
    ------
    TurbineFileError
        If the file is not YAML or its top level is not a mapping.
    """
    try:
        raw = yaml.safe_load(path.read_text())
    except yaml.YAMLError as err:
        raise TurbineFileError(f"{path}: not valid YAML: {err}") from err
    if not isinstance(raw, dict):
        raise TurbineFileError(f"{path}: top level must be a mapping, got {type(raw).__name__}")
    return raw


def turbine_from_mapping(path: Path, raw: dict[str, Any]) -> Turbine:
    """A turbine from the mapping of a native ``turbine.yaml`` and the files it names.

    Parameters
    ----------
    path : Path
        The file (its folder holds the files the mapping names).
    raw : dict
        Its parsed YAML (:func:`read_turbine_mapping`).

    Returns
    -------
    Turbine

    Raises
    ------
    TurbineFileError
        Naming the file, the field and the allowed range.
    """
    check_keys(path, "top level", raw, _TOP_KEYS)
    check_schema_version(path, raw)
    sections = {}
    for sec, cls in _SECTIONS.items():
        sections[sec] = _build_section(path, sec, raw[sec], cls)
    files = raw["files"]
    check_keys(path, "files", files, _FILE_KEYS)
    base = path.parent
    scale = sections["rotor"].blade_mass_scale
    try:
        polars, index_of = _read_polars(base / str(files["airfoil_index"]), base)
        blade = _read_blade_aero(base / str(files["blade_aero"]), index_of)
        bstruct = _read_blade_structure(base / str(files["blade_structure"]), scale)
        tstruct = _read_tower_structure(base / str(files["tower_structure"]))
        modes = _read_mode_shapes(base / str(files["mode_shapes"]))
        return Turbine(name=str(raw["name"]), source=str(path), blade=blade, polars=polars,
                       blade_structure=bstruct, tower_structure=tstruct, mode_shapes=modes,
                       geometry=sections["geometry"], operation=sections["operation"],
                       environment=sections["environment"], rotor=sections["rotor"],
                       nacelle=sections["nacelle"], drivetrain=sections["drivetrain"],
                       generator=sections["generator"],
                       pitch_actuator=sections["pitch_actuator"], damping=sections["structure"])
    except TurbineFileError:
        raise
    except ValueError as err:
        raise TurbineFileError(f"{path}: {err}") from err


def check_schema_version(path: Path, raw: dict[str, Any]) -> None:
    """Raise unless a turbine file's ``schema_version`` is the one this release reads.

    Parameters
    ----------
    path : Path
        The file, for the message.
    raw : dict
        Its parsed YAML.

    Raises
    ------
    TurbineFileError
        Naming the version found and the one expected.
    """
    if raw["schema_version"] != SCHEMA_VERSION:
        raise TurbineFileError(f"{path}: schema_version must be {SCHEMA_VERSION}, got "
                               f"{raw['schema_version']!r}")


def check_keys(path: Path, where: str, d: Any, allowed: set[str]) -> None:
    """Raise naming the unknown and the missing keys of a section.

    Parameters
    ----------
    path : Path
        The file, for the message.
    where : str
        The section, for the message.
    d : Any
        The section's value (must be a mapping).
    allowed : set of str
        Its keys, all required.

    Raises
    ------
    TurbineFileError
        If ``d`` is not a mapping, or has unknown or missing keys.
    """
    if not isinstance(d, dict):
        raise TurbineFileError(f"{path}: section {where!r} must be a mapping")
    unknown = sorted(set(d) - allowed)
    missing = sorted(allowed - set(d))
    msg = []
    if unknown:
        msg.append(f"unknown keys {unknown}")
    if missing:
        msg.append(f"missing keys {missing}")
    if msg:
        raise TurbineFileError(f"{path}: section {where!r}: " + "; ".join(msg))


def _build_section(path: Path, sec: str, d: Any, cls: type) -> Any:
    meta = {f.metadata["key"]: f for f in fields(cls)}
    optional = {k for k, f in meta.items() if f.metadata.get("optional")}
    if isinstance(d, dict):
        d = {**{k: meta[k].default for k in optional if k not in d}, **d}
    check_keys(path, sec, d, set(meta))
    kwargs = {}
    for key, f in meta.items():
        v = d[key]
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise TurbineFileError(f"{path}: {sec}.{key} must be a number, got {v!r}")
        kwargs[f.name] = int(v) if f.name == "number_of_blades" else float(v) * f.metadata["scale"]
    try:
        return cls(**kwargs)
    except ValueError as err:
        raise TurbineFileError(f"{path}: {sec}: {err}") from err


def _read_csv(path: Path, required: tuple[str, ...],
              text_cols: tuple[str, ...] = (),
              optional: tuple[str, ...] = ()) -> dict[str, Any]:
    """The ``required`` columns of a CSV file, and those of ``optional`` it has (numbers unless
    in ``text_cols``); an error names the file, the line and the column."""
    if not path.is_file():
        raise TurbineFileError(f"{path}: file not found")
    with path.open(newline="") as fh:
        rows = [r for r in csv.reader(fh) if r and any(c.strip() for c in r)]
    if not rows:
        raise TurbineFileError(f"{path}: empty file")
    header = [h.strip() for h in rows[0]]
    missing = [c for c in required if c not in header]
    if missing:
        raise TurbineFileError(f"{path}: missing columns {missing}; has {header}")
    out: dict[str, Any] = {}
    for col in (*required, *(c for c in optional if c in header)):
        j = header.index(col)
        vals = []
        for i, row in enumerate(rows[1:], start=2):
            if j >= len(row):
                raise TurbineFileError(f"{path}: line {i} has no column {col!r}")
            cell = row[j].strip()
            if col in text_cols:
                vals.append(cell)
                continue
            try:
                v = float(cell)
            except ValueError:
                raise TurbineFileError(f"{path}: line {i}, column {col!r}: {cell!r} "
                                       f"is not a number") from None
            if not math.isfinite(v):
                raise TurbineFileError(f"{path}: line {i}, column {col!r}: {cell!r} "
                                       f"is not finite")
            vals.append(v)
        out[col] = vals if col in text_cols else np.array(vals)
    return out


def _require(path: Path, col: str, values: FloatArray, ok: Callable[[FloatArray], Any],
             allowed: str) -> None:
    bad = ~np.asarray(ok(values), dtype=bool)
    if np.any(bad):
        i = int(np.argmax(bad))
        raise TurbineFileError(f"{path}: column {col!r}, data row {i + 1}: {values[i]!r}; "
                               f"allowed {allowed}")


def _read_polars(index_path: Path, base: Path) -> tuple[tuple[Polar, ...], dict[int, int]]:
    """Read the airfoil index; its ``file`` column is relative to the turbine directory."""
    idx = _read_csv(index_path, ("af_id", "name", "file"), text_cols=("name", "file"),
                    optional=_UA_COLUMNS)
    polars = []
    index_of: dict[int, int] = {}
    for k, (af_id, name, file) in enumerate(zip(idx["af_id"], idx["name"], idx["file"])):
        p = base / file
        tab = _read_csv(p, ("alpha_deg", "cl", "cd"))
        try:
            polars.append(Polar(name=name, alpha_rad=np.radians(tab["alpha_deg"]),
                                cl=tab["cl"], cd=tab["cd"], ua=_ua_of(index_path, k, idx)))
        except ValueError as err:
            raise TurbineFileError(f"{p}: {err}") from err
        index_of[int(af_id)] = k
    return tuple(polars), index_of


#: the airfoil index's optional UA columns (all three or none)
_UA_COLUMNS = ("ua_alpha0_deg", "ua_Cn_alpha_per_rad", "ua_Cd0")


def _ua_of(path: Path, k: int, cols: dict[str, Any]) -> UAParams | None:
    """Airfoil k's UA coefficients from the index (None without the UA columns, or where
    C_n,alpha is 0: no UA data)."""
    if not all(c in cols for c in _UA_COLUMNS) or not cols["ua_Cn_alpha_per_rad"][k] > 0:
        return None
    try:
        return UAParams(alpha0_rad=math.radians(cols["ua_alpha0_deg"][k]),
                        cn_alpha=cols["ua_Cn_alpha_per_rad"][k], cd0=cols["ua_Cd0"][k])
    except ValueError as err:
        raise TurbineFileError(f"{path}: data row {k + 1}: {err}") from err


def _read_blade_aero(path: Path, index_of: dict[int, int]) -> BladeAero:
    t = _read_csv(path, ("RNodes_m_from_apex", "DRNodes_m", "AeroTwst_deg", "Chord_m", "af_id"))
    r = t["RNodes_m_from_apex"]
    _require(path, "RNodes_m_from_apex", r, lambda v: v > 0, "> 0 m")
    if np.any(np.diff(r) <= 0):
        i = int(np.argmax(np.diff(r) <= 0)) + 1
        raise TurbineFileError(f"{path}: column 'RNodes_m_from_apex' must be strictly increasing "
                               f"(non-monotonic span at data row {i + 1}: {r[i]!r} after "
                               f"{r[i - 1]!r})")
    _require(path, "DRNodes_m", t["DRNodes_m"], lambda v: v > 0, "> 0 m")
    _require(path, "Chord_m", t["Chord_m"], lambda v: v > 0, "> 0 m")
    _require(path, "AeroTwst_deg", t["AeroTwst_deg"], lambda v: np.abs(v) <= 90, "-90..90 deg")
    ids = t["af_id"].astype(int)
    _require(path, "af_id", t["af_id"], lambda v: np.isin(v.astype(int), list(index_of)),
             f"one of the airfoil index ids {sorted(index_of)}")
    return BladeAero(r=r, dr=t["DRNodes_m"], chord=t["Chord_m"],
                     twist_rad=np.radians(t["AeroTwst_deg"]),
                     airfoil=np.array([index_of[i] for i in ids]))


def _stations(path: Path, col: str, x: FloatArray) -> None:
    _require(path, col, x, lambda v: (v >= 0) & (v <= 1), "0..1")
    if np.any(np.diff(x) <= 0) or abs(x[0]) > 1e-9 or abs(x[-1] - 1) > 1e-9:
        raise TurbineFileError(f"{path}: column {col!r} must increase strictly from 0 to 1")


def _read_blade_structure(path: Path, scale: float) -> BladeStructure:
    cols = ("BlFract", "BMassDen_kg_per_m", "FlpStff_Nm2", "EdgStff_Nm2")
    t = _read_csv(path, cols, optional=("StrcTwst_deg",))
    _stations(path, "BlFract", t["BlFract"])
    for c in cols[1:]:
        _require(path, c, t[c], lambda v: v > 0, "> 0")
    twist = _optional(path, t, "StrcTwst_deg", lambda v: np.abs(v) <= 90, "-90..90 deg")
    if twist is not None:
        twist = np.radians(twist)
    return BladeStructure(span_fraction=t["BlFract"], mass_per_length=t["BMassDen_kg_per_m"] * scale,
                          flap_stiffness=t["FlpStff_Nm2"], edge_stiffness=t["EdgStff_Nm2"],
                          structural_twist_rad=twist)


def _optional(path: Path, t: dict[str, Any], col: str, ok: Callable[[FloatArray], Any],
              allowed: str) -> FloatArray | None:
    """An optional column of a table read by :func:`_read_csv`, checked (None when the file
    has no such column)."""
    if col not in t:
        return None
    _require(path, col, t[col], ok, allowed)
    return t[col]


def _read_tower_structure(path: Path) -> TowerStructure:
    cols = ("HtFract", "TMassDen_kg_per_m", "TwFAStif_Nm2", "TwSSStif_Nm2")
    t = _read_csv(path, cols, optional=("TwrDiam_m", "TwrCd"))
    _stations(path, "HtFract", t["HtFract"])
    for c in cols[1:]:
        _require(path, c, t[c], lambda v: v > 0, "> 0")
    diameter = _optional(path, t, "TwrDiam_m", lambda v: v > 0, "> 0")
    cd = _optional(path, t, "TwrCd", lambda v: (v >= 0) & (v <= 5), "0..5")
    return TowerStructure(height_fraction=t["HtFract"], mass_per_length=t["TMassDen_kg_per_m"],
                          fa_stiffness=t["TwFAStif_Nm2"], ss_stiffness=t["TwSSStif_Nm2"],
                          outer_diameter=diameter, drag_coefficient=cd)


def _read_mode_shapes(path: Path) -> ModeShapes:
    if not path.is_file():
        raise TurbineFileError(f"{path}: file not found")
    with path.open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    by_name = {r["mode"].strip(): r for r in rows if r.get("mode")}
    need = {"tower_fa1": "tower_fore_aft_1", "tower_ss1": "tower_side_side_1",
            "blade_flap1": "blade_flap_1"}
    missing = [m for m in need.values() if m not in by_name]
    if missing:
        raise TurbineFileError(f"{path}: missing modes {missing}")
    if "blade_edge_1" in by_name:
        need["blade_edge1"] = "blade_edge_1"
    kwargs = {}
    for fname, mode in need.items():
        try:
            kwargs[fname] = np.array([float(by_name[mode][f"c_x{k}"]) for k in range(2, 7)])
        except (KeyError, ValueError, TypeError) as err:
            raise TurbineFileError(f"{path}: mode {mode}: coefficients c_x2..c_x6 must be "
                                   f"numbers ({err})") from err
    try:
        return ModeShapes(**kwargs)
    except ValueError as err:
        raise TurbineFileError(f"{path}: {err}") from err

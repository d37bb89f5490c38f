"""Nonlinear wind-turbine plant: BEM rotor, flexible tower and blades, drivetrain, actuators.

The plant is a pure right-hand side ``f(t, x, u, d, params) -> dx/dt`` with an output map
``h(t, x, u, d, params) -> z`` (python-control's ``updfcn``/``outfcn`` form), usable with any
integrator; :func:`rk4_simulate` is the fixed-step RK4 stepper that comes with it.

States (Madsen et al. 2012, eq 16, come first)::

     0 tower_fa_displacement   x_t    tower-top fore-aft, positive downwind      [m]
     1 tower_fa_velocity       dx_t                                              [m/s]
     2 rotor_speed             omega_r                                           [rad/s]
     3 gen_speed               omega_g                                           [rad/s]
     4 shaft_torsion           theta = rotor angle - generator angle / N         [rad]
     5-7 pitch_1..3            beta_i, positive toward feather                   [rad]
     8 tower_ss_displacement   y_t    tower-top side-side, positive to +y        [m]
     9 tower_ss_velocity                                                         [m/s]
    10-12 flap_1..3            first flap mode, tip deflection, positive downwind [m]
    13-15 flap_rate_1..3                                                         [m/s]
    16 azimuth                 psi of blade 1, 0 = up, in the direction of rotation [rad]

Inputs ``u = (pitch_ref_1, pitch_ref_2, pitch_ref_3, gen_torque_ref)`` [rad, rad, rad, N m].
Disturbance ``d``: the free longitudinal wind speed at every blade element, (n_blade, n_r)
[m/s] (the reduced form with one speed per blade at 75 % span fills each blade's row).

Each degree of freedom switches on and off like FAST's (:class:`PlantConfig`): a switched-off
DOF keeps its states frozen (zero derivative), so the same plant yields Madsen's 8-state model,
Clemens's 7-state model and Do's model with blade flap.

Equations
---------
* Aerodynamics: :mod:`linearize.bem` (Madsen eqs 1-7) per element, with the element's relative
  velocity including tower fore-aft and side-side motion, tower-top rotation, flap velocity,
  shaft tilt and precone.
* Tower fore-aft (Madsen eq 10) and side-side: one assumed mode each (ElastoDyn polynomial
  shapes), modal mass and stiffness integrated from the distributed properties with gravity
  softening and the rotor-nacelle masses above the tower top; modal damping ratio from data.
* Blade flap: first flap mode per blade, centrifugally stiffened (K = K_0 + Omega^2 K_cf),
  inertially coupled to the tower fore-aft mode.
* Drivetrain (Madsen eq 11), generator power (eq 13), pitch servo (eqs 14-15), generator torque
  limits (eq 12; the rate limit acts on the held command in the stepper).
* Coleman tilt and yaw moments (Madsen eqs 8-9) are outputs.

References
----------
Madsen, Filsoe, Soltani (2012), IEEE CCA, doi:10.1109/CCA.2012.6402671.
Jonkman et al. (2009), NREL/TP-500-38060 (NREL 5-MW data).
Hansen (2015), Aerodynamics of Wind Turbines, ch. 11-12 (modal structural models).
"""
from __future__ import annotations

import math
from collections import namedtuple
from dataclasses import dataclass, field
from typing import Any

import numba as nb
import numpy as np

from linearize._typing import FloatArray
from linearize.bem import (
    MODE_NOLIMITS,
    AeroOptions,
    aero_flags,
    element_kernel,
    locate_cell,
    polar_table_of,
)
from linearize.errors import SimulationDivergedError
from linearize.turbine import Turbine, mode_shape
from linearize.validate import check_array, check_positive

__all__ = [
    "DOF_NAMES", "STATE_NAMES", "STATE_UNITS", "INPUT_NAMES", "INPUT_UNITS", "OUTPUT_NAMES",
    "OUTPUT_UNITS", "MADSEN_OUTPUTS", "PlantConfig", "PlantParams", "plant_params", "plant_rhs",
    "plant_outputs", "element_wind", "SteadyWind", "GridWind", "SimulationResult",
    "SimulationDivergedError", "rk4_simulate", "PlantStepper", "step_kernel",
    "structural_frequencies", "n_x", "n_u", "n_z",
]

DOF_NAMES = ("tower_fa", "tower_ss", "drivetrain", "generator", "blade_flap", "pitch_actuator",
             "blade_edge")

STATE_NAMES = (
    "tower_fa_displacement", "tower_fa_velocity", "rotor_speed", "gen_speed", "shaft_torsion",
    "pitch_1", "pitch_2", "pitch_3", "tower_ss_displacement", "tower_ss_velocity",
    "flap_1", "flap_2", "flap_3", "flap_rate_1", "flap_rate_2", "flap_rate_3", "azimuth",
    "edge_1", "edge_2", "edge_3", "edge_rate_1", "edge_rate_2", "edge_rate_3")
STATE_UNITS = ("m", "m/s", "rad/s", "rad/s", "rad", "rad", "rad", "rad", "m", "m/s",
               "m", "m", "m", "m/s", "m/s", "m/s", "rad", "m", "m", "m", "m/s", "m/s", "m/s")
INPUT_NAMES = ("pitch_ref_1", "pitch_ref_2", "pitch_ref_3", "gen_torque_ref")
INPUT_UNITS = ("rad", "rad", "rad", "N m")
OUTPUT_NAMES = (
    "gen_power", "pitch_1", "pitch_2", "pitch_3", "pitch_rate_1", "pitch_rate_2",
    "pitch_rate_3", "tower_fa_velocity", "rotor_speed", "shaft_torsion",
    "flap_moment_1", "flap_moment_2", "flap_moment_3",
    "edge_moment_1", "edge_moment_2", "edge_moment_3",
    "tower_base_fa_moment", "tower_base_ss_moment", "lss_torque", "tilt_moment", "yaw_moment",
    "azimuth", "aero_torque", "thrust", "aero_power", "gen_speed", "gen_torque",
    "tower_fa_acceleration", "tower_ss_acceleration", "tower_fa_displacement",
    "tower_ss_displacement")
OUTPUT_UNITS = (
    "W", "rad", "rad", "rad", "rad/s", "rad/s", "rad/s", "m/s", "rad/s", "rad",
    "N m", "N m", "N m", "N m", "N m", "N m", "N m", "N m", "N m", "N m", "N m",
    "rad", "N m", "N", "W", "rad/s", "N m", "m/s^2", "m/s^2", "m", "m")
#: The performance outputs z of Madsen et al. (2012) eq 17, in order.
MADSEN_OUTPUTS = OUTPUT_NAMES[:13]

n_x = len(STATE_NAMES)
n_u = len(INPUT_NAMES)
n_z = len(OUTPUT_NAMES)
_N_BLADE = 3

_IX = {n: i for i, n in enumerate(STATE_NAMES)}
_DENSE = (8,)                   # the strides of a 1-D C-contiguous float64 array


@dataclass(frozen=True)
class PlantConfig:
    """Which degrees of freedom and aerodynamic effects the plant has.

    Parameters
    ----------
    dofs : frozenset of str
        Enabled degrees of freedom, a subset of :data:`DOF_NAMES`. Default: all.
    aero : AeroOptions
        Aerodynamic switches (tilt, cone, gravity, loss models, ...).
    integration : {"midpoint", "trapezoid"}
        Spanwise load integration: element-centre midpoint rule with the element lengths
        (AeroDyn v13 / WT_Perf style) or trapezoid over the element centres with zero load at
        hub and tip (CCBlade style).
    """

    dofs: frozenset[str] = frozenset(DOF_NAMES)
    aero: AeroOptions = field(default_factory=AeroOptions)
    integration: str = "midpoint"

    def __post_init__(self) -> None:
        dofs = frozenset(self.dofs)
        unknown = sorted(dofs - set(DOF_NAMES))
        if unknown:
            raise ValueError(f"dofs has unknown names {unknown}; allowed {list(DOF_NAMES)}")
        object.__setattr__(self, "dofs", dofs)
        if self.integration not in ("midpoint", "trapezoid"):
            raise ValueError(f"integration must be 'midpoint' or 'trapezoid', "
                             f"got {self.integration!r}")

    @classmethod
    def madsen(cls, aero: AeroOptions | None = None) -> "PlantConfig":
        """Madsen et al. (2012) 8-state model: tower fore-aft, drivetrain, generator, pitch."""
        return cls(frozenset({"tower_fa", "drivetrain", "generator", "pitch_actuator"}),
                   aero or AeroOptions())

    @classmethod
    def clemens(cls, aero: AeroOptions | None = None) -> "PlantConfig":
        """Clemens et al. 7-state model: tower fore-aft and side-side, drivetrain, generator."""
        return cls(frozenset({"tower_fa", "tower_ss", "drivetrain", "generator"}),
                   aero or AeroOptions())

    @classmethod
    def do(cls, aero: AeroOptions | None = None) -> "PlantConfig":
        """Do et al. model: tower fore-aft, drivetrain, generator, blade flap, pitch."""
        return cls(frozenset({"tower_fa", "drivetrain", "generator", "blade_flap",
                              "pitch_actuator"}), aero or AeroOptions())

    def active_states(self) -> tuple[str, ...]:
        """Names of the states that evolve under this configuration (azimuth excluded).

        With a rigid drivetrain (no ``drivetrain`` DOF) the generator speed is N times the rotor
        speed: it is not a state of the linear models (an exact zero, uncontrollable eigenvalue
        otherwise), and the outputs that depend on it act through the rotor speed.

        Returns
        -------
        tuple of str
            Names of :data:`STATE_NAMES`, in their order.
        """
        groups = {
            "tower_fa": ("tower_fa_displacement", "tower_fa_velocity"),
            "generator": ("rotor_speed", "gen_speed"),
            "drivetrain": ("shaft_torsion",),
            "pitch_actuator": ("pitch_1", "pitch_2", "pitch_3"),
            "tower_ss": ("tower_ss_displacement", "tower_ss_velocity"),
            "blade_flap": ("flap_1", "flap_2", "flap_3", "flap_rate_1", "flap_rate_2",
                           "flap_rate_3"),
            "blade_edge": ("edge_1", "edge_2", "edge_3", "edge_rate_1", "edge_rate_2",
                           "edge_rate_3"),
        }
        on = {n for d in self.dofs for n in groups[d]}
        if "drivetrain" not in self.dofs:
            # rigid shaft: the generator turns at N times the rotor, no state of its own
            on.discard("shaft_torsion")
            on.discard("gen_speed")
        return tuple(n for n in STATE_NAMES if n in on)


_Pack = namedtuple("_Pack", [
    "dof", "flags", "opt", "nb", "rho", "grav", "rtip", "rhub", "zhub", "cone", "tilt",
    "r", "w", "chord", "twist", "af", "phi_flap", "table", "alpha0", "dalpha",
    "ngear", "eta_gen", "j_rot", "j_gen", "k_shaft", "c_shaft",
    "m_fa", "k_fa", "c_fa", "hub_fa", "slope_fa", "m_ss", "k_ss", "c_ss", "hub_ss", "slope_ss",
    "m_b", "k_b", "k_cf", "c_b", "m_c", "s1", "s_phi_s", "s_phi_r", "i_edge",
    "tau_p", "rate_p", "min_p", "max_p", "min_tq", "max_tq",
    "fa_static", "fa_pdelta", "fa_inertia", "ss_pdelta", "ss_inertia",
    "phi_edge", "m_e", "k_e", "k_cf_e", "c_e", "s_e", "g_e", "s_phie_s"])


@dataclass(frozen=True)
class PlantParams:
    """Numbers the plant equations use, derived from a :class:`Turbine` and a config.

    Parameters
    ----------
    turbine : Turbine
    config : PlantConfig
    rotor_inertia : float
        Rotor (hub + blades) inertia about the shaft [kg m^2].
    rotor_mass : float
        Hub plus blades [kg].
    blade_mass : float
        One blade [kg].
    tower_fa_modal_mass, tower_fa_modal_stiffness, tower_fa_modal_damping : float
        Fore-aft first mode referred to the tower-top displacement [kg, N/m, N s/m].
    tower_ss_modal_mass, tower_ss_modal_stiffness, tower_ss_modal_damping : float
        Side-side first mode [kg, N/m, N s/m].
    blade_modal_mass, blade_modal_stiffness, blade_centrifugal_stiffness : float
        Flap mode per blade referred to the tip deflection: mass [kg], non-rotating stiffness
        [N/m], centrifugal stiffness per Omega^2 [N s^2/m].
    blade_modal_damping : float
        [N s/m].
    blade_tower_coupling : float
        int m phi ds, the flap mode's inertial coupling to rotor translation [kg].
    edge_modal_mass, edge_modal_stiffness, edge_centrifugal_stiffness : float
        First edgewise mode per blade referred to the tip deflection (ElastoDyn's edge mode
        shape and EdgStff): int m phi_e^2 [kg], int EI_e phi_e''^2 [N/m], int N phi_e'^2 per
        Omega^2 [N s^2/m]; NaN when the turbine has no edge mode shape.
    edge_rotor_coupling : float
        int m phi_e r ds, the edge mode's inertial coupling to rotor rotation [kg m].
    """

    turbine: Turbine
    config: PlantConfig
    rotor_inertia: float
    rotor_mass: float
    blade_mass: float
    tower_fa_modal_mass: float
    tower_fa_modal_stiffness: float
    tower_fa_modal_damping: float
    tower_ss_modal_mass: float
    tower_ss_modal_stiffness: float
    tower_ss_modal_damping: float
    blade_modal_mass: float
    blade_modal_stiffness: float
    blade_centrifugal_stiffness: float
    blade_modal_damping: float
    blade_tower_coupling: float
    edge_modal_mass: float = math.nan
    edge_modal_stiffness: float = math.nan
    edge_centrifugal_stiffness: float = math.nan
    edge_rotor_coupling: float = math.nan
    pack: Any = field(repr=False, compare=False, default=None)

    def dof(self, name: str) -> bool:
        """True if the degree of freedom ``name`` is on.

        Parameters
        ----------
        name : str
            A name of :data:`DOF_NAMES`.

        Returns
        -------
        bool
            Whether it is on.
        """
        return name in self.config.dofs


def _cumtrapz_from_end(y: FloatArray, x: FloatArray) -> FloatArray:
    """int_x^end y dx at each x."""
    seg = 0.5 * (y[1:] + y[:-1]) * np.diff(x)
    out = np.zeros_like(x)
    out[:-1] = np.cumsum(seg[::-1])[::-1]
    return out


def plant_params(turbine: Turbine, config: PlantConfig | None = None) -> PlantParams:
    """Derive modal, inertial and geometric plant parameters from the turbine data.

    Modal mass and stiffness of each assumed mode phi (Hansen 2015, ch. 11):
    ``m = int mu phi^2 + sum_bodies``, ``k = int EI phi''^2 - g int N(h) phi'^2`` (gravity
    softening with N the weight above h), damping ``c = 2 zeta sqrt(k m)``.

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    config : PlantConfig, optional
        Degrees of freedom and aerodynamic options (default: all on).

    Returns
    -------
    PlantParams
        The plant's parameters.
    """
    cfg = config or PlantConfig()
    t = turbine
    g = t.geometry
    grav = t.environment.gravity
    nblade = g.number_of_blades
    cone = g.precone_rad if cfg.aero.cone else 0.0
    tilt = g.shaft_tilt_rad if cfg.aero.tilt else 0.0

    # --- blade distributed properties on a fine grid
    lb = g.tip_radius - g.hub_radius
    xs = np.linspace(0.0, 1.0, 2001)
    s = xs * lb
    bs = t.blade_structure
    mu = np.interp(xs, bs.span_fraction, bs.mass_per_length)
    ei = np.interp(xs, bs.span_fraction, bs.flap_stiffness)
    phi = mode_shape(t.mode_shapes.blade_flap1, xs)
    dphi = mode_shape(t.mode_shapes.blade_flap1, xs, 1) / lb
    ddphi = mode_shape(t.mode_shapes.blade_flap1, xs, 2) / lb**2
    blade_mass = float(np.trapezoid(mu, s))
    s1 = float(np.trapezoid(mu * s, s))
    m_b = float(np.trapezoid(mu * phi**2, s))
    k_b = float(np.trapezoid(ei * ddphi**2, s))
    tension = _cumtrapz_from_end(mu * (g.hub_radius + s), s)   # per Omega^2
    k_cf = float(np.trapezoid(tension * dphi**2, s))
    m_c = float(np.trapezoid(mu * phi, s))
    s_phi_s = float(np.trapezoid(mu * phi * s, s))
    s_phi_r = float(np.trapezoid(mu * phi * (g.hub_radius + s), s))
    i_edge = float(np.trapezoid(mu * s * (g.hub_radius + s), s))
    c_b = 2.0 * t.damping.blade * math.sqrt(k_b * m_b)
    j_blade = float(np.trapezoid(mu * ((g.hub_radius + s) * math.cos(g.precone_rad)) ** 2, s))
    rotor_inertia = t.rotor.hub_inertia + nblade * j_blade
    rotor_mass = t.rotor.hub_mass + nblade * blade_mass

    # --- tower
    ht = g.tower_height - g.tower_base_height          # flexible length, clamped at its base
    xh = np.linspace(0.0, 1.0, 2001)
    h = xh * ht
    ts = t.tower_structure
    mt = np.interp(xh, ts.height_fraction, ts.mass_per_length)
    m_top = rotor_mass + t.nacelle.mass
    # bodies above the tower top: (mass, downwind x, height above top, rotary inertia in plane)
    bodies = ((rotor_mass, -g.overhang, g.twr2shft),
              (t.nacelle.mass, g.nacelle_cm_downwind, g.nacelle_cm_vertical))
    weight_above = grav * (_cumtrapz_from_end(mt, h) + m_top)

    def tower_mode(coeffs: FloatArray, ei_tab: FloatArray, rot_inertia: float,
                   zeta: float) -> tuple[float, float, float, float, float, float, float]:
        ph = mode_shape(coeffs, xh)
        dph = mode_shape(coeffs, xh, 1) / ht
        ddph = mode_shape(coeffs, xh, 2) / ht**2
        eit = np.interp(xh, ts.height_fraction, ei_tab)
        slope = float(dph[-1])
        mass = float(np.trapezoid(mt * ph**2, h)) + rot_inertia * slope**2
        inertia_moment = float(np.trapezoid(mt * ph * h, h)) + rot_inertia * slope
        k = float(np.trapezoid(eit * ddph**2, h)) - float(np.trapezoid(weight_above * dph**2, h))
        for mb, xb, zb in bodies:
            mass += mb * ((1.0 + zb * slope) ** 2 + (xb * slope) ** 2)
            inertia_moment += mb * (ht + zb) * (1.0 + zb * slope)
            k -= grav * mb * zb * slope**2
        if k <= 0:
            raise ValueError(f"tower modal stiffness {k:g} N/m is not positive: the tower "
                             f"buckles under the top mass")
        c = 2.0 * zeta * math.sqrt(k * mass)
        pdelta = grav * (m_top + float(np.trapezoid(mt * ph, h)))
        return mass, k, c, 1.0 + g.twr2shft * slope, slope, pdelta, inertia_moment

    m_fa, k_fa, c_fa, hub_fa, slope_fa, pd_fa, in_fa = tower_mode(
        t.mode_shapes.tower_fa1, ts.fa_stiffness, 0.5 * rotor_inertia, t.damping.tower_fa)
    m_ss, k_ss, c_ss, hub_ss, slope_ss, pd_ss, in_ss = tower_mode(
        t.mode_shapes.tower_ss1, ts.ss_stiffness, 0.0, t.damping.tower_ss)

    # --- aero element data
    b = t.blade
    if cfg.integration == "midpoint":
        weights = b.dr.copy()
    else:
        rr = np.concatenate(([g.hub_radius], b.r, [g.tip_radius]))
        weights = 0.5 * (rr[2:] - rr[:-2])
    phi_el = mode_shape(t.mode_shapes.blade_flap1, (b.r - g.hub_radius) / lb)
    edge, edge_pack = _edge_mode(t, s, mu, tension)
    if "blade_edge" in cfg.dofs and not edge:
        raise ValueError("config.dofs has 'blade_edge' but the turbine's mode-shape table has "
                         "no 'blade_edge_1' row; add it or leave the DOF out "
                         f"(PlantConfig(dofs={sorted(cfg.dofs - {'blade_edge'})!r}))")
    tab = polar_table_of(t)
    pa = t.pitch_actuator
    dofs = np.array([d in cfg.dofs for d in DOF_NAMES], dtype=np.int64)
    opt = np.array([cfg.aero.gravity], dtype=np.int64)
    fa_static = grav * (t.nacelle.mass * g.nacelle_cm_downwind - rotor_mass * g.overhang)
    pack = _Pack(
        dof=dofs, flags=aero_flags(cfg.aero), opt=opt, nb=float(nblade),
        rho=t.environment.air_density, grav=grav, rtip=g.tip_radius, rhub=g.hub_radius,
        zhub=g.hub_height, cone=cone, tilt=tilt, r=b.r, w=weights, chord=b.chord,
        twist=b.twist_rad, af=b.airfoil, phi_flap=phi_el, table=tab.table, alpha0=tab.alpha0,
        dalpha=tab.dalpha, ngear=t.drivetrain.gearbox_ratio,
        eta_gen=t.drivetrain.generator_efficiency * t.drivetrain.gearbox_efficiency,
        j_rot=rotor_inertia, j_gen=t.drivetrain.generator_inertia,
        k_shaft=t.drivetrain.shaft_stiffness, c_shaft=t.drivetrain.shaft_damping,
        m_fa=m_fa, k_fa=k_fa, c_fa=c_fa, hub_fa=hub_fa, slope_fa=slope_fa,
        m_ss=m_ss, k_ss=k_ss, c_ss=c_ss, hub_ss=hub_ss, slope_ss=slope_ss,
        m_b=m_b, k_b=k_b, k_cf=k_cf, c_b=c_b, m_c=m_c * hub_fa, s1=s1, s_phi_s=s_phi_s,
        s_phi_r=s_phi_r, i_edge=i_edge, tau_p=pa.time_constant, rate_p=pa.max_rate_rad_s,
        min_p=pa.min_pitch_rad, max_p=pa.max_pitch_rad, min_tq=t.generator.min_torque,
        max_tq=t.generator.max_torque, fa_static=fa_static, fa_pdelta=pd_fa,
        fa_inertia=in_fa, ss_pdelta=pd_ss, ss_inertia=in_ss, **edge_pack)
    return PlantParams(
        turbine=t, config=cfg, rotor_inertia=rotor_inertia, rotor_mass=rotor_mass,
        blade_mass=blade_mass, tower_fa_modal_mass=m_fa, tower_fa_modal_stiffness=k_fa,
        tower_fa_modal_damping=c_fa, tower_ss_modal_mass=m_ss, tower_ss_modal_stiffness=k_ss,
        tower_ss_modal_damping=c_ss, blade_modal_mass=m_b, blade_modal_stiffness=k_b,
        blade_centrifugal_stiffness=k_cf, blade_modal_damping=c_b, blade_tower_coupling=m_c,
        **edge, pack=pack)


def _edge_mode(t: Turbine, s: FloatArray, mu: FloatArray,
               tension: FloatArray) -> tuple[dict[str, float], dict[str, Any]]:
    """Edgewise modal properties of one blade (assumed mode, as the flap one; Hansen 2015,
    ch. 11) on the span grid ``s`` [m] from the root, with mass per length ``mu`` and the
    centrifugal tension per Omega^2 ``tension``: the :class:`PlantParams` fields and the
    kernel's (zeros when the turbine has no edge mode shape). The damping ratio is the flap
    mode's (ElastoDyn's BldEdDmp1 = BldFlDmp1 = 0.477 % for the NREL 5-MW)."""
    shape = t.mode_shapes.blade_edge1
    b = t.blade
    if shape is None:
        zero = dict.fromkeys(("m_e", "k_e", "k_cf_e", "c_e", "s_e", "g_e", "s_phie_s"), 0.0)
        return {}, {"phi_edge": np.zeros_like(b.r), **zero}
    g = t.geometry
    lb = g.tip_radius - g.hub_radius
    xs = s / lb
    phi = mode_shape(shape, xs)
    dphi = mode_shape(shape, xs, 1) / lb
    ddphi = mode_shape(shape, xs, 2) / lb**2
    ei = np.interp(xs, t.blade_structure.span_fraction, t.blade_structure.edge_stiffness)
    m_e = float(np.trapezoid(mu * phi**2, s))
    k_e = float(np.trapezoid(ei * ddphi**2, s))
    k_cf_e = float(np.trapezoid(tension * dphi**2, s))
    s_e = float(np.trapezoid(mu * phi * (g.hub_radius + s), s))
    public = {"edge_modal_mass": m_e, "edge_modal_stiffness": k_e,
              "edge_centrifugal_stiffness": k_cf_e, "edge_rotor_coupling": s_e}
    kernel = {"phi_edge": mode_shape(shape, (b.r - g.hub_radius) / lb), "m_e": m_e, "k_e": k_e,
              "k_cf_e": k_cf_e, "c_e": 2.0 * t.damping.blade * math.sqrt(k_e * m_e),
              "s_e": s_e, "g_e": float(np.trapezoid(mu * phi, s)),
              "s_phie_s": float(np.trapezoid(mu * phi * s, s))}
    return public, kernel


# --------------------------------------------------------------------------------------------
# Kernels
# --------------------------------------------------------------------------------------------
_JIT = dict(cache=True, error_model="numpy")
_TWO_PI_3 = 2.0 * math.pi / 3.0


@nb.njit(**_JIT)
def _clip(v, lo, hi):  # pragma: no cover - compiled
    return lo + 0.0 * v if v.real < lo else (hi + 0.0 * v if v.real > hi else v)


@nb.njit(**_JIT)
def evaluate_plant(x, u, wind, p, hint, mode):  # pragma: no cover - compiled
    """Derivatives, outputs and BEM state at one instant (generic over float and complex).

    ``wind``: (3, n_r) [m/s]. ``hint``: (4, 3, n_r) BEM state of a nearby earlier solve --
    inflow angle, residual slope, axial and tangential induced velocities (NaN: none); the same
    layout is returned.
    ``mode``: bits of :mod:`linearize.bem` (frozen wake, complex step, tight, no limits).
    """
    dof_fa, dof_ss, dof_dt, dof_gen, dof_flap, dof_pitch = (p.dof[0], p.dof[1], p.dof[2],
                                                            p.dof[3], p.dof[4], p.dof[5])
    dof_edge = p.dof[6]
    limits = (mode & MODE_NOLIMITS) == 0
    nr = p.r.size
    dx = np.zeros(n_x, dtype=x.dtype)
    z = np.zeros(31, dtype=x.dtype)
    bem = np.empty((4, 3, nr), dtype=x.dtype)
    xd = x[1]
    wr = x[2]
    wg = x[3]
    th = x[4]
    yd = x[9]
    psi = x[16]
    # pitch actually applied and its rate
    pitch = np.empty(3, dtype=x.dtype)
    prate = np.zeros(3, dtype=x.dtype)
    for i in range(3):
        ref = _clip(u[i], p.min_p, p.max_p) if limits else u[i]
        if dof_pitch:
            pitch[i] = x[5 + i]
            rate = (ref - x[5 + i]) / p.tau_p
            prate[i] = _clip(rate, -p.rate_p, p.rate_p) if limits else rate
        else:
            pitch[i] = ref
    tq = _clip(u[3], p.min_tq, p.max_tq) if limits else u[3]
    cc = math.cos(p.cone)
    sc = math.sin(p.cone)
    ct = math.cos(p.tilt)
    st = math.sin(p.tilt)
    vhub_x = p.hub_fa * xd if dof_fa else 0.0 * xd
    vhub_y = p.hub_ss * yd if dof_ss else 0.0 * yd
    nod = p.slope_fa * xd if dof_fa else 0.0 * xd       # tower-top pitch rate
    roll = -p.slope_ss * yd if dof_ss else 0.0 * yd     # tower-top roll rate about +x
    torque = 0.0 * wr
    thrust = 0.0 * wr
    fy = 0.0 * wr
    mtilt = 0.0 * wr
    myaw = 0.0 * wr
    mflap_aero = np.zeros(3, dtype=x.dtype)
    medge_aero = np.zeros(3, dtype=x.dtype)
    gq = np.zeros(3, dtype=x.dtype)
    ge = np.zeros(3, dtype=x.dtype)
    for i in range(3):
        psi_i = psi + i * _TWO_PI_3
        sp = np.sin(psi_i)
        cp = np.cos(psi_i)
        qd = x[13 + i] if dof_flap else 0.0 * x[13 + i]
        ed = x[20 + i] if dof_edge else 0.0 * x[20 + i]
        tor_i = 0.0 * wr
        thr_i = 0.0 * wr
        mf = 0.0 * wr
        me = 0.0 * wr
        gqi = 0.0 * wr
        for j in range(nr):
            rj = p.r[j]
            vrel = wind[i, j] - vhub_x - nod * rj * cc * cp
            vx = vrel * (ct * cc + st * sc * cp) - qd * p.phi_flap[j]
            vy = (wr + roll) * rj * cc + vrel * st * sp - vhub_y * cp + ed * p.phi_edge[j]
            npr, tpr, ph, sl, u_ind, v_ind = element_kernel(
                vx, vy, rj, p.chord[j], p.twist[j] + pitch[i], p.af[j], p.table, p.alpha0,
                p.dalpha, p.nb, p.rtip, p.rhub, p.flags, p.rho, hint[0, i, j].real,
                hint[1, i, j].real, hint[2, i, j].real, hint[3, i, j].real, mode)
            bem[0, i, j] = ph
            bem[1, i, j] = sl
            bem[2, i, j] = u_ind
            bem[3, i, j] = v_ind
            wj = p.w[j]
            tor_i += tpr * rj * cc * wj
            thr_i += npr * cc * wj
            mf += npr * (rj - p.rhub) * wj
            me += tpr * (rj - p.rhub) * wj
            gqi += npr * p.phi_flap[j] * wj
            ge[i] += tpr * p.phi_edge[j] * wj
            fy += -tpr * cp * wj
        torque += tor_i
        thrust += thr_i
        mflap_aero[i] = mf
        medge_aero[i] = me
        gq[i] = gqi
        if p.opt[0]:
            ge[i] += p.grav * p.g_e * sp * ct
        mtilt += mf * cp
        myaw += mf * sp
    # edgewise modes: elastic, damping and aerodynamic/gravity forces F_i; the rotor and the
    # edges share the inertia S_e = int m phi_e r ds (M_e q'' + S_e Omega' = F)
    fe = np.zeros(3, dtype=x.dtype)
    cpl = 0.0 * wr
    j_cut = 0.0
    if dof_edge:
        ke = p.k_e + wr * wr * (p.k_cf_e - p.m_e)
        for i in range(3):
            fe[i] = ge[i] - p.c_e * x[20 + i] - ke * x[17 + i]
        cpl = p.s_e / p.m_e * (fe[0] + fe[1] + fe[2])
        j_cut = 3.0 * p.s_e * p.s_e / p.m_e
    # drivetrain (Madsen eq 11), rotor inertia less what the edge modes carry
    if dof_gen:
        if dof_dt:
            qs = p.k_shaft * th + p.c_shaft * (wr - wg / p.ngear)
            dwr = (torque - qs - cpl) / (p.j_rot - j_cut)
            dwg = (qs / p.ngear - tq) / p.j_gen
            dth = wr - wg / p.ngear
        else:
            jt = p.j_rot + p.ngear * p.ngear * p.j_gen
            dwr = (torque - p.ngear * tq - cpl) / (jt - j_cut)
            dwg = p.ngear * dwr
            dth = 0.0 * dwr
    else:
        dwr = 0.0 * wr
        dwg = 0.0 * wr
        dth = 0.0 * wr
        qs = p.k_shaft * th if dof_dt else p.ngear * tq
    edd = np.zeros(3, dtype=x.dtype)
    if dof_edge:
        for i in range(3):
            edd[i] = (fe[i] - p.s_e * dwr) / p.m_e
    if dof_gen and not dof_dt:
        # rotor side: J_r Omega' + S_e sum q'' = Q_aero - Q_shaft
        qs = torque - p.j_rot * dwr - p.s_e * (edd[0] + edd[1] + edd[2])
    # reaction torque on the nacelle about +x (rotor and generator spin the same way)
    m_react = tq + (1.0 - 1.0 / p.ngear) * qs
    # tower fore-aft + blade flap (inertially coupled)
    omega2 = wr * wr
    kq = p.k_b + omega2 * p.k_cf
    fq = np.zeros(3, dtype=x.dtype)
    for i in range(3):
        if dof_flap:
            fq[i] = gq[i] - p.c_b * x[13 + i] - kq * x[10 + i]
    xdd = 0.0 * wr
    if dof_fa:
        ft = (thrust * ct * p.hub_fa + mtilt * p.slope_fa - p.c_fa * xd - p.k_fa * x[0])
        if dof_flap:
            ratio = p.m_c / p.m_b
            xdd = (ft - ratio * (fq[0] + fq[1] + fq[2])) / (p.m_fa - 3.0 * p.m_c * ratio)
        else:
            xdd = ft / p.m_fa
    qdd = np.zeros(3, dtype=x.dtype)
    if dof_flap:
        for i in range(3):
            qdd[i] = (fq[i] - p.m_c * xdd) / p.m_b
    ydd = 0.0 * wr
    if dof_ss:
        fss = fy * p.hub_ss - m_react * p.slope_ss - p.c_ss * yd - p.k_ss * x[8]
        ydd = fss / p.m_ss
    # derivatives
    if dof_fa:
        dx[0] = xd
        dx[1] = xdd
    dx[2] = dwr
    dx[3] = dwg
    dx[4] = dth
    if dof_pitch:
        dx[5] = prate[0]
        dx[6] = prate[1]
        dx[7] = prate[2]
    if dof_ss:
        dx[8] = yd
        dx[9] = ydd
    if dof_flap:
        for i in range(3):
            dx[10 + i] = x[13 + i]
            dx[13 + i] = qdd[i]
    dx[16] = wr
    if dof_edge:
        for i in range(3):
            dx[17 + i] = x[20 + i]
            dx[20 + i] = edd[i]
    # outputs
    z[0] = p.eta_gen * tq * wg
    for i in range(3):
        z[1 + i] = pitch[i]
        z[4 + i] = prate[i]
    z[7] = xd
    z[8] = wr
    z[9] = th
    for i in range(3):
        psi_i = psi + i * _TWO_PI_3
        q = x[10 + i] if dof_flap else 0.0 * x[10 + i]
        mf = (mflap_aero[i] - p.hub_fa * xdd * p.s1 - qdd[i] * p.s_phi_s
              - omega2 * q * p.s_phi_r)
        me = medge_aero[i] - dwr * p.i_edge - edd[i] * p.s_phie_s
        if p.opt[0]:
            me += p.grav * p.s1 * np.sin(psi_i) * ct
        z[10 + i] = mf
        z[13 + i] = me
    z[16] = (thrust * ct * p.zhub + mtilt + p.fa_static + p.fa_pdelta * x[0]
             - p.fa_inertia * xdd)
    z[17] = m_react - fy * p.zhub - p.ss_pdelta * x[8] + p.ss_inertia * ydd
    z[18] = qs
    tl = 0.0 * wr
    yw = 0.0 * wr
    for i in range(3):
        psi_i = psi + i * _TWO_PI_3
        tl += np.cos(psi_i) * z[10 + i]
        yw += np.sin(psi_i) * z[10 + i]
    z[19] = 2.0 / 3.0 * tl
    z[20] = 2.0 / 3.0 * yw
    z[21] = psi - 2.0 * math.pi * math.floor(psi.real / (2.0 * math.pi))
    z[22] = torque
    z[23] = thrust
    z[24] = torque * wr
    z[25] = wg
    z[26] = tq
    z[27] = xdd
    z[28] = ydd
    z[29] = x[0]
    z[30] = x[8]
    return dx, z, bem


# wind kinds: 0 = steady power law (speed, exponent), 1 = grid (t, y, z) trilinear
@nb.njit(**_JIT)
def _element_positions(psi, p):  # pragma: no cover - compiled
    nr = p.r.size
    ys = np.empty((3, nr))
    zs = np.empty((3, nr))
    cc = math.cos(p.cone)
    ct = math.cos(p.tilt)
    for i in range(3):
        psi_i = psi + i * _TWO_PI_3
        s = math.sin(psi_i)
        c = math.cos(psi_i)
        for j in range(nr):
            rr = p.r[j] * cc
            ys[i, j] = -rr * s
            zs[i, j] = p.zhub + rr * c * ct
    return ys, zs


@nb.njit(**_JIT)
def sample_wind(t, psi, p, kind, wpar, grid):  # pragma: no cover - compiled
    ys, zs = _element_positions(psi, p)
    nr = p.r.size
    out = np.empty((3, nr))
    if kind == 0:
        v = wpar[0]
        a = wpar[1]
        for i in range(3):
            for j in range(nr):
                zz = zs[i, j] if zs[i, j] > 1e-3 else 1e-3
                out[i, j] = v * (zz / p.zhub) ** a if a != 0.0 else v
        return out
    t0, dt, y0, dy, z0, dz = wpar[0], wpar[1], wpar[2], wpar[3], wpar[4], wpar[5]
    nt, ny, nz = grid.shape
    if nt == 1:
        it, at = 0, 0.0
    else:
        it, at = locate_cell((t - t0) / dt, nt)
    for i in range(3):
        for j in range(nr):
            iy, ay = locate_cell((ys[i, j] - y0) / dy, ny)
            iz, az = locate_cell((zs[i, j] - z0) / dz, nz)
            acc = 0.0
            for kt in range(2):
                if nt == 1 and kt == 1:
                    break
                wt = (1.0 - at) if kt == 0 else at
                if nt == 1:
                    wt = 1.0
                g = grid[it + kt]
                acc += wt * ((1 - ay) * (1 - az) * g[iy, iz] + ay * (1 - az) * g[iy + 1, iz]
                             + (1 - ay) * az * g[iy, iz + 1] + ay * az * g[iy + 1, iz + 1])
            out[i, j] = acc
    return out


@nb.njit(**_JIT)
def _rk4(t, x, u, h, p, kind, wpar, grid, hint, dphi):  # pragma: no cover - compiled
    """One RK4 step. ``hint`` seeds the BEM solves; ``dphi`` is each element's change of
    inflow angle over the previous step, used to extrapolate the hints of stages 2 and 4.

    Returns the new state, the outputs at t, the stage-4 BEM state and the new ``dphi``.
    """
    w1 = sample_wind(t, x[16], p, kind, wpar, grid)
    k1, z, ph1 = evaluate_plant(x, u, w1, p, hint, 0)
    x2 = x + 0.5 * h * k1
    hint2 = ph1.copy()
    hint2[0] += 0.5 * dphi
    k2, _, ph2 = evaluate_plant(x2, u, sample_wind(t + 0.5 * h, x2[16], p, kind, wpar, grid), p, hint2,
                       0)
    x3 = x + 0.5 * h * k2
    k3, _, ph3 = evaluate_plant(x3, u, sample_wind(t + 0.5 * h, x3[16], p, kind, wpar, grid), p, ph2, 0)
    x4 = x + h * k3
    hint4 = ph3.copy()
    hint4[0] += 0.5 * dphi
    k4, _, ph4 = evaluate_plant(x4, u, sample_wind(t + h, x4[16], p, kind, wpar, grid), p, hint4, 0)
    xn = x + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    new_dphi = ph4[0] - ph1[0]
    for i in range(new_dphi.shape[0]):
        for j in range(new_dphi.shape[1]):
            if new_dphi[i, j] != new_dphi[i, j]:
                new_dphi[i, j] = 0.0
    return xn, z, ph4, new_dphi


@nb.njit(**_JIT)
def _bad_state(x, lim):  # pragma: no cover - compiled
    # lim: (2, n_x) lower and upper bounds
    for k in range(x.size):
        if not (lim[0, k] <= x[k] <= lim[1, k]):   # also catches NaN
            return k
    return -1


@nb.njit(**_JIT)
def _rk4_into(t, x, u, h, p, kind, wpar, grid, hint, dphi, lim, x_out, z_out):  # pragma: no cover
    """:func:`_rk4` with its results written into ``x_out``, ``z_out`` and the warm start
    (``hint``, ``dphi``) in place; returns the first state outside the envelope ``lim`` (-1:
    none). Nothing is returned to Python but an int: no arrays to box at every step."""
    xn, z, ph4, nd = _rk4(t, x, u, h, p, kind, wpar, grid, hint, dphi)
    x_out[:] = xn
    z_out[:] = z
    hint[:] = ph4
    dphi[:] = nd
    return _bad_state(xn, lim)


#: The compiled RK4 step of :meth:`PlantStepper.step_into`, for closed loops compiled with their
#: controller: ``step_kernel(t, x, u, *stepper.kernel_args(), x_out, z_out)`` in nopython code
#: advances the plant and the stepper's warm start and returns the first state outside the
#: envelope (-1: none).
step_kernel = _rk4_into


@nb.njit(**_JIT)
def _simulate(x0, u_seq, t0, h, n_steps, p, kind, wpar, grid, lim, rate_tq):  # pragma: no cover
    nx = x0.size
    xs = np.empty((n_steps + 1, nx))
    zs = np.empty((n_steps + 1, 31))
    us = np.empty((n_steps + 1, 4))
    x = x0.copy()
    hint = np.full((4, 3, p.r.size), np.nan)
    dphi = np.zeros((3, p.r.size))
    u = u_seq[0].copy()
    tq = u[3]
    for k in range(n_steps + 1):
        uk = u_seq[min(k, u_seq.shape[0] - 1)]
        for i in range(3):
            u[i] = uk[i]
        step = rate_tq * h
        tq = tq + _clip(uk[3] - tq, -step, step)
        u[3] = tq
        xs[k] = x
        us[k] = u
        t = t0 + k * h
        if k == n_steps:
            w = sample_wind(t, x[16], p, kind, wpar, grid)
            _, z, _ = evaluate_plant(x, u, w, p, hint, 0)
            zs[k] = z
            break
        xn, z, hint, dphi = _rk4(t, x, u, h, p, kind, wpar, grid, hint, dphi)
        zs[k] = z
        bad = _bad_state(xn, lim)
        if bad >= 0:
            return xs[:k + 1], zs[:k + 1], us[:k + 1], k + 1, bad, xn[bad]
        x = xn
    return xs, zs, us, n_steps + 1, -1, 0.0


# --------------------------------------------------------------------------------------------
# Public API
# --------------------------------------------------------------------------------------------
def _check_xud(x: Any, u: Any, d: Any, n_r: int) -> tuple[FloatArray, FloatArray, FloatArray]:
    x = check_array("x", x, (n_x,), shape_names="(n_x,)")
    u = check_array("u", u, (n_u,), shape_names="(n_u,)")
    d = np.asarray(d, dtype=float)
    if d.shape == (_N_BLADE,):
        d = np.repeat(d[:, None], n_r, axis=1)
    d = check_array("d (wind)", d, (_N_BLADE, n_r), shape_names="(n_blade, n_r) or (n_blade,)")
    if np.any(d < 0):
        raise ValueError(f"d (wind) must be >= 0 m/s, got min {d.min()!r}")
    return x, u, d


def plant_rhs(t: float, x: FloatArray, u: FloatArray, d: FloatArray,
              params: PlantParams) -> FloatArray:
    """State derivative dx/dt of the plant (Madsen et al. 2012, eq 16, extended).

    Parameters
    ----------
    t : float
        Time [s] (the plant is time-invariant; kept for integrator signatures).
    x : (n_x,) ndarray
        State, see the module docstring.
    u : (n_u,) ndarray
        Inputs (pitch_ref_1..3 [rad], gen_torque_ref [N m]).
    d : (n_blade, n_r) or (n_blade,) ndarray
        Free wind speed at each blade element, or one speed per blade [m/s].
    params : PlantParams

    Returns
    -------
    dxdt : (n_x,) ndarray

    Raises
    ------
    ValueError
        On a wrong shape, a non-finite entry or a negative wind speed.
    """
    x, u, d = _check_xud(x, u, d, params.pack.r.size)
    hint = np.full((4, _N_BLADE, params.pack.r.size), np.nan)
    dx, _, _ = evaluate_plant(x, u, d, params.pack, hint, 0)
    return dx


def plant_outputs(t: float, x: FloatArray, u: FloatArray, d: FloatArray,
                  params: PlantParams) -> FloatArray:
    """Performance outputs z (Madsen eq 17 first, then :data:`OUTPUT_NAMES`), (n_z,) ndarray.

    Parameters
    ----------
    t : float
        Time [s].
    x : (n_x,) ndarray
        State.
    u : (n_u,) ndarray
        Inputs.
    d : (n_d,) ndarray
        Wind disturbances [m/s].
    params : PlantParams
        The plant.

    Returns
    -------
    (n_z,) ndarray
        The outputs.
    """
    x, u, d = _check_xud(x, u, d, params.pack.r.size)
    hint = np.full((4, _N_BLADE, params.pack.r.size), np.nan)
    _, z, _ = evaluate_plant(x, u, d, params.pack, hint, 0)
    return z


def element_wind(params: PlantParams, azimuth_rad: float, hub_speed: float,
                 shear_exponent: float = 0.0) -> FloatArray:
    """Free wind at each element from a steady power-law profile, (n_blade, n_r) [m/s].

    Parameters
    ----------
    params : PlantParams
        The plant.
    azimuth_rad : float
        Azimuth of blade 1 [rad].
    hub_speed : float
        Hub-height wind speed [m/s].
    shear_exponent : float
        Power-law exponent [-].

    Returns
    -------
    (n_blade, n_r) ndarray
        Free wind at each element [m/s].
    """
    ws = SteadyWind(hub_speed, shear_exponent)
    kind, wpar, grid = ws._kernel_args()
    return sample_wind(0.0, float(azimuth_rad), params.pack, kind, wpar, grid)


@dataclass(frozen=True)
class SteadyWind:
    """Steady wind with a power-law shear profile V(z) = V_hub (z / z_hub)^alpha.

    Parameters
    ----------
    speed : float
        Hub-height speed [m/s], >= 0.
    shear_exponent : float
        alpha [-], 0 for uniform wind.
    """

    speed: float
    shear_exponent: float = 0.0

    def __post_init__(self) -> None:
        v = float(self.speed)
        if not math.isfinite(v) or v < 0:
            raise ValueError(f"wind speed must be finite and >= 0 m/s, got {self.speed!r}")
        a = float(self.shear_exponent)
        if not math.isfinite(a) or not -1.0 <= a <= 1.0:
            raise ValueError(f"shear_exponent must be in [-1, 1], got {self.shear_exponent!r}")

    def _kernel_args(self) -> tuple[int, FloatArray, FloatArray]:
        return (0, np.array([float(self.speed), float(self.shear_exponent)]),
                np.zeros((1, 1, 1), dtype=np.float32))

    def check_covers(self, params: PlantParams, t_end: float) -> None:
        """Steady wind covers any rotor and any duration.

        Parameters
        ----------
        params : PlantParams
            The plant.
        t_end : float
            End of the simulation [s].
        """


@dataclass(frozen=True)
class GridWind:
    """Longitudinal wind on a regular (t, y, z) grid in the rotor plane, sampled trilinearly.

    Parameters
    ----------
    t : (n_t,) ndarray
        Uniformly spaced times [s].
    y : (n_y,) ndarray
        Uniformly spaced lateral positions, +y to the left looking downwind [m].
    z : (n_z,) ndarray
        Uniformly spaced heights above ground [m].
    u : (n_t, n_y, n_z) ndarray
        Longitudinal wind speed [m/s], finite and >= 0; kept as float32 (a 600 s turbulent
        field on 32 x 32 points at 20 Hz is 50 MB).
    """

    t: FloatArray
    y: FloatArray
    z: FloatArray
    u: FloatArray

    def __post_init__(self) -> None:
        for name in ("t", "y", "z"):
            a = np.array(getattr(self, name), dtype=float)
            if a.ndim != 1 or a.size < 2 or not np.all(np.isfinite(a)):
                raise ValueError(f"GridWind.{name} must be a finite 1-D array of length >= 2")
            st = np.diff(a)
            if np.any(st <= 0) or np.ptp(st) > 1e-6 * abs(st[0]) + 1e-12:
                raise ValueError(f"GridWind.{name} must be uniformly increasing")
            a.flags.writeable = False
            object.__setattr__(self, name, a)
        u = check_array("GridWind.u", self.u, (self.t.size, self.y.size, self.z.size),
                        shape_names="(n_t, n_y, n_z)", dtype=np.float32)
        if np.any(u < 0):
            raise ValueError(f"GridWind.u must be >= 0 m/s, got min {u.min()!r}")
        # adopt a read-only contiguous float32 array (it cannot change under us), else copy
        if (u is self.u and self.u.flags.writeable) or u.base is not None \
                or not u.flags.c_contiguous:
            u = np.array(u, dtype=np.float32, order="C")
        u.flags.writeable = False
        object.__setattr__(self, "u", u)

    def _kernel_args(self) -> tuple[int, FloatArray, FloatArray]:
        par = np.array([self.t[0], self.t[1] - self.t[0], self.y[0], self.y[1] - self.y[0],
                        self.z[0], self.z[1] - self.z[0]])
        return 1, par, self.u

    def check_covers(self, params: PlantParams, t_end: float) -> None:
        """Raise if the grid does not cover the rotor disc or the time span.

        Parameters
        ----------
        params : PlantParams
            The plant (rotor size and hub height).
        t_end : float
            End of the simulation [s].
        """
        g = params.turbine.geometry
        rad = g.tip_radius
        if (self.y[0] > -rad or self.y[-1] < rad or self.z[0] > g.hub_height - rad
                or self.z[-1] < g.hub_height + rad):
            raise ValueError(
                f"wind grid y {self.y[0]:g}..{self.y[-1]:g} m, z {self.z[0]:g}..{self.z[-1]:g} m "
                f"does not cover the rotor (y +-{rad:g} m, z {g.hub_height - rad:g}.."
                f"{g.hub_height + rad:g} m)")
        if self.t[-1] < t_end - 1e-9:
            raise ValueError(f"wind field ends at t = {self.t[-1]:g} s, before the simulation "
                             f"end t = {t_end:g} s")


@dataclass(frozen=True)
class SimulationResult:
    """Open-loop simulation result.

    Parameters
    ----------
    t : (n_t,) ndarray
        Time [s].
    x : (n_t, n_x) ndarray
        States (:data:`STATE_NAMES`, units :data:`STATE_UNITS`).
    u : (n_t, n_u) ndarray
        Inputs applied after the torque rate limit (:data:`INPUT_NAMES`).
    z : (n_t, n_z) ndarray
        Outputs (:data:`OUTPUT_NAMES`, units :data:`OUTPUT_UNITS`).
    """

    t: FloatArray
    x: FloatArray
    u: FloatArray
    z: FloatArray

    def state(self, name: str) -> FloatArray:
        """One state's time series by name.

        Parameters
        ----------
        name : str
            A name of :data:`STATE_NAMES`.

        Returns
        -------
        (n_t,) ndarray
            Its time series (SI).
        """
        if name not in STATE_NAMES:
            raise KeyError(f"no state {name!r}; states are {list(STATE_NAMES)}")
        return self.x[:, STATE_NAMES.index(name)]

    def output(self, name: str) -> FloatArray:
        """One output's time series by name.

        Parameters
        ----------
        name : str
            A name of :data:`OUTPUT_NAMES`.

        Returns
        -------
        (n_t,) ndarray
            Its time series (SI).
        """
        if name not in OUTPUT_NAMES:
            raise KeyError(f"no output {name!r}; outputs are {list(OUTPUT_NAMES)}")
        return self.z[:, OUTPUT_NAMES.index(name)]


def _state_limits(params: PlantParams) -> FloatArray:
    """Physical envelope (2, n_x): lower and upper bounds; leaving it means the simulation
    diverged. Symmetric except for the rotor and generator speeds, which may not run backwards
    by more than 10 % of rated (the aerodynamics are not valid for a reversed rotor)."""
    t = params.turbine
    wr = t.operation.rated_rotor_speed_rad_s
    lim = np.full(n_x, np.inf)
    lim[0] = lim[8] = 0.5 * t.geometry.tower_height         # tower deflection [m]
    lim[1] = lim[9] = 50.0                                   # [m/s]
    lim[2] = 4.0 * wr
    lim[3] = 4.0 * wr * t.drivetrain.gearbox_ratio
    lim[4] = 0.5                                             # shaft torsion [rad]
    lim[5:8] = 2.0 * math.pi
    lim[10:13] = 0.5 * (t.geometry.tip_radius - t.geometry.hub_radius)
    lim[13:16] = 200.0
    lim[16] = 1e12
    lim[17:20] = 0.25 * (t.geometry.tip_radius - t.geometry.hub_radius)
    lim[20:23] = 200.0
    lo = -lim
    lo[2], lo[3] = -0.1 * wr, -0.1 * wr * t.drivetrain.gearbox_ratio
    return np.vstack([lo, lim])


def rk4_simulate(params: PlantParams, x0: FloatArray, u: FloatArray,
                 wind: SteadyWind | GridWind, duration: float, dt: float = 1.0 / 80.0,
                 t0: float = 0.0) -> SimulationResult:
    """Integrate the plant with fixed-step RK4, inputs held over each step (zero-order hold).

    Parameters
    ----------
    params : PlantParams
    x0 : (n_x,) ndarray
        Initial state.
    u : (n_u,) or (n_t, n_u) ndarray
        Constant inputs, or one row per step (the last row is held).
    wind : SteadyWind or GridWind
        The free wind, sampled at every blade element at every RK4 stage.
    duration : float
        [s], > 0.
    dt : float
        Step [s], default 1/80 s (80 Hz).
    t0 : float
        Start time [s].

    Returns
    -------
    SimulationResult
        With ``n_t = round(duration / dt) + 1`` samples.

    Raises
    ------
    SimulationDivergedError
        If a state leaves the physical envelope or becomes non-finite; names the time and the
        state and carries the partial result in ``.partial``.
    ValueError
        On bad shapes or values, or a wind field that does not cover the rotor or the time.
    """
    check_positive("duration", duration)
    check_positive("dt", dt)
    n_steps = int(round(duration / dt))
    if n_steps < 1:
        raise ValueError(f"duration ({duration!r} s) must be at least one step dt = {dt!r} s")
    x0 = check_array("x0", x0, (n_x,), shape_names="(n_x,)")
    u = np.asarray(u, dtype=float)
    if u.ndim == 1:
        u = u[None, :]
    u = check_array("u", u, (None, n_u), shape_names="(n_t, n_u)")
    if not isinstance(wind, (SteadyWind, GridWind)):
        raise TypeError(f"wind must be SteadyWind or GridWind, got {type(wind).__name__}")
    wind.check_covers(params, t0 + n_steps * dt)
    kind, wpar, grid = wind._kernel_args()
    lim = _state_limits(params)
    xs, zs, us, n, bad, val = _simulate(x0, np.ascontiguousarray(u), float(t0), float(dt),
                                        n_steps, params.pack, kind, wpar, grid, lim,
                                        params.turbine.generator.max_torque_rate)
    t = t0 + dt * np.arange(n)
    res = SimulationResult(t=t, x=xs, u=us, z=zs)
    if bad >= 0:
        raise SimulationDivergedError(
            f"simulation diverged at t = {t0 + n * dt:.4f} s: state {STATE_NAMES[bad]!r} = "
            f"{val!r} {STATE_UNITS[bad]} left its envelope {lim[0, bad]:g}..{lim[1, bad]:g}; "
            f"the {n} samples before are kept in .partial", res)
    return res


class PlantStepper:
    """The plant advanced one fixed RK4 step at a time, for closed loops.

    :func:`rk4_simulate` runs a whole input sequence in compiled code; a closed loop needs the
    controller between steps, so this object keeps the integrator's BEM warm start (the
    previous step's inflow angles) and the wind's sampling data between calls. It validates
    once, at construction; :meth:`step` trusts its arguments.

    Parameters
    ----------
    params : PlantParams
        The plant.
    wind : SteadyWind or GridWind
        The free wind over the whole run.
    dt : float
        Step [s], > 0 (default 1/80 s).
    duration : float
        Length of the run [s]; the wind must cover it.

    Raises
    ------
    ValueError
        If ``dt`` or ``duration`` is not > 0, or the wind does not cover the rotor or the run.
    TypeError
        If ``wind`` is not a :class:`SteadyWind` or :class:`GridWind`.
    """

    def __init__(self, params: PlantParams, wind: "SteadyWind | GridWind", dt: float = 1.0 / 80.0,
                 duration: float = 0.0) -> None:
        self.dt = check_positive("dt", dt)
        check_positive("duration", duration, allow_zero=True)
        if not isinstance(wind, (SteadyWind, GridWind)):
            raise TypeError(f"wind must be SteadyWind or GridWind, got {type(wind).__name__}")
        wind.check_covers(params, duration)
        self.params = params
        self._kind, self._wpar, self._grid = wind._kernel_args()
        self._pack = params.pack
        self.limits = _state_limits(params)
        self.reset()

    def reset(self) -> None:
        """Forget the BEM warm start (a new run)."""
        n_r = self._pack.r.size
        self._hint = np.full((4, _N_BLADE, n_r), np.nan)
        self._dphi = np.zeros((_N_BLADE, n_r))
        self._into_entry: Any = None

    def step(self, t: float, x: FloatArray, u: FloatArray) -> tuple[FloatArray, FloatArray]:
        """One RK4 step from ``t`` with the inputs held.

        Parameters
        ----------
        t : float
            Time at the start of the step [s].
        x : (n_x,) ndarray
            State at ``t``.
        u : (n_u,) ndarray
            Inputs over the step (after any rate limit).

        Returns
        -------
        x_next : (n_x,) ndarray
            State at ``t + dt``.
        z : (n_z,) ndarray
            Outputs at ``t`` (:data:`OUTPUT_NAMES`).
        """
        xn, z = np.empty(n_x), np.empty(n_z)
        self.step_into(t, np.ascontiguousarray(x, dtype=np.float64),
                       np.ascontiguousarray(u, dtype=np.float64), xn, z)
        return xn, z

    def step_into(self, t: float, x: FloatArray, u: FloatArray, x_out: FloatArray,
                  z_out: FloatArray) -> int:
        """:meth:`step` writing into given arrays (a closed loop's record rows), and the
        envelope check of :meth:`outside_envelope` on the new state, in one compiled call.

        Parameters
        ----------
        t : float
            Time at the start of the step [s].
        x, u : (n_x,), (n_u,) ndarray
            State at ``t`` and inputs over the step (C-contiguous float64).
        x_out, z_out : (n_x,), (n_z,) ndarray
            Written: the state at ``t + dt`` and the outputs at ``t`` (C-contiguous float64,
            writable; ``x_out`` must not be ``x``).

        Returns
        -------
        int
            Index of the first state of ``x_out`` outside the envelope, or -1.
        """
        # numba's dispatcher types every argument at every call, and typing the plant's 64-field
        # parameter tuple costs 5-10 us a step; the compiled overload is looked up once and
        # called directly. It reads 1-D arrays as dense float64, so that is checked at every
        # call (a strided view would be misread)
        for name, a in (("x", x), ("u", u), ("x_out", x_out), ("z_out", z_out)):
            if a.strides != _DENSE or a.dtype != np.float64:
                raise ValueError(f"{name} must be a 1-D C-contiguous float64 array, got "
                                 f"dtype {a.dtype}, strides {a.strides}")
        args = (float(t), x, u, self.dt, self._pack, self._kind, self._wpar, self._grid,
                self._hint, self._dphi, self.limits, x_out, z_out)
        if self._into_entry is None:
            self._into_entry = _rk4_into.compile(tuple(nb.typeof(a) for a in args))
        return self._into_entry(*args)

    def kernel_args(self) -> tuple[Any, ...]:
        """What :data:`step_kernel` takes between the inputs and the outputs: (dt, the packed
        parameters, the wind's kind, parameters and grid, the BEM warm start (hint, dphi; updated
        in place), the state envelope).

        Returns
        -------
        tuple
            For ``step_kernel(t, x, u, *kernel_args(), x_out, z_out)``.
        """
        return (self.dt, self._pack, self._kind, self._wpar, self._grid, self._hint,
                self._dphi, self.limits)

    def outputs(self, t: float, x: FloatArray, u: FloatArray) -> FloatArray:
        """The outputs at ``t`` without stepping, (n_z,) (:data:`OUTPUT_NAMES`).

        Parameters
        ----------
        t : float
            Time [s].
        x : (n_x,) ndarray
            State.
        u : (n_u,) ndarray
            Inputs.

        Returns
        -------
        (n_z,) ndarray
            Outputs.
        """
        w = sample_wind(t, x[16], self._pack, self._kind, self._wpar, self._grid)
        return evaluate_plant(x, u, w, self._pack, self._hint, 0)[1]

    def outside_envelope(self, x: FloatArray) -> int:
        """Index of the first state outside the physical envelope (or non-finite), else -1.

        Parameters
        ----------
        x : (n_x,) ndarray
            A state.

        Returns
        -------
        int
            The state's index in :data:`STATE_NAMES`, or -1 when all are inside.
        """
        return int(_bad_state(x, self.limits))


def structural_frequencies(params: PlantParams, rotor_speed_rad_s: float = 0.0) -> dict[str, float]:
    """Natural frequencies of the structural modes without aerodynamics [Hz].

    Tower fore-aft coupled with the three flap modes through the mass matrix (so a collective
    and two asymmetric flap modes appear), tower side-side alone. The flap stiffness includes
    centrifugal stiffening at ``rotor_speed_rad_s``; the drivetrain torsion frequency is that
    of the free-free two-mass system (rigid blades).

    With an edge mode shape in the turbine data, also the edgewise modes: the asymmetric edge
    mode of one blade (stiffness K_e + Omega^2 (K_cf,e - M_e): centrifugal stiffening and the
    in-plane softening), and, with the generator locked as in the NREL 5-MW report's Table 9-1
    (RotSpeed = 0, GenDOF = False), the collective edge mode and the shaft torsion coupled
    through the rotor inertia: M = [[J_r, 3 S_e], [3 S_e, 3 M_e]], K = diag(K_shaft, 3 K_e)
    with S_e = int m phi_e r ds. The plant's state equations do not carry the edge DOF yet.

    Parameters
    ----------
    params : PlantParams
        The plant.
    rotor_speed_rad_s : float
        Rotor speed for the centrifugal stiffening [rad/s].

    Returns
    -------
    dict
        Keys ``tower_fa``, ``tower_ss``, ``flap_collective``, ``flap_asymmetric``,
        ``drivetrain``, ``drivetrain_locked_generator_rigid_blades`` [Hz]; with an edge mode
        shape also ``edge_asymmetric``, ``edge_collective_locked_generator`` and
        ``drivetrain_locked_generator`` [Hz].
    """
    import scipy.linalg as sl

    pk = params.pack
    kq = pk.k_b + rotor_speed_rad_s**2 * pk.k_cf
    m = np.array([[pk.m_fa, pk.m_c, pk.m_c, pk.m_c], [pk.m_c, pk.m_b, 0, 0],
                  [pk.m_c, 0, pk.m_b, 0], [pk.m_c, 0, 0, pk.m_b]])
    k = np.diag([pk.k_fa, kq, kq, kq])
    w2, vec = sl.eigh(k, m)
    f = np.sqrt(w2) / (2 * math.pi)
    tower_share = np.abs(vec[0]) * math.sqrt(pk.m_fa)
    i_tower = int(np.argmax(tower_share))
    others = [i for i in range(4) if i != i_tower]
    coll = max(others, key=lambda i: abs(vec[0, i]))
    asym = [i for i in others if i != coll]
    j_eq = pk.j_rot * pk.j_gen * pk.ngear**2 / (pk.j_rot + pk.j_gen * pk.ngear**2)
    out = {"tower_fa": float(f[i_tower]),
           "tower_ss": math.sqrt(pk.k_ss / pk.m_ss) / (2 * math.pi),
           "flap_collective": float(f[coll]), "flap_asymmetric": float(np.mean(f[asym])),
           "drivetrain": math.sqrt(pk.k_shaft / j_eq) / (2 * math.pi),
           "drivetrain_locked_generator_rigid_blades":
               math.sqrt(pk.k_shaft / pk.j_rot) / (2 * math.pi)}
    if math.isfinite(params.edge_modal_mass):
        me, se = params.edge_modal_mass, params.edge_rotor_coupling
        ke = (params.edge_modal_stiffness
              + rotor_speed_rad_s**2 * (params.edge_centrifugal_stiffness - me))
        w2e, vece = sl.eigh(np.diag([pk.k_shaft, 3 * ke]),
                            np.array([[pk.j_rot, 3 * se], [3 * se, 3 * me]]))
        # the drivetrain mode is the one whose strain energy is mostly the shaft's
        shaft_energy = pk.k_shaft * vece[0] ** 2
        i_dt = int(np.argmax(shaft_energy / (shaft_energy + 3 * ke * vece[1] ** 2)))
        fe = np.sqrt(w2e) / (2 * math.pi)
        out.update(edge_asymmetric=math.sqrt(ke / me) / (2 * math.pi),
                   drivetrain_locked_generator=float(fe[i_dt]),
                   edge_collective_locked_generator=float(fe[1 - i_dt]))
    return out

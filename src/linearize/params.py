"""The plant's names and parameters: states, inputs and outputs with their units, the degrees of
freedom a configuration switches on (:class:`PlantConfig`), and the modal, inertial and
geometric parameters derived from the turbine data (:class:`PlantParams`,
:func:`plant_params`; Hansen 2015, ch. 11), with the structural frequencies they give.
"""
from __future__ import annotations

import math
from collections import namedtuple
from dataclasses import dataclass, field, replace
from typing import Any, Mapping

import numpy as np

from linearize._kept import Kept
from linearize._typing import FloatArray
from linearize.bem import (
    AeroOptions,
    aero_flags,
    polar_table_of,
)
from linearize.turbine import Turbine, mode_shape
from linearize.unsteady import UA_PAR

__all__ = ["DOF_NAMES", "STATE_NAMES", "STATE_UNITS", "INPUT_NAMES", "INPUT_UNITS", "OUTPUT_NAMES",
           "OUTPUT_UNITS", "MADSEN_OUTPUTS", "n_x", "n_u", "n_z", "PlantConfig", "PlantParams",
           "plant_params", "structural_frequencies"]

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


N_BLADE = 3


_IX = {n: i for i, n in enumerate(STATE_NAMES)}


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
        (AeroDyn v13 / WT_Perf style) or trapezoid over the element centres, the hub and the
        tip (AeroDyn 15): zero load at the hub; at the tip, with the tip loss on, AeroDyn 15's
        fixed-induction tip node (a = 1, a' = 0, the inflow in the rotor plane: C_l and C_d at
        alpha = -(pitch + twist) with the last element's chord, twist and airfoil), else zero.
    blade_body_forces : bool
        The blade's own forces normal to it on the flap mode and in the out-of-plane root
        moment: the centrifugal force of the coned blade, Omega^2 r cos(c) sin(c) per unit
        mass, and gravity, g (sin(t) cos(c) - sin(c) cos(t) cos(psi)) with shaft tilt t,
        precone c and azimuth psi (Jonkman 2007, NREL/TP-500-41958, sec. 3: ElastoDyn's
        blade kinematics; Hansen 2015, sec. 11.3). Gravity follows ``aero.gravity``; both
        vanish without cone and tilt. On by default, in the paper models (:meth:`madsen`,
        :meth:`clemens`, :meth:`do`) and in :meth:`openfast`: a turbine's root-moment gauges
        read them (about 1 MN m of the NREL 5-MW's 5-8 MN m at rated), and an observer of
        the root moments designed without them misreads the wind (LQR-PIO's stopped the
        rotor in OpenFAST's regression case).
    inplane_wind : bool
        The free wind's lateral and vertical components (a :class:`GridWind` with ``v`` and
        ``w``) in the blade elements' velocities (AeroDyn's relative wind; Jonkman 2007,
        NREL/TP-500-41958): the rotor's side force and yaw moment in a lateral gust, the
        blades' 1P in-plane loading. Without it the plant meets u alone.
    tower_shadow : bool
        Potential flow around the tower in front of it (AeroDyn's ``TwrPotent = 1``; Moriarty
        and Hansen 2005, NREL/EL-500-36881, sec. 7): the wind a blade meets as it passes the
        tower, on turbines whose data give the tower's outer diameter
        (``TowerStructure.outer_diameter``). Off by default: a narrow azimuthal feature that
        the trim's and the linearization's few azimuth samples misrepresent; on in
        :meth:`openfast`.
    unsteady_aero, twisted_modes, tower_drag : bool
        Beddoes-Leishman-type unsteady airfoil aerodynamics (:mod:`linearize.unsteady`), the
        blade modes along their pitched, twisted principal axes, and the tower's drag (see
        the validation page on the plant against OpenFAST). Off by default; on in
        :meth:`openfast`.
    skewed_wake : bool
        The skewed-wake correction of the axial induction (Pitt and Peters 1981, as AeroDyn's
        ``Skew_Mod = 1`` with ``SkewRedistr_Mod = 1`` and ``BEM_Mod = 1``; Moriarty and Hansen
        2005, NREL/EL-500-36881, the skewed-wake correction): each element's solved
        induction a is scaled by 1 + (15 pi/32) tan(chi/2) (r/R) cos(gamma), where chi =
        (0.6 a + 1) chi_0, chi_0 the angle between the shaft and the disk-averaged wind
        relative to the hub (tilt and the wind's own direction) and gamma the angle in the
        rotor plane between the blade and that wind's in-plane part (the induction grows on the
        side toward which the wake is skewed). The loads follow the corrected induction; for
        three blades the correction cancels in the rotor's thrust and torque to first order
        and moves load between the blades (1P loads, tilt and yaw moments, the rotor's side
        force). It acts in simulation and in the trim; the linear models leave it out, as they
        leave out the unsteady aerodynamics. Off by default; on in :meth:`openfast`.
    deflected_blades : bool
        Each blade element meets the wind at its deflected orientation and place, as AeroDyn
        does on ElastoDyn's blade motion (Jonkman 2007, NREL/TP-500-41958, the blade coordinate
        systems): its local cone is the precone less the out-of-plane bending slope,
        c_j = c - (q phi_f'(r_j) cos(theta_j) - q_e phi_e'(r_j) sin(theta_j)), with the flap and
        edge mode coordinates q, q_e and theta_j the element's pitch and structural twist
        (rotor-plane modes: cos = 1, sin = 0), and the normal velocity and the normal force's
        thrust component follow it; its distance from the shaft moves with the out-of-plane
        deflection along the coned normal and shrinks with the inextensible blade's shortening
        0.5 q^2 int_0^r phi'^2; the in-plane deflection, turned with the rotor, moves radially
        inward, a velocity with a part along the coned normal. On the NREL 5-MW the downwind
        deflection undoes the upwind precone toward the tip: 4 m at the tip costs 0.4-0.6 % of
        the torque, within 0.1 points of AeroDyn 15 with the same deflection as prebend. The
        trim finds the deflection and the loads it changes together (a fixed point). Off by
        default (the linear models and the controllers' designs are of the undeflected rotor);
        on in :meth:`openfast`.
    """

    dofs: frozenset[str] = frozenset(DOF_NAMES)
    aero: AeroOptions = field(default_factory=AeroOptions)
    integration: str = "midpoint"
    blade_body_forces: bool = True
    inplane_wind: bool = True
    tower_shadow: bool = False
    unsteady_aero: bool = False
    twisted_modes: bool = False
    tower_drag: bool = False
    skewed_wake: bool = False
    deflected_blades: bool = False

    def __post_init__(self) -> None:
        dofs = frozenset(self.dofs)
        unknown = sorted(dofs - set(DOF_NAMES))
        if unknown:
            raise ValueError(f"dofs has unknown names {unknown}; allowed {list(DOF_NAMES)}")
        object.__setattr__(self, "dofs", dofs)
        if self.integration not in ("midpoint", "trapezoid"):
            raise ValueError(f"integration must be 'midpoint' or 'trapezoid', "
                             f"got {self.integration!r}")

    #: The effects a user switches on or off by name (:meth:`with_switches`).
    SWITCHES = ("blade_body_forces", "inplane_wind", "tower_shadow", "unsteady_aero",
                "twisted_modes", "tower_drag", "skewed_wake", "deflected_blades")

    def with_switches(self, switches: Mapping[str, bool] | None) -> "PlantConfig":
        """This configuration with the named effects (:attr:`SWITCHES`) set.

        Parameters
        ----------
        switches : mapping of str to bool, optional
            E.g. ``{"twisted_modes": True}``; None or empty: unchanged.

        Returns
        -------
        PlantConfig

        Raises
        ------
        ValueError
            A name that is not a switch, or a value that is not true or false.
        """
        if not switches:
            return self
        if not isinstance(switches, Mapping):
            raise ValueError(f"plant switches must be a mapping of switch to true/false, got "
                             f"{switches!r}")
        for k, v in switches.items():
            if k not in self.SWITCHES:
                raise ValueError(f"plant switch {k!r} is unknown; switches are "
                                 f"{list(self.SWITCHES)}")
            if not isinstance(v, (bool, np.bool_)):
                raise ValueError(f"plant switch {k!r} must be true or false, got {v!r}")
        return replace(self, **{k: bool(v) for k, v in switches.items()})

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

    @classmethod
    def openfast(cls, *, unsteady_aero: bool = True, tower_drag: bool = True,
                 tower_shadow: bool = True, twisted_modes: bool = True,
                 blade_body_forces: bool = True, skewed_wake: bool = True,
                 deflected_blades: bool = True, integration: str = "trapezoid",
                 dofs: frozenset[str] | None = None) -> "PlantConfig":
        """Every effect OpenFAST's ElastoDyn and AeroDyn 15 models and the plant has, as the
        regression case ``5MW_Land_DLL_WTurb`` runs them (AeroDyn's ``UA_Mod = 3``,
        ``TwrPotent = 1`` and ``TwrAero``; the rest are on by default): for comparisons with
        OpenFAST runs.

        Parameters
        ----------
        unsteady_aero, tower_drag, tower_shadow, skewed_wake : bool
            AeroDyn's effects, off by default (the AeroDyn file's ``UA_Mod > 0``, ``TwrAero``,
            ``TwrPotent > 0`` and ``Skew_Mod = 1``).
        twisted_modes, blade_body_forces, deflected_blades : bool
            ElastoDyn's modes along the principal axes, its blade kinematics and the deflected
            blade's orientation in AeroDyn, off by default.
        integration : {"trapezoid", "midpoint"}
            AeroDyn 15 integrates the line loads of its nodes, the blade's element centres and
            its root and tip: the trapezoid rule, with the tip node's load as AeroDyn has it
            (the tip loss fixes its inductions at a = 1, a' = 0: alpha = -(pitch + twist)).
            The default plant's midpoint rule is AeroDyn 14's; on the NREL 5-MW it gives
            0.7-1.1 % more torque than AeroDyn 15, the trapezoid rule 0.4-0.9 % less.
        dofs : frozenset of str, optional
            Degrees of freedom (default: all).

        Returns
        -------
        PlantConfig
        """
        return cls(frozenset(DOF_NAMES) if dofs is None else frozenset(dofs),
                   integration=integration, unsteady_aero=unsteady_aero,
                   tower_drag=tower_drag, tower_shadow=tower_shadow,
                   twisted_modes=twisted_modes, blade_body_forces=blade_body_forces,
                   skewed_wake=skewed_wake, deflected_blades=deflected_blades)

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
    "ngear", "eta_gen", "eta_gbx", "j_rot", "j_gen", "k_shaft", "c_shaft",
    "m_fa", "k_fa", "c_fa", "hub_fa", "slope_fa", "m_ss", "k_ss", "c_ss", "hub_ss", "slope_ss",
    "m_b", "k_b", "k_cf", "c_b", "m_c", "s1", "s_phi_r", "i_edge",
    "tau_p", "rate_p", "min_p", "max_p", "min_tq", "max_tq",
    "fa_static", "fa_pdelta", "fa_inertia", "ss_pdelta", "ss_inertia",
    "phi_edge", "m_e", "k_e", "k_cf_e", "c_e", "s_e", "g_e", "g_b",
    "twr_h", "twr_r", "x_apex", "ua",
    "twist_s", "sfc", "sfs", "sec", "ses", "tq_h", "tq_w", "tq_fa", "tq_ss",
    "dphi_flap", "dphi_edge", "ax_flap", "ax_edge"])


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


def _cumtrapz(y: FloatArray, x: FloatArray) -> FloatArray:
    """int_0^x y dx at each x."""
    return np.concatenate(([0.0], np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(x))))


def _cumtrapz_from_end(y: FloatArray, x: FloatArray) -> FloatArray:
    """int_x^end y dx at each x."""
    seg = 0.5 * (y[1:] + y[:-1]) * np.diff(x)
    out = np.zeros_like(x)
    out[:-1] = np.cumsum(seg[::-1])[::-1]
    return out


#: how many derivations :func:`plant_params` keeps
PARAMS_KEPT = 16
#: the last parameters derived in this process, by (id(turbine), config); a kept PlantParams
#: holds its turbine, so the id names that turbine for as long as the entry is kept
_DERIVED = Kept(PARAMS_KEPT)


def plant_params(turbine: Turbine, config: PlantConfig | None = None) -> PlantParams:
    """Derive modal, inertial and geometric plant parameters from the turbine data.

    Modal mass and stiffness of each assumed mode phi (Hansen 2015, ch. 11):
    ``m = int mu phi^2 + sum_bodies``, ``k = int EI phi''^2 - g int N(h) phi'^2`` (gravity
    softening with N the weight above h), damping ``c = 2 zeta sqrt(k m)``.

    The process keeps the last :data:`PARAMS_KEPT` derivations, by the turbine object (a
    :class:`Turbine` is immutable) and the config: a steady solve, a trim or a C_P table asks
    for the same parameters thousands of times in a design, and the derivation takes
    milliseconds. The kept :class:`PlantParams` is shared; it is not to be changed.

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    config : PlantConfig, optional
        Degrees of freedom and aerodynamic options (default: all on). The degrees of freedom
        the turbine holds rigid (:attr:`Turbine.rigid_dofs`, an OpenFAST deck's ElastoDyn
        switches) are left out of it: ``PlantParams.config`` is the configuration in effect.

    Returns
    -------
    PlantParams
        The plant's parameters.

    Raises
    ------
    ValueError
        If the turbine's ``rigid_dofs`` names a degree of freedom the plant does not have.
    """
    cfg = _without_rigid(turbine, config or PlantConfig())
    return _DERIVED.get((id(turbine), cfg), lambda: _derive_plant_params(turbine, cfg))


def _without_rigid(turbine: Turbine, cfg: PlantConfig) -> PlantConfig:
    """``cfg`` without the degrees of freedom the turbine holds rigid."""
    rigid = set(turbine.rigid_dofs)
    unknown = sorted(rigid - set(DOF_NAMES))
    if unknown:
        raise ValueError(f"Turbine.rigid_dofs has unknown names {unknown}; allowed "
                         f"{list(DOF_NAMES)}")
    return replace(cfg, dofs=cfg.dofs - rigid) if cfg.dofs & rigid else cfg


def _derive_plant_params(turbine: Turbine, cfg: PlantConfig) -> PlantParams:
    """:func:`plant_params` computed afresh."""
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
        m_tower = float(np.trapezoid(mt * ph**2, h))
        mass = m_tower + rot_inertia * slope**2
        inertia_moment = float(np.trapezoid(mt * ph * h, h)) + rot_inertia * slope
        k_elastic = float(np.trapezoid(eit * ddph**2, h))
        k = k_elastic - float(np.trapezoid(weight_above * dph**2, h))
        for mb, xb, zb in bodies:
            mass += mb * ((1.0 + zb * slope) ** 2 + (xb * slope) ** 2)
            inertia_moment += mb * (ht + zb) * (1.0 + zb * slope)
            k -= grav * mb * zb * slope**2
        if k <= 0:
            raise ValueError(f"tower modal stiffness {k:g} N/m is not positive: the tower "
                             f"buckles under the top mass")
        # the damping ratio is of the isolated tower's mode, as ElastoDyn's TwrFADmp/TwrSSDmp
        # and the NREL 5-MW's 1 %: stiffness-proportional, c = zeta K_el / (pi f_iso) with
        # f_iso from the tower's own elastic stiffness and mass (no top mass, no gravity)
        c = 2.0 * zeta * math.sqrt(k_elastic * m_tower)
        pdelta = grav * (m_top + float(np.trapezoid(mt * ph, h)))
        return mass, k, c, 1.0 + g.twr2shft * slope, slope, pdelta, inertia_moment

    m_fa, k_fa, c_fa, hub_fa, slope_fa, pd_fa, in_fa = tower_mode(
        t.mode_shapes.tower_fa1, ts.fa_stiffness, 0.5 * rotor_inertia, t.damping.tower_fa)
    m_ss, k_ss, c_ss, hub_ss, slope_ss, pd_ss, in_ss = tower_mode(
        t.mode_shapes.tower_ss1, ts.ss_stiffness, 0.0, t.damping.tower_ss)

    # --- aero element data
    b = t.blade
    # the tip node of AeroDyn 15's trapezoid rule (its weight, the flap and edge modes there):
    # with the tip loss on, its inductions are fixed at a = 1, a' = 0 (the kernel's loads).
    # The kernel finds it after the elements' weights in ``w`` (n_r + 3 entries): one more
    # field in the packed parameters costs the default plant 6 % of its speed
    tip = np.zeros(3)
    if cfg.integration == "midpoint":
        weights = b.dr.copy()
    else:
        rr = np.concatenate(([g.hub_radius], b.r, [g.tip_radius]))
        weights = 0.5 * (rr[2:] - rr[:-2])
        if cfg.aero.tip_loss:
            tip[0] = 0.5 * (g.tip_radius - b.r[-1])
            tip[1] = float(mode_shape(t.mode_shapes.blade_flap1, np.ones(1))[0])
            if t.mode_shapes.blade_edge1 is not None:
                tip[2] = float(mode_shape(t.mode_shapes.blade_edge1, np.ones(1))[0])
    phi_el = mode_shape(t.mode_shapes.blade_flap1, (b.r - g.hub_radius) / lb)
    dphi_el, ax_fl = _element_slopes(t, t.mode_shapes.blade_flap1, s, dphi)
    edge, edge_pack = _edge_mode(t, s, mu, tension)
    twisted = _twisted_modes(t, cfg, s, mu, phi, b.r)
    if "blade_edge" in cfg.dofs and not edge:
        raise ValueError("config.dofs has 'blade_edge' but the turbine's mode-shape table has "
                         "no 'blade_edge_1' row; add it or leave the DOF out "
                         f"(PlantConfig(dofs={sorted(cfg.dofs - {'blade_edge'})!r}))")
    tab = polar_table_of(t)
    pa = t.pitch_actuator
    dofs = np.array([d in cfg.dofs for d in DOF_NAMES], dtype=np.int64)
    opt = np.array([cfg.aero.gravity, cfg.blade_body_forces, cfg.inplane_wind,
                    cfg.tower_shadow, cfg.unsteady_aero, twisted["on"], 0, cfg.skewed_wake,
                    cfg.deflected_blades],
                   dtype=np.int64)
    drag = _tower_drag_points(t, ht)
    opt[6] = int(cfg.tower_drag and drag["tq_h"].size > 0)
    ua = np.array([pol.ua.row() if pol.ua is not None else (0.0,) * len(UA_PAR)
                   for pol in t.polars], dtype=float)
    twr_h, twr_r = np.zeros(1), np.zeros(1)
    if ts.outer_diameter is not None:
        twr_h = g.tower_base_height + ts.height_fraction * ht
        twr_r = 0.5 * np.asarray(ts.outer_diameter, dtype=float)
    fa_static = grav * (t.nacelle.mass * g.nacelle_cm_downwind - rotor_mass * g.overhang)
    pack = _Pack(
        dof=dofs, flags=aero_flags(cfg.aero), opt=opt, nb=float(nblade),
        rho=t.environment.air_density, grav=grav, rtip=g.tip_radius, rhub=g.hub_radius,
        zhub=g.hub_height, cone=cone, tilt=tilt, r=b.r, w=np.concatenate((weights, tip)),
        chord=b.chord,
        twist=b.twist_rad, af=b.airfoil, phi_flap=phi_el, table=tab.table, alpha0=tab.alpha0,
        dalpha=tab.dalpha, ngear=t.drivetrain.gearbox_ratio,
        eta_gen=t.drivetrain.generator_efficiency, eta_gbx=t.drivetrain.gearbox_efficiency,
        j_rot=rotor_inertia, j_gen=t.drivetrain.generator_inertia,
        k_shaft=t.drivetrain.shaft_stiffness, c_shaft=t.drivetrain.shaft_damping,
        m_fa=m_fa, k_fa=k_fa, c_fa=c_fa, hub_fa=hub_fa, slope_fa=slope_fa,
        m_ss=m_ss, k_ss=k_ss, c_ss=c_ss, hub_ss=hub_ss, slope_ss=slope_ss,
        m_b=m_b, k_b=k_b, k_cf=k_cf, c_b=c_b, m_c=m_c * hub_fa, s1=s1,
        s_phi_r=s_phi_r, i_edge=i_edge, tau_p=pa.time_constant, rate_p=pa.max_rate_rad_s,
        min_p=pa.min_pitch_rad, max_p=pa.max_pitch_rad, min_tq=t.generator.min_torque,
        max_tq=t.generator.max_torque, fa_static=fa_static, fa_pdelta=pd_fa,
        fa_inertia=in_fa, ss_pdelta=pd_ss, ss_inertia=in_ss, g_b=m_c,
        twr_h=twr_h, twr_r=twr_r, x_apex=-g.overhang * math.cos(g.shaft_tilt_rad), ua=ua,
        twist_s=twisted["twist_s"], sfc=twisted["sfc"], sfs=twisted["sfs"], sec=twisted["sec"],
        ses=twisted["ses"], dphi_flap=dphi_el, ax_flap=ax_fl, **drag, **edge_pack)
    return PlantParams(
        turbine=t, config=cfg, rotor_inertia=rotor_inertia, rotor_mass=rotor_mass,
        blade_mass=blade_mass, tower_fa_modal_mass=m_fa, tower_fa_modal_stiffness=k_fa,
        tower_fa_modal_damping=c_fa, tower_ss_modal_mass=m_ss, tower_ss_modal_stiffness=k_ss,
        tower_ss_modal_damping=c_ss, blade_modal_mass=m_b, blade_modal_stiffness=k_b,
        blade_centrifugal_stiffness=k_cf, blade_modal_damping=c_b, blade_tower_coupling=m_c,
        **edge, pack=pack)


def _element_slopes(t: Turbine, shape: FloatArray, s: FloatArray,
                    dphi: FloatArray) -> tuple[FloatArray, FloatArray]:
    """A blade mode's slope at the aero elements [1/m] (held at the tip beyond it) and the
    blade's axial shortening there per unit modal deflection squared, 0.5 int_0^s phi'^2 [1/m],
    from the slope ``dphi`` on the span grid ``s`` (``deflected_blades``)."""
    g = t.geometry
    lb = g.tip_radius - g.hub_radius
    x_el = np.minimum((t.blade.r - g.hub_radius) / lb, 1.0)
    return (mode_shape(shape, x_el, 1) / lb,
            0.5 * np.interp(x_el * lb, s, _cumtrapz(dphi**2, s)))


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
        zero = dict.fromkeys(("m_e", "k_e", "k_cf_e", "c_e", "s_e", "g_e"), 0.0)
        return {}, {"phi_edge": np.zeros_like(b.r), "dphi_edge": np.zeros_like(b.r),
                    "ax_edge": np.zeros_like(b.r), **zero}
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
    dphi_el, ax_el = _element_slopes(t, shape, s, dphi)
    kernel = {"phi_edge": mode_shape(shape, (b.r - g.hub_radius) / lb), "dphi_edge": dphi_el,
              "ax_edge": ax_el, "m_e": m_e, "k_e": k_e,
              "k_cf_e": k_cf_e, "c_e": 2.0 * t.damping.blade * math.sqrt(k_e * m_e),
              "s_e": s_e, "g_e": float(np.trapezoid(mu * phi, s))}
    return public, kernel


#: tower drag: the flexible tower's quadrature points
N_TOWER_POINTS = 20


def _tower_drag_points(t: Turbine, ht: float) -> dict[str, FloatArray]:
    """The tower-drag quadrature: heights above ground [m] (midpoints of equal segments of the
    flexible tower), weights 0.5 rho C_d D dh [kg/m], and the fore-aft and side-side mode
    shapes there (empty when the data have no diameter or drag coefficient)."""
    ts = t.tower_structure
    if ts.outer_diameter is None or ts.drag_coefficient is None:
        empty = np.zeros(0)
        return {"tq_h": empty, "tq_w": empty, "tq_fa": empty, "tq_ss": empty}
    x = (np.arange(N_TOWER_POINTS) + 0.5) / N_TOWER_POINTS
    d = np.interp(x, ts.height_fraction, ts.outer_diameter)
    cd = np.interp(x, ts.height_fraction, ts.drag_coefficient)
    return {"tq_h": t.geometry.tower_base_height + x * ht,
            "tq_w": 0.5 * t.environment.air_density * cd * d * ht / N_TOWER_POINTS,
            "tq_fa": mode_shape(t.mode_shapes.tower_fa1, x),
            "tq_ss": mode_shape(t.mode_shapes.tower_ss1, x)}


def _twisted_modes(t: Turbine, cfg: PlantConfig, s: FloatArray, mu: FloatArray,
                   phi: FloatArray, r_el: FloatArray) -> dict[str, Any]:
    """The kernel's data for modes along the twisted principal axes: the structural twist at
    each aero element [rad] and the root-moment integrals int m phi s cos/sin(twist) of the flap
    (sfc, sfs) and edge (sec, ses) modes [kg m]; rotor-plane values when off."""
    g = t.geometry
    lb = g.tip_radius - g.hub_radius
    tw_data = t.blade_structure.structural_twist_rad
    shape_e = t.mode_shapes.blade_edge1
    phi_e = mode_shape(shape_e, s / lb) if shape_e is not None else np.zeros_like(s)
    on = bool(cfg.twisted_modes and tw_data is not None)
    frac = t.blade_structure.span_fraction
    tw = np.interp(s / lb, frac, tw_data) if on else np.zeros_like(s)
    return {"on": on,
            "twist_s": (np.interp((r_el - g.hub_radius) / lb, frac, tw_data) if on
                        else np.zeros_like(r_el)),
            "sfc": float(np.trapezoid(mu * phi * s * np.cos(tw), s)),
            "sfs": float(np.trapezoid(mu * phi * s * np.sin(tw), s)),
            "sec": float(np.trapezoid(mu * phi_e * s * np.cos(tw), s)),
            "ses": float(np.trapezoid(mu * phi_e * s * np.sin(tw), s))}


#: RK4 integrates an undamped mode stably while omega h stays below 2 sqrt(2); the plant's
#: step is refused a little before that bound, where the mode's decay is already wrong.
RK4_OMEGA_H = 2.8


def check_plant_step(params: PlantParams, dt: float) -> None:
    """Refuse a plant step that cannot integrate the turbine's drivetrain torsion mode.

    The shaft's torsion mode, f = sqrt(K_shaft / J_eq) / (2 pi) with J_eq the rotor's and the
    generator's inertias in series, is the stiffest state of the plant; RK4 at step ``dt``
    diverges where 2 pi f dt > :data:`RK4_OMEGA_H`. A rigid drivetrain's stiffness given as a
    spring (a large ``DTTorSpr`` with the DOF on) lands there; a deck's ``DrTrDOF False`` holds
    the drivetrain rigid (:attr:`Turbine.rigid_dofs`), with no torsion mode to step.

    Parameters
    ----------
    params : PlantParams
        The plant.
    dt : float
        The plant's step [s].

    Raises
    ------
    ValueError
        Naming the mode's frequency, the stiffness and where it came from, the step, and the
        largest step or stiffness that would integrate.
    """
    if not (params.dof("drivetrain") and params.dof("generator")):
        return
    pk = params.pack
    j_eq = pk.j_rot * pk.j_gen * pk.ngear**2 / (pk.j_rot + pk.j_gen * pk.ngear**2)
    omega = math.sqrt(pk.k_shaft / j_eq)
    if omega * dt <= RK4_OMEGA_H:
        return
    src = params.turbine.report.source("shaft stiffness")
    k_max = (RK4_OMEGA_H / dt) ** 2 * j_eq
    raise ValueError(
        f"the drivetrain's torsion mode at {omega / (2 * math.pi):.4g} Hz (shaft stiffness "
        f"{pk.k_shaft:.4g} N m/rad{f', {src}' if src else ''}) is beyond what the plant's step "
        f"of {dt:g} s integrates ({RK4_OMEGA_H / dt / (2 * math.pi):.3g} Hz at most): a step "
        f"of at most {RK4_OMEGA_H / omega:.3g} s, or a shaft stiffness of at most "
        f"{k_max:.4g} N m/rad")


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

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
* Tower base moments: what the blade roots pass on (the thrust less the flap modes' inertia
  relative to the hub, int m phi q'', and the root moments' tilt), the tower's and the top
  mass's inertia, P-delta, gravity and drag, about the base.

References
----------
Madsen, Filsoe, Soltani (2012), IEEE CCA, doi:10.1109/CCA.2012.6402671.
Jonkman et al. (2009), NREL/TP-500-38060 (NREL 5-MW data).
Hansen (2015), Aerodynamics of Wind Turbines, ch. 11-12 (modal structural models).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numba as nb
import numpy as np

from linearize._typing import FloatArray
from linearize.errors import SimulationDivergedError
from linearize.kernel import (
    DENSE_STRIDES,
    bad_state,
    evaluate_plant,
    evaluate_plant_vw,
    new_hint,
    sample_inplane,
    sample_tower,
    sample_wind,
    simulate_kernel,
    step_kernel,
)
from linearize.params import (
    N_BLADE,
    OUTPUT_NAMES,
    STATE_NAMES,
    STATE_UNITS,
    PlantParams,
    check_plant_step,
    n_u,
    n_x,
    n_z,
)
from linearize.validate import check_array, check_positive
from linearize.wind import GridWind, SteadyWind

__all__ = ["plant_rhs", "plant_outputs", "SimulationResult", "rk4_simulate", "PlantStepper"]


# --------------------------------------------------------------------------------------------
# Public API
# --------------------------------------------------------------------------------------------
def _check_xud(x: Any, u: Any, d: Any, n_r: int) -> tuple[FloatArray, FloatArray, FloatArray]:
    x = check_array("x", x, (n_x,), shape_names="(n_x,)")
    u = check_array("u", u, (n_u,), shape_names="(n_u,)")
    d = np.asarray(d, dtype=float)
    if d.shape == (N_BLADE,):
        d = np.repeat(d[:, None], n_r, axis=1)
    d = check_array("d (wind)", d, (N_BLADE, n_r), shape_names="(n_blade, n_r) or (n_blade,)")
    if np.any(d < 0):
        raise ValueError(f"d (wind) must be >= 0 m/s, got min {d.min()!r}")
    return x.copy(), u.copy(), d.copy()   # writable: one compiled kernel for every caller


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
    hint = np.full((4, N_BLADE, params.pack.r.size), np.nan)
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
    hint = np.full((4, N_BLADE, params.pack.r.size), np.nan)
    _, z, _ = evaluate_plant(x, u, d, params.pack, hint, 0)
    return z


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
    # writable copies: numba compiles a read-only array's kernel apart
    xs, zs, us, n, bad, val = simulate_kernel(np.array(x0, dtype=float), np.array(u, order="C"),
                                        float(t0), float(dt),
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
        check_plant_step(params, self.dt)
        self.params = params
        self._kind, self._wpar, self._grid = wind._kernel_args()
        self._pack = params.pack
        self.limits = _state_limits(params)
        self.reset()

    def reset(self) -> None:
        """Forget the BEM warm start (a new run)."""
        n_r = self._pack.r.size
        self._hint = new_hint(self._pack, self.dt)
        self._dphi = np.zeros((N_BLADE, n_r))
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
            if a.strides != DENSE_STRIDES or a.dtype != np.float64:
                raise ValueError(f"{name} must be a 1-D C-contiguous float64 array, got "
                                 f"dtype {a.dtype}, strides {a.strides}")
        args = (float(t), x, u, self.dt, self._pack, self._kind, self._wpar, self._grid,
                self._hint, self._dphi, self.limits, x_out, z_out)
        if self._into_entry is None:
            self._into_entry = step_kernel.compile(tuple(nb.typeof(a) for a in args))
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
        w = sample_wind(t, x[16], self._pack, self._kind, self._wpar, self._grid[0])
        vw = sample_inplane(t, x[16], self._pack, self._kind, self._wpar, self._grid[1])
        tw = sample_tower(t, self._pack, self._kind, self._wpar, self._grid)
        return evaluate_plant_vw(x, u, w, (vw, tw), self._pack, self._hint, 0)[1]

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
        return int(bad_state(x, self.limits))

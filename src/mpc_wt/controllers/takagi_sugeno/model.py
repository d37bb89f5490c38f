"""The Takagi-Sugeno model of Clemens et al.: the plant's linear models at the vertices of a grid
over rotor-effective wind and power reduction, blended by triangular membership functions.
"""
from __future__ import annotations

import functools
import itertools
import math
from dataclasses import dataclass, field
from typing import Any, Sequence

import numba as nb
import numpy as np

import linearize
from mpc_wt.errors import PremiseError

__all__ = ["turbine_scales", "fore_aft_frequency", "SIDE_SIDE_STATES", "CLEMENS_MEASURED", "TURBINE_MEASURED", "DEFAULT_SCALES", "DEFAULT_WIND_GRID",
           "DEFAULT_REDUCTION_GRID", "TSModel", "build_ts_model"]

#: Clemens et al. eq 6: tower side-side and fore-aft displacement, rotor and generator speed.
CLEMENS_MEASURED = ("tower_ss_displacement", "tower_fa_displacement", "rotor_speed", "gen_speed")
#: The tower's side-side states of the TS model: a mode the collective pitch and the torque
#: barely reach, which the default design leaves to its own damping
#: (:func:`~mpc_wt.controllers.takagi_sugeno.synthesis.design_ts_controller`'s ``uncontrolled``).
SIDE_SIDE_STATES = ("tower_ss_displacement", "tower_ss_velocity")
#: What a turbine's controller is given in their place (the Bladed interface's records 53, 54,
#: 21 and 20): the tower-top fore-aft and side-side accelerations, rotor and generator speed.
TURBINE_MEASURED = ("tower_fa_acceleration", "tower_ss_acceleration", "rotor_speed",
                    "gen_speed")


#: Typical magnitudes of the TS model's variables (scaling of the LMIs; SI units).
DEFAULT_SCALES = {"tower_fa_displacement": 0.1, "tower_fa_velocity": 0.1, "rotor_speed": 0.1,
                  "gen_speed": 0.1 * 97.0, "shaft_torsion": 1e-3, "tower_ss_displacement": 0.02,
                  "tower_ss_velocity": 0.02, "pitch_ref_coll": math.radians(1.0),
                  "gen_torque_ref": 4e3, "wind": 1.0, "tower_fa_acceleration": 1.0,
                  "tower_ss_acceleration": 0.2}
#: (The accelerations' scales weigh the observer's trust in them: on the NREL 5-MW at 18 m/s
#: in class-A turbulence, 0.1 and 0.02 m/s^2 made the pitch travel 761 deg per blade in 120 s,
#: 1 and 0.2 138 deg (the displacements' observer: 97 deg), and 3 and 0.5 let the tower's
#: fore-aft mode go into a limit cycle.)


def turbine_scales(turbine: linearize.Turbine) -> dict[str, float]:
    """:data:`DEFAULT_SCALES` carried from the NREL 5-MW to ``turbine``: rotor and generator
    speed, generator torque and shaft torsion in proportion to the turbine's own at rated wind
    (:func:`mpc_wt.controllers.mpc.turbine_scale_ratios`; the generator speed is the rotor's
    times the gearbox ratio); displacements, accelerations, angles and the wind keep theirs.

    The tower's displacements, velocities and accelerations go with the tower top's
    fore-aft deflection at rated wind (thrust over stiffness), times its first fore-aft
    frequency to the power 0, 1 and 2 (:func:`_tower_ratios`: 2.35, 1.72 and 1.26 on the
    IEA-15-240-RWT). With the NREL 5-MW's, the IEA-15's tower moved twice as far as the
    design took as typical, and its PDC gains pitched on that motion.

    With the NREL 5-MW's scales the IEA-15's direct-drive generator speed (0.79 rad/s at
    rated) was scaled by 9.7 rad/s and its torque (19 MN m) by 4 kN m: the observer all but
    ignored the generator speed, and its drivetrain estimate swung by +-2 rad/s in steady wind.

    Parameters
    ----------
    turbine : Turbine

    Returns
    -------
    dict of str to float
        The NREL 5-MW's are :data:`DEFAULT_SCALES` exactly.
    """
    from mpc_wt.controllers.mpc import turbine_scale_ratios

    r = turbine_scale_ratios(turbine)
    out = dict(DEFAULT_SCALES)
    tower = _tower_ratios(turbine)
    for side in ("fa", "ss"):
        out[f"tower_{side}_displacement"] *= tower["displacement"]
        out[f"tower_{side}_velocity"] *= tower["velocity"]
        out[f"tower_{side}_acceleration"] *= tower["acceleration"]
    out["rotor_speed"] *= r["rotor_speed"]
    out["gen_speed"] = DEFAULT_SCALES["gen_speed"] * r["rotor_speed"] * (
        turbine.drivetrain.gearbox_ratio / 97.0)
    out["gen_torque_ref"] *= r["gen_torque_ref"]
    out["shaft_torsion"] *= r["shaft_torsion"]
    return out


def _tower_magnitudes(turbine: linearize.Turbine) -> tuple[float, float]:
    """The tower top's fore-aft deflection at rated wind [m] and the plant's first fore-aft
    frequency there [rad/s] (the eigenvalue of the linear model at rated wind, 2 m/s above,
    whose eigenvector lies most on the tower's fore-aft states)."""
    v = linearize.rated_wind_speed(turbine)
    op = linearize.trim(turbine, v)
    model = linearize.linearize(turbine, v + 2.0)
    return (abs(float(op.as_dict()["tower_fa_deflection_m"])),
            fore_aft_frequency(model.A, model.states))


def fore_aft_frequency(a: np.ndarray, states: Sequence[str]) -> float:
    """The tower's first fore-aft frequency of a linear model [rad/s]: the modulus of the
    eigenvalue of ``a`` whose eigenvector lies most on ``tower_fa_displacement`` and
    ``tower_fa_velocity`` (of those with a positive imaginary part).

    Parameters
    ----------
    a : (n, n) ndarray
        The state matrix.
    states : sequence of str
        Its states' names.

    Returns
    -------
    float
        [rad/s].

    Raises
    ------
    ValueError
        Without the tower's fore-aft states.
    """
    idx = [list(states).index(n) for n in ("tower_fa_displacement", "tower_fa_velocity")
           if n in states]
    if not idx:
        raise ValueError(f"the model has no tower fore-aft states ({list(states)})")
    ev, vec = np.linalg.eig(a)
    share = np.linalg.norm(vec[idx], axis=0) / np.linalg.norm(vec, axis=0)
    share[ev.imag <= 0] = 0.0
    return abs(complex(ev[int(np.argmax(share))]))


@functools.lru_cache(maxsize=8)
def _nrel5mw_tower() -> tuple[float, float]:
    return _tower_magnitudes(linearize.load_turbine("nrel5mw"))


def _tower_ratios(turbine: linearize.Turbine) -> dict[str, float]:
    """``turbine``'s tower-top deflection at rated wind, and its velocity and acceleration at
    the first fore-aft frequency, over the NREL 5-MW's: 1 on the NREL 5-MW (the same
    computation)."""
    d0, w0 = _nrel5mw_tower()
    d, w = _tower_magnitudes(turbine)
    return {"displacement": d / d0, "velocity": d * w / (d0 * w0),
            "acceleration": d * w * w / (d0 * w0 * w0)}


@nb.njit(cache=True, nogil=True)
def hat_weights(grid: np.ndarray, s: float) -> tuple[int, float, float, bool]:
    """The clipped premise's cell k on ``grid`` and the hat weights of its two ends (one end
    weight 1 for a single-point grid); whether ``s`` was clipped."""
    n = grid.size
    c = min(max(s, grid[0]), grid[n - 1])
    clipped = c != s
    if n == 1:
        return 0, 1.0, 0.0, clipped
    k = np.searchsorted(grid, c) - 1
    k = min(max(k, 0), n - 2)
    f = (c - grid[k]) / (grid[k + 1] - grid[k])
    return k, 1.0 - f, f, clipped


@nb.njit(cache=True, nogil=True)
def memberships(wg: np.ndarray, rg: np.ndarray, v: float, dp: float, h: np.ndarray
                 ) -> tuple[float, bool]:
    """h (zeroed, then filled) = the tensor-product hats of Clemens et al. eq 3 at the clipped
    premise (v, dp), vertex (a, b) at a * n_b + b (row-major, wind outer); returns the clipped
    dp and whether either was clipped. Compiled: the TS controller's step calls it twice."""
    h[:] = 0.0
    ka, wa0, wa1, c1 = hat_weights(wg, v)
    kb, wb0, wb1, c2 = hat_weights(rg, dp)
    nb_ = rg.size
    for ia, wa in ((ka, wa0), (ka + 1, wa1)):
        if wa == 0.0 or ia >= wg.size:
            continue
        for ib, wb in ((kb, wb0), (kb + 1, wb1)):
            if wb == 0.0 or ib >= nb_:
                continue
            h[ia * nb_ + ib] += wa * wb
    return min(max(dp, rg[0]), rg[rg.size - 1]), c1 or c2


@dataclass(frozen=True)
class TSModel:
    """Takagi-Sugeno model over the premise z = [v, Delta P] (Clemens et al. eqs 1-3).

    Vertex i = (a, b) of the grid ``wind_grid`` x ``reduction_grid`` (row-major: wind index
    outer) carries A[i] (n_x, n_x), B[i] (n_x, n_u), B_d[i] (n_x,) and the equilibrium
    x0[i], u0[i], v0[i] (v0 = the vertex wind [m/s]).

    Parameters
    ----------
    wind_grid : (n_a,) ndarray
        Vertex wind speeds [m/s], strictly increasing.
    reduction_grid : (n_b,) ndarray
        Vertex power reductions Delta P [-] in [0, 1), strictly increasing.
    A, B, B_d, x0, u0, v0 : ndarray
        Stacked over the N = n_a n_b vertices.
    states, inputs : names
    C : (n_y, n_x) or (N, n_y, n_x) ndarray
        Measured rows (``measured`` names): common to the vertices (measured states) or one
        per vertex (measured outputs such as an acceleration, whose rows are the model's).
    rated_power : float
        Electrical power at Delta P = 0 [W].
    D : (N, n_y, n_u) ndarray, optional
        The measurements' input feedthrough per vertex (default zero).
    E : (N, n_y) ndarray, optional
        Their wind feedthrough per vertex (default zero).
    y0 : (N, n_y) ndarray, optional
        Their equilibrium values per vertex (default C x0, right for measured states): a
        measurement is y0_i + C_i (x - x0_i) + D_i (u - u0_i) + E_i (v - v0_i) at vertex i.
    scales : dict of name to float, optional
        The typical magnitudes the designs scale the LMIs with (default
        :data:`DEFAULT_SCALES`, the NREL 5-MW's; :func:`build_ts_model` carries them to its
        turbine with :func:`turbine_scales`).
    """

    wind_grid: np.ndarray
    reduction_grid: np.ndarray
    A: np.ndarray
    B: np.ndarray
    B_d: np.ndarray
    x0: np.ndarray
    u0: np.ndarray
    v0: np.ndarray
    states: tuple[str, ...]
    inputs: tuple[str, ...]
    measured: tuple[str, ...]
    C: np.ndarray
    rated_power: float
    D: Any = None
    E: Any = None
    y0: Any = None
    scales: Any = None
    info: dict[str, Any] = field(default_factory=dict, compare=False)

    def __post_init__(self) -> None:
        nv0 = np.shape(self.A)[0]
        ny = len(self.measured)
        c = np.array(self.C, dtype=float)
        if c.ndim == 2:
            c = np.broadcast_to(c, (nv0,) + c.shape)
        defaults = {"C": c,
                    "D": np.zeros((nv0, ny, np.shape(self.B)[2])) if self.D is None else self.D,
                    "E": np.zeros((nv0, ny)) if self.E is None else self.E}
        if self.y0 is None and c.shape[1:] == (ny, np.shape(self.A)[1]):
            defaults["y0"] = np.einsum("iyx,ix->iy", c, np.asarray(self.x0, float))
        for n, v in defaults.items():
            object.__setattr__(self, n, v)
        for n in ("wind_grid", "reduction_grid", "A", "B", "B_d", "x0", "u0", "v0", "C", "D",
                  "E", "y0"):
            a = np.array(getattr(self, n), dtype=float)
            a.flags.writeable = False
            object.__setattr__(self, n, a)
        for n, g in (("wind_grid", self.wind_grid), ("reduction_grid", self.reduction_grid)):
            if g.ndim != 1 or g.size < 1 or np.any(np.diff(g) <= 0) or not np.all(np.isfinite(g)):
                raise ValueError(f"{n} must be finite and strictly increasing, got {g}")
        nv = self.wind_grid.size * self.reduction_grid.size
        nx, nu = len(self.states), len(self.inputs)
        want = {"A": (nv, nx, nx), "B": (nv, nx, nu), "B_d": (nv, nx), "x0": (nv, nx),
                "u0": (nv, nu), "v0": (nv,), "C": (nv, len(self.measured), nx),
                "D": (nv, len(self.measured), nu), "E": (nv, len(self.measured)),
                "y0": (nv, len(self.measured))}
        for n, shp in want.items():
            if getattr(self, n).shape != shp:
                raise ValueError(f"TSModel.{n} has shape {getattr(self, n).shape}; expected "
                                 f"{shp}")

    @property
    def common_output(self) -> bool:
        """Whether every vertex measures alike (measured states: one C, no feedthrough)."""
        return bool(np.all(self.C == self.C[0]) and not np.any(self.D) and not np.any(self.E))

    def output_offset(self) -> np.ndarray:
        """The measurements' offsets: at vertex i a measurement is C_i x + D_i u + E_i v plus
        this.

        Returns
        -------
        (N, n_y) ndarray
            y0_i - C_i x0_i - D_i u0_i - E_i v0_i [measurement units].
        """
        return (self.y0 - np.einsum("iyx,ix->iy", self.C, self.x0)
                - np.einsum("iyu,iu->iy", self.D, self.u0) - self.E * self.v0[:, None])

    @property
    def n_vertices(self) -> int:
        return self.A.shape[0]

    @property
    def vertices(self) -> np.ndarray:
        """(N, 2) premise values [v, Delta P] of the vertices."""
        return np.array(list(itertools.product(self.wind_grid, self.reduction_grid)))

    def cells(self) -> list[tuple[int, ...]]:
        """Vertex indices of each grid cell (the vertices that can be active together).

        Returns
        -------
        list of tuple of int
            Vertex indices per cell.
        """
        na, nb = self.wind_grid.size, self.reduction_grid.size
        out = []
        for a in range(max(na - 1, 1)):
            for b in range(max(nb - 1, 1)):
                ia = [a] if na == 1 else [a, a + 1]
                ib = [b] if nb == 1 else [b, b + 1]
                out.append(tuple(i * nb + j for i in ia for j in ib))
        return out

    def active_pairs(self) -> list[tuple[int, int]]:
        """The ordered vertex pairs (i, j), i = j included, that can be active together (in
        one cell).

        Returns
        -------
        list of (int, int)
            Sorted.
        """
        return sorted({(i, j) for cell in self.cells() for i in cell for j in cell})

    def check_premise(self, wind: float, reduction: float) -> None:
        """Raise :class:`PremiseError` unless [wind, reduction] lies in the vertex grid.

        Parameters
        ----------
        wind : float
            Premise wind [m/s].
        reduction : float
            Premise power reduction [-].
        """
        for name, s, g, unit in (("wind speed", wind, self.wind_grid, " m/s"),
                                 ("power reduction", reduction, self.reduction_grid, "")):
            tol = 1e-9 * max(1.0, abs(g[-1]))
            if not (math.isfinite(s) and g[0] - tol <= s <= g[-1] + tol):
                raise PremiseError(f"premise {name} = {s!r}{unit} is outside the TS model's "
                                   f"vertices {g[0]:g}..{g[-1]:g}{unit}; add vertices or clip")

    def membership(self, wind: float, reduction: float = 0.0) -> np.ndarray:
        """h_i(z) for z = [wind, reduction] (N,): >= 0, summing to 1 (eq 3).


        Parameters
        ----------
        wind : float
            Premise wind [m/s].
        reduction : float
            Premise power reduction [-].

        Returns
        -------
        (N,) ndarray
            Memberships h_i [-].

        Raises
        ------
        PremiseError
            If z is outside the vertex grid (or not finite).
        """
        self.check_premise(wind, reduction)
        h = np.empty(self.n_vertices)
        memberships(self.wind_grid, self.reduction_grid, float(wind), float(reduction), h)
        return h

    def wind_at_pitch(self, pitch: float) -> float:
        """The wind whose vertex equilibrium (no power reduction) has a collective pitch,
        interpolated linearly over the wind grid and clipped to it: where an observer can
        start from a measured pitch.

        Parameters
        ----------
        pitch : float
            Collective pitch [rad].

        Returns
        -------
        float
            Wind speed [m/s].
        """
        dp0 = float(self.reduction_grid[0])
        eq = np.array([self.blend(self.membership(float(v), dp0))["u0"][0]
                       for v in self.wind_grid])
        order = np.argsort(eq)
        return float(np.interp(pitch, eq[order], np.asarray(self.wind_grid, float)[order]))

    def blend(self, h: np.ndarray) -> dict[str, np.ndarray]:
        """The model's matrices and equilibria weighted by memberships ``h``.

        Parameters
        ----------
        h : (N,) ndarray
            Memberships.

        Returns
        -------
        dict of str to ndarray
            ``A``, ``B``, ``B_d``, ``x0``, ``u0``, ``v0`` weighted by ``h``.
        """
        return {n: np.tensordot(h, getattr(self, n), axes=1)
                for n in ("A", "B", "B_d", "x0", "u0", "v0")}

    def rhs(self, x: np.ndarray, u: np.ndarray, v: float, reduction: float = 0.0) -> np.ndarray:
        """dx/dt of eq 1 with premise [v, reduction] [state units / s].

        Parameters
        ----------
        x : (n_x,) ndarray
            State.
        u : (n_u,) ndarray
            Inputs.
        v : float
            Wind [m/s] (the premise and the disturbance).
        reduction : float
            Premise power reduction [-].

        Returns
        -------
        (n_x,) ndarray
            dx/dt.
        """
        h = self.membership(v, reduction)
        x, u = np.asarray(x, dtype=float), np.asarray(u, dtype=float)
        return sum(h[i] * (self.A[i] @ (x - self.x0[i]) + self.B[i] @ (u - self.u0[i])
                           + self.B_d[i] * (v - self.v0[i]))
                   for i in np.nonzero(h)[0])

    def to_dict(self) -> dict[str, Any]:
        """Plain data for JSON.

        Returns
        -------
        dict
            Grids, names and the vertex matrices as lists.
        """
        return {"wind_grid": self.wind_grid.tolist(), "reduction_grid":
                self.reduction_grid.tolist(), "states": list(self.states),
                "inputs": list(self.inputs), "measured": list(self.measured),
                "rated_power": self.rated_power, "A": self.A.tolist(), "B": self.B.tolist(),
                "B_d": self.B_d.tolist(), "x0": self.x0.tolist(), "u0": self.u0.tolist(),
                "v0": self.v0.tolist(), "C": self.C.tolist(), "D": self.D.tolist(),
                "E": self.E.tolist(), "y0": self.y0.tolist()}


#: The vertex grids of the TS model the controller kind ``ts`` builds: winds [m/s] and power
#: reductions [-].
DEFAULT_WIND_GRID = (12.0, 14.0, 16.0, 19.0, 22.0, 25.0)
DEFAULT_REDUCTION_GRID = (0.0, 0.4, 0.8)


def build_ts_model(turbine: linearize.Turbine,
                   wind_grid: Sequence[float] = DEFAULT_WIND_GRID,
                   reduction_grid: Sequence[float] = DEFAULT_REDUCTION_GRID, *,
                   measured: Sequence[str] = CLEMENS_MEASURED,
                   progress: bool = False) -> TSModel:
    """The TS model of ``turbine`` at the vertices wind_grid x reduction_grid.

    Each vertex is a :func:`linearize.linearize` of the Clemens 7-state configuration with one
    rotor-effective wind disturbance, in multi-blade coordinates (collective pitch input), at
    the trim for electrical power (1 - Delta P) P_rated (full load: rated rotor speed).


    Returns
    -------
    TSModel
        Vertex matrices, equilibria and memberships over the grid.


    Parameters
    ----------
    turbine : Turbine
        The turbine.
    wind_grid : sequence of float
        Vertex winds [m/s], increasing.
    reduction_grid : sequence of float
        Vertex power reductions Delta P in [0, 1) [-].
    measured : sequence of str
        The measured states or outputs (default Clemens et al.'s; :data:`TURBINE_MEASURED`
        is what a turbine's controller is given).
    progress : bool
        Show a progress bar.

    Raises
    ------
    ValueError
        A grid not strictly increasing, a reduction outside [0, 1), an unknown measured name.
    linearize.TrimError
        A vertex that cannot be trimmed (wind outside cut-in..cut-out, power not available).
    """
    from tqdm import tqdm

    va = np.asarray(wind_grid, dtype=float)
    vb = np.asarray(reduction_grid, dtype=float)
    if vb.size and (vb.min() < 0 or vb.max() >= 1):
        raise ValueError(f"reduction_grid values must be in [0, 1), got {vb}")
    rated = turbine.operation.rated_power
    cfg = linearize.PlantConfig.clemens()
    params = linearize.plant_params(turbine, cfg)
    mats: dict[str, list[np.ndarray]] = {k: [] for k in ("A", "B", "B_d", "x0", "u0", "v0",
                                                         "C", "D", "E", "y0")}
    model = None
    for v, dp in tqdm(list(itertools.product(va, vb)), desc="TS vertices", unit="vertex",
                      disable=not progress):
        m = linearize.linearize(turbine, float(v), params=params, disturbance="rotor",
                                coordinates="mbc",
                                power_W=None if dp == 0 else rated * (1.0 - float(dp)))
        model = m.select(inputs=("pitch_ref_coll", "gen_torque_ref"))
        mats["A"].append(model.A)
        mats["B"].append(model.B_u)
        mats["B_d"].append(model.B_d[:, 0])
        mats["x0"].append(model.x0)
        mats["u0"].append(model.u0)
        mats["v0"].append(np.asarray(v))
        bad = [n for n in measured if n not in model.states and n not in model.outputs]
        if bad:
            raise ValueError(f"measured {bad} are neither states nor outputs of the TS model "
                             f"(states {list(model.states)}, outputs {list(model.outputs)})")
        for key, val in zip(("C", "D", "E", "y0"), _measurement_rows(model, measured)):
            mats[key].append(val)
    assert model is not None
    return TSModel(wind_grid=va, reduction_grid=vb, states=model.states, inputs=model.inputs,
                   measured=tuple(measured), rated_power=float(rated),
                   scales=turbine_scales(turbine),
                   info={"turbine": turbine.name, "config": "clemens"},
                   **{k: np.array(v) for k, v in mats.items()})


def _measurement_rows(model: linearize.LinearModel, measured: Sequence[str]
                      ) -> tuple[np.ndarray, ...]:
    """C, D, E (wind) and y0 rows of the measured names at one vertex: a state's unit row, or
    an output's rows of the linear model (an acceleration responds to inputs and wind)."""
    nx, nu = len(model.states), len(model.inputs)
    rows = []
    for n in measured:
        if n in model.states:
            i = model.states.index(n)
            rows.append((np.eye(nx)[i], np.zeros(nu), 0.0, model.x0[i]))
        else:
            i = model.outputs.index(n)
            rows.append((model.C_z[i], model.D_u[i], model.D_d[i, 0], model.z0[i]))
    return tuple(np.array([r[k] for r in rows], dtype=float) for k in range(4))

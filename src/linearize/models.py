"""Linear models of the plant and families of them over mean wind: containers with their
names, units and operating points, their transforms (actuator states, a power input), and
their files (``.mat``, ``.npz``, ``.json``).
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Sequence

import numpy as np
import scipy.linalg

from linearize._typing import FloatArray
from linearize.errors import LinearizationError
from linearize.validate import check_finite_scalar, check_positive

__all__ = ["SCHEMA_VERSION", "LinearModel", "augment_actuator", "with_power_input",
           "LinearModelFamily", "sensitivities"]

SCHEMA_VERSION = 1


# --------------------------------------------------------------------------------------------
# The model
# --------------------------------------------------------------------------------------------
def _frozen(a: Any) -> FloatArray:
    arr = np.array(a, dtype=float)
    arr.flags.writeable = False
    return arr


@dataclass(frozen=True)
class LinearModel:
    """A linear model about an operating point (Madsen et al. 2012, eqs 18-19).

    Parameters
    ----------
    A : (n_x, n_x) ndarray
    B_u : (n_x, n_u) ndarray
    B_d : (n_x, n_d) ndarray
    C_z : (n_z, n_x) ndarray
    D_u : (n_z, n_u) ndarray
    D_d : (n_z, n_d) ndarray
    states, inputs, disturbances, outputs : tuple of str
        Names (see docs/nomenclature.md; MBC models use ``_coll``, ``_cos``, ``_sin``).
    state_units, input_units, disturbance_units, output_units : tuple of str
    x0, u0, d0, z0 : ndarray
        Operating-point values of the states, inputs, disturbances and outputs; the model's
        variables are perturbations from them.
    wind_mps : float
        Mean (hub-height) wind speed of the operating point [m/s].
    wake : str
        "quasi-steady" or "frozen".
    coordinates : str
        "blade" or "mbc".
    dt : float or None
        Sample time of a discrete model [s]; None for continuous.
    info : dict
        Operating-point summary (pitch, rotor speed, power, region, config).
    """

    A: FloatArray
    B_u: FloatArray
    B_d: FloatArray
    C_z: FloatArray
    D_u: FloatArray
    D_d: FloatArray
    states: tuple[str, ...]
    inputs: tuple[str, ...]
    disturbances: tuple[str, ...]
    outputs: tuple[str, ...]
    state_units: tuple[str, ...]
    input_units: tuple[str, ...]
    disturbance_units: tuple[str, ...]
    output_units: tuple[str, ...]
    x0: FloatArray
    u0: FloatArray
    d0: FloatArray
    z0: FloatArray
    wind_mps: float
    wake: str = "quasi-steady"
    coordinates: str = "blade"
    dt: float | None = None
    info: dict[str, Any] = field(default_factory=dict, compare=False)

    def __post_init__(self) -> None:
        for name in ("A", "B_u", "B_d", "C_z", "D_u", "D_d", "x0", "u0", "d0", "z0"):
            object.__setattr__(self, name, _frozen(getattr(self, name)))
        nx, nu, nd, nz = len(self.states), len(self.inputs), len(self.disturbances), \
            len(self.outputs)
        shapes = {"A": (nx, nx), "B_u": (nx, nu), "B_d": (nx, nd), "C_z": (nz, nx),
                  "D_u": (nz, nu), "D_d": (nz, nd), "x0": (nx,), "u0": (nu,), "d0": (nd,),
                  "z0": (nz,)}
        for name, shp in shapes.items():
            got = getattr(self, name).shape
            if got != shp:
                raise ValueError(f"LinearModel.{name} has shape {got}; expected {shp} "
                                 f"(n_x, n_u, n_d, n_z = {nx}, {nu}, {nd}, {nz})")
        for name in ("A", "B_u", "B_d", "C_z", "D_u", "D_d"):
            m = getattr(self, name)
            if not np.all(np.isfinite(m)):
                i = np.argwhere(~np.isfinite(m))[0]
                raise LinearizationError(f"LinearModel.{name}[{i[0]}, {i[1]}] is {m[tuple(i)]}")

    # -- sizes and lookup
    @property
    def n_x(self) -> int:
        """Number of states."""
        return len(self.states)

    def index(self, kind: str, name: str) -> int:
        """Index of a named state, input, disturbance or output (``kind`` e.g. "output").

        Parameters
        ----------
        kind : {"state", "input", "disturbance", "output"}
            Which names to look in.
        name : str
            The name.

        Returns
        -------
        int
            Its index.
        """
        names = {"state": self.states, "input": self.inputs, "disturbance": self.disturbances,
                 "output": self.outputs}[kind]
        if name not in names:
            raise KeyError(f"no {kind} {name!r}; {kind}s are {list(names)}")
        return names.index(name)

    # -- transformations
    def discretize(self, dt: float) -> "LinearModel":
        """Zero-order hold on inputs and disturbances at sample time ``dt`` [s].

        Parameters
        ----------
        dt : float
            Sample time [s].

        Returns
        -------
        LinearModel
            The discrete-time model.

        Raises
        ------
        ValueError
            If ``dt`` is not finite and > 0 or the model is already discrete.
        """
        check_positive("dt", dt)
        if self.dt is not None:
            raise ValueError(f"model is already discrete (dt = {self.dt} s)")
        nx, nu = self.n_x, len(self.inputs)
        b = np.hstack([self.B_u, self.B_d])
        m = np.zeros((nx + b.shape[1], nx + b.shape[1]))
        m[:nx, :nx] = self.A
        m[:nx, nx:] = b
        e = scipy.linalg.expm(m * dt)
        return replace(self, A=e[:nx, :nx], B_u=e[:nx, nx:nx + nu], B_d=e[:nx, nx + nu:],
                       dt=float(dt))

    def to_statespace(self) -> Any:
        """python-control ``StateSpace`` with inputs [u, d] and the model's names.

        Returns
        -------
        control.StateSpace
            The model.
        """
        import control

        return control.ss(self.A, np.hstack([self.B_u, self.B_d]), self.C_z,
                          np.hstack([self.D_u, self.D_d]), 0 if self.dt is None else self.dt,
                          states=list(self.states),
                          inputs=list(self.inputs) + list(self.disturbances),
                          outputs=list(self.outputs))

    def select(self, inputs: Sequence[str] | None = None,
               disturbances: Sequence[str] | None = None,
               outputs: Sequence[str] | None = None) -> "LinearModel":
        """The same dynamics with a subset of inputs, disturbances and outputs (names).

        Parameters
        ----------
        inputs, disturbances, outputs : sequence of str, optional
            The names kept (default: all).

        Returns
        -------
        LinearModel
            The reduced model.
        """
        iu = [self.index("input", n) for n in (inputs or self.inputs)]
        idd = [self.index("disturbance", n) for n in (disturbances or self.disturbances)]
        iz = [self.index("output", n) for n in (outputs or self.outputs)]
        return replace(
            self, B_u=self.B_u[:, iu], B_d=self.B_d[:, idd], C_z=self.C_z[iz],
            D_u=self.D_u[np.ix_(iz, iu)], D_d=self.D_d[np.ix_(iz, idd)],
            inputs=tuple(self.inputs[i] for i in iu),
            input_units=tuple(self.input_units[i] for i in iu),
            disturbances=tuple(self.disturbances[i] for i in idd),
            disturbance_units=tuple(self.disturbance_units[i] for i in idd),
            outputs=tuple(self.outputs[i] for i in iz),
            output_units=tuple(self.output_units[i] for i in iz),
            u0=self.u0[iu], d0=self.d0[idd], z0=self.z0[iz])

    def modes(self) -> list[dict[str, Any]]:
        """Oscillatory modes: frequency [Hz], damping ratio [-] and a name from participation.

        The name is the state group with the largest participation factor abs(phi_k psi_k)
        (right and left eigenvectors): tower fore-aft, tower side-side, drivetrain torsion,
        blade flap or blade edge (collective or asymmetric), rotor, pitch actuator.

        Returns
        -------
        list of dict
            One per oscillatory mode: ``frequency_Hz`` (natural), ``damped_frequency_Hz``,
            ``damping_ratio`` and ``name``.
        """
        a = self.A
        if self.dt is not None:
            a = scipy.linalg.logm(self.A).real / self.dt
        lam, vr = scipy.linalg.eig(a)
        vl = np.linalg.inv(vr)
        part = np.abs(vr * vl.T)
        out = []
        for k in np.argsort(np.abs(lam)):
            if lam[k].imag <= 1e-9:
                continue
            wn = abs(lam[k])
            name = self._mode_name(part[:, k], vr[:, k])
            out.append({"frequency_Hz": float(wn / (2 * math.pi)),
                        "damped_frequency_Hz": float(lam[k].imag / (2 * math.pi)),
                        "damping_ratio": float(-lam[k].real / wn), "name": name})
        return out

    def _mode_name(self, part: FloatArray, vec: np.ndarray) -> str:
        groups = {"tower fore-aft": ("tower_fa_",), "tower side-side": ("tower_ss_",),
                  "drivetrain torsion": ("shaft_torsion", "gen_speed"),
                  "rotor": ("rotor_speed",), "blade flap": ("flap",), "blade edge": ("edge",),
                  "pitch actuator": ("pitch",)}
        score = {}
        for g, prefixes in groups.items():
            idx = [i for i, n in enumerate(self.states) if n.startswith(prefixes)]
            score[g] = float(part[idx].sum()) if idx else 0.0
        best = max(score, key=score.get)
        if best in ("blade flap", "blade edge"):
            stem = best.split()[1] + "_"
            idx = [i for i, n in enumerate(self.states) if n.startswith(stem) and "rate" not in n]
            if self.coordinates == "mbc":
                coll = [i for i in idx if self.states[i].endswith("_coll")]
                share = part[coll].sum() / max(part[idx].sum(), 1e-300)
            else:
                v = vec[idx]
                share = abs(v.sum()) / max(np.abs(v).sum(), 1e-300)
            best += " (collective)" if share > 0.5 else " (asymmetric)"
        return best

    # -- I/O
    def to_dict(self) -> dict[str, Any]:
        """Plain dict (lists, floats, strings) for JSON.

        Returns
        -------
        dict
            Names and units of states, inputs, disturbances and outputs, the matrices
            (``A``, ``B_u``, ``B_d``, ``C_z``, ``D_u``, ``D_d``), the operating point, wake,
            coordinates, sample time and schema version.
        """
        d = {k: getattr(self, k) for k in ("states", "inputs", "disturbances", "outputs",
                                            "state_units", "input_units", "disturbance_units",
                                            "output_units", "wake", "coordinates", "dt", "info")}
        d["wind_speed"] = self.wind_mps       # the file key (schema 1) keeps its name
        for k in ("A", "B_u", "B_d", "C_z", "D_u", "D_d", "x0", "u0", "d0", "z0"):
            d[k] = getattr(self, k).tolist()
        d = {k: (list(v) if isinstance(v, tuple) else v) for k, v in d.items()}
        d["schema_version"] = SCHEMA_VERSION
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "LinearModel":
        """Inverse of :meth:`to_dict`; rejects another schema version."""
        if d.get("schema_version") != SCHEMA_VERSION:
            raise ValueError(f"schema_version must be {SCHEMA_VERSION}, got "
                             f"{d.get('schema_version')!r}")
        kw = {k: v for k, v in d.items() if k not in ("schema_version", "wind_speed")}
        kw["wind_mps"] = d["wind_speed"]
        for k in ("states", "inputs", "disturbances", "outputs", "state_units", "input_units",
                  "disturbance_units", "output_units"):
            kw[k] = tuple(kw[k])
        return cls(**kw)


# --------------------------------------------------------------------------------------------
# Forms
# --------------------------------------------------------------------------------------------
def augment_actuator(model: LinearModel, time_constant: float,
                     inputs: Sequence[str] = ("pitch_ref_1", "pitch_ref_2", "pitch_ref_3")
                     ) -> LinearModel:
    """Append first-order actuator states to a model whose inputs act directly (Do et al.
    2020, eq 6): d/dt [x; beta] = [[A, B], [0, -I/tau]] [x; beta] + [0; I/tau] u.

    The new states are named after the inputs with ``_ref`` dropped (``pitch_1`` ...).

    Parameters
    ----------
    model : LinearModel
        The model.
    time_constant : float
        Actuator time constant tau [s].
    inputs : sequence of str
        The inputs that get an actuator.

    Returns
    -------
    LinearModel
        The augmented model.

    Raises
    ------
    ValueError
        If the time constant is not > 0, an input is unknown, or the state exists already.
    """
    tau = check_positive("time_constant", time_constant)
    idx = [model.index("input", n) for n in inputs]
    new = tuple(n.replace("_ref", "") for n in inputs)
    clash = [n for n in new if n in model.states]
    if clash:
        raise ValueError(f"model already has states {clash}: it already includes the actuator")
    nx, k = model.n_x, len(idx)
    a = np.zeros((nx + k, nx + k))
    a[:nx, :nx] = model.A
    a[:nx, nx:] = model.B_u[:, idx]
    a[nx:, nx:] = -np.eye(k) / tau
    b = np.vstack([model.B_u, np.zeros((k, model.B_u.shape[1]))])
    b[:nx, idx] = 0.0
    b[nx + np.arange(k), idx] = 1.0 / tau
    bd = np.vstack([model.B_d, np.zeros((k, model.B_d.shape[1]))])
    c = np.hstack([model.C_z, model.D_u[:, idx]])
    du = model.D_u.copy()
    du[:, idx] = 0.0
    return replace(model, A=a, B_u=b, B_d=bd, C_z=c, D_u=du, states=model.states + new,
                   state_units=model.state_units + tuple(model.input_units[i] for i in idx),
                   x0=np.concatenate([model.x0, model.u0[idx]]))


def with_power_input(model: LinearModel, generator_efficiency: float) -> LinearModel:
    """Replace the generator-torque input by an electrical power reference.

    The converter sets T_g = P_ref / (eta omega_g), so
    dT_g = dP_ref / (eta omega_g0) - P_0 / (eta omega_g0^2) d omega_g: the torque input column
    becomes the power input (scaled) and feeds back on generator speed. This is the model of a
    turbine following a power reference (down-regulation, active power control; Clemens et al.
    eq 11).

    Parameters
    ----------
    model : LinearModel
        A model with a generator-torque input.
    generator_efficiency : float
        eta [-].

    Returns
    -------
    LinearModel
        The model with ``power_ref`` in place of ``gen_torque_ref``.

    Raises
    ------
    ValueError
        If the model has no ``gen_torque_ref`` input or no ``gen_speed`` state.
    """
    eta = check_positive("generator_efficiency", generator_efficiency)
    it = model.index("input", "gen_torque_ref")
    iw = model.index("state", "gen_speed")
    wg0 = model.x0[iw]
    tg0 = model.u0[it]
    p0 = eta * tg0 * wg0
    k_w = -p0 / (eta * wg0**2)
    a = model.A + np.outer(model.B_u[:, it], np.eye(model.n_x)[iw]) * k_w
    c = model.C_z + np.outer(model.D_u[:, it], np.eye(model.n_x)[iw]) * k_w
    b = model.B_u.copy()
    d = model.D_u.copy()
    b[:, it] /= eta * wg0
    d[:, it] /= eta * wg0
    inputs = list(model.inputs)
    units = list(model.input_units)
    inputs[it], units[it] = "power_ref", "W"
    u0 = model.u0.copy()
    u0[it] = p0
    return replace(model, A=a, B_u=b, C_z=c, D_u=d, inputs=tuple(inputs),
                   input_units=tuple(units), u0=u0)


# --------------------------------------------------------------------------------------------
# Family over mean wind
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class LinearModelFamily:
    """Linear models on a grid of mean wind speeds, interpolated linearly between them.

    Parameters
    ----------
    wind_mps : (n_op,) ndarray
        Strictly increasing [m/s].
    models : tuple of LinearModel
        One per wind speed, with identical names.
    """

    wind_mps: FloatArray
    models: tuple[LinearModel, ...]

    def __post_init__(self) -> None:
        v = _frozen(self.wind_mps)
        object.__setattr__(self, "wind_mps", v)
        check_wind_grid(v)
        if len(self.models) != v.size:
            raise ValueError(f"{len(self.models)} models for {v.size} wind speeds")
        ref = self.models[0]
        for m in self.models[1:]:
            if (m.states, m.inputs, m.disturbances, m.outputs) != (ref.states, ref.inputs,
                                                                  ref.disturbances, ref.outputs):
                raise ValueError("models of a family must have the same names")

    def stacked(self, name: str) -> FloatArray:
        """Matrices or operating-point vectors stacked over wind: (n_op, ...).

        Parameters
        ----------
        name : str
            An attribute of :class:`LinearModel`: ``A``, ``B_u``, ``B_d``, ``C_z``, ``D_u``,
            ``D_d``, ``x0``, ``u0``, ``d0`` or ``z0``.

        Returns
        -------
        (n_op, ...) ndarray
            The stack.
        """
        return np.stack([getattr(m, name) for m in self.models])

    def at(self, wind_mps: float) -> LinearModel:
        """The model at a mean wind speed, interpolated linearly in every matrix and in the
        operating point between the two neighbouring grid points.

        Parameters
        ----------
        wind_mps : float
            Mean wind speed [m/s].

        Returns
        -------
        LinearModel
            The interpolated model.

        Raises
        ------
        ValueError
            If the wind speed is outside the family's range.
        """
        v = check_finite_scalar("wind_mps", wind_mps)
        lo, hi = float(self.wind_mps[0]), float(self.wind_mps[-1])
        if not lo <= v <= hi:
            raise ValueError(f"wind_mps = {v:g} m/s is outside the family's range "
                             f"{lo:g}..{hi:g} m/s")
        k = int(np.clip(np.searchsorted(self.wind_mps, v) - 1, 0, self.wind_mps.size - 2))
        w = (v - self.wind_mps[k]) / (self.wind_mps[k + 1] - self.wind_mps[k])
        m0, m1 = self.models[k], self.models[k + 1]
        mix = {n: (1 - w) * getattr(m0, n) + w * getattr(m1, n)
               for n in ("A", "B_u", "B_d", "C_z", "D_u", "D_d", "x0", "u0", "d0", "z0")}
        return replace(m0, wind_mps=v, info={"interpolated_between": [m0.wind_mps,
                                                                       m1.wind_mps]}, **mix)

    # -- I/O
    def save(self, path: str | Path) -> Path:
        """Write ``.mat`` (MATLAB), ``.npz`` or ``.json`` by the file suffix.

        Parameters
        ----------
        path : str or Path
            ``.mat``, ``.npz`` or ``.json``.

        Returns
        -------
        Path
            The file written.
        """
        path = Path(path)
        suffix = path.suffix.lower()
        ref = self.models[0]
        names = {"state_names": list(ref.states), "input_names": list(ref.inputs),
                 "disturbance_names": list(ref.disturbances), "output_names": list(ref.outputs),
                 "state_units": list(ref.state_units), "input_units": list(ref.input_units),
                 "disturbance_units": list(ref.disturbance_units),
                 "output_units": list(ref.output_units)}
        meta = {"schema_version": SCHEMA_VERSION, "wake": ref.wake,
                "coordinates": ref.coordinates, "info": [m.info for m in self.models]}
        mats = {k: self.stacked(k) for k in ("A", "B_u", "B_d", "C_z", "D_u", "D_d", "x0", "u0",
                                              "d0", "z0")}
        if suffix == ".mat":
            import scipy.io

            out: dict[str, Any] = {"wind_speed": self.wind_mps.reshape(-1, 1)}
            matlab = {"A": "A", "B_u": "Bu", "B_d": "Bd", "C_z": "Cz", "D_u": "Du", "D_d": "Dd"}
            for k, mk in matlab.items():
                out[mk] = np.moveaxis(mats[k], 0, -1)   # A(:, :, k) is the k-th wind speed
            for k, mk in (("x0", "x_op"), ("u0", "u_op"), ("d0", "d_op"), ("z0", "z_op")):
                out[mk] = mats[k].T
            for k, v in names.items():
                out[k] = np.array(v, dtype=object).reshape(-1, 1)
            out["meta_json"] = json.dumps(meta)
            scipy.io.savemat(path, out, do_compression=True)
        elif suffix == ".npz":
            np.savez_compressed(path, wind_speed=self.wind_mps, **mats,
                                names_json=json.dumps(names), meta_json=json.dumps(meta))
        elif suffix == ".json":
            path.write_text(json.dumps({"wind_speed": self.wind_mps.tolist(), **meta,
                                        **names,
                                        "models": [m.to_dict() for m in self.models]}))
        else:
            raise ValueError(f"file suffix must be .mat, .npz or .json, got {path.suffix!r}")
        return path

    @classmethod
    def load(cls, path: str | Path) -> "LinearModelFamily":
        """Read a family written by :meth:`save` (any of the three formats).

        Raises
        ------
        ValueError
            If the file is of another schema version or misses a field.
        """
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix == ".json":
            d = json.loads(path.read_text())
            _check_schema(d.get("schema_version"), path)
            return cls(np.array(d["wind_speed"]),
                       tuple(LinearModel.from_dict(m) for m in d["models"]))
        if suffix == ".mat":
            import scipy.io

            raw = scipy.io.loadmat(path)
            meta = json.loads(str(raw["meta_json"][0]))
            _check_schema(meta.get("schema_version"), path)
            v = raw["wind_speed"].ravel()
            mats = {k: np.moveaxis(raw[mk], -1, 0) for k, mk in
                    (("A", "A"), ("B_u", "Bu"), ("B_d", "Bd"), ("C_z", "Cz"), ("D_u", "Du"),
                     ("D_d", "Dd"))}
            for k, mk in (("x0", "x_op"), ("u0", "u_op"), ("d0", "d_op"), ("z0", "z_op")):
                mats[k] = raw[mk].T
            names = {k: tuple(str(s[0]) for s in raw[k].ravel()) for k in
                     ("state_names", "input_names", "disturbance_names", "output_names",
                      "state_units", "input_units", "disturbance_units", "output_units")}
        elif suffix == ".npz":
            with np.load(path, allow_pickle=False) as raw:
                meta = json.loads(str(raw["meta_json"]))
                _check_schema(meta.get("schema_version"), path)
                v = raw["wind_speed"]
                mats = {k: raw[k] for k in ("A", "B_u", "B_d", "C_z", "D_u", "D_d", "x0", "u0",
                                             "d0", "z0")}
                names = {k: tuple(val) for k, val in json.loads(str(raw["names_json"])).items()}
        else:
            raise ValueError(f"file suffix must be .mat, .npz or .json, got {path.suffix!r}")
        models = []
        for k, vk in enumerate(v):
            models.append(LinearModel(
                **{n: mats[n][k] for n in mats}, states=names["state_names"],
                inputs=names["input_names"], disturbances=names["disturbance_names"],
                outputs=names["output_names"], state_units=names["state_units"],
                input_units=names["input_units"], disturbance_units=names["disturbance_units"],
                output_units=names["output_units"], wind_mps=float(vk), wake=meta["wake"],
                coordinates=meta["coordinates"], info=meta["info"][k]))
        return cls(np.asarray(v, dtype=float), tuple(models))


def _check_schema(version: Any, path: Path) -> None:
    if version != SCHEMA_VERSION:
        raise ValueError(f"{path}: schema_version must be {SCHEMA_VERSION}, got {version!r}")


def check_wind_grid(v: FloatArray) -> None:
    """Raise unless a family's wind grid is finite, 1-D and strictly increasing.

    Parameters
    ----------
    v : (n_op,) ndarray
        Mean wind speeds [m/s].

    Raises
    ------
    ValueError
        Naming the first pair out of order.
    """
    if v.ndim != 1 or v.size < 1 or not np.all(np.isfinite(v)):
        raise ValueError(f"wind_mps must be a finite 1-D array, got {v!r}")
    if np.any(np.diff(v) <= 0):
        i = int(np.argmax(np.diff(v) <= 0))
        raise ValueError(f"wind_mps must be strictly increasing; {v[i + 1]:g} follows "
                         f"{v[i]:g} m/s")


def sensitivities(model: LinearModel) -> dict[str, float]:
    """Aerodynamic sensitivities of a blade-coordinate or MBC model.

    Parameters
    ----------
    model : LinearModel
        A model with ``aero_power``, ``aero_torque`` and ``thrust`` outputs.

    Returns
    -------
    dict
        ``dP_dpitch_W_per_rad``: aerodynamic power per collective pitch (all blades together)
        [W/rad]; ``dQ_domega``: aerodynamic torque per rotor speed [N m s/rad];
        ``dT_dV``: thrust per uniform wind speed [N s/m].
    """
    io_p = model.index("output", "aero_power")
    io_q = model.index("output", "aero_torque")
    io_t = model.index("output", "thrust")
    blade = [n for n in model.states if n.startswith("pitch_")]
    if model.coordinates == "mbc":
        if "pitch_coll" in model.states:
            dp = model.C_z[io_p, model.index("state", "pitch_coll")]
        else:
            dp = model.D_u[io_p, model.index("input", "pitch_ref_coll")]
        dt = model.D_d[io_t, 0]
    else:
        if blade:
            dp = sum(model.C_z[io_p, model.index("state", n)] for n in blade)
        else:
            dp = sum(model.D_u[io_p, model.index("input", f"pitch_ref_{i}")] for i in (1, 2, 3))
        dt = model.D_d[io_t].sum()
    return {"dP_dpitch_W_per_rad": float(dp),
            "dQ_domega": float(model.C_z[io_q, model.index("state", "rotor_speed")]),
            "dT_dV": float(dt)}

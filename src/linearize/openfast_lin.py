"""OpenFAST linearization files (``.lin``) as :class:`~linearize.LinearModel`, the multi-blade
coordinate transform of a set of them (MBC3, Bir 2008), and our models written in that layout.

One file is one linearization at one rotor azimuth: the operating point and the rotating-frame
flag of every state, input and output, and the matrices A, B, C, D. :func:`read_lin` names the
ElastoDyn states and inputs it knows by our names (:data:`linearize.STATE_NAMES`,
:data:`linearize.INPUT_NAMES`: ``tower_fa_displacement``, ``flap_1``, ``pitch_ref_1``,
``gen_torque_ref``, ...), keeps the others under their OpenFAST descriptions, keeps output
channels under their OpenFAST names (``RtAeroMxh``, ``GenPwr``) and units, and splits the
InflowWind inputs off as disturbances.

:func:`read_lin_set` takes the files of one operating point at several azimuths, transforms each
to non-rotating coordinates (Bir 2008, NREL/TP-500-42553, eqs 6-16: for blade quantities q_b =
q_0 + q_c cos psi_b + q_s sin psi_b with psi_b = psi + 2 pi (b - 1)/3, and for second-order
states the Omega-dependent terms of the velocity transform) and averages them over azimuth. The
transform is the one :func:`linearize.linearize` applies to our plant (``coordinates="mbc"``);
the tests write our blade-coordinate models at 8 azimuths with :func:`write_lin`, read them back
through :func:`read_lin_set` and compare with our own MBC model.
"""
from __future__ import annotations

import logging
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from linearize._typing import FloatArray
from linearize.errors import LinearizationError, LinFileError
from linearize.linear import mbc_matrices
from linearize.models import LinearModel
from linearize.openfast_channels import SI_UNIT, resolve_channels, unit_key

__all__ = ["read_lin", "read_lin_set", "write_lin", "compare_with_openfast", "LinFileError"]

_log = logging.getLogger("linearize.openfast_lin")


@dataclass(frozen=True)
class _Rows:
    op: FloatArray
    rotating: np.ndarray
    order: np.ndarray
    desc: tuple[str, ...]


@dataclass(frozen=True)
class _Lin:
    path: Path
    rotor_speed: float
    azimuth: float
    wind: float
    states: _Rows
    inputs: _Rows
    outputs: _Rows
    A: FloatArray
    B: FloatArray
    C: FloatArray
    D: FloatArray


# --------------------------------------------------------------------------------------------
# Names: ElastoDyn descriptions <-> ours
# --------------------------------------------------------------------------------------------
_INTERNAL = re.compile(r"\s*\(internal DOF index = [^)]*\)")
_STATE_PATTERNS = (
    (re.compile(r"1st tower fore-aft bending mode DOF"), "tower_fa_displacement",
     "tower_fa_velocity"),
    (re.compile(r"1st tower side-to-side bending mode DOF"), "tower_ss_displacement",
     "tower_ss_velocity"),
    (re.compile(r"Variable speed generator DOF"), "azimuth", "rotor_speed"),
    (re.compile(r"Drivetrain rotational-flexibility DOF"), "shaft_torsion",
     "shaft_torsion_rate"),
    (re.compile(r"1st flapwise bending-mode DOF of blade (\d)"), "flap_{b}", "flap_rate_{b}"),
    (re.compile(r"1st edgewise bending-mode DOF of blade (\d)"), "edge_{b}", "edge_rate_{b}"),
    (re.compile(r"[Bb]lade (\d) pitch actuator"), "pitch_{b}", None),
)
_INPUT_PATTERNS = (
    (re.compile(r"Blade (\d) pitch command"), "pitch_ref_{b}"),
    (re.compile(r"Generator torque"), "gen_torque_ref"),
    (re.compile(r"collective blade-pitch command"), "pitch_ref_collective"),
    (re.compile(r"Yaw moment"), "yaw_moment_ref"),
    (re.compile(r"horizontal wind speed"), "wind"),
    (re.compile(r"vertical power-law shear exponent"), "shear_exponent"),
    (re.compile(r"propagation direction"), "wind_direction"),
)
#: Our state -> the ElastoDyn description :func:`write_lin` gives it (``{b}`` the blade).
_WRITE_STATES = {
    "tower_fa_displacement": "ED 1st tower fore-aft bending mode DOF (internal DOF index = "
                             "DOF_TFA1), m",
    "tower_ss_displacement": "ED 1st tower side-to-side bending mode DOF (internal DOF index = "
                             "DOF_TSS1), m",
    "azimuth": "ED Variable speed generator DOF (internal DOF index = DOF_GeAz), rad",
    "shaft_torsion": "ED Drivetrain rotational-flexibility DOF (internal DOF index = "
                     "DOF_DrTr), rad",
    "flap_{b}": "ED 1st flapwise bending-mode DOF of blade {b} (internal DOF index = "
                "DOF_BF({b},1)), m",
    "edge_{b}": "ED 1st edgewise bending-mode DOF of blade {b} (internal DOF index = "
                "DOF_BE({b},1)), m",
    "pitch_{b}": "mpc-wt blade {b} pitch actuator, rad",
}
_RATE_OF = {"tower_fa_velocity": "tower_fa_displacement",
            "tower_ss_velocity": "tower_ss_displacement", "rotor_speed": "azimuth",
            "shaft_torsion_rate": "shaft_torsion",
            **{f"flap_rate_{b}": f"flap_{b}" for b in (1, 2, 3)},
            **{f"edge_rate_{b}": f"edge_{b}" for b in (1, 2, 3)}}


_MODULES = ("ED", "BD", "AD", "IfW", "SrvD", "HD", "SD", "MAP", "MD", "ExtPtfm", "mpc-wt")


def _core(desc: str) -> str:
    """A description without the module, the internal DOF index and the unit."""
    text = _INTERNAL.sub("", desc).rsplit(",", 1)[0].strip()
    head, _, rest = text.partition(" ")
    return rest if head in _MODULES and rest else text


def _unit_of(desc: str) -> str:
    m = re.search(r",\s*\(?([^,()]*)\)?\s*$", desc)
    return m.group(1).strip() if m else "-"


def _state_name(desc: str) -> str:
    text = _INTERNAL.sub("", desc)
    rate = "First time derivative of" in text
    for pat, pos, vel in _STATE_PATTERNS:
        m = pat.search(text)
        if m:
            name = vel if rate else pos
            if name is None:
                break
            return name.format(b=m.group(1)) if m.groups() else name
    return _core(desc)


def _input_name(desc: str) -> str:
    for pat, name in _INPUT_PATTERNS:
        m = pat.search(desc)
        if m:
            return name.format(b=m.group(1)) if m.groups() else name
    return _core(desc)


def _output_name(desc: str) -> tuple[str, str]:
    m = re.match(r"^\s*(\S+)\s+([^,]+?)\s*,\s*\(([^)]*)\)\s*$", desc)
    if m:
        return m.group(2), m.group(3)
    return desc.strip(), "-"


# --------------------------------------------------------------------------------------------
# Parsing
# --------------------------------------------------------------------------------------------
def _parse(path: str | Path) -> _Lin:
    p = Path(path)
    if not p.is_file():
        raise LinFileError(f"{p}: file not found")
    lines = p.read_text(errors="replace").splitlines()

    def header(key: str, required: bool = True) -> float:
        for ln in lines[:40]:
            if ln.strip().startswith(key + ":"):
                try:
                    return float(ln.split(":", 1)[1].split()[0])
                except (ValueError, IndexError):
                    raise LinFileError(f"{p}: header {key!r}: {ln.strip()!r} has no "
                                       f"number") from None
        if required:
            raise LinFileError(f"{p}: no header line {key!r}: not an OpenFAST .lin file")
        return math.nan

    n_x = int(header("Number of continuous states"))
    n_u = int(header("Number of inputs"))
    n_y = int(header("Number of outputs"))
    if header("Number of discrete states", False) or header("Number of constraint states", False):
        raise LinFileError(f"{p}: discrete or constraint states are not supported (only "
                           f"continuous states)")

    def rows(title: str, n: int) -> _Rows:
        try:
            i = next(k for k, ln in enumerate(lines) if ln.strip().startswith(title))
        except StopIteration:
            if n == 0:
                return _Rows(np.zeros(0), np.zeros(0, bool), np.zeros(0, int), ())
            raise LinFileError(f"{p}: no section {title!r}") from None
        has_order = "Derivative Order" in lines[i + 1]
        op, rot, order, desc = [], [], [], []
        for k in range(i + 3, i + 3 + n):
            if k >= len(lines):
                raise LinFileError(f"{p}: section {title!r} ends at line {len(lines)}; "
                                   f"expected {n} rows")
            toks = lines[k].split(None, 4 if has_order else 3)
            try:
                op.append(float(toks[1]))
                if toks[2] not in ("T", "F"):
                    raise ValueError
                rot.append(toks[2] == "T")
                order.append(int(toks[3]) if has_order else 0)
                desc.append(toks[4] if has_order else toks[3])
            except (ValueError, IndexError):
                raise LinFileError(f"{p}: line {k + 1}: {lines[k].strip()[:70]!r} is not a row "
                                   f"'index, operating point, T/F, description'") from None
        return _Rows(np.array(op), np.array(rot), np.array(order), tuple(desc))

    def matrix(name: str, n: int, m: int) -> FloatArray:
        if n == 0 or m == 0:
            return np.zeros((n, m))
        pat = re.compile(rf"^{name}:\s*(\d+)\s*x\s*(\d+)")
        for k, ln in enumerate(lines):
            mt = pat.match(ln.strip())
            if mt:
                if (int(mt.group(1)), int(mt.group(2))) != (n, m):
                    raise LinFileError(f"{p}: line {k + 1}: {name} is {mt.group(1)} x "
                                       f"{mt.group(2)}; the header gives {n} x {m}")
                try:
                    a = np.array([[float(v) for v in lines[k + 1 + r].split()]
                                  for r in range(n)])
                except (ValueError, IndexError):
                    raise LinFileError(f"{p}: matrix {name} after line {k + 1} is short or "
                                       f"not numeric") from None
                if a.shape != (n, m):
                    raise LinFileError(f"{p}: matrix {name} after line {k + 1} has rows of "
                                       f"{a.shape} values; expected {n} x {m}")
                if not np.all(np.isfinite(a)):
                    raise LinFileError(f"{p}: matrix {name} has non-finite entries")
                return a
        raise LinFileError(f"{p}: no matrix {name!r} ({n} x {m})")

    states = rows("Order of continuous states:", n_x)
    inputs = rows("Order of inputs:", n_u)
    outputs = rows("Order of outputs:", n_y)
    wind = header("Wind Speed", False)
    if not math.isfinite(wind):
        i_w = [k for k, d in enumerate(inputs.desc) if "horizontal wind speed" in d]
        wind = float(inputs.op[i_w[0]]) if i_w else math.nan
    return _Lin(path=p, rotor_speed=header("Rotor Speed"), azimuth=header("Azimuth"), wind=wind,
                states=states, inputs=inputs, outputs=outputs, A=matrix("A", n_x, n_x),
                B=matrix("B", n_x, n_u), C=matrix("C", n_y, n_x), D=matrix("D", n_y, n_u))


def _outputs_si(lin: _Lin) -> tuple[list[str], list[str], FloatArray]:
    """Output names (ours where mapped), units after conversion and the factor of each row."""
    raw = [_output_name(d) for d in lin.outputs.desc]
    try:
        res = resolve_channels([n for n, _ in raw], [u for _, u in raw], str(lin.path))
    except ValueError as err:
        raise LinFileError(str(err)) from None
    names, units, scale = [], [], []
    for (n, u), r in zip(raw, res):
        if not math.isfinite(r[1]):
            names.append(n)
            units.append(u)
            scale.append(1.0)
        else:
            names.append(r[0])
            units.append(SI_UNIT.get(unit_key(u), u))
            scale.append(r[1])
    return names, units, np.array(scale)


def _split_inputs(lin: _Lin) -> tuple[list[int], list[int]]:
    dist = [k for k, d in enumerate(lin.inputs.desc) if d.startswith("IfW")]
    ctrl = [k for k in range(len(lin.inputs.desc)) if k not in dist]
    return ctrl, dist


def _to_model(lin: _Lin, A: FloatArray, B: FloatArray, C: FloatArray, D: FloatArray,
              x0: FloatArray, u0: FloatArray, y0: FloatArray, names: tuple[list[str], ...],
              coordinates: str, info: dict) -> LinearModel:
    snames, inames, onames = names
    ctrl, dist = _split_inputs(lin)
    _, ounits, scale = _outputs_si(lin)
    C, D, y0 = C * scale[:, None], D * scale[:, None], y0 * scale
    return LinearModel(
        A=A, B_u=B[:, ctrl], B_d=B[:, dist], C_z=C, D_u=D[:, ctrl], D_d=D[:, dist],
        states=tuple(snames), inputs=tuple(inames[k] for k in ctrl),
        disturbances=tuple(inames[k] for k in dist), outputs=tuple(onames),
        state_units=tuple(_unit_of(d) for d in lin.states.desc),
        input_units=tuple(_unit_of(lin.inputs.desc[k]) for k in ctrl),
        disturbance_units=tuple(_unit_of(lin.inputs.desc[k]) for k in dist),
        output_units=tuple(ounits), x0=x0, u0=u0[ctrl], d0=u0[dist], z0=y0,
        wind_mps=lin.wind, wake="quasi-steady", coordinates=coordinates, info=info)


def _names(lin: _Lin) -> tuple[list[str], list[str], list[str]]:
    snames = [_state_name(d) for d in lin.states.desc]
    if "shaft_torsion" in snames:       # with a flexible shaft, GeAz is the generator's
        snames = [{"azimuth": "gen_azimuth", "rotor_speed": "gen_speed_lss"}.get(n, n)
                  if "Variable speed generator DOF" in d else n
                  for n, d in zip(snames, lin.states.desc)]
    inames = [_input_name(d) for d in lin.inputs.desc]
    onames = _outputs_si(lin)[0]
    for lst, descs in ((snames, lin.states.desc), (inames, lin.inputs.desc),
                       (onames, lin.outputs.desc)):
        for k, n in enumerate(lst):
            if lst.count(n) > 1:
                lst[k] = descs[k].strip()
    return snames, inames, onames


def read_lin(path: str | Path) -> LinearModel:
    """One OpenFAST ``.lin`` file as a :class:`LinearModel` in the rotating (blade) frame.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    LinearModel
        States and inputs under our names where ElastoDyn's are recognized, else their
        descriptions; outputs under the OpenFAST channel names with their units; InflowWind's
        inputs as disturbances (``wind``, ``shear_exponent``, ``wind_direction``). ``info``
        holds ``source``, ``azimuth_rad``, ``rotor_speed_rad_s``, the rotating-frame flags and
        the OpenFAST descriptions.

    Raises
    ------
    LinFileError
        Naming the file and line: missing header, section or matrix, wrong sizes, non-numbers.
    """
    lin = _parse(path)
    info = {"source": str(lin.path), "azimuth_rad": lin.azimuth,
            "rotor_speed_rad_s": lin.rotor_speed, "rotor_speed_rpm": lin.rotor_speed * 30 / math.pi,
            "state_rotating": lin.states.rotating.tolist(),
            "input_rotating": lin.inputs.rotating.tolist(),
            "output_rotating": lin.outputs.rotating.tolist(),
            "state_descriptions": list(lin.states.desc),
            "input_descriptions": list(lin.inputs.desc),
            "output_descriptions": list(lin.outputs.desc), "openfast": True}
    return _to_model(lin, lin.A, lin.B, lin.C, lin.D, lin.states.op, lin.inputs.op,
                     lin.outputs.op, _names(lin), "blade", info)


# --------------------------------------------------------------------------------------------
# MBC3
# --------------------------------------------------------------------------------------------
_BLADE_NUM = (re.compile(r"(?<=[Bb]lade )([123])"), re.compile(r"(?<=^B)([123])(?=N)"),
              re.compile(r"(?<=^AB)([123])"), re.compile(r"(?<=_)([123])$"),
              re.compile(r"([123])(?=\D*$)"))


def _triplets(names: Sequence[str], rotating: np.ndarray) -> tuple[list[list[int]], list[int]]:
    """Rotating rows grouped by blade (blade 1, 2, 3 order); the rows left over."""
    groups: dict[str, dict[int, int]] = {}
    for k, (n, rot) in enumerate(zip(names, rotating)):
        if not rot:
            continue
        for pat in _BLADE_NUM:
            m = pat.search(n)
            if m:
                key = n[:m.start()] + "#" + n[m.end():]
                groups.setdefault(key, {})[int(m.group(1))] = k
                break
        else:
            groups.setdefault(n, {})[0] = k
    out, left = [], []
    for g in groups.values():
        if sorted(g) == [1, 2, 3]:
            out.append([g[1], g[2], g[3]])
        else:
            left.extend(g.values())
    return out, sorted(left)


def _mbc_suffix(name: str, k: int) -> str:
    for pat in _BLADE_NUM:
        m = pat.search(name)
        if m:
            stem = (name[:m.start()] + name[m.end():]).rstrip("_ ")
            return f"{stem}_{('coll', 'cos', 'sin')[k]}"
    return name


def read_lin_set(paths: Sequence[str | Path]) -> LinearModel:
    """The files of one operating point at several azimuths, in multi-blade coordinates and
    averaged over azimuth (MBC3, Bir 2008).

    Parameters
    ----------
    paths : sequence of str or Path
        At least 3 files with the same states, inputs and outputs, taken at different
        azimuths (OpenFAST's ``NLinTimes`` over one revolution).

    Returns
    -------
    LinearModel
        ``coordinates="mbc"``; blade triplets renamed ``_coll``, ``_cos``, ``_sin`` (our
        ``flap_1..3`` -> ``flap_coll``, ``flap_cos``, ``flap_sin``); ``info["mbc_untransformed"]``
        lists rotating rows that are not complete blade triplets (left in the rotating frame,
        also logged), ``info["azimuths_rad"]`` the azimuths averaged.

    Raises
    ------
    LinFileError
        If fewer than 3 files, the files differ in their rows, or a rotating velocity triplet
        has no displacement triplet.
    """
    lins = [_parse(p) for p in paths]
    if len(lins) < 3:
        raise LinFileError(f"paths: {len(lins)} files; MBC3 needs at least 3 azimuths")
    ref = lins[0]
    for lin in lins[1:]:
        for what in ("states", "inputs", "outputs"):
            if getattr(lin, what).desc != getattr(ref, what).desc:
                raise LinFileError(f"{lin.path}: its {what} differ from {ref.path}'s: a set "
                                   f"must be one model at several azimuths")
    snames, inames, onames = _names(ref)
    xs, xleft = _triplets(snames, ref.states.rotating)
    us, uleft = _triplets(inames, ref.inputs.rotating)
    ys, yleft = _triplets(onames, ref.outputs.rotating)
    # second-order state triplets: velocity triplet -> its displacement triplet
    pairs = []
    prefix = "First time derivative of "
    for tv in xs:
        core = _core(ref.states.desc[tv[0]])
        if not core.startswith(prefix):
            continue
        target = core[len(prefix):]
        match = [tp for tp in xs if _core(ref.states.desc[tp[0]]) == target]
        if not match:
            raise LinFileError(f"{ref.path}: velocity triplet {snames[tv[0]]!r} has no "
                               f"displacement triplet ({target!r})")
        pairs.append((match[0], tv))
    left = {"states": [snames[k] for k in xleft], "inputs": [inames[k] for k in uleft],
            "outputs": [onames[k] for k in yleft]}
    if any(left.values()):
        _log.warning("%s: rotating rows not in blade triplets stay in the rotating frame: %s",
                     ref.path, left)
    acc = None
    for lin in lins:
        mats = _mbc(lin, xs, us, ys, pairs)
        acc = list(mats) if acc is None else [a + m for a, m in zip(acc, mats)]
    assert acc is not None
    A, B, C, D, x0, u0, y0 = (m / len(lins) for m in acc)
    for lst, groups in ((snames, xs), (inames, us), (onames, ys)):
        for g in groups:
            base = lst[g[0]]
            for k, i in enumerate(g):
                lst[i] = _mbc_suffix(base, k)
    info = {"source": [str(lin.path) for lin in lins],
            "azimuths_rad": [lin.azimuth for lin in lins],
            "rotor_speed_rad_s": float(np.mean([lin.rotor_speed for lin in lins])),
            "rotor_speed_rpm": float(np.mean([lin.rotor_speed for lin in lins])) * 30 / math.pi,
            "mbc_untransformed": left, "openfast": True,
            "state_descriptions": list(ref.states.desc),
            "input_descriptions": list(ref.inputs.desc),
            "output_descriptions": list(ref.outputs.desc)}
    try:
        return _to_model(ref, A, B, C, D, x0, u0, y0, (snames, inames, onames), "mbc", info)
    except LinearizationError as err:
        raise LinFileError(f"{ref.path}: {err}") from err


def _mbc(lin: _Lin, xs: list[list[int]], us: list[list[int]], ys: list[list[int]],
         pairs: list[tuple[list[int], list[int]]]) -> tuple[FloatArray, ...]:
    t, tinv, tdot, tddot = mbc_matrices(lin.azimuth, lin.rotor_speed)
    n_x, n_u, n_y = lin.A.shape[0], lin.B.shape[1], lin.C.shape[0]
    tx, txdot = np.eye(n_x), np.zeros((n_x, n_x))
    for g in xs:
        tx[np.ix_(g, g)] = t
        txdot[np.ix_(g, g)] = tdot
    for gp, gv in pairs:
        tx[np.ix_(gv, gp)] = tdot
        txdot[np.ix_(gv, gp)] = tddot
    tu = np.eye(n_u)
    for g in us:
        tu[np.ix_(g, g)] = t
    ty_inv = np.eye(n_y)
    for g in ys:
        ty_inv[np.ix_(g, g)] = tinv
    tx_inv = np.linalg.inv(tx)
    A = tx_inv @ (lin.A @ tx - txdot)
    return (A, tx_inv @ lin.B @ tu, ty_inv @ lin.C @ tx, ty_inv @ lin.D @ tu,
            tx_inv @ lin.states.op, np.linalg.solve(tu, lin.inputs.op), ty_inv @ lin.outputs.op)


# --------------------------------------------------------------------------------------------
# Writing
# --------------------------------------------------------------------------------------------
_ROTATING_STATE = re.compile(r"^(flap|flap_rate|edge|edge_rate|pitch)_[123]$")
_ROTATING_IO = re.compile(r"^(pitch_ref|pitch|pitch_rate|flap_moment|edge_moment|flap|edge"
                          r"|wind)_[123]$")


def _state_desc(name: str, unit: str) -> str:
    m = re.match(r"^(.*)_([123])$", name)
    for key, desc in _WRITE_STATES.items():
        if key == name or (m and key == f"{m.group(1)}_{{b}}"):
            return desc.format(b=m.group(2) if m else "")
    if name in _RATE_OF:
        pos = _state_desc(_RATE_OF[name], unit)
        return "ED First time derivative of " + pos[3:].rsplit(",", 1)[0] + f", {unit}"
    return f"mpc-wt {name}, {unit}"


def _input_desc(name: str, unit: str, disturbance: bool) -> str:
    m = re.match(r"^pitch_ref_([123])$", name)
    if m:
        return f"ED Blade {m.group(1)} pitch command, {unit}"
    if name == "gen_torque_ref":
        return f"ED Generator torque, {unit}"
    if disturbance and name == "wind":
        return f"IfW Extended input: horizontal wind speed (steady/uniform wind), {unit}"
    return f"{'IfW' if disturbance else 'mpc-wt'} {name}, {unit}"


def write_lin(model: LinearModel, path: str | Path, *, azimuth_rad: float,
              rotor_speed_rad_s: float | None = None) -> Path:
    """Write a blade-coordinate model in OpenFAST's ``.lin`` layout (readable by
    :func:`read_lin` and by openfast-io's ``FASTLinearizationFile``).

    Blade states, inputs, outputs and the per-blade winds are flagged rotating; states get
    ElastoDyn's descriptions where there is one; the disturbances follow the inputs (wind
    first, with InflowWind's ``IfW`` prefix).

    Parameters
    ----------
    model : LinearModel
        In blade coordinates.
    path : str or Path
    azimuth_rad : float
        The azimuth the model was made at [rad].
    rotor_speed_rad_s : float, optional
        Default: the model's ``info["rotor_speed_rpm"]``.

    Returns
    -------
    Path
    """
    if model.coordinates != "blade":
        raise ValueError("write_lin: the model must be in blade coordinates; .lin files are "
                         "per azimuth in the rotating frame")
    omega = rotor_speed_rad_s if rotor_speed_rad_s is not None else \
        float(model.info["rotor_speed_rpm"]) * math.pi / 30
    n_x, n_u, n_d, n_y = model.n_x, len(model.inputs), len(model.disturbances), \
        len(model.outputs)
    B = np.hstack([model.B_d, model.B_u])
    D = np.hstack([model.D_d, model.D_u])
    u0 = np.concatenate([model.d0, model.u0])
    ins = [(_input_desc(n, u, True), bool(_ROTATING_IO.match(n)))
           for n, u in zip(model.disturbances, model.disturbance_units)]
    ins += [(_input_desc(n, u, False), bool(_ROTATING_IO.match(n)))
            for n, u in zip(model.inputs, model.input_units)]

    def row(k: int, v: float, rot: bool, desc: str) -> str:
        return f"{k:11d} {v:16.8E}{'':40s}{'T' if rot else 'F'}        {desc}"

    head = "   ---------- ---------------                                    --------------- -----------"
    out = ["", "Linearized model: written by mpc-wt (linearize.write_lin)", "",
           f"Description from the FAST input file: {model.info.get('turbine', 'mpc-wt model')}",
           "", "Simulation information:", f"   Simulation time:  {0.0:20.4f} s",
           f"   Rotor Speed:      {omega!r:>20s} rad/s",
           f"   Azimuth:          {float(azimuth_rad)!r:>20s} rad",
           f"   Wind Speed:       {float(model.wind_mps)!r:>20s} m/s",
           f"   Number of continuous states: {n_x:8d}",
           f"   Number of discrete states:   {0:8d}",
           f"   Number of constraint states: {0:8d}",
           f"   Number of inputs:            {n_u + n_d:8d}",
           f"   Number of outputs:           {n_y:8d}",
           "   Jacobians included in this file?    No", "",
           "Order of continuous states:",
           "   Row/Column Operating Point                                    Rotating Frame? "
           "Description", head]
    flexible = "shaft_torsion" in model.states   # then ElastoDyn's GeAz is the generator's
    out += [row(k + 1, model.x0[k], bool(_ROTATING_STATE.match(n)),
                f"mpc-wt {n}, {u}" if flexible and n in ("rotor_speed", "azimuth")
                else _state_desc(n, u))
            for k, (n, u) in enumerate(zip(model.states, model.state_units))]
    out += ["", "Order of inputs:",
            "     Column   Operating Point                                    Rotating Frame? "
            "Description", head]
    out += [row(k + 1, u0[k], rot, d) for k, (d, rot) in enumerate(ins)]
    out += ["", "Order of outputs:",
            "        Row   Operating Point                                    Rotating Frame? "
            "Description", head]
    out += [row(k + 1, model.z0[k], bool(_ROTATING_IO.match(n)), f"mpc-wt {n}, ({u})")
            for k, (n, u) in enumerate(zip(model.outputs, model.output_units))]
    out += ["", "", "Linearized state matrices:", ""]
    for name, m in (("A", model.A), ("B", B), ("C", model.C_z), ("D", D)):
        out.append(f"{name}: {m.shape[0]} x {m.shape[1]}")
        out += [" ".join(f"{v:23.15E}" for v in r) for r in m]
    p = Path(path)
    p.write_text("\n".join(out) + "\n")
    return p


# --------------------------------------------------------------------------------------------
# Comparison with our plant
# --------------------------------------------------------------------------------------------
_DOF_OF_STATE = {"tower_fa_displacement": "tower_fa", "tower_ss_displacement": "tower_ss",
                 "shaft_torsion": "drivetrain", "flap_1": "blade_flap", "flap_coll": "blade_flap",
                 "edge_1": "blade_edge", "edge_coll": "blade_edge"}


def _collective(model: LinearModel, mat: FloatArray) -> float | None:
    names = model.inputs
    for n in ("pitch_ref_collective", "pitch_ref_coll"):
        if n in names:
            return float(mat[names.index(n)])
    if all(f"pitch_ref_{b}" in names for b in (1, 2, 3)):
        return float(sum(mat[names.index(f"pitch_ref_{b}")] for b in (1, 2, 3)))
    return None


def _derivatives(model: LinearModel) -> dict[str, float | None]:
    out: dict[str, float | None] = {}
    wind = next((k for k, n in enumerate(model.disturbances)
                 if n in ("wind", "wind_coll")), None)
    for sym, name in (("Q", "aero_torque"), ("T", "thrust")):
        if name not in model.outputs:
            for k in ("V", "pitch", "Omega", "tower_velocity"):
                out[f"d{sym}/d{k}"] = None
            continue
        i = model.outputs.index(name)
        if wind is not None:
            out[f"d{sym}/dV"] = float(model.D_d[i, wind])
        elif all(f"wind_{b}" in model.disturbances for b in (1, 2, 3)):
            out[f"d{sym}/dV"] = float(model.D_d[i].sum())
        else:
            out[f"d{sym}/dV"] = None
        out[f"d{sym}/dpitch"] = _collective(model, model.D_u[i])
        for k, state in (("Omega", "rotor_speed"), ("tower_velocity", "tower_fa_velocity")):
            out[f"d{sym}/d{k}"] = (float(model.C_z[i, model.states.index(state)])
                                   if state in model.states else None)
    return out


def compare_with_openfast(turbine: object, openfast: LinearModel) -> dict[str, object]:
    """Our plant linearized at an OpenFAST model's operating point, beside it.

    The operating point is the file's wind (``Wind Speed`` or InflowWind's input), rotor speed
    and collective pitch (:func:`linearize.operating_point`); our plant gets the degrees of
    freedom the file has (tower fore-aft and side-side, drivetrain, blade flap and edge; the
    generator always), the quasi-steady wake OpenFAST linearizes with, one rotor wind, and an
    average over azimuth.

    Parameters
    ----------
    turbine : Turbine
    openfast : LinearModel
        From :func:`read_lin` or :func:`read_lin_set`.

    Returns
    -------
    dict
        ``operating_point`` (wind, rotor speed, pitch), ``derivatives``: {name: {"openfast",
        "mpc_wt", "ratio"}} for the aerodynamic torque Q and thrust T against wind V,
        collective pitch, rotor speed and tower fore-aft velocity [SI], and ``modes`` of each.

    Raises
    ------
    LinFileError
        If the model has no finite wind speed or no pitch operating point.
    """
    from linearize.linear import linearize
    from linearize.params import PlantConfig
    from linearize.trim import operating_point

    v = openfast.wind_mps
    if not math.isfinite(v):
        raise LinFileError("the OpenFAST model has no wind speed (no 'Wind Speed' header and "
                           "no InflowWind input)")
    omega = float(openfast.info["rotor_speed_rad_s"])
    pitch = None
    for n in ("pitch_ref_collective", "pitch_ref_coll", "pitch_ref_1"):
        if n in openfast.inputs:
            pitch = float(openfast.u0[openfast.inputs.index(n)])
            break
    if pitch is None:
        raise LinFileError(f"the OpenFAST model has no pitch input among {openfast.inputs}")
    dofs = {"generator"} | {d for s, d in _DOF_OF_STATE.items() if s in openfast.states}
    cfg = PlantConfig(frozenset(dofs))
    op = operating_point(turbine, v, omega, pitch, config=cfg)  # type: ignore[arg-type]
    ours = linearize(turbine, v, config=cfg, operating_point=op,  # type: ignore[arg-type]
                     disturbance="rotor")
    a, b = _derivatives(openfast), _derivatives(ours)
    table = {}
    for k in a:
        fa, fb = a[k], b.get(k)
        table[k] = {"openfast": fa, "mpc_wt": fb,
                    "ratio": (fb / fa) if fa not in (None, 0.0) and fb is not None else None}
    return {"operating_point": {"wind_mps": v, "rotor_speed_rpm": omega * 30 / math.pi,
                                "pitch_deg": math.degrees(pitch), "dofs": sorted(dofs)},
            "derivatives": table, "modes": {"openfast": openfast.modes(), "mpc_wt": ours.modes()}}

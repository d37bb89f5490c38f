"""OpenFAST decks as turbines: ElastoDyn, AeroDyn 15, ServoDyn and ROSCO's ``DISCON.IN``.

:func:`load_openfast` reads a ``.fst`` deck (or an ElastoDyn + AeroDyn pair) into a
:class:`~linearize.turbine.Turbine` and a :class:`~linearize.turbine.LoadReport` of what was read
from which file and key and what was defaulted. The files are read by the small line parser
below rather than by ``openfast-io``: that reader parses every module of a deck (HydroDyn,
SubDyn, MoorDyn, ...) into nested dictionaries with pandas and ruamel, which costs more than the
rest of the load and cannot say which key of which file is wrong; the tests check this parser
against ``openfast-io`` value by value.

What is read (OpenFAST sign conventions turned into ours, see ``docs/turbine-format.md``):

- ElastoDyn: rotor and tower geometry, masses and inertias, drivetrain, damping, the first
  tower fore-aft, side-side, blade flap and edge mode shapes; its blade and tower files'
  distributed properties with their adjustment factors applied (``AdjBlMs``, ``AdjFlSt``,
  ``AdjEdSt``, ``AdjTwMa``, ``AdjFASt``, ``AdjSSSt``).
- AeroDyn 15: air density, the blade nodes (span, chord, twist, airfoil id), the airfoil
  polars (first table of each file; the shape coordinates are not read) with their unsteady-
  aerodynamics coefficients (``InclUAdata``: ``alpha0``, ``C_nalpha``, ``Cd0``, ``A1``, ``A2``,
  ``b1``, ``b2``, ``T_p``, ``T_f0``, ``filtCutOff``, ``UACutout``), and the tower's diameter and
  drag coefficient (``TwrElev``, ``TwrDiam``, ``TwrCd``).
- ElastoDyn's blade file: also the structural twist (``StrcTwst``).
- ServoDyn: generator efficiency. ``DISCON.IN``: rated power and speed, minimum speed, fine
  pitch, pitch and torque limits and rates, the pitch actuator's corner frequency.

Blade elements are AeroDyn's nodes strictly inside the rotor, each weighted by the trapezoid
rule with zero load at hub and tip (where the hub- and tip-loss factors vanish), so that the
midpoint sum of the plant is AeroDyn's and CCBlade's trapezoid over the nodes. A support below
the tower base (SubDyn, HydroDyn) is not modelled: the tower is clamped at ``TowerBsHt``.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Sequence

import numpy as np

from linearize._typing import FloatArray
from linearize.errors import TurbineFileError
from linearize.turbine import (
    BladeAero,
    BladeStructure,
    Damping,
    Drivetrain,
    Environment,
    Generator,
    Geometry,
    LoadReport,
    MinPitchTable,
    ModeShapes,
    Nacelle,
    Operation,
    PitchActuator,
    Polar,
    ReportEntry,
    RotorMass,
    TowerStructure,
    Turbine,
    UAParams,
)

__all__ = ["load_openfast", "OpenFASTFile", "read_airfoil_polar"]

_DEG = math.pi / 180.0
_RPM = math.pi / 30.0
_TOKEN = re.compile(r'"[^"]*"|\'[^\']*\'|[^\s,]+')
_KEY = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*(\(\d+\))?$")
_LITERALS = {"true", "false", "t", "f", "default", "none", "unused"}
_NUMERIC_ROW = re.compile(r"^[\s\d.eEdD+\-,]*$")
#: Defaults for what a deck does not hold, with the reason the report gives.
DEFAULTS = {
    "cut_in_wind": (3.0, "not in an OpenFAST deck; IEC class default 3 m/s"),
    "cut_out_wind": (25.0, "not in an OpenFAST deck; IEC class default 25 m/s"),
    "pitch_time_constant": (0.1, "the deck's pitch actuator is ideal (ROSCO PA_Mode = 0); "
                                 "mpc-wt's first-order servo needs one: 0.1 s"),
}


def _norm(key: str) -> str:
    return key.replace("(", "").replace(")", "").lower()


def _unquote(tok: str) -> str:
    tok = tok.lstrip("@")
    if len(tok) >= 2 and tok[0] == tok[-1] and tok[0] in "\"'":
        return tok[1:-1]
    return tok


class OpenFASTFile:
    """One OpenFAST-style input file: ``value  Key  - description`` lines and tables.

    Also reads ROSCO's ``value ! Key - description`` and AirfoilInfo's ``value Key ! ...``.
    Keys are case-insensitive and ``Key(1)`` equals ``Key1``; the first occurrence wins.

    Parameters
    ----------
    path : str or Path
        The file.

    Raises
    ------
    TurbineFileError
        If the file does not exist or cannot be read as text.
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        if not self.path.is_file():
            raise TurbineFileError(f"{self.path}: file not found")
        try:
            self.lines = self.path.read_text(errors="replace").splitlines()
        except OSError as err:
            raise TurbineFileError(f"{self.path}: cannot be read: {err}") from err
        self.keys: dict[str, tuple[list[str], int]] = {}
        #: every key line in file order, (normalized key, values, line index)
        self.entries: list[tuple[str, list[str], int]] = []
        for i, line in enumerate(self.lines):
            if _NUMERIC_ROW.match(line):
                continue
            parsed = _key_line(line)
            if parsed is not None:
                values, key = parsed
                self.entries.append((_norm(key), values, i))
                self.keys.setdefault(_norm(key), (values, i))

    def has(self, key: str) -> bool:
        """Whether ``key`` appears in the file.

        Parameters
        ----------
        key : str
            The key, as OpenFAST names it.

        Returns
        -------
        bool
            Whether it is there.
        """
        return _norm(key) in self.keys

    def where(self, key: str) -> str:
        """``file:line key`` of a key, for reports and errors.

        Parameters
        ----------
        key : str
            The key, as OpenFAST names it.

        Returns
        -------
        str
            ``file:line key``.
        """
        _, i = self.keys[_norm(key)]
        return f"{self.path.name}:{i + 1} {key}"

    def raw(self, key: str) -> list[str]:
        """The value tokens of ``key`` (quotes kept).

        Parameters
        ----------
        key : str
            The key, as OpenFAST names it.

        Returns
        -------
        list of str
            The tokens.
        """
        try:
            return self.keys[_norm(key)][0]
        except KeyError:
            raise TurbineFileError(f"{self.path}: key {key!r} not found") from None

    def text(self, key: str) -> str:
        """A string value, unquoted.

        Parameters
        ----------
        key : str
            The key, as OpenFAST names it.

        Returns
        -------
        str
            The value.
        """
        return _unquote(self.raw(key)[0])

    def is_default(self, key: str) -> bool:
        """Whether the value is OpenFAST's ``DEFAULT``.

        Parameters
        ----------
        key : str
            The key, as OpenFAST names it.

        Returns
        -------
        bool
            Whether it reads DEFAULT.
        """
        return self.text(key).lower() == "default"

    def number(self, key: str, lo: float = -math.inf, hi: float = math.inf) -> float:
        """A finite number in ``[lo, hi]``; the error names file, line, key and range.

        Parameters
        ----------
        key : str
            The key, as OpenFAST names it.
        lo, hi : float
            Allowed range.

        Returns
        -------
        float
            The value.
        """
        tok = self.text(key)
        try:
            v = float(tok.replace("d", "e").replace("D", "E"))
        except ValueError:
            raise TurbineFileError(f"{self.path}: {self.where(key)} = {tok!r} is not a "
                                   f"number") from None
        if not math.isfinite(v) or v < lo or v > hi:
            raise TurbineFileError(f"{self.path}: {self.where(key)} = {tok}; allowed "
                                   f"{lo:g}..{hi:g}")
        return v

    def numbers(self, key: str) -> FloatArray:
        """All numeric value tokens of ``key``.

        Parameters
        ----------
        key : str
            The key, as OpenFAST names it.

        Returns
        -------
        ndarray
            The values.
        """
        out = []
        for tok in self.raw(key):
            try:
                out.append(float(_unquote(tok)))
            except ValueError:
                raise TurbineFileError(f"{self.path}: {self.where(key)}: {tok!r} is not a "
                                       f"number") from None
        return np.array(out)

    def flag(self, key: str) -> bool:
        """A boolean (``True``/``False``/``T``/``F``).

        Parameters
        ----------
        key : str
            The key, as OpenFAST names it.

        Returns
        -------
        bool
            The value.
        """
        tok = self.text(key).lower()
        if tok in ("true", "t"):
            return True
        if tok in ("false", "f"):
            return False
        raise TurbineFileError(f"{self.path}: {self.where(key)} = {tok!r}; allowed True/False")

    def file(self, key: str) -> Path | None:
        """A file named by ``key``, relative to this file's folder unless absolute.

        Parameters
        ----------
        key : str
            The key, as OpenFAST names it.

        Returns
        -------
        Path or None
            The resolved path; None when the key is absent or names no file (``unused``,
            ``none``, empty).
        """
        if not self.has(key):
            return None
        name = self.text(key)
        if name.lower() in ("unused", "none", ""):
            return None
        return Path(name) if Path(name).is_absolute() else (self.path.parent / name).resolve()

    def integer(self, key: str, lo: int = -(2**31), hi: int = 2**31) -> int:
        """An integer in ``[lo, hi]``.

        Parameters
        ----------
        key : str
            The key, as OpenFAST names it.
        lo, hi : int
            Allowed range.

        Returns
        -------
        int
            The value.
        """
        v = self.number(key, lo, hi)
        if v != int(v):
            raise TurbineFileError(f"{self.path}: {self.where(key)} = {v!r} must be an integer")
        return int(v)

    def table(self, columns: Sequence[str], n_rows: int,
              after_key: str | None = None) -> dict[str, FloatArray]:
        """A table whose header line names ``columns`` (among others), ``n_rows`` rows.

        A units line (``(m) (deg) ...``) under the header is skipped. The error names the file,
        the line and the column of a missing or non-numeric entry.

        Parameters
        ----------
        columns : sequence of str
            Column names wanted.
        n_rows : int
            Number of rows.
        after_key : str, optional
            Search for the header only after this key's line.

        Returns
        -------
        dict of str to ndarray
            Each wanted column.
        """
        start = self.keys[_norm(after_key)][1] + 1 if after_key else 0
        want = [c.lower() for c in columns]
        for i in range(start, len(self.lines)):
            head = [t.lower() for t in _TOKEN.findall(self.lines[i])]
            if head and head[0] in ("!", "#"):
                head = head[1:]
            # a comment after the column names is not a column
            head = next((head[:k] for k, t in enumerate(head) if t.startswith(("!", "#"))),
                        head)
            if all(c in head for c in want):
                break
        else:
            raise TurbineFileError(f"{self.path}: no table with columns {list(columns)}")
        j = i + 1
        if j < len(self.lines) and self.lines[j].strip().startswith(("(", "!")):
            j += 1
        return _rows(self.path, self.lines, j, n_rows, head, columns)


def _rows(path: Path, lines: list[str], j: int, n_rows: int, head: list[str],
          columns: Sequence[str]) -> dict[str, FloatArray]:
    rows = []
    for k in range(j, j + n_rows):
        if k >= len(lines):
            raise TurbineFileError(f"{path}: table ends at line {len(lines)}; expected "
                                   f"{n_rows} rows from line {j + 1}")
        toks = lines[k].split()
        try:
            rows.append([float(t) for t in toks[:len(head)]])
        except ValueError:
            raise TurbineFileError(f"{path}: line {k + 1}: {lines[k].strip()[:60]!r} is not a "
                                   f"row of numbers (table of {n_rows} rows)") from None
        if len(rows[-1]) < len(head):
            raise TurbineFileError(f"{path}: line {k + 1} has {len(rows[-1])} columns; "
                                   f"expected {len(head)} ({' '.join(head)})")
    arr = np.array(rows, dtype=float).reshape(n_rows, len(head))
    out = {}
    for c in columns:
        col = arr[:, head.index(c.lower())]
        if not np.all(np.isfinite(col)):
            raise TurbineFileError(f"{path}: column {c!r} has non-finite values")
        out[c] = col
    return out


def _key_line(line: str) -> tuple[list[str], str] | None:
    s = line.strip()
    if not s or s.startswith(("---", "===", "!", "#")):
        return None
    toks = _TOKEN.findall(s)
    values: list[str] = toks[:1]
    for tok in toks[1:]:
        if tok == "!" or tok == "-":
            continue
        t = tok[1:] if tok.startswith("!") else tok
        if _KEY.match(t) and t.lower() not in _LITERALS:
            return values, t
        values.append(tok)
    return None


def read_airfoil_polar(path: str | Path, name: str | None = None,
                       columns: tuple[int, int, int] = (1, 2, 3),
                       table_mode: int = 1) -> tuple[Polar, str | None]:
    """Read one table of an AeroDyn 15 AirfoilInfo file as a :class:`Polar`.

    Parameters
    ----------
    path : str or Path
        The polar file (the shape coordinates it may point to are not read).
    name : str, optional
        Polar name; the file's stem by default.
    columns : (3,) tuple of int
        1-based columns of alpha [deg], C_l and C_d (AeroDyn's ``InCol_Alfa/Cl/Cd``).
    table_mode : int
        AeroDyn's ``AFTabMod``: 1 takes the first table (as AeroDyn does); 2 (interpolation on
        Reynolds number) the table of the highest Re; 3 (on ``UserProp``, e.g. a trailing-edge
        flap angle) the table at ``UserProp`` = 0, the undeflected setting.

    Returns
    -------
    Polar, str or None
        The polar and a note when the file holds several tables, naming the one used.

    Raises
    ------
    TurbineFileError
        Naming the file and line: no ``NumAlf``, short rows, alpha not covering -180..180 deg.
    """
    f = OpenFASTFile(path)
    starts: list[dict] = []
    for k, vals, i in f.entries:
        if k == "re":
            starts.append({"re": _num(f, i, vals), "ua": {}})
        elif k in ("userprop", "ctrl") and starts:
            starts[-1]["prop"] = _num(f, i, vals)
        elif k == "numalf":
            if not starts:
                starts.append({"ua": {}})
            starts[-1]["numalf"] = (i, _num(f, i, vals))
        elif starts and "numalf" not in starts[-1]:
            starts[-1]["ua"][k] = vals[0] if vals else ""
    tables = [t for t in starts if "numalf" in t]
    if not tables:
        raise TurbineFileError(f"{f.path}: key 'NumAlf' not found: not an AirfoilInfo file")
    pick = 0
    if len(tables) > 1 and table_mode == 2:
        pick = int(np.argmax([t.get("re", 0.0) for t in tables]))
    elif len(tables) > 1 and table_mode == 3:
        pick = int(np.argmin([abs(t.get("prop", 0.0)) for t in tables]))
    i_key, n = tables[pick]["numalf"]
    if n < 2 or n != int(n):
        raise TurbineFileError(f"{f.path}: line {i_key + 1}: NumAlf = {n:g}; allowed an "
                               f"integer >= 2")
    i = i_key + 1
    while i < len(f.lines) and (not f.lines[i].strip() or f.lines[i].strip().startswith("!")):
        i += 1
    width = max(columns)
    head = [f"c{k}" for k in range(1, width + 1)]
    tab = _rows(f.path, f.lines, i, int(n), head, [f"c{c}" for c in columns])
    a, cl, cd = (tab[f"c{c}"] for c in columns)
    note = None
    if len(tables) > 1:
        t = tables[pick]
        note = (f"{f.path.name}: {len(tables)} tables, table {pick + 1} used (AFTabMod = "
                f"{table_mode}; Re = {t.get('re', float('nan')):g} M, UserProp = "
                f"{t.get('prop', 0.0):g})")
    try:
        return Polar(name=name or f.path.stem, alpha_rad=np.radians(a), cl=cl, cd=cd,
                     ua=_ua_params(tables[pick]["ua"])), note
    except ValueError as err:
        raise TurbineFileError(f"{f.path}: {err}") from err


#: AirfoilInfo's UA keys -> (UAParams field, factor to its unit); others keep their defaults
_UA_KEYS = {"alpha0": ("alpha0_rad", math.pi / 180), "c_nalpha": ("cn_alpha", 1.0),
            "cd0": ("cd0", 1.0), "a1": ("a1", 1.0), "a2": ("a2", 1.0), "b1": ("b1", 1.0),
            "b2": ("b2", 1.0), "t_p": ("t_p", 1.0), "t_f0": ("t_f0", 1.0),
            "filtcutoff": ("filt_cutoff", 1.0), "uacutout": ("cutout_rad", math.pi / 180)}


def _ua_params(keys: dict[str, str]) -> UAParams | None:
    """An AirfoilInfo table's UA coefficients (``InclUAdata`` true, ``C_nalpha`` > 0), with
    AeroDyn's defaults for the ``"Default"`` entries; None without them."""
    if _unquote(keys.get("incluadata", "false")).lower() not in ("true", "t"):
        return None
    kw: dict[str, float] = {}
    for key, (fld, scale) in _UA_KEYS.items():
        raw = _unquote(keys.get(key, "default"))
        if raw.lower() == "default":
            continue
        try:
            kw[fld] = float(raw) * scale
        except ValueError:
            return None
    if not kw.get("cn_alpha", 0.0) > 0 or "alpha0_rad" not in kw or "cd0" not in kw:
        return None
    try:
        return UAParams(**kw)
    except ValueError:
        return None


def _num(f: OpenFASTFile, i: int, vals: list[str]) -> float:
    try:
        return float(_unquote(vals[0]))
    except ValueError:
        raise TurbineFileError(f"{f.path}: line {i + 1}: {vals[0]!r} is not a number") from None


# --------------------------------------------------------------------------------------------
# The deck
# --------------------------------------------------------------------------------------------
@dataclass
class _Recorder:
    entries: list[ReportEntry]
    notes: list[str]

    def read(self, quantity: str, value: float, unit: str, f: OpenFASTFile, key: str,
             how: str = "") -> float:
        src = f.where(key) + (f" ({how})" if how else "")
        self.entries.append(ReportEntry(quantity, f"{value:.6g} {unit}".strip(), src))
        return value

    def default(self, quantity: str, value: float, unit: str, why: str) -> float:
        self.entries.append(ReportEntry(quantity, f"{value:.6g} {unit}".strip(),
                                        f"default: {why}"))
        return value


def load_openfast(fst: str | Path | None = None, *, elastodyn: str | Path | None = None,
                  aerodyn: str | Path | None = None, servodyn: str | Path | None = None,
                  discon: str | Path | None = None, name: str | None = None) -> Turbine:
    """Read an OpenFAST deck into a :class:`Turbine` with its :class:`LoadReport`.

    Parameters
    ----------
    fst : str or Path, optional
        The ``.fst`` main file; its ElastoDyn, AeroDyn and ServoDyn files and ServoDyn's
        ``DLL_InFile`` (ROSCO's ``DISCON.IN``) are followed.
    elastodyn, aerodyn : str or Path, optional
        Without ``fst``: the ElastoDyn and AeroDyn 15 main files (both required). With ``fst``
        they override the deck's.
    servodyn, discon : str or Path, optional
        Overrides; without them, rated power and speed, limits and rates come from DISCON.IN
        if the deck has one, else :class:`TurbineFileError` names what is missing.
    name : str, optional
        Turbine name; the file stem by default.

    Returns
    -------
    Turbine
        With ``report`` listing each quantity, its value and ``file:line key`` or the default
        and why.

    Raises
    ------
    TurbineFileError
        Naming the file and key: a missing file or key, a value out of range, an unsupported
        feature (BeamDyn blades without an ElastoDyn blade file, OLAF, floating platforms,
        a platform DOF, MHK turbines, a number of blades other than 3).
    """
    notes: list[str] = []
    rec = _Recorder([], notes)
    fixed_bottom = False
    gravity_src: tuple[OpenFASTFile, str] | None = None
    rho_src: tuple[OpenFASTFile, str] | None = None
    if fst is not None:
        main = OpenFASTFile(fst)
        _check_main(main)
        if main.has("Gravity"):
            gravity_src = (main, "Gravity")
        if main.has("AirDens"):
            rho_src = (main, "AirDens")
        elastodyn = elastodyn or main.file("EDFile")
        aerodyn = aerodyn or (main.file("AeroFile")
                              if main.integer("CompAero", 0, 3) == 2 else None)
        if main.integer("CompServo", 0, 1) == 1:
            servodyn = servodyn or main.file("ServoFile")
        fixed_bottom = main.integer("CompSub", 0, 2) == 1
        if main.integer("CompSub", 0, 2) or main.integer("CompHydro", 0, 1):
            notes.append(f"{main.path.name}: CompSub/CompHydro set (fixed-bottom support); the "
                         f"support below the tower base is not modelled: the tower is clamped "
                         f"at its base (ElastoDyn TowerBsHt)")
        if main.integer("CompElast", 1, 3) == 2:
            notes.append(f"{main.path.name}: CompElast = 2 (BeamDyn blades); the ElastoDyn "
                         f"blade file is used for the blade structure and mode shapes")
        label = name or main.path.stem
        source = str(main.path)
    else:
        if elastodyn is None or aerodyn is None:
            raise TurbineFileError("load_openfast: give fst, or both elastodyn and aerodyn "
                                   f"(got elastodyn={elastodyn!r}, aerodyn={aerodyn!r})")
        label = name or Path(elastodyn).stem
        source = f"{elastodyn} + {aerodyn}"
    if elastodyn is None:
        raise TurbineFileError(f"{fst}: EDFile: ElastoDyn is required")
    if aerodyn is None:
        raise TurbineFileError(f"{fst}: CompAero must be 2 (AeroDyn 15); AeroDisk and external "
                               f"loads are not supported")
    ed = OpenFASTFile(elastodyn)
    ad = OpenFASTFile(aerodyn)
    srv = OpenFASTFile(servodyn) if servodyn is not None else None
    if discon is None and srv is not None and srv.has("DLL_InFile"):
        p = srv.file("DLL_InFile")
        discon = p if p is not None and p.is_file() else None
    dis = OpenFASTFile(discon) if discon is not None else None
    if gravity_src is None:
        gravity_src = (ed, "Gravity")
    if rho_src is None or rho_src[0].is_default(rho_src[1]):
        rho_src = (ad, "AirDens") if not ad.is_default("AirDens") else rho_src
    if rho_src is None:
        raise TurbineFileError(f"{ad.path}: AirDens is DEFAULT and no .fst gives it")

    _check_elastodyn(ed, fixed_bottom, notes)
    _check_aerodyn(ad)
    geometry = _geometry(ed, rec)
    drive = _drivetrain(ed, srv, dis, rec)
    blade_file = ed.file("BldFile1")
    tower_file = ed.file("TwrFile")
    if blade_file is None or not blade_file.is_file():
        raise TurbineFileError(f"{ed.path}: {ed.where('BldFile1')}: ElastoDyn blade file "
                               f"{blade_file} not found; BeamDyn-only blades are not supported "
                               f"(mpc-wt needs ElastoDyn's modal blade)")
    if tower_file is None:
        raise TurbineFileError(f"{ed.path}: TwrFile: a tower file is required")
    bld = OpenFASTFile(blade_file)
    twr = OpenFASTFile(tower_file)
    bstruct, bmodes, blade_damp, scale = _blade_structure(bld, rec)
    tstruct, tmodes, fa_damp, ss_damp = _tower_structure(twr, rec)
    tstruct = _with_tower_diameter(tstruct, ad, geometry, rec)
    blade_aero, polars = _aero(ad, geometry, rec)
    rotor = RotorMass(hub_mass=rec.read("hub mass", ed.number("HubMass", 0), "kg", ed, "HubMass"),
                      hub_inertia=rec.read("hub inertia", ed.number("HubIner", 0), "kg m^2", ed,
                                           "HubIner"),
                      blade_mass_scale=scale)
    nac_mass = ed.number("NacMass", 0)
    yaw_br = ed.number("YawBrMass", 0) if ed.has("YawBrMass") else 0.0
    rec.read("nacelle mass", nac_mass + yaw_br, "kg", ed, "NacMass",
             "+ YawBrMass at the tower top" if yaw_br else "")
    nacelle = Nacelle(mass=nac_mass + yaw_br,
                      yaw_inertia=rec.read("nacelle yaw inertia", ed.number("NacYIner", 0),
                                           "kg m^2", ed, "NacYIner"))
    geometry = _with_nacelle_cm(geometry, ed, nac_mass, yaw_br)
    operation, generator, pitch = _control(ed, srv, dis, drive, rec)
    min_pitch = _min_pitch_table(dis, rec) if dis is not None else None
    rigid = _rigid_dofs(ed, rec)
    if gravity_src[0].has(gravity_src[1]):
        g = rec.read("gravity", gravity_src[0].number(gravity_src[1], 0, 20), "m/s^2",
                     *gravity_src)
    else:
        g = rec.default("gravity", 9.80665, "m/s^2", "no .fst and no ElastoDyn Gravity: "
                        "standard gravity")
    rho = rec.read("air density", rho_src[0].number(rho_src[1], 0.5, 1.6), "kg/m^3", *rho_src)
    try:
        return Turbine(
            name=label, source=source, geometry=geometry, operation=operation,
            environment=Environment(air_density=rho, gravity=g), rotor=rotor, nacelle=nacelle,
            drivetrain=drive, generator=generator, pitch_actuator=pitch,
            damping=Damping(blade=blade_damp, tower_fa=fa_damp, tower_ss=ss_damp),
            blade=blade_aero, polars=polars, blade_structure=bstruct, tower_structure=tstruct,
            mode_shapes=ModeShapes(tower_fa1=tmodes[0], tower_ss1=tmodes[1],
                                   blade_flap1=bmodes[0], blade_edge1=bmodes[1]),
            rigid_dofs=rigid, min_pitch=min_pitch,
            report=LoadReport(tuple(rec.entries), tuple(notes)))
    except ValueError as err:
        raise TurbineFileError(f"{source}: {err}") from err


def _min_pitch_table(dis: OpenFASTFile, rec: _Recorder) -> MinPitchTable | None:
    """ROSCO's minimum-pitch schedule (``PS_BldPitchMin`` over ``PS_WindSpeeds``) where
    ``PS_Mode`` applies it (1; 0 or absent: none), with the keys' lines in the report."""
    if not dis.has("PS_Mode") or dis.integer("PS_Mode", 0, 3) == 0:
        return None
    for key in ("PS_WindSpeeds", "PS_BldPitchMin"):
        if not dis.has(key):
            raise TurbineFileError(f"{dis.path}: {dis.where('PS_Mode')} applies a minimum-pitch "
                                   f"schedule but the file has no {key}")
    w, b = dis.numbers("PS_WindSpeeds"), dis.numbers("PS_BldPitchMin")
    if dis.has("PS_BldPitchMin_N"):
        n = dis.integer("PS_BldPitchMin_N", 2)
        if not w.size == b.size == n:
            raise TurbineFileError(f"{dis.path}: {dis.where('PS_BldPitchMin_N')} = {n}, but "
                                   f"{dis.where('PS_WindSpeeds')} holds {w.size} values and "
                                   f"{dis.where('PS_BldPitchMin')} {b.size}")
    try:
        table = MinPitchTable(tuple(w), tuple(b))
    except ValueError as err:
        raise TurbineFileError(f"{dis.path}: {dis.where('PS_BldPitchMin')}: {err}") from err
    rec.entries.append(ReportEntry(
        "minimum-pitch schedule", f"{math.degrees(min(b)):.3g}..{math.degrees(max(b)):.3g} deg "
        f"over {w[0]:.3g}..{w[-1]:.3g} m/s ({w.size} points)",
        f"{dis.where('PS_BldPitchMin')} over {dis.where('PS_WindSpeeds')} "
        f"({dis.where('PS_Mode')} = 1: every operating point pitches at least this)"))
    return table


#: the plant's degrees of freedom and the ElastoDyn switch of each (its first mode)
ELASTODYN_DOFS = {"tower_fa": "TwFADOF1", "tower_ss": "TwSSDOF1", "drivetrain": "DrTrDOF",
                  "generator": "GenDOF", "blade_flap": "FlapDOF1", "blade_edge": "EdgeDOF"}


#: the switches a turbine read from a deck holds rigid in every run and design; the others
#: are reported (the TS and LQR-PIO designs are built on the tower's and blades' states)
RIGID_FROM_DECK = ("drivetrain", "generator")


def _rigid_dofs(ed: OpenFASTFile, rec: _Recorder) -> tuple[str, ...]:
    """The plant's degrees of freedom that ElastoDyn's switches hold rigid (a drivetrain with
    ``DrTrDOF`` False is one inertia: its ``DTTorSpr`` is not a spring the plant steps); the
    tower and blade switches set to False are noted, their DOFs left flexible."""
    off = sorted(d for d, key in ELASTODYN_DOFS.items() if ed.has(key) and not ed.flag(key))
    rigid = tuple(d for d in off if d in RIGID_FROM_DECK)
    if rigid:
        keys = ", ".join(ed.where(ELASTODYN_DOFS[d]) for d in rigid)
        rec.entries.append(ReportEntry("rigid degrees of freedom", ", ".join(rigid),
                                       f"{keys} False (the plant holds them rigid)"))
    kept = [d for d in off if d not in RIGID_FROM_DECK]
    if kept:
        rec.notes.append(f"{ed.path.name}: {', '.join(ed.where(ELASTODYN_DOFS[d]) for d in kept)}"
                         f" False: the plant's {', '.join(kept)} stay flexible (in every run "
                         f"but an OpenFAST case's, which follows the switches)")
    return rigid


def _check_main(main: OpenFASTFile) -> None:
    mhk = main.integer("MHK", 0, 2) if main.has("MHK") else 0
    if mhk:
        raise TurbineFileError(f"{main.path}: {main.where('MHK')} = {mhk}; only wind turbines "
                               f"(MHK = 0) are supported")
    if main.has("CompMooring") and main.integer("CompMooring", 0, 4):
        raise TurbineFileError(f"{main.path}: {main.where('CompMooring')} = "
                               f"{main.integer('CompMooring')}: floating platforms are not "
                               f"supported (CompMooring must be 0)")
    if main.integer("CompElast", 1, 3) == 3:
        raise TurbineFileError(f"{main.path}: {main.where('CompElast')} = 3 (simplified "
                               f"ElastoDyn) is not supported; allowed 1 or 2")
    if main.has("NRotors") and main.integer("NRotors", 1) != 1:
        raise TurbineFileError(f"{main.path}: {main.where('NRotors')}: one rotor is supported")


def _check_elastodyn(ed: OpenFASTFile, fixed_bottom: bool, notes: list[str]) -> None:
    nb = ed.integer("NumBl", 1, 3)
    if nb != 3:
        raise TurbineFileError(f"{ed.path}: {ed.where('NumBl')} = {nb}; the plant supports "
                               f"3 blades")
    on = [k for k in ("PtfmSgDOF", "PtfmSwDOF", "PtfmHvDOF", "PtfmRDOF", "PtfmPDOF", "PtfmYDOF")
          if ed.has(k) and ed.flag(k)]
    if on and not fixed_bottom:
        raise TurbineFileError(f"{ed.path}: {ed.where(on[0])} = True without SubDyn: platform "
                               f"degrees of freedom (floating platforms) are not supported")
    if on:
        notes.append(f"{ed.path.name}: platform DOFs {on} (SubDyn interface) are not modelled")


def _check_aerodyn(ad: OpenFASTFile) -> None:
    key = "Wake_Mod" if ad.has("Wake_Mod") else "WakeMod"
    wake = ad.integer(key, 0, 3)
    if wake == 3:
        raise TurbineFileError(f"{ad.path}: {ad.where(key)} = 3 (OLAF free vortex wake) is not "
                               f"supported; allowed 0-2 (BEM; mpc-wt runs its own BEM)")


def _geometry(ed: OpenFASTFile, rec: _Recorder) -> Geometry:
    tip = rec.read("tip radius", ed.number("TipRad", 0), "m", ed, "TipRad")
    hub = rec.read("hub radius", ed.number("HubRad", 0), "m", ed, "HubRad")
    cone = -ed.number("PreCone1", -20, 20)
    rec.read("precone", cone, "deg", ed, "PreCone(1)", "sign flipped: positive upwind")
    tilt = -ed.number("ShftTilt", -20, 20)
    rec.read("shaft tilt", tilt, "deg", ed, "ShftTilt", "sign flipped: positive nose up")
    overhang = -ed.number("OverHang", -30, 30)
    rec.read("overhang", overhang, "m", ed, "OverHang", "sign flipped: positive upwind")
    tower_ht = rec.read("tower height", ed.number("TowerHt", 0), "m", ed, "TowerHt")
    base = ed.number("TowerBsHt", 0, tower_ht) if ed.has("TowerBsHt") else 0.0
    rec.read("tower base height", base, "m", ed, "TowerBsHt", "the tower is clamped here")
    twr2shft = rec.read("tower top to shaft", ed.number("Twr2Shft"), "m", ed, "Twr2Shft")
    # ElastoDyn: HubHt = TowerHt + Twr2Shft + OverHang sin(ShftTilt), OpenFAST signs
    hub_ht = tower_ht + twr2shft + ed.number("OverHang") * math.sin(ed.number("ShftTilt") * _DEG)
    rec.entries.append(ReportEntry("hub height", f"{hub_ht:.6g} m",
                                   "TowerHt + Twr2Shft + OverHang sin(ShftTilt) (ElastoDyn)"))
    for key in ("HubCM", "NacCMyn"):
        if ed.has(key) and ed.number(key) != 0.0:
            rec.notes.append(f"{ed.where(key)} = {ed.number(key):g} m is not modelled (taken 0)")
    try:
        geo = Geometry(number_of_blades=3, tip_radius=tip, hub_radius=hub, hub_height=hub_ht,
                       tower_height=tower_ht, tower_base_height=base, twr2shft=twr2shft,
                       overhang=overhang, precone_rad=cone * _DEG, shaft_tilt_rad=tilt * _DEG,
                       nacelle_cm_downwind=0.0, nacelle_cm_vertical=0.0)
    except ValueError as err:
        raise TurbineFileError(f"{ed.path}: {err}") from err
    return geo


def _with_nacelle_cm(geo: Geometry, ed: OpenFASTFile, nac: float, yaw_br: float) -> Geometry:
    import dataclasses
    x = ed.number("NacCMxn", -30, 30)
    z = ed.number("NacCMzn", -30, 30)
    total = nac + yaw_br
    return dataclasses.replace(geo, nacelle_cm_downwind=x * nac / total,
                               nacelle_cm_vertical=z * nac / total)


def _drivetrain(ed: OpenFASTFile, srv: OpenFASTFile | None, dis: OpenFASTFile | None,
                rec: _Recorder) -> Drivetrain:
    if srv is not None and srv.has("GenEff"):
        eff = rec.read("generator efficiency", srv.number("GenEff", 1, 100) / 100, "", srv,
                       "GenEff", "percent")
    elif dis is not None and dis.has("VS_GenEff"):
        eff = rec.read("generator efficiency", dis.number("VS_GenEff", 1, 100) / 100, "", dis,
                       "VS_GenEff", "percent")
    else:
        raise TurbineFileError(f"{ed.path}: no ServoDyn GenEff nor DISCON VS_GenEff: the "
                               f"generator efficiency is needed")
    return Drivetrain(
        gearbox_ratio=rec.read("gearbox ratio", ed.number("GBRatio", 1, 1000), "", ed, "GBRatio"),
        gearbox_efficiency=rec.read("gearbox efficiency", ed.number("GBoxEff", 1, 100) / 100,
                                    "", ed, "GBoxEff", "percent"),
        generator_efficiency=eff,
        generator_inertia=rec.read("generator inertia", ed.number("GenIner", 0), "kg m^2", ed,
                                   "GenIner", "about the high-speed shaft"),
        shaft_stiffness=rec.read("shaft stiffness", ed.number("DTTorSpr", 0), "N m/rad", ed,
                                 "DTTorSpr"),
        shaft_damping=rec.read("shaft damping", ed.number("DTTorDmp", 0), "N m s/rad", ed,
                               "DTTorDmp"))


def _make(f: OpenFASTFile, cls: type, **kwargs: object) -> object:
    """Build a dataclass; its ValueError becomes a TurbineFileError naming the file."""
    try:
        return cls(**kwargs)
    except ValueError as err:
        raise TurbineFileError(f"{f.path}: {err}") from err


def _positive(f: OpenFASTFile, t: dict[str, FloatArray], cols: Sequence[str]) -> None:
    for col in cols:
        if np.any(t[col] <= 0):
            i = int(np.argmax(t[col] <= 0))
            raise TurbineFileError(f"{f.path}: column {col!r}, row {i + 1}: {t[col][i]!r}; "
                                   f"allowed > 0")


def _shape(f: OpenFASTFile, stem: str) -> FloatArray:
    return np.array([f.number(f"{stem}{k}") for k in range(2, 7)])


def _blade_structure(bld: OpenFASTFile, rec: _Recorder
                     ) -> tuple[BladeStructure, tuple[FloatArray, FloatArray], float, float]:
    n = bld.integer("NBlInpSt", 2, 10000)
    t = bld.table(("BlFract", "BMassDen", "FlpStff", "EdgStff"), n)
    scale = bld.number("AdjBlMs", 0.5, 2.0)
    rec.read("blade mass scale", scale, "", bld, "AdjBlMs")
    fl = bld.number("AdjFlSt", 0.1, 10) if bld.has("AdjFlSt") else 1.0
    eg = bld.number("AdjEdSt", 0.1, 10) if bld.has("AdjEdSt") else 1.0
    for key in ("FlStTunr1",):
        if bld.has(key) and bld.number(key) != 1.0:
            rec.notes.append(f"{bld.where(key)} = {bld.number(key):g}: modal stiffness tuners "
                             f"are not applied")
    _positive(bld, t, ("BMassDen", "FlpStff", "EdgStff"))
    damp = bld.number("BldFlDmp1", 0, 50) / 100
    rec.read("blade damping ratio", damp, "", bld, "BldFlDmp(1)", "percent")
    twist = None
    try:
        twist = np.radians(bld.table(("BlFract", "StrcTwst"), n)["StrcTwst"])
    except TurbineFileError:
        rec.notes.append(f"{bld.path.name}: no StrcTwst column: the blade modes vibrate in and "
                         f"out of the rotor plane")
    bs = _make(bld, BladeStructure, span_fraction=t["BlFract"],
               mass_per_length=t["BMassDen"] * scale, flap_stiffness=t["FlpStff"] * fl,
               edge_stiffness=t["EdgStff"] * eg, structural_twist_rad=twist)
    rec.entries.append(ReportEntry("blade structure", f"{n} stations",
                                   f"{bld.path.name} BlFract, BMassDen x AdjBlMs, FlpStff x "
                                   f"AdjFlSt, EdgStff x AdjEdSt"))
    return bs, (_shape(bld, "BldFl1Sh"), _shape(bld, "BldEdgSh")), damp, scale


def _tower_structure(twr: OpenFASTFile, rec: _Recorder
                     ) -> tuple[TowerStructure, tuple[FloatArray, FloatArray], float, float]:
    n = twr.integer("NTwInpSt", 2, 10000)
    t = twr.table(("HtFract", "TMassDen", "TwFAStif", "TwSSStif"), n)
    adj = {k: (twr.number(k, 0.1, 10) if twr.has(k) else 1.0)
           for k in ("AdjTwMa", "AdjFASt", "AdjSSSt")}
    _positive(twr, t, ("TMassDen", "TwFAStif", "TwSSStif"))
    fa = twr.number("TwrFADmp1", 0, 50) / 100
    ss = twr.number("TwrSSDmp1", 0, 50) / 100
    rec.read("tower fore-aft damping ratio", fa, "", twr, "TwrFADmp(1)", "percent")
    rec.read("tower side-side damping ratio", ss, "", twr, "TwrSSDmp(1)", "percent")
    ts = _make(twr, TowerStructure, height_fraction=t["HtFract"],
               mass_per_length=t["TMassDen"] * adj["AdjTwMa"],
               fa_stiffness=t["TwFAStif"] * adj["AdjFASt"],
               ss_stiffness=t["TwSSStif"] * adj["AdjSSSt"])
    rec.entries.append(ReportEntry("tower structure", f"{n} stations",
                                   f"{twr.path.name} HtFract, TMassDen, TwFAStif, TwSSStif "
                                   f"with the Adj factors"))
    return ts, (_shape(twr, "TwFAM1Sh"), _shape(twr, "TwSSM1Sh")), fa, ss


def _with_tower_diameter(ts: TowerStructure, ad: OpenFASTFile, geo: Geometry,
                         rec: _Recorder) -> TowerStructure:
    """The tower structure with AeroDyn's tower diameters (``TwrElev``, ``TwrDiam``)
    interpolated at its stations, when AeroDyn has a tower table (``NumTwrNds`` >= 2)."""
    if not ad.has("NumTwrNds"):
        return ts
    n = ad.integer("NumTwrNds", 0, 100000)
    if n < 2:
        return ts
    t = ad.table(("TwrElev", "TwrDiam", "TwrCd"), n)
    _positive(ad, t, ("TwrDiam",))
    h = geo.tower_base_height + ts.height_fraction * (geo.tower_height - geo.tower_base_height)
    order = np.argsort(t["TwrElev"])
    d = np.interp(h, t["TwrElev"][order], t["TwrDiam"][order])
    cd = np.interp(h, t["TwrElev"][order], t["TwrCd"][order])
    rec.entries.append(ReportEntry("tower outer diameter", f"{d[0]:.4g}..{d[-1]:.4g} m",
                                   f"{ad.path.name} TwrElev, TwrDiam ({n} nodes), "
                                   f"interpolated at the tower stations"))
    rec.entries.append(ReportEntry("tower drag coefficient", f"{cd.min():.4g}..{cd.max():.4g}",
                                   f"{ad.path.name} TwrCd ({n} nodes)"))
    return replace(ts, outer_diameter=d, drag_coefficient=cd)


def _aero(ad: OpenFASTFile, geo: Geometry, rec: _Recorder
          ) -> tuple[BladeAero, tuple[Polar, ...]]:
    base = ad.path.parent
    n_af = ad.integer("NumAFfiles", 1, 10000)
    first = ad.keys["afnames"][1]
    names = [ad.text("AFNames")]
    for k in range(1, n_af):
        i = first + k
        toks = _TOKEN.findall(ad.lines[i]) if i < len(ad.lines) else []
        if not toks:
            raise TurbineFileError(f"{ad.path}: line {i + 1}: expected airfoil file {k + 1} of "
                                   f"NumAFfiles = {n_af}")
        names.append(_unquote(toks[0]))
    cols = tuple(ad.integer(k, 1, 100) if ad.has(k) else d
                 for k, d in (("InCol_Alfa", 1), ("InCol_Cl", 2), ("InCol_Cd", 3)))
    mode = ad.integer("AFTabMod", 1, 3) if ad.has("AFTabMod") else 1
    polars = []
    for nm in names:
        p = (base / nm).resolve()
        polar, note = read_airfoil_polar(p, columns=cols,  # type: ignore[arg-type]
                                         table_mode=mode)
        if note:
            rec.notes.append(note)
        polars.append(polar)
    key = "ADBlFile1"
    bl_path = ad.file(key)
    if bl_path is None:
        raise TurbineFileError(f"{ad.path}: {ad.where(key)}: a blade file is required")
    blf = OpenFASTFile(bl_path)
    n = blf.integer("NumBlNds", 2, 10000)
    t = blf.table(("BlSpn", "BlTwist", "BlChord", "BlAFID"), n)
    afid = t["BlAFID"].astype(int)
    if np.any(afid < 1) or np.any(afid > n_af) or np.any(afid != t["BlAFID"]):
        i = int(np.argmax((afid < 1) | (afid > n_af)))
        raise TurbineFileError(f"{blf.path}: column 'BlAFID', row {i + 1}: {t['BlAFID'][i]!r}; "
                               f"allowed 1..NumAFfiles = {n_af}")
    _positive(blf, t, ("BlChord",))
    r = geo.hub_radius + t["BlSpn"]
    if np.any(np.diff(r) <= 0):
        i = int(np.argmax(np.diff(r) <= 0)) + 1
        raise TurbineFileError(f"{blf.path}: column 'BlSpn' must increase strictly "
                               f"(row {i + 1}: {t['BlSpn'][i]!r} after {t['BlSpn'][i - 1]!r})")
    if r[-1] > geo.tip_radius + 1e-3:
        raise TurbineFileError(f"{blf.path}: column 'BlSpn' reaches {t['BlSpn'][-1]:g} m; "
                               f"the blade is TipRad - HubRad = "
                               f"{geo.tip_radius - geo.hub_radius:g} m long")
    blade = _node_elements(r, t["BlChord"], np.radians(t["BlTwist"]), afid - 1, geo)
    rec.entries.append(ReportEntry(
        "blade aerodynamics", f"{blade.r.size} elements, {len(polars)} polars",
        f"{blf.path.name} BlSpn, BlChord, BlTwist, BlAFID (nodes inside the rotor, trapezoid "
        f"weights); prebend and sweep (BlCrvAC, BlSwpAC) not modelled"))
    return blade, tuple(polars)


def _node_elements(r: FloatArray, chord: FloatArray, twist: FloatArray, af: np.ndarray,
                   geo: Geometry) -> BladeAero:
    """AeroDyn nodes strictly inside (hub, tip) as elements with trapezoid weights, the load at
    hub and tip taken zero (hub- and tip-loss factors vanish there)."""
    inside = (r > geo.hub_radius + 1e-6) & (r < geo.tip_radius - 1e-6)
    rr = np.concatenate(([geo.hub_radius], r[inside], [geo.tip_radius]))
    w = 0.5 * (rr[2:] - rr[:-2])
    return BladeAero(r=r[inside], dr=w, chord=chord[inside], twist_rad=twist[inside],
                     airfoil=af[inside], layout="nodes")


def _control(ed: OpenFASTFile, srv: OpenFASTFile | None, dis: OpenFASTFile | None,
             drive: Drivetrain, rec: _Recorder
             ) -> tuple[Operation, Generator, PitchActuator]:
    if dis is None:
        raise TurbineFileError(f"{ed.path}: no DISCON.IN (ServoDyn DLL_InFile): rated power, "
                               f"rated speed and the pitch and torque limits are read from it; "
                               f"pass discon=PATH")
    n = drive.gearbox_ratio
    power = rec.read("rated power", dis.number("VS_RtPwr", 1), "W", dis, "VS_RtPwr")
    rated = dis.number("PC_RefSpd", 0) / n
    rec.read("rated rotor speed", rated / _RPM, "rpm", dis, "PC_RefSpd",
             "generator speed / GBRatio")
    omin = dis.number("VS_MinOMSpd", 0) / n if dis.has("VS_MinOMSpd") else 0.0
    rec.read("minimum rotor speed", omin / _RPM, "rpm", dis, "VS_MinOMSpd",
             "generator speed / GBRatio")
    pmin = dis.number("PC_MinPit", -0.6, 0.6)
    fine = dis.number("PC_FinePit", -0.6, 0.6) if dis.has("PC_FinePit") else pmin
    rec.read("fine pitch", fine / _DEG, "deg", dis,
             "PC_FinePit" if dis.has("PC_FinePit") else "PC_MinPit")
    if fine < pmin:
        raise TurbineFileError(f"{dis.where('PC_FinePit')}: the fine pitch "
                               f"{fine / _DEG:.4g} deg is below the minimum pitch "
                               f"{pmin / _DEG:.4g} deg ({dis.where('PC_MinPit')}): the "
                               f"region-2 pitch must be one the actuator can reach")
    ci, why_ci = DEFAULTS["cut_in_wind"]
    co, why_co = DEFAULTS["cut_out_wind"]
    rec.default("cut-in wind", ci, "m/s", why_ci)
    rec.default("cut-out wind", co, "m/s", why_co)
    try:
        op = Operation(rated_power=power, cut_in_wind=ci, cut_out_wind=co,
                       min_rotor_speed_rad_s=omin, rated_rotor_speed_rad_s=rated,
                       fine_pitch_rad=fine)
        gen = Generator(
            min_torque=rec.read("minimum generator torque", dis.number("VS_MinTq"), "N m", dis,
                                "VS_MinTq") if dis.has("VS_MinTq") else 0.0,
            max_torque=rec.read("maximum generator torque", dis.number("VS_MaxTq", 0), "N m",
                                dis, "VS_MaxTq"),
            max_torque_rate=rec.read("generator torque rate", dis.number("VS_MaxRat", 0),
                                     "N m/s", dis, "VS_MaxRat"))
        mode = dis.integer("PA_Mode", 0, 2) if dis.has("PA_Mode") else 0
        if mode >= 1 and dis.has("PA_CornerFreq"):
            tau = rec.read("pitch servo time constant", 1.0 / dis.number("PA_CornerFreq", 0.2),
                           "s", dis, "PA_CornerFreq", "1 / corner frequency")
        else:
            tau = rec.default("pitch servo time constant", DEFAULTS["pitch_time_constant"][0],
                              "s", DEFAULTS["pitch_time_constant"][1])
        pitch = PitchActuator(
            min_pitch_rad=rec.read("minimum pitch", pmin / _DEG, "deg", dis, "PC_MinPit")
            * _DEG,
            max_pitch_rad=rec.read("maximum pitch", dis.number("PC_MaxPit", 0, 1.7) / _DEG,
                                   "deg", dis, "PC_MaxPit") * _DEG,
            max_rate_rad_s=rec.read("pitch rate limit", dis.number("PC_MaxRat", 0) / _DEG,
                                    "deg/s", dis, "PC_MaxRat") * _DEG,
            time_constant=tau)
    except ValueError as err:
        raise TurbineFileError(f"{dis.path}: {err}") from err
    return op, gen, pitch

"""Rotor performance tables C_P, C_T, C_Q over tip-speed ratio and pitch, in ROSCO's layout.

ROSCO's ``Cp_Ct_Cq.txt`` holds a pitch vector [deg] (matrix columns), a TSR vector (matrix rows),
one wind speed [m/s] and the three matrices, each under a comment line naming it. ROSCO's own
reader (``rosco.toolbox.utilities.load_from_txt``) finds each block by the words "Pitch angle",
"TSR", "Power", "Thrust" and "Torque"; :func:`write_rotor_performance` keeps those and writes
every number with 17 significant digits, so that :func:`read_rotor_performance` gives back the
same floats.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from linearize._kept import Kept
from linearize._typing import FloatArray
from linearize.bem import AeroOptions
from linearize.errors import TurbineFileError
from linearize.turbine import content_digest
from linearize.validate import frozen_array

__all__ = ["RotorPerformance", "read_rotor_performance", "write_rotor_performance",
           "rotor_performance"]


@dataclass(frozen=True)
class RotorPerformance:
    """Steady rotor coefficients on a (TSR, pitch) grid.

    Parameters
    ----------
    pitch_deg : (n_p,) ndarray
        Collective pitch, strictly increasing [deg]: kept in the table's own unit so that a
        file read and written again is the same to the last digit (:attr:`pitch_rad` converts).
    tsr : (n_l,) ndarray
        Tip-speed ratio, strictly increasing [-].
    cp, ct, cq : (n_l, n_p) ndarray
        Power, thrust and torque coefficients [-]; rows TSR, columns pitch.
    wind_mps : float
        The wind speed the table was made at [m/s] (ROSCO's "z axis").
    name : str
        Turbine name for the header.
    """

    pitch_deg: FloatArray
    tsr: FloatArray
    cp: FloatArray
    ct: FloatArray
    cq: FloatArray
    wind_mps: float = float("nan")
    name: str = ""

    def __post_init__(self) -> None:
        for n in ("pitch_deg", "tsr", "cp", "ct", "cq"):
            object.__setattr__(self, n, frozen_array(getattr(self, n)))
        for n in ("pitch_deg", "tsr"):
            v = getattr(self, n)
            if v.ndim != 1 or v.size < 2 or np.any(np.diff(v) <= 0):
                raise ValueError(f"RotorPerformance.{n} must be 1-D, strictly increasing, with "
                                 f"at least 2 entries; got shape {v.shape}")
        shape = (self.tsr.size, self.pitch_deg.size)
        for n in ("cp", "ct", "cq"):
            m = getattr(self, n)
            if m.shape != shape:
                raise ValueError(f"RotorPerformance.{n} has shape {m.shape}; expected "
                                 f"(n_tsr, n_pitch) = {shape}")
            if not np.all(np.isfinite(m)):
                raise ValueError(f"RotorPerformance.{n} has non-finite entries")

    @property
    def pitch_rad(self) -> FloatArray:
        """Pitch [rad]."""
        return np.radians(self.pitch_deg)

    def cp_max(self) -> tuple[float, float, float]:
        """Largest C_P on the grid and where: (C_P, TSR, pitch [rad]).

        Returns
        -------
        cp : float
            Largest C_P [-].
        tsr : float
            Its tip-speed ratio [-].
        pitch_rad : float
            Its pitch [rad].
        """
        i, j = np.unravel_index(int(np.argmax(self.cp)), self.cp.shape)
        return float(self.cp[i, j]), float(self.tsr[i]), float(self.pitch_rad[j])


#: how many tables :func:`rotor_performance` keeps
TABLES_KEPT = 8
#: tables computed in this process, by (turbine content, grid, wind, shear, options)
_TABLES = Kept(TABLES_KEPT)


def rotor_performance(turbine: object, tsr: FloatArray, pitch_deg: FloatArray, *,
                      wind_mps: float = 10.0, shear_exponent: float = 0.0,
                      options: AeroOptions | None = None) -> RotorPerformance:
    """Tabulate the plant's steady C_P, C_T and C_Q on a grid.

    C_P, C_T and the TSR use the projected radius R cos(precone) (as CCBlade and
    :func:`steady_coefficients`); C_Q follows ROSCO's tables, C_Q = C_P / (TSR cos(precone)),
    i.e. the torque over the projected area and the blade's tip radius (checked on ROSCO's NREL
    5-MW table: the ratio is 1/cos 2.5 deg to 1e-5).

    A table takes seconds (a wind estimator's 69 x 91 points with shear: about 3 s for the
    NREL 5-MW, 9 s for the IEA-15). The process keeps the last :data:`TABLES_KEPT` tables, keyed
    on the turbine's content (:func:`linearize.turbine.content_digest`), the grid, the wind, the
    shear and the options: asking again for the same table returns the kept one (immutable),
    so that the designs of one turbine share it.

    Parameters
    ----------
    turbine : Turbine
    tsr : (n_l,) ndarray
        Tip-speed ratios [-], strictly increasing.
    pitch_deg : (n_p,) ndarray
        Pitch angles [deg], strictly increasing.
    wind_mps : float
        Recorded as the table's wind speed [m/s] (the rigid-rotor coefficients do not depend
        on it).
    shear_exponent : float
        Power-law shear [-].
    options : AeroOptions, optional
        Aerodynamic switches.

    Returns
    -------
    RotorPerformance
    """
    from linearize.steady import steady_coefficients

    lam = np.asarray(tsr, dtype=float)
    beta = np.asarray(pitch_deg, dtype=float)
    if lam.ndim != 1 or beta.ndim != 1:
        raise ValueError(f"tsr and pitch_deg must be 1-D; got shapes {lam.shape}, {beta.shape}")
    if np.any(lam <= 0):
        raise ValueError(f"tsr must be > 0, got min {lam.min():g}")
    opts = options or AeroOptions()
    key = (content_digest(turbine), lam.tobytes(), beta.tobytes(), float(wind_mps),
           float(shear_exponent), repr(opts))

    def make() -> RotorPerformance:
        L, B = np.meshgrid(lam, beta, indexing="ij")
        cp, ct = steady_coefficients(turbine, L, B, options,  # type: ignore[arg-type]
                                     shear_exponent=shear_exponent)
        cone = turbine.geometry.precone_rad if opts.cone else 0.0  # type: ignore[attr-defined]
        return RotorPerformance(pitch_deg=beta, tsr=lam, cp=cp, ct=ct,
                                cq=cp / (L * math.cos(cone)), wind_mps=float(wind_mps),
                                name=getattr(turbine, "name", ""))
    return _TABLES.get(key, make)


def _fmt(v: float) -> str:
    return repr(float(v))


def write_rotor_performance(perf: RotorPerformance, path: str | Path) -> Path:
    """Write a table in ROSCO's ``Cp_Ct_Cq.txt`` layout (numbers at full precision).

    Parameters
    ----------
    perf : RotorPerformance
    path : str or Path

    Returns
    -------
    Path
    """
    p = Path(path)
    wind = perf.wind_mps if math.isfinite(perf.wind_mps) else 0.0
    lines = [f"# ----- Rotor performance tables for the {perf.name or 'mpc-wt'} wind turbine ----- ",
             "# ------------ Written by mpc-wt (linearize.write_rotor_performance) ------------ ",
             "",
             f"# Pitch angle vector, {perf.pitch_rad.size} entries - x axis (matrix columns) (deg)",
             "   ".join(_fmt(v) for v in perf.pitch_deg),
             f"# TSR vector, {perf.tsr.size} entries - y axis (matrix rows) (-)",
             "   ".join(_fmt(v) for v in perf.tsr),
             "# Wind speed vector - z axis (m/s)",
             _fmt(wind), ""]
    for title, m in (("# Power coefficient", perf.cp), ("#  Thrust coefficient", perf.ct),
                     ("# Torque coefficient", perf.cq)):
        lines += [title, ""]
        lines += ["   ".join(_fmt(v) for v in row) for row in m]
        lines += ["", ""]
    p.write_text("\n".join(lines))
    return p


def read_rotor_performance(path: str | Path) -> RotorPerformance:
    """Read a ROSCO ``Cp_Ct_Cq.txt`` performance table.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    RotorPerformance

    Raises
    ------
    TurbineFileError
        Naming the file and line: a missing block, a row of the wrong length, a non-number.
    """
    p = Path(path)
    if not p.is_file():
        raise TurbineFileError(f"{p}: file not found")
    lines = p.read_text(errors="replace").splitlines()

    def numbers(i: int) -> FloatArray:
        try:
            return np.array([float(x) for x in lines[i].split()])
        except (ValueError, IndexError):
            raise TurbineFileError(f"{p}: line {i + 1}: expected a row of numbers, got "
                                   f"{lines[i][:60]!r}" if i < len(lines) else
                                   f"{p}: ends at line {len(lines)}; expected more rows") from None

    def find(word: str) -> int:
        for i, ln in enumerate(lines):
            if ln.lstrip().startswith("#") and word in ln:
                return i
        raise TurbineFileError(f"{p}: no '# ... {word} ...' line: not a ROSCO performance table")

    pitch = numbers(find("Pitch angle") + 1)
    tsr = numbers(find("TSR") + 1)
    i_w = find("Wind speed")
    wind = numbers(i_w + 1)
    mats = []
    for word in ("Power", "Thrust", "Torque"):
        i = find(word) + 1
        while i < len(lines) and not lines[i].strip():
            i += 1
        rows = []
        for k in range(tsr.size):
            row = numbers(i + k)
            if row.size != pitch.size:
                raise TurbineFileError(f"{p}: line {i + k + 1}: {row.size} values in the "
                                       f"{word.lower()} table; expected {pitch.size} "
                                       f"(one per pitch angle)")
            rows.append(row)
        mats.append(np.array(rows))
    name = lines[0].split("for the", 1)[-1].split("wind turbine")[0].strip() if lines else ""
    try:
        return RotorPerformance(pitch_deg=pitch, tsr=tsr, cp=mats[0], ct=mats[1],
                                cq=mats[2], wind_mps=float(wind[0]) if wind.size else math.nan,
                                name=name)
    except ValueError as err:
        raise TurbineFileError(f"{p}: {err}") from err

"""Helpers shared by the command modules: ranges, turbines, tables, number lists."""
from __future__ import annotations

import argparse
import csv
import math
import os
import tempfile
from pathlib import Path
from typing import Any, Sequence

import numpy as np

import linearize
from linearize import OperatingPoint
from mpc_wt.errors import UsageError
from mpc_wt.io.json_text import to_json

__all__ = ["parse_range", "add_turbine", "schedule", "format_table", "write_points_csv",
           "cp_surface", "write_surface_csv", "pairs", "floats", "check_suffix", "check_out_file",
           "to_json"]

TURBINE_HELP = ("packaged turbine name (nrel5mw, iea15mw), a turbine.yaml or an OpenFAST .fst "
                "deck (default nrel5mw)")



def check_out_file(flag: str, value: str, suffix: str) -> Path:
    """An output file named on the command line, checked before any work
    (:func:`check_suffix`), with ``suffix`` added when it has none.

    Parameters
    ----------
    flag : str
        The option, for the message.
    value : str
        The path given.
    suffix : str
        The one suffix the command writes, e.g. ``".nc"``.

    Returns
    -------
    Path
        The path, with ``suffix`` when it had none.

    Raises
    ------
    UsageError
        Naming the option, the path and what is allowed.
    """
    out = Path(value)
    if value.endswith(("/", os.sep)) or out.is_dir():
        raise UsageError(f"{flag} {value}: is a folder; name a file ending in {suffix}")
    if out.suffix == "":
        out = out.with_suffix(suffix)
    check_suffix(str(out), flag, (suffix,))
    return out


def check_out_folder(flag: str, value: str | Path | None) -> Path | None:
    """An output folder named on the command line, checked before any work: it may exist (as a
    folder) or not yet; a file of that name is refused.

    Parameters
    ----------
    flag : str
        The option, for the message.
    value : str or Path or None
        The path given (None: the command's default, not checked here).

    Returns
    -------
    Path or None

    Raises
    ------
    UsageError
        Naming the option and the path.
    """
    if value is None:
        return None
    out = Path(value)
    if out.exists() and not out.is_dir():
        raise UsageError(f"{flag} {value}: is a file; the command writes a folder there: name "
                         f"a new folder or an existing one")
    for parent in out.parents:
        if parent.exists() and not parent.is_dir():
            raise UsageError(f"{flag} {value}: {parent} is a file, not a folder")
    return out


def add_turbine(p: argparse.ArgumentParser) -> None:
    """Add ``--turbine`` to a parser.

    Parameters
    ----------
    p : argparse.ArgumentParser
        The command's parser.
    """
    p.add_argument("--turbine", default="nrel5mw", help=TURBINE_HELP)


#: The most values a ``START:STOP:STEP`` range may make.
MAX_RANGE = 1000


def parse_range(text: str, name: str) -> np.ndarray:
    """Parse ``START:STOP:STEP`` (STOP included), ``START:STOP`` (step 1) or ``A,B,C``.

    Parameters
    ----------
    text : str
        The option's value.
    name : str
        The option's flag, for messages.

    Returns
    -------
    (n,) ndarray
        The values.

    Raises
    ------
    UsageError
        Naming the option and the value if it is not a finite, increasing range.
    """
    try:
        if ":" in text:
            parts = [float(p) for p in text.split(":")]
            if len(parts) == 2:
                parts.append(1.0)
            if len(parts) != 3:
                raise ValueError
            a, b, s = parts
            if not all(math.isfinite(v) for v in parts) or s <= 0 or b < a:
                raise ValueError
            n = int(math.floor((b - a) / s + 1e-9)) + 1
            if n > MAX_RANGE:
                raise UsageError(f"{name} {text}: makes {n} values, more than {MAX_RANGE}; "
                                 f"give a larger STEP")
            vals = a + s * np.arange(n)
        else:
            vals = np.array([float(p) for p in text.split(",")])
    except UsageError:
        raise
    except ValueError:
        raise UsageError(f"{name} must be START:STOP:STEP with STEP > 0 and STOP >= START, "
                         f"or a comma list of numbers; got {text!r}") from None
    if vals.size == 0 or not np.all(np.isfinite(vals)):
        raise UsageError(f"{name} must hold finite numbers; got {text!r}")
    return vals


def check_suffix(path: str | None, name: str, allowed: Sequence[str]) -> None:
    """Raise before any work if a file's suffix is not one we can write, it names a folder,
    or its folder does not exist or is not writable.

    Parameters
    ----------
    path : str or None
        The file (None: not given).
    name : str
        The option's flag.
    allowed : sequence of str
        Suffixes with the dot (".mat").

    Raises
    ------
    UsageError
        Naming the option, the value and the allowed suffixes.
    """
    if path is None:
        return
    out = Path(path)
    if out.suffix.lower() not in allowed:
        raise UsageError(f"{name} must end in {', '.join(allowed)}; got {path!r}")
    if out.is_dir():
        raise UsageError(f"{name} {path}: is a folder; name a file ending in "
                         f"{', '.join(allowed)}")
    folder = out.parent
    if not folder.is_dir():
        raise UsageError(f"{name} {path}: the folder {folder} does not exist")
    try:        # a file made and removed: os.access answers yes for root, even in /proc
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as err:
        raise UsageError(f"{name} {path}: the folder {folder} is not writable "
                         f"({err.strerror or err})") from None


def schedule(turbine: linearize.Turbine, winds: np.ndarray, power_W: float | None,
             progress: bool) -> list[OperatingPoint]:
    """Trim at each wind with a progress bar.

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    winds : (n,) ndarray
        Mean winds [m/s].
    power_W : float or None
        Power reference below rated [W].
    progress : bool
        Show the bar.

    Returns
    -------
    list of OperatingPoint
        One per wind.
    """
    from linearize.progress import progress as bar

    params = linearize.plant_params(turbine)
    return [linearize.trim(turbine, float(v), power_W, params=params)
            for v in bar(winds, "trim", "pt", enabled=progress)]


_TABLE_COLS = (("wind_mps", "wind [m/s]", "{:8.2f}"), ("region", "region", "{:>6s}"),
               ("pitch_deg", "pitch [deg]", "{:11.3f}"),
               ("rotor_speed_rpm", "rotor [rpm]", "{:11.3f}"),
               ("gen_torque_Nm", "gen torque [N m]", "{:16.1f}"),
               ("power_W", "power [kW]", "{:10.1f}"), ("thrust_N", "thrust [kN]", "{:11.1f}"),
               ("cp", "C_P", "{:6.3f}"), ("tower_fa_deflection_m", "tower FA [m]", "{:12.4f}"))


def format_table(points: Sequence[OperatingPoint]) -> str:
    """The steady operating table as aligned text.

    Parameters
    ----------
    points : sequence of OperatingPoint
        Rows.

    Returns
    -------
    str
        Header and one line per point (power and thrust in k units).
    """
    head = " ".join(f"{h:>{len(fmt.format(0.0 if 's' not in fmt else ''))}s}"
                    for _, h, fmt in _TABLE_COLS)
    lines = [head]
    for p in points:
        d = p.as_dict()
        lines.append(" ".join(fmt.format(d[key] / 1e3 if key in ("power_W", "thrust_N")
                                         else d[key]) for key, _, fmt in _TABLE_COLS))
    return "\n".join(lines)


def write_points_csv(points: Sequence[OperatingPoint], path: Path) -> None:
    """Write operating points as CSV, one row each.

    Parameters
    ----------
    points : sequence of OperatingPoint
        Rows.
    path : Path
        The file.
    """
    rows = [p.as_dict() for p in points]
    with path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


def cp_surface(turbine: linearize.Turbine, tsr: np.ndarray, pitch: np.ndarray) -> np.ndarray:
    """C_P over a grid.

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    tsr : (n_tsr,) ndarray
        Tip-speed ratios [-].
    pitch : (n_pitch,) ndarray
        Pitch angles [deg].

    Returns
    -------
    (n_pitch, n_tsr) ndarray
        C_P [-].
    """
    lam, pit = np.meshgrid(tsr, pitch)
    cp, _ = linearize.steady_coefficients(turbine, lam, pit)
    return cp


def write_surface_csv(tsr: np.ndarray, pitch: np.ndarray, cp: np.ndarray, path: Path) -> None:
    """Write a C_P table (rows pitch, columns tip-speed ratio).

    Parameters
    ----------
    tsr : (n_tsr,) ndarray
        Column values [-].
    pitch : (n_pitch,) ndarray
        Row values [deg].
    cp : (n_pitch, n_tsr) ndarray
        C_P [-].
    path : Path
        The file.
    """
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["pitch_deg \\ tsr"] + [f"{v:g}" for v in tsr])
        for b, row in zip(pitch, cp):
            w.writerow([f"{b:g}"] + [f"{c:.6f}" for c in row])


def pairs(items: Sequence[str] | None, name: str) -> dict[str, Any]:
    """``NAME=VALUE`` options to a dict; values parsed as YAML scalars (numbers, true, null).

    Parameters
    ----------
    items : sequence of str or None
        The repeated option's values.
    name : str
        The option's flag.

    Returns
    -------
    dict
        Name -> value.

    Raises
    ------
    UsageError
        For an item without ``=`` or a name.
    """
    import yaml

    out: dict[str, Any] = {}
    for it in items or []:
        key, sep, val = it.partition("=")
        if not sep or not key.strip():
            raise UsageError(f"{name} takes NAME=VALUE, got {it!r}")
        try:
            out[key.strip()] = yaml.safe_load(val)
        except yaml.YAMLError:
            out[key.strip()] = val
    return out


def number_pairs(items: Sequence[str] | None, name: str) -> dict[str, float]:
    """``NAME=VALUE`` options with numeric values.

    Parameters
    ----------
    items : sequence of str or None
        The repeated option's values.
    name : str
        The option's flag.

    Returns
    -------
    dict of str to float
        Name -> value.

    Raises
    ------
    UsageError
        For an item that is not NAME=NUMBER.
    """
    out = {}
    for k, v in pairs(items, name).items():
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise UsageError(f"{name} takes NAME=VALUE with a number, got {k}={v!r}")
        out[k] = float(v)
    return out


def floats(text: str, name: str) -> list[float]:
    """A comma list of finite numbers.

    Parameters
    ----------
    text : str
        The option's value.
    name : str
        The option's flag.

    Returns
    -------
    list of float
        The numbers.

    Raises
    ------
    UsageError
        If an item is not a finite number or the list is empty.
    """
    try:
        vals = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise UsageError(f"{name} takes a comma list of numbers, got {text!r}") from None
    if not vals or not all(math.isfinite(v) for v in vals):
        raise UsageError(f"{name} takes a comma list of finite numbers, got {text!r}")
    return vals

"""Running the user's OpenFAST on a deck with a controller library in it.

mpc-wt ships no OpenFAST: :func:`find_openfast` takes the executable from the caller, from
``$MPCWT_OPENFAST``, or from ``PATH``, in that order. :func:`prepare_deck` writes a copy of a
deck's main file and ServoDyn file into a folder of the caller's, with every file they name
made absolute (the other input files stay where they are, read in place) and ServoDyn's
Bladed-interface lines pointed at an exported library (``DLL_FileName``, ``DLL_InFile``,
``DLL_DT``, ``Ptch_Cntrl 1``): the user's deck is never written to. :func:`run_openfast` runs
it and returns the output file, or raises with OpenFAST's own last lines.
"""
from __future__ import annotations

import logging
import math
import os
import re
import shutil
import subprocess
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from mpc_wt.errors import OpenFASTRunError

__all__ = ["OPENFAST_ENV", "find_openfast", "lidar_points", "prepare_deck", "run_openfast",
           "write_lidar_inflow", "write_wind_deck"]

#: the environment variable that names the OpenFAST executable
OPENFAST_ENV = "MPCWT_OPENFAST"

log = logging.getLogger(__name__)

#: a line whose value is a quoted path: ``"path"   KEY  - description``
_PATH_LINE = re.compile(r'^(\s*)"([^"]*)"(\s+)(\S+)(.*)$')
#: the keys of file names in a main, ServoDyn or InflowWind file (a list of StC files
#: included; InflowWind's FileName_BTS, FileName_Uni, FileName_u, ...)
_FILE_KEY = re.compile(r"(File|files|FileName|InFile)(\(\d\)|\d)?$|^FileName_\w+$|^FilenameRoot$")


def find_openfast(path: str | Path | None = None) -> Path:
    """The OpenFAST executable: ``path``, else ``$MPCWT_OPENFAST``, else ``openfast`` on
    ``PATH``.

    Parameters
    ----------
    path : str or Path, optional
        Given by the user (an option).

    Returns
    -------
    Path

    Raises
    ------
    OpenFASTRunError
        None of them is an executable file (naming what was tried and how to give one).
    """
    tried = []
    for src, cand in (("the given path", path), (f"${OPENFAST_ENV}", os.environ.get(OPENFAST_ENV)),
                      ("PATH", shutil.which("openfast"))):
        if not cand:
            tried.append(f"{src}: not set" if src != "PATH" else "PATH: no 'openfast'")
            continue
        p = Path(cand).expanduser()
        if p.is_file() and os.access(p, os.X_OK):
            return p.resolve()
        tried.append(f"{src}: {p} is not an executable file")
    raise OpenFASTRunError("no OpenFAST executable (" + "; ".join(tried) + "); pass its path "
                           f"(--openfast PATH) or set {OPENFAST_ENV}", ran=False)


def _absolute_paths(text: str, base: Path, keep: dict[str, str]) -> str:
    """``text`` with every quoted file name of a file key made absolute against ``base``, and
    the keys in ``keep`` given those values (quoted)."""
    out = []
    for line in text.splitlines():
        m = _PATH_LINE.match(line)
        if m and (m.group(4) in keep or _FILE_KEY.search(m.group(4))):
            lead, value, gap, key, rest = m.groups()
            if key in keep:
                value = keep[key]
            elif value.strip().lower() not in ("", "unused", "none") \
                    and not Path(value).is_absolute():
                value = str((base / value).resolve())
            line = f'{lead}"{value}"{gap}{key}{rest}'
        out.append(line)
    return "\n".join(out) + "\n"


def _set_value(text: str, key: str, value: str) -> str:
    """``text`` with the value of ``key`` (its first word, quoted or not) replaced."""
    pat = re.compile(rf'^(\s*)("[^"]*"|\S+)(\s+{re.escape(key)}(?=\s|$).*)$', re.M)
    new, n = pat.subn(lambda m: f"{m.group(1)}{value}{m.group(3)}", text, count=1)
    if n != 1:
        raise ValueError(f"no line with the key {key!r} in the file")
    return new


def prepare_deck(fst: str | Path, out: str | Path, library: str | Path, input_file: str | Path,
                 dt: float, *, tmax: float | None = None,
                 inflow: str | Path | None = None,
                 values: Mapping[str, Any] | None = None) -> Path:
    """A copy of a deck's main file and ServoDyn file in ``out`` that runs ``library``.

    Parameters
    ----------
    fst : str or Path
        The deck's main (``.fst``) file.
    out : str or Path
        The folder for the copies and OpenFAST's output (created).
    library, input_file : str or Path
        The controller library and its input file.
    dt : float
        The library's interval [s] (``DLL_DT``).
    tmax : float, optional
        ``TMax`` [s] in place of the deck's.
    inflow : str or Path, optional
        An InflowWind file in place of the deck's ``InflowFile`` (e.g. one with a lidar; the
        paths it names are its own folder's).
    values : mapping, optional
        Keys given these values in the copies: ``KEY`` of the main file, ``FILEKEY:KEY`` of
        the file the main file names under ``FILEKEY`` (copied too), e.g. ``{"CompHydro": 0,
        "CompSub": 0, "CompSeaSt": 0, "EDFile:PtfmSgDOF": "False", ...}`` to run an offshore
        deck fixed at its tower base.

    Returns
    -------
    Path
        The copy of the main file (OpenFAST writes ``<its stem>.out``/``.outb`` beside it).
        Where ``dt`` is not a whole multiple of the deck's ``DT`` (ServoDyn refuses that), the
        copy's ``DT`` is the largest step below the deck's that divides it, and a warning says
        so (the IEA-15-240-RWT's 0.005 s against a library's 0.0125 s: 0.0041667 s).

    Raises
    ------
    FileNotFoundError
        The main file, its ServoDyn file, the library or its input file is missing.
    ValueError
        A main file without ``ServoFile`` or a ServoDyn file without the Bladed-interface keys.
    """
    fst = Path(fst).resolve()
    for what, p in (("deck's main file", fst), ("library", Path(library)),
                    ("library's input file", Path(input_file))):
        if not p.is_file():
            raise FileNotFoundError(f"the {what} {p} does not exist")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    main = fst.read_text(errors="replace")
    srv = _named_file(main, fst, "ServoFile")
    srv_copy = out / srv.name
    text = _servodyn_text(srv, library, input_file, dt)
    by_file = _values_by_file(values)
    for key, val in by_file.pop("ServoFile", {}).items():
        text = _set_value(text, key, val)
    srv_copy.write_text(text)
    swap = {"ServoFile": str(srv_copy.resolve()), **_value_copies(main, fst, out, by_file)}
    if inflow is not None:
        if not Path(inflow).is_file():
            raise FileNotFoundError(f"the InflowWind file {inflow} does not exist")
        swap["InflowFile"] = str(Path(inflow).resolve())
    main = _absolute_paths(main, fst.parent, swap)
    if tmax is not None:
        main = _set_value(main, "TMax", f"{float(tmax):.10g}")
    for key, val in by_file.get("", {}).items():
        main = _set_value(main, key, val)
    main = _step_dividing(main, fst, float(dt))
    copy = out / fst.name
    copy.write_text(main)
    for ext in (".out", ".outb"):          # an earlier run's output is not this run's
        copy.with_suffix(ext).unlink(missing_ok=True)
    return copy


def _servodyn_text(srv: Path, library: str | Path, input_file: str | Path, dt: float) -> str:
    """A ServoDyn file's text with its Bladed interface pointed at ``library``."""
    text = _absolute_paths(srv.read_text(errors="replace"), srv.parent,
                           {"DLL_FileName": str(Path(library).resolve()),
                            "DLL_InFile": str(Path(input_file).resolve())})
    text = _set_value(_set_value(text, "DLL_DT", f"{dt:.10g}"), "Ptch_Cntrl", "1")
    for key, val in (("PCMode", "5"), ("VSContrl", "5")):
        text = _set_value(text, key, val)
    return text


def _values_by_file(values: Mapping[str, Any] | None) -> dict[str, dict[str, str]]:
    """``{"KEY": v, "FILEKEY:KEY": w}`` as ``{"": {"KEY": "v"}, "FILEKEY": {"KEY": "w"}}``."""
    by_file: dict[str, dict[str, str]] = {}
    for key, val in (values or {}).items():
        file_key, _, name = str(key).rpartition(":")
        by_file.setdefault(file_key, {})[name] = str(val)
    return by_file


def _value_copies(main: str, fst: Path, out: Path,
                  by_file: dict[str, dict[str, str]]) -> dict[str, str]:
    """Copies in ``out`` of the files the main file names under each ``FILEKEY`` with their
    values set; the main file's keys -> the copies' paths."""
    return {file_key: str(_file_copy(main, fst, out, file_key, vals))
            for file_key, vals in by_file.items() if file_key}


def _file_copy(main: str, fst: Path, out: Path, file_key: str, values: Mapping[str, str],
               keep: dict[str, str] | None = None) -> Path:
    """A copy in ``out`` of the file the main file names under ``file_key``: its file names
    absolute (those in ``keep`` given those values), ``values`` set; its resolved path."""
    src = _named_file(main, fst, file_key)
    text = _absolute_paths(src.read_text(errors="replace"), src.parent, keep or {})
    for key, val in values.items():
        text = _set_value(text, key, val)
    copy = out / src.name
    copy.write_text(text)
    return copy.resolve()


def _step_dividing(main: str, fst: Path, dt: float) -> str:
    """``main`` with ``DT`` made a whole fraction of the library's interval ``dt`` where it is
    not one (the largest such step below the deck's), with a warning."""
    m = re.search(r"^\s*(\S+)\s+DT\s", main, re.M)
    if m is None:
        raise ValueError(f"{fst}: no DT line")
    try:
        step = float(m.group(1))
    except ValueError:
        raise ValueError(f"{fst}: DT = {m.group(1)!r} is not a number") from None
    n = dt / step
    if not step > 0 or abs(n - round(n)) <= 1e-9 * max(1.0, n):
        return main
    new = dt / math.ceil(n - 1e-9)
    log.warning("%s: DT %g s is not a whole fraction of the library's interval %g s (DLL_DT): "
                "the copy runs at DT %.10g s", fst, step, dt, new)
    return _set_value(main, "DT", f"{new:.15g}")


def _named_file(main: str, fst: Path, key: str) -> Path:
    """The file a main file names under ``key``, resolved against its folder."""
    m = re.search(rf'^\s*"([^"]+)"\s+{re.escape(key)}\b', main, re.M)
    if m is None:
        raise ValueError(f"{fst}: no {key} line")
    path = (fst.parent / m.group(1)).resolve()
    if not path.is_file():
        raise FileNotFoundError(f"{fst}: its {key} {path} does not exist")
    return path


def write_wind_deck(fst: str | Path, out: str | Path, bts: str | Path, *,
                    tmax: float | None = None, start: Any = None) -> Path:
    """A copy of a deck that runs in a TurbSim field of the caller's (e.g. one mpc-wt wrote
    with :meth:`lidar.WindField.save`): its main, InflowWind (``WindType 3``,
    ``FileName_BTS``) and ElastoDyn files in ``out``, the rest read in place.

    Parameters
    ----------
    fst : str or Path
        The deck's main file (not written to).
    out : str or Path
        The folder for the copies (created).
    bts : str or Path
        The ``.bts`` field.
    tmax : float, optional
        ``TMax`` [s] in place of the deck's.
    start : linearize.OperatingPoint, optional
        ElastoDyn's initial rotor speed, pitch, tower-top fore-aft and blade-tip out-of-plane
        deflections from this trim (e.g. :func:`linearize.trim` at the field's mean speed), so
        that the run starts where the turbine would be.

    Returns
    -------
    Path
        The copy of the main file.

    Raises
    ------
    FileNotFoundError
        The main file, its InflowWind or ElastoDyn file, or ``bts`` is missing.
    ValueError
        A file without the keys named above.
    """
    fst = Path(fst).resolve()
    if not fst.is_file():
        raise FileNotFoundError(f"the deck's main file {fst} does not exist")
    if not Path(bts).is_file():
        raise FileNotFoundError(f"the wind field {bts} does not exist")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    main = fst.read_text(errors="replace")
    iw = _file_copy(main, fst, out, "InflowFile", {"WindType": "3"},
                    keep={"FileName_BTS": str(Path(bts).resolve())})
    init: dict[str, str] = {}
    if start is not None:
        blades = re.findall(r"\sBlPitch\(\d\)", _named_file(main, fst, "EDFile").read_text(
            errors="replace"))
        init = {"RotSpeed": f"{start.rotor_speed_rad_s * 30.0 / np.pi:.6g}",
                **{b.strip(): f"{np.degrees(start.pitch_rad):.6g}" for b in blades},
                "TTDspFA": f"{float(start.x[0]):.6g}",
                "OoPDefl": f"{float(np.mean(start.x[10:13])):.6g}"}
    ed = _file_copy(main, fst, out, "EDFile", init)
    main = _absolute_paths(main, fst.parent, {"InflowFile": str(iw), "EDFile": str(ed)})
    if tmax is not None:
        main = _set_value(main, "TMax", f"{float(tmax):.10g}")
    copy = out / fst.name
    copy.write_text(main)
    return copy


def _set_values(text: str, key: str, values: str) -> str:
    """``text`` with every value before ``key`` on its line (one or several, comma-separated)
    replaced by ``values``."""
    pat = re.compile(rf'^(\s*)(\S.*?)(\s+{re.escape(key)}\b.*)$', re.M)
    new, n = pat.subn(lambda m: f"{m.group(1)}{values}{m.group(3)}", text, count=1)
    if n != 1:
        raise ValueError(f"no line with the key {key!r} in the file")
    return new


def lidar_points(focus_distance: float, radius: float, n: int = 5) -> np.ndarray:
    """``n`` InflowWind single points on the ring a hub-mounted CW lidar focuses on:
    ``focus_distance`` upwind of the hub, ``radius`` from the shaft, at blade-1-up azimuths 0,
    360 / n, ... deg (OpenFAST's frame: y = -r sin(psi), z = r cos(psi)).

    Parameters
    ----------
    focus_distance, radius : float
        [m], > 0.
    n : int
        Points, 3-5 (InflowWind's ``NumBeam`` at most 5; with 5 the LIDAR kinds' 1P fit is a
        least-squares one and about as good as mpc-wt's CW lidar in OpenFAST's case).

    Returns
    -------
    (n, 3) ndarray
        x, y, z from the hub [m].
    """
    if not (focus_distance > 0 and radius > 0) or not 3 <= int(n) <= 5:
        raise ValueError(f"lidar points need focus_distance > 0 m, radius > 0 m and 3-5 points, "
                         f"got {focus_distance!r}, {radius!r}, {n!r}")
    psi = 2.0 * np.pi * np.arange(int(n)) / int(n)
    return np.stack([np.full(int(n), -float(focus_distance)), -radius * np.sin(psi),
                     radius * np.cos(psi)], axis=1)


def write_lidar_inflow(inflow: str | Path, out: str | Path, points: Any,
                       interval: float) -> Path:
    """A copy of an InflowWind file (v4 or v5 layout, with its LIDAR section) whose lidar is
    single points (``SensorType 1``) at ``points`` measured every ``interval``, the files it
    names made absolute: the lidar an exported LIDAR kind reads in OpenFAST.

    Parameters
    ----------
    inflow : str or Path
        The deck's InflowWind file (not written to).
    out : str or Path
        The copy's path.
    points : (n, 3) array_like
        x, y, z from the hub [m], 1-5 points upwind (:func:`lidar_points`).
    interval : float
        ``MeasurementInterval`` [s] (the library's ``DLL_DT``).

    Returns
    -------
    Path

    Raises
    ------
    FileNotFoundError
        No such InflowWind file.
    ValueError
        A file without the LIDAR section's keys, or points InflowWind refuses.
    """
    import lidar as _lidar

    inflow = Path(inflow)
    if not inflow.is_file():
        raise FileNotFoundError(f"the InflowWind file {inflow} does not exist")
    pts = _lidar.PointLidar(points, float(interval)).points      # checked as InflowWind would
    text = _absolute_paths(inflow.read_text(errors="replace"), inflow.parent.resolve(), {})
    fmt = lambda col: ", ".join(f"{v:.4f}" for v in pts[:, col])  # noqa: E731
    try:
        for key, val in (("SensorType", "1"), ("NumPulseGate", "1"),
                         ("NumBeam", str(pts.shape[0])), ("FocalDistanceX", fmt(0)),
                         ("FocalDistanceY", fmt(1)), ("FocalDistanceZ", fmt(2)),
                         ("RotorApexOffsetPos", "0, 0, 0"),
                         ("MeasurementInterval", f"{float(interval):.10g}"),
                         ("LidRadialVel", "False"), ("ConsiderHubMotion", "1")):
            text = _set_values(text, key, val)
    except ValueError as err:
        raise ValueError(f"{inflow}: {err} (an InflowWind file with its LIDAR section, "
                         f"OpenFAST v3 on)") from None
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(text)
    return out


def run_openfast(exe: str | Path, fst: str | Path, *, timeout: float = 3600.0,
                 progress: Any = None) -> Path:
    """Run OpenFAST on a main file and return its output file.

    Parameters
    ----------
    exe : str or Path
        The executable (:func:`find_openfast`).
    fst : str or Path
        The main file (:func:`prepare_deck`'s copy); OpenFAST runs in its folder.
    timeout : float
        Longest run [s].
    progress : callable, optional
        Called with each simulated time OpenFAST reports [s].

    Returns
    -------
    Path
        ``<stem>.outb``, else ``<stem>.out``, beside ``fst``.

    Raises
    ------
    OpenFASTRunError
        It did not finish, timed out or wrote no output; the message holds its last lines.
    """
    fst = Path(fst).resolve()
    log = fst.with_suffix(".log")
    try:
        with log.open("w") as fh:
            proc = subprocess.Popen([str(exe), str(fst)], cwd=fst.parent, stdout=subprocess.PIPE,
                                    stderr=subprocess.STDOUT, text=True, bufsize=1)
            assert proc.stdout is not None
            for line in proc.stdout:
                fh.write(line)
                m = re.search(r"Time:\s*([0-9.eE+-]+)\s+of", line)
                if m and progress is not None:
                    progress(float(m.group(1)))
            code = proc.wait(timeout=timeout)
    except (OSError, subprocess.TimeoutExpired) as err:
        raise OpenFASTRunError(f"OpenFAST ({exe}) on {fst}: {err}") from err
    tail = "\n".join(log.read_text(errors="replace").strip().splitlines()[-12:])
    if code != 0:
        raise OpenFASTRunError(f"OpenFAST ({exe}) on {fst} stopped (exit {code}); its last "
                               f"lines (all in {log}):\n{tail}")
    for ext in (".outb", ".out"):
        if fst.with_suffix(ext).is_file():
            return fst.with_suffix(ext)
    raise OpenFASTRunError(f"OpenFAST ({exe}) on {fst} finished but wrote no output file; its "
                           f"last lines (all in {log}):\n{tail}")

"""Gain tables: one document per designed controller, exported to CSV, JSON, MATLAB and ROSCO.

The format only: each kind's module makes its own table (``baseline_table`` in
:mod:`mpc_wt.kinds.baseline`, ``lqr_table`` in :mod:`mpc_wt.kinds.lqr`, ...) with
:func:`document`. A gain table is a JSON-able dict (``design.json`` in a design directory):

    {"schema": "mpc-wt gain table", "schema_version": 1,
     "kind": "baseline" | "lqr" | "ts" | "ibc" | "coleman-ipc" | ...,
     "turbine": ..., "software": {"mpc_wt": version}, "settings": {...},
     "schedule": {"columns": [...], "units": [...], "rows": [[...], ...]},
     "matrices": {name: {"unit": ..., "rows": [...], "cols": [...], "data": [[[...]]] }},
     "plot": {...}}   (optional: how the design's plot draws it)

``schedule`` has one row per operating point (wind speed for the LQR family, premise vertex
for TS with its membership breakpoints ``wind_grid`` / ``reduction_grid`` in ``settings``,
pitch angle for the PI baseline, the individual blade control and the Coleman IPC);
``matrices`` stacks gain matrices over those points with row/column names and one unit string
per matrix.

Formats (:func:`export`):

* ``json``: the document itself (``gains.json``);
* ``csv``: ``gains_schedule.csv`` (wide: one row per point, headers ``name [unit]``) and
  ``gains_matrices.csv`` (long: matrix, point, row, col, value, unit); a first ``#`` line gives
  schema and kind (``pandas.read_csv(..., comment="#")``);
* ``mat``: ``gains.mat`` (scipy.io.savemat) with the schedule columns as vectors and every
  matrix as an (n_points, n_rows, n_cols) array, names and units as cell strings;
* ``rosco``: a complete ROSCO 2.10 ``DISCON.IN`` (every parameter; the design's PI schedule,
  torque law, limits, filters and IPC, ROSCO's defaults elsewhere) and its ``Cp_Ct_Cq`` table
  (PC_GS_n/angles/KP/KI/KD/TF, PC_RefSpd, PC_MaxPit/MinPit/MaxRat/MinRat, VS_Rgn2K, VS_RtTq,
  VS_RefSpd, VS_RtPwr, VS_MaxTq, VS_MinTq, VS_MaxRat, VS_MinOMSpd); ROSCO's pitch gains act on
  the speed error (reference minus measured), so they carry the opposite sign of ours.
"""
from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Any, Sequence

import numpy as np

import linearize
from mpc_wt._version import __version__
from mpc_wt.errors import GainTableError
from mpc_wt.io.json_text import write_json

__all__ = ["SCHEMA_VERSION", "GainTableError", "document", "matrix", "unit_ratio",
           "design_turbine", "save_design", "load_design", "export", "read_rosco", "FORMATS"]

SCHEMA_VERSION = 1
SCHEMA = "mpc-wt gain table"
FORMATS = ("csv", "json", "mat", "rosco", "discon")


def unit_ratio(num: str, den: str) -> str:
    """The unit of a gain from its numerator's and denominator's units.

    Parameters
    ----------
    num, den : str
        The units ("-" or "" for none).

    Returns
    -------
    str
        ``num/den``, parenthesised where ``den`` is compound; "-" where they are equal.
    """
    if den in ("-", ""):
        return num
    if num == den:
        return "-"
    return f"{num}/({den})" if " " in den or "/" in den else f"{num}/{den}"


def document(kind: str, turbine: linearize.Turbine, settings: dict[str, Any],
             columns: list[str], units: list[str], rows: list[list[float]],
             matrices: dict[str, dict[str, Any]],
             plot: dict[str, Any] | None = None) -> dict[str, Any]:
    """A gain-table document: what a kind's table function returns.

    Parameters
    ----------
    kind : str
        The controller kind.
    turbine : Turbine
        The turbine designed for (its name is recorded).
    settings : dict
        The design's settings (JSON-able).
    columns, units : list of str
        The schedule's column names and units.
    rows : list of list of float
        The schedule, one row per operating point.
    matrices : dict
        Name -> :func:`matrix`.
    plot : dict, optional
        How :func:`mpc_wt.plotting.plot_design` draws it: ``{"columns": [...], "label": ...}``
        plots those schedule columns (times ``scale``, default 1) against wind speed;
        otherwise the largest gains of the matrix ``K`` normalised, against wind speed or, with
        ``{"x": "vertex"}``, the row index; ``title`` names what is drawn (default "KIND
        gains").

    Returns
    -------
    dict
        The document (schema "mpc-wt gain table").
    """
    doc = {"schema": SCHEMA, "schema_version": SCHEMA_VERSION, "kind": kind,
           "turbine": turbine.name, "software": {"mpc_wt": __version__},
           "settings": settings,
           "schedule": {"columns": columns, "units": units,
                        "rows": [[float(v) for v in r] for r in rows]},
           "matrices": matrices}
    if plot is not None:
        doc["plot"] = dict(plot)
    return doc


def matrix(stack: np.ndarray, rows: Sequence[str], cols: Sequence[str], unit: str,
           units: Sequence[str] | None = None) -> dict[str, Any]:
    """A stack of gain matrices over the schedule's points, as a document's matrix entry.

    Parameters
    ----------
    stack : array_like, shape (n_points, n_rows, n_cols)
        The matrices.
    rows, cols : sequence of str
        Row and column names.
    unit : str
        The matrix's unit (one string).
    units : sequence of str, optional
        One unit per entry, row-major.

    Returns
    -------
    dict
        ``unit``, ``rows``, ``cols``, ``data`` (and ``units``).
    """
    d = {"unit": unit, "rows": list(rows), "cols": list(cols),
         "data": np.asarray(stack, dtype=float).tolist()}
    if units is not None:
        d["units"] = list(units)
    return d


def _check(doc: Any, where: str) -> dict[str, Any]:
    if not isinstance(doc, dict) or doc.get("schema") != SCHEMA:
        raise GainTableError(f"{where} is not an mpc-wt gain table (no schema {SCHEMA!r})")
    if doc.get("schema_version") != SCHEMA_VERSION:
        raise GainTableError(f"{where} has schema_version {doc.get('schema_version')!r}; this "
                             f"mpc-wt reads version {SCHEMA_VERSION}")
    missing = [k for k in ("kind", "schedule", "matrices", "settings") if k not in doc]
    if missing:
        raise GainTableError(f"{where} misses the keys {missing}")
    s = doc["schedule"]
    if not all(len(r) == len(s["columns"]) for r in s["rows"]) or \
            len(s["units"]) != len(s["columns"]):
        raise GainTableError(f"{where}: schedule rows, columns and units differ in length")
    return doc






def save_design(doc: dict[str, Any], out_dir: str | Path) -> Path:
    """Write ``design.json`` into ``out_dir`` (created).

    Parameters
    ----------
    doc : dict
        A gain-table document.
    out_dir : str or Path
        The design directory.

    Returns
    -------
    Path
        The file written.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    p = out / "design.json"
    write_json(p, _check(doc, "the design"))
    return p


def load_design(path: str | Path) -> dict[str, Any]:
    """Read a design directory's ``design.json`` (or a gain-table JSON file).


    Parameters
    ----------
    path : str or Path
        A design directory or a JSON file.

    Returns
    -------
    dict
        The checked document.

    Raises
    ------
    GainTableError
        Missing, not JSON, another schema or version, inconsistent lengths.
    """
    p = Path(path)
    if p.is_dir():
        p = p / "design.json"
    if not p.exists():
        raise GainTableError(f"{p} does not exist (run `mpcwt design ... --out DIR` first)")
    try:
        doc = json.loads(p.read_text())
    except json.JSONDecodeError as err:
        raise GainTableError(f"{p} is not valid JSON: {err}") from err
    return _check(doc, str(p))


def _write_csv(doc: dict[str, Any], out: Path) -> list[Path]:
    s = doc["schedule"]
    head = f"# {SCHEMA}, schema_version {SCHEMA_VERSION}, kind {doc['kind']}, " \
           f"turbine {doc['turbine']}"
    p1 = out / "gains_schedule.csv"
    with p1.open("w", newline="") as fh:
        fh.write(head + "\n")
        w = csv.writer(fh)
        w.writerow([f"{c} [{u}]" for c, u in zip(s["columns"], s["units"])])
        w.writerows([[repr(float(v)) for v in r] for r in s["rows"]])
    p2 = out / "gains_matrices.csv"
    with p2.open("w", newline="") as fh:
        fh.write(head + "\n")
        w = csv.writer(fh)
        w.writerow(["matrix", "point", "row", "col", "value", "unit"])
        for name, m in doc["matrices"].items():
            data = np.asarray(m["data"], dtype=float)
            ncol = len(m["cols"])
            for k in range(data.shape[0]):
                for i, rn in enumerate(m["rows"]):
                    for j, cn in enumerate(m["cols"]):
                        unit = m["units"][i * ncol + j] if "units" in m else m["unit"]
                        w.writerow([name, k, rn, cn, repr(float(data[k, i, j])), unit])
    return [p1, p2]


def _write_mat(doc: dict[str, Any], out: Path) -> list[Path]:
    import scipy.io

    s = doc["schedule"]
    rows = np.asarray(s["rows"], dtype=float).reshape(-1, len(s["columns"]))
    d: dict[str, Any] = {"schema_version": SCHEMA_VERSION, "kind": doc["kind"],
                         "turbine": doc["turbine"],
                         "schedule_columns": np.array(s["columns"], dtype=object),
                         "schedule_units": np.array(s["units"], dtype=object),
                         "schedule": rows}
    for c, col in zip(s["columns"], rows.T):
        d[f"s_{c}"[:63]] = col
    for name, m in doc["matrices"].items():
        d[name] = np.asarray(m["data"], dtype=float)
        d[f"{name}_rows"] = np.array(m["rows"], dtype=object)
        d[f"{name}_cols"] = np.array(m["cols"], dtype=object)
        d[f"{name}_unit"] = m["unit"]
    p = out / "gains.mat"
    scipy.io.savemat(p, d, long_field_names=True, do_compression=True)
    return [p]


def design_turbine(doc: dict[str, Any], turbine: linearize.Turbine | None = None
                   ) -> linearize.Turbine:
    """The turbine of a design document: ``turbine`` when given, else the packaged turbine of
    the document's turbine name.

    Parameters
    ----------
    doc : dict
        A gain-table document.
    turbine : Turbine, optional
        The design's turbine, when it is not a packaged one.

    Returns
    -------
    Turbine

    Raises
    ------
    GainTableError
        No packaged turbine has that name and none was given.
    """
    if turbine is not None:
        return turbine
    for name in linearize.available_turbines():
        t = linearize.load_turbine(name)
        if t.name == doc["turbine"]:
            return t
    raise GainTableError(f"the design's turbine {doc['turbine']!r} is not a packaged one "
                         f"{linearize.available_turbines()}: give its turbine (export(..., "
                         f"turbine=...), mpcwt export --turbine PATH) for the rosco and discon "
                         f"formats")


def _write_rosco(doc: dict[str, Any], out: Path,
                 turbine: linearize.Turbine | None = None) -> list[Path]:
    from mpc_wt.io.rosco import write_rosco_discon

    if doc["kind"] not in ("baseline", "coleman-ipc"):
        raise GainTableError(f"the rosco format holds a PI pitch schedule, torque set points and "
                             f"Coleman IPC; a {doc['kind']!r} design has none: export a baseline "
                             f"(`mpcwt design baseline`), derated or not, or a coleman-ipc design "
                             f"for ROSCO, or use csv/json/mat")
    t = design_turbine(doc, turbine)
    if doc["kind"] == "coleman-ipc":
        base = doc["settings"].get("baseline")
        if base is None:
            raise GainTableError("this coleman-ipc design holds no baseline gain table for "
                                 "ROSCO's pitch schedule (saved by an older mpc-wt): design it "
                                 "again with `mpcwt design coleman-ipc --out DIR`")
        return write_rosco_discon(t, _check(base, "its baseline"), out, ipc=doc)
    return write_rosco_discon(t, doc, out)


def _write_discon(doc: dict[str, Any], out: Path,
                  turbine: linearize.Turbine | None = None) -> list[Path]:
    raise GainTableError(f"a {doc['kind']!r} design exports as a controller library through its "
                         f"kind's export: mpc_wt.run.export_saved_design (mpcwt export "
                         f"--format discon)")


def read_rosco(path: str | Path) -> dict[str, Any]:
    """Parse ``NAME`` values from DISCON.IN-style lines (``values ! NAME - text``): a float,
    or a list of floats when the line holds several. Lines without ``!`` are skipped.

    Parameters
    ----------
    path : str or Path
        A DISCON.IN-style file.

    Returns
    -------
    dict
        Name -> float or list of floats.
    """
    out: dict[str, Any] = {}
    for line in Path(path).read_text().splitlines():
        if "!" not in line or line.lstrip().startswith("!"):
            continue
        vals, comment = line.split("!", 1)
        name = comment.split()[0] if comment.split() else ""
        try:
            nums = [float(v) for v in vals.split()]
        except ValueError:
            continue
        if name and nums:
            out[name] = nums if len(nums) > 1 or name in ("PC_GS_angles", "PC_GS_KP",
                                                          "PC_GS_KI", "PC_GS_KD",
                                                          "PC_GS_TF") else nums[0]
    return out


def export(doc_or_dir: dict[str, Any] | str | Path, fmt: str,
           out_dir: str | Path | None = None,
           turbine: linearize.Turbine | None = None) -> list[Path]:
    """Export a gain table (a document, or a design directory) to ``fmt`` in ``out_dir``
    (default the design directory). Returns the files written.


    Parameters
    ----------
    doc_or_dir : dict or str or Path
        A gain-table document or a design directory.
    fmt : {"csv", "json", "mat", "rosco", "discon"}
        The format (``discon``, a Bladed-style controller library, is written by the design's
        kind: :func:`mpc_wt.run.export_saved_design`; here it raises GainTableError).
    out_dir : str or Path, optional
        Where to write (default the design directory).
    turbine : Turbine, optional
        For ``rosco`` and ``discon``: the design's turbine (default: the packaged turbine of
        that name).

    Returns
    -------
    list of Path
        The files written (``rosco``: a complete ROSCO 2.10 ``DISCON.IN`` and its
        ``Cp_Ct_Cq`` table, :mod:`mpc_wt.io.rosco`).

    Raises
    ------
    ValueError
        An unknown format.
    GainTableError
        A broken table, or ``rosco`` for a design that is not the PI baseline.
    """
    if fmt not in FORMATS:
        raise ValueError(f"format must be one of {list(FORMATS)}, got {fmt!r}")
    if isinstance(doc_or_dir, dict):
        doc = _check(doc_or_dir, "the design")
        if out_dir is None:
            raise ValueError("out_dir is needed when exporting a document")
    else:
        doc = load_design(doc_or_dir)
        if out_dir is None:
            p = Path(doc_or_dir)
            out_dir = p if p.is_dir() else p.parent
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    if fmt == "json":
        p = out / "gains.json"
        write_json(p, doc)
        return [p]
    if fmt == "csv":
        return _write_csv(doc, out)
    if fmt == "mat":
        return _write_mat(doc, out)
    if fmt == "discon":
        return _write_discon(doc, out, turbine)
    return _write_rosco(doc, out, turbine)

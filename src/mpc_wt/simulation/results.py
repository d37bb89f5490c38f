"""Results of closed-loop runs and their files: :class:`ClosedLoopResult` (netCDF, written and
read by mpc-wt, openable without it) and :func:`load_series`, which reads a run -- ours, or
any CSV with a time column -- as time and named channels for assessment."""
from __future__ import annotations

import contextlib
import csv
import io
import json
import os
import uuid
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

import linearize
from linearize.openfast_channels import blade_frame_moment
from mpc_wt._version import __version__
from mpc_wt.errors import ResultFileError

__all__ = ["ClosedLoopResult", "load_series", "shaft_bending_resultant", "SCHEMA_VERSION"]

SCHEMA_VERSION = 1
_Z = {n: i for i, n in enumerate(linearize.OUTPUT_NAMES)}


def _in_process() -> Any:
    """Writing in this process whatever Dask's global scheduler says: xarray asks Dask for its
    scheduler even for NumPy data, and a ``distributed.Client`` that failed to connect leaves
    the config naming the distributed scheduler with no client, which made every later write
    in the process fail."""
    try:
        import dask
    except ImportError:                   # pragma: no cover - dask is a dependency
        return contextlib.nullcontext()
    return dask.config.set(scheduler="sync")


#: the blade-frame root moments :meth:`ClosedLoopResult.channel` derives
_BLADE_FRAME = tuple(f"{k}_moment_{b}" for k in ("flapwise", "edgewise") for b in (1, 2, 3))
#: the shaft's derived channels and their units
DERIVED_UNITS = {"shaft_bending_blade1": "N m", "shaft_bending_resultant": "N m"}


def shaft_bending_resultant(m1: Any, m2: Any, m3: Any) -> np.ndarray:
    """The magnitude of the low-speed shaft's bending moment from the three blades' flap
    moments [N m]: abs(sum_k M_k exp(i psi_k)) with the blades 120 deg apart,
    sqrt(M1^2 + M2^2 + M3^2 - M1 M2 - M2 M3 - M3 M1).

    The bending toward blade 1, M1 - (M2 + M3) / 2, is this vector's projection on blade 1's
    azimuth, so it never exceeds the resultant and reaches it only when the vector points at
    blade 1. A shaft's section sees the resultant at some fiber at every instant: its extreme
    design load is the resultant's, independent of where blade 1 happens to be when a gust
    peaks (the fatigue of one fiber is read on the rotating channel).

    Parameters
    ----------
    m1, m2, m3 : array_like
        Flap (out-of-plane) root moments of blades 1-3 [N m].

    Returns
    -------
    ndarray
        [N m], >= 0.
    """
    a, b, c = (np.asarray(m, dtype=float) for m in (m1, m2, m3))
    # the sum of squares of differences is the form that cannot go negative by rounding
    return np.sqrt(0.5 * ((a - b) ** 2 + (b - c) ** 2 + (c - a) ** 2))


@dataclass(frozen=True)
class ClosedLoopResult:
    """Everything a closed-loop run produced.

    Parameters
    ----------
    t : (n_t,) ndarray
        [s]
    x : (n_t, n_x) ndarray
        Plant states (:data:`linearize.STATE_NAMES`).
    u : (n_t, n_u) ndarray
        Applied inputs (after the plant's torque rate limit).
    z : (n_t, n_z) ndarray
        Plant outputs (:data:`linearize.OUTPUT_NAMES`).
    controller : dict of str to (n_t,) ndarray
        The controller's internal signals.
    meta : dict
        Configuration and software version.
    """

    t: np.ndarray
    x: np.ndarray
    u: np.ndarray
    z: np.ndarray
    controller: dict[str, np.ndarray] = field(default_factory=dict)
    meta: dict[str, Any] = field(default_factory=dict)

    def channel(self, name: str) -> np.ndarray:
        """A time series by name: output, state, input, controller signal, or a derived one:
        ``shaft_bending_blade1``, the rotating low-speed-shaft bending moment in the direction
        of blade 1 from the blades' flap moments, M_1 - (M_2 + M_3) / 2 [N m] (rotor weight
        and hub inertia left out); ``shaft_bending_resultant``, the magnitude of that bending
        moment's vector, the largest over the shaft section's circumference [N m]
        (:func:`shaft_bending_resultant`: what a shaft's extreme design load is read on,
        whatever the azimuth); ``flapwise_moment_i`` and ``edgewise_moment_i``, blade i's
        root moments in the frame that pitches with it (OpenFAST's ``RootMyb``, ``RootMxb``;
        :func:`blade_frame_moment`).

        Parameters
        ----------
        name : str
            A name of :meth:`channels`.

        Returns
        -------
        (n_t,) ndarray
            The series (SI units of the name's table).

        Raises
        ------
        KeyError
            Naming the channel and listing the channels.
        """
        if name in ("shaft_bending_blade1", "shaft_bending_resultant"):
            f = self.z[:, _Z["flap_moment_1"]:_Z["flap_moment_3"] + 1]
            if name == "shaft_bending_resultant":
                return shaft_bending_resultant(f[:, 0], f[:, 1], f[:, 2])
            return f[:, 0] - 0.5 * (f[:, 1] + f[:, 2])
        if name in _BLADE_FRAME:
            return blade_frame_moment(name, self.z[:, _Z[f"pitch_{name[-1]}"]],
                                      self.z[:, _Z[f"flap_moment_{name[-1]}"]],
                                      self.z[:, _Z[f"edge_moment_{name[-1]}"]])
        if name in _Z:
            return self.z[:, _Z[name]]
        if name in linearize.STATE_NAMES:
            return self.x[:, linearize.STATE_NAMES.index(name)]
        if name in linearize.INPUT_NAMES:
            return self.u[:, linearize.INPUT_NAMES.index(name)]
        if name in self.controller:
            return self.controller[name]
        raise KeyError(f"no channel {name!r}; channels are {self.channels()}")

    def channels(self) -> list[str]:
        """All channel names.

        Returns
        -------
        list of str
            Outputs, states, inputs, derived channels and controller signals.
        """
        return (list(linearize.OUTPUT_NAMES) + [n for n in linearize.STATE_NAMES
                                                if n not in _Z]
                + list(linearize.INPUT_NAMES) + list(DERIVED_UNITS) + list(_BLADE_FRAME)
                + list(self.controller))

    def save(self, path: str | Path) -> Path:
        """Write a self-describing netCDF file (xarray; openable without mpc-wt) with units,
        the configuration and the software version; written to a temporary file, then renamed.

        Parameters
        ----------
        path : str or Path
            The netCDF file.

        Returns
        -------
        Path
            ``path``.
        """
        import xarray as xr

        path = Path(path)
        data = {}
        units = dict(zip(linearize.OUTPUT_NAMES, linearize.OUTPUT_UNITS))
        units.update(zip(linearize.STATE_NAMES, linearize.STATE_UNITS))
        units.update(zip(linearize.INPUT_NAMES, linearize.INPUT_UNITS))
        units.update(DERIVED_UNITS)
        units.update({n: "N m" for n in _BLADE_FRAME})
        for n in self.channels():
            key = n if n not in data else f"{n}_state"
            data[key] = xr.Variable("time", self.channel(n),
                                    {"units": units.get(n, ""),
                                     "source": "controller" if n in self.controller else "plant"})
        ds = xr.Dataset(data, coords={"time": ("time", self.t, {"units": "s"})},
                        attrs={"schema_version": SCHEMA_VERSION, "software": "mpc-wt",
                               "software_version": __version__,
                               "meta_json": json.dumps(self.meta)})
        # a name of this writer's own: two writers of one case (a retried task) never share it
        tmp = path.with_name(f".{path.name}.{os.getpid()}.{uuid.uuid4().hex[:8]}.tmp")
        try:
            with _in_process():
                ds.to_netcdf(tmp, engine="scipy")
            tmp.replace(path)
        finally:
            tmp.unlink(missing_ok=True)
        return path

    @staticmethod
    def read_meta(path: str | Path) -> dict[str, Any] | None:
        """The metadata of a result written by :meth:`save`, from the file's header alone (a
        few ms where :meth:`load` reads every channel).

        Returns
        -------
        dict or None
            The ``meta`` :meth:`load` would give; None for a file that cannot be read or
            holds none.
        """
        from scipy.io import netcdf_file

        try:
            f = netcdf_file(path, "r", mmap=True)
            try:
                raw = getattr(f, "meta_json", None)
            finally:
                f.close()
            meta = None if raw is None else json.loads(
                raw.decode() if isinstance(raw, bytes) else raw)
        except (OSError, ValueError, TypeError):
            return None
        return meta if isinstance(meta, dict) else None

    @classmethod
    def load(cls, path: str | Path) -> "ClosedLoopResult":
        """Read a result written by :meth:`save`.

        Raises
        ------
        ResultFileError
            If the file is missing, truncated, of another schema or misses plant channels.
        """
        import xarray as xr

        path = Path(path)
        if not path.is_file():
            raise ResultFileError(f"{path}: file not found")
        with path.open("rb") as fh:
            magic = fh.read(4)
        if magic[:3] != b"CDF" or magic[3:] not in (b"\x01", b"\x02"):
            raise ResultFileError(f"{path}: not an mpc-wt result file: it does not begin as a "
                                  f"netCDF-3 file does (its first bytes {magic!r}; mpc-wt "
                                  f"writes netCDF-3)")
        try:
            with xr.open_dataset(path, engine="scipy") as ds:
                ds = ds.load()
        except Exception as err:  # noqa: BLE001 - any reader failure means a broken file
            first = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
            raise ResultFileError(f"{path}: not a readable result file ({first})") from err
        ver = ds.attrs.get("schema_version")
        if isinstance(ver, (np.integer, int)):
            ver = int(ver)
        if ver != SCHEMA_VERSION:
            raise ResultFileError(f"{path}: schema_version must be {SCHEMA_VERSION}, got {ver!r} "
                                  f"(written by {ds.attrs.get('software_version', '?')})")
        missing = [n for n in linearize.OUTPUT_NAMES if n not in ds]
        if missing:
            raise ResultFileError(f"{path}: missing channels {missing}")
        z = np.column_stack([ds[n].values for n in linearize.OUTPUT_NAMES])
        x = np.column_stack([ds[n if n not in _Z else n].values for n in linearize.STATE_NAMES])
        u = np.column_stack([ds[n].values for n in linearize.INPUT_NAMES])
        ctrl = {n: ds[n].values for n in ds.data_vars
                if ds[n].attrs.get("source") == "controller"}
        return cls(t=ds["time"].values, x=x, u=u, z=z, controller=ctrl,
                   meta=json.loads(ds.attrs.get("meta_json", "{}")))


def load_series(path: str | Path, time_column: str = "time") -> tuple[np.ndarray,
                                                                       dict[str, np.ndarray]]:
    """Time and channels of a run: ours (netCDF), an OpenFAST output (``.out``, ``.outb``) or a
    CSV with a time column.

    OpenFAST channels (also as CSV headers, ``RootMyb1``, ``RootMyb1_[kN-m]`` or ``RootMyb1
    (kN-m)``; a bare name is taken in OpenFAST's unit) are mapped to ours in SI by
    :data:`mpc_wt.io.openfast_output.CHANNEL_MAP`; the notes on unmapped channels are logged.

    Parameters
    ----------
    path : str or Path
        A result file (.nc), an OpenFAST output (.out, .outb) or a CSV with a header row.
    time_column : str
        The CSV's time column (``Time`` is also taken when ``time`` is absent).

    Returns
    -------
    t : (n_t,) ndarray
        Time [s].
    cols : dict of str to (n_t,) ndarray
        The other columns by name.

    Raises
    ------
    ResultFileError
        If the file cannot be read, has no time column, non-numeric cells, an OpenFAST channel
        with a unit it cannot have, or a suffix other than .nc, .out, .outb, .csv; if its time
        is not uniform and increasing (:func:`check_time`) or a channel is not finite (the
        message names the file, the channel and the time).
    """
    from mpc_wt.assessment.series import check_time

    path = Path(path)
    t, cols = _load_any(path, time_column)
    try:
        check_time(t)
    except ValueError as err:
        raise ResultFileError(f"{path}: {err}") from None
    for name, x in cols.items():
        x = np.asarray(x)
        if x.shape != t.shape:
            raise ResultFileError(f"{path}: channel {name!r} has {x.size} samples, the time "
                                  f"{t.size}")
        bad = ~np.isfinite(x)
        if bad.any():
            i = int(np.argmax(bad))
            raise ResultFileError(f"{path}: channel {name!r} is {float(x[i])!r} at t = "
                                  f"{t[i]:g} s (sample {i}); a run's channels must be finite")
    return t, cols


def _load_any(path: Path, time_column: str) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    import logging

    from mpc_wt.io.openfast_output import read_openfast_output, to_mpcwt_channels

    log = logging.getLogger("mpc_wt.simulation.results")
    suffix = path.suffix.lower()
    if suffix in (".out", ".outb"):
        series = read_openfast_output(path)
        cols, notes = to_mpcwt_channels(series, str(path))
        for n in notes:
            log.info("%s: %s", path, n)
        return series.t, cols
    if suffix == ".csv":
        return _load_csv(path, time_column, log)
    if suffix != ".nc":
        raise ResultFileError(f"{path}: suffix {path.suffix!r} is not a run file mpc-wt reads; "
                              f"allowed .nc (ours), .out / .outb (OpenFAST), .csv")
    res = ClosedLoopResult.load(path)
    return res.t, {n: res.channel(n) for n in res.channels()}


#: A CSV time column's unit, from its header (``time [ms]``), in seconds.
TIME_UNITS = {"s": 1.0, "sec": 1.0, "ms": 1e-3, "min": 60.0}


def _seconds(path: Path, header: str, unit: str | None, t: np.ndarray) -> np.ndarray:
    """A CSV's time column in seconds: by the unit its header gives; without one, a median
    step above 1 s is refused (a run in ms would have its energy 1000x)."""
    if unit is not None:
        if unit not in TIME_UNITS:
            raise ResultFileError(f"{path}: time column {header!r}: unit {unit!r}; allowed "
                                  f"{sorted(TIME_UNITS)}")
        return t * TIME_UNITS[unit]
    step = float(np.median(np.diff(t))) if t.size > 1 else 0.0
    if step > 1.0:
        raise ResultFileError(f"{path}: time column {header!r} steps by {step:g} per sample, "
                              f"more than 1 s: if it is in ms, say so in its header "
                              f"('{header} [ms]'); a run's time is in s")
    return t


def _load_csv(path: Path, time_column: str, log: Any) -> tuple[np.ndarray,
                                                               dict[str, np.ndarray]]:
    """A CSV run; columns with OpenFAST channel names are mapped to ours in SI."""
    from mpc_wt.io.openfast_output import (
        CHANNEL_MAP,
        DEFAULT_UNITS,
        OpenFASTSeries,
        check_line_end,
        split_csv_header,
        to_mpcwt_channels,
    )

    if not path.is_file():
        raise ResultFileError(f"{path}: file not found")
    text = path.read_text(errors="replace")
    check_line_end(path, text, sep=",")
    rows = list(csv.reader(io.StringIO(text, newline="")))
    if not rows:
        raise ResultFileError(f"{path}: empty file")
    head = [h.strip() for h in rows[0]]
    twice = sorted({h for h in head if head.count(h) > 1})
    if twice:
        raise ResultFileError(f"{path}: the columns {twice} appear more than once; a column's "
                              f"name must say which signal it holds")
    split = [split_csv_header(h) for h in head]
    bare = [n for n, _ in split]
    if time_column not in head and time_column in ("time", "Time") and \
            ("Time" in bare or "time" in bare):
        time_column = head[bare.index("Time" if "Time" in bare else "time")]
    if time_column not in head:
        raise ResultFileError(f"{path}: no time column {time_column!r}; columns {head}")
    try:
        data = np.array([[float(c) for c in r] for r in rows[1:] if r], dtype=float)
    except ValueError as err:
        raise ResultFileError(f"{path}: non-numeric cell ({err})") from err
    if data.ndim != 2 or data.shape[1] != len(head):
        raise ResultFileError(f"{path}: ragged rows")
    it = head.index(time_column)
    data[:, it] = _seconds(path, head[it], split[it][1], data[:, it])
    if any(n in CHANNEL_MAP for n in bare):
        names = tuple(n for k, n in enumerate(bare) if k != it)
        units = tuple((u if u is not None else DEFAULT_UNITS.get(n, "-"))
                      for k, (n, u) in enumerate(split) if k != it)
        series = OpenFASTSeries(t=data[:, it], names=names, units=units,
                                data=np.delete(data, it, axis=1))
        cols, notes = to_mpcwt_channels(series, str(path))
        for n in notes:
            log.info("%s: %s", path, n)
        return series.t, cols
    cols = {h: data[:, i] for i, h in enumerate(head)}
    return cols.pop(time_column), cols

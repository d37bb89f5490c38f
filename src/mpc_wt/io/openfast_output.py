"""OpenFAST time-series outputs: text ``.out``, binary ``.outb`` and CSV with OpenFAST channel
names, read as time and channels under mpc-wt's names in SI, and written back.

OpenFAST's binary layout (``FileFmtID`` 1-4: compressed with a packed time channel, compressed
with a first time and a step, uncompressed float64, compressed with the channel-name length
given) is read with ``numpy.frombuffer`` in one pass; openfast-io's reader does the same job
value by value through ``struct`` and needs pandas installed, so we read it ourselves and the
tests check the two against each other.

Channel map (OpenFAST -> ours): :data:`linearize.openfast_channels.CHANNEL_MAP`, shared with the
``.lin`` reader; where several channels of a file map to one of ours the earlier entry of the
map wins (``RtAeroFxh`` over ``RotThrust``); the blade root moments keep their frames
(``RootMyc1`` -> ``flap_moment_1``, out of plane; ``RootMyb1`` -> ``flapwise_moment_1``, pitching
with the blade). A mapped channel whose unit is not one
the map expects is an error naming channel and unit; channels the map does not know keep their
OpenFAST names, converted to SI when their unit is in :data:`UNIT_SCALE` (and reported in
``unmapped``), else kept as written and listed in ``unconverted``.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from linearize.openfast_channels import (
    CHANNEL_MAP,
    DEFAULT_UNITS,
    UNIT_SCALE,
    resolve_channels,
    unit_key,
)
from mpc_wt.errors import ResultFileError

__all__ = ["OpenFASTSeries", "read_openfast_output", "write_openfast_output", "CHANNEL_MAP",
           "UNIT_SCALE", "DEFAULT_UNITS", "to_mpcwt_channels", "from_mpcwt_channels",
           "split_csv_header"]


@dataclass(frozen=True)
class OpenFASTSeries:
    """An OpenFAST output as read.

    Parameters
    ----------
    t : (n_t,) ndarray
        Time [s].
    names, units : tuple of str
        The channels as written (without time), units without parentheses.
    data : (n_t, n_ch) ndarray
        Values in the file's units.
    description : str
        The file's description line.
    """

    t: np.ndarray
    names: tuple[str, ...]
    units: tuple[str, ...]
    data: np.ndarray
    description: str = ""


def read_openfast_output(path: str | Path) -> OpenFASTSeries:
    """Read an OpenFAST ``.out`` (text) or ``.outb`` (binary) output file.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    OpenFASTSeries

    Raises
    ------
    ResultFileError
        Naming the file and what is wrong: not found, no ``Time`` channel, truncated binary
        data, an unknown binary format id, ragged or non-numeric text rows.
    """
    p = Path(path)
    if not p.is_file():
        raise ResultFileError(f"{p}: file not found")
    if p.suffix.lower() == ".outb":
        return _read_binary(p)
    return _read_text(p)


def check_line_end(p: Path, text: str, sep: str | None = None) -> None:
    """Refuse a text file cut while it was written, whose last number may be cut too
    (``4100.5`` read as ``4``).

    OpenFAST ends every line of its text output (``sep`` None): a last line without a line
    end is cut. Other tools' CSV files (``sep=","``) often lack the last line end: there the
    last line is cut when its last field is shorter than every one of the 50 rows before in
    that column.

    Parameters
    ----------
    p : Path
        The file, for the message.
    text : str
        Its content.
    sep : str, optional
        The CSV's separator; None for OpenFAST's text output.

    Raises
    ------
    ResultFileError
        Naming the file and the cut line.
    """
    if not text or text.endswith(("\n", "\r")):
        return
    lines = text.splitlines()
    last = lines[-1]
    if sep is not None:
        before = [ln.split(sep) for ln in lines[-51:-1][1:] if ln.strip()]
        k = len(last.split(sep)) - 1
        widths = [len(r[k].strip()) for r in before if len(r) > k]
        if not widths or len(last.split(sep)[k].strip()) >= min(widths):
            return
    raise ResultFileError(f"{p}: line {len(lines)} ends without a line end "
                          f"({last.strip()[-40:]!r}): the file was cut while it was written, "
                          f"and its last number may be cut; remove the line or write the "
                          f"file again")


def _read_text(p: Path) -> OpenFASTSeries:
    text = p.read_text(errors="replace")
    check_line_end(p, text)
    lines = text.splitlines()
    head = None
    for i, ln in enumerate(lines[:40]):
        toks = ln.split()
        if toks and toks[0] == "Time":
            head = i
            break
    if head is None:
        raise ResultFileError(f"{p}: no header line starting with 'Time' in the first 40 lines: "
                              f"not an OpenFAST text output")
    names = lines[head].split()
    units = [u.strip("()") for u in lines[head + 1].split()] if head + 1 < len(lines) else []
    if len(units) != len(names):
        raise ResultFileError(f"{p}: line {head + 2}: {len(units)} units for {len(names)} "
                              f"channels")
    body = [ln for ln in lines[head + 2:] if ln.strip()]
    try:
        flat = np.array(" ".join(body).split(), dtype=float)
    except ValueError:
        flat = None
    if flat is None or flat.size != len(body) * len(names):
        for k, ln in enumerate(lines[head + 2:], start=head + 3):   # name the bad line
            toks = ln.split()
            if not toks:
                continue
            if len(toks) != len(names):
                raise ResultFileError(f"{p}: line {k}: {len(toks)} values; expected "
                                      f"{len(names)}")
            try:
                [float(x) for x in toks]
            except ValueError:
                raise ResultFileError(f"{p}: line {k}: non-numeric value in "
                                      f"{ln.strip()[:60]!r}") from None
    assert flat is not None
    if len(body) < 2:
        raise ResultFileError(f"{p}: fewer than 2 rows of data")
    data = flat.reshape(len(body), len(names))
    desc = lines[head - 2].strip() if head >= 2 else ""
    return OpenFASTSeries(t=data[:, 0], names=tuple(names[1:]), units=tuple(units[1:]),
                          data=data[:, 1:], description=desc)


_WITH_TIME, _WITHOUT_TIME, _NO_COMPRESS, _CHANLEN_IN = 1, 2, 3, 4


class _Buf:
    def __init__(self, p: Path) -> None:
        self.p, self.b, self.i = p, p.read_bytes(), 0

    def take(self, dtype: str, n: int = 1) -> np.ndarray:
        size = np.dtype(dtype).itemsize * n
        if self.i + size > len(self.b):
            raise ResultFileError(f"{self.p}: truncated at byte {len(self.b)}: {n} x {dtype} "
                                  f"expected at byte {self.i}")
        out = np.frombuffer(self.b, dtype=dtype, count=n, offset=self.i)
        self.i += size
        return out

    def text(self, n: int) -> str:
        return self.take("u1", n).tobytes().decode("latin-1").strip()


def _read_binary(p: Path) -> OpenFASTSeries:
    f = _Buf(p)
    fid = int(f.take("<i2")[0])
    if fid not in (_WITH_TIME, _WITHOUT_TIME, _NO_COMPRESS, _CHANLEN_IN):
        raise ResultFileError(f"{p}: FileFmtID {fid} is not an OpenFAST binary output format "
                              f"(allowed 1-4)")
    len_name = int(f.take("<i2")[0]) if fid == _CHANLEN_IN else 10
    n_ch = int(f.take("<i4")[0])
    n_t = int(f.take("<i4")[0])
    if n_ch < 1 or n_t < 1:
        raise ResultFileError(f"{p}: {n_ch} channels and {n_t} time steps; both must be >= 1")
    if fid == _WITH_TIME:
        t_scl, t_off = f.take("<f8", 2)
    else:
        t0, dt = f.take("<f8", 2)
    if fid != _NO_COMPRESS:
        scl = f.take("<f4", n_ch).astype(float)
        off = f.take("<f4", n_ch).astype(float)
    desc = f.text(int(f.take("<i4")[0]))
    names = [f.text(len_name) for _ in range(n_ch + 1)]
    units = [f.text(len_name).strip("()") for _ in range(n_ch + 1)]
    if fid == _WITH_TIME:
        t = (f.take("<i4", n_t).astype(float) - t_off) / t_scl
    else:
        t = t0 + dt * np.arange(n_t)
    if fid == _NO_COMPRESS:
        data = f.take("<f8", n_t * n_ch).reshape(n_t, n_ch).copy()
    else:
        data = (f.take("<i2", n_t * n_ch).reshape(n_t, n_ch) - off) / scl
    return OpenFASTSeries(t=t, names=tuple(names[1:]), units=tuple(units[1:]), data=data,
                          description=desc)


def write_openfast_output(path: str | Path, t: np.ndarray, channels: dict[str, np.ndarray],
                          units: dict[str, str] | None = None, *, binary_format: int = 3,
                          description: str = "written by mpc-wt") -> Path:
    """Write channels as an OpenFAST output: text (``.out``) or binary (``.outb``).

    Parameters
    ----------
    path : str or Path
        ``.out`` for text (tab-separated, OpenFAST's header), ``.outb`` for binary.
    t : (n_t,) ndarray
        Time [s].
    channels : dict of str to (n_t,) ndarray
        By OpenFAST name, in the units given.
    units : dict of str to str, optional
        Unit per channel (default ``"-"``).
    binary_format : {1, 2, 3, 4}
        OpenFAST's ``FileFmtID``: 3 (uncompressed float64, exact; the default), 1 (int16 with
        a packed int32 time channel), 2 (int16, first time and step), 4 (as 2 with the name
        length written). The compressed formats keep 16 bits per value, as OpenFAST does.
    description : str

    Returns
    -------
    Path
    """
    p = Path(path)
    t = np.asarray(t, dtype=float)
    names = list(channels)
    units = units or {}
    data = np.column_stack([np.asarray(channels[n], dtype=float) for n in names])
    if data.shape[0] != t.size:
        raise ValueError(f"channels have {data.shape[0]} samples; t has {t.size}")
    if p.suffix.lower() != ".outb":
        head = ["", "", "", "", description, "", "\t".join(["Time"] + names),
                "\t".join(["(s)"] + [f"({units.get(n, '-')})" for n in names])]
        body = ["\t".join([repr(float(v)) for v in row])
                for row in np.column_stack([t, data])]
        p.write_text("\n".join(head + body) + "\n")
        return p
    if binary_format not in (1, 2, 3, 4):
        raise ValueError(f"binary_format must be 1, 2, 3 or 4, got {binary_format!r}")
    len_name = 10 if binary_format != 4 else max(10, max(len(n) for n in names + ["Time"]))
    parts = [np.array([binary_format], "<i2").tobytes()]
    if binary_format == 4:
        parts.append(np.array([len_name], "<i2").tobytes())
    parts.append(np.array([len(names), t.size], "<i4").tobytes())
    if binary_format == 1:
        t_scl = 4294967295.0 / (t[-1] - t[0]) if t[-1] > t[0] else 1.0
        t_off = -2147483648.0 - t_scl * t[0]
        parts.append(np.array([t_scl, t_off], "<f8").tobytes())
    else:
        dt = (t[-1] - t[0]) / (t.size - 1) if t.size > 1 else 0.0
        parts.append(np.array([t[0], dt], "<f8").tobytes())
    if binary_format != 3:
        lo, hi = data.min(axis=0), data.max(axis=0)
        scl = np.where(hi > lo, 65535.0 / np.where(hi > lo, hi - lo, 1.0), 1.0).astype("<f4")
        off = (-32768.0 - scl.astype(float) * lo).astype("<f4")
        parts += [scl.tobytes(), off.tobytes()]
    d = description.encode("latin-1")
    parts += [np.array([len(d)], "<i4").tobytes(), d]
    parts += [f"{n:<{len_name}.{len_name}}".encode("latin-1") for n in ["Time"] + names]
    parts += [f"{'(' + u + ')':<{len_name}.{len_name}}".encode("latin-1")
              for u in ["s"] + [units.get(n, "-") for n in names]]
    if binary_format == 1:
        parts.append(np.clip(np.round(t_scl * t + t_off), -2147483648, 2147483647)
                     .astype("<i4").tobytes())
    if binary_format == 3:
        parts.append(data.astype("<f8").tobytes())
    else:
        packed = np.clip(np.round(data * scl.astype(float) + off.astype(float)), -32768, 32767)
        parts.append(packed.astype("<i2").tobytes())
    p.write_bytes(b"".join(parts))
    return p


_CSV_NAME = re.compile(r"^(?P<name>[A-Za-z0-9_]+?)(?:_?\s*[\[(](?P<unit>[^\])]*)[\])])?$")


def split_csv_header(header: str) -> tuple[str, str | None]:
    """Split a CSV header into an OpenFAST channel name and its unit.

    Parameters
    ----------
    header : str
        ``"RootMyb1_[kN-m]"``, ``"RootMyb1 (kN-m)"`` or a bare ``"RootMyb1"``.

    Returns
    -------
    name : str
    unit : str or None
        None for a bare name.
    """
    m = _CSV_NAME.match(header.strip())
    if not m:
        return header.strip(), None
    return m.group("name"), m.group("unit")


def to_mpcwt_channels(series: OpenFASTSeries, source: str = ""
                      ) -> tuple[dict[str, np.ndarray], list[str]]:
    """Map OpenFAST channels to ours in SI.

    Parameters
    ----------
    series : OpenFASTSeries
    source : str
        The file, for messages.

    Returns
    -------
    cols : dict of str to (n_t,) ndarray
        Mapped channels under our names (SI); the others under their OpenFAST names, in SI
        where their unit is known.
    notes : list of str
        What was not mapped or not converted.

    Raises
    ------
    ResultFileError
        A mapped channel with a unit the map does not allow, naming channel, unit and the
        allowed units.
    """
    cols: dict[str, np.ndarray] = {}
    unmapped, unconverted = [], []
    try:
        resolved = resolve_channels(series.names, series.units, source)
    except ValueError as err:
        raise ResultFileError(str(err)) from None
    for j, (name, unit, (ours, scale)) in enumerate(zip(series.names, series.units,
                                                        resolved)):
        if name in CHANNEL_MAP:
            cols[ours] = series.data[:, j] * scale
        elif np.isfinite(scale):
            cols[name] = series.data[:, j] * scale
            unmapped.append(name)
        else:
            cols[name] = series.data[:, j].copy()
            unconverted.append(f"{name} ({unit})")
    notes = []
    if unmapped:
        notes.append(f"{len(unmapped)} channels kept under their OpenFAST names, in SI: "
                     f"{', '.join(unmapped[:8])}{' ...' if len(unmapped) > 8 else ''}")
    if unconverted:
        notes.append(f"units not known, kept as written: {', '.join(unconverted)}")
    return cols, notes


def from_mpcwt_channels(cols: dict[str, np.ndarray]
                        ) -> tuple[dict[str, np.ndarray], dict[str, str]]:
    """Our channels (SI) as OpenFAST channels in OpenFAST's units, for
    :func:`write_openfast_output`: the first OpenFAST name of each of ours in
    :data:`CHANNEL_MAP` (``flap_moment_1`` -> ``RootMyc1`` in kN-m, ``flapwise_moment_1`` ->
    ``RootMyb1``, ``pitch_1`` ->
    ``BldPitch1`` in deg, ``gen_speed`` -> ``GenSpeed`` in rpm, ...). Channels without an
    OpenFAST name are left out.

    Parameters
    ----------
    cols : dict of str to (n_t,) ndarray

    Returns
    -------
    channels : dict of str to (n_t,) ndarray
    units : dict of str to str
    """
    first: dict[str, str] = {}
    for of, (ours, _) in CHANNEL_MAP.items():
        first.setdefault(ours, of)
    out, units = {}, {}
    for ours, values in cols.items():
        of = first.get(ours)
        if of is None:
            continue
        unit = DEFAULT_UNITS[of]
        out[of] = np.asarray(values, dtype=float) / UNIT_SCALE[unit_key(unit)]
        units[of] = unit
    return out, units

"""Wind fields on a (y, z) grid in the rotor plane over time, with I/O and sampling.

Frame (docs/nomenclature.md): x downwind, z up, y to the left looking downwind. ``t`` is the
time at which the wind reaches the rotor plane; with Taylor's frozen turbulence the wind at
upstream distance x_up at time t is the field at ``t + x_up / mean_speed``.
"""
from __future__ import annotations

import json
import zipfile
import math
import struct
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numba as nb
import numpy as np

from lidar._typing import FloatArray
from lidar.errors import FieldFileError

__all__ = ["WindField", "FieldFileError"]

SCHEMA_VERSION = 1


def _frozen(a: Any, name: str, single: bool = False) -> FloatArray:
    """Read-only contiguous copy, float64 (or float32 when ``single``: the wind components,
    whose 7 significant digits are far finer than any measured or generated wind); an array
    that is already read-only and of that type is adopted without copying (it cannot change
    under us), strided or not (an evolved field is stored point-major:
    :func:`lidar.generate_evolved_field`)."""
    dtype = np.float32 if single else np.float64
    if isinstance(a, np.ndarray) and a.dtype == dtype and not a.flags.writeable:
        arr = a
    else:
        arr = np.array(a, dtype=dtype, order="C")
    # a float32 array's sum in double is finite exactly when every entry is (float32
    # magnitudes cannot overflow it): no array of flags the field's size
    finite = (math.isfinite(float(arr.sum(dtype=np.float64))) if single
              else bool(np.all(np.isfinite(arr))))
    if not finite:
        bad = np.argwhere(~np.isfinite(arr))[0]
        raise ValueError(f"WindField.{name} must be finite; entry {tuple(int(i) for i in bad)} "
                         f"is {arr[tuple(bad)]!r}")
    arr.flags.writeable = False
    return arr


@nb.njit(cache=True)
def trilinear_point(data, grid, t, y, z):  # pragma: no cover - compiled
    """Trilinear interpolation of ``data`` (n_t, n_y, n_z) on the uniform grid ``grid`` =
    (t0, dt, y0, dy, z0, dz) at one point; a point on the edge (or within rounding of it)
    takes the last cell. The caller checks that the point is inside."""
    nt, ny, nz = data.shape
    xt = (t - grid[0]) / grid[1]
    xy = (y - grid[2]) / grid[3]
    xz = (z - grid[4]) / grid[5]
    it = min(max(int(math.floor(xt)), 0), nt - 2)
    iy = min(max(int(math.floor(xy)), 0), ny - 2)
    iz = min(max(int(math.floor(xz)), 0), nz - 2)
    at = min(max(xt - it, 0.0), 1.0)
    ay = min(max(xy - iy, 0.0), 1.0)
    az = min(max(xz - iz, 0.0), 1.0)
    acc = 0.0
    for dt_ in range(2):
        wt = at if dt_ else 1.0 - at
        for dy_ in range(2):
            wy = ay if dy_ else 1.0 - ay
            for dz_ in range(2):
                wz = az if dz_ else 1.0 - az
                acc += wt * wy * wz * data[it + dt_, iy + dy_, iz + dz_]
    return acc


@nb.njit(cache=True)
def _trilinear(data, grid, tt, yy, zz, out):  # pragma: no cover - compiled
    """:func:`trilinear_point` at the points (tt, yy, zz), written into ``out`` (compiled: one
    call per LIDAR measurement instead of some fifty numpy operations)."""
    for k in range(tt.size):
        out[k] = trilinear_point(data, grid, tt[k], yy[k], zz[k])


def _uniform(name: str, a: FloatArray) -> float:
    if a.ndim != 1 or a.size < 2:
        raise ValueError(f"WindField.{name} must be 1-D with at least 2 points, got shape "
                         f"{a.shape}")
    d = np.diff(a)
    if np.any(d <= 0) or np.ptp(d) > 1e-6 * abs(d[0]):
        raise ValueError(f"WindField.{name} must be uniformly increasing")
    return float(d[0])


@dataclass(frozen=True)
class WindField:
    """Three wind components on a regular (t, y, z) grid.

    Parameters
    ----------
    t : (n_t,) ndarray
        Uniform times at which the wind reaches the rotor plane [s].
    y : (n_y,) ndarray
        Uniform lateral positions, +y to the left looking downwind [m].
    z : (n_z,) ndarray
        Uniform heights above ground [m].
    u, v, w : (n_t, n_y, n_z) ndarray
        Longitudinal, lateral and vertical components [m/s]; stored as float32 (a 600 s,
        32 x 32 field at 20 Hz is 150 MB instead of 300 MB).
    mean_speed : float
        Mean hub-height speed, used for Taylor's frozen turbulence [m/s].
    hub_height : float
        [m].
    meta : dict
        Generation parameters (model, class, seed, ...), saved with the field.
    """

    t: FloatArray
    y: FloatArray
    z: FloatArray
    u: FloatArray
    v: FloatArray
    w: FloatArray
    mean_speed: float
    hub_height: float
    meta: dict[str, Any] = field(default_factory=dict, compare=False)

    def __post_init__(self) -> None:
        for n in ("t", "y", "z", "u", "v", "w"):
            object.__setattr__(self, n, _frozen(getattr(self, n), n, single=n in ("u", "v", "w")))
        for n in ("t", "y", "z"):
            _uniform(n, getattr(self, n))
        shape = (self.t.size, self.y.size, self.z.size)
        for n in ("u", "v", "w"):
            if getattr(self, n).shape != shape:
                raise ValueError(f"WindField.{n} has shape {getattr(self, n).shape}; expected "
                                 f"(n_t, n_y, n_z) = {shape}")
        if not (math.isfinite(self.mean_speed) and self.mean_speed > 0):
            raise ValueError(f"WindField.mean_speed must be > 0 m/s, got {self.mean_speed!r}")

    @property
    def dt(self) -> float:
        """Time step [s]."""
        return float(self.t[1] - self.t[0])

    @property
    def duration(self) -> float:
        """t[-1] - t[0] [s]."""
        return float(self.t[-1] - self.t[0])

    # ---------------------------------------------------------------------------------------
    # Sampling
    # ---------------------------------------------------------------------------------------
    def grid_spacing(self) -> FloatArray:
        """The uniform grid's origin and spacing, for :func:`trilinear_point`.

        Returns
        -------
        (6,) ndarray
            (t0, dt, y0, dy, z0, dz) [s, s, m, m, m, m].
        """
        return np.array([self.t[0], self.t[1] - self.t[0], self.y[0], self.y[1] - self.y[0],
                         self.z[0], self.z[1] - self.z[0]])

    def sample(self, t: Any, y: Any, z: Any, component: str = "u") -> FloatArray:
        """Trilinear interpolation of one component at points (t, y, z), broadcast together.

        Parameters
        ----------
        t, y, z : array_like
            Times [s] and lateral and vertical positions [m], broadcast together.
        component : {"u", "v", "w"}
            The wind component.

        Returns
        -------
        ndarray
            The component at the points, in their broadcast shape [m/s].

        Raises
        ------
        ValueError
            If a point lies outside the field in time, y or z (names the coordinate and the
            value), or the component is not u, v or w.
        """
        if component not in ("u", "v", "w"):
            raise ValueError(f"component must be 'u', 'v' or 'w', got {component!r}")
        return self.sample_components(t, y, z, component)[0]

    def sample_components(self, t: Any, y: Any, z: Any, components: str = "uvw"
                          ) -> tuple[FloatArray, ...]:
        """:meth:`sample` of several components at the same points (checked once).

        Parameters
        ----------
        t, y, z : array_like
            Times [s] and lateral and vertical positions [m], broadcast together.
        components : str
            Letters of "uvw", in the order wanted.

        Returns
        -------
        tuple of ndarray
            One per letter, in the points' broadcast shape [m/s].

        Raises
        ------
        ValueError
            As :meth:`sample`.
        """
        if not components or set(components) - set("uvw"):
            raise ValueError(f"components must be letters of 'uvw', got {components!r}")
        tt, yy, zz = np.broadcast_arrays(np.asarray(t, float), np.asarray(y, float),
                                         np.asarray(z, float))
        for name, val, ax in (("t", tt, self.t), ("y", yy, self.y), ("z", zz, self.z)):
            lo, hi = ax[0], ax[-1]
            tol = 1e-9 * max(1.0, abs(hi))
            if val.size and (val.min() < lo - tol or val.max() > hi + tol):
                bad = val.min() if val.min() < lo - tol else val.max()
                raise ValueError(f"point {name} = {bad:.6g} is outside the wind field "
                                 f"({name} {lo:.6g}..{hi:.6g}); a longer or wider field is needed")
        grid = self.grid_spacing()
        ft, fy, fz = (np.ascontiguousarray(tt).ravel(), np.ascontiguousarray(yy).ravel(),
                      np.ascontiguousarray(zz).ravel())
        outs = []
        for comp in components:
            out = np.empty(tt.size)
            _trilinear(getattr(self, comp), grid, ft, fy, fz, out)
            outs.append(out.reshape(tt.shape))
        return tuple(outs)

    # ---------------------------------------------------------------------------------------
    # I/O
    # ---------------------------------------------------------------------------------------
    def save(self, path: str | Path) -> Path:
        """Write ``.npz`` (native, with metadata) or ``.bts`` (TurbSim binary) by suffix.

        Parameters
        ----------
        path : str or Path
            ``.npz`` or ``.bts``.

        Returns
        -------
        Path
            The file written.
        """
        path = Path(path)
        if path.suffix.lower() == ".bts":
            _write_bts(self, path)
        elif path.suffix.lower() == ".npz":
            np.savez_compressed(path, t=self.t, y=self.y, z=self.z, u=self.u, v=self.v, w=self.w,
                                mean_speed=self.mean_speed, hub_height=self.hub_height,
                                meta_json=json.dumps({**self.meta,
                                                      "schema_version": SCHEMA_VERSION}))
        else:
            raise ValueError(f"file suffix must be .npz or .bts, got {path.suffix!r}")
        return path

    @classmethod
    def load(cls, path: str | Path) -> "WindField":
        """Read ``.npz`` (native) or ``.bts`` (TurbSim binary).

        Raises
        ------
        FieldFileError
            If the file is missing, truncated, of another schema, or holds NaN.
        """
        path = Path(path)
        if not path.is_file():
            raise FieldFileError(f"{path}: file not found")
        suffix = path.suffix.lower()
        try:
            if suffix == ".bts":
                return _read_bts(path)
            if suffix == ".npz":
                with np.load(path, allow_pickle=False) as d:
                    meta = json.loads(str(d["meta_json"]))
                    if meta.get("schema_version") != SCHEMA_VERSION:
                        raise FieldFileError(f"{path}: schema_version must be {SCHEMA_VERSION}, "
                                             f"got {meta.get('schema_version')!r}")
                    return cls(t=d["t"], y=d["y"], z=d["z"], u=d["u"], v=d["v"], w=d["w"],
                               mean_speed=float(d["mean_speed"]),
                               hub_height=float(d["hub_height"]), meta=meta)
        except FieldFileError:
            raise
        except zipfile.BadZipFile as err:
            raise FieldFileError(f"{path}: not a complete .npz file (cut short or another "
                                 f"format: {err})") from err
        except (ValueError, KeyError, OSError, EOFError) as err:
            raise FieldFileError(f"{path}: {err}") from err
        raise FieldFileError(f"{path}: suffix must be .npz or .bts, got {path.suffix!r}")


# ------------------------------------------------------------------------------------------
# TurbSim .bts (full-field binary): header, then int16 (u, v, w) per point, y fastest, then z,
# per time step; value = (int - offset) / slope per component.
# ------------------------------------------------------------------------------------------
_BTS_HEAD = struct.Struct("<h4l6f6fl")


def _write_bts(f: WindField, path: Path) -> None:
    comps = np.stack([f.u, f.v, f.w])                      # (3, n_t, n_y, n_z)
    lo = comps.min(axis=(1, 2, 3))
    hi = comps.max(axis=(1, 2, 3))
    rng = np.where(hi > lo, hi - lo, 1.0)
    slope = (65534.0 / rng).astype(np.float32)             # int16 span -32767..32767
    offset = (-32767.0 - lo * slope).astype(np.float32)
    ints = np.rint(comps * slope[:, None, None, None] + offset[:, None, None, None])
    ints = np.clip(ints, -32768, 32767).astype("<i2")
    data = np.transpose(ints, (1, 3, 2, 0))                 # (n_t, n_z, n_y, 3)
    info = (f"mpc-wt wind field {json.dumps(f.meta)}").encode("ascii", "replace")
    dz = float(f.z[1] - f.z[0])
    dy = float(f.y[1] - f.y[0])
    head = _BTS_HEAD.pack(7, f.z.size, f.y.size, 0, f.t.size, dz, dy, f.dt, f.mean_speed,
                          f.hub_height, float(f.z[0]), slope[0], offset[0], slope[1], offset[1],
                          slope[2], offset[2], len(info))
    with path.open("wb") as fh:
        fh.write(head)
        fh.write(info)
        fh.write(np.ascontiguousarray(data).tobytes())


def _read_bts(path: Path) -> WindField:
    raw = path.read_bytes()
    if len(raw) < _BTS_HEAD.size:
        raise FieldFileError(f"{path}: truncated .bts header ({len(raw)} bytes)")
    (ident, nz, ny, ntwr, nt, dz, dy, dt, uhub, zhub, zbot, s0, o0, s1, o1, s2, o2,
     nchar) = _BTS_HEAD.unpack_from(raw)
    if ident not in (7, 8) or min(nz, ny, nt) < 1 or ntwr < 0 or nchar < 0:
        raise FieldFileError(f"{path}: not a TurbSim full-field file (id {ident}, nz {nz}, "
                             f"ny {ny}, nt {nt})")
    start = _BTS_HEAD.size + nchar
    npts = 3 * (ny * nz + ntwr)
    need = start + 2 * npts * nt
    if len(raw) < need:
        raise FieldFileError(f"{path}: truncated .bts: {len(raw)} bytes, header promises "
                             f"{need} ({nt} steps of {ny} x {nz} points)")
    data = np.frombuffer(raw, dtype="<i2", count=npts * nt, offset=start).reshape(nt, npts)
    grid = data[:, :3 * ny * nz].reshape(nt, nz, ny, 3).astype(float)
    slope = np.array([s0, s1, s2])
    offset = np.array([o0, o1, o2])
    if np.any(slope == 0) or not np.all(np.isfinite(np.r_[slope, offset, dz, dy, dt, uhub, zhub])):
        raise FieldFileError(f"{path}: header has zero or non-finite scaling")
    vel = (grid - offset) / slope                          # (nt, nz, ny, 3)
    vel = np.transpose(vel, (3, 0, 2, 1))                   # (3, nt, ny, nz)
    y = (np.arange(ny) - (ny - 1) / 2.0) * dy
    z = zbot + np.arange(nz) * dz
    t = np.arange(nt) * dt
    try:
        return WindField(t=t, y=y, z=z, u=vel[0], v=vel[1], w=vel[2], mean_speed=float(uhub),
                         hub_height=float(zhub),
                         meta={"source": str(path), "bts_info": raw[_BTS_HEAD.size:start]
                               .decode("ascii", "replace")})
    except ValueError as err:
        raise FieldFileError(f"{path}: {err}") from err

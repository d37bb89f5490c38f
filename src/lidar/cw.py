"""Hub-mounted continuous-wave LIDAR with per-blade preview (Madsen et al. 2012, sec. II-E).

Geometry: the LIDAR sits at the hub and rotates with the rotor. Beam i points upstream at the
axial distance D (``focus_distance``, default 6/7 of the rotor radius: Madsen's 54 m on the
NREL 5-MW's 63 m) on a circle of radius r_m (75 % span), and
leads blade i by the angle omega_r T_p with T_p = D / V (Madsen fig. 5): what it measures now
reaches blade i's position T_p later. The beam's half-cone angle is atan(r_m / D) and its range
to focus F = sqrt(D^2 + r_m^2).

Measurement: the line-of-sight (LOS) speed is the projection of (u, v, w) on the beam,
weighted along it by the CW range-weighting function, a Lorentzian centred at F with half-width
Gamma = lambda F^2 / (pi a^2) (wavelength lambda, beam radius a at the lens). The weight is
integrated in the variable theta with s = F + Gamma tan(theta), in which the Lorentzian is
uniform, so equal weights on a uniform theta grid cover it exactly; points beyond the end of the
wind field keep their weight on the last point inside, so the whole weight counts. The
horizontal speed is reconstructed as u_hat = v_LOS F / D, assuming v = w = 0.

Madsen's idealizations are switches: ``perfect_alignment`` (the yaw misalignment is set to zero),
``los_error`` (False measures u directly, as if v = w = 0 were true), ``range_weighting``
(False: a point measurement at the focus), and frozen turbulence, which is the default of the
field (wind evolution is applied to the field, see :func:`lidar.evolve_field`).
"""
from __future__ import annotations

import functools
import hashlib
import math
from dataclasses import dataclass
from pathlib import Path

import numba as nb
import numpy as np

from lidar import field as _field
from lidar._typing import FloatArray
from lidar.field import WindField, trilinear_point

__all__ = ["CWLidar", "LidarMeasurement", "FOCUS_PER_RADIUS"]

#: The default focus distance per rotor radius [-]: Madsen et al.'s 54 m on the NREL 5-MW's
#: 63 m tip radius.
FOCUS_PER_RADIUS = 54.0 / 63.0


@dataclass(frozen=True)
class CWLidar:
    """A hub-mounted CW LIDAR with one beam per blade.

    Parameters
    ----------
    rotor_radius : float
        Tip radius [m] (a number, so this package needs no turbine object).
    focus_distance : float, optional
        Axial upstream distance D of the focus [m]. Default :data:`FOCUS_PER_RADIUS` x
        ``rotor_radius``: Madsen et al.'s 54 m on the NREL 5-MW's 63 m rotor (sec. II-E: 3 s
        of preview at 18 m/s, and the beams' half-cone angle at 75 % span, 41 deg, below the
        45 deg their reference recommends), the same angle and a preview that grows with the
        rotor on any other (121.7 m on the IEA-22-280-RWT).
    span_fraction : float
        Radius of the measurement circle as a fraction of the rotor radius (default 0.75).
    wavelength : float
        [m] (default 1.565e-6).
    beam_radius : float
        Beam radius a at the lens [m] (default 0.028).
    sample_rate : float
        Measurements per second per beam [Hz] (default 10).
    noise_std : float
        Standard deviation of additive LOS noise [m/s] (default 0).
    misalignment_rad : float
        Yaw misalignment of the mean wind with the rotor axis [rad].
    perfect_alignment, los_error, range_weighting : bool
        Idealization switches (module docstring).
    n_range : int
        Quadrature points along the beam (default 41).
    """

    rotor_radius: float
    focus_distance: float | None = None
    span_fraction: float = 0.75
    wavelength: float = 1.565e-6
    beam_radius: float = 0.028
    sample_rate: float = 10.0
    noise_std: float = 0.0
    misalignment_rad: float = 0.0
    perfect_alignment: bool = True
    los_error: bool = True
    range_weighting: bool = True
    n_range: int = 41

    def __post_init__(self) -> None:
        r = self.rotor_radius
        if self.focus_distance is None and isinstance(r, (int, float)) and math.isfinite(r):
            object.__setattr__(self, "focus_distance", FOCUS_PER_RADIUS * float(r))
        for name in ("rotor_radius", "focus_distance", "wavelength", "beam_radius",
                     "sample_rate"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ValueError(f"{name} must be a finite number > 0, got {v!r}")
        if not 0 < self.span_fraction <= 1:
            raise ValueError(f"span_fraction must be in (0, 1], got {self.span_fraction!r}")
        if not (math.isfinite(self.noise_std) and self.noise_std >= 0):
            raise ValueError(f"noise_std must be >= 0 m/s, got {self.noise_std!r}")
        if not (math.isfinite(self.misalignment_rad) and abs(self.misalignment_rad) < math.pi / 2):
            raise ValueError(f"misalignment_rad must be in (-pi/2, pi/2), got "
                             f"{self.misalignment_rad!r}")
        if self.n_range < 1:
            raise ValueError(f"n_range must be >= 1, got {self.n_range!r}")

    @property
    def radius(self) -> float:
        """Measurement-circle radius r_m [m]."""
        return self.span_fraction * self.rotor_radius

    @property
    def focus_range(self) -> float:
        """Range along the beam to the focus F [m]."""
        return math.hypot(self.focus_distance, self.radius)

    @property
    def cone_angle_rad(self) -> float:
        """Half-cone angle of the beams, atan(r_m / D) [rad]."""
        return math.atan2(self.radius, self.focus_distance)

    @property
    def half_width(self) -> float:
        """Lorentzian half-width Gamma = lambda F^2 / (pi a^2) [m]."""
        return self.wavelength * self.focus_range**2 / (math.pi * self.beam_radius**2)

    def preview_time(self, mean_speed: float) -> float:
        """T_p = D / V [s].

        Parameters
        ----------
        mean_speed : float
            Mean wind speed [m/s].

        Returns
        -------
        float
            Preview time T_p [s].
        """
        return self.focus_distance / mean_speed

    def weighting(self, s: FloatArray) -> FloatArray:
        """Range-weighting function W(s) along the beam, normalized on s in (0, inf) [1/m].

        Parameters
        ----------
        s : (n_s,) ndarray
            Ranges along the beam [m].

        Returns
        -------
        (n_s,) ndarray
            W(s) [1/m].
        """
        g = self.half_width
        f = self.focus_range
        norm = 0.5 + math.atan(f / g) / math.pi
        return (g / math.pi) / (g**2 + (np.asarray(s, float) - f) ** 2) / norm

    def range_quadrature(self, s_max: float = math.inf) -> tuple[FloatArray, FloatArray]:
        """Ranges s_k [m] and weights (summing to 1) of the beam integral on (0, s_max).

        Uniform in theta = atan((s - F) / Gamma), where the Lorentzian is uniform; the weight of
        (s_max, inf) stays on the last point, so the weights always sum to exactly 1.

        Parameters
        ----------
        s_max : float
            Largest range integrated [m] (default: the whole beam).

        Returns
        -------
        s : (n_s,) ndarray
            Ranges [m].
        w : (n_s,) ndarray
            Weights, summing to 1 [-].
        """
        return _range_quadrature(self, float(s_max))

    def _quadrature(self, s_max: float) -> tuple[FloatArray, FloatArray]:
        if not self.range_weighting:
            return np.array([self.focus_range]), np.array([1.0])
        g, f = self.half_width, self.focus_range
        lo = math.atan(-f / g)
        hi = math.atan((s_max - f) / g) if math.isfinite(s_max) else 0.5 * math.pi
        n = self.n_range
        edges = np.linspace(lo, hi, n + 1)
        mid = 0.5 * (edges[1:] + edges[:-1])
        w = np.diff(edges) / (0.5 * math.pi - lo)          # Lorentzian mass of each cell
        w[-1] += (0.5 * math.pi - hi) / (0.5 * math.pi - lo)  # tail beyond s_max
        return f + g * np.tan(mid), w

    def beam_azimuths(self, blade_azimuth_rad: FloatArray, rotor_speed_rad_s: FloatArray,
                      mean_speed: float) -> FloatArray:
        """Azimuth of each beam, (n_t, 3): blade azimuth + (i - 1) 2 pi / 3 + omega_r T_p.

        Parameters
        ----------
        blade_azimuth_rad : (n_t,) ndarray
            Azimuth of blade 1 [rad].
        rotor_speed_rad_s : (n_t,) ndarray or float
            Rotor speed [rad/s].
        mean_speed : float
            Mean wind speed that sets the preview time [m/s].

        Returns
        -------
        (n_t, 3) ndarray
            Azimuth of each beam [rad].
        """
        psi = np.asarray(blade_azimuth_rad, float)[:, None] + 2 * math.pi * np.arange(3) / 3
        lead = np.asarray(rotor_speed_rad_s, float)[:, None] * self.preview_time(mean_speed)
        return psi + lead

    def measure(self, field: WindField, t: FloatArray, blade_azimuth_rad: FloatArray,
                rotor_speed_rad_s: FloatArray | float,
                rng: np.random.Generator | None = None) -> "LidarMeasurement":
        """Simulate the three beams over a time series of rotor azimuth and speed.

        Parameters
        ----------
        field : WindField
            The wind that reaches the rotor (frozen turbulence: the upstream wind at time t
            and distance x is the field at t + x / V).
        t : (n_t,) ndarray
            Measurement times [s].
        blade_azimuth_rad : (n_t,) ndarray
            Azimuth of blade 1 at each time (0 = up, in the direction of rotation) [rad].
        rotor_speed_rad_s : (n_t,) ndarray or float
            [rad/s].
        rng : Generator, optional
            For the measurement noise.

        Returns
        -------
        LidarMeasurement

        Raises
        ------
        ValueError
            If the beams leave the field (focus too far, field too narrow) or the field ends
            before the last measurement's preview; the message names the value.
        """
        t = np.asarray(t, float)
        psi_b = np.asarray(blade_azimuth_rad, float)
        if t.ndim != 1 or psi_b.shape != t.shape:
            raise ValueError(f"t and blade_azimuth_rad must be 1-D of equal length, got "
                             f"{t.shape} and {psi_b.shape}")
        om = np.broadcast_to(np.asarray(rotor_speed_rad_s, float), t.shape)
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(psi_b)) and np.all(np.isfinite(om))):
            raise ValueError("t, blade_azimuth_rad and rotor_speed_rad_s must be finite")
        v = field.mean_speed
        ang = self.beam_azimuths(psi_b, om, v)                       # (n_t, 3)
        cos_b = math.cos(self.cone_angle_rad)
        sin_b = math.sin(self.cone_angle_rad)
        # the farthest range that stays inside the field in y, z and time
        r_field = min(-field.y[0], field.y[-1], field.z[-1] - field.hub_height,
                      field.hub_height - field.z[0])
        x_time = (field.t[-1] - t.max()) * v if t.size else 0.0
        s_max = min(r_field / sin_b, x_time / cos_b)
        if s_max <= self.focus_range:
            which = ("the field's lateral/vertical extent" if r_field / sin_b < x_time / cos_b
                     else "the field's duration")
            raise ValueError(
                f"focus_distance = {self.focus_distance:g} m puts the focus (range "
                f"{self.focus_range:.1f} m, radius {self.radius:.1f} m, "
                f"{self.focus_distance / v:.2f} s ahead) beyond {which}: the field covers "
                f"radius {r_field:.1f} m and t up to {field.t[-1]:g} s")
        s, wts = self.range_quadrature(s_max)
        x_up = s * cos_b                                             # (n_s,)
        rad = s * sin_b
        gam = 0.0 if self.perfect_alignment else self.misalignment_rad
        if t.size and t.min() + x_up[0] / v >= field.t[0]:
            # every point inside the field (s_max keeps them in y, z and the end of time):
            # the compiled beam sums
            los = np.empty((t.size, 3))
            vw = (field.v, field.w) if self.los_error else (field.u, field.u)
            _los_kernel(field.u, *vw, field.grid_spacing(), t, ang, x_up, rad,
                        wts, field.hub_height, v, cos_b, sin_b, math.cos(gam), math.sin(gam),
                        self.los_error, los)
            return self._measurement(t, los, ang, cos_b, v, rng)
        tt = t[:, None, None] + x_up[None, None, :] / v               # (n_t, 1, n_s)
        yy = -rad[None, None, :] * np.sin(ang)[:, :, None]
        zz = field.hub_height + rad[None, None, :] * np.cos(ang)[:, :, None]
        tt = np.broadcast_to(tt, yy.shape)
        if self.los_error:
            u, vv, ww = field.sample_components(tt, yy, zz, "uvw")
            if gam:
                u, vv = u * math.cos(gam) - vv * math.sin(gam), u * math.sin(gam) + vv * math.cos(gam)
            # beam direction (from the hub): (-cos_b, -sin_b sin(ang), sin_b cos(ang));
            # LOS speed positive toward the LIDAR: -(e . V)
            los_pts = (u * cos_b + vv * (sin_b * np.sin(ang))[:, :, None]
                       - ww * (sin_b * np.cos(ang))[:, :, None])
        else:
            los_pts = field.sample(tt, yy, zz, "u") * cos_b
        los = (los_pts * wts[None, None, :]).sum(axis=2)
        return self._measurement(t, los, ang, cos_b, v, rng)

    def _measurement(self, t: FloatArray, los: FloatArray, ang: FloatArray, cos_b: float,
                     v: float, rng: np.random.Generator | None) -> "LidarMeasurement":
        """The measurement of the beam sums ``los``, with the noise added."""
        if self.noise_std > 0:
            gen = rng if rng is not None else np.random.default_rng()
            los = los + gen.normal(0.0, self.noise_std, los.shape)
        return LidarMeasurement(t=t, los=los, u_hat=los / cos_b, beam_azimuth_rad=ang,
                                preview_time=self.preview_time(v), radius=self.radius)


@nb.njit(cache=True)
def _los_kernel(u, v, w, grid, t, ang, x_up, rad, wts, hub, mean, cos_b, sin_b, cos_g, sin_g,
                los_error, out):  # pragma: no cover - compiled
    """The range-weighted LOS speed of each beam at each time, into ``out`` (n_t, 3): the
    field (frozen turbulence: the wind at x upstream and time t is the field's at t + x / V)
    at the quadrature's points, every point checked inside the field by the caller."""
    for k in range(t.size):
        for i in range(3):
            sa = math.sin(ang[k, i])
            ca = math.cos(ang[k, i])
            acc = 0.0
            for j in range(x_up.size):
                tt = t[k] + x_up[j] / mean
                yy = -rad[j] * sa
                zz = hub + rad[j] * ca
                uu = trilinear_point(u, grid, tt, yy, zz)
                if los_error:
                    vv = trilinear_point(v, grid, tt, yy, zz)
                    ww = trilinear_point(w, grid, tt, yy, zz)
                    uu, vv = uu * cos_g - vv * sin_g, uu * sin_g + vv * cos_g
                    acc += wts[j] * (uu * cos_b + vv * (sin_b * sa) - ww * (sin_b * ca))
                else:
                    acc += wts[j] * (uu * cos_b)
            out[k, i] = acc


@functools.lru_cache(maxsize=64)
def _range_quadrature(lidar: CWLidar, s_max: float) -> tuple[FloatArray, FloatArray]:
    """:meth:`CWLidar.range_quadrature`, kept (read-only) for the next measurement of the same
    LIDAR: a LIDAR in the loop measures once a step with the same beam limit."""
    s, w = lidar._quadrature(s_max)
    s.flags.writeable = False
    w.flags.writeable = False
    return s, w


@dataclass(frozen=True)
class LidarMeasurement:
    """What the LIDAR measured.

    Parameters
    ----------
    t : (n_t,) ndarray
        Measurement times [s].
    los : (n_t, 3) ndarray
        LOS speed of each beam, positive toward the LIDAR [m/s].
    u_hat : (n_t, 3) ndarray
        Reconstructed horizontal speed u_hat = v_LOS / cos(cone) per beam [m/s]; beam i
        previews blade i.
    beam_azimuth_rad : (n_t, 3) ndarray
        Azimuth of each measurement point [rad].
    preview_time : float
        T_p [s].
    radius : float
        Measurement-circle radius [m].
    """

    t: FloatArray
    los: FloatArray
    u_hat: FloatArray
    beam_azimuth_rad: FloatArray
    preview_time: float
    radius: float


class LidarSensor:
    """A CW LIDAR in a controller: the instrument, and the wind field it measures, which the
    simulator binds before each run (:meth:`bind`). A controller's design chooses the
    instrument; the wind it sees is the case's, so the design never holds it.

    Parameters
    ----------
    instrument : CWLidar
        The LIDAR.
    evolution : bool
        Whether the field it measures is the rotor's evolved over the focus distance
        (:func:`lidar.evolve_field`; the simulator makes it) or the rotor's own (frozen
        turbulence).
    field : WindField, optional
        Bind at once (a field made by hand, e.g. in a test).
    """

    def __init__(self, instrument: CWLidar, evolution: bool = True,
                 field: WindField | None = None) -> None:
        if not isinstance(instrument, CWLidar):
            raise TypeError(f"instrument must be a CWLidar, got {type(instrument).__name__}")
        self.instrument, self.evolution = instrument, bool(evolution)
        self._field = field

    @property
    def distance(self) -> float:
        """The distance over which the wind it measures has evolved [m] (0: frozen)."""
        return self.instrument.focus_distance if self.evolution else 0.0

    @property
    def focus_distance(self) -> float:
        """The instrument's focus distance D [m]."""
        return self.instrument.focus_distance

    def bind(self, field: WindField) -> None:
        """Give the sensor the wind field of the next run.

        Parameters
        ----------
        field : WindField
            What the LIDAR measures.
        """
        if not isinstance(field, WindField):
            raise TypeError(f"field must be a WindField, got {type(field).__name__}")
        self._field = field

    @property
    def field(self) -> WindField:
        """The bound field.

        Raises
        ------
        RuntimeError
            Before :meth:`bind`.
        """
        if self._field is None:
            raise RuntimeError("the LIDAR has no wind to measure: the simulator binds the "
                               "case's field (LidarSensor.bind) before the run")
        return self._field

    def measure(self, t: FloatArray, blade_azimuth_rad: FloatArray,
                rotor_speed_rad_s: FloatArray | float) -> LidarMeasurement:
        """:meth:`CWLidar.measure` on the bound field.

        Parameters
        ----------
        t : (n_t,) ndarray
            Measurement times [s].
        blade_azimuth_rad : (n_t,) ndarray
            Azimuth of blade 1 [rad].
        rotor_speed_rad_s : (n_t,) ndarray or float
            [rad/s].

        Returns
        -------
        LidarMeasurement
        """
        return self.instrument.measure(self.field, t, blade_azimuth_rad, rotor_speed_rad_s)


def _key_cache_on_field() -> None:
    """:func:`_los_kernel` compiles the field's interpolation into itself, and numba keys its
    disk cache on this file only: the field module's source enters the key too, so that an
    edit or upgrade of it recompiles the kernel (through numba 0.68's cache object; on another
    layout numba's own key stays)."""
    cache_file = getattr(getattr(_los_kernel, "_cache", None), "_cache_file", None)
    if cache_file is not None and hasattr(cache_file, "_source_stamp"):
        h = hashlib.sha256(repr(cache_file._source_stamp).encode())
        h.update(Path(_field.__file__).read_bytes())
        cache_file._source_stamp = h.hexdigest()


_key_cache_on_field()

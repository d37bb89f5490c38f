"""What the plant's rotor meets: steady power-law wind (:class:`SteadyWind`), a gridded
turbulent field (:class:`GridWind`), and the free wind at each blade element
(:func:`element_wind`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from linearize._typing import FloatArray
from linearize.kernel import NO_GRID, sample_wind
from linearize.params import PlantParams
from linearize.validate import check_array

__all__ = ["element_wind", "SteadyWind", "GridWind"]


def element_wind(params: PlantParams, azimuth_rad: float, hub_speed: float,
                 shear_exponent: float = 0.0) -> FloatArray:
    """Free wind at each element from a steady power-law profile, (n_blade, n_r) [m/s].

    Parameters
    ----------
    params : PlantParams
        The plant.
    azimuth_rad : float
        Azimuth of blade 1 [rad].
    hub_speed : float
        Hub-height wind speed [m/s].
    shear_exponent : float
        Power-law exponent [-].

    Returns
    -------
    (n_blade, n_r) ndarray
        Free wind at each element [m/s].
    """
    ws = SteadyWind(hub_speed, shear_exponent)
    kind, wpar, grid = ws._kernel_args()
    return sample_wind(0.0, float(azimuth_rad), params.pack, kind, wpar, grid[0])


@dataclass(frozen=True)
class SteadyWind:
    """Steady wind with a power-law shear profile V(z) = V_hub (z / z_hub)^alpha.

    Parameters
    ----------
    speed : float
        Hub-height speed [m/s], >= 0.
    shear_exponent : float
        alpha [-], 0 for uniform wind.
    """

    speed: float
    shear_exponent: float = 0.0

    def __post_init__(self) -> None:
        v = float(self.speed)
        if not math.isfinite(v) or v < 0:
            raise ValueError(f"wind speed must be finite and >= 0 m/s, got {self.speed!r}")
        a = float(self.shear_exponent)
        if not math.isfinite(a) or not -1.0 <= a <= 1.0:
            raise ValueError(f"shear_exponent must be in [-1, 1], got {self.shear_exponent!r}")

    def _kernel_args(self) -> tuple[int, FloatArray, tuple[FloatArray, FloatArray]]:
        return (0, np.array([float(self.speed), float(self.shear_exponent)]), (NO_GRID, _NO_VW))

    def check_covers(self, params: PlantParams, t_end: float) -> None:
        """Steady wind covers any rotor and any duration.

        Parameters
        ----------
        params : PlantParams
            The plant.
        t_end : float
            End of the simulation [s].
        """


#: the kernel's v-w grid of a wind without lateral and vertical components (read-only, as
#: :data:`linearize.kernel.NO_GRID`)
_NO_VW = np.zeros((2, 1, 1, 1), dtype=np.float32)
_NO_VW.flags.writeable = False


@dataclass(frozen=True)
class GridWind:
    """Wind on a regular (t, y, z) grid in the rotor plane, sampled trilinearly: the
    longitudinal component, and optionally the lateral and vertical ones.

    Parameters
    ----------
    t : (n_t,) ndarray
        Uniformly spaced times [s].
    y : (n_y,) ndarray
        Uniformly spaced lateral positions, +y to the left looking downwind [m].
    z : (n_z,) ndarray
        Uniformly spaced heights above ground [m].
    u : (n_t, n_y, n_z) ndarray
        Longitudinal wind speed [m/s], finite and >= 0; kept as float32 (a 600 s turbulent
        field on 32 x 32 points at 20 Hz is 50 MB).
    v, w : (n_t, n_y, n_z) ndarray, optional
        Lateral (+y) and vertical (+z) wind speed [m/s], finite; both or neither (kept
        together as one float32 array). Without them the plant meets u alone.
    """

    t: FloatArray
    y: FloatArray
    z: FloatArray
    u: FloatArray
    v: FloatArray | None = None
    w: FloatArray | None = None

    def __post_init__(self) -> None:
        for name in ("t", "y", "z"):
            a = np.array(getattr(self, name), dtype=float)
            if a.ndim != 1 or a.size < 2 or not np.all(np.isfinite(a)):
                raise ValueError(f"GridWind.{name} must be a finite 1-D array of length >= 2")
            st = np.diff(a)
            if np.any(st <= 0) or np.ptp(st) > 1e-6 * abs(st[0]) + 1e-12:
                raise ValueError(f"GridWind.{name} must be uniformly increasing")
            a.flags.writeable = False
            object.__setattr__(self, name, a)
        u = check_array("GridWind.u", self.u, (self.t.size, self.y.size, self.z.size),
                        shape_names="(n_t, n_y, n_z)", dtype=np.float32)
        if np.any(u < 0):
            raise ValueError(f"GridWind.u must be >= 0 m/s, got min {u.min()!r}")
        # adopt a read-only contiguous float32 array (it cannot change under us), else copy
        if (u is self.u and self.u.flags.writeable) or u.base is not None \
                or not u.flags.c_contiguous:
            u = np.array(u, dtype=np.float32, order="C")
        u.flags.writeable = False
        object.__setattr__(self, "u", u)
        if (self.v is None) != (self.w is None):
            raise ValueError("GridWind.v and GridWind.w must be given together (or neither)")
        vw = _NO_VW
        if self.v is not None:
            shape = (self.t.size, self.y.size, self.z.size)
            vw = np.empty((2,) + shape, dtype=np.float32)
            vw[0] = check_array("GridWind.v", self.v, shape, shape_names="(n_t, n_y, n_z)")
            vw[1] = check_array("GridWind.w", self.w, shape, shape_names="(n_t, n_y, n_z)")
            vw.flags.writeable = False
            object.__setattr__(self, "v", vw[0])
            object.__setattr__(self, "w", vw[1])
        object.__setattr__(self, "_vw", vw)

    @property
    def has_inplane(self) -> bool:
        """Whether the grid carries the lateral and vertical components."""
        return self.v is not None

    def _kernel_args(self) -> tuple[int, FloatArray, tuple[FloatArray, FloatArray]]:
        par = np.array([self.t[0], self.t[1] - self.t[0], self.y[0], self.y[1] - self.y[0],
                        self.z[0], self.z[1] - self.z[0]])
        return 1, par, (self.u, self._vw)   # type: ignore[attr-defined]

    def check_covers(self, params: PlantParams, t_end: float) -> None:
        """Raise if the grid does not cover the rotor disc or the time span.

        Parameters
        ----------
        params : PlantParams
            The plant (rotor size and hub height).
        t_end : float
            End of the simulation [s].
        """
        g = params.turbine.geometry
        rad = g.tip_radius
        if (self.y[0] > -rad or self.y[-1] < rad or self.z[0] > g.hub_height - rad
                or self.z[-1] < g.hub_height + rad):
            raise ValueError(
                f"wind grid y {self.y[0]:g}..{self.y[-1]:g} m, z {self.z[0]:g}..{self.z[-1]:g} m "
                f"does not cover the rotor (y +-{rad:g} m, z {g.hub_height - rad:g}.."
                f"{g.hub_height + rad:g} m)")
        if self.t[-1] < t_end - 1e-9:
            raise ValueError(f"wind field ends at t = {self.t[-1]:g} s, before the simulation "
                             f"end t = {t_end:g} s")

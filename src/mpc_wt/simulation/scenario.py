"""The load case as the simulator meets it (:class:`Scenario`: mean wind, turbulence, seed,
duration, shear, an IEC 61400-1 wind condition), its rules written once, and its wind
(:func:`make_wind`).
"""
from __future__ import annotations

import dataclasses
import functools
import math
import threading
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

import lidar
import linearize
from linearize.validate import check_finite_scalar, check_positive, check_range

__all__ = ["Scenario", "check_turbulence", "check_condition", "is_deterministic", "field_grid",
           "make_wind", "field_spec", "iec_site", "lidar_field", "check_wind_file",
           "read_wind_file", "start_wind", "START_WINDOW", "FieldMemo", "DEFAULT_FIELDS"]

#: Second word of the seed of the wind-evolution field (ASCII "evol"): a stream of its own.
_EVOLUTION_STREAM = 0x65766F6C


#: The longest run a scenario takes [s]: the turbulent field of 3 h on the default grid (32 x 32
#: points every 0.05 s, u only, float32) takes 0.9 GB stored, several times that while it is
#: generated, before the LIDAR's own field and the result.
MAX_DURATION_S = 10800.0


@dataclass(frozen=True)
class Scenario:
    """One load case: mean wind, turbulence, seed, length and shear, and optionally an IEC
    61400-1 wind condition (:func:`lidar.iec_field`); or the user's own wind from a file.

    Parameters
    ----------
    wind_mps : float
        Mean hub-height wind [m/s], > 0 (None with ``wind_file``).
    turbulence : str or float
        IEC class "A", "B", "C", "steady", or a turbulence intensity in (0, 1) [-].
    seed : int
        Seed of the turbulent field, >= 0.
    duration : float
        Simulated time [s], > 0.
    shear_exponent : float
        Power-law shear exponent [-], in [-1, 1].
    condition : str
        IEC 61400-1 ed. 3 wind condition (:data:`lidar.CONDITIONS`): "ntm" (default: the
        turbulence given), "etm" (the extreme turbulence model's sigma_1 for the category
        ``turbulence``), "nwp" (steady) or a deterministic transient ("eog", "edc", "ecd",
        "ews-v", "ews-h") for the class ``iec_class`` and the category ``turbulence``.
    iec_class : str
        Wind turbine class "I", "II" or "III" (V_ref of the EOG and ECD).
    sign : {1, -1}
        Direction of a direction change or a shear.
    event_at : float
        When a transient starts [s] (simulation time).
    wind_file : str, optional
        A wind field file instead of a generated one: TurbSim full-field binary (``.bts``) or
        mpc-wt's own ``.npz`` (:meth:`lidar.WindField.load`). No mean wind is declared
        (``wind_mps`` None); the plant starts from the trim at the rotor-disc mean of the
        file's first 5 s; turbulence, seed and shear are the file's.

    Raises
    ------
    ValueError
        Naming the field, the value and what is allowed.
    """

    wind_mps: float | None = None
    turbulence: str | float = "A"
    seed: int = 1
    duration: float = 600.0
    shear_exponent: float = 0.2
    condition: str = "ntm"
    iec_class: str = "I"
    sign: int = 1
    event_at: float = 0.0
    wind_file: str | None = None

    def __post_init__(self) -> None:
        if self.wind_file is None:
            if self.wind_mps is None:
                raise ValueError("wind_mps must be a mean wind > 0 m/s (or give wind_file), "
                                 "got None")
            check_positive("wind_mps", self.wind_mps)
        else:
            check_wind_file(self.wind_file)
            if self.wind_mps is not None:
                raise ValueError(f"wind_mps must be None with a wind_file (the file's wind is "
                                 f"the case's; nothing declares a mean), got {self.wind_mps!r}")
            if self.condition != "ntm":
                raise ValueError(f"condition must be 'ntm' with a wind_file, got "
                                 f"{self.condition!r}")
        check_positive("duration", self.duration)
        if self.duration > MAX_DURATION_S:
            raise ValueError(f"duration must be at most {MAX_DURATION_S:g} s (3 h: a longer "
                             f"turbulent field takes several GB to make), got "
                             f"{self.duration:g}; split a longer run")
        check_range("shear_exponent", self.shear_exponent, -1.0, 1.0)
        check_turbulence(self.turbulence)
        if isinstance(self.seed, bool) or not isinstance(self.seed, (int, np.integer)) \
                or self.seed < 0:
            raise ValueError(f"seed must be an integer >= 0, got {self.seed!r}")
        check_condition(self.condition, (self.turbulence,))
        if self.sign not in (1, -1):
            raise ValueError(f"sign must be 1 or -1, got {self.sign!r}")
        check_range("event_at", self.event_at, 0.0, math.inf)

    @property
    def deterministic(self) -> bool:
        """True for a wind without turbulence: steady, NWP or an IEC transient (False for a
        wind file)."""
        return self.wind_file is None and is_deterministic(self.condition, (self.turbulence,))

    def meta(self) -> dict[str, Any]:
        """The case as plain data for a result's ``meta``.

        Returns
        -------
        dict
            ``wind_mps``, ``turbulence``, ``seed``, ``duration_s``, ``shear_exponent`` (the I/O keys
            carry units); with an IEC condition also ``condition``, ``iec_class``, ``sign``,
            ``event_at_s``.
        """
        if self.wind_file is not None:
            return {"wind_file": str(self.wind_file), "duration_s": self.duration}
        out = {"wind_mps": self.wind_mps, "turbulence": self.turbulence, "seed": self.seed,
               "duration_s": self.duration, "shear_exponent": self.shear_exponent}
        if self.condition != "ntm":
            out.update(condition=self.condition, iec_class=self.iec_class, sign=self.sign,
                       event_at_s=self.event_at)
        return out


# The scenario's rules, written once: Scenario checks itself with them, and the campaign spec
# and the command line call them to name their own key or flag in the message.

def check_turbulence(value: Any) -> str | float:
    """An IEC class letter, "steady", or a turbulence intensity, checked.

    Parameters
    ----------
    value : str or float
        "A", "B", "C", "steady" or an intensity in (0, 1) [-].

    Returns
    -------
    str or float
        The value (an intensity as float).

    Raises
    ------
    ValueError
        Naming what is allowed and the value.
    """
    if isinstance(value, str):
        if value not in ("A", "B", "C", "steady"):
            raise ValueError(f"turbulence must be 'A', 'B', 'C', 'steady' or an intensity in "
                             f"(0, 1), got {value!r}")
        return value
    if isinstance(value, bool) or not isinstance(value, (int, float, np.floating)) \
            or not 0.0 < check_finite_scalar("turbulence", value) < 1.0:
        raise ValueError(f"turbulence intensity must be in (0, 1), got {value!r}")
    return float(value)


def check_condition(condition: str, turbulence: tuple[str | float, ...]) -> None:
    """An IEC 61400-1 wind condition and the turbulence it is given with, checked: a
    condition other than NTM and NWP takes the turbulence as the site's category.

    Parameters
    ----------
    condition : str
        A key of :data:`lidar.CONDITIONS`.
    turbulence : tuple of str or float
        The turbulence values it runs with.

    Raises
    ------
    ValueError
        An unknown condition, or a condition that needs a category given an intensity or
        "steady".
    """
    if condition not in lidar.CONDITIONS:
        raise ValueError(f"condition must be one of {sorted(lidar.CONDITIONS)}, got "
                         f"{condition!r}")
    if condition not in ("ntm", "nwp") and not all(t in ("A", "B", "C") for t in turbulence):
        shown = turbulence[0] if len(turbulence) == 1 else list(turbulence)
        raise ValueError(f"condition {condition!r} needs an IEC turbulence category 'A', 'B' "
                         f"or 'C' as turbulence, got {shown!r}")


def is_deterministic(condition: str, turbulence: tuple[str | float, ...]) -> bool:
    """Whether runs of this condition and turbulence have no turbulence (one run per wind and
    sign: steady wind, NWP or an IEC transient) rather than seeds.

    Parameters
    ----------
    condition : str
        A key of :data:`lidar.CONDITIONS`.
    turbulence : tuple of str or float
        The turbulence values.

    Returns
    -------
    bool
    """
    return condition not in ("ntm", "etm") or tuple(turbulence) == ("steady",)


def field_grid(turbine: linearize.Turbine) -> tuple[float, int]:
    """Side [m] and points per side of a square turbulence grid that covers the rotor.

    150 m and 32 points (4.8 m spacing) for rotors up to 63 m; larger rotors get 12 m of margin
    on each side of the tip and the same spacing (the IEA-15-240-RWT: 266 m, 56 points).

    Parameters
    ----------
    turbine : Turbine
        For the tip radius.

    Returns
    -------
    width : float
        [m].
    n : int
        Even number of points per side.
    """
    width = max(150.0, 2.0 * turbine.geometry.tip_radius + 24.0)
    n = max(32, 2 * math.ceil(width / 150.0 * 16))
    return width, n



class FieldMemo:
    """Keeps the turbulent fields of the last few scenarios for the next run that meets the
    same one: the controllers of a campaign compared on one seed, a LIDAR's evolved field.

    A field is a pure function of the turbine's grid, the scenario's turbulence, mean wind,
    duration and seed (and for a LIDAR's field the focus distance), so a kept one is the same
    object a new generation would equal bit for bit; its arrays are read-only. Fields are
    dropped oldest first once the kept arrays pass ``max_bytes``. A campaign worker keeps one
    (:data:`mpc_wt.campaign.task.WORKER_FIELDS`) and the runner hands it the cases of one
    field one after another.

    Parameters
    ----------
    max_bytes : float
        Largest memory the kept arrays may hold [B] (default 1 GB: three 600 s fields on
        32 x 32 points with a LIDAR's evolved field).
    """

    def __init__(self, max_bytes: float = 1.0e9) -> None:
        if not (math.isfinite(max_bytes) and max_bytes >= 0):
            raise ValueError(f"max_bytes must be finite and >= 0, got {max_bytes!r}")
        self.max_bytes = float(max_bytes)
        self._kept: dict[tuple[Any, ...], tuple[Any, int]] = {}
        self._lock = threading.Lock()
        self.hits = 0
        self.misses = 0

    def __len__(self) -> int:
        return len(self._kept)

    @property
    def nbytes(self) -> int:
        """Bytes held by the kept arrays."""
        return sum(n for _, n in self._kept.values())

    def clear(self) -> None:
        """Drop every kept field."""
        self._kept.clear()

    def get(self, key: tuple[Any, ...], make: Any) -> Any:
        """The value kept under ``key``, else ``make()`` (kept if it fits).

        Parameters
        ----------
        key : tuple
            What the value is a pure function of (hashable).
        make : callable
            Makes the value on a miss.

        Returns
        -------
        object
            The kept or the new value.
        """
        with self._lock:
            val = self._kept.pop(key, None)
            if val is not None:
                self.hits += 1
                self._kept[key] = val              # most recently used last
                return val[0]
            self.misses += 1
        value = make()
        size = _array_bytes(value)
        if size <= self.max_bytes:
            with self._lock:
                while self._kept and self.nbytes + size > self.max_bytes:
                    self._kept.pop(next(iter(self._kept)))
                self._kept[key] = (value, size)
        return value


#: The fields :func:`mpc_wt.run.run_controller` and :func:`mpc_wt.run.build_controller` keep
#: when given none: the last runs' fields, up to 600 MB (on the NREL 5-MW's grid a 600 s field
#: takes 51 MB with u alone, 153 MB with u, v and w), for the next run of the same scenario
#: (controllers compared on one case). A run that would not fit in the memory available
#: otherwise releases them first (logged); ``DEFAULT_FIELDS.clear()`` releases them;
#: ``fields=FieldMemo(0)`` keeps none.
DEFAULT_FIELDS = FieldMemo(max_bytes=6.0e8)


def _array_bytes(value: Any) -> int:
    """Bytes of the distinct arrays (and their bases) in a field, a wind or a tuple of them."""
    seen: dict[int, int] = {}

    def visit(obj: Any) -> None:
        if isinstance(obj, np.ndarray):
            base = obj
            while isinstance(base.base, np.ndarray):
                base = base.base
            seen[id(base)] = base.nbytes
        elif isinstance(obj, tuple):
            for o in obj:
                visit(o)
        elif dataclasses.is_dataclass(obj):
            for f in dataclasses.fields(obj):
                visit(getattr(obj, f.name))
    visit(value)
    return sum(seen.values())


def make_wind(turbine: linearize.Turbine, scenario: Scenario, components: str = "uvw", *,
              samplers: lidar.SamplerCache | None = None, fields: FieldMemo | None = None
              ) -> tuple[linearize.SteadyWind | linearize.GridWind, lidar.WindField]:
    """The plant's wind for a scenario and the same field for a LIDAR in the loop.

    Parameters
    ----------
    turbine : Turbine
        For the hub height.
    scenario : Scenario
        The load case; the field is 20 s longer than the run.
    components : str
        The turbulent components to generate ("uvw" default; "u": v = w = 0, for runs
        without a LIDAR; u is the same either way, drawn first from the seed's stream).
    samplers : lidar.SamplerCache, optional
        Keeps the turbulence generator's sampler for the next field of the same wind and grid
        (the fields are the same with or without it).
    fields : FieldMemo, optional
        Keeps the turbulent field (and the plant's wind made of it) for the next run of the
        same scenario.

    Returns
    -------
    wind : SteadyWind or GridWind
        What the plant meets (negative speeds of a turbulent field clipped at 0).
    field : lidar.WindField
        The same field.
    """
    if scenario.wind_file is not None:
        return _file_wind(turbine, scenario)
    hub = turbine.geometry.hub_height
    v, alpha = scenario.wind_mps, scenario.shear_exponent
    if scenario.condition not in ("ntm", "nwp", "etm"):
        width, n = field_grid(turbine)
        return _iec_wind(scenario, iec_site(turbine, scenario), width, n)
    if scenario.turbulence == "steady" or scenario.condition == "nwp":
        width, _ = field_grid(turbine)
        spec = lidar.TurbulenceSpec(v, 0.01, hub_height=hub, duration=scenario.duration + 20.0,
                                    dt=1.0, n_y=8, n_z=8, width=width, height=width,
                                    shear_exponent=alpha)
        t, y, z = spec.grid()
        u = np.broadcast_to(v * (z / hub) ** alpha, (t.size, y.size, z.size))
        zero = np.zeros(u.shape)
        f = lidar.WindField(t=t, y=y, z=z, u=u, v=zero, w=zero, mean_speed=v, hub_height=hub,
                            meta={"model": "steady power law"})
        return linearize.SteadyWind(v, alpha), f
    spec = field_spec(turbine, scenario)

    def make() -> tuple[linearize.GridWind, lidar.WindField]:
        f = lidar.generate_field(spec, scenario.seed, components=components, samplers=samplers)
        if scenario.condition == "etm":
            f = dataclasses.replace(f, meta={**f.meta, "condition": "etm",
                                             "iec_class": scenario.iec_class,
                                             "turbulence_class": scenario.turbulence})
        return _grid_wind(f)
    if fields is None:
        return make()
    key = ("case", spec, scenario.seed, components, scenario.condition, scenario.iec_class,
           scenario.turbulence)
    return fields.get(key, make)


def field_spec(turbine: linearize.Turbine, scenario: Scenario) -> lidar.TurbulenceSpec:
    """The turbulence of a turbulent scenario's field: the NTM of its class or intensity, or
    the ETM's sigma (IEC 61400-1 eq. 19) for its IEC class, on :func:`field_grid`'s grid, 20 s
    longer than the run.

    Parameters
    ----------
    turbine : Turbine
        For the hub height and the grid.
    scenario : Scenario
        A turbulent load case (condition ``ntm`` or ``etm``, turbulence not ``steady``).

    Returns
    -------
    lidar.TurbulenceSpec

    Raises
    ------
    ValueError
        For a deterministic scenario (steady, NWP or an IEC transient), naming it.
    """
    if scenario.deterministic:
        raise ValueError(f"scenario {scenario.condition!r} with turbulence "
                         f"{scenario.turbulence!r} has no turbulent field")
    v = scenario.wind_mps
    width, n = field_grid(turbine)
    turb = scenario.turbulence
    if scenario.condition == "etm":
        site = iec_site(turbine, scenario)
        turb = site.magnitudes(site.check_speed("etm", v))["sigma_etm"] / v
    return lidar.TurbulenceSpec(v, turb, hub_height=turbine.geometry.hub_height, width=width,
                                height=width, n_y=n, n_z=n, duration=scenario.duration + 20.0,
                                shear_exponent=scenario.shear_exponent)


def _grid_wind(f: lidar.WindField) -> tuple[linearize.GridWind, lidar.WindField]:
    """The plant's wind: the field's u (read-only float32) unless a gust of a very turbulent
    low wind (or a direction change beyond 90 deg) runs backwards: then the clipped copy. A
    field made for the plant alone (u only) then holds the clipped u itself instead of
    beside it (50 MB for a 600 s field on 32 x 32 points), with ``meta["u_clipped_at_zero"]``;
    a LIDAR never measures it (:func:`lidar_field` makes its own field)."""
    u = f.u
    if float(u.min()) < 0.0:
        u = np.maximum(f.u, np.float32(0.0))
        u.flags.writeable = False
        if f.meta.get("components") == "u":
            f = dataclasses.replace(f, u=u, meta={**f.meta, "u_clipped_at_zero": True})
    return linearize.GridWind(t=f.t, y=f.y, z=f.z, u=u), f


def iec_site(turbine: linearize.Turbine, scenario: Scenario) -> lidar.IECSite:
    """The turbine's IEC 61400-1 site for a scenario: its class and category, hub height,
    rotor diameter, the scenario's shear and the turbine's operating range.

    Parameters
    ----------
    turbine : Turbine
        For the hub height, the rotor and cut-in / cut-out.
    scenario : Scenario
        For ``iec_class``, the category (``turbulence``) and the shear.

    Returns
    -------
    lidar.IECSite
    """
    op = turbine.operation
    return lidar.IECSite(scenario.iec_class, str(scenario.turbulence),
                         hub_height=turbine.geometry.hub_height,
                         diameter=2.0 * turbine.geometry.tip_radius,
                         shear_exponent=scenario.shear_exponent, cut_in=op.cut_in_wind,
                         cut_out=op.cut_out_wind)


def _iec_wind(scenario: Scenario, site: lidar.IECSite, width: float, n: int
              ) -> tuple[linearize.GridWind, lidar.WindField]:
    """A deterministic IEC transient on the turbulence grid, 20 s longer than the run. The
    plant meets the rotor-normal component u = V cos(theta) of a direction change (no skewed
    inflow model); a LIDAR in the loop sees u and v."""
    f = lidar.iec_field(scenario.condition, scenario.wind_mps, site,
                        t_start=scenario.event_at, duration=scenario.duration + 20.0,
                        dt=0.05, width=width, n=n, sign=scenario.sign)
    return _grid_wind(f)


def check_wind_file(path: Any) -> Path:
    """A wind field file that exists and has a suffix mpc-wt reads.

    Parameters
    ----------
    path : str or Path
        ``.bts`` (TurbSim) or ``.npz``.

    Returns
    -------
    Path

    Raises
    ------
    ValueError
        Naming the file and what is allowed.
    """
    p = Path(str(path))
    if p.suffix.lower() not in (".bts", ".npz"):
        raise ValueError(f"wind_file must be a TurbSim .bts or an mpc-wt .npz field, got "
                         f"{str(path)!r}")
    if not p.is_file():
        raise ValueError(f"wind_file {str(path)!r}: no such file")
    return p


@functools.lru_cache(maxsize=2)
def _load_field(path: str, mtime_ns: int) -> lidar.WindField:
    return lidar.WindField.load(path)


#: The largest mean wind a wind file may blow [m/s]: IEC 61400-1's 50-year extreme of class I
#: (1.4 V_ref = 70 m/s).
MAX_FILE_WIND = 70.0

#: How far a file's header mean wind may lie from its data's mean at the hub (a fraction of
#: the data's): a field made for another wind, or a header edited, is refused.
HEADER_TOLERANCE = 0.5


def read_wind_file(path: str) -> lidar.WindField:
    """A wind file's field, its wind checked as ``--wind`` is (the last two read are kept:
    the trim and the run read it once).

    The mean of the longitudinal wind at the grid point nearest the hub (over the file's
    time) must be finite and in (0, :data:`MAX_FILE_WIND`] m/s (the wind blows downwind,
    along +x), and the header's mean wind (TurbSim's hub speed, the ``.npz``'s
    ``mean_speed``) within :data:`HEADER_TOLERANCE` of it: the header sets the frozen
    turbulence's speed and a campaign's wind bin.

    Parameters
    ----------
    path : str
        ``.bts`` or ``.npz``.

    Returns
    -------
    lidar.WindField

    Raises
    ------
    lidar.FieldFileError
        A missing, truncated or broken file.
    ValueError
        A wind out of range or against its header, naming the file and both values.
    """
    p = check_wind_file(path)
    f = _load_field(str(p.resolve()), p.stat().st_mtime_ns)
    _check_field_wind(str(path), f)
    return f


def _check_field_wind(name: str, f: lidar.WindField) -> None:
    """:func:`read_wind_file`'s check of the wind a file blows."""
    iy = int(np.argmin(np.abs(f.y)))
    iz = int(np.argmin(np.abs(f.z - f.hub_height)))
    hub = float(np.mean(f.u[:, iy, iz], dtype=float))
    where = f"at the grid point nearest the hub (y {f.y[iy]:g} m, z {f.z[iz]:g} m)"
    if not (math.isfinite(hub) and 0.0 < hub <= MAX_FILE_WIND):
        raise ValueError(f"wind_file {name!r}: its mean wind {where} is {hub:.4g} m/s; a wind "
                         f"file must blow downwind (+x) with a mean in (0, {MAX_FILE_WIND:g}] "
                         f"m/s")
    if abs(f.mean_speed - hub) > HEADER_TOLERANCE * hub:
        raise ValueError(f"wind_file {name!r}: its header's mean wind {f.mean_speed:.4g} m/s "
                         f"disagrees with its data's {hub:.4g} m/s {where} (allowed within "
                         f"{HEADER_TOLERANCE:.0%}): a field made for another wind, or an "
                         f"edited header")


#: The first seconds of a wind file whose rotor-disc mean wind sets the plant's start [s].
START_WINDOW = 5.0


def start_wind(turbine: linearize.Turbine, scenario: Scenario) -> float:
    """The wind the plant is trimmed at before the run: the scenario's mean wind, or the
    rotor-disc mean of a wind file's first :data:`START_WINDOW` seconds (within the turbine's
    operating range). The simulator's, never a controller's.

    Parameters
    ----------
    turbine : Turbine
        Rotor radius and operating range.
    scenario : Scenario
        The case.

    Returns
    -------
    float
        [m/s]
    """
    if scenario.wind_file is None:
        return float(scenario.wind_mps)         # type: ignore[arg-type]
    f = _rotor_field(turbine, scenario.wind_file)
    first = f.t <= f.t[0] + START_WINDOW
    u = lidar.rotor_effective_wind(f, turbine.geometry.tip_radius)[first].mean()
    op = turbine.operation
    return float(min(max(u, op.cut_in_wind), op.cut_out_wind))


def _rotor_field(turbine: linearize.Turbine, name: str) -> lidar.WindField:
    """A wind file's field, checked to cover the turbine's rotor."""
    f = read_wind_file(name)
    r, hub = turbine.geometry.tip_radius, turbine.geometry.hub_height
    if f.y[0] > -r or f.y[-1] < r or f.z[0] > hub - r or f.z[-1] < hub + r:
        raise ValueError(f"wind_file {name!r}: its grid (y {f.y[0]:g}..{f.y[-1]:g} m, z "
                         f"{f.z[0]:g}..{f.z[-1]:g} m) does not cover the rotor (radius {r:g} m "
                         f"at hub height {hub:g} m)")
    return f


def _file_wind(turbine: linearize.Turbine, scenario: Scenario
               ) -> tuple[linearize.GridWind, lidar.WindField]:
    """The plant's wind from the scenario's file, checked to cover the rotor and the run."""
    name = str(scenario.wind_file)
    f = _rotor_field(turbine, name)
    if f.t[-1] - f.t[0] < scenario.duration:
        raise ValueError(f"wind_file {name!r} holds {f.t[-1] - f.t[0]:g} s of wind; the run's "
                         f"duration is {scenario.duration:g} s")
    f = dataclasses.replace(f, t=f.t - f.t[0],
                            meta={**f.meta, "wind_file": str(name),
                                  "file_mean_wind_mps": float(f.mean_speed)})
    grid, f = _grid_wind(f)
    # a wind file's lateral and vertical components reach the plant too (every controller of
    # a campaign runs on the same file, so all meet them)
    return dataclasses.replace(grid, v=f.v, w=f.w), f


def lidar_field(turbine: linearize.Turbine, scenario: Scenario, field: lidar.WindField,
                distance: float, samplers: lidar.SamplerCache | None = None,
                fields: FieldMemo | None = None) -> lidar.WindField:
    """The field a LIDAR focused ``distance`` upstream measures in a case: the case's field
    evolved over that distance with Simley and Pao's coherence (:func:`lidar.evolve_field`; its
    independent part seeded from the case's seed, so every controller sees the same wind).

    This is the simulator's side of a LIDAR in the loop (the wind it sees is physics, not
    design): the harness binds it to each LIDAR a controller declared
    (:class:`~mpc_wt.simulation.preview.LidarSensor`). A turbulent case's evolved field is
    made from the case's spec and seed (:func:`lidar.generate_evolved_field`), not from
    ``field``: so the case's field needs only the plant's u, and the two are never held side by
    side with the case's v and w. With frozen turbulence (distance 0) a u-only case field is
    made whole again from its seed.

    Parameters
    ----------
    turbine : Turbine
        For the field's grid.
    scenario : Scenario
        The case.
    field : lidar.WindField
        The case's field (:func:`make_wind`).
    distance : float
        [m], >= 0; 0 (or a deterministic case) gives the field itself: frozen turbulence.
    samplers : lidar.SamplerCache, optional
        Keeps the turbulence generator's sampler.
    fields : FieldMemo, optional
        Keeps a turbulent case's LIDAR field for the next run of the same case and distance.

    Returns
    -------
    lidar.WindField
    """
    if scenario.deterministic:
        return field
    if scenario.wind_file is not None:
        if distance == 0.0:
            return field
        return lidar.evolve_field(field, distance, seed=np.random.default_rng(
            [0, _EVOLUTION_STREAM]), samplers=samplers)
    spec = field_spec(turbine, scenario)
    if distance == 0.0 and set(field.meta.get("components", "uvw")) >= set("uvw"):
        return field

    def make() -> lidar.WindField:
        if distance == 0.0:
            # the case's field was made with u only (the plant's): the whole field, whose u
            # is the same
            whole = lidar.generate_field(spec, scenario.seed, samplers=samplers)
            return dataclasses.replace(whole, meta=field.meta | {"components": "uvw"})
        # made without the case's field: it is generate_evolved_field(spec, seed, ...), the
        # evolution of generate_field(spec, seed) to single-precision rounding
        seed = np.random.default_rng([scenario.seed, _EVOLUTION_STREAM])
        seen = lidar.generate_evolved_field(spec, scenario.seed, distance, seed,
                                            samplers=samplers)
        return dataclasses.replace(seen, meta={**field.meta, **seen.meta, "components": "uvw"})
    if fields is None:
        return make()
    key = ("lidar", spec, scenario.seed, float(distance), scenario.condition,
           scenario.iec_class, scenario.turbulence)
    return fields.get(key, make)

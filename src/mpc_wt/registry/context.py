"""What a controller kind's build receives (BuildContext) and returns (Built), and the design cache.
"""
from __future__ import annotations

import dataclasses
import hashlib
import math
import threading
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

import lidar
import linearize
from linearize.turbine import content_digest
from mpc_wt.errors import CaseDataError

__all__ = ["turbine_key", "design_digest", "DesignCache", "DEFAULT_CACHE", "BuildContext",
           "Built"]


def turbine_key(turbine: linearize.Turbine) -> str:
    """A digest of a turbine's content (every field and array; not where it was read from),
    for caching designs and naming a campaign's turbine (:func:`linearize.turbine.content_digest`).

    Parameters
    ----------
    turbine : Turbine
        Any turbine.

    Returns
    -------
    str
        SHA-256 hex digest; equal turbines give equal keys whatever their identity.
    """
    return content_digest(turbine)


#: Types a design digest does not walk into: solver handles and compiled functions hold
#: addresses and caches, not design data (their data are the QP's arrays, walked beside them).
_OPAQUE = ("ctypes", "numba", "osqp", "daqp", "scipy.interpolate", "logging", "threading",
           "_thread", "concurrent", "multiprocessing")


def design_digest(obj: Any) -> str:
    """A digest of a built controller's design: every array, number, string and option it holds
    (walked through dataclasses, containers and object attributes; a turbine by its content,
    not the file it was read from; solver handles, compiled functions, modules, the wind a LIDAR
    is bound to, the design's own solve times (``*_time_s``), classes marked ``__design__ =
    False`` and the attributes a class names in ``__not_design__`` are skipped; an object with a
    ``design_identity()`` method is digested by what it returns: a controller library by its
    bytes and its input file's text, not the folders it was copied to).

    Two builds give equal digests when they hold the same gains, models and QP data; a design
    that read the case (its mean wind, its field) differs from case to case.

    Parameters
    ----------
    obj : object
        A controller (or any design object).

    Returns
    -------
    str
        SHA-256 hex digest.
    """
    h = hashlib.sha256()
    seen: set[int] = set()

    def walk(o: Any, depth: int) -> None:
        if depth > 40:
            return
        if isinstance(o, lidar.WindField):      # the wind a LIDAR measures: the case's
            return
        if isinstance(o, linearize.Turbine):    # its content, not where it was read from
            h.update(content_digest(o).encode())
            return
        if isinstance(o, lidar.LidarSensor):    # the instrument, not the wind bound to it
            h.update(b"LidarSensor")
            walk(o.instrument, depth + 1)
            walk(o.evolution, depth + 1)
            return
        if o is None or isinstance(o, (bool, int, str, bytes)):
            h.update(repr(o).encode())
        elif isinstance(o, float):
            h.update(b"nan" if math.isnan(o) else repr(o).encode())
        elif isinstance(o, np.ndarray):
            if o.dtype.kind in "fciub":
                h.update(str(o.shape).encode())
                h.update(np.ascontiguousarray(o).tobytes())
        elif isinstance(o, np.generic):
            h.update(repr(o.item()).encode())
        elif isinstance(o, (list, tuple)):
            h.update(f"[{len(o)}".encode())
            for v in o:
                walk(v, depth + 1)
        elif isinstance(o, dict):
            for k in sorted(o, key=str):
                h.update(str(k).encode())
                walk(o[k], depth + 1)
        elif callable(o) and not hasattr(o, "__dict__") or isinstance(o, type):
            return
        else:
            mod = type(o).__module__ or ""
            if mod.startswith(_OPAQUE) or id(o) in seen \
                    or getattr(type(o), "__design__", True) is False:
                return
            seen.add(id(o))
            h.update(type(o).__name__.encode())
            for k, v in _design_items(o):
                h.update(k.encode())
                walk(v, depth + 1)

    walk(obj, 0)
    return h.hexdigest()


def _design_items(o: Any) -> list[tuple[str, Any]]:
    """An object's design data by name, in order: what its ``design_identity()`` returns, or
    its fields (dataclass, ``__dict__``, ``__slots__``) without the skipped ones (see
    :func:`design_digest`)."""
    ident = getattr(o, "design_identity", None)
    if callable(ident):                         # what the object says its design is
        return [("design_identity", ident())]
    if dataclasses.is_dataclass(o):
        items = {f.name: getattr(o, f.name) for f in dataclasses.fields(o)}
    else:
        items = dict(getattr(o, "__dict__", {}))
        for name in getattr(type(o), "__slots__", ()):
            if hasattr(o, name):
                items[name] = getattr(o, name)
    skip = set(getattr(type(o), "__not_design__", ()))
    return [(k, items[k]) for k in sorted(items)
            if not (k.startswith("__") or k.endswith("_time_s") or k in skip
                    or callable(items[k]) and not hasattr(items[k], "__dict__"))]


class DesignCache:
    """Designs kept per process, keyed on the turbine's content and the design's settings
    (a campaign worker designs a TS controller once, not once per case).

    Parameters
    ----------
    max_items : int
        Entries kept; the one used longest ago goes first (default 64: a campaign worker
        keeps every kind of the sign-off, each its design, its shipped law and the parts they
        are made of).
    """

    def __init__(self, max_items: int = 64) -> None:
        self.max_items = int(max_items)
        self._items: dict[tuple[Any, ...], Any] = {}
        self._lock = threading.Lock()
        self.hits = 0
        #: designs made (misses), by the key's first element ("built", "ts", ...)
        self.made: dict[str, int] = {}

    def get(self, turbine: linearize.Turbine, key: tuple[Any, ...],
            make: Callable[[], Any]) -> Any:
        """The cached design for (turbine content, key), made by ``make()`` on a miss.

        Parameters
        ----------
        turbine : Turbine
            Its content is part of the key.
        key : tuple
            Hashable settings of the design.
        make : callable
            Builds the design.

        Returns
        -------
        object
            The design.
        """
        full = (turbine_key(turbine), *key)
        with self._lock:
            if full in self._items:
                self.hits += 1
                value = self._items.pop(full)     # the most recently used goes last
                self._items[full] = value
                return value
        value = make()
        with self._lock:
            name = str(key[0]) if key else ""
            self.made[name] = self.made.get(name, 0) + 1
            self._items[full] = value
            while len(self._items) > self.max_items:
                self._items.pop(next(iter(self._items)))
        return value

    def clear(self, kind: str | None = None) -> None:
        """Drop every design, or those whose key starts with ``kind`` (``"built"``: the whole
        controllers, keeping the parts they are made of).

        Parameters
        ----------
        kind : str, optional
            The first element of the keys to drop.
        """
        with self._lock:
            if kind is None:
                self._items.clear()
                return
            for k in [k for k in self._items if len(k) > 1 and k[1] == kind]:
                del self._items[k]


#: The process-wide cache used by :func:`~mpc_wt.run.run_controller` by default.
DEFAULT_CACHE = DesignCache()


#: What a design may not read, and why (the message of :class:`~mpc_wt.errors.CaseDataError`).
_CASE_DATA = ("a controller's design depends on the turbine, its options and the controller's "
              "sample time only: the case's mean wind, seed, turbulence and wind field are the "
              "simulator's, and a real controller knows none of them. Start from the first "
              "measurement in step() (as ROSCO starts its integrator from the measured pitch), "
              "schedule on a wind estimated from measurements "
              "(mpc_wt.controllers.wind_estimator.WindSpeedEstimator), and take a LIDAR's wind "
              "from ctx.lidar(...)")


def _case_data(name: str, what: str) -> property:
    """A BuildContext attribute that a design may not read: it raises CaseDataError."""
    def get(self: Any) -> Any:
        raise CaseDataError(f"BuildContext.{name}: {_CASE_DATA}")
    get.__doc__ = f"""Not available to a design ({what}).

        Raises
        ------
        CaseDataError
            Always.
        """
    return property(get)


@dataclass(frozen=True)
class BuildContext:
    """Everything a kind's ``build`` may use: the turbine and the harness's step, nothing of
    the case.

    A design made from it is the same whatever case it then runs (the registry keeps it in
    :attr:`cache` and runs every case of a campaign worker with it, ``reset()`` between
    them); reading :attr:`scenario`, :attr:`field` or :attr:`op` raises
    :class:`~mpc_wt.errors.CaseDataError`. A LIDAR is declared with :meth:`lidar`: the
    instrument is the design's, the wind it measures is bound by the simulator before each
    run.

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    params : PlantParams
        Its plant parameters.
    dt : float
        The plant's (and the fastest controller's) step [s].
    cache : DesignCache
        For designs that cost seconds.
    """

    turbine: linearize.Turbine
    params: linearize.PlantParams
    dt: float = 1.0 / 80.0
    cache: DesignCache = DEFAULT_CACHE
    sensors: list[Any] = field(default_factory=list, compare=False, repr=False)

    def lidar(self, instrument: Any, evolution: bool = True) -> Any:
        """Declare a LIDAR of the design: the simulator binds the wind it measures before each
        run (the case's field, evolved over the focus distance unless ``evolution`` is off).

        Parameters
        ----------
        instrument : lidar.CWLidar
            The instrument.
        evolution : bool
            Wind evolution between the focus and the rotor (False: frozen turbulence).

        Returns
        -------
        lidar.LidarSensor
            Unbound; give it to the controller or the preview.
        """
        sensor = lidar.LidarSensor(instrument, evolution)
        self.sensors.append(sensor)
        return sensor

    scenario = _case_data("scenario", "the load case")
    field = _case_data("field", "the case's wind field")
    op = _case_data("op", "the trim point, which holds the case's mean wind")


@dataclass
class Built:
    """A built controller and what the harness needs to run it.

    Parameters
    ----------
    controller : Controller
        ``reset()`` and ``step(t, meas)``.
    controller_dt : float, optional
        Its period [s] (None: the plant's step).
    preview : LidarPreview, optional
        A LIDAR in the loop.
    meta : dict
        Design data stored with the result.
    power_fraction : float
        The fraction of rated power the design targets (add-ons tune for it) [-].
    sensors : list of lidar.LidarSensor
        The LIDARs the design declared (:meth:`BuildContext.lidar`); the harness binds them.
    design : object, optional
        The design's own objects where ``controller`` runs it otherwise (its shipped law: the
        compiled library through the host); None: ``controller`` is the design.
    """

    controller: Any
    controller_dt: float | None = None
    preview: Any = None
    meta: dict[str, Any] = field(default_factory=dict)
    power_fraction: float = 1.0
    sensors: list[Any] = field(default_factory=list)
    design: Any = None

    @property
    def designed(self) -> Any:
        """The design's own objects: :attr:`design` where the controller runs it as shipped,
        else the controller (gains, models, settings to read; what an export writes out).

        Returns
        -------
        object
        """
        return self.controller if self.design is None else self.design

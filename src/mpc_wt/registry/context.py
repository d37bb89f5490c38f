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
from mpc_wt.simulation.scenario import Scenario, field_spec

__all__ = ["turbine_key", "DesignCache", "DEFAULT_CACHE", "BuildContext", "Built"]


def turbine_key(turbine: linearize.Turbine) -> str:
    """A digest of a turbine's content (every field and array; not where it was read from),
    for caching designs and naming a campaign's turbine.

    Parameters
    ----------
    turbine : Turbine
        Any turbine.

    Returns
    -------
    str
        SHA-256 hex digest; equal turbines give equal keys whatever their identity.
    """
    h = hashlib.sha256()
    _feed(h, turbine)
    return h.hexdigest()


def _feed(h: Any, obj: Any) -> None:
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        h.update(type(obj).__name__.encode())
        for f in dataclasses.fields(obj):
            if not f.compare:           # provenance (a turbine's source path, its load report)
                continue
            h.update(f.name.encode())
            _feed(h, getattr(obj, f.name))
    elif isinstance(obj, np.ndarray):
        h.update(str(obj.shape).encode())
        h.update(np.ascontiguousarray(obj, dtype=float).tobytes())
    elif isinstance(obj, dict):
        for k in sorted(obj, key=str):
            h.update(str(k).encode())
            _feed(h, obj[k])
    elif isinstance(obj, (list, tuple)):
        for v in obj:
            _feed(h, v)
    elif isinstance(obj, float) and math.isnan(obj):
        h.update(b"nan")
    else:
        h.update(repr(obj).encode())


class DesignCache:
    """Designs kept per process, keyed on the turbine's content and the design's settings
    (a campaign worker designs a TS controller once, not once per case).

    Parameters
    ----------
    max_items : int
        Entries kept; the oldest goes first (default 16).
    """

    def __init__(self, max_items: int = 16) -> None:
        self.max_items = int(max_items)
        self._items: dict[tuple[Any, ...], Any] = {}
        self._lock = threading.Lock()
        self.hits = 0

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
                return self._items[full]
        value = make()
        with self._lock:
            self._items[full] = value
            while len(self._items) > self.max_items:
                self._items.pop(next(iter(self._items)))
        return value

    def clear(self) -> None:
        """Drop every design."""
        with self._lock:
            self._items.clear()


#: The process-wide cache used by :func:`~mpc_wt.run.run_controller` by default.
DEFAULT_CACHE = DesignCache()


#: Second word of the seed of the wind-evolution field (ASCII "evol"): a stream of its own.
_EVOLUTION_STREAM = 0x65766F6C


@dataclass(frozen=True)
class BuildContext:
    """Everything a kind's ``build`` may use.

    Parameters
    ----------
    turbine : Turbine
        The turbine.
    params : PlantParams
        Its plant parameters.
    op : OperatingPoint
        The trim point the run starts from.
    scenario : Scenario
        The load case.
    field : lidar.WindField
        The wind field of the case (for a LIDAR in the loop).
    cache : DesignCache
        For designs that cost seconds.
    samplers : lidar.SamplerCache, optional
        Keeps the turbulence generator's sampler between the fields of a run and, if the
        caller keeps it, of the next runs.
    """

    turbine: linearize.Turbine
    params: linearize.PlantParams
    op: linearize.OperatingPoint
    scenario: Scenario
    field: Any
    cache: DesignCache = DEFAULT_CACHE
    samplers: lidar.SamplerCache | None = None

    def lidar_field(self, distance: float) -> Any:
        """The field a LIDAR focused ``distance`` upstream measures: the case's field evolved
        over that distance with Simley and Pao's coherence (:func:`lidar.evolve_field`; its
        independent part seeded from the case's seed, so every kind sees the same wind).

        A turbulent case's evolved field is made from the case's spec and seed
        (:func:`lidar.generate_evolved_field`), not from ``field``: so the case's field needs
        only the plant's u (``field_components="u"``), and the two are never held side by side
        with the case's v and w (a 600 s mpc-lidar run peaks some 300 MB lower). With frozen
        turbulence (distance 0) a u-only case field is made whole again from its seed.

        Parameters
        ----------
        distance : float
            [m], >= 0; 0 (or a steady case) gives the field itself: frozen turbulence.

        Returns
        -------
        lidar.WindField
        """
        if self.scenario.deterministic:
            return self.field
        spec = field_spec(self.turbine, self.scenario)
        if distance == 0.0:
            if set(self.field.meta.get("components", "uvw")) >= set("uvw"):
                return self.field
            # the case's field was made with u only (the plant's): the whole field, whose u
            # is the same
            return dataclasses.replace(lidar.generate_field(spec, self.scenario.seed,
                                                            samplers=self.samplers),
                                       meta=self.field.meta | {"components": "uvw"})
        # made without the case's field: it is generate_evolved_field(spec, seed, ...), the
        # evolution of generate_field(spec, seed) to single-precision rounding
        seed = np.random.default_rng([self.scenario.seed, _EVOLUTION_STREAM])
        seen = lidar.generate_evolved_field(spec, self.scenario.seed, distance, seed,
                                            samplers=self.samplers)
        return dataclasses.replace(seen, meta={**self.field.meta, **seen.meta,
                                               "components": "uvw"})


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
    """

    controller: Any
    controller_dt: float | None = None
    preview: Any = None
    meta: dict[str, Any] = field(default_factory=dict)
    power_fraction: float = 1.0

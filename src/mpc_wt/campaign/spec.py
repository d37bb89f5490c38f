"""Campaign specification: a YAML file naming the turbine, the controllers, the load case grid
(mean winds x turbulence x seeds, IEC DLC 1.2 style), the load channels with their Woehler
exponents, the wind distribution and the lifetime; validated on load (errors name the key).

A campaign expands into *cases*, one simulation each. A case's hash covers only what its
simulation depends on (turbine files, controller settings, wind, seed, turbulence, duration,
shear, LIDAR), so editing the spec invalidates only the cases it touches; its *assessment*
hash covers the channels and the discarded transient, which are recomputed from the stored
time series without simulating again.
"""
from __future__ import annotations

import copy
import dataclasses
import hashlib
import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping, Sequence

import numpy as np
import yaml

import linearize
from mpc_wt.campaign.checksum import file_sha256
from mpc_wt.errors import SpecError
from mpc_wt.simulation.scenario import (
    MAX_DURATION_S,
    Scenario,
    check_condition,
    check_turbulence,
    is_deterministic,
)

__all__ = ["SpecError", "CampaignSpec", "ControllerSpec", "Case", "LoadCase", "WindFile",
           "DLC_DEFAULTS", "FILE_MARGIN_S", "load_spec", "spec_from_dict"]


_TOP_KEYS = {"name", "description", "turbine", "duration", "transient", "turbulence",
             "shear_exponent", "winds", "seeds", "lidar", "controllers", "channels",
             "wind_distribution", "lifetime_years", "reference", "report", "plugins",
             "del_convention", "load_cases", "iec_class", "supervisor", "ultimate_channels",
             "plant"}
#: A controller entry's own keys; any other key is an option of the controller's kind.
_CONTROLLER_KEYS = {"name", "controller", "winds", "seeds", "turbulence", "label", "options",
                    "mpc_options", "retrofit_options", "dlcs"}
_LOAD_CASE_KEYS = {"dlc", "condition", "winds", "seeds", "signs", "turbulence", "family",
                   "fatigue", "duration", "transient", "event_at", "supervisor", "extrapolate",
                   "label", "wind_files"}
#: The keys a load case of wind files does not take: its files are its winds and seeds.
_GRID_KEYS = ("winds", "seeds", "signs", "event_at", "condition")
#: Seconds of a wind file left after a case's run by default: the time a LIDAR 54 m ahead
#: needs at 2.7 m/s (the same margin as ``mpcwt simulate --wind-file``).
FILE_MARGIN_S = 20.0
#: IEC 61400-1 ed. 3 table 2: the partial safety factor family of a DLC's ultimate loads
#: ("N" normal, "A" abnormal) and whether its runs count for fatigue. DLC 1.2's turbulent runs
#: also give its ultimate loads (the runs of DLC 1.1, normal family).
DLC_DEFAULTS: dict[str, tuple[str, bool]] = {
    "1.1": ("N", False), "1.2": ("N", True), "1.3": ("N", False), "1.4": ("N", False),
    "1.5": ("N", False), "2.1": ("N", False), "2.2": ("A", False), "2.3": ("A", False),
    "2.4": ("N", True), "3.2": ("N", False), "3.3": ("N", False), "4.2": ("N", False),
    "5.1": ("N", False)}
#: The supervisor's settings a spec may give (:class:`mpc_wt.controllers.supervisor.Supervisor`); the
#: times are counted from the end of the case's transient. ``pitch_fault_azimuth_deg`` may be a
#: list: the load case's seeds take its azimuths in turn.
_SUPERVISOR_KEYS = {"overspeed", "shutdown_at", "grid_loss_at", "pitch_rate", "torque_ramp_s",
                    "pitch_fault_at", "pitch_fault", "pitch_fault_blade", "fault_detect_s",
                    "pitch_fault_azimuth_deg"}
#: The supervisor settings that may be given one per seed.
_PER_SEED_KEYS = ("pitch_fault_azimuth_deg",)
_REPORT_KEYS = {"paper", "notes", "psd_wind", "cs_wind", "sweep", "title"}


#: the most seeds per wind a spec may give, and the most cases a campaign may hold (a spec
#: over them is a mistake, not a study: 100,000 cases of 600 s take months on 2 cores)
MAX_SEEDS = 1000

#: At most this many mean winds in a load case.
MAX_WINDS = 1000

#: The largest seed: the campaign index stores seeds as SQLite integers (64-bit signed).
MAX_SEED = 2**63 - 1

#: The shortest assessed time of a case after its transient [s]: the assessment's floor
#: (:func:`mpc_wt.campaign.task.assess_case` refuses less).
MIN_ASSESSED_S = 10.0
MAX_CASES = 100_000


def _fail(key: str, msg: str) -> SpecError:
    return SpecError(f"campaign spec: {key}: {msg}")


#: what a name that becomes part of a file or folder name may hold
NAME_CHARS = "letters, digits and - _ . + (not starting with a dot), at most 100 characters"


def check_name(key: str, value: Any, fail: Any = None) -> str:
    """A name a spec sets that becomes part of a file or folder name (the campaign's, a
    controller's, a load case's): letters, digits and ``-_.+``, not starting with a dot, at
    most 100 characters, so that no name reaches outside its output folder.

    Parameters
    ----------
    key : str
        The spec key, for the error.
    value : Any
        The name.
    fail : callable, optional
        ``fail(key, message) -> Exception`` (default: a campaign spec's).

    Returns
    -------
    str
        The name.

    Raises
    ------
    SpecError
        Naming the key, the value and what is allowed.
    """
    text = str(value).strip() if isinstance(value, (str, int, float)) else None
    if not text or len(text) > 100 or text.startswith(".") or not all(
            ch.isascii() and (ch.isalnum() or ch in "-_.+") for ch in text):
        raise (fail or _fail)(key, f"must be a name of {NAME_CHARS}; got {value!r}")
    return text


def _number(key: str, val: Any, lo: float | None = None, hi: float | None = None,
            lo_open: bool = False) -> float:
    """A finite number within bounds (:func:`linearize.validate.check_number`), or a
    :class:`SpecError` naming the key."""
    from linearize.validate import check_number

    try:
        return check_number(key, val, lo=lo, hi=hi, lo_open=lo_open)
    except ValueError as err:
        raise _fail(key, str(err).removeprefix(f"{key} ")) from None


def _assessed(key: str, val: Any) -> float:
    """A case's assessed duration after its transient [s]: at least :data:`MIN_ASSESSED_S`,
    at most :data:`MAX_DURATION_S`."""
    d = _number(key, val, 0.0, MAX_DURATION_S, lo_open=True)
    if d < MIN_ASSESSED_S:
        raise _fail(key, f"the time assessed after the transient must be at least "
                         f"{MIN_ASSESSED_S:g} s (the fatigue and statistics need it), got {d:g}")
    return d


def _events_within(key: str, sup: Mapping[str, Any], duration: float) -> None:
    """Refuse a supervisor event (``*_at``, counted from the transient's end) at or after the
    end of a case's assessed time: it would not happen."""
    for k, at in sup.items():
        if k.endswith("_at") and isinstance(at, (int, float)) and at >= duration:
            raise _fail(f"{key}.{k}", f"{at:g} s is at or after the case's end ({duration:g} s "
                                      f"after the transient): the event would not happen")


def _winds(key: str, val: Any) -> tuple[float, ...]:
    """A list of mean winds [m/s], or {start, stop, step} (stop included)."""
    if isinstance(val, Mapping):
        extra = set(val) - {"start", "stop", "step"}
        if extra or {"start", "stop"} - set(val):
            raise _fail(key, f"a range needs start, stop and optionally step; got keys "
                             f"{sorted(val)}")
        a = _number(f"{key}.start", val["start"], 0.0, 60.0, lo_open=True)
        b = _number(f"{key}.stop", val["stop"], a, 60.0)
        s = _number(f"{key}.step", val.get("step", 1.0), 0.0, lo_open=True)
        n = int(math.floor((b - a) / s + 1e-9)) + 1
        if n > MAX_WINDS:
            raise _fail(f"{key}.step", f"{s:g} m/s from {a:g} to {b:g} m/s makes {n} mean winds, "
                                       f"more than {MAX_WINDS}")
        out = [round(a + i * s, 6) for i in range(n)]
    elif isinstance(val, (list, tuple)):
        if len(val) > MAX_WINDS:
            raise _fail(key, f"at most {MAX_WINDS} mean winds, got {len(val)}")
        out = [_number(f"{key}[{i}]", v, 0.0, 60.0, lo_open=True) for i, v in enumerate(val)]
    else:
        out = [_number(key, val, 0.0, 60.0, lo_open=True)]
    if not out:
        raise _fail(key, "no mean wind given")
    if len(set(out)) != len(out):
        raise _fail(key, f"repeated mean winds {out}")
    return tuple(sorted(float(v) for v in out))


def _seeds(key: str, val: Any) -> tuple[int, ...]:
    """A count n (seeds 1..n) or a list of seeds."""
    if isinstance(val, bool):
        raise _fail(key, f"must be a count or a list of integers, got {val!r}")
    if isinstance(val, int):
        if not 1 <= val <= MAX_SEEDS:
            raise _fail(key, f"a seed count must be between 1 and {MAX_SEEDS}, got {val}")
        return tuple(range(1, val + 1))
    if isinstance(val, (list, tuple)) and val:
        if not all(isinstance(s, int) and not isinstance(s, bool) and s >= 0 for s in val):
            raise _fail(key, f"seeds must be integers >= 0, got {list(val)}")
        big = [s for s in val if s > MAX_SEED]
        if big:
            raise _fail(key, f"seeds must be at most 2**63 - 1 = {MAX_SEED}, got {big[0]}")
        if len(set(val)) != len(val):
            raise _fail(key, f"repeated seeds {list(val)}")
        if len(val) > MAX_SEEDS:
            raise _fail(key, f"at most {MAX_SEEDS} seeds, got {len(val)}")
        return tuple(val)
    raise _fail(key, f"must be a count >= 1 or a non-empty list of integers, got {val!r}")


def _turbulence(key: str, val: Any) -> tuple[str | float, ...]:
    """IEC classes "A"/"B"/"C", intensities in (0, 1), or "steady"."""
    vals = list(val) if isinstance(val, (list, tuple)) else [val]
    out: list[str | float] = []
    for i, v in enumerate(vals):
        k = f"{key}[{i}]" if isinstance(val, (list, tuple)) else key
        try:
            out.append(check_turbulence(v))
        except ValueError as err:
            raise _fail(k, str(err).replace("turbulence ", "", 1)) from None
    if not out or len(set(out)) != len(out):
        raise _fail(key, f"needs distinct values, got {vals}")
    return tuple(out)


def turbulence_tag(turb: str | float) -> str:
    """A file-name-safe tag: the class letter or the intensity in percent (``ti12``)."""
    return turb if isinstance(turb, str) else f"ti{100 * turb:g}"


@dataclass(frozen=True)
class ControllerSpec:
    """One controller of a campaign.

    Parameters
    ----------
    name : str
        Label in the index, the file names and the report (letters, digits, ``-_.+``).
    controller : str
        A registered controller name (``baseline``, ``mpc-lidar``, ``ts``, ``derate80+ibc``
        ...; :func:`mpc_wt.registry.kinds`).
    options : dict
        The kind's options as given (checked by the registry when the spec loads), e.g.
        ``apc_frequency`` [Hz], ``horizon``, ``lidar``.
    winds, seeds, turbulence : tuple or None
        This controller's own grid (default: the campaign's; not with ``load_cases``).
    label : str, optional
        Text for the report.
    dlcs : tuple of str, optional
        The load cases this controller runs (default all of the spec's ``load_cases``).
    design_hash : str, optional
        SHA-256 over every option of the kind as it resolves now, its defaults included (None
        for a plugin's kind read without its plugin): a case computed under other defaults (an
        upgrade that changed them) is computed again.
    """

    name: str
    controller: str
    options: dict[str, Any] = field(default_factory=dict)
    winds: tuple[float, ...] | None = None
    seeds: tuple[int, ...] | None = None
    turbulence: tuple[str | float, ...] | None = None
    label: str | None = None
    dlcs: tuple[str, ...] | None = None
    design_hash: str | None = None


@dataclass(frozen=True)
class LoadCase:
    """One design load case of a campaign (IEC 61400-1 ed. 3 table 2 style).

    Parameters
    ----------
    dlc : str
        Its name, e.g. "1.3" (:data:`DLC_DEFAULTS` gives the family and the fatigue flag of
        the standard's).
    condition : str
        Wind condition (:data:`lidar.CONDITIONS`; "ntm": the turbulence given).
    winds : tuple of float
        Mean hub-height winds [m/s].
    seeds : tuple of int
        Seeds of a turbulent condition (a deterministic one runs once per sign).
    signs : tuple of int
        Directions of a direction change or shear (deterministic conditions).
    turbulence : tuple
        Classes or intensities (ntm); the category of the site (other conditions).
    family : str
        Partial safety factor family of its ultimate loads: "N", "A" or "T".
    fatigue : bool
        Its runs enter the fatigue, AEP and duty tables.
    duration, transient : float
        Assessed length and discarded start [s].
    event_at : float
        When a transient starts, after the discarded start [s].
    supervisor : dict
        :class:`mpc_wt.controllers.supervisor.Supervisor` settings, times after the discarded start.
    extrapolate : bool
        Extrapolate its maxima statistically to 50 years (turbulent conditions).
    legacy : bool
        The grid of a spec without ``load_cases`` (case ids without the DLC).
    wind_files : tuple of WindFile
        The user's own wind: one case per file instead of the ``winds`` x ``seeds`` grid.
    """

    dlc: str
    condition: str
    winds: tuple[float, ...]
    seeds: tuple[int, ...]
    signs: tuple[int, ...]
    turbulence: tuple[str | float, ...]
    family: str
    fatigue: bool
    duration: float
    transient: float
    event_at: float = 0.0
    supervisor: dict[str, Any] = field(default_factory=dict)
    extrapolate: bool = False
    legacy: bool = False
    wind_files: tuple["WindFile", ...] = ()

    @property
    def deterministic(self) -> bool:
        """True for a condition without turbulence (one run per wind and sign)."""
        return not self.wind_files and is_deterministic(self.condition, self.turbulence)

    def runs_per_wind(self) -> dict[float, int]:
        """How many runs each mean-wind bin holds (per turbulence and controller).

        Returns
        -------
        dict of float to int
            Bin [m/s] -> runs: the seeds (or signs) of a grid, the files of a bin.
        """
        if self.wind_files:
            out: dict[float, int] = {}
            for f in self.wind_files:
                out[f.wind_mps] = out.get(f.wind_mps, 0) + 1
            return out
        n = len(self.signs) if self.deterministic else len(self.seeds)
        return {v: n for v in self.winds}


@dataclass(frozen=True)
class WindFile:
    """One of the user's wind files in a campaign (a load case's ``wind_files``).

    Parameters
    ----------
    path : str
        The file, resolved (TurbSim ``.bts`` or mpc-wt ``.npz``).
    wind_mps : float
        The mean-wind bin its case counts in for the lifetime tables [m/s]: as the spec gives
        it, or the file's mean hub-height wind rounded to a whole m/s. The assessment's, never
        the controller's (the controller sees only the wind the file blows).
    sha256 : str
        The file's content hash (the case hash's: an edited file is a new case).
    duration : float
        Simulated time of its case [s] (the load case's ``duration`` plus its transient, or
        the file's length less :data:`FILE_MARGIN_S`).
    index : int
        1, 2, ... in the spec's order: the case's "seed" in the tables.
    """

    path: str
    wind_mps: float
    sha256: str
    duration: float
    index: int

    @property
    def stem(self) -> str:
        """The file name without its suffix, made safe for a case id."""
        return "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in Path(self.path).stem)


@dataclass(frozen=True)
class Case:
    """One simulation of a campaign (a pure task: these fields -> one result file + metrics).

    Parameters
    ----------
    case_id : str
        ``controller__turbulence__vWIND__sSEED`` (and the load case's forms).
    controller : str
        The controller's label in the spec.
    run_name : str
        The registered kind it runs.
    options : dict
        The kind's options.
    scenario : Scenario
        What the simulator meets: mean wind, turbulence, seed, simulated time (the assessed
        duration plus the transient), shear and the IEC condition.
    transient : float
        Discarded start [s].
    turbine : str
        Packaged name or resolved path.
    turbine_hash : str
        SHA-256 over the turbine's files.
    channels : dict of str to float
        Channel -> Woehler exponent.
    case_hash, assess_hash : str
        Hashes of the simulation and the assessment inputs.
    plugins : tuple of str
        Modules that register controller kinds, imported by the worker.
    plugin_folder : str or None
        The spec's folder, where its plugins are looked for first.
    del_convention : str
        The DEL convention of the assessment (:data:`mpc_wt.assessment.fatigue.DEL_CONVENTIONS`).
    dlc : str
        Its load case.
    supervisor : dict or None
        :class:`mpc_wt.controllers.supervisor.Supervisor` settings (times of simulation) or None.
    family : str
        Partial safety factor family of the load case.
    fatigue : bool
        The case enters the fatigue tables.
    bin_wind_mps : float, optional
        A wind file's bin wind [m/s].
    design_hash : str, optional
        :attr:`ControllerSpec.design_hash` of its controller.
    extremes_of : tuple of str
        Channels beyond ``channels`` whose extremes are recorded (the spec's
        ``ultimate_channels``).
    plant : dict or None
        The simulated plant's effects switched from their defaults (the spec's ``plant``).
    """

    case_id: str
    controller: str
    run_name: str
    options: dict[str, Any]
    scenario: Scenario
    transient: float
    turbine: str
    turbine_hash: str
    channels: dict[str, float]
    case_hash: str
    assess_hash: str
    plugins: tuple[str, ...] = ()
    plugin_folder: str | None = None
    del_convention: str = "range-1hz"
    dlc: str = "1.2"
    supervisor: dict[str, Any] | None = None
    family: str = "N"
    fatigue: bool = True
    bin_wind_mps: float | None = None
    design_hash: str | None = None
    extremes_of: tuple[str, ...] = ()
    plant: dict[str, bool] | None = None

    @property
    def wind_mps(self) -> float:
        """Mean wind [m/s]: the scenario's, or the bin of a wind file's case."""
        if self.scenario.wind_mps is None:
            return float(self.bin_wind_mps)         # type: ignore[arg-type]
        return self.scenario.wind_mps

    @property
    def seed(self) -> int:
        """Seed of the field."""
        return self.scenario.seed

    @property
    def turbulence(self) -> str | float:
        """Class letter or intensity."""
        return self.scenario.turbulence

    @property
    def sign(self) -> int:
        """Direction of a deterministic condition (1 or -1)."""
        return self.scenario.sign

    @property
    def duration(self) -> float:
        """Assessed length [s] (the simulated time less the transient)."""
        return self.scenario.duration - self.transient

    def to_dict(self) -> dict[str, Any]:
        """Plain data for a worker and the store (pickles and JSON-serialises).

        Returns
        -------
        dict
            Every field; ``scenario`` as the dict of its fields.
        """
        out = {k: copy.deepcopy(getattr(self, k)) for k in self.__dataclass_fields__}
        out["scenario"] = dataclasses.asdict(self.scenario)
        return out

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> "Case":
        """A case from :meth:`to_dict`'s data, or from the flat form of stores written before
        a case held its :class:`Scenario` (wind, seed, turbulence, duration, shear, condition
        and sign as fields of their own).

        Parameters
        ----------
        d : mapping
            The data.

        Returns
        -------
        Case
        """
        d = dict(d)
        d["plugins"] = tuple(d.get("plugins", ()))
        d["extremes_of"] = tuple(d.get("extremes_of", ()))
        if "scenario" in d:
            scenario = Scenario(**d.pop("scenario"))
        else:
            cond = d.pop("condition", None) or {}
            d.pop("sign", None)
            scenario = Scenario(d.pop("wind_mps"), d.pop("turbulence"), d.pop("seed"),
                                d.pop("duration") + d["transient"], d.pop("shear_exponent"),
                                **cond)
        return cls(scenario=scenario, **d)


@dataclass(frozen=True)
class CampaignSpec:
    """A validated campaign. Build it with :func:`load_spec` or :func:`spec_from_dict`.

    Parameters
    ----------
    name, description : str
        Name and text of the campaign.
    turbine, turbine_hash : str
        Packaged name or resolved path, and the hash of its files.
    duration, transient : float
        Assessed length and discarded start of each case [s].
    turbulence : tuple
        Classes or intensities.
    shear_exponent : float
        Power-law shear [-].
    winds : tuple of float
        Mean winds [m/s].
    seeds : tuple of int
        Seeds.
    lidar : dict
        LIDAR settings of the kinds that take ``lidar``.
    controllers : tuple of ControllerSpec
        The controllers.
    channels : dict of str to float
        Channel -> Woehler exponent.
    wind_distribution : dict
        Rayleigh or Weibull parameters.
    lifetime_years : float
        Design life [years].
    reference : str
        The reference controller's label.
    report : dict
        Report settings and paper rows.
    raw : dict
        The spec as given.
    source : str, optional
        The spec's file.
    plugins : tuple of str
        Modules that register controller kinds.
    plugin_folder : str or None
        The spec's folder: its plugins and relative library paths are resolved there.
    del_convention : str
        The DEL convention (``range-1hz``, default; ``clemens``; ``pcrunch``): DEL per case and
        the lifetime DEL's weights (Clemens eq 18 weights bins by their counted cycles).
    load_cases : tuple of LoadCase
        The design load cases (one ``legacy`` DLC 1.2 of ``winds`` x ``seeds`` x
        ``turbulence`` when the spec gives none).
    iec_class : str
        Wind turbine class "I", "II" or "III" of the IEC conditions.
    ultimate_channels : tuple of str or None
        The channels the ultimate and governing design loads are read on (None: the fatigue
        ``channels``); e.g. ``shaft_bending_resultant`` for the shaft, whose section sees the
        resultant at some fiber whatever the azimuth.
    plant : dict of str to bool
        The simulated plant's effects switched from their defaults
        (:meth:`linearize.PlantConfig.with_switches`; empty: the default plant).
    """

    name: str
    description: str
    turbine: str
    turbine_hash: str
    duration: float
    transient: float
    turbulence: tuple[str | float, ...]
    shear_exponent: float
    winds: tuple[float, ...]
    seeds: tuple[int, ...]
    lidar: dict[str, Any]
    controllers: tuple[ControllerSpec, ...]
    channels: dict[str, float]
    wind_distribution: dict[str, Any]
    lifetime_years: float
    reference: str
    report: dict[str, Any]
    raw: dict[str, Any]
    source: str | None = None
    plugins: tuple[str, ...] = ()
    plugin_folder: str | None = None
    del_convention: str = "range-1hz"
    load_cases: tuple[LoadCase, ...] = ()
    iec_class: str = "I"
    ultimate_channels: tuple[str, ...] | None = None
    plant: dict[str, bool] = field(default_factory=dict)

    @property
    def ultimate(self) -> tuple[str, ...]:
        """The channels of the ultimate loads: ``ultimate_channels``, else the fatigue ones."""
        return tuple(self.channels) if self.ultimate_channels is None \
            else self.ultimate_channels

    @property
    def extra_extremes(self) -> tuple[str, ...]:
        """The ultimate channels that are not fatigue channels (a case records their
        extremes beside its channels')."""
        return tuple(ch for ch in self.ultimate if ch not in self.channels)

    @property
    def spec_hash(self) -> str:
        """SHA-256 of the canonical spec (with the turbine files' hash)."""
        return _digest({"spec": self.raw, "turbine": self.turbine_hash})

    def resolved_raw(self) -> dict[str, Any]:
        """The spec as given, with its turbine and wind files as resolved paths (and each file's
        bin): what the index keeps, to be read again from any folder.

        Returns
        -------
        dict
        """
        raw = copy.deepcopy(self.raw)
        raw["turbine"] = self.turbine
        for lc, entry in zip(self.load_cases, raw.get("load_cases") or ()):
            if lc.wind_files:
                entry["wind_files"] = [{"file": f.path, "wind": f.wind_mps}
                                       for f in lc.wind_files]
        return raw

    def bin_probabilities(self, winds: Any) -> np.ndarray:
        """The wind distribution's probability of each mean-wind bin
        (:func:`mpc_wt.assessment.fatigue.wind_bin_probabilities`).

        Parameters
        ----------
        winds : array_like
            Bin centres [m/s], ascending.

        Returns
        -------
        ndarray
            One probability per bin.
        """
        from mpc_wt.assessment.fatigue import wind_bin_probabilities

        d, w = self.wind_distribution, np.asarray(winds, float)
        if d["kind"] == "rayleigh":
            return wind_bin_probabilities(w, "rayleigh", mean=d["mean"])
        return wind_bin_probabilities(w, "weibull", shape=d["shape"], scale=d["scale"])

    def controller(self, name: str) -> ControllerSpec:
        """The controller labelled ``name``.

        Parameters
        ----------
        name : str
            A label of the spec.

        Returns
        -------
        ControllerSpec
            That controller.
        """
        for c in self.controllers:
            if c.name == name:
                return c
        raise KeyError(f"no controller {name!r}; controllers are "
                       f"{[c.name for c in self.controllers]}")

    def cases(self) -> list[Case]:
        """Every case of the campaign, in a stable order (controller, load case, turbulence,
        wind, seed or sign).

        Returns
        -------
        list of Case
            Every case.
        """
        out = []
        assess: dict[str, Any] = {"channels": self.channels, "transient": self.transient}
        if self.del_convention != "range-1hz":      # the default keeps older hashes valid
            assess["del_convention"] = self.del_convention
        if self.ultimate_channels is not None:
            assess["ultimate_channels"] = list(self.ultimate_channels)
        for c in self.controllers:
            for lc in self.load_cases:
                if c.dlcs is None or lc.dlc in c.dlcs:
                    out += self._cases_of(c, lc, assess)
        return out

    def _cases_of(self, c: ControllerSpec, lc: LoadCase, assess: dict[str, Any]
                  ) -> list[Case]:
        """The cases of one controller in one load case."""
        a = assess if lc.transient == self.transient else {**assess, "transient": lc.transient}
        sup_all = ({k: (lc.transient + x if k.endswith("_at") else x)
                    for k, x in lc.supervisor.items()} if lc.supervisor else None)
        if lc.wind_files:
            return self._file_cases(c, lc, a, _seed_supervisor(sup_all, 0, (0,)))
        if lc.legacy:
            grid = [(t, v, s, 1) for t in c.turbulence or lc.turbulence
                    for v in c.winds or lc.winds for s in c.seeds or lc.seeds]
        elif lc.deterministic:
            grid = [(t, v, 0, g) for t in lc.turbulence for v in lc.winds for g in lc.signs]
        else:
            grid = [(t, v, s, 1) for t in lc.turbulence for v in lc.winds for s in lc.seeds]
        out = []
        for turb, v, seed, sign in grid:
            sup = _seed_supervisor(sup_all, seed, c.seeds or lc.seeds)
            sim = {"turbine": self.turbine_hash, "controller": c.controller,
                   "options": c.options, "wind_mps": v, "seed": seed, "turbulence": turb,
                   "duration": lc.duration + lc.transient,
                   "shear_exponent": self.shear_exponent}
            cond = None
            if lc.condition != "ntm":
                cond = {"condition": lc.condition, "iec_class": self.iec_class,
                        "sign": sign, "event_at": lc.transient + lc.event_at}
                sim["condition"] = cond
            if sup:
                sim["supervisor"] = sup
            if self.plant:                  # the default plant keeps older hashes valid
                sim["plant"] = self.plant
            out.append(Case(
                case_id=_case_id(c.name, lc, turb, v, seed, sign), controller=c.name,
                run_name=c.controller, options=copy.deepcopy(c.options),
                scenario=Scenario(v, turb, seed, lc.duration + lc.transient,
                                  self.shear_exponent, **(cond or {})),
                transient=lc.transient, turbine=self.turbine,
                turbine_hash=self.turbine_hash, channels=dict(self.channels),
                case_hash=_digest(sim), assess_hash=_digest(a), plugins=self.plugins,
                plugin_folder=self.plugin_folder,
                del_convention=self.del_convention, dlc=lc.dlc,
                supervisor=copy.deepcopy(sup), family=lc.family, fatigue=lc.fatigue,
                design_hash=c.design_hash,
                extremes_of=self.extra_extremes, plant=dict(self.plant) or None))
        return out

    def _file_cases(self, c: ControllerSpec, lc: LoadCase, a: dict[str, Any],
                    sup: dict[str, Any] | None) -> list[Case]:
        """One case per wind file of a load case (assessment ``a``, supervisor ``sup`` as
        :meth:`_cases_of` makes them): the file is the case's wind and seed."""
        out = []
        for f in lc.wind_files:
            sim = {"turbine": self.turbine_hash, "controller": c.controller,
                   "options": c.options, "wind_file": f.sha256, "duration": f.duration}
            if sup:
                sim["supervisor"] = sup
            if self.plant:
                sim["plant"] = self.plant
            out.append(Case(
                case_id=f"{c.name}__dlc{lc.dlc}__file-{f.stem}__v{f.wind_mps:g}",
                controller=c.name, run_name=c.controller, options=copy.deepcopy(c.options),
                scenario=Scenario(turbulence=lc.turbulence[0], seed=f.index,
                                  duration=f.duration, wind_file=f.path),
                transient=lc.transient, turbine=self.turbine, turbine_hash=self.turbine_hash,
                channels=dict(self.channels), case_hash=_digest(sim), assess_hash=_digest(a),
                plugins=self.plugins, plugin_folder=self.plugin_folder,
                del_convention=self.del_convention, dlc=lc.dlc,
                supervisor=copy.deepcopy(sup), family=lc.family, fatigue=lc.fatigue,
                bin_wind_mps=f.wind_mps, design_hash=c.design_hash,
                extremes_of=self.extra_extremes, plant=dict(self.plant) or None))
        return out


def _case_id(ctl: str, lc: LoadCase, turb: str | float, v: float, seed: int,
             sign: int) -> str:
    """``ctl__TURB__vV__sS`` (a spec without load cases), ``ctl__dlcD__[COND-]TURB__vV__sS``
    (turbulent) or ``ctl__dlcD__COND__vV__pos|neg`` (deterministic)."""
    if lc.legacy:
        return f"{ctl}__{turbulence_tag(turb)}__v{v:g}__s{seed}"
    if lc.deterministic:
        return f"{ctl}__dlc{lc.dlc}__{lc.condition}__v{v:g}__{'pos' if sign > 0 else 'neg'}"
    cond = "" if lc.condition == "ntm" else f"{lc.condition}-"
    return f"{ctl}__dlc{lc.dlc}__{cond}{turbulence_tag(turb)}__v{v:g}__s{seed}"


def _digest(obj: Any) -> str:
    return hashlib.sha256(json.dumps(obj, sort_keys=True, default=str).encode()).hexdigest()


def turbine_files_hash(turbine: str, base: Path | None = None) -> tuple[str, str]:
    """(resolved turbine reference, SHA-256 over its files): a packaged name or a path to a
    turbine file or folder (relative paths against ``base``, the spec's folder)."""
    import linearize

    if turbine in linearize.available_turbines():
        from importlib import resources

        root = resources.files("linearize") / "data" / turbine
        with resources.as_file(root) as p:
            folder, ref = Path(p), turbine
    else:
        p = Path(turbine)
        if not p.is_absolute() and base is not None:
            p = base / p
        if not p.exists():
            raise _fail("turbine", f"{turbine!r} is neither a packaged turbine "
                                   f"{linearize.available_turbines()} nor an existing path")
        folder = p if p.is_dir() else p.parent
        ref = str(p.resolve())
        try:
            loaded = linearize.load_turbine(p)
        except Exception as err:  # noqa: BLE001 - any loader error is reported with the key
            raise _fail("turbine", f"{turbine!r} does not load: {err}") from err
        if p.suffix.lower() == ".fst":      # a deck reads files outside its folder: hash what
            from mpc_wt.registry.context import turbine_key
            return ref, turbine_key(loaded)
    h = hashlib.sha256()
    for f in sorted(folder.rglob("*")):
        if f.is_file() and "__pycache__" not in f.parts:
            h.update(str(f.relative_to(folder)).encode())
            h.update(f.read_bytes())
    return ref, h.hexdigest()


def _controller_options(key: str, raw: Mapping[str, Any], run_name: str,
                        lidar: dict[str, Any], plugin_kinds: bool = False) -> dict[str, Any]:
    """The entry's controller options, checked by the registry: every key that is not one of
    the campaign's own (name, grid, label) is an option of the kind; ``options:`` holds them
    too, and the groups ``mpc_options`` / ``retrofit_options`` of older specs are flattened.
    The campaign's ``lidar`` settings are the defaults of a kind that takes ``lidar``.
    ``plugin_kinds``: the spec's plugins were not imported (reading a stored campaign), so a
    kind the registry does not know is taken as a plugin's, its options unchecked."""
    from mpc_wt.errors import OptionsError
    from mpc_wt.registry.registry import resolve

    opts: dict[str, Any] = {}
    for group in ("options", "mpc_options", "retrofit_options"):
        if group in raw:
            if not isinstance(raw[group], Mapping):
                raise _fail(f"{key}.{group}", f"must be a mapping, got {raw[group]!r}")
            opts.update(raw[group])
    opts.update({k: v for k, v in raw.items() if k not in _CONTROLLER_KEYS})
    try:
        try:
            sel = resolve(run_name)
        except ValueError:
            if plugin_kinds:
                return copy.deepcopy(opts), None
            raise
        if "lidar" in sel.option_names() and (lidar or "lidar" in opts):
            extra = opts.get("lidar", {})
            if not isinstance(extra, Mapping):
                raise _fail(f"{key}.lidar", f"must be a mapping, got {extra!r}")
            opts["lidar"] = {**lidar, **extra}
        resolved = sel.options(opts)
    except OptionsError as err:
        raise _fail(f"{key}.{err.key}", str(err)) from err
    except ValueError as err:
        raise _fail(f"{key}.controller", str(err)) from err
    return copy.deepcopy(opts), _digest([o.to_dict() for o in resolved])


def _controller(i: int, raw: Any, lidar: dict[str, Any],
                plugin_kinds: bool = False) -> ControllerSpec:
    key = f"controllers[{i}]"
    if isinstance(raw, str):
        raw = {"name": raw, "controller": raw}
    if not isinstance(raw, Mapping):
        raise _fail(key, f"must be a controller name or a mapping, got {raw!r}")
    name = raw.get("name", raw.get("controller"))
    if not isinstance(name, str):
        raise _fail(f"{key}.name", f"must be a name of {NAME_CHARS}; got {name!r}")
    name = check_name(f"{key}.name", name)
    run_name = str(raw.get("controller", name))
    opts, design = _controller_options(key, raw, run_name, lidar, plugin_kinds)
    dlcs = raw.get("dlcs")
    if dlcs is not None and (not isinstance(dlcs, list) or not dlcs
                             or not all(isinstance(d, (str, int, float)) for d in dlcs)):
        raise _fail(f"{key}.dlcs", f"must be a non-empty list of load case names, got {dlcs!r}")
    for j, d in enumerate(dlcs or ()):
        check_name(f"{key}.dlcs[{j}]", d)
    return ControllerSpec(
        name=name, controller=run_name, options=opts,
        dlcs=None if dlcs is None else tuple(str(d) for d in dlcs),
        winds=_winds(f"{key}.winds", raw["winds"]) if "winds" in raw else None,
        seeds=_seeds(f"{key}.seeds", raw["seeds"]) if "seeds" in raw else None,
        turbulence=(_turbulence(f"{key}.turbulence", raw["turbulence"])
                    if "turbulence" in raw else None),
        label=str(raw["label"]) if "label" in raw else None, design_hash=design)


def _lidar(key: str, raw: Any) -> dict[str, Any]:
    """The campaign's LIDAR settings (defaults of the kinds that take ``lidar``), checked by
    :class:`mpc_wt.kinds.LidarOptions`."""
    from mpc_wt.errors import OptionsError
    from mpc_wt.kinds import LidarOptions

    if not isinstance(raw, Mapping):
        raise _fail(key, f"must be a mapping, got {raw!r}")
    try:
        opts = LidarOptions.from_dict(raw, prefix=f"{key}.")
        return {k: getattr(opts, k) for k in raw}
    except OptionsError as err:
        raise _fail(err.key, str(err)) from err


def _keys_of(key: str, raw: Any, allowed: set[str]) -> None:
    """``raw`` is a mapping whose keys are all ``allowed``, or a :class:`SpecError`."""
    if not isinstance(raw, Mapping):
        raise _fail(key, f"must be a mapping, got {raw!r}")
    extra = set(raw) - allowed
    if extra:
        raise _fail(f"{key}.{sorted(extra)[0]}", f"unknown key; allowed: {sorted(allowed)}")


def _seed_supervisor(sup: dict[str, Any] | None, seed: int, seeds: Sequence[int]
                     ) -> dict[str, Any] | None:
    """A load case's supervisor settings for one of its seeds: a per-seed list
    (:data:`_PER_SEED_KEYS`) gives the seed's entry, the seeds taking the list in turn."""
    if not sup:
        return sup
    seeds = list(seeds)
    i = seeds.index(seed) if seed in seeds else 0
    return {k: (v[i % len(v)] if k in _PER_SEED_KEYS and isinstance(v, list) else v)
            for k, v in sup.items()}


def _supervisor(key: str, raw: Any, turbine: str) -> dict[str, Any]:
    """Supervisor settings (:data:`_SUPERVISOR_KEYS`), checked by
    :class:`mpc_wt.controllers.supervisor.Supervisor` itself on the campaign's turbine."""
    from mpc_wt.campaign.task import load_case_turbine
    from mpc_wt.controllers.supervisor import Supervisor

    if raw is None:
        return {}
    _keys_of(key, raw, _SUPERVISOR_KEYS)
    raw = dict(raw)
    per_seed = {k: list(raw.pop(k)) for k in _PER_SEED_KEYS
                if isinstance(raw.get(k), (list, tuple))}
    for k, vs in per_seed.items():
        if not vs:
            raise _fail(f"{key}.{k}", "must be a value or a non-empty list (one per seed in "
                                      "turn), got []")
    tb = load_case_turbine(turbine)
    try:
        Supervisor.check_settings(tb, **raw)
        for k, vs in per_seed.items():
            for v in vs:
                Supervisor.check_settings(tb, **{**raw, k: v})
    except (TypeError, ValueError) as err:
        raise _fail(key, str(err)) from err
    out = {k: (v if v is None or k == "pitch_fault" else
               int(v) if k == "pitch_fault_blade" else float(v)) for k, v in raw.items()}
    out.update({k: [float(x) for x in vs] for k, vs in per_seed.items()})
    return out


def _load_case(i: int, raw: Any, top: Mapping[str, Any]) -> LoadCase:
    """One entry of ``load_cases``, its defaults from the spec's top level (``top``)."""
    import lidar

    key = f"load_cases[{i}]"
    _keys_of(key, raw, _LOAD_CASE_KEYS)
    dlc = raw.get("dlc")
    if not isinstance(dlc, (str, int, float)) or not str(dlc).strip():
        raise _fail(f"{key}.dlc", f"must name the load case, e.g. '1.3', got {dlc!r}")
    dlc = check_name(f"{key}.dlc", dlc)
    cond = str(raw.get("condition", "ntm")).lower()
    if cond not in lidar.CONDITIONS:
        raise _fail(f"{key}.condition", f"must be one of {sorted(lidar.CONDITIONS)}, got "
                                        f"{raw.get('condition')!r}")
    fam0, fat0 = DLC_DEFAULTS.get(dlc, ("N", False))
    family = raw.get("family", fam0)
    if family not in ("N", "A", "T"):
        raise _fail(f"{key}.family", f"must be 'N', 'A' or 'T' (IEC 61400-1 table 3), got "
                                     f"{family!r}")
    if "wind_files" in raw:
        return _file_load_case(key, raw, top, dlc, family, fat0)
    turb = _turbulence(f"{key}.turbulence", raw.get("turbulence", top["turbulence"]))
    try:
        check_condition(cond, turb)
    except ValueError as err:
        raise _fail(f"{key}.turbulence", str(err)) from None
    turbulent = not is_deterministic(cond, turb)
    signs = raw.get("signs", [1])
    if not isinstance(signs, list) or not signs or any(g not in (1, -1) for g in signs) \
            or len(set(signs)) != len(signs):
        raise _fail(f"{key}.signs", f"must be a list of distinct 1 and -1, got {signs!r}")
    if "winds" not in raw and "winds" not in top:
        raise _fail(f"{key}.winds", "missing (no top-level winds to default to)")
    extrapolate = raw.get("extrapolate", False)
    if not isinstance(extrapolate, bool) or (extrapolate and not turbulent):
        raise _fail(f"{key}.extrapolate", f"must be true or false, and true only for a "
                                          f"turbulent condition (ntm, etm), got {extrapolate!r}")
    fatigue = raw.get("fatigue", fat0 and turbulent)
    if not isinstance(fatigue, bool):
        raise _fail(f"{key}.fatigue", f"must be true or false, got {fatigue!r}")
    sup = {**top["supervisor"], **_supervisor(f"{key}.supervisor", raw.get("supervisor"),
                                              top["turbine"])}
    duration = _assessed(f"{key}.duration", raw.get(
        "duration", top["duration"] if turbulent else 60.0))
    _events_within(f"{key}.supervisor", sup, duration)
    return LoadCase(
        dlc=dlc, condition=cond, winds=_winds(f"{key}.winds", raw.get("winds", top.get(
            "winds"))), seeds=_seeds(f"{key}.seeds", raw.get("seeds", top["seeds"])),
        signs=tuple(int(g) for g in signs), turbulence=turb, family=family, fatigue=fatigue,
        duration=duration,
        transient=_number(f"{key}.transient", raw.get("transient", top["transient"]), 0.0),
        event_at=_number(f"{key}.event_at", raw.get("event_at", 10.0), 0.0),
        supervisor=sup, extrapolate=extrapolate)


def _file_load_case(key: str, raw: Mapping[str, Any], top: Mapping[str, Any], dlc: str,
                    family: str, fat0: bool) -> LoadCase:
    """A load case of the user's wind files: one case per file, binned by its mean wind."""
    given = [k for k in _GRID_KEYS if k in raw]
    if given:
        raise _fail(f"{key}.{given[0]}", "not with wind_files: each file is a case's wind "
                                         "(its mean wind, turbulence and seed are the file's)")
    turb = _turbulence(f"{key}.turbulence", raw.get("turbulence", top["turbulence"]))
    if len(turb) != 1:
        raise _fail(f"{key}.turbulence", f"with wind_files, one class or intensity that labels "
                                         f"the files in the tables, got {list(turb)}")
    transient = _number(f"{key}.transient", raw.get("transient", top["transient"]), 0.0)
    duration = (None if "duration" not in raw else _assessed(f"{key}.duration",
                                                             raw["duration"]))
    files = _wind_files(f"{key}.wind_files", raw["wind_files"], top.get("base"), transient,
                        duration)
    extrapolate = raw.get("extrapolate", False)
    fatigue = raw.get("fatigue", fat0)
    for k, v in (("extrapolate", extrapolate), ("fatigue", fatigue)):
        if not isinstance(v, bool):
            raise _fail(f"{key}.{k}", f"must be true or false, got {v!r}")
    sup = {**top["supervisor"], **_supervisor(f"{key}.supervisor", raw.get("supervisor"),
                                              top["turbine"])}
    _events_within(f"{key}.supervisor", sup, min(f.duration for f in files) - transient)
    return LoadCase(
        dlc=dlc, condition="ntm", winds=tuple(sorted({f.wind_mps for f in files})),
        seeds=tuple(f.index for f in files), signs=(1,), turbulence=turb, family=family,
        fatigue=fatigue, duration=min(f.duration for f in files) - transient,
        transient=transient, supervisor=sup, extrapolate=extrapolate, wind_files=files)


def _wind_files(key: str, raw: Any, base: Path | None, transient: float,
                duration: float | None) -> tuple[WindFile, ...]:
    """The entries of ``wind_files``: a path, or {file, wind} to set the file's mean-wind bin
    [m/s]; relative paths against the spec's folder. Each file is read once here: its length
    must hold the transient and the duration."""
    import lidar
    from mpc_wt.simulation.scenario import check_wind_file, read_wind_file

    if not isinstance(raw, list) or not raw:
        raise _fail(key, f"must be a non-empty list of files (or {{file, wind}} entries), "
                         f"got {raw!r}")
    out: list[WindFile] = []
    for i, entry in enumerate(raw):
        k = f"{key}[{i}]"
        if isinstance(entry, Mapping):
            _keys_of(k, entry, {"file", "wind"})
            if "file" not in entry:
                raise _fail(f"{k}.file", "missing (the wind file's path)")
            name, wind = entry["file"], entry.get("wind")
        else:
            name, wind = entry, None
        if not isinstance(name, (str, Path)) or not str(name).strip():
            raise _fail(k, f"must be a file's path, got {name!r}")
        p = Path(str(name)).expanduser()
        if not p.is_absolute() and base is not None:
            p = base / p
        try:
            p = check_wind_file(p).resolve()
            f = read_wind_file(str(p))
        except (ValueError, lidar.FieldFileError) as err:
            raise _fail(k, str(err)) from None
        length = float(f.t[-1] - f.t[0])
        sim = length - FILE_MARGIN_S if duration is None else duration + transient
        if sim < transient + MIN_ASSESSED_S or sim > length:
            need = (f"the transient {transient:g} s, {MIN_ASSESSED_S:g} s to assess and "
                    f"{FILE_MARGIN_S:g} s" if duration is None
                    else f"the transient and duration, {duration + transient:g} s")
            raise _fail(k, f"{str(name)!r} holds {length:g} s of wind; it must hold {need}")
        v = (round(float(f.mean_speed)) if wind is None else
             _number(f"{k}.wind", wind, 0.0, 60.0, lo_open=True))
        if v <= 0:
            raise _fail(k, f"{str(name)!r}: its mean wind {float(f.mean_speed):g} m/s rounds "
                           f"to no bin; give {{file, wind}}")
        out.append(WindFile(path=str(p), wind_mps=float(v), sha256=file_sha256(p),
                            duration=sim, index=i + 1))
    stems = [f.stem for f in out]
    dup = sorted({s for s in stems if stems.count(s) > 1})
    if dup:
        raise _fail(key, f"files of the same name {dup}: a case is named by its file; rename "
                         f"them")
    return tuple(out)


def _load_cases(raw: Mapping[str, Any], duration: float, transient: float,
                turbine: str, base: Path | None = None) -> tuple[LoadCase, ...]:
    """The spec's load cases, or the one legacy DLC 1.2 of a spec without them."""
    sup = _supervisor("supervisor", raw.get("supervisor"), turbine)
    top = {"turbulence": raw.get("turbulence", "A"), "seeds": raw.get("seeds", 1),
           "duration": duration, "transient": transient, "supervisor": sup,
           "turbine": turbine, "base": base}
    if "winds" in raw:
        top["winds"] = raw["winds"]
    if "load_cases" not in raw:
        if "winds" not in raw:
            raise _fail("winds", "missing (required: name, winds or load_cases, controllers)")
        _events_within("supervisor", sup, duration)
        return (LoadCase(dlc="1.2", condition="ntm", winds=_winds("winds", raw["winds"]),
                         seeds=_seeds("seeds", top["seeds"]), signs=(1,),
                         turbulence=_turbulence("turbulence", top["turbulence"]), family="N",
                         fatigue=True, duration=duration, transient=transient,
                         supervisor=sup, legacy=True),)
    lcs = raw["load_cases"]
    if not isinstance(lcs, list) or not lcs:
        raise _fail("load_cases", f"must be a non-empty list, got {lcs!r}")
    out = tuple(_load_case(i, lc, top) for i, lc in enumerate(lcs))
    names = [lc.dlc for lc in out]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise _fail("load_cases", f"repeated dlc names {dup}; give each a distinct name "
                                  f"(e.g. '2.3a')")
    return out


def _distribution(raw: Any) -> dict[str, Any]:
    key = "wind_distribution"
    if not isinstance(raw, Mapping):
        raise _fail(key, f"must be a mapping, got {raw!r}")
    kind = raw.get("kind", "rayleigh")
    if kind == "rayleigh":
        extra = set(raw) - {"kind", "mean"}
        if extra:
            raise _fail(f"{key}.{sorted(extra)[0]}", "unknown key; rayleigh takes: kind, mean")
        return {"kind": kind, "mean": _number(f"{key}.mean", raw.get("mean", 10.0), 0.0,
                                              lo_open=True)}
    if kind == "weibull":
        extra = set(raw) - {"kind", "scale", "shape"}
        if extra:
            raise _fail(f"{key}.{sorted(extra)[0]}", "unknown key; weibull takes: kind, scale, "
                                                     "shape")
        if "scale" not in raw:
            raise _fail(f"{key}.scale", "weibull needs scale [m/s]")
        return {"kind": kind,
                "scale": _number(f"{key}.scale", raw["scale"], 0.0, lo_open=True),
                "shape": _number(f"{key}.shape", raw.get("shape", 2.0), 0.0, lo_open=True)}
    raise _fail(f"{key}.kind", f"must be 'rayleigh' or 'weibull', got {kind!r}")


def _convention(raw: Any) -> str:
    from mpc_wt.assessment.fatigue import DEL_CONVENTIONS

    if raw not in DEL_CONVENTIONS:
        raise _fail("del_convention", f"must be one of {list(DEL_CONVENTIONS)}, got {raw!r}")
    return str(raw)


def _plugins(raw: Any, load: bool = True, base: Path | None = None) -> tuple[str, ...]:
    """Modules that register controller kinds, looked for first in the spec's folder ``base``
    and imported here (unless ``load`` is False) and in every worker."""
    from mpc_wt.registry.registry import load_plugins

    if not isinstance(raw, list) or not all(isinstance(m, str) and m for m in raw):
        raise _fail("plugins", f"must be a list of module names, got {raw!r}")
    if not load:
        return tuple(raw)
    try:
        load_plugins(raw, base)
    except ImportError as err:
        raise _fail("plugins", str(err)) from err
    return tuple(raw)


def _known_channels() -> set[str]:
    """The plant's channels a campaign assesses: outputs, states, inputs and the shaft's."""
    import linearize
    from mpc_wt.simulation.results import DERIVED_UNITS

    return {*linearize.OUTPUT_NAMES, *linearize.STATE_NAMES, *linearize.INPUT_NAMES,
            *DERIVED_UNITS}


def _ultimate_channels(raw: Any) -> tuple[str, ...] | None:
    """The ``ultimate_channels`` list, checked (None when absent)."""
    if raw is None:
        return None
    if isinstance(raw, str) or not isinstance(raw, Sequence) or not raw:
        raise _fail("ultimate_channels", f"must be a non-empty list of channel names, got "
                                         f"{raw!r}")
    known = _known_channels()
    for i, k in enumerate(raw):
        if k not in known:
            raise _fail(f"ultimate_channels[{i}]", f"unknown channel {k!r}; channels are "
                                                   f"{sorted(known)}")
    if len(set(raw)) != len(raw):
        raise _fail("ultimate_channels", f"names a channel twice: {list(raw)}")
    return tuple(str(k) for k in raw)


def _description(desc: Any) -> str:
    if not isinstance(desc, str):
        raise _fail("description", f"must be a string, got {desc!r}")
    return desc


def _plant(raw: Any) -> dict[str, bool]:
    """The ``plant`` mapping of effect switches, checked (empty when absent)."""
    if raw is None:
        return {}
    try:
        linearize.PlantConfig().with_switches(raw)
    except ValueError as err:
        raise _fail("plant", str(err)) from None
    return {str(k): bool(v) for k, v in dict(raw).items()}


def _channels(raw: Any) -> dict[str, float]:
    """Channel -> Woehler exponent (default :data:`mpc_wt.assessment.series.DEFAULT_CHANNELS`)."""
    from mpc_wt.assessment.series import DEFAULT_CHANNELS

    chans_raw = DEFAULT_CHANNELS if raw is None else raw
    if not isinstance(chans_raw, Mapping) or not chans_raw:
        raise _fail("channels", "must be a non-empty mapping of channel name to Woehler "
                                "exponent m")
    chans = {}
    known = _known_channels()
    for k, m in chans_raw.items():
        if k not in known:
            raise _fail(f"channels.{k}", f"unknown channel; channels are {sorted(known)}")
        chans[str(k)] = _number(f"channels.{k}", m, 0.0, 30.0, lo_open=True)
    return chans


def _report(report: Any, names: list[str], chans: Mapping[str, float]) -> dict[str, Any]:
    """The report settings and the paper rows, checked."""
    if not isinstance(report, Mapping):
        raise _fail("report", f"must be a mapping, got {report!r}")
    extra = set(report) - _REPORT_KEYS
    if extra:
        raise _fail(f"report.{sorted(extra)[0]}", f"unknown key; allowed: {sorted(_REPORT_KEYS)}")
    for k in ("psd_wind", "cs_wind"):
        if k in report:
            _number(f"report.{k}", report[k], 0.0, lo_open=True)
    for i, p in enumerate(report.get("paper", []) or []):
        _paper_row(f"report.paper[{i}]", p, names, chans)
    return dict(report)


def _check_controller_grids(ctls: tuple[ControllerSpec, ...],
                            load_cases: tuple[LoadCase, ...]) -> None:
    """A controller's own grid only without load cases; its ``dlcs`` must name load cases."""
    names = [lc.dlc for lc in load_cases]
    for i, c in enumerate(ctls):
        if not load_cases[0].legacy:
            for k in ("winds", "seeds", "turbulence"):
                if getattr(c, k) is not None:
                    raise _fail(f"controllers[{i}].{k}", "a controller's own grid is not "
                                                         "allowed with load_cases; restrict "
                                                         "it with dlcs")
        elif c.dlcs is not None:
            raise _fail(f"controllers[{i}].dlcs", "only with load_cases")
        for d in c.dlcs or ():
            if d not in names:
                raise _fail(f"controllers[{i}].dlcs", f"{d!r} is not a load case; load cases "
                                                      f"are {names}")


def _controllers(raw: Any, lidar: dict[str, Any], plugin_kinds: bool,
                 base: Path | None = None) -> tuple[ControllerSpec, ...]:
    """The ``controllers`` list, each validated, their names distinct; relative library and
    input-file paths (``discon_library``, ``discon_in``) resolved against the spec's folder
    ``base``."""
    if not isinstance(raw, list) or not raw:
        raise _fail("controllers", "must be a non-empty list")
    if base is not None:
        raw = [_beside(base, c) for c in raw]
    ctls = tuple(_controller(i, c, lidar, plugin_kinds) for i, c in enumerate(raw))
    names = [c.name for c in ctls]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise _fail("controllers", f"repeated names {dup}; give each a distinct name")
    return ctls


def _beside(base: Path, entry: Any) -> Any:
    """A controller entry with its relative ``discon_library`` and ``discon_in`` taken from
    the spec's folder ``base`` (``shipped`` and absolute paths as given)."""
    if not isinstance(entry, Mapping):
        return entry
    out = dict(entry)
    for k in ("discon_library", "discon_in"):
        v = out.get(k)
        if isinstance(v, str) and v != "shipped" and not Path(v).expanduser().is_absolute():
            out[k] = str((base / v).resolve())
    return out


def _check_size(raw: Mapping[str, Any], ctls: tuple[ControllerSpec, ...],
                load_cases: tuple[LoadCase, ...]) -> None:
    """At most :data:`MAX_CASES` cases."""
    n_cases = sum(_n_cases(c, lc) for c in ctls for lc in load_cases
                  if c.dlcs is None or lc.dlc in c.dlcs)
    if n_cases > MAX_CASES:
        raise _fail("load_cases" if "load_cases" in raw else "seeds",
                    f"the spec makes {n_cases} cases, more than {MAX_CASES}: fewer winds, "
                    f"seeds or controllers")


def _n_cases(c: ControllerSpec, lc: LoadCase) -> int:
    """How many cases a controller has in a load case (as :meth:`CampaignSpec.cases` makes
    them), counted without making them."""
    if lc.wind_files:
        return len(lc.wind_files)
    if lc.legacy:
        return (len(c.turbulence or lc.turbulence) * len(c.winds or lc.winds)
                * len(c.seeds or lc.seeds))
    per = len(lc.signs) if lc.deterministic else len(lc.seeds)
    return len(lc.turbulence) * len(lc.winds) * per


def spec_from_dict(raw: Mapping[str, Any], base: Path | None = None,
                   source: str | None = None, *, import_plugins: bool = True) -> CampaignSpec:
    """Validate a campaign given as a mapping (the parsed YAML).

    Its ``plugins`` are imported (they register the kinds it names) unless ``import_plugins``
    is False: then none of its code runs, and unknown kinds' options are taken as given.


    Parameters
    ----------
    raw : mapping
        The parsed YAML.
    base : Path, optional
        Folder against which relative turbine paths are resolved.
    source : str, optional
        The spec's file, kept for the record.
    import_plugins : bool
        Import the spec's plugins (default; False to read a stored campaign).

    Returns
    -------
    CampaignSpec
        The validated campaign.

    Raises
    ------
    SpecError
        Naming the key: unknown or missing keys, values of the wrong type or out of range,
        repeated controllers, winds or seeds, a reference controller not in the list.
    """
    if not isinstance(raw, Mapping):
        raise SpecError(f"campaign spec: must be a mapping at the top level, got "
                        f"{type(raw).__name__}")
    raw = copy.deepcopy(dict(raw))
    extra = set(raw) - _TOP_KEYS
    if extra:
        raise _fail(sorted(extra)[0], f"unknown key; allowed: {sorted(_TOP_KEYS)}")
    missing = [k for k in ("name", "controllers") if k not in raw]
    if missing:
        raise _fail(missing[0], f"missing (required: name, winds or load_cases, "
                                f"controllers; missing {missing})")
    name = check_name("name", raw["name"])
    plugins = _plugins(raw.get("plugins", []), import_plugins, base)
    turbine, thash = turbine_files_hash(str(raw.get("turbine", "nrel5mw")), base)
    duration = _assessed("duration", raw.get("duration", 600.0))
    transient = _number("transient", raw.get("transient", 60.0), 0.0)
    lidar = _lidar("lidar", raw.get("lidar", {}))
    ctls = _controllers(raw["controllers"], lidar, bool(plugins) and not import_plugins, base)
    iec_class = raw.get("iec_class", "I")
    if iec_class not in ("I", "II", "III"):
        raise _fail("iec_class", f"must be 'I', 'II' or 'III' (IEC 61400-1 table 1), got "
                                 f"{iec_class!r}")
    load_cases = _load_cases(raw, duration, transient, turbine, base)
    _check_controller_grids(ctls, load_cases)
    _check_size(raw, ctls, load_cases)
    names = [c.name for c in ctls]
    chans = _channels(raw.get("channels"))
    ref = raw.get("reference", names[0])
    if ref not in names:
        raise _fail("reference", f"{ref!r} is not a controller name; names are {names}")
    report = _report(raw.get("report", {}), names, chans)
    desc = _description(raw.get("description", ""))
    return CampaignSpec(
        name=name, description=desc, turbine=turbine, turbine_hash=thash,
        duration=duration, transient=transient,
        turbulence=_turbulence("turbulence", raw.get("turbulence", "A")),
        shear_exponent=_number("shear_exponent", raw.get("shear_exponent", 0.2), -1.0, 1.0),
        winds=load_cases[0].winds if "winds" not in raw else _winds("winds", raw["winds"]),
        seeds=_seeds("seeds", raw.get("seeds", 1)), load_cases=load_cases,
        iec_class=iec_class, lidar=lidar, controllers=ctls, channels=chans,
        wind_distribution=_distribution(raw.get("wind_distribution", {})),
        lifetime_years=_number("lifetime_years", raw.get("lifetime_years", 20.0), 0.0,
                               lo_open=True),
        reference=ref, report=report, raw=raw, source=source, plugins=plugins,
        plugin_folder=str(base) if base is not None and plugins else None,
        del_convention=_convention(raw.get("del_convention", "range-1hz")),
        ultimate_channels=_ultimate_channels(raw.get("ultimate_channels")),
        plant=_plant(raw.get("plant")))


_PAPER_METRICS = {"del_change_pct", "lifetime_del_change_pct", "aep_change_pct",
                  "cs_change_pct", "pitch_change_pct", "value", "extension_years"}


def _paper_row(key: str, p: Any, names: list[str], chans: Mapping[str, float]) -> None:
    """A paper value to place next to ours: {metric, controller, value | direction,
    [channel|measure], [wind], [turbulence], [source], [note]}."""
    if not isinstance(p, Mapping):
        raise _fail(key, f"must be a mapping, got {p!r}")
    allowed = {"metric", "controller", "value", "direction", "channel", "measure", "wind",
               "source", "turbulence", "note"}
    extra = set(p) - allowed
    if extra:
        raise _fail(f"{key}.{sorted(extra)[0]}", f"unknown key; allowed: {sorted(allowed)}")
    if p.get("metric") not in _PAPER_METRICS:
        raise _fail(f"{key}.metric", f"must be one of {sorted(_PAPER_METRICS)}, got "
                                     f"{p.get('metric')!r}")
    if p.get("controller") not in names:
        raise _fail(f"{key}.controller", f"{p.get('controller')!r} is not a controller name; "
                                         f"names are {names}")
    if "channel" in p and p["channel"] not in chans:
        raise _fail(f"{key}.channel", f"{p['channel']!r} is not a campaign channel")
    if "direction" in p:
        if p["direction"] not in ("increase", "decrease") or "value" in p:
            raise _fail(f"{key}.direction", f"must be 'increase' or 'decrease' (for a paper "
                                            f"that gives a figure, not a number) and without "
                                            f"value, got {p['direction']!r}")
    else:
        _number(f"{key}.value", p.get("value"))
    if p["metric"] in ("del_change_pct", "cs_change_pct", "value") and "wind" not in p:
        raise _fail(f"{key}.wind", f"metric {p['metric']!r} is per mean wind: give wind [m/s]")


def foreign_code(path: str | Path) -> list[str]:
    """The code a spec would run that another user wrote: the spec file itself, the plugin
    modules beside it (``NAME.py`` in its folder) and the controller libraries it names
    (``discon_library``), each owned by neither the current user nor root. Read with a safe
    YAML loader; nothing of the spec runs.

    Parameters
    ----------
    path : str or Path
        The spec (a campaign's or a tuning's).

    Returns
    -------
    list of str
        ``"FILE (owner uid N)"`` per such file; empty when all are the user's or root's.
    """
    path = Path(path)
    try:
        raw = yaml.safe_load(path.read_text())
    except (OSError, yaml.YAMLError):
        return []                   # load_spec names what is wrong with the file
    files = [path]
    if isinstance(raw, Mapping):
        plugins = raw.get("plugins") or []
        files += [path.parent / f"{m}.py" for m in plugins if isinstance(m, str)]
        ctls = [raw.get("controller")] + list(raw.get("controllers") or [])
        files += [Path(c["discon_library"]) if Path(c["discon_library"]).is_absolute()
                  else path.parent / c["discon_library"] for c in ctls
                  if isinstance(c, Mapping) and isinstance(c.get("discon_library"), str)]
    me = os.getuid() if hasattr(os, "getuid") else None
    out = []
    for f in files:
        try:
            uid = f.stat().st_uid
        except OSError:
            continue
        if me is not None and uid not in (me, 0):
            out.append(f"{f} (owner uid {uid})")
    return out


def load_spec(path: str | Path) -> CampaignSpec:
    """Read and validate a campaign YAML file (relative turbine paths against its folder).


    Parameters
    ----------
    path : str or Path
        The YAML file.

    Returns
    -------
    CampaignSpec
        The validated campaign.

    Raises
    ------
    SpecError
        Unreadable YAML (with its line) or an invalid spec (naming the key).
    FileNotFoundError
        If the file does not exist.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"campaign spec {path}: file not found")
    try:
        raw = yaml.safe_load(path.read_text())
    except yaml.YAMLError as err:
        raise SpecError(f"campaign spec {path}: not valid YAML ({err})") from err
    try:
        return spec_from_dict(raw, base=path.parent, source=str(path))
    except SpecError as err:
        raise SpecError(f"{path}: {err}") from err

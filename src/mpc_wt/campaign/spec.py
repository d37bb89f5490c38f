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
import hashlib
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping

import yaml

from ..errors import SpecError

__all__ = ["SpecError", "CampaignSpec", "ControllerSpec", "Case", "load_spec", "spec_from_dict"]


_TOP_KEYS = {"name", "description", "turbine", "duration", "transient", "turbulence",
             "shear_exponent", "winds", "seeds", "lidar", "controllers", "channels",
             "wind_distribution", "lifetime_years", "reference", "report", "plugins",
             "del_convention"}
#: A controller entry's own keys; any other key is an option of the controller's kind.
_CONTROLLER_KEYS = {"name", "controller", "winds", "seeds", "turbulence", "label", "options",
                    "mpc_options", "retrofit_options"}
_REPORT_KEYS = {"paper", "notes", "psd_wind", "cs_wind", "sweep", "title"}


def _fail(key: str, msg: str) -> SpecError:
    return SpecError(f"campaign spec: {key}: {msg}")


def _number(key: str, val: Any, lo: float | None = None, hi: float | None = None,
            lo_open: bool = False) -> float:
    """A finite number within bounds (:func:`linearize.validate.check_number`), or a
    :class:`SpecError` naming the key."""
    from linearize.validate import check_number

    try:
        return check_number(key, val, lo=lo, hi=hi, lo_open=lo_open)
    except ValueError as err:
        raise _fail(key, str(err).removeprefix(f"{key} ")) from None


def _winds(key: str, val: Any) -> tuple[float, ...]:
    """A list of mean winds [m/s], or {start, stop, step} (stop included)."""
    if isinstance(val, Mapping):
        extra = set(val) - {"start", "stop", "step"}
        if extra or {"start", "stop"} - set(val):
            raise _fail(key, f"a range needs start, stop and optionally step; got keys "
                             f"{sorted(val)}")
        a = _number(f"{key}.start", val["start"], 0.0, lo_open=True)
        b = _number(f"{key}.stop", val["stop"], a)
        s = _number(f"{key}.step", val.get("step", 1.0), 0.0, lo_open=True)
        out = [round(a + i * s, 6) for i in range(int(math.floor((b - a) / s + 1e-9)) + 1)]
    elif isinstance(val, (list, tuple)):
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
        if val < 1:
            raise _fail(key, f"a seed count must be >= 1, got {val}")
        return tuple(range(1, val + 1))
    if isinstance(val, (list, tuple)) and val:
        if not all(isinstance(s, int) and not isinstance(s, bool) and s >= 0 for s in val):
            raise _fail(key, f"seeds must be integers >= 0, got {list(val)}")
        if len(set(val)) != len(val):
            raise _fail(key, f"repeated seeds {list(val)}")
        return tuple(val)
    raise _fail(key, f"must be a count >= 1 or a non-empty list of integers, got {val!r}")


def _turbulence(key: str, val: Any) -> tuple[str | float, ...]:
    """IEC classes "A"/"B"/"C", intensities in (0, 1), or "steady"."""
    vals = list(val) if isinstance(val, (list, tuple)) else [val]
    out: list[str | float] = []
    for i, v in enumerate(vals):
        k = f"{key}[{i}]" if isinstance(val, (list, tuple)) else key
        if isinstance(v, str):
            if v not in ("A", "B", "C", "steady"):
                raise _fail(k, f"must be an IEC class 'A', 'B', 'C', 'steady' or an intensity "
                               f"in (0, 1), got {v!r}")
            out.append(v)
        else:
            out.append(_number(k, v, 0.0, 1.0, lo_open=True))
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
        ...; :func:`mpc_wt.controllers.kinds`).
    options : dict
        The kind's options as given (checked by the registry when the spec loads), e.g.
        ``apc_frequency`` [Hz], ``horizon``, ``lidar``.
    winds, seeds, turbulence : tuple or None
        This controller's own grid (default: the campaign's).
    """

    name: str
    controller: str
    options: dict[str, Any] = field(default_factory=dict)
    winds: tuple[float, ...] | None = None
    seeds: tuple[int, ...] | None = None
    turbulence: tuple[str | float, ...] | None = None
    label: str | None = None


@dataclass(frozen=True)
class Case:
    """One simulation of a campaign (a pure task: these fields -> one result file + metrics).

    Parameters
    ----------
    case_id : str
        ``controller__turbulence__vWIND__sSEED``.
    controller : str
        The controller's label in the spec.
    run_name : str
        The registered kind it runs.
    options : dict
        The kind's options.
    wind_mps : float
        Mean wind [m/s].
    seed : int
        Seed of the field.
    turbulence : str or float
        Class letter or intensity.
    duration, transient : float
        Assessed length and discarded start [s].
    shear_exponent : float
        Power-law shear [-].
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
    del_convention : str
        The DEL convention of the assessment (:data:`mpc_wt.assess.DEL_CONVENTIONS`).
    """

    case_id: str
    controller: str
    run_name: str
    options: dict[str, Any]
    wind_mps: float
    seed: int
    turbulence: str | float
    duration: float
    transient: float
    shear_exponent: float
    turbine: str
    turbine_hash: str
    channels: dict[str, float]
    case_hash: str
    assess_hash: str
    plugins: tuple[str, ...] = ()
    del_convention: str = "range-1hz"

    def to_dict(self) -> dict[str, Any]:
        """Plain data for a worker (pickles and JSON-serialises).

        Returns
        -------
        dict
            Every field.
        """
        return {k: copy.deepcopy(getattr(self, k)) for k in self.__dataclass_fields__}


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
    del_convention : str
        The DEL convention (``range-1hz``, default; ``clemens``; ``pcrunch``): DEL per case and
        the lifetime DEL's weights (Clemens eq 18 weights bins by their counted cycles).
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
    del_convention: str = "range-1hz"

    @property
    def spec_hash(self) -> str:
        """SHA-256 of the canonical spec (with the turbine files' hash)."""
        return _digest({"spec": self.raw, "turbine": self.turbine_hash})

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
        """Every case of the campaign, in a stable order (controller, turbulence, wind, seed).

        Returns
        -------
        list of Case
            Every case.
        """
        out = []
        assess: dict[str, Any] = {"channels": self.channels, "transient": self.transient}
        if self.del_convention != "range-1hz":      # the default keeps older hashes valid
            assess["del_convention"] = self.del_convention
        for c in self.controllers:
            for turb in c.turbulence or self.turbulence:
                for v in c.winds or self.winds:
                    for s in c.seeds or self.seeds:
                        sim = {"turbine": self.turbine_hash, "controller": c.controller,
                               "options": c.options, "wind_mps": v, "seed": s,
                               "turbulence": turb, "duration": self.duration + self.transient,
                               "shear_exponent": self.shear_exponent}
                        cid = f"{c.name}__{turbulence_tag(turb)}__v{v:g}__s{s}"
                        out.append(Case(case_id=cid, controller=c.name,
                                        run_name=c.controller, options=copy.deepcopy(c.options),
                                        wind_mps=v, seed=s, turbulence=turb,
                                        duration=self.duration, transient=self.transient,
                                        shear_exponent=self.shear_exponent,
                                        turbine=self.turbine, turbine_hash=self.turbine_hash,
                                        channels=dict(self.channels), case_hash=_digest(sim),
                                        assess_hash=_digest(assess),
                                        plugins=self.plugins,
                                        del_convention=self.del_convention))
        return out


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
            from ..controllers.context import turbine_key   # was read, not the folder
            return ref, turbine_key(loaded)
    h = hashlib.sha256()
    for f in sorted(folder.rglob("*")):
        if f.is_file() and "__pycache__" not in f.parts:
            h.update(str(f.relative_to(folder)).encode())
            h.update(f.read_bytes())
    return ref, h.hexdigest()


def _controller_options(key: str, raw: Mapping[str, Any], run_name: str,
                        lidar: dict[str, Any]) -> dict[str, Any]:
    """The entry's controller options, checked by the registry: every key that is not one of
    the campaign's own (name, grid, label) is an option of the kind; ``options:`` holds them
    too, and the groups ``mpc_options`` / ``retrofit_options`` of older specs are flattened.
    The campaign's ``lidar`` settings are the defaults of a kind that takes ``lidar``."""
    from ..controllers import resolve
    from ..errors import OptionsError

    opts: dict[str, Any] = {}
    for group in ("options", "mpc_options", "retrofit_options"):
        if group in raw:
            if not isinstance(raw[group], Mapping):
                raise _fail(f"{key}.{group}", f"must be a mapping, got {raw[group]!r}")
            opts.update(raw[group])
    opts.update({k: v for k, v in raw.items() if k not in _CONTROLLER_KEYS})
    try:
        sel = resolve(run_name)
        if "lidar" in sel.option_names() and (lidar or "lidar" in opts):
            extra = opts.get("lidar", {})
            if not isinstance(extra, Mapping):
                raise _fail(f"{key}.lidar", f"must be a mapping, got {extra!r}")
            opts["lidar"] = {**lidar, **extra}
        sel.options(opts)
    except OptionsError as err:
        raise _fail(f"{key}.{err.key}", str(err)) from err
    except ValueError as err:
        raise _fail(f"{key}.controller", str(err)) from err
    return copy.deepcopy(opts)


def _controller(i: int, raw: Any, lidar: dict[str, Any]) -> ControllerSpec:
    key = f"controllers[{i}]"
    if isinstance(raw, str):
        raw = {"name": raw, "controller": raw}
    if not isinstance(raw, Mapping):
        raise _fail(key, f"must be a controller name or a mapping, got {raw!r}")
    name = raw.get("name", raw.get("controller"))
    if not isinstance(name, str) or not name or not all(
            ch.isalnum() or ch in "-_.+" for ch in name):
        raise _fail(f"{key}.name", f"must be a non-empty label of letters, digits and -_.+, "
                                   f"got {name!r}")
    run_name = str(raw.get("controller", name))
    opts = _controller_options(key, raw, run_name, lidar)
    return ControllerSpec(
        name=name, controller=run_name, options=opts,
        winds=_winds(f"{key}.winds", raw["winds"]) if "winds" in raw else None,
        seeds=_seeds(f"{key}.seeds", raw["seeds"]) if "seeds" in raw else None,
        turbulence=(_turbulence(f"{key}.turbulence", raw["turbulence"])
                    if "turbulence" in raw else None),
        label=str(raw["label"]) if "label" in raw else None)


def _lidar(key: str, raw: Any) -> dict[str, Any]:
    """The campaign's LIDAR settings (defaults of the kinds that take ``lidar``), checked by
    :class:`mpc_wt.controllers.LidarOptions`."""
    from ..controllers import LidarOptions
    from ..errors import OptionsError

    if not isinstance(raw, Mapping):
        raise _fail(key, f"must be a mapping, got {raw!r}")
    try:
        opts = LidarOptions.from_dict(raw, prefix=f"{key}.")
        return {k: getattr(opts, k) for k in raw}
    except OptionsError as err:
        raise _fail(err.key, str(err)) from err


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
    from ..assess import DEL_CONVENTIONS

    if raw not in DEL_CONVENTIONS:
        raise _fail("del_convention", f"must be one of {list(DEL_CONVENTIONS)}, got {raw!r}")
    return str(raw)


def _plugins(raw: Any) -> tuple[str, ...]:
    """Modules that register controller kinds, imported here and in every worker."""
    from ..controllers import load_plugins

    if not isinstance(raw, list) or not all(isinstance(m, str) and m for m in raw):
        raise _fail("plugins", f"must be a list of module names, got {raw!r}")
    try:
        load_plugins(raw)
    except ImportError as err:
        raise _fail("plugins", str(err)) from err
    return tuple(raw)


def _channels(raw: Any) -> dict[str, float]:
    """Channel -> Woehler exponent (default :data:`mpc_wt.assess.DEFAULT_CHANNELS`)."""
    import linearize

    from ..assess import DEFAULT_CHANNELS

    chans_raw = DEFAULT_CHANNELS if raw is None else raw
    if not isinstance(chans_raw, Mapping) or not chans_raw:
        raise _fail("channels", "must be a non-empty mapping of channel name to Woehler "
                                "exponent m")
    known = {*linearize.OUTPUT_NAMES, *linearize.STATE_NAMES, *linearize.INPUT_NAMES,
             "shaft_bending_blade1"}
    chans = {}
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


def spec_from_dict(raw: Mapping[str, Any], base: Path | None = None,
                   source: str | None = None) -> CampaignSpec:
    """Validate a campaign given as a mapping (the parsed YAML).


    Parameters
    ----------
    raw : mapping
        The parsed YAML.
    base : Path, optional
        Folder against which relative turbine paths are resolved.
    source : str, optional
        The spec's file, kept for the record.

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
    missing = [k for k in ("name", "winds", "controllers") if k not in raw]
    if missing:
        raise _fail(missing[0], f"missing (required: name, winds, controllers; missing "
                                f"{missing})")
    name = raw["name"]
    if not isinstance(name, str) or not name.strip():
        raise _fail("name", f"must be a non-empty string, got {name!r}")
    plugins = _plugins(raw.get("plugins", []))
    turbine, thash = turbine_files_hash(str(raw.get("turbine", "nrel5mw")), base)
    duration = _number("duration", raw.get("duration", 600.0), 0.0, lo_open=True)
    transient = _number("transient", raw.get("transient", 60.0), 0.0)
    lidar = _lidar("lidar", raw.get("lidar", {}))
    ctl_raw = raw["controllers"]
    if not isinstance(ctl_raw, list) or not ctl_raw:
        raise _fail("controllers", "must be a non-empty list")
    ctls = tuple(_controller(i, c, lidar) for i, c in enumerate(ctl_raw))
    names = [c.name for c in ctls]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise _fail("controllers", f"repeated names {dup}; give each a distinct name")
    chans = _channels(raw.get("channels"))
    ref = raw.get("reference", names[0])
    if ref not in names:
        raise _fail("reference", f"{ref!r} is not a controller name; names are {names}")
    report = _report(raw.get("report", {}), names, chans)
    desc = raw.get("description", "")
    if not isinstance(desc, str):
        raise _fail("description", f"must be a string, got {desc!r}")
    return CampaignSpec(
        name=name.strip(), description=desc, turbine=turbine, turbine_hash=thash,
        duration=duration, transient=transient,
        turbulence=_turbulence("turbulence", raw.get("turbulence", "A")),
        shear_exponent=_number("shear_exponent", raw.get("shear_exponent", 0.2), -1.0, 1.0),
        winds=_winds("winds", raw["winds"]), seeds=_seeds("seeds", raw.get("seeds", 1)),
        lidar=lidar, controllers=ctls, channels=chans,
        wind_distribution=_distribution(raw.get("wind_distribution", {})),
        lifetime_years=_number("lifetime_years", raw.get("lifetime_years", 20.0), 0.0,
                               lo_open=True),
        reference=ref, report=report, raw=raw, source=source, plugins=plugins,
        del_convention=_convention(raw.get("del_convention", "range-1hz")))


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

"""The tuning spec: a campaign's load cases plus what to tune, against what, within which bounds.

YAML, the campaign's keys (``turbine``, ``duration``, ``transient``, ``turbulence``,
``shear_exponent``, ``winds``, ``seeds``: the tuning set, ``channels``, ``wind_distribution``,
``lidar``, ``plugins``, ``del_convention``) and::

    controller: {controller: lqr-pio, observer_q: 1000}    # the kind and its fixed options
    reference: {name: pi, controller: baseline-ct}         # what every ratio is against
    parameters:                                            # option -> search range
      w_rotor_speed: {low: 0.1, high: 100, log: true}
      weights.flap_moment: {low: 0.01, high: 10, log: true}    # nested options: dotted
    objective:                                             # weighted mean of ratios
      - {metric: "del:tower_base_fa_moment", weight: 1}
      - {metric: cs1, weight: 0.5}
    constraints:                                           # ratio <= max_ratio
      - {metric: rotor_speed_std, max_ratio: 1.0}
    trials: 40
    sampler: tpe
    seed: 1
    holdout_seeds: [4, 5, 6]                               # evaluated once, after the search

Every measure is a ratio to the reference over the same cases
(:func:`mpc_wt.campaign.aggregate.relative_metrics`): ``del:CHANNEL`` (lifetime DEL of a channel
of ``channels``), ``cs1``..``cs5``, ``power_mean``, ``power_std``, ``rotor_speed_std``,
``rotor_speed_max``, ``pitch_travel``, ``pitch_rate_std``, ``pitch_acc_std``, ``flap_1p``,
``flap_3p``. A constraint may give ``max_change_pct`` instead (``max_ratio = 1 + pct/100``),
a lower bound with ``min_ratio`` or ``min_change_pct`` (``power_mean`` at least 0.995),
or bound a measure per case with ``max_value``: ``pitch_rate_limit_hits`` (times a blade
reached its pitch-rate limit per case), ``pitch_rate_limit_s``, ``pitch_rate_max_degps``.
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

from mpc_wt.campaign.aggregate import ABSOLUTE_METRICS, RELATIVE_METRICS
from mpc_wt.campaign.spec import CampaignSpec, check_name, spec_from_dict
from mpc_wt.errors import SpecError
from mpc_wt.tuning.optimizer import SAMPLERS, Constraint, Parameter

__all__ = ["TuneSpec", "load_tune_spec", "tune_spec_from_dict", "nest"]

_CAMPAIGN_KEYS = {"turbine", "duration", "transient", "turbulence", "shear_exponent", "winds",
                  "seeds", "lidar", "channels", "wind_distribution", "lifetime_years",
                  "plugins", "del_convention"}
_TUNE_KEYS = {"name", "description", "controller", "reference", "parameters", "objective",
              "constraints", "trials", "sampler", "seed", "holdout_seeds", "initial"}


def _fail(key: str, msg: str) -> SpecError:
    err = SpecError(f"tuning spec: {key}: {msg}")
    err.key = key  # type: ignore[attr-defined]
    return err


def nest(flat: Mapping[str, Any]) -> dict[str, Any]:
    """Dotted option names as nested mappings: ``{"a.b": 1, "c": 2}`` -> ``{"a": {"b": 1},
    "c": 2}``.

    Parameters
    ----------
    flat : mapping of str to object

    Returns
    -------
    dict
    """
    out: dict[str, Any] = {}
    for key, val in flat.items():
        *head, last = key.split(".")
        node = out
        for h in head:
            node = node.setdefault(h, {})
        node[last] = val
    return out


def _merge(a: Mapping[str, Any], b: Mapping[str, Any]) -> dict[str, Any]:
    out = copy.deepcopy(dict(a))
    for k, v in b.items():
        out[k] = _merge(out[k], v) if isinstance(v, Mapping) and isinstance(
            out.get(k), Mapping) else v
    return out


@dataclass(frozen=True)
class TuneSpec:
    """A validated tuning spec (:func:`load_tune_spec`).

    Parameters
    ----------
    name : str
    controller : dict
        The tuned kind's campaign entry (``controller`` and its fixed options).
    reference : dict
        The reference's campaign entry (with its ``name``).
    parameters : tuple of Parameter
    objective : tuple of (metric, weight)
    constraints : tuple of Constraint
        On ratios to the reference.
    trials, seed : int
    sampler : str
    holdout_seeds : tuple of int
    initial : tuple of dict
        Parameter sets tried first.
    campaign_raw : dict
        The campaign keys of the spec.
    base : Path or None
        Folder of the spec file (relative turbine paths).
    raw : dict
        The whole spec as given.
    """

    name: str
    description: str
    controller: dict[str, Any]
    reference: dict[str, Any]
    parameters: tuple[Parameter, ...]
    objective: tuple[tuple[str, float], ...]
    constraints: tuple[Constraint, ...]
    trials: int
    sampler: str
    seed: int
    holdout_seeds: tuple[int, ...]
    initial: tuple[dict[str, float], ...]
    campaign_raw: dict[str, Any]
    base: Path | None = None
    raw: dict[str, Any] = field(default_factory=dict)

    @property
    def kind(self) -> str:
        """The tuned controller kind."""
        return str(self.controller["controller"])

    def candidate_name(self, params: Mapping[str, float]) -> str:
        """A design's controller name in the campaign.

        Parameters
        ----------
        params : mapping of str to float

        Returns
        -------
        str
            ``c-`` + a digest of the parameters, so that the same design always maps to the
            same (reused) cases.
        """
        blob = json.dumps({k: float(f"{float(v):.9g}") for k, v in sorted(params.items())})
        return "c-" + hashlib.sha1(blob.encode()).hexdigest()[:10]

    def options(self, params: Mapping[str, float]) -> dict[str, Any]:
        """The kind's options of a design.

        Parameters
        ----------
        params : mapping of str to float
            Dotted names for nested options.

        Returns
        -------
        dict
            The fixed options with the parameters in place.
        """
        fixed = {k: v for k, v in self.controller.items() if k != "controller"}
        return _merge(fixed, nest(params))

    def campaign(self, designs: Mapping[str, Mapping[str, float] | None], *,
                 seeds: Any = None) -> CampaignSpec:
        """The campaign of the reference and the given designs.

        Parameters
        ----------
        designs : mapping of str to (mapping or None)
            Name -> parameters (None: the kind's hand-set defaults with the fixed options).
        seeds : sequence of int, optional
            Other seeds than the tuning set (the held-out ones).

        Returns
        -------
        CampaignSpec
        """
        raw = copy.deepcopy(self.campaign_raw)
        if seeds is not None:
            raw["seeds"] = list(seeds)
        ctls = [copy.deepcopy(self.reference)]
        for name, params in designs.items():
            ctls.append({"name": name, "controller": self.kind,
                         **self.options(params or {})})
        raw.update(name=self.name, controllers=ctls, reference=self.reference["name"])
        return spec_from_dict(raw, base=self.base)

    def metrics(self, ratios: Mapping[str, float]) -> dict[str, float]:
        """The measures with the objective added.

        Parameters
        ----------
        ratios : mapping of str to float
            Ratios to the reference (and per-case measures).

        Returns
        -------
        dict of str to float
            With ``objective``: the weighted mean of the objective's ratios.

        Raises
        ------
        ValueError
            If a measure of the objective is missing (naming it and those there are).
        """
        missing = [m for m, _ in self.objective if m not in ratios]
        if missing:
            raise ValueError(f"objective measures {missing} missing from the campaign's "
                             f"ratios {sorted(ratios)}")
        tot = sum(w for _, w in self.objective)
        return {**ratios, "objective": sum(w * ratios[m] for m, w in self.objective) / tot}


def _number(key: str, v: Any, lo: float | None = None, lo_open: bool = False) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or (
            lo is not None and (v <= lo if lo_open else v < lo)):
        rng = "" if lo is None else f" {'>' if lo_open else '>='} {lo:g}"
        raise _fail(key, f"must be a finite number{rng}, got {v!r}")
    return float(v)


def _parameters(raw: Any) -> tuple[Parameter, ...]:
    if not isinstance(raw, Mapping) or not raw:
        raise _fail("parameters", f"must be a non-empty mapping of option -> {{low, high, "
                                  f"log}}, got {raw!r}")
    out = []
    for name, r in raw.items():
        key = f"parameters.{name}"
        if not isinstance(r, Mapping):
            raise _fail(key, f"must be a mapping {{low, high, log, integer}}, got {r!r}")
        extra = set(r) - {"low", "high", "log", "integer"}
        if extra:
            raise _fail(f"{key}.{sorted(extra)[0]}", "unknown key; allowed: high, integer, "
                                                      "log, low")
        for k in ("low", "high"):
            if k not in r:
                raise _fail(f"{key}.{k}", "missing")
        try:
            out.append(Parameter(str(name), _number(f"{key}.low", r["low"]),
                                 _number(f"{key}.high", r["high"]), bool(r.get("log", False)),
                                 bool(r.get("integer", False))))
        except ValueError as err:
            raise _fail(key, str(err)) from err
    return tuple(out)


def _metric_name(key: str, m: Any, channels: Mapping[str, float]) -> str:
    allowed = sorted(RELATIVE_METRICS) + [f"del:{c}" for c in channels]
    if m not in allowed:
        raise _fail(key, f"unknown measure {m!r}; allowed: {allowed}")
    return str(m)


def _objective(raw: Any, channels: Mapping[str, float]) -> tuple[tuple[str, float], ...]:
    if not isinstance(raw, list) or not raw:
        raise _fail("objective", f"must be a non-empty list of {{metric, weight}}, got {raw!r}")
    out = []
    for i, e in enumerate(raw):
        key = f"objective[{i}]"
        if not isinstance(e, Mapping) or set(e) - {"metric", "weight"} or "metric" not in e:
            raise _fail(key, f"must be {{metric, weight}}, got {e!r}")
        out.append((_metric_name(f"{key}.metric", e["metric"], channels),
                    _number(f"{key}.weight", e.get("weight", 1.0), 0.0, lo_open=True)))
    return tuple(out)


def _constraints(raw: Any, channels: Mapping[str, float]) -> tuple[Constraint, ...]:
    if not isinstance(raw, list):
        raise _fail("constraints", f"must be a list of {{metric, max_ratio | "
                                   f"max_change_pct | min_ratio | min_change_pct | max_value}}, "
                                   f"got {raw!r}")
    out = []
    bounds = ("max_ratio", "max_change_pct", "min_ratio", "min_change_pct", "max_value")
    for i, e in enumerate(raw):
        key = f"constraints[{i}]"
        if not isinstance(e, Mapping) or "metric" not in e or \
                set(e) - {"metric", *bounds} or sum(b in e for b in bounds) != 1:
            raise _fail(key, f"must be {{metric, max_ratio}}, {{metric, max_change_pct}}, "
                             f"{{metric, min_ratio}}, {{metric, min_change_pct}} or "
                             f"{{metric, max_value}}, got {e!r}")
        if "max_value" in e:
            if e["metric"] not in ABSOLUTE_METRICS:
                raise _fail(f"{key}.metric", f"max_value bounds a measure per case: one of "
                                             f"{sorted(ABSOLUTE_METRICS)}, got {e['metric']!r}")
            out.append(Constraint(str(e["metric"]), _number(f"{key}.max_value",
                                                            e["max_value"], 0.0)))
            continue
        m = _metric_name(f"{key}.metric", e["metric"], channels)
        lower = "min_ratio" in e or "min_change_pct" in e
        kind = next(b for b in bounds if b in e)
        if kind.endswith("_ratio"):
            bound = _number(f"{key}.{kind}", e[kind], 0.0, lo_open=True)
        else:
            bound = 1.0 + _number(f"{key}.{kind}", e[kind], -100.0, lo_open=True) / 100.0
        out.append(Constraint(m, bound, lower))
    return tuple(out)


def _integer(key: str, v: Any, lo: int) -> int:
    if isinstance(v, bool) or not isinstance(v, int) or v < lo:
        raise _fail(key, f"must be an integer >= {lo}, got {v!r}")
    return v


def tune_spec_from_dict(raw: Mapping[str, Any], base: Path | None = None) -> TuneSpec:
    """Validate a tuning spec given as a mapping.

    Parameters
    ----------
    raw : mapping
        The parsed YAML.
    base : Path, optional
        Folder of relative turbine paths.

    Returns
    -------
    TuneSpec

    Raises
    ------
    SpecError
        Naming the key: unknown or missing keys, a parameter that is not an option of the
        kind, an unknown measure, bounds out of range, a campaign key the campaign refuses.
    """
    if not isinstance(raw, Mapping):
        raise SpecError(f"tuning spec: must be a mapping at the top level, got "
                        f"{type(raw).__name__}")
    raw = copy.deepcopy(dict(raw))
    extra = set(raw) - _CAMPAIGN_KEYS - _TUNE_KEYS
    if extra:
        raise _fail(sorted(extra)[0], f"unknown key; allowed: "
                                      f"{sorted(_CAMPAIGN_KEYS | _TUNE_KEYS)}")
    for k in ("name", "winds", "controller", "reference", "parameters", "objective"):
        if k not in raw:
            raise _fail(k, "missing (required: name, winds, controller, reference, parameters, "
                           "objective)")
    name = raw["name"]
    if not isinstance(name, str) or not name.strip():
        raise _fail("name", f"must be a non-empty string, got {name!r}")
    check_name("name", name, _fail)
    ctl, ref = raw["controller"], raw["reference"]
    if not isinstance(ctl, Mapping) or "controller" not in ctl or "name" in ctl:
        raise _fail("controller", f"must be a mapping with `controller` (the kind) and its "
                                  f"fixed options, no name; got {ctl!r}")
    if not isinstance(ref, Mapping) or "name" not in ref or "controller" not in ref:
        raise _fail("reference", f"must be a mapping with `name` and `controller`, got {ref!r}")
    check_name("reference.name", ref["name"], _fail)
    camp = {k: raw[k] for k in _CAMPAIGN_KEYS if k in raw}
    camp["winds"] = raw["winds"]
    params = _parameters(raw["parameters"])
    chans = camp.get("channels") or {}
    spec = TuneSpec(
        name=name.strip(), description=str(raw.get("description", "")), controller=dict(ctl),
        reference=dict(ref), parameters=params,
        objective=_objective(raw["objective"], chans),
        constraints=_constraints(raw.get("constraints", []), chans),
        trials=_integer("trials", raw.get("trials", 40), 1),
        sampler=str(raw.get("sampler", "tpe")), seed=_integer("seed", raw.get("seed", 0), 0),
        holdout_seeds=tuple(_integer(f"holdout_seeds[{i}]", s, 0)
                            for i, s in enumerate(raw.get("holdout_seeds", []))),
        initial=tuple(dict(p) for p in raw.get("initial", [])), campaign_raw=camp, base=base,
        raw=raw)
    if spec.sampler not in SAMPLERS:
        raise _fail("sampler", f"must be one of {list(SAMPLERS)}, got {spec.sampler!r}")
    _check_parameters(spec)
    try:      # the campaign keys, the reference, the kind and its fixed options
        spec.campaign({"tuned": None})
    except SpecError as err:
        msg = str(err).replace("campaign spec: ", "", 1)
        top = msg.split(":", 1)[0]
        key = ("reference" if top.startswith("controllers[0]") else
               "controller" if top.startswith("controllers[1]") else top.split(".")[0])
        raise _fail(key, msg.split(": ", 1)[1] if key == top else msg) from err
    return spec


def _check_parameters(spec: TuneSpec) -> None:
    """Every parameter is an option of the kind and both ends of its range are allowed."""
    from mpc_wt.errors import OptionsError
    from mpc_wt.registry.registry import resolve

    try:
        sel = resolve(spec.kind)
        sel.options(spec.options({}))
    except OptionsError as err:
        raise _fail(f"controller.{err.key}", str(err)) from err
    except ValueError as err:
        raise _fail("controller", str(err)) from err
    for p in spec.parameters:
        for end in (p.low, p.high):
            try:
                sel.options(spec.options({p.name: int(end) if p.integer else end}))
            except OptionsError as err:
                raise _fail(f"parameters.{p.name}", str(err)) from err


def load_tune_spec(path: str | Path) -> TuneSpec:
    """Read and validate a tuning YAML file.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    TuneSpec

    Raises
    ------
    FileNotFoundError
    SpecError
        Unreadable YAML or an invalid spec (naming the key).
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"tuning spec {path}: file not found")
    try:
        raw = yaml.safe_load(path.read_text())
    except yaml.YAMLError as err:
        raise SpecError(f"tuning spec {path}: not valid YAML ({err})") from err
    return tune_spec_from_dict(raw, base=path.parent)

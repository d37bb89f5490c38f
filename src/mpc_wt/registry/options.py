"""Typed controller options: frozen dataclasses whose fields declare their own checks.

Each controller kind has one options class. :meth:`Options.from_dict` rejects unknown keys,
naming them and the allowed ones, reports a missing required option, and converts and checks
each value by the field's metadata (set with :func:`option`). The command line and campaign
specs read the same metadata (flag name, help, choices), so a rule is written once.
"""
from __future__ import annotations

import dataclasses
import typing
from dataclasses import dataclass, fields
from typing import Any, Callable, Mapping, TypeVar

from linearize.validate import check_number
from mpc_wt.errors import OptionsError

__all__ = ["Options", "option", "REQUIRED"]

T = TypeVar("T", bound="Options")


class _Required:
    """Marker of an option without a default."""

    def __repr__(self) -> str:
        return "REQUIRED"


#: Default of an option that must be given.
REQUIRED: Any = _Required()


def option(default: Any = None, *, help: str = "", unit: str = "", lo: float | None = None,
           hi: float | None = None, lo_open: bool = False, choices: tuple[Any, ...] = (),
           flag: str | None = None, flag_value: Any = None) -> Any:
    """A dataclass field with the metadata of a controller option.

    Parameters
    ----------
    default : object
        The default, or :data:`REQUIRED`.
    help : str
        One line for ``mpcwt simulate --help`` and the registry listing.
    unit : str
        Unit of a number ("Hz", "rad/s", "-").
    lo, hi : float, optional
        Bounds of a number (``lo_open``: lo itself excluded).
    lo_open : bool
        Whether ``lo`` is excluded.
    choices : tuple
        Allowed values (strings, or None).
    flag : str, optional
        Command-line flag (default ``--`` + the name with dashes).
    flag_value : object, optional
        For a flag without an argument: the option's value when the flag is given.

    Returns
    -------
    dataclasses.Field
        For a frozen :class:`Options` subclass.
    """
    meta = {"help": help, "unit": unit, "lo": lo, "hi": hi, "lo_open": lo_open,
            "choices": tuple(choices), "flag": flag, "flag_value": flag_value}
    if default is REQUIRED:
        return dataclasses.field(default=REQUIRED, metadata=meta)
    if isinstance(default, (dict, list)):
        return dataclasses.field(default_factory=lambda: type(default)(default), metadata=meta)
    return dataclasses.field(default=default, metadata=meta)


def _base_type(tp: Any) -> tuple[Any, bool]:
    """(the non-None type of an annotation, whether None is allowed)."""
    args = typing.get_args(tp)
    if args and type(None) in args:
        rest = [a for a in args if a is not type(None)]
        return (rest[0] if len(rest) == 1 else tuple(rest)), True
    return tp, False


def _convert(key: str, val: Any, tp: Any, meta: Mapping[str, Any]) -> Any:
    base, nullable = _base_type(tp)
    if val is None:
        if nullable or None in meta["choices"]:
            return None
        raise OptionsError(f"{key} must not be empty (null)", key)
    if meta["choices"] and val not in meta["choices"]:
        allowed = ", ".join(repr(c) for c in meta["choices"])
        raise OptionsError(f"{key} must be one of {allowed}, got {val!r}", key)
    if base is bool:
        if not isinstance(val, bool):
            raise OptionsError(f"{key} must be true or false, got {val!r}", key)
        return val
    if base in (int, float):
        return _number(key, val, base, meta)
    if base is str:
        if not isinstance(val, str):
            raise OptionsError(f"{key} must be a string, got {val!r}", key)
        return val
    origin = typing.get_origin(base)
    if origin is tuple:
        if not isinstance(val, (list, tuple)):
            raise OptionsError(f"{key} must be a list, got {val!r}", key)
        inner = typing.get_args(base)[0]
        return tuple(_number(f"{key}[{i}]", v, inner, meta) for i, v in enumerate(val))
    if isinstance(base, type) and issubclass(base, Options):
        if not isinstance(val, (Mapping, base)):
            raise OptionsError(f"{key} must be a mapping, got {val!r}", key)
        return val if isinstance(val, base) else base.from_dict(val, prefix=f"{key}.")
    return val


def _number(key: str, val: Any, base: Any, meta: Mapping[str, Any]) -> float | int:
    if isinstance(val, str):
        # YAML 1.1 (PyYAML) reads 4.2e5, without a dot in the mantissa, as a string
        try:
            val = int(val.strip()) if base is int else float(val.strip())
        except ValueError:
            raise OptionsError(f"{key} must be a number, got {val!r}", key) from None
    try:
        v = check_number(key, val, lo=meta.get("lo"), hi=meta.get("hi"),
                         lo_open=bool(meta.get("lo_open")), unit=meta.get("unit") or "",
                         say_finite=False)
    except ValueError as err:
        raise OptionsError(str(err), key) from None
    if base is int:
        if int(v) != v or isinstance(val, float):
            raise OptionsError(f"{key} must be an integer, got {val!r}", key)
        return int(v)
    return v


@dataclass(frozen=True)
class Options:
    """Base of every controller kind's options (an empty set: a kind without options).

    A subclass's docstring gains a numpydoc ``Parameters`` section written from its fields'
    metadata (:func:`option`), so the options are documented where they are declared.
    """

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        entries: dict[str, tuple[Any, Any, Mapping[str, Any]]] = {}
        for klass in reversed(cls.__mro__):
            own = klass.__dict__
            if "__dataclass_fields__" in own:          # a processed dataclass: its fields
                for f in own["__dataclass_fields__"].values():
                    entries[f.name] = (f.type, f.default, f.metadata)
            for name, ann in own.get("__annotations__", {}).items():
                f = own.get(name)
                if isinstance(f, dataclasses.Field):   # this class, before @dataclass
                    entries[name] = (ann, f.default, f.metadata)
        lines = []
        for name, (ann, default, meta) in entries.items():
            unit = f" [{meta['unit']}]" if meta.get("unit") else ""
            req = ("required" if default is REQUIRED else "default: its own defaults"
                   if isinstance(default, Options) else f"default {default!r}")
            tname = ann if isinstance(ann, str) else _type_name(ann)
            lines += [f"{name} : {tname}, {req}",
                      f"    {meta.get('help') or 'Setting of the same name.'}{unit}"]
        if lines:
            cls.__doc__ = ((cls.__doc__ or "").rstrip() + "\n\nParameters\n----------\n"
                           + "\n".join(lines))

    @classmethod
    def from_dict(cls: type[T], raw: Mapping[str, Any] | None, *, prefix: str = "") -> T:
        """Validated options from a mapping.

        Parameters
        ----------
        raw : mapping or None
            Option name to value (None: every default).
        prefix : str
            Prepended to the names in messages (``lidar.``).

        Returns
        -------
        Options
            An instance of ``cls``.

        Raises
        ------
        OptionsError
            Naming the first unknown key with the allowed ones, a missing required option, or a
            value of the wrong type or out of range.
        """
        raw = dict(raw or {})
        names = [f.name for f in fields(cls)]
        unknown = sorted(set(raw) - set(names))
        if unknown:
            raise OptionsError(f"{prefix}{unknown[0]}: unknown option; allowed: {names}",
                               prefix + unknown[0])
        hints = typing.get_type_hints(cls)
        vals = {}
        for f in fields(cls):
            if f.name in raw:
                vals[f.name] = _convert(prefix + f.name, raw[f.name], hints[f.name], f.metadata)
            elif f.default is REQUIRED:
                raise OptionsError(f"{prefix}{f.name} is required: {f.metadata.get('help', '')}",
                                   prefix + f.name)
        return cls(**vals)

    def to_dict(self) -> dict[str, Any]:
        """Every option with its value (nested options as mappings).

        Returns
        -------
        dict
            Name -> value (tuples as lists, nested options as mappings).
        """
        out = {}
        for f in fields(self):
            v = getattr(self, f.name)
            out[f.name] = v.to_dict() if isinstance(v, Options) else (
                list(v) if isinstance(v, tuple) else v)
        return out

    @classmethod
    def describe(cls) -> list[dict[str, Any]]:
        """One row per option: name, type, default, unit, help, choices and flag."""
        hints = typing.get_type_hints(cls)
        rows = []
        for f in fields(cls):
            default = f.default if f.default is not dataclasses.MISSING else (
                f.default_factory() if f.default_factory is not dataclasses.MISSING else None)
            rows.append({"name": f.name, "type": _type_name(hints[f.name]),
                         "default": default, "unit": f.metadata.get("unit", ""),
                         "help": f.metadata.get("help", ""),
                         "choices": list(f.metadata.get("choices", ())),
                         "flag": flag_of(f)})
        return rows


def flag_of(f: dataclasses.Field) -> str:  # type: ignore[type-arg]
    """The command-line flag of an option field."""
    return f.metadata.get("flag") or "--" + f.name.replace("_", "-")


def _type_name(tp: Any) -> str:
    base, nullable = _base_type(tp)
    name = getattr(base, "__name__", str(base))
    return f"{name} or None" if nullable else name


def option_fields(cls: type[Options]) -> list[dataclasses.Field]:  # type: ignore[type-arg]
    """The fields of an options class."""
    return list(fields(cls))


Builder = Callable[..., Any]

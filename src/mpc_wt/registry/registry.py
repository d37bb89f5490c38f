"""The controller registry: one :class:`ControllerKind` per kind, found by name.

A kind declares its name, its options class, how it finds its operating point and how it
builds the controller; optionally a design function and a gain-table function. An *add-on*
kind (IBC, Coleman IPC) wraps a base controller; a name such as ``derate80+ibc`` selects a
base (``derate`` through its name pattern, with ``power_fraction = 0.8``) and add-ons. The
command line, campaign specs and :func:`~mpc_wt.run.run_controller` all resolve names
and check options here (STYLE rule 10: cvxpy's solver map is the model).

User kinds register with :func:`register`; modules named by ``--plugin`` (command line),
``plugins:`` (campaign spec) or the ``mpc_wt.controllers`` entry-point group are imported by
:func:`load_plugins`, and their registrations are then usable everywhere.
"""
from __future__ import annotations


import importlib
import logging
import re
import sys
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

from mpc_wt.errors import OptionsError
from mpc_wt.registry.options import REQUIRED, Options, flag_of, option_fields

__all__ = ["ControllerKind", "Selection", "Naming", "register", "register_kind", "get_kind",
           "resolve", "kinds", "designs", "describe", "exportable", "law_export", "load_plugins",
           "API_NAMING", "cli_naming"]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class ControllerKind:
    """One registered controller kind.

    Parameters
    ----------
    name : str
        The name users write (``baseline``, ``mpc-lidar``).
    options : type
        Its :class:`~mpc_wt.registry.Options` subclass.
    build : callable
        ``build(ctx, options) -> Built`` for a base kind; ``build(ctx, options, base) -> Built``
        for an add-on (``base`` is the wrapped controller's :class:`Built`).
    summary : str
        One line for listings.
    operating_point : callable, optional
        ``operating_point(turbine, scenario, options) -> OperatingPoint``; default: trim at the
        mean wind.
    addon_to : tuple of str
        Non-empty for an add-on: the base kinds it can wrap.
    default_base : str, optional
        The base an add-on wraps when named alone (``ibc`` = ``baseline+ibc``).
    pattern : str, optional
        A regular expression for parametric names (``derate(\\d+(?:\\.\\d+)?)``) and
        ``pattern_options(match) -> dict`` the options it sets; ``pattern_help`` for messages.
    design : callable, optional
        ``design(turbine, **args) -> (gain-table document, note)`` for ``mpcwt design``.
    design_name : str
        The name under ``mpcwt design`` (default: ``name``).
    more_designs : tuple of (str, callable)
        Further design functions under other names (as ``design``).
    group : str
        Words for messages about options this kind shares with its family
        (``the MPC controllers``).
    field_components : str
        The wind components its build reads from ``ctx.field`` ("uvw", the default; "u": the
        case's field is generated without v and w, a third of the memory and time; the plant
        meets only u either way). A LIDAR that takes its field from
        ``ctx.lidar_field`` (all the built-in ones) needs only "u": that field is made whole
        from the case's seed.
    export : object, optional
        How the kind exports as a Bladed-style controller library
        (:class:`mpc_wt.io.discon_export.LawExport`: its name, what it becomes, its C law and
        the design's numbers for it; ``export.base`` the base an add-on's export is made on).
        A kind with one is exported by ``mpcwt export`` and
        :func:`~mpc_wt.run.export_discon`, and every run calls its compiled law (the design
        as it is shipped). None: the kind's Python step is its law.
    """

    name: str
    options: type[Options]
    build: Callable[..., Any]
    summary: str = ""
    operating_point: Callable[..., Any] | None = None
    addon_to: tuple[str, ...] = ()
    default_base: str | None = None
    pattern: str | None = None
    pattern_options: Callable[[re.Match[str]], dict[str, Any]] | None = None
    pattern_help: str = ""
    design: Callable[..., Any] | None = None
    design_name: str = ""
    more_designs: tuple[tuple[str, Callable[..., Any]], ...] = ()
    group: str = ""
    field_components: str = "uvw"
    export: Any = None

    @property
    def is_addon(self) -> bool:
        """Whether the kind wraps a base controller."""
        return bool(self.addon_to)


_KINDS: dict[str, ControllerKind] = {}
_PLUGINS_LOADED: set[str] = set()
#: The module that registers the kinds mpc-wt ships, imported before any other registration
#: (by its path: the registry itself knows no kind).
BUILTIN_KINDS = "mpc_wt.kinds"
_BUILTIN: list[bool] = []          # [] before, [False] while, [True] after it is imported


def _ensure_builtin() -> None:
    """Import :data:`BUILTIN_KINDS` once, so that the shipped kinds are registered first."""
    if _BUILTIN:
        return
    _BUILTIN.append(False)
    try:
        importlib.import_module(BUILTIN_KINDS)
    except BaseException:
        _BUILTIN.clear()
        raise
    _BUILTIN[0] = True


def register_kind(kind: ControllerKind, *, replace: bool = False) -> ControllerKind:
    """Add a kind to the registry.

    Parameters
    ----------
    kind : ControllerKind
        The kind.
    replace : bool
        Allow replacing a kind of the same name.

    Returns
    -------
    ControllerKind
        ``kind``.

    Raises
    ------
    ValueError
        If the name is taken (and ``replace`` is false) or not a plain name.
    """
    if not re.fullmatch(r"[A-Za-z][A-Za-z0-9_.-]*", kind.name):
        raise ValueError(f"controller kind name must be letters, digits and -_. starting with "
                         f"a letter, got {kind.name!r}")
    _ensure_builtin()
    if kind.name in _KINDS and not replace:
        raise ValueError(f"controller kind {kind.name!r} is registered already")
    _KINDS[kind.name] = kind
    return kind


def register(name: str, options: type[Options] = Options, *, summary: str = "",
             replace: bool = False, **kw: Any) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Decorator: register the decorated build function as controller kind ``name``.

    Parameters
    ----------
    name : str
        The kind's name.
    options : type
        Its options class (default: no options).
    summary : str
        One line for listings.
    replace : bool
        Allow replacing a kind of the same name.
    **kw
        Further :class:`ControllerKind` fields (``operating_point``, ``addon_to``, ...).

    Returns
    -------
    callable
        The decorator; it returns the build function unchanged.
    """
    def deco(build: Callable[..., Any]) -> Callable[..., Any]:
        register_kind(ControllerKind(name=name, options=options, build=build,
                                     summary=summary or (build.__doc__ or "").split("\n")[0],
                                     **kw), replace=replace)
        return build
    return deco


def kinds() -> dict[str, ControllerKind]:
    """Every registered kind by name, in registration order (entry-point plugins loaded).

    Returns
    -------
    dict of str to ControllerKind
        A copy of the registry.
    """
    _ensure_builtin()
    _load_entry_points()
    return dict(_KINDS)


def get_kind(name: str) -> ControllerKind:
    """The kind called ``name`` (no patterns, no add-on syntax).

    Parameters
    ----------
    name : str
        A registered name.

    Returns
    -------
    ControllerKind
        The kind.

    Raises
    ------
    ValueError
        Naming the registered kinds.
    """
    ks = kinds()
    if name not in ks:
        raise ValueError(f"no controller kind {name!r}; kinds are {list(ks)}")
    return ks[name]


@dataclass(frozen=True)
class Naming:
    """How messages name options and controllers: by key for the API and campaign specs, by
    flag for the command line.

    Parameters
    ----------
    key : callable
        Option name -> words (``apc_frequency`` or ``--apc-frequency``).
    one : callable
        Controller name -> words (``controller 'apc'`` or ``--controller apc``).
    many : callable
        Controller names -> words (``controllers ts and apc``).
    """

    key: Callable[[str], str]
    one: Callable[[str], str]
    many: Callable[[Sequence[str]], str]


#: Messages of the Python API and campaign specs.
API_NAMING = Naming(key=lambda k: k, one=lambda n: f"controller {n!r}",
                    many=lambda ns: "controllers " + " and ".join(ns))


def cli_naming(flags: Mapping[str, str]) -> Naming:
    """Messages of the command line: options by their flags.

    Parameters
    ----------
    flags : mapping of str to str
        Option name -> flag.

    Returns
    -------
    Naming
        For :meth:`Selection.options`.
    """
    return Naming(key=lambda k: flags.get(k, k), one=lambda n: f"--controller {n}",
                  many=lambda ns: "--controller " + " and ".join(ns))


@dataclass(frozen=True)
class Selection:
    """A resolved controller name: a base kind, options its name sets, and add-ons.

    Parameters
    ----------
    name : str
        The name as written (``derate80+ibc``).
    base : ControllerKind
        The base kind.
    preset : dict
        Options set by the name (``{"power_fraction": 0.8}``).
    addons : tuple of ControllerKind
        Add-ons, innermost first.
    """

    name: str
    base: ControllerKind
    preset: dict[str, Any] = field(default_factory=dict)
    addons: tuple[ControllerKind, ...] = ()

    @property
    def parts(self) -> tuple[ControllerKind, ...]:
        """The base, then the add-ons."""
        return (self.base, *self.addons)

    @property
    def export(self) -> Any:
        """The export of this composition (:attr:`ControllerKind.export` of its last part,
        where the composition is that export's: an add-on on its export's base), else None."""
        ex = self.parts[-1].export
        if ex is None:
            return None
        base = getattr(ex, "base", None)
        if base is None:
            return ex if not self.addons else None
        bases = (base,) if isinstance(base, str) else tuple(base)
        return ex if len(self.addons) == 1 and self.base.name in bases else None

    @property
    def field_components(self) -> str:
        """The wind components any part reads from the case's field, in ``"uvw"`` order."""
        return "".join(c for c in "uvw" if any(c in k.field_components for k in self.parts))

    def option_names(self) -> set[str]:
        """Every option any part takes.

        Returns
        -------
        set of str
            The option names of the base and its add-ons.
        """
        return {f.name for k in self.parts for f in option_fields(k.options)}

    def options(self, raw: Mapping[str, Any] | tuple[Options, ...] | None = None,
                naming: Naming = API_NAMING) -> tuple[Options, ...]:
        """Split a flat mapping of options over the parts and validate each part's share.

        Parameters
        ----------
        raw : mapping or tuple of Options, optional
            Option name -> value; or options this method returned for the same name, which are
            taken as they are (already checked).
        naming : Naming
            How messages name options and controllers.

        Returns
        -------
        tuple of Options
            One per part, base first.

        Raises
        ------
        OptionsError
            For an option no part takes (naming the kinds that take it), one the name already
            sets, a missing required option, or a bad value; ``.key`` is the option's name.
        """
        if isinstance(raw, tuple):
            if len(raw) == len(self.parts) and all(
                    type(o) is k.options for o, k in zip(raw, self.parts)):
                return raw
            raise OptionsError(f"checked options for {naming.one(self.name)} are one of "
                               f"{[k.options.__name__ for k in self.parts]} each, got "
                               f"{[type(o).__name__ for o in raw]}")
        raw = dict(raw or {})
        for k in raw:
            if k in self.preset:
                raise OptionsError(f"{naming.key(k)} is set by the name {self.name!r}", k)
        raw.update(self.preset)
        out = []
        claimed: set[str] = set()
        for kind in self.parts:
            names = {f.name for f in option_fields(kind.options)}
            mine = {k: v for k, v in raw.items() if k in names}
            claimed |= set(mine)
            for f in option_fields(kind.options):
                if f.default is REQUIRED and f.name not in mine:
                    hint = f.metadata.get("help", "")
                    raise OptionsError(f"{naming.one(self.name)} needs {naming.key(f.name)}"
                                       f"{' (' + hint + ')' if hint else ''}", f.name)
            out.append(kind.options.from_dict(mine))
        stray = [k for k in raw if k not in claimed]
        if stray:
            raise OptionsError(_not_taken(stray[0], self.name, naming), stray[0])
        return tuple(out)


def _not_taken(key: str, name: str, naming: Naming) -> str:
    """The message for an option ``name`` does not take, naming the kinds that do."""
    takers = [k for k in kinds().values()
              if key in {f.name for f in option_fields(k.options)}]
    if not takers:
        allowed = sorted(resolve(name).option_names())
        return f"{naming.key(key)}: unknown option of {naming.one(name)}; allowed: {allowed}"
    groups = {k.group for k in takers}
    owner = _declaring_class(takers[0].options, key)
    flagged = [f for f in option_fields(owner) if f.metadata.get("flag") != ""
               and f.name in owner.__dict__.get("__annotations__", {})]
    if len(groups) == 1 and "" not in groups and key in {f.name for f in flagged}:
        flags = "/".join(naming.key(f.name) for f in flagged)
        return f"{flags} apply to {groups.pop()} only, not to {naming.one(name)}"
    return (f"{naming.key(key)} applies to {naming.many([k.name for k in takers])} only, not "
            f"to {naming.one(name)}")


def _declaring_class(cls: type[Options], key: str) -> type[Options]:
    for c in cls.__mro__:
        if key in c.__dict__.get("__annotations__", {}):
            return c
    return cls


def resolve(name: str) -> Selection:
    """Resolve a controller name (``baseline``, ``derate80+ibc``, ``ibc``) to its parts.

    Parameters
    ----------
    name : str
        The name.

    Returns
    -------
    Selection
        Base, preset options and add-ons.

    Raises
    ------
    ValueError
        For an unknown name (listing the kinds), a bad pattern value or an add-on that does not
        fit its base.
    """
    if not isinstance(name, str) or not name:
        raise ValueError(f"controller must be a non-empty name, got {name!r}")
    ks = kinds()
    head, *rest = name.split("+")
    base, preset = _base_of(head, name, ks)
    addons = []
    if base.is_addon:
        addons.append(base)
        base = ks[base.default_base or ""]
    for a in rest:
        kind = ks.get(a)
        if kind is None or not kind.is_addon:
            raise ValueError(_unknown(name, ks))
        addons.append(kind)
    for a in addons:
        if base.name not in a.addon_to:
            raise ValueError(f"add-on {a.name!r} goes on {list(a.addon_to)}, not on "
                             f"{base.name!r} (in {name!r})")
    return Selection(name=name, base=base, preset=preset, addons=tuple(addons))


def _base_of(head: str, name: str, ks: Mapping[str, ControllerKind]
             ) -> tuple[ControllerKind, dict[str, Any]]:
    if head in ks and not ks[head].pattern:
        return ks[head], {}
    for k in ks.values():
        if k.pattern:
            mt = re.fullmatch(k.pattern, head)
            if mt:
                return k, (k.pattern_options(mt) if k.pattern_options else {})
    raise ValueError(_unknown(name, ks))


def _unknown(name: str, ks: Mapping[str, ControllerKind]) -> str:
    plain = [k.name for k in ks.values() if not k.pattern]
    pats = [k.pattern_help or k.pattern for k in ks.values() if k.pattern]
    addons = [k.name for k in ks.values() if k.is_addon]
    return (f"controller must be one of {plain}" + (f" or {', '.join(pats)}" if pats else "")
            + (f", optionally +ADDON ({'|'.join(addons)}) on a base" if addons else "")
            + f", got {name!r}")


def exportable() -> dict[str, Any]:
    """The controller names that export as a controller library, and their exports.

    Returns
    -------
    dict of str to object
        The export's name (``baseline+lidar-ff``) -> the kind's export
        (:class:`mpc_wt.io.discon_export.LawExport`), in registration order.
    """
    return {k.export.name: k.export for k in kinds().values() if k.export is not None}


def law_export(name: str) -> Any:
    """The export of a controller name: a kind that exports, or an add-on on its export's base
    (``ibc`` is ``baseline+ibc``).

    Parameters
    ----------
    name : str
        A controller name.

    Returns
    -------
    object
        Its export (:class:`mpc_wt.io.discon_export.LawExport`).

    Raises
    ------
    ValueError
        A name that does not export (or no kind), listing those that do.
    """
    try:
        ex = resolve(name).export
    except ValueError:
        ex = None
    if ex is None:
        raise ValueError(f"controller kind {name!r} does not export as a DISCON library; "
                         f"the kinds that do: {sorted(exportable())}")
    return ex


def designs() -> dict[str, ControllerKind]:
    """The kinds with a design function, by their design name.

    Returns
    -------
    dict of str to ControllerKind
        ``design_name`` (or name) -> kind.
    """
    out = {k.design_name or k.name: k for k in kinds().values() if k.design is not None}
    for k in kinds().values():
        for name, fn in k.more_designs:
            out[name] = replace(k, design=fn, design_name=name, more_designs=())
    return out


def describe() -> list[dict[str, Any]]:
    """Every kind with its options, as plain data (``mpcwt controllers --json``).

    Returns
    -------
    list of dict
        ``name``, ``summary``, ``addon_to``, ``pattern``, ``design`` (bool) and ``options``
        (rows of :meth:`Options.describe`).
    """
    return [{"name": k.name, "summary": k.summary, "addon_to": list(k.addon_to),
             "pattern": k.pattern_help or k.pattern, "design": k.design is not None,
             "options": k.options.describe()} for k in kinds().values()]


def cli_flags() -> dict[str, dict[str, Any]]:
    """Every option of every kind that has a command-line flag: name -> field metadata with
    ``flag`` and the option's type (the first kind declaring a name wins).

    Returns
    -------
    dict of str to dict
        Option name -> {flag, help, choices, flag_value, type}.
    """
    import typing

    out: dict[str, dict[str, Any]] = {}
    for k in kinds().values():
        hints = typing.get_type_hints(k.options)
        for f in option_fields(k.options):
            if f.name in out or f.metadata.get("flag") == "":
                continue
            out[f.name] = {**f.metadata, "flag": flag_of(f), "type": hints[f.name]}
    return out


def load_plugins(modules: Sequence[str] = (), folder: str | Path | None = None) -> list[str]:
    """Import modules that register controller kinds (and the entry-point plugins).

    Parameters
    ----------
    modules : sequence of str
        Importable module names (``my_controllers``).
    folder : str or Path, optional
        A folder searched first (a campaign spec's: its plugins are resolved beside it, in
        whatever folder the command runs).

    Returns
    -------
    list of str
        The modules imported now (those imported before are skipped).

    Raises
    ------
    ImportError
        Naming the module that does not import, and why: not found, a syntax error (file and
        line), or what it raised while imported (``SystemExit`` included).
    """
    _load_entry_points()
    done = []
    for mod in modules:
        if mod in _PLUGINS_LOADED:
            continue
        path = [str(folder)] if folder is not None else []
        sys.path[:0] = path
        try:
            importlib.import_module(mod)
        except ImportError as err:
            raise ImportError(f"controller plugin {mod!r} does not import: {err}") from err
        except SyntaxError as err:
            raise ImportError(f"controller plugin {mod!r} does not import: a syntax error at "
                              f"{err.filename}:{err.lineno}: {err.msg}") from err
        except SystemExit as err:
            raise ImportError(f"controller plugin {mod!r} does not import: it raised "
                              f"SystemExit({err.code!r}) while imported") from err
        except Exception as err:
            raise ImportError(f"controller plugin {mod!r} does not import: it raised "
                              f"{type(err).__name__}: {err}") from err
        finally:
            if path and sys.path[:1] == path:
                del sys.path[0]
        _PLUGINS_LOADED.add(mod)
        done.append(mod)
    return done


def _load_entry_points() -> None:
    if "<entry-points>" in _PLUGINS_LOADED:
        return
    _PLUGINS_LOADED.add("<entry-points>")
    from importlib.metadata import entry_points

    for ep in entry_points(group="mpc_wt.controllers"):
        try:
            ep.load()
        except Exception as err:  # noqa: BLE001 - a broken plugin must not break the tool
            log.warning("controller plugin %s (%s) failed to load: %s", ep.name, ep.value, err)

"""The controller registry: every controller kind by name, its typed options and its build.

A kind is one :class:`ControllerKind` (name, frozen options dataclass, how it builds the
controller); :func:`register` adds one, :func:`kinds` and :func:`describe` list them. The
command line, campaign specs and the Python API read this one registry. The kinds mpc-wt ships
are registered by :mod:`mpc_wt.kinds`, imported before any other registration; the registry
itself knows no kind. A build receives a :class:`BuildContext` and returns a :class:`Built`;
designs that cost seconds are kept in a :class:`DesignCache`.
"""
from mpc_wt.registry.context import DEFAULT_CACHE, BuildContext, Built, DesignCache, turbine_key
from mpc_wt.registry.options import REQUIRED, Options, option
from mpc_wt.registry.registry import (
                                     API_NAMING,
                                     ControllerKind,
                                     Naming,
                                     Selection,
                                     cli_naming,
                                     describe,
                                     designs,
                                     exportable,
                                     get_kind,
                                     kinds,
                                     law_export,
                                     load_plugins,
                                     register,
                                     register_kind,
                                     resolve,
)

__all__ = ["DEFAULT_CACHE", "BuildContext", "Built", "DesignCache", "turbine_key", "REQUIRED",
           "Options", "option", "API_NAMING", "ControllerKind", "Naming", "Selection",
           "cli_naming", "describe", "designs", "exportable", "get_kind", "kinds", "law_export",
           "load_plugins", "register", "register_kind", "resolve"]

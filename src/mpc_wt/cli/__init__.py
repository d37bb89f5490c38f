"""The ``mpcwt`` command line (:func:`main`); one module per command group.

:func:`main` loads the toolkit only for a command: ``mpcwt --version`` answers at once.
"""
import importlib
from typing import Any

from mpc_wt.cli.entry import main

__all__ = ["main", "build_parser", "parse_range", "UsageError"]

_WHERE = {"build_parser": "mpc_wt.cli.app", "parse_range": "mpc_wt.cli.common",
          "UsageError": "mpc_wt.errors"}


def __getattr__(name: str) -> Any:
    """A public name of the command line, imported from its module on first use."""
    where = _WHERE.get(name)
    if where is None:
        raise AttributeError(f"module 'mpc_wt.cli' has no attribute {name!r}")
    value = getattr(importlib.import_module(where), name)
    globals()[name] = value
    return value

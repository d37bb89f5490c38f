"""The ``mpcwt`` command line (:func:`main`); one module per command group."""
from mpc_wt.cli.common import parse_range
from mpc_wt.cli.main import build_parser, main
from mpc_wt.errors import UsageError

__all__ = ["main", "build_parser", "parse_range", "UsageError"]

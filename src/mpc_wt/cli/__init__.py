"""The ``mpcwt`` command line (:func:`main`); one module per command group."""
from ..errors import UsageError
from .common import parse_range
from .main import build_parser, main

__all__ = ["main", "build_parser", "parse_range", "UsageError"]

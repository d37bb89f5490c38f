"""Exceptions of ``lidar``, each a subclass of a built-in."""
from __future__ import annotations

__all__ = ["FieldFileError"]


class FieldFileError(ValueError):
    """A wind-field file is missing, truncated, or holds non-finite values."""

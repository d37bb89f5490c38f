"""Standard JSON text: what every JSON file and ``--json`` output of mpc-wt is written with.

Python's ``json`` writes NaN and Infinity, which are not JSON: a strict parser (JavaScript's,
``jq``, most languages') refuses the file. Here an undefined value is ``null``.
"""
from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["to_json", "write_json"]


def _plain(obj: Any) -> Any:
    """``obj`` with numpy scalars and arrays as Python values and non-finite floats as None."""
    if isinstance(obj, dict):
        return {str(k): _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _plain(obj.tolist())
    if isinstance(obj, (np.bool_, bool)):
        return bool(obj)
    if isinstance(obj, (np.integer, int)):
        return int(obj)
    if isinstance(obj, (np.floating, float)):
        v = float(obj)
        return v if math.isfinite(v) else None
    if obj is None or isinstance(obj, str):
        return obj
    return str(obj)


def to_json(obj: Any, indent: int | None = 1) -> str:
    """Standard JSON text of ``obj``: NaN and infinities (undefined values) as null, numpy
    values as numbers, anything else unknown as its string.

    Parameters
    ----------
    obj : Any
        Nested dicts, lists, numbers, strings.
    indent : int or None
        As :func:`json.dumps`.

    Returns
    -------
    str
        JSON that any strict parser reads.
    """
    return json.dumps(_plain(obj), indent=indent, allow_nan=False)


def write_json(path: str | Path, obj: Any, indent: int | None = 1) -> Path:
    """Write ``obj`` to ``path`` as standard JSON.

    Parameters
    ----------
    path : str or Path
        The file.
    obj, indent
        As :func:`to_json`.

    Returns
    -------
    Path
    """
    path = Path(path)
    path.write_text(to_json(obj, indent))
    return path

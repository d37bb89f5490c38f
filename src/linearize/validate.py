"""One helper per recurring check on user input (style rule 6).

Every message names the argument, the value received and what is allowed.
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from linearize._typing import FloatArray


def check_positive(name: str, value: float, *, allow_zero: bool = False) -> float:
    """Return ``value`` as float if it is finite and > 0 (>= 0 with ``allow_zero``)."""
    v = check_finite_scalar(name, value)
    if (v < 0.0) if allow_zero else (v <= 0.0):
        bound = ">= 0" if allow_zero else "> 0"
        raise ValueError(f"{name} must be {bound}, got {value!r}")
    return v


def check_finite_scalar(name: str, value: Any) -> float:
    """Return ``value`` as a finite float or raise naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"{name} must be a real number, got {type(value).__name__} {value!r}")
    v = float(value)
    if not math.isfinite(v):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return v


def check_number(name: str, value: Any, *, lo: float | None = None, hi: float | None = None,
                 lo_open: bool = False, unit: str = "", reason: str = "",
                 say_finite: bool = True) -> float:
    """Return ``value`` as float if it is a finite real number within the bounds.

    Parameters
    ----------
    name : str
        The argument's name, for the message.
    value : object
        The value.
    lo, hi : float, optional
        Bounds (``hi`` included; ``lo`` excluded with ``lo_open``).
    lo_open : bool
        Whether ``lo`` itself is not allowed.
    unit : str
        Unit for the message ("m/s").
    reason : str
        Why, for the message ("the QP must be convex").
    say_finite : bool
        Whether the message says "finite and" before the bounds.

    Returns
    -------
    float
        The value.

    Raises
    ------
    ValueError
        ``{name} must be finite and > 0 m/s, got -1.0`` style: names the argument, what is
        allowed and the value (also for a non-number).
    """
    cond = []
    if lo is not None:
        cond.append(f"{'>' if lo_open else '>='} {lo:g}")
    if hi is not None:
        cond.append(f"<= {hi:g}")
    head = ("finite and " if say_finite else "") if cond else "finite"
    what = (head + " and ".join(cond) + (f" {unit}" if unit else "")
            + (f" ({reason})" if reason else ""))
    ok = not isinstance(value, bool) and isinstance(value, (int, float, np.integer, np.floating))
    v = float(value) if ok else math.nan
    if not (math.isfinite(v) and (lo is None or (v > lo if lo_open else v >= lo))
            and (hi is None or v <= hi)):
        raise ValueError(f"{name} must be {what}, got {value!r}")
    return v


def check_range(name: str, value: float, lo: float, hi: float) -> float:
    """Return ``value`` if ``lo <= value <= hi``."""
    v = check_finite_scalar(name, value)
    if not lo <= v <= hi:
        raise ValueError(f"{name} must be in [{lo:g}, {hi:g}], got {value!r}")
    return v


def check_array(name: str, value: Any, shape: tuple[int | None, ...], *,
                shape_names: str | None = None, finite: bool = True,
                dtype: Any = np.float64) -> FloatArray:
    """Return ``value`` as a float64 (or ``dtype``) array of the given shape (``None`` = any
    length).

    ``shape_names`` is the symbolic shape used in the message, e.g. ``"(n_blade, n_r)"``.
    """
    arr = np.asarray(value, dtype=dtype)
    ok = arr.ndim == len(shape) and all(s is None or s == a for s, a in zip(shape, arr.shape))
    if not ok:
        want = tuple("any" if s is None else s for s in shape)
        sym = f"{shape_names} = " if shape_names else ""
        raise ValueError(f"{name} has shape {arr.shape}; expected {sym}{want}")
    if finite and not np.all(np.isfinite(arr)):
        bad = np.argwhere(~np.isfinite(arr))[0]
        raise ValueError(f"{name} must be finite; entry {tuple(int(i) for i in bad)} is "
                         f"{arr[tuple(bad)]!r}")
    return arr


def check_wind_speed(name: str, value: Any) -> FloatArray:
    """Wind speeds must be finite and >= 0 [m/s]; return them as a float array."""
    arr = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite, got {value!r}")
    if np.any(arr < 0.0):
        raise ValueError(f"{name} must be >= 0 m/s, got {value!r}")
    return arr


def frozen_array(value: Any) -> FloatArray:
    """Copy to a read-only float64 array (for frozen dataclass fields)."""
    arr = np.array(value, dtype=float)
    arr.flags.writeable = False
    return arr

"""The last few values a process computed, by key: what :func:`linearize.plant_params` and
:func:`linearize.rotor_performance` keep for the next caller asking for the same one."""
from __future__ import annotations

import threading
from collections import OrderedDict
from typing import Any, Callable, Hashable


class Kept:
    """The last ``size`` values made, by key, the least recently asked for out first
    (thread-safe; a value is made outside the lock, so two threads asking at once may both
    make it).

    Parameters
    ----------
    size : int
        How many values are kept.
    """

    def __init__(self, size: int) -> None:
        self.size = size
        self._values: OrderedDict[Hashable, Any] = OrderedDict()
        self._lock = threading.Lock()

    def get(self, key: Hashable, make: Callable[[], Any]) -> Any:
        """The value kept under ``key``, else ``make()``, kept.

        Parameters
        ----------
        key : hashable
            What the value is a function of.
        make : callable
            Makes the value on a miss.

        Returns
        -------
        object
        """
        with self._lock:
            if key in self._values:
                self._values.move_to_end(key)
                return self._values[key]
        value = make()
        with self._lock:
            self._values[key] = value
            self._values.move_to_end(key)
            while len(self._values) > self.size:
                self._values.popitem(last=False)
        return value

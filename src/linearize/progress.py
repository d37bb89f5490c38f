"""Progress bars over work whose first item may compile the plant's kernels.

numba compiles the kernels on a process's first use (and caches them beside the package), so
the first trim point or linear model of a fresh install takes tens of seconds and the rest a
fraction of a second: an ETA from that first item is wrong by minutes. These bars name what
they run and show no ETA until the first item is done.
"""
from __future__ import annotations

import sys
from typing import Any, Iterable, Iterator, TypeVar

__all__ = ["progress"]

T = TypeVar("T")


def progress(items: Iterable[T], desc: str, unit: str, enabled: bool = True,
             file: Any = None) -> Iterator[T]:
    """Iterate over ``items`` with a tqdm bar named ``desc``, without an ETA until the first
    item is done (it may compile the kernels).

    Parameters
    ----------
    items : iterable
        The work; a sized one gives the bar its total.
    desc : str
        What runs (the bar's name).
    unit : str
        The unit of one item.
    enabled : bool
        False: no bar.
    file : file-like, optional
        Where the bar goes (default standard error).

    Yields
    ------
    object
        The items, in order.
    """
    from tqdm import tqdm

    bar = tqdm(items, desc=desc, unit=unit, disable=not enabled, file=file or sys.stderr,
               bar_format="{desc}: {n_fmt}/{total_fmt} {unit} [{elapsed}; the first may "
                          "compile the kernels]")
    first = True
    for item in bar:
        yield item
        if first:
            first = False
            bar.bar_format = None

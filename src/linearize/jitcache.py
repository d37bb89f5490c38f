"""numba's disk cache keyed on every source a kernel compiles in.

numba keys a cached kernel on its own file's source only. A kernel that calls
kernels of another module compiles their code into its own, so an edit of the callee's module
(or an upgrade that leaves the caller's file as it was) would load the caller's stale machine
code: the plant would run yesterday's BEM. :func:`key_caches_on_callees` replaces that stamp,
for each cached kernel of a module, with a hash of its own source and of the sources of every
kernel it reaches, so that any change among them recompiles it.
"""
from __future__ import annotations

import hashlib
import inspect
import logging
import sys
import types
from pathlib import Path
from typing import Any

from numba.core.registry import CPUDispatcher

__all__ = ["key_caches_on_callees"]

log = logging.getLogger(__name__)


def _referenced(func: Any) -> list[Any]:
    """The global objects a function's code names, and the attributes of named modules
    those names could reach (``linearize.kernel.step_kernel``)."""
    codes, names = [func.__code__], []
    while codes:
        code = codes.pop()
        names.extend(code.co_names)
        codes.extend(c for c in code.co_consts if isinstance(c, types.CodeType))
    found = []
    for name in names:
        obj = func.__globals__.get(name)
        if isinstance(obj, types.ModuleType):
            found.extend(getattr(obj, n) for n in names if isinstance(getattr(obj, n, None),
                                                                       CPUDispatcher))
        elif obj is not None:
            found.append(obj)
    return found


def _sources(dispatcher: CPUDispatcher) -> set[str]:
    """Source files of every kernel ``dispatcher`` reaches, its own included."""
    seen, todo, files = set(), [dispatcher], set()
    while todo:
        d = todo.pop()
        if id(d) in seen:
            continue
        seen.add(id(d))
        files.add(inspect.getsourcefile(d.py_func) or "")
        todo.extend(o for o in _referenced(d.py_func) if isinstance(o, CPUDispatcher))
    files.discard("")
    return files


def key_caches_on_callees(module_name: str) -> int:
    """Key the disk cache of each cached kernel defined in ``module_name`` on the sources of
    all kernels it compiles in; call it at the end of the module.

    Works through numba's cache object (its attributes as of numba 0.68); on another layout it
    leaves numba's own key.

    Parameters
    ----------
    module_name : str
        The module (imported), usually ``__name__``.

    Returns
    -------
    int
        The number of kernels whose key now covers another module's source.
    """
    module = sys.modules[module_name]
    tied = 0
    for obj in list(vars(module).values()):
        if not (isinstance(obj, CPUDispatcher) and obj.py_func.__module__ == module_name):
            continue
        cache = getattr(obj, "_cache", None)
        cache_file = getattr(cache, "_cache_file", None)
        if cache_file is None or not hasattr(cache_file, "_source_stamp"):
            continue                               # not cached, or another numba
        own = inspect.getsourcefile(obj.py_func)
        others = sorted(_sources(obj) - {own})
        if not others:
            continue
        try:
            h = hashlib.sha256(repr(cache_file._source_stamp).encode())
            for path in others:
                h.update(Path(path).read_bytes())
        except OSError as err:                     # pragma: no cover - sources not on disk
            log.debug("%s keyed on its own source only: %s", obj.__name__, err)
            continue
        cache_file._source_stamp = h.hexdigest()
        tied += 1
    return tied

"""numba's disk cache after an edit of a callee's module: the caller recompiles (numba's own key
would load the stale machine code), and an unchanged tree still loads from the cache."""
from __future__ import annotations

import importlib
import os
import pkgutil
import subprocess
import sys
import types
from pathlib import Path

from numba.core.registry import CPUDispatcher

_CALLEE = "import numba as nb\n\n\n@nb.njit(cache=True)\ndef g(x):\n    return x + {value}\n"
_CALLER = ("import numba as nb\n\nfrom linearize.jitcache import key_caches_on_callees\n"
           "from {pkg}.callee import g\n\n\n@nb.njit(cache=True)\ndef f(x):\n    return 2 * g(x)\n"
           "\n\nkey_caches_on_callees(__name__)\n")
_CALLER_UNKEYED = _CALLER.replace("key_caches_on_callees(__name__)\n", "")


def _run(root: Path, pkg: str) -> tuple[int, str]:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(root / "cache"), NUMBA_DEBUG_CACHE="1",
               PYTHONPATH=os.pathsep.join([str(root), os.environ.get("PYTHONPATH", "")]))
    out = subprocess.run([sys.executable, "-c", f"from {pkg}.caller import f; print(f(1))"],
                         env=env, capture_output=True, text=True, check=True).stdout
    return int(out.strip().splitlines()[-1]), out


def _package(root: Path, pkg: str, caller: str, value: int) -> None:
    (root / pkg).mkdir(exist_ok=True)
    (root / pkg / "__init__.py").write_text("")
    (root / pkg / "callee.py").write_text(_CALLEE.format(value=value))
    (root / pkg / "caller.py").write_text(caller.format(pkg=pkg))


def test_an_edit_of_the_callee_recompiles_the_caller(tmp_path: Path) -> None:
    _package(tmp_path, "keyed", _CALLER, 1)
    assert _run(tmp_path, "keyed")[0] == 4                      # 2 * (1 + 1)
    value, log = _run(tmp_path, "keyed")
    assert value == 4 and "data loaded" in log                   # unchanged: from the cache
    (tmp_path / "keyed" / "callee.py").write_text(_CALLEE.format(value=10))
    assert _run(tmp_path, "keyed")[0] == 22                     # 2 * (1 + 10), not the stale 4


def test_numba_alone_loads_the_stale_caller(tmp_path: Path) -> None:
    """What the key is for: numba 0.68's own key misses the callee's edit. Should numba learn
    to see it, this test fails and the key can go."""
    _package(tmp_path, "unkeyed", _CALLER_UNKEYED, 1)
    assert _run(tmp_path, "unkeyed")[0] == 4
    (tmp_path / "unkeyed" / "callee.py").write_text(_CALLEE.format(value=10))
    assert _run(tmp_path, "unkeyed")[0] == 4


def _modules() -> list[types.ModuleType]:
    out = []
    for name in ("linearize", "lidar", "mpc_wt"):
        pkg = importlib.import_module(name)
        for info in pkgutil.walk_packages(pkg.__path__, name + "."):
            if not info.name.startswith("mpc_wt.cli"):
                out.append(importlib.import_module(info.name))
    return out


def _calls_another_module(d: CPUDispatcher) -> bool:
    """Names in the kernel's code bound, in its module, to another module's kernel."""
    g = d.py_func.__globals__
    return any(isinstance(g.get(n), CPUDispatcher) and g[n].py_func.__module__ != d.__module__
               or isinstance(g.get(n), types.ModuleType) and g[n].__name__.startswith(
                   ("linearize", "lidar", "mpc_wt"))
               for n in d.py_func.__code__.co_names)


def test_every_kernel_that_compiles_another_modules_kernel_is_keyed_on_it() -> None:
    plain, seen = [], 0
    for module in _modules():
        for name, obj in vars(module).items():
            if (isinstance(obj, CPUDispatcher) and obj.py_func.__module__ == module.__name__
                    and obj._cache.__class__.__name__ == "FunctionCache"
                    and _calls_another_module(obj)):
                seen += 1
                stamp = obj._cache._cache_file._source_stamp
                if stamp == obj._cache._impl.locator.get_source_stamp():
                    plain.append(f"{module.__name__}.{name}")
    assert seen >= 8 and not plain, f"keyed on their own file only: {plain}"


def test_steady_and_grid_winds_share_one_compiled_plant_kernel() -> None:
    """numba compiles a kernel again for every new combination of argument types, read-only
    arrays apart from writable ones, and the plant's simulation kernel takes tens of seconds.
    A steady wind and a gridded one, a read-only trim state and input history and writable
    ones, all run on one compiled version of it; the closed loop's step kernel, stepped in
    both winds, has one too. (A kernel another loads from numba's cache, as the step inside
    the simulation kernel, lists no version of its own: the step is counted where it is
    called.)"""
    import numpy as np

    import linearize
    from linearize import kernel

    tb = linearize.load_turbine("nrel5mw")
    params = linearize.plant_params(tb)
    op = linearize.trim(tb, 12.0)
    assert not op.x.flags.writeable                   # the trim hands out read-only states
    t, y, z = np.array([0.0, 1.0]), np.array([-80.0, 80.0]), np.array([0.0, 200.0])
    grid = linearize.GridWind(t, y, z, np.full((2, 2, 2), 12.0, np.float32))
    u_ro = np.tile(op.u, (3, 1))
    u_ro.flags.writeable = False
    for wind in (linearize.SteadyWind(12.0), grid):
        for x0, u in ((op.x, u_ro), (np.array(op.x), np.array(u_ro))):
            linearize.rk4_simulate(params, x0, u, wind, duration=3 / 80)
    real = [s for s in kernel.simulate_kernel.signatures if "complex" not in str(s)]
    assert len(real) == 1, real
    x, x_out, z_out = np.array(op.x), np.empty_like(op.x), np.empty(len(linearize.OUTPUT_NAMES))
    for wind in (linearize.SteadyWind(12.0), grid):
        linearize.PlantStepper(params, wind, duration=0.5).step_into(0.0, x, np.array(op.u),
                                                                     x_out, z_out)
    steps = kernel.step_kernel.signatures
    assert len(steps) == 1, steps

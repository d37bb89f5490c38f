"""Every public function, class and method of ``linearize``, ``lidar`` and ``mpc_wt`` documents
its parameters and its return value in numpydoc sections (python-control's
``docstrings_test.py`` shows the idea). Public means: named in a module's ``__all__``; methods:
those a public class defines without a leading underscore (an override without a docstring
inherits its base's)."""
from __future__ import annotations

import importlib
import inspect
import pkgutil
from typing import Any

import pytest

import lidar
import linearize
import mpc_wt

PACKAGES = (linearize, lidar, mpc_wt)


def _public_api() -> dict[str, Any]:
    out: dict[str, Any] = {}
    mods = [p.__name__ for p in PACKAGES] + [
        m.name for p in PACKAGES for m in pkgutil.walk_packages(p.__path__, p.__name__ + ".")
        if not m.name.endswith("__main__")]
    for name in mods:
        mod = importlib.import_module(name)
        for attr in getattr(mod, "__all__", []):
            obj = getattr(mod, attr)
            if not (inspect.isfunction(obj) or inspect.isclass(obj)):
                continue
            if not getattr(obj, "__module__", "").startswith(name.split(".")[0]):
                continue
            out[f"{obj.__module__}.{obj.__qualname__}"] = obj
            if inspect.isclass(obj):
                for mname, meth in vars(obj).items():
                    if not mname.startswith("_") and inspect.isfunction(meth):
                        out[f"{obj.__module__}.{obj.__qualname__}.{mname}"] = meth
    return out


def _missing(obj: Any) -> list[str]:
    """The numpydoc sections an object lacks."""
    doc = inspect.getdoc(obj) or ""
    if inspect.isclass(obj):
        if issubclass(obj, BaseException) or getattr(obj, "_is_protocol", False):
            return []
        try:
            params = inspect.signature(obj).parameters
        except (TypeError, ValueError):
            return []
        return ["Parameters"] if params and "Parameters\n---" not in doc else []
    sig = inspect.signature(obj)
    out = []
    if any(p not in ("self", "cls") for p in sig.parameters) and "Parameters\n---" not in doc:
        out.append("Parameters")
    result = "Yields" if inspect.isgeneratorfunction(obj) else "Returns"   # numpydoc's names
    if sig.return_annotation not in (None, "None", inspect.Signature.empty) \
            and f"{result}\n---" not in doc:
        out.append(result)
    return out


API = _public_api()


def test_the_public_api_is_listed() -> None:
    # the names the issue asks for, and a floor on the size of what is checked
    for name in ("mpc_wt.controllers.mpc.MPC", "mpc_wt.controllers.mpc.MPCSettings", "mpc_wt.controllers.lqr.design_lqr",
                 "mpc_wt.simulation.loop.simulate_closed_loop", "mpc_wt.run.run_controller",
                 "mpc_wt.registry.registry.register"):
        assert name in API
    assert len(API) > 200


@pytest.mark.parametrize("name", sorted(API))
def test_public_object_has_numpydoc_sections(name: str) -> None:
    missing = _missing(API[name])
    assert not missing, f"{name} lacks the numpydoc section(s) {missing}"


def test_checker_finds_a_missing_section() -> None:
    def f(x: float) -> float:
        """Twice x."""
        return 2 * x

    def g(x: float) -> float:
        """Twice x.

        Parameters
        ----------
        x : float
            A number.

        Returns
        -------
        float
            2 x.
        """
        return 2 * x

    assert _missing(f) == ["Parameters", "Returns"] and _missing(g) == []

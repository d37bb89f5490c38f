"""Load a turbine by name, from a ``turbine.yaml`` file or from an OpenFAST deck.

The one entry point that knows every turbine source: native YAML (:mod:`linearize.turbine`) and
OpenFAST decks (:mod:`linearize.openfast`), which both build on the turbine's dataclasses.
"""
from __future__ import annotations

from importlib import resources
from pathlib import Path
from typing import Any

from linearize.openfast import load_openfast
from linearize.turbine import (
    Turbine,
    available_turbines,
    check_keys,
    check_schema_version,
    read_turbine_mapping,
    turbine_from_mapping,
)

__all__ = ["load_turbine"]


def load_turbine(name_or_path: str | Path = "nrel5mw") -> Turbine:
    """Load a turbine shipped with mpc-wt (by name), a turbine file or an OpenFAST deck.

    Parameters
    ----------
    name_or_path : str or Path
        A packaged name (see :func:`available_turbines`, default ``"nrel5mw"``), a path to a
        ``turbine.yaml`` file or a directory holding one, or an OpenFAST ``.fst`` deck (read by
        :func:`linearize.load_openfast`, whose report is ``Turbine.report``).

    Returns
    -------
    Turbine

    Raises
    ------
    TurbineFileError
        Naming the file, the field and the allowed range: unknown or missing keys, values out of
        range, non-monotonic span, polars not covering -180..180 deg, non-positive masses or
        stiffnesses, elements outside the rotor; for decks, the file and key.
    FileNotFoundError
        If neither a packaged name nor an existing path.
    """
    text = str(name_or_path)
    if isinstance(name_or_path, str) and text in available_turbines():
        ref = resources.files("linearize") / "data" / text / "turbine.yaml"
        with resources.as_file(ref) as p:
            return _load_path(Path(p))
    path = Path(name_or_path)
    if path.is_dir():
        path = path / "turbine.yaml"
    if not path.is_file():
        raise FileNotFoundError(
            f"turbine {text!r} is neither a packaged turbine {available_turbines()} "
            f"nor an existing turbine file or OpenFAST .fst deck")
    if path.suffix.lower() == ".fst":
        return load_openfast(path)
    return _load_path(path)


def _load_path(path: Path) -> Turbine:
    raw = read_turbine_mapping(path)
    if "openfast_deck" in raw:
        return _load_deck_pointer(path, raw)
    return turbine_from_mapping(path, raw)


def _load_deck_pointer(path: Path, raw: dict[str, Any]) -> Turbine:
    """A ``turbine.yaml`` that names an OpenFAST deck: ``schema_version``, ``name`` and
    ``openfast_deck`` (path relative to the YAML file)."""
    check_keys(path, "top level", raw, {"schema_version", "name", "openfast_deck"})
    check_schema_version(path, raw)
    return load_openfast(path.parent / str(raw["openfast_deck"]), name=str(raw["name"]))

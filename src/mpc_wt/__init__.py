"""mpc-wt: model-based wind-turbine control design.

Controllers, closed-loop simulation, assessment and the ``mpcwt`` command line. Builds on
``linearize`` (the plant) and ``lidar`` (wind fields and preview).
"""
from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("mpc-wt")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0+unknown"

__all__ = ["__version__"]

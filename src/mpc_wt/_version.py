"""The installed distribution's version."""
from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("mpc-wt")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0+unknown"

__all__ = ["__version__"]

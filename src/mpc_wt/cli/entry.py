"""The ``mpcwt`` script's entry: ``mpcwt --version`` answers before the toolkit is loaded;
every other command loads what it needs (:func:`mpc_wt.cli.app.main`)."""
from __future__ import annotations

import sys
from typing import Sequence

__all__ = ["main"]


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``mpcwt`` with ``argv`` (default ``sys.argv[1:]``).

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments.

    Returns
    -------
    int
        The exit status.
    """
    args = list(sys.argv[1:] if argv is None else argv)
    if args == ["--version"]:
        from mpc_wt._version import __version__

        print(f"mpcwt (mpc-wt) {__version__}")
        raise SystemExit(0)         # as argparse's version action
    from mpc_wt.cli.app import main as run

    return run(argv)

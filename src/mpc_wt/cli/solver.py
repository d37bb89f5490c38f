"""``mpcwt solver fetch`` and ``mpcwt solver status``: the QP solver's C sources that an
exported MPC library is built with, in the per-user cache."""
from __future__ import annotations

import argparse
from typing import Any

from mpc_wt.cli.common import to_json

__all__ = ["add_parsers"]


def add_parsers(sub: Any) -> None:
    """Add ``solver`` to the subcommands.

    Parameters
    ----------
    sub : argparse subparsers action
        Of the top-level parser.
    """
    p = sub.add_parser("solver", help="the exported MPC's QP solver sources (DAQP's published "
                       "source distribution, cached per user)")
    cmd = p.add_subparsers(dest="solver_command", required=True)
    q = cmd.add_parser("fetch", help="download DAQP's source distribution with pip (or take "
                       "--from FILE), check its SHA-256 and cache it")
    q.add_argument("--from", dest="archive", default=None, metavar="FILE",
                   help="daqp-<version>.tar.gz copied from a machine that has it")
    q.set_defaults(func=_fetch)
    q = cmd.add_parser("status", help="where the cache is and whether it holds the sources")
    q.add_argument("--json", action="store_true")
    q.set_defaults(func=_status)


def _fetch(args: argparse.Namespace) -> int:
    from mpc_wt.io import solver_sources as ss

    if args.archive is not None:
        path = ss.install_daqp_archive(args.archive)
    else:
        path = ss.fetch_daqp()
    src = ss.daqp_sources(download=False)
    print(f"DAQP {src.version}: {len(src.c_files)} C files, SHA-256 "
          f"{ss.DAQP_SDIST_SHA256[src.version]} checked; cached at {path}")
    return 0


def _status(args: argparse.Namespace) -> int:
    from mpc_wt.errors import SolverSourceError
    from mpc_wt.io import solver_sources as ss

    try:
        src = ss.daqp_sources(download=False)
        state, archive = "cached", str(src.archive)
    except SolverSourceError as err:
        state, archive = f"missing: {err}", None
    doc = {"cache": str(ss.cache_dir()), "solver": "daqp", "version": ss.DAQP_VERSION,
           "sha256": ss.DAQP_SDIST_SHA256[ss.DAQP_VERSION], "archive": archive, "state": state}
    if args.json:
        print(to_json(doc))
    else:
        print(f"cache: {doc['cache']}\nDAQP {doc['version']} (sha256 {doc['sha256']}): {state}")
    return 0

"""The ``mpcwt`` command line: one module per command group, each adding its parsers.

Subcommands::

    run          the main job on a turbine: steady operating table, C_P surface, baseline run
    trim         steady operating points against wind speed (table or --json)
    linearize    linear models over mean wind, saved as .mat/.npz/.json (--json summary)
    aero         rotor aerodynamics: aero cp-surface --out FILE.csv [--plot FILE.png]
    simulate     closed loop of any registered controller kind: simulate --controller
                 baseline --wind 18 --out RUN
    controllers  the registered controller kinds and their options
    assess       DELs, CS1-CS5, pitch duty, energy of runs or CSV time series
    wind         turbulent wind fields: wind generate --mean 18 --class A --out FIELD.bts
    lidar        CW LIDAR preview: lidar evaluate --field FIELD [--focus 54] [--json]
    design       gain synthesis: design baseline|lqr|ts|ibc|coleman-ipc [...] --out DIR
    export       gain tables: export DIR --format csv|json|mat|rosco
    campaign     load-case campaigns on Dask: campaign run SPEC.yaml, status, report
    tune         design parameters optimized over load cases: tune SPEC.yaml --out DIR
    bench        bench mpc: QP solver comparison
    compare-openfast  an OpenFAST case run on mpc-wt's plant, compared with its output:
                 compare-openfast CASE.fst --outb CASE.outb [--wind FILE.bts]
    verify-openfast  a kind exported and run in your OpenFAST and on mpc-wt's plant,
                 differences flagged: verify-openfast KIND CASE.fst --out DIR
    solver       the exported MPC's QP solver sources: solver fetch [--from FILE], status

``--plugin MODULE`` (before the subcommand, repeatable) imports a module that registers
controller kinds, which ``simulate`` and campaign specs can then use.

Errors in the arguments or the turbine file print one line naming the parameter and the value
to stderr and exit with status 2; no command does its work before its arguments are checked.
"""
from __future__ import annotations

import argparse
import logging
import sys
from pathlib import Path
from typing import Sequence

import linearize
from mpc_wt.cli import campaign, compare, design, runs, solver, steady, wind
from mpc_wt.errors import (CampaignIndexError, CampaignLockedError, ControllerLibraryError,
                           OpenFASTRunError, UsageError)

__all__ = ["main", "build_parser"]

_GROUPS = (runs, steady, wind, design, campaign, compare, solver)


def build_parser() -> argparse.ArgumentParser:
    """The ``mpcwt`` parser, with the controller kinds registered now.

    Returns
    -------
    argparse.ArgumentParser
        Every command group's subcommands.
    """
    from mpc_wt import __version__

    ap = argparse.ArgumentParser(
        prog="mpcwt", description="mpc-wt: model-based wind-turbine control design. Run the "
        "main job on a turbine, design and simulate controllers, assess loads, run load-case "
        "campaigns, export gains and controller libraries, compare with OpenFAST.")
    ap.add_argument("--version", action="version", version=f"mpcwt (mpc-wt) {__version__}")
    ap.add_argument("--plugin", action="append", default=[], metavar="MODULE",
                    help="import MODULE, which registers controller kinds (repeatable)")
    sub = ap.add_subparsers(dest="command", required=True)
    for group in _GROUPS:
        group.add_parsers(sub)
    return ap


def _plugins(argv: Sequence[str]) -> list[str]:
    """The ``--plugin`` modules, read before the parser is built (its choices include them)."""
    mods = []
    for i, a in enumerate(argv):
        if a == "--plugin" and i + 1 < len(argv):
            mods.append(argv[i + 1])
        elif a.startswith("--plugin="):
            mods.append(a.split("=", 1)[1])
    return mods


_ERRORS = (UsageError, linearize.TurbineFileError, linearize.TrimError, FileNotFoundError,
           ValueError, KeyError, ImportError, linearize.LinearizationError,
           CampaignLockedError, PermissionError, FileExistsError, NotADirectoryError,
           IsADirectoryError)


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``mpcwt``.

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments (default ``sys.argv[1:]``).

    Returns
    -------
    int
        0 on success; 1 when a run failed (a simulation diverged, a controller library stopped
        it), a campaign finished with failed cases or a tuning found no design that meets its
        constraints; 2 on a usage or input error (the message names the parameter and the
        value); 130 when interrupted (Ctrl-C).
    """
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    argv = list(sys.argv[1:] if argv is None else argv)
    try:
        from mpc_wt.registry.registry import load_plugins

        load_plugins(_plugins(argv), folder=Path.cwd())     # as ``python -m`` finds them
    except ImportError as err:
        print(f"mpcwt: error: --plugin: {err}", file=sys.stderr)
        return 2
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args))
    except KeyboardInterrupt:
        resume = {"campaign": "run the same command again to resume: finished cases are kept",
                  "tune": "run the same command again to resume: finished trials are kept"}
        print(f"mpcwt {args.command}: interrupted; "
              f"{resume.get(args.command, 'nothing was written after the interruption')}",
              file=sys.stderr)
        return 130
    except (linearize.SimulationDivergedError, ControllerLibraryError) as err:
        if getattr(err, "partial", None) is None and isinstance(err, ControllerLibraryError):
            print(f"mpcwt {args.command}: error: {err}", file=sys.stderr)
            return 2                          # the library could not be loaded: input
        print(f"mpcwt {args.command}: run failed: {err}", file=sys.stderr)
        return 1
    except OpenFASTRunError as err:            # none found: input; it failed: the run
        print(f"mpcwt {args.command}: {'run failed' if err.ran else 'error'}: {err}",
              file=sys.stderr)
        return 1 if err.ran else 2
    except CampaignIndexError as err:         # a full disk: the run failed; damaged: input
        print(f"mpcwt {args.command}: {'run failed' if err.storage else 'error'}: {err}",
              file=sys.stderr)
        return 1 if err.storage else 2
    except _ERRORS as err:
        print(f"mpcwt {args.command}: error: {err}", file=sys.stderr)
        return 2
    except OSError as err:                    # a full disk, a lost mount: the run failed
        print(f"mpcwt {args.command}: run failed: {err}", file=sys.stderr)
        return 1

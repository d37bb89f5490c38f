"""Shared parts of the studies: the paper studies' command line (run length, discarded
transient, output folder), the seed-grid studies' (winds, seeds, run length, discarded
transient, workers) and an iterator with a length for the progress bars."""
from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any, Callable


class Sized:
    """An iterator with a length, for the progress bar's total."""

    def __init__(self, it: Any, n: int) -> None:
        self.it, self.n = it, n

    def __len__(self) -> int:
        return self.n

    def __iter__(self) -> Any:
        return iter(self.it)


def study_args(doc: str, default_out: str,
               extra: Callable[[argparse.ArgumentParser], None] | None = None
               ) -> tuple[argparse.Namespace, Path]:
    """Parse --duration, --transient, --out (created) and the study's own options."""
    ap = argparse.ArgumentParser(description=doc.split("\n")[0])
    ap.add_argument("--duration", type=float, default=600.0, help="assessed length [s]")
    ap.add_argument("--transient", type=float, default=60.0, help="discarded start [s]")
    ap.add_argument("--out", default=default_out)
    if extra is not None:
        extra(ap)
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    return args, out


def add_grid_args(ap: argparse.ArgumentParser, winds: str) -> None:
    """Add a seed-grid study's --winds (default ``winds``), --seeds, --duration, --transient
    and --workers."""
    ap.add_argument("--winds", default=winds, help="mean winds [m/s]")
    ap.add_argument("--seeds", default="11,12")
    ap.add_argument("--duration", type=float, default=300.0, help="assessed length [s]")
    ap.add_argument("--transient", type=float, default=30.0, help="discarded start [s]")
    ap.add_argument("--workers", type=int, default=2)


def grid(args: argparse.Namespace) -> tuple[list[float], list[int]]:
    """The winds [m/s] and seeds of :func:`add_grid_args`'s options."""
    return ([float(x) for x in args.winds.split(",")],
            [int(x) for x in args.seeds.split(",")])

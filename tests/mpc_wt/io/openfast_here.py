"""The OpenFAST the tests may run: the user's (``$MPCWT_OPENFAST`` or ``openfast`` on ``PATH``,
as :func:`mpc_wt.io.openfast_run.find_openfast` finds it), else the v5.0.0 binary beside the
checkout; None without either (the tests that need it skip)."""
from __future__ import annotations

import os
from pathlib import Path

from mpc_wt.errors import OpenFASTRunError
from mpc_wt.io.openfast_run import find_openfast

SHARED = Path(__file__).resolve().parents[4] / "shared"
BINARY = SHARED / "tools" / "openfast" / "bin" / "openfast"


def installed_openfast() -> str | None:
    """The executable's path, or None."""
    try:
        return str(find_openfast())
    except OpenFASTRunError:
        return str(BINARY) if BINARY.is_file() and os.access(BINARY, os.X_OK) else None

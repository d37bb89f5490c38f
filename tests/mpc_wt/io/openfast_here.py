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


def exported(kind: str, folder: Path):
    """The NREL 5-MW's ``kind`` exported into ``folder`` (:func:`mpc_wt.run.export_discon`);
    the test skips without a C compiler."""
    import pytest

    import linearize
    from mpc_wt.io.discon_export import find_compiler
    from mpc_wt.run import export_discon

    if find_compiler() is None:
        pytest.skip("needs a C compiler")
    return export_discon(linearize.load_turbine("nrel5mw"), kind, folder)

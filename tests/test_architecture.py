"""Imports flow one way: mpc_wt -> linearize, mpc_wt -> lidar; linearize and lidar import
neither mpc_wt nor each other (STYLE.md rule 1). Walks every import with ast."""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src"
FORBIDDEN = {"linearize": {"mpc_wt", "lidar"}, "lidar": {"mpc_wt", "linearize"}, "mpc_wt": set()}


def _imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text(), filename=str(path))
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out.update(a.name.split(".")[0] for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            out.add(node.module.split(".")[0])
    return out


@pytest.mark.parametrize("package", sorted(FORBIDDEN))
def test_no_forbidden_imports(package: str) -> None:
    files = sorted((SRC / package).rglob("*.py"))
    assert files, f"no sources found for {package}"
    bad = {str(f.relative_to(SRC)): sorted(_imports(f) & FORBIDDEN[package]) for f in files}
    bad = {k: v for k, v in bad.items() if v}
    assert not bad, f"forbidden imports: {bad}"


def test_checker_catches_a_forbidden_edge(tmp_path: Path) -> None:
    f = tmp_path / "x.py"
    f.write_text("import numpy\nfrom mpc_wt.cli import main\n")
    assert "mpc_wt" in _imports(f)


def test_init_files_have_no_logic() -> None:
    """Re-exports and ``__all__`` only; a module ``__getattr__`` may serve names lazily (the
    controllers package serves the registry's plugin API that way)."""
    for init in SRC.rglob("__init__.py"):
        tree = ast.parse(init.read_text())
        for node in tree.body:
            if isinstance(node, ast.FunctionDef) and node.name == "__getattr__":
                continue
            assert isinstance(node, (ast.Expr, ast.Import, ast.ImportFrom, ast.Assign,
                                     ast.AnnAssign, ast.Try)), \
                f"{init}: only re-exports and __all__ allowed, found {type(node).__name__}"


def _private_imports(path: Path) -> list[str]:
    """Names starting with ``_`` imported from linearize or lidar (modules or attributes)."""
    tree = ast.parse(path.read_text(), filename=str(path))
    bad = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            root = node.module.split(".")[0]
            if root in ("linearize", "lidar"):
                parts = node.module.split(".")[1:] + [a.name for a in node.names]
                bad += [f"{node.module}.{a.name}" for a in node.names
                        if any(p.startswith("_") for p in parts)]
        elif isinstance(node, ast.Import):
            bad += [a.name for a in node.names if a.name.split(".")[0] in ("linearize", "lidar")
                    and any(p.startswith("_") for p in a.name.split(".")[1:])]
        elif isinstance(node, ast.Attribute) and node.attr.startswith("_") \
                and not node.attr.startswith("__"):
            base = node.value
            while isinstance(base, ast.Attribute):
                base = base.value
            if isinstance(base, ast.Name) and base.id in ("linearize", "lidar"):
                bad.append(f"{base.id}...{node.attr}")
    return bad


def test_mpc_wt_imports_no_private_name_of_linearize_or_lidar() -> None:
    bad = {str(f.relative_to(SRC)): _private_imports(f)
           for f in sorted((SRC / "mpc_wt").rglob("*.py"))}
    bad = {k: v for k, v in bad.items() if v}
    assert not bad, f"private names of linearize/lidar used in mpc_wt: {bad}"


def test_private_import_checker_catches_one(tmp_path: Path) -> None:
    f = tmp_path / "x.py"
    f.write_text("from linearize.plant import _rk4\nimport linearize\nlinearize.plant._eval\n"
                 "from linearize import trim\n")
    assert _private_imports(f) == ["linearize.plant._rk4", "linearize..._eval"]


def _is_numba_kernel(fn: ast.FunctionDef) -> bool:
    for d in fn.decorator_list:
        target = d.func if isinstance(d, ast.Call) else d
        name = target.attr if isinstance(target, ast.Attribute) else getattr(target, "id", "")
        if name in ("njit", "jit", "vectorize", "guvectorize"):
            return True
    return False


def _long_functions(path: Path, limit: int = 80) -> list[str]:
    tree = ast.parse(path.read_text(), filename=str(path))
    return [f"{fn.name} ({fn.end_lineno - fn.lineno + 1} lines)" for fn in ast.walk(tree)
            if isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef))
            and fn.end_lineno - fn.lineno + 1 > limit and not _is_numba_kernel(fn)]


def test_no_function_in_mpc_wt_longer_than_80_lines() -> None:
    """STYLE rule 12: an orchestration function past 60-80 lines hides a step."""
    bad = {str(f.relative_to(SRC)): _long_functions(f)
           for f in sorted((SRC / "mpc_wt").rglob("*.py"))}
    bad = {k: v for k, v in bad.items() if v}
    assert not bad, f"functions longer than 80 lines: {bad}"


def test_length_checker_counts_lines_and_spares_kernels(tmp_path: Path) -> None:
    f = tmp_path / "x.py"
    body = "\n".join(f"    x{i} = {i}" for i in range(81))
    f.write_text(f"import numba as nb\n\ndef long():\n{body}\n\n\n@nb.njit\ndef kern():\n"
                 f"{body}\n")
    assert _long_functions(f) == ["long (82 lines)"]


def test_runs_module_is_gone_and_one_simulation_diverged_error() -> None:
    assert not (SRC / "mpc_wt" / "runs.py").exists()
    import linearize
    import mpc_wt
    from mpc_wt.simulation import loop

    assert mpc_wt.SimulationDivergedError is linearize.SimulationDivergedError
    assert loop.SimulationDivergedError is linearize.SimulationDivergedError
    for pkg in ("linearize", "lidar", "mpc_wt"):
        tree = ast.parse((SRC / pkg / "errors.py").read_text())
        classes = [n.name for n in tree.body if isinstance(n, ast.ClassDef)]
        assert classes, pkg
    # exception classes are defined only in the errors modules
    for f in sorted(SRC.rglob("*.py")):
        if f.name == "errors.py":
            continue
        tree = ast.parse(f.read_text())
        for n in ast.walk(tree):
            if isinstance(n, ast.ClassDef) and n.name.endswith("Error"):
                raise AssertionError(f"{f.relative_to(SRC)} defines {n.name}; errors belong "
                                     f"in the package's errors module")


#: What marks a file as someone else's: a licence file, a licence or copyright header, the
#: definition of a known QP solver's entry point (DAQP, OSQP, qpOASES, HPIPM, Eigen's own).
_LICENCE_FILES = ("LICENSE", "LICENCE", "COPYING", "NOTICE")
_FOREIGN_HEADERS = ("SPDX-License-Identifier", "Permission is hereby granted",
                    "Licensed under the", "Copyright (c)", "Copyright (C)", "GNU General Public",
                    "Redistribution and use in source")
_SOLVER_DEFINITIONS = ("setup_daqp(", "daqp_solve(", "osqp_setup(", "osqp_solve(",
                       "qpOASES_", "d_ocp_qp_ipm_solve(", "EIGEN_WORLD_VERSION")


def _foreign_files(root: Path) -> list[str]:
    """The files under ``root`` that are not ours: licence files, files whose first 60 lines
    carry a licence or copyright header, C and C++ sources that define a known QP solver."""
    bad = []
    for p in sorted(root.rglob("*")):
        if not p.is_file() or "__pycache__" in p.parts:
            continue
        rel = str(p.relative_to(root))
        if p.name.split(".")[0].upper() in _LICENCE_FILES:
            bad.append(f"{rel}: a licence file")
            continue
        if p.suffix not in (".py", ".c", ".h", ".cpp", ".hpp", ".f90", ".f", ".pyx"):
            continue
        text = p.read_text(errors="replace")
        head = "\n".join(text.splitlines()[:60])
        hits = [h for h in _FOREIGN_HEADERS if h in head]
        if p.suffix in (".c", ".h", ".cpp", ".hpp"):
            hits += [d for d in _SOLVER_DEFINITIONS if d in text and _defines(text, d)]
        if hits:
            bad.append(f"{rel}: {', '.join(hits)}")
    return bad


def _defines(text: str, name: str) -> bool:
    """Whether C source ``text`` defines (not only calls) ``name``: the name at the start of a
    line or after a return type at the start of a line, followed by a body."""
    for line in text.splitlines():
        s = line.strip()
        if name in s and not s.startswith(("//", "/*", "*")) and not line.startswith((" ", "\t")) \
                and not s.endswith(";"):
            return True
    return False


def test_no_third_party_code_in_src() -> None:
    """mpc-wt's sources are its own: no vendored library (the exported MPC's QP solver comes
    from DAQP's published distribution at export time)."""
    assert _foreign_files(SRC) == []


def test_the_foreign_code_check_catches_a_vendored_solver(tmp_path: Path) -> None:
    (tmp_path / "solver").mkdir()
    (tmp_path / "solver" / "LICENSE").write_text("MIT License\n")
    (tmp_path / "solver" / "api.c").write_text(
        "#include \"api.h\"\nint setup_daqp(DAQPProblem *p, DAQPWorkspace *w, c_float *t)\n{\n"
        "    return 0;\n}\n")
    (tmp_path / "lib.py").write_text("# SPDX-License-Identifier: BSD-3-Clause\nx = 1\n")
    (tmp_path / "ours.c").write_text("static int f(void)\n{\n    return setup_daqp(0, 0, 0);\n}\n")
    bad = _foreign_files(tmp_path)
    assert [b.split(":")[0] for b in bad] == ["lib.py", "solver/LICENSE", "solver/api.c"]

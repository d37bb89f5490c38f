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
    for init in SRC.rglob("__init__.py"):
        tree = ast.parse(init.read_text())
        for node in tree.body:
            assert isinstance(node, (ast.Expr, ast.Import, ast.ImportFrom, ast.Assign,
                                     ast.AnnAssign, ast.Try)), \
                f"{init}: only re-exports and __all__ allowed, found {type(node).__name__}"

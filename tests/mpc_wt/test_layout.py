"""The layout by role holds: layers inside ``mpc_wt``, no import cycle anywhere, no private
name used from another module, and the public API and plugin registration where users find
them. Imports are read with ``ast`` (every import statement, also those inside functions)."""
from __future__ import annotations

import ast
import importlib
import re
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[2] / "src"
PACKAGES = ("linearize", "lidar", "mpc_wt")

#: what each part of mpc_wt may not import (parts: subpackages and top-level modules)
FORBIDDEN = {
    "controllers": {"simulation", "registry", "kinds", "run", "campaign", "tuning", "cli",
                    "plotting", "io"},
    "simulation": {"registry", "kinds", "run", "campaign", "tuning", "cli"},
    "assessment": {"controllers", "simulation", "registry", "kinds", "run", "campaign", "tuning",
                   "cli", "plotting", "io"},
    "io": {"simulation", "registry", "kinds", "run", "campaign", "tuning", "cli", "plotting"},
    # the mechanism only: it knows no controller, no format and no kind
    "registry": {"controllers", "io", "kinds", "plotting", "run", "campaign", "tuning", "cli"},
    "kinds": {"run", "campaign", "tuning", "cli"},
    "plotting": {"controllers", "simulation", "registry", "kinds", "run", "campaign", "tuning",
                 "cli"},
    "run": {"campaign", "tuning", "cli"},
    "campaign": {"tuning", "cli"},
    "tuning": {"cli"},
}


def _modules() -> dict[str, Path]:
    out = {}
    for pkg in PACKAGES:
        for p in (SRC / pkg).rglob("*.py"):
            parts = list(p.relative_to(SRC).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            out[".".join(parts)] = p
    return out


MODULES = _modules()


def _resolve(importer: str, node: ast.ImportFrom | ast.Import, is_pkg: bool,
             modules: dict[str, Path] = MODULES) -> list[str]:
    """The modules of ours an import statement names (a submodule where it names one)."""
    if isinstance(node, ast.Import):
        return [a.name for a in node.names if a.name.split(".")[0] in PACKAGES]
    if node.level:
        base = importer.split(".") if is_pkg else importer.split(".")[:-1]
        base = base[:len(base) - (node.level - 1)]
        mod = ".".join(base + ([node.module] if node.module else []))
    else:
        mod = node.module or ""
    if mod.split(".")[0] not in PACKAGES:
        return []
    return [f"{mod}.{a.name}" if f"{mod}.{a.name}" in modules else mod for a in node.names]


def import_graph(modules: dict[str, Path] = MODULES) -> dict[str, set[str]]:
    """Module -> the modules of ours it imports (at any place in the module)."""
    graph = {}
    for name, path in modules.items():
        tree = ast.parse(path.read_text(), filename=str(path))
        deps: set[str] = set()
        for node in ast.walk(tree):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                deps.update(_resolve(name, node, path.name == "__init__.py", modules))
        graph[name] = {d for d in deps if d != name}
    return graph


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one member (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def _part(module: str) -> str | None:
    """The part of mpc_wt a module belongs to (subpackage or top-level module)."""
    parts = module.split(".")
    if parts[0] != "mpc_wt" or len(parts) < 2:
        return None
    return parts[1]


def _package_graph(graph: dict[str, set[str]]) -> dict[str, set[str]]:
    """Edges between the parts of each package."""
    out: dict[str, set[str]] = {}
    for a, deps in graph.items():
        pa = ".".join(a.split(".")[:2])
        for b in deps:
            pb = ".".join(b.split(".")[:2])
            if pa != pb:
                out.setdefault(pa, set()).add(pb)
    return out


def test_no_module_imports_a_layer_above_its_own() -> None:
    graph = import_graph()
    bad = sorted(f"{a} -> {b}" for a, deps in graph.items() for b in deps
                 if _part(a) in FORBIDDEN and _part(b) in FORBIDDEN[_part(a)])
    assert not bad, "upward imports:\n" + "\n".join(bad)


def test_no_import_cycle_between_modules() -> None:
    assert _cycles(import_graph()) == []


def test_no_import_cycle_between_the_parts_of_a_package() -> None:
    assert _cycles(_package_graph(import_graph())) == []


def test_the_cycle_finder_finds_a_cycle_and_a_layer_breach(tmp_path: Path) -> None:
    (tmp_path / "mpc_wt" / "controllers").mkdir(parents=True)
    (tmp_path / "mpc_wt" / "simulation").mkdir()
    files = {"mpc_wt/controllers/a.py": "from mpc_wt.simulation import b\n",
             "mpc_wt/simulation/b.py": "def f():\n    from mpc_wt.controllers.a import x\n",
             "mpc_wt/simulation/c.py": "import numpy\n"}
    mods = {}
    for rel, text in files.items():
        (tmp_path / rel).write_text(text)
        mods[rel[:-3].replace("/", ".")] = tmp_path / rel
    mods["mpc_wt.simulation"] = tmp_path / "mpc_wt/simulation/c.py"
    graph = import_graph(mods)
    assert _cycles(graph) == [["mpc_wt.controllers.a", "mpc_wt.simulation.b"]]
    assert "simulation" in FORBIDDEN["controllers"]
    assert _part("mpc_wt.controllers.a") == "controllers"


def _private_uses(path: Path, module: str) -> list[str]:
    """Private names (``_x``) this module takes from another module of ours."""
    tree = ast.parse(path.read_text(), filename=str(path))
    ours: dict[str, str] = {}          # local alias -> our module
    bad = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            for target, a in zip(_resolve(module, node, path.name == "__init__.py"),
                                 node.names):
                if target == module:
                    continue
                if a.name.startswith("_") and not a.name.startswith("__"):
                    bad.append(f"{target}.{a.name}")
                if f"{target}" in MODULES and target.endswith("." + a.name):
                    ours[a.asname or a.name] = target
        elif isinstance(node, ast.Import):
            for a in node.names:
                if a.name.split(".")[0] in PACKAGES:
                    ours[a.asname or a.name.split(".")[0]] = a.name
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and node.attr.startswith("_") \
                and not node.attr.startswith("__"):
            base = node.value
            while isinstance(base, ast.Attribute):
                base = base.value
            if isinstance(base, ast.Name) and base.id in ours:
                bad.append(f"{ours[base.id]}...{node.attr}")
    return bad


def test_no_private_name_used_from_another_module() -> None:
    bad = {m: _private_uses(p, m) for m, p in MODULES.items()}
    bad = {k: v for k, v in bad.items() if v}
    assert not bad, f"private names used across modules: {bad}"


def test_the_private_name_checker_catches_both_forms(tmp_path: Path) -> None:
    f = tmp_path / "x.py"
    f.write_text("from mpc_wt.plotting import pyplot, _hidden\nfrom mpc_wt import plotting\n"
                 "plotting._other()\n")
    assert _private_uses(f, "mpc_wt.x") == ["mpc_wt.plotting._hidden",
                                             "mpc_wt.plotting..._other"]


#: the roles and the modules a newcomer finds in them
LAYOUT = {
    "controllers": {"base", "baseline", "baseline_law", "mpc", "qp", "estimator", "lqr",
                    "discon_kernel",
                    "discon_child",
                    "ipc", "apc", "derating", "lidar_feedforward", "supervisor", "discon",
                    "filters", "wind_estimator", "scheduling"},
    "controllers/takagi_sugeno": {"model", "synthesis", "controller", "robustness"},
    "registry": {"registry", "options", "context"},
    "kinds": {"common", "baseline", "ipc", "mpc", "lqr", "ts", "apc", "libraries", "lidar_ff"},
    "simulation": {"scenario", "loop", "compiled", "results", "preview", "solver_timing", "memory"},
    "assessment": {"fatigue", "performance", "series", "ultimate", "lidar", "compare"},
    "io": {"gain_tables", "rosco", "openfast_output", "discon_export", "openfast_case",
           "json_text", "solver_sources", "openfast_run"},
}


@pytest.mark.parametrize("role", sorted(LAYOUT))
def test_each_role_is_a_package_with_its_modules(role: str) -> None:
    found = {p.stem for p in (SRC / "mpc_wt" / role).glob("*.py")} - {"__init__"}
    assert found == LAYOUT[role]
    flat = {p.stem for p in (SRC / "mpc_wt").glob("*.py")}
    assert flat == {"__init__", "_typing", "_version", "errors", "run", "plotting"}


def test_the_public_api_is_where_users_find_it() -> None:
    import mpc_wt

    for name in mpc_wt.__all__:
        assert getattr(mpc_wt, name) is not None, name
    for name in ("MPC", "run_controller", "Scenario", "register", "simulate_closed_loop",
                 "BaselineController", "design_lqr", "TSController", "tune",
                 "ClosedLoopResult", "lifetime_del", "build_controller"):
        assert name in mpc_wt.__all__, name


def test_the_plugin_api_has_one_home() -> None:
    """The registry's mechanism is :mod:`mpc_wt.registry`; the controllers package serves none
    of it (no shim), and the kinds' options are :mod:`mpc_wt.kinds`'."""
    import mpc_wt.controllers as controllers
    import mpc_wt.kinds as kinds
    import mpc_wt.registry as registry

    for name in ("register", "Options", "option", "Built", "BuildContext", "kinds", "resolve"):
        assert hasattr(registry, name) and not hasattr(controllers, name), name
    assert "MPCOptions" in kinds.__all__ and not hasattr(registry, "MPCOptions")


def _kind_names_in_code(path: Path, names: set[str]) -> list[str]:
    """String constants of a module's code (not its docstrings) that name a kind."""
    tree = ast.parse(path.read_text(), filename=str(path))
    docs = {id(n.body[0].value) for n in ast.walk(tree)
            if isinstance(n, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef))
            and n.body and isinstance(n.body[0], ast.Expr)
            and isinstance(n.body[0].value, ast.Constant)}
    return [f"{path.name}:{n.lineno}: {n.value!r}" for n in ast.walk(tree)
            if isinstance(n, ast.Constant) and isinstance(n.value, str) and id(n) not in docs
            and any(re.search(rf"(?<![\w-]){re.escape(k)}(?![\w-])", n.value) for k in names)]


def test_the_registry_knows_no_kind() -> None:
    """No module of ``registry/`` names a kind mpc-wt ships in its code: the kinds register
    themselves from :mod:`mpc_wt.kinds`."""
    from mpc_wt.registry import kinds

    names = set(kinds()) | {"derate80"}
    bad = [hit for p in sorted((SRC / "mpc_wt" / "registry").glob("*.py"))
           for hit in _kind_names_in_code(p, names)]
    assert bad == []


def test_the_kind_name_check_catches_one(tmp_path: Path) -> None:
    f = tmp_path / "m.py"
    f.write_text('"""Doc naming mpc-lidar."""\nX = {"mpc-lidar": 1}\nY = "baseline-like"\n')
    assert _kind_names_in_code(f, {"mpc-lidar", "baseline"}) == ["m.py:2: 'mpc-lidar'"]


@pytest.mark.parametrize("module", sorted(m for m in MODULES if m.startswith("mpc_wt")
                                          and ".cli.__main__" not in m))
def test_every_module_imports_alone(module: str) -> None:
    importlib.import_module(module)

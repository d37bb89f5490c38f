"""Every Python block of the docs runs as it is: a page's blocks in order in one fresh
interpreter (a later block may use an earlier one's names), in an empty folder, so a stale
example fails. A block that cannot run here says why on the line before it
(``<!-- not run: REASON -->``: a cluster it needs, a fragment of a module whose whole is a
test)."""
from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FENCE = re.compile(r"(?:^<!-- not run: (?P<why>[^\n]*?) -->\n)?^```python\n(?P<code>.*?)^```",
                   flags=re.S | re.M)


def _pages() -> dict[str, list[tuple[str | None, str]]]:
    out = {}
    for page in sorted((ROOT / "docs").rglob("*.md")):
        if "_build" in page.parts:
            continue
        blocks = [(m.group("why"), m.group("code")) for m in FENCE.finditer(page.read_text())]
        if blocks:
            out[str(page.relative_to(ROOT))] = blocks
    return out


PAGES = _pages()


def test_the_docs_have_python_examples_and_each_skip_says_why() -> None:
    assert len(PAGES) >= 8
    for page, blocks in PAGES.items():
        for why, _ in blocks:
            assert why is None or len(why.split()) >= 3, f"{page}: a skip without its reason"


@pytest.mark.parametrize("page", sorted(PAGES))
def test_a_docs_pages_python_blocks_run(page: str, tmp_path: Path) -> None:
    code = "\n".join(c for why, c in PAGES[page] if why is None)
    if not code.strip():
        pytest.skip(f"{page}: every block says why it is not run")
    done = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                          text=True, timeout=900, env={**__import__("os").environ,
                                                       "MPLBACKEND": "Agg"})
    assert done.returncode == 0, f"{page}:\n{done.stderr[-3000:]}"


BASH = re.compile(r"^```(?:bash|sh|console)\n(?P<code>.*?)^```", flags=re.S | re.M)


def _commands() -> list[tuple[str, str]]:
    """Every ``mpcwt ...`` line of the README's and the docs' shell blocks (a line continued
    with a backslash joined; a trailing comment dropped), but usage synopses (``[--flag X]``,
    ``a|b``, ``...``)."""
    out = []
    for page in [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]:
        if "_build" in page.parts:
            continue
        for m in BASH.finditer(page.read_text()):
            text = m.group("code").replace("\\\n", " ")
            for line in text.splitlines():
                for part in line.split("&&"):
                    cmd = part.split(" #")[0].strip()
                    if cmd.startswith("mpcwt ") and not any(c in cmd for c in "[|") \
                            and "..." not in cmd:
                        out.append((str(page.relative_to(ROOT)), cmd))
    return out


COMMANDS = _commands()


def test_the_docs_shell_blocks_hold_commands() -> None:
    assert len(COMMANDS) >= 20


@pytest.mark.parametrize("page, cmd", COMMANDS, ids=[f"{p}: {c[:60]}" for p, c in COMMANDS])
def test_a_docs_command_parses(page: str, cmd: str) -> None:
    """Each documented command is one ``mpcwt`` accepts as written: its subcommand, flags and
    choices (the commands run for minutes to hours; their runs are the studies')."""
    import shlex

    from mpc_wt.cli.app import _plugins, build_parser
    from mpc_wt.registry.registry import load_plugins

    argv = shlex.split(cmd)[1:]
    load_plugins([p for p in _plugins(argv) if (ROOT / f"{p}.py").is_file()])
    try:
        build_parser().parse_args(argv)
    except SystemExit as stop:
        assert stop.code == 0, f"{page}: `{cmd}` is refused by the parser"

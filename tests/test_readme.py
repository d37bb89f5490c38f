"""The README's Python blocks run as they are (each in a fresh interpreter; the docs' in
``test_docs_blocks.py``), and the README stays a front page: short, with no development
history in it."""
from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
BLOCKS = re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)


def test_the_readme_has_python_examples() -> None:
    assert len(BLOCKS) >= 2


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_readme_python_block_runs(index: int, tmp_path: Path) -> None:
    done = subprocess.run([sys.executable, "-c", BLOCKS[index]], cwd=tmp_path,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]


def test_the_readme_is_a_front_page() -> None:
    text = README.read_text()
    assert len(text.splitlines()) < 300
    assert not re.search(r"issue [0-9]", text, flags=re.I)
    assert not re.search(r"\b20[0-9]{2}-[01][0-9]-[0-3][0-9]\b", text), "dated history"


@pytest.mark.parametrize("folder", ["src", "docs", "tests"])
def test_no_issue_numbers_in_code_or_docs(folder: str) -> None:
    hits = []
    for path in sorted((ROOT / folder).rglob("*")):
        if not path.is_file() or path.suffix not in (".py", ".md", ".rst", ".txt") \
                or "_build" in path.parts or "generated" in path.parts \
                or "auto_examples" in path.parts:
            continue
        for n, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
            if re.search(r"issue [0-9]", line, flags=re.I):
                hits.append(f"{path.relative_to(ROOT)}:{n}: {line.strip()}")
    assert not hits, "\n".join(hits)


@pytest.mark.parametrize("name", ["CHANGELOG.md", "benchmarks/RESULTS.md"])
def test_no_issue_numbers_in_the_changelog_and_the_results(name: str) -> None:
    text = (ROOT / name).read_text()
    hits = [f"{name}:{n}: {line.strip()}" for n, line in enumerate(text.splitlines(), 1)
            if re.search(r"issue [0-9]", line, flags=re.I)]
    assert not hits, "\n".join(hits)


def test_the_changelog_is_release_notes() -> None:
    """One section per version, newest first, one 'Unreleased' at most; no dated history."""
    text = (ROOT / "CHANGELOG.md").read_text()
    heads = re.findall(r"^## (.+)$", text, flags=re.M)
    assert heads[0] == "Unreleased" and heads.count("Unreleased") == 1
    assert all(re.fullmatch(r"[0-9]+\.[0-9]+\.[0-9]+", h) for h in heads[1:]), heads
    assert not re.search(r"\b20[0-9]{2}-[01][0-9]-[0-3][0-9]\b", text), "dated history"

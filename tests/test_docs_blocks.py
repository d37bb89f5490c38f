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

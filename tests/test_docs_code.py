"""Every Python block of the documentation runs as written: each page's blocks in order, in
one namespace per page (as the README's are run by tests/test_readme.py)."""

from __future__ import annotations

import re
from pathlib import Path

import matplotlib
import pytest

DOCS = Path(__file__).resolve().parent.parent / "docs"
_BLOCK = re.compile(r"^```(?:python|\{code-cell\} ipython3)\n(.*?)^```", re.MULTILINE | re.DOTALL)
PAGES = sorted(path for path in DOCS.rglob("*.md")
               if "_build" not in path.parts and _BLOCK.search(path.read_text(encoding="utf-8")))


def test_the_guides_have_python_blocks():
    assert len(PAGES) >= 12


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(DOCS)))
def test_the_blocks_of_a_page_run_in_order(page, tmp_path, monkeypatch):
    matplotlib.use("Agg")
    monkeypatch.chdir(tmp_path)  # blocks may write files
    namespace: dict = {"__name__": "__docs__"}
    for number, block in enumerate(_BLOCK.findall(page.read_text(encoding="utf-8")), start=1):
        try:
            exec(compile(block, f"{page.name} python block {number}", "exec"), namespace)  # our own docs
        except Exception as error:  # report which block broke
            pytest.fail(f"{page.relative_to(DOCS)} python block {number} fails: "
                        f"{type(error).__name__}: {error}\n{block}")
    import matplotlib.pyplot as plt

    plt.close("all")

"""The documentation site builds with warnings as errors (notebooks executed, API from docstrings)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tests._docs_build import built_docs
from tests._notebook_runs import NOTEBOOKS

DOCS = Path(__file__).resolve().parent.parent / "docs"


def test_docs_build_without_warnings():
    pytest.importorskip("sphinx")
    pytest.importorskip("myst_nb")
    pytest.importorskip("nbclient")
    pytest.importorskip("mathjax", reason="the docs typeset with the packaged MathJax (the pages extra)")
    html, status, output = built_docs()  # built once, shared with test_browser
    assert status == 0, output
    for page in ("index.html", "getting-started.html", "api.html", "gallery.html",
                 "guide/scenes.html", "guide/cli.html"):
        assert (html / page).exists(), page
    for notebook in NOTEBOOKS:  # rendered with their outputs (every notebook draws a figure)
        rendered = (html / "_notebooks" / f"{notebook.stem}.html").read_text(encoding="utf-8")
        assert "<img" in rendered, notebook.name
    api = (html / "api.html").read_text(encoding="utf-8")
    assert "draw_scene" in api and "Solution" in api
    # the packaged MathJax, no CDN (tests/test_browser.py checks the typesetting itself)
    assert (html / "_static" / "mathjax" / "tex-svg-full.js").stat().st_size > 1_000_000
    for page in ("index.html", "algorithm.html", "_notebooks/02_example2_resolvent.html"):
        text = (html / page).read_text(encoding="utf-8")
        scripts = re.findall(r'<script[^>]*src="([^"]*)"', text)
        assert any(src.endswith("mathjax/tex-svg-full.js") for src in scripts), page
        assert not [src for src in scripts if src.startswith(("http:", "https:", "//"))], page


def test_figures_of_every_bundled_scene_are_in_the_docs():
    import laplace_springs as ls

    folder = DOCS / "_static" / "scenes"
    for name in ls.bundled_scenes():
        for kind in ("diagram", "motion"):
            assert (folder / f"{name}-{kind}.png").exists(), f"{name}-{kind}.png"

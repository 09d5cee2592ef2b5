"""The documentation site builds with warnings as errors (notebooks executed, API from docstrings)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests._notebook_runs import NOTEBOOKS, executed_notebooks

DOCS = Path(__file__).resolve().parent.parent / "docs"


def test_docs_build_without_warnings(tmp_path):
    pytest.importorskip("sphinx")
    pytest.importorskip("myst_nb")
    pytest.importorskip("nbclient")
    outdir, errors = executed_notebooks()  # executed once, shared with test_notebooks
    failed = [name for name, error in errors.items() if error is not None]
    assert not failed, f"notebooks that fail to execute: {failed} (see test_notebooks)"
    environment = dict(os.environ, LAPLACE_SPRINGS_EXECUTED_NOTEBOOKS=str(outdir))
    command = [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-E", "-q", "-b", "html",
               "-d", str(tmp_path / "doctrees"), str(DOCS), str(tmp_path / "html")]
    result = subprocess.run(command, capture_output=True, text=True, timeout=600, env=environment,
                            check=False)
    assert result.returncode == 0, result.stdout[-4000:] + result.stderr[-4000:]
    html = tmp_path / "html"
    for page in ("index.html", "getting-started.html", "api.html", "gallery.html",
                 "guide/scenes.html", "guide/cli.html"):
        assert (html / page).exists(), page
    for notebook in NOTEBOOKS:  # rendered with their outputs (every notebook draws a figure)
        rendered = (html / "_notebooks" / f"{notebook.stem}.html").read_text(encoding="utf-8")
        assert "<img" in rendered, notebook.name
    api = (html / "api.html").read_text(encoding="utf-8")
    assert "draw_scene" in api and "Solution" in api


def test_figures_of_every_bundled_scene_are_in_the_docs():
    import laplace_springs as ls

    folder = DOCS / "_static" / "scenes"
    for name in ls.bundled_scenes():
        for kind in ("diagram", "motion"):
            assert (folder / f"{name}-{kind}.png").exists(), f"{name}-{kind}.png"

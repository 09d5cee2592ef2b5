"""Sphinx configuration: MyST Markdown pages, the notebooks (executed), numpydoc API reference.

Build with ``sphinx-build -W -b html docs docs/_build/html`` (warnings are errors; the test
suite does the same in tests/test_docs.py). Each build copies ../notebooks/*.ipynb into
_notebooks/ (MyST-NB executes them, so the pages show their outputs) and redraws the
figures of every bundled scene into _static/scenes/ (see make_figures.py).

Formulas are typeset by the packaged MathJax 3 (the ``pages`` extra, django-static-mathjax;
see laplace_springs.publish.mathjax): the build copies its one-file ``tex-svg-full.js`` into
the site's _static/mathjax/, so the site needs no network, as the worked-example pages
(tests/test_browser.py opens both in headless Chromium with the network off).
"""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(HERE))

import make_figures

import laplace_springs
from laplace_springs.publish.mathjax import MATHJAX_FILE
from laplace_springs.publish.mathjax import mathjax_path as packaged_mathjax

project = "laplace_springs"
author = "laplace_springs contributors"
copyright = "laplace_springs contributors"
version = release = laplace_springs.__version__

extensions = [
    "myst_nb",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
]
exclude_patterns = ["_build", "jupyter_execute", ".gitignore", "README.md"]
source_suffix = {".md": "myst-nb", ".ipynb": "myst-nb"}
root_doc = "index"

# MyST and MyST-NB
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence"]
myst_heading_anchors = 3
# LAPLACE_SPRINGS_EXECUTED_NOTEBOOKS names a folder of already executed copies (the test suite
# executes the notebooks once and passes them here); otherwise MyST-NB executes them.
EXECUTED_NOTEBOOKS = os.environ.get("LAPLACE_SPRINGS_EXECUTED_NOTEBOOKS")
nb_execution_mode = "off" if EXECUTED_NOTEBOOKS else "auto"   # "auto": notebooks without outputs
nb_execution_timeout = 180
nb_execution_raise_on_error = True  # a failing cell fails the build
nb_execution_show_tb = True
nb_merge_streams = True

# API reference from the numpydoc docstrings
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_rtype = False
autodoc_member_order = "bysource"
autodoc_typehints = "none"           # the docstrings state the types
autodoc_default_options = {"members": True, "show-inheritance": False}

# The packaged MathJax (no CDN): copied into _static/mathjax/ by _copy_mathjax below. Inline
# math is \( \) (MyST writes $...$ as it); $...$ and $$...$$ too inside math and notebook
# output areas, where the notebooks' _repr_latex_ outputs put them.
mathjax_path = f"mathjax/{MATHJAX_FILE}"
mathjax3_config = {
    "tex": {"inlineMath": [["\\(", "\\)"], ["$", "$"]], "displayMath": [["\\[", "\\]"], ["$$", "$$"]]},
    "options": {"enableMenu": False},
}
# No widget manager from a CDN: widget outputs of the executed notebooks show their text form.
nb_ipywidgets_js: dict = {}

# numpydoc types and attribute names such as "values", "name" or "text" resolve to attributes of
# that name in several classes; Sphinx warns that the reference is ambiguous (not broken).
suppress_warnings = ["ref.python"]

html_theme = "alabaster"
html_static_path = ["_static"]
html_title = "laplace_springs"


def _copy_notebooks() -> None:
    target = HERE / "_notebooks"
    target.mkdir(exist_ok=True)
    for old in target.glob("*.ipynb"):
        old.unlink()
    for notebook in sorted((ROOT / "notebooks").glob("*.ipynb")):
        executed = Path(EXECUTED_NOTEBOOKS or ROOT / "notebooks") / notebook.name
        shutil.copy2(executed if executed.exists() else notebook, target / notebook.name)


def _copy_mathjax(app, exception) -> None:
    """Put the packaged MathJax where mathjax_path points, once the pages are written."""
    if exception is None and app.builder.format == "html":
        target = Path(app.outdir) / "_static" / "mathjax"
        target.mkdir(parents=True, exist_ok=True)
        shutil.copy2(packaged_mathjax(), target / MATHJAX_FILE)


def setup(app):
    _copy_notebooks()
    make_figures.main(HERE / "_static" / "scenes")
    _connect_hygiene(app)
    app.connect("build-finished", _copy_mathjax)


# ----------------------------------------------------------------------------
# Docstring hygiene: the docstrings are plain-text numpydoc, read as reStructuredText
# ----------------------------------------------------------------------------

_SECTIONS = ("Parameters", "Returns", "Yields", "Raises", "Attributes", "Examples", "Notes",
             "References", "See Also", "Warns", "Other Parameters", "Methods")


def _split_glued_header(lines: list[str]) -> list[str]:
    """``Some text. Attributes`` followed by dashes: move the header to its own line."""
    out: list[str] = []
    for i, line in enumerate(lines):
        following = lines[i + 1].strip() if i + 1 < len(lines) else ""
        glued = next((name for name in _SECTIONS if line.rstrip().endswith(" " + name)), None)
        if glued and following and set(following) == {"-"} and line.strip() != glued:
            indent = line[: len(line) - len(line.lstrip())]
            out += [line.rstrip()[: -len(glued)].rstrip(), "", indent + glued]
        else:
            out.append(line)
    return out


def _escape_bars(lines: list[str]) -> list[str]:
    """Escape ``|`` (absolute values such as |x|) outside doctests, literal blocks, line blocks
    (``| text``) and grid tables (``+---``); a line that opens with an absolute value, such as
    ``|x_i(t) − value_i| ≤ ...``, is escaped too."""
    out, literal_indent = [], None
    for line in lines:
        stripped = line.strip()
        indent = len(line) - len(line.lstrip())
        if literal_indent is not None and stripped and indent <= literal_indent:
            literal_indent = None
        structural = stripped in ("|", "+") or stripped.startswith(("| ", "+-", "+="))
        escape = literal_indent is None and not stripped.startswith((">>>", "...")) and not structural
        out.append(line.replace("|", "\\|") if escape else line)
        if stripped.endswith("::"):
            literal_indent = indent
    return out


def _clean_docstring(app, what, name, obj, options, lines):
    lines[:] = _escape_bars(_split_glued_header(lines))


def _connect_hygiene(app) -> None:
    app.connect("autodoc-process-docstring", _clean_docstring, priority=600)

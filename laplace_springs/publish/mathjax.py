"""The packaged MathJax that typesets the worked-example pages and the documentation offline.

MathJax 3 comes from the PyPI package ``django-static-mathjax`` (import name ``mathjax``;
it ships MathJax's ``es5`` build and needs no Django): the optional extra ``pages``
(``pip install "laplace_springs[pages]"``). Its ``tex-svg-full.js`` is one file that holds
the TeX input with every extension and the SVG output, whose glyphs are paths: no font
files and no further downloads, so a page that carries it inline renders with no network.
The documentation site copies the same file into its ``_static`` folder (docs/conf.py).
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["MATHJAX_FILE", "mathjax_path", "mathjax_script", "mathjax_config", "MathJaxMissing"]

#: The MathJax component used: TeX input (all extensions), SVG output, in one file.
MATHJAX_FILE = "tex-svg-full.js"


class MathJaxMissing(ImportError):
    """The packaged MathJax is not installed (the message says how to install it)."""


def mathjax_path() -> Path:
    """The path of the packaged ``tex-svg-full.js``.

    Raises
    ------
    MathJaxMissing
        Without the ``django-static-mathjax`` package.

    Examples
    --------
    >>> mathjax_path().name
    'tex-svg-full.js'
    """
    try:
        import mathjax
    except ImportError:
        raise MathJaxMissing('the worked-example pages typeset their formulas with the packaged '
                             'MathJax: pip install "laplace_springs[pages]" (django-static-mathjax)'
                             ) from None
    path = Path(mathjax.__file__).resolve().parent / "static" / "mathjax" / "es5" / MATHJAX_FILE
    if not path.is_file():
        raise MathJaxMissing(f"the mathjax package has no {path}; reinstall django-static-mathjax>=3.2")
    return path


def mathjax_script() -> str:
    """The text of ``tex-svg-full.js``, safe inside an HTML ``<script>`` element."""
    text = mathjax_path().read_text(encoding="utf-8")
    # an HTML comment opener inside a script is harmless here, but leave the parser no doubt
    return text.replace("/<!--.*?-->/g", "/<\\!--.*?--\\>/g").replace("</script", "<\\/script")


def mathjax_config(ready_flag: str = "typeset") -> str:
    """The ``window.MathJax`` configuration (a ``<script>`` body) used by the pages.

    ``\\( \\)`` and ``\\[ \\]`` delimit math (so a ``$`` in text is just a dollar); when the
    page is typeset, ``document.body.dataset[ready_flag]`` becomes ``"done"`` (tests wait
    for it). The context menu is off: it would offer to load more components.
    """
    return ("window.MathJax = {tex: {inlineMath: [['\\\\(', '\\\\)']], displayMath: [['\\\\[', '\\\\]']]},"
            " svg: {fontCache: 'global'}, options: {enableMenu: false},"
            " startup: {pageReady: function () { return MathJax.startup.defaultPageReady().then("
            f"function () {{ document.body.dataset.{ready_flag} = 'done'; }}); }}}}}};")

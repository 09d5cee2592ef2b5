"""A worked example as a standalone LaTeX document (the ``.tex`` twin of the HTML page).

The sections of :mod:`~laplace_springs.publish.content` become ``\\section*`` headings,
paragraphs (LaTeX's special characters escaped, inline math kept), ``align*`` blocks of
the same formulas the page shows and ``\\includegraphics`` of the figures, written as PNG
files beside the document. It needs amsmath, amssymb, graphicx and geometry, and compiles
with pdflatex (tests/output/test_latex.py compiles every bundled scene's).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path

from .content import Section

__all__ = ["document_tex", "write_document", "text_tex"]

_PREAMBLE = r"""\documentclass[11pt]{article}
\usepackage[utf8]{inputenc}
\usepackage{amsmath,amssymb,graphicx}
\usepackage[margin=2cm,landscape]{geometry}
\allowdisplaybreaks
\title{%s}
\author{Worked by laplace\_springs}
\date{}
\begin{document}
\maketitle
"""

_ESCAPES = {"\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#", "_": r"\_",
            "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}", "^": r"\textasciicircum{}"}
_INLINE = re.compile(r"\\\((.*?)\\\)", re.DOTALL)
#: Characters of the page's prose that pdflatex's default fonts lack, as LaTeX.
_UNICODE = {"Δ": r"$\Delta$", "λ": r"$\lambda$", "ℚ": r"$\mathbb{Q}$", "≤": r"$\le$", "≥": r"$\ge$",
            "–": "--", "—": "---", "⁻¹": r"$^{-1}$", "·": r"$\cdot$", "ω": r"$\omega$",
            "×": r"$\times$", "≠": r"$\ne$", "ζ": r"$\zeta$", "μ": r"$\mu$", "δ": r"$\delta$"}


def _escape(text: str) -> str:
    out = "".join(_ESCAPES.get(ch, ch) for ch in text)
    for key, value in _UNICODE.items():
        out = out.replace(key, value)
    return out


def text_tex(text: str) -> str:
    """A paragraph of the page as LaTeX: prose escaped, ``\\( \\)`` math kept as ``$ $``.

    >>> text_tex("Both 50% and \\\\(x_{1} = 2\\\\) & more")
    'Both 50\\\\% and $x_{1} = 2$ \\\\& more'
    """
    pieces, last = [], 0
    for match in _INLINE.finditer(text):
        pieces.append(_escape(text[last:match.start()]))
        pieces.append(f"${match.group(1)}$")
        last = match.end()
    pieces.append(_escape(text[last:]))
    return "".join(pieces)


def _display(block: str) -> str:
    if "\\begin{aligned}" in block:
        return block.replace("\\begin{aligned}", "\\begin{align*}").replace("\\end{aligned}", "\\end{align*}")
    return "\\begin{equation*}\n" + block + "\n\\end{equation*}"


def document_tex(title: str, parts: Sequence[Section], *, image_stem: str) -> str:
    """The document's text; figure k is ``<image_stem>-k.png``."""
    body, k = [_PREAMBLE % _escape(title)], 0
    for section in parts:
        body.append(f"\\section*{{{_escape(section.title)}}}")
        body += [text_tex(text) + "\n" for text in section.text]
        body += [_display(block) for block in section.math]
        if section.preformatted:
            body.append("\\begin{verbatim}\n" + section.preformatted + "\n\\end{verbatim}")
        for caption, _ in section.images:
            k += 1
            body.append("\\begin{center}\n"
                        f"\\includegraphics[width=0.8\\linewidth,height=0.4\\textheight,keepaspectratio]"
                        f"{{{image_stem}-{k}.png}}\\\\\n{{\\small {_escape(caption)}}}\n\\end{{center}}")
        body += [text_tex(text) + "\n" for text in section.notes]
    body.append("\\end{document}\n")
    return "\n\n".join(body)


def write_document(path: Path, title: str, parts: Sequence[Section]) -> Path:
    """Write the document and its figures (``<stem>-1.png``, ...) beside it."""
    k = 0
    for section in parts:
        for _, data in section.images:
            k += 1
            (path.parent / f"{path.stem}-{k}.png").write_bytes(data)
    path.write_text(document_tex(title, parts, image_stem=path.stem), encoding="utf-8")
    return path


"""A diagram as SVG text, written directly from its artists (no matplotlib rendering).

The explorer redraws the diagram on every slider move; rendering the matplotlib figure
takes 50-90 ms, writing the same lines, rectangles, circles, arrows and labels as SVG
elements about a millisecond. :func:`diagram_svg` reads the artists of a
:class:`~laplace_springs.output.diagram.Diagram` (positions as they are after
:meth:`~laplace_springs.output.diagram.Diagram.move`) and writes them in the axes' data
coordinates (y flipped), labels included: :func:`mathtext_svg` turns the mathtext of a
label (``$k_{1} = \\frac{2}{5}$``) into SVG text with sub- and superscripts.
"""

from __future__ import annotations

import html
import re
from typing import TYPE_CHECKING, Any

import numpy as np

from .diagram import SCALE_INCHES, text_extent

if TYPE_CHECKING:
    from .diagram import Diagram

__all__ = ["diagram_svg", "mathtext_svg", "polyline_svg"]

_GREEK = {"alpha": "α", "beta": "β", "gamma": "γ", "delta": "δ", "epsilon": "ε", "zeta": "ζ",
          "eta": "η", "theta": "θ", "kappa": "κ", "lambda": "λ", "mu": "μ", "nu": "ν", "xi": "ξ",
          "rho": "ρ", "sigma": "σ", "tau": "τ", "phi": "φ", "chi": "χ", "psi": "ψ", "omega": "ω",
          "pi": "π", "Delta": "Δ", "Omega": "Ω", "cdot": "·", "times": "×"}
_FRACTION = re.compile(r"\\frac\{([^{}]*)\}\{([^{}]*)\}")


def _plain(tex: str) -> str:
    """Mathtext without fractions, \\left/\\right and commands (Greek letters as Unicode)."""
    text = tex.replace("\\left", "").replace("\\right", "").replace("\\,", " ").replace("\\ ", " ")
    while _FRACTION.search(text):
        text = _FRACTION.sub(lambda m: f"{_group(m.group(1))}/{_group(m.group(2))}", text)
    text = re.sub(r"\\([A-Za-z]+)", lambda m: _GREEK.get(m.group(1), m.group(1)), text)
    return text


def _group(part: str) -> str:
    return part if re.fullmatch(r"[\w.]+", part) else f"({part})"


def mathtext_svg(label: str) -> str:
    """A label's mathtext as the content of an SVG ``<text>`` (escaped, with tspans).

    Examples
    --------
    >>> mathtext_svg("$k_{1} = \\\\frac{2}{5}$")
    'k<tspan baseline-shift="sub" font-size="70%">1</tspan> = 2/5'
    >>> mathtext_svg("$\\\\mu_{2}$")
    'μ<tspan baseline-shift="sub" font-size="70%">2</tspan>'
    """
    text = _plain(label.strip("$"))
    out, i = [], 0
    while i < len(text):
        ch = text[i]
        if ch in "_^" and i + 1 < len(text):
            if text[i + 1] == "{":
                end = _closing(text, i + 1)
                inner, i = text[i + 2:end], end + 1
            else:
                inner, i = text[i + 1], i + 2
            shift = "sub" if ch == "_" else "super"
            out.append(f'<tspan baseline-shift="{shift}" font-size="70%">'
                       f"{html.escape(inner.replace('{', '').replace('}', ''))}</tspan>")
            continue
        if ch not in "{}":
            out.append(html.escape(ch))
        i += 1
    return "".join(out)


def _closing(text: str, start: int) -> int:
    depth = 0
    for j in range(start, len(text)):
        depth += {"{": 1, "}": -1}.get(text[j], 0)
        if depth == 0:
            return j
    return len(text) - 1


def _colour(rgba: Any) -> tuple[str, float]:
    r, g, b, a = (float(v) for v in rgba)
    return f"rgb({round(255 * r)},{round(255 * g)},{round(255 * b)})", a


def polyline_svg(points: np.ndarray, *, stroke: str = "black", width: float = 0.03,
                 fill: str = "none", closed: bool = False) -> str:
    """An SVG polyline (or polygon) through ``points`` (data coordinates, y up)."""
    coordinates = " ".join(f"{x:.3f},{-y:.3f}" for x, y in points)
    tag = "polygon" if closed else "polyline"
    return (f'<{tag} points="{coordinates}" fill="{fill}" stroke="{stroke}" '
            f'stroke-width="{width:.3f}" stroke-linejoin="round"/>')


def diagram_svg(diagram: Diagram, *, width: int = 640) -> str:
    """The diagram, as it is now, as an SVG element ``width`` pixels wide.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> import laplace_springs as ls
    >>> from laplace_springs.output.diagram import build_diagram
    >>> svg = diagram_svg(build_diagram(ls.load_scene("wall-pair"), Figure().subplots()))
    >>> svg.startswith("<svg") and svg.count("<rect") >= 2 and "x<tspan" in svg
    True
    """
    from matplotlib.lines import Line2D
    from matplotlib.patches import Circle, FancyArrowPatch, Rectangle

    ax = diagram.ax
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    height = round(width * (y1 - y0) / (x1 - x0))
    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
             f'viewBox="{x0:.3f} {-y1:.3f} {x1 - x0:.3f} {y1 - y0:.3f}" font-family="DejaVu Sans, sans-serif">',
             '<defs><pattern id="ls-hatch" width="0.12" height="0.12" patternUnits="userSpaceOnUse" '
             'patternTransform="rotate(45)"><line x1="0" y1="0" x2="0" y2="0.12" stroke="#595959" '
             'stroke-width="0.025"/></pattern></defs>']
    unit = 1.0 / (SCALE_INCHES * 72.0)  # a point at the diagram's natural scale, in data units
    nominal = {id(artist): width for artist, width in diagram._widths}  # before fitting to the axes
    for artist in sorted(ax.get_children(), key=lambda a: a.get_zorder()):
        if not artist.get_visible():
            continue
        if isinstance(artist, Line2D):
            colour, _ = _colour(artist.get_color() if isinstance(artist.get_color(), tuple)
                                else _rgba(artist.get_color()))
            parts.append(polyline_svg(np.asarray(artist.get_xydata()), stroke=colour,
                                      width=nominal.get(id(artist), 1.0) * unit))
        elif isinstance(artist, Rectangle) and artist.get_gid() is not None:
            parts.append(_rectangle(artist, nominal.get(id(artist), 1.0) * unit))
        elif isinstance(artist, Circle):
            cx, cy = artist.center
            parts.append(f'<circle cx="{cx:.3f}" cy="{-cy:.3f}" r="{artist.radius:.3f}" fill="none" '
                         f'stroke="black" stroke-width="{1.2 * unit:.3f}"/>')
        elif isinstance(artist, FancyArrowPatch):
            parts.append(_arrow(artist, unit))
    for text in ax.texts:
        if not text.get_visible() or not text.get_text():
            continue
        x, y = text.get_position()
        colour, _ = _colour(_rgba(text.get_color()))
        placed = next((label for label in diagram._labels if label.artist is text), None)
        size = placed.size if placed is not None else 0.28
        content = mathtext_svg(text.get_text())
        room = placed.width if placed is not None else text_extent(text.get_text())[0] * size
        visible = len(re.sub(r"<[^>]*>", "", html.unescape(content)))
        fit = (f' textLength="{room:.3f}" lengthAdjust="spacingAndGlyphs"'
               if 0.62 * visible * size > room else "")  # inline fractions are wider than stacked ones
        parts.append(f'<text x="{x:.3f}" y="{-y:.3f}" font-size="{size:.3f}" fill="{colour}" '
                     f'text-anchor="middle" dominant-baseline="central"{fit}>{content}</text>')
    title = ax.get_title()
    if title:
        parts.insert(2, f'<title>{html.escape(title)}</title>')
    parts.append("</svg>")
    return "\n".join(parts)


def _rgba(colour: Any) -> tuple[float, float, float, float]:
    from matplotlib.colors import to_rgba

    return to_rgba(colour)


def _rectangle(artist: Any, line_width: float) -> str:
    x, y = artist.get_xy()
    w, h = artist.get_width(), artist.get_height()
    if artist.get_hatch():
        return (f'<rect x="{x:.3f}" y="{-(y + h):.3f}" width="{w:.3f}" height="{h:.3f}" '
                'fill="url(#ls-hatch)" stroke="none"/>')
    fill, alpha = _colour(artist.get_facecolor())
    edge, _ = _colour(artist.get_edgecolor())
    return (f'<rect x="{x:.3f}" y="{-(y + h):.3f}" width="{w:.3f}" height="{h:.3f}" fill="{fill}" '
            f'fill-opacity="{alpha:.2f}" stroke="{edge}" stroke-width="{line_width:.3f}"/>')


def _arrow(artist: Any, unit: float) -> str:
    (xa, ya), (xb, yb) = artist._posA_posB
    start, stop = np.array([xa, ya]), np.array([xb, yb])
    along = stop - start
    length = float(np.hypot(*along)) or 1.0
    direction = along / length
    normal = np.array([-direction[1], direction[0]])
    head = min(0.18, 0.45 * length)
    parts = [polyline_svg(np.array([start, stop]), width=1.4 * unit)]
    ends = [(stop, direction)]
    if artist.get_arrowstyle().__class__.__name__ in ("CurveFilledAB",):
        ends.append((start, -direction))
    for tip, pointing in ends:
        base = tip - head * pointing
        triangle = np.array([tip, base + 0.4 * head * normal, base - 0.4 * head * normal])
        parts.append(polyline_svg(triangle, fill="black", width=0.0, closed=True))
    return "".join(parts)

"""Worked-example pages: a self-contained HTML page (and a LaTeX document) for any scene.

:func:`worked_example` works a scene through as the seed's course page works its examples
(:mod:`~laplace_springs.publish.content`: diagram, equations of motion, M, C, K and A, B,
Δ(λ) and the resolvent, partial fractions and g-functions where the scene has them, the
solution in its named form, ``verify()``'s residuals, plots), adds the animation
(:func:`laplace_springs.output.animation.animate`) and sliders over a precomputed
parameter grid (:mod:`~laplace_springs.publish.grid`), and renders it as one HTML file:

- no network: the formulas are typeset in the browser by the packaged MathJax
  (:mod:`~laplace_springs.publish.mathjax`), carried inside the page; images are inline
  PNGs; the sliders are a few lines of plain JavaScript redrawing an inline SVG;
- :meth:`WorkedExample.save_html` writes it, :meth:`WorkedExample.save_tex` writes the
  same worked example as a LaTeX document (:mod:`~laplace_springs.publish.document`).

The command line: ``laplace-springs page three-dashpots -o page.html``.
"""

from __future__ import annotations

import base64
import html
import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .._version import __version__
from ..limits import limits
from ..model.errors import SceneError
from ..model.scene import Scene
from ..model.units import axis_label
from ..output.animation import animate
from ..solution import Solution
from .content import Section, page_t_end, sections
from .document import document_tex, write_document
from .grid import SliderGrid, slider_grid
from .mathjax import mathjax_config, mathjax_script

__all__ = ["WorkedExample", "worked_example", "nice_ticks"]

#: Curve colours of the sliders' plot (matplotlib's default cycle, as in the PNG plots).
COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2",
           "#7f7f7f", "#bcbd22", "#17becf")
_WIDTH, _HEIGHT, _LEFT, _RIGHT, _TOP, _BOTTOM = 680, 300, 64, 16, 14, 40


@dataclass
class WorkedExample:
    """A scene worked through, ready to be written as HTML or LaTeX.

    Attributes
    ----------
    scene : Scene
    solution : Solution
        The scene's solution (symbolic for a scene with parameters).
    plotted : Solution
        The solution the plots, animation and check use (at ``values`` for a symbolic scene).
    sections : list of Section
    animation_html : str or None
        The animation (matplotlib's ``to_jshtml``), or None.
    grid : SliderGrid or None
        The sliders' precomputed data, or None (``grid_note`` says why).
    grid_note : str
    """

    scene: Scene
    solution: Solution
    plotted: Solution
    sections: list[Section]
    animation_html: str | None
    grid: SliderGrid | None
    grid_note: str = ""

    @property
    def title(self) -> str:
        return self.scene.title or "A spring-mass system"

    def html(self) -> str:
        """The page: one self-contained HTML document."""
        return _page(self)

    def save_html(self, path: str | Path) -> Path:
        """Write the page to ``path`` (UTF-8)."""
        path = Path(path)
        path.write_text(self.html(), encoding="utf-8")
        return path

    def tex(self) -> str:
        """The worked example as a standalone LaTeX document (figures as separate PNG files:
        use :meth:`save_tex`)."""
        return document_tex(self.title, self.sections, image_stem="figure")

    def save_tex(self, path: str | Path) -> Path:
        """Write the LaTeX document to ``path`` and its figures beside it (``<stem>-1.png``, ...);
        ``pdflatex`` compiles it (amsmath, amssymb, graphicx, geometry)."""
        return write_document(Path(path), self.title, self.sections)

    def _repr_html_(self) -> str:
        """In a notebook: the page in a frame (its scripts kept apart from the notebook's)."""
        return ('<iframe style="width:100%;height:720px;border:1px solid #ccc" srcdoc="'
                + html.escape(self.html(), quote=True) + '"></iframe>')


def worked_example(scene: Scene, *, values: Mapping[str, Any] | None = None,
                   t_end: float | None = None, animation: bool = True,
                   sliders: Sequence[str] | None = None) -> WorkedExample:
    """Work a scene through as the seed's course page does (see the module notes).

    Parameters
    ----------
    scene : Scene
    values : mapping, optional
        Numbers for the plots, animation and sliders of a scene with parameters (1 for
        any not given; the page says which values it used).
    t_end : float, optional
        Last time of the plots and the sliders' curves (default: a few periods).
    animation : bool
        Include the animation (31 inline JPEG frames, about 1.3 MB).
    sliders : sequence of str, optional
        The knobs of the sliders (component or mass labels, parameter names; at most 3);
        by default the parameters, or the first springs and dashpots.

    Returns
    -------
    WorkedExample

    Raises
    ------
    SceneError
        For a scene that cannot be solved, or ``values`` naming no parameter.
    MathJaxMissing
        (from :meth:`WorkedExample.html`) without the packaged MathJax.

    Examples
    --------
    >>> import laplace_springs as ls
    >>> example = worked_example(ls.load_scene("vertical-pair"), animation=False)
    >>> [part.title for part in example.sections][:3]
    ['The system', 'The characteristic polynomial and the resolvent', 'Partial fractions']
    >>> page = example.html()
    >>> "<script" in page and "https://" not in page.split("</head>")[1]
    True
    """
    parts, solution, plotted = sections(scene, values=values, t_end=t_end)
    end = page_t_end(plotted, t_end)
    movie = None
    if animation:
        try:
            clip = animate(plotted, t_end=end, duration=3.0, fps=10, figsize=_animation_size(scene))
        except SceneError as exc:  # a scene without a drawing: the plots and sliders remain
            parts.append(Section("animation", "Animation", (f"(No animation: {exc}.)",)))
        else:
            movie = clip.to_jshtml(dpi=72, frame_format="jpeg")
    grid, note = None, ""
    if scene.n <= 8:
        try:
            grid = slider_grid(scene, t_end=end, knobs=sliders, values=values)
        except SceneError as exc:
            note = f"(No sliders: {exc}.)"
    else:
        note = f"(No sliders: {scene.n} coordinates are more than a page's precomputed grid holds.)"
    return WorkedExample(scene, solution, plotted, parts, movie, grid, note)


def _animation_size(scene: Scene) -> tuple[float, float]:
    return (7.0, 5.0) if scene.layout == "horizontal" else (8.0, 4.6)


# ---------------------------------------------------------------------------
# HTML
# ---------------------------------------------------------------------------

_STYLE = """
body { font-family: Georgia, 'Times New Roman', serif; max-width: 920px; margin: 2em auto;
       padding: 0 1em; color: #222; line-height: 1.5; }
h1 { font-size: 1.7em; border-bottom: 2px solid #8b0000; padding-bottom: .2em; }
h2 { font-size: 1.3em; color: #8b0000; margin-top: 1.8em; }
.math { overflow-x: auto; margin: .6em 0; }
figure { margin: 1em 0; text-align: center; }
figure img { max-width: 100%; }
figcaption { font-size: .9em; color: #555; }
pre { background: #f6f6f6; padding: .6em; overflow-x: auto; font-size: .85em; }
nav { font-size: .9em; background: #f6f6f6; padding: .4em .8em; }
nav a { margin-right: .8em; }
.sliders label { display: inline-block; min-width: 5em; }
.sliders div { margin: .3em 0; }
.sliders input { width: 18em; vertical-align: middle; }
.sliders output { font-family: monospace; margin-left: .6em; }
footer { margin-top: 3em; font-size: .8em; color: #666; border-top: 1px solid #ccc; padding-top: .5em; }
"""


def _png(data: bytes, caption: str) -> str:
    encoded = base64.b64encode(data).decode("ascii")
    return (f'<figure><img alt="{html.escape(caption, quote=True)}" src="data:image/png;base64,{encoded}">'
            f"<figcaption>{html.escape(caption)}</figcaption></figure>")


def _section_html(section: Section) -> str:
    parts = [f'<section id="{section.key}"><h2>{html.escape(section.title)}</h2>']
    texts = [f"<p>{html.escape(text)}</p>" for text in section.text]
    images = [_png(data, caption) for caption, data in section.images]
    if section.images_first:
        parts += texts[:1] + images + texts[1:]
    else:
        parts += texts
    parts += [f'<div class="math">\\[{html.escape(block)}\\]</div>' for block in section.math]
    if section.preformatted:
        parts.append(f"<pre>{html.escape(section.preformatted)}</pre>")
    if not section.images_first:
        parts += images
    parts += [f"<p>{html.escape(text)}</p>" for text in section.notes]
    parts.append("</section>")
    return "\n".join(parts)


def nice_ticks(low: float, high: float, count: int = 5) -> list[float]:
    """Round tick values (1, 2, 2.5 or 5 times a power of ten) spanning [low, high].

    >>> nice_ticks(-0.204, 0.202)
    [-0.2, -0.1, 0.0, 0.1, 0.2]
    """
    span = high - low
    if not span > 0:
        return [low]
    raw = span / count
    power = 10 ** np.floor(np.log10(raw))
    step = next(m * power for m in (1, 2, 2.5, 5, 10) if m * power >= raw)
    first = int(np.ceil(low / step))
    last = int(np.floor(high / step + 1e-9))
    return [float(round(k * step, 12)) for k in range(first, last + 1)]


def _svg_plot(grid: SliderGrid, scene: Scene) -> tuple[str, dict[str, float]]:
    """The sliders' plot: axes, ticks and one empty polyline per coordinate (JavaScript fills them);
    the axes say the scene's units, or none for a scene written without units."""
    low, high = float(np.min(grid.values)), float(np.max(grid.values))
    pad = 0.05 * (high - low or 1.0)
    low, high = low - pad, high + pad
    t_end = float(grid.times[-1])
    inner_w, inner_h = _WIDTH - _LEFT - _RIGHT, _HEIGHT - _TOP - _BOTTOM

    def x(t: float) -> float:
        return _LEFT + inner_w * t / t_end

    def y(v: float) -> float:
        return _TOP + inner_h * (high - v) / (high - low)

    parts = [f'<svg id="ls-plot" xmlns="http://www.w3.org/2000/svg" width="{_WIDTH}" height="{_HEIGHT}" '
             f'viewBox="0 0 {_WIDTH} {_HEIGHT}" font-family="sans-serif" font-size="11">',
             f'<rect x="{_LEFT}" y="{_TOP}" width="{inner_w}" height="{inner_h}" fill="none" stroke="#444"/>']
    for value in nice_ticks(low, high):
        parts.append(f'<line x1="{_LEFT}" x2="{_LEFT + inner_w}" y1="{y(value):.1f}" y2="{y(value):.1f}" '
                     'stroke="#ddd"/>')
        parts.append(f'<text x="{_LEFT - 6}" y="{y(value) + 4:.1f}" text-anchor="end">{value:g}</text>')
    for value in nice_ticks(0.0, t_end):
        parts.append(f'<text x="{x(value):.1f}" y="{_HEIGHT - _BOTTOM + 15}" text-anchor="middle">{value:g}</text>')
    time_label, position_label = (html.escape(axis_label(q, scene)) for q in ("time", "position"))
    parts.append(f'<text x="{_LEFT + inner_w / 2}" y="{_HEIGHT - 6}" text-anchor="middle">{time_label}</text>')
    parts.append(f'<text transform="translate(14,{_TOP + inner_h / 2}) rotate(-90)" '
                 f'text-anchor="middle">{position_label}</text>')
    if low < 0 < high:
        parts.append(f'<line x1="{_LEFT}" x2="{_LEFT + inner_w}" y1="{y(0):.1f}" y2="{y(0):.1f}" stroke="#999"/>')
    for i, name in enumerate(grid.names):
        colour = COLOURS[i % len(COLOURS)]
        parts.append(f'<polyline id="ls-curve-{i}" fill="none" stroke="{colour}" stroke-width="2" points=""/>')
        parts.append(f'<text x="{_LEFT + inner_w - 8}" y="{_TOP + 16 + 15 * i}" text-anchor="end" '
                     f'fill="{colour}">{html.escape(name)}(t)</text>')
    parts.append("</svg>")
    geometry = {"left": _LEFT, "top": _TOP, "width": inner_w, "height": inner_h, "low": low, "high": high,
                "tEnd": t_end}
    return "\n".join(parts), geometry


_SLIDER_SCRIPT = """
(function () {
  var data = JSON.parse(document.getElementById('ls-grid-data').textContent);
  var raw = atob(data.values), bytes = new Uint8Array(raw.length);
  for (var b = 0; b < raw.length; b++) { bytes[b] = raw.charCodeAt(b); }
  var values = new Float32Array(bytes.buffer), g = data.geometry;
  var sliders = data.knobs.map(function (k, a) { return document.getElementById('ls-knob-' + a); });
  function show(v) { return Math.abs(v) >= 1e4 || (v !== 0 && Math.abs(v) < 1e-3) ? v.toExponential(3) : String(Number(v.toPrecision(4))); }
  function draw() {
    var set = 0;
    sliders.forEach(function (s, a) {
      set = set * data.knobs[a].values.length + Number(s.value);
      document.getElementById('ls-knob-value-' + a).textContent = show(data.knobs[a].values[Number(s.value)]);
    });
    for (var i = 0; i < data.n; i++) {
      var points = [];
      for (var j = 0; j < data.times.length; j++) {
        var v = values[(set * data.n + i) * data.times.length + j];
        var x = g.left + g.width * data.times[j] / g.tEnd, y = g.top + g.height * (g.high - v) / (g.high - g.low);
        points.push(x.toFixed(1) + ',' + y.toFixed(1));
      }
      document.getElementById('ls-curve-' + i).setAttribute('points', points.join(' '));
    }
    document.getElementById('ls-plot').dataset.set = String(set);
  }
  sliders.forEach(function (s) { s.addEventListener('input', draw); });
  draw();
})();
"""


def _sliders_html(example: WorkedExample) -> str:
    grid = example.grid
    head = '<section id="sliders"><h2>Turn the knobs</h2>'
    if grid is None:
        return f"{head}<p>{html.escape(example.grid_note)}</p></section>"
    start = grid.start()
    rows = []
    for a, (knob, axis) in enumerate(zip(grid.knobs, grid.axes)):
        rows.append(f'<div><label for="ls-knob-{a}">\\({html.escape(knob.label)}\\)</label>'
                    f'<input type="range" id="ls-knob-{a}" min="0" max="{len(axis) - 1}" step="1" '
                    f'value="{start[a]}"><output id="ls-knob-value-{a}"></output></div>')
    svg, geometry = _svg_plot(grid, example.scene)
    data = {"knobs": [{"name": k.name, "values": [float(v) for v in axis]} for k, axis in zip(grid.knobs, grid.axes)],
            "n": len(grid.names), "times": [float(t) for t in grid.times], "geometry": geometry,
            "values": grid.encoded()}
    listed = ", ".join(f"\\({html.escape(k.label)}\\)" for k in grid.knobs)
    text = (f"<p>x(t) for {len(grid.values)} values of {listed}, computed in advance by one parameter "
            f"sweep (each to {limits().explore_target:g} of the motion's size, far below a pixel); the "
            "sliders pick one of them, no Python needed.</p>")
    payload = json.dumps(data).replace("</", "<\\/")
    return "\n".join([head, text, '<div class="sliders">', *rows, "</div>", svg,
                      f'<script type="application/json" id="ls-grid-data">{payload}</script>',
                      f"<script>{_SLIDER_SCRIPT}</script></section>"])


def _page(example: WorkedExample) -> str:
    body = [_section_html(section) for section in example.sections]
    if example.animation_html is not None:
        body.append('<section id="animation"><h2>Animation</h2><p>The masses moving along the '
                    "solution (frames from one vectorised evaluation), with x(t) drawn up to "
                    f"the current time.</p>{example.animation_html}</section>")
    body.append(_sliders_html(example))
    nav = " ".join(f'<a href="#{s.key}">{html.escape(s.title)}</a>' for s in example.sections)
    title = html.escape(example.title)
    return f"""<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<meta name="generator" content="laplace_springs {__version__}">
<title>{title}</title>
<style>{_STYLE}</style>
<script>{mathjax_config()}</script>
<script>{mathjax_script()}</script>
</head>
<body>
<h1>{title}</h1>
<nav>{nav} <a href="#sliders">Turn the knobs</a></nav>
{chr(10).join(body)}
<footer>Worked by laplace_springs {__version__}: exact Laplace-transform solutions of
spring&ndash;mass&ndash;damper systems. Formulas typeset by MathJax 3 (Apache License 2.0), which this
page carries: it needs no network.</footer>
</body>
</html>
"""

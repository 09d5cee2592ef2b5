"""The interactive explorer: sliders in Jupyter that redraw the motion, the diagram and the
closed form on every move.

:func:`explore` turns a scene's knobs (:mod:`~laplace_springs.publish.knobs`: its
parameters or its springs, dashpots and masses, the initial data, a harmonic force's
amplitude and frequency) into ipywidgets sliders. The scene with its knobs as parameters is
compiled once (:func:`laplace_springs.sweeps.compile.compile_scene`: the coefficients of
D(λ) and of every numerator as NumPy functions), so a move costs one evaluation of the
compiled scene at one parameter set (its roots, residues and the curves at 400 times, to
:attr:`~laplace_springs.limits.Limits.explore_target` of the motion's size, far below a
pixel: a set whose estimate misses it is solved exactly), the curves and the diagram written as SVG (:mod:`laplace_springs.output.svg`)
and the closed form x_i(t) = Σ e^{αt}(a cos βt + b sin βt) with the current numbers. About
5 ms per move on the seed's scenes (``benchmarks/bench_explore.py``).

An :class:`Explorer` can be driven from code (``explorer.set(k1=500)``), which is how the
notebook ``notebooks/08_explore.ipynb`` and the tests use it. It needs ipywidgets
(``pip install "laplace_springs[notebooks]"``).
"""

from __future__ import annotations

import html
import time
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..limits import limits
from ..model.errors import SceneError
from ..model.scene import Scene
from ..model.units import axis_label
from ..output.chain import latex_symbol, math_label
from ..output.diagram import MAX_SHIFT, Diagram, build_diagram
from ..output.plots import default_t_end
from ..output.svg import diagram_svg
from ..solving import solve
from ..sweeps.chunks import evaluate_rows
from ..sweeps.compile import CompiledScene, compile_scene, parameter_rows
from .content import plot_values
from .knobs import Knob, knob_values, knobbed_scene
from .page import nice_ticks

__all__ = ["Explorer", "explore", "closed_form_latex"]

COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b")
#: Coordinates whose closed form the explorer writes out.
FORMULA_COORDINATES = 4


def _number(value: float) -> str:
    text = f"{value:.4g}"
    if "e" in text:
        mantissa, exponent = text.split("e")
        return f"{mantissa} \\times 10^{{{int(exponent)}}}"
    return text


def _term(coefficient: float, body: str, first: bool) -> str:
    sign = "-" if coefficient < 0 else ("" if first else "+")
    return f"{sign} {_number(abs(coefficient))}{body}"


def closed_form_latex(compiled: CompiledScene, row: np.ndarray, roots: np.ndarray,
                      names: Sequence[str]) -> str:
    """x_i(t) as damped sines and cosines with float coefficients, for one parameter set.

    Residues N_i(r)/D'(r) at the simple roots r of D(λ); a conjugate pair gives
    e^{αt}(a cos βt + b sin βt) with a = 2 Re(res), b = −2 Im(res). Repeated roots (a
    cluster within 1e-7 relative) are not written out: the text says so.

    Examples
    --------
    >>> import laplace_springs as ls
    >>> scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[["k"]], x0=[1], v0=[0], parameters=["c", "k"])
    >>> compiled = compile_scene(scene)
    >>> row = parameter_rows(compiled, {"c": 2.0, "k": 26.0})[0]
    >>> print(closed_form_latex(compiled, row, np.array([-1 + 5j, -1 - 5j]), ["x1"]))
    x_{1}(t) &\\approx e^{-1t}\\left(1\\cos 5t + 0.2\\sin 5t\\right)
    """
    finite = bool(np.isfinite(roots).all()) and roots.size > 0
    size = float(np.max(np.abs(roots))) if finite else 0.0
    gaps = np.abs(roots[:, None] - roots[None, :])
    np.fill_diagonal(gaps, np.inf)
    if not finite or np.min(gaps) < 1e-7 * max(size, 1e-300):
        return "\\text{repeated roots at these values: the curves come from the exact solution}"
    den, num, _, _ = compiled.coefficients(row[None, :])
    derivative = np.polyder(den[0])
    rows = []
    for i, name in enumerate(names[:FORMULA_COORDINATES]):
        residues = np.polyval(num[0, i], roots) / np.polyval(derivative, roots)
        pieces: list[str] = []
        largest = float(np.max(np.abs(residues), initial=0.0))
        for r, res in sorted(zip(roots, residues), key=lambda p: (-p[0].real, abs(p[0].imag))):
            if abs(res) <= 1e-12 * largest or r.imag < -1e-12 * size:
                continue
            decay = "" if abs(r.real) <= 1e-12 * size else f"e^{{{_number(r.real)}t}}"
            if abs(r.imag) <= 1e-12 * size:
                pieces.append(_term(res.real, decay or "", not pieces))
                continue
            a, b = 2 * res.real, -2 * res.imag
            beta = _number(r.imag)
            inner = f"{_number(a)}\\cos {beta}t {'-' if b < 0 else '+'} {_number(abs(b))}\\sin {beta}t"
            pieces.append(("" if not pieces else "+ ") + f"{decay}\\left({inner}\\right)")
        rows.append(f"{latex_symbol(name)}(t) &\\approx {' '.join(pieces) or '0'}")
    return " \\\\\n".join(rows)


class Explorer:
    """Sliders for a scene's knobs with the motion, diagram and closed form they drive.

    Attributes
    ----------
    scene : Scene
    knobs : list of Knob
    compiled : CompiledScene
        The scene with its knobs as parameters, compiled once.
    times : numpy.ndarray
    positions : numpy.ndarray
        x(t) at the current values, shape (n, len(times)).
    closed_form : str
        LaTeX of x(t) at the current values.
    last_update_seconds : float
        How long the last move took (evaluation, SVG, formula, widgets).
    widget : ipywidgets.VBox
    """

    def __init__(self, scene: Scene, *, knobs: Sequence[str] | None = None,
                 values: Mapping[str, Any] | None = None, t_end: float | None = None,
                 samples: int = 400) -> None:
        import ipywidgets as widgets

        self.scene = scene
        knobbed, self.knobs = knobbed_scene(scene, knobs=knobs, values=values)
        self.compiled = compile_scene(knobbed)
        numbers, _ = plot_values(scene, values)
        end = default_t_end(solve(numbers)) if t_end is None else float(t_end)
        self.times = np.linspace(0.0, end, int(samples))
        self.positions = np.zeros((scene.n, self.times.size))
        self.closed_form = ""
        self.last_update_seconds = 0.0
        self._paused = False
        self.diagram = self._diagram(numbers)
        self._sliders = {knob.name: self._slider(widgets, knob) for knob in self.knobs}
        self._picture = widgets.HTML()
        self._plot = widgets.HTML()
        self._formula = widgets.HTMLMath()
        self._status = widgets.HTML()
        for slider in self._sliders.values():
            slider.observe(self._moved, names="value")
        groups = [widgets.HBox(list(self._sliders.values())[k:k + 3])
                  for k in range(0, len(self._sliders), 3)]
        self.widget = widgets.VBox([*groups, self._picture, self._plot, self._formula, self._status])
        self.update()

    # -- widgets ---------------------------------------------------------------------
    @staticmethod
    def _slider(widgets: Any, knob: Knob) -> Any:
        style = {"description_width": "initial"}
        layout = widgets.Layout(width="32%")
        if knob.log:
            return widgets.FloatLogSlider(value=knob.value, base=10, min=np.log10(knob.low),
                                          max=np.log10(knob.high), step=0.01, description=knob.name,
                                          readout_format=".4g", continuous_update=True, style=style,
                                          layout=layout)
        return widgets.FloatSlider(value=knob.value, min=knob.low, max=knob.high,
                                   step=(knob.high - knob.low) / 400 or 0.01, description=knob.name,
                                   readout_format=".4g", continuous_update=True, style=style, layout=layout)

    def _diagram(self, numbers: Scene) -> Diagram | None:
        from matplotlib.figure import Figure

        try:
            return build_diagram(numbers, Figure().subplots(), show_values=True, title=False)
        except SceneError:
            return None

    def _repr_mimebundle_(self, **kwargs: Any) -> Any:
        return self.widget._repr_mimebundle_(**kwargs)

    def _moved(self, change: Any) -> None:
        if not self._paused:
            self.update()

    # -- state -------------------------------------------------------------------------
    @property
    def values(self) -> dict[str, float]:
        """The knobs' current values."""
        return {name: float(slider.value) for name, slider in self._sliders.items()}

    def set(self, **values: float) -> None:
        """Move sliders from code (one update for all of them)."""
        unknown = set(values) - set(self._sliders)
        if unknown:
            raise SceneError(f"explore: {', '.join(sorted(unknown))} is not a knob; the knobs are "
                             f"{', '.join(self._sliders)}")
        self._paused = True
        try:
            for name, value in values.items():
                self._sliders[name].value = float(value)
        finally:
            self._paused = False
        self.update()

    def reset(self) -> None:
        """Every slider back to the scene's own value."""
        self.set(**knob_values(self.knobs))

    # -- the move ----------------------------------------------------------------------
    def update(self) -> None:
        """Evaluate the compiled scene at the sliders' values and redraw everything."""
        start = time.perf_counter()
        values = self.values
        rows = parameter_rows(self.compiled, values)
        x, _, exact, roots, _ = evaluate_rows(self.compiled, rows, self.times,
                                              target=limits().explore_target)
        self.positions = x[0]
        self.closed_form = closed_form_latex(self.compiled, rows[0], roots[0], self.scene.names)
        self._plot.value = _curves_svg(self.times, self.positions, self.scene.names, self.scene)
        self._formula.value = "$$\\begin{aligned}" + self.closed_form + "\\end{aligned}$$"
        if self.diagram is not None:
            self._picture.value = self._diagram_svg(values)
        self.last_update_seconds = time.perf_counter() - start
        route = "exact solution (repeated roots)" if exact[0] else "compiled scene"
        self._status.value = (f"<small>{self.last_update_seconds * 1e3:.1f} ms per move, from the "
                              f"{route}</small>")

    def _diagram_svg(self, values: Mapping[str, float]) -> str:
        """The diagram at t = 0 (blocks at x(0)) with the knobs' values in its labels."""
        assert self.diagram is not None
        shown = {knob.name: knob for knob in self.knobs if knob.kind in ("spring", "dashpot", "mass",
                                                                          "parameter")}
        for text in self.diagram.labels:
            label = text.get_text()
            for name in shown:
                prefix = math_label(name)[:-1] + " = "
                if label.startswith(prefix):
                    text.set_text(f"{prefix}{values[name]:.4g}$")
        largest = float(np.max(np.abs(self.positions), initial=0.0))
        scale = MAX_SHIFT / largest if largest > 0 else 0.0
        self.diagram.move(scale * self.positions[:, 0])
        width = 640 if self.diagram.orientation == "horizontal" else 260
        return diagram_svg(self.diagram, width=width)


def _curves_svg(times: np.ndarray, positions: np.ndarray, names: Sequence[str], scene: Scene | None = None,
                width: int = 680, height: int = 260) -> str:
    """x(t) as an SVG plot with an axis frame, a zero line and tick labels (the time axis in the
    scene's unit, none for a scene written without units)."""
    left, right, top, bottom = 60, 12, 10, 34
    inner_w, inner_h = width - left - right, height - top - bottom
    low, high = float(np.min(positions)), float(np.max(positions))
    pad = 0.06 * (high - low or max(abs(high), 1.0))
    low, high = low - pad, high + pad
    t_end = float(times[-1]) or 1.0
    xs = left + inner_w * times / t_end
    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
             'font-family="sans-serif" font-size="11">',
             f'<rect x="{left}" y="{top}" width="{inner_w}" height="{inner_h}" fill="none" stroke="#444"/>']
    for value in nice_ticks(low, high):
        y = top + inner_h * (high - value) / (high - low)
        parts.append(f'<text x="{left - 5}" y="{y + 4:.1f}" text-anchor="end">{value:.3g}</text>')
    for value in nice_ticks(0.0, t_end):
        parts.append(f'<text x="{left + inner_w * value / t_end:.1f}" y="{height - bottom + 14}" '
                     f'text-anchor="middle">{value:.3g}</text>')
    time_label = html.escape(axis_label("time", scene))
    parts.append(f'<text x="{left + inner_w / 2}" y="{height - 4}" text-anchor="middle">{time_label}</text>')
    if low < 0 < high:
        y0 = top + inner_h * high / (high - low)
        parts.append(f'<line x1="{left}" x2="{left + inner_w}" y1="{y0:.1f}" y2="{y0:.1f}" stroke="#aaa"/>')
    for i, (row, name) in enumerate(zip(positions, names)):
        ys = top + inner_h * (high - row) / (high - low)
        points = " ".join(f"{x:.1f},{y:.1f}" for x, y in zip(xs, ys))
        colour = COLOURS[i % len(COLOURS)]
        parts.append(f'<polyline points="{points}" fill="none" stroke="{colour}" stroke-width="1.8"/>')
        parts.append(f'<text x="{left + inner_w - 6}" y="{top + 14 + 13 * i}" text-anchor="end" '
                     f'fill="{colour}">{html.escape(name)}(t)</text>')
    parts.append("</svg>")
    return "\n".join(parts)


def explore(scene: Scene, *, knobs: Sequence[str] | None = None, values: Mapping[str, Any] | None = None,
            t_end: float | None = None, samples: int = 400) -> Explorer:
    """Sliders for a scene in Jupyter (see the module notes).

    Parameters
    ----------
    scene : Scene
        Up to :attr:`~laplace_springs.limits.Limits.sweep_max_coordinates` coordinates; forces
        given as formulas (not sampled, periodic or delayed).
    knobs : sequence of str, optional
        The components, masses or parameters with sliders (default: all); the initial data
        and the harmonic force always have theirs.
    values : mapping, optional
        Starting values of a symbolic scene's parameters (default 1).
    t_end : float, optional
        The last time plotted (default: a few periods of the scene at its starting values).
    samples : int
        Times per curve.

    Returns
    -------
    Explorer
        Display it in a notebook (it shows its widgets); drive it with ``.set(...)``.

    Examples
    --------
    >>> import laplace_springs as ls
    >>> explorer = explore(ls.load_scene("wall-pair"))
    >>> [knob.name for knob in explorer.knobs][:4]
    ['k1', 'k2', 'k3', 'm1']
    >>> explorer.set(k2=0.2)
    >>> explorer.values["k2"], explorer.positions.shape
    (0.2, (2, 400))
    """
    return Explorer(scene, knobs=knobs, values=values, t_end=t_end, samples=samples)

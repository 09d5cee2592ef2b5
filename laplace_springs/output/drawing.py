"""Scene diagrams in the style of the seed's figures: blocks, zigzag springs, pistons.

:func:`draw_scene` draws a scene (``Scene.draw()`` is the same function) with the seed's
look: masses as labelled, translucent blocks, springs as zigzags, dashpots as pistons,
walls, ceilings and floors hatched, the coordinate arrows along the direction of motion,
moving supports with their u(t). Where each part goes, and how labels keep clear of the
drawing at any figure size: :mod:`laplace_springs.output.diagram`. Which scenes can be
drawn (components, or matrices that are a chain in disguise):
:mod:`laplace_springs.output.chain`.

:func:`scene_image` is the diagram behind a notebook's display of a Scene; importing this
module registers it (and ``Scene.draw``) with :mod:`laplace_springs.model.scene`.
"""

from __future__ import annotations

import io
from typing import TYPE_CHECKING, Any

from ..model.errors import SceneError
from ..model.scene import Scene, register_diagram_renderer, register_scene_drawer
from .diagram import SCALE_INCHES, build_diagram

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["draw_scene", "scene_image", "fit_figure", "DISPLAY_MAX_MASSES"]


def draw_scene(scene: Scene, ax: Axes | None = None, *, show_values: bool = False,
               title: str | bool = True, label_size: float = 16) -> Axes:
    """Draw the scene's masses, springs, dashpots and supports like the seed's figures.

    Parameters
    ----------
    scene : Scene
        A scene built from components, or a matrix scene that is a chain (see
        :mod:`laplace_springs.output.chain`); its ``layout`` and supports decide the
        orientation (see :mod:`laplace_springs.output.diagram`).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; a new figure sized to the drawing when omitted.
    show_values : bool
        Write the values beside the labels (``k_1 = 0.3``) and the moving supports' u(t).
    title : str or bool
        A title; True uses the scene's title, False none.
    label_size : float
        Font size of the labels, in points, in a figure sized to the drawing; in smaller
        axes the labels shrink with the drawing, so they never overlap.

    Returns
    -------
    matplotlib.axes.Axes

    Raises
    ------
    SceneError
        For a matrix scene that is not a chain of springs and dashpots.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> from laplace_springs import load_scene
    >>> ax = draw_scene(load_scene("wall-pair"), Figure().subplots())
    >>> sorted(t.get_text() for t in ax.texts)
    ['$k_{1}$', '$k_{2}$', '$k_{3}$', '$m_{1}$', '$m_{2}$', '$x_{1}$', '$x_{2}$']
    >>> load_scene("wall-pair").draw(Figure().subplots()).get_title()
    'Example 3: two masses between walls, three springs'
    """
    return build_diagram(scene, ax, show_values=show_values, title=title, label_size=label_size).ax


#: Largest scene drawn for a notebook's display of a Scene (its diagram is unreadable beyond).
DISPLAY_MAX_MASSES = 24


def scene_image(scene: Scene, fmt: str = "png") -> bytes | str | None:
    """The scene's diagram as PNG bytes or SVG text, for a notebook's display of a Scene.

    Drawn on a figure outside pyplot (nothing is left open, nothing shows twice). None
    without matplotlib, for a scene :func:`draw_scene` cannot draw, or one with more than
    :data:`DISPLAY_MAX_MASSES` masses.

    Parameters
    ----------
    scene : Scene
    fmt : {"png", "svg"}

    Returns
    -------
    bytes, str or None

    Examples
    --------
    >>> from laplace_springs import load_scene
    >>> scene_image(load_scene("three-dashpots"))[:4]
    b'\\x89PNG'
    >>> scene_image(load_scene("three-dashpots"), "svg").lstrip().startswith("<?xml")
    True
    """
    if fmt not in ("png", "svg") or scene.n > DISPLAY_MAX_MASSES:
        return None
    try:
        from matplotlib.figure import Figure
    except ImportError:
        return None
    figure = Figure()
    ax = figure.add_axes((0.0, 0.0, 1.0, 1.0))
    try:
        draw_scene(scene, ax)
    except SceneError:
        return None
    fit_figure(figure, ax)
    buffer = io.BytesIO()
    figure.savefig(buffer, format=fmt, dpi=80)
    data = buffer.getvalue()
    return data if fmt == "png" else data.decode("utf-8")


def fit_figure(figure: Any, ax: Axes) -> None:
    """Size a figure holding one diagram axes to the drawing (as :func:`draw_scene` sizes its own)."""
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    titled = bool(ax.get_title())
    figure.set_size_inches((x1 - x0) * SCALE_INCHES, (y1 - y0) * SCALE_INCHES + (0.45 if titled else 0.0))
    ax.set_position((0.0, 0.0, 1.0, (y1 - y0) * SCALE_INCHES / figure.get_figheight()))


register_diagram_renderer(scene_image)
register_scene_drawer(draw_scene)

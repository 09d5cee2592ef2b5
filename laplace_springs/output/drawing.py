"""Scene diagrams in the style of the seed's figures: blocks, zigzag springs, pistons.

:func:`draw_scene` draws a chain of masses with matplotlib: masses as labelled,
translucent blocks (pink, blue, purple, as on the seed page), springs as zigzags,
dashpots as pistons, walls and ceilings hatched, the coordinate arrows x1, x2, ...
and the labels k1, m1, μ2 taken from the scene's own names. ``layout="vertical"``
hangs the chain from a ceiling (the seed's Example 1); ``"horizontal"`` puts it between
walls on rollers (Examples 3-5).

Where things go
---------------
Masses sit in coordinate order along the chain. A component between neighbouring
masses goes in the gap between them; several in the same gap are drawn side by
side (a spring above a dashpot, as in the seed's Example 5). A component from the
first mass to a support goes to the start wall (left, or the ceiling); from the last
mass, to the end wall (right, or the floor); for a single mass the component's own
order decides (``("wall", "m1")`` is on the left). Supports named ``ground`` or
``air``, and supports of middle masses, are drawn across the chain: in a horizontal
chain down to the ground (friction with the surface, the seed's δ), in a vertical
chain sideways to a hatched side wall (air resistance). Springs and dashpots
between non-neighbouring masses are routed over the blocks.

Scenes without components
-------------------------
A scene built from matrices is drawn when it is a chain in disguise: with a
diagonal M and symmetric C, K, off-diagonal entries ``-K[i,j]`` are springs between
masses i and j and row sums are springs to a support (likewise dashpots from C). A
normalised scene ``x'' + Bx' + Ax = 0`` with a non-symmetric A (the seed's
``A = [[3, -1], [-2, 2]]``) is first rescaled by the masses d_i that make
``diag(d) A`` symmetric (here m2/m1 = 1/2). Anything else (a non-diagonal M, a
positive off-diagonal stiffness, an unsymmetrisable A) raises
:class:`~laplace_springs.model.errors.SceneError` saying why; build such a scene with
:meth:`Scene.from_components <laplace_springs.model.scene.Scene.from_components>` to draw it.
"""

from __future__ import annotations

import io
import textwrap
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
import sympy as sp

from ..model.components import Component
from ..model.errors import SceneError
from ..model.numbers import to_exact
from ..model.scene import Scene, register_diagram_renderer

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["Chain", "chain_of", "physical_matrices", "draw_scene", "math_label"]

#: Block colours, in the seed's order (Pink, Blue, Purple, ...), drawn at 50 % opacity.
BLOCK_COLOURS = ("pink", "blue", "purple", "orange", "green", "gold")
LABEL_COLOUR = "red"

_GREEK = {"alpha", "beta", "gamma", "delta", "epsilon", "zeta", "eta", "theta", "kappa",
          "lambda", "mu", "nu", "xi", "rho", "sigma", "tau", "phi", "chi", "psi", "omega"}
_ACROSS_SUPPORTS = {"ground", "air"}

# Geometry, in chain coordinates: u along the chain, v across it (units of a block).
_BLOCK = 1.0            # block length along the chain
_GAP = 2.5              # gap between blocks (and to a wall)
_MARGIN = 0.4           # end gap when nothing attaches to that end
_V_LOW, _V_HIGH = 0.2, 1.2   # block extent across the chain
_V_ARROW = 1.5          # coordinate arrows
_GROUND = -1.1          # ground / side wall level for components across the chain
_HATCH = 0.3            # thickness of hatched supports


# ----------------------------------------------------------------------------
# The chain: masses and components, from components or inferred from matrices
# ----------------------------------------------------------------------------


@dataclass(frozen=True)
class Chain:
    """A scene as a drawable chain: masses, their values, coordinates and components.

    Attributes
    ----------
    masses : tuple of str
        Mass labels in coordinate order (``m1``, ``m2``, ...).
    mass_values : tuple of sympy.Expr
        The masses (for a rescaled normalised scene, the rescaling weights).
    coordinates : tuple of str
        The coordinate names (``x1``, ...), one per mass.
    components : tuple of Component
        Springs and dashpots.
    layout : str
        ``"horizontal"`` or ``"vertical"``.
    inferred : bool
        True when the components were read off the matrices.
    """

    masses: tuple[str, ...]
    mass_values: tuple[sp.Expr, ...]
    coordinates: tuple[str, ...]
    components: tuple[Component, ...]
    layout: str
    inferred: bool = False


def _is_zero(value: sp.Expr) -> bool:
    value = sp.cancel(value) if value.free_symbols else value
    return value == 0


def _symmetrising_weights(A: sp.MatrixBase, B: sp.MatrixBase) -> list[sp.Expr]:
    """Positive d with diag(d)·A and diag(d)·B symmetric (d = 1 on each component's root)."""
    n = A.rows
    weights: list[sp.Expr | None] = [None] * n
    for root in range(n):
        if weights[root] is not None:
            continue
        weights[root] = sp.Integer(1)
        stack = [root]
        while stack:
            i = stack.pop()
            for j in range(n):
                if j == i or weights[j] is not None:
                    continue
                ratio = _ratio(A, B, i, j)
                if ratio is None:
                    continue
                weights[j] = sp.cancel(weights[i] * ratio)
                stack.append(j)
    return [w for w in weights if w is not None]


def _ratio(A: sp.MatrixBase, B: sp.MatrixBase, i: int, j: int) -> sp.Expr | None:
    """d_j / d_i from the first coupling of i and j in A or B (None when uncoupled)."""
    for matrix, name in ((A, "A"), (B, "B")):
        forward, backward = matrix[i, j], matrix[j, i]
        if _is_zero(forward) and _is_zero(backward):
            continue
        if _is_zero(forward) or _is_zero(backward):
            raise SceneError(
                f"cannot draw this scene as a chain: {name}[{i},{j}] = {forward} but "
                f"{name}[{j},{i}] = {backward} (a one-way coupling is no spring or dashpot)")
        ratio = sp.cancel(forward / backward)
        if ratio.is_positive is False:
            raise SceneError(
                f"cannot draw this scene as a chain: {name}[{i},{j}] = {forward} and "
                f"{name}[{j},{i}] = {backward} have opposite signs")
        return ratio
    return None


def physical_matrices(scene: Scene) -> tuple[sp.ImmutableMatrix, sp.ImmutableMatrix, sp.ImmutableMatrix]:
    """Symmetric ``(M, C, K)`` describing the scene's mechanics, M diagonal when possible.

    A scene whose M, C, K are symmetric is returned as it is. A scene with a diagonal
    M and non-symmetric ``A = M⁻¹K`` (the seed's normalised Example 1) is rescaled by
    the weights d with ``diag(d)·A`` and ``diag(d)·B`` symmetric; the motion is the
    same, and ``½vᵀMv + ½xᵀKx`` is then its energy.

    Raises
    ------
    SceneError
        When no such rescaling exists.

    Examples
    --------
    >>> from laplace_springs import Scene
    >>> M, C, K = physical_matrices(Scene.from_normalized(A=[[3, -1], [-2, 2]], x0=[1, 0], v0=[0, 0]))
    >>> M.tolist(), K.tolist()
    ([[1, 0], [0, 1/2]], [[3, -1], [-1, 1]])
    """
    M, C, K = scene.M, scene.C, scene.K
    if all(m.is_symmetric() for m in (M, C, K)):
        return M, C, K
    if not M.is_diagonal():
        raise SceneError("cannot symmetrise a scene with a non-diagonal mass matrix M and "
                         f"non-symmetric K or C; M = {M.tolist()}")
    A, B = scene.normalized()
    weights = _symmetrising_weights(A, B)
    D = sp.diag(*weights)
    K2, C2 = (D * A).applyfunc(sp.cancel), (D * B).applyfunc(sp.cancel)
    for matrix, name in ((K2, "A"), (C2, "B")):
        difference = (matrix - matrix.T).applyfunc(sp.cancel)
        if any(entry != 0 for entry in difference):
            raise SceneError(f"cannot draw this scene as a chain: no positive masses make "
                             f"diag(m)·{name} symmetric for {name} = {(A if name == 'A' else B).tolist()}")
    return sp.ImmutableMatrix(D), sp.ImmutableMatrix(C2), sp.ImmutableMatrix(K2)


def _support_for(index: int, n: int, layout: str, kind: str) -> tuple[str, bool]:
    """The support a mass's grounded component attaches to, and whether it comes first.

    Ends of the chain for springs (and for dashpots of a horizontal chain, as in the
    seed's Example 5); air resistance, across the chain, for dashpots of a vertical one
    (the seed's Example 2).
    """
    if layout == "vertical" and kind == "dashpot":
        return "air", True
    start, end = ("ceiling", "floor") if layout == "vertical" else ("wall", "wall")
    if index == 0:
        return start, True
    if index == n - 1:
        return end, False
    return "ground", True


def _inferred_components(matrix: sp.MatrixBase, kind: str, masses: Sequence[str],
                         layout: str) -> list[tuple[float, Component]]:
    """(position, component) pairs read off a symmetric stiffness or damping matrix."""
    letter = "K" if kind == "spring" else "C"
    n = matrix.rows
    found = []
    for i in range(n):
        grounded = sp.cancel(sum(matrix[i, j] for j in range(n)))
        if grounded.is_negative:
            raise SceneError(f"cannot draw this scene as a chain: row {i} of {letter} sums to "
                             f"{grounded} < 0 (a negative {kind} to a support)")
        if grounded != 0:
            support, first = _support_for(i, n, layout, kind)
            ends = (support, masses[i]) if first else (masses[i], support)
            position = i - 0.5 if first and i == 0 else (i + 0.5 if not first else i + 0.25)
            found.append((position, Component(kind, "", *ends, grounded)))
        for j in range(i + 1, n):
            value = sp.cancel(-matrix[i, j])
            if value.is_negative:
                raise SceneError(f"cannot draw this scene as a chain: {letter}[{i},{j}] = "
                                 f"{matrix[i, j]} > 0 (a {kind} has a negative off-diagonal entry)")
            if value != 0:
                found.append(((i + j) / 2, Component(kind, "", masses[i], masses[j], value)))
    return found


def _infer_chain(scene: Scene) -> Chain:
    M, C, K = physical_matrices(scene)
    if not M.is_diagonal():
        raise SceneError("cannot draw a scene with a non-diagonal mass matrix M = "
                         f"{M.tolist()}; build it with Scene.from_components to draw it")
    masses = tuple(f"m{i + 1}" for i in range(scene.n))
    components = []
    for kind, matrix, prefix in (("spring", K, "k"), ("dashpot", C, "mu")):
        found = sorted(_inferred_components(matrix, kind, masses, scene.layout), key=lambda p: p[0])
        components += [Component(c.kind, f"{prefix}{j}", c.a, c.b, c.value)
                       for j, (_, c) in enumerate(found, start=1)]
    return Chain(masses, tuple(M[i, i] for i in range(scene.n)), scene.names,
                 tuple(components), scene.layout, inferred=True)


def chain_of(scene: Scene) -> Chain:
    """The scene as a chain of masses and components (see the module notes).

    Examples
    --------
    >>> from laplace_springs import load_scene, Scene
    >>> [c.label for c in chain_of(load_scene("three-dashpots")).components]
    ['k1', 'k2', 'k3', 'mu1', 'mu2', 'mu3']
    >>> chain = chain_of(Scene.from_matrices(M=[[1, 0], [0, 2]], K=[[3, -1], [-1, 1]],
    ...                                      C=[[1, 0], [0, 0]], x0=[1, 0], v0=[0, 0]))
    >>> [(c.label, c.a, c.b, c.value) for c in chain.components]
    [('k1', 'wall', 'm1', 2), ('k2', 'm1', 'm2', 1), ('mu1', 'wall', 'm1', 1)]
    """
    if scene.components:
        M = scene.M
        return Chain(scene.mass_names, tuple(M[i, i] for i in range(scene.n)), scene.names,
                     scene.components, scene.layout)
    return _infer_chain(scene)


# ----------------------------------------------------------------------------
# Labels
# ----------------------------------------------------------------------------


def math_label(name: str, value: Any = None) -> str:
    """A name as matplotlib mathtext: ``k1`` → ``$k_{1}$``, ``mu2`` → ``$\\mu_{2}$``.

    Examples
    --------
    >>> math_label("k1"), math_label("mu2"), math_label("b"), math_label("delta_1")
    ('$k_{1}$', '$\\\\mu_{2}$', '$b$', '$\\\\delta_{1}$')
    >>> math_label("m2", sp.Rational(2, 3))
    '$m_{2} = \\\\frac{2}{3}$'
    """
    head = name.rstrip("0123456789").rstrip("_")
    tail = name[len(head):].lstrip("_")
    if not head or not head.isalpha():
        head, tail = name, ""
    symbol = f"\\{head}" if head.lower() in _GREEK else head
    text = f"{symbol}_{{{tail}}}" if tail else symbol
    if value is not None:
        text += f" = {sp.latex(to_exact(value, name))}"
    return f"${text}$"


# ----------------------------------------------------------------------------
# Layout of the chain in (u, v) coordinates
# ----------------------------------------------------------------------------


@dataclass
class _Slots:
    gaps: dict[int, list[Component]]        # gap g: between mass g-1 and mass g (0: start, n: end)
    across: dict[int, list[Component]]      # components from mass i across the chain
    bridges: list[tuple[int, int, Component]]


def _slots(chain: Chain) -> _Slots:
    index = {name: i for i, name in enumerate(chain.masses)}
    n = len(chain.masses)
    slots = _Slots({g: [] for g in range(n + 1)}, {i: [] for i in range(n)}, [])
    for component in chain.components:
        a, b = index.get(component.a), index.get(component.b)
        if a is not None and b is not None:
            i, j = min(a, b), max(a, b)
            if j == i + 1:
                slots.gaps[j].append(component)
            else:
                slots.bridges.append((i, j, component))
            continue
        if a is not None:
            mass, support, support_first = a, component.b, False
        elif b is not None:
            mass, support, support_first = b, component.a, True
        else:
            raise SceneError(f"cannot draw {component.label or component.kind}: it joins "
                             f"{component.a} and {component.b}, neither of them a mass")
        if support in _ACROSS_SUPPORTS or (chain.layout == "horizontal" and support == "floor"):
            slots.across[mass].append(component)
        elif n == 1:
            slots.gaps[0 if support_first else 1].append(component)
        elif mass == 0:
            slots.gaps[0].append(component)
        elif mass == n - 1:
            slots.gaps[n].append(component)
        else:
            slots.across[mass].append(component)
    for items in slots.gaps.values():
        items.sort(key=lambda c: c.kind != "spring")
    return slots


def _block_starts(slots: _Slots, n: int) -> tuple[list[float], float]:
    """u of each block's start edge, and the chain's end u."""
    u = _GAP if slots.gaps[0] else _MARGIN
    starts = []
    for _ in range(n):
        starts.append(u)
        u += _BLOCK + _GAP
    end = starts[-1] + _BLOCK + (_GAP if slots.gaps[n] else _MARGIN)
    return starts, end


def _lanes(count: int) -> tuple[list[float], float]:
    """v of each of ``count`` parallel lanes, and the zigzag/piston half-width."""
    if count == 1:
        return [0.5 * (_V_LOW + _V_HIGH)], 0.25
    top, bottom = _V_HIGH - 0.15, _V_LOW + 0.3
    spacing = (top - bottom) / (count - 1)
    return [top - spacing * j for j in range(count)], min(0.25, 0.25 * spacing)


# ----------------------------------------------------------------------------
# Primitive shapes (points in (u, v); _Canvas maps them to the axes)
# ----------------------------------------------------------------------------


def _zigzag(p0: np.ndarray, p1: np.ndarray, width: float, coils: int = 8) -> np.ndarray:
    """Polyline of a spring from p0 to p1: straight leads and ``coils`` half-waves."""
    along = p1 - p0
    length = np.hypot(*along)
    unit = along / length
    normal = np.array([-unit[1], unit[0]])
    lead = 0.18 * length
    step = (length - 2 * lead) / coils
    points = [p0, p0 + lead * unit]
    for k in range(coils):
        sign = 1 if k % 2 == 0 else -1
        points.append(p0 + (lead + step * (k + 0.5)) * unit + sign * width * normal)
    points += [p1 - lead * unit, p1]
    return np.array(points)


def _piston(p0: np.ndarray, p1: np.ndarray, width: float) -> list[np.ndarray]:
    """Polylines of a dashpot: rod, open cylinder (closed end towards p0), plate and rod."""
    along = p1 - p0
    length = np.hypot(*along)
    unit = along / length
    normal = np.array([-unit[1], unit[0]])
    cylinder = min(0.4 * length, 1.0)
    closed = p0 + (0.5 * length - 0.5 * cylinder) * unit
    opened = closed + cylinder * unit
    plate = closed + 0.55 * cylinder * unit
    return [
        np.array([p0, closed]),
        np.array([opened + width * normal, closed + width * normal,
                  closed - width * normal, opened - width * normal]),
        np.array([plate + 0.75 * width * normal, plate - 0.75 * width * normal]),
        np.array([plate, p1]),
    ]


def _to_xy(points: Any, vertical: bool) -> np.ndarray:
    """Chain coordinates (u, v) as axes coordinates (x, y): a vertical chain runs downwards."""
    points = np.atleast_2d(np.asarray(points, dtype=float))
    if vertical:
        return np.column_stack([points[:, 1], -points[:, 0]])
    return points


class _Canvas:
    """Draws in chain coordinates (u along the chain, v across) on matplotlib axes."""

    def __init__(self, ax: Axes, layout: str) -> None:
        self.ax = ax
        self.vertical = layout == "vertical"

    def xy(self, points: Any) -> np.ndarray:
        return _to_xy(points, self.vertical)

    def line(self, points: Any, **style: Any) -> None:
        xy = self.xy(points)
        self.ax.plot(xy[:, 0], xy[:, 1], color=style.pop("color", "black"),
                     solid_capstyle="butt", **style)

    def box(self, u0: float, u1: float, v0: float, v1: float, **style: Any) -> None:
        from matplotlib.patches import Rectangle

        corners = self.xy([[u0, v0], [u1, v1]])
        (x0, y0), (x1, y1) = corners.min(axis=0), corners.max(axis=0)
        self.ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, **style))

    def circle(self, u: float, v: float, radius: float) -> None:
        from matplotlib.patches import Circle

        self.ax.add_patch(Circle(tuple(self.xy([u, v])[0]), radius, fill=False, linewidth=1.2))

    def text(self, u: float, v: float, label: str, side: int = 0, **style: Any) -> None:
        """Text centred at (u, v); in a vertical chain ``side`` = ±1 aligns it away from v."""
        x, y = self.xy([u, v])[0]
        ha = "center"
        if self.vertical and side:
            ha = "left" if side > 0 else "right"
        self.ax.text(x, y, label, ha=ha, va="center", **style)

    def arrow(self, p0: Any, p1: Any) -> None:
        from matplotlib.patches import FancyArrowPatch

        start, stop = self.xy([p0, p1])
        self.ax.add_patch(FancyArrowPatch(tuple(start), tuple(stop), arrowstyle="-|>",
                                          mutation_scale=14, linewidth=1.4, color="black",
                                          shrinkA=0, shrinkB=0))


# ----------------------------------------------------------------------------
# Drawing
# ----------------------------------------------------------------------------


@dataclass
class _Style:
    show_values: bool
    label_size: float
    line_width: float


def _support(canvas: _Canvas, u: float, v0: float, v1: float, side: int) -> None:
    """A fixed support across the chain at u (a wall or ceiling), hatched on ``side``."""
    canvas.box(u, u + side * _HATCH, v0, v1, fill=False, hatch="////", linewidth=0,
               edgecolor="0.35")
    canvas.line([[u, v0], [u, v1]], linewidth=3)


def _ground(canvas: _Canvas, u0: float, u1: float, v: float) -> None:
    """A fixed surface along the chain at v, hatched on its far side."""
    canvas.box(u0, u1, v, v - _HATCH, fill=False, hatch="////", linewidth=0, edgecolor="0.35")
    canvas.line([[u0, v], [u1, v]], linewidth=3)


def _element(canvas: _Canvas, component: Component, p0: Any, p1: Any, width: float,
             style: _Style) -> None:
    p0, p1 = np.asarray(p0, dtype=float), np.asarray(p1, dtype=float)
    if component.kind == "spring":
        canvas.line(_zigzag(p0, p1, width), linewidth=style.line_width)
    else:
        for part in _piston(p0, p1, width):
            canvas.line(part, linewidth=style.line_width)


def _component_label(canvas: _Canvas, component: Component, u: float, v: float,
                     style: _Style, side: int = 0) -> None:
    value = component.value if style.show_values else None
    canvas.text(u, v, math_label(component.label, value), side, color=LABEL_COLOUR,
                fontsize=style.label_size)


def _draw_gap(canvas: _Canvas, items: list[Component], u0: float, u1: float,
              style: _Style) -> None:
    lanes, width = _lanes(len(items))
    for j, (component, v) in enumerate(zip(items, lanes)):
        _element(canvas, component, (u0, v), (u1, v), width, style)
        side = -1 if len(items) > 1 and j == len(items) - 1 else 1
        gap = (0.12 if canvas.vertical else 0.3) if side > 0 else (0.12 if canvas.vertical else 0.2)
        _component_label(canvas, component, 0.5 * (u0 + u1), v + side * (width + gap), style, side)


def _draw_block(canvas: _Canvas, chain: Chain, i: int, u0: float, style: _Style,
                wheels: bool) -> None:
    from matplotlib.colors import to_rgba

    colour = to_rgba(BLOCK_COLOURS[i % len(BLOCK_COLOURS)], 0.5)
    canvas.box(u0, u0 + _BLOCK, _V_LOW, _V_HIGH, facecolor=colour, edgecolor="black",
               linewidth=2, zorder=3)
    value = chain.mass_values[i] if style.show_values else None
    canvas.text(u0 + 0.5 * _BLOCK, 0.5 * (_V_LOW + _V_HIGH), math_label(chain.masses[i], value),
                fontsize=style.label_size if value is None else 0.8 * style.label_size, zorder=4)
    if wheels:
        for du in (0.25, 0.75):
            canvas.circle(u0 + du * _BLOCK, 0.5 * _V_LOW, 0.08)
    canvas.line([[u0, _V_ARROW - 0.12], [u0, _V_ARROW + 0.12]], linewidth=1.2)
    canvas.arrow((u0, _V_ARROW), (u0 + 0.5, _V_ARROW))
    text_at = (u0 + 0.85, _V_ARROW) if not canvas.vertical else (u0 + 0.8, _V_ARROW + 0.05)
    canvas.text(*text_at, math_label(chain.coordinates[i]), fontsize=style.label_size)


def _draw_across(canvas: _Canvas, items: list[Component], u0: float, style: _Style) -> None:
    """Components from a block across the chain to the ground (or a side wall)."""
    count = len(items)
    for j, component in enumerate(items):
        u = u0 + _BLOCK * (j + 1) / (count + 1)
        width = min(0.12, 0.3 / count)
        _element(canvas, component, (u, 0.0 if not canvas.vertical else _V_LOW),
                 (u, _GROUND), width, style)
        v_label = 0.5 * (_GROUND + _V_LOW)
        _component_label(canvas, component, u + (0.3 if count == 1 else 0.0) + width,
                         v_label if count == 1 else _GROUND - 0.6, style)
    if canvas.vertical:
        _ground(canvas, u0 - 0.2, u0 + _BLOCK + 0.2, _GROUND)


def _draw_bridges(canvas: _Canvas, bridges: list[tuple[int, int, Component]],
                  starts: list[float], style: _Style) -> None:
    """Components between non-neighbouring masses, routed over the blocks."""
    for k, (i, j, component) in enumerate(bridges):
        v = _V_ARROW + 0.7 + 0.8 * k
        ua, ub = starts[i] + 0.6 * _BLOCK, starts[j] + 0.6 * _BLOCK
        canvas.line([[ua, _V_HIGH], [ua, v]], linewidth=style.line_width)
        canvas.line([[ub, _V_HIGH], [ub, v]], linewidth=style.line_width)
        _element(canvas, component, (ua, v), (ub, v), 0.15, style)
        _component_label(canvas, component, 0.5 * (ua + ub), v + 0.4, style)


def draw_scene(scene: Scene, ax: Axes | None = None, *, show_values: bool = False,
               title: str | bool = True, label_size: float = 16) -> Axes:
    """Draw the scene's masses, springs, dashpots and supports like the seed's figures.

    Parameters
    ----------
    scene : Scene
        A scene built from components, or a matrix scene that is a chain (see the
        module notes); its ``layout`` decides horizontal or vertical.
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; a new figure sized to the drawing when omitted.
    show_values : bool
        Write the values beside the labels (``k_1 = 0.3``).
    title : str or bool
        A title; True uses the scene's title, False none.
    label_size : float
        Font size of the labels, in points.

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
    """
    chain = chain_of(scene)
    style = _Style(show_values, label_size, 1.6)
    slots = _slots(chain)
    n = len(chain.masses)
    starts, end = _block_starts(slots, n)
    has_across = any(slots.across.values())
    horizontal = chain.layout == "horizontal"
    floor = _GROUND if (horizontal and has_across) else 0.0
    v_low = floor if horizontal else (_GROUND if has_across else -0.1)
    v_high = _V_ARROW + 0.3 + (0.8 * len(slots.bridges) + 0.5 if slots.bridges else 0.0)
    limits = _limits(chain.layout, end, v_low, v_high)
    if ax is None:
        ax = _new_axes(limits, bool(title))
    canvas = _Canvas(ax, chain.layout)
    wall_low = floor if horizontal else -0.1
    wall_high = _V_ARROW + 0.1 if horizontal else _V_HIGH + 0.2
    if slots.gaps[0]:
        _support(canvas, 0.0, wall_low, wall_high, -1)
        _draw_gap(canvas, slots.gaps[0], 0.0, starts[0], style)
    if slots.gaps[n]:
        _support(canvas, end, wall_low, wall_high, +1)
        _draw_gap(canvas, slots.gaps[n], starts[-1] + _BLOCK, end, style)
    for g in range(1, n):
        if slots.gaps[g]:
            _draw_gap(canvas, slots.gaps[g], starts[g - 1] + _BLOCK, starts[g], style)
    if horizontal:
        _ground(canvas, 0.0, end, floor)
    for i, u0 in enumerate(starts):
        _draw_block(canvas, chain, i, u0, style, wheels=horizontal and not has_across)
        if slots.across[i]:
            _draw_across(canvas, slots.across[i], u0, style)
    if slots.bridges:
        _draw_bridges(canvas, slots.bridges, starts, style)
    _finish(ax, limits)
    if title:
        text = scene.title if title is True else title
        if not horizontal:  # a tall, narrow drawing: wrap a long title
            text = textwrap.fill(text, 30)
        ax.set_title(text, fontsize=0.8 * label_size)
    return ax


def _limits(layout: str, end: float, v_low: float, v_high: float) -> tuple[float, float, float, float]:
    """(x0, x1, y0, y1) of the drawing."""
    corners = _to_xy([[-_HATCH - 0.1, v_low - _HATCH - 0.1], [end + _HATCH + 0.1, v_high]],
                     layout == "vertical")
    (x0, y0), (x1, y1) = corners.min(axis=0), corners.max(axis=0)
    return x0, x1, y0, y1


def _new_axes(limits: tuple[float, float, float, float], titled: bool) -> Axes:
    import matplotlib.pyplot as plt

    x0, x1, y0, y1 = limits
    scale = 0.8  # inches per block length
    fig = plt.figure(figsize=((x1 - x0) * scale, (y1 - y0) * scale + (0.45 if titled else 0.0)))
    height = (y1 - y0) * scale / fig.get_figheight()
    return fig.add_axes((0.0, 0.0, 1.0, height))


def _finish(ax: Axes, limits: tuple[float, float, float, float]) -> None:
    x0, x1, y0, y1 = limits
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    ax.set_axis_off()


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
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    scale, titled = 0.8, bool(ax.get_title())  # as draw_scene sizes its own figure
    figure.set_size_inches((x1 - x0) * scale, (y1 - y0) * scale + (0.45 if titled else 0.0))
    ax.set_position((0.0, 0.0, 1.0, (y1 - y0) * scale / figure.get_figheight()))
    buffer = io.BytesIO()
    figure.savefig(buffer, format=fmt, dpi=80)
    data = buffer.getvalue()
    return data if fmt == "png" else data.decode("utf-8")


register_diagram_renderer(scene_image)

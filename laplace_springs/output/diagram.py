"""Scene diagrams in the style of the seed's figures, with artists that can move.

:func:`build_diagram` draws a chain of masses (see :mod:`laplace_springs.output.chain`)
with matplotlib: masses as labelled, translucent blocks (pink, blue, purple, as on the
seed page), springs as zigzags, dashpots as pistons, walls, ceilings and floors hatched,
the coordinate arrows x1, x2, ... along the direction of motion and the labels k1, m1,
μ2 taken from the scene's own names. It returns a :class:`Diagram`, whose
:meth:`Diagram.move` puts the masses and the moving supports at given displacements
(springs stretch, pistons slide): the animations move the same artists.

Where things go
---------------
Masses sit in coordinate order along the chain. A component between neighbouring masses
goes in the gap between them; several in the same gap are drawn side by side (a spring
above a dashpot, as in the seed's Example 5). A component from the first mass to a
support goes to the start (the left wall, the ceiling, or the floor); from the last mass,
to the end; for a single mass the component's own order decides (``("wall", "m1")`` is on
the left). Supports named ``ground`` or ``air``, and supports of middle masses, are drawn
across the chain: in a horizontal chain down to the ground (friction with the surface, the
seed's δ), in a vertical chain sideways to a hatched side wall (air resistance). Springs
and dashpots between non-neighbouring masses are routed over the blocks.

Three orientations: ``"horizontal"`` (between walls, on rollers: the seed's Examples 3-5),
``"hanging"`` (a scene with ``layout="vertical"``: from a ceiling, x pointing down, the
seed's Examples 1-2) and ``"standing"`` (a scene whose only supports are floors or the
ground, with a spring to one: on a floor, x pointing up, as in base excitation). A moving
support is drawn with a double arrow and its displacement u(t).

Labels
------
Labels are sized in units of the drawing, not in points, so they keep their place at any
figure size: a drawing in a small subplot has small labels, never overlapping ones. Each
label goes to the first of its candidate places (above or beside what it names, then
further out) that overlaps neither the drawing nor another label, shrinking if none does.
"""

from __future__ import annotations

import functools
import textwrap
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import sympy as sp

from ..model.components import Component
from ..model.errors import SceneError
from ..model.scene import Scene
from ..model.supports import SUPPORTS, support_name
from .chain import Chain, chain_of, math_label, value_text

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.text import Text

__all__ = ["Diagram", "build_diagram", "orientation_of", "BLOCK_COLOURS", "SCALE_INCHES",
           "MAX_SHIFT"]

#: Block colours, in the seed's order (Pink, Blue, Purple, ...), drawn at 50 % opacity.
BLOCK_COLOURS = ("pink", "blue", "purple", "orange", "green", "gold")
LABEL_COLOUR = "red"
#: Inches per block length in a figure the diagram sizes itself (labels then have their
#: nominal size in points).
SCALE_INCHES = 0.8
#: The largest displacement an animation draws, in block lengths (pistons stay closed).
MAX_SHIFT = 0.3

# Geometry, in chain coordinates: u along the chain, v across it (units of a block).
_BLOCK = 1.0            # block length along the chain
_GAP = 2.5              # gap between blocks (and to a wall)
_MARGIN = 0.4           # end gap when nothing attaches to that end
_V_LOW, _V_HIGH = 0.2, 1.2   # block extent across the chain
_V_ARROW = 1.5          # coordinate arrows
_GROUND = -1.1          # ground / side wall level for components across the chain
_HATCH = 0.3            # thickness of hatched supports
_PAD = 0.06             # clearance between a label and what it names
_FLOORS = {"floor", "ground"}


def _base(node: str) -> str | None:
    """The support word a node names (``wall_left`` -> ``wall``), None for a mass."""
    name = support_name(node)
    if name is None:
        return None
    return next(word for word in sorted(SUPPORTS, key=len, reverse=True) if name.startswith(word))


def orientation_of(chain: Chain) -> str:
    """``"horizontal"``, ``"hanging"`` or ``"standing"`` (see the module notes).

    Examples
    --------
    >>> from laplace_springs import Scene, load_scene
    >>> from laplace_springs.output.chain import chain_of
    >>> orientation_of(chain_of(load_scene("vertical-pair"))), orientation_of(chain_of(load_scene("wall-pair")))
    ('hanging', 'horizontal')
    >>> orientation_of(chain_of(Scene.from_components(masses={"m": 1}, springs={"k": ("floor", "m", 4)})))
    'standing'
    """
    bases = {_base(node) for c in chain.components for node in (c.a, c.b)} - {None}
    floor_springs = any(c.kind == "spring" and (_base(c.a) in _FLOORS or _base(c.b) in _FLOORS)
                        for c in chain.components)
    if bases and bases <= _FLOORS | {"air"} and floor_springs:
        return "standing"
    return "hanging" if chain.layout == "vertical" else "horizontal"


# ----------------------------------------------------------------------------
# Where the components go
# ----------------------------------------------------------------------------


@dataclass
class _Slots:
    gaps: dict[int, list[Component]]        # gap g: between mass g-1 and mass g (0: start, n: end)
    across: dict[int, list[Component]]      # components from mass i across the chain
    bridges: list[tuple[int, int, Component]]
    ends: dict[int, list[str]]              # the support nodes at the start (0) and the end (n)


def _support_slot(orientation: str, base: str, mass: int, n: int, first: bool) -> str:
    """"start", "end" or "across" for a component from mass ``mass`` to a support."""
    if orientation == "standing":
        return "start" if base in _FLOORS and mass == 0 else "across"
    if base in ("ground", "air") or (orientation == "horizontal" and base == "floor"):
        return "across"
    if n == 1:
        return "start" if first else "end"
    return {0: "start", n - 1: "end"}.get(mass, "across")


def _slots(chain: Chain, orientation: str) -> _Slots:
    index = {name: i for i, name in enumerate(chain.masses)}
    n = len(chain.masses)
    slots = _Slots({g: [] for g in range(n + 1)}, {i: [] for i in range(n)}, [], {0: [], n: []})
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
            mass, support, first = a, component.b, False
        elif b is not None:
            mass, support, first = b, component.a, True
        else:
            raise SceneError(f"cannot draw {component.label or component.kind}: it joins "
                             f"{component.a} and {component.b}, neither of them a mass")
        slot = _support_slot(orientation, _base(support) or "wall", mass, n, first)
        if slot == "across":
            slots.across[mass].append(component)
        else:
            g = 0 if slot == "start" else n
            slots.gaps[g].append(component)
            slots.ends[g].append(support_name(support) or support)
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
# Primitive shapes (points in (u, v))
# ----------------------------------------------------------------------------


def _frame(p0: np.ndarray, p1: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    along = p1 - p0
    length = float(np.hypot(*along))
    unit = along / length if length > 0 else np.array([1.0, 0.0])
    return length, unit, np.array([-unit[1], unit[0]])


def _zigzag(p0: np.ndarray, p1: np.ndarray, width: float, coils: int = 8) -> np.ndarray:
    """Polyline of a spring from p0 to p1: straight leads and ``coils`` half-waves."""
    length, unit, normal = _frame(p0, p1)
    lead = 0.18 * length
    step = (length - 2 * lead) / coils
    points = [p0, p0 + lead * unit]
    for k in range(coils):
        sign = 1 if k % 2 == 0 else -1
        points.append(p0 + (lead + step * (k + 0.5)) * unit + sign * width * normal)
    points += [p1 - lead * unit, p1]
    return np.array(points)


def _piston(p0: np.ndarray, p1: np.ndarray, width: float, rest: float) -> list[np.ndarray]:
    """Polylines of a dashpot of rest length ``rest``: rod, open cylinder (closed end towards
    p0, fixed to it), plate (fixed to p1; in the middle of the cylinder at rest) and rod."""
    length, unit, normal = _frame(p0, p1)
    closed = p0 + 0.2 * rest * unit
    opened = closed + 0.6 * rest * unit
    travel = float(np.clip(length - 0.5 * rest, 0.22 * rest, 0.8 * rest))  # plate inside
    plate = p0 + travel * unit
    return [
        np.array([p0, closed]),
        np.array([opened + width * normal, closed + width * normal,
                  closed - width * normal, opened - width * normal]),
        np.array([plate + 0.75 * width * normal, plate - 0.75 * width * normal]),
        np.array([plate, p1]),
    ]


def _to_xy(points: Any, orientation: str) -> np.ndarray:
    """Chain coordinates (u, v) as axes coordinates (x, y)."""
    points = np.atleast_2d(np.asarray(points, dtype=float))
    if orientation == "hanging":
        return np.column_stack([points[:, 1], -points[:, 0]])
    if orientation == "standing":
        return np.column_stack([points[:, 1], points[:, 0]])
    return points


# ----------------------------------------------------------------------------
# Labels: sized in drawing units, placed where they overlap nothing
# ----------------------------------------------------------------------------

Box = tuple[float, float, float, float]  # x0, y0, x1, y1


@functools.lru_cache(maxsize=4096)
def text_extent(text: str) -> tuple[float, float]:
    """Width and height of matplotlib's layout box of ``text``, in units of its font size.

    Examples
    --------
    >>> width, height = text_extent("$k_{1}$")
    >>> 0.5 < width < 2 and 0.8 < height < 2
    True
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(dpi=72)
    canvas = FigureCanvasAgg(figure)
    artist = figure.text(0, 0, text, fontsize=100)
    box = artist.get_window_extent(renderer=canvas.get_renderer())
    return float(box.width) / 100.0, float(box.height) / 100.0


def _overlaps(a: Box, b: Box) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def _padded(box: Box, pad: float) -> Box:
    return box[0] - pad, box[1] - pad, box[2] + pad, box[3] + pad


@dataclass
class _Label:
    """A label: its text artist, its size (font size in drawing units) and what it follows."""

    artist: Text
    size: float
    follows: Callable[[np.ndarray, dict[str, float]], np.ndarray]
    owner: str = ""
    rest: np.ndarray = field(default_factory=lambda: np.zeros(2))
    width: float = 0.0   # the width of the box it was placed in (drawing units)


def _candidates(target: Box, width: float, height: float, sides: Sequence[str]) -> list[tuple[float, float]]:
    """Centres of a (width x height) box beside ``target`` on each side, then further out."""
    x0, y0, x1, y1 = target
    cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
    out = []
    for distance in (_PAD, _PAD + 0.25, _PAD + 0.6):
        for side in sides:
            if side == "above":
                out.append((cx, y1 + distance + 0.5 * height))
            elif side == "below":
                out.append((cx, y0 - distance - 0.5 * height))
            elif side == "right":
                out.append((x1 + distance + 0.5 * width, cy))
            elif side == "left":
                out.append((x0 - distance - 0.5 * width, cy))
            else:  # "inside"
                out.append((cx, cy))
    return out


class _Placer:
    """Finds label places that overlap neither the drawing's boxes nor placed labels."""

    def __init__(self, obstacles: list[tuple[Box, str]]) -> None:
        self.obstacles = obstacles
        self.placed: list[Box] = []

    def free(self, box: Box, owner: str) -> bool:
        if any(_overlaps(box, other) for other in self.placed):
            return False
        return not any(_overlaps(box, obstacle) for obstacle, name in self.obstacles
                       if not (owner and name == owner))

    def place(self, text: str, size: float, target: Box, sides: Sequence[str],
              owner: str = "") -> tuple[tuple[float, float], float]:
        """(centre, size) of the first free place, shrinking the label if none is free."""
        em_width, em_height = text_extent(text)
        first = None
        for scale in (1.0, 0.9, 0.8, 0.7, 0.6, 0.5, 0.45):
            width, height = em_width * size * scale, em_height * size * scale
            for centre in _candidates(target, width, height, sides):
                box = (centre[0] - width / 2, centre[1] - height / 2,
                       centre[0] + width / 2, centre[1] + height / 2)
                if owner and "inside" in sides and not _inside(box, target):
                    continue
                first = first or (centre, size * scale, box)
                if self.free(box, owner):
                    self.placed.append(box)
                    return centre, size * scale
        assert first is not None
        self.placed.append(first[2])
        return first[0], first[1]


def _inside(box: Box, target: Box) -> bool:
    return box[0] >= target[0] and box[1] >= target[1] and box[2] <= target[2] and box[3] <= target[3]


# ----------------------------------------------------------------------------
# The diagram
# ----------------------------------------------------------------------------


class Diagram:
    """A drawn scene whose masses and moving supports can be moved (:meth:`move`).

    Attributes
    ----------
    ax : matplotlib.axes.Axes
    chain : Chain
    orientation : str
        ``"horizontal"``, ``"hanging"`` or ``"standing"``.
    starts : list of float
        Where each block starts along the chain, at rest (drawing units).
    labels : list of matplotlib.text.Text
        The labels (components, masses, coordinates, moving supports).
    moving_supports : dict of str to sympy.Expr
        The supports drawn as moving, and their displacements u(t).
    """

    def __init__(self, ax: Axes, chain: Chain, orientation: str, scene: Scene) -> None:
        self.ax = ax
        self.chain = chain
        self.orientation = orientation
        self.scene = scene
        self.starts: list[float] = []
        self.end = 0.0
        self._movers: list[Callable[[np.ndarray, dict[str, float]], None]] = []
        self._labels: list[_Label] = []
        self.moving_supports = dict(getattr(scene, "support_motion", ()))
        self.obstacles: list[tuple[Box, str]] = []   # the drawing's boxes at rest, and their owners
        self._widths: list[tuple[Any, float]] = []   # (artist, line width in points at natural scale)
        self._arrows: list[tuple[Any, float]] = []   # (arrow, head size in points at natural scale)
        self._title_size = 12.0

    # -- coordinates ------------------------------------------------------------------
    def xy(self, points: Any) -> np.ndarray:
        return _to_xy(points, self.orientation)

    def direction(self) -> np.ndarray:
        """The unit vector (x, y) of a positive displacement."""
        return self.xy([[1.0, 0.0]])[0] - self.xy([[0.0, 0.0]])[0]

    @property
    def labels(self) -> list[Text]:
        return [label.artist for label in self._labels]

    @property
    def blocks(self) -> list[Any]:
        """The mass blocks (matplotlib Rectangles), in coordinate order."""
        return [artist for artist in self.ax.patches if str(artist.get_gid()).startswith("block:")]

    def block_positions(self) -> np.ndarray:
        """Each block's displacement from rest along the chain, read from its artist."""
        direction = self.direction()
        out = []
        for i, block in enumerate(self.blocks):
            x, y = block.get_xy()
            rest = self.xy([[self.starts[i], _V_LOW]])[0]
            corner = self.xy([[self.starts[i] + _BLOCK, _V_HIGH]])[0]
            lower = np.minimum(rest, corner)
            out.append(float(np.dot(np.array([x, y]) - lower, direction)))
        return np.array(out)

    # -- motion -----------------------------------------------------------------------
    def move(self, shifts: Any, supports: dict[str, float] | None = None) -> None:
        """Put mass i at displacement ``shifts[i]`` and each moving support at ``supports[name]``
        (drawing units along the chain; 0 is rest)."""
        shifts = np.asarray(shifts, dtype=float).reshape(-1)
        if shifts.size != len(self.chain.masses):
            raise ValueError(f"move: {shifts.size} displacements for {len(self.chain.masses)} masses")
        moved = {name: float(value) for name, value in (supports or {}).items()}
        for mover in self._movers:
            mover(shifts, moved)
        for label in self._labels:
            label.artist.set_position(tuple(label.rest + label.follows(shifts, moved)))

    def _shift(self, amount: float) -> np.ndarray:
        return amount * self.direction()

    def _follow_mass(self, i: int) -> Callable[[np.ndarray, dict[str, float]], np.ndarray]:
        return lambda d, s: self._shift(d[i])

    def _node_shift(self, node: int | str, d: np.ndarray, s: dict[str, float]) -> float:
        return float(d[node]) if isinstance(node, int) else s.get(node, 0.0)

    # -- fonts ------------------------------------------------------------------------
    def units_to_points(self) -> float:
        """Points per drawing unit in the axes as they are now."""
        transform = self.ax.transData
        pixels = abs(transform.transform((1.0, 0.0))[0] - transform.transform((0.0, 0.0))[0])
        return float(pixels * 72.0 / self.ax.figure.dpi)

    def fit_fonts(self) -> None:
        """Size every label, line and arrow head to its drawing-unit size, and the title to
        the axes' width."""
        scale = self.units_to_points()
        ratio = scale / (SCALE_INCHES * 72.0)
        for artist, width in self._widths:
            if abs(artist.get_linewidth() - width * ratio) > 1e-3:
                artist.set_linewidth(width * ratio)
        for arrow, head in self._arrows:
            if abs(arrow.get_mutation_scale() - head * ratio) > 1e-3:
                arrow.set_mutation_scale(head * ratio)
        for label in self._labels:
            _set_size(label.artist, max(label.size * scale, 0.5))
        title = self.ax.title
        if title.get_text():
            _set_size(title, self._fitted_title_size(title.get_text()))

    def _fitted_title_size(self, text: str) -> float:
        """The title's size: as asked, or smaller to fit the axes' slot (before the aspect)."""
        from matplotlib.transforms import TransformedBbox

        figure = self.ax.figure
        assert figure is not None
        slot = TransformedBbox(self.ax.get_position(original=True), figure.transSubfigure)
        width = slot.width * 72.0 / figure.dpi
        em = max(text_extent(line)[0] for line in text.split("\n"))
        return max(min(self._title_size, 0.95 * width / max(em, 1e-9)), 0.5)


# ----------------------------------------------------------------------------
# Drawing
# ----------------------------------------------------------------------------


@dataclass
class _Style:
    show_values: bool
    size: float          # label font size in drawing units
    line_width: float


class _Builder:
    """Draws the chain's artists on a Diagram, then places its labels."""

    def __init__(self, diagram: Diagram, style: _Style, slots: _Slots) -> None:
        self.d = diagram
        self.style = style
        self.slots = slots
        self.obstacles = diagram.obstacles
        self.pending: list[tuple[str, float, Box, Sequence[str], str, Callable[..., np.ndarray],
                                 dict[str, Any]]] = []

    # -- artists ----------------------------------------------------------------------
    def _box_of(self, xy: np.ndarray, pad: float = 0.03) -> Box:
        return (float(xy[:, 0].min()) - pad, float(xy[:, 1].min()) - pad,
                float(xy[:, 0].max()) + pad, float(xy[:, 1].max()) + pad)

    def line(self, points: Any, gid: str = "", **style: Any) -> Any:
        xy = self.d.xy(points)
        (artist,) = self.d.ax.plot(xy[:, 0], xy[:, 1], color=style.pop("color", "black"),
                                   solid_capstyle="butt", **style)
        artist.set_gid(gid or "drawing")
        self.obstacles.append((self._box_of(xy), gid))
        self.d._widths.append((artist, artist.get_linewidth()))
        return artist

    def box(self, u0: float, u1: float, v0: float, v1: float, gid: str = "", **style: Any) -> Any:
        from matplotlib.patches import Rectangle

        corners = self.d.xy([[u0, v0], [u1, v1]])
        (x0, y0), (x1, y1) = corners.min(axis=0), corners.max(axis=0)
        artist = Rectangle((x0, y0), x1 - x0, y1 - y0, **style)
        artist.set_gid(gid or "drawing")
        self.d.ax.add_patch(artist)
        self.obstacles.append(((x0, y0, x1, y1), gid))
        self.d._widths.append((artist, artist.get_linewidth()))
        return artist

    def circle(self, u: float, v: float, radius: float) -> Any:
        from matplotlib.patches import Circle

        centre = self.d.xy([u, v])[0]
        artist = Circle(tuple(centre), radius, fill=False, linewidth=1.2, gid="drawing")
        self.d.ax.add_patch(artist)
        self.obstacles.append(((centre[0] - radius, centre[1] - radius,
                                centre[0] + radius, centre[1] + radius), ""))
        self.d._widths.append((artist, artist.get_linewidth()))
        return artist

    def arrow(self, p0: Any, p1: Any, both: bool = False) -> Any:
        from matplotlib.patches import FancyArrowPatch

        start, stop = self.d.xy([p0, p1])
        artist = FancyArrowPatch(tuple(start), tuple(stop), arrowstyle="<|-|>" if both else "-|>",
                                 mutation_scale=14, linewidth=1.4, color="black",
                                 shrinkA=0, shrinkB=0, gid="drawing")
        self.d.ax.add_patch(artist)
        self.obstacles.append((self._box_of(np.array([start, stop]), pad=0.1), ""))
        self.d._widths.append((artist, artist.get_linewidth()))
        self.d._arrows.append((artist, artist.get_mutation_scale()))
        return artist

    def label(self, text: str, target: Box, sides: Sequence[str], follows: Callable[..., np.ndarray],
              owner: str = "", size: float | None = None, **style: Any) -> None:
        """Queue a label beside ``target`` (placed after every artist is drawn)."""
        self.pending.append((text, self.style.size if size is None else size, target, sides,
                             owner, follows, style))

    def place_labels(self) -> None:
        placer = _Placer(self.obstacles)
        for text, size, target, sides, owner, follows, style in self.pending:
            centre, fitted = placer.place(text, size, target, sides, owner)
            artist = self.d.ax.text(centre[0], centre[1], text, ha="center", va="center",
                                    fontsize=12, gid=f"label:{owner}" if owner else "label", **style)
            width = text_extent(text)[0] * fitted
            self.d._labels.append(_Label(artist, fitted, follows, owner, np.array(centre), width))

    # -- parts of the chain -----------------------------------------------------------
    def support(self, u: float, v0: float, v1: float, side: int, node: str | None) -> None:
        """A fixed support across the chain at u (a wall, ceiling or floor), hatched on ``side``."""
        hatch = self.box(u, u + side * _HATCH, v0, v1, fill=False, hatch="////", linewidth=0,
                         edgecolor="0.35")
        edge = self.line([[u, v0], [u, v1]], linewidth=3)
        if node is None or node not in self.d.moving_supports:
            return
        rest_hatch, rest_edge = np.array(hatch.get_xy()), edge.get_xydata().copy()

        def move(d: np.ndarray, s: dict[str, float]) -> None:
            offset = self.d._shift(s.get(node, 0.0))
            hatch.set_xy(tuple(rest_hatch + offset))
            edge.set_data(rest_edge[:, 0] + offset[0], rest_edge[:, 1] + offset[1])

        self.d._movers.append(move)
        marker_v = v1 + 0.35
        self.arrow((u - 0.4, marker_v), (u + 0.4, marker_v), both=True)
        u_text = "u(t)"
        if self.style.show_values:
            u_text += " = " + _latex(self.d.moving_supports[node])
        target = self._box_of(self.d.xy([[u - 0.4, marker_v], [u + 0.4, marker_v]]), pad=0.1)
        sides = ("above", "right") if self.d.orientation == "horizontal" else ("right", "above")
        self.label(f"${u_text}$", target, sides, lambda d, s: np.zeros(2))

    def ground(self, u0: float, u1: float, v: float) -> None:
        """A fixed surface along the chain at v, hatched on its far side."""
        self.box(u0, u1, v, v - _HATCH, fill=False, hatch="////", linewidth=0, edgecolor="0.35")
        self.line([[u0, v], [u1, v]], linewidth=3)

    def element(self, component: Component, ends: tuple[int | str, int | str], p0: Any, p1: Any,
                width: float, rigid: int | None = None) -> Box:
        """A spring or dashpot from p0 to p1 (rest positions); its ends follow the nodes
        ``ends`` (a mass index or a support name), or both follow mass ``rigid``."""
        p0, p1 = np.asarray(p0, dtype=float), np.asarray(p1, dtype=float)
        rest = float(np.hypot(*(p1 - p0)))
        lw = self.style.line_width
        if component.kind == "spring":
            parts = [_zigzag(p0, p1, width)]
        else:
            parts = _piston(p0, p1, width, rest)
        artists = [self.line(part, linewidth=lw) for part in parts]
        d = self.d

        def shape(a: np.ndarray, b: np.ndarray) -> list[np.ndarray]:
            return [_zigzag(a, b, width)] if component.kind == "spring" else _piston(a, b, width, rest)

        def move(shifts: np.ndarray, s: dict[str, float]) -> None:
            if rigid is not None:
                da = db = float(shifts[rigid])
            else:
                da, db = (d._node_shift(node, shifts, s) for node in ends)
            along = np.array([1.0, 0.0])
            for artist, part in zip(artists, shape(p0 + da * along, p1 + db * along)):
                xy = d.xy(part)
                artist.set_data(xy[:, 0], xy[:, 1])

        d._movers.append(move)
        return self._box_of(d.xy(np.vstack(parts)), pad=0.0)

    def component_label(self, component: Component, target: Box, sides: Sequence[str],
                        follows: Callable[..., np.ndarray]) -> None:
        value = None
        if self.style.show_values:
            value = value_text(component.value, "stiffness" if component.kind == "spring" else "damping",
                               self.d.scene)
        self.label(math_label(component.label, value), target, sides, follows, color=LABEL_COLOUR)

    def gap(self, g: int, u0: float, u1: float) -> None:
        items = self.slots.gaps[g]
        n = len(self.d.chain.masses)
        lanes, width = _lanes(len(items))
        left: int | str = g - 1 if g > 0 else self._end_node(0)
        right: int | str = g if g < n else self._end_node(n)
        d = self.d
        for j, (component, v) in enumerate(zip(items, lanes)):
            box = self.element(component, (left, right), (u0, v), (u1, v), width)
            last = len(items) > 1 and j == len(items) - 1
            if self.d.orientation == "horizontal":
                sides = ("below", "above") if last else ("above", "below")
            else:
                sides = ("left", "right") if last else ("right", "left")

            def follows(shifts: np.ndarray, s: dict[str, float], a: int | str = left,
                        b: int | str = right) -> np.ndarray:
                return d._shift(0.5 * (d._node_shift(a, shifts, s) + d._node_shift(b, shifts, s)))

            self.component_label(component, box, sides, follows)

    def _end_node(self, g: int) -> str:
        nodes = self.slots.ends.get(g, [])
        moving = [node for node in nodes if node in self.d.moving_supports]
        return moving[0] if moving else (nodes[0] if nodes else "")

    def block(self, i: int, u0: float, wheels: bool) -> None:
        from matplotlib.colors import to_rgba

        chain, d = self.d.chain, self.d
        colour = to_rgba(BLOCK_COLOURS[i % len(BLOCK_COLOURS)], 0.5)
        owner = f"block:{chain.masses[i]}"
        rectangle = self.box(u0, u0 + _BLOCK, _V_LOW, _V_HIGH, gid=owner, facecolor=colour,
                             edgecolor="black", linewidth=2, zorder=3)
        rest = np.array(rectangle.get_xy())
        parts: list[tuple[Any, np.ndarray]] = []
        if wheels:
            for du in (0.25, 0.75):
                wheel = self.circle(u0 + du * _BLOCK, 0.5 * _V_LOW, 0.08)
                parts.append((wheel, np.array(wheel.center)))

        def move(shifts: np.ndarray, s: dict[str, float]) -> None:
            offset = d._shift(shifts[i])
            rectangle.set_xy(tuple(rest + offset))
            for wheel, centre in parts:
                wheel.center = tuple(centre + offset)

        d._movers.append(move)
        value = value_text(chain.mass_values[i], "mass", d.scene) if self.style.show_values else None
        inside = (rest[0], rest[1], rest[0] + rectangle.get_width(), rest[1] + rectangle.get_height())
        self.label(math_label(chain.masses[i], value), _padded(inside, -0.06), ("inside",),
                   self.d._follow_mass(i), owner=owner, zorder=4)
        self.coordinate_arrow(i, u0)

    def coordinate_arrow(self, i: int, u0: float) -> None:
        """The coordinate's arrow along the direction of motion, from the block's rest edge."""
        self.line([[u0, _V_ARROW - 0.12], [u0, _V_ARROW + 0.12]], linewidth=1.2)
        self.arrow((u0, _V_ARROW), (u0 + 0.5, _V_ARROW))
        tip = self._box_of(self.d.xy([[u0, _V_ARROW], [u0 + 0.5, _V_ARROW]]), pad=0.1)
        sides = ("right", "above") if self.d.orientation == "horizontal" else ("right", "below")
        if self.d.orientation == "horizontal":
            target = (tip[2] - 0.02, tip[1], tip[2], tip[3])
        else:
            target = tip
        self.label(math_label(self.d.chain.coordinates[i]), target, sides, lambda d, s: np.zeros(2))

    def across(self, i: int, u0: float) -> None:
        """Components from a block across the chain to the ground (or a side wall)."""
        items = self.slots.across[i]
        count = len(items)
        vertical = self.d.orientation != "horizontal"
        for j, component in enumerate(items):
            u = u0 + _BLOCK * (j + 1) / (count + 1)
            width = min(0.12, 0.3 / count)
            top = _V_LOW if vertical else 0.0
            box = self.element(component, (i, i), (u, top), (u, _GROUND), width, rigid=i)
            sides: tuple[str, ...] = ("below", "above") if vertical else ("right", "left")
            if count > 1:
                sides = ("below", *sides) if not vertical else ("right", *sides)
            self.component_label(component, box, sides, self.d._follow_mass(i))
        if vertical:
            self.ground(u0 - 0.2, u0 + _BLOCK + 0.2, _GROUND)

    def bridges(self) -> None:
        """Components between non-neighbouring masses, routed over the blocks."""
        d = self.d
        for k, (i, j, component) in enumerate(self.slots.bridges):
            v = _V_ARROW + 0.7 + 0.8 * k
            ua, ub = self.d.starts[i] + 0.6 * _BLOCK, self.d.starts[j] + 0.6 * _BLOCK
            posts = [self.line([[ua, _V_HIGH], [ua, v]], linewidth=self.style.line_width),
                     self.line([[ub, _V_HIGH], [ub, v]], linewidth=self.style.line_width)]
            rests = [post.get_xydata().copy() for post in posts]

            def move(shifts: np.ndarray, s: dict[str, float], posts: list[Any] = posts,
                     rests: list[np.ndarray] = rests, ends: tuple[int, int] = (i, j)) -> None:
                for post, rest, mass in zip(posts, rests, ends):
                    offset = d._shift(shifts[mass])
                    post.set_data(rest[:, 0] + offset[0], rest[:, 1] + offset[1])

            d._movers.append(move)
            box = self.element(component, (i, j), (ua, v), (ub, v), 0.15)

            def follows(shifts: np.ndarray, s: dict[str, float], a: int = i, b: int = j) -> np.ndarray:
                return d._shift(0.5 * (shifts[a] + shifts[b]))

            self.component_label(component, box, ("above", "below"), follows)


def _set_size(text: Text, size: float) -> None:
    if abs(float(text.get_fontsize()) - size) > 1e-3:  # unchanged: leave the figure clean
        text.set_fontsize(size)


def _latex(expr: Any) -> str:
    return str(sp.latex(expr))


def _fitter(diagram: Diagram) -> Any:
    """An invisible artist, drawn first in its axes, that sizes the diagram's labels."""
    from matplotlib.artist import Artist

    class LabelFitter(Artist):
        def draw(self, renderer: Any) -> None:
            diagram.fit_fonts()

    fitter = LabelFitter()
    fitter.set_zorder(-1e9)
    fitter.set_gid("fitter")
    return fitter


def build_diagram(scene: Scene, ax: Axes | None = None, *, show_values: bool = False,
                  title: str | bool = True, label_size: float = 16, chain: Chain | None = None) -> Diagram:
    """Draw the scene's masses, springs, dashpots and supports like the seed's figures.

    Parameters
    ----------
    scene : Scene
        A scene built from components, or a matrix scene that is a chain (see
        :mod:`laplace_springs.output.chain`).
    ax : matplotlib.axes.Axes, optional
        Axes to draw on; a new pyplot figure sized to the drawing when omitted.
    show_values : bool
        Write the values beside the labels (``k_1 = 0.3``) and the moving supports' u(t).
    title : str or bool
        A title; True uses the scene's title, False none.
    label_size : float
        Font size of the labels, in points, in a figure of :data:`SCALE_INCHES` inches per
        block length (in smaller axes the labels shrink with the drawing).
    chain : Chain, optional
        The chain to draw (default ``chain_of(scene)``): the animations draw a part of a
        large scene.

    Returns
    -------
    Diagram

    Raises
    ------
    SceneError
        For a matrix scene that is not a chain of springs and dashpots.

    Examples
    --------
    >>> from matplotlib.figure import Figure
    >>> from laplace_springs import load_scene
    >>> diagram = build_diagram(load_scene("wall-pair"), Figure().subplots())
    >>> diagram.orientation, len(diagram.blocks)
    ('horizontal', 2)
    >>> diagram.move([0.2, -0.1]); diagram.block_positions().round(6).tolist()
    [0.2, -0.1]
    """
    chain = chain_of(scene) if chain is None else chain
    orientation = orientation_of(chain)
    style = _Style(show_values, label_size / 72.0 / SCALE_INCHES, 1.6)
    slots = _slots(chain, orientation)
    n = len(chain.masses)
    starts, end = _block_starts(slots, n)
    if ax is None:
        ax = _new_axes(_rough_limits(orientation, end), bool(title))
    diagram = Diagram(ax, chain, orientation, scene)
    diagram.starts, diagram.end = starts, end
    builder = _Builder(diagram, style, slots)
    _draw_chain(builder, slots, starts, end)
    builder.place_labels()
    ax.add_artist(_fitter(diagram))
    _finish(diagram)
    if title:
        text = scene.title if title is True else title
        if orientation != "horizontal":  # a tall, narrow drawing: wrap a long title
            text = textwrap.fill(text, 30)
        diagram._title_size = 0.8 * label_size
        ax.set_title(text, fontsize=0.8 * label_size)
    diagram.fit_fonts()
    return diagram


def _draw_chain(builder: _Builder, slots: _Slots, starts: list[float], end: float) -> None:
    n = len(starts)
    horizontal = builder.d.orientation == "horizontal"
    has_across = any(slots.across.values())
    floor = _GROUND if (horizontal and has_across) else 0.0
    wall_low = floor if horizontal else -0.1
    wall_high = _V_ARROW + 0.1 if horizontal else _V_HIGH + 0.2
    if slots.gaps[0]:
        builder.support(0.0, wall_low, wall_high, -1, builder._end_node(0) or None)
        builder.gap(0, 0.0, starts[0])
    if slots.gaps[n]:
        builder.support(end, wall_low, wall_high, +1, builder._end_node(n) or None)
        builder.gap(n, starts[-1] + _BLOCK, end)
    for g in range(1, n):
        if slots.gaps[g]:
            builder.gap(g, starts[g - 1] + _BLOCK, starts[g])
    if horizontal:
        builder.ground(0.0, end, floor)
    for i, u0 in enumerate(starts):
        builder.block(i, u0, wheels=horizontal and not has_across)
        if slots.across[i]:
            builder.across(i, u0)
    if slots.bridges:
        builder.bridges()


def _rough_limits(orientation: str, end: float) -> tuple[float, float, float, float]:
    corners = _to_xy([[-_HATCH - 0.1, _GROUND - _HATCH - 0.1], [end + _HATCH + 0.1, _V_ARROW + 0.5]],
                     orientation)
    (x0, y0), (x1, y1) = corners.min(axis=0), corners.max(axis=0)
    return x0, x1, y0, y1


def _new_axes(limits: tuple[float, float, float, float], titled: bool) -> Axes:
    import matplotlib.pyplot as plt

    x0, x1, y0, y1 = limits
    fig = plt.figure(figsize=((x1 - x0) * SCALE_INCHES, (y1 - y0) * SCALE_INCHES + (0.45 if titled else 0.0)))
    height = (y1 - y0) * SCALE_INCHES / fig.get_figheight()
    return fig.add_axes((0.0, 0.0, 1.0, height))


def content_box(diagram: Diagram) -> Box:
    """The box (x0, y0, x1, y1) holding every artist and label of the diagram at rest."""
    boxes = [box for box, _ in diagram.obstacles]
    boxes += [_label_box(label) for label in diagram._labels]
    return (min(b[0] for b in boxes), min(b[1] for b in boxes),
            max(b[2] for b in boxes), max(b[3] for b in boxes))


def _label_box(label: _Label) -> Box:
    width, height = text_extent(label.artist.get_text())
    w, h = width * label.size, height * label.size
    x, y = label.rest
    return x - w / 2, y - h / 2, x + w / 2, y + h / 2


def _finish(diagram: Diagram) -> None:
    """Limits around everything drawn (with room for the motion), equal aspect, no axes."""
    x0, y0, x1, y1 = content_box(diagram)
    room = MAX_SHIFT + 0.1
    ax = diagram.ax
    ax.set_xlim(x0 - room if diagram.orientation == "horizontal" else x0 - 0.1,
                x1 + room if diagram.orientation == "horizontal" else x1 + 0.1)
    ax.set_ylim(y0 - (room if diagram.orientation != "horizontal" else 0.1),
                y1 + (room if diagram.orientation != "horizontal" else 0.1))
    ax.set_aspect("equal")
    ax.set_axis_off()

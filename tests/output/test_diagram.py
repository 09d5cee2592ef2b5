"""Diagrams that hold up: labels clear of each other and of the drawing at any figure size,
moving masses and supports, the direction of motion, values shown."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import itertools

import numpy as np
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

import laplace_springs as ls
from laplace_springs.output.chain import chain_of
from laplace_springs.output.diagram import MAX_SHIFT, build_diagram, orientation_of


def _shaken():
    return ls.Scene.from_components(masses={"m": 1}, springs={"k": ("floor", "m", 4)},
                                    dashpots={"c": ("floor", "m", "0.4")},
                                    support_motion={"floor": "sin(3*t)/100"})


def _bridged():
    return ls.Scene.from_components(
        masses={"m1": 1, "m2": 2, "m3": 3},
        springs={"k1": ("wall", "m1", 1), "k2": ("m1", "m2", 1), "k3": ("m2", "m3", 1),
                 "k4": ("m1", "m3", 2), "k5": ("m3", "wall", 1)},
        dashpots={"c2": ("ground", "m2", 1)})


def _moving_wall():
    return ls.Scene.from_components(
        masses={"m1": 1, "m2": "1/2"},
        springs={"k1": ("wall_left", "m1", 3), "k2": ("m1", "m2", 1), "k3": ("m2", "wall_right", 2)},
        dashpots={"c": ("wall_left", "m1", "1/2")}, support_motion={"wall_left": "cos(2*t)/10"})


def _matrix_scene():
    base = ls.load_scene("three-dashpots")
    return ls.Scene.from_matrices(M=base.M, C=base.C, K=base.K, x0=base.x0, v0=base.v0)


SCENES = {name: (lambda name=name: ls.load_scene(name)) for name in ls.bundled_scenes()}
SCENES.update(shaken=_shaken, bridged=_bridged, moving_wall=_moving_wall, matrices=_matrix_scene)
#: (figure width, height) in inches and a subplot grid: a diagram alone, beside a plot, small
SIZES = [((8.0, 4.0), (1, 1)), ((9.0, 7.0), (2, 1)), ((4.0, 3.0), (1, 2)), ((12.0, 6.0), (2, 3))]


def _boxes(ax, renderer):
    """(label boxes with their owners, drawing boxes with their gids), in pixels."""
    labels = [(t.get_window_extent(renderer), str(t.get_gid())) for t in ax.texts]
    drawing = []
    for artist in list(ax.lines) + list(ax.patches):
        gid = str(artist.get_gid())
        if gid == "drawing" or gid.startswith("block:"):
            drawing.append((artist.get_window_extent(renderer), gid))
    return labels, drawing


def _overlap(a, b, tolerance=0.5):
    return (a.x0 + tolerance < b.x1 and b.x0 + tolerance < a.x1
            and a.y0 + tolerance < b.y1 and b.y0 + tolerance < a.y1)


def _cases():
    """Every scene with its values at every size; without values (shorter labels) at one."""
    for name in sorted(SCENES):
        yield pytest.param(name, True, SIZES, id=f"{name}-values")
        yield pytest.param(name, False, SIZES[2:3], id=f"{name}-names")


@pytest.mark.parametrize("name, show_values, sizes", _cases())
def test_labels_overlap_neither_each_other_nor_the_drawing_at_any_size(name, show_values, sizes):
    scene = SCENES[name]()
    for size, grid in sizes:
        figure = Figure(figsize=size, layout="constrained")
        axes = figure.subplots(*grid, squeeze=False).ravel()
        diagram = build_diagram(scene, axes[0], show_values=show_values)
        for other in axes[1:]:
            other.plot([0, 1], [0, 1])
        canvas = FigureCanvasAgg(figure)
        canvas.draw()
        renderer = canvas.get_renderer()
        labels, drawing = _boxes(diagram.ax, renderer)
        assert len(labels) == len(diagram.labels)
        for (a, _), (b, _) in itertools.combinations(labels, 2):
            assert not _overlap(a, b), (name, size, "labels overlap")
        for (box, owner), (part, gid) in itertools.product(labels, drawing):
            if owner == f"label:{gid}":
                assert box.x0 >= part.x0 - 0.5 and box.x1 <= part.x1 + 0.5, "mass label leaves its block"
                continue
            assert not _overlap(box, part), (name, size, owner, gid)
        title = diagram.ax.title.get_window_extent(renderer)
        assert title.x0 >= -0.5 and title.x1 <= figure.bbox.width + 0.5, "title wider than the figure"


def test_labels_are_sized_with_the_drawing():
    # The same diagram in a figure half as wide: every label half as large, in points.
    sizes = []
    for width in (8.0, 4.0):
        figure = Figure(figsize=(width, width / 2))
        diagram = build_diagram(ls.load_scene("wall-pair"), figure.subplots())
        FigureCanvasAgg(figure).draw()
        sizes.append(np.array([t.get_fontsize() for t in diagram.labels]))
    assert np.allclose(sizes[1], sizes[0] / 2, rtol=1e-6)


def test_values_of_a_moving_floor_scene_and_its_motion():
    diagram = build_diagram(_shaken(), Figure().subplots(), show_values=True)
    texts = [t.get_text() for t in diagram.labels]
    assert "$k = 4$" in texts and "$c = \\frac{2}{5}$" in texts and "$m = 1$" in texts
    motion = [t for t in texts if t.startswith("$u(t)")]
    assert motion == ["$u(t) = \\frac{\\sin{\\left(3 t \\right)}}{100}$"]
    assert diagram.orientation == "standing"
    assert np.allclose(diagram.direction(), [0.0, 1.0])  # x1 points up: the motion is vertical
    level = [line for line in diagram.ax.lines if np.ptp(line.get_ydata()) == 0]
    floor = max(level, key=lambda line: line.get_linewidth())  # the thick line of the floor
    before = floor.get_ydata().copy()
    diagram.move([0.1], {"floor": 0.05})
    assert np.allclose(floor.get_ydata(), before + 0.05)  # the floor moves with u(t)


def test_arrows_point_along_the_motion():
    for name, direction in (("vertical-pair", [0, -1]), ("wall-pair", [1, 0])):
        diagram = build_diagram(ls.load_scene(name), Figure().subplots())
        assert np.allclose(diagram.direction(), direction)
        arrows = [p for p in diagram.ax.patches if type(p).__name__ == "FancyArrowPatch"]
        for arrow in arrows:
            (x0, y0), (x1, y1) = arrow._posA_posB
            assert np.allclose(np.sign([x1 - x0, y1 - y0]), direction)


@pytest.mark.parametrize("name", sorted(SCENES))
def test_moved_blocks_are_where_they_were_put(name):
    diagram = build_diagram(SCENES[name](), Figure().subplots())
    n = len(diagram.blocks)
    shifts = np.linspace(-MAX_SHIFT, MAX_SHIFT, n)
    supports = dict.fromkeys(diagram.moving_supports, 0.1)
    diagram.move(shifts, supports)
    assert np.allclose(diagram.block_positions(), shifts)
    diagram.move(np.zeros(n))
    assert np.allclose(diagram.block_positions(), 0.0)


def test_orientations():
    assert orientation_of(chain_of(ls.load_scene("vertical-pair-damped"))) == "hanging"
    assert orientation_of(chain_of(_moving_wall())) == "horizontal"
    assert orientation_of(chain_of(_shaken())) == "standing"
    # ground friction alone (no spring to the ground) keeps a horizontal chain horizontal
    rolling = ls.Scene.from_components(masses={"m1": 1, "m2": 1}, springs={"k": ("m1", "m2", 1)},
                                       dashpots={"d1": ("ground", "m1", 1), "d2": ("ground", "m2", 1)})
    assert orientation_of(chain_of(rolling)) == "horizontal"


def test_scene_draw_is_draw_scene():
    ax = ls.load_scene("three-dashpots").draw(Figure().subplots(), show_values=True)
    assert "$k_{1} = 400$" in [t.get_text() for t in ax.texts]


@pytest.mark.parametrize("name", ["three-dashpots", "vertical-pair"])
def test_motion_legend_stays_inside_its_subplot(name):
    figure = Figure(figsize=(6.0, 3.0), layout="constrained")
    left, right = figure.subplots(1, 2)
    ls.solve(ls.load_scene(name)).plot(right)
    left.plot([0, 1], [0, 1])
    canvas = FigureCanvasAgg(figure)
    canvas.draw()
    legend = right.get_legend().get_window_extent(canvas.get_renderer())
    frame = right.get_window_extent(canvas.get_renderer())
    assert frame.x0 <= legend.x0 and legend.x1 <= frame.x1 and frame.y0 <= legend.y0 and legend.y1 <= frame.y1

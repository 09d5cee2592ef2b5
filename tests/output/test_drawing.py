"""Scene diagrams: every bundled scene draws, with the seed's labels in the seed's places."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest
import sympy as sp
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle

import laplace_springs as ls
from laplace_springs.output.chain import chain_of, math_label, physical_matrices
from laplace_springs.output.drawing import draw_scene


def _axes():
    return Figure().subplots()


def _texts(ax) -> dict[str, tuple[float, float]]:
    return {text.get_text(): text.get_position() for text in ax.texts if text.get_text()}


def _blocks(ax) -> list[Rectangle]:
    """The mass blocks: filled rectangles (hatched supports are unfilled)."""
    return [p for p in ax.patches if isinstance(p, Rectangle) and p.get_fill()]


@pytest.mark.parametrize("name", sorted(ls.bundled_scenes()))
def test_every_bundled_scene_draws_with_its_own_labels(name):
    scene = ls.load_scene(name)
    ax = draw_scene(scene, _axes())
    texts = _texts(ax)
    expected = {math_label(c.label) for c in scene.components}
    expected |= {math_label(m) for m in scene.mass_names} | {math_label(x) for x in scene.names}
    assert expected <= set(texts)
    assert len(_blocks(ax)) == scene.n
    assert " ".join(ax.get_title().split()) == scene.title  # long titles wrap when vertical


def test_vertical_pair_hangs_from_the_ceiling_like_example_1():
    # Seed figure: ceiling on top, k1, m1, k2, m2 downwards; arrows x1, x2 point down.
    ax = draw_scene(ls.load_scene("vertical-pair"), _axes())
    texts = _texts(ax)
    ys = [texts[label][1] for label in ("$k_{1}$", "$m_{1}$", "$k_{2}$", "$m_{2}$")]
    assert ys == sorted(ys, reverse=True)
    xs = {round(texts[label][0], 6) for label in ("$m_{1}$", "$m_{2}$")}
    assert len(xs) == 1  # one column
    top_line = max(max(line.get_ydata()) for line in ax.lines)
    assert top_line >= max(ys)  # the ceiling is above everything


def test_wall_pair_runs_left_to_right_like_example_3():
    ax = draw_scene(ls.load_scene("wall-pair"), _axes())
    texts = _texts(ax)
    xs = [texts[label][0] for label in ("$k_{1}$", "$m_{1}$", "$k_{2}$", "$m_{2}$", "$k_{3}$")]
    assert xs == sorted(xs)
    blocks = _blocks(ax)
    assert len({round(b.get_y(), 6) for b in blocks}) == 1  # same height


def test_parallel_spring_and_dashpot_share_a_gap_like_example_5():
    ax = draw_scene(ls.load_scene("three-dashpots"), _axes())
    texts = _texts(ax)
    for j in (1, 2, 3):
        k, mu = texts[f"$k_{{{j}}}$"], texts[f"$\\mu_{{{j}}}$"]
        assert k[0] == pytest.approx(mu[0])  # same gap
        assert k[1] > mu[1]  # spring above, dashpot below


def test_show_values_writes_exact_values():
    ax = draw_scene(ls.load_scene("wall-pair"), _axes(), show_values=True)
    assert "$m_{2} = \\frac{2}{3}$" in _texts(ax)
    assert "$k_{2} = \\frac{2}{25}$" in _texts(ax)


def test_matrix_scene_is_read_as_a_chain():
    # Example 5 from its matrices: the row sums are the wall springs and dashpots.
    scene = ls.load_scene("three-dashpots")
    plain = ls.Scene.from_matrices(M=scene.M, C=scene.C, K=scene.K, x0=scene.x0, v0=scene.v0)
    chain = chain_of(plain)
    found = {(c.kind, c.a, c.b, c.value) for c in chain.components}
    given = {(c.kind, c.a, c.b, c.value) for c in scene.components}
    assert found == given
    assert len(_blocks(draw_scene(plain, _axes()))) == 2


def test_normalized_example_1_is_rescaled_to_masses():
    # A = [[3, -1], [-2, 2]] is M⁻¹K for m2/m1 = 1/2 (the seed's (1.1) with k1 = 2, k2 = 1).
    scene = ls.Scene.from_normalized(A=[[3, -1], [-2, 2]], x0=[1, 0], v0=[0, 0], layout="vertical")
    M, C, K = physical_matrices(scene)
    assert M.tolist() == [[1, 0], [0, sp.Rational(1, 2)]]
    assert (M.inv() * K).tolist() == [[3, -1], [-2, 2]]
    assert [c.label for c in chain_of(scene).components] == ["k1", "k2"]


@pytest.mark.parametrize("K, message", [
    ([[2, 1], [1, 2]], "K\\[0,1\\] = 1 > 0"),
    ([[1, -2], [-2, 1]], "row 0 of K sums to -1"),
])
def test_matrix_scene_that_is_no_chain_raises(K, message):
    scene = ls.Scene.from_matrices(M=[[1, 0], [0, 1]], K=K, x0=[1, 0], v0=[0, 0])
    with pytest.raises(ls.SceneError, match=message):
        draw_scene(scene, _axes())


def test_one_way_coupling_raises():
    scene = ls.Scene.from_normalized(A=[[2, -1], [0, 1]], x0=[1, 0], v0=[0, 0])
    with pytest.raises(ls.SceneError, match="one-way coupling"):
        draw_scene(scene, _axes())


def test_longer_chain_with_bridge_and_ground_dashpot():
    scene = ls.Scene.from_components(
        masses={"m1": 1, "m2": 2, "m3": 3},
        springs={"k1": ("wall", "m1", 1), "k2": ("m1", "m2", 1), "k3": ("m2", "m3", 1),
                 "k4": ("m1", "m3", 2), "k5": ("m3", "wall", 1)},
        dashpots={"c2": ("ground", "m2", 1)})
    ax = draw_scene(scene, _axes())
    texts = _texts(ax)
    assert texts["$k_{4}$"][1] > texts["$x_{1}$"][1]  # routed over the blocks
    assert texts["$c_{2}$"][1] < min(b.get_y() for b in _blocks(ax))  # below the blocks


def test_new_figure_is_sized_to_the_drawing():
    ax = draw_scene(ls.load_scene("vertical-pair"))
    width, height = ax.figure.get_size_inches()
    assert height > width  # a hanging chain is tall
    plt.close(ax.figure)


def test_math_label_of_plain_names():
    assert math_label("x") == "$x$"
    assert math_label("omega_2") == "$\\omega_{2}$"
    assert np.isclose(float(chain_of(ls.load_scene("wall-pair")).mass_values[1]), 2 / 3)

"""The explorer: each move's curves are the solution at the sliders' values, its closed form
evaluates to them, and a move is fast (timed in benchmarks/bench_explore.py, not here)."""

from __future__ import annotations

import re

import numpy as np
import pytest
import sympy as sp

import laplace_springs as ls

pytest.importorskip("ipywidgets")
from laplace_springs.publish.explore import explore


def _formula_values(latex: str, times: np.ndarray) -> np.ndarray:
    """Evaluate the explorer's closed form (4 significant digits) at ``times``."""
    number = r"(-?[0-9.]+(?: \\times 10\^\{-?\d+\})?)"

    def value(text: str) -> float:
        mantissa, _, exponent = text.partition(" \\times 10^{")
        return float(mantissa) * 10 ** int(exponent.rstrip("}") or 0)

    rows = []
    for line in latex.split("\\\\"):
        total = np.zeros_like(times)
        body = line.split("\\approx", 1)[1]
        pattern = (rf"(?:e\^\{{{number}t\}})?\\left\({number}\\cos {number}t ([+-]) {number}\\sin {number}t\\right\)")
        for rate, a, beta, sign, b, _ in re.findall(pattern, body):
            decay = np.exp(value(rate) * times) if rate else 1.0
            w = value(beta)
            total += decay * (value(a) * np.cos(w * times) + (1 if sign == "+" else -1) * value(b) * np.sin(w * times))
        rows.append(total)
    return np.array(rows)


def test_a_move_shows_the_solution_at_the_new_values():
    explorer = explore(ls.load_scene("three-dashpots"))
    explorer.set(k1=600.0, x0_2=0.02)
    # the same scene written out with k1 = 600 and x2(0) = 1/50, solved on its own
    moved = ls.Scene.from_components(
        masses={"m1": 1, "m2": "4/5"},
        springs={"k1": ("wall", "m1", 600), "k2": ("m1", "m2", 379), "k3": ("m2", "wall", 100)},
        dashpots={"mu1": ("wall", "m1", "1/2"), "mu2": ("m1", "m2", "7/5"), "mu3": ("m2", "wall", "9/10")},
        x0=["1/20", "1/50"], v0=[3, 2])
    expected = np.asarray(ls.solve(moved).evaluate(explorer.times), dtype=float)
    assert np.allclose(explorer.positions, expected, rtol=0, atol=1e-12)
    early = explorer.times <= 1.0  # 4 significant digits of each frequency: the phase drifts later
    formula = _formula_values(explorer.closed_form, explorer.times[early])
    assert np.allclose(formula, expected[:, early], atol=3e-3 * np.max(np.abs(expected)))
    assert "k_{1} = 600" in explorer._picture.value.replace("<tspan baseline-shift=\"sub\" font-size=\"70%\">1</tspan>", "_{1}")


def test_the_harmonic_drive_of_a_free_scene():
    explorer = explore(ls.load_scene("wall-pair"), knobs=[])
    assert [k.name for k in explorer.knobs] == ["x0_1", "x0_2", "v0_1", "v0_2", "F", "w"]
    explorer.set(F=0.1, w=0.4)
    base = ls.load_scene("wall-pair")
    driven = ls.Scene.from_matrices(M=base.M, C=base.C, K=base.K, x0=base.x0, v0=base.v0,
                                    forcing=[sp.Rational(1, 10) * sp.cos(sp.Rational(2, 5) * ls.t), 0])
    expected = np.asarray(ls.solve(driven).evaluate(explorer.times), dtype=float)
    assert np.allclose(explorer.positions, expected, rtol=0, atol=1e-12)
    explorer.reset()
    assert explorer.values["F"] == 0


def test_repeated_roots_fall_back_to_the_exact_solution():
    scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[["k"]], x0=[1], v0=[0], parameters=["c", "k"])
    explorer = explore(scene, values={"c": 1, "k": 1}, t_end=5)
    explorer.set(c=2.0, k=1.0)  # critical damping: x = (1 + t) e^{-t}
    assert np.allclose(explorer.positions[0], (1 + explorer.times) * np.exp(-explorer.times), atol=1e-12)
    assert "repeated roots" in explorer.closed_form


def test_unknown_knobs_are_named():
    explorer = explore(ls.load_scene("wall-pair"), knobs=["k1"])
    with pytest.raises(ls.SceneError, match="'?k9'? is not a knob"):
        explorer.set(k9=1.0)

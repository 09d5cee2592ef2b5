"""Hostile sizes (issue 22): requests that would exhaust memory or run for minutes are
refused at once by a limit of :class:`~laplace_springs.limits.Limits` that the message
names, with the way out, before anything of that size is allocated or converted.

Arrays of 10⁸-10¹² entries are given as NumPy views of one number (``broadcast_to``:
no memory), so a regression that converts or copies them fails with a MemoryError or the
time limit of the child process, not by luck.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.model.errors import LimitError, SceneError
from tests._hostile import attempts

ONE = ls.Scene.from_matrices(M=[[1]], C=[["1/2"]], K=[[4]], x0=[1], v0=[0])


class Untouchable:
    """A time that fails the test when it is converted: counts must come first."""

    def __float__(self):
        raise AssertionError("a time was converted before the count was checked")

    __index__ = __int__ = __float__


def test_too_many_times_are_refused_before_any_is_read(set_limits):
    set_limits(max_times=10)
    with pytest.raises(LimitError, match=r"11 times, more than Limits.max_times = 10 in one "
                                         r"evaluation; evaluate them in chunks of at most 10 times"):
        ls.solve(ONE).evaluate([Untouchable()] * 11)
    values = ls.solve(ONE).evaluate(np.linspace(0, 1, 10))
    # x = e^{-t/4}(cos(ωt) + sin(ωt)/(4ω)), ω = √(4 - 1/16): the textbook underdamped motion
    omega = np.sqrt(4 - 1 / 16)
    times = np.linspace(0, 1, 10)
    expected = np.exp(-times / 4) * (np.cos(omega * times) + np.sin(omega * times) / (4 * omega))
    assert np.allclose(values[0], expected, rtol=1e-12, atol=1e-14)


def test_sizes_of_the_issue_are_refused_at_once_in_a_child():
    found = attempts("""
import numpy as np
import laplace_springs as ls
one = ls.Scene.from_matrices(M=[[1]], C=[["1/2"]], K=[[4]], x0=[1], v0=[0])
pair = ls.load_scene("wall-pair")
sc = ls.Scene.from_matrices(M=[["m"]], C=[["c"]], K=[["k"]], x0=[1], v0=[0],
                            parameters={"m": "positive", "k": "positive", "c": "nonnegative"})
huge = np.broadcast_to(0.5, (10**9,))
""", {
        "evaluate 10^8": "ls.solve(one).evaluate(np.broadcast_to(0.5, (10**8,)))",
        "pair 3*10^7": "ls.solve(pair).evaluate(np.broadcast_to(0.5, (3 * 10**7,)))",
        "list 3*10^7": "ls.solve(one).evaluate([0.5] * (3 * 10**7))",
        "frequency_response 10^9": "ls.frequency_response(pair, huge)",
        "transmissibility 10^9": "ls.transmissibility(ls.Scene.from_components(masses={'m': 1}, "
                                 "springs={'k': ('floor', 'm', 4)}), huge)",
        "grid 10^12": "ls.grid(a=np.arange(10**6), b=np.arange(10**6))",
        "grid 10^12 in three": "ls.grid(m=np.ones(10**4), k=np.ones(10**4), c=np.ones(10**4))",
        "sample_parameters 10^12": "ls.sample_parameters({'k': ('normal', 1, 0.1)}, 10**12)",
        "sweep 10^9 values": "ls.sweep(sc, {'m': np.ones(10**4), 'k': np.ones(10**4), 'c': np.zeros(10**4)}, "
                             "np.linspace(0, 1, 10**5))",
    }, timeout=120)
    limits_named = {
        "evaluate 10^8": "Limits.max_times", "pair 3*10^7": "Limits.max_times",
        "list 3*10^7": "Limits.max_times", "frequency_response 10^9": "Limits.max_evaluation_values",
        "transmissibility 10^9": "Limits.max_evaluation_values", "grid 10^12": "Limits.sweep_max_sets",
        "grid 10^12 in three": "Limits.sweep_max_sets", "sample_parameters 10^12": "Limits.sweep_max_sets",
        "sweep 10^9 values": "Limits.max_evaluation_values",
    }
    for name, outcome in found.items():
        assert outcome.kind == "LimitError", (name, outcome)
        assert limits_named[name] in outcome.text, (name, outcome)
    assert "give out= (a .npy path or a numpy.memmap" in found["sweep 10^9 values"].text
    assert "1,000,000 x 1,000,000 = 1,000,000,000,000 parameter sets" in found["grid 10^12"].text


def test_a_sweep_too_large_for_memory_streams_to_a_store_or_to_quantities(set_limits, tmp_path):
    scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[["k"]], x0=[1], v0=[0],
                                   parameters={"k": "positive", "c": "nonnegative"})
    values = {"k": [1, 4, 9], "c": [2, 0, 0]}
    times = np.linspace(0, 3, 7)
    set_limits(max_evaluation_values=20)
    with pytest.raises(LimitError, match=r"3 sets x 1 outputs x 7 times = 21 values, more than "
                                         r"Limits.max_evaluation_values = 20 in memory; give out="):
        ls.sweep(scene, values, times)
    with pytest.raises(LimitError, match="give error_out="):
        ls.sweep(scene, values, times, out=tmp_path / "x.npy", return_error=True)
    stored = ls.sweep(scene, values, times, out=tmp_path / "x.npy")
    # critical damping (1 + t)e^{-t}, then cos(2t), cos(3t): textbook motions
    expected = np.array([(1 + times) * np.exp(-times), np.cos(2 * times), np.cos(3 * times)])
    assert np.allclose(np.asarray(stored)[:, 0, :], expected, rtol=1e-12, atol=1e-14)
    peaks = ls.sweep(scene, values, times, quantities=["peak"]).quantities["peak"]
    assert np.allclose(peaks[:, 0], 1.0, rtol=1e-12)


def test_a_grid_at_the_limit_is_built(set_limits):
    set_limits(sweep_max_sets=6)
    g = ls.grid(k=[1, 2], c=[0.1, 0.2, 0.3])
    assert g.shape == (2, 3) and g["c"].tolist() == [0.1, 0.2, 0.3] * 2
    with pytest.raises(LimitError, match=r"grid: 2 x 4 = 8 parameter sets, more than Limits.sweep_max_sets = 6"):
        ls.grid(k=[1, 2], c=[0.1, 0.2, 0.3, 0.4])


def test_frequency_requests_are_held_to_the_evaluation_limit(set_limits):
    pair = ls.load_scene("wall-pair")
    set_limits(max_evaluation_values=40)
    assert ls.frequency_response(pair, np.linspace(0.1, 1, 10)).shape == (10, 2, 2)
    with pytest.raises(LimitError, match=r"11 frequencies x 4 values each = 44 values, more than "
                                         r"Limits.max_evaluation_values = 40; give at most 10 frequencies"):
        ls.frequency_response(pair, np.linspace(0.1, 1, 11))


def test_huge_powers_in_text_are_refused_at_once():
    found = attempts("import laplace_springs as ls", {
        text: f"ls.Scene.from_matrices(M=[[1]], K=[[4]], x0=[0], v0=[0], forcing=[{text!r}])"
        for text in ("t**1000000", "t**(10**6)", "(t+1)**(10**5)", "exp(t)**(10**6)")
    }, timeout=60)
    for text, outcome in found.items():
        assert outcome.kind in ("SceneError", "LimitError"), (text, outcome)
    assert "magnitude about 1e+37382 at t = 97/89" in found["t**1000000"].text


def test_sympy_forcing_of_unknown_functions_and_deep_nesting_is_named():
    f = sp.Function("f")(ls.t)
    with pytest.raises(SceneError, match=r"f\(t\) is not supported: f\(t\) is an unknown function"):
        ls.Scene.from_matrices(M=[[1]], K=[[4]], x0=[0], v0=[0], forcing=[f])
    deep = ls.t
    for _ in range(400):
        deep = sp.sin(deep, evaluate=False)
    nested = r"the expression is nested more than 100 levels deep \(Limits.max_nesting_depth\)"
    with pytest.raises(SceneError, match=nested):
        ls.Scene.from_matrices(M=[[1]], K=[[4]], x0=[0], v0=[0], forcing=[deep])
    with pytest.raises(SceneError, match=nested):
        ls.Scene.from_matrices(M=[[1]], K=[[4]], x0=[0], v0=[0]).with_forcing([deep])
    number = sp.Integer(1)
    for _ in range(400):
        number = sp.sin(number, evaluate=False)
    for M in ([[number]], sp.ImmutableMatrix([[number]])):
        with pytest.raises(SceneError, match="nested"):  # SymPy's RecursionError never escapes
            ls.Scene.from_matrices(M=M, K=[[4]], x0=[0], v0=[0])
    shallow = ls.t
    for _ in range(3):
        shallow = sp.sin(shallow)
    with pytest.raises(SceneError, match="not supported"):  # within the depth: judged as usual
        ls.Scene.from_matrices(M=[[1]], K=[[4]], x0=[0], v0=[0], forcing=[shallow])


def test_animation_frames_are_held_to_the_pixel_limit():
    movie = ls.animate(ls.solve(ls.load_scene("wall-pair")), duration=1, fps=2)
    for dpi in (0, -1, float("nan"), float("inf"), True, "80"):
        with pytest.raises(SceneError, match="dpi must be a positive number"):
            movie.save("never-written.gif", dpi=dpi)
    with pytest.raises(SceneError, match=r"at dpi = 1e\+09 gives frames of .* pixels, more than "
                                         r"Limits.animation_max_frame_pixels = 4,000,000; use dpi <= "):
        movie.save("never-written.gif", dpi=1e9)
    with pytest.raises(SceneError, match=r"1000 x 1000 inches at dpi = 100 .* a smaller figsize"):
        ls.animate(ls.solve(ls.load_scene("wall-pair")), duration=1, fps=2, figsize=(1000, 1000))
    with pytest.raises(SceneError, match="figsize must be two positive numbers"):
        ls.animate(ls.solve(ls.load_scene("wall-pair")), duration=1, fps=2, figsize=(0, 3))

"""The per-scene tables of numeric/first_order.py: read once, exact, and dropped with
their scene (a long session of scenes must not keep every one's data alive)."""

from __future__ import annotations

import gc
import weakref
from fractions import Fraction

import laplace_springs as ls
from laplace_springs.numeric import first_order
from laplace_springs.numeric.first_order import rational_matrices, scene_cache


def test_the_entries_are_the_exact_input():
    scene = ls.Scene.from_matrices(M=[[2, 0], [0, "1/3"]], C=[["0.1", 0], [0, 0]],
                                   K=[[3, -1], [-1, "7/2"]], x0=["-1/7", 0], v0=[0, "2.5"])
    M, C, K, x0, v0 = rational_matrices(scene, ("M", "C", "K", "x0", "v0"))
    as_fractions = {name: {key: Fraction(int(v.p), int(v.q)) for key, v in entries.items()}
                    for name, entries in zip("MCKxv", (M, C, K, x0, v0))}
    assert as_fractions["M"] == {(0, 0): 2, (1, 1): Fraction(1, 3)}
    assert as_fractions["C"] == {(0, 0): Fraction(1, 10)}
    assert as_fractions["K"] == {(0, 0): 3, (0, 1): -1, (1, 0): -1, (1, 1): Fraction(7, 2)}
    assert as_fractions["x"] == {(0, 0): Fraction(-1, 7)}
    assert as_fractions["v"] == {(1, 0): Fraction(5, 2)}
    # read once: the same objects on the next call
    assert rational_matrices(scene, ("K",))[0] is K


def test_a_symbolic_entry_is_no_rational_matrix():
    scene = ls.Scene.from_matrices(M=[[1]], K=[["k"]], x0=[1], v0=[0], parameters=["k"])
    assert rational_matrices(scene, ("M", "K"))[1] is None


def test_the_table_goes_with_its_scene():
    scene = ls.Scene.from_matrices(M=[[1]], C=[[1]], K=[[4]], x0=[1], v0=[0])
    ls.solve(scene).evaluate([0.5])
    key, alive = id(scene), weakref.ref(scene)
    assert scene_cache(scene) and key in first_order._ENTRIES
    del scene
    gc.collect()
    assert alive() is None and key not in first_order._ENTRIES

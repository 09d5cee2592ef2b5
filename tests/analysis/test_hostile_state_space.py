"""Hostile state-space input (issue 22): shapes that are not matrices are SceneErrors that
say what is wrong (``from_state_space([0, 1])`` raised "'int' object is not iterable")."""

from __future__ import annotations

import numpy as np
import pytest

import laplace_springs as ls
from laplace_springs.model.errors import SceneError


@pytest.mark.parametrize(("A", "fragment"), [
    ([0, 1], "row 0 is 0, not a row of entries (a flat list is a vector"),
    (np.array([0, 1]), "row 0 is 0, not a row of entries"),
    (5, "A must be a matrix: rows of entries"),
    (None, "A must be a matrix"),
    ("[[0, 1], [1, 0]]", "A must be a matrix"),
    ({"a": 1}, "A must be a matrix"),
    ([[0, 1], [1]], "A has rows of different lengths: [2, 1]"),
    ([[0, 1], "ab"], "row 1 is 'ab'"),
    ([[0, 1, 0], [0, 0, 1], [1, 1, 1]], "even size 2n"),
    ([], "even size 2n"),
    (np.zeros((5000, 5000)), "A has 5,000 rows; at most 1000 square is read"),
    ([[0, 1], [-1, "x"]], "A[1,1]: expected a number, got 'x'"),
], ids=["flat list", "flat array", "int", "None", "text", "dict", "ragged", "text row", "odd",
        "empty", "huge", "undeclared name"])
def test_bad_state_matrices_are_named(A, fragment):
    with pytest.raises(SceneError) as caught:
        ls.from_state_space(A)
    assert fragment in str(caught.value)


def test_a_good_state_matrix_still_reads():
    scene = ls.from_state_space(np.array([[0, 1], [-4, -0.5]]), x0=[1], v0=[0])
    assert scene.K.tolist() == [[4]] and scene.C.tolist() == [[ls.Scene.from_matrices(
        M=[[1]], C=[["1/2"]], K=[[4]], x0=[1], v0=[0]).C[0, 0]]]

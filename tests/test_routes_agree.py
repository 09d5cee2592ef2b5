"""Sylvester's matrix functions (the seed's Example 1 route) agree with the Laplace route."""

from __future__ import annotations

import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.exact.sylvester import cos_sqrt, expm, first_order_matrix, sinc_sqrt
from laplace_springs.numeric.mp_expr import numeric_value


@pytest.mark.parametrize("name", ["vertical-pair", "wall-pair"])
def test_undamped_psi_phi_equal_laplace_solution(name):
    scene = ls.load_scene(name)
    A, _ = scene.normalized()
    sylvester = cos_sqrt(A, ls.t) * scene.x0 + sinc_sqrt(A, ls.t) * scene.v0
    laplace = ls.solve(scene).x
    difference = (sylvester - laplace).applyfunc(lambda e: sp.simplify(sp.expand(e)))
    assert difference == sp.zeros(scene.n, 1)


@pytest.mark.parametrize("name", ["vertical-pair-damped", "wall-pair-dashpot"])
def test_first_order_exponential_equals_laplace_solution(name):
    scene = ls.load_scene(name)
    A, B = scene.normalized()
    y = expm(first_order_matrix(A, B), ls.t) * sp.Matrix([*scene.x0, *scene.v0])
    laplace = ls.solve(scene).x
    for tv in ("0.3", "2.9", "13.5"):
        for i in range(scene.n):
            gap = (y[i] - laplace[i]).subs(ls.t, sp.Rational(tv))
            assert abs(numeric_value(gap, 30)) < 1e-25

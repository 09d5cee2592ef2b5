"""The one first-order builder against an independent construction, and the float backend
against the exact one."""

from __future__ import annotations

from fractions import Fraction

import mpmath
import numpy as np
import pytest
import sympy as sp

from laplace_springs import Scene
from laplace_springs.bench.reference import reference_system
from laplace_springs.kernels.dd import dd_add, dd_mul, from_exact, phase, two_prod, two_sum
from laplace_springs.kernels.first_order import FLOAT, SYMPY, first_order, massless_nodes
from laplace_springs.numeric.first_order import first_order_system


def random_scene(seed: int) -> Scene:
    """A random symmetric network with some massless nodes held by dashpots."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 6))
    light = set(rng.choice(n, size=int(rng.integers(0, n - 1)), replace=False).tolist())
    M = sp.diag(*[0 if i in light else sp.Rational(int(rng.integers(1, 9)), 4) for i in range(n)])
    K, C = sp.zeros(n, n), sp.zeros(n, n)
    for i in range(n):
        K[i, i] += sp.Rational(int(rng.integers(1, 9)), 2)
        C[i, i] += sp.Rational(int(rng.integers(1, 5)), 8)
        for j in range(i + 1, n):
            if rng.random() < 0.6:
                k, c = sp.Rational(int(rng.integers(1, 9)), 3), sp.Rational(int(rng.integers(0, 3)), 5)
                K[i, i] += k; K[j, j] += k; K[i, j] -= k; K[j, i] -= k  # noqa: E702
                C[i, i] += c; C[j, j] += c; C[i, j] -= c; C[j, i] -= c  # noqa: E702
    x0 = [sp.Rational(int(rng.integers(-4, 5)), 3) for _ in range(n)]
    v0 = [sp.Rational(int(rng.integers(-4, 5)), 7) for _ in range(n)]
    return Scene.from_matrices(M=M, C=C, K=K, x0=x0, v0=v0)


@pytest.mark.parametrize("seed", range(8))
def test_the_builder_agrees_with_the_independent_reference(seed):
    scene = random_scene(seed)
    Z, y0, massive = first_order_system(scene)
    Zr, y0r = reference_system(scene)
    assert Zr == Z and y0 == y0r
    assert massive == [i for i in range(scene.n) if scene.M[i, i] != 0]


@pytest.mark.parametrize("seed", range(4))
def test_float_backend_rounds_the_exact_matrix(seed):
    scene = random_scene(seed)
    exact, _, _ = first_order_system(scene)
    arrays = [np.array(sp.Matrix(a), dtype=float) for a in (scene.M, scene.C, scene.K)]
    Z, y0, _ = first_order(*arrays, [float(v) for v in scene.x0], [float(v) for v in scene.v0],
                           FLOAT)
    assert np.max(np.abs(Z - np.array(exact, dtype=float))) <= 1e-13 * max(1.0, np.max(np.abs(Z)))


def test_massless_nodes_and_a_singular_dashpot_block():
    assert massless_nodes([(0, 0), (0, 2), (2, 0)], 4) == [1, 3]
    with pytest.raises(ValueError):  # a massless node held by no dashpot: no first-order form
        first_order(sp.diag(1, 0), sp.zeros(2, 2), sp.Matrix([[2, -1], [-1, 1]]), [0, 0], [0, 0],
                    SYMPY)


def test_double_double_operations_are_error_free_where_they_claim():
    rng = np.random.default_rng(3)
    for a, b in rng.normal(size=(200, 2)) * 10.0 ** rng.integers(-20, 20, size=(200, 2)):
        s, e = two_sum(float(a), float(b))
        assert Fraction(s) + Fraction(e) == Fraction(float(a)) + Fraction(float(b))
        p, e = two_prod(float(a), float(b))
        assert Fraction(p) + Fraction(e) == Fraction(float(a)) * Fraction(float(b))
    third, seventh = from_exact(Fraction(1, 3)), from_exact(Fraction(1, 7))
    total = dd_add(*third, *seventh)
    product = dd_mul(*third, *seventh)
    assert abs(Fraction(total[0]) + Fraction(total[1]) - Fraction(10, 21)) < Fraction(1, 10**31)
    assert abs(Fraction(product[0]) + Fraction(product[1]) - Fraction(1, 21)) < Fraction(1, 10**32)


def test_phase_in_double_double_matches_mpmath_at_huge_times():
    omega = from_exact(sp.Rational(7, 3))
    times = np.array([1e6, 123456789.25, 1e15])
    c, s, _ = phase(omega[0], omega[1], times, np.zeros(3))
    with mpmath.workdps(60):
        for k, t in enumerate(times):
            angle = mpmath.mpf(7) / 3 * mpmath.mpf(float(t))
            assert abs(c[k] - float(mpmath.cos(angle))) < 4e-16
            assert abs(s[k] - float(mpmath.sin(angle))) < 4e-16

"""The tiny engine's basis from the modes of classically damped scenes
(numeric/tiny_modes.py) against python-flint's certified arb matrix exponential
(``reference_motion_arb``: its own first-order matrix, no modes or eigenvectors).

Every entry's error must be within its bound; the scenes are those the modal basis is
for (repeated and near-repeated frequencies, critical and near-critical modes, rigid-body
modes, Rayleigh damping), where the eigenvectors of the 2n x 2n matrix are nearly
parallel, and the bound must meet the target where the eigenvector basis missed it.
"""

from __future__ import annotations

import random
from fractions import Fraction

import numpy as np
import pytest

from laplace_springs import Scene, solve
from laplace_springs.bench.reference import reference_motion_arb
from laplace_springs.numeric import tiny_blocks
from laplace_springs.numeric.times import as_times
from laplace_springs.numeric.tiny import tiny_data, tiny_motion
from laplace_springs.numeric.tiny_blocks import BlockMotion
from laplace_springs.numeric.tiny_modes import classical_modes

TARGET = 1e-13


def _scene(M, C, K, x0, v0) -> Scene:
    text = [[str(v) for v in row] for row in M], [[str(v) for v in row] for row in C], \
        [[str(v) for v in row] for row in K]
    return Scene.from_matrices(M=text[0], C=text[1], K=text[2], x0=[str(v) for v in x0],
                               v0=[str(v) for v in v0])


def _critical_pair(p: int, q: int, mass: Fraction, detune: Fraction = Fraction(0)) -> Scene:
    """Two equal masses whose two modes (ω = p, q) are both critically damped (C = αM + βK
    with α + βω² = 2ω for both), α detuned by the factor 1 + detune."""
    a, b = Fraction(p * p + q * q, 2), Fraction(q * q - p * p, 2)
    K = [[a * mass, -b * mass], [-b * mass, a * mass]]
    beta, alpha = Fraction(2, p + q), Fraction(2 * p * q, p + q) * (1 + detune)
    C = [[alpha * mass + beta * K[0][0], beta * K[0][1]], [beta * K[1][0], alpha * mass + beta * K[1][1]]]
    return _scene([[mass, 0], [0, mass]], C, K, [1, 0], [0, 1])


def _ring(n: int, damping: str) -> Scene:
    """n equal masses on a ring of equal springs, each also held by a spring to a wall: each
    frequency but the lowest repeated."""
    K = [[3 if i == j else -1 if abs(i - j) in (1, n - 1) else 0 for j in range(n)] for i in range(n)]
    eye = [[int(i == j) for j in range(n)] for i in range(n)]
    C = [[damping if i == j else 0 for j in range(n)] for i in range(n)]
    return _scene(eye, C, K, [1] + [0] * (n - 1), [0] * (n - 1) + [1])


SCENES = {
    "critical pair": _critical_pair(1, 2, Fraction(3, 2)),
    "near-critical pair": _critical_pair(2, 3, Fraction(1), Fraction(1, 10**9)),
    "ring of three, damped": _ring(3, "1/10"),
    "ring of four, undamped": _ring(4, "0"),
    "free-free chain": _scene([[1, 0, 0], [0, 2, 0], [0, 0, 1]], [[0] * 3] * 3,
                              [[1, -1, 0], [-1, 2, -1], [0, -1, 1]], [1, 0, 0], [0, 0, "1/3"]),
    "Rayleigh chain": _scene([[2, 0, 0, 0], [0, Fraction(1, 3), 0, 0], [0, 0, 1, 0], [0, 0, 0, 5]],
                             [[Fraction(1, 10) * 2 + Fraction(1, 50) * 3, -Fraction(1, 50), 0, 0],
                              [-Fraction(1, 50), Fraction(1, 30) + Fraction(1, 50) * 2, -Fraction(1, 50), 0],
                              [0, -Fraction(1, 50), Fraction(1, 10) + Fraction(1, 50) * 2, -Fraction(1, 50)],
                              [0, 0, -Fraction(1, 50), Fraction(1, 2) + Fraction(1, 50) * 3]],
                             [[3, -1, 0, 0], [-1, 2, -1, 0], [0, -1, 2, -1], [0, 0, -1, 3]],
                             [1, 0, -1, 0], [0, 2, 0, 0]),
}


@pytest.mark.parametrize("name", sorted(SCENES))
def test_modal_basis_values_are_within_their_bounds(name: str, monkeypatch) -> None:
    # every classical scene takes the modes' basis (by default only where the eigenvectors
    # are far from orthogonal)
    monkeypatch.setattr(tiny_blocks, "_MODAL_CONDITION", 0.0)
    scene = SCENES[name]
    data = tiny_data(scene)
    A, B = data.normalized()
    assert classical_modes(data.n, data.M, data.K, data.C, data.normalized_floats, (A, B)) \
        is not None
    rng = random.Random(name)
    times = sorted({0.0, 1e-3, *(rng.uniform(0, 60) for _ in range(6)), 60.0})
    values, bounds = tiny_motion(scene).evaluate(as_times(times), 0)
    reference = np.array(reference_motion_arb(scene, times, digits=40), dtype=float)
    error = np.abs(values - reference)
    assert (error <= bounds).all(), (error / bounds).max()
    scale = np.abs(reference).max()
    # informative (not a bound of the whole scale): the free-free chain's rigid-body mode
    # grows its bound like t³ (2e-10 at t = 60), the others stay below 1e-12
    assert bounds.max() <= (1e-9 if name == "free-free chain" else 1e-12) * scale


@pytest.mark.parametrize("name", ["critical pair", "near-critical pair", "free-free chain"])
def test_modal_basis_meets_the_target_and_solve_uses_it(name: str) -> None:
    scene = SCENES[name]
    times = np.linspace(0.0, 30.0, 41)
    solution = solve(scene)
    values, bounds = solution.evaluate(times, return_error=True)
    reference = np.array(reference_motion_arb(scene, times.tolist(), digits=40), dtype=float)
    assert solution.method == "tiny"
    assert tiny_motion(scene).form.basis == "modes"  # its eigenvectors are nearly parallel
    assert (np.abs(values - reference) <= bounds).all()
    assert bounds.max() <= TARGET * max(1.0, np.abs(reference).max())


def test_modal_bound_is_tighter_than_the_eigenvector_basis_on_a_critical_pair() -> None:
    """Both modes critical: the eigenvector basis needs two SVD-built blocks; the modes give
    them directly, and the bound over [0, 100] is no larger (it was 4.2e-14 against
    3.0e-14 when this was written)."""
    data = tiny_data(_critical_pair(1, 2, Fraction(1)))
    A, B = data.normalized()
    floats = data.normalized_floats
    modes = classical_modes(data.n, data.M, data.K, data.C, floats, (A, B))
    modal = BlockMotion(data.n, A, B, data.x0, data.v0, floats=floats, modes=lambda: modes)
    eig = BlockMotion(data.n, A, B, data.x0, data.v0, floats=floats)
    assert len(modal.doubles) == 2 and modal.basis == "modes" and eig.basis == "eigenvectors"
    assert modal.bound_until(100.0) <= eig.bound_until(100.0)


@pytest.mark.parametrize("M, C, K", [
    ([[1, 0], [0, 1]], [[1, 0], [0, 0]], [[2, -1], [-1, 1]]),   # a dashpot on one mass
    ([[1, 0], [0, 2]], [[1, 0], [0, 1]], [[2, -1], [-1, 1]]),   # C = I but M ≠ I
    ([[2, 1], [1, 2]], [[0, 0], [0, 0]], [[2, -1], [-1, 1]]),   # M not diagonal
    ([[1, 0], [0, 1]], [[0, 0], [0, 0]], [[2, -1], [0, 1]]),    # K not symmetric
])
def test_scenes_that_are_not_classical_take_the_eigenvector_basis(M, C, K) -> None:
    data = tiny_data(_scene(M, C, K, [1, 0], [0, 0]))
    A, B = data.normalized()
    assert classical_modes(data.n, data.M, data.K, data.C, data.normalized_floats, (A, B)) is None


def test_proportional_damping_with_unequal_masses_is_classical() -> None:
    """C = αM + βK with unequal masses: classical, though C is not a multiple of I."""
    M, K = [[1, 0], [0, 3]], [[5, -2], [-2, 2]]
    C = [[Fraction(1, 5) * M[i][j] + Fraction(1, 7) * K[i][j] for j in range(2)] for i in range(2)]
    data = tiny_data(_scene(M, C, K, [1, 0], [0, 0]))
    A, B = data.normalized()
    modes = classical_modes(data.n, data.M, data.K, data.C, data.normalized_floats, (A, B))
    assert modes is not None
    # the generalized eigenvalues of (K, M): det(K − λM) = 3λ² − 17λ + 6
    roots = sorted(np.roots([3.0, -17.0, 6.0]).tolist())
    assert sorted(modes.stiffness) == pytest.approx(roots, rel=1e-14)

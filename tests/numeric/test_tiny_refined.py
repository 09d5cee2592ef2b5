"""The tiny engine's long horizons (numeric/tiny_refined.py) against independent references.

References: the textbook modal closed form of a two-mass chain with damping proportional
to M, written here in mpmath at 40 digits; and python-flint's certified arb matrix
exponential of the first-order system (``reference_motion_arb``) for a dashpot on one
mass and a ring of four (repeated frequencies). Every entry's error must be within its
bound, the bounds must meet the contract's target, and the planner must keep every time
on the tiny engine (before the refined evaluation, the late times went to the certified
engine).
"""

from __future__ import annotations

from fractions import Fraction

import mpmath
import numpy as np
import pytest

from laplace_springs import Scene, solve
from laplace_springs.bench.reference import reference_motion_arb
from laplace_springs.numeric.times import as_times
from laplace_springs.numeric.tiny import tiny_motion

TARGET = 1e-13


def _chain_reference(eps: str, times: list, order: int = 0) -> list[list]:
    """x^(order) of x'' + εx' + [[2, −1], [−1, 2]]x = 0, x(0) = (1, 0), x'(0) = 0: the
    modes (1, 1)/√2 and (1, −1)/√2 with ω² = 1 and 3, each q = e^{−εt/2}(cos ω_d t +
    ε/(2ω_d) sin ω_d t), ω_d = √(ω² − ε²/4); q' = −(ω²/ω_d)e^{−εt/2} sin ω_d t and
    q'' = −εq' − ω²q (the textbook forms)."""
    with mpmath.workdps(40):
        e = mpmath.mpf(Fraction(eps).numerator) / Fraction(eps).denominator

        def q(omega2: int, t: mpmath.mpf) -> mpmath.mpf:
            wd = mpmath.sqrt(omega2 - e * e / 4)
            decay = mpmath.exp(-e * t / 2)
            value = decay * (mpmath.cos(wd * t) + e / (2 * wd) * mpmath.sin(wd * t))
            slope = -omega2 / wd * decay * mpmath.sin(wd * t)
            return (value, slope, -e * slope - omega2 * value)[order]

        rows: list[list] = [[], []]
        for time in times:
            t = mpmath.mpf(time)
            a, b = q(1, t), q(3, t)
            rows[0].append((a + b) / 2)
            rows[1].append((a - b) / 2)
        return rows


def _check(values: np.ndarray, bounds: np.ndarray, reference: list, floor: float) -> None:
    for i, row in enumerate(reference):
        for col, exact in enumerate(row):
            error = abs(float(mpmath.mpf(values[i, col]) - exact))
            assert error <= bounds[i, col], (i, col, error, bounds[i, col])
            assert bounds[i, col] <= TARGET * floor, (i, col, bounds[i, col] / floor)


@pytest.mark.parametrize("eps", ["0", "1/1000000", "1/1000"])
def test_light_damping_chain_over_long_horizons(eps: str) -> None:
    scene = Scene.from_matrices(M=[[1, 0], [0, 1]], C=[[eps, 0], [0, eps]],
                                K=[[2, -1], [-1, 2]], x0=[1, 0], v0=[0, 0])
    times = [0.0, 3.0, 97.25, 1234.5, 10_000.0, 54_321.0, 100_000.0]
    sol = solve(scene)
    assert sol.method == "tiny"
    values, bounds, report = sol.evaluate(times, return_error=True, return_report=True)
    assert set(report.engines) == {"tiny"}
    _check(values, bounds, _chain_reference(eps, times), sol._floor(0))


@pytest.mark.parametrize("order", [1, 2])
def test_derivatives_over_long_horizons(order: int) -> None:
    scene = Scene.from_matrices(M=[[1, 0], [0, 1]], C=[["1/1000000", 0], [0, "1/1000000"]],
                                K=[[2, -1], [-1, 2]], x0=[1, 0], v0=[0, 0])
    times = [0.0, 3.0, 1234.5, 10_000.0, 54_321.0]
    sol = solve(scene)
    values, bounds, report = sol.evaluate(times, return_error=True, return_report=True,
                                          derivative=order)
    assert set(report.engines) == {"tiny"}
    _check(values, bounds, _chain_reference("1/1000000", times, order), sol._floor(order))


def test_decimal_times_keep_their_low_parts() -> None:
    """"12345.678" is not a float64 number: the phase is taken at the decimal, and a
    value taken at the float alone would be off by about |ω|·u·t ≈ 3e-12 of it."""
    scene = Scene.from_matrices(M=[[1, 0], [0, 1]], K=[[2, -1], [-1, 2]], x0=[1, 0], v0=[0, 0])
    times = ["12345.678", "98765.4321"]
    sol = solve(scene)
    values, bounds, report = sol.evaluate(times, return_error=True, return_report=True)
    assert set(report.engines) == {"tiny"}
    with mpmath.workdps(40):
        reference = _chain_reference("0", [mpmath.mpf(t) for t in times])
    _check(values, bounds, reference, sol._floor(0))


@pytest.mark.parametrize("name, M, C, K, x0, v0, last", [
    ("dashpot on one mass", [[1, 0], [0, 2]], [["1/100000", 0], [0, 0]],
     [[4, -3], [-3, 5]], [1, 0], [0, 1], 20_000.0),
    ("ring of four", np.eye(4, dtype=int).tolist(), [[0] * 4] * 4,
     [[3, -1, 0, -1], [-1, 3, -1, 0], [0, -1, 3, -1], [-1, 0, -1, 3]],
     [1, 0, 0, 0], [0, 0, 1, 0], 100.0),
])
def test_against_arb_matrix_exponential(name: str, M: list, C: list, K: list, x0: list,
                                        v0: list, last: float) -> None:
    scene = Scene.from_matrices(M=M, C=C, K=K, x0=x0, v0=v0)
    times = [0.0, last / 7, last / 3, last * 0.61803, last]
    sol = solve(scene)
    values, bounds, report = sol.evaluate(times, return_error=True, return_report=True)
    assert set(report.engines) == {"tiny"}, name
    reference = reference_motion_arb(scene, [mpmath.mpf(t) for t in times], 40)
    rows = [[reference[i, j] for j in range(len(times))] for i in range(scene.n)]
    _check(values, bounds, rows, sol._floor(0))


def test_a_time_does_not_depend_on_the_others() -> None:
    """The refined evaluation starts at a constant of the scene: a time's value and bound
    are the same alone as among later times (which make the refined evaluation run)."""
    scene = Scene.from_matrices(M=[[1, 0], [0, 1]], C=[["1/1000000", 0], [0, 0]],
                                K=[[2, -1], [-1, 2]], x0=[1, 0], v0=[0, 1])
    motion = tiny_motion(scene)
    motion.evaluate(as_times([90_000.0]), 0)
    low, high = motion.form._switch  # the ends of the switch's bisection: times between
    assert 0 < low < high < 90_000.0  # them are judged one by one
    many = [0.5, 7.0, *np.linspace(low, high, 6).tolist(), 250.0, 5000.0, 90_000.0]
    together = tiny_motion(scene).evaluate(as_times(many), 0)
    for col, t in enumerate(many):
        alone = tiny_motion(Scene.from_matrices(
            M=[[1, 0], [0, 1]], C=[["1/1000000", 0], [0, 0]], K=[[2, -1], [-1, 2]],
            x0=[1, 0], v0=[0, 1])).evaluate(as_times([t]), 0)
        assert np.array_equal(alone[0][:, 0], together[0][:, col])
        assert np.array_equal(alone[1][:, 0], together[1][:, col])


def test_bound_until_covers_every_bound() -> None:
    scene = Scene.from_matrices(M=[[1, 0], [0, 3]], C=[["1/10000000", 0], [0, 0]],
                                K=[[5, -2], [-2, 2]], x0=[0, 1], v0=[1, 0])
    motion = tiny_motion(scene)
    t = np.linspace(0.0, 50_000.0, 2001)
    bounds = motion.evaluate(as_times(t), 0)[1]
    assert float(bounds.max()) <= motion.bound_until(50_000.0)
    assert motion.bound_until(50_000.0) < 1e-13 * 2  # and the bound is still useful


def test_integer_entries_beyond_two_to_the_53_are_held_exactly() -> None:
    """K = 10⁴⁰·[[1, −1], [−1, 3]]: 10⁴⁰ is an integer but not a float64 number. The
    first-order matrix took it as exact (no low part), so the refined eigenvalues were off
    by u·|λ| and the late times' bounds were 300 to 60,000 times below the errors.
    Reference: the modes of [[1, −1], [−1, 3]] (mpmath's symmetric eigensolver at 60
    digits) and x = Σ φ_j φ_jᵀ x0 cos(ω_j t)."""
    scene = Scene.from_matrices(M=[[1, 0], [0, 1]], K=[["1e40", "-1e40"], ["-1e40", "3e40"]],
                                x0=[1, 0], v0=[0, 0])
    times = [1e-17, 3e-15, 1e-12]
    values, bounds = tiny_motion(scene).evaluate(as_times(times), 0)
    with mpmath.workdps(60):
        E, Q = mpmath.eigsy(mpmath.matrix([[1, -1], [-1, 3]]))
        for col, t in enumerate(times):
            for i in range(2):
                exact = sum(Q[i, j] * Q[0, j] * mpmath.cos(mpmath.sqrt(E[j] * mpmath.mpf(10) ** 40)
                                                             * mpmath.mpf(t)) for j in range(2))
                error = abs(float(exact - mpmath.mpf(values[i, col])))
                assert error <= bounds[i, col], (t, i, error, bounds[i, col])


def test_far_times_of_a_damped_scene_are_zero_with_a_bound() -> None:
    """At t = 10²⁴ the exponent a·t ≈ −10²², held as p + e with |e| up to u|p| ≈ 10⁶:
    e^p·e^e was 0·inf = NaN (an infinite bound, escalated, beyond what ``bound_until``
    promised). The motion has decayed far below float64's range: 0, within the bound's
    floor 1e-300·(1 + t)."""
    scene = Scene.from_matrices(M=[[1, 0], [0, 1]], C=[["1/10", 0], [0, 0]],
                                K=[[2, -1], [-1, 2]], x0=[1, 0], v0=[0, 1])
    motion = tiny_motion(scene)
    times = [1e20, 3.3e22, 1e24]
    values, bounds = motion.evaluate(as_times(times), 0)
    assert np.all(values == 0)
    assert np.all(bounds <= 1e-300 * (1 + np.array(times)) * 10)
    assert np.all(bounds <= motion.bound_until(1e24))

"""The krylov engine's long Bessel steps against python-flint's arb matrix exponential of
the exact first-order system (no code of the package in the reference)."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from flint import arb_mat, ctx, fmpq

from laplace_springs import Scene
from laplace_springs.numeric.krylov import krylov_motion
from laplace_springs.numeric.krylov_bessel import BesselMotion


def _mesh(n: int = 16) -> dict[str, list[list[object]]]:
    """A ring of n masses (1 or 2) with chords, springs 1-3, two springs to the wall,
    Rayleigh-like damping K/400 + M/200 and one dashpot 1/5 to the wall (not classical)."""
    M = [[0] * n for _ in range(n)]
    K = [[Fraction(0)] * n for _ in range(n)]
    for i in range(n):
        M[i][i] = 1 + i % 2
    springs = [(i, (i + 1) % n, 1 + i % 3) for i in range(n)] + [(i, (i + 5) % n, 2) for i in range(0, n, 3)]
    for i, j, k in springs:
        K[i][i] += k
        K[j][j] += k
        K[i][j] -= k
        K[j][i] -= k
    K[0][0] += 3
    K[n // 2][n // 2] += 1
    C = [[K[i][j] / 400 + (Fraction(M[i][j], 200) if i == j else 0) for j in range(n)] for i in range(n)]
    C[3][3] += Fraction(1, 5)
    text = [[str(v) for v in row] for row in C]
    return {"M": M, "K": [[str(v) for v in row] for row in K], "C": text}


def _reference(matrices: dict[str, list[list[object]]], x0: list[object], v0: list[object],
               times: list[float]) -> np.ndarray:
    """(x, v) at the times from arb's exp(tA), A = [[0, I], [−M⁻¹K, −M⁻¹C]] exact."""
    n = len(x0)
    q = [[Fraction(str(v)) for v in row] for row in matrices["K"]]
    c = [[Fraction(str(v)) for v in row] for row in matrices["C"]]
    m = [Fraction(str(matrices["M"][i][i])) for i in range(n)]
    A = [[Fraction(0)] * (2 * n) for _ in range(2 * n)]
    for i in range(n):
        A[i][n + i] = Fraction(1)
        for j in range(n):
            A[n + i][j] = -q[i][j] / m[i]
            A[n + i][n + j] = -c[i][j] / m[i]
    z0 = [Fraction(str(v)) for v in list(x0) + list(v0)]
    saved = ctx.prec
    ctx.prec = 200
    try:
        Aa = arb_mat([[fmpq(v.numerator, v.denominator) for v in row] for row in A])
        za = arb_mat([[fmpq(v.numerator, v.denominator)] for v in z0])
        out = []
        for t in times:
            tq = Fraction(t)
            z = (Aa * fmpq(tq.numerator, tq.denominator)).exp() * za
            out.append([float(z[i, 0].mid()) for i in range(2 * n)])
    finally:
        ctx.prec = saved
    return np.array(out).T


@pytest.fixture(scope="module")
def case() -> tuple[Scene, np.ndarray, np.ndarray, dict[str, list[list[object]]]]:
    matrices = _mesh()
    n = len(matrices["M"])
    x0 = [1] + [0] * (n - 2) + ["-1/3"]
    v0 = [0, "1/2"] + [0] * (n - 2)
    scene = Scene.from_matrices(**matrices, x0=x0, v0=v0)
    times = np.concatenate([np.linspace(0.0, 150.0, 16), [0.001, 7.3, 31.25, 149.9]])
    reference = _reference(matrices, x0, v0, [float(t) for t in times])
    return scene, times, reference, matrices


def test_the_scene_takes_the_bessel_path(case) -> None:
    scene = case[0]
    motion = krylov_motion(scene)
    assert isinstance(motion, BesselMotion)
    assert motion.H * 3 < 150     # several steps up to t = 150


@pytest.mark.parametrize("order", [0, 1])
def test_values_within_their_bounds_against_arb(case, order: int) -> None:
    scene, times, reference, _ = case
    n = scene.n
    values, bounds = krylov_motion(scene).evaluate(times, order)
    exact = reference[:n] if order == 0 else reference[n:]
    error = np.abs(values - exact)
    assert np.all(error <= bounds)
    scale = np.max(np.abs(reference[:n]))
    assert np.max(bounds) < 1e-13 * max(scale, 1) * 10
    assert np.max(error) < 1e-14 * max(scale, 1)


def test_acceleration_within_its_bound_against_arb(case) -> None:
    scene, times, reference, matrices = case
    n = scene.n
    q = np.array([[float(Fraction(v)) for v in row] for row in matrices["K"]])
    c = np.array([[float(Fraction(v)) for v in row] for row in matrices["C"]])
    m = np.array([float(matrices["M"][i][i]) for i in range(n)])
    exact = -(q @ reference[:n] + c @ reference[n:]) / m[:, None]
    values, bounds = krylov_motion(scene).evaluate(times, 2)
    # the float64 reference product itself is off by about 1e-15 of its terms
    slack = 1e-14 * (np.abs(q) @ np.abs(reference[:n]) + np.abs(c) @ np.abs(reference[n:]))
    assert np.all(np.abs(values - exact) <= bounds + slack)


def test_a_time_alone_gives_the_same_bits(case) -> None:
    scene, times, _, _ = case
    motion = krylov_motion(scene)
    values, bounds = motion.evaluate(times)
    for k in (0, 5, len(times) - 1):
        alone, bound = krylov_motion(scene).evaluate(times[k:k + 1])
        assert np.array_equal(alone[:, 0], values[:, k]) and bound[0, 0] == bounds[0, k]


@pytest.mark.parametrize(("a", "c", "H", "times"), [
    (0.25, 0.0, 3.25, [0.0, 0.7, 3.2]),
    (0.28125, 0.015625, 9.0, [0.1, 4.4, 8.9]),
])
def test_coefficients_within_their_bounds_against_mpmath(a: float, c: float, H: float, times) -> None:
    """The values' coefficients (long-double FFT) and the next state's (arb) against
    ε_k e^{−δs} J_k(2s/a) in mpmath at 40 digits."""
    import mpmath

    from laplace_springs.numeric.krylov_bessel import _state_coefficients, kapteyn, value_coefficients

    X = 2 * H / a
    K = next(k for k in range(1, 1000) if X * kapteyn(k, X) * 5 <= 2.0**-62)
    s = np.array(times)
    coef, bound = value_coefficients(s, a, c, X, K)
    with mpmath.workdps(40):
        def exact(t: float, k: int) -> object:
            x = mpmath.mpf(2) * mpmath.mpf(t) / mpmath.mpf(a)
            damp = mpmath.exp(-mpmath.mpf(c) / mpmath.mpf(a) * mpmath.mpf(t))
            return damp * (1 if k == 0 else 2) * mpmath.besselj(k, x)

        for i, t in enumerate(times):
            error = mpmath.sqrt(sum((mpmath.mpf(coef[k, i]) - exact(t, k)) ** 2 for k in range(K + 1)))
            assert error <= bound[i]
        hi, lo, err = _state_coefficients(H, a, c, K)
        for k in range(K + 1):
            assert abs(mpmath.mpf(hi[k]) + mpmath.mpf(lo[k]) - exact(H, k)) <= err[k] + mpmath.mpf(10) ** -38

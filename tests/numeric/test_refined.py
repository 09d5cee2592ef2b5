"""The long-horizon engine (numeric/refined.py) against independent references.

References (none shares code with the engine):

* the analytic modes of a uniform fixed-fixed chain, θ_k = 4 sin²(kπ/(2(n+1))),
  φ_k(j) ∝ sin(jkπ/(n+1)), each mode's textbook solution, in mpmath at 40 digits;
* a 40-digit mpmath eigen-decomposition (``mpmath.eigsy`` on L⁻¹KL⁻ᵀ, M = LLᵀ, with
  C folded in by a generic multiple so that damping inside a repeated eigenvalue of K
  is diagonalised too) and each mode's solution
  q(t) = e^{−ct/2}[q0 cosh(dt) + (q0' + c q0/2) sinh(dt)/d], d = √(c²/4 − θ), in mpmath;
* closed forms: a critically damped mass, (1 + t)e^{−t}.

Each value must lie within its bound, and the bound must meet the contract's 1e-13 of
max(‖x(t)‖∞, S₀) where float64 allows.
"""

from __future__ import annotations

import math
from fractions import Fraction

import mpmath
import numpy as np
import pytest

from laplace_springs import Scene
from laplace_springs.numeric import refined
from laplace_springs.numeric.refined import (
    RefinedMotion,
    refined_cost,
    refined_motion,
    refined_refusal,
)
from laplace_springs.numeric.times import as_times

TARGET = 1e-13


# ----------------------------------------------------------------------------- references


def uniform_chain_reference(n: int, times: list, first: int = 0, dps: int = 40) -> np.ndarray:
    """x(t) of n unit masses between walls, unit springs, x0 = e_{first}, v0 = 0, from the
    analytic modes (textbook: Strang, Introduction to Applied Mathematics, §2.2)."""
    out = np.empty((n, len(times)))
    with mpmath.workdps(dps):
        N = n + 1
        k = range(1, n + 1)
        omega = [2 * mpmath.sin(j * mpmath.pi / (2 * N)) for j in k]
        shape = [[mpmath.sin(i * j * mpmath.pi / N) for j in k] for i in range(1, n + 1)]
        for c, given in enumerate(times):
            t = mpmath.mpf(Fraction(given).numerator) / Fraction(given).denominator
            q = [2 / mpmath.mpf(N) * shape[first][j] * mpmath.cos(omega[j] * t) for j in range(n)]
            for i in range(n):
                out[i, c] = float(mpmath.fsum(shape[i][j] * q[j] for j in range(n)))
    return out


def _mp_matrix(rows: list[list[Fraction]]) -> mpmath.matrix:
    return mpmath.matrix([[mpmath.mpf(v.numerator) / v.denominator for v in row] for row in rows])


def modal_reference(M: list, C: list, K: list, x0: list, v0: list, times: list, order: int = 0,
                    dps: int = 40) -> np.ndarray:
    """d^order x/dt^order of M x'' + C x' + K x = 0 (classical damping) from a 40-digit
    eigen-decomposition (module notes)."""
    F = [[[Fraction(v) for v in row] for row in A] for A in (M, C, K)]
    n = len(x0)
    with mpmath.workdps(dps):
        Mm, Cm, Km = (_mp_matrix(A) for A in F)
        L = mpmath.cholesky(Mm)
        Li = mpmath.inverse(L)
        A = Li * Km * Li.T
        B = Li * Cm * Li.T
        weight = mpmath.mpf("0.7390851332151606416553120876738734040134")  # cos's fixed point
        scale_k = max(abs(A[i, j]) for i in range(n) for j in range(n))
        scale_c = max([abs(B[i, j]) for i in range(n) for j in range(n)] + [mpmath.mpf(0)])
        joint = A + B * (weight * scale_k / scale_c) if scale_c else A
        _, V = mpmath.eigsy((joint + joint.T) / 2)
        Phi = Li.T * V
        x = mpmath.matrix([mpmath.mpf(Fraction(v).numerator) / Fraction(v).denominator for v in x0])
        v = mpmath.matrix([mpmath.mpf(Fraction(w).numerator) / Fraction(w).denominator for w in v0])
        out = np.empty((n, len(times)))
        modes = []
        for j in range(n):
            phi = Phi[:, j]
            theta = (phi.T * Km * phi)[0]
            c = (phi.T * Cm * phi)[0]
            q0, dq0 = (phi.T * Mm * x)[0], (phi.T * Mm * v)[0]
            u = [q0, dq0]
            for _ in range(order):
                u.append(-c * u[-1] - theta * u[-2])
            modes.append((phi, theta, c, u[order], u[order + 1]))
        for col, given in enumerate(times):
            t = mpmath.mpf(Fraction(given).numerator) / Fraction(given).denominator
            total = mpmath.matrix(n, 1)
            for phi, theta, c, a, b in modes:
                h = c / 2
                d = mpmath.sqrt(mpmath.mpc(h * h - theta))
                sinhc = mpmath.sinh(d * t) / d if d != 0 else t
                q = mpmath.exp(-h * t) * (a * mpmath.cosh(d * t) + (b + h * a) * sinhc)
                total += phi * mpmath.re(q)
            for i in range(n):
                out[i, col] = float(total[i])
        return out


def check(values: np.ndarray, bounds: np.ndarray, reference: np.ndarray, scale: np.ndarray | float,
          target: float | None = TARGET) -> None:
    """Values within their bounds (the reference's own rounding, ≤ 1e-40 of the scale, is
    far below); bounds within the target where asked."""
    error = np.abs(values - reference)
    assert np.all(np.isfinite(values)) and not np.any(np.isnan(bounds))
    worst = np.max(error - bounds)
    assert worst <= 0, f"bound below the true error by {worst:.2e} (error {error.max():.2e})"
    if target is not None:
        ratio = np.max(bounds / (target * np.broadcast_to(scale, bounds.shape[1:])))
        assert ratio <= 1, f"bound {bounds.max():.2e} misses the target ({ratio:.2f} x)"


def contract_scale(reference: np.ndarray, x0: list, v0: list, poles: np.ndarray) -> np.ndarray:
    rho = float(np.max(np.abs(poles)))
    s0 = max(abs(float(Fraction(v))) for v in x0)
    if rho > 0:
        s0 += max(abs(float(Fraction(v))) for v in v0) / rho
    return np.maximum(np.max(np.abs(reference), axis=0), s0)


# ----------------------------------------------------------------------------- scenes


def fixed_chain(n: int, first: int = 0) -> Scene:
    masses = {f"m{i}": 1 for i in range(n)}
    springs = {"k0": ("wall", "m0", 1), **{f"k{i}": (f"m{i - 1}", f"m{i}", 1) for i in range(1, n)},
               f"k{n}": (f"m{n - 1}", "wall", 1)}
    x0 = [0] * n
    x0[first] = 1
    return Scene.from_components(masses=masses, springs=springs, x0=x0, v0=[0] * n)


def matrices(scene_M: list, scene_C: list, scene_K: list, x0: list, v0: list) -> Scene:
    text = [[[str(Fraction(v)) for v in row] for row in A] for A in (scene_M, scene_C, scene_K)]
    return Scene.from_matrices(M=text[0], C=text[1], K=text[2], x0=[str(Fraction(v)) for v in x0],
                               v0=[str(Fraction(v)) for v in v0])


def free_chains(count: int, size: int, masses: list, springs: list, a: Fraction, b: Fraction):
    """``count`` identical free–free chains side by side, Rayleigh damping C = aK + bM."""
    n = count * size
    M = [[Fraction(0)] * n for _ in range(n)]
    K = [[Fraction(0)] * n for _ in range(n)]
    for block in range(count):
        o = block * size
        for i in range(size):
            M[o + i][o + i] = Fraction(masses[i])
        for i, k in enumerate(springs):
            for p, q, s in ((o + i, o + i, 1), (o + i + 1, o + i + 1, 1), (o + i, o + i + 1, -1),
                            (o + i + 1, o + i, -1)):
                K[p][q] += s * Fraction(k)
    C = [[a * K[i][j] + (b * M[i][j]) for j in range(n)] for i in range(n)]
    return M, C, K


def motion_of(M, C, K, x0, v0) -> RefinedMotion:
    scene = matrices(M, C, K, x0, v0)
    assert refined_refusal(scene, t_max=1e7, count=1, order=0) is None
    return refined_motion(scene)


# ----------------------------------------------------------------------------- the chain


@pytest.fixture(scope="module")
def chain200() -> RefinedMotion:
    return refined_motion(fixed_chain(200))


def test_chain200_long_horizon_against_the_analytic_modes(chain200):
    """The issue's request: 200 masses, x0 = e1, t = 1e5, 1e6 (and 1e9), to 1e-13."""
    times = [0, 1e5, 1e6, 1e9, "1000000.1"]
    values, bounds = chain200.evaluate(as_times(times), 0)
    reference = uniform_chain_reference(200, [0, 1e5, 1e6, 1e9, Fraction("1000000.1")])
    check(values, bounds, reference, 1.0)
    assert np.max(np.abs(values - reference)) <= 1e-15
    assert chain200.refined.residual <= 1e-29  # refined to the double-double level


def test_chain200_residual_term_is_negligible_at_long_times(chain200):
    """The bound's residual part (∝ t) stays far below the float64 sums at t = 1e9."""
    m = chain200.refined
    assert np.max(m.rho_K) < 1e-28 and m.e0 < 1e-26 and m.theta_low > 2.4e-4
    s = chain200._scalars
    _, _, _, _, supC, supS = refined._closed_forms(s, np.array([1e9]), np.array([0.0]))
    energy = chain200._energy(np.array([1e9]), np.array([0.0]), 0, supC, supS)
    assert energy[0] < 1e-16


def test_chain_interior_start_and_velocities(chain200):
    """x0 = e1: velocities and accelerations against the analytic modes differentiated."""
    n = 200
    times = [3.5, 2e5]
    for order in (1, 2):
        values, bounds = chain200.evaluate(as_times(times), order)
        with mpmath.workdps(40):
            N = n + 1
            out = np.empty((n, len(times)))
            for c, given in enumerate(times):
                t = mpmath.mpf(given)
                q = []
                for j in range(1, n + 1):
                    w = 2 * mpmath.sin(j * mpmath.pi / (2 * N))
                    amp = 2 / mpmath.mpf(N) * mpmath.sin(j * mpmath.pi / N)
                    q.append(amp * (-w * mpmath.sin(w * t) if order == 1 else -w * w * mpmath.cos(w * t)))
                for i in range(1, n + 1):
                    out[i - 1, c] = float(mpmath.fsum(mpmath.sin(i * j * mpmath.pi / N) * q[j - 1]
                                                      for j in range(1, n + 1)))
        check(values, bounds, out, np.maximum(np.max(np.abs(out), axis=0), 1.0))


def test_values_do_not_depend_on_the_other_times(chain200):
    times = [0.25, 17.0, 1e6, 3e8, 12345.678]
    batch, batch_bounds = chain200.evaluate(as_times(times), 0)
    for k, t in enumerate(times):
        alone, alone_bounds = chain200.evaluate(as_times([t]), 0)
        assert np.array_equal(alone[:, 0], batch[:, k])
        assert np.array_equal(alone_bounds[:, 0], batch_bounds[:, k])


def test_exact_decimal_times_are_used_exactly():
    """t = "1000000.1" (not the float 1000000.1): the phase at ω = 2 sees the difference."""
    motion = refined_motion(Scene.from_matrices(M=[[1]], K=[[4]], x0=[1], v0=[0]))
    values, bounds = motion.evaluate(as_times(["1000000.1", 1000000.1]), 0)
    with mpmath.workdps(40):
        exact = float(mpmath.cos(2 * mpmath.mpf("1000000.1")))
        floated = float(mpmath.cos(2 * mpmath.mpf(1000000.1)))
    assert abs(values[0, 0] - exact) <= bounds[0, 0] <= 2e-15
    assert abs(values[0, 1] - floated) <= bounds[0, 1] <= 2e-15
    assert abs(exact - floated) > 1e-11


# ----------------------------------------------------------------------------- repeated eigenvalues


def test_two_identical_free_free_chains_to_1e9():
    """Two identical free–free 9-mass chains (18 coordinates): rigid modes θ = 0 (one
    drifts, q = a + b·t) and every eigenvalue twice; light Rayleigh damping, so the waves
    live to t = 1e7. The rigid modes are the exact null vectors of K: no residual."""
    masses = [1, 2, 1, 3, 1, 2, 1, 2, 1]
    springs = [2, 1, 3, 1, 2, 5, 1, 2]
    M, C, K = free_chains(2, 9, masses, springs, Fraction(1, 10**8), Fraction(0))
    x0 = [Fraction(1, 2), 0, 0, Fraction(-1, 3), 0, 0, 0, 0, 1] + [0, 1, 0, 0, 0, 0, 0, 0, Fraction(1, 4)]
    v0 = [0] * 17 + [Fraction(1, 1000)]
    motion = motion_of(M, C, K, x0, v0)
    times = [0, 2.5, 1e4, 1e6, 1e7, 1e9]
    values, bounds = motion.evaluate(as_times(times), 0)
    reference = modal_reference(M, C, K, x0, v0, times)
    check(values, bounds, reference, contract_scale(reference, x0, v0, motion.poles()))
    assert len(motion.refined.th) == 18 and np.count_nonzero(motion.refined.th == 0) == 2
    clusters = sorted(len(c) for c in refined._clusters(motion.refined.th))
    assert clusters == [2] * 9


def test_free_chains_with_mass_proportional_damping_and_derivatives():
    masses = [1, 1, 2, 1]
    springs = [3, 1, 2]
    M, C, K = free_chains(2, 4, masses, springs, Fraction(1, 50), Fraction(1, 20))
    x0 = [1, 0, 0, 0, 0, 0, Fraction(1, 2), 0]
    v0 = [0, 1, 0, 0, 0, 0, 0, -1]
    motion = motion_of(M, C, K, x0, v0)
    times = [0, 0.75, 40.0, 500.0, 1e5]
    for order in (0, 1, 2):
        values, bounds = motion.evaluate(as_times(times), order)
        reference = modal_reference(M, C, K, x0, v0, times, order)
        check(values, bounds, reference, np.maximum(np.max(np.abs(reference), axis=0), 1.0))


def test_damping_that_differs_inside_an_eigenspace():
    """Two identical 3-mass chains with different Rayleigh coefficients: K's eigenvalues
    are double, C separates them (still C M⁻¹K = K M⁻¹C)."""
    _, _, K3 = free_chains(1, 3, [1, 1, 1], [1, 1], Fraction(0), Fraction(0))
    n = 6
    K = [[Fraction(0)] * n for _ in range(n)]
    C = [[Fraction(0)] * n for _ in range(n)]
    for o, (a, b) in ((0, (Fraction(1, 10), Fraction(1, 7))), (3, (Fraction(3, 10), Fraction(1, 100)))):
        for i in range(3):
            for j in range(3):
                K[o + i][o + j] = K3[i][j] + (2 if i == j else 0)
                C[o + i][o + j] = a * K[o + i][o + j] + (b if i == j else 0)
    M = [[Fraction(int(i == j)) for j in range(n)] for i in range(n)]
    x0, v0 = [1, 0, 0, 1, 0, 0], [0, 0, 1, 0, 0, 1]
    motion = motion_of(M, C, K, x0, v0)
    times = [0, 1.0, 10.0, 100.0]
    values, bounds = motion.evaluate(as_times(times), 0)
    reference = modal_reference(M, C, K, x0, v0, times)
    check(values, bounds, reference, contract_scale(reference, x0, v0, motion.poles()))


# ----------------------------------------------------------------------------- random and graded scenes


def _random_scene(rng: np.random.Generator, n: int, dense_mass: bool) -> tuple:
    B = rng.integers(-3, 4, size=(n, n))
    K = (B @ B.T + np.diag(rng.integers(1, 4, size=n))).tolist()
    if dense_mass:
        A = rng.integers(-1, 2, size=(n, n))
        M = (A @ A.T + 3 * np.eye(n, dtype=int)).tolist()
    else:
        M = np.diag(rng.integers(1, 6, size=n)).tolist()
    kind = rng.integers(0, 3)
    a, b = [(Fraction(0), Fraction(0)), (Fraction(1, 20), Fraction(1, 10)), (Fraction(2), Fraction(3))][kind]
    C = [[a * K[i][j] + b * M[i][j] for j in range(n)] for i in range(n)]
    x0 = [Fraction(int(v), 4) for v in rng.integers(-4, 5, size=n)]
    v0 = [Fraction(int(v), 2) for v in rng.integers(-2, 3, size=n)]
    x0[0] = Fraction(1)
    return M, C, K, x0, v0


@pytest.mark.parametrize("seed", range(6))
def test_random_symmetric_scenes_against_mpmath(seed):
    """Random integer K = BBᵀ + D, diagonal or dense M, undamped / light / heavy
    (overdamped modes) Rayleigh damping, t up to 1e6."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 7))
    M, C, K, x0, v0 = _random_scene(rng, n, dense_mass=seed % 2 == 1)
    motion = motion_of(M, C, K, x0, v0)
    times = [0, 0.3, 7.0, 1e3, 1e6]
    for order in (0, 1):
        values, bounds = motion.evaluate(as_times(times), order)
        reference = modal_reference(M, C, K, x0, v0, times, order)
        if order == 0:
            scale = contract_scale(reference, x0, v0, motion.poles())
        else:
            scale = np.maximum(np.max(np.abs(reference), axis=0), 1.0)
        check(values, bounds, reference, scale, target=TARGET if order == 0 else 1e-11)


def test_graded_stiffness_rayleigh_chain():
    """16 masses, springs from 1e-6 to 1e6 (geometric), Rayleigh damping, t = 1e3 and 1e4:
    the case that takes the Chebyshev route 12.5 s and more than 60 s."""
    n = 16
    springs = [Fraction(10) ** (-6 + (12 * i) // n) for i in range(n + 1)]
    K = [[Fraction(0)] * n for _ in range(n)]
    for i, k in enumerate(springs):
        for p, q, s in ((i - 1, i - 1, 1), (i, i, 1), (i - 1, i, -1), (i, i - 1, -1)):
            if 0 <= p < n and 0 <= q < n:
                K[p][q] += s * k
    M = [[Fraction(int(i == j)) for j in range(n)] for i in range(n)]
    a, b = Fraction(1, 10**9), Fraction(1, 10**6)
    C = [[a * K[i][j] + b * M[i][j] for j in range(n)] for i in range(n)]
    x0 = [Fraction(1)] + [Fraction(0)] * (n - 1)
    v0 = [Fraction(0)] * (n - 1) + [Fraction(1, 100)]
    motion = motion_of(M, C, K, x0, v0)
    times = [0, 1.0, 1e3, 1e4]
    values, bounds = motion.evaluate(as_times(times), 0)
    reference = modal_reference(M, C, K, x0, v0, times)
    check(values, bounds, reference, contract_scale(reference, x0, v0, motion.poles()))


def test_critical_and_nearly_critical_masses():
    """x'' + 2x' + x = 0 ((1 + t)e^{−t}), and x'' + (2 − 1e-12)x' + x = 0 (a mode whose
    damped frequency is 1e-6: the entire forms, not sin(βt)/β with a rounded β)."""
    critical = refined_motion(Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[0]))
    times = [0, 0.5, 3.0, 40.0]
    values, bounds = critical.evaluate(as_times(times), 0)
    exact = np.array([(1 + t) * math.exp(-t) for t in times])
    check(values, bounds, exact[None, :], 1.0)
    near = ([[1]], [[Fraction(2) - Fraction(1, 10**12)]], [[1]], [1], [0])
    motion = motion_of(*near)
    values, bounds = motion.evaluate(as_times(times), 0)
    check(values, bounds, modal_reference(*near, times), 1.0)
    over = ([[1]], [[Fraction(2) + Fraction(1, 10**12)]], [[1]], [1], [Fraction(-1, 3)])
    motion = motion_of(*over)
    values, bounds = motion.evaluate(as_times(times), 1)
    check(values, bounds, modal_reference(*over, times, 1), 1.0)


# ----------------------------------------------------------------------------- interface


def test_refusals_name_their_reason(set_limits):
    chain = fixed_chain(5)
    assert refined_refusal(chain, t_max=1e12, count=10**6, order=0) is None
    forced = Scene.from_matrices(M=[[1]], K=[[1]], x0=[1], v0=[0], forcing=["sin(t)"])
    assert refined_refusal(forced, t_max=1, count=1, order=0) == "the scene is forced"
    symbolic = Scene.from_matrices(M=[[1]], K=[["k"]], x0=[1], v0=[0], parameters=["k"])
    assert "rational" in refined_refusal(symbolic, t_max=1, count=1, order=0)
    general = Scene.from_matrices(M=[[1, 0], [0, 1]], C=[[1, 0], [0, 0]], K=[[2, -1], [-1, 2]],
                                  x0=[1, 0], v0=[0, 0])
    assert "not classical" in refined_refusal(general, t_max=1, count=1, order=0)
    assert "Limits.refined_max_order" in refined_refusal(chain, t_max=1, count=1, order=5)
    set_limits(refined_max_coordinates=4)
    assert "Limits.refined_max_coordinates" in refined_refusal(chain, t_max=1, count=1, order=0)
    set_limits(refined_max_coordinates=4000, refined_max_products=10)
    assert "Limits.refined_max_products" in refined_refusal(chain, t_max=1, count=1, order=0)


def test_cost_does_not_depend_on_the_horizon():
    small, large = fixed_chain(10), fixed_chain(40)
    assert refined_cost(small, t_max=1.0, count=10, order=0) == refined_cost(small, t_max=1e9, count=10,
                                                                             order=0)
    assert 0 < refined_cost(small, t_max=1, count=10, order=0) < refined_cost(large, t_max=1, count=10,
                                                                              order=0)
    assert refined_cost(small, t_max=1, count=10, order=0) < refined_cost(small, t_max=1, count=1000,
                                                                          order=0)


def test_poles_are_those_of_the_modes():
    motion = refined_motion(fixed_chain(6))
    poles = np.sort(motion.poles().imag)
    expected = np.sort(np.concatenate([w := 2 * np.sin(np.arange(1, 7) * np.pi / 14), -w]))
    assert np.allclose(poles, expected, rtol=0, atol=1e-15)
    assert np.all(motion.poles().real == 0)


def test_empty_times_and_bad_order():
    motion = refined_motion(fixed_chain(3))
    values, bounds = motion.evaluate(as_times([]), 0)
    assert values.shape == (3, 0) and bounds.shape == (3, 0)
    with pytest.raises(ValueError, match="order must be a non-negative integer"):
        motion.evaluate(as_times([1.0]), -1)


def test_dense_stiffness_by_exact_slices(set_limits):
    """A dense K takes the error-free sliced products (forced here on a small scene by
    narrowing Limits.banded_max_bandwidth): the products against exact rationals, and the
    motion against mpmath (the issue's dense scene: M = I, K = B·Bᵀ + 10·I)."""
    set_limits(banded_max_bandwidth=1)
    rng = np.random.default_rng(5)
    n = 12
    B = rng.integers(-3, 4, size=(n, n))
    K = (B @ B.T + 10 * np.eye(n, dtype=int)).tolist()
    M = np.eye(n, dtype=int).tolist()
    C = np.zeros((n, n), dtype=int).tolist()
    x0, v0 = [1] + [0] * (n - 1), [0] * (n - 1) + [1]
    motion = motion_of(M, C, K, x0, v0)
    exact = refined._exact_data(motion.scene)
    assert isinstance(exact.K, refined._Dense)
    X = rng.standard_normal((n, 2))
    hi, lo = refined._apply(exact.K, X, X * 1e-17)
    for i in range(n):
        for j in range(2):
            value = sum(Fraction(K[i][k]) * (Fraction(X[k, j]) + Fraction(X[k, j] * 1e-17)) for k in range(n))
            size = sum(abs(Fraction(K[i][k]) * Fraction(X[k, j])) for k in range(n))
            assert abs(Fraction(hi[i, j]) + Fraction(lo[i, j]) - value) <= Fraction(2.0**-104) * size
    times = [0, 1.0, 1e4, 1e6]
    values, bounds = motion.evaluate(as_times(times), 0)
    reference = modal_reference(M, C, K, x0, v0, times)
    check(values, bounds, reference, contract_scale(reference, x0, v0, motion.poles()))


def test_free_parts_are_exact_rigid_modes():
    """Indicator vectors of free parts are used as rigid modes only when they are exact,
    M-orthogonal null vectors of K that C keeps apart."""
    chains = matrices(*free_chains(2, 3, [1, 2, 1], [1, 1], Fraction(0), Fraction(1, 10))[:3],
                      [1] * 6, [0] * 6)
    assert [list(c) for c in refined._free_components(chains, refined._exact_data(chains))] == [[0, 1, 2], [3, 4, 5]]
    grounded = fixed_chain(4)
    assert refined._free_components(grounded, refined._exact_data(grounded)) == []
    M, C, K = free_chains(2, 2, [1, 1], [1], Fraction(0), Fraction(0))
    C[1][2] = C[2][1] = Fraction(-1)  # a dashpot between the two parts
    C[1][1] += 1
    C[2][2] += 1
    coupled = matrices(M, C, K, [1, 0, 0, 0], [0] * 4)
    assert refined._free_components(coupled, refined._exact_data(coupled)) == []
    motion = refined_motion(chains)
    values, bounds = motion.evaluate(as_times([1e8]), 0)
    assert np.count_nonzero(motion.refined.rho_K == 0) == 2
    M, C, K = free_chains(2, 3, [1, 2, 1], [1, 1], Fraction(0), Fraction(1, 10))
    reference = modal_reference(M, C, K, [1] * 6, [0] * 6, [1e8])
    check(values, bounds, reference, 1.0)


def test_irrational_initial_data():
    """x0 = √2, v0 = π (not rational): held to 40 digits, x(1e6) = √2 cos 2e6 + π/2 sin 2e6."""
    motion = refined_motion(Scene.from_matrices(M=[[1]], K=[[4]], x0=["sqrt(2)"], v0=["pi"]))
    values, bounds = motion.evaluate(as_times([1e6]), 0)
    with mpmath.workdps(40):
        phase = 2 * mpmath.mpf(10) ** 6
        exact = float(mpmath.sqrt(2) * mpmath.cos(phase) + mpmath.pi / 2 * mpmath.sin(phase))
    assert abs(values[0, 0] - exact) <= bounds[0, 0] <= 1e-14


def test_modal_form_and_modes_for_the_solution_classes():
    """What the route's solution class reads of a motion: modes (θ, c, Φ), the modal form,
    the engine's name, and rigid modes served (has_zero_frequency)."""
    motion = refined_motion(fixed_chain(5))
    assert motion.engine == "refined" and not motion.has_zero_frequency
    theta = np.sort(motion.modes.theta)
    assert np.allclose(theta, 4 * np.sin(np.arange(1, 6) * np.pi / 12) ** 2, rtol=0, atol=1e-15)
    values, _ = motion.evaluate(as_times([0.5, 3.0]), 0)
    assert np.allclose(motion.modal_form()(np.array([0.5, 3.0])), values, rtol=0, atol=1e-14)
    M, C, K = free_chains(1, 3, [1, 2, 1], [1, 1], Fraction(0), Fraction(0))
    assert motion_of(M, C, K, [1, 0, 0], [0, 0, 1]).has_zero_frequency


def test_masses_spread_over_twelve_decades():
    """Masses from 1e-6 to 1e6 on a chain: θ spreads over 1e16, float64's ΦᵀMΦ cannot
    show θ_min > 0, the double-double one can (θ_low > 0: the bound grows like t, not t²)."""
    n = 5
    masses = [Fraction(10) ** e for e in (-6, -3, 0, 3, 6)]
    M = [[masses[i] if i == j else Fraction(0) for j in range(n)] for i in range(n)]
    K = [[Fraction(0)] * n for _ in range(n)]
    for i in range(n + 1):
        for p, q, s in ((i - 1, i - 1, 1), (i, i, 1), (i - 1, i, -1), (i, i - 1, -1)):
            if 0 <= p < n and 0 <= q < n:
                K[p][q] += s
    C = [[Fraction(0)] * n for _ in range(n)]
    x0, v0 = [1, 0, 0, 0, 1], [0, 0, 1, 0, 0]
    motion = motion_of(M, C, K, x0, v0)
    assert motion.refined.theta_low > 0
    times = [0, 1e-4, 1.0, 1e4, 1e6]
    values, bounds = motion.evaluate(as_times(times), 0)
    reference = modal_reference(M, C, K, x0, v0, times)
    check(values, bounds, reference, contract_scale(reference, x0, v0, motion.poles()))

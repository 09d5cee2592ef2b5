"""The Chebyshev route (Rayleigh damping, diagonal M) against independent references.

References: the analytic modes of a uniform fixed-fixed chain (ω_j = 2 sin(jπ/(2(n+1))),
shapes sin(ijπ/(n+1)), each mode's textbook solution; per-mode damping 0.01 + 0.002 ω_j²),
the 40-digit matrix-exponential reference of :mod:`laplace_springs.bench.reference`, and
central differences of it for derivatives. Every bound must cover the true error.
"""

from __future__ import annotations

import sys
from fractions import Fraction
from pathlib import Path

import mpmath
import numpy as np
import pytest

import laplace_springs as ls
from laplace_springs import Scene, SceneError, policy
from laplace_springs.bench.reference import reference_motion
from laplace_springs.numeric import chebyshev
from laplace_springs.numeric.chebyshev import ChebyshevMotion, chebyshev_motion, rayleigh_coefficients
from laplace_springs.numeric.classical import ModalForm, classical_damping
from laplace_springs.planning import Request, SceneFacts, plan

from .test_classical import analytic_chain, chain

FLOAT_REFERENCE = 1e-14  # the float64 analytic reference's own error


def analytic_rows(n: int, rows: list[int], times: np.ndarray, a: float, b: float) -> np.ndarray:
    """Rows of the analytic chain solution (x0 = e1, v0 = 0) without the n x n shapes."""
    j = np.arange(1, n + 1)
    theta = 4 * np.sin(j * np.pi / (2 * (n + 1))) ** 2
    first = np.sqrt(2 / (n + 1)) * np.sin(j * np.pi / (n + 1))
    h = (a * theta + b) / 2
    root = np.sqrt((theta - h**2).astype(complex))
    out = np.empty((len(rows), len(times)))
    for s, t in enumerate(times):
        with np.errstate(invalid="ignore", divide="ignore"):
            sinc = np.where(root != 0, np.sin(root * t) / np.where(root != 0, root, 1), t)
        q = (first * np.exp(-h * t) * (np.cos(root * t) + h * sinc)).real
        for r, i in enumerate(rows):
            out[r, s] = np.sqrt(2 / (n + 1)) * np.sin((i + 1) * j * np.pi / (n + 1)) @ q
    return out


def random_rayleigh(seed: int, *, a=None, b=None) -> Scene:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(4, 8))
    names = [f"m{i}" for i in range(n)]
    masses = {m: str(Fraction(int(rng.integers(1, 9)), int(rng.integers(1, 5)))) for m in names}
    nodes = ["wall", *names, "wall"]
    springs = {f"k{i}": (p, q, str(Fraction(int(rng.integers(1, 40)), 4)))
               for i, (p, q) in enumerate(zip(nodes, nodes[1:]))}
    springs["x"] = (names[0], names[-1], "3/2")  # not a chain: K is not banded
    base = Scene.from_components(masses=masses, springs=springs, x0={names[0]: 1, names[2]: "-1/2"},
                                 v0={names[-1]: "3/4"})
    a = Fraction(int(rng.integers(0, 30)), 100) if a is None else Fraction(a)
    b = Fraction(int(rng.integers(0, 300)), 100) if b is None else Fraction(b)
    return Scene.from_matrices(M=base.M, C=a * base.K + b * base.M, K=base.K, x0=base.x0, v0=base.v0)


def test_rayleigh_detection_is_exact():
    scene = random_rayleigh(0, a="1/7", b="2/3")
    assert [str(v) for v in rayleigh_coefficients(scene)] == ["1/7", "2/3"]
    M, K = scene.M, scene.K
    # classical but not Rayleigh: C = K M⁻¹ K commutes, yet is no combination of K and M
    other = Scene.from_matrices(M=M, C=K * M.inv() * K / 100, K=K, x0=scene.x0, v0=scene.v0)
    assert classical_damping(other) and rayleigh_coefficients(other) is None
    negative = Scene.from_matrices(M=M, C=-K / 10, K=K, x0=scene.x0, v0=scene.v0)
    assert rayleigh_coefficients(negative) is None
    with pytest.raises(SceneError, match="Rayleigh"):
        chebyshev_motion(other)


def _exact_class(M, C, K) -> tuple[bool, bool]:
    """(Rayleigh with a, b ≥ 0, classical) by python-flint matrices, written here: C = aK + bM
    for the a, b solving two entries, and C M⁻¹K symmetric."""
    from flint import fmpq, fmpq_mat
    n = M.shape[0]
    Mq, Cq, Kq = (fmpq_mat(n, n, [fmpq(int(v.p), int(v.q)) for v in A]) for A in (M, C, K))
    P = Cq * Mq.inv() * Kq
    classical = P.transpose() == P and Cq == Cq.transpose() and Kq == Kq.transpose()
    a = Cq[0, 1] / Kq[0, 1]
    b = (Cq[0, 0] - a * Kq[0, 0]) / Mq[0, 0]
    return (Cq == a * Kq + b * Mq and a >= 0 and b >= 0), classical


@pytest.mark.parametrize("change", ["none", "tiny", "dashpot", "commuting"])
def test_large_scenes_are_classed_exactly_whatever_the_float_screens_see(change):
    """Beyond 64 dashpot entries float64 screens may reject a damping class before the
    exact pass: a change of 1e-30 (far below them) must still be found, and a class they
    cannot reject must be confirmed exactly (a 60-mass chain with cross springs)."""
    import sympy as sp
    n = 60
    names = [f"m{i}" for i in range(n)]
    nodes = ["wall", *names, "wall"]
    springs = {f"k{i}": (p, q, str(Fraction(1 + i % 5, 2))) for i, (p, q) in enumerate(zip(nodes, nodes[1:]))}
    springs.update({f"x{i}": (names[i], names[i + 3], "1/3") for i in range(0, n - 3, 2)})
    base = Scene.from_components(masses={m: str(Fraction(1 + i % 3, 2)) for i, m in enumerate(names)},
                                 springs=springs, x0={names[0]: 1}, v0={})
    M, K = base.M, base.K
    C = K / 7 + M * sp.Rational(2, 3)
    if change == "tiny":
        C = C + sp.Rational(1, 10**30) * (sp.eye(n)[:, [3]] * sp.eye(n)[[8], :] + sp.eye(n)[:, [8]] * sp.eye(n)[[3], :])
    elif change == "dashpot":
        C = C + sp.Rational(1, 3) * sp.eye(n)[:, [5]] * sp.eye(n)[[5], :]
    elif change == "commuting":
        C = K * M.inv() * K / 100
    scene = Scene.from_matrices(M=M, C=C, K=K, x0=base.x0, v0=base.v0)
    rayleigh, classical = _exact_class(M, C, K)
    assert (rayleigh_coefficients(scene) is not None) == rayleigh
    assert classical_damping(scene) == classical
    assert (rayleigh, classical) == {"none": (True, True), "tiny": (False, False),
                                     "dashpot": (False, False), "commuting": (False, True)}[change]


@pytest.mark.parametrize("seed", range(5))
@pytest.mark.parametrize("damping", [None, ("0", "0"), ("0", "5")])  # random, undamped, overdamped
def test_random_rayleigh_scenes_match_the_40_digit_reference_within_their_bound(seed, damping):
    scene = random_rayleigh(seed, **({} if damping is None else dict(zip("ab", damping))))
    motion = chebyshev_motion(scene)
    times = [0.0, 0.3, 1.7, 8.0, 25.0]
    reference = reference_motion(scene, times, dps=40)
    values, bounds = motion.values(np.array(times)), motion.bound(np.array(times))
    error = np.abs(values - reference)
    assert np.all(error <= bounds)
    assert error.max() < 1e-12 * max(1.0, np.abs(reference).max())
    step = 1e-5  # x' and x'' by central differences of the reference
    around = reference_motion(scene, [times[2] - step, times[2], times[2] + step], dps=40)
    for order, estimate in ((1, (around[:, 2] - around[:, 0]) / (2 * step)),
                            (2, (around[:, 2] - 2 * around[:, 1] + around[:, 0]) / step**2)):
        derivatives = motion.values(np.array(times), order)
        assert np.max(np.abs(derivatives[:, 2] - estimate)) < 1e-6 * max(1.0, np.abs(estimate).max())
        size = max(1.0, np.abs(derivatives).max())  # pessimistic (∝ t and N³ u) but useful
        assert np.all(motion.bound(np.array(times), order) < 1e-9 * size)


def test_chain_values_and_derivatives_match_the_analytic_modes():
    n = 400
    sol = ls.solve(chain(n))
    assert isinstance(sol.motion, ChebyshevMotion) and "Chebyshev" in sol.reason
    times = np.array([0.0, 0.5, 3.0, 17.0, 60.0, 100.0])
    values, bounds = sol.evaluate(times, return_error=True)
    error = np.abs(values - analytic_chain(n, times, 0.002, 0.01))
    assert error.max() < 1e-12 and np.all(bounds + FLOAT_REFERENCE >= error)
    assert np.max(bounds) < 1e-9  # pessimistic (about N³ u at t = 100) but useful
    # velocity: x'(t) against the analytic x differentiated by a 4th-order difference
    step = 1e-3
    t = np.array([17.0])
    samples = [analytic_chain(n, t + k * step, 0.002, 0.01)[:, 0] for k in (-2, -1, 1, 2)]
    slope = (samples[0] - 8 * samples[1] + 8 * samples[2] - samples[3]) / (12 * step)
    assert np.max(np.abs(sol.evaluate(t, derivative=1)[:, 0] - slope)) < 1e-9


def test_a_value_does_not_depend_on_the_other_times():
    sol = ls.solve(chain(300))
    times = np.array([0.25, 2.0, 40.0])
    together = sol.evaluate(times)
    for k, t in enumerate(times):
        alone = sol.evaluate([t])[:, 0]
        assert np.max(np.abs(alone - together[:, k])) <= 1e-15 * np.max(np.abs(together[:, k])) + 1e-300


def test_poles_modes_and_x_of_a_chebyshev_solution():
    n = 250
    sol = ls.solve(chain(n, a="0", b="1/10"))
    assert isinstance(sol.motion, ChebyshevMotion)
    omega = 2 * np.sin(np.arange(1, n + 1) * np.pi / (2 * (n + 1)))
    root = np.sqrt((0.0025 - omega**2).astype(complex))  # λ² + λ/10 + ω²: the low modes overdamped
    expected = np.sort_complex(np.concatenate([-0.05 + root, -0.05 - root]))
    assert np.max(np.abs(np.sort_complex(sol.poles) - expected)) < 1e-12
    assert isinstance(sol.x, ModalForm)
    reference = analytic_chain(n, np.array([2.5]), 0.0, 0.1)
    assert np.max(np.abs(sol.x(np.array([2.5])) - reference)) < 1e-12


def test_shapes_beyond_their_size_are_refused_with_the_reason(set_limits):
    set_limits(classical_max_coordinates=200)
    sol = ls.solve(chain(250))
    assert sol.evaluate([1.0]).shape == (250, 1)
    with pytest.raises(SceneError, match="Limits.classical_max_coordinates = 200"):
        sol.x


def test_planner_routes_rayleigh_and_refuses_other_large_classical_scenes():
    facts = {"symbolic": False, "forced": False, "rational": True, "first_order": True,
             "classical": True, "diagonal_mass": True, "stiffness_bound": 4.0, "pole_bound": 2.1}
    big = SceneFacts(n=50_000, rayleigh=True, nnz=150_000, **facts)
    assert plan(big, Request()).primary == "chebyshev"
    other = SceneFacts(n=5_000, rayleigh=False, nnz=15_000, **facts)
    refusals = {r.engine: r for r in plan(other, Request(), method="classical").refusals}
    assert "Limits.classical_max_coordinates = 4,000" in refusals["classical"].reason
    assert refusals["classical"].limit == "classical_max_coordinates"
    assert plan(other, Request(), method="classical").chain == ()


def test_ten_thousand_masses():
    n = 10_000
    scene = chain(n)
    times = np.linspace(0, 50, 11)
    values, bounds = ls.solve(scene).evaluate(times, return_error=True)
    rows = [0, 1, n // 2, n - 1]
    error = np.abs(values[rows] - analytic_rows(n, rows, times, 0.002, 0.01))
    assert error.max() < 1e-12 and np.all(bounds[rows] + FLOAT_REFERENCE >= error)


def test_free_free_chain_with_rigid_motion_matches_the_reference():
    # K is singular (λ = 0: F = 1, G = t); the drift v0 makes x grow linearly
    names = [f"m{i}" for i in range(6)]
    springs = {f"k{i}": (p, q, str(i + 1)) for i, (p, q) in enumerate(zip(names, names[1:]))}
    dashpots = {f"c{i}": (p, q, f"{i + 1}/20") for i, (p, q) in enumerate(zip(names, names[1:]))}
    scene = Scene.from_components(masses={m: str(k % 3 + 1) for k, m in enumerate(names)},
                                  springs=springs, dashpots=dashpots, x0={"m0": 1},
                                  v0={"m5": "1/2", "m2": "-1/4"})
    motion = chebyshev_motion(scene)
    times = [0.0, 1.1, 6.0, 30.0]
    reference = reference_motion(scene, times, dps=40)
    values, bounds = motion.values(np.array(times)), motion.bound(np.array(times))
    assert np.all(np.abs(values - reference) <= bounds)
    assert np.max(np.abs(values - reference)) < 1e-12 * np.abs(reference).max()


def test_verify_runs_on_a_scene_beyond_the_dense_size_limit_and_catches_a_wrong_motion():
    """verify() takes its products over the scene's nonzero entries: a 2,000-mass chain
    (twice Limits.general_modal_max_coordinates, where dense float arrays are refused) verifies; the same
    motion checked against a chain with stiffer springs does not."""
    scene = chain(2 * policy.limits().general_modal_max_coordinates)
    sol = ls.solve(scene)
    assert sol.verify()
    stiffer = chain(2 * policy.limits().general_modal_max_coordinates, k=2)
    wrong = type(sol).__new__(type(sol))
    wrong.__dict__.update(sol.__dict__)
    wrong.scene = stiffer  # the motion of the first chain is not one of the stiffer chain
    assert not wrong.verify()


# ----------------------------------------------------------------------------- tight bounds
# (issue 14: the working-precision recurrence and node values, and the tail sums S_j)


def bench_module():
    """benchmarks/bench_scaling.py (the scenes and its double-double Taylor reference)."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
    try:
        import bench_scaling
    finally:
        sys.path.pop(0)
    return bench_scaling


def mp_chain_rows(n: int, rows: list[int], times, a=Fraction(1, 500), b=Fraction(1, 100),
                  dps: int = 40) -> np.ndarray:
    """Rows of the unit chain's motion (x0 = e1, v0 = 0) from its analytic modes in mpmath
    (any damping: the complex √δ gives the overdamped modes too)."""
    with mpmath.workdps(dps):
        pi = mpmath.pi
        scale = mpmath.sqrt(mpmath.mpf(2) / (n + 1))
        modes = []
        for j in range(1, n + 1):
            theta = 4 * mpmath.sin(j * pi / (2 * (n + 1))) ** 2
            h = (mpmath.mpf(a.numerator) / a.denominator * theta + mpmath.mpf(b.numerator) / b.denominator) / 2
            modes.append((j, h, mpmath.sqrt(mpmath.mpc(theta - h * h)), scale * mpmath.sin(j * pi / (n + 1))))
        out = np.empty((len(rows), len(times)))
        for s, time in enumerate(times):
            t = mpmath.mpf(float(time))
            q = [(j, first * mpmath.exp(-h * t) * (mpmath.cos(d * t) + h * mpmath.sin(d * t) / d).real)
                 for j, h, d, first in modes]
            for r, i in enumerate(rows):
                out[r, s] = float(mpmath.fsum(scale * mpmath.sin((i + 1) * j * pi / (n + 1)) * value
                                              for j, value in q))
    return out


CHAIN_TIMES = np.array([0.0, 0.37, 4.1, 17.0, 33.3, 50.0])


@pytest.fixture(scope="module")
def chain_1000():
    n, rows = 1000, [0, 1, 2, 500, 999]
    return n, rows, mp_chain_rows(n, rows, CHAIN_TIMES)


def test_chain_bound_covers_the_40_digit_analytic_error_and_meets_the_target(chain_1000):
    n, rows, reference = chain_1000
    motion = chebyshev_motion(chain(n))
    assert motion.exact_data
    values, bounds = motion.values(CHAIN_TIMES)[rows], motion.bound(CHAIN_TIMES)[rows]
    error = np.abs(values - reference)
    assert np.all(error <= bounds)
    assert np.max(bounds) <= 1e-13 * np.max(np.abs(reference))
    assert np.max(error) > 0  # the comparison sees rounding


def test_a_lowered_degree_is_covered_by_the_truncation_bound(chain_1000, monkeypatch):
    n, rows, reference = chain_1000
    motion = chebyshev_motion(chain(n))
    full = motion._degrees
    monkeypatch.setattr(motion, "_degrees", lambda t, order: np.maximum(16, full(t, order) - 32))
    values, bounds = motion.values(CHAIN_TIMES)[rows], motion.bound(CHAIN_TIMES)[rows]
    error = np.abs(values - reference)
    assert np.max(error) > 1e-9  # a real truncation error ...
    assert np.all(error <= bounds)  # ... and the bound covers it


def test_a_float64_working_precision_is_covered_and_is_what_the_long_double_tightens(chain_1000, monkeypatch):
    n, rows, reference = chain_1000
    tight = np.max(chebyshev_motion(chain(n)).bound(CHAIN_TIMES))
    monkeypatch.setattr(chebyshev, "_WORK", np.float64)
    monkeypatch.setattr(chebyshev, "_UW", chebyshev._U)
    motion = chebyshev_motion(chain(n))
    values, bounds = motion.values(CHAIN_TIMES)[rows], motion.bound(CHAIN_TIMES)[rows]
    assert motion._operator["P_work"].dtype == np.float64
    assert np.all(np.abs(values - reference) <= bounds)
    assert np.max(bounds) > 100 * tight


def test_inexact_float_data_is_accounted_for():
    # masses like 7/3 are not float64 numbers: the operator's rounding enters the bound
    scene = random_rayleigh(3)
    motion = chebyshev_motion(scene)
    assert not motion.exact_data
    times = [0.0, 2.0, 20.0]
    reference = reference_motion(scene, times, dps=40)
    assert np.all(np.abs(motion.values(np.array(times)) - reference) <= motion.bound(np.array(times)))


def test_mesh_bound_covers_the_double_double_reference_and_meets_the_target():
    bench = bench_module()
    spec = bench.scene_spec("mesh-rayleigh", 300)
    times = np.linspace(0.0, 50.0, 11)
    high, low = bench.DoubleDoubleTaylor(spec).motion(times)
    sol = ls.solve(bench.build_scene(spec))
    assert isinstance(sol.motion, ChebyshevMotion)
    values, bounds = sol.evaluate(times, return_error=True)
    error = np.abs((values - high) - low)
    assert np.all(error <= bounds)
    assert np.max(bounds) <= 1e-13 * np.max(np.abs(high))


def test_tail_sums_bound_the_clenshaw_tails():
    # S_j ≥ max |Σ_{k≥j} c_k U_{k−j}(x)| on [−1, 1], checked on a fine grid (plus rounding)
    rng = np.random.default_rng(7)
    coef = rng.standard_normal((40, 3)) * np.exp(-0.1 * np.arange(40))[:, None]
    S = chebyshev._tails(coef, np.abs(coef))
    x = np.cos(np.linspace(0.0, np.pi, 4001))
    for column in range(3):
        b1, b2 = np.zeros_like(x), np.zeros_like(x)
        for j in range(39, -1, -1):  # Clenshaw: b_j = c_j + 2x b_{j+1} − b_{j+2}
            b1, b2 = coef[j, column] + 2 * x * b1 - b2, b1
            assert np.max(np.abs(b1)) <= S[j, column] * (1 + 1e-12)
        crude = np.sum(np.abs(coef[:, column]) * np.arange(1, 41))
        assert S[0, column] < crude


@pytest.mark.parametrize("family", ["chain-rayleigh", "mesh-rayleigh"])
def test_benchmark_scenes_meet_the_target_with_their_own_bound(family):
    """The scaling benchmark's scenes (1,000 masses, 1,000 times on [0, 50]): the bound
    itself is below 1e-13 of max |x| (it was 2e-11 and 8e-10 with the float64 recurrence)."""
    bench = bench_module()
    sol = ls.solve(bench.build_scene(bench.scene_spec(family, 1000)))
    assert isinstance(sol.motion, ChebyshevMotion)
    values, bounds = sol.evaluate(np.linspace(0.0, 50.0, 1000), return_error=True)
    assert np.max(bounds) <= 1e-13 * np.max(np.abs(values))


# -- issue 21: a verified interval, or a refusal -----------------------------------------


def _dense_scene(n: int, seed: int = 0, shift: int | None = None) -> tuple[Scene, np.ndarray]:
    B = np.random.default_rng(seed).integers(-5, 6, size=(n, n))
    K = B @ B.T + (n if shift is None else shift) * np.eye(n, dtype=int)
    scene = Scene.from_matrices(M=np.eye(n, dtype=int).tolist(), K=K.tolist(),
                                x0=[1] + [0] * (n - 1), v0=[0] * n)
    return scene, K


@pytest.mark.parametrize("n", [30, 100])
def test_dense_stiffness_not_diagonally_dominant(n):
    # K = BBᵀ + n·I: Gershgorin reaches far below 0 (to -8,791 for n = 100), where the
    # expansion grew like e^{94} and returned x₁(1) = 2.9e23; the Cholesky proof of K ≻ 0
    # moves the interval's lower end to 0. Reference: scipy.linalg.eigh (K is well
    # conditioned: eigenvalues in [100, 4255] for n = 100).
    import scipy.linalg as sl

    scene, K = _dense_scene(n)
    lo, hi = chebyshev.chebyshev_interval(scene)
    w, V = sl.eigh(K.astype(float))
    assert lo == 0.0 and hi >= w[-1]
    times = np.array([0.5, 1.0, 3.0])
    motion = chebyshev_motion(scene)
    values, bounds = motion.values(times), motion.bound(times)
    ref = V @ (np.cos(np.outer(np.sqrt(w), times)) * V[0][:, None])
    error = np.abs(values - ref)
    assert np.all(error <= bounds), np.max(error / bounds)
    assert np.max(bounds) <= 1e-12


def test_an_indefinite_stiffness_is_declined_past_the_growth_limit():
    # K with a negative eigenvalue (-2): the motion does grow like cosh(√2 t); the interval
    # cannot be proved nonnegative, and past e^{μt} > Limits.chebyshev_max_growth the engine
    # declines; below it the bound still covers the error (40-digit reference)
    scene = Scene.from_matrices(M=[[1, 0], [0, 1]], K=[[1, 3], [3, 1]], x0=[1, 0], v0=[0, 0])
    assert chebyshev.chebyshev_interval(scene)[0] < 0
    assert chebyshev.chebyshev_refusal(scene, t_max=1.0, count=3, order=0) is None
    why = chebyshev.chebyshev_refusal(scene, t_max=10.0, count=3, order=0)
    assert why is not None and "Limits.chebyshev_max_growth" in why
    times = np.array([0.25, 1.0])
    motion = chebyshev_motion(scene)
    with mpmath.workdps(40):   # x'' = −Kx: the exponential of [[0, I], [−K, 0]]·t
        Z = mpmath.matrix([[0, 0, 1, 0], [0, 0, 0, 1], [-1, -3, 0, 0], [-3, -1, 0, 0]])
        ref = np.array([[float((mpmath.expm(Z * mpmath.mpf(t)) * mpmath.matrix([1, 0, 0, 0]))[i])
                         for t in times] for i in range(2)])
    assert np.all(np.abs(motion.values(times) - ref) <= motion.bound(times))


def test_times_beyond_the_vector_memory_get_an_infinite_bound(set_limits):
    # instead of a SceneError from deep inside: the time is not served (the planner's next
    # engine takes it), the others are
    n = 6
    scene = chain(n, a="0", b="0")
    set_limits(chebyshev_max_vector_floats=400)
    motion = chebyshev_motion(scene)
    times = np.array([1.0, 500.0])
    bounds = motion.bound(times)
    assert np.all(np.isfinite(bounds[:, 0])) and np.all(np.isinf(bounds[:, 1]))
    why = chebyshev.chebyshev_refusal(scene, t_max=500.0, count=2, order=0)
    assert why is not None and "Limits.chebyshev_max_vector_floats" in why


def test_cost_and_degree_follow_the_engine():
    scene = chain(40)
    lo, hi = chebyshev.chebyshev_interval(scene)
    a, b = (float(c) for c in rayleigh_coefficients(scene))
    motion = chebyshev_motion(scene)
    for t in (1.0, 10.0, 100.0):
        assert chebyshev.chebyshev_degree(lo, hi, a, b, t) == int(motion._degrees(np.array([t]), 0)[0])
    costs = [chebyshev.chebyshev_cost(scene, t_max=t, count=c, order=0)
             for t, c in ((1.0, 10), (100.0, 10), (100.0, 1000))]
    assert 0 < costs[0] < costs[1] < costs[2]

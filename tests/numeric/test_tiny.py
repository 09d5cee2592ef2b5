"""The tiny engine (numeric/tiny.py, numeric/tiny_blocks.py) against independent references.

One coordinate: the closed form written here in mpmath at 60 digits from the roots of
m s² + c s + k (the textbook formula, nothing of the engine's entire-function form).
Two to four coordinates: python-flint's certified arb matrix exponential of the
first-order system (``reference_motion_arb``: its own first-order matrix, no
eigenvectors); derivatives through the scene whose initial data are (x', x'') or
(x'', x'''), formed here with SymPy. Every entry's error must be within its bound; on the
scenes the engine is built for, the bound must also meet the contract's target.
"""

from __future__ import annotations

import random
from fractions import Fraction

import mpmath
import numpy as np
import pytest
import sympy as sp

from laplace_springs import Scene, solve
from laplace_springs.bench.reference import reference_motion_arb
from laplace_springs.model.errors import SceneError
from laplace_springs.numeric.times import as_times
from laplace_springs.numeric.tiny import tiny_cost, tiny_motion, tiny_refusal

TARGET = 1e-13


# ----------------------------------------------------------------------------- references


def _one_mass_reference(m: str, c: str, k: str, x0: str, v0: str, times: list,
                        order: int) -> list:
    """x^(order)(t) of m x'' + c x' + k x = 0 in mpmath at 60 digits: residues of the two
    roots, or (A + Bt)e^{λt} for a double root."""
    with mpmath.workdps(60):
        m_, c_, k_ = (mpmath.mpf(Fraction(v).numerator) / Fraction(v).denominator
                      for v in (m, c, k))
        x, v = (mpmath.mpf(Fraction(s).numerator) / Fraction(s).denominator for s in (x0, v0))
        disc = c_ * c_ - 4 * m_ * k_
        out = []
        for given in times:
            t = mpmath.mpf(Fraction(given).numerator) / Fraction(given).denominator \
                if isinstance(given, str) else mpmath.mpf(given)
            if disc == 0:
                lam = -c_ / (2 * m_)
                b = v - lam * x  # x = (x + b t) e^{λt}
                # d^r/dt^r [(x + b t) e^{λt}] = e^{λt}(λ^r (x + b t) + r λ^(r-1) b)
                value = mpmath.exp(lam * t) * (lam**order * (x + b * t)
                                               + (order * lam ** (order - 1) * b if order else 0))
            else:
                root = mpmath.sqrt(mpmath.mpc(disc))
                l1, l2 = (-c_ + root) / (2 * m_), (-c_ - root) / (2 * m_)
                a1 = (v - l2 * x) / (l1 - l2)
                a2 = (l1 * x - v) / (l1 - l2)
                value = mpmath.re(a1 * l1**order * mpmath.exp(l1 * t)
                                  + a2 * l2**order * mpmath.exp(l2 * t))
            out.append(value)
        return out


def _derived(scene: Scene, order: int) -> Scene:
    """The scene whose motion is x^(order): initial data (x^(order)(0), x^(order+1)(0))."""
    M, C, K = (sp.Matrix(matrix) for matrix in (scene.M, scene.C, scene.K))
    x, v = sp.Matrix(scene.x0), sp.Matrix(scene.v0)
    for _ in range(order):
        x, v = v, -M.LUsolve(C * v + K * x)
    return Scene.from_matrices(M=M.tolist(), C=C.tolist(), K=K.tolist(), x0=list(x), v0=list(v))


def _errors(values: np.ndarray, reference) -> np.ndarray:
    with mpmath.workdps(40):
        return np.array([[float(abs(mpmath.mpf(float(values[i, j])) - reference[i][j]))
                          for j in range(values.shape[1])] for i in range(values.shape[0])])


def _scale(motion, values: np.ndarray, order: int) -> np.ndarray:
    """max(‖x^(order)(t)‖∞, S₀ρ^order) per time (the contract's scale)."""
    data = motion.data
    rho = float(np.max(np.abs(motion.poles())))
    start = float(np.max(np.abs(data.x0))) + (float(np.max(np.abs(data.v0))) / rho if rho else 0)
    return np.maximum(np.max(np.abs(values), axis=0), start * rho**order)


def _check(scene: Scene, times: list, orders=(0, 1, 2), *, served: bool = True,
           one_mass: tuple | None = None) -> None:
    motion = tiny_motion(scene)
    T = as_times(times)
    for order in orders:
        values, bounds = motion.evaluate(T, order)
        assert np.all(np.isfinite(bounds) | np.isinf(bounds)) and not np.isnan(bounds).any()
        if one_mass is not None:
            reference = [_one_mass_reference(*one_mass, times, order)]
        else:
            reference = reference_motion_arb(_derived(scene, order), times, digits=30)
        errors = _errors(values, reference)
        scale = _scale(motion, values, order)
        # the references are good to 30 digits (the one-mass formula to 60 minus its own
        # cancellation near critical damping): below 1e-30 of the scale they are noise
        slack = 1e-30 * scale[None, :]
        worst = np.unravel_index(np.argmax(errors - bounds), errors.shape)
        assert np.all(errors <= bounds + slack), (order, worst, errors[worst], bounds[worst])
        if served:  # the contract's target; x'' (whose error has a factor ‖Z‖ more) within 3x
            relative = np.max(bounds, axis=0) / scale
            assert np.all(relative <= TARGET * (3 if order == 2 else 1)), (order, relative.max())


# ----------------------------------------------------------------------------- one coordinate


ONE_MASS = {
    # name: (m, c, k, x0, v0), times
    "critical": (("1", "2", "1", "1", "0"), [0.0, 0.5, 1.25, 7.0, 40.0, "0.1"]),
    "critical fast, overshoot": (("1", "2000", "1000000", "1", "-5000"),
                                 [0.0, 1e-4, 0.00125, 0.01, 0.04]),
    "near-critical below 1e-14": (("1", "1.99999999999998", "1", "1", "0"),
                                  [0.0, 0.3, 2.5, 10.0, 40.0]),
    "near-critical above 1e-14": (("1", "2.00000000000002", "1", "1", "0"),
                                  [0.0, 0.3, 2.5, 10.0, 40.0]),
    "near-critical above 1e-8": (("1", "2.00000002", "1", "1", "1/3"),
                                 [0.0, 0.3, 2.5, 10.0, 40.0]),
    "separated roots c = 1e6": (("1", "1000000", "1", "1", "0"),
                                [0.0, 1e-7, 1e-6, 0.01, 1.0, 1e3, 1e6, 3e6]),
    "separated roots, started by a velocity": (("1", "1000000", "1", "0", "1"),
                                               [0.0, 1e-7, 1e-6, 0.01, 1.0, 1e3, 1e6]),
    "undamped": (("2", "0", "8", "1", "3"), [0.0, 0.1, 1.0, 100.0, 1e4, "12345.6789"]),
    "light damping, long phase": (("1", "0.000001", "1", "1", "0"),
                                  [0.0, 10.0, 1e3, 1e4, 1e5]),
    "free body with a dashpot": (("1", "1/1000", "0", "0", "1"), [0.0, 1.0, 1e3, 1e4]),
    "a slow dashpot": (("1", "0.000001", "0", "0", "1"), [0.0, 1e-9, 1e-3, 1.0]),
    "decayed below the normal range": (("1", "8", "16", "4", "-2"), [0.0, 150.0, 178.0, 185.0]),
    "seed-like, m = 1, c = 1/10, k = 4": (("1", "1/10", "4", "1", "0"),
                                          [0.0, 0.1, 1.0, 10.0, 100.0, "0.1"]),
}


@pytest.mark.parametrize("name", list(ONE_MASS))
def test_one_mass_within_bound_and_target(name: str) -> None:
    (m, c, k, x0, v0), times = ONE_MASS[name]
    scene = Scene.from_matrices(M=[[m]], C=[[c]], K=[[k]], x0=[x0], v0=[v0])
    _check(scene, times, one_mass=(m, c, k, x0, v0))


def test_one_mass_unstable_growth_is_bounded_never_nan() -> None:
    """Negative damping: the motion grows like e^{t/2}; bounds stay upper bounds, and where
    the value leaves float64 the bound is infinite (never NaN)."""
    args = ("1", "-1", "4", "1", "0")
    scene = Scene.from_matrices(M=[["1"]], C=[["-1"]], K=[["4"]], x0=["1"], v0=["0"])
    _check(scene, [0.0, 1.0, 30.0, 300.0], orders=(0, 1), served=False, one_mass=args)
    values, bounds = tiny_motion(scene).evaluate(as_times([1e4]), 0)
    assert not np.isnan(bounds).any() and np.isinf(bounds).all()


# ----------------------------------------------------------------------------- 2 to 4 coordinates


def _chain(masses, springs, dashpots, x0, v0, *, walls=(True, True)) -> Scene:
    n = len(masses)
    names = [f"m{i + 1}" for i in range(n)]
    nodes = (["wall"] if walls[0] else []) + names + (["wall"] if walls[1] else [])
    links = list(zip(nodes, nodes[1:]))
    return Scene.from_components(
        masses=dict(zip(names, masses)),
        springs={f"k{i}": (a, b, v) for i, ((a, b), v) in enumerate(zip(links, springs)) if v != "0"},
        dashpots={f"c{i}": (a, b, v) for i, ((a, b), v) in enumerate(zip(links, dashpots)) if v != "0"},
        x0=x0, v0=v0)


SEVERAL = {
    # Δ(λ) = (λ² + λ + 1)²: a defective complex pair (an exceptional point)
    "exceptional point": (Scene.from_components(
        masses={"m1": 1, "m2": 1}, springs={"k1": ("wall", "m1", 1), "k2": ("m1", "m2", 1)},
        dashpots={"c1": ("wall", "m1", 2)}, x0=[1, 0], v0=[0, 0]),
        [0.0, 0.5, 3.0, 6.0, 20.0, 60.0], True),
    # both modes critically damped: double poles −1 and −2
    "critical pair": (_chain(["1", "1"], ["1", "3/2", "1"], ["2", "1", "2"], ["1", "0"], ["0", "1"]),
                      [0.0, 0.7, 2.0, 9.0, 30.0], True),
    # the seed's Example 2 (two masses hanging from a ceiling, air resistance)
    "seed example 2": (Scene.from_matrices(M=[[1, 0], [0, "1/2"]], C=[["1/5", 0], [0, "1/10"]],
                                           K=[[3, -1], [-1, 1]], x0=[1, 0], v0=[0, 0]),
                       [0.0, 0.25, 1.0, 5.0, 20.0, "0.1"], True),
    # the exceptional point moved by 1e-10: two pairs 1e-5 apart, residues of 1e5
    "near exceptional point": (Scene.from_components(
        masses={"m1": 1, "m2": 1}, springs={"k1": ("wall", "m1", 1), "k2": ("m1", "m2", 1)},
        dashpots={"c1": ("wall", "m1", "2.0000000002")}, x0=[1, 0], v0=[0, 0]),
        [0.0, 0.5, 3.0, 6.0, 20.0], True),
    # a rigid-body drift (double pole at 0) beside the vibration
    "free-free chain": (_chain(["1", "2", "1"], ["1", "1"], [], ["1", "0", "0"], ["1", "0", "0"],
                               walls=(False, False)), [0.0, 0.5, 2.0, 10.0], False),
    # double (non-defective) frequencies from a symmetry
    "ring of four": (Scene.from_components(
        masses={f"m{i}": 1 for i in range(4)},
        springs={**{f"k{i}": (f"m{i}", f"m{(i + 1) % 4}", 1) for i in range(4)},
                 **{f"g{i}": ("wall", f"m{i}", 1) for i in range(4)}},
        x0=[1, 0, 0, 0], v0=[0, 1, 0, 0]), [0.0, 0.5, 2.0, 10.0], True),
    "damped chain of three, unequal masses": (
        _chain(["1", "2", "3"], ["1", "2", "1", "3"], ["1/10", "0", "0", "1/5"],
               ["1", "0", "-1/2"], ["0", "1", "0"]), [0.0, 1.0, 5.0, 30.0], True),
    "non-diagonal mass matrix": (Scene.from_matrices(
        M=[[2, 1], [1, 2]], C=[["1/4", 0], [0, "1/8"]], K=[[5, -2], [-2, 3]],
        x0=[1, "1/2"], v0=[0, -1]), [0.0, 1.0, 10.0], True),
}


@pytest.mark.parametrize("name", list(SEVERAL))
def test_several_coordinates_within_bound(name: str) -> None:
    scene, times, served = SEVERAL[name]
    _check(scene, times, served=served)


def _random_scene(rng: random.Random) -> Scene:
    n = rng.randint(2, 4)

    def q(low: int, high: int, den: int = 4) -> str:
        return str(Fraction(rng.randint(low * den, high * den), rng.randint(1, den)))

    masses = [str(Fraction(rng.randint(1, 8), rng.randint(1, 4))) for _ in range(n)]
    G = [[Fraction(q(-2, 2)) for _ in range(n)] for _ in range(n)]
    K = [[str(sum(G[i][k] * G[j][k] for k in range(n)) + (rng.randint(0, 2) if i == j else 0))
          for j in range(n)] for i in range(n)]
    H = [[Fraction(q(-1, 1)) for _ in range(n)] for _ in range(n)]
    C = [[str(sum(H[i][k] * H[j][k] for k in range(n)) * rng.choice([0, 1, Fraction(1, 10)]))
          for j in range(n)] for i in range(n)]
    M = [[masses[i] if i == j else "0" for j in range(n)] for i in range(n)]
    return Scene.from_matrices(M=M, C=C, K=K, x0=[q(-2, 2) for _ in range(n)],
                               v0=[q(-2, 2) for _ in range(n)])


@pytest.mark.parametrize("seed", range(12))
def test_random_scenes_bound_is_never_below_the_error(seed: int) -> None:
    rng = random.Random(seed)
    scene = _random_scene(rng)
    tmax = rng.choice([1.0, 10.0, 50.0])
    times = [0.0] + sorted(rng.uniform(0, tmax) for _ in range(5)) + ["1/3"]
    _check(scene, times, served=False)


@pytest.mark.parametrize("seed", range(12))
def test_the_bound_until_a_time_covers_every_bound_and_error_before_it(seed: int) -> None:
    """``bound_until`` (the probe's first, per-time-free judge) is at least every bound the
    engine gives on [0, t_max] (a dense grid) and the true error there (arb)."""
    scene = _random_scene(random.Random(seed))
    motion = tiny_motion(scene)
    for t_max in (1.0, 10.0, 50.0):
        envelope = motion.bound_until(t_max)
        if envelope == np.inf:
            assert motion.form.doubles or motion.refusal() is not None
            continue
        grid = np.linspace(0.0, t_max, 1001)
        assert motion.largest_bound(grid) <= envelope
    times = [0.0, 0.125, 0.5, 1.0]
    values, _ = motion.evaluate(as_times(times), 0)
    errors = _errors(values, reference_motion_arb(scene, times, digits=30))
    assert errors.max() <= motion.bound_until(1.0)


@pytest.mark.parametrize("name", ["exceptional point", "critical pair"])
def test_the_bound_until_a_time_covers_the_bounds_and_errors_of_2x2_blocks(name: str) -> None:
    """With 2 x 2 blocks (defective pairs) ``bound_until`` is at least every bound the
    engine gives on [0, t_max] (a dense grid) and the true error there (arb)."""
    scene = SEVERAL[name][0]
    motion = tiny_motion(scene)
    assert motion.form.doubles
    for t_max in (0.5, 1.0, 10.0, 100.0):
        envelope = motion.bound_until(t_max)
        assert envelope < np.inf
        assert motion.largest_bound(np.linspace(0.0, t_max, 4001)) <= envelope
    times = [0.0, 0.125, 0.5, 1.0, 7.5, 10.0]
    values, _ = motion.evaluate(as_times(times), 0)
    errors = _errors(values, reference_motion_arb(scene, times, digits=30))
    assert errors.max() <= motion.bound_until(10.0)


@pytest.mark.parametrize(("c", "k", "x0", "v0"), [
    ("1/10", "4", "1", "0"),        # under-damped
    ("0", "1", "1", "-3"),          # undamped
    ("2", "1", "1", "1"),           # critical
    ("0", "0", "1", "2"),           # a free mass (D = 0, α = 0: x = x0 + v0 t)
    ("2.0000001", "1", "1", "0"),   # over-damped, √D·t < 1/2 on [0, 50]
    ("1000", "1", "-2", "5"),       # over-damped, both branches
    ("-1/5", "3", "1", "0"),        # negative damping: a growing motion
])
def test_the_bound_until_a_time_of_one_mass_covers_its_bounds_and_errors(
        c: str, k: str, x0: str, v0: str) -> None:
    """One coordinate's ``bound_until`` (float constants of the closed form) is at least
    every bound the engine gives on [0, t_max] (a dense grid) and the true error (arb)."""
    scene = Scene.from_matrices(M=[[1]], C=[[c]], K=[[k]], x0=[x0], v0=[v0])
    motion = tiny_motion(scene)
    for t_max in (0.5, 1.0, 50.0):
        envelope = motion.bound_until(t_max)
        assert envelope < np.inf
        grid = np.linspace(0.0, t_max, 2001)
        assert motion.largest_bound(grid) <= envelope
    times = [0.0, 0.125, 0.5, 1.0, 37.0, 50.0]
    values, _ = motion.evaluate(as_times(times), 0)
    errors = _errors(values, reference_motion_arb(scene, times, digits=30))
    assert errors.max() <= motion.bound_until(50.0)


@pytest.mark.parametrize("name", ["exceptional point", "critical pair", "seed example 2",
                                  "damped chain of three, unequal masses"])
def test_the_bound_until_a_time_of_a_decaying_motion_is_that_of_its_worst_time(name: str) -> None:
    """Where the motion decays, ``bound_until`` is within 2x of the largest bound on a dense
    grid: each t^k·e^{rt} of the bound taken at its peak, not at t_max with the decay left
    out (which gave 100x, and sent evaluations without bounds through per-time bounds)."""
    motion = tiny_motion(SEVERAL[name][0])
    for t_max in (10.0, 60.0):
        envelope = motion.bound_until(t_max)
        largest = motion.largest_bound(np.linspace(0.0, t_max, 6001))
        assert largest <= envelope <= 2 * largest


@pytest.mark.parametrize("seed", range(8))
def test_values_without_bounds_are_the_same_bits(seed: int) -> None:
    """``evaluate(times)`` (no bounds asked) forms the values alone where the engine's
    ``bound_until`` meets the target: they are the values ``return_error=True`` gives, bit
    for bit, and within the target of the arb reference."""
    scene = _random_scene(random.Random(seed))
    times = [0.0, 0.25, 1.0, 3.5, "1/3"]
    sol = solve(scene)
    alone = sol.evaluate(times)
    values, bounds = sol.evaluate(times, return_error=True)
    assert np.array_equal(alone, values)
    errors = _errors(alone, reference_motion_arb(scene, times, digits=30))
    assert np.all(errors <= bounds)


# ----------------------------------------------------------------------------- contract details


@pytest.mark.parametrize("scene", [
    Scene.from_matrices(M=[[1]], C=[["1/10"]], K=[[4]], x0=[1], v0=[0]),
    SEVERAL["exceptional point"][0],
    SEVERAL["damped chain of three, unequal masses"][0],
], ids=["one mass", "exceptional point", "chain of three"])
def test_a_time_alone_or_in_a_batch_gives_the_same_bits(scene: Scene) -> None:
    times = [0.0, 0.37, 1.5, 4.0, 9.75, 33.3, "0.1"]
    for order in (0, 1, 2):
        together = tiny_motion(scene).evaluate(as_times(times), order)
        for j, t in enumerate(times):
            alone = tiny_motion(scene).evaluate(as_times([t]), order)
            assert np.array_equal(alone[0][:, 0], together[0][:, j])
            assert np.array_equal(alone[1][:, 0], together[1][:, j])


def test_initial_data_at_t0_exactly() -> None:
    scene = Scene.from_matrices(M=[[1, 0], [0, 2]], C=[[1, 0], [0, 0]], K=[[2, -1], [-1, 1]],
                                x0=["0.1", "-0.3"], v0=["1/3", "0"])
    motion = tiny_motion(scene)
    values, _ = motion.evaluate(as_times([0.0]), 0)
    assert values[:, 0].tolist() == [0.1, -0.3]
    values, _ = motion.evaluate(as_times([0.0]), 2)  # x''(0) = −M⁻¹(C v0 + K x0)
    assert values[:, 0].tolist() == [float(-(Fraction(1, 3) + Fraction(1, 5) + Fraction(3, 10))),
                                     float(-(Fraction(-1, 10) - Fraction(3, 10)) / 2)]


@pytest.mark.parametrize("times", [[0.0, 1.0, 2.0], [1.0, 0.0, 2.0], [0.0, 3.0, 0.0, 1.5],
                                   [2.0, 0.0], [0.0]])
def test_initial_data_wherever_t0_stands(times: list[float]) -> None:
    """Every t = 0 column (one or several, first or not) is the scene's initial data with a
    bound of its rounding; the other columns are the motion (no column carries another's)."""
    scene = Scene.from_matrices(M=[[1, 0], [0, 2]], C=[[1, 0], [0, 0]], K=[[2, -1], [-1, 1]],
                                x0=["0.1", "-0.3"], v0=["1/3", "0"])
    values, bounds = tiny_motion(scene).evaluate(as_times(times), 1)
    for j, t in enumerate(times):
        if t == 0:
            assert values[:, j].tolist() == [1 / 3, 0.0]
            assert bounds[:, j].tolist() == [2.0**-53 / 3, 0.0]
        else:
            assert abs(values[0, j] - 1 / 3) > 1e-3 and bounds[0, j] > 0


def test_poles_are_the_roots_of_the_characteristic_polynomial() -> None:
    scene = SEVERAL["seed example 2"][0]
    lam = sp.Symbol("lam")
    delta = sp.Poly((lam**2 * sp.Matrix(scene.M) + lam * sp.Matrix(scene.C)
                     + sp.Matrix(scene.K)).det(), lam)
    with mpmath.workdps(30):
        roots = sorted((complex(r) for r in mpmath.polyroots(
            [mpmath.mpf(sp.Rational(c).p) / sp.Rational(c).q for c in delta.all_coeffs()])),
            key=lambda z: (z.real, z.imag))
    poles = tiny_motion(scene).poles()
    assert len(poles) == len(roots)
    assert all(min(abs(p - r) for p in poles) < 1e-14 for r in roots)


@pytest.mark.parametrize("scene, reason", [
    (Scene.from_matrices(M=[[1]], K=[["k"]], x0=[1], v0=[0], parameters=["k"]),
     "needs rational entries"),
    (Scene.from_matrices(M=[[1]], K=[[4]], x0=[1], v0=[0], forcing=["cos(t)"]),
     "the scene is forced"),
    (Scene.from_components(masses={"m": 1, "n": 0}, springs={"k1": ("wall", "m", 1),
                                                              "k2": ("wall", "n", 3)},
                           dashpots={"c": ("n", "m", 1)}, x0=[1, 0], v0=[0, 0]),
     "massless"),
    (Scene.from_matrices(M=np.eye(5, dtype=int).tolist(), K=np.eye(5, dtype=int).tolist(),
                         x0=[1, 0, 0, 0, 0], v0=[0] * 5),
     "Limits.tiny_max_coordinates = 4"),
], ids=["symbols", "forced", "massless", "five coordinates"])
def test_refusals_name_the_reason(scene: Scene, reason: str) -> None:
    assert reason in tiny_refusal(scene)
    with pytest.raises(SceneError, match="tiny engine cannot take"):
        tiny_motion(scene)


def test_refusal_follows_the_limit(set_limits) -> None:
    scene = Scene.from_matrices(M=[[1, 0], [0, 1]], K=[[2, -1], [-1, 2]], x0=[1, 0], v0=[0, 0])
    set_limits(tiny_max_coordinates=1)
    assert "Limits.tiny_max_coordinates = 1" in tiny_refusal(scene)


def test_cost_model_ranks_the_work() -> None:
    one = Scene.from_matrices(M=[[1]], C=[[1]], K=[[4]], x0=[1], v0=[0])
    pair = SEVERAL["seed example 2"][0]
    assert 0 < tiny_cost(one, count=100) < tiny_cost(pair, count=100) < tiny_cost(pair, count=10_000)

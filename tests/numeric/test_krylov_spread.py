"""The krylov engine's Taylor steps on stiff networks with widely spread masses and springs.

Reference: python-flint's ``arb_mat.exp`` of the exact first-order matrix at 256 bits (a
ball, its radius added to the checks), which shares no code with the engine. The bound
must hold (a bound below the error is a wrong answer) and stay near the float64 floor: on
these scenes (ν ≈ 130-150, about 900 steps to t = 30) it is 1e-14 or less of the scale
max(max|x(t)|, S₀) (measured 2.8e-16 to 2.7e-15; before the a posteriori truncation, the
per-coordinate energy norms and the ordered float sum 4.1e-16 to 8.6e-14, growing
linearly in t).
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
from flint import arb, arb_mat, fmpq, fmpq_mat

from laplace_springs import Scene
from laplace_springs.kernels.precision import flint_workprec
from laplace_springs.numeric.krylov_data import krylov_data
from laplace_springs.numeric.krylov_march import KrylovMotion


def spread_network(seed: int, n: int, spread: float = 6.0) -> Scene:
    """A chain between two walls with cross springs: masses over 10^±spread/4, springs
    over 10^±spread/2, a few light dashpots (non-classical damping)."""
    rng = np.random.default_rng(seed)

    def value(low: float, high: float) -> str:
        return str(Fraction(10 ** rng.uniform(low, high)).limit_denominator(1000))

    masses = {f"m{i}": value(-spread / 4, spread / 4) for i in range(n)}
    nodes = ["wall", *masses, "wall"]
    springs = {f"k{i}": (a, b, value(-spread / 2, spread / 2))
               for i, (a, b) in enumerate(zip(nodes, nodes[1:]))}
    for j in range(n // 3):
        a, b = (str(v) for v in rng.choice(list(masses), 2, replace=False))
        springs[f"x{j}"] = (a, b, value(-spread / 2, spread / 2))
    dashpots = {f"c{j}": (a, b, value(-spread / 2 - 1, spread / 4))
                for j, (a, b) in enumerate(zip(nodes, nodes[1:])) if rng.random() < 0.15}
    dashpots.setdefault("c0", ("wall", "m0", "1/10"))
    return Scene.from_components(masses=masses, springs=springs, dashpots=dashpots,
                                 x0=["1"] + ["0"] * (n - 1), v0=["0"] * (n - 1) + ["1/2"])


def _exact(value: object) -> fmpq:
    q = Fraction(str(value))
    return fmpq(q.numerator, q.denominator)


def _double(hi: float, lo: float) -> fmpq:
    """The exact value of the double-double hi + lo."""
    return fmpq(*Fraction(float(hi)).as_integer_ratio()) + fmpq(*Fraction(float(lo)).as_integer_ratio())


def first_order(scene: Scene) -> tuple[fmpq_mat, fmpq_mat, fmpq_mat]:
    """The exact A = [[0, I], [−M⁻¹K, −M⁻¹C]], M and K."""
    n = scene.n
    M, K, C = (fmpq_mat([[_exact(getattr(scene, name)[i, j]) for j in range(n)] for i in range(n)])
               for name in ("M", "K", "C"))
    B, D = M.inv() * K, M.inv() * C
    A = fmpq_mat(2 * n, 2 * n)
    for i in range(n):
        A[i, n + i] = 1
        for j in range(n):
            A[n + i, j], A[n + i, n + j] = -B[i, j], -D[i, j]
    return A, M, K


def propagate(A: fmpq_mat, t: float, z: list[fmpq]) -> tuple[np.ndarray, float]:
    """exp(tA)·z at 256 bits: midpoints and the largest radius."""
    with flint_workprec(256):
        y = (arb_mat(A) * arb(fmpq(*Fraction(t).as_integer_ratio()))).exp() * arb_mat([[arb(q)] for q in z])
        mids = np.array([float(y[i, 0].mid()) for i in range(y.nrows())])
        radius = max(float(y[i, 0].rad()) for i in range(y.nrows()))
    return mids, radius


SCENES = [(11, 24), (12, 30), (13, 36)]
TIMES = [0.5, 7.0, 30.0]


@pytest.mark.parametrize("seed,n", SCENES)
def test_bound_holds_and_is_near_the_floor(seed: int, n: int) -> None:
    scene = spread_network(seed, n)
    A, _, _ = first_order(scene)
    motion = KrylovMotion(krylov_data(scene))
    assert motion.data.nu > 100                     # stiff: thousands of steps to t = 30
    values, bounds = motion.evaluate(np.array(TIMES))
    z0 = [_exact(scene.x0[i]) for i in range(n)] + [_exact(scene.v0[i]) for i in range(n)]
    for k, t in enumerate(TIMES):
        reference, radius = propagate(A, t, z0)
        error = np.abs(values[:, k] - reference[:n])
        assert np.all(error <= bounds[:, k] - radius), (t, error.max(), bounds[:, k].min())
        scale = max(float(np.max(np.abs(reference[:n]))), 1.0)   # the contract's S₀ ≥ ‖x0‖∞ = 1
        assert np.max(bounds[:, k]) <= 1e-14 * scale, (t, np.max(bounds[:, k]) / scale)


@pytest.mark.parametrize("budget", [2.0**-6, 2.0**-30, 2.0**-58])
def test_one_step_local_bounds(budget: float, set_limits) -> None:
    """One step from a random state ẑ against exp(HA)ẑ: its energy-norm error within the
    step's local bound (truncation + the terms' rounding + the sum's), its x part within
    the x bound. A large budget leaves few terms: the a posteriori truncation carries it."""
    set_limits(krylov_step_error=budget)
    scene = spread_network(21, 20)
    A, M, K = first_order(scene)
    n = scene.n
    data = krylov_data(scene)
    motion = KrylovMotion(data)
    stepper = motion.stepper
    rng = np.random.default_rng(5)
    zh = rng.standard_normal(2 * n)
    zl = zh * rng.uniform(-1, 1, 2 * n) * 2.0**-54
    terms = stepper.terms(zh, zl)
    local = terms.truncation + terms.rounding
    local_x = terms.truncation_x + data.H * terms.rounding_x / math.sqrt(data.m_min)
    sh, sl, sum_energy, sum_x = stepper.advance(terms)
    local, local_x = local + sum_energy, local_x + sum_x
    z0 = [_double(h, low) for h, low in zip(zh, zl)]
    with flint_workprec(256):
        y = (arb_mat(A) * arb(_double(data.H, 0.0))).exp() * arb_mat([[arb(q)] for q in z0])
        e = arb_mat([[arb(_double(h, low)) - y[i, 0]] for i, (h, low) in enumerate(zip(sh, sl))])
        ex, ev = arb_mat([[e[i, 0]] for i in range(n)]), arb_mat([[e[n + i, 0]] for i in range(n)])
        energy = ((ex.transpose() * arb_mat(K) * ex)[0, 0] + (ev.transpose() * arb_mat(M) * ev)[0, 0]).sqrt()
        worst_x = max(float(abs(e[i, 0]).upper()) for i in range(n))
        energy_up = float(energy.upper())
    assert energy_up <= local, (energy_up, local)
    assert worst_x <= local_x, (worst_x, local_x)
    if budget > 2.0**-10:
        assert terms.truncation > 10 * (terms.rounding + sum_energy)   # the tail carries it
        assert energy_up > terms.truncation / 1e4                     # and is not loose

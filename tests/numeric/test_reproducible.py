"""A time's value does not depend on the other times of the call (issue 21 item 3).

For every engine: random batches of times (random sizes, the time at a random position,
batches of 1 to 300 times including huge and tiny times and sample times), and the same
time evaluated alone, must give the same float64 bits, for the value and its bound. The
reference is the engine itself on one time: there is no tolerance.
"""

from __future__ import annotations

import numpy as np
import pytest

import laplace_springs as ls
from laplace_springs.kernels.batch import BLOCKED, WIDTH, columns_product, rows_product
from laplace_springs.model.sampled import sampled

RAYLEIGH_CHAIN = {
    "M": [[1 if i == j else 0 for j in range(16)] for i in range(16)],
    "K": [[2 if i == j else (-1 if abs(i - j) == 1 else 0) for j in range(16)] for i in range(16)],
}
RAYLEIGH_CHAIN["C"] = [[f"{2 * v}/100" if i == j else (f"{v}/100" if v else 0)
                        for j, v in enumerate(row)] for i, row in enumerate(RAYLEIGH_CHAIN["K"])]


def _chain(n: int, damping: str | None = None) -> ls.Scene:
    K = [[2 if i == j else (-1 if abs(i - j) == 1 else 0) for j in range(n)] for i in range(n)]
    M = [[(1 + i % 3) if i == j else 0 for j in range(n)] for i in range(n)]
    C = [[0] * n for _ in range(n)]
    if damping == "one dashpot":
        C[0][0] = "3/10"
    return ls.Scene.from_matrices(M=M, C=C, K=K, x0=[1] + [0] * (n - 1),
                                  v0=[0] * (n - 2) + ["1/2", 0])


def _scenes() -> dict[str, tuple[ls.Scene, str]]:
    T = np.sort(np.concatenate([[0.0, 5.0], np.random.default_rng(2).uniform(0, 5, 60)]))
    return {
        "chebyshev": (ls.Scene.from_matrices(**RAYLEIGH_CHAIN, x0=[1] + [0] * 15,
                                             v0=[0] * 15 + [1]), "chebyshev"),
        "classical": (_chain(12), "classical"),
        "modal": (_chain(12, "one dashpot"), "modal"),
        # a defective pair (λ² + λ + 1)²: the modal engine's blocks e^{Tt}
        "modal_blocks": (ls.Scene.from_matrices(M=[[1, 0], [0, 1]], C=[[2, 0], [0, 0]],
                                                K=[[2, -1], [-1, 1]], x0=[1, 0], v0=[0, 1]),
                         "modal"),
        "exact": (ls.Scene.from_matrices(M=[[1, 0], [0, 2]], C=[["1/10", 0], [0, 0]],
                                         K=[[3, -1], [-1, 1]], x0=[1, 0], v0=[0, "1/3"]), "exact"),
        "periodic": (ls.Scene.from_matrices(M=[[1]], C=[["1/5"]], K=[[4]], x0=["1/10"], v0=[0],
                                            forcing=[ls.square_wave(1, "3/7")]), "exact"),
        "sampled": (ls.Scene.from_matrices(M=[[1, 0], [0, 1]], C=[["1/10", 0], [0, 0]],
                                           K=[[2, -1], [-1, 2]], x0=[1, 0], v0=[0, 0],
                                           forcing=[sampled(T, np.sin(3 * T)), 0]), "auto"),
        # the other engines of the planner (their times up to 100: krylov's cost grows with t)
        "refined": (_chain(12), "refined"),
        "tiny": (ls.Scene.from_matrices(M=[[1, 0], [0, 2]], C=[["1/10", 0], [0, 0]],
                                        K=[[3, -1], [-1, 1]], x0=[1, 0], v0=[0, "1/3"]), "tiny"),
        "krylov": (_chain(12, "one dashpot"), "krylov"),
        "certified": (ls.Scene.from_matrices(M=[[1]], C=[["1/10"]], K=[[4]], x0=[1], v0=[0]),
                      "certified"),
    }
LONGEST = {"refined": 100.0, "tiny": 100.0, "krylov": 100.0, "certified": 100.0}


SCENES = _scenes()


def _batches(rng: np.random.Generator, count: int) -> list[np.ndarray]:
    out = []
    for _ in range(count):
        size = int(rng.integers(1, 300))
        times = rng.uniform(0, 60, size)
        extra = np.array([0.0, 1e-9, 0.37, 5.0, 123.456, 7e3])
        chosen = extra[rng.integers(0, extra.size, int(rng.integers(0, 4)))]
        times[rng.integers(0, size, chosen.size)] = chosen
        out.append(times)
    return out


@pytest.mark.parametrize("name", sorted(SCENES))
@pytest.mark.parametrize("order", [0, 1])
def test_alone_and_in_a_batch_give_the_same_bits(name, order):
    scene, method = SCENES[name]
    sol = ls.solve(scene, method=method)
    rng = np.random.default_rng(len(name) * 7 + order)
    for batch in _batches(rng, 3):
        times = np.minimum(batch, LONGEST.get(name, np.inf))
        values, bounds = sol.evaluate(times, return_error=True, derivative=order, target=0.5)
        for column in rng.choice(times.size, size=min(4, times.size), replace=False):
            alone, alone_bound = sol.evaluate([times[column]], return_error=True,
                                              derivative=order, target=0.5)
            assert np.array_equal(values[:, column], alone[:, 0]), \
                (name, times[column], np.max(np.abs(values[:, column] - alone[:, 0])))
            assert np.array_equal(bounds[:, column], alone_bound[:, 0]), (name, times[column])


@pytest.mark.parametrize("name", ["classical", "modal", "exact", "chebyshev"])
def test_the_default_target_escalates_time_by_time(name):
    # with the contract's target (times may move to the next engine): the decision for a
    # time looks at that time alone, so its value is still the same alone
    scene, method = SCENES[name]
    sol = ls.solve(scene, method=method)
    times = np.array([0.5, 3e3, 7e3, 2.0, 1e4])
    values = sol.evaluate(times)
    for column, t in enumerate(times):
        assert np.array_equal(values[:, column], sol.evaluate([t])[:, 0]), (name, t)


def test_the_mp_engine_gives_a_time_its_own_precision():
    """Found by an attack: x₂ ≈ 2.08e-47 beside a scale of 1e-27 right after a ramp switches
    on, finished by the mp engine, came out in other bits beside t = 2.6 (one working
    precision for the call). The reference, 2.0833351196096980715e-47, is an mpmath
    variation-of-parameters solution at 45 and 70 digits."""
    scene = ls.Scene.from_matrices(M=[["9/10", 0], [0, 4]], C=[[2, 0], [0, "1/5"]],
                                   K=[["7/5", "-9/10"], ["-9/10", "93/70"]], x0=[0, 0],
                                   v0=[0, 0], forcing=["10*(t - 13/5)*Heaviside(t - 13/5)", "0"])
    sol = ls.solve(scene)
    t = 2.600000001
    alone, bound = sol.evaluate([t], return_error=True)
    for times in ([2.6, t], [0.0, t, 1000.0], [t, 1e-9]):
        values, bounds = sol.evaluate(times, return_error=True)
        column = times.index(t)
        assert values[1, column] == alone[1, 0] and bounds[1, column] == bound[1, 0], times
    assert abs(alone[1, 0] - 2.0833351196096980715e-47) <= bound[1, 0]


# (p, k): small-matrix kernels, chunks of WIDTH, blocked kernels (p·k·WIDTH > BLOCKED), a row
SHAPES = [(3, 5), (12, 12), (60, 120), (2, 500), (10, 1000), (400, 400), (1, 3000), (300, 2)]


@pytest.mark.parametrize("shape", SHAPES)
@pytest.mark.parametrize("kinds", ["real", "complex", "mixed", "fortran"])
def test_products_give_a_column_the_same_bits_whatever_the_others(shape, kinds):
    # OpenBLAS rounds a column differently by the number of columns (gemv for one, edge
    # kernels, small-matrix kernels up to 100³ multiply-adds, k split into blocks beyond)
    p, k = shape
    rng = np.random.default_rng(p * 1000 + k)
    A = rng.standard_normal((p, k))
    if kinds in ("complex", "mixed"):
        A = A + 1j * rng.standard_normal((p, k))
    if kinds == "fortran":
        A = np.asfortranarray(A)
    for count in (1, WIDTH - 1, WIDTH + 3, 37 * WIDTH, 2000):
        if p * k * count > 4e8:
            continue
        B = rng.standard_normal((k, count))
        if kinds == "complex":
            B = B + 1j * rng.standard_normal((k, count))
        together, rows = columns_product(A, B), rows_product(B.T, A.T)
        for column in rng.choice(count, size=min(3, count), replace=False):
            for alone in (B[:, [column]], np.concatenate([B[:, :2], B[:, [column]]], axis=1)):
                assert np.array_equal(together[:, column], columns_product(A, alone)[:, -1]), \
                    (shape, kinds, count, p * k * WIDTH > BLOCKED)
                assert np.array_equal(rows[column], rows_product(alone.T, A.T)[-1])
        assert np.allclose(together, A @ B, rtol=1e-12, atol=1e-12 * np.abs(A).max() * k)

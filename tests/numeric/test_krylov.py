"""The krylov (double-double Taylor) route against independent references.

References: the 60-digit matrix exponential of :mod:`laplace_springs.bench.reference`
(small random non-classical scenes) and the benchmark's own double-double Taylor
reference on the exact sparse matrix (``benchmarks/bench_scaling.py``, a 200-mass chain
with a wall dashpot), which shares no code with the route.
"""

from __future__ import annotations

import sys
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

import laplace_springs.routes.engines  # noqa: F401 - registers the engines a plan may call
from laplace_springs import Scene, SceneError
from laplace_springs.bench.reference import reference_motion
from laplace_springs.numeric.krylov import krylov_refusal
from laplace_springs.routes.krylov import krylov_ok, krylov_solution


def random_network(seed: int, n: int) -> Scene:
    """Random masses, springs and dashpots (a dashpot on one mass only: non-classical)."""
    rng = np.random.default_rng(seed)
    names = [f"m{i}" for i in range(n)]
    masses = {name: str(Fraction(int(rng.integers(1, 5)), int(rng.integers(1, 4)))) for name in names}
    springs = {f"k{i}": (names[i], names[i + 1], str(Fraction(int(rng.integers(1, 9)), 2)))
               for i in range(n - 1)}
    springs["kw"] = (names[0], "wall", "3")
    for e in range(n // 2):
        i, j = (int(v) for v in rng.choice(n, 2, replace=False))
        springs[f"x{e}"] = (names[i], names[j], str(Fraction(int(rng.integers(1, 5)), 3)))
    dashpots = {"c0": (names[int(rng.integers(n))], "wall", str(Fraction(int(rng.integers(1, 9)), 8)))}
    for e in range(n // 3):
        i, j = (int(v) for v in rng.choice(n, 2, replace=False))
        dashpots[f"d{e}"] = (names[i], names[j], str(Fraction(int(rng.integers(1, 5)), 10)))
    x0 = {name: str(Fraction(int(rng.integers(-4, 5)), 4)) for name in names[:2]}
    v0 = {names[-1]: "1/2"}
    return Scene.from_components(masses=masses, springs=springs, dashpots=dashpots, x0=x0, v0=v0)


TIMES = np.array([0.0, 0.3, 1.7, 6.25, 23.0])


@pytest.mark.parametrize("seed,n", [(1, 3), (2, 6), (3, 12)])
def test_random_networks_against_the_60_digit_reference(seed: int, n: int) -> None:
    scene = random_network(seed, n)
    assert krylov_ok(scene)
    sol = krylov_solution(scene, reason="test")
    reference = np.array(reference_motion(scene, list(TIMES), dps=60), dtype=float)
    values, bounds = sol.motion.evaluate(TIMES, 0)
    error = np.abs(values - reference)
    assert np.all(error <= bounds), (error.max(), bounds.min())
    scale = max(np.max(np.abs(reference)), sol._floor(0))
    assert np.max(bounds) <= 1e-13 * scale


@pytest.mark.parametrize("order", [1, 2])
def test_velocity_and_acceleration_against_the_exact_route(order: int) -> None:
    """x' and x'' against the exact route's mpmath evaluation (30 digits)."""
    scene = random_network(4, 4)
    sol = krylov_solution(scene, reason="test")
    times = np.array([0.0, 0.5, 4.0, 11.0])
    exact = np.array(sol._exact_form.evaluate(times, dps=30, derivative=order), dtype=float)
    values, bounds = sol.motion.evaluate(times, order)
    assert np.all(np.abs(values - exact) <= bounds)
    assert np.max(bounds) <= 1e-13 * sol._floor(order)


def test_verify() -> None:
    assert krylov_solution(random_network(5, 7), reason="test").verify(tolerance=1e-12)


def test_chain_of_200_against_the_benchmarks_double_double_reference() -> None:
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
    try:
        import bench_scaling as bench
    finally:
        sys.path.pop(0)
    spec = bench.scene_spec("chain-wall-dashpot", 200)
    times = np.linspace(0.0, 50.0, 101)
    reference = bench.DoubleDoubleTaylor(spec).motion(times)
    sol = krylov_solution(bench.build_scene(spec), reason="test")
    values, bounds = sol.evaluate(times, return_error=True)
    error = np.abs((values - reference[0]) - reference[1])
    assert np.all(error <= bounds)
    assert np.max(bounds) <= 1e-13 * np.max(np.abs(reference[0]))
    with pytest.raises(SceneError, match="no closed form"):
        sol.x


def test_small_scene_matches_the_exact_route_and_keeps_its_closed_form() -> None:
    scene = Scene.from_matrices(M=[[1, 0], [0, 2]], C=[["1/2", 0], [0, 0]],
                                K=[[3, -1], [-1, 1]], x0=[1, 0], v0=[0, "1/3"])
    sol = krylov_solution(scene, reason="test")
    assert "mp" in sol.plan([1.0]).chain and sol.x.shape == (2, 1)
    exact = np.array(sol.evaluate([0.2, 9.0], dps=30), dtype=float)
    values = sol.evaluate([0.2, 9.0])
    assert np.max(np.abs(values - exact)) < 1e-13
    assert len(sol.poles) == 4 and np.all(sol.poles.real < 0)


def test_refusals_name_the_reason() -> None:
    negative = Scene.from_matrices(M=[[1]], C=[[-1]], K=[[1]], x0=[1], v0=[0])
    assert "C + Cᵀ" in krylov_refusal(negative)
    mass = Scene.from_matrices(M=[[2, 1], [1, 2]], K=[[1, 0], [0, 1]], x0=[1, 0], v0=[0, 0])
    assert "diagonal" in krylov_refusal(mass)
    with pytest.raises(SceneError, match="krylov"):
        krylov_solution(negative, reason="test")


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize("matrices,reason", [
    ({"M": [["1e-300"]], "K": [["1e300"]], "x0": [1], "v0": [0]}, "beyond"),
    ({"M": [["1e300"]], "K": [["1e-300"]], "x0": [1], "v0": [0]}, "beyond"),
    ({"M": [[1]], "C": [["1e300"]], "K": [[1]], "x0": [1], "v0": [0]}, "beyond"),
    ({"M": [["1e-200"]], "K": [[1]], "x0": [1], "v0": [0]}, "mass is below"),
    ({"M": [[1]], "K": [["1e100"]], "x0": ["1e120"], "v0": [0]}, "initial data"),
])
def test_scenes_beyond_float64_are_declined_with_a_reason(matrices, reason) -> None:
    """Extreme scales: a refusal the planner reads (no crash, no overflow warning)."""
    scene = Scene.from_matrices(**matrices)
    why = krylov_refusal(scene, t_max=1e3)
    assert why is not None and reason in why
    with pytest.raises(SceneError, match="krylov"):
        krylov_solution(scene, reason="test")


def test_a_slow_scene_is_served_within_its_bound() -> None:
    """ν far below 1 (a tiny spring on a heavy mass): one long step, against the closed
    form x = cos(ωt) in mpmath."""
    import mpmath

    scene = Scene.from_matrices(M=[["1e60"]], K=[["1e-60"]], x0=[1], v0=[0])
    times = np.array([0.0, 1.0, 1e3, 1e50])
    values, bounds = krylov_solution(scene, reason="test").motion.evaluate(times, 0)
    with mpmath.workdps(80):
        exact = [float(mpmath.cos(mpmath.mpf(t) * mpmath.mpf(10) ** -60)) for t in times]
    assert np.all(np.abs(values[0] - exact) <= bounds[0]) and np.max(bounds) < 1e-13


def test_auto_takes_the_krylov_route_for_a_large_network() -> None:
    """A 250-mass chain with one extra wall dashpot (damping not classical): "auto" takes the
    krylov route (the dense 2n x 2n route costs far more), and its values hold
    their bound against the benchmark's independent double-double Taylor reference (SciPy's
    dense expm is off by 4e-13 at t = 40 on this scene, above the route's bound)."""
    import laplace_springs as ls


    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
    try:
        import bench_scaling as bench
    finally:
        sys.path.pop(0)
    spec = bench.scene_spec("chain-wall-dashpot", 250)
    sol = ls.solve(bench.build_scene(spec))
    assert sol.method == "krylov" and "250 coordinates" in sol.reason
    times = np.array([0.0, 3.0, 17.5, 40.0])
    reference = bench.DoubleDoubleTaylor(spec).motion(times)
    values, bounds = sol.evaluate(times, return_error=True)
    assert np.all(np.abs((values - reference[0]) - reference[1]) <= bounds)

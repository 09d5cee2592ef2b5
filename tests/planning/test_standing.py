"""The standing plan (laplace_springs.planning.standing): on a scene the tiny engine takes,
``solve`` and ``evaluate`` skip planning because the plan is known to start with the tiny
engine. Checked against the planner itself (the claim is about its decisions) on random
scenes and requests, and the values against an independent reference (mpmath's matrix
exponential) where the shortcut falls back to the full plan."""

from __future__ import annotations

import random
from fractions import Fraction

import mpmath
import numpy as np
import pytest

import laplace_springs as ls
from laplace_springs import solving  # fills BUILDERS
from laplace_springs.planning import Request, plan, scene_facts
from laplace_springs.planning.execute import BUILDERS
from laplace_springs.planning.standing import STANDING_MAX_COUNT, standing_engine


def _random_scene(rng: random.Random) -> ls.Scene:
    """A random scene of 1-4 coordinates with rational entries: symmetric positive M, K and
    C from random factors, some undamped, some with a rigid-body mode."""
    n = rng.randint(1, 4)

    def rational() -> str:
        return f"{rng.randint(1, 40)}/{rng.randint(1, 12)}"

    def symmetric(diagonal_only: bool, zero: bool = False) -> list[list[str]]:
        out = [["0"] * n for _ in range(n)]
        if zero:
            return out
        for i in range(n):
            out[i][i] = rational()
        if not diagonal_only:
            for i in range(n - 1):  # a chain: weakly coupled, still positive definite
                c = Fraction(min(Fraction(out[i][i]), Fraction(out[i + 1][i + 1]))) / 3
                out[i][i + 1] = out[i + 1][i] = str(-c)
        return out

    return ls.Scene.from_matrices(
        M=symmetric(True), C=symmetric(rng.random() < 0.5, zero=rng.random() < 0.3),
        K=symmetric(False), x0=[rational() for _ in range(n)],
        v0=[rng.choice(["0", rational()]) for _ in range(n)])


@pytest.mark.parametrize("seed", range(40))
def test_the_planner_puts_the_tiny_engine_first_for_every_request_of_x(seed):
    rng = random.Random(seed)
    scene = _random_scene(rng)
    assert standing_engine(scene, "auto") == "tiny"
    facts = scene_facts(scene)
    for _ in range(25):
        request = Request(count=rng.choice([1, 3, 100, 1000, STANDING_MAX_COUNT]),
                          t_max=rng.choice([0.0, 1.0, 100.0, 1e4, 1e8]),
                          target=10.0 ** rng.uniform(-16, -3))
        for built in ((), ("tiny",)):
            made = plan(facts, request, built=built, available=set(BUILDERS) | set(built))
            assert made.primary == "tiny", (request, built, made)


def _planned(sol: ls.Solution, times, **kw):
    """The same evaluation through the plan (a report asks for it)."""
    values, bounds, report = sol.evaluate(times, return_error=True, return_report=True, **kw)
    return values, bounds, report


@pytest.mark.parametrize("seed", range(12))
def test_a_standing_solution_is_the_planned_one(seed, monkeypatch):
    rng = random.Random(100 + seed)
    scene = _random_scene(rng)
    sol = ls.solve(scene)
    if not sol._standing:  # the tiny bound missed at the probe times: planned in full
        assert "tiny" in sol.excluded and "tiny: its own bound" in sol.reason
        return
    assert sol.method == "tiny" and sol.requested == "auto"
    with monkeypatch.context() as patched:  # the same scene solved without the shortcut
        patched.setattr(solving, "standing_engine", lambda scene, method: None)
        planned = ls.solve(_random_scene(random.Random(100 + seed)))
    assert not planned._standing and planned.method == "tiny"
    assert sol.reason == planned.reason and sol.excluded == planned.excluded
    times = np.sort(np.array([rng.uniform(0, 30) for _ in range(20)] + [0.0]))
    values, bounds = sol.evaluate(times, return_error=True)
    planned, planned_bounds, report = _planned(sol, times)
    if set(report.engines) == {"tiny"}:  # nothing escalated: the same numbers
        assert np.array_equal(values, planned) and np.array_equal(bounds, planned_bounds)


def _reference(scene: ls.Scene, times, digits: int = 40) -> np.ndarray:
    """x(t) = [I 0] expm(Z t) y0 in mpmath, Z = [[0, I], [-M⁻¹K, -M⁻¹C]] (its own
    construction from the scene's entries)."""
    n = scene.n
    with mpmath.workdps(digits):
        def mat(a):
            return mpmath.matrix([[mpmath.mpf(Fraction(str(v)).numerator)
                                   / Fraction(str(v)).denominator for v in row]
                                  for row in a.tolist()])
        Minv = mat(scene.M) ** -1
        A, B = Minv * mat(scene.K), Minv * mat(scene.C)
        Z = mpmath.zeros(2 * n, 2 * n)
        for i in range(n):
            Z[i, n + i] = 1
            for j in range(n):
                Z[n + i, j], Z[n + i, n + j] = -A[i, j], -B[i, j]
        y0 = mpmath.matrix([mpmath.mpf(Fraction(str(v)).numerator) / Fraction(str(v)).denominator
                            for v in [*scene.x0, *scene.v0]])
        out = np.empty((n, len(times)))
        for k, t in enumerate(times):
            y = mpmath.expm(Z * mpmath.mpf(t)) * y0
            out[:, k] = [float(y[i]) for i in range(n)]
    return out


@pytest.mark.parametrize("K, kw", [([[3, -1], [-1, 1]], {"target": 1e-16}),
                                   ([["100000001/100000000", "-1/100000000"],
                                     ["-1/100000000", "100000001/100000000"]], {})])
def test_times_the_tiny_bound_misses_are_escalated_as_planned(K, kw):
    # undamped pairs far out: no tiny bound meets 1e-16; and two frequencies 1e-8 apart
    # keep a bound that grows like t (the refined evaluation's coupling term) and misses
    # 1e-13 there. Those times go to the certified or ball engine
    M = [[1, 0], [0, 2]] if kw else [[1, 0], [0, 1]]
    scene = ls.Scene.from_matrices(M=M, K=K, x0=[1, 0], v0=[0, "1/3"])
    sol = ls.solve(scene)
    assert sol._standing
    times = np.array([0.5, 2.0, 3e3, 2e4])
    values, bounds = sol.evaluate(times, return_error=True, **kw)
    planned, planned_bounds, report = _planned(sol, times, **kw)
    assert set(report.engines) - {"tiny"}  # some time escalated (certified, ball)
    assert np.array_equal(values, planned) and np.array_equal(bounds, planned_bounds)
    reference = _reference(scene, times, digits=50)
    assert np.all(np.abs(values - reference) <= bounds)


def test_scenes_without_a_standing_plan_are_planned():
    eye = [[int(i == j) for j in range(5)] for i in range(5)]
    five = ls.Scene.from_matrices(M=eye, K=eye, x0=[1, 0, 0, 0, 0], v0=[0] * 5)
    forced = ls.Scene.from_matrices(M=[[1]], K=[[4]], x0=[0], v0=[0], forcing=["cos(t)"])
    symbolic = ls.Scene.from_matrices(M=[[1]], K=[["k"]], x0=[1], v0=[0], parameters=["k"])
    for scene in (five, forced, symbolic):
        assert standing_engine(scene, "auto") is None
    assert not ls.solve(five)._standing and not ls.solve(forced)._standing
    plain = ls.Scene.from_matrices(M=[[1]], K=[[4]], x0=[1], v0=[0])
    assert standing_engine(plain, "exact") is None and not ls.solve(plain, method="tiny")._standing


def test_a_standing_evaluation_matches_the_reference_within_its_bounds():
    rng = random.Random(7)
    for _ in range(6):
        scene = _random_scene(rng)
        times = np.sort(np.array([0.0, *(rng.uniform(0, 20) for _ in range(7))]))
        values, bounds = ls.solve(scene).evaluate(times, return_error=True)
        reference = _reference(scene, times)
        assert np.all(np.abs(values - reference) <= bounds), scene

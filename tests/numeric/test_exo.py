"""The numeric forced route ("exo"): formula and periodic forces through the inputs' own
dynamics, checked against closed forms written here and against the exact route (partial
fractions of the resolvent: no code shared with the augmented scenes)."""

from __future__ import annotations

import numpy as np
import pytest

import laplace_springs as ls
from laplace_springs.model.errors import LimitError

TIMES = [0.0, 0.25, 1.0, 1.5, 2.0, 3.3, 7.75, 20.1]


@pytest.fixture
def small(set_limits):
    """Let the exo route take scenes of any size (by default it starts at 9 coordinates)."""
    set_limits(exo_min_coordinates=1)


def _chain(n: int, forcing: list[str], *, damping: str = "1/5", x0: list[int] | None = None):
    masses = {f"m{i}": 1 for i in range(n)}
    springs = {"k0": ("wall", "m0", 2), **{f"k{i}": (f"m{i-1}", f"m{i}", 1) for i in range(1, n)}}
    dashpots = {f"c{i}": (f"m{i}", "wall", damping) for i in range(n)}
    return ls.Scene.from_components(masses=masses, springs=springs, dashpots=dashpots,
                                    x0=x0 or [0] * n, v0=[0] * n, forcing=forcing + ["0"] * (n - len(forcing)))


def test_a_cosine_from_rest_matches_its_closed_form(small):
    # x'' + 4x = cos t, x(0) = x'(0) = 0: x = (cos t − cos 2t)/3, x' = (−sin t + 2 sin 2t)/3
    scene = ls.Scene.from_matrices(M=[[1]], K=[[4]], x0=[0], v0=[0], forcing=["cos(t)"])
    sol = ls.solve(scene, method="exo")
    t = np.array(TIMES)
    values, bounds = sol.evaluate(t, return_error=True)
    expected = (np.cos(t) - np.cos(2 * t)) / 3
    assert sol.method.endswith("+exo")
    assert np.all(np.abs(values[0] - expected) <= bounds[0] + 2e-16 * np.abs(expected))
    assert bounds.max() < 1e-13
    velocity = sol.evaluate(t, derivative=1)[0]
    assert np.max(np.abs(velocity - (-np.sin(t) + 2 * np.sin(2 * t)) / 3)) < 1e-13
    assert values[0, 0] == 0.0   # the initial data, exactly


@pytest.mark.parametrize("forcing", [
    "square_wave(1, 2)",
    "sawtooth(3, 3/2)",
    "3*DiracDelta(t - 1) + exp(-t)*sin(3*t)*Heaviside(t - 2) + t",
    "pulse_train(2, 1, 1/4) + cos(5*t)",
    "2*DiracDelta(t) + Heaviside(t - 1)*exp(t/5)",
    "cos(sqrt(2)*t) + t*sin(t)",   # irrational and degree-4 inputs: the augmented scene
])
def test_forced_pairs_match_the_exact_route(small, forcing):
    scene = ls.Scene.from_matrices(M=[[1, 0], [0, "1/2"]], C=[["1/5", 0], [0, "1/10"]],
                                   K=[[3, -1], [-1, 1]], x0=[1, 0], v0=[0, "1/2"],
                                   forcing=[forcing, "0"])
    exact = ls.solve(scene, method="exact")
    ours = ls.solve(scene, method="exo")
    times = [t for t in TIMES if t not in (1.0, 2.0)]  # away from the switching times
    for order in (0, 1, 2):
        reference = exact.evaluate(times, derivative=order)
        values, bounds = ours.evaluate(times, derivative=order, return_error=True)
        scale = np.max(np.abs(reference), axis=0)
        assert np.all(np.abs(values - reference) <= bounds + 2e-15 * scale), (forcing, order)
        assert np.max(bounds / np.maximum(scale, 1e-3)) < 1e-11
    assert ours.verify()


def test_the_planner_takes_the_exo_route_for_larger_forced_scenes_and_it_matches_the_exact_route():
    scene = _chain(9, ["cos(2*t)", "0", "0", "square_wave(1, 3)"])
    assert ls.plan(scene).primary == "exo"
    ours = ls.solve(scene, method="exo")
    assert ours.method.endswith("+exo")
    exact = ls.solve(scene, method="exact")
    times = [0.5, 2.9, 6.1]
    reference = exact.evaluate(times)
    values, bounds = ours.evaluate(times, return_error=True)
    assert np.all(np.abs(values - reference) <= bounds + 1e-15 * np.abs(reference).max())


def test_a_sweep_of_a_forced_chain_equals_the_sets_solved_alone():
    scene = ls.Scene.from_components(
        masses={f"m{i}": 1 for i in range(10)},
        springs={"k0": ("wall", "m0", "k"), **{f"k{i}": (f"m{i-1}", f"m{i}", 1) for i in range(1, 10)}},
        dashpots={f"c{i}": (f"m{i}", "wall", "1/5") for i in range(10)}, x0=[0] * 10, v0=[0] * 10,
        forcing=["cos(3*t/2)"] + ["0"] * 9, parameters=["k"])
    times = np.linspace(0, 12, 13)
    result = ls.sweep(scene, {"k": [1, 3]}, times, return_error=True)
    for row, k in enumerate((1, 3)):
        sol = ls.solve(scene.subs({"k": k}))
        assert sol.method.endswith("+exo")
        alone, bounds = sol.evaluate(times, return_error=True)
        np.testing.assert_array_equal(result.values[row], alone)
        np.testing.assert_array_equal(result.error[row], bounds)


def test_too_many_periods_is_a_limit_error_naming_the_limit(small, set_limits):
    set_limits(exo_max_periods=10)
    scene = ls.Scene.from_matrices(M=[[1]], K=[[4]], x0=[0], v0=[0], forcing=["square_wave(1, 1)"])
    sol = ls.solve(scene, method="exo")
    with pytest.raises(LimitError, match="exo_max_periods"):
        sol.evaluate([100.0])


def test_the_exo_route_refuses_free_and_sampled_scenes_by_name(small):
    free = ls.Scene.from_matrices(M=[[1]], K=[[4]], x0=[1], v0=[0])
    with pytest.raises(ValueError, match="exo"):
        ls.solve(free, method="exo")


def test_a_square_wave_on_a_chain_matches_the_same_force_given_as_samples():
    # the sampled route (double-double segment maps, exact for a zero-order hold) is an
    # independent route: a square wave is exactly the held samples 1, 0, 1, 0, ...
    n = 12
    masses = {f"m{i}": 1 for i in range(n)}
    springs = {"k0": ("wall", "m0", 2), **{f"k{i}": (f"m{i-1}", f"m{i}", 1) for i in range(1, n)}}
    dashpots = {"c0": ("wall", "m0", "1/10"), "c1": (f"m{n-1}", "wall", "1/5")}

    def scene(force):
        return ls.Scene.from_components(masses=masses, springs=springs, dashpots=dashpots,
                                        x0=[1] + [0] * (n - 1), v0=[0] * n,
                                        forcing=[force] + ["0"] * (n - 1))
    times = np.array([0.5, 3.25, 7.0, 11.5, 19.75])
    ours = ls.solve(scene("square_wave(1, 2)"))
    assert ours.method.endswith("+exo")
    values, bounds = ours.evaluate(times, return_error=True)
    steps = np.arange(0, 21)
    samples = ls.solve(scene(ls.sampled(steps, (steps % 2 == 0).astype(float), kind="zoh")))
    reference, reference_bounds = samples.evaluate(times, return_error=True)
    assert np.all(np.abs(values - reference) <= bounds + reference_bounds)
    assert bounds.max() < 1e-12


def test_digits_of_a_forced_pair_match_the_exact_route_at_30_digits(small):
    scene = ls.Scene.from_matrices(M=[[1, 0], [0, "1/2"]], C=[["1/5", 0], [0, "1/10"]],
                                   K=[[3, -1], [-1, 1]], x0=[1, 0], v0=[0, "1/2"],
                                   forcing=["cos(3*t) + square_wave(1, 2)", "0"])
    values, bounds = ls.solve(scene, method="exo").evaluate(["1.5", "3.7"], dps=30,
                                                            return_error=True)
    reference = ls.solve(scene, method="exact").evaluate(["1.5", "3.7"], dps=40)
    for i in range(2):
        for j in range(2):
            assert abs(values[i, j] - reference[i, j]) <= bounds[i, j]
            assert bounds[i, j] < 1e-28

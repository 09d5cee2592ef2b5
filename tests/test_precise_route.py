"""The ball-arithmetic modal route for stiff, widely scaled scenes (precise_route.py).

References are python-flint's certified arb matrix exponential of the first-order
system (reference_motion_arb), a route with no eigen-decomposition at all.
"""

from __future__ import annotations

from itertools import pairwise

import numpy as np
import pytest

from laplace_springs import Scene, solve
from laplace_springs.numeric.balls import PreciseModes, decompose_precise, solve_precise
from laplace_springs.bench.reference import reference_motion_arb, relative_error


def chain(n: int, *, stiff: str = "1", light: str = "1", damping: str = "1/100", ends=("wall", "wall")):
    """n masses between the ends; odd springs have stiffness ``stiff``, odd masses ``light``."""
    masses = {f"m{i + 1}": (light if i % 2 else "1") for i in range(n)}
    nodes = [ends[0], *masses, ends[1]]
    links = [(a, b) for a, b in pairwise(nodes) if "free" not in (a, b)]
    springs = {f"k{i + 1}": (a, b, stiff if i % 2 else "1") for i, (a, b) in enumerate(links)}
    dashpots = {f"c{i + 1}": (a, b, damping) for i, (a, b) in enumerate(links)}
    return Scene.from_components(masses=masses, springs=springs, dashpots=dashpots,
                                 x0=[1] + [0] * (n - 1), v0=[0] * (n - 1) + ["1/2"])


def _check(scene, times, bound=1e-14, sol=None):
    """sol (auto by default) within ``bound`` of the arb reference and within its own error."""
    sol = solve(scene) if sol is None else sol
    values, errors = sol.evaluate(times, return_error=True)
    reference = reference_motion_arb(scene, list(times), digits=25)
    actual = np.abs(values - reference.astype(float))
    assert relative_error(values, reference) < bound
    assert np.all(actual <= errors + 1e-300)
    return sol


def test_auto_takes_the_ball_route_on_a_stiff_twenty_mass_chain():
    scene = chain(20, stiff="100000000")
    sol = _check(scene, np.linspace(0, 20, 40))
    assert sol.method == "numeric" and isinstance(sol.modes, PreciseModes)
    assert "ball arithmetic" in sol.reason


def test_mass_ratio_one_in_a_million_over_a_long_horizon():
    _check(chain(10, light="1/1000000"), np.array([0.0, 0.5, 3.0, 100.0, 2500.0]))


def test_ball_route_matches_the_reference_on_a_massless_node():
    # a Maxwell element (spring in series with a dashpot) between two stiff-coupled masses
    scene = Scene.from_components(
        masses={"m1": 1, "m2": "1/1000", "n": 0},
        springs={"k1": ("wall", "m1", 1), "k2": ("m1", "m2", 10**8), "k3": ("m2", "n", 3)},
        dashpots={"c1": ("n", "wall", "1/2")}, x0=[1, 0, 0], v0=[0, 1, 0])
    _check(scene, np.array([0.0, 0.25, 2.0, 9.0]), 1e-14, solve_precise(scene, reason="test"))


def test_verify_passes_on_the_ball_route():
    assert solve_precise(chain(6, stiff="1000000"), reason="test").verify()


@pytest.mark.parametrize("scene", [
    Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[0]),          # critical damping
    Scene.from_matrices(M=[[1, 0], [0, 1]], K=[[1, 0], [0, 1]], x0=[1, 1], v0=[0, 0]),  # equal frequencies
])
def test_repeated_eigenvalues_are_declined(scene):
    assert decompose_precise(scene) is None


def test_well_conditioned_large_scenes_stay_on_the_float_route():
    sol = solve(chain(12))
    assert sol.method == "numeric" and not isinstance(sol.modes, PreciseModes)


def test_free_free_stiff_chain_splits_off_its_rigid_motion():
    # springs 1 and 1e8 alternate, no walls: the double pole at 0 is split off exactly
    scene = chain(20, stiff="100000000", ends=("free", "free"))
    sol = _check(scene, np.array([0.0, 0.3, 2.0, 7.5, 40.0]))
    assert isinstance(sol.modes, PreciseModes) and sol.modes.split is not None
    assert np.sum(np.abs(sol.poles) < 1e-12) == 2


def test_two_free_masses_joined_by_a_dashpot_only():
    # K = 0: the inner scene keeps a simple pole at 0 and one at -c(1/m1 + 1/m2)
    scene = Scene.from_matrices(M=[[1, 0], [0, 3]], C=[["1/2", "-1/2"], ["-1/2", "1/2"]],
                                x0=[1, -1], v0=[2, 0])
    sol = _check(scene, np.array([0.0, 1.0, 10.0, 100.0]), 1e-15, solve_precise(scene, reason="test"))
    assert sol.verify()


def test_float_evaluation_escalates_over_a_long_horizon():
    # a lightly damped 20-mass chain: float64 rates drift by ~1e-15·t, so at t = 1e5 the
    # float route's own estimate exceeds 1e-13 and evaluate switches to ball arithmetic
    scene = chain(20, damping="1/1000")
    sol = solve(scene)
    assert not isinstance(sol.modes, PreciseModes)
    _check(scene, np.array([0.0, 1.0, 3.0e4, 1.0e5]), 1e-15, sol)


def test_float_route_block_spanning_decades_stays_finite():
    # mass ratio 1e-6 in a 20-mass chain: one block holds poles from -2e4 to ~0; its
    # exponential is taken relative to its rightmost rate (it used to overflow to NaN)
    from laplace_springs.numeric.modal import solve_numeric

    scene = chain(20, light="1/1000000")
    times = np.linspace(0.0, 20.0, 9)
    values, errors = solve_numeric(scene).modes.values_and_errors(times)
    reference = reference_motion_arb(scene, list(times), digits=20).astype(float)
    assert np.all(np.isfinite(values)) and np.all(np.abs(values - reference) <= errors)

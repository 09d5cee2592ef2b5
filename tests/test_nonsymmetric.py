"""Non-symmetric M, C, K: what is accepted (see the scenes guide, "Non-symmetric matrices").

- A gyroscopic C (antisymmetric part G = -Gᵀ) and a circulatory K (antisymmetric part) are real
  physics: every route solves them, checked against the arb matrix-exponential reference and,
  for the gyroscopic case, against conservation of energy (G does no work).
- A non-symmetric M given as a matrix is refused; the seed's non-symmetric A = M⁻¹K enters
  through ``Scene.from_normalized`` (M = I), and equations with a non-symmetric invertible M
  are solved for the accelerations by ``Scene.from_equations``.
"""

from __future__ import annotations

import numpy as np
import pytest

from laplace_springs import Scene, SceneError, solve
from laplace_springs.bench.reference import reference_motion_arb

TIMES = np.array([0.0, 0.7, 2.5, 9.0])
ROUTES = ("exact", "modal", "certified")


def gyroscopic_pair() -> Scene:
    """A spinning rotor's two tilts: M = I, C = [[0, 2], [-2, 0]] (Coriolis), K = diag(3, 5)."""
    return Scene.from_matrices(M=[[1, 0], [0, 1]], C=[[0, 2], [-2, 0]], K=[[3, 0], [0, 5]],
                               x0=[1, 0], v0=[0, "1/2"])


def follower_pair() -> Scene:
    """A circulatory (follower) force: K = [[2, 1], [-1, 2]], lightly damped."""
    return Scene.from_matrices(M=[[1, 0], [0, 2]], C=[["1/10", 0], [0, "1/10"]],
                               K=[[2, 1], [-1, 2]], x0=[1, 0], v0=[0, 0])


@pytest.mark.parametrize("route", ROUTES)
@pytest.mark.parametrize("build", [gyroscopic_pair, follower_pair])
def test_gyroscopic_and_circulatory_scenes_solve_on_every_route(build, route):
    scene = build()
    values, bounds = solve(scene, method=route).evaluate(TIMES, return_error=True)
    reference = reference_motion_arb(scene, list(TIMES), digits=30).astype(float)
    assert np.all(np.abs(values - reference) <= bounds + 1e-300)
    assert np.max(np.abs(values - reference)) < 1e-12


def test_gyroscopic_forces_do_no_work():
    # E = ½ẋᵀẋ + ½xᵀKx is constant when C is antisymmetric and K symmetric
    sol = solve(gyroscopic_pair())
    x = sol.evaluate(TIMES)
    v = sol.evaluate(TIMES, derivative=1)
    K = np.diag([3.0, 5.0])
    energy = 0.5 * np.sum(v * v, axis=0) + 0.5 * np.einsum("it,ij,jt->t", x, K, x)
    assert energy == pytest.approx(np.full(len(TIMES), 0.5 * 3 + 0.5 * 0.25), rel=1e-13)


def test_the_circulatory_scene_flutters():
    # K's antisymmetric part feeds energy in: with light damping the motion grows (a known
    # instability of follower forces), and the exact route says so with a positive growth rate
    poles = solve(follower_pair(), method="certified").poles
    assert max(poles.real) > 0


@pytest.mark.parametrize("M", [[[1, 1], [0, 1]], [[2, "1/2"], [0, 1]], [["m", 1], [0, "m"]]])
def test_a_non_symmetric_mass_matrix_is_refused(M):
    with pytest.raises(SceneError, match=r"M must be symmetric .* M\[0,1\] = .* but M\[1,0\] = .*from_normalized"):
        Scene.from_matrices(M=M, K=[[1, 0], [0, 1]], x0=[1, 0], v0=[0, 0], parameters=["m"])


def test_the_seeds_non_symmetric_A_is_the_normalized_form():
    scene = Scene.from_normalized(A=[[3, -1], [-2, 2]], x0=[1, 0], v0=[0, 1])
    reference = reference_motion_arb(scene, list(TIMES), digits=30).astype(float)
    assert np.max(np.abs(solve(scene).evaluate(TIMES) - reference)) < 1e-13


def test_equations_with_a_non_symmetric_mass_matrix_are_solved_for_the_accelerations():
    """2x'' + y'' + 2x − y = 0 and y'' − x + 2y = 0 (M = [[2, 1], [0, 1]]) were refused for
    a non-symmetric M. By hand: y'' = x − 2y and x'' = (−2x + y − y'')/2 = −3x/2 + 3y/2,
    the seed's normalized form with A = [[3/2, −3/2], [−1, 2]] (the reference)."""
    scene = Scene.from_equations(["2*x'' + y'' + 2*x - y = 0", "y'' - x + 2*y = 0"],
                                 coordinates=["x", "y"], x0={"x": 1, "y": 0},
                                 v0={"x": 0, "y": "1/2"})
    by_hand = Scene.from_normalized(A=[["3/2", "-3/2"], [-1, 2]], x0=[1, 0], v0=[0, "1/2"])
    reference = reference_motion_arb(by_hand, list(TIMES), digits=30).astype(float)
    assert np.max(np.abs(solve(scene).evaluate(TIMES) - reference)) < 1e-13

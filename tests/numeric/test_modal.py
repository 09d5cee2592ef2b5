"""The modal route (float64 eigen-decomposition) against independent references.

References: mpmath's expm of the first-order system (reference_motion), python-flint's
certified arb matrix exponential (reference_motion_arb), and textbook closed forms
evaluated with mpmath. Never the route's own formulas.
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
import sympy as sp

from laplace_springs import ModalSolution, Scene, SceneError, bundled_scenes, load_scene, solve, t
from laplace_springs.bench.reference import reference_motion, reference_motion_arb, relative_error


def solve_numeric(scene: Scene) -> ModalSolution:
    sol = solve(scene, method="modal")
    assert isinstance(sol, ModalSolution)
    return sol

TIMES = np.array([0.0, 0.3, 1.0, 2.5, 7.0, 15.0, 40.0])


def chain(n: int, *, damping="1/20", walls: bool = True, ground=None) -> Scene:
    """n unit masses joined by unit springs (and dashpots), walls at both ends if ``walls``."""
    masses = {f"m{i + 1}": 1 for i in range(n)}
    nodes = ["wall", *masses, "wall"] if walls else list(masses)
    springs = {f"k{i}": (a, b, 1) for i, (a, b) in enumerate(zip(nodes, nodes[1:]))}
    dashpots = {f"c{i}": (a, b, damping) for i, (a, b) in enumerate(zip(nodes, nodes[1:])) if damping}
    if ground:
        dashpots.update({f"g{i}": ("ground", m, ground) for i, m in enumerate(masses)})
    x0 = {"m1": 1, f"m{n // 2 + 1}": "-1/2"}
    return Scene.from_components(masses=masses, springs=springs, dashpots=dashpots, x0=x0,
                                 v0={f"m{n}": "1/3"})


def secular(expr: sp.Expr) -> bool:
    """Whether t occurs outside exp/cos/sin (a t^k factor)."""
    dummies = {f: sp.Dummy() for f in expr.atoms(sp.exp, sp.cos, sp.sin)}
    return expr.xreplace(dummies).has(t)


# ----------------------------------------------------------------------------- accuracy


@pytest.mark.parametrize("name", sorted(bundled_scenes()))
def test_bundled_scenes_match_mpmath_expm(name):
    scene = load_scene(name)
    sol = solve_numeric(scene)
    assert relative_error(sol.evaluate(TIMES), reference_motion(scene, list(TIMES), dps=30)) < 1e-12
    assert sol.verify()


@pytest.mark.parametrize("n", [8, 20, 50])
def test_damped_chains_match_arb_expm(n):
    scene = chain(n, ground="1/50")
    times = np.array([0.0, 1.5, 9.0, 60.0])
    sol = solve_numeric(scene)
    values, errors = sol.evaluate(times, return_error=True)
    error = relative_error(values, reference_motion_arb(scene, list(times), digits=20))
    assert error < 1e-12
    assert np.max(errors) / np.max(np.abs(values)) < 1e-10  # the estimate is honest and small


def test_critical_damping_is_one_defective_pole():
    # x'' + 2x' + x = 0, x(0) = 1, v(0) = -3: x = (1 - 2t) e^{-t} (textbook)
    sol = solve_numeric(Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[-3]))
    np.testing.assert_allclose(sol.poles, [-1, -1], atol=1e-12)
    with mpmath.workdps(30):
        expected = [float((1 - 2 * mpmath.mpf(v)) * mpmath.exp(-mpmath.mpf(v))) for v in TIMES]
    assert relative_error(sol.evaluate(TIMES)[0], expected) < 1e-14
    assert secular(sol.x[0])


@pytest.mark.parametrize("c", ["1.99999999999998", "2.00000000000002", "1.999998", "2.002"])
def test_near_critical_damping_both_sides(c):
    scene = Scene.from_matrices(M=[[1]], C=[[c]], K=[[1]], x0=[1], v0=["1/7"])
    sol = solve_numeric(scene)
    assert relative_error(sol.evaluate(TIMES), reference_motion_arb(scene, list(TIMES), digits=25)) < 1e-12


def test_exceptional_point():
    # det(λ²I + λC + K) = (λ² + λ + 1)²; λ²I + λC + K has rank 1 at the roots: defective pair
    scene = Scene.from_matrices(M=[[1, 0], [0, 1]], C=[[2, 0], [0, 0]], K=[[2, -1], [-1, 1]],
                                x0=[1, 0], v0=[0, 1])
    sol = solve_numeric(scene)
    root = complex(-0.5, np.sqrt(3) / 2)
    poles = sorted(sol.poles, key=lambda z: z.imag)
    np.testing.assert_allclose(poles, [root.conjugate()] * 2 + [root] * 2, atol=1e-10)
    assert relative_error(sol.evaluate(TIMES), reference_motion(scene, list(TIMES), dps=30)) < 1e-12
    assert all(secular(row) for row in sol.x)
    assert sol.verify()


def test_free_free_chain_has_rigid_body_motion():
    scene = chain(6, damping="1/10", walls=False)
    sol = solve_numeric(scene)
    assert np.sum(np.abs(sol.poles) < 1e-9) == 2  # the double (defective) pole at 0
    assert relative_error(sol.evaluate(TIMES), reference_motion_arb(scene, list(TIMES), digits=20)) < 1e-12
    # momentum: the centre of mass moves at v0 total / total mass = (1/3)/6
    centre = sol.evaluate([0.0, 40.0]).mean(axis=0)
    assert centre[1] - centre[0] == pytest.approx(40 * (1 / 3) / 6, rel=1e-12)


def test_free_mass_with_dashpot():
    # x'' + x' = 0, x(0) = 1, v(0) = 2: x = 3 - 2 e^{-t}
    sol = solve_numeric(Scene.from_matrices(M=[[1]], C=[[1]], x0=[1], v0=[2]))
    assert relative_error(sol.evaluate(TIMES)[0], 3 - 2 * np.exp(-TIMES)) < 1e-14


def test_free_mass_moves_uniformly():
    sol = solve_numeric(Scene.from_matrices(M=[[2]], x0=[1], v0=[-1]))
    np.testing.assert_allclose(sol.evaluate(TIMES)[0], 1 - TIMES, rtol=1e-14, atol=1e-14)


def test_equal_frequencies_give_no_secular_terms():
    scene = Scene.from_matrices(M=[[1, 0, 0], [0, 1, 0], [0, 0, 1]],
                                C=[["0.1", 0, 0], [0, "0.1", 0], [0, 0, "0.1"]],
                                K=[[2, -1, -1], [-1, 2, -1], [-1, -1, 2]], x0=[1, 0, 0], v0=[0, 0, 1])
    sol = solve_numeric(scene)
    assert not any(secular(row) for row in sol.x)
    assert relative_error(sol.evaluate(TIMES), reference_motion(scene, list(TIMES), dps=30)) < 1e-12


def test_heavy_damping_keeps_the_slow_pole():
    # x'' + 1e6 x' + x = 0, x(0) = 1: two real exponentials, rates from the stable root formula
    sol = solve_numeric(Scene.from_matrices(M=[[1]], C=[[10**6]], K=[[1]], x0=[1], v0=[0]))
    times = [0.0, 1e-6, 1e-3, 1.0, 1e3, 1e6]
    with mpmath.workdps(40):
        q = -(10**6 + mpmath.sqrt(mpmath.mpf(10) ** 12 - 4)) / 2
        slow, fast = 1 / q, q
        a = fast / (fast - slow)  # x(0) = 1, x'(0) = 0
        expected = [a * mpmath.exp(slow * v) + (1 - a) * mpmath.exp(fast * v) for v in times]
    assert relative_error(sol.evaluate(times)[0], expected) < 1e-12
    assert abs(sol.poles.real.max() - float(slow)) < 1e-15 * 1e-6


def test_closed_form_agrees_with_the_reference():
    # the Float closed form (what x is for scenes too large for an exact one)
    scene = load_scene("three-dashpots")
    form = solve_numeric(scene).motion.closed_form()
    assert form.atoms(sp.Float) and not form.has(sp.CRootOf)
    f = sp.lambdify(t, form, "mpmath")
    values = np.array([[float(v) for v in f(mpmath.mpf(tv))] for tv in TIMES]).T
    assert relative_error(values, reference_motion(scene, list(TIMES), dps=30)) < 1e-12


def test_dps_evaluation_is_certified():
    scene = load_scene("wall-pair-dashpot")
    values, errors = solve_numeric(scene).evaluate([0.5, "2.25", 10], dps=40, return_error=True)
    reference = reference_motion(scene, [0.5, "2.25", 10], dps=60)
    assert values.dtype == object and isinstance(values[0, 0], mpmath.mpf)
    assert relative_error(values, reference) < 1e-38
    assert np.max(errors) < 1e-38


def test_error_estimate_bounds_the_error():
    for scene in (load_scene("vertical-pair-damped"), chain(10, damping="1/7")):
        values, errors = solve_numeric(scene).evaluate(TIMES, return_error=True)
        reference = reference_motion_arb(scene, list(TIMES), digits=25)
        actual = np.abs(values - reference.astype(float))
        assert np.all(actual <= errors + 1e-300)


# ----------------------------------------------------------------------------- interface


def test_interface_and_verify():
    scene = load_scene("vertical-pair-damped")
    sol = solve_numeric(scene)
    assert sol.method in ("classical", "chebyshev", "modal") and "method='modal' was requested" in sol.reason
    assert "modal" in repr(sol)
    assert sol.evaluate(TIMES).shape == (2, len(TIMES)) and sol.evaluate(1.0).shape == (2, 1)
    assert sol.poles.dtype == complex and len(sol.poles) == 4
    # up to EXACT_FORM_MAX_COORDINATES coordinates x is the exact closed form, built on request
    assert sol.x == solve(scene, method="exact").x
    check = sol.verify()
    assert check and check.ode_residual < 1e-12 and check.initial_residual < 1e-12


def test_verify_catches_a_wrong_solution():
    scene = load_scene("vertical-pair-damped")
    other = solve_numeric(scene.with_initial(x0=[0, 1]))
    wrong = ModalSolution(scene, other.motion, reason="wrong initial data")
    wrong.requested = other.method  # evaluate with this (wrong) motion, not another engine's
    assert not wrong.verify()


def test_symbolic_scene_is_refused_by_name():
    scene = Scene.from_matrices(M=[[1, 0], [0, "m"]], K=[[2, -1], [-1, "k"]], x0=[1, 0], v0=[0, 0],
                                parameters=["m", "k"])
    with pytest.raises(SceneError, match=r"M\[1,1\] = m.*K\[1,1\] = k"):
        solve(scene, method="modal")


def maxwell(k_spring_only: bool = False) -> Scene:
    """wall - k1 - massless node - dashpot c - mass m - k2 - wall (a Maxwell element)."""
    C = [[0, 0], [0, 0]] if k_spring_only else [[2, -2], [-2, 2]]
    return Scene.from_matrices(M=[[0, 0], [0, 1]], C=C, K=[[3, -1 if k_spring_only else 0],
                                                            [-1 if k_spring_only else 0, 1]],
                               x0=["1/2", 1], v0=[0, "-1/3"])


def test_massless_node_held_by_a_dashpot():
    scene = maxwell()
    sol = solve_numeric(scene)
    assert len(sol.poles) == 3  # deg Δ = 2·1 + 1
    assert relative_error(sol.evaluate(TIMES), reference_motion_arb(scene, list(TIMES), digits=25)) < 1e-12
    decimals = [repr(float(v)) for v in TIMES]  # the same decimal times for both routes
    values = sol.evaluate(decimals, dps=30)
    assert relative_error(values, reference_motion_arb(scene, decimals, digits=35)) < 1e-28
    assert sol.verify()


def test_massless_node_without_a_dashpot_is_refused_clearly():
    with pytest.raises(SceneError, match="massless"):
        solve(maxwell(k_spring_only=True), method="modal")


def test_a_whole_block_bounds_its_own_exponential():
    # found by tests/test_properties.py: a 3-mass scene held as one 6 x 6 block; its
    # perturbed decompositions share e^{Tt}'s rounding, so the sampled bound (4.1e-15)
    # missed the true error (1.05e-14 at t = 3): every value within its bound, against
    # flint's arb matrix exponential
    scene = Scene.from_matrices(M=[[1, 0, 0], [0, 3, 0], [0, 0, 1]],
                                C=[["15/4", "-1/2", -2], ["-1/2", 2, 0], [-2, 0, "7/2"]],
                                K=[["3/2", -1, "-1/2"], [-1, "31/12", "-1/3"], ["-1/2", "-1/3", "7/6"]],
                                x0=[0, 0, 1], v0=[0, 0, 0])
    times = [0.4, 1.1, 3.0, 8.5]
    motion = solve(scene, method="modal").motion
    reference = np.array(reference_motion_arb(scene, times, digits=30), dtype=float)
    assert np.all(np.abs(motion.values(np.array(times)) - reference) <= motion.bound(np.array(times)))

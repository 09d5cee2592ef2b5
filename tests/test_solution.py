"""solve() on every bundled scene against an independent 40-digit matrix exponential."""

from __future__ import annotations

import dataclasses
import math
import warnings

import mpmath
import numpy as np
import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.bench.reference import reference_motion, relative_error
from laplace_springs.planning import ENGINE_NAMES

BUNDLED = ["vertical-pair", "vertical-pair-damped", "wall-pair", "wall-pair-dashpot",
           "three-dashpots"]
# decimal strings: the same exact times for the routes, the closed form and the reference
TIMES = ["0", "0.35", "1", "2.5", "7.75", "15"]


@pytest.fixture(scope="module", params=BUNDLED)
def solved(request):
    scene = ls.load_scene(request.param)
    return scene, ls.solve(scene), reference_motion(scene, TIMES)


def test_float64_evaluation_matches_reference(solved):
    scene, sol, ref = solved
    values = sol.evaluate(TIMES)
    assert values.shape == (scene.n, len(TIMES)) and values.dtype == float
    assert relative_error(values, ref) < 1e-13


def test_high_precision_evaluation_matches_reference(solved):
    _, sol, ref = solved
    assert relative_error(sol.evaluate(TIMES, dps=30), ref) < 1e-27


def test_exact_expression_matches_reference(solved):
    _, sol, ref = solved
    exact = np.array([[sp.N(e.subs(ls.t, sp.Rational(tv)), 35) for tv in TIMES] for e in sol.x])
    assert relative_error(exact, ref) < 1e-30


def test_closed_form_is_real_and_heaviside_free(solved):
    _, sol, _ = solved
    assert not sol.x.has(sp.I, sp.Heaviside, sp.Float, sp.DiracDelta)


def test_verify_accepts_the_solution(solved):
    _, sol, _ = solved
    assert sol.verify()


def test_verify_rejects_a_wrong_solution():
    sol = ls.solve(ls.load_scene("vertical-pair-damped"), method="exact")
    piece = sol.pieces[0]
    first = piece.terms[0][0]
    broken = dataclasses.replace(first, alpha=first.alpha * sp.Rational(101, 100))
    terms = ((broken, *piece.terms[0][1:]), *piece.terms[1:])
    motion = dataclasses.replace(sol.motion, pieces=(dataclasses.replace(piece, terms=terms),))
    report = ls.ExactSolution(motion, reason="tampered").verify()
    assert not report and report.ode_residual > 1e-6


def test_undamped_scene_has_no_exponentials():
    sol = ls.solve(ls.load_scene("wall-pair"))
    assert not sol.x.has(sp.exp)


def test_irreducible_quartic_uses_algebraic_numbers():
    sol = ls.solve(ls.load_scene("three-dashpots"))
    assert sol.x.has(sp.CRootOf)
    assert ls.resolvent(sol.scene).determinant.factor_list()[1][0][0].degree() == 4


@pytest.mark.parametrize("M, C, K, x0, v0, expected", [
    # critically damped mass: x'' + 2x' + x = 0 (textbook: (x0 + (v0 + x0) t) e^{-t})
    ([[1]], [[2]], [[1]], [1], [0], (1 + ls.t) * sp.exp(-ls.t)),
    # free body with a dashpot only: x'' + x' = 0, x(0) = 0, x'(0) = 1 -> 1 - e^{-t}
    ([[1]], [[1]], None, [0], [1], 1 - sp.exp(-ls.t)),
    # overdamped: x'' + 3x' + 2x = 0, x(0) = 1 -> 2e^{-t} - e^{-2t}
    ([[1]], [[3]], [[2]], [1], [0], 2 * sp.exp(-ls.t) - sp.exp(-2 * ls.t)),
])
def test_single_mass_textbook_cases(M, C, K, x0, v0, expected):
    sol = ls.solve(ls.Scene.from_matrices(M=M, C=C, K=K, x0=x0, v0=v0))
    assert sp.simplify(sol.x[0] - expected) == 0


def test_latex_has_one_line_per_coordinate():
    text = ls.solve(ls.load_scene("vertical-pair")).latex()
    assert text.count(r"(t) &=") == 2 and "x_{1}(t)" in text
    assert r"\sin" in text and r"\cos" in text


def test_unknown_method_is_an_error():
    with pytest.raises(ValueError, match="method"):
        ls.solve(ls.load_scene("vertical-pair"), method="magic")


@pytest.mark.parametrize("times", [[0, 1, 2], np.arange(3), np.array([0.0, 1.0, 2.0]),
                                   ["0", "1", "2"], [sp.Integer(0), 1, sp.Rational(2)]])
def test_high_precision_evaluation_accepts_any_kind_of_time(times):
    scene = ls.Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[0])
    values = ls.solve(scene).evaluate(times, dps=25)
    with mpmath.workdps(40):  # critically damped mass: (1 + t) e^{-t}
        expected = [(1 + tv) * mpmath.exp(-tv) for tv in range(3)]
        assert all(abs(v - e) < 1e-24 for v, e in zip(values[0], expected))


def test_auto_takes_the_modal_route_for_large_numeric_scenes():
    n = 12
    K = [[2 if i == j else -1 if abs(i - j) == 1 else 0 for j in range(n)] for i in range(n)]
    M = [[1 if i == j else 0 for j in range(n)] for i in range(n)]
    scene = ls.Scene.from_matrices(M=M, C=[["0.1" if i == j else 0 for j in range(n)]
                                           for i in range(n)], K=K,
                                   x0=[1] + [0] * (n - 1), v0=[0] * n)
    sol = ls.solve(scene)
    assert sol.method in ("classical", "chebyshev", "modal") and "12 coordinates" in sol.reason
    times = [0.0, 1.5, 7.0]
    assert relative_error(sol.evaluate(times), reference_motion(scene, times)) < 1e-12
    small = ls.solve(ls.load_scene("wall-pair"))
    assert small.method in ENGINE_NAMES
    with pytest.raises(ls.SceneError, match="modal route cannot take this scene: .*is forced"):
        ls.solve(scene.with_forcing({"x1": "cos(t)"}), method="modal")
    with pytest.raises(ValueError, match="method must be one of"):
        ls.solve(scene, method="fast")


def test_exact_solution_subs_solves_again_so_critical_damping_stays_exact():
    scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[[1]], x0=[1], v0=[0], parameters=["c"])
    generic = ls.solve(scene)
    critical = generic.subs({"c": 2})  # x'' + 2x' + x = 0, x(0) = 1: the textbook (1 + t)e^{-t}
    assert sp.simplify(critical.x[0] - (1 + ls.t) * sp.exp(-ls.t)) == 0
    assert critical.evaluate([1.0])[0, 0] == pytest.approx(2 * math.exp(-1), rel=1e-15)
    with pytest.raises(ls.SceneError, match="'k' is not a parameter of this scene"):
        generic.subs({"k": 1})
    numeric = ls.solve(scene.subs({"c": 1}), method="modal")
    with pytest.raises(ls.SceneError, match="'c' is not a parameter of this scene; its parameters are none"):
        numeric.subs({"c": 2})


def test_evaluating_a_scene_with_parameters_names_them():
    sol = ls.solve(ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[["k"]], x0=[1], v0=[0],
                                          parameters=["k", "c"]))
    with pytest.raises(ls.SceneError, match="evaluate needs numbers, but the scene has the "
                                            "parameters c, k"):
        sol.evaluate([1.0])
    assert sol.subs({"k": 4, "c": "1/10"}).evaluate([0.0]).tolist() == [[1.0]]


def test_initial_data_a_massless_node_cannot_keep_are_named_not_dropped_silently():
    """x2 has no mass and no dashpot: −x1 + x2 = 0 sets x2(0⁺) = x1(0) = 1 (by hand), so the
    given x0[x2] = 5 and v0[x2] = 3 are not kept; the solution says so and warns."""
    scene = ls.Scene.from_matrices(M=[[1, 0], [0, 0]], K=[[2, -1], [-1, 1]], x0=[1, 5],
                                   v0=[0, 3])
    with pytest.warns(ls.InitialDataWarning) as caught:
        sol = ls.solve(scene)
    messages = [str(w.message) for w in caught]
    assert any("x0[x2] = 5 is not kept" in m and "x2(0⁺) = 1" in m for m in messages)
    assert any("v0[x2] = 3 is not kept" in m for m in messages)
    assert "note: x0[x2] = 5 is not kept" in sol.reason
    # x1'' + x1 = 0 with x1(0) = 1: cos t, and x2 follows x1
    assert np.allclose(sol.evaluate([0.5]), np.cos(0.5), rtol=1e-14)
    # a dashpot holds the node: x0 kept, the given velocity is not
    held = ls.Scene.from_matrices(M=[[1, 0], [0, 0]], C=[[0, 0], [0, 1]], K=[[2, -1], [-1, 1]],
                                  x0=[1, 5], v0=[0, 7])
    with pytest.warns(ls.InitialDataWarning, match=r"v0\[x2\] = 7 is not kept"):
        ls.solve(held)


def test_consistent_initial_data_at_massless_nodes_give_no_warning():
    scene = ls.Scene.from_matrices(M=[[1, 0], [0, 0]], K=[[2, -1], [-1, 1]], x0=[1, 1],
                                   v0=[0, 0])
    with warnings.catch_warnings():
        warnings.simplefilter("error", ls.InitialDataWarning)
        sol = ls.solve(scene)
    assert "not kept" not in sol.reason


@pytest.mark.parametrize(("asked", "host"), [("ball", "certified"), ("mp", "exact")])
def test_the_arbitrary_precision_engines_asked_by_name_are_served_by_their_host(asked, host):
    """They have no float64 values of their own: solve(method='mp') refused with every
    other engine's refusal (found by the numeric attack); their host serves, digits too."""
    scene = ls.load_scene("wall-pair")
    sol = ls.solve(scene, method=asked)
    assert sol.method == host and f"method='{asked}' was requested" in sol.reason
    times = [0.5, 3.0]
    reference = reference_motion(scene, times, dps=40)
    values, bounds = sol.evaluate(times, return_error=True)
    assert np.all(np.abs(values - reference.astype(float)) <= bounds)
    digits = sol.evaluate(times, dps=25)
    assert all(abs(digits[i, j] - reference[i, j]) < mpmath.mpf(10) ** -23
               for i in range(2) for j in range(2))

"""Scenes with irrational entries (√2, π, e, √2 + ∛3): served by some engine in auto mode,
and accurate within their bounds.

Before: a forced scene with an irrational mass raised a LimitError in auto mode (the exact
route refuses a factor of degree ≥ 3 with irrational coefficients only when it builds, and
the exo engine declined every scene below Limits.exo_min_coordinates); an evaluation of a
free irrational scene that escalated raised the exact route's InversionError; and the
exact route spent 5-25 s simplifying in SymPy's EX domain before refusing √2 + ∛3.

Reference: the first-order system integrated by mpmath's Taylor-series ODE solver
(``mpmath.odefun``) at 25 digits, written here from the scene's numbers: it shares nothing
with the package's routes.
"""

from __future__ import annotations

import time
import warnings

import mpmath
import numpy as np
import pytest
import sympy as sp

import laplace_springs as ls

TIMES = [0.5, 2.0, 6.0]


def reference(M: list, C: list, K: list, x0: list, forcing: list, times: list[float]
              ) -> np.ndarray:
    """x(t) of M x'' + C x' + K x = f(t) from rest velocity, x(0) = x0 (diagonal M), by
    mpmath.odefun at 25 digits. ``forcing`` holds callables of an mpf time (or 0)."""
    n = len(M)
    with mpmath.workdps(25):
        m = [mpmath.mpmathify(sp.N(M[i][i], 40)) for i in range(n)]
        c = [[mpmath.mpmathify(sp.N(v, 40)) for v in row] for row in C]
        k = [[mpmath.mpmathify(sp.N(v, 40)) for v in row] for row in K]

        def rhs(t, y):
            x, v = y[:n], y[n:]
            acc = [((forcing[i](t) if forcing[i] else 0)
                    - mpmath.fsum(c[i][j] * v[j] + k[i][j] * x[j] for j in range(n))) / m[i]
                   for i in range(n)]
            return list(v) + acc

        solution = mpmath.odefun(rhs, 0, [mpmath.mpf(v) for v in x0] + [0] * n)
        return np.array([[float(solution(t)[i]) for t in times] for i in range(n)])


PAIR_C = [[1, 0], [0, 0]]
PAIR_K = [[2, -1], [-1, 2]]


@pytest.mark.parametrize("mass", [sp.sqrt(2), sp.pi, sp.sqrt(2) + sp.cbrt(3)],
                         ids=["sqrt2", "pi", "sqrt2+cbrt3"])
def test_forced_pair_with_an_irrational_mass_is_served_within_its_bound(mass):
    M = [[mass, 0], [0, 1]]
    scene = ls.Scene.from_matrices(M=M, C=PAIR_C, K=PAIR_K, x0=[1, 0], v0=[0, 0],
                                   forcing=["cos(t)", 0])
    start = time.perf_counter()
    sol = ls.solve(scene)
    took = time.perf_counter() - start
    values, bounds = sol.evaluate(TIMES, return_error=True)
    expected = reference(M, PAIR_C, PAIR_K, [1, 0], [mpmath.cos, 0], TIMES)
    assert "exo" in sol.method
    assert "irrational" in sol.reason  # why the exact route declined
    assert np.all(np.abs(values - expected) <= bounds)
    assert np.max(bounds) <= 1e-13 * max(1.0, float(np.max(np.abs(expected))))
    assert took < 20  # no minutes of simplification before the exact route refuses


def test_forced_single_irrational_mass_is_exact_when_its_factor_is_quadratic():
    """One mass: Δ = √2 λ² + λ + 2 has degree 2, solved in closed form; the forcing
    cos t adds λ² + 1."""
    M, C, K = [[sp.sqrt(2)]], [[1]], [[2]]
    sol = ls.solve(ls.Scene.from_matrices(M=M, C=C, K=K, x0=[1], v0=[0], forcing=["cos(t)"]))
    values, bounds = sol.evaluate(TIMES, return_error=True)
    expected = reference(M, C, K, [1], [mpmath.cos], TIMES)
    assert np.all(np.abs(values - expected) <= bounds)


def test_critical_damping_with_pi_keeps_its_double_root():
    """x'' + 2πx' + π²x = cos t: (λ + π)² is a double root, which the exact route must
    see (the numeric separation test sends close roots to SymPy's squarefree split)."""
    M, C, K = [[1]], [[2 * sp.pi]], [[sp.pi**2]]
    sol = ls.solve(ls.Scene.from_matrices(M=M, C=C, K=K, x0=[1], v0=[0], forcing=["cos(t)"]))
    assert sol.method == "exact"
    u = sp.Symbol("u")
    decaying = sp.expand(sol.x[0].subs(sp.exp(-sp.pi * ls.t), u)).coeff(u)
    assert decaying.has(ls.t)  # t·e^{-πt}: the double root
    values, bounds = sol.evaluate(TIMES, return_error=True)
    expected = reference(M, C, K, [1], [mpmath.cos], TIMES)
    assert np.all(np.abs(values - expected) <= bounds)


def test_exo_asked_by_name_serves_a_small_rational_scene():
    """method='exo' on a pair below Limits.exo_min_coordinates: served (auto prefers the
    exact route's closed form there; a request by name is honoured)."""
    M = [[2, 0], [0, 1]]
    scene = ls.Scene.from_matrices(M=M, C=PAIR_C, K=PAIR_K, x0=[1, 0], v0=[0, 0],
                                   forcing=["cos(t)", 0])
    assert ls.solve(scene).method == "exact"
    sol = ls.solve(scene, method="exo")
    assert "exo" in sol.method
    values, bounds = sol.evaluate(TIMES, return_error=True)
    expected = reference(M, PAIR_C, PAIR_K, [1, 0], [mpmath.cos, 0], TIMES)
    assert np.all(np.abs(values - expected) <= bounds)


def test_free_irrational_scene_escalates_without_the_exact_routes_error():
    """A target no float64 engine meets sends times to the escalation; the exact route
    refuses the irrational factor there and the others keep their values and bounds."""
    M = [[sp.sqrt(2), 0], [0, 1]]
    scene = ls.Scene.from_matrices(M=M, C=PAIR_C, K=PAIR_K, x0=[1, 0], v0=[0, 0])
    sol = ls.solve(scene)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        values, bounds = sol.evaluate(TIMES, return_error=True, target=1e-16)
    expected = reference(M, PAIR_C, PAIR_K, [1, 0], [0, 0], TIMES)
    assert np.all(np.abs(values - expected) <= bounds)
    assert np.max(bounds) < 1e-12


def test_one_transcendental_number_keeps_the_exact_route():
    """m = π, forcing e^{-t}: Δ·(λ + 1) is factored with π as an unknown over ℚ (EX left it
    whole and the exact route refused a cubic with irrational coefficients)."""
    M, C, K = [[sp.pi]], [[1]], [[1]]
    sol = ls.solve(ls.Scene.from_matrices(M=M, C=C, K=K, x0=[1], v0=[0], forcing=["exp(-t)"]))
    assert sol.method == "exact" and sol.x[0].has(sp.pi)
    values, bounds = sol.evaluate(TIMES, return_error=True)
    expected = reference(M, C, K, [1], [lambda t: mpmath.exp(-t)], TIMES)
    assert np.all(np.abs(values - expected) <= bounds)


def test_mixed_irrational_numbers_go_to_the_numeric_engines_at_once():
    """√5 − 1, e and π/3 on one forced mass: the exact terms took 20 s and a coefficient of
    180,000 characters (before that, the planner's LimitError); the screen declines them
    and the exo engine serves."""
    M, C, K = [[sp.sqrt(5) - 1]], [[sp.E]], [[sp.pi / 3]]
    scene = ls.Scene.from_matrices(M=M, C=C, K=K, x0=[1], v0=[0], forcing=["exp(-t)"])
    start = time.perf_counter()
    sol = ls.solve(scene)
    values, bounds = sol.evaluate(TIMES, return_error=True)
    took = time.perf_counter() - start
    assert "exo" in sol.method and "Limits.max_exact_irrationals" in sol.reason
    assert took < 10
    expected = reference(M, C, K, [1], [lambda t: mpmath.exp(-t)], TIMES)
    assert np.all(np.abs(values - expected) <= bounds)


@pytest.mark.parametrize("forcing", [[0, "1"], ["t", 0]], ids=["step", "ramp"])
def test_polynomial_forces_on_irrational_entries_are_bounded(forcing):
    """Forces 1 and t join the scene as states held constant (w' = 0, a Jordan pair at 0
    for t). The general modal engine's sampled copies moved those exact rows of zeros
    (LAPACK's balancing then cost 7 digits) and compared the envelope of a 6 x 6 block with
    that of separated pairs: bounds of 4e-8 and 4.5 (a refusal) on values good to 1e-15."""
    masses = [sp.sqrt(5) - 1, sp.E]
    springs = [sp.cbrt(2), sp.sqrt(3) / 3]
    dashpots = [sp.pi / 3, sp.Rational(3, 7)]
    M = [[masses[0], 0], [0, masses[1]]]
    K = [[springs[0] + springs[1], -springs[1]], [-springs[1], springs[1]]]
    C = [[dashpots[0] + dashpots[1], -dashpots[1]], [-dashpots[1], dashpots[1]]]
    scene = ls.Scene.from_matrices(M=M, C=C, K=K, x0=[1, 0], v0=[0, 0], forcing=forcing)
    sol = ls.solve(scene)
    values, bounds = sol.evaluate(TIMES, return_error=True)
    laws = [None if f == 0 else (lambda t: 1) if f == "1" else (lambda t: t) for f in forcing]
    expected = reference(M, C, K, [1, 0], laws, TIMES)
    assert np.all(np.abs(values - expected) <= bounds)
    assert np.max(bounds) <= 1e-10 * max(1.0, float(np.max(np.abs(expected))))


@pytest.mark.parametrize(("mass", "spring", "force", "law"), [
    (sp.pi, sp.pi, "cos(t)", mpmath.cos),
    (sp.sqrt(2), 2 * sp.sqrt(2), "sin(sqrt(2)*t)", lambda t: mpmath.sin(mpmath.sqrt(2) * t)),
], ids=["pi", "sqrt2"])
def test_resonance_with_irrational_entries_keeps_its_double_pole(mass, spring, force, law):
    """The force's poles are the scene's: Δ(λ) and the force's denominator share λ² + ω²,
    so they are factored together (t·sin and t·cos terms), not one by one."""
    M, C, K = [[mass]], [[0]], [[spring]]
    sol = ls.solve(ls.Scene.from_matrices(M=M, C=C, K=K, x0=[1], v0=[0], forcing=[force]))
    assert sol.method == "exact"
    values, bounds = sol.evaluate(TIMES, return_error=True)
    expected = reference(M, C, K, [1], [law], TIMES)
    assert np.all(np.abs(values - expected) <= bounds)
    growing = [term for term in sp.Add.make_args(sp.expand(sol.x[0])) if term.has(ls.t)
               and sp.degree(term.as_independent(sp.sin, sp.cos)[0], ls.t) == 1]
    assert growing  # the resonant t·sin or t·cos term


def test_x_of_a_free_scene_without_an_exact_form_is_its_float_column():
    """√2 and π: Δ is an irreducible quartic with irrational coefficients. ``x`` and
    ``latex()`` raised the exact route's InversionError; they are now the float64 terms,
    and ``inexact_reason`` says why."""
    M = [[sp.sqrt(2), 0], [0, 1]]
    C = [[sp.Rational(1, 10), 0], [0, 0]]
    K = [[2 + sp.pi, -sp.pi], [-sp.pi, sp.pi]]
    sol = ls.solve(ls.Scene.from_matrices(M=M, C=C, K=K, x0=[1, 0], v0=[0, 0]))
    x = sol.x
    assert "irrational coefficients" in sol.inexact_reason
    assert sol.latex().startswith("\\begin{aligned}")
    expected = reference(M, C, K, [1, 0], [0, 0], TIMES)
    printed = np.array([[float(x[i].subs(ls.t, t)) for t in TIMES] for i in range(2)])
    assert np.max(np.abs(printed - expected)) < 1e-12

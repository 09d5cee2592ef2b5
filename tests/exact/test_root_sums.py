"""Symbolic scenes of any degree (issue 12, item 4): where Δ(λ) has a factor with
symbolic coefficients and no closed-form roots, the answer is a sum over its roots,
x_i(t) = Σ_{Δ(λ)=0} N_i(λ)/Δ'(λ) e^{λt}, built in milliseconds.

Every value is checked against an independent route after substituting numbers: the
40-digit matrix exponential of :mod:`laplace_springs.bench.reference` (free and
exosystem-driven scenes), mpmath's Talbot inversion of the transform, discriminants
and power sums computed by SymPy from the substituted polynomial.
"""

from __future__ import annotations

import re
import time

import mpmath
import numpy as np
import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.bench.reference import reference_forced_motion, reference_motion, relative_error
from laplace_springs.exact.assembly import exact_motion
from laplace_springs.exact.partial_fractions import RootSumGroup, partial_fractions
from laplace_springs.exact.real_terms import RootSumTerm, group_terms, terms_expr
from laplace_springs.exact.root_sums import Condition, SumOverRoots, root_sum_weights, sum_over_roots
from laplace_springs.output import latex as latex_module

s, t = sp.symbols("s t")
a = sp.Symbol("a", positive=True)
m1, m2, k1, k2, c, w = sp.symbols("m1 m2 k1 k2 c w", positive=True)
NUMBERS = {m1: 1, m2: 2, k1: 3, k2: 5, c: sp.Rational(1, 10)}
TIMES = ["0.37", "1.3", "4.1", "25"]


def damped_pair(**kw) -> ls.Scene:
    """The issue's symbolic damped two-mass scene: Δ is an irreducible symbolic quartic."""
    kw.setdefault("x0", [1, 0])
    kw.setdefault("v0", [0, 0])
    return ls.Scene.from_matrices(M=[[m1, 0], [0, m2]], C=[[c, -c], [-c, c]],
                                  K=[[k1 + k2, -k2], [-k2, k2]], **kw)


def values_at(x, times, digits=30) -> list[list[sp.Expr]]:
    """Each coordinate of x (numbers substituted) at the times, by evalf."""
    return [[e.subs(ls.t, sp.Rational(tv)).evalf(digits) for tv in times] for e in x]


def inverse(F) -> sp.Expr:
    """The real-form inverse of F with sums over roots (what inverse_laplace will call)."""
    pf = partial_fractions(F, s, closed_form=True, root_sums=True)
    return terms_expr([term for group in pf.groups for term in group_terms(group)], t)


def talbot(function, value: str, digits: int = 40):
    """mpmath's Talbot inversion of the transform ``function`` (of an mpmath z) at t = value."""
    with mpmath.workdps(digits):
        return mpmath.invertlaplace(function, mpmath.mpf(value), method="talbot")


def close_to(value: sp.Expr, reference, tolerance: float) -> bool:
    with mpmath.workdps(40):
        got = mpmath.mpc(*(mpmath.mpf(str(part)) for part in sp.N(value, 35).as_real_imag()))
        return bool(abs(got - reference) <= tolerance * max(1, abs(reference)))


# -- the check ----------------------------------------------------------------
def test_symbolic_damped_pair_solves_in_seconds_and_matches_the_reference():
    start = time.perf_counter()
    sol = ls.solve(damped_pair())
    seconds = time.perf_counter() - start
    assert seconds < 5, seconds  # measured: 0.06-0.13 s (before: refused; earlier 222 s)
    assert sol.method == "exact"
    assert all(isinstance(e, SumOverRoots) for e in sol.x)
    x = sol.x.subs(NUMBERS)
    reference = reference_motion(damped_pair().subs(NUMBERS), TIMES, dps=40)
    assert relative_error(values_at(x, TIMES), reference) < 1e-20


def test_doit_expands_over_exact_algebraic_roots():
    # .doit() gives Σ f(CRootOf(q, k)); SymPy's own RootSum.doit (the quartic formula in
    # radicals) evaluated to 0.477 where the value is 0.517.
    f = inverse(1 / (s**3 + a * s + 1)).subs(a, 2)
    expanded = f.doit()
    assert expanded.atoms(sp.CRootOf) and not expanded.atoms(sp.RootSum)
    reference = talbot(lambda z: 1 / (z**3 + 2 * z + 1), "1.7")
    assert close_to(expanded.subs(t, sp.Rational(17, 10)), reference, 1e-20)


def test_symbolic_solution_substitutes_partially_and_evaluates():
    sol = ls.solve(damped_pair())
    partial = sol.x.subs({m1: 1, m2: 2})  # still symbolic: stays a sum over roots
    assert all(isinstance(e, SumOverRoots) for e in partial)
    x = partial.subs({k1: 3, k2: 5, c: sp.Rational(1, 10)})
    reference = reference_motion(damped_pair().subs(NUMBERS), TIMES[:2], dps=40)
    assert relative_error(values_at(x, TIMES[:2]), reference) < 1e-20


def test_numbers_for_the_scene_keep_the_numeric_routes():
    sol = ls.solve(damped_pair().subs(NUMBERS))
    assert sol.method in ("tiny", "certified", "modal")  # a float64 engine, not the exact route
    exact = ls.solve(damped_pair().subs(NUMBERS), method="exact")
    assert not any(e.atoms(sp.RootSum) for e in exact.x)  # rational quartic: CRootOf terms
    reference = reference_motion(damped_pair().subs(NUMBERS), TIMES, dps=40)
    assert relative_error(exact.evaluate(TIMES, dps=30), reference) < 1e-25


def test_initial_data_and_equations_hold_exactly():
    # x(0) = x0 and x'(0) = v0 are exact identities of the sums (Newton's power sums at
    # t = 0), and M x''(0) = -C v0 - K x0.
    sol = ls.solve(damped_pair(v0=[0, 2]))
    at_zero = [sol.x.subs(ls.t, 0), sol.x.diff(ls.t).subs(ls.t, 0), sol.x.diff(ls.t, 2).subs(ls.t, 0)]
    x, v, acc = (m.subs(NUMBERS) for m in at_zero)
    scene = damped_pair(v0=[0, 2]).subs(NUMBERS)
    assert list(x) == [1, 0] and list(v) == [0, 2]
    assert list(scene.M * acc) == list(-scene.C * sp.Matrix([0, 2]) - scene.K * sp.Matrix([1, 0]))
    assert sol.verify()


def test_derivative_in_a_parameter_moves_the_roots():
    # d/dk1 of the sum must include dρ/dk1 (SymPy's RootSum differentiates the summand only)
    x1 = ls.solve(damped_pair()).x[0]
    derivative = x1.diff(k1).subs(NUMBERS).subs(ls.t, sp.Rational(13, 10)).evalf(30)
    h = sp.Rational(1, 10**12)
    ahead, behind = (reference_motion(damped_pair().subs({**NUMBERS, k1: 3 + d}), ["1.3"], dps=60)[0, 0]
                     for d in (h, -h))
    with mpmath.workdps(60):
        difference = (ahead - behind) / (2 * mpmath.mpf(h.p) / h.q)
        assert abs(mpmath.mpf(str(derivative)) - difference) < 1e-20


def test_symbolic_three_mass_chain_with_damping():
    ms, ks = sp.symbols("m1:4", positive=True), sp.symbols("k1:5", positive=True)
    d = sp.symbols("d1:5", positive=True)

    def tridiagonal(v):
        return [[v[0] + v[1], -v[1], 0], [-v[1], v[1] + v[2], -v[2]], [0, -v[2], v[2] + v[3]]]

    scene = ls.Scene.from_matrices(M=sp.diag(*ms).tolist(), C=tridiagonal(d), K=tridiagonal(ks),
                                   x0=[1, 0, 0], v0=[0, 0, sp.Rational(1, 2)])
    start = time.perf_counter()
    sol = ls.solve(scene)
    assert time.perf_counter() - start < 10  # measured 0.5 s; Δ: an irreducible sextic
    assert all(e.atoms(SumOverRoots) for e in sol.x)
    numbers = {**dict(zip(ms, [1, 2, 3])), **dict(zip(ks, [3, 5, 2, 4])),
               **dict(zip(d, [sp.Rational(1, 10), sp.Rational(1, 5), sp.Rational(3, 10), sp.Rational(1, 7)]))}
    x = sol.x.subs(numbers)
    reference = reference_motion(scene.subs(numbers), TIMES, dps=40)
    assert relative_error(values_at(x, TIMES), reference) < 1e-20


def test_forced_symbolic_pair_matches_the_exosystem_reference():
    # f = (cos w t, 1): transient sums over the roots of Δ plus steady real terms
    scene = damped_pair(x0=[1, 0], v0=[0, 0], forcing=[sp.cos(w * ls.t), 1])
    start = time.perf_counter()
    sol = ls.solve(scene)
    assert time.perf_counter() - start < 5  # measured 0.4 s
    assert sol.transient.atoms(SumOverRoots) and not sol.steady_state.atoms(SumOverRoots)
    numbers = {**NUMBERS, w: sp.Rational(3, 2)}
    x = sol.x.subs(numbers)
    S = [[0, -sp.Rational(3, 2), 0], [sp.Rational(3, 2), 0, 0], [0, 0, 0]]
    reference = reference_forced_motion(scene.subs(numbers), S, [1, 0, 1], [[1, 0, 0], [0, 0, 1]],
                                        TIMES, dps=40)
    assert relative_error(values_at(x, TIMES), reference) < 1e-20


def test_delayed_input_switches_a_sum_on():
    scene = damped_pair(x0=[0, 0], forcing=[0, sp.Heaviside(ls.t - 2)])
    sol = ls.solve(scene)
    assert [piece.delay for piece in sol.pieces] == [0, 2]
    x = sol.x.subs(NUMBERS)
    # before t = 2 nothing moves; after, x - x(∞) is the step response shifted by 2
    assert values_at(x, ["1.5"]) == [[0], [0]]
    step = damped_pair(x0=[0, 0]).subs(NUMBERS)
    reference = reference_forced_motion(step, [[0]], [1], [[0], [1]], ["2.3", "9"], dps=40)
    assert relative_error(values_at(x, ["4.3", "11"]), reference) < 1e-20


# -- inverse transforms ----------------------------------------------------------------
@pytest.mark.parametrize("F, value, function", [
    (1 / (s**4 + a * s + 1), 3, lambda z: 1 / (z**4 + 3 * z + 1)),
    ((s + 1) / ((s**5 + a * s + 1) * (s**2 + 1)), 2,  # a rational quadratic keeps its terms
     lambda z: (z + 1) / ((z**5 + 2 * z + 1) * (z**2 + 1))),
    (1 / (s**3 + a * s + 1) ** 2, 2, lambda z: 1 / (z**3 + 2 * z + 1) ** 2),  # t e^{ρt} terms
    (s**2 / ((s**3 + a * s + 1) ** 2 * (s + a)), sp.Rational(1, 2),
     lambda z: z**2 / ((z**3 + z / 2 + 1) ** 2 * (z + mpmath.mpf(1) / 2))),
    (1 / (s**4 + a * s + 1), 2, lambda z: 1 / (z**4 + 2 * z + 1)),  # (s + 1)·cubic at a = 2
])
def test_inverse_with_symbolic_factors_matches_talbot(F, value, function):
    start = time.perf_counter()
    f = inverse(F)
    assert time.perf_counter() - start < 2  # measured 0.02-0.07 s
    assert f.atoms(SumOverRoots)
    for tv in ("0.4", "1.7", "6"):
        got = f.subs(a, value).subs(t, sp.Rational(tv)).evalf(30)
        assert close_to(got, talbot(function, tv), 1e-25)


def test_partial_fractions_recombine_with_root_sum_groups():
    F = (s + 1) / ((s**5 + a * s + 1) * (s**2 + 1))
    pf = partial_fractions(F, s, closed_form=True, root_sums=True)
    (group,) = [g for g in pf.groups if isinstance(g, RootSumGroup)]
    assert group.residues == () and group.order == 1 and group.degree == 5
    z = sp.Rational(3, 7)
    total = pf.as_expr().subs(a, 2).subs(s, z).doit()
    assert sp.nsimplify(sp.N(total - F.subs(a, 2).subs(s, z), 40), tolerance=1e-35) == 0


def test_without_root_sums_symbolic_factors_are_still_refused_at_once():
    start = time.perf_counter()
    with pytest.raises(ls.InversionError, match="degree 4 has symbolic coefficients"):
        partial_fractions(1 / (s**4 + a * s + 1), s, closed_form=True)
    assert time.perf_counter() - start < 2


# -- the sum object ----------------------------------------------------------------------
def test_sum_over_a_rational_summand_is_the_exact_trace():
    # Σ 1/(ρ - 2) over the roots of q is -q'(2)/q(2) = -9/7 (q'/q = Σ 1/(s - ρ))
    q = sp.Poly(s**3 - s**2 + s + 1, s)
    f = sum_over_roots(q, (1 / (s - 2),), 0)
    assert f == sp.Rational(-9, 7)
    fourth = sum(r**4 for r in sp.roots(q, multiple=True))  # radicals, summed numerically
    assert sum_over_roots(q, (s**4,), 0) == -5 and abs(sp.N(fourth + 5, 40)) < 1e-30
    symbolic = sum_over_roots(sp.Poly(s**3 + a * s + 1, s), (1 / (s - 2),), 0)
    assert isinstance(symbolic, SumOverRoots)  # left as it is: no symmetric-function blowup
    assert symbolic.subs(a, -1) == sum_over_roots(sp.Poly(s**3 - s + 1, s), (1 / (s - 2),), 0)


def test_evalf_is_real_for_a_real_polynomial_and_fast():
    f = inverse(1 / (s**4 + a * s + 1)).subs(a, 3)
    start = time.perf_counter()
    values = [f.subs(t, tv).evalf(30) for tv in (sp.Rational(1, 3), 10, 1000)]
    assert time.perf_counter() - start < 2
    assert all(v.is_real and v.is_Float for v in values)


def test_weights_are_residues():
    # simple root: Res e^{λt} N/D = N(ρ)/D'(ρ) e^{ρt}; double root of 1/q²:
    # e^{ρt}(t/q'(ρ)² - q''(ρ)/q'(ρ)³) (the Laurent series of 1/q² at ρ)
    q = sp.Poly(s**3 + a * s + 1, s)
    (weight,) = root_sum_weights(q, sp.Poly(s, s), q)
    assert sp.simplify(weight - s / (3 * s**2 + a)) == 0
    w0, w1 = root_sum_weights(q, sp.Poly(1, s), q**2, 2)
    assert sp.simplify(w1 - 1 / (3 * s**2 + a) ** 2) == 0
    assert sp.simplify(w0 + 6 * s / (3 * s**2 + a) ** 3) == 0


# -- conditions --------------------------------------------------------------------------
def test_the_genericity_condition_is_recorded_and_checks_numbers():
    motion = exact_motion(damped_pair())
    (condition,) = motion.conditions
    assert ls.solve(damped_pair()).conditions == (condition,)
    assert condition.cofactor.degree() == 0 and "simple roots" in condition.meaning
    assert condition.holds_at(NUMBERS)
    delta = sp.Poly(motion.resolvent.determinant.as_expr().subs(NUMBERS), sp.Symbol("lambda"))
    assert condition.expr.subs(NUMBERS) == sp.discriminant(delta) != 0
    cubic = Condition(sp.Poly(s**3 + a * s + 1, s), sp.Poly(1, s))
    double = -3 * sp.Rational(1, 4) ** sp.Rational(1, 3)  # a³ = -27/4: a double root
    assert sp.simplify(sp.discriminant(sp.Poly(s**3 + double * s + 1, s))) == 0
    assert not cubic.holds_at({a: double}) and cubic.holds_at({a: 1})
    assert sp.simplify(cubic.expr - (-4 * a**3 - 27)) == 0


def test_forced_conditions_name_the_inputs():
    scene = damped_pair(x0=[0, 0], forcing=[sp.cos(w * ls.t), 0])
    conditions = ls.solve(scene).conditions
    assert any("lambda**2 + w**2" in condition.meaning for condition in conditions)
    assert all(condition.holds_at({**NUMBERS, w: 1}) for condition in conditions)


def test_numeric_scenes_have_no_conditions():
    assert exact_motion(damped_pair().subs(NUMBERS)).conditions == ()


# -- printing ----------------------------------------------------------------------------
def test_latex_reads_like_a_textbook():
    sol = ls.solve(damped_pair())
    tex = sol.latex()
    assert r"x_{1}(t) &= \sum_{\Delta(\lambda) = 0} \frac{N_{1}(\lambda)}{\Delta'(\lambda)} \, e^{\lambda t}" in tex
    assert r"x_{2}(t) &= \sum_{\Delta(\lambda) = 0} \frac{N_{2}(\lambda)}{\Delta'(\lambda)} \, e^{\lambda t}" in tex
    assert r"\text{where}\quad \Delta(\lambda) &= \lambda^{4}" in tex
    assert r"N_{1}(\lambda) &= \lambda^{3}" in tex and r"N_{2}(\lambda) &= " in tex
    assert r"\operatorname{disc}_{\lambda} \Delta(\lambda) \neq 0" in tex
    assert "RootSum" not in tex and "Lambda" not in tex


def test_latex_definitions_are_the_resolvent_blocks():
    # Δ in the "where" list is the Δ of X_i(λ) = N_i(λ)/Δ(λ) in the resolvent block
    tex = ls.solve(damped_pair()).latex(resolvent=True)
    rows = re.findall(r"\\Delta\(\\lambda\) &= (.*?)(?: && .*)? \\\\$", tex, re.MULTILINE)
    assert len(rows) == 2 and rows[0] == rows[1]
    # N_1 = adj·r scaled as Δ: λ(λ² + cλ/m1 + cλ/m2 + k2/m2) for x0 = (1, 0)
    (n1,) = re.findall(r"N_\{1\}\(\\lambda\) &= (.*?) \\\\$", tex, re.MULTILINE)
    lam = sp.Symbol("lambda")
    expected = sp.Poly(lam * (lam**2 + c * lam / m1 + c * lam / m2 + k2 / m2), lam)
    assert n1 == latex_module._readable_poly_tex(expected)


def test_latex_of_forced_and_g_forms():
    tex = ls.solve(damped_pair(x0=[0, 0], forcing=[0, sp.Heaviside(ls.t - 2)])).latex()
    assert r"\frac{N_{1,1}(\lambda)}{\Delta'(\lambda) \, E(\lambda)} \, e^{\lambda \cdot \left(t - 2\right)}" in tex
    assert r"E(\lambda) &= \lambda" in tex and r"\theta\left(t - 2\right)" in tex
    assert r"none of them a root of } E(\lambda)" in tex
    g = ls.solve(damped_pair()).latex(form="g")
    assert r"g_{0}(t) = \mathcal{L}^{-1}\left[\frac{\lambda^{0}}{\Delta(\lambda)}\right] &= \sum_{\Delta(\lambda) = 0} \frac{1}{\Delta'(\lambda)} \, e^{\lambda t}" in g


def test_plain_printing_does_not_crash():
    sol = ls.solve(damped_pair())
    assert "RootSum(" in str(sol.x[0]) and "RootSum(" in repr(sol)
    assert sp.pretty(sol.x[0])
    assert sp.latex(sol.x[0]).startswith(r"\sum_{")


def test_sum_terms_are_structured():
    motion = exact_motion(damped_pair())
    ((piece, coordinate, term),) = motion.root_sums[:1]
    assert isinstance(term, RootSumTerm) and term.kind == "root_sum" and (piece, coordinate) == (0, 0)
    assert term.factor.degree() == 4
    assert sp.expand(term.group.numerator.as_expr() - motion.resolvent.numerators[0].as_expr()) == 0
    derivative = motion.derivative().x[0].subs(NUMBERS)
    assert np.isclose(float(derivative.subs(ls.t, 0).evalf(20)), 0)

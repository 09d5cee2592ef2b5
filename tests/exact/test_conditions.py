"""Genericity conditions of closed forms with symbolic coefficients (issue 12 item 5).

1/(s(s² + a s + 1)) has a generic inverse that is 0/0 at a = 2: the result must say
"valid for a² − 4 ≠ 0". The references are SymPy's own inverse transform at numbers and
the direct observation that the generic formula breaks where the condition fails.
"""

from __future__ import annotations

import sympy as sp

import laplace_springs as ls
from laplace_springs.exact.named import expand_names

s = sp.Symbol("s")
t = ls.t


def _meanings(conditions):
    return [c.meaning for c in conditions]


def test_quadratic_factor_records_its_discriminant():
    a = sp.Symbol("a")
    F = 1 / (s * (s**2 + a * s + 1))
    result = ls.inverse_laplace_terms(F, s)
    assert _meanings(result.conditions) == ["a**2 - 4 != 0"]
    (condition,) = result.conditions
    assert not condition.holds_at({a: 2}) and not condition.holds_at({a: -2})
    assert condition.holds_at({a: 3}) and condition.holds_at({a: 1})
    generic = expand_names(result.as_expr(t))
    # where the condition fails the generic formula is 0/0 (not finite) ...
    broken = generic.subs(a, 2).subs(t, sp.Rational(1, 3))
    assert broken.has(sp.nan, sp.zoo) or not sp.N(broken).is_finite
    # ... and where it holds it is the inverse (SymPy's transform as the reference)
    for value in (1, 3):
        reference = sp.inverse_laplace_transform(F.subs(a, value), s, t)
        difference = (generic.subs(a, value) - reference).subs(t, sp.Rational(7, 5))
        assert abs(sp.N(difference, 30)) < 1e-25


def test_leading_coefficient_and_shared_roots():
    a, b = sp.symbols("a b")
    assert _meanings(ls.partial_fractions(1 / (a * s**2 + b * s + 1), s).conditions) == \
        ["a != 0", "-4*a + b**2 != 0"]
    assert _meanings(ls.partial_fractions(1 / ((s + 1) * (s + a)), s).conditions) == ["a - 1 != 0"]
    assert ls.partial_fractions(1 / (s**2 + 2 * s + 5), s).conditions == ()
    positive = sp.Symbol("p", positive=True)   # s and s + p never share a root
    assert ls.partial_fractions(1 / (s * (s + positive)), s).conditions == ()


def test_scene_conditions_reach_the_solution_and_its_latex():
    scene = ls.Scene.from_matrices(M=[["m"]], C=[["c"]], K=[["k"]], x0=[0], v0=[1],
                                   parameters=["m", "c", "k"])
    sol = ls.solve(scene)
    assert _meanings(sol.conditions) == ["c**2 - 4*k*m != 0"]
    assert r"\text{valid for } c^{2} - 4 k m \neq 0" in sol.latex()
    # critical damping is where the generic formula fails; solving again there is exact
    m, c, k = (sp.Symbol(n, positive=True) for n in "mck")
    (condition,) = sol.conditions
    assert not condition.holds_at({m: 1, c: 2, k: 1})
    assert sol.subs({"m": 1, "c": 2, "k": 1}).x[0] == t * sp.exp(-t)
    numeric = ls.solve(ls.Scene.from_matrices(M=[[1]], C=[[1]], K=[[4]], x0=[0], v0=[1]))
    assert numeric.conditions == ()

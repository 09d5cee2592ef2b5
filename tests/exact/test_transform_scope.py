"""ls.laplace and ls.inverse_laplace at their scope's edges (issue 24): unknown functions
and their derivatives in SymPy's convention, matrices, the sifting property, and a clear
refusal (SceneError or InversionError naming what is unsupported) for everything outside,
never a traceback from inside SymPy. Expected values are SymPy's own answers (a peer) or
the textbook rules."""

from __future__ import annotations

import time

import pytest
import sympy as sp

import laplace_springs as ls

t, s, w = sp.symbols("t s w")
a, b, c = sp.symbols("a b c", positive=True)
f, g, x = sp.Function("f"), sp.Function("g"), sp.Function("x")


@pytest.mark.parametrize("expr", [
    sp.Derivative(x(t), t),
    sp.Derivative(x(t), (t, 3)),
    10 * sp.diff(f(t), (t, 1)),
    sp.Derivative(x(t), (t, 2)) + 3 * x(t) - sp.cos(t),
    a * f(t),
    sp.Derivative(x(t), (t, 2)) + c * sp.Derivative(x(t), t) + b * x(t) - sp.Heaviside(t - 1),
])
def test_the_derivative_rule_is_sympys(expr):
    assert ls.laplace(expr, t, s) == sp.laplace_transform(expr, t, s, noconds=True)


def test_derivative_rule_with_initial_values_and_another_variable():
    # L[x''] = s^2 X - s x(0) - x'(0) (any table); x(0), x'(0) as constants of the rest too
    ours = ls.laplace(sp.Derivative(x(w), (w, 2)) + x(0) * sp.exp(-w), w, s)
    X = sp.LaplaceTransform(x(w), w, s)
    expected = s**2 * X - s * x(0) - sp.Subs(sp.Derivative(x(w), w), w, 0) + x(0) / (s + 1)
    assert sp.expand(ours - expected) == 0


@pytest.mark.parametrize(("expr", "expected"), [
    (f(t) * sp.DiracDelta(t - 42), f(42) * sp.exp(-42 * s)),                     # SymPy's tests
    (f(t) * sp.DiracDelta(b * t - a), f(a / b) * sp.exp(-a * s / b) / b),
    (f(t) * sp.DiracDelta(b * t + a), sp.S.Zero),
    (sp.cos(t) * sp.DiracDelta(t - sp.pi), -sp.exp(-sp.pi * s)),
])
def test_the_sifting_property(expr, expected):
    assert sp.simplify(ls.laplace(expr, t, s) - expected) == 0


def test_matrices_both_ways_entry_by_entry():
    Mt = sp.Matrix([[sp.exp(t), t * sp.exp(-t)], [t * sp.exp(-t), sp.exp(t)]])
    Ms = sp.Matrix([[1 / (s - 1), (s + 1) ** -2], [(s + 1) ** -2, 1 / (s - 1)]])  # SymPy's test
    assert ls.laplace(Mt, t, s) == Ms
    assert (ls.inverse_laplace(Ms, s, t) - Mt).applyfunc(sp.simplify) == sp.zeros(2, 2)
    resolvent = (s * sp.eye(2) - sp.Matrix([[1, 0], [0, 2]])).inv()
    assert ls.inverse_laplace(resolvent, s, t) == sp.Matrix([[sp.exp(t), 0], [0, sp.exp(2 * t)]])
    q = sp.Symbol("q")
    value, where = ls.inverse_laplace(sp.Matrix([sp.exp(-q * s) / s]), s, t, conditions=True)
    assert value[0] == sp.Heaviside(t - q) and where[0].as_relational() == sp.Ge(q, 0)


FORWARD_REFUSED = [
    sp.exp(-a * sp.exp(-t)), sp.exp(-a * sp.exp(t)), sp.exp(-a / t), t**4 * sp.exp(-2 / t),
    sp.exp(-2 * t**2), t ** sp.Rational(5, 2), b / (t + a), sp.log(t), sp.sin(a * t) / t,
    sp.Abs(sp.sin(a * t)), sp.besselj(0, a * t), sp.erf(a * t), sp.fresnels(t),
    sp.sin(f(t)), f(t) * g(t), t * f(t), f(t) * sp.exp(-a * t), f(t - 1) * sp.Heaviside(t - 1),
    b * f(t / a), sp.Derivative(f(t), a), sp.Integral(f(t), t), sp.Derivative(f(t, w), t),
    sp.DiracDelta(t**2 - 1), sp.DiracDelta(t) * sp.DiracDelta(t - 1), sp.DiracDelta(t - 1, 1),
    sp.Heaviside(sp.Symbol("p") * t - 1),
    sp.Heaviside(t - sp.Symbol("p")) * sp.Heaviside(t - sp.Symbol("r")),
    sp.exp(sp.I * t), sp.cos(t**2),
]


@pytest.mark.parametrize("expr", FORWARD_REFUSED, ids=str)
def test_forward_refusals_are_clear(expr):
    start = time.perf_counter()
    with pytest.raises(ls.SceneError, match="not supported|expected a real number|not linear|"
                                            "unknown function|nonlinear|order is unknown"):
        ls.laplace(expr, t, s)
    assert time.perf_counter() - start < 3


INVERSE_REFUSED = [
    sp.sqrt(s), 1 / sp.sqrt(s**2 + a**2), s**-b, sp.exp(-a * s) / s**b, sp.cos(s),
    f(s), s**42 * f(s), sp.LaplaceTransform(f(t), t, s), sp.exp(2 * s), 2 * sp.exp(3 * s) - 5 * sp.exp(-7 * s),
    sp.exp(sp.Symbol("z", extended_real=False) * s), sp.exp(sp.Symbol("z", imaginary=True, zero=False) * s),
    sp.Matrix([[1 / s, sp.sqrt(s)]]), 1 / (s + sp.exp(-s)),
]


@pytest.mark.parametrize("expr", INVERSE_REFUSED, ids=str)
def test_inverse_refusals_are_clear(expr):
    start = time.perf_counter()
    with pytest.raises(ls.InversionError):
        ls.inverse_laplace(expr, s, t)
    assert time.perf_counter() - start < 3


def test_a_real_advance_of_unknown_sign_is_answered_with_its_condition():
    r = sp.Symbol("r", real=True)  # SymPy leaves exp(r*s) unevaluated: e^{rs} inverts only for r <= 0
    value, (condition,) = ls.inverse_laplace(sp.exp(r * s), s, t, conditions=True)
    assert value == sp.DiracDelta(t + r)
    assert condition.holds_at({r: -1}) and not condition.holds_at({r: 1})

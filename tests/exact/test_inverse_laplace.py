"""inverse_laplace against a table of Laplace pairs and an independent residue route."""

from __future__ import annotations

import mpmath
import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.exact.inverse import inverse_laplace_terms

s = sp.Symbol("s")
t = sp.Symbol("t", positive=True)
a, w = sp.symbols("a w", positive=True)

# Standard table pairs (e.g. Abramowitz & Stegun 29.3; Kreyszig, Advanced Engineering
# Mathematics, Table 6.9). Numeric parameters where the table has letters, so that
# each pair is checked as the reader would use it.
TABLE = [
    (1 / s, 1),
    (1 / s**4, t**3 / 6),
    (1 / (s + 3), sp.exp(-3 * t)),
    (1 / ((s + 1) * (s + 4)), (sp.exp(-t) - sp.exp(-4 * t)) / 3),
    (1 / (s + 2) ** 3, t**2 * sp.exp(-2 * t) / 2),
    (5 / (s**2 + 25), sp.sin(5 * t)),
    (s / (s**2 + 7), sp.cos(sp.sqrt(7) * t)),
    (1 / (s**2 - 3), sp.sinh(sp.sqrt(3) * t) / sp.sqrt(3)),
    (s / (s**2 - 3), sp.cosh(sp.sqrt(3) * t)),
    ((s + 1) / ((s + 1) ** 2 + 4), sp.exp(-t) * sp.cos(2 * t)),
    (2 / ((s + 1) ** 2 + 4), sp.exp(-t) * sp.sin(2 * t)),
    (6 * s / (s**2 + 9) ** 2, t * sp.sin(3 * t)),
    (54 / (s**2 + 9) ** 2, sp.sin(3 * t) - 3 * t * sp.cos(3 * t)),
    ((s**2 - 4) / (s**2 + 4) ** 2, t * sp.cos(2 * t)),
    (1 / (s * (s**2 + 4)), (1 - sp.cos(2 * t)) / 4),
    (1 / (s**2 * (s + 1)), t - 1 + sp.exp(-t)),
    (8 / (s**2 + 1) ** 3, 3 * sp.sin(t) - 3 * t * sp.cos(t) - t**2 * sp.sin(t)),
    (1 / (s**4 - 1), (sp.sinh(t) - sp.sin(t)) / 2),
    (1 / (s**4 + 4), (sp.sin(t) * sp.cosh(t) - sp.cos(t) * sp.sinh(t)) / 4),
    (1 / ((s**2 + 1) * (s**2 + 4)), (2 * sp.sin(t) - sp.sin(2 * t)) / 6),
    (sp.Rational(1, 2) / (s**2 + s + 1), sp.exp(-t / 2) * sp.sin(sp.sqrt(3) * t / 2) / sp.sqrt(3)),
    (s / (s**2 + w**2), sp.cos(w * t)),
    (1 / (s**2 + w**2), sp.sin(w * t) / w),
    (1 / (s + a) ** 2, t * sp.exp(-a * t)),
    (1 / ((s + a) ** 2 + w**2), sp.exp(-a * t) * sp.sin(w * t) / w),
]


def _values(expr, times, subs=None, dps=30):
    subs = subs or {}
    with mpmath.workdps(dps):
        return [sp.N(expr.subs(subs).subs(t, tv), dps) for tv in times]


@pytest.mark.parametrize("F, expected", TABLE, ids=[str(p[0]) for p in TABLE])
def test_table_pair(F, expected):
    result = ls.inverse_laplace(F, s, t)
    assert not result.has(sp.I, sp.Heaviside, sp.Float, sp.InverseLaplaceTransform)
    params = {a: sp.Rational(3, 7), w: sp.Rational(5, 3)}
    times = [sp.Rational(1, 10), sp.Rational(17, 10), sp.Rational(23, 4)]
    for got, want in zip(_values(result, times, params), _values(sp.sympify(expected), times, params)):
        assert abs(got - want) <= sp.Float("1e-25") * max(1, abs(want))


def _residue_route(F, times, dps=50):
    """Σ Res[F(s) e^{st}] at numerically found simple roots: an independent route."""
    num, den = sp.fraction(sp.cancel(F))
    with mpmath.workdps(dps):
        dcoeffs = [mpmath.mpf(sp.Rational(c).p) / sp.Rational(c).q for c in sp.Poly(den, s).all_coeffs()]
        roots = mpmath.polyroots(dcoeffs, maxsteps=200, extraprec=200)
        ddiff = sp.lambdify(s, sp.diff(den, s), "mpmath")
        nfun = sp.lambdify(s, num, "mpmath")
        return [mpmath.nstr(mpmath.re(sum(nfun(r) / ddiff(r) * mpmath.exp(r * mpmath.mpf(tv))
                                          for r in roots)), 40)
                for tv in times]


@pytest.mark.parametrize("F", [
    1 / (100 + 25 * s + 126 * s**2 + 10 * s**3 + 25 * s**4),        # seed, Example 2
    s**3 / (80 * s**4 + 382 * s**3 + 110461 * s**2 + 164060 * s + 22950000),  # Example 5 quartic
    (s**2 + 3) / (s**3 + s + 1),                                      # irreducible cubic
    (2 * s - 1) / (s**5 + 3 * s**2 + 2),                              # irreducible quintic
    (s + 1) / (s**6 + s**4 + 3 * s + 7),
    1 / (s**4 - 5 * s**2 + 3),                                        # real quadratic surds
])
def test_against_residue_route(F):
    result = ls.inverse_laplace(F, s, t)
    assert not result.has(sp.I, sp.Heaviside, sp.Float)
    times = ["0.3", "2.5", "7.25"]
    reference = _residue_route(F, times)
    for tv, text in zip(times, reference):
        got = sp.N(result.subs(t, sp.Rational(tv)), 30)
        want = sp.Float(text, 40)
        assert abs(got - want) <= sp.Float("1e-22") * max(1, abs(want))


def test_degree_three_and_up_uses_algebraic_numbers_not_radicals():
    result = ls.inverse_laplace(1 / (s**3 + s + 1), s, t)
    assert result.has(sp.CRootOf)
    assert not any(p.exp == sp.Rational(1, 3) for p in result.atoms(sp.Pow))


@pytest.mark.parametrize("F", [
    1 / ((s + 1) ** 2 * (s**2 + 1)),
    (s**3 + 2) / ((s**2 + 2 * s + 5) ** 2 * (s - 3)),
    (s + 5) / ((s**3 + s + 1) ** 2 * s**2),
    (3 * s**2 + 1) / (s**4 - 5 * s**2 + 3),
    (s + a) / ((s**2 + w**2) * (s + 1)),
])
def test_decomposition_recombines_to_F(F):
    pf = ls.partial_fractions(F, s)
    assert sp.cancel(pf.as_expr() - F) == 0


def test_structured_terms_carry_multiplicity_alpha_beta():
    inv = inverse_laplace_terms(1 / (s**2 + 2 * s + 5) ** 2, s)
    assert {(term.kind, term.power, term.alpha, term.beta) for term in inv.terms} == {
        ("oscillatory", 0, -1, 2), ("oscillatory", 1, -1, 2)}


def test_common_factors_cancel():
    # (s + 1) cancels: the result has no exp(-t) term at all.
    result = ls.inverse_laplace((s + 1) / ((s + 1) * (s**2 + 1)), s, t)
    assert result == sp.sin(t)


def test_improper_transform_yields_impulses():
    result = ls.inverse_laplace((s**3 + s**2 + 1) / (s**2 + 1), s, t)
    # s³+s²+1 = (s + 1)(s² + 1) - s: impulses δ' + δ, and -s/(s²+1) -> -cos t
    assert result == sp.DiracDelta(t, 1) + sp.DiracDelta(t) - sp.cos(t)


def test_floats_are_taken_as_their_decimal_value():
    assert ls.inverse_laplace(0.2 / (s + 0.5), s, t) == sp.exp(-t / 2) / 5


@pytest.mark.parametrize("F, match", [
    (sp.exp(-s**2) / s, "not a rational function"),
    (1 / (s - s), "not finite"),
    ("__import__('os').system('touch x')", "expected an expression in s, got .*unexpected character '_'"),
    ("1/(s + a)", "unknown name 'a'.*declare it: parameters=\\['a'\\]"),
    ("sqrt(s)*exp(-s)", "not a rational function"),
    ("t/s", "contains the time t"),
    ([1, 2], "must be text or a SymPy expression"),
])
def test_errors_are_clear(F, match):
    with pytest.raises(ls.InversionError, match=match):
        ls.inverse_laplace(F, s, t)


def test_text_is_parsed_safely_and_names_only_declared_parameters(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert ls.inverse_laplace("1/(s**2 + 2*s + 5)", s, t) == sp.exp(-t) * sp.sin(2 * t) / 2
    b = sp.Symbol("b", positive=True)
    assert ls.inverse_laplace("1/(s + b)", s, t, parameters=["b"]) == sp.exp(-b * t)
    with pytest.raises(ls.InversionError):
        ls.partial_fractions("__import__('os').system('touch x')", s)
    assert not (tmp_path / "x").exists()
    groups = ls.partial_fractions("1/(s*(s + 1))", s).groups  # 1/s - 1/(s + 1)
    assert [(g.factor.as_expr(), g.residues[0].as_expr()) for g in groups] == [(s, 1), (s + 1, -1)]


def test_a_lone_symbol_gets_no_name():
    # 1/((s + a)² + 1) -> e^{-a t} sin t, with a itself, not a named gamma_1
    result = ls.inverse_laplace(1 / ((s + a) ** 2 + 1), s, t)
    assert result == sp.exp(-a * t) * sp.sin(t)


def test_a_symbolic_cubic_inverts_to_a_sum_over_its_roots():
    # 1/(s^3 + a s + 1): Σ_{q(ρ)=0} e^{ρt}/q'(ρ); at a = 2 it equals the mpmath Talbot inverse
    result = ls.inverse_laplace(1 / (s**3 + a * s + 1), s, t)
    assert result.atoms(sp.RootSum)
    value = complex(result.subs({a: 2}).subs(t, sp.Rational(3, 2)).evalf(30))
    import mpmath
    reference = mpmath.invertlaplace(lambda z: 1 / (z**3 + 2 * z + 1), 1.5, method="talbot")
    assert abs(value.imag) < 1e-25 and value.real == pytest.approx(float(reference), rel=1e-12)

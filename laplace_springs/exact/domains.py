"""Polynomials in s over one exact field, also when the coefficients hold functions.

SymPy builds the coefficient domain of ``Poly(expr, s)`` itself, and falls back to its
expression domain EX when a coefficient is a function of a parameter that is also a
generator: ``exp(a*b)*s**2 + b*s`` is over EX, not over ℚ(b, e^{ab}). Over EX nothing
factors (s²(s + b)·e^{ab} is "irreducible") and the inversions would refuse a cubic that
is not one, or return a sum over its roots. :func:`field_polys` rebuilds such polynomials
over the field of fractions ℚ(parameters, functions of them), treating each function
(e^{ab}, cos a) as a generator: the partial fractions are then computed over that field,
and every identity they use holds after the functions are evaluated (they are rational
in the generators).

Examples
--------
>>> import sympy as sp
>>> a, b, s = sp.symbols("a b s")
>>> (D,) = field_polys([sp.exp(a*b)*s**3 + b*sp.exp(a*b)*s**2], s)
>>> D.domain, [f.as_expr() for f, _ in D.factor_list()[1]]
(QQ(b,exp(a*b)), [b + s, s])
"""

from __future__ import annotations

from collections.abc import Sequence

import sympy as sp
from sympy.core.function import AppliedUndef
from sympy.polys.polyerrors import CoercionFailed, GeneratorsError

__all__ = ["field_polys"]


def _canonical_exponentials(expr: sp.Expr) -> sp.Expr:
    """e^{-u} written 1/e^{u}, so that e^{ab} and e^{-ab} are one generator."""
    flipped = {e: 1 / sp.exp(-e.args[0]) for e in expr.atoms(sp.exp)
               if e.args[0].could_extract_minus_sign()}
    return expr.xreplace(flipped) if flipped else expr


def _generators(polys: Sequence[sp.Poly]) -> list[sp.Expr] | None:
    """The symbols and function applications of the coefficients, or None when a
    coefficient holds an irrational number (sqrt(2), pi: left to SymPy's domains)."""
    found: set[sp.Expr] = set()
    for poly in polys:
        for coefficient in poly.coeffs():
            value = poly.domain.to_sympy(coefficient)
            functions = {f for f in value.atoms(sp.Function) if f.free_symbols and not isinstance(f, AppliedUndef)}
            rest = value.xreplace({f: sp.Dummy() for f in functions})
            if any(not atom.is_Rational for atom in rest.atoms(sp.Number, sp.NumberSymbol)) \
                    or rest.atoms(sp.Pow) and any(p.exp.is_Rational and not p.exp.is_Integer
                                                 for p in rest.atoms(sp.Pow)):
                return None
            found |= functions | {x for x in rest.free_symbols if isinstance(x, sp.Symbol)
                                  and not isinstance(x, sp.Dummy)}
    return sorted(found, key=sp.default_sort_key)


def field_polys(exprs: Sequence[sp.Expr], s: sp.Symbol) -> list[sp.Poly]:
    """``exprs`` as Polys in ``s`` over one domain: SymPy's own, or, where that is EX,
    ℚ(generators) with the functions of the parameters as generators.

    The Polys keep SymPy's domain whenever it is not EX (numbers, algebraic numbers and
    polynomial parameters are unchanged).
    """
    polys = [sp.Poly(expr, s) for expr in exprs]
    if not any(poly.domain.is_EX or poly.domain.is_EXRAW for poly in polys):
        return polys
    canonical = [_canonical_exponentials(sp.expand(expr)) for expr in exprs]
    gens = _generators([sp.Poly(expr, s) for expr in canonical])
    if not gens:
        return polys
    field = sp.QQ.frac_field(*gens)
    try:
        return [sp.Poly(expr, s, domain=field) for expr in canonical]
    except (CoercionFailed, GeneratorsError):
        return polys

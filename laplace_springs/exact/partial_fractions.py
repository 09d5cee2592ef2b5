"""Partial fractions over the coefficient field, one irreducible factor at a time.

A proper rational function N(s)/D(s) with D = c · Π q_j(s)^{m_j} (each q_j monic and
irreducible over the coefficient field) is written as

    N/D = Σ_j Σ_{k=1}^{m_j} Σ_{q_j(ρ)=0} h_{jk}(ρ) / (s - ρ)^k,

where every residue h_{jk} is a polynomial of degree < deg q_j with coefficients in the
field: an element of the number field K[x]/(q_j). The residues are the Laurent
coefficients of N/D at a root ρ of q_j, computed by series arithmetic in u = s - ρ with
coefficients reduced modulo q_j, so no root is ever approximated here and common factors
of N and D simply give zero residues (the pole cancels).

This is the algebraic core behind :func:`laplace_springs.inverse_laplace`; the real
damped sine/cosine form is built from it in :mod:`laplace_springs.exact.real_terms`.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import factorial

import sympy as sp

from ..model.errors import InversionError

__all__ = ["PoleGroup", "PartialFractions", "partial_fractions", "decompose"]


@dataclass(frozen=True)
class PoleGroup:
    """The principal parts of a rational function at the roots of one irreducible factor.

    Attributes
    ----------
    factor : sympy.Poly
        Monic polynomial q(s), irreducible over the coefficient field.
    multiplicity : int
        Its multiplicity m in the denominator.
    residues : tuple of sympy.Poly
        ``residues[k - 1]`` is h_k with deg h_k < deg q: the coefficient of 1/(s - ρ)^k
        at every root ρ of q is h_k(ρ). Trailing zero residues mean the pole has a lower
        order than m after cancellation.
    """

    factor: sp.Poly
    multiplicity: int
    residues: tuple[sp.Poly, ...]

    @property
    def degree(self) -> int:
        """Degree of the irreducible factor."""
        return self.factor.degree()

    @property
    def order(self) -> int:
        """Order of the pole after cancellation (0 if the group vanishes)."""
        nonzero = [k for k, h in enumerate(self.residues, start=1) if not h.is_zero]
        return max(nonzero, default=0)

    def as_expr(self) -> sp.Expr:
        """Recombine the principal parts into a rational function of s, exactly.

        Uses Σ_ρ h(ρ)/(s - ρ) = rem(h·q', q)/q and, for the k-th powers, its
        (k-1)-th derivative times (-1)^{k-1}/(k-1)!.
        """
        q = self.factor
        s = q.gen
        total = sp.S.Zero
        for k, h in enumerate(self.residues, start=1):
            if h.is_zero:
                continue
            simple = (h * q.diff()).rem(q).as_expr() / q.as_expr()
            total += (-1) ** (k - 1) * residue_scale(k) * sp.diff(simple, s, k - 1)
        return total


@dataclass(frozen=True)
class PartialFractions:
    """Structured partial-fraction decomposition of a rational function of ``variable``.

    ``polynomial`` is the polynomial part (zero for a proper function) and ``groups`` the
    principal parts, one :class:`PoleGroup` per irreducible factor of the denominator.
    """

    variable: sp.Symbol
    polynomial: sp.Poly
    groups: tuple[PoleGroup, ...]

    def as_expr(self) -> sp.Expr:
        """Recombine the decomposition into a single rational function (for checks)."""
        total = self.polynomial.as_expr()
        for group in self.groups:
            total += group.as_expr()
        return sp.cancel(sp.together(total))


def _field_polys(F: sp.Expr, s: sp.Symbol) -> tuple[sp.Poly, sp.Poly]:
    """Numerator and denominator of F as polynomials in s over a common field."""
    if not isinstance(s, sp.Symbol):
        raise InversionError(f"the transform variable must be a Symbol, got {s!r}")
    try:
        F = sp.sympify(F, strict=True)  # expressions and numbers; text is never parsed
    except sp.SympifyError:
        raise InversionError(f"the transform must be a SymPy expression, got {F!r}") from None
    if F.has(sp.zoo, sp.oo, -sp.oo, sp.nan):
        raise InversionError(f"the transform is not finite: {F} (a zero denominator?)")
    if F.has(sp.Float):
        F = F.xreplace({f: sp.Rational(str(f)) for f in F.atoms(sp.Float)})
    numerator, denominator = sp.fraction(sp.cancel(sp.together(F)))
    try:
        N = sp.Poly(numerator, s)
        D = sp.Poly(denominator, s)
    except sp.PolynomialError as exc:
        raise InversionError(f"not a rational function of {s}: {F}") from exc
    if D.is_zero:
        raise InversionError(f"the denominator of {F} is zero")
    domain = N.domain.unify(D.domain)
    if not domain.is_Exact:
        raise InversionError(f"inexact coefficients in {F}")
    field = domain.get_field()
    return N.set_domain(field), D.set_domain(field)


def _taylor(p: sp.Poly, q: sp.Poly, order: int) -> list[sp.Poly]:
    """Taylor coefficients p^{(j)}(ρ)/j! at a root ρ of q, reduced mod q, for j < order."""
    out = []
    for j in range(order):
        out.append(p.rem(q))
        p = p.diff().quo_ground(j + 1)
    return out


def _series_mul(a: list[sp.Poly], b: list[sp.Poly], q: sp.Poly) -> list[sp.Poly]:
    """Truncated product of two power series in u with coefficients in K[x]/(q)."""
    order = len(a)
    return [sum((a[i] * b[j - i] for i in range(j + 1)), start=q * 0).rem(q) for j in range(order)]


def _series_inv(b: list[sp.Poly], q: sp.Poly) -> list[sp.Poly]:
    """Truncated inverse of a power series whose constant term is a unit mod q."""
    inv0 = b[0].invert(q)
    out = [inv0]
    for j in range(1, len(b)):
        acc = sum((b[i] * out[j - i] for i in range(1, j + 1)), start=q * 0)
        out.append((-inv0 * acc).rem(q))
    return out


def _principal_parts(numerators: list[sp.Poly], cofactor_inverse: list[sp.Poly],
                     q: sp.Poly) -> list[tuple[sp.Poly, ...]]:
    """Residues h_k of each numerator, given the series of 1/(Q1^m R) at ρ."""
    m = len(cofactor_inverse)
    parts = []
    for N in numerators:
        H = _series_mul(_taylor(N, q, m), cofactor_inverse, q)
        parts.append(tuple(H[m - k] for k in range(1, m + 1)))
    return parts


def _cofactor_inverse(q: sp.Poly, m: int, rest: sp.Poly) -> list[sp.Poly]:
    """Series in u of 1/(Q1(u)^m R(ρ+u)) where q(ρ+u) = u·Q1(u) and rest = D/q^m."""
    Q1 = _taylor(q, q, m + 1)[1:]
    series = _taylor(rest, q, m)
    for _ in range(m):
        series = _series_mul(series, Q1, q)
    return _series_inv(series, q)


def decompose(numerators: list[sp.Poly], denominator: sp.Poly) -> list[PartialFractions]:
    """Partial fractions of several numerators over one shared denominator.

    The denominator is factored once and the inverse series of each factor's cofactor is
    shared, which is what a solution vector X(λ) = adj(λ)·r(λ)/Δ(λ) needs.

    Parameters
    ----------
    numerators : list of sympy.Poly
        Polynomials over the same field and generator as ``denominator``.
    denominator : sympy.Poly
        Nonzero polynomial.

    Returns
    -------
    list of PartialFractions
        One decomposition per numerator, in order.
    """
    s = denominator.gen
    own_field = denominator.domain.get_field()
    field = own_field
    for N in numerators:
        field = field.unify(N.domain.get_field())
    denominator = denominator.set_domain(own_field)
    lc = denominator.LC()
    factors = [(f.set_domain(own_field).monic(), m) for f, m in denominator.factor_list()[1]]
    if field != own_field:
        factors = [(f.set_domain(field), m) for f, m in factors]
        denominator = denominator.set_domain(field)
    numerators = [N.set_domain(field) for N in numerators]
    quotients = [N.div(denominator) for N in numerators]
    groups_per: list[list[PoleGroup]] = [[] for _ in numerators]
    for index, (q, m) in enumerate(factors):
        rest = sp.Poly(lc, s, domain=field)
        for j, (other, mult) in enumerate(factors):
            if j != index:
                rest = rest * other ** mult
        inverse = _cofactor_inverse(q, m, rest)
        for target, residues in zip(groups_per, _principal_parts(numerators, inverse, q)):
            group = PoleGroup(q, m, residues)
            if group.order:
                target.append(group)
    return [PartialFractions(s, quotient, tuple(groups))
            for (quotient, _), groups in zip(quotients, groups_per)]


def partial_fractions(F: sp.Expr, s: sp.Symbol) -> PartialFractions:
    """Structured partial-fraction decomposition of a rational function F(s).

    Parameters
    ----------
    F : sympy expression
        Rational in ``s`` with rational, algebraic or symbolic coefficients.
    s : sympy.Symbol
        The transform variable.

    Returns
    -------
    PartialFractions
        Polynomial part and one :class:`PoleGroup` per irreducible factor of the
        denominator over the coefficient field (ℚ for numeric input).

    Examples
    --------
    >>> import sympy as sp
    >>> s = sp.Symbol("s")
    >>> pf = partial_fractions(1 / ((s + 1) ** 2 * (s**2 + 1)), s)
    >>> [(g.factor.as_expr(), g.multiplicity, [h.as_expr() for h in g.residues]) for g in pf.groups]
    [(s + 1, 2, [1/2, 1/2]), (s**2 + 1, 1, [-1/4])]
    >>> sp.simplify(pf.as_expr() - 1 / ((s + 1) ** 2 * (s**2 + 1)))
    0
    """
    N, D = _field_polys(F, s)
    return decompose([N], D)[0]


def residue_scale(k: int) -> sp.Rational:
    """1/(k-1)!: the factor turning a residue of 1/(s-ρ)^k into the t^{k-1} coefficient."""
    return sp.Rational(1, factorial(k - 1))

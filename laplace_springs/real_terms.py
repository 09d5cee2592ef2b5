"""Real damped sine/cosine terms from a partial-fraction decomposition.

Each pole group of :mod:`laplace_springs.partial_fractions` becomes terms

    t^k e^{αt} (a cos βt + b sin βt)     a complex-conjugate pair α ± iβ,
    t^k e^{αt} (a cosh σt + b sinh σt)   a pair of real quadratic surds α ± σ,
    t^k e^{αt} a                         a real root α (a polynomial term when α = 0),

with exact α, β, a, b. This module is the one place where conjugate roots are folded
into real form.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import sympy as sp

from .algebraic import AlgebraicRoot
from .errors import InversionError
from .partial_fractions import PoleGroup, residue_scale

__all__ = ["Term", "group_terms", "terms_expr"]

Kind = Literal["real", "oscillatory", "hyperbolic"]


@dataclass(frozen=True)
class Term:
    """One real term t^power · e^{alpha t} · (a·c(beta t) + b·s(beta t)).

    For ``kind == "oscillatory"`` c, s are cos, sin; for ``"hyperbolic"`` cosh, sinh
    (``beta`` is then the real σ of the roots α ± σ); for ``"real"`` only ``a`` is used
    and ``beta == b == 0``.
    """

    kind: Kind
    power: int
    alpha: sp.Expr
    beta: sp.Expr
    a: sp.Expr
    b: sp.Expr

    def as_expr(self, t: sp.Symbol) -> sp.Expr:
        """The term as a SymPy expression in ``t`` (zero parts left out)."""
        if self.kind == "real":
            wave = self.a
        else:
            cos, sin = (sp.cos, sp.sin) if self.kind == "oscillatory" else (sp.cosh, sp.sinh)
            wave = self.a * cos(self.beta * t) + self.b * sin(self.beta * t)
        return t**self.power * sp.exp(self.alpha * t) * wave


def _clean(expr: sp.Expr) -> sp.Expr:
    """Light normalisation of an exact coefficient."""
    expr = sp.sympify(expr)
    expr = sp.expand(expr) if expr.is_number else sp.factor_terms(sp.cancel(expr))
    return sp.radsimp(expr) if expr.has(sp.Pow) and expr.is_number else expr


def _term(kind: Kind, power: int, alpha, beta, a, b, *, clean: bool = True) -> Term | None:
    """A Term, or None when both weights vanish; ``clean`` normalises radicals."""
    if clean:
        alpha, beta, a, b = (_clean(v) for v in (alpha, beta, a, b))
    if a == 0 and b == 0:
        return None
    return Term(kind, power, alpha, beta, a, b)


def _linear_terms(group: PoleGroup) -> list[Term]:
    root = -group.factor.nth(0)  # q = s - root (monic); nth gives a SymPy number
    out = []
    for k, h in enumerate(group.residues, start=1):
        term = _term("real", k - 1, root, 0, h.as_expr() * residue_scale(k), 0)
        if term:
            out.append(term)
    return out


def _quadratic_kind(disc: sp.Expr) -> Kind:
    """Oscillatory unless the discriminant p²/4 - r is known to be positive.

    For an unknown sign the oscillatory form with β = sqrt(-disc) is still exact as an
    identity in the parameters (cos(iσt) = cosh σt, sin(iσt)/i = sinh σt).
    """
    return "hyperbolic" if disc.is_positive else "oscillatory"


def _quadratic_terms(group: PoleGroup) -> list[Term]:
    """q = s² + p s + r with roots α ± iβ (or α ± σ); h(ρ) = u + v ρ."""
    to_sympy = group.factor.domain.to_sympy
    _, p, r = (to_sympy(c) for c in group.factor.all_coeffs())
    alpha = -p / 2
    disc = sp.factor_terms(sp.cancel(alpha**2 - r))
    kind = _quadratic_kind(disc)
    omega = sp.sqrt(disc) if kind == "hyperbolic" else sp.sqrt(-disc)
    sign = 1 if kind == "hyperbolic" else -1
    out = []
    for k, h in enumerate(group.residues, start=1):
        coeffs = [to_sympy(c) for c in h.all_coeffs()]
        v, u = (coeffs[-2] if len(coeffs) > 1 else 0), coeffs[-1]
        scale = residue_scale(k)
        term = _term(kind, k - 1, alpha, omega,
                     2 * (u + v * alpha) * scale, sign * 2 * v * omega * scale)
        if term:
            out.append(term)
    return out


def _upper_roots(q: sp.Poly) -> tuple[list[sp.CRootOf], list[sp.CRootOf]]:
    """Real roots and the upper-half-plane member of each conjugate pair, as CRootOf."""
    expr = q.as_expr()
    real_count = q.count_roots()
    real = [AlgebraicRoot(expr, i) for i in range(real_count)]
    upper = []
    for i in range(real_count, q.degree()):
        root = AlgebraicRoot(expr, i)
        if root._get_interval().ay > 0:
            upper.append(root)
    return real, upper


def _complex_parts(h: sp.Poly, alpha: sp.Expr, beta: sp.Expr) -> tuple[sp.Expr, sp.Expr]:
    """Real and imaginary parts of h(α + iβ) as polynomials in α and β (no I).

    Uses (x + iy)^{j+1} = (P_j x - Q_j y) + i(P_j y + Q_j x) on polynomials in x, y.
    """
    x, y = sp.Dummy("x"), sp.Dummy("y")
    P, Q = sp.Poly(1, x, y, domain=h.domain), sp.Poly(0, x, y, domain=h.domain)
    X, Y = sp.Poly(x, x, y, domain=h.domain), sp.Poly(y, x, y, domain=h.domain)
    re, im = P * 0, P * 0
    for c in reversed(h.all_coeffs()):
        re, im = re + P * c, im + Q * c
        P, Q = P * X - Q * Y, P * Y + Q * X
    values = {x: alpha, y: beta}
    return re.as_expr().xreplace(values), im.as_expr().xreplace(values)


def _rational_factor(q: sp.Poly) -> sp.Poly:
    """q over ℚ, or an InversionError if its coefficients are not rational."""
    coeffs = [q.domain.to_sympy(c) for c in q.all_coeffs()]
    if not all(c.is_Rational for c in coeffs):
        raise InversionError(
            f"irreducible factor {q.as_expr()} of degree {q.degree()} has symbolic "
            "coefficients: its roots have no closed form; substitute numbers")
    return sp.Poly(coeffs, q.gen, domain=sp.QQ)


def _algebraic_terms(group: PoleGroup) -> list[Term]:
    real, upper = _upper_roots(_rational_factor(group.factor))
    out = []
    for k, h in enumerate(group.residues, start=1):
        scale = residue_scale(k)
        for root in real:
            value = (h * scale).as_expr().xreplace({h.gen: root})
            term = _term("real", k - 1, root, 0, value, 0, clean=False)
            if term:
                out.append(term)
        for root in upper:
            alpha, beta = sp.re(root), sp.im(root)
            x, y = _complex_parts(h * (2 * scale), alpha, beta)
            term = _term("oscillatory", k - 1, alpha, beta, x, -y, clean=False)
            if term:
                out.append(term)
    return out


def _is_symbolic_biquadratic(q: sp.Poly) -> bool:
    """s⁴ + p s² + r with coefficients that are not all rational."""
    coeffs = [q.domain.to_sympy(c) for c in q.all_coeffs()]
    return q.degree() == 4 and coeffs[1] == 0 and coeffs[3] == 0 and not all(
        c.is_Rational for c in coeffs)


def _biquadratic_terms(group: PoleGroup) -> list[Term]:
    """q = s⁴ + p s² + r, an undamped pair: roots ±iω with ω² = -z, z² + p z + r = 0.

    With h(s) = h_e(s²) + s·h_o(s²), the pair ±iω contributes
    2 h_e(z) cos ωt - 2ω h_o(z) sin ωt, an identity in ω whatever the sign of z.
    """
    to_sympy = group.factor.domain.to_sympy
    _, _, p, _, r = (to_sympy(c) for c in group.factor.all_coeffs())
    root = sp.sqrt(sp.factor(p**2 - 4 * r))
    out = []
    for z in ((-p + root) / 2, (-p - root) / 2):
        omega = sp.sqrt(-z)
        for k, h in enumerate(group.residues, start=1):
            c = [to_sympy(v) for v in reversed(h.all_coeffs())] + [0] * 4
            even, odd = c[0] + c[2] * z, c[1] + c[3] * z
            scale = 2 * residue_scale(k)
            term = _term("oscillatory", k - 1, 0, omega, sp.factor_terms(even * scale),
                         sp.factor_terms(-omega * odd * scale), clean=False)
            if term:
                out.append(term)
    return out


def group_terms(group: PoleGroup) -> list[Term]:
    """Real terms of one pole group (see the module docstring for the forms)."""
    if group.degree == 1:
        return _linear_terms(group)
    if group.degree == 2:
        return _quadratic_terms(group)
    if _is_symbolic_biquadratic(group.factor):
        return _biquadratic_terms(group)
    return _algebraic_terms(group)


def terms_expr(terms: list[Term], t: sp.Symbol) -> sp.Expr:
    """Sum of terms as one expression in t."""
    return sp.Add(*(term.as_expr(t) for term in terms))

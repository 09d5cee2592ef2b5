"""Real damped sine/cosine terms from a partial-fraction decomposition.

Each pole group of :mod:`laplace_springs.exact.partial_fractions` becomes terms

    t^k e^{αt} (a cos βt + b sin βt)     a complex-conjugate pair α ± iβ,
    t^k e^{αt} (a cosh σt + b sinh σt)   a pair of real quadratic surds α ± σ,
    t^k e^{αt} a                         a real root α (a polynomial term when α = 0),

with exact α, β, a, b. This module is the one place where conjugate roots are folded
into real form. A factor whose roots have no closed form (degree ≥ 3, symbolic
coefficients) gives one :class:`RootSumTerm` instead: Σ_{q(λ)=0} N(λ)/D'(λ) e^{λt}, a
sum over its roots (:mod:`laplace_springs.exact.root_sums`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, field
from typing import Literal

import sympy as sp

from ..model.errors import InversionError
from .algebraic import AlgebraicRoot
from .named import named
from .partial_fractions import PoleGroup, RootSumGroup, is_symbolic_biquadratic, residue_scale
from .root_sums import Condition, sum_over_roots

__all__ = ["Term", "RootSumTerm", "derivative_terms", "group_terms", "terms_expr",
           "solution_terms", "naming_scope", "reserved_names"]

Kind = Literal["real", "oscillatory", "hyperbolic", "root_sum"]


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


@dataclass(frozen=True)
class RootSumTerm(Term):
    """Σ_{q(λ)=0} Σ_k w_k(λ) t^k e^{λt}: the terms of a factor without closed-form roots.

    ``kind`` is ``"root_sum"``; the single-pole fields ``alpha``, ``beta``, ``a``, ``b``
    are NaN (no one pole), ``power`` is 0. For a simple factor w_0 = N(λ)/D'(λ) (the
    residue of N/D at a root), so :meth:`as_expr` is the textbook
    Σ_{Δ(λ)=0} N_i(λ)/Δ'(λ) e^{λt} for the free motion of a scene.

    Attributes
    ----------
    factor : sympy.Poly
        q(λ), summed over.
    weights : tuple of sympy.Expr
        w_k(λ), in q's generator.
    group : RootSumGroup
        The numerator N and denominator D it comes from (for printing and conditions).
    """

    factor: sp.Poly
    weights: tuple[sp.Expr, ...]
    group: RootSumGroup

    def as_expr(self, t: sp.Expr) -> sp.Expr:
        """The sum over the roots as one :class:`~laplace_springs.exact.root_sums.SumOverRoots`."""
        return sum_over_roots(self.factor, self.weights, t)

    @property
    def condition(self) -> Condition:
        """Where the formula holds: q's roots are simple roots of the denominator."""
        group = self.group
        return Condition(_primitive(group.factor),
                         _primitive(group.denominator.exquo(group.factor ** group.multiplicity)))

    def derivative(self) -> RootSumTerm:
        """d/dt, term by term: t^k e^{λt} → k t^{k-1} e^{λt} + λ t^k e^{λt}."""
        var, w = self.factor.gen, list(self.weights)
        weights = tuple(var * w[k] + (k + 1) * (w[k + 1] if k + 1 < len(w) else 0)
                        for k in range(len(w)))
        return dataclasses.replace(self, weights=weights)


def root_sum_term(group: RootSumGroup) -> RootSumTerm:
    """The term of a :class:`RootSumGroup`."""
    nan = sp.nan
    return RootSumTerm("root_sum", 0, nan, nan, nan, nan, factor=group.factor,
                       weights=group.weights, group=group)


def _primitive(poly: sp.Poly) -> sp.Poly:
    _, cleared = poly.clear_denoms(convert=True)
    return cleared.primitive()[1]


def _clean(expr: sp.Expr) -> sp.Expr:
    """Light normalisation of an exact coefficient: radicals out of denominators where
    the number has at most two kinds of radical (with more, SymPy's radsimp expands
    without end: √5 − 1, ∛2 and √3/3 on one forced mass ran for minutes)."""
    expr = sp.sympify(expr, strict=True)
    expr = sp.expand(expr) if expr.is_number else sp.factor_terms(sp.cancel(expr))
    if not (expr.is_number and expr.has(sp.Pow)):
        return expr
    radicals = {p for p in expr.atoms(sp.Pow) if p.exp.is_Rational and not p.exp.is_Integer}
    return sp.radsimp(expr) if len(radicals) <= _RADICALS else expr


#: Most kinds of radical in a coefficient that radsimp rationalises.
_RADICALS = 2


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


def _upper_roots(q: sp.Poly) -> tuple[list[sp.Expr], list[tuple[sp.Expr, sp.Expr]]]:
    """Real roots, and (α, β) with β > 0 for each conjugate pair α ± iβ, exactly.

    An even factor q(s) = p(s²) whose p has only negative roots μ (an undamped,
    irreducible biquadratic) gives the pairs ±i√(−μ) with μ a real CRootOf of p, so
    β = √(−μ) is written as a real number rather than as im(CRootOf(q)).
    """
    even = _even_part(q)
    if even is not None and even.count_roots() == even.degree():
        if even.degree() <= 2:
            mus = sorted(sp.roots(even).keys(), key=float)
        else:
            mus = [AlgebraicRoot(even.as_expr(), i) for i in range(even.degree())]
        if all(mu.is_negative for mu in mus):
            return [], [(sp.S.Zero, sp.sqrtdenest(sp.sqrt(-mu))) for mu in mus]
    expr = q.as_expr()
    real_count = q.count_roots()
    real = [AlgebraicRoot(expr, i) for i in range(real_count)]
    upper = []
    for i in range(real_count, q.degree()):
        root = AlgebraicRoot(expr, i)  # may come back rescaled, e.g. 2*CRootOf(...)
        inner = root if isinstance(root, sp.CRootOf) else next(iter(root.atoms(sp.CRootOf)))
        sign = 1 if inner is root else sp.sign(root / inner)
        if sign * inner._get_interval().ay > 0:
            upper.append((sp.re(root), sp.im(root)))
    return real, upper


def _even_part(q: sp.Poly) -> sp.Poly | None:
    """p with q(s) = p(s²), or None when q has an odd power."""
    coeffs = q.all_coeffs()[::-1]
    if any(c != 0 for c in coeffs[1::2]):
        return None
    return sp.Poly(list(reversed(coeffs[0::2])), q.gen, domain=q.domain)  # in μ = s²


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
        for alpha, beta in upper:
            x, y = _complex_parts(h * (2 * scale), alpha, beta)
            term = _term("oscillatory", k - 1, alpha, beta, x, -y, clean=False)
            if term:
                out.append(term)
    return out


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


# ---------------------------------------------------------------------------
# symbolic factors: named frequencies and damping rates
# ---------------------------------------------------------------------------
@dataclass
class _Names:
    """Numbering of named quantities shared by all coordinates of one solution."""

    counters: dict[str, int] = field(default_factory=dict)
    assigned: dict[tuple, sp.Expr] = field(default_factory=dict)

    def get(self, key: tuple, base: str, definition: sp.Expr, *, positive: bool | None,
            meaning: str, display: sp.Expr | None = None) -> sp.Expr:
        """The named atom for (factor key, base); the next free index on first use."""
        if (key, base) not in self.assigned:
            index = self.counters.get(base, 0) + 1
            taken = _RESERVED.get()
            while f"{base}_{index}" in taken:  # a parameter of the scene has that name
                index += 1
            atom = named(base, index, definition, positive=positive, meaning=meaning,
                         display=display)
            if atom.free_symbols:
                self.counters[base] = index
            self.assigned[key, base] = atom
        return self.assigned[key, base]


_SCOPE: ContextVar[_Names | None] = ContextVar("laplace_springs_names", default=None)
_RESERVED: ContextVar[frozenset[str]] = ContextVar("laplace_springs_reserved", default=frozenset())


@contextmanager
def reserved_names(names: Iterable[str]) -> Iterator[None]:
    """Printed names the named quantities made inside must not take: the names of the
    scene's parameters, so that a parameter called ``omega_1`` or ``gamma_1`` is never
    shown next to a different quantity of the same name (ω₁ = √ω₁).

    >>> import sympy as sp
    >>> from laplace_springs.model.scene import Scene
    >>> from laplace_springs.exact.assembly import exact_motion   # reserves the scene's names
    >>> exact_motion(Scene.from_matrices(M=[[1]], K=[[sp.Symbol("omega_1")]], x0=[1], v0=[0])).x[0]
    cos(t*omega_2)
    """
    token = _RESERVED.set(_RESERVED.get() | frozenset(names))
    try:
        yield
    finally:
        _RESERVED.reset(token)


@contextmanager
def naming_scope() -> Iterator[None]:
    """Number named quantities (ω₁, ω₂, γ₁, ...) consistently across several calls.

    Inside the scope every :func:`group_terms` call shares one numbering, so two
    factors of one Δ(λ) get distinct names and every coordinate uses the same ones.
    Outside a scope each call numbers from 1 (fine when Δ has one symbolic factor).
    """
    token = _SCOPE.set(_Names())
    try:
        yield
    finally:
        _SCOPE.reset(token)


def _names() -> _Names:
    return _SCOPE.get() or _Names()


def _factor_key(q: sp.Poly) -> tuple:
    return tuple(q.domain.to_sympy(c) for c in q.all_coeffs())


def _group_numerator(group: PoleGroup) -> list[sp.Expr]:
    """Ascending coefficients of Ñ with Σ_{q(ρ)=0} h(ρ)/(s - ρ) = Ñ(s)/q(s) (simple pole)."""
    q = group.factor
    numerator = (group.residues[0] * q.diff()).rem(q)
    to_sympy = q.domain.to_sympy
    coeffs = [sp.factor(to_sympy(c)) for c in reversed(numerator.all_coeffs())]
    return coeffs + [sp.S.Zero] * (q.degree() - len(coeffs))


def _tidy(expr: sp.Expr) -> sp.Expr:
    """A coefficient written over one denominator, common factors pulled out."""
    return sp.factor_terms(sp.together(expr))


def _is_symbolic(q: sp.Poly) -> bool:
    return any(q.domain.to_sympy(c).free_symbols for c in q.all_coeffs())


def _named_quadratic_terms(group: PoleGroup) -> list[Term]:
    """q = s² + p s + r with symbolic p, r: e^{-γt}(Ñ₁ cos ωt + (Ñ₀ - γÑ₁) sin(ωt)/ω).

    γ = p/2 is the damping rate, ω² = r - γ² the damped frequency squared. When
    γ² - r is known to be positive (overdamped) the pair is cosh/sinh with σ² = γ² - r;
    otherwise the oscillatory form is used, and it stays an identity for overdamped
    values (cos iσt = cosh σt, sin(iσt)/(iσ) = sinh(σt)/σ): only the critical case
    ω = 0 is excluded, which the name's meaning states.
    """
    _, p, r = _factor_key(group.factor)
    names, key = _names(), _factor_key(group.factor)
    rate = sp.factor(p / 2)
    gamma = names.get(key, "gamma", _readable(rate), positive=rate.is_positive or None,
                      meaning="damping rate") if rate != 0 else sp.S.Zero
    square = sp.factor(r - rate**2)
    shown_square = _readable(r) - gamma**2
    if (-square).is_positive:
        kind: Kind = "hyperbolic"
        frequency = names.get(key, "sigma", sp.sqrt(-square), positive=True,
                              meaning="hyperbolic rate (overdamped)", display=sp.sqrt(-shown_square))
    else:
        kind = "oscillatory"
        meaning = "natural frequency" if rate == 0 else "damped frequency"
        if not square.is_positive:
            meaning += ", underdamped assumed (positive radicand)"
        frequency = names.get(key, "omega", sp.sqrt(square), positive=square.is_positive or None,
                              meaning=meaning, display=sp.sqrt(shown_square) if rate != 0 else None)
    c0, c1 = _group_numerator(group)
    sin_weight = _readable(c0 - rate * c1)
    if rate != 0:
        sin_weight = _readable(sin_weight.subs(_readable(rate), gamma))
    term = _term(kind, 0, -gamma, frequency, c1, sin_weight / frequency, clean=False)
    return [term] if term else []


def _named_biquadratic_terms(group: PoleGroup) -> list[Term]:
    """q = s⁴ + S s² + P = (s² + ω₁²)(s² + ω₂²): an undamped symbolic pair.

    ω₁² ≤ ω₂² are the roots of z² - S z + P = 0 (S = ω₁² + ω₂², P = ω₁²ω₂²). With
    Ñ(s) = E(s²) + s·O(s²),

        Ñ/q = Σ_j [O(-ω_j²) s + E(-ω_j²)] / [(s² + ω_j²)(ω_k² - ω_j²)],  k ≠ j,

    so the pair contributes Σ_j ±[O(-ω_j²) cos ω_j t + E(-ω_j²) sin(ω_j t)/ω_j]/(ω₂² - ω₁²).
    """
    _, _, total, _, product = _factor_key(group.factor)
    names, key = _names(), _factor_key(group.factor)
    positive = True if (total.is_positive and product.is_positive) else None
    S = names.get(key, "S", _readable(total), positive=total.is_positive or None,
                  meaning="sum of the squared natural frequencies")
    P = names.get(key, "P", _readable(product), positive=product.is_positive or None,
                  meaning="product of the squared natural frequencies")
    root = sp.sqrt(sp.factor(total**2 - 4 * product))
    shown_root = sp.sqrt(S**2 - 4 * P)
    omegas = [names.get(key + (j,), "omega", sp.sqrt((total + sign * root) / 2),
                        positive=positive, meaning="natural frequency",
                        display=sp.sqrt((S + sign * shown_root) / 2))
              for j, sign in ((0, -1), (1, 1))]
    c0, c1, c2, c3 = _group_numerator(group)
    gap = omegas[1] ** 2 - omegas[0] ** 2
    out = []
    for j, w in enumerate(omegas):
        z, sign = -w**2, (1, -1)[j]
        cos_weight = sp.Mul(sign, _readable(c1 + c3 * z), 1 / gap, evaluate=True)
        sin_weight = sp.Mul(sign, _readable(c0 + c2 * z), 1 / (w * gap))
        term = _term("oscillatory", 0, 0, w, cos_weight, sin_weight, clean=False)
        if term:
            out.append(term)
    return out


def _readable(expr: sp.Expr) -> sp.Expr:
    """A sum of simple fractions: terms grouped by denominator, numerators factored.

    ((k1 + k2)/m1 + (k2 + k3)/m2 rather than one fraction over m1·m2.)
    """
    groups: dict[sp.Expr, list[sp.Expr]] = {}
    for term in sp.Add.make_args(sp.expand(expr)):
        numerator, denominator = sp.fraction(term)
        groups.setdefault(denominator, []).append(numerator)
    return sp.Add(*(sp.factor_terms(sp.Add(*parts)) / denominator
                    for denominator, parts in groups.items()))


def _named_terms(group: PoleGroup) -> list[Term] | None:
    """Named-quantity terms for a simple symbolic quadratic or even quartic, else None."""
    if group.multiplicity != 1 or not _is_symbolic(group.factor):
        return None
    if group.degree == 2:
        return _named_quadratic_terms(group)
    if is_symbolic_biquadratic(group.factor):
        return _named_biquadratic_terms(group)
    return None


def group_terms(group: PoleGroup) -> list[Term]:
    """Real terms of one pole group (see the module docstring for the forms).

    Symbolic quadratic and even quartic factors with simple roots come out in named
    quantities (ω_j, γ_j, σ_j: see :mod:`laplace_springs.exact.named`).
    """
    if isinstance(group, RootSumGroup):
        return [root_sum_term(group)]
    named_terms = _named_terms(group)
    if named_terms is not None:
        return named_terms
    if group.degree == 1:
        return _linear_terms(group)
    if group.degree == 2:
        return _quadratic_terms(group)
    if is_symbolic_biquadratic(group.factor):
        return _biquadratic_terms(group)
    return _algebraic_terms(group)


def solution_terms(decompositions) -> tuple[tuple[Term, ...], ...]:
    """Terms of every coordinate, with one numbering of named quantities for all."""
    with naming_scope():
        return tuple(tuple(term for group in pf.groups for term in group_terms(group))
                     for pf in decompositions)


def terms_expr(terms: list[Term], t: sp.Symbol) -> sp.Expr:
    """Sum of terms as one expression in t."""
    return sp.Add(*(term.as_expr(t) for term in terms))


def _derivative(term: Term) -> list[Term]:
    """The exact derivative of one real term, as real terms of the same kind."""
    if isinstance(term, RootSumTerm):
        return [term.derivative()]
    p, alpha, beta, a, b = term.power, term.alpha, term.beta, term.a, term.b
    out = []
    if p:
        out.append(Term(term.kind, p - 1, alpha, beta, p * a, p * b))
    if term.kind == "real":
        out.append(Term("real", p, alpha, beta, alpha * a, sp.Integer(0)))
    elif term.kind == "oscillatory":  # (a cos + b sin)' = β(b cos − a sin)
        out.append(Term(term.kind, p, alpha, beta, alpha * a + beta * b, alpha * b - beta * a))
    else:  # (a cosh + b sinh)' = σ(b cosh + a sinh)
        out.append(Term(term.kind, p, alpha, beta, alpha * a + beta * b, alpha * b + beta * a))
    return out


def derivative_terms(rows) -> tuple[tuple[Term, ...], ...]:
    """The exact terms of d/dt of each row of terms, term by term.

    Examples
    --------
    >>> rows = derivative_terms([[Term("oscillatory", 0, 0, 2, 1, 0)]])   # cos 2t
    >>> terms_expr(list(rows[0]), sp.Symbol("t"))
    -2*sin(2*t)
    """
    return tuple(tuple(d for term in row for d in _derivative(term)) for row in rows)

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

**What has real terms, and the limit.** Every factor of degree ≤ 2 has closed-form
roots, whatever its coefficients, and so has an even quartic s⁴ + p s² + r (a quadratic
in s²). A factor of degree ≥ 3 with rational coefficients has exact algebraic roots
(``CRootOf``), but its terms grow fast with the degree d: the root isolation and the
real and imaginary parts of the residues cost about d⁴ (measured for s^d + s + 1, one
transform: d = 12 0.18 s, 16 0.37 s, 24 1.2 s, 30 2.9 s, 40 9.9 s), and a scene pays it
once per coordinate (a damped 8-mass chain with an irreducible Δ of degree 16: 4 s).
Beyond :attr:`~laplace_springs.limits.Limits.max_exact_factor_degree` the inversion is refused at once, as is a factor
of degree ≥ 3 with irrational coefficients, or one whose roots SymPy's ``CRootOf`` would
number only after minutes (roots whose sizes span hundreds of decades:
:attr:`~laplace_springs.limits.Limits.max_exact_isolation`,
:mod:`laplace_springs.exact.isolation`): :func:`closed_form_obstacle` says which,
before any residue is computed (``closed_form=True``). A factor of degree ≥ 3 with
symbolic coefficients (an even quartic excepted) has no closed-form roots either; with
``root_sums=True`` it becomes a :class:`RootSumGroup`, whose terms are a sum over its
roots Σ_{q(ρ)=0} N(ρ)/D'(ρ) e^{ρt} (:mod:`laplace_springs.exact.root_sums`): nothing is
reduced modulo q, so it costs milliseconds where its residues took minutes of gcds over
the parameters' field (without ``root_sums`` it is refused). The partial fractions
themselves stay cheap (degree 200: 0.01 s) for rational coefficients, so
:func:`partial_fractions` refuses nothing by default. A factor that cancels from every
numerator (its principal parts all vanish) is never refused.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from math import factorial
from typing import Any

import flint
import mpmath
import sympy as sp

from ..kernels.precision import workdps
from ..limits import limits
from ..model.errors import InternalError, InversionError, SceneError
from ..model.numbers import TRANSCENDENTAL, declare_parameters, parse_expression, shown
from ..model.symbols import TIME
from .domains import field_polys
from .isolation import isolation_size
from .rational import from_poly, rational_partial_fractions, to_poly
from .root_sums import Condition, SumOverRoots, root_sum_weights

__all__ = ["PoleGroup", "RootSumGroup", "PartialFractions", "partial_fractions", "decompose", "exact_factors",
           "closed_form_obstacle", "isolation_obstacle", "check_closed_form",
           "is_symbolic_biquadratic", "is_root_sum_factor", "transform_of", "GenericCondition",
           "denominator_conditions"]



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
class RootSumGroup(PoleGroup):
    """The principal parts of N/D at the roots of a factor without closed-form roots.

    Its residues are not computed (that takes gcds over the parameters' field): the
    group keeps N and D, and its terms are Σ_{q(ρ)=0} N(ρ)/D'(ρ) e^{ρt} (with t^k terms
    when q^m, m > 1, divides D). ``residues`` is empty.

    Attributes
    ----------
    numerator, denominator : sympy.Poly
        N and D, with the powers of q that divide N cancelled from both:
        q^multiplicity divides D exactly and q does not divide N.
    """

    numerator: sp.Poly
    denominator: sp.Poly

    @property
    def order(self) -> int:
        """Order of the pole (q does not divide the numerator, so it does not cancel)."""
        return self.multiplicity

    @property
    def weights(self) -> tuple[sp.Expr, ...]:
        """w_k(λ) with the inverse Σ_{q(λ)=0} Σ_k w_k(λ) t^k e^{λt} (see
        :func:`~laplace_springs.exact.root_sums.root_sum_weights`)."""
        return root_sum_weights(self.factor, self.numerator, self.denominator, self.multiplicity)

    def as_expr(self) -> sp.Expr:
        """Σ_{q(ρ)=0} Σ_k k! w_k(ρ)/(s − ρ)^{k+1}, a sum over the roots (unevaluated)."""
        s = self.factor.gen
        rho = sp.Dummy("rho")
        summand = sp.Add(*(factorial(k) * w.xreplace({s: rho}) / (s - rho) ** (k + 1)
                           for k, w in enumerate(self.weights)))
        poly = sp.PurePoly(self.factor.as_expr().xreplace({s: rho}), rho)
        return SumOverRoots._new(poly, sp.Lambda(rho, summand))


@dataclass(frozen=True)
class PartialFractions:
    """Structured partial-fraction decomposition of a rational function of ``variable``.

    ``polynomial`` is the polynomial part (zero for a proper function) and ``groups`` the
    principal parts, one :class:`PoleGroup` per irreducible factor of the denominator.
    """

    variable: sp.Symbol
    polynomial: sp.Poly
    groups: tuple[PoleGroup, ...]
    conditions: tuple[Condition, ...] = field(default=(), compare=False)

    def as_expr(self) -> sp.Expr:
        """Recombine the decomposition into a single rational function (for checks)."""
        total = self.polynomial.as_expr()
        for group in self.groups:
            total += group.as_expr()
        return sp.cancel(sp.together(total))


def is_symbolic_biquadratic(q: sp.Poly) -> bool:
    """s⁴ + p s² + r with coefficients that are not all rational (roots in radicals)."""
    coeffs = [q.domain.to_sympy(c) for c in q.all_coeffs()]
    return q.degree() == 4 and coeffs[1] == 0 and coeffs[3] == 0 and not all(
        c.is_Rational for c in coeffs)


def is_root_sum_factor(q: sp.Poly) -> bool:
    """An irreducible factor of degree ≥ 3 with symbolic coefficients, not an even quartic:
    its roots have no closed form in the parameters, its terms are a sum over its roots.

    >>> s, a = sp.symbols("s a")
    >>> is_root_sum_factor(sp.Poly(s**3 + a*s + 1, s)), is_root_sum_factor(sp.Poly(s**4 + a*s**2 + 1, s))
    (True, False)
    """
    if q.degree() < 3 or is_symbolic_biquadratic(q):
        return False
    return any(q.domain.to_sympy(c).free_symbols for c in q.all_coeffs())


def closed_form_obstacle(q: sp.Poly) -> str | None:
    """Why the irreducible factor ``q`` has no exact real terms, or None if it has.

    Cheap: it looks at the degree and the coefficients, and for a rational factor of
    degree ≥ 3 at flint's enclosures of its roots (:func:`isolation_obstacle`,
    milliseconds).

    Examples
    --------
    >>> s, a = sp.symbols("s a")
    >>> closed_form_obstacle(sp.Poly(s**4 + a*s**2 + 1, s)) is None   # a quadratic in s²
    True
    >>> print(closed_form_obstacle(sp.Poly(s**4 + a*s + 1, s)))   # doctest: +ELLIPSIS
    irreducible factor of degree 4 has symbolic coefficients (a*s + s**4 + 1): ...
    >>> print(closed_form_obstacle(sp.Poly(s**200 + 2*s + 2, s)))   # doctest: +ELLIPSIS
    irreducible factor of degree 200 > Limits.max_exact_factor_degree = 24: ...
    >>> e = sp.Rational(1, 10**300)   # a frequency of 1.6 against a decay rate of 1e-301
    >>> print(closed_form_obstacle(sp.Poly(s**4 + e*s**3 + 3*s**2 + e*s + 1, s)))  # doctest: +ELLIPSIS
    irreducible factor of degree 4 whose roots SymPy's CRootOf numbers only after about 1.6e+07 units of work > Limits.max_exact_isolation = 2,000,000 ...
    """
    degree = q.degree()
    if degree <= 2:
        return None
    coeffs = [q.domain.to_sympy(c) for c in q.all_coeffs()]
    if all(c.is_Rational for c in coeffs):
        if degree <= limits().max_exact_factor_degree:
            return isolation_obstacle(coeffs)
        longer = f", {degree}: longer" if degree > 40 else ""
        return (f"irreducible factor of degree {degree} > Limits.max_exact_factor_degree = "
                f"{limits().max_exact_factor_degree}: exact terms in written-out form cost about the "
                f"fourth power of the degree (degree 16: 0.4 s, 24: 1.2 s, 40: 10 s{longer}); the numeric "
                "routes evaluate any degree for the free motion and for sampled forces "
                "(ls.solve(scene, method='modal') or method='certified'; a free scene with rational "
                "entries is also solved exactly in named roots); formula and periodic forces on "
                "numeric scenes go by the inputs' own dynamics (ls.solve(scene), method='exo')")
    if is_symbolic_biquadratic(q):
        return None
    symbols = sorted(set().union(*(c.free_symbols for c in coeffs)), key=str)
    if symbols:
        names = ", ".join(map(str, symbols))
        return (f"irreducible factor of degree {degree} has symbolic coefficients "
                f"({q.as_expr()}): its roots have no closed form (in the parameters only factors "
                "of degree <= 2 and even quartics s**4 + p*s**2 + r are solved); the exact "
                "inverse is a sum over its roots (root_sums=True), or substitute "
                f"numbers for {names}")
    return (f"irreducible factor of degree {degree} has irrational coefficients "
            f"({q.as_expr()}): its roots are not computed exactly; use rational numbers "
            "(decimals are exact), or ls.solve(scene) with method='auto' (a numeric engine "
            "serves it: 'modal' for the free motion, 'exo' for formula forces)")


def isolation_obstacle(coeffs: list[sp.Rational], cause: str = "entries of very different sizes"
                       ) -> str | None:
    """Why SymPy's ``CRootOf`` cannot number the roots of the irreducible rational
    polynomial with these coefficients (highest first) in reasonable time, or None: its
    :func:`~laplace_springs.exact.isolation.isolation_work` beyond
    :attr:`~laplace_springs.limits.Limits.max_exact_isolation`. ``cause`` says where
    the scales come from (the scene's entries, when known). None for coefficients that
    are not rational (other obstacles apply to them)."""
    if not all(isinstance(c, sp.Rational) for c in coeffs):
        return None
    poly = flint.fmpq_poly([flint.fmpq(int(c.p), int(c.q)) for c in reversed(coeffs)])
    size = isolation_size(poly)
    most = limits().max_exact_isolation
    if size.work <= most:
        return None
    return (f"irreducible factor of degree {poly.degree()} whose roots SymPy's CRootOf numbers only "
            f"after about {size.work:.1e} units of work > Limits.max_exact_isolation = {most:,} "
            f"(3 to 15 s; 1.5e-6 to 2e-5 s a unit, k²·D·b): {size.off_line} roots off the real line, "
            f"{size.bisections:.0f} bisections from a root of size {size.largest} down to a part "
            f"of {size.smallest}, coefficients of {size.bits:,} bits. The dynamics span scales "
            f"that far apart ({cause}); the free motion of a scene with rational entries is "
            "still solved exactly, in named roots (ls.solve(scene, method='exact')), and "
            "numerically (method='certified'); with "
            f"ls.using_limits(max_exact_isolation={_above(size.work)}) the written-out terms are "
            "built, slowly")


def _above(work: float) -> str:
    """A round number above ``work`` for a message (two significant digits, with _)."""
    power = 10 ** max(int(math.log10(max(work, 1.0))) - 1, 0)
    return f"{math.ceil(work / power) * power:_}"


def _divides(q: sp.Poly, N: sp.Poly) -> bool:
    """Whether q divides N, by pseudo-division over the coefficient ring (no gcds)."""
    if N.is_zero:
        return True
    if N.degree() < q.degree():
        return False
    _, q = q.clear_denoms(convert=True)
    _, N = N.clear_denoms(convert=True)
    domain = q.domain.unify(N.domain)
    return N.set_domain(domain).prem(q.set_domain(domain)).is_zero


def check_closed_form(factors: list[tuple[sp.Poly, int]], numerators: list[sp.Poly], *,
                      root_sums: bool = False) -> set[int]:
    """Raise InversionError if a factor without exact real terms stays in some fraction.

    ``factors`` are the irreducible factors q with their multiplicities m in the shared
    denominator; q is refused (:func:`closed_form_obstacle`) unless q^m divides every
    numerator, so that its principal parts all vanish. Cheap: degrees, coefficients and,
    only for such a factor, pseudo-remainders. With ``root_sums`` the factors of
    :func:`is_root_sum_factor` are not refused (their terms are sums over their roots).

    Returns
    -------
    set of int
        The indices of the factors without exact real terms that cancel from every
        numerator: their principal parts are zero and need not be computed.
    """
    cancelled = set()
    for index, (q, m) in enumerate(factors):
        obstacle = closed_form_obstacle(q)
        if obstacle is None or (root_sums and is_root_sum_factor(q)):
            continue
        if not all(_divides(q**m, N) for N in numerators):
            raise InversionError(obstacle)
        cancelled.add(index)
    return cancelled


def transform_of(F: object, s: sp.Symbol, parameters: object = None) -> sp.Expr:
    """F as a SymPy expression: text is read by the safe parser, never evaluated.

    Text may name ``s`` and the declared ``parameters`` (names, positive by default, or
    a mapping name -> assumption; see
    :func:`laplace_springs.model.numbers.declare_parameters`); any other name is refused.

    Examples
    --------
    >>> s = sp.Symbol("s")
    >>> transform_of("1/(s**2 + a*s + 1)", s, ["a"])
    1/(a*s + s**2 + 1)
    >>> transform_of("__import__('os').system('ls')", s)
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.InversionError: the transform: expected an expression in s, got "__import__('os').system('ls')": unexpected character '_' at column 1
    """
    if not isinstance(s, sp.Symbol):
        raise InversionError(f"the transform variable must be a Symbol, got {shown(s)}")
    if isinstance(F, str):
        try:
            declared = declare_parameters(parameters)
            parsed = parse_expression(F.strip(), "the transform", variables={**declared, s.name: s},
                                      expected=f"an expression in {s.name}")
        except SceneError as exc:
            raise InversionError(str(exc)) from None
        if s != TIME and parsed.has(TIME):
            raise InversionError(f"the transform {parsed} contains the time t; write it in {s.name}")
        return parsed
    try:
        return sp.sympify(F, strict=True)  # expressions and numbers
    except sp.SympifyError:
        raise InversionError(f"the transform must be text or a SymPy expression, got {shown(F)}") from None


def _field_polys(F: sp.Expr, s: sp.Symbol) -> tuple[sp.Poly, sp.Poly]:
    """Numerator and denominator of F as polynomials in s over a common field."""
    F = transform_of(F, s)
    if F.has(sp.zoo, sp.oo, -sp.oo, sp.nan):
        raise InversionError(f"the transform is not finite: {F} (a zero denominator?)")
    if F.has(sp.Float):
        F = F.xreplace({f: sp.Rational(str(f)) for f in F.atoms(sp.Float)})
    numerator, denominator = sp.fraction(sp.cancel(sp.together(F)))
    try:
        N, D = field_polys([numerator, denominator], s)  # not EX when e^{ab} is a coefficient
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


def _root_sum_group(q: sp.Poly, m: int, N: sp.Poly, D: sp.Poly) -> RootSumGroup | None:
    """The group of N/D at q's roots, the powers of q dividing N cancelled (None if all)."""
    while m and _divides(q, N):  # pseudo-division first: no gcds unless q divides N
        N, D, m = N.exquo(q), D.exquo(q), m - 1
    return RootSumGroup(q, m, (), N, D) if m else None


def decompose(numerators: list[sp.Poly], denominator: sp.Poly, *,
              closed_form: bool = False, root_sums: bool = False,
              parts: tuple[sp.Poly, ...] = ()) -> list[PartialFractions]:
    """Partial fractions of several numerators over one shared denominator.

    The denominator is factored once and the inverse series of each factor's cofactor is
    shared, which is what a solution vector X(λ) = adj(λ)·r(λ)/Δ(λ) needs.

    Parameters
    ----------
    numerators : list of sympy.Poly
        Polynomials over the same field and generator as ``denominator``.
    denominator : sympy.Poly
        Nonzero polynomial.
    closed_form : bool
        Refuse at once, right after factoring and before any residue is computed, when a
        factor has no exact real terms (:func:`closed_form_obstacle`): what the
        inversions ask for. The residues of a symbolic factor of degree ≥ 3 can take
        minutes (gcds over the parameters' field).
    root_sums : bool
        With ``closed_form``: a factor of :func:`is_root_sum_factor` (symbolic
        coefficients, degree ≥ 3, no closed-form roots) is not refused but gives a
        :class:`RootSumGroup` per numerator, without residues (milliseconds).
    parts : tuple of sympy.Poly, optional
        Polynomials whose product is ``denominator`` (Δ(λ) and the forces' own
        denominator): with irrational coefficients they are factored one by one where
        they share no root.

    Returns
    -------
    list of PartialFractions
        One decomposition per numerator, in order.
    """
    s = denominator.gen
    if _numeric_generators(denominator.domain) or any(_numeric_generators(N.domain) for N in numerators):
        # ZZ[pi, sqrt(pi)] takes sqrt(pi)**2 for a new unknown: (λ + √π)² would be a simple
        # factor with residues over 0. EX simplifies the numbers' expressions instead.
        denominator = denominator.set_domain(sp.EX)
        numerators = [N.set_domain(sp.EX) for N in numerators]
    own_field = denominator.domain.get_field()
    field = own_field
    for N in numerators:
        field = field.unify(N.domain.get_field())
    denominator = denominator.set_domain(own_field)
    lc = denominator.LC()
    # over EX (irrational entries) SymPy's factor_list leaves a square whole: exact_factors
    factors = [(f.set_domain(own_field).monic(), m) for f, m in _factors(denominator, parts)]
    summed = root_sums and closed_form
    cancelled = check_closed_form(factors, numerators, root_sums=summed) if closed_form else set()
    if field != own_field:
        factors = [(f.set_domain(field), m) for f, m in factors]
        denominator = denominator.set_domain(field)
    numerators = [N.set_domain(field) for N in numerators]
    if field.is_QQ:  # residues in python-flint, the same polynomials
        return _rational_decompose(numerators, denominator, factors, cancelled)
    quotients = [N.div(denominator) for N in numerators]
    groups_per: list[list[PoleGroup]] = [[] for _ in numerators]
    for index, (q, m) in enumerate(factors):
        if index in cancelled:  # no pole left: every principal part is zero
            continue
        if summed and is_root_sum_factor(q):  # a sum over q's roots: no residues
            for target, N in zip(groups_per, numerators):
                found = _root_sum_group(q, m, N, denominator)
                if found is not None:
                    target.append(found)
            continue
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


def _factors(denominator: sp.Poly, parts: tuple[sp.Poly, ...]) -> list[tuple[sp.Poly, int]]:
    """:func:`exact_factors` of ``denominator``, the product of ``parts``: over EX each
    part on its own where no two share a root (Δ(λ) of irrational entries, squarefree,
    and a rational (λ² + 1)·λ²: no gcds over EX)."""
    if not (denominator.domain.is_EX and len(parts) > 1 and _coprime(list(parts))):
        return exact_factors(denominator)
    return [found for part in parts if part.degree() > 0
            for found in exact_factors(part.set_domain(sp.EX))]


def exact_factors(poly: sp.Poly) -> list[tuple[sp.Poly, int]]:
    """The factors of ``poly`` with their multiplicities (``factor_list()[1]``), where SymPy's
    own would hide a square: numbers taken as unknowns (ZZ[pi, sqrt(pi)]) are read in EX,
    and factors over EX are split into squarefree parts (:func:`_squarefree`).

    >>> lam = sp.Symbol("lambda")
    >>> exact_factors(sp.Poly(lam**3 + 2*sp.sqrt(sp.pi)*lam**2 + sp.pi*lam, lam))
    [(Poly(lambda, lambda, domain='EX'), 1), (Poly(lambda + sqrt(pi), lambda, domain='EX'), 2)]
    """
    if _numeric_generators(poly.domain):
        poly = poly.set_domain(sp.EX)
    if not poly.domain.is_EX:
        return list(poly.factor_list()[1])
    ring = _in_exact_ring(poly)  # EX does not factor (√2λ² + λ + 2)(λ² + 1)
    if ring is None or (ring[1] and ring[0].domain.is_AlgebraicField):
        # SymPy factors over a number field with unknowns π, e by norms: minutes
        return _squarefree(poly.factor_list()[1])
    return _squarefree([(_in_ex(f, poly.gen, ring[1]), m) for f, m in ring[0].factor_list()[1]])


def _numeric_generators(domain: Any) -> bool:
    """Whether ``domain`` is a ring or field of numbers taken as unknowns (ZZ[pi, sqrt(pi)],
    QQ(E)): SymPy cannot see the relations between them."""
    if not (domain.is_PolynomialRing or domain.is_FractionField):
        return False
    symbols: tuple[Any, ...] = tuple(getattr(domain, "symbols", ()))
    return bool(symbols) and all(not sp.sympify(symbol).free_symbols for symbol in symbols)


def _squarefree(factors: list[tuple[sp.Poly, int]]) -> list[tuple[sp.Poly, int]]:
    """Factors over EX split into squarefree parts with their multiplicities.

    Over EX (entries such as √2 or π) ``factor_list`` returns λ² + 2√2 λ + 2 = (λ + √2)²
    as one simple factor, whose residues then divide by zero (critical damping with
    irrational coefficients). Each part's coefficients are written without nested
    radicals in their denominators (``sqf_list`` gives √2 as 3802396√3/(1901198√6 − ...)).

    >>> lam = sp.Symbol("lambda")
    >>> _squarefree([(sp.Poly(lam**2 + 2*sp.sqrt(2)*lam + 2, lam, domain="EX"), 1)])
    [(Poly(lambda + sqrt(2), lambda, domain='EX'), 2)]
    """
    out: dict[sp.Poly, int] = {}
    for factor, multiplicity in factors:
        for part, power in _squarefree_parts(factor):
            if part.degree() < 1:
                continue
            coefficients = [sp.sqrtdenest(sp.radsimp(c)) for c in part.monic().all_coeffs()]
            cleaned = sp.Poly(coefficients, part.gen, domain=part.domain)
            out[cleaned] = out.get(cleaned, 0) + multiplicity * power
    return list(out.items())


def _squarefree_parts(factor: sp.Poly) -> list[tuple[sp.Poly, int]]:
    """``factor.sqf_list()[1]``: the factor itself where its roots are numerically
    separated (milliseconds); else taken over the exact ring of its coefficients where they
    are algebraic numbers and π, e (:func:`_in_exact_ring`: √2 + ∛3 in 11 ms, where EX
    simplified for 5 s), in EX otherwise."""
    if _separated_roots(factor):
        return [(factor, 1)]
    ring = _in_exact_ring(factor)
    if ring is None:
        return list(factor.sqf_list()[1])
    exact, back = ring
    return [(_in_ex(part, factor.gen, back), power) for part, power in exact.sqf_list()[1]]


def _in_exact_ring(poly: sp.Poly) -> tuple[sp.Poly, dict[sp.Dummy, sp.Expr]] | None:
    """``poly`` (over EX) with its algebraic numbers in their number field (QQ<√2>) and
    π, e, γ and Catalan's constant as unknowns over it, and the map back from those
    unknowns; None where other numbers appear (√π, e², log 2: their relations to the rest
    would be unseen).

    >>> lam = sp.Symbol("lambda")
    >>> exact, back = _in_exact_ring(sp.Poly(lam**2 + sp.sqrt(2)*sp.pi*lam, lam, domain="EX"))
    >>> exact.domain, sorted(map(str, back.values()))
    (QQ<sqrt(2)>, ['pi'])
    >>> _in_exact_ring(sp.Poly(lam + sp.sqrt(sp.pi), lam, domain="EX")) is None
    True
    """
    expr = poly.as_expr()
    names = {c: sp.Dummy(str(c)) for c in TRANSCENDENTAL if expr.has(c)}
    try:
        exact = sp.Poly(expr.xreplace(names), poly.gen, *names.values(), extension=True)
    except (sp.PolynomialError, sp.CoercionFailed, NotImplementedError):
        return None
    domain = exact.domain
    if not (domain.is_ZZ or domain.is_QQ or domain.is_AlgebraicField):
        return None
    return exact, {v: k for k, v in names.items()}


def _in_ex(poly: sp.Poly, gen: sp.Symbol, back: dict[sp.Dummy, sp.Expr]) -> sp.Poly:
    return sp.Poly(poly.as_expr().xreplace(back), gen, domain=sp.EX)


def _separated_roots(factor: sp.Poly, digits: int = 60) -> bool:
    """Whether the roots of ``factor`` (numeric coefficients) are distinct
    (:func:`_apart`). Such a factor is squarefree; one with close roots is left to
    ``sqf_list``.

    >>> lam = sp.Symbol("lambda")
    >>> _separated_roots(sp.Poly(lam**3 + sp.pi*lam + 1, lam, domain="EX"))
    True
    >>> _separated_roots(sp.Poly((lam + sp.pi)**2 * (lam + 1), lam, domain="EX"))
    False
    """
    if factor.degree() < 2:
        return True
    found = _numeric_roots(factor, digits)
    return found is not None and _apart([(a, b) for i, a in enumerate(found[0])
                                         for b in found[0][i + 1:]], found[1], digits)


def _coprime(parts: list[sp.Poly], digits: int = 60) -> bool:
    """Whether no root of one of ``parts`` is a root of another (:func:`_apart`)."""
    numbered: list[tuple[list, Any] | None] = [
        _numeric_roots(p, digits) if p.degree() > 0 else ([], 0) for p in parts]
    found = [f for f in numbered if f is not None]
    if len(found) < len(numbered):
        return False
    pairs = [(a, b) for i, (roots, _) in enumerate(found) for other, _ in found[i + 1:]
             for a in roots for b in other]
    return _apart(pairs, max(error for _, error in found), digits)


def _numeric_roots(poly: sp.Poly, digits: int) -> tuple[list, Any] | None:
    """The roots of ``poly`` (numeric coefficients) at ``digits`` digits and mpmath's error
    estimate, or None where they cannot be numbered."""
    if poly.free_symbols - {poly.gen}:
        return None
    with workdps(digits):
        try:
            coeffs = [mpmath.mpmathify(sp.N(c, digits + 10)) for c in poly.all_coeffs()]
            roots, error = mpmath.polyroots(coeffs, maxsteps=200, extraprec=2 * digits,
                                            error=True)
        except (TypeError, ValueError, mpmath.libmp.NoConvergence):
            return None
    return list(roots), error


def _apart(pairs: list[tuple[Any, Any]], error: Any, digits: int) -> bool:
    """Whether every two roots of ``pairs`` are apart by more than 10^(-digits/3) of their
    size and by more than a million times the roots' error (a double root agrees to about
    digits/2 digits)."""
    if not pairs:
        return True
    with workdps(digits):
        size = max(1, *(max(abs(a), abs(b)) for a, b in pairs))
        gap = min(abs(a - b) for a, b in pairs)
        return bool(gap > max(size * mpmath.mpf(10) ** (-digits // 3), 1e6 * error))


def _over_q(poly: sp.Poly) -> Any:
    """A polynomial over ℚ as a flint fmpq_poly (the caller checked its domain)."""
    converted = from_poly(poly)
    if converted is None:
        raise InternalError(f"{poly} was taken for a polynomial over QQ")
    return converted


def _rational_decompose(numerators: list[sp.Poly], denominator: sp.Poly,
                        factors: list[tuple[sp.Poly, int]], cancelled: set[int]) -> list[PartialFractions]:
    """:func:`decompose` over ℚ by :func:`~laplace_springs.exact.rational.rational_partial_fractions`
    (residues reduced modulo each factor in python-flint), the factors in SymPy's order."""
    s = denominator.gen
    flint_numerators = [_over_q(N) for N in numerators]
    flint_factors = [(_over_q(q), m) for q, m in factors]
    quotients, groups = rational_partial_fractions(flint_numerators, _over_q(denominator), flint_factors)
    out = []
    for i, quotient in enumerate(quotients):
        found = []
        for index, ((q, m), group) in enumerate(zip(factors, groups)):
            if index in cancelled:
                continue
            pole = PoleGroup(q, m, tuple(to_poly(h, s) for h in group.residues[i]))
            if pole.order:
                found.append(pole)
        out.append(PartialFractions(s, to_poly(quotient, s), tuple(found)))
    return out


def partial_fractions(F: sp.Expr | str, s: sp.Symbol, *, closed_form: bool = False,
                      root_sums: bool = False, parameters: object = None) -> PartialFractions:
    """Structured partial-fraction decomposition of a rational function F(s).

    Parameters
    ----------
    F : sympy expression
        Rational in ``s`` with rational, algebraic or symbolic coefficients.
    s : sympy.Symbol
        The transform variable.
    closed_form : bool
        Raise :class:`InversionError` at once when a factor has no exact real terms
        (see :func:`closed_form_obstacle`), as the inversions do.
    root_sums : bool
        With ``closed_form``: a symbolic factor of degree ≥ 3 without closed-form roots
        gives a :class:`RootSumGroup` (terms summed over its roots) instead of a refusal.
    parameters : sequence or mapping, optional
        Names that text ``F`` may use besides ``s`` (see :func:`transform_of`).

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
    N, D = _field_polys(transform_of(F, s, parameters), s)
    pf = decompose([N], D, closed_form=closed_form, root_sums=root_sums)[0]
    return PartialFractions(pf.variable, pf.polynomial, pf.groups, denominator_conditions(D))


@dataclass(frozen=True)
class GenericCondition(Condition):
    """Where a decomposition with symbolic coefficients holds: a polynomial in the
    parameters that must not vanish.

    The denominator is factored over ℚ(parameters); the decomposition assumes each
    irreducible factor q keeps its degree (``leading``: its leading coefficient ≠ 0),
    has simple roots (disc q ≠ 0) and shares no root with another factor r
    (``cofactor``: res(q, r) ≠ 0). At a parameter value where one fails the generic
    formula is 0/0 (s² + a s + 1 at a = 2 is (s + 1)²): substitute first, then invert.
    The real form of a quadratic needs no sign of its discriminant: the oscillatory form
    with β = √(−disc) is an identity in the parameters (cos iσt = cosh σt).

    Examples
    --------
    >>> s, a = sp.symbols("s a")
    >>> (c,) = denominator_conditions(sp.Poly(s**3 + a*s**2 + s, s))
    >>> c.meaning, c.holds_at({a: 2}), c.holds_at({a: 3})
    ('a**2 - 4 != 0', False, True)
    """

    leading: sp.Expr | None = None

    @cached_property
    def expr(self) -> sp.Expr:
        """The polynomial in the parameters that must not be 0."""
        if self.leading is not None:
            return sp.factor(self.leading)
        q = self.factor
        if self.cofactor.degree() > 0:
            return sp.factor(sp.resultant(q, self.cofactor))
        return sp.factor(sp.discriminant(q))

    @property
    def meaning(self) -> str:
        """The condition as text, e.g. ``a**2 - 4 != 0``."""
        return f"{sp.expand(self.expr)} != 0"

    def latex(self) -> str:
        """The condition in LaTeX, e.g. ``a^{2} - 4 \\neq 0``."""
        return rf"{sp.latex(sp.expand(self.expr))} \neq 0"

    def holds_at(self, values: dict) -> bool:
        """Whether the condition holds at numbers for the parameters."""
        return sp.simplify(self.expr.subs(values)) != 0


def denominator_conditions(D: sp.Poly) -> tuple[GenericCondition, ...]:
    """Where partial fractions over the denominator ``D`` (symbolic coefficients) hold.

    One :class:`GenericCondition` per requirement that involves the parameters and is
    not known to hold from their assumptions (a positive ``a`` makes ``a ≠ 0`` hold):
    the leading coefficient, the discriminant of each quadratic factor and the resultant
    of each pair of factors of degree ≤ 2. Factors of higher degree are left out: a sum
    over their roots carries its own condition, and the discriminant of a symbolic
    biquadratic (an undamped two-mass chain) is a page long. Empty for numeric
    coefficients.

    Examples
    --------
    >>> s, a = sp.symbols("s a")
    >>> [c.meaning for c in denominator_conditions(sp.Poly((s + 1) * (s + a), s))]
    ['a - 1 != 0']
    >>> denominator_conditions(sp.Poly(s**2 + 2*s + 5, s))
    ()
    """
    D = sp.Poly(D.as_expr(), D.gen)
    if not D.free_symbols - {D.gen}:
        return ()
    found: list[GenericCondition] = []
    one = sp.Poly(1, D.gen)

    def keep(condition: GenericCondition) -> None:
        value = condition.expr
        if value.free_symbols and value.is_zero is not False \
                and all(sp.expand(value - c.expr) != 0 for c in found):
            found.append(condition)

    leading, factors = D.factor_list()
    lc = leading * sp.Mul(*(f.LC() ** m for f, m in factors))
    keep(GenericCondition(D, one, leading=lc))
    primitive = [f for f, _ in factors if 0 < f.degree() <= 2]
    for i, q in enumerate(primitive):
        if q.degree() == 2:
            keep(GenericCondition(q, one))
        for r in primitive[i + 1:]:
            if q.free_symbols - {D.gen} or r.free_symbols - {D.gen}:
                keep(GenericCondition(q, r))
    return tuple(found)


def residue_scale(k: int) -> sp.Rational:
    """1/(k-1)!: the factor turning a residue of 1/(s-ρ)^k into the t^{k-1} coefficient."""
    return sp.Rational(1, factorial(k - 1))

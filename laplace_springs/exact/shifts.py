"""Delays and periodic transforms: F(s) = Σ_τ e^{-τs} R_τ(s), optionally over 1 ∓ e^{-Ps}.

Two pieces of exact algebra behind :func:`laplace_springs.inverse_laplace` for transforms
that are not rational in s:

**Splitting.** :func:`split_delays` writes F as

    F(s) = Σ_τ e^{-τs} N_τ(s) / D(s)                     (delays), or
    F(s) = Σ_τ e^{-τs} N_τ(s) / (D(s) (1 - σ e^{-Ps}))   (periodic, σ = ±1),

with τ ≥ 0 exact and N_τ, D polynomials over one field. The exponentials are replaced by
powers of z = e^{-us} (u the common unit of commensurate delays, one z per class of
incommensurate ones) so that F is rational in (s, z) and the polynomial algebra does the
rest: the denominator must factor into a part in s, powers of z (shifts) and, for one z,
distinct cyclotomic factors, i.e. a divisor B(z) of 1 - z^M. B = 1 + z^n is kept as it is
(σ = -1, P = n·u: the sums alternate in sign); any other B becomes C(z)/(1 - z^M) with a
polynomial C (σ = 1, P = M·u), e.g. 1/(1 + z + z²) = (1 - z)/(1 - z³). Refused, with
the reason: a time advance (τ < 0), a factor mixing s and e^{-τs} (a delay equation with
infinitely many poles), a periodic factor that is not a divisor of 1 - e^{-Ps}
(1 - a e^{-s}), a repeated one ((1 - e^{-s})²), and periodic factors in two
incommensurate delays.

**Periodic sums.** For g(x) = Σ x^m e^{px} (the inverse of one R_τ) the sum
Σ_{j=0}^{N} σ^j g(v - jP), N = floor(v/P), is a finite geometric sum. With the reduced
time w = v - N P ∈ [0, P) and φ solving the difference equation φ(x) - σφ(x + P) = g(x),

    Σ_{j=0}^{N} σ^j g(v - jP) = σ^N Σ_{i=0}^{N} σ^i g(w + iP) = σ^N φ(w) - σ φ(v + P)

(telescoping), and -σφ(v + P) = g(v) - φ(v) is the transient, an exponential polynomial
in v. :func:`difference_solution` builds φ exactly in real form: for σe^{pP} ≠ 1, φ for
x^m e^{px} is ∂_p^m [e^{px} / (1 - σe^{pP})], whose complex coefficients are folded into
cos/sin pairs with e^{αP}, cos βP, sin βP; at a resonant pole (σe^{pP} = 1: p = 2πik/P
for σ = 1, p = iπ(2k + 1)/P for σ = -1) φ = ψ_m(x) e^{px} with the Bernoulli polynomial
ψ_m(x) = -P^m B_{m+1}(x/P)/(m + 1), whose growth in v is the true growth of the sum.
"""

from __future__ import annotations

import functools
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from math import comb

import sympy as sp

from ..limits import limits
from ..model.errors import InversionError
from ..model.switching import SwitchCondition
from .domains import field_polys
from .real_terms import Term

__all__ = ["DelaySplit", "split_delays", "shift_terms", "combine_terms", "difference_solution",
           "proved_zero", "order_delays", "is_resonant"]

_HYPERBOLIC = (sp.sinh, sp.cosh, sp.tanh, sp.coth, sp.sech, sp.csch)


@dataclass(frozen=True)
class DelaySplit:
    """F(s) = Σ_k e^{-delays[k] s} numerators[k](s) / denominator(s) [/ (1 - sign·e^{-period s})].

    ``numerators`` and ``denominator`` are Polys in s over one exact field, ready for
    :func:`laplace_springs.exact.partial_fractions.decompose`; the delays are distinct
    and ≥ 0. ``period`` is None when F has no periodic factor; ``sign`` is -1 for the
    factor 1 + e^{-Ts} (antiperiodic sums Σ (-1)^j g(t - jT), period 2T), else +1.
    ``conditions``: a symbolic delay or period of unknown sign (a plain or real Symbol)
    is taken as one, where it is ≥ 0 (> 0 for the period); see
    :class:`~laplace_springs.model.switching.SwitchCondition`.
    """

    delays: tuple[sp.Expr, ...]
    numerators: tuple[sp.Poly, ...]
    denominator: sp.Poly
    period: sp.Expr | None
    sign: int = 1
    conditions: tuple[SwitchCondition, ...] = ()


def _exact(F: sp.Expr) -> sp.Expr:
    """Floats as their decimal value (0.2 is 1/5), as the rational path reads them."""
    if F.has(sp.Float):
        F = F.xreplace({f: sp.Rational(str(f)) for f in F.atoms(sp.Float)})
    return F


def _with_exponentials(F: sp.Expr, s: sp.Symbol) -> sp.Expr:
    """Hyperbolic functions of s (coth(πs/2) in the tables) written with exponentials."""
    hyperbolic = [h for h in F.atoms(*_HYPERBOLIC) if s in h.free_symbols]
    if not hyperbolic:
        return F
    return F.xreplace({h: h.rewrite(sp.exp) for h in hyperbolic})


def _delay_of(atom: sp.Expr, s: sp.Symbol, F: sp.Expr) -> tuple[sp.Expr, sp.Expr]:
    """(τ, c) with atom = e^{c} e^{-τs}; τ must be real and free of s."""
    argument = sp.expand(atom.args[0])
    try:
        poly = sp.Poly(argument, s)
    except sp.PolynomialError:
        poly = None
    if poly is None or poly.degree() != 1:
        raise InversionError(f"not a rational function of {s} and exponentials e^(-tau*{s}): "
                             f"{atom} in {F} (only exponents linear in {s} are delays)")
    tau = -poly.coeff_monomial(s)
    if tau.is_extended_real is False:
        raise InversionError(f"{atom} in {F} is not a delay e^(-tau*{s}) with a real tau")
    return tau, poly.coeff_monomial(1)


def _positive_unit(unit: sp.Expr) -> sp.Expr:
    """``unit`` or ``-unit``: the positive one, or for an unknown sign the one written
    without a leading minus (the delays' conditions then say it must be ≥ 0)."""
    if unit.is_positive:
        return unit
    if unit.is_negative or unit.could_extract_minus_sign():
        return -unit
    return unit


def _units(delays: Iterable[sp.Expr]) -> list[tuple[sp.Expr, list[sp.Expr]]]:
    """Commensurate classes: (positive unit u, members), every member an integer times u."""
    classes: list[list[sp.Expr]] = []
    for tau in delays:
        for members in classes:
            if sp.cancel(tau / members[0]).is_Rational:
                members.append(tau)
                break
        else:
            classes.append([tau])
    out = []
    for members in classes:
        base = members[0]
        ratios = [sp.Rational(sp.cancel(tau / base)) for tau in members]
        out.append((_positive_unit(base * functools.reduce(sp.gcd, ratios)), members))
    return out




def _generators(delays: set[sp.Expr], in_denominator: set[sp.Expr]
                ) -> tuple[list[sp.Expr], dict[sp.Expr, tuple[int, int]]]:
    """Units u_j > 0 and, for each delay τ, (j, n) with τ = n·u_j."""

    def powers(classes):
        return {tau: (j, int(sp.Rational(sp.cancel(tau / unit))))
                for j, (unit, members) in enumerate(classes) for tau in members}

    classes = _units(delays)
    found = powers(classes)
    if all(abs(n) <= limits().max_delay_power for _, n in found.values()):
        return [unit for unit, _ in classes], found
    classes = _units(in_denominator)
    found = powers(classes)
    for j, n in found.values():
        if abs(n) > limits().max_delay_power:
            unit = classes[j][0]
            raise InversionError(
                f"the delays {', '.join(str(abs(d)) for d in classes[j][1])} in the denominator have "
                f"the common unit {unit}: a polynomial of degree {abs(n)} in exp(-{unit}*s), above "
                f"Limits.max_delay_power = {limits().max_delay_power}")
    units = [unit for unit, _ in classes]
    for tau in delays - set(found):
        for j, unit in enumerate(units):
            ratio = sp.cancel(tau / unit)
            if ratio.is_Integer and abs(ratio) <= limits().max_delay_power:
                found[tau] = (j, int(ratio))
                break
        else:  # a delay of the numerator alone: its own generator
            unit = _positive_unit(tau)
            units.append(unit)
            found[tau] = (len(units) - 1, 1 if unit == tau else -1)
    return units, found


def _cyclotomic_order(g: sp.Poly) -> int | None:
    """n with g = Φ_n (g monic with integer coefficients), or None."""
    if not g.is_cyclotomic:
        return None
    degree, z = g.degree(), g.gen
    for n in range(1, 4 * degree * degree + 3):
        if sp.totient(n) == degree and sp.Poly(sp.cyclotomic_poly(n, z), z, domain=sp.ZZ) == g:
            return n
    return None  # pragma: no cover - every cyclotomic polynomial has an order


def _as_cyclotomic(f: sp.Poly, z: sp.Symbol) -> tuple[sp.Poly, int] | None:
    """(Φ_n as a Poly in z, ±1) with f = ±Φ_n, or None."""
    g = sp.Poly(f.as_expr(), z)
    if g.domain not in (sp.ZZ, sp.QQ):
        return None
    sign = 1 if g.LC() > 0 else -1
    g = g * sign
    if g.LC() != 1 or not all(c.is_Integer for c in g.all_coeffs()):
        return None
    return g.set_domain(sp.ZZ), sign


def _periodic_factor(factors: list[tuple[sp.Poly, int]], z: sp.Symbol, F: sp.Expr,
                     back: dict) -> tuple[int, int, sp.Poly, int]:
    """(M, σ, C, sign) with Π factors = sign·(1 - σ z^M)/C for distinct cyclotomic factors.

    σ = -1 when the product is 1 + z^M (C = 1), else σ = 1 with 1 - z^M, M the lcm of
    the orders.
    """
    orders = []
    product = sp.Poly(1, z, domain=sp.ZZ)
    sign = 1
    for f, multiplicity in factors:
        cyclotomic = _as_cyclotomic(f, z)
        order = None if cyclotomic is None else _cyclotomic_order(cyclotomic[0])
        if cyclotomic is None or order is None:
            raise InversionError(
                f"the denominator factor {f.as_expr().xreplace(back)} of {F} is not periodic: only factors of "
                "1 - e^(-P*s) (such as 1 - e^(-T*s), 1 + e^(-T*s)) give periodic functions")
        if multiplicity > 1:
            raise InversionError(
                f"the periodic factor {f.as_expr().xreplace(back)} of {F} is repeated (power {multiplicity}): "
                "its inverse is a sum of periodic sums (growing like t^k), which is not supported")
        orders.append(order)
        product *= cyclotomic[0]
        sign *= cyclotomic[1]
    n = product.degree()
    if product == sp.Poly(z**n + 1, z, domain=sp.ZZ):
        return n, -1, sp.Poly(1, z, domain=sp.ZZ), sign
    M = functools.reduce(sp.ilcm, orders, 1)
    cofactor, remainder = sp.Poly(1 - z**M, z, domain=sp.ZZ).div(product)
    assert remainder.is_zero
    return int(M), 1, cofactor, sign


def split_delays(F: sp.Expr, s: sp.Symbol) -> DelaySplit | None:
    """F as Σ_τ e^{-τs} N_τ(s)/D(s) [/(1 - e^{-Ps})]; None when F is rational in s.

    Raises
    ------
    InversionError
        For a time advance, a factor mixing s and e^{-τs}, a non-periodic or repeated
        periodic factor, several incommensurate periods, or exponents not linear in s.

    Examples
    --------
    >>> s = sp.Symbol("s")
    >>> split = split_delays((1 + sp.exp(-4*s)) / (s*(s + 1)), s)
    >>> split.delays, [N.as_expr() for N in split.numerators], split.denominator.as_expr()
    ((0, 4), [1, 1], s**2 + s)
    >>> split = split_delays(1 / (s * (1 + sp.exp(-s))), s)    # the square wave
    >>> split.period, split.sign, split.delays, [N.as_expr() for N in split.numerators]
    (1, -1, (0,), [1])
    >>> split = split_delays(1 / (s * (1 + sp.exp(-s) + sp.exp(-2*s))), s)
    >>> split.period, split.sign, split.delays, [N.as_expr() for N in split.numerators]
    (3, 1, (0, 1), [1, -1])
    """
    F = _with_exponentials(_exact(F), s)
    atoms = [e for e in F.atoms(sp.exp) if s in e.free_symbols]
    if not atoms:
        return None
    delays = {atom: _delay_of(atom, s, F) for atom in atoms}
    below = {a for power in F.atoms(sp.Pow) if power.exp.is_negative  # in a denominator
             for a in power.base.atoms(sp.exp) if a in delays}
    units, powers = _generators({tau for tau, _ in delays.values() if tau != 0},
                                {delays[a][0] for a in below} - {0})
    zs = [sp.Dummy(f"z{j}") for j in range(len(units))]
    replacement = {}
    for atom, (tau, constant) in delays.items():
        power: sp.Expr = sp.S.One
        if tau != 0:
            j, n = powers[tau]
            power = zs[j] ** n
        replacement[atom] = sp.exp(constant) * power
    numerator, denominator = sp.fraction(sp.cancel(sp.together(F.xreplace(replacement))))
    gens = (s, *zs)
    try:
        N = sp.Poly(numerator, *gens)
        D = sp.Poly(denominator, *gens)
    except sp.PolynomialError as exc:
        raise InversionError(f"not a rational function of {s} and exponentials e^(-tau*{s}): {F}") from exc
    if D.is_zero:
        raise InversionError(f"the denominator of {F} is zero")
    if F.has(sp.zoo, sp.oo, -sp.oo, sp.nan):
        raise InversionError(f"the transform is not finite: {F} (a zero denominator?)")
    constant, factors = D.factor_list()
    in_s = sp.Poly(constant, *gens)
    shifts = [0] * len(zs)
    periodic: dict[int, list[tuple[sp.Poly, int]]] = {}
    for f, m in factors:
        used = [j for j, gen in enumerate(gens) if f.degree(gen) > 0]
        if used == [0]:
            in_s *= f**m
        elif len(used) == 1 and f.is_monomial:
            shifts[used[0] - 1] += m * f.degree(gens[used[0]])
        elif len(used) == 1:
            periodic.setdefault(used[0] - 1, []).append((f, m))
        elif 0 in used:
            raise InversionError(
                f"the denominator factor {f.as_expr().xreplace(_back(zs, units, s))} of {F} mixes "
                f"{s} and e^(-tau*{s}) (a delay equation, with infinitely many poles): only "
                f"R({s}) e^(-tau*{s}) and R({s})/(1 -+ e^(-T*{s})) are inverted")
        else:
            raise InversionError(
                f"the denominator factor {f.as_expr().xreplace(_back(zs, units, s))} of {F} mixes "
                "incommensurate delays: not a periodic factor 1 - e^(-P*s)")
    if len(periodic) > 1:
        raise InversionError(f"{F} has periodic factors in incommensurate periods "
                             f"{', '.join(str(units[j]) for j in periodic)}: not periodic")
    period, alternating = None, 1
    if periodic:
        j, group = next(iter(periodic.items()))
        M, alternating, cofactor, sign = _periodic_factor(group, zs[j], F, _back(zs, units, s))
        period = M * units[j]
        N = N * sp.Poly(cofactor.as_expr(), *gens)
        in_s *= sign
    classes: dict[sp.Expr, sp.Expr] = {}
    for monomial, coefficient in N.terms():
        tau = sp.Add(*((e - k) * unit for e, k, unit in zip(monomial[1:], shifts, units)))
        if tau.is_negative:
            raise InversionError(f"a time advance e^(+tau*{s}) with tau = {-tau} in {F} has no "
                                 f"causal inverse: only delays e^(-tau*{s}), tau >= 0, are inverted")
        classes[tau] = classes.get(tau, sp.S.Zero) + coefficient * s ** monomial[0]
    conditions = _delay_conditions([tau for tau, N in classes.items() if N != 0], period, s, F)
    return _field_split(classes, in_s.as_expr(), s, period, alternating, F, conditions)


def _delay_conditions(delays: list[sp.Expr], period: sp.Expr | None, s: sp.Symbol,
                      F: sp.Expr) -> tuple[SwitchCondition, ...]:
    """τ ≥ 0 for each delay of unknown sign, P > 0 for a period of unknown sign; an
    InversionError when two delays of unknown sign have opposite signs (one is an advance)."""
    unknown = [tau for tau in delays if tau != 0 and tau.is_nonnegative is not True]
    for i, first in enumerate(unknown):
        for second in unknown[i + 1:]:
            ratio = sp.cancel(first / second)
            if ratio.is_Rational and ratio < 0:
                raise InversionError(
                    f"e^(-({first})*{s}) and e^(-({second})*{s}) in {F}: one of them is a time "
                    f"advance whatever the sign of {second} (no causal inverse)")
    conditions = [SwitchCondition(tau, ">=", f"the delay exp(-({tau})*{s})") for tau in unknown]
    if period is not None and period.is_positive is not True:
        conditions.append(SwitchCondition(period, ">", f"the period of 1 -+ exp(-({period})*{s})"))
    return tuple(conditions)


def _back(zs: Sequence[sp.Symbol], units: Sequence[sp.Expr], s: sp.Symbol) -> dict:
    return {z: sp.exp(-unit * s) for z, unit in zip(zs, units)}


def _field_split(classes: dict[sp.Expr, sp.Expr], denominator: sp.Expr, s: sp.Symbol,
                 period: sp.Expr | None, sign: int, F: sp.Expr,
                 conditions: tuple[SwitchCondition, ...] = ()) -> DelaySplit:
    """Polys over one exact field, delays in increasing order where that is decidable."""
    items = [(tau, numerator) for tau, numerator in classes.items() if numerator != 0]
    order = order_delays([tau for tau, _ in items])
    if order is not None:
        items = [items[i] for i in order]
    D, *Ns = field_polys([denominator, *(numerator for _, numerator in items)], s)
    domain = D.domain
    for N in Ns:
        domain = domain.unify(N.domain)
    if not domain.is_Exact:
        raise InversionError(f"inexact coefficients in {F}")
    field = domain.get_field()
    return DelaySplit(tuple(tau for tau, _ in items), tuple(N.set_domain(field) for N in Ns),
                      D.set_domain(field), period, sign, conditions)


def order_delays(delays: Sequence[sp.Expr]) -> list[int] | None:
    """Indices sorting ``delays`` increasingly, or None when an order is undecidable."""

    def compare(i: int, j: int) -> int:
        difference = delays[i] - delays[j]
        if difference.is_positive:
            return 1
        if difference.is_negative:
            return -1
        if difference == 0:
            return 0
        raise ValueError

    try:
        return sorted(range(len(delays)), key=functools.cmp_to_key(compare))
    except ValueError:
        return None


# ---------------------------------------------------------------------------
# exponential polynomials in real form: shifts, sums, periodic sums
# ---------------------------------------------------------------------------
def _check_kind(term: Term) -> None:
    if term.kind not in ("real", "oscillatory", "hyperbolic"):
        raise InversionError(f"periodic sums and shifts of {term.kind} terms are not supported "
                             "(only closed-form poles: substitute numbers for the parameters)")


def shift_terms(terms: Iterable[Term], tau: sp.Expr) -> list[Term]:
    """Real terms of g(x - τ) in x for g = Σ terms (same exponents α, β).

    Examples
    --------
    >>> x = sp.Symbol("x")
    >>> sp.expand(sum(t.as_expr(x) for t in shift_terms([Term("real", 2, 0, 0, 1, 0)], 3)))
    x**2 - 6*x + 9
    """
    out = []
    for term in terms:
        _check_kind(term)
        scale = sp.exp(-term.alpha * tau) if term.alpha != 0 else sp.S.One
        a, b = term.a, term.b
        if term.kind == "oscillatory":
            c, d = sp.cos(term.beta * tau), sp.sin(term.beta * tau)
            a, b = a * c - b * d, a * d + b * c
        elif term.kind == "hyperbolic":
            c, d = sp.cosh(term.beta * tau), sp.sinh(term.beta * tau)
            a, b = a * c - b * d, b * c - a * d
        for power in range(term.power + 1):
            weight = scale * comb(term.power, power) * (-tau) ** (term.power - power)
            out.append(Term(term.kind, power, term.alpha, term.beta, weight * a, weight * b))
    return out


def proved_zero(expr: sp.Expr) -> bool:
    """Whether ``expr`` is exactly zero, proved (False also means 'not proved')."""
    expr = sp.expand(expr)
    if expr == 0:
        return True
    if expr.is_number:
        value = sp.N(expr, 30)
        if value.is_number and abs(value) > sp.Float(10) ** -20 * (1 + max(
                (abs(sp.N(arg, 15)) for arg in sp.Add.make_args(expr)), default=0)):
            return False
    try:
        return sp.simplify(expr) == 0
    except Exception:  # a failed simplification proves nothing
        return False


def _tidy(expr: sp.Expr) -> sp.Expr:
    """One fraction, common factors pulled out (cheap: no trigonometric simplification)."""
    return sp.factor_terms(sp.together(expr))


def combine_terms(terms: Iterable[Term]) -> list[Term]:
    """Terms with the same kind, power and exponents summed; proved zeros dropped."""
    sums: dict[tuple, list[sp.Expr]] = {}
    for term in terms:
        key = (term.kind, term.power, term.alpha, term.beta)
        entry = sums.setdefault(key, [sp.S.Zero, sp.S.Zero])
        entry[0] += term.a
        entry[1] += term.b
    out = []
    for (kind, power, alpha, beta), (a_sum, b_sum) in sums.items():
        a = sp.S.Zero if proved_zero(a_sum) else _tidy(a_sum)
        b = sp.S.Zero if kind == "real" or proved_zero(b_sum) else _tidy(b_sum)
        if a != 0 or b != 0:
            out.append(Term(kind, power, alpha, beta, a, b))
    return out


@functools.lru_cache(maxsize=32)
def _geometric_numerator(order: int) -> sp.Poly:
    """Q_l with (y d/dy)^l [1/(1 - y)] = Q_l(y)/(1 - y)^{l+1}."""
    y = sp.Symbol("y")
    expr = 1 / (1 - y)
    for _ in range(order):
        expr = y * sp.diff(expr, y)
    return sp.Poly(sp.cancel(expr * (1 - y) ** (order + 1)), y)


def _geometric_derivative(order: int, alpha: sp.Expr, beta: sp.Expr, period: sp.Expr,
                          sign: int) -> tuple[sp.Expr, sp.Expr]:
    """Real and imaginary parts of ∂_p^l [1/(1 - σ e^{pP})] at p = α + iβ, without I.

    It is P^l Q_l(y)/(1 - y)^{l+1} with y = σ e^{pP} = σE e^{iθ}; multiplying by
    (1 - ȳ)^{l+1} gives the denominator |1 - y|^{2(l+1)} = (1 - 2σE cos θ + E²)^{l+1} and
    a numerator whose monomials y^j ȳ^k are (σE)^{j+k}(cos (j-k)θ + i sin (j-k)θ).
    """
    E = sign * sp.exp(alpha * period)
    Q = _geometric_numerator(order)
    if beta == 0:
        return period**order * Q.as_expr().xreplace({Q.gen: E}) / (1 - E) ** (order + 1), sp.S.Zero
    theta = beta * period
    yb = sp.Symbol("yb")
    product = sp.Poly(Q.as_expr() * (1 - yb) ** (order + 1), Q.gen, yb)
    re, im = sp.S.Zero, sp.S.Zero
    for (j, k), c in product.terms():
        weight = c * E ** (j + k)
        re += weight * sp.cos((j - k) * theta)
        im += weight * sp.sin((j - k) * theta)
    scale = period**order / (1 - 2 * E * sp.cos(theta) + E**2) ** (order + 1)
    return re * scale, im * scale


def _bernoulli_sum(power: int, period: sp.Expr) -> list[sp.Expr]:
    """Coefficients c_k of ψ(x) = Σ c_k x^k with ψ(x) - ψ(x + P) = x^power."""
    x = sp.Dummy("x")
    psi = sp.expand(-period**power * sp.bernoulli(power + 1, x / period) / (power + 1))
    return [sp.expand(c) for c in reversed(sp.Poly(psi, x).all_coeffs())]


def _resonant(alpha: sp.Expr, beta: sp.Expr, period: sp.Expr, sign: int) -> bool:
    """Whether σ e^{(α + iβ)P} = 1 exactly: α = 0 and βP a multiple of 2π (σ = 1) or an
    odd multiple of π (σ = -1).

    Symbolic exponents are taken as generic (not resonant).
    """
    if alpha != 0:
        return False
    if beta == 0:
        return sign == 1
    ratio = beta * period / (2 * sp.pi) - (0 if sign == 1 else sp.Rational(1, 2))
    if ratio.free_symbols:
        return False
    value = sp.N(ratio, 40)
    nearest = sp.Integer(round(value))
    if abs(value - nearest) > sp.Float(10) ** -30:
        return False
    if proved_zero(ratio - nearest):
        return True
    raise InversionError(f"cannot decide whether the pole {alpha} + {beta}*I resonates with the "
                         f"period {period} (beta*P/(2*pi) = {ratio} is within 1e-30 of {nearest})")


def is_resonant(term: Term, period: sp.Expr, sign: int = 1) -> bool:
    """Whether the exponent of ``term`` is a pole of 1/(1 - σe^{-Ps}) (σ e^{pP} = 1).

    Examples
    --------
    >>> is_resonant(Term("oscillatory", 0, 0, sp.pi, 1, 0), 2), is_resonant(Term("real", 0, -1, 0, 1, 0), 2)
    (True, False)
    """
    if term.kind == "hyperbolic":
        return False
    _check_kind(term)
    return _resonant(term.alpha, term.beta if term.kind == "oscillatory" else sp.S.Zero, period, sign)


def _resonant_terms(term: Term, period: sp.Expr) -> list[Term]:
    return [Term(term.kind, k, term.alpha, term.beta, c * term.a, c * term.b)
            for k, c in enumerate(_bernoulli_sum(term.power, period)) if c != 0]


def difference_solution(term: Term, period: sp.Expr, sign: int = 1) -> list[Term]:
    """Real terms of φ with φ(x) - σ φ(x + P) = term(x), in the exponents of ``term``.

    Then Σ_{i=0}^{N} σ^i term(w + iP) = φ(w) - σ^{N+1} φ(w + (N + 1)P) for every N ≥ 0
    (σ = ``sign`` = ±1). At a resonant pole (σ e^{pP} = 1) φ = ψ(x) e^{px} with a
    Bernoulli polynomial ψ, one degree higher than the term's power.

    Examples
    --------
    >>> x = sp.Symbol("x")
    >>> phi = difference_solution(Term("real", 0, 0, 0, 1, 0), 1)    # the staircase
    >>> sum(t.as_expr(x) for t in phi)
    1/2 - x
    >>> phi = difference_solution(Term("real", 0, 0, 0, 1, 0), 1, -1)    # the square wave
    >>> sum(t.as_expr(x) for t in phi)
    1/2
    """
    if term.kind == "hyperbolic":  # a cosh σx + b sinh σx = (a+b)/2 e^{σx} + (a-b)/2 e^{-σx}
        halves = [Term("real", term.power, term.alpha + term.beta, 0, (term.a + term.b) / 2, 0),
                  Term("real", term.power, term.alpha - term.beta, 0, (term.a - term.b) / 2, 0)]
        return [phi for half in halves for phi in difference_solution(half, period, sign)]
    _check_kind(term)
    beta = term.beta if term.kind == "oscillatory" else sp.S.Zero
    if _resonant(term.alpha, beta, period, sign):
        return _resonant_terms(term, period)
    m = term.power
    out = []
    for order in range(m + 1):
        re, im = _geometric_derivative(order, term.alpha, beta, period, sign)
        weight = comb(m, order)
        if term.kind == "real":
            out.append(Term("real", m - order, term.alpha, 0, weight * term.a * re, sp.S.Zero))
        else:  # Re[(a - ib)(re + i im) x^k e^{px}]
            out.append(Term("oscillatory", m - order, term.alpha, term.beta,
                            weight * (term.a * re + term.b * im),
                            weight * (term.b * re - term.a * im)))
    return out

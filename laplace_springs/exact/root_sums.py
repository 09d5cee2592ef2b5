"""Sums over the roots of a polynomial: the exact answer where the roots have no closed form.

An irreducible factor q(λ) of degree ≥ 3 with symbolic coefficients (the damped
two-mass chain with masses, springs and dashpot left as symbols: Δ(λ) is such a
quartic) has roots with no useful closed form. Its part of the inverse transform of
N(λ)/D(λ) (q divides D) is still exact: at a simple root ρ the residue of
N(λ) e^{λt}/D(λ) is N(ρ)/D'(ρ) e^{ρt}, so

    Σ_{q(ρ)=0} N(ρ)/D'(ρ) · e^{ρt}                                      (q² ∤ D),

and for the free motion of a scene, D = Δ(λ) and N = N_i(λ) (the adjugate numerators
with the initial data): x_i(t) = Σ_{Δ(λ)=0} N_i(λ)/Δ'(λ) e^{λt}. Nothing is reduced
modulo q, so no gcd over the parameters' field is ever taken (those made the residues of
such a factor cost minutes): building the sum takes milliseconds.

The sum is a :class:`SumOverRoots`, SymPy's ``RootSum`` with these repairs:

- numbers in: ``evalf`` takes the roots from python-flint's certified isolation and
  sums in mpmath, doubling the working precision until two sums agree (milliseconds;
  SymPy's ``CRootOf`` takes seconds per complex root at 30 digits), and returns a real
  number for a real polynomial and a real summand; ``doit()`` sums over ``CRootOf``
  (exact algebraic roots) instead of SymPy's radicals (for the damped pair at t = 0.37
  the radical form evaluated to 0.477; the value is 0.517);
- a rational summand with symbolic coefficients (``subs(t, 0)``) stays unevaluated
  rather than going through SymPy's symmetric-function expansion (4 s for the damped
  pair); with rational coefficients it is the exact trace Σ h(ρ) = Σ h_j p_j
  (Newton's power sums);
- ``subs`` of one parameter among several rebuilds the sum once, without factoring q
  while q stays symbolic (SymPy factors it at every step);
- d/dp for a parameter p of q includes the motion of the roots,
  dρ/dp = −q_p(ρ)/q'(ρ) (SymPy differentiates the summand only);
- LaTeX reads Σ_{q(λ)=0} f(λ).

**Genericity.** The formula needs each root of q to be a simple root of D: it holds
where disc_λ q ≠ 0 and res_λ(q, D/q^m) ≠ 0 (:class:`Condition`). An irreducible q has
a nonzero discriminant as a polynomial in the parameters, so this fails only on a
hypersurface of parameter values (there the numeric scene solves exactly anyway:
``ls.solve(scene.subs(values))``). When q^m with m > 1 divides D structurally the
weights are the full residues (t^k terms, :func:`root_sum_weights`).

Examples
--------
>>> s, t, a = sp.symbols("s t a")
>>> q = sp.Poly(s**4 + a*s + 1, s)
>>> f = sum_over_roots(q, root_sum_weights(q, sp.Poly(1, s), q), t)
>>> f
RootSum(a*s + s**4 + 1, Lambda(s, exp(s*t)/(a + 4*s**3)))
>>> f.subs(a, 2)            # s⁴ + 2s + 1 = (s + 1)(s³ - s² + s + 1)
RootSum(s**3 - s**2 + s + 1, Lambda(s, exp(s*t)/(4*s**3 + 2))) - exp(-t)/2
>>> f.subs({a: 2, t: 1}).evalf(20)   # mpmath's Talbot inversion: 0.16370260777879102845
0.16370260777879102845
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property, lru_cache
from math import comb, factorial
from typing import Any

import flint
import mpmath
import sympy as sp
from sympy.core.evalf import prec_to_dps

from ..kernels.precision import flint_workprec, workdps, workprec

__all__ = ["SumOverRoots", "Condition", "root_sum_weights", "sum_over_roots", "is_rational_poly"]

#: Functions that commute with complex conjugation (f(z̄) = conj f(z)): a summand built
#: from them and real numbers, summed over the roots of a real polynomial, is real.
_REAL_FUNCTIONS = (sp.exp, sp.sin, sp.cos, sp.sinh, sp.cosh)


def _coefficients(poly: sp.Poly) -> list[sp.Expr]:
    return list(poly.all_coeffs())  # already SymPy numbers (to_sympy again fails over ZZ_I)


def is_rational_poly(poly: sp.Poly) -> bool:
    """Whether every coefficient of ``poly`` is a rational number."""
    return all(c.is_Rational for c in _coefficients(poly))


def _power_sums(q: sp.Poly, count: int) -> list[sp.Expr]:
    """p_k = Σ ρ^k over the roots of q (with multiplicity), k < count, by Newton's identities."""
    monic = q.monic()
    n = monic.degree()
    a = {n - j: c for j, c in enumerate(_coefficients(monic))}  # a[k]: coefficient of λ^k
    sums: list[sp.Expr] = [sp.Integer(n)]
    for k in range(1, count):
        value = -sum((a.get(n - i, 0) * sums[k - i] for i in range(1, min(k, n + 1))), sp.S.Zero)
        value += -k * a.get(n - k, 0) if k <= n else 0
        sums.append(value)
    return sums


@lru_cache(maxsize=256)
def _roots(coefficients: tuple[int, ...], bits: int) -> tuple[tuple[int, int, int, int, int], ...]:
    """Roots of the integer polynomial (ascending ``coefficients``), with multiplicity, as
    exact binary midpoints (re mantissa, re exponent, im mantissa, im exponent,
    multiplicity) of python-flint's certified isolating balls at ``bits`` of precision."""
    with flint_workprec(bits):  # (the stubs say list of acb; it is (acb, multiplicity))
        found: Any = flint.fmpz_poly(list(coefficients)).complex_roots()
    out = []
    for z, multiplicity in found:
        re, im = z.real.mid().man_exp(), z.imag.mid().man_exp()
        out.append((int(re[0]), int(re[1]), int(im[0]), int(im[1]), int(multiplicity)))
    return tuple(out)


class _Unsupported(Exception):
    """A summand the small mpmath evaluator does not know: SymPy evaluates it instead."""


_MP_FUNCTIONS = {sp.exp: mpmath.exp, sp.sin: mpmath.sin, sp.cos: mpmath.cos,
                 sp.sinh: mpmath.sinh, sp.cosh: mpmath.cosh}


def _mp(expr: sp.Expr, var: sp.Symbol, z, dps: int):
    """``expr`` at var = z in mpmath (current precision): +, ×, powers, exp, sin, cos, ..."""
    if expr == var:
        return z
    if expr.is_Integer:
        return mpmath.mpf(int(expr))
    if expr.is_Rational:
        return mpmath.mpf(int(expr.p)) / int(expr.q)
    if expr.is_Float:
        return mpmath.mpf(expr._mpf_)
    if isinstance(expr, sp.Add):
        return mpmath.fsum(_mp(a, var, z, dps) for a in expr.args)
    if isinstance(expr, sp.Mul):
        return mpmath.fprod(_mp(a, var, z, dps) for a in expr.args)
    if isinstance(expr, sp.Pow):
        base, exponent = expr.args
        if exponent.is_Integer:
            return _mp(base, var, z, dps) ** int(exponent)
        return _mp(base, var, z, dps) ** _mp(exponent, var, z, dps)
    for function, mp_function in _MP_FUNCTIONS.items():
        if isinstance(expr, function):
            return mp_function(_mp(expr.args[0], var, z, dps))
    if expr.is_number:  # I, π, √2, ...
        value = sp.N(expr, dps)
        re, im = value.as_real_imag()
        if not (re.is_Float or re.is_zero) or not (im.is_Float or im.is_zero):
            raise _Unsupported(expr)
        return mpmath.mpc(mpmath.mpf(re._mpf_) if re.is_Float else 0,
                          mpmath.mpf(im._mpf_) if im.is_Float else 0)
    raise _Unsupported(expr)


def _mp_roots(coefficients: tuple[int, ...], digits: int) -> list[tuple[Any, int]]:
    """(root as an mpmath mpc, multiplicity) good to about ``digits`` digits."""
    bits = int(digits * 3.33) + 30
    out = []
    with workprec(bits + 64):  # the midpoints are exact binary numbers: kept whole
        for re_man, re_exp, im_man, im_exp, multiplicity in _roots(coefficients, bits):
            root = mpmath.mpc(mpmath.ldexp(re_man, re_exp), mpmath.ldexp(im_man, im_exp))
            out.append((root, multiplicity))
    return out


class SumOverRoots(sp.RootSum):
    """Σ_{q(λ)=0} f(λ), over the roots of q counted with multiplicity (a SymPy ``RootSum``).

    Substitutes like any expression (``subs``, ``xreplace``), differentiates (also with
    respect to a parameter of q), ``doit()`` expands over ``CRootOf`` once q has rational
    coefficients and ``evalf`` evaluates from the isolated roots. See the module notes.
    """

    @classmethod
    def _rational_case(cls, poly, func):
        """Σ f(ρ) for a rational f: exact trace for rational q, else left as it is."""
        var, expr = func.variables[0], func.expr
        if not is_rational_poly(poly) or expr.free_symbols - {var}:
            return cls._new(poly, func, True)
        q = sp.Poly(poly.as_expr(), poly.gen, domain=sp.QQ)
        q = sp.Poly(q.as_expr().xreplace({poly.gen: var}), var, domain=sp.QQ)
        numerator, denominator = sp.fraction(sp.together(expr))
        try:
            A = sp.Poly(numerator, var, domain=sp.QQ)
            B = sp.Poly(denominator, var, domain=sp.QQ)
        except (sp.PolynomialError, sp.CoercionFailed):
            return cls._new(poly, func, True)
        if q.gcd(B).degree() > 0:  # a root of q is a pole of f: no finite value
            return cls._new(poly, func, True)
        h = (A * B.invert(q)).rem(q)
        sums = _power_sums(q, q.degree())
        return sp.Add(*(c * sums[k] for (k,), c in h.terms()))

    def _rational_poly(self) -> sp.Poly | None:
        """The polynomial over ℚ, or None if a coefficient is not a rational number."""
        if not is_rational_poly(self.poly):
            return None
        return sp.Poly(self.poly.as_expr(), self.poly.gen, domain=sp.QQ)

    def _summands(self, q: sp.Poly) -> sp.Expr:
        return sp.Add(*(self.fun(sp.CRootOf(q, i)) for i in range(q.degree())))

    def _is_real_sum(self) -> bool:
        """A real polynomial and a summand with f(z̄) = conj f(z): the sum is real."""
        var, expr = self.fun.variables[0], self.fun.expr
        if expr.has(sp.I) or expr.free_symbols - {var}:
            return False
        if not all(c.is_real for c in _coefficients(self.poly)):
            return False
        numbers = expr.atoms(sp.Number)
        functions = expr.atoms(sp.Function)
        return (all(x.is_real for x in numbers)
                and all(isinstance(f, _REAL_FUNCTIONS) for f in functions))

    def doit(self, **hints: Any) -> sp.Expr:
        """Σ f(ρ) over ``CRootOf`` roots once q is rational (the sum itself otherwise)."""
        if not hints.get("roots", True):
            return self
        q = self._rational_poly()
        if q is None:
            return self
        return self._summands(q)

    def _eval_evalf(self, prec):
        """The sum from certified roots (arb, rational q) or mpmath's roots (other numbers).

        With rational q the roots come from python-flint's certified isolation at a
        working precision that is raised until two evaluations agree to the digits asked
        for (SymPy's ``CRootOf`` takes seconds per complex root at 30 digits).
        """
        if not all(c.is_number for c in _coefficients(self.poly)):
            return self
        q = self._rational_poly()
        dps = prec_to_dps(prec)
        if q is None:
            value = super()._eval_evalf(prec)
        else:
            value = self._certified_sum(q, dps)
        if value.is_number and self._is_real_sum():
            value = sp.re(value)
        return value

    def _certified_sum(self, q: sp.Poly, dps: int) -> sp.Expr:
        """Σ f(ρ) at ``dps`` digits: roots from arb, f in mpmath, the working precision
        doubled until two evaluations agree (SymPy evaluates f if mpmath cannot)."""
        var, expr = self.fun.variables[0], self.fun.expr
        _, integer = q.clear_denoms(convert=True)
        coefficients = tuple(int(c) for c in reversed(integer.all_coeffs()))
        if expr.free_symbols - {var}:  # other symbols left (t): one SymPy evaluation
            return self._sympy_sum(coefficients, expr, var, dps + 20).evalf(dps)
        work = dps + 20
        previous = None
        try:
            for _ in range(6):
                with workdps(work):
                    value = mpmath.fsum(_mp(expr, var, root, work) * multiplicity
                                        for root, multiplicity in _mp_roots(coefficients, work))
                    if previous is not None and abs(value - previous) <= abs(value) * mpmath.mpf(10) ** (-dps - 3):
                        break
                previous, work = value, 2 * work
        except _Unsupported:
            return self._sympy_sum(coefficients, expr, var, dps + 20).evalf(dps)
        with workdps(work):
            value = mpmath.mpmathify(value)
            if isinstance(value, mpmath.mpc) and value.imag != 0:
                return sp.Float(value.real, dps) + sp.I * sp.Float(value.imag, dps)
            return sp.Float(value.real, dps)

    @staticmethod
    def _sympy_sum(coefficients: tuple[int, ...], expr: sp.Expr, var: sp.Symbol,
                   digits: int) -> sp.Expr:
        roots = []
        for root, multiplicity in _mp_roots(coefficients, digits):
            value = sp.Float(root.real, digits) + sp.I * sp.Float(root.imag, digits)
            roots += [value] * multiplicity
        return sp.Add(*(expr.xreplace({var: root}) for root in roots))

    def _eval_subs(self, old, new):
        """A substitution that leaves symbols in q is one rebuild without factoring q
        (``subs`` replaces one parameter at a time: SymPy would factor q each time)."""
        var, gen = self.fun.variables[0], self.poly.gen
        if old in (var, gen):
            return None
        poly = self.poly.as_expr().subs(old, new)
        if not poly.free_symbols - {gen}:
            return None  # numbers: SymPy's constructor factors q over ℚ
        return self._make(sp.PurePoly(poly, gen), sp.Lambda(var, self.fun.expr.subs(old, new)))

    @classmethod
    def _make(cls, poly: sp.PurePoly, func: sp.Lambda) -> sp.Expr:
        """Σ func over the roots of poly, without factoring poly."""
        var, expr = func.variables[0], func.expr
        if not expr.has(var):
            return poly.degree() * expr
        if expr.is_rational_function(var):
            return cls._rational_case(poly, func)
        return cls._new(poly, func, True)

    def _eval_derivative(self, x):
        var, expr = self.fun.variables[0], self.fun.expr
        summand = expr.diff(x)
        if x in self.poly.free_symbols:  # the roots move: dρ/dx = -q_x(ρ)/q'(ρ)
            q = self.poly.as_expr().xreplace({self.poly.gen: var})
            summand -= expr.diff(var) * q.diff(x) / q.diff(var)
        return self._make(self.poly, sp.Lambda(var, summand))

    def _latex(self, printer, exp=None) -> str:
        var, expr = self.fun.variables[0], self.fun.expr
        poly = self.poly.as_expr().xreplace({self.poly.gen: var})
        tex = rf"\sum_{{{printer._print(poly)} = 0}} {printer._print(expr)}"
        return rf"\left({tex}\right)^{{{exp}}}" if exp else tex


def sum_over_roots(factor: sp.Poly, weights: tuple[sp.Expr, ...] | list[sp.Expr],
                   t: sp.Expr) -> sp.Expr:
    """Σ_{q(λ)=0} Σ_k w_k(λ) t^k e^{λt} as one :class:`SumOverRoots` (λ = q's generator).

    ``factor`` is written with integer (or parameter-polynomial) coefficients, content 1;
    the weights are expressions in its generator. Nothing is expanded (at t = 0, with
    rational coefficients, the sum of the rational summand is the exact trace).
    """
    var = factor.gen
    summand = sp.Add(*(w * t**k for k, w in enumerate(weights))) * sp.exp(var * t)
    if not summand.has(var):
        return factor.degree() * summand
    return SumOverRoots._make(_pure(factor), sp.Lambda(var, summand))


@lru_cache(maxsize=256)
def _pure(factor: sp.Poly) -> sp.PurePoly:
    """q with content 1 as a PurePoly, built from the Poly (never re-parsed from an
    expression: for a symbolic chain's Δ that took a second per coordinate)."""
    return sp.PurePoly(_primitive(factor))


def _primitive(poly: sp.Poly) -> sp.Poly:
    """``poly`` with its denominators cleared and its content removed."""
    _, cleared = poly.clear_denoms(convert=True)
    return cleared.primitive()[1]


def _ratio(numerator: sp.Poly, denominator: sp.Poly) -> sp.Expr:
    """numerator/denominator as an expression, each polynomial with denominators cleared."""
    cn, N = numerator.clear_denoms(convert=True)
    cd, D = denominator.clear_denoms(convert=True)
    scale = numerator.domain.to_sympy(cd) / numerator.domain.to_sympy(cn) if cn != cd else 1
    return scale * N.as_expr() / D.as_expr()


def root_sum_weights(factor: sp.Poly, numerator: sp.Poly, denominator: sp.Poly,
                     multiplicity: int = 1) -> tuple[sp.Expr, ...]:
    """The w_k(λ) of Σ_{q(λ)=0} Σ_k w_k(λ) t^k e^{λt}, the inverse of N/D at q's roots.

    Parameters
    ----------
    factor : sympy.Poly
        q(λ), with simple roots (irreducible over the coefficients' field).
    numerator, denominator : sympy.Poly
        N and D with q^multiplicity dividing D exactly (and q not dividing N).
    multiplicity : int
        m. For m = 1 the weight is N(λ)/D'(λ). For m > 1 it is the full residue: with
        q(λ) = (λ − ρ)Q₁(λ, ρ) and G(λ) = N(λ)/(Q₁(λ, ρ)^m S(λ)), S = D/q^m,
        w_j(ρ) = C(m−1, j)/(m−1)! · G^{(m−1−j)}(ρ).

    Returns
    -------
    tuple of sympy.Expr
        ``(w_0, ..., w_{m-1})`` in q's generator.
    """
    var = factor.gen
    if multiplicity == 1:
        return (_ratio(numerator, denominator.diff(var)),)
    m = multiplicity
    rho = sp.Dummy("rho")
    q = factor.as_expr()
    Q1 = sp.quo(q - q.xreplace({var: rho}), var - rho, var)
    S = denominator.quo(factor ** m)
    G = _ratio(numerator, S) / Q1 ** m
    weights = []
    for j in range(m):
        derivative = sp.diff(G, var, m - 1 - j) if m - 1 - j else G
        value = derivative.xreplace({var: rho}).xreplace({rho: var})
        weights.append(sp.Rational(comb(m - 1, j), factorial(m - 1)) * value)
    return tuple(weights)


@dataclass(frozen=True)
class Condition:
    """Where a sum over the roots of q holds: each root of q is a simple root of D.

    That is disc_λ q(λ) ≠ 0 and res_λ(q, S) ≠ 0 with S = D/q^m the rest of the
    denominator; :attr:`expr` is their product, a polynomial in the parameters
    (computed on first use: for a sextic in eight parameters it takes minutes, while
    :meth:`holds_at` with numbers takes milliseconds).

    Attributes
    ----------
    factor : sympy.Poly
        q(λ), the polynomial summed over.
    cofactor : sympy.Poly
        S(λ) = D(λ)/q(λ)^m: the rest of the denominator (a constant for the free motion
        of a scene whose Δ(λ) is irreducible).
    """

    factor: sp.Poly
    cofactor: sp.Poly

    @property
    def meaning(self) -> str:
        """The condition in words."""
        if self.cofactor.degree() <= 0:
            return f"{self.factor.as_expr()} has simple roots (its discriminant is not 0)"
        return (f"the roots of {self.factor.as_expr()} are simple and are not roots of "
                f"{self.cofactor.as_expr()}")

    @cached_property
    def expr(self) -> sp.Expr:
        """disc_λ q · res_λ(q, S): the formula holds where this is not zero."""
        q = _primitive(self.factor)
        value = sp.discriminant(q)
        if self.cofactor.degree() > 0:
            value *= sp.resultant(q, _primitive(self.cofactor))
        return sp.factor(value)

    def as_relational(self) -> sp.Ne:
        """``Ne(disc · res, 0)``."""
        return sp.Ne(self.expr, 0)

    def holds_at(self, values: dict) -> bool:
        """Whether the condition holds at numbers for the parameters (no symbolic disc).

        Examples
        --------
        >>> s, a = sp.symbols("s a")
        >>> condition = Condition(sp.Poly(s**3 + a*s + 1, s), sp.Poly(1, s))
        >>> condition.holds_at({a: 1}), condition.holds_at({a: -sp.Rational(3, 2) * 2**sp.Rational(1, 3)})
        (True, False)
        """
        q = sp.Poly(self.factor.as_expr().subs(values), self.factor.gen)
        rest = sp.Poly(self.cofactor.as_expr().subs(values), self.factor.gen)
        if q.degree() < self.factor.degree():
            return False
        if sp.simplify(sp.discriminant(q)) == 0:
            return False
        return rest.degree() <= 0 or sp.simplify(sp.resultant(q, rest)) != 0

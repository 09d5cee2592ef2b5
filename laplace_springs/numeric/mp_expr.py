"""Fast mpmath values of exact closed-form coefficients.

The coefficients of a solution built on roots of an irreducible polynomial are large
polynomials in re(ρ), im(ρ) with big rational coefficients. ``sympy.N`` walks and
rebuilds them several times (5 s for the sixteen-pole terms of an eight-mass chain);
here each expression tree is evaluated once in mpmath arithmetic at a guard precision,
twice (at two precisions) to confirm the digits, sharing subexpressions.

Precision and conditioning
--------------------------
The polynomials cancel: their terms can be far larger than the value (an eight-
decade spread of masses gives 60 digits of cancellation, where SymPy's evalf on the
rounded roots returns garbage). Evaluations at ``dps + g`` and ``dps + 2g`` digits
must agree to ``dps`` digits relative to the value; g starts at 30 and doubles until
they do. Anything unsupported (a free symbol, an unknown function) goes to
:func:`numeric_value`, SymPy's adaptive evalf.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import mpmath
import sympy as sp
from sympy.polys.rootoftools import ComplexRootOf

from ..exact.algebraic import AlgebraicRoot
from ..exact.named import NamedNumber, NamedQuantity
from ..kernels.precision import workdps

__all__ = ["mp_size", "mp_value", "numeric_value"]

#: Guard digits are doubled while two evaluations disagree, up to this many.
_MAX_GUARD = 4000



def numeric_value(expr: sp.Expr, dps: int) -> sp.Expr:
    """``N(expr, dps)``, with each algebraic root in it evaluated once, not per occurrence.

    SymPy's adaptive evalf asks every occurrence of a root (inside ``re``, ``im`` and
    powers) for its value at several precisions; substituting the roots first makes
    the evaluation of a closed form cost one flint call per root.
    """
    expr = sp.sympify(expr, strict=True)
    roots = expr.atoms(AlgebraicRoot)
    if roots:
        expr = expr.xreplace({r: r.evalf(dps + 10) for r in roots})
    return sp.N(expr, dps)


class _Unsupported(Exception):
    """An expression node this evaluator does not handle."""


_FUNCTIONS = {sp.exp: mpmath.exp, sp.cos: mpmath.cos, sp.sin: mpmath.sin,
              sp.cosh: mpmath.cosh, sp.sinh: mpmath.sinh, sp.log: mpmath.log,
              sp.re: mpmath.re, sp.im: mpmath.im, sp.Abs: abs}


def _root(expr: ComplexRootOf, dps: int):
    value = numeric_value(expr, dps)
    re, im = value.as_real_imag()
    return mpmath.mpc(mpmath.mpf(sp.Float(re, dps)._mpf_), mpmath.mpf(sp.Float(im, dps)._mpf_))


def _evaluate(expr: sp.Expr, cache: dict, dps: int):
    if expr in cache:
        return cache[expr]
    if expr.is_Rational:
        value = mpmath.mpf(int(expr.p)) / int(expr.q)
    elif isinstance(expr, ComplexRootOf):
        value = _root(expr, dps)
    elif isinstance(expr, NamedNumber):  # certified digits at the working precision
        value = expr.value(mpmath.mp.prec)
    elif isinstance(expr, NamedQuantity) and not expr.free_symbols:
        value = _evaluate(expr.definition, cache, dps)
    elif expr.is_Add:
        value = mpmath.fsum(_evaluate(a, cache, dps) for a in expr.args)
    elif expr.is_Mul:
        value = mpmath.fprod(_evaluate(a, cache, dps) for a in expr.args)
    elif expr.is_Pow:
        base, power = expr.args
        exponent = int(power) if power.is_Integer else _evaluate(power, cache, dps)
        value = _evaluate(base, cache, dps) ** exponent
    elif expr is sp.I:
        value = mpmath.mpc(0, 1)
    elif expr is sp.pi:
        value = +mpmath.pi
    elif expr is sp.E:
        value = mpmath.e
    elif expr.is_Float:
        value = mpmath.mpf(expr._mpf_)
    elif expr.func in _FUNCTIONS and len(expr.args) == 1:
        value = _FUNCTIONS[expr.func](_evaluate(expr.args[0], cache, dps))
    else:
        raise _Unsupported(expr)
    cache[expr] = value
    return value


def _at(expr: sp.Expr, dps: int, caches: dict):
    cache = caches.setdefault(dps, {})
    with workdps(dps):
        return _evaluate(expr, cache, dps)


def mp_value(expr: sp.Expr, dps: int, caches: dict | None = None) -> mpmath.mpf:
    """The real value of an exact expression as an mpf good to ``dps`` digits.

    Parameters
    ----------
    expr : sympy expression
        A real number: rationals, algebraic roots (``CRootOf``), radicals, re/im, ...
    dps : int
        Decimal digits wanted.
    caches : dict, optional
        Shared between calls (keyed by working precision) so that common
        subexpressions, in particular the roots, are evaluated once.

    Returns
    -------
    mpmath.mpf
        At precision ``dps`` (a number of that precision; the current mpmath
        precision is left unchanged).

    Examples
    --------
    >>> import sympy as sp
    >>> x = sp.Symbol("x")
    >>> from laplace_springs.exact.algebraic import AlgebraicRoot
    >>> r = AlgebraicRoot(x**5 - x - 1, 1)
    >>> expr = sp.re(r)**2 - sp.im(r)**2 + sp.Rational(1, 3)
    >>> value = mp_value(expr, 30)
    >>> with mpmath.workdps(30):
    ...     print(value)
    0.794145339335825321676835577914
    >>> sp.N(expr, 30)
    0.794145339335825321676835577914
    """
    expr = sp.sympify(expr)
    high = _converged(expr, dps, {} if caches is None else caches, _agree)
    if high is None:
        return _fallback(expr, dps)
    with workdps(dps):
        return +mpmath.re(high)


def mp_size(expr: sp.Expr, dps: int, caches: dict | None = None) -> mpmath.mpf:
    """|expr| to ``dps`` digits *absolute* (or relative, if larger): what a residual that
    should vanish needs. :func:`mp_value` asks for relative digits, which a value of
    exactly 0 never gives (its guard doubles to the limit, then SymPy's evalf runs).

    Two evaluations at ``dps + g`` and ``dps + 2g`` digits must agree within
    10^-dps·max(1, |value|); g doubles until they do.

    >>> import sympy as sp
    >>> r = sp.sqrt(2)
    >>> float(mp_size(r**2 - 2, 40)) < 1e-40
    True
    """
    expr = sp.sympify(expr)
    high = _converged(expr, dps, {} if caches is None else caches, _agree_absolute)
    if high is not None:
        return abs(high)
    size = sp.Abs(numeric_value(expr, dps))   # SymPy's adaptive evalf: complex values too
    with workdps(dps):
        return mpmath.mpf(sp.Float(size, dps)._mpf_)


def _converged(expr: sp.Expr, dps: int, caches: dict, agree: Callable[[Any, Any, int], bool]):
    """The evaluation at ``dps + 2g`` digits once it ``agree``s with the one at ``dps + g``
    (g = 30, doubled up to _MAX_GUARD), or None (unsupported nodes, no agreement)."""
    guard = 30
    try:
        low = _at_or_none(expr, dps + guard, caches)
        while guard <= _MAX_GUARD:
            high = _at_or_none(expr, dps + 2 * guard, caches)
            if low is not None and high is not None and agree(low, high, dps):
                return high
            low, guard = high, 2 * guard
    except (_Unsupported, TypeError, ValueError):
        pass
    return None


def _agree_absolute(low, high, dps: int) -> bool:
    """Do two evaluations agree within 10^-dps·max(1, |high|)?"""
    with workdps(dps + 10):
        return abs(low - high) <= mpmath.mpf(10) ** (-dps) * max(1, abs(high))


def _at_or_none(expr: sp.Expr, dps: int, caches: dict):
    """:func:`_at`, or None where a difference cancelled to an exact zero that is then
    divided by (1 − e^{−Pλ} at a period P below 10^{-dps}: more digits are needed, not
    SymPy's evalf, which returns such a quotient wrong without a word)."""
    try:
        return _at(expr, dps, caches)
    except ZeroDivisionError:
        return None


def _agree(low, high, dps: int) -> bool:
    """Do two evaluations agree to ``dps`` digits (and is the value real)?"""
    with workdps(dps + 10):
        tol = abs(high) * mpmath.mpf(10) ** (-dps - 2)
        return abs(mpmath.im(high)) <= tol and abs(low - high) <= tol


def _fallback(expr: sp.Expr, dps: int) -> mpmath.mpf:
    value = numeric_value(expr, dps)
    if value.is_real is False:
        value = sp.re(value)
    with workdps(dps):
        return mpmath.mpf(sp.Float(value, dps)._mpf_)

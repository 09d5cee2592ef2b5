"""Exact algebraic roots that evaluate fast: CRootOf with certified flint numerics.

SymPy's ``CRootOf`` is the right exact object for a root of an irreducible polynomial
of degree ≥ 3, but its ``evalf`` refines the isolating rectangle by bisection (1.7 s
for the four roots of the seed's Example 5 quartic at 30 digits). :class:`AlgebraicRoot`
is the same object, printed the same way, whose numerical value comes instead from
python-flint's certified complex root enclosures (arb), matched to SymPy's isolating
interval so that the index keeps its meaning. It costs about a millisecond.
"""

from __future__ import annotations

from fractions import Fraction
from functools import lru_cache
from typing import cast

import flint
import mpmath
import sympy as sp
from sympy.core.evalf import prec_to_dps
from sympy.polys.rootoftools import ComplexRootOf

from ..kernels.precision import flint_workdps, workdps

__all__ = ["AlgebraicRoot", "root_enclosures"]


@lru_cache(maxsize=512)
def root_enclosures(coeffs: tuple[sp.Rational, ...], dps: int) -> tuple[tuple[mpmath.mpf, mpmath.mpf], ...]:
    """All complex roots of a rational polynomial as (real, imag) mpmath numbers.

    ``coeffs`` are ascending. The enclosures are certified by arb; their midpoints are
    returned exactly (binary mantissa and exponent, rounded to the current mpmath
    precision): no decimal strings, which Python refuses to turn into integers beyond
    4,300 digits (the mp engine asks up to Limits.max_dps = 10,000).
    """
    poly = flint.fmpq_poly([flint.fmpq(int(c.p), int(c.q)) for c in coeffs])
    with flint_workdps(dps):
        # python-flint's stub declares list[acb]; the call returns (root, multiplicity) pairs
        pairs = cast(list[tuple[flint.acb, int]], poly.complex_roots())
        return tuple((_binary(r.real.mid()), _binary(r.imag.mid())) for r, _ in pairs)


def _binary(value: flint.arb) -> mpmath.mpf:
    """An exact arb midpoint as an mpf."""
    mantissa, exponent = value.man_exp()
    return mpmath.mpf((int(mantissa), int(exponent)))


def _mpf(value) -> mpmath.mpf:
    """An exact rational bound (SymPy or flint ground type) as an mpf."""
    fraction = Fraction(str(value))
    return mpmath.mpf(fraction.numerator) / fraction.denominator


def _inside(interval, re: mpmath.mpf, im: mpmath.mpf) -> bool:
    """Is re + i·im inside a CRootOf isolating interval (real) or rectangle (complex)?"""
    if hasattr(interval, "ax"):
        return (_mpf(interval.ax) <= re <= _mpf(interval.bx)
                and _mpf(interval.ay) <= im <= _mpf(interval.by))
    return _mpf(interval.a) <= re <= _mpf(interval.b) and not im


class AlgebraicRoot(ComplexRootOf):
    """``CRootOf(f, index)`` whose ``evalf`` uses certified flint root enclosures.

    Examples
    --------
    >>> import sympy as sp
    >>> x = sp.Symbol("x")
    >>> r = AlgebraicRoot(x**3 + x + 1, 0)
    >>> r
    CRootOf(x**3 + x + 1, 0)
    >>> sp.N(r, 30)
    -0.682327803828019327369483739711
    >>> abs(sp.N(r**3 + r + 1, 40)) < 1e-35
    True
    """

    __slots__ = ()

    def _eval_evalf(self, prec, **kwargs):
        value = _root_value(self, prec_to_dps(prec) + 10)
        if value is None:  # an enclosure on an interval edge: SymPy's refinement decides
            return super()._eval_evalf(prec, **kwargs)
        return value.evalf(prec_to_dps(prec))


@lru_cache(maxsize=4096)
def _root_value(root: AlgebraicRoot, dps: int) -> sp.Expr | None:
    """Value of a root at ``dps`` digits from flint, or None if the match is ambiguous."""
    coeffs = tuple(reversed([sp.Rational(c) for c in root.poly.all_coeffs()]))
    interval = root._get_interval()
    with workdps(dps):
        found = list(root_enclosures(coeffs, dps))
        inside = [z for z in found if _inside(interval, *z)]
        if len(inside) != 1:
            return None
        re, im = inside[0]
        return sp.Float(re, dps) + sp.I * sp.Float(im, dps) if im else sp.Float(re, dps)

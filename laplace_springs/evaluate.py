"""Numeric evaluation of real-form terms, in float64 or at any mpmath precision.

Exact term data (α, β, a, b, possibly built on ``CRootOf``) are first converted to
mpmath numbers at a working precision well above the target: algebraic roots come
from python-flint's certified complex root enclosures, matched to SymPy's isolating
rectangles, instead of SymPy's much slower ``CRootOf.evalf``. Hyperbolic pairs
e^{αt}(a cosh σt + b sinh σt) are split into two real exponentials whose rates α ± σ
are formed at that working precision, so widely separated real roots keep full
relative accuracy in float64.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from functools import lru_cache
from typing import Sequence

import flint
import mpmath
import numpy as np
import sympy as sp

from .real_terms import Term

__all__ = ["NumericTerms", "numeric_terms", "evaluate_float", "evaluate_mp"]


@lru_cache(maxsize=256)
def _flint_roots(coeffs: tuple[sp.Rational, ...], dps: int) -> tuple[tuple[str, str], ...]:
    """Roots of a rational polynomial (ascending coefficients) as decimal strings."""
    poly = flint.fmpq_poly([flint.fmpq(int(c.p), int(c.q)) for c in coeffs])
    with flint.ctx.workdps(dps):
        roots = [r for r, _ in poly.complex_roots()]
        return tuple((r.real.mid().str(dps, radius=False), r.imag.mid().str(dps, radius=False))
                     for r in roots)


def _mpf(value) -> mpmath.mpf:
    """An exact rational bound (SymPy or flint ground type) as an mpf."""
    fraction = Fraction(str(value))
    return mpmath.mpf(fraction.numerator) / fraction.denominator


def _contains(interval, re: mpmath.mpf, im: mpmath.mpf) -> bool:
    """Is re + i·im inside a CRootOf isolating interval or rectangle?"""
    if hasattr(interval, "ax"):
        return (_mpf(interval.ax) <= re <= _mpf(interval.bx)
                and _mpf(interval.ay) <= im <= _mpf(interval.by))
    return _mpf(interval.a) <= re <= _mpf(interval.b) and not im


def _root_value(root: sp.CRootOf, dps: int) -> sp.Expr:
    """Value of a CRootOf at ``dps`` digits, from flint's enclosures."""
    coeffs = tuple(reversed([sp.Rational(c) for c in root.poly.all_coeffs()]))
    interval = root._get_interval()
    with mpmath.workdps(dps):
        candidates = [(mpmath.mpf(re), mpmath.mpf(im)) for re, im in _flint_roots(coeffs, dps)]
        inside = [c for c in candidates if _contains(interval, *c)]
        if len(inside) != 1:  # enclosure on an edge: fall back on SymPy's own refinement
            return root.evalf(dps)
        re, im = inside[0]
        return sp.Float(re, dps) + sp.I * sp.Float(im, dps) if im else sp.Float(re, dps)


def _mp_value(expr: sp.Expr, dps: int) -> mpmath.mpf:
    """An exact real expression as an mpmath number at ``dps`` digits."""
    expr = sp.sympify(expr)
    roots = expr.atoms(sp.CRootOf)
    if roots:
        expr = expr.xreplace({r: _root_value(r, dps + 10) for r in roots})
    value = sp.N(expr, dps)
    if value.is_real is False:
        value = sp.re(value)
    return mpmath.mpf(sp.Float(value, dps)._mpf_)


@dataclass(frozen=True)
class NumericTerms:
    """Terms as arrays: row, power, rate, frequency (0 for real terms), cos and sin weights.

    Hyperbolic terms have been split into two real exponentials.
    """

    row: np.ndarray
    power: np.ndarray
    rate: list
    frequency: list
    a: list
    b: list
    dps: int

    def as_float(self) -> tuple[np.ndarray, ...]:
        """The float64 arrays (rate, frequency, a, b)."""
        return tuple(np.array([float(v) for v in vals], dtype=float)
                     for vals in (self.rate, self.frequency, self.a, self.b))


def _numeric_rows(term: Term, dps: int) -> list[tuple]:
    """(power, rate, frequency, a, b) tuples of one exact term at ``dps`` digits."""
    alpha, a = _mp_value(term.alpha, dps), _mp_value(term.a, dps)
    if term.kind == "real":
        return [(term.power, alpha, mpmath.mpf(0), a, mpmath.mpf(0))]
    beta, b = _mp_value(term.beta, dps), _mp_value(term.b, dps)
    if term.kind == "oscillatory":
        return [(term.power, alpha, beta, a, b)]
    with mpmath.workdps(dps):  # a cosh σt + b sinh σt = (a+b)/2 e^{σt} + (a-b)/2 e^{-σt}
        zero = mpmath.mpf(0)
        return [(term.power, alpha + beta, zero, (a + b) / 2, zero),
                (term.power, alpha - beta, zero, (a - b) / 2, zero)]


def numeric_terms(rows: Sequence[Sequence[Term]], dps: int = 40) -> NumericTerms:
    """Convert the exact terms of each coordinate to mpmath data at ``dps`` digits."""
    table = []
    for i, terms in enumerate(rows):
        for term in terms:
            table.extend((i, *values) for values in _numeric_rows(term, dps))
    columns = list(zip(*table)) if table else [(), (), (), (), (), ()]
    return NumericTerms(np.array(columns[0], dtype=int), np.array(columns[1], dtype=int),
                        list(columns[2]), list(columns[3]), list(columns[4]), list(columns[5]),
                        dps)


def evaluate_float(data: NumericTerms, n: int, times: np.ndarray) -> np.ndarray:
    """Sum the terms in float64 at ``times``; shape (n, len(times))."""
    times = np.asarray(times, dtype=float)
    out = np.zeros((n, times.size))
    rate, freq, a, b = data.as_float()
    for j in range(len(rate)):
        value = np.exp(rate[j] * times)
        if freq[j]:
            phase = freq[j] * times
            value = value * (a[j] * np.cos(phase) + b[j] * np.sin(phase))
        else:
            value = value * a[j]
        if data.power[j]:
            value = value * times ** data.power[j]
        out[data.row[j]] += value
    return out


def evaluate_mp(data: NumericTerms, n: int, times: Sequence, dps: int) -> np.ndarray:
    """Sum the terms with mpmath at ``dps`` digits; an object array of mpf values."""
    out = np.empty((n, len(times)), dtype=object)
    with mpmath.workdps(dps):
        ts = [mpmath.mpf(str(v)) if isinstance(v, (float, np.floating)) else mpmath.mpf(v)
              for v in times]
        out[:] = mpmath.mpf(0)
        for j in range(len(data.rate)):
            i, k = data.row[j], int(data.power[j])
            for col, tv in enumerate(ts):
                value = mpmath.exp(data.rate[j] * tv) * tv**k
                if data.frequency[j]:
                    phase = data.frequency[j] * tv
                    value *= data.a[j] * mpmath.cos(phase) + data.b[j] * mpmath.sin(phase)
                else:
                    value *= data.a[j]
                out[i, col] += value
    return out

"""Numeric evaluation of real-form terms, in float64 or at any mpmath precision.

Exact term data (α, β, a, b, possibly built on algebraic roots, whose values come
from flint: see :mod:`laplace_springs.algebraic`) are first converted to mpmath
numbers at a working precision well above the target. Hyperbolic pairs
e^{αt}(a cosh σt + b sinh σt) are split into two real exponentials whose rates α ± σ
are formed at that working precision, so widely separated real roots keep full
relative accuracy in float64.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import mpmath
import numpy as np
import sympy as sp

from .algebraic import numeric_value
from .real_terms import Term

__all__ = ["NumericTerms", "numeric_terms", "evaluate_float", "evaluate_mp"]


def _mp_value(expr: sp.Expr, dps: int) -> mpmath.mpf:
    """An exact real expression as an mpmath number at ``dps`` digits."""
    value = numeric_value(expr, dps)
    if value.is_real is False:
        value = sp.re(value)
    with mpmath.workdps(dps):
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


def _mp_time(value) -> mpmath.mpf:
    """A time as an mpf: floats by their shortest decimal (0.1 is 1/10), like all input."""
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float):
        return mpmath.mpf(repr(value))
    if isinstance(value, sp.Basic):
        return mpmath.mpf(sp.Float(value, mpmath.mp.dps)._mpf_)
    return mpmath.mpf(value)


def evaluate_mp(data: NumericTerms, n: int, times: Sequence, dps: int) -> np.ndarray:
    """Sum the terms with mpmath at ``dps`` digits; an object array of mpf values."""
    out = np.empty((n, len(times)), dtype=object)
    with mpmath.workdps(dps):
        ts = [_mp_time(v) for v in times]
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

"""Double-double arithmetic (float expansions of two terms), the one copy in the package.

A double-double is an unevaluated sum hi + lo of two float64 numbers with |lo| ≤ ulp(hi)/2,
about 106 bits. The error-free transformations below (Knuth's two-sum, Dekker's split and
two-product) work elementwise on floats and NumPy arrays alike; the engines that carry
states, phases or weights in double-double (krylov, sampled forcing, pole sums, the
long-horizon engine) use these and no copies of their own.

References: Dekker (1971), Knuth TAOCP vol. 2 §4.2.2, Shewchuk (1997), Joldes, Muller &
Popescu, "Tight and rigorous error bounds for basic building blocks of double-word
arithmetic" (2017): the add below (their Algorithm 6, "AccurateDWPlusDW") has relative
error ≤ 3u² + 13u³ and the multiplication (Algorithm 12 without the last FMA) ≤ 7u².

>>> hi, lo = two_sum(1.0, 1e-20)
>>> hi, lo
(1.0, 1e-20)
>>> from fractions import Fraction
>>> hi, lo = from_exact(Fraction(1, 3))
>>> Fraction(hi) + Fraction(lo) - Fraction(1, 3) < Fraction(1, 10**32)
True
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Any

import numpy as np

__all__ = ["U", "UNIT_DD", "SPLITTER", "split", "two_sum", "fast_two_sum", "two_prod",
           "two_diff", "dd_add", "dd_mul", "dd_mul_float", "dd_div", "dd_sqrt", "dd_sum",
           "from_exact", "to_fraction", "phase"]

#: Unit roundoff of float64.
U = 2.0**-53
#: A generous relative rounding of one double-double operation (3u² + 13u³ < 2^-104).
UNIT_DD = 2.0**-100
#: Dekker's splitting constant 2^27 + 1.
SPLITTER = 134217729.0


def split(a: Any) -> tuple[Any, Any]:
    """a = hi + lo exactly, each half with at most 26 significant bits (Dekker)."""
    c = SPLITTER * a
    hi = c - (c - a)
    return hi, a - hi


def two_sum(a: Any, b: Any) -> tuple[Any, Any]:
    """s = fl(a + b) and the exact error a + b − s (Knuth; no ordering of |a|, |b| needed)."""
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


def fast_two_sum(a: Any, b: Any) -> tuple[Any, Any]:
    """s = fl(a + b) and its exact error, for |a| ≥ |b| (or a = 0)."""
    s = a + b
    return s, b - (s - a)


def two_prod(a: Any, b: Any) -> tuple[Any, Any]:
    """p = fl(a·b) and the exact error a·b − p (Dekker; no overflow in the split assumed).

    Where the product overflows or the split does, the error is returned as 0.
    """
    p = a * b
    ah, al = split(a)
    bh, bl = split(b)
    with np.errstate(invalid="ignore", over="ignore"):
        e = ((ah * bh - p) + ah * bl + al * bh) + al * bl
    if isinstance(e, np.ndarray):
        return p, np.where(np.isfinite(e), e, 0.0)
    return p, e if math.isfinite(e) else 0.0


def two_diff(a: Any, b_hi: float, b_lo: float) -> tuple[Any, Any]:
    """a − (b_hi + b_lo) as a double-double, a exact floats."""
    s = a - b_hi
    v = s - a
    err = (a - (s - v)) - (b_hi + v)
    lo = err - b_lo
    hi = s + lo
    return hi, lo - (hi - s)


def dd_add(ah: Any, al: Any, bh: Any, bl: Any) -> tuple[Any, Any]:
    """(ah + al) + (bh + bl), relative error ≤ 3u² + 13u³."""
    s, e = two_sum(ah, bh)
    t, f = two_sum(al, bl)
    s, e = fast_two_sum(s, e + t)
    return fast_two_sum(s, e + f)


def dd_mul(ah: Any, al: Any, bh: Any, bl: Any) -> tuple[Any, Any]:
    """(ah + al)·(bh + bl), relative error ≤ 7u²."""
    p, e = two_prod(ah, bh)
    return fast_two_sum(p, e + (ah * bl + al * bh))


def dd_mul_float(ah: Any, al: Any, b: Any) -> tuple[Any, Any]:
    """(ah + al)·b for a float b, relative error ≤ 2u²."""
    p, e = two_prod(ah, b)
    return fast_two_sum(p, e + al * b)


def dd_div(ah: Any, al: Any, bh: Any, bl: Any) -> tuple[Any, Any]:
    """(ah + al)/(bh + bl), relative error ≤ 15u² + 56u³ (Joldes, Muller & Popescu's
    Algorithm 17, "DWDivDW2"); b ≠ 0.

    >>> from fractions import Fraction
    >>> hi, lo = dd_div(1.0, 0.0, 3.0, 0.0)
    >>> abs(Fraction(hi) + Fraction(lo) - Fraction(1, 3)) < Fraction(1, 10**31)
    True
    """
    th = ah / bh
    rh, rl = dd_mul_float(bh, bl, th)
    tl = ((ah - rh) + (al - rl)) / bh
    return fast_two_sum(th, tl)


def dd_sqrt(ah: Any, al: Any) -> tuple[Any, Any]:
    """√(ah + al) for ah + al ≥ 0 (0 for 0), relative error ≤ 4u²: one Newton step from
    the float64 root s, (a − s²)/(2s) with s² formed exactly.

    >>> from fractions import Fraction
    >>> hi, lo = dd_sqrt(2.0, 0.0)
    >>> abs((Fraction(hi) + Fraction(lo)) ** 2 - 2) < Fraction(1, 10**31)
    True
    """
    s = np.sqrt(ah)
    p, e = two_prod(s, s)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = ((ah - p) - e + al) / (2 * s)
    r = np.where(s > 0, r, 0.0) if isinstance(r, np.ndarray) else (r if s > 0 else 0.0)
    return fast_two_sum(s, r)


def dd_sum(hi: np.ndarray, lo: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Σ_i (hi[i] + lo[i]) along the first axis as a double-double, vectorised over the
    other axes: Rump, Ogita & Oishi's error-free extraction ("ExtractVector", Accurate
    floating-point summation I, 2008) splits the m terms three or four times at a common
    power of two σ ≥ 2^M·max|hi|, 2^M ≥ m + 2, so that each slice sums exactly in any order;
    the low parts are summed in float64. |result − exact| ≤ γ_m·Σ|lo[i]| + 2u²·Σ|hi[i]|
    (γ_m = mu/(1 − mu)).

    >>> s, e = dd_sum(np.array([[1.0], [1e-20], [-1.0]]), np.zeros((3, 1)))
    >>> float(s[0]), float(e[0])
    (1e-20, 0.0)
    """
    m = hi.shape[0]
    M = math.ceil(math.log2(m + 2))
    rest = np.array(hi, dtype=float, copy=True)
    total = np.zeros(hi.shape[1:])
    err = np.sum(lo, axis=0)
    for _ in range(3 if m <= 2**16 else 4):
        largest = np.max(np.abs(rest), axis=0)
        _, exponent = np.frexp(largest)
        sigma = np.where(largest > 0, np.ldexp(1.0, M + exponent), 1.0)
        sliced = (sigma + rest) - sigma
        rest -= sliced
        total, sliced_error = two_sum(total, np.sum(sliced, axis=0))
        err += sliced_error
    return two_sum(total, err + np.sum(rest, axis=0))


def from_exact(value: Any) -> tuple[float, float]:
    """An exact rational (Fraction, int, SymPy Rational, python-flint fmpq) or an mpmath
    real as hi + lo: hi correctly rounded, lo the rounded remainder (|error| ≤ u²|value|)."""
    if hasattr(value, "_mpf_") or type(value).__name__ == "mpf":  # mpmath
        hi = float(value)
        return hi, (float(value - hi) if math.isfinite(hi) else 0.0)
    q = to_fraction(value)
    hi = q.numerator / q.denominator
    return hi, float(q - Fraction(hi))


def to_fraction(value: Any) -> Fraction:
    """An exact rational as a Fraction (Fraction, int, SymPy Rational, fmpq, float)."""
    if isinstance(value, Fraction):
        return value
    if isinstance(value, (int, float)):
        return Fraction(value)
    p = getattr(value, "p", None)
    if p is not None:  # SymPy Rational/Integer, python-flint fmpq
        q = value.q
        return Fraction(int(p() if callable(p) else p), int(q() if callable(q) else q))
    return Fraction(str(value))


def phase(w_hi: Any, w_lo: Any, t_hi: Any, t_lo: Any) -> tuple[Any, Any, float]:
    """cos and sin of ω·t with ω = w_hi + w_lo and t = t_hi + t_lo, the product in
    double-double; and the relative error of the phase argument formed (a bound on
    |θ − ωt|/|ωt|, before cos and sin, whose own rounding is ≤ 2u each).

    The phase θ = p + e with p = fl(ω_hi t_hi): cos θ = cos p cos e − sin p sin e, with
    the libm's correctly reduced cos and sin of p at any size.

    >>> import numpy as np
    >>> c, s, rel = phase(1.0, 0.0, np.array([1e20]), np.array([0.0]))
    >>> bool(abs(c[0] - np.cos(1e20)) < 1e-15)
    True
    """
    p, e = two_prod(w_hi, t_hi)
    e = e + (w_lo * t_hi + w_hi * t_lo)
    ce, se = np.cos(e), np.sin(e)
    cp, sp = np.cos(p), np.sin(p)
    return cp * ce - sp * se, sp * ce + cp * se, 4 * U * U

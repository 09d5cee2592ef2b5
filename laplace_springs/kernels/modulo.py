"""Times reduced modulo a period, vectorised and exact where it claims to be.

A periodic response is evaluated at (t − τ) mod P. For float times t and rational τ and P
the reduction is done in double-double: k = floor((t − τ)/P) from float64, then
r = (t − τ) − k·P with t − τ and k·P formed exactly (two-sum, two-product) and only the
product's low part k·P_lo rounded: |r − r_exact| ≤ (k + 2)·|P|·2⁻¹⁰⁴. The floor is checked
on r (r < 0 or r ≥ P move k by one); entries where that check is within the error, or
where k exceeds 2⁴⁰ (tiny periods, huge times), are left to the exact rational reduction
of the caller (the returned mask). 10⁶ times take tens of milliseconds instead of seconds
of Fractions.

>>> import numpy as np
>>> from fractions import Fraction
>>> hi, lo, done = reduce_modulo(np.array([7.25, 1e6 + 0.25]), Fraction(1, 3), Fraction(2))
>>> done.tolist(), [round(float(h), 12) for h in hi]
([True, True], [0.916666666667, 1.916666666667])
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from .dd import fast_two_sum, from_exact, two_diff, two_prod, two_sum

__all__ = ["reduce_modulo"]

#: Largest quotient k = (t − τ)/P reduced in double-double (the error grows like k·P·2⁻¹⁰⁴).
_MAX_QUOTIENT = 2.0**40


def reduce_modulo(times: np.ndarray, tau: Fraction, period: Fraction
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(t − τ) mod P as double-doubles (hi, lo) for float times ``times`` (exact floats),
    and a mask of the entries reduced here (the others are left to exact arithmetic).

    Parameters
    ----------
    times : numpy.ndarray
        float64 times, each the exact number it holds.
    tau, period : Fraction
        The delay and the period (P > 0).
    """
    tau_hi, tau_lo = from_exact(tau)
    p_hi, p_lo = from_exact(period)
    d_hi, d_lo = two_diff(np.asarray(times, dtype=float), tau_hi, tau_lo)  # t − τ, exact-ish
    with np.errstate(over="ignore", invalid="ignore"):
        k = np.floor(d_hi / p_hi)
        k_hi, k_err = two_prod(k, p_hi)                         # k·P_hi exactly
        r_hi, r_lo = two_diff(d_hi, k_hi, k_err + k * p_lo)    # (t − τ) − k·P
        r_lo = r_lo + d_lo
    r = r_hi + r_lo
    below, above = r < 0, r >= p_hi
    step = below.astype(float) - above.astype(float)
    k = k - step
    r_hi, carry = two_sum(r_hi, step * p_hi)
    r_hi, r_lo = fast_two_sum(r_hi, r_lo + carry + step * p_lo)
    error = (np.abs(k) + 2) * abs(p_hi) * 2.0**-104
    r = r_hi + r_lo
    safe = (np.abs(k) <= _MAX_QUOTIENT) & np.isfinite(r) & (r > error) & (p_hi - r > error)
    return r_hi, r_lo, safe

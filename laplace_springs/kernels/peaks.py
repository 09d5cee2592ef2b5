"""The largest value of t^k·e^{rt} over an interval [0, T], rounded up: the bounds written
as sums of such terms (the tiny engine's ``bound_until``) take each at its worst time."""

from __future__ import annotations

import math

__all__ = ["peak"]


def peak(rate: float, power: int, T: float) -> float:
    """max over t in [0, T] of t^power·e^{rate·t}, rounded up (inf beyond float64): at
    t = power/|rate| for a decaying rate whose maximum is inside, else at T.

    >>> round(peak(-2.0, 1, 10.0) * 2 * math.e, 12)   # at t = 1/2: (1/2)·e^{-1}
    1.0
    >>> peak(-2.0, 1, 0.25) == 0.25 * math.exp(-0.5) * (1 + 1e-14)   # at T
    True
    """
    try:
        if rate < 0 and power < -rate * T:  # the maximum is inside: (k/|r|)^k e^{−k}
            top = power / -rate
            value = top ** power * math.exp(-power)
        else:
            exponent = rate * T
            value = T ** power * math.exp(exponent) if exponent < 709 else math.inf
    except OverflowError:
        return math.inf
    return value * (1 + 1e-14)

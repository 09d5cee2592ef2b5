"""The symbols every stage shares: the time t and the transform variable λ.

>>> from laplace_springs.model.symbols import TIME, lam
>>> TIME, TIME.is_nonnegative, lam
(t, True, lambda)
"""

from __future__ import annotations

import sympy

__all__ = ["TIME", "lam"]

#: Time, the variable of every motion (solutions hold for t ≥ 0).
TIME = sympy.Symbol("t", nonnegative=True)

#: The transform variable λ (the seed's notation), used by every exact stage.
lam = sympy.Symbol("lambda")

"""The symbols every stage shares: the time t and the transform variables λ and s.

>>> from laplace_springs.model.symbols import S, TIME, lam
>>> TIME, TIME.is_nonnegative, lam, S
(t, True, lambda, s)
"""

from __future__ import annotations

import sympy

__all__ = ["S", "TIME", "lam"]

#: Time, the variable of every motion (solutions hold for t ≥ 0).
TIME = sympy.Symbol("t", nonnegative=True)

#: The transform variable λ (the seed's notation), used by every exact stage.
lam = sympy.Symbol("lambda")

#: The transform variable s of the public transforms (``ls.s``): :func:`laplace_springs.laplace`
#: returns F(s), and ``inverse_laplace(F, ls.s, ls.t)`` takes it back.
S = sympy.Symbol("s")

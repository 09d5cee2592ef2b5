"""The symbols every stage shares: the time t, the transform variables λ and s, the
frequency ω, and the names they reserve.

>>> from laplace_springs.model.symbols import OMEGA, S, TIME, lam
>>> TIME, TIME.is_nonnegative, lam, S, OMEGA, OMEGA.is_positive
(t, True, lambda, s, omega, True)

A parameter may not be named like one of them (:data:`RESERVED_NAMES`): a parameter
``omega`` would be the same SymPy symbol as ``ls.omega``, and ``frequency_response`` would
mix the stiffness with the frequency; a parameter ``s`` would print like the transform
variable in ``transfer_function``.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

import sympy

__all__ = ["OMEGA", "RESERVED_NAMES", "S", "TIME", "lam", "reserved_name_message"]

#: Time, the variable of every motion (solutions hold for t ≥ 0).
TIME = sympy.Symbol("t", nonnegative=True)

#: The transform variable λ (the seed's notation), used by every exact stage.
lam = sympy.Symbol("lambda")

#: The transform variable s of the public transforms (``ls.s``): :func:`laplace_springs.laplace`
#: returns F(s), and ``inverse_laplace(F, ls.s, ls.t)`` takes it back.
S = sympy.Symbol("s")

#: The driving frequency ω of exact frequency responses (``ls.omega``, rad per unit time).
OMEGA = sympy.Symbol("omega", positive=True)

#: Names a parameter may not have, and what each one already means in the toolkit (the
#: symbols the package exports and puts into its results).
RESERVED_NAMES: Mapping[str, str] = MappingProxyType({
    "t": "the time (ls.t)",
    "s": "the transform variable of ls.laplace and ls.transfer_function (ls.s)",
    "lambda": "the resolvent's variable λ (ls.lam)",
    "lam": "the resolvent's variable λ (ls.lam, printed 'lambda')",
    "omega": "the driving frequency of ls.frequency_response (ls.omega)",
})


def reserved_name_message(name: str) -> str | None:
    """Why ``name`` cannot name a parameter, with what to do instead; None if it can.

    Examples
    --------
    >>> reserved_name_message("omega")
    "'omega' cannot be a parameter name: it is the driving frequency of ls.frequency_response (ls.omega); rename the parameter, e.g. 'omega_0'"
    >>> reserved_name_message("k") is None
    True
    """
    meaning = RESERVED_NAMES.get(name)
    if meaning is None:
        return None
    return (f"{name!r} cannot be a parameter name: it is {meaning}; rename the parameter, "
            f"e.g. {name + '_0'!r}")

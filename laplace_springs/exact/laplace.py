"""The forward Laplace transform of the forcing class, exactly.

F(s) = ∫₀^∞ f(t) e^{-st} dt for f a finite sum of products of constants, powers t^k,
exp, cos, sin, cosh, sinh of linear arguments, steps ``Heaviside(t - τ)`` and impulses
``DiracDelta(t - τ)`` (the class :mod:`laplace_springs.model.forcing` accepts as forcing).
The result is Σ_τ e^{-τ s} R_τ(s) with rational R_τ, the shape that
:func:`laplace_springs.inverse_laplace` takes back. An impulse at 0 counts whole:
L[δ(t)] = 1.
"""

from __future__ import annotations

import sympy as sp

from ..model.forcing import input_transform, parse_forcing
from ..model.numbers import declare_parameters
from ..model.symbols import TIME, S

__all__ = ["laplace"]


def laplace(f: sp.Expr | str, t: sp.Symbol | None = None, s: sp.Symbol | None = None, *,
            parameters: object = None) -> sp.Expr:
    """Exact Laplace transform F(s) of an input f(t) of the forcing class.

    Parameters
    ----------
    f : sympy.Expr or str
        The function of time: text (read by the safe parser, never evaluated; it may use
        ``t`` and the declared ``parameters``), a number, or a SymPy expression.
    t : sympy.Symbol, optional
        The time variable of ``f`` (default :data:`laplace_springs.t`; any Symbol named
        ``t`` is taken as time too).
    s : sympy.Symbol, optional
        The transform variable (default :data:`laplace_springs.s`).
    parameters : sequence or mapping, optional
        Names text ``f`` may use as symbols (positive by default).

    Returns
    -------
    sympy.Expr
        Σ_τ R_τ(s) e^{-τ s}, each R_τ rational with a factored denominator.

    Raises
    ------
    SceneError
        For text that does not parse or names an undeclared parameter, and for an f
        outside the class (``1/(t + 1)``, ``cos(t**2)``); the message says why.

    Examples
    --------
    >>> import sympy as sp
    >>> from laplace_springs.model.symbols import S as s, TIME as t
    >>> laplace("t*sin(2*t)")
    4*s/(s**2 + 4)**2
    >>> laplace(sp.exp(-t) * sp.cos(3 * t))
    (s + 1)/(s**2 + 2*s + 10)
    >>> laplace("Heaviside(t - 1) - Heaviside(t - 3)")
    exp(-s)/s - exp(-3*s)/s
    >>> laplace("F0*DiracDelta(t - 2)", parameters=["F0"])
    F0*exp(-2*s)
    """
    s = S if s is None else s
    declared = declare_parameters(parameters)
    if t is not None and t != TIME and isinstance(f, sp.Basic):
        f = f.xreplace({t: TIME})
    expr = parse_forcing(f, "f", declared)
    transform = input_transform(expr, "f", s)
    return sp.Add(*(sp.factor(R) * sp.exp(-s * tau) for tau, R in transform.parts))

"""The forward Laplace transform of the forcing class, exactly.

F(s) = ∫₀^∞ f(t) e^{-st} dt for f a finite sum of products of constants, powers t^k,
exp, cos, sin, cosh, sinh of linear arguments, steps ``Heaviside(t - τ)`` and impulses
``DiracDelta(t - τ)`` (the class :mod:`laplace_springs.model.forcing` accepts as forcing),
and periodic inputs ``periodic(g, T)`` (:mod:`laplace_springs.model.periodic`).
The result is Σ_τ e^{-τ s} R_τ(s) with rational R_τ, the shape that
:func:`laplace_springs.inverse_laplace` takes back; a periodic input adds
(transform of one period)/(1 - e^{-Ts}). An impulse at 0 counts whole: L[δ(t)] = 1.
"""

from __future__ import annotations

import functools

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
        Σ_τ R_τ(s) e^{-τ s}, each R_τ rational with a factored denominator. A periodic
        input of period T adds Σ_τ R_τ(s) e^{-τ s}/(1 - e^{-Ts}) (its one period over the
        periodic factor), with the common factors of numerator and 1 - e^{-Ts}
        cancelled when the delays are multiples of T/q, q ≤ 64 (the ±1 square wave of
        period 2 gives (1 - e^{-s})/(s(1 + e^{-s})) = tanh(s/2)/s).

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
    >>> laplace("periodic(1 - 2*Heaviside(t - 1), 2)")     # ±1 square wave: tanh(s/2)/s
    (1 - exp(-s))/(s*(1 + exp(-s)))
    >>> laplace("sawtooth(1, 1)")
    (-s*exp(-s) + 1 - exp(-s))/(s**2*(1 - exp(-s)))
    """
    s = S if s is None else s
    declared = declare_parameters(parameters)
    if t is not None and t != TIME and isinstance(f, sp.Basic):
        f = f.xreplace({t: TIME})
    expr = parse_forcing(f, "f", declared)
    transform = input_transform(expr, "f", s)
    total = sp.Add(*(sp.factor(R) * sp.exp(-s * tau) for tau, R in transform.parts))
    if transform.period is None:
        return total
    return total + _over_period(transform.periodic, transform.period, s)


#: Largest q for which the delays of one period, multiples of T/q, are written as powers
#: of e^{-Ts/q} to cancel common factors with 1 - e^{-Ts}.
_MAX_PERIOD_DIVISIONS = 64


def _over_period(parts: tuple[tuple[sp.Expr, sp.Expr], ...], period: sp.Expr, s: sp.Symbol) -> sp.Expr:
    """Σ_τ R_τ e^{-τs}/(1 - e^{-Ts}), cancelled in z = e^{-Ts/q} where the τ allow."""
    ratios = [sp.Rational(tau / period) for tau, _ in parts if (tau / period).is_Rational]
    if len(ratios) < len(parts):
        return sp.Add(*(sp.factor(R) * sp.exp(-s * tau) for tau, R in parts)) / (1 - sp.exp(-s * period))
    q = functools.reduce(sp.ilcm, [r.q for r in ratios], 1)
    if q > _MAX_PERIOD_DIVISIONS:
        return sp.Add(*(sp.factor(R) * sp.exp(-s * tau) for tau, R in parts)) / (1 - sp.exp(-s * period))
    z = sp.Dummy("z")
    numerator = sp.Add(*(R * z ** int(r * q) for (_, R), r in zip(parts, ratios)))
    N, D = sp.fraction(sp.cancel(numerator / (1 - z**q)))
    factor = sp.Poly(D, z)
    if len(factor.terms()) != 2 or factor.terms()[-1][0] != (0,):
        return sp.Add(*(sp.factor(R) * sp.exp(-s * tau) for tau, R in parts)) / (1 - sp.exp(-s * period))
    (m,), top = factor.terms()[0]
    bottom = factor.terms()[-1][1]
    ratio = sp.cancel(top / bottom)  # ±1: the factor is a multiple of 1 ± z^m
    one = sp.factor_terms(sp.cancel(N / bottom))
    return (sp.factor(one) if not one.has(z) else one).xreplace({z: sp.exp(-s * period / q)}) / (
        1 + ratio * sp.exp(-s * period * m / q))

"""The forward Laplace transform of the forcing class, exactly.

F(s) = ∫₀^∞ f(t) e^{-st} dt for f a finite sum of products of constants, powers t^k,
exp, cos, sin, cosh, sinh of linear arguments, steps ``Heaviside(t - τ)`` and impulses
``DiracDelta(t - τ)`` (the class :mod:`laplace_springs.model.forcing` accepts as forcing),
and periodic inputs ``periodic(g, T)`` (:mod:`laplace_springs.model.periodic`).
The result is Σ_τ e^{-τ s} R_τ(s) with rational R_τ, the shape that
:func:`laplace_springs.inverse_laplace` takes back; a periodic input adds
(transform of one period)/(1 - e^{-Ts}). An impulse at 0 counts whole: L[δ(t)] = 1.

Two more inputs, in SymPy's convention: an unknown function x(t) and its derivatives
(the derivative rule L[x''] = s²X(s) - s x(0) - x'(0), with X(s) written
``LaplaceTransform(x(t), t, s)``, x'(0) as ``Subs(Derivative(x(t), t), t, 0)``), and a
Matrix, transformed entry by entry.

**Symbols.** A plain SymPy ``Symbol`` (no assumptions) is a complex number: the answer
holds for every complex value (L[e^{qt}] = 1/(s - q)), or carries its condition. A
symbolic switching time (``Heaviside(t - a)``, ``DiracDelta(t - a)``) is a delay where it
is ≥ 0, and ``DiracDelta(a t)`` is δ(t)/|a| for real a ≠ 0: ``conditions=True`` returns
these conditions (:class:`~laplace_springs.model.switching.SwitchCondition`); declared
parameters (positive by default) need none.
"""

from __future__ import annotations

import functools
from typing import Any

import sympy as sp
from sympy.core.function import AppliedUndef

from ..model.errors import SceneError
from ..model.forcing import input_transform, parse_forcing
from ..model.numbers import declare_parameters, shown
from ..model.switching import SwitchCondition, switching_time
from ..model.symbols import TIME, S

__all__ = ["laplace", "derivative_transform"]


def laplace(f: Any, t: sp.Symbol | None = None, s: sp.Symbol | None = None, *,
            parameters: object = None, conditions: bool = False) -> Any:
    """Exact Laplace transform F(s) of an input f(t) of the forcing class.

    Parameters
    ----------
    f : sympy.Expr, str or sympy.Matrix
        The function of time: text (read by the safe parser, never evaluated; it may use
        ``t`` and the declared ``parameters``), a number, or a SymPy expression, which may
        also hold unknown functions x(t) and their derivatives (linearly, with constant
        coefficients). A Matrix is transformed entry by entry.
    t : sympy.Symbol, optional
        The time variable of ``f`` (default :data:`laplace_springs.t`; any Symbol named
        ``t`` is taken as time too).
    s : sympy.Symbol, optional
        The transform variable (default :data:`laplace_springs.s`).
    parameters : sequence or mapping, optional
        Names text ``f`` may use as symbols (positive by default).
    conditions : bool, optional
        Also return the conditions under which F holds (see the module docstring).

    Returns
    -------
    sympy.Expr or sympy.Matrix, or (F, conditions) with ``conditions=True``
        Σ_τ R_τ(s) e^{-τ s}, each R_τ rational with a factored denominator. A periodic
        input of period T adds Σ_τ R_τ(s) e^{-τ s}/(1 - e^{-Ts}) (its one period over the
        periodic factor), with the common factors of numerator and 1 - e^{-Ts}
        cancelled when the delays are multiples of T/q, q ≤ 64 (the ±1 square wave of
        period 2 gives (1 - e^{-s})/(s(1 + e^{-s})) = tanh(s/2)/s). An unknown x(t)
        gives ``LaplaceTransform(x(t), t, s)`` and its derivatives the initial values.

    Raises
    ------
    SceneError
        For text that does not parse or names an undeclared parameter, and for an f
        outside the class (``1/(t + 1)``, ``cos(t**2)``, ``exp(-a/t)``, ``t*x(t)``,
        ``sin(x(t))``, a third-order ``Derivative`` is fine but ``x(t - 1)`` is not); the
        message names the part and why.

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

    Plain symbols are complex numbers; symbolic switching times carry their condition:

    >>> q, a = sp.symbols("q a")
    >>> laplace(sp.exp(-q * t))
    1/(q + s)
    >>> F, where = laplace(sp.sin(t - a) * sp.Heaviside(t - a), conditions=True)
    >>> F, [c.meaning for c in where]
    (exp(-a*s)/(s**2 + 1), ['a >= 0 (the switching time of Heaviside(-a + t))'])

    Unknown functions follow the derivative rule, in SymPy's notation:

    >>> x = sp.Function("x")
    >>> laplace(sp.Derivative(x(t), (t, 2)) + 3 * x(t) - sp.cos(t))
    s**2*LaplaceTransform(x(t), t, s) - s*x(0) - s/(s**2 + 1) + 3*LaplaceTransform(x(t), t, s) - Subs(Derivative(x(t), t), t, 0)
    """
    s = S if s is None else s
    if isinstance(f, sp.MatrixBase):
        return entrywise(f, lambda entry: laplace(entry, t, s, parameters=parameters, conditions=True),
                          conditions)
    declared = declare_parameters(parameters)
    found: list[SwitchCondition] = []
    unknown_part: sp.Expr = sp.S.Zero
    constants: dict[sp.Expr, sp.Expr] = {}
    if isinstance(f, sp.Basic) and _unknowns_in(f):
        time = _time_of(f, t)
        f, unknown_part = _split_unknowns(f, time, s)
        constants = {c: sp.Dummy(f"c{i}") for i, c in enumerate(
            sorted(f.atoms(AppliedUndef, sp.Subs), key=sp.default_sort_key)) if time not in c.free_symbols}
        f = f.xreplace(constants)  # initial values x(0), x'(0): constants of the rest
    if t is not None and t != TIME and isinstance(f, sp.Basic):
        f = f.xreplace({t: TIME})
    expr = parse_forcing(f, "f", declared)
    transform = input_transform(expr, "f", s)
    found += transform.conditions
    total = sp.Add(*(_tidy(R, s) * sp.exp(-s * tau) for tau, R in transform.parts))
    if transform.period is not None:
        total += _over_period(transform.periodic, transform.period, s)
    if constants:
        total = total.xreplace({dummy: c for c, dummy in constants.items()})
    total += unknown_part
    return (total, tuple(found)) if conditions else total


def _tidy(R: sp.Expr, s: sp.Symbol) -> sp.Expr:
    """R factored, each factor of the denominator with a positive leading coefficient
    in s (1/(s - q), not -1/(q - s))."""
    R = sp.factor(R)
    numerator, denominator = sp.fraction(R)
    sign, factors = 1, []
    for factor in sp.Mul.make_args(denominator):
        base, exponent = factor.as_base_exp()
        if base.has(s) and base.is_polynomial(s) and sp.Poly(base, s).LC().could_extract_minus_sign():
            base = sp.expand(-base)
            sign *= (-1) ** exponent
        factors.append(base**exponent)
    return sign * numerator / sp.Mul(*factors) if sign != 1 or factors != list(sp.Mul.make_args(denominator)) else R


def entrywise(matrix: sp.MatrixBase, transform: Any, conditions: bool) -> Any:
    """``transform`` (returning (value, conditions)) applied to each entry of ``matrix``."""
    found: dict[tuple, Any] = {}
    values = []
    for entry in matrix:
        value, where = transform(entry)
        values.append(value)
        for condition in where:
            found.setdefault((type(condition).__name__, str(condition.meaning)), condition)
    result = sp.ImmutableMatrix(matrix.rows, matrix.cols, values)
    return (result, tuple(found.values())) if conditions else result


def _unknowns_in(f: sp.Basic) -> bool:
    return bool(f.atoms(AppliedUndef, sp.Derivative))


def _time_of(f: sp.Basic, t: sp.Symbol | None) -> sp.Symbol:
    """The time symbol of an expression with unknown functions: ``t`` if given, else
    the Symbol named t in it, else :data:`~laplace_springs.model.symbols.TIME`."""
    if t is not None:
        return t
    named = sorted((x for x in f.free_symbols if isinstance(x, sp.Symbol) and x.name == "t"),
                   key=sp.default_sort_key)
    return named[0] if named else TIME


def _split_unknowns(f: sp.Basic, t: sp.Symbol, s: sp.Symbol) -> tuple[sp.Expr, sp.Expr]:
    """(the rest of f, the transform of its terms in unknown functions of t)."""
    if not isinstance(f, sp.Expr):
        raise SceneError(f"f: expected an expression in t, got {shown(f)}")
    f = f.replace(lambda e: isinstance(e, sp.Derivative) and not isinstance(e.expr, AppliedUndef),
                  lambda e: e.doit())
    rest, transformed = [], []
    for term in sp.Add.make_args(sp.expand(f)):
        if not any(u.has(t) for u in term.atoms(AppliedUndef, sp.Derivative)):
            rest.append(term)
            continue
        sifted = _sifted(term, t)
        if sifted is not None:  # f(t) δ(t - τ) = f(τ) δ(t - τ): a constant times an impulse
            rest.append(sifted)
            continue
        coefficient, core = term.as_independent(t, as_Add=False)
        transformed.append(coefficient * derivative_transform(core, t, s, whole=term))
    return sp.Add(*rest), sp.Add(*transformed)


def _sifted(term: sp.Expr, t: sp.Symbol) -> sp.Expr | None:
    """``term`` with its other factors evaluated at the time of its one impulse
    δ(c t + d) (the sifting property: f(t) δ(t - 42) = f(42) δ(t - 42)), or None when
    ``term`` has no such impulse."""
    impulses = [f for f in sp.Mul.make_args(term) if isinstance(f, sp.DiracDelta) and f.has(t)]
    if len(impulses) != 1 or (len(impulses[0].args) > 1 and impulses[0].args[1] != 0):
        return None
    found = switching_time(impulses[0].args[0], t)
    if found is None:
        return None
    others = term / impulses[0]
    return others.subs(t, found[2]) * impulses[0]


def derivative_transform(core: sp.Expr, t: sp.Symbol, s: sp.Symbol, *,
                         whole: sp.Expr | None = None) -> sp.Expr:
    """L[x^{(n)}(t)] = s^n X(s) - Σ_{j<n} s^{n-1-j} x^{(j)}(0), in SymPy's notation.

    Parameters
    ----------
    core : sympy.Expr
        ``x(t)`` or ``Derivative(x(t), (t, n))`` for an unknown function x.
    t, s : sympy.Symbol
        Time and transform variable.
    whole : sympy.Expr, optional
        The term ``core`` came from, for the message.

    Raises
    ------
    SceneError
        For anything else: an unknown function of another argument (``x(t - 1)``), a
        product with a function of t (``t*x(t)``), a nonlinear term (``x(t)**2``,
        ``sin(x(t))``), a derivative in another variable.

    Examples
    --------
    >>> t, s = sp.symbols("t s")
    >>> x = sp.Function("x")
    >>> derivative_transform(sp.Derivative(x(t), t), t, s)
    s*LaplaceTransform(x(t), t, s) - x(0)
    >>> derivative_transform(t * x(t), t, s)
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: f: t*x(t) is not supported: an unknown function times a function of t; only constant multiples of x(t) and its derivatives are transformed
    """
    whole = core if whole is None else whole
    order, function = 0, core
    if isinstance(core, sp.Derivative):
        function = core.expr
        if {v for v, _ in core.variable_count} != {t}:
            raise SceneError(f"f: {whole} is not supported: {core} is a derivative in "
                             f"{', '.join(str(v) for v, _ in core.variable_count)}, not in {t}")
        order = int(core.derivative_count)
    if isinstance(function, AppliedUndef):
        if function.args != (t,):
            raise SceneError(f"f: {whole} is not supported: {function} is an unknown function of "
                             f"{', '.join(map(str, function.args))}; only unknown functions of {t} itself "
                             f"(such as {function.func}({t})) and their derivatives are transformed")
        X = sp.LaplaceTransform(function, t, s)
        initial = [function.func(0) if j == 0 else sp.Subs(sp.Derivative(function, (t, j)), t, 0)
                   for j in range(order)]
        return s**order * X - sp.Add(*(s ** (order - 1 - j) * value for j, value in enumerate(initial)))
    raise SceneError(f"f: {whole} is not supported: {_why(core, t)}; only constant multiples of "
                     f"x(t) and its derivatives are transformed")


def _why(core: sp.Expr, t: sp.Symbol) -> str:
    unknown = sorted(core.atoms(AppliedUndef), key=sp.default_sort_key)
    if core.has(sp.Integral):
        return "integrals of unknown functions are not transformed"
    if isinstance(core, sp.Mul) and sum(1 for factor in core.args if factor.has(*unknown)) == 1:
        return "an unknown function times a function of t"
    if isinstance(core, (sp.Pow, sp.Mul)):
        return f"it is nonlinear in {', '.join(map(str, unknown))}"
    return f"it is a function of the unknown {', '.join(map(str, unknown))}, not linear in it"


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

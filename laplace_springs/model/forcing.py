"""Forcing inputs f(t): parsing, small constructors, and exact Laplace transforms.

A forcing term is any finite sum of products of

    constants, t^k, e^{a t}, cos(b t + φ), sin(b t + φ), cosh, sinh,
    Heaviside(c t + d) (steps, windows), DiracDelta(c t + d) (impulses),

with a, b, c, d, φ exact real numbers or symbols. Its transform is
F(s) = Σ_τ e^{-sτ} R_τ(s) with rational R_τ: one rational part per delay τ ≥ 0. The
solution stage turns each part into a response switched on at τ.

Sizes. An input is held to :attr:`~laplace_springs.limits.Limits.max_forcing_terms` atoms
and :attr:`~laplace_springs.limits.Limits.max_forcing_degree` in t, estimated from the
expression before it is expanded (:mod:`laplace_springs.model.forcing_size`), and to
:attr:`~laplace_springs.limits.Limits.max_forcing_delays` switching times and
:attr:`~laplace_springs.limits.Limits.max_forcing_constants` irrational or symbolic
constants, counted on its atoms before their fractions are summed.

Inside the module every product is reduced to atoms c · t^k · e^{z t} switched on at τ
(z complex: a ± i b), whose transform is c · k!/(s - z)^{k+1} times e^{-sτ}; the atoms
of each delay are summed and brought back to a real rational function.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from math import comb, factorial
from typing import Any

import sympy as sp
from sympy.core.function import AppliedUndef

from ..limits import limits
from .errors import LimitError, SceneError
from .forcing_size import check_forcing_size
from .numbers import ALLOWED_FUNCTIONS, MAX_MAGNITUDE, _order, check_depth, parse_expression, to_exact
from .periodic import PERIODIC_FUNCTIONS, Periodic, common_period
from .sampled import Sampled
from .switching import SwitchCondition, UndecidableOrder, latest_delay, sorted_delays, switch_conditions
from .symbols import TIME, lam

__all__ = [
    "InputTransform",
    "parse_forcing",
    "input_transform",
    "cosine",
    "sine",
    "step",
    "impulse",
    "ramp",
]

t = TIME
_WAVES = (sp.exp, sp.cos, sp.sin, sp.cosh, sp.sinh)


# ----------------------------------------------------------------------------
# Parsing and constructors
# ----------------------------------------------------------------------------

def parse_forcing(value: Any, entry: str, parameters: Mapping[str, sp.Symbol] | None = None) -> sp.Expr:
    """One forcing entry as an exact SymPy expression in :data:`laplace_springs.t`.

    Parameters
    ----------
    value : str, number or sympy.Expr
        Text such as ``"10*cos(20*t)"`` (parsed safely, never evaluated), a number
        (a constant force), or a SymPy expression; a symbol named ``t`` in it is time.
    entry : str
        What the value is, for error messages, e.g. ``"forcing[0]"``.
    parameters : mapping of str to sympy.Symbol, optional
        The declared parameters text may name besides ``t``.

    Returns
    -------
    sympy.Expr
        Exact: floats become their decimal value (0.2 is 1/5).

    Raises
    ------
    SceneError
        For text that does not parse, or an input whose transform is not rational times
        delays (e.g. ``1/(t + 1)``, ``cos(t**2)``); the message names ``entry``.
    LimitError
        For an input beyond the limits of :mod:`laplace_springs.model.forcing_size`
        (``t**1000``, ``(cos(t) + sin(2*t))**30``, 10⁴ steps), checked on the expression
        before any work is done on it, and one whose terms switch at more than
        :attr:`~laplace_springs.limits.Limits.max_forcing_delays` times or hold more than
        :attr:`~laplace_springs.limits.Limits.max_forcing_constants` irrational or
        symbolic constants.

    Examples
    --------
    >>> parse_forcing("3*sin(2*t + 1/2)", "forcing[0]")
    3*sin(2*t + 1/2)
    >>> parse_forcing(0.5, "forcing[1]")
    1/2
    >>> parse_forcing("1/(t + 1)", "forcing[0]")
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: forcing[0]: 1/(t + 1) is not supported: 1/(t + 1) is not a power t**k, exp, cos, sin, cosh, sinh, Heaviside or DiracDelta of a linear argument
    """
    if isinstance(value, str):
        expr = parse_expression(value.strip(), entry, variables=parameters,
                                expected="an expression in t",
                                allowed_functions={**ALLOWED_FUNCTIONS, **PERIODIC_FUNCTIONS})
        check_forcing_size(expr, entry)
    elif isinstance(value, sp.Basic):
        check_depth(value, entry)  # SymPy input has no text limits: its nesting and size
        check_forcing_size(value, entry)  # are checked before any work on it
        time_like = [s for s in value.free_symbols if isinstance(s, sp.Symbol) and s.name == "t"]
        _refuse_unknown_functions(value, entry)
        expr = to_exact(value.xreplace(dict.fromkeys(time_like, t)), entry)
    else:
        expr = to_exact(value, entry)
    input_transform(expr, entry)  # refuse unsupported inputs now, with their entry
    return expr


def cosine(amplitude: Any = 1, frequency: Any = 1, phase: Any = 0) -> sp.Expr:
    """``amplitude * cos(frequency * t + phase)``, exactly.

    Examples
    --------
    >>> cosine(10, 20)
    10*cos(20*t)
    >>> cosine("1/2", 3, "pi/4")
    cos(3*t + pi/4)/2
    """
    return (to_exact(amplitude, "amplitude")
            * sp.cos(to_exact(frequency, "frequency") * t + to_exact(phase, "phase")))


def sine(amplitude: Any = 1, frequency: Any = 1, phase: Any = 0) -> sp.Expr:
    """``amplitude * sin(frequency * t + phase)``, exactly.

    Examples
    --------
    >>> sine(2, 0.5)
    2*sin(t/2)
    """
    return (to_exact(amplitude, "amplitude")
            * sp.sin(to_exact(frequency, "frequency") * t + to_exact(phase, "phase")))


def step(amplitude: Any = 1, at: Any = 0) -> sp.Expr:
    """A step of height ``amplitude`` switched on at time ``at`` (a constant if at = 0).

    Examples
    --------
    >>> step(3)
    3
    >>> step(2, at=1.5)
    2*Heaviside(t - 3/2)
    """
    at = _nonnegative(at, "at")
    height = to_exact(amplitude, "amplitude")
    return height if at == 0 else height * sp.Heaviside(t - at)


def impulse(amplitude: Any = 1, at: Any = 0) -> sp.Expr:
    """An impulse ``amplitude * DiracDelta(t - at)``: a blow that changes momentum.

    Examples
    --------
    >>> impulse(2, at=1)
    2*DiracDelta(t - 1)
    """
    return to_exact(amplitude, "amplitude") * sp.DiracDelta(t - _nonnegative(at, "at"))


def ramp(slope: Any = 1, at: Any = 0) -> sp.Expr:
    """A ramp ``slope * (t - at)`` starting at time ``at``.

    Examples
    --------
    >>> ramp(2)
    2*t
    >>> ramp(1, at=2)
    (t - 2)*Heaviside(t - 2)
    """
    at = _nonnegative(at, "at")
    rise = to_exact(slope, "slope") * (t - at)
    return rise if at == 0 else rise * sp.Heaviside(t - at)


def _nonnegative(value: Any, entry: str) -> sp.Expr:
    """A switching time: a number ≥ 0, or a parameter expression not known to be negative
    (taken as a delay, as ``Heaviside(t - tau)`` in text is: see
    :mod:`laplace_springs.model.switching`)."""
    value = to_exact(value, entry)
    if value.has(t) or value.is_negative or (value.is_number and not value.is_nonnegative):
        raise SceneError(f"{entry} must be a number >= 0 or a parameter, got {value}")
    return value


# ----------------------------------------------------------------------------
# Laplace transform
# ----------------------------------------------------------------------------

@dataclass(frozen=True)
class InputTransform:
    """F(s) = Σ_τ e^{-sτ} R_τ(s) of one forcing input.

    Attributes
    ----------
    parts : tuple of (sympy.Expr, sympy.Expr)
        ``(τ, R_τ(s))`` pairs, τ ≥ 0 increasing, R_τ a rational function of ``s``.
    variable : sympy.Symbol
        The transform variable s.
    period : sympy.Expr or None
        T of the periodic inputs (:class:`~laplace_springs.model.periodic.Periodic`), if any.
    periodic : tuple of (sympy.Expr, sympy.Expr)
        ``(τ, R_τ(s))`` with 0 ≤ τ < T: the periodic inputs' transform is
        Σ_τ e^{-sτ} R_τ(s) / (1 - e^{-sT}) (one period over the periodic factor).
    conditions : tuple of SwitchCondition
        Where the parts hold: symbolic switching times of unknown sign are taken as
        delays (``a >= 0``), see :mod:`laplace_springs.model.switching`.

    Examples
    --------
    >>> s = sp.Symbol("s")
    >>> input_transform(parse_forcing("Heaviside(t - 1) + t", "f"), "f", s).as_expr()
    exp(-s)/s + s**(-2)
    """

    parts: tuple[tuple[sp.Expr, sp.Expr], ...]
    variable: sp.Symbol
    period: sp.Expr | None = None
    periodic: tuple[tuple[sp.Expr, sp.Expr], ...] = ()
    conditions: tuple[SwitchCondition, ...] = ()

    def as_expr(self) -> sp.Expr:
        """The transform as one expression with explicit ``exp(-s τ)`` factors."""
        s = self.variable
        total = sp.Add(*(R * sp.exp(-s * tau) for tau, R in self.parts))
        if self.period is None:
            return total
        return total + sp.Add(*(R * sp.exp(-s * tau) for tau, R in self.periodic)) / (
            1 - sp.exp(-s * self.period))


@dataclass(frozen=True)
class _Atom:
    coefficient: sp.Expr
    power: int
    rate: sp.Expr  # complex exponent z
    delay: sp.Expr


class _Unsupported(Exception):
    def __init__(self, factor: sp.Expr, why: str = ""):
        super().__init__(factor)
        self.factor, self.why = factor, why


_KINDS = "a power t**k, exp, cos, sin, cosh, sinh, Heaviside or DiracDelta of a linear argument"


def input_transform(f: sp.Expr, entry: str, s: sp.Symbol | None = None) -> InputTransform:
    """Exact Laplace transform of a forcing input, one rational part per delay.

    Parameters
    ----------
    f : sympy.Expr
        The input, in :data:`laplace_springs.t` (see :func:`parse_forcing`).
    entry : str
        What the input is, for error messages.
    s : sympy.Symbol, optional
        The transform variable (default ``lambda``, the resolvent's variable).

    Returns
    -------
    InputTransform

    Raises
    ------
    SceneError
        When f is not a sum of the supported products.

    Notes
    -----
    Results are cached (with the limits in force): scene construction,
    :func:`laplace_springs.solve` and ``verify`` all ask for the same transforms.

    Examples
    --------
    >>> s = sp.Symbol("s")
    >>> input_transform(parse_forcing("10*cos(20*t)", "f"), "f", s).parts
    ((0, 10*s/(s**2 + 400)),)
    >>> input_transform(parse_forcing("exp(-t)*t**2", "f"), "f", s).parts
    ((0, 2/(s**3 + 3*s**2 + 3*s + 1)),)
    >>> input_transform(parse_forcing("DiracDelta(t - 2)", "f"), "f", s).parts
    ((2, 1),)
    """
    return _transform(f, entry, lam if s is None else s, limits())


@lru_cache(maxsize=512)
def _transform(f: sp.Expr, entry: str, s: sp.Symbol, _limits: Any) -> InputTransform:
    """:func:`input_transform` under the limits ``_limits`` (part of the cache key)."""
    check_forcing_size(f, entry)
    try:
        terms = sp.Add.make_args(_expanded(f))
        atoms = [atom for term in terms if not term.has(Periodic) for atom in _term_atoms(term)]
        period, periodic = _periodic_parts([term for term in terms if term.has(Periodic)], entry, s)
    except _Unsupported as exc:
        why = exc.why or f"{exc.factor} is not {_KINDS}"
        raise SceneError(f"{entry}: {f} is not supported: {why}") from None
    by_delay: dict[sp.Expr, list[_Atom]] = {}
    for atom in atoms:
        by_delay.setdefault(atom.delay, []).append(atom)
    _check_parts(by_delay, periodic, entry)
    parts = []
    for tau in sorted_delays(by_delay):
        R = _real_rational(by_delay[tau], s)
        if R != 0:
            parts.append((tau, R))
    return InputTransform(tuple(parts), s, period, periodic, switch_conditions(f))


def _check_parts(by_delay: Mapping[sp.Expr, list[_Atom]],
                 periodic: tuple[tuple[sp.Expr, sp.Expr], ...], entry: str) -> None:
    """Switching times within MAX_MAGNITUDE, Limits.max_forcing_delays and
    Limits.max_forcing_constants, on the atoms of an input before their fractions are
    summed (each delay is one more exact solve of the scene, and each constant one more
    variable of every polynomial the solve forms)."""
    for tau in by_delay:
        if tau.is_number and abs(tau) > MAX_MAGNITUDE:
            raise SceneError(
                f"{entry}: the input switches at t = {_order(tau)}, beyond the limit 1e300 "
                "(MAX_MAGNITUDE) of times that float64 evaluation can hold; leave that switch "
                "out of the input (it would not act before t = 1e300)")
    delays = len(by_delay) + len(periodic)
    if delays > limits().max_forcing_delays:
        raise LimitError(
            f"{entry}: the input switches at {delays} different times, above the limit "
            f"{limits().max_forcing_delays} (Limits.max_forcing_delays); give it as samples "
            "(ls.sampled) or as a periodic input (ls.periodic)")
    constants: set[sp.Basic] = set()
    for atoms in by_delay.values():
        for atom in atoms:
            for part in (atom.coefficient, atom.rate, atom.delay):
                if not part.is_Rational:
                    constants |= _constants(part)
    if len(constants) > limits().max_forcing_constants:
        listed = ", ".join(sorted(map(_shown_constant, constants))[:6])
        raise LimitError(
            f"{entry}: the input's terms hold {len(constants)} different irrational or symbolic "
            f"constants ({listed}, ...), above the limit {limits().max_forcing_constants} "
            "(Limits.max_forcing_constants); give phases and switching times as rationals, or "
            "the force as samples (ls.sampled)")


def _constants(expr: sp.Expr) -> set[sp.Basic]:
    """The generators of ``expr`` over ℚ: symbols, function values such as cos(1/2), roots
    such as √2 and constants such as π; a phase e^{±ib} (cos b and sin b) counts once."""
    found: set[sp.Basic] = set(expr.free_symbols)
    for function in expr.atoms(sp.Function):
        if function.has(t):
            continue
        if isinstance(function, sp.exp):
            a, b = _split_imaginary(function.args[0])
            function = sp.exp(a + sp.I * min(b, sp.expand(-b), key=sp.default_sort_key))  # noqa: PLW2901
        found.add(function)
    found |= {p for p in expr.atoms(sp.Pow) if p.is_number and not p.exp.is_Integer}
    found |= expr.atoms(sp.NumberSymbol)
    return found - {sp.S.One}


def _shown_constant(constant: sp.Basic) -> str:
    """A constant as the input shows it: e^{ib} as cos(b)."""
    if isinstance(constant, sp.exp):
        a, b = _split_imaginary(constant.args[0])
        if a == 0 and b != 0:
            return str(sp.cos(b, evaluate=False)) if b.is_positive else str(sp.cos(-b, evaluate=False))
    return str(constant)


def _expanded(f: sp.Expr) -> sp.Expr:
    """f as a sum of products, its symbolic constant denominators kept whole: ``expand``
    would multiply 1/(a + 1) into e^{-t} and give 1/(a e^t + e^t), not a product."""
    kept = {power: sp.Dummy() for power in f.atoms(sp.Pow)
            if power.exp.is_negative and not power.has(t) and not power.is_number}
    return sp.expand(f.xreplace(kept)).xreplace({dummy: power for power, dummy in kept.items()})


def _periodic_parts(terms: list[sp.Expr], entry: str, s: sp.Symbol
                    ) -> tuple[sp.Expr | None, tuple[tuple[sp.Expr, sp.Expr], ...]]:
    """(P, parts) with Σ terms = Σ_τ e^{-sτ} R_τ(s)/(1 - e^{-sP}), 0 ≤ τ < P.

    Each term is c·periodic(g, T) (c free of t); periods T | P are brought to the common
    period P: 1/(1 - e^{-sT}) = Σ_{k < P/T} e^{-skT}/(1 - e^{-sP}).
    """
    if not terms:
        return None, ()
    found = []
    for term in terms:
        waves = [f for f in sp.Mul.make_args(term) if f.has(t)]
        if len(waves) != 1 or not isinstance(waves[0], Periodic):
            raise _Unsupported(term, f"{term} is not a constant times one periodic input")
        found.append((term / waves[0], waves[0]))
    P = common_period([wave.period for _, wave in found])
    sums: dict[sp.Expr, sp.Expr] = {}
    for c, wave in found:
        for tau, R in input_transform(c * wave.window, entry, s).parts:
            for k in range(int(P / wave.period)):
                sums[tau + k * wave.period] = sums.get(tau + k * wave.period, sp.S.Zero) + R
    parts = tuple((tau, sp.factor_terms(sp.cancel(sums[tau]))) for tau in sorted_delays(sums)
                  if sums[tau] != 0)
    return P, parts


def _linear(arg: sp.Expr, factor: sp.Expr) -> tuple[sp.Expr, sp.Expr]:
    """(c, d) with arg = c t + d, or _Unsupported."""
    linear = arg.has(t) and sp.expand(arg).is_polynomial(t) is True
    poly = sp.Poly(sp.expand(arg), t) if linear else None
    if poly is None or poly.degree() > 1 or any(c.has(t) for c in poly.all_coeffs()):
        raise _Unsupported(factor, f"the argument of {factor} is not linear in t")
    c, d = (poly.all_coeffs() + [0])[:2] if poly.degree() == 1 else (0, poly.all_coeffs()[0])
    return sp.sympify(c, strict=True), sp.sympify(d, strict=True)


def _switch_time(c: sp.Expr, d: sp.Expr, factor: sp.Expr) -> sp.Expr:
    """τ = -d/c, exact; a symbolic τ of unknown sign is a delay where τ ≥ 0 (the
    input's conditions, :func:`~laplace_springs.model.switching.switch_conditions`)."""
    tau = sp.expand(-d / c)
    if tau.is_extended_real is False:
        raise _Unsupported(factor, f"the switching time {tau} of {factor} is not real")
    return sp.nsimplify(tau) if tau.is_Float else tau


def _term_atoms(term: sp.Expr) -> list[_Atom]:
    """Atoms of one product term."""
    coefficient: sp.Expr = sp.S.One
    power = 0
    waves: list[list[tuple[sp.Expr, sp.Expr]]] = []  # each factor: alternatives (weight, z)
    switches: list[list[tuple[int, sp.Expr]]] = []   # each factor: alternatives (sign, delay)
    deltas: list[tuple[sp.Expr, sp.Expr]] = []       # (weight, time)
    for factor in sp.Mul.make_args(term):
        base, exponent = factor.as_base_exp()
        if not factor.has(t):
            coefficient *= factor
        elif base == t and exponent.is_Integer and exponent >= 0:
            power += int(exponent)
        elif exponent.is_Integer and exponent > 0 and isinstance(base, _WAVES):
            waves.extend([_wave(base)] * int(exponent))
        elif isinstance(factor, _WAVES):
            waves.append(_wave(factor))
        elif isinstance(factor, sp.Heaviside):
            switches.append(_switch(factor))
        elif isinstance(factor, sp.DiracDelta):
            deltas.append(_delta(factor))
        else:
            raise _Unsupported(factor)
    if len(deltas) > 1:
        raise _Unsupported(term, f"{term} multiplies impulses")
    if deltas:
        return _impulse_atoms(term, coefficient, deltas[0])
    atoms = []
    products = _wave_products(waves)
    for switch in itertools.product(*switches):
        sign = sp.Mul(*(sgn for sgn, _ in switch))
        try:
            delay = latest_delay([d for _, d in switch])
        except UndecidableOrder as exc:
            raise _Unsupported(term, f"{term} multiplies steps at {exc.first} and {exc.second}: "
                               "their order is unknown (declare the parameters' signs)") from None
        for rate, weight in products.items():
            atoms.extend(_shifted(coefficient * sign * weight, power, rate, delay))
    return atoms


def _wave_products(waves: list[list[tuple[sp.Expr, sp.Expr]]]) -> dict[sp.Expr, sp.Expr]:
    """Π_f Σ w·e^{z t} over the wave factors, as rate -> weight, equal rates merged as the
    product is formed: cos(t)**30 is 31 rates, not 2**30 products."""
    products: dict[sp.Expr, sp.Expr] = {sp.S.Zero: sp.S.One}
    for alternatives in waves:
        merged: dict[sp.Expr, sp.Expr] = {}
        for rate, weight in products.items():
            for w, z in alternatives:
                key = sp.expand(rate + z)
                merged[key] = merged.get(key, sp.S.Zero) + weight * w
        products = merged
    return products


def _wave(factor: sp.Expr) -> list[tuple[sp.Expr, sp.Expr]]:
    """A factor e^{z}, cos, sin, cosh, sinh of a linear argument as Σ weight·e^{z t}."""
    c, d = _linear(factor.args[0], factor)
    if isinstance(factor, sp.exp):
        return [(sp.exp(d), c)]
    if isinstance(factor, sp.cosh):
        return [(sp.exp(d) / 2, c), (sp.exp(-d) / 2, -c)]
    if isinstance(factor, sp.sinh):
        return [(sp.exp(d) / 2, c), (-sp.exp(-d) / 2, -c)]
    i = sp.I
    if isinstance(factor, sp.cos):
        return [(sp.exp(i * d) / 2, i * c), (sp.exp(-i * d) / 2, -i * c)]
    return [(sp.exp(i * d) / (2 * i), i * c), (-sp.exp(-i * d) / (2 * i), -i * c)]


def _real_form(expr: sp.Expr) -> sp.Expr:
    """``expr`` expanded, each e^{a + ib} written e^a (cos b + i sin b) (an identity for
    complex a, b: no re/im of symbols), and expanded again, so that I cancels."""
    expr = sp.expand(expr)
    waves = {e: sp.exp(a) * (sp.cos(b) + sp.I * sp.sin(b))
             for e in expr.atoms(sp.exp) for a, b in [_split_imaginary(e.args[0])] if b != 0}
    return sp.expand(expr.xreplace(waves)) if waves else expr


def _split_imaginary(z: sp.Expr) -> tuple[sp.Expr, sp.Expr]:
    """(a, b) with z = a + i b as polynomials in I: a and b free of I, not re/im
    (a plain Symbol q is complex, and q = q + i·0 here)."""
    z = sp.expand(z)
    b = z.coeff(sp.I)
    return sp.expand(z - sp.I * b), b


def _switch(factor: sp.Heaviside) -> list[tuple[int, sp.Expr]]:
    """Heaviside(c t + d) for t > 0 as alternatives (sign, delay): Σ sign·H(t - delay)."""
    c, d = _linear(factor.args[0], factor)
    if c == 0:
        raise _Unsupported(factor)
    if c.is_positive is None and c.is_negative is None:
        raise _Unsupported(factor, f"the sign of {c}, the coefficient of t in {factor}, is unknown "
                           "(declare its parameters positive or negative)")
    tau = _switch_time(c, d, factor)
    if c.is_positive:
        return [(1, sp.S.Zero if tau.is_nonpositive else tau)]
    if tau.is_nonpositive:
        return []
    return [(1, sp.S.Zero), (-1, tau)]


def _delta(factor: sp.DiracDelta) -> tuple[sp.Expr, sp.Expr]:
    """DiracDelta(c t + d) = δ(t - τ)/|c|, as (weight, τ)."""
    if len(factor.args) > 1 and factor.args[1] != 0:
        raise _Unsupported(factor, f"derivatives of impulses ({factor}) are not supported")
    c, d = _linear(factor.args[0], factor)
    if c == 0:
        raise _Unsupported(factor)
    if c.is_extended_real is False:
        raise _Unsupported(factor, f"the scale {c} of {factor} is not real")
    return 1 / sp.Abs(c), _switch_time(c, d, factor)


def _impulse_atoms(term: sp.Expr, coefficient: sp.Expr, delta: tuple[sp.Expr, sp.Expr]) -> list[_Atom]:
    """g(t)·δ(t - τ) = g(τ)·δ(t - τ): an atom of power -1 (transform e^{-sτ})."""
    weight, tau = delta
    if tau.is_negative:
        return []
    others = sp.Mul(*(f for f in sp.Mul.make_args(term)
                      if f.has(t) and not isinstance(f, sp.DiracDelta)))
    for step in (f for f in sp.Mul.make_args(term) if isinstance(f, sp.Heaviside)):
        if step.args[0].subs(t, tau) == 0:  # a step switching at the impulse: no value there
            raise _Unsupported(term, f"{term} multiplies an impulse by a step that switches "
                               "at the same time")
    value = sp.simplify(coefficient * weight * others.subs(t, tau))  # steps are 0 or 1 at τ
    return [_Atom(value, -1, sp.S.Zero, tau)] if value != 0 else []


def _shifted(weight: sp.Expr, power: int, rate: sp.Expr, delay: sp.Expr) -> list[_Atom]:
    """c t^k e^{zt} H(t - τ) = e^{zτ} Σ_j C(k, j) τ^{k-j} (t-τ)^j e^{z(t-τ)} H(t - τ)."""
    if delay == 0:
        return [_Atom(weight, power, rate, delay)]
    shift = weight * sp.exp(rate * delay)
    return [_Atom(shift * comb(power, j) * delay ** (power - j), j, rate, delay)
            for j in range(power + 1)]


def _real_rational(atoms: list[_Atom], s: sp.Symbol) -> sp.Expr:
    """Σ c k!/(s - z)^{k+1} (and c for impulses) as a real rational function of s.

    Rates and weights are polynomials in I with real-form coefficients (cos, sin of
    the phases), so z = a + ib is split algebraically (:func:`_split_imaginary`), never
    by re/im: a plain Symbol q is a complex number, and e^{qt} gives 1/(s - q) for every
    q. A rate a + ib with b ≠ 0 is paired with its algebraic conjugate a - ib (the
    input is a real-form expression, so both occur, with conjugate weights c, c̄), and
    c k!/(s - z)^{k+1} + c̄ k!/(s - z̄)^{k+1} = k![c (s - z̄)^{k+1} + c̄ (s - z)^{k+1}]
    / ((s - a)² + b²)^{k+1}, whose numerator expands free of I.

    The fractions are summed as polynomials in s (:func:`_sum_fractions`): one base
    q = s - a or (s - a)² + b² per rate, so that 100 cosines take a second, not the
    minutes of SymPy's ``together`` and ``cancel`` on the nested sum.
    """
    grouped: dict[tuple[sp.Expr, sp.Expr, int], sp.Expr] = {}
    for atom in atoms:
        key = (*_split_imaginary(atom.rate), atom.power)
        grouped[key] = grouped.get(key, sp.S.Zero) + atom.coefficient
    polynomial = sp.S.Zero
    pieces: dict[tuple[sp.Expr, sp.Expr], list[tuple[int, sp.Expr]]] = {}
    done: set[tuple[sp.Expr, sp.Expr, int]] = set()
    for (a, b, k), coefficient in grouped.items():
        if (a, b, k) in done:
            continue
        if k < 0:
            polynomial += _real_form(coefficient)
            continue
        if b == 0:
            pieces.setdefault((a, b), []).append((k, _real_form(coefficient) * factorial(k)))
            continue
        partner = (a, sp.expand(-b), k)
        done.add(partner)
        numerator = _real_form(factorial(k) * (coefficient * (s - a + sp.I * b) ** (k + 1)
                                               + grouped.get(partner, sp.S.Zero) * (s - a - sp.I * b) ** (k + 1)))
        rate = (a, partner[1]) if (a, partner[1]) in pieces else (a, b)
        pieces.setdefault(rate, []).append((k, numerator))
    fractions = [(s - a if b == 0 else sp.expand((s - a) ** 2 + b ** 2), items)
                 for (a, b), items in pieces.items()]
    return sp.factor_terms(sp.cancel(_sum_fractions(polynomial, fractions, s)))


def _sum_fractions(polynomial: sp.Expr, fractions: list[tuple[sp.Expr, list[tuple[int, sp.Expr]]]],
                   s: sp.Symbol) -> sp.Expr:
    """polynomial + Σ_q Σ_k N_k / q^{k+1} as one fraction P/Q, formed with polynomials in s.

    Each base q gets the exponent e = max k + 1 and the numerator Σ_k N_k q^{e-k-1}; the
    bases are distinct, and the products of the other bases' powers come from prefix and
    suffix products (linear in the number of bases).
    """
    exponents = [max(k for k, _ in items) + 1 for _, items in fractions]
    given = [polynomial, *(q for q, _ in fractions),
             *(numerator for _, items in fractions for _, numerator in items)]
    polys, _ = sp.parallel_poly_from_expr(given, s)
    total, bases, rest = polys[0], polys[1:1 + len(fractions)], iter(polys[1 + len(fractions):])
    powers = [q ** e for q, e in zip(bases, exponents)]
    numerators = []
    for q, e, (_, items) in zip(bases, exponents, fractions):
        numerators.append(sum((next(rest) * q ** (e - k - 1) for k, _ in items), total.zero))
    prefix = [total.one]
    for power in powers:
        prefix.append(prefix[-1] * power)
    suffix = [total.one]
    for power in reversed(powers):
        suffix.append(suffix[-1] * power)
    suffix.reverse()
    numerator = total * prefix[-1]
    for i, part in enumerate(numerators):
        numerator += part * prefix[i] * suffix[i + 1]
    return numerator.as_expr() / prefix[-1].as_expr()


def _refuse_unknown_functions(value: sp.Basic, entry: str) -> None:
    """A SceneError for unknown functions, derivatives and integrals in a forcing entry."""
    unknown = value.atoms(AppliedUndef, sp.Derivative, sp.Integral, sp.Subs)
    if unknown:
        first = sorted(unknown, key=sp.default_sort_key)[0]
        raise SceneError(f"{entry}: {value} is not supported: {first} is an unknown function or its "
                         "derivative, not a known input of t (equations of motion with unknown "
                         "functions go to Scene.from_equations; ls.laplace transforms their "
                         "derivatives)")


def forcing_vector(values: Sequence[Any] | None, n: int,
                   parameters: Mapping[str, sp.Symbol] | None = None) -> sp.ImmutableMatrix | None:
    """Forcing entries (one per coordinate) as an exact column, or None when all zero."""
    if values is None:
        return None
    if isinstance(values, (str, sp.Basic)) or not hasattr(values, "__len__"):
        raise SceneError(f"forcing must be a sequence with one entry per coordinate, got {values!r}")
    if len(values) != n:
        raise SceneError(f"forcing has {len(values)} entries, expected {n} (one per coordinate)")
    column = [parse_forcing(0 if v is None or isinstance(v, Sampled) else v, f"forcing[{i}]", parameters)
              for i, v in enumerate(values)]  # sampled histories: Scene.sampled (model/sampled.py)
    if all(entry == 0 for entry in column):
        return None
    return sp.ImmutableMatrix(column)

"""Periodic inputs: one period of a forcing function, repeated forever.

``Periodic(g, T)`` (printed ``periodic(g, T)``) is the function f(t) = g(t mod T): the
expression g (in :data:`laplace_springs.t`, of the forcing class of
:mod:`laplace_springs.model.forcing`) is read on [0, T) only and repeated with the period
T > 0, an exact real number. It is a SymPy function of t, so it lives in
``Scene.forcing`` like any other input; substituting a time gives its value, and
``Scene.subs`` reaches the parameters inside. Its Laplace transform is
R_T(s)/(1 − e^{−Ts}), R_T the transform of one period g·(1 − θ(t − T)).

The constructors :func:`periodic`, :func:`square_wave`, :func:`sawtooth` and
:func:`pulse_train` build it with exact entries; in forcing text the same names may be
called, e.g. ``"periodic(1 - Heaviside(t - 1), 2)"`` or ``"3*square_wave(1, 2)"``.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping
from typing import Any

import sympy as sp

from ..limits import limits
from .errors import SceneError
from .numbers import parse_expression, to_exact
from .symbols import TIME

__all__ = ["Periodic", "periodic", "square_wave", "sawtooth", "pulse_train", "common_period",
           "PERIODIC_FUNCTIONS"]

t = TIME



def _period(value: Any, entry: str = "period") -> sp.Expr:
    """``value`` as an exact real number > 0, or a SceneError naming it."""
    period = to_exact(value, entry)
    if not (period.is_number and period.is_extended_real and period.is_positive):
        raise SceneError(f"{entry} must be a real number > 0, got {period}")
    return period


class Periodic(sp.Function):
    """f(t) = g(t mod T): one period g, read on [0, T), repeated with period T.

    Build it with :func:`periodic` (or the helpers); ``Periodic(g, T)`` checks T.

    Examples
    --------
    >>> f = Periodic(1 - sp.Heaviside(t - 1), 2)
    >>> f
    periodic(1 - Heaviside(t - 1), 2)
    >>> f.subs(t, sp.Rational(7, 2)), f.subs(t, 1000)
    (0, 1)
    >>> f.one_period, f.period
    (1 - Heaviside(t - 1), 2)
    """

    nargs = 2
    is_real = True

    @classmethod
    def eval(cls, g: sp.Expr, period: sp.Expr) -> None:
        _period(period)
        if g.has(Periodic):
            raise SceneError(f"one period of a periodic input may not itself be periodic: {g}")

    @property
    def one_period(self) -> sp.Expr:
        """g, the expression read on [0, T)."""
        return self.args[0]

    @property
    def period(self) -> sp.Expr:
        """T > 0."""
        return self.args[1]

    @property
    def window(self) -> sp.Expr:
        """g·(1 − θ(t − T)): one period alone (zero from T on), in the forcing class."""
        return self.one_period * (1 - sp.Heaviside(t - self.period))

    def at(self, time: sp.Expr) -> sp.Expr:
        """f at ``time``: g at the reduced time ``time − T·floor(time/T)``."""
        reduced = time - self.period * sp.floor(time / self.period)
        return self.one_period.subs(t, reduced)

    def _eval_subs(self, old: sp.Basic, new: sp.Basic) -> sp.Expr | None:
        if old == t and new != t:
            return self.at(new)
        return None

    def _eval_derivative(self, symbol: sp.Symbol) -> sp.Expr:
        """d/dt on t ≥ 0 (f(0⁻) = 0): g' inside each period, plus the jumps g(0) at t = 0 and
        g(0) − g(T⁻) at t = T, 2T, ... as impulses; d/da of a parameter a is periodic(∂g/∂a, T).

        >>> Periodic(t / 2, 2).diff(t)       # a sawtooth falls by 1 at t = 2, 4, ...
        DiracDelta(t) + periodic(1/2 - DiracDelta(t), 2)
        """
        g, period = self.one_period, self.period
        if symbol != t:
            return Periodic(sp.diff(g, symbol), period) if g.has(symbol) else sp.S.Zero
        start, end = g.subs(t, 0), sp.limit(g, t, period, dir="-")
        inner = sp.diff(g, t) + (start - end) * sp.DiracDelta(t)
        return (Periodic(inner, period) if inner != 0 else sp.S.Zero) + end * sp.DiracDelta(t)

    def _eval_is_real(self) -> bool | None:
        return self.one_period.is_real

    def _sympystr(self, printer: Any) -> str:
        return f"periodic({printer._print(self.one_period)}, {printer._print(self.period)})"

    def _latex(self, printer: Any, exp: Any = None) -> str:
        body = (rf"\left. \left[ {printer._print(self.one_period)} \right] "
                rf"\right|_{{t \bmod {printer._print(self.period)}}}")
        return rf"\left( {body} \right)^{{{printer._print(exp)}}}" if exp is not None else body


def _one_period(value: Any, parameters: Mapping[str, sp.Symbol] | None) -> sp.Expr:
    if isinstance(value, str):
        return parse_expression(value.strip(), "one_period", variables=parameters,
                                expected="an expression in t")
    if isinstance(value, sp.Basic):
        time_like = [s for s in value.free_symbols if isinstance(s, sp.Symbol) and s.name == "t"]
        return to_exact(value.xreplace(dict.fromkeys(time_like, t)), "one_period")
    return to_exact(value, "one_period")


def periodic(one_period: Any, period: Any, *, parameters: Mapping[str, sp.Symbol] | None = None
             ) -> sp.Expr:
    """The periodic input equal to ``one_period`` on [0, period), repeated.

    Parameters
    ----------
    one_period : str, number or sympy.Expr
        g(t) on [0, T), of the forcing class (text is read by the safe parser, never
        evaluated). What g does from T on is ignored.
    period : number or str
        T, an exact real number > 0 (0.5 is 1/2).
    parameters : mapping of str to sympy.Symbol, optional
        Declared parameters the text may name.

    Returns
    -------
    Periodic

    Raises
    ------
    SceneError
        For text that does not parse, or a period that is not a number > 0 (the
        message names it). Whether g is in the forcing class is checked where the
        input is used (a scene, :func:`laplace_springs.laplace`).

    Examples
    --------
    >>> periodic("1 - Heaviside(t - 1)", 2)
    periodic(1 - Heaviside(t - 1), 2)
    >>> periodic("t", 0.5).subs(t, sp.Rational(7, 4))
    1/4
    >>> periodic(1, -2)
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: period must be a real number > 0, got -2
    """
    T = _period(period)
    return Periodic(_one_period(one_period, parameters), T)


def square_wave(amplitude: Any = 1, period: Any = 2, duty: Any = "1/2") -> sp.Expr:
    """``amplitude`` on the first ``duty`` fraction of each period, 0 on the rest.

    For a wave between −A and A use ``2*square_wave(A, T) - A``.

    Examples
    --------
    >>> square_wave()
    periodic(1 - Heaviside(t - 1), 2)
    >>> square_wave(3, 1, 0.25)
    periodic(3 - 3*Heaviside(t - 1/4), 1)
    """
    T = _period(period)
    fraction = to_exact(duty, "duty")
    if not (fraction.is_number and fraction.is_positive and (fraction - 1).is_negative):
        raise SceneError(f"duty must be a number with 0 < duty < 1, got {fraction}")
    A = to_exact(amplitude, "amplitude")
    return Periodic(sp.expand(A * (1 - sp.Heaviside(t - fraction * T))), T)


def sawtooth(amplitude: Any = 1, period: Any = 1) -> sp.Expr:
    """A ramp from 0 up to ``amplitude`` over each period (``amplitude * (t mod T)/T``).

    Examples
    --------
    >>> sawtooth(2, 4)
    periodic(t/2, 4)
    """
    T = _period(period)
    return Periodic(to_exact(amplitude, "amplitude") * t / T, T)


def pulse_train(amplitude: Any = 1, period: Any = 1, width: Any = "1/10") -> sp.Expr:
    """Rectangular pulses of height ``amplitude`` and duration ``width`` at t = 0, T, 2T, …

    Examples
    --------
    >>> pulse_train(5, 2, 0.1)
    periodic(5 - 5*Heaviside(t - 1/10), 2)
    >>> pulse_train(1, 1, 2)
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: width must be a number with 0 < width < period = 1, got 2
    """
    T = _period(period)
    w = to_exact(width, "width")
    if not (w.is_number and w.is_positive and (w - T).is_negative):
        raise SceneError(f"width must be a number with 0 < width < period = {T}, got {w}")
    A = to_exact(amplitude, "amplitude")
    return Periodic(sp.expand(A * (1 - sp.Heaviside(t - w))), T)


def _text_periodic(one_period: sp.Expr, period: sp.Expr) -> sp.Expr:
    return Periodic(one_period, _period(period))


#: The functions forcing text may call besides the safe parser's table.
PERIODIC_FUNCTIONS: dict[str, Callable[..., sp.Expr]] = {"periodic": _text_periodic, "square_wave": square_wave,
                      "sawtooth": sawtooth, "pulse_train": pulse_train}


def common_period(periods: list[sp.Expr]) -> sp.Expr:
    """The least common period P of exact periods (each P/T an integer ≤ Limits.max_period_ratio).

    Raises
    ------
    SceneError
        For incommensurate periods (1 and √2: the sum is not periodic) or a ratio above
        :attr:`~laplace_springs.limits.Limits.max_period_ratio`.

    Examples
    --------
    >>> common_period([sp.Integer(2), sp.Integer(3), sp.Rational(1, 2)])
    6
    """
    base = periods[0]
    ratios = []
    for T in periods:
        ratio = sp.simplify(T / base)
        if not ratio.is_Rational:
            raise SceneError(f"the periods {base} and {T} are incommensurate: their sum is not "
                             "periodic (give the inputs commensurate periods)")
        ratios.append(ratio)
    numerator = functools.reduce(sp.ilcm, [r.p for r in ratios], 1)
    denominator = functools.reduce(sp.igcd, [r.q for r in ratios], 0)
    P = base * sp.Rational(numerator, denominator)
    for T in periods:
        if limits().max_period_ratio < P / T:
            raise SceneError(f"the common period {P} of the periodic inputs is {P / T} times the "
                             f"period {T}, above Limits.max_period_ratio = {limits().max_period_ratio}")
    return P

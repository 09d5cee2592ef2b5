"""Evaluation times: validated once, held exactly, converted lazily.

A time given as a float is the number that float holds (``0.1`` is
0.1000000000000000055511151231257827…), exactly as float arithmetic would use it; a
string (``"0.1"``), a :class:`fractions.Fraction` or a SymPy rational is used exactly; an
irrational one (``"pi/8"``, ``"sqrt(2)"``, ``sympy.E``) as a rational within
10^-(Limits.max_dps + 700) of it, closer than any ``dps`` can tell.
Every route reads the same value: the float64 kernels as a double-double
(``hi + lo``), the high-precision ones as an exact rational. A value therefore never
depends on the route that evaluates it, even at phases ωt of 10³⁰.

Times must be finite and t ≥ 0: the solutions hold for t ≥ 0 (forcing and jumps are
stated from t = 0 on).
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

import mpmath
import numpy as np
import sympy as sp

from ..limits import limits
from ..model.errors import LimitError, SceneError
from ..model.numbers import shown, to_exact
from ..model.units import times_to_seconds

__all__ = ["Times", "as_times", "check_dps", "check_flat"]



@dataclass(frozen=True, eq=False)
class Times:
    """Times as float64 double-doubles ``hi + lo`` and, on demand, exact rationals.

    Attributes
    ----------
    hi, lo : numpy.ndarray
        float64; ``hi`` is the nearest float to each time, ``lo`` the remainder (zero
        for float input).
    given : tuple
        The values as given (kept to form exact rationals lazily).
    """

    hi: np.ndarray
    lo: np.ndarray
    given: tuple = field(repr=False)
    #: (min, max) of ``hi`` where the maker knows it (read by :attr:`span`)
    known_span: tuple[float, float] | None = field(default=None, repr=False)

    def __len__(self) -> int:
        return int(self.hi.size)

    @property
    def span(self) -> tuple[float, float]:
        """(first, last) of the float times ``hi`` ((0, 0) for no times), found once.

        >>> as_times([2.0, 0.0, 1.5]).span
        (0.0, 2.0)
        """
        if self.known_span is None:
            hi = self.hi
            object.__setattr__(self, "known_span", (float(hi.min()), float(hi.max()))
                               if hi.size else (0.0, 0.0))
        span: tuple[float, float] = self.known_span  # type: ignore[assignment]
        return span

    def exact(self, index: int) -> Fraction:
        """Time ``index`` as an exact rational."""
        return _exact(self.given[index]) if self.given else Fraction(float(self.hi[index]))

    def subset(self, columns: np.ndarray) -> Times:
        """The times at the given column indices."""
        columns = np.asarray(columns, dtype=int)
        given = tuple(self.given[int(c)] for c in columns) if self.given else ()
        return Times(self.hi[columns], self.lo[columns], given)

    def mpf(self, index: int) -> mpmath.mpf:
        """Time ``index`` as an mpf at the current mpmath precision."""
        value = self.exact(index)
        return mpmath.mpf(value.numerator) / value.denominator


def _exact(value: object) -> Fraction:
    if isinstance(value, Fraction):
        return value
    if isinstance(value, (float, np.floating)):
        return Fraction(float(value))
    if isinstance(value, (int, np.integer)):
        return Fraction(int(value))
    if isinstance(value, mpmath.mpf):
        sign, man, exp, _ = value._mpf_
        return Fraction(-man if sign else man) * Fraction(2) ** exp
    if isinstance(value, sp.Rational):
        return Fraction(int(value.p), int(value.q))
    if isinstance(value, sp.Basic):  # an irrational number (as_times converts them at once)
        return _irrational(value)
    raise TypeError(value)


#: Digits of an irrational time beyond Limits.max_dps: the time's rational stand-in is then
#: within 10^-(max_dps + 700) of it, so even a phase ωt with ω and t up to 1e300 (the
#: limits of an entry and of a time) is off by less than 10^-(max_dps + 100).
_IRRATIONAL_GUARD_DIGITS = 700


def _irrational(value: sp.Basic, entry: str = "a time") -> Fraction:
    """An irrational time (``pi``, ``sqrt(2)``, ``pi/8``) as a rational close enough for every
    precision ``evaluate`` takes (:data:`_IRRATIONAL_GUARD_DIGITS`); a ValueError if SymPy
    cannot evaluate it."""
    digits = limits().max_dps + _IRRATIONAL_GUARD_DIGITS
    number = sp.N(value, digits, maxn=4 * digits)
    if not number.is_Float:
        raise ValueError(f"{entry} = {shown(value)} is not a real number SymPy can evaluate")
    sign, mantissa, exponent, _ = number._mpf_
    return Fraction(-mantissa if sign else mantissa) * Fraction(2) ** exponent


def _convert(value: object, index: int) -> object:
    """One time as a float or an exact number, or a ValueError naming it."""
    if isinstance(value, (bool, np.bool_)):
        raise ValueError(f"times[{index}] must be a number, got {value!r}")
    if isinstance(value, str):
        try:
            value = to_exact(value, f"times[{index}]")
        except SceneError as exc:
            raise ValueError(str(exc)) from None
    if isinstance(value, sp.Basic):
        if not (isinstance(value, sp.Expr) and value.is_number and value.is_extended_real):
            raise ValueError(f"times[{index}] must be a real number, got {value!r}")
        if value.is_Float:
            value = sp.Rational(value)
        elif not value.is_Rational:
            value = _irrational(value, f"times[{index}]")
    elif isinstance(value, mpmath.mpf):
        if not mpmath.isfinite(value):
            raise ValueError(f"times[{index}] must be finite, got {value}")
    elif isinstance(value, numbers.Real):
        try:
            finite = math.isfinite(float(value))
        except OverflowError:  # an int or Fraction beyond float64
            raise ValueError(f"times[{index}] = {shown(value)} is beyond the float64 "
                             "range") from None
        if not finite:
            raise ValueError(f"times[{index}] must be finite, got {value!r}")
    else:
        raise ValueError(f"times[{index}] must be a number, got {value!r}")
    return value


def _float_pair(value: object) -> tuple[float, float]:
    """(hi, lo) with hi + lo the time to double-double accuracy (an int beyond 2⁵³ too);
    hi = inf beyond the float64 range."""
    if isinstance(value, (float, np.floating)):
        return float(value), 0.0
    exact = _exact(value)
    try:
        hi = float(exact)
    except OverflowError:
        return math.inf, 0.0
    return hi, float(exact - Fraction(hi)) if math.isfinite(hi) else 0.0


def as_times(times: object) -> Times:
    """Validate evaluation times (a scalar is one time).

    Times may carry units (``"0.5 s"``, ``"250 ms"``, a pint Quantity): they are converted
    to exact seconds (:func:`laplace_springs.model.units.times_to_seconds`).

    Raises
    ------
    ValueError
        For NaN, an infinity, a negative time or a non-number, naming the entry, or times
        with more than one axis (a SceneError, naming the shape).
    LimitError
        For more than :attr:`~laplace_springs.limits.Limits.max_times` times, before any
        is read.

    Examples
    --------
    >>> T = as_times([0, 0.5, "0.1"])
    >>> T.hi.tolist(), bool(T.lo[2] != 0), T.exact(2)
    ([0.0, 0.5, 0.1], True, Fraction(1, 10))
    >>> as_times([1.0, float("nan")])
    Traceback (most recent call last):
    ...
    ValueError: times[1] must be finite, got nan
    """
    if type(times) is np.ndarray and times.dtype == np.float64 and times.size \
            and times.ndim == 1:
        fast = _float_times(times)  # the common call: float64 seconds, nothing to convert
        if fast is not None:
            return fast
    check_flat(times, "times")
    _check_count(times)
    times = times_to_seconds(times)
    numeric = times if isinstance(times, np.ndarray) else _plain_numbers(times)
    if numeric is not None and numeric.dtype.kind in "fiu":
        hi = np.atleast_1d(numeric).astype(float).ravel()
        bad = np.flatnonzero(~np.isfinite(hi) | (hi < 0))
        if bad.size:
            _refuse(int(bad[0]), float(hi[bad[0]]))
        return Times(hi, np.zeros_like(hi), ())
    values = list(np.atleast_1d(np.asarray(times, dtype=object)).ravel()) \
        if not isinstance(times, (str, bytes)) else [times]
    converted = [_convert(v, i) for i, v in enumerate(values)]
    pairs = [_float_pair(v) for v in converted]
    hi = np.array([p[0] for p in pairs], dtype=float)
    lo = np.array([p[1] for p in pairs], dtype=float)
    for i, v in enumerate(converted):
        if _negative(v):
            _refuse(i, values[i])
    if not np.all(np.isfinite(hi)):
        i = int(np.flatnonzero(~np.isfinite(hi))[0])
        raise ValueError(f"times[{i}] = {shown(values[i])} is beyond the float64 range")
    return Times(hi, lo, tuple(converted))


def check_flat(value: Any, what: str, hint: str = "") -> None:
    """A SceneError (a ValueError) naming ``what`` and the shape where ``value`` has more
    than one axis: evaluations and sweeps take a number or a 1-D array and never flatten
    one silently (NumPy's rule for 1-D arguments). A ragged or unreadable value passes,
    for its reader to name the bad entry.

    >>> check_flat([[0.0, 1.0], [2.0, 3.0]], "sweep: times")
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: sweep: times must be a 1-D array (or a number), got shape (2, 2)
    """
    shape = getattr(value, "shape", None)
    if shape is None and isinstance(value, (list, tuple)):
        try:
            shape = np.asarray(value, dtype=object).shape
        except ValueError:
            return
    if isinstance(shape, tuple) and len(shape) > 1:
        raise SceneError(f"{what} must be a 1-D array (or a number), got shape "
                         f"{tuple(int(k) for k in shape)}{hint}")


def _float_times(times: np.ndarray) -> Times | None:
    """Times from a float64 array, or None when one is negative or not finite (the general
    path then names it)."""
    if times.size > limits().max_times:
        return None
    hi = times.astype(float, copy=True).ravel()
    first, last = float(np.minimum.reduce(hi)), float(np.maximum.reduce(hi))
    if not (first >= 0 and last < math.inf):
        return None
    return Times(hi, np.zeros(hi.size), (), (first, last))


def _check_count(times: object) -> None:
    """Refuse more than Limits.max_times times before any is converted or copied."""
    if isinstance(times, (str, bytes)):
        return
    size = getattr(times, "size", None)  # a NumPy array, or a pint Quantity of one
    try:
        count = int(size) if isinstance(size, (int, np.integer)) else len(times)  # type: ignore[arg-type]
    except TypeError:
        return  # a scalar, or an iterable without a length (checked as it is read)
    most = limits().max_times
    if count > most:
        raise LimitError(f"{count:,} times, more than Limits.max_times = {most:,} in one evaluation; "
                         f"evaluate them in chunks of at most {most:,} times")


def _plain_numbers(times: object) -> np.ndarray | None:
    """``times`` as a numeric array when it holds only Python or numpy ints and floats."""
    if isinstance(times, (str, bytes)):
        return None
    try:
        array = np.asarray(times)
    except (ValueError, TypeError):
        return None
    if array.dtype.kind not in "fiu":
        return None
    if array.dtype.kind in "iu" and array.size and np.max(np.abs(array)) >= 2**53:
        return None  # integers beyond 2^53: keep them exact
    return array


def _negative(value: object) -> bool:
    if isinstance(value, sp.Basic):
        return bool(value < 0)
    return bool(value < 0)  # type: ignore[operator]


def _refuse(index: int, value: object) -> None:
    if isinstance(value, float) and not math.isfinite(value):
        raise ValueError(f"times[{index}] must be finite, got {value!r}")
    raise ValueError(f"times[{index}] = {value!r} is negative; the motion is stated for t >= 0")


def check_dps(dps: object) -> int:
    """``dps`` as an int in 1..Limits.max_dps, or a ValueError naming it.

    >>> check_dps(30)
    30
    >>> check_dps(0)
    Traceback (most recent call last):
    ...
    ValueError: dps must be an integer from 1 to 10000 (decimal digits), got 0
    """
    if isinstance(dps, (bool, np.bool_)) or not isinstance(dps, (int, np.integer)) \
            or not 1 <= int(dps) <= limits().max_dps:
        raise ValueError(f"dps must be an integer from 1 to {limits().max_dps} (decimal digits), got {dps!r}")
    return int(dps)

"""Numeric evaluation of real-form terms, in float64 or at any mpmath precision.

The exact terms (α, β, a, b, possibly built on algebraic roots whose values come from
flint, see :mod:`laplace_springs.algebraic`) are converted once, at a working precision
well above float64, to a pole sum x_i(t) = Σ C_ijk t^k e^{z_j t}
(:class:`laplace_springs.pole_sum.PoleSum`).

**Float64** (:func:`evaluate_float`). Close poles are grouped into blocks evaluated in
a Newton (divided-difference) basis whose coefficients are as large as x itself, and
every phase is formed in double-double; see :mod:`laplace_springs.pole_sum`. A running
error bound is kept; columns (times) whose bound exceeds 1e-13 of max |x| over the times
asked are recomputed with mpmath at a precision chosen from the cancellation, inside
the call (scoped ``workdps``), so the result is within about 1e-15 of max |x| everywhere.

**mpmath** (:func:`evaluate_mp`). The pole sum is added term by term at a working
precision raised by the digits the sum cancels (measured, then recomputed), with the
pole data itself reconverted from the exact terms when it is not precise enough.

Precision and conditioning
--------------------------
Relative to max |x| over the requested times the float64 result is accurate to a few
units of 1e-16 on the stiff and extreme battery (:mod:`laplace_springs.battery`):
near-critical damping (|ζ − 1| = 1e-14), c = 1e6 at t = 1e6, exceptional points, rigid
modes, phases ωt up to 1e6. The error bound returned with ``return_error=True`` is an
estimate from running error analysis (eps times what was summed, weighted by block size),
not a certificate.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import mpmath
import numpy as np
import sympy as sp

from .mp_expr import mp_value
from .pole_sum import Block, PoleSum, evaluate_blocks, plan_blocks, two_diff
from .real_terms import Term

__all__ = ["NumericTerms", "evaluate_float", "evaluate_mp", "numeric_terms"]

#: Float64 columns whose estimated error exceeds this, relative to max |x|, are redone in mpmath.
FALLBACK_TOLERANCE = 1e-13
_EPS = np.finfo(float).eps


@dataclass(frozen=True, eq=False)
class NumericTerms:
    """The exact terms of each coordinate as a pole sum at ``dps`` digits.

    Attributes
    ----------
    rows : tuple of tuple of Term
        The exact terms (kept so that a higher precision can be reached later).
    poles : PoleSum
        Nodes z_j (closed under conjugation) and coefficients C_ijk at ``dps`` digits.
    dps : int
        Working precision of ``poles``.
    """

    rows: tuple
    poles: PoleSum
    dps: int
    _cache: dict = field(default_factory=dict, repr=False, compare=False)

    @property
    def blocks(self) -> list[Block]:
        """The float64 evaluation plan (built on first use)."""
        if "blocks" not in self._cache:
            self._cache["blocks"] = plan_blocks(self.poles)
        return self._cache["blocks"]

    def at_precision(self, dps: int) -> NumericTerms:
        """The same terms converted at ``dps`` digits or more (cached)."""
        if dps <= self.dps:
            return self
        key = ("dps", dps)
        if key not in self._cache:
            self._cache[key] = numeric_terms(self.rows, dps)
        return self._cache[key]


class _Builder:
    """Collects pole-sum nodes and coefficients from exact terms."""

    def __init__(self, n: int, dps: int):
        self.n, self.dps = n, dps
        self.index: dict = {}
        self.nodes: list = []
        self.coeffs: list[list[list]] = []
        self.mirror: list[int] = []
        self.values: dict = {}
        self.caches: dict = {}

    def value(self, expr: sp.Expr) -> mpmath.mpf:
        if expr not in self.values:
            self.values[expr] = mp_value(expr, self.dps, self.caches)
        return self.values[expr]

    def node(self, key, value, mirror_key, mirror_value) -> tuple[int, int]:
        if key not in self.index:
            for k, v in ((key, value), (mirror_key, mirror_value)):
                if k not in self.index:
                    self.index[k] = len(self.nodes)
                    self.nodes.append(v)
                    self.coeffs.append([])
                    self.mirror.append(-1)
            a, b = self.index[key], self.index[mirror_key]
            self.mirror[a], self.mirror[b] = b, a
        return self.index[key], self.index[mirror_key]

    def add(self, j: int, power: int, row: int, c) -> None:
        powers = self.coeffs[j]
        while len(powers) <= power:
            powers.append([mpmath.mpc(0)] * self.n)
        powers[power][row] += c

    def term(self, row: int, term: Term) -> None:
        alpha, a = self.value(term.alpha), self.value(term.a)
        k = term.power
        if term.kind == "real":
            j, _ = self.node(("r", term.alpha), mpmath.mpc(alpha), ("r", term.alpha),
                             mpmath.mpc(alpha))
            self.add(j, k, row, mpmath.mpc(a))
            return
        beta, b = self.value(term.beta), self.value(term.b)
        if term.kind == "oscillatory":  # Re[(a - ib) e^{(α+iβ)t}], halves on z and z̄
            up, down = self.node(("o+", term.alpha, term.beta), mpmath.mpc(alpha, beta),
                                 ("o-", term.alpha, term.beta), mpmath.mpc(alpha, -beta))
            self.add(up, k, row, mpmath.mpc(a, -b) / 2)
            self.add(down, k, row, mpmath.mpc(a, b) / 2)
            return
        for sign in (1, -1):  # a cosh σt + b sinh σt = Σ± (a ± b)/2 e^{±σt}
            key = ("h", sign, term.alpha, term.beta)
            j, _ = self.node(key, mpmath.mpc(alpha + sign * beta), key,
                             mpmath.mpc(alpha + sign * beta))
            self.add(j, k, row, mpmath.mpc((a + sign * b) / 2))

    def build(self) -> PoleSum:
        return PoleSum(self.n, tuple(self.nodes),
                       tuple(tuple(tuple(p) for p in c) for c in self.coeffs),
                       tuple(self.mirror), self.dps)


def numeric_terms(rows: Sequence[Sequence[Term]], dps: int = 40) -> NumericTerms:
    """Convert the exact terms of each coordinate to a pole sum at ``dps`` digits.

    Parameters
    ----------
    rows : sequence of sequence of Term
        ``rows[i]`` are the real-form terms of coordinate i.
    dps : int
        Working precision (decimal digits) of the conversion.

    Returns
    -------
    NumericTerms

    Examples
    --------
    (cos t − cos(1.00000001 t))/(1.00000001² − 1): two poles 1e-8 apart whose
    coefficients (5e7) cancel; float64 evaluation keeps full accuracy.

    >>> import sympy as sp
    >>> w = sp.Rational(100000001, 100000000)
    >>> A = 1 / (w**2 - 1)
    >>> terms = [Term("oscillatory", 0, 0, 1, A, 0), Term("oscillatory", 0, 0, w, -A, 0)]
    >>> data = numeric_terms([terms])
    >>> x = evaluate_float(data, 1, np.array([0.0, 1e-3, 1e4]))
    >>> with mpmath.workdps(40):
    ...     exact = [float((mpmath.cos(t) - mpmath.cos(t * w.p / w.q)) * A.p / A.q)
    ...              for t in map(mpmath.mpf, (0, 1e-3, 1e4))]
    >>> bool(np.max(np.abs(x[0] - exact)) < 1e-15 * np.max(np.abs(exact)))
    True
    """
    rows = tuple(tuple(r) for r in rows)
    builder = _Builder(len(rows), dps)
    with mpmath.workdps(dps):
        for i, terms in enumerate(rows):
            for term in terms:
                builder.term(i, term)
        poles = builder.build()
    return NumericTerms(rows, poles, dps)


# ----------------------------------------------------------------------------- mpmath sums


def _mp_sum(poles: PoleSum, n: int, ts: Sequence[mpmath.mpf]) -> tuple[list, list]:
    """x(t) and Σ|terms| (lists of n lists of mpf) at the current mpmath precision."""
    values = [[mpmath.mpf(0)] * len(ts) for _ in range(n)]
    sizes = [[mpmath.mpf(0)] * len(ts) for _ in range(n)]
    for j, z in enumerate(poles.nodes):
        if mpmath.im(z) < 0:
            continue
        weight = 2 if mpmath.im(z) > 0 else 1
        for col, tv in enumerate(ts):
            base = mpmath.exp(z * tv)
            power = mpmath.mpf(1)
            for ck in poles.coefficients[j]:
                wave = base * power * weight
                for i in range(min(n, poles.n)):
                    if ck[i]:
                        term = ck[i] * wave
                        values[i][col] += mpmath.re(term)
                        sizes[i][col] += abs(term)
                power *= tv
    return values, sizes


def _digits(ratio) -> int:
    """Decimal digits lost to a cancellation ratio Σ|terms| / max |x|."""
    if not ratio or not mpmath.isfinite(ratio):
        return 0 if not ratio else 30
    return max(0, math.ceil(float(mpmath.log10(ratio))))


def _mp_values(data: NumericTerms, n: int, ts: list, digits: int,
               scale=None) -> tuple[list, list, int]:
    """x at ``ts`` good to ``digits`` relative to max |x| (or ``scale``): values, sizes, dps.

    The working precision covers the digits the sum cancels (measured, then redone) and
    the digits of the largest phase |z t| (an absolute error in z·t is one in the phase).
    """
    with mpmath.workdps(15):
        reach = (max((abs(z) for z in data.poles.nodes), default=mpmath.mpf(0))
                 * max((abs(tv) for tv in ts), default=mpmath.mpf(0)))
    extra = _digits(reach)
    work = digits + extra + 10
    while True:
        source = data.at_precision(work + 10)
        with mpmath.workdps(work):
            values, sizes = _mp_sum(source.poles, n, ts)
            top = scale if scale else max((abs(v) for row in values for v in row), default=0)
            mag = max((s for row in sizes for s in row), default=mpmath.mpf(0))
        lost = _digits(mag / top) if top else 0
        if work - lost - extra >= digits + 5 or work > 4 * digits + 200:
            return values, sizes, work
        work = digits + lost + extra + 10


# ----------------------------------------------------------------------------- public


def evaluate_float(data: NumericTerms, n: int, times, *, return_error: bool = False,
                   delay=None):
    """Sum the terms in float64 at ``times``; shape (n, len(times)).

    Parameters
    ----------
    data : NumericTerms
        From :func:`numeric_terms`.
    n : int
        Number of coordinates (rows of the result).
    times : array_like
        Times (floats, read as their exact binary values); non-negative in use, any
        size (t = 0 and t = 1e6 alike).
    return_error : bool
        Also return an estimated absolute error bound of the same shape.
    delay : number, optional
        Evaluate at ``times - delay`` with the difference formed exactly (double-double),
        for a piece of a forced response that starts at t = delay: float64 ``t - τ``
        would shift a phase ωt by up to ω·ulp(t) (1e-12 at t = 1e4). Floats, ints,
        decimal strings, mpmath and exact SymPy numbers (1/3, sqrt(2)) are accepted.

    Returns
    -------
    numpy.ndarray, or (numpy.ndarray, numpy.ndarray)
        Values (and error estimates). Columns whose float64 estimate exceeds
        ``FALLBACK_TOLERANCE`` · max |x| were recomputed with mpmath.
    """
    times = np.asarray(times, dtype=float).ravel()
    tau = _delay(delay)
    if tau is None:
        shifted, shifted_lo = times, None
    else:
        with mpmath.workdps(40):
            tau_hi = float(tau)
            tau_lo = float(tau - tau_hi)
        shifted, shifted_lo = two_diff(times, tau_hi, tau_lo)
    values, bound = evaluate_blocks(data.blocks, n, shifted, shifted_lo)
    finite = np.isfinite(values)
    scale = float(np.max(np.abs(values[finite]), initial=0.0))
    flagged = np.flatnonzero(np.any(bound > FALLBACK_TOLERANCE * scale, axis=0)
                             & np.all(finite, axis=0)) if scale > 0 else np.array([], int)
    if flagged.size:
        redo, error = _fallback(data, n, times[flagged], scale, tau)
        values[:, flagged] = redo
        bound[:, flagged] = error
    return (values, bound) if return_error else values


def _delay(delay) -> mpmath.mpf | None:
    """A delay as a 40-digit mpf (None for no delay)."""
    if delay is None or (not isinstance(delay, (str, sp.Basic)) and delay == 0):
        return None
    if isinstance(delay, sp.Basic):
        return mp_value(delay, 40) if delay != 0 else None
    with mpmath.workdps(40):
        value = mpmath.mpf(delay.item() if isinstance(delay, np.generic) else delay)
    return value if value else None


def _fallback(data: NumericTerms, n: int, times: np.ndarray, scale: float,
              tau: mpmath.mpf | None) -> tuple[np.ndarray, np.ndarray]:
    """mpmath values of the flagged columns, rounded to float64, and their error bounds."""
    with mpmath.workdps(60):
        ts = [mpmath.mpf(float(v)) - (tau or 0) for v in times]  # exact binary values
        top = mpmath.mpf(scale)
    values, sizes, work = _mp_values(data, n, ts, 20, top)
    out = np.array([[float(v) for v in row] for row in values])
    with mpmath.workdps(work):
        error = np.array([[float(s * mpmath.mpf(10) ** (2 - work)) for s in row]
                          for row in sizes])
    return out, error + 0.5 * _EPS * np.abs(out)


def _mp_time(value) -> mpmath.mpf:
    """A time as an mpf: floats by their shortest decimal (0.1 is 1/10), like all input."""
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float):
        return mpmath.mpf(repr(value))
    if isinstance(value, sp.Basic):
        return mpmath.mpf(sp.Float(value, mpmath.mp.dps)._mpf_)
    return mpmath.mpf(value)


def evaluate_mp(data: NumericTerms, n: int, times: Sequence, dps: int) -> np.ndarray:
    """Sum the terms with mpmath, good to ``dps`` digits relative to max |x| over ``times``.

    The working precision is raised by the digits the pole sum cancels, and the pole
    data reconverted from the exact terms when needed. Floats are read by their
    shortest decimal form (0.1 means 1/10), like all input.

    Returns
    -------
    numpy.ndarray
        Object array of mpf values at ``dps`` digits, shape (n, len(times)).
    """
    with mpmath.workdps(dps + 20):
        ts = [_mp_time(v) for v in times]
    values, _, _ = _mp_values(data, n, ts, dps)
    out = np.empty((n, len(ts)), dtype=object)
    with mpmath.workdps(dps):
        for i in range(n):
            for col in range(len(ts)):
                out[i, col] = +values[i][col]
    return out

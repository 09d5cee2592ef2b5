"""Numeric evaluation of real-form terms, in float64 or at any mpmath precision.

The exact terms (α, β, a, b, possibly built on algebraic roots whose values come from
flint, see :mod:`laplace_springs.exact.algebraic`) are converted once, at a working precision
well above float64, to a pole sum x_i(t) = Σ C_ijk t^k e^{z_j t}
(:class:`laplace_springs.numeric.pole_sum.PoleSum`).

**Float64** (:func:`float_values`). Close poles are grouped into blocks evaluated in
a Newton (divided-difference) basis whose coefficients are as large as x itself, and
every phase is formed in double-double; see :mod:`laplace_springs.numeric.pole_sum`. A
running error bound is kept, including the phase error of the stored poles (|z|·t times
their relative precision), so a time whose phase outgrows float64 says so.

**mpmath** (:func:`mp_values`). The pole sum is added term by term at a working
precision raised by the digits the sum cancels (measured, then recomputed) and the
digits of the largest phase, with the pole data itself reconverted from the exact terms
when it is not precise enough. The route policy (:mod:`laplace_springs.policy`) sends a
time here when its float64 bound misses the target.

Precision and conditioning
--------------------------
Relative to max |x| the float64 result is accurate to a few units of 1e-16 on the stiff
and extreme battery (:mod:`laplace_springs.bench.battery`): near-critical damping
(|ζ − 1| = 1e-14), c = 1e6 at t = 1e6, exceptional points, rigid modes, phases ωt up
to 1e6. The bound is a running error analysis (eps times what was summed, weighted by
block size, plus the phase terms), not a certificate.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import mpmath
import numpy as np
import sympy as sp

from ..exact.real_terms import Term
from ..kernels.precision import workdps
from ..limits import limits
from .mp_expr import mp_value
from .pole_sum import Block, PoleSum, evaluate_blocks, plan_blocks

__all__ = ["NumericTerms", "float_values", "mp_values", "numeric_terms"]

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
        #: per node, the absolute error of its coefficients: each is a sum of terms' a, b
        #: held to dps digits of themselves, and may cancel far below them (a cosh σt +
        #: b sinh σt with a ≈ −b ≈ 5e15 gives (a + b)/2 ≈ 0.33 on e^{σt})
        self.absolute: list[float] = []
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
                    self.absolute.append(0.0)
            a, b = self.index[key], self.index[mirror_key]
            self.mirror[a], self.mirror[b] = b, a
        return self.index[key], self.index[mirror_key]

    def add(self, j: int, power: int, row: int, c, size) -> None:
        """Add ``c`` (formed from numbers of magnitude up to ``size``) to node j's power."""
        powers = self.coeffs[j]
        while len(powers) <= power:
            powers.append([mpmath.mpc(0)] * self.n)
        powers[power][row] += c
        self.absolute[j] += float(size) * 10.0 ** (3 - self.dps)

    def term(self, row: int, term: Term) -> None:
        if term.kind == "root_sum":
            raise ValueError("a sum over the roots of Δ needs numbers: substitute the parameters "
                             "(scene.subs({...})) and solve again")
        alpha, a = self.value(term.alpha), self.value(term.a)
        k = term.power
        if term.kind == "real":
            j, _ = self.node(("r", term.alpha), mpmath.mpc(alpha), ("r", term.alpha),
                             mpmath.mpc(alpha))
            self.add(j, k, row, mpmath.mpc(a), abs(a))
            return
        beta, b = self.value(term.beta), self.value(term.b)
        if term.kind == "oscillatory":  # Re[(a - ib) e^{(α+iβ)t}], halves on z and z̄
            up, down = self.node(("o+", term.alpha, term.beta), mpmath.mpc(alpha, beta),
                                 ("o-", term.alpha, term.beta), mpmath.mpc(alpha, -beta))
            size = abs(a) + abs(b)
            self.add(up, k, row, mpmath.mpc(a, -b) / 2, size)
            self.add(down, k, row, mpmath.mpc(a, b) / 2, size)
            return
        for sign in (1, -1):  # a cosh σt + b sinh σt = Σ± (a ± b)/2 e^{±σt}
            key = ("h", sign, term.alpha, term.beta)
            j, _ = self.node(key, mpmath.mpc(alpha + sign * beta), key,
                             mpmath.mpc(alpha + sign * beta))
            self.add(j, k, row, mpmath.mpc((a + sign * b) / 2), abs(a) + abs(b))

    def build(self) -> PoleSum:
        return PoleSum(self.n, tuple(self.nodes),
                       tuple(tuple(tuple(p) for p in c) for c in self.coeffs),
                       tuple(self.mirror), self.dps, tuple(self.absolute))


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
    e^{-t}(cos 2t + sin 2t) is the pole pair −1 ± 2i with coefficients (1 ∓ i)/2:

    >>> data = numeric_terms([[Term("oscillatory", 0, -1, 2, 1, 1)]], dps=20)
    >>> data.poles.nodes, data.poles.coefficients[0][0][0]
    ((mpc(real='-1.0', imag='2.0'), mpc(real='-1.0', imag='-2.0')), mpc(real='0.5', imag='-0.5'))
    """
    rows = tuple(tuple(r) for r in rows)
    builder = _Builder(len(rows), dps)
    with workdps(dps):
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


def _cancelled(mag, top, work: int) -> int:
    """Digits lost where terms of size ``mag`` sum to ``top``: a sum that cancelled to
    exactly 0 lost every digit (a periodic response's one-period sums at a period of
    1e-35: terms of 1e34 whose sum is of order 1)."""
    return _digits(mag / top) if top else (work if mag else 0)


def _mp_values(data: NumericTerms, n: int, ts: list, digits: int,
               scale=None) -> tuple[list, list, int]:
    """x at ``ts`` good to ``digits`` relative to each time's max(‖x(t)‖∞, ``scale``)
    (without a scale, its own max |x(t)|): values, sizes, dps.

    The working precision covers the digits the sum cancels (measured, then redone) and
    the digits of the largest phase |z t| (an absolute error in z·t is one in the phase).
    """
    with workdps(15):
        reach = (max((abs(z) for z in data.poles.nodes), default=mpmath.mpf(0))
                 * max((abs(tv) for tv in ts), default=mpmath.mpf(0)))
        small = min((abs(tv) for tv in ts if tv), default=mpmath.mpf(1))
    extra = _digits(reach)
    # a sum of m basis functions t^k e^{zt} that is not identically zero vanishes to order
    # at most m - 1 at t = 0: near it the sum may cancel (m - 1)·log10(1/t) digits more
    # (x'(1e-300) of a system driven from rest, about 1e-300 from terms of order 1)
    near_zero = (sum(data.poles.multiplicity) - 1) * _digits(1 / small) if small < 1 else 0
    work = digits + extra + 10
    while True:
        source = data.at_precision(work + 10)
        with workdps(work):
            values, sizes = _mp_sum(source.poles, n, ts)
            mag = max((s for row in sizes for s in row), default=mpmath.mpf(0))
            # each time against its own max(|x(t)|, scale) (not the call's largest, which
            # let x'(1e-300) of a system driven from rest ride on x'(1e-200) beside it,
            # nor the scale alone, which took e^{87000} growing without a cancellation
            # for 37,800 digits lost)
            lost = max((_cancelled(max(row[j] for row in sizes),
                                   max(scale or 0, *(abs(row[j]) for row in values)), work)
                        for j in range(len(ts)) if n), default=0)
        cap = min(4 * digits + 200 + _digits(mag / scale if scale else mag) + near_zero,
                  max(limits().max_dps, 4 * digits + 200))
        if work - lost - extra >= digits + 5 or work > cap:
            return values, sizes, work
        work = digits + lost + extra + 10


# ----------------------------------------------------------------------------- public


def float_values(data: NumericTerms, n: int, hi: np.ndarray,
                 lo: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Sum the terms in float64 at the times ``hi + lo`` (double-double); values, bounds.

    Both arrays have shape (n, len(hi)). The bound is a running error bound of the
    float64 sum, including the phase error of the stored poles and of the time; it is
    ``inf`` where the sum is not finite. Nothing is recomputed here: the caller decides
    which times need :func:`mp_values` (see :mod:`laplace_springs.policy`).

    Examples
    --------
    (cos t − cos(1.00000001 t))/(1.00000001² − 1): two poles 1e-8 apart whose
    coefficients (5e7) cancel; float64 evaluation keeps full accuracy.

    >>> import sympy as sp
    >>> w = sp.Rational(100000001, 100000000)
    >>> A = 1 / (w**2 - 1)
    >>> terms = [Term("oscillatory", 0, 0, 1, A, 0), Term("oscillatory", 0, 0, w, -A, 0)]
    >>> x, bound = float_values(numeric_terms([terms]), 1, np.array([0.0, 1e-3, 1e4]))
    >>> with mpmath.workdps(40):
    ...     exact = [float((mpmath.cos(t) - mpmath.cos(t * w.p / w.q)) * A.p / A.q)
    ...              for t in map(mpmath.mpf, (0, 1e-3, 1e4))]
    >>> bool(np.max(np.abs(x[0] - exact)) < 1e-15 * np.max(np.abs(exact)))
    True
    """
    values, bound = evaluate_blocks(data.blocks, n, hi, lo)
    bad = ~np.isfinite(values) | ~np.isfinite(bound)
    return np.where(bad, 0.0, values), np.where(bad, np.inf, bound)


def mp_values(data: NumericTerms, n: int, times: Sequence[mpmath.mpf], digits: int,
              scales: Sequence[float]) -> tuple[list[list[mpmath.mpf]], list[list[mpmath.mpf]], int]:
    """x at ``times`` with mpmath, good to ``digits`` relative to max(‖x(t)‖∞, scale) (the
    contract's scale; ``scales``: one floor per time).

    The working precision is raised by the digits the pole sum cancels (measured, then
    recomputed) and by the digits of the largest phase |z t|; the pole data is
    reconverted from the exact terms when it is not precise enough.

    Each time is evaluated at the precision its own phase, cancellation and scale need, so
    its value does not depend on the other times of the call (with one precision for the
    call, a value of 1e-47 beside a scale of 1e-27 came out in other bits beside another
    time).

    Returns
    -------
    values, bounds : list of n lists of mpf
        The values and bounds on their errors (the sum of |terms| times the working
        precision's unit, which bounds the rounding of every step).
    work : int
        The largest working precision used (decimal digits).
    """
    values: list[list[mpmath.mpf]] = [[] for _ in range(n)]
    bounds: list[list[mpmath.mpf]] = [[] for _ in range(n)]
    most = 0
    for tv, scale in zip(times, scales):
        with workdps(30):
            floor = mpmath.mpf(scale) if scale > 0 else None
        column, sizes, work = _mp_values(data, n, [tv], digits, floor)
        with workdps(work):
            unit = mpmath.mpf(10) ** (2 - work)
            for i in range(n):
                values[i].append(column[i][0])
                bounds[i].append(sizes[i][0] * unit)
        most = max(most, work)
    return values, bounds, most

"""Certified route: exact polynomials of the first-order system, certified poles and
residues, evaluation in ball arithmetic.

For a scene with rational data the motion is x(t) = first n entries of e^{Zt} y0 with the
exact first-order system of :func:`~laplace_springs.numeric.first_order.first_order_system`.
Its transform is X(λ) = (λI − Z)⁻¹ y0 = N(λ)/Δ(λ), and everything up to the roots is
exact rational arithmetic in python-flint:

1. Δ(λ) = det(λI − Z) by ``fmpq_mat.charpoly``; the numerators N(λ) = adj(λI − Z) y0 by
   the Krylov recurrence b_{N−1} = y0, b_{k−1} = Z b_k + a_k y0, N(λ) = Σ b_k λ^k.
2. Common factors of Δ and all N_i cancel exactly (gcd): a repeated but semisimple
   eigenvalue (two identical chains, symmetric frequencies) becomes a simple pole.
3. The reduced denominator is factored over ℚ; each irreducible factor q of multiplicity
   m has simple roots ρ, enclosed in certified balls by ``fmpq_poly.complex_roots``.
4. The residue of e^{λt} N_i(λ)/D(λ) at ρ is Σ_{k<m} c_k t^k e^{ρt}, with c_k the Laurent
   coefficients of N_i/D at ρ, computed from Taylor coefficients in ball arithmetic:
   defective poles (critical damping, rigid-body drift, exceptional points) give their
   t^k terms exactly, without any eigenvector.

Evaluation sums Re Σ c t^k e^{ρt} in ball arithmetic (``acb_mat`` products); the returned
value is the ball's midpoint and the error bound its radius plus the final rounding, so
the bound is certified. The working precision starts from the digits of the largest
phase, abs(ρ)·t, and is doubled, per column, until the radius meets the caller's target.

For the float64 fast path the same poles and residues become a
:class:`~laplace_springs.numeric.pole_sum.PoleSum` (midpoints at 40+ digits), evaluated by
the stable kernels of :mod:`laplace_springs.numeric.pole_sum`.

Cost (2 cores): 20-mass chains with springs 1 and 1e8 in about 0.03 s; degree 100
(50 masses) about 1 s per precision level, spent finding the roots.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import mpmath
import numpy as np
import sympy as sp
from flint import acb, acb_mat, acb_poly, arb, fmpq, fmpq_mat, fmpq_poly

from ..kernels.precision import flint_workprec, workdps
from ..limits import limits
from ..model.scene import Scene
from ..model.symbols import TIME
from .first_order import first_order_system, is_rational
from .pole_sum import PoleSum
from .times import Times

__all__ = ["CertifiedPoles", "certified_poles", "certified_values", "certified_digits", "closed_form"]

_EPS = 2.0**-53


def _fmpq(value):

    return fmpq(int(value.p), int(value.q))


@dataclass(frozen=True, eq=False)
class _Pole:
    """One root ρ (Im ρ ≥ 0) of the reduced denominator and its residue coefficients.

    ``coefficients[k][i]`` multiplies t^k e^{ρt} in coordinate i; ``weight`` is 2 for a
    complex root (its conjugate is folded in through the real part), 1 for a real one.
    """
    root: Any  # acb
    coefficients: list[list[Any]]  # [k][i] -> acb
    weight: int


@dataclass(frozen=True, eq=False)
class _Balls:
    bits: int
    poles: list[_Pole]


@dataclass(frozen=True, eq=False)
class CertifiedPoles:
    """The exact data of X(λ) = N(λ)/D(λ) and its certified poles at any precision.

    Build it with :func:`certified_poles`.

    Attributes
    ----------
    n : int
        Number of coordinates.
    denominator : flint.fmpq_poly
        D(λ), Δ(λ) with the factors common to every N_i cancelled.
    numerators : list of flint.fmpq_poly
        N_i(λ) over the same denominator.
    factors : list of (flint.fmpq_poly, int)
        Irreducible factors of D and their multiplicities.
    """
    n: int
    denominator: Any
    numerators: list[Any]
    factors: list[tuple[Any, int]]
    _balls: dict[int, _Balls] = field(default_factory=dict, repr=False)

    @property
    def degree(self) -> int:
        """deg D: the number of poles, with multiplicity."""
        return int(self.denominator.degree())

    def poles(self, bits: int) -> list[_Pole]:
        """The poles with Im ρ ≥ 0 and their residue coefficients at ``bits`` (cached)."""
        if bits not in self._balls:
            self._balls[bits] = _Balls(bits, _poles(self, bits))
        return self._balls[bits].poles

    def spectral_radius(self) -> float:
        """max |ρ| over the poles (float, from 64-bit enclosures)."""
        poles = self.poles(64)
        with flint_workprec(64):
            return max((float(abs(p.root).mid()) for p in poles), default=0.0)

    def evaluate(self, times: Times, order: int, bits: int) -> tuple[np.ndarray, np.ndarray]:
        """d^order x/dt^order at the times in ball arithmetic at ``bits``: midpoints, radii.

        Returns float64 arrays of shape (n, len(times)); radii include nothing else (the
        rounding of the midpoints to float64 is the caller's to add).
        """

        with flint_workprec(bits):
            balls = self._balls_at(times, order, bits)
            mids = np.array([[float(b.real.mid()) for b in row] for row in balls])
            rads = np.array([[float(b.real.rad()) for b in row] for row in balls])
        return mids.reshape(self.n, len(times)), rads.reshape(self.n, len(times))

    def evaluate_mp(self, times: Times, order: int, bits: int) -> tuple[list, list]:
        """As :meth:`evaluate`, but midpoints and radii as exact mpmath numbers (n lists)."""

        with flint_workprec(bits):
            balls = self._balls_at(times, order, bits)
            mids = [[_mpf(b.real.mid()) for b in row] for row in balls]
            rads = [[_mpf(b.real.rad()) for b in row] for row in balls]
        return mids, rads

    def _balls_at(self, times: Times, order: int, bits: int) -> list[list]:

        poles = self.poles(bits)
        stamps = [arb(fmpq(f.numerator, f.denominator)) for f in map(times.exact, range(len(times)))]
        columns = [(p, k) for p in poles for k in range(len(p.coefficients))]
        if not columns:
            return [[acb(0)] * len(times) for _ in range(self.n)]
        weights = acb_mat(self.n, len(columns),
                          [p.coefficients[k][i] * p.weight for i in range(self.n) for p, k in columns])
        entries = [_derivative_entry(p.root, k, order, stamp) for p, k in columns for stamp in stamps]
        values = weights * acb_mat(len(columns), len(stamps), entries)
        return [[values[i, j] for j in range(len(stamps))] for i in range(self.n)]

    def pole_sum(self, dps: int) -> PoleSum:
        """The poles and residues as a :class:`PoleSum` good to about ``dps`` digits.

        Roots to ``dps`` digits relative to themselves, coefficients to ``dps`` digits of
        the largest coefficient (their errors add absolutely to x).
        """
        bits = int(dps * 3.33) + 64
        while True:
            poles = self.poles(bits)
            with flint_workprec(bits):
                precise = _precision(poles) <= 10.0 ** -(dps + 2)
            if precise or bits >= limits().max_bits:
                return _pole_sum(self.n, poles, dps)
            bits *= 2


def _precision(poles: list[_Pole]) -> float:
    """The worst relative radius of the roots and of the coefficients (normwise); inf
    when a ball is not finite (max() would pass over a NaN midpoint: a pole sum of NaN
    coefficients at 64 bits for poles 1e-61 apart)."""
    if not all(p.root.is_finite() and all(c.is_finite() for row in p.coefficients for c in row)
               for p in poles):
        return math.inf
    roots = max((_relative_radius(p.root) for p in poles), default=0.0)
    sizes = [float(abs(c).mid()) for p in poles for row in p.coefficients for c in row]
    radii = [float(abs(c).rad()) for p in poles for row in p.coefficients for c in row]
    top = max(sizes, default=0.0)
    coefficients = max(radii, default=0.0) / top if top else (0.0 if not any(radii) else math.inf)
    return max(roots, coefficients)


def _mpf(value) -> mpmath.mpf:
    """An exact arb midpoint (or radius) as an mpf, exactly: no rounding to mpmath's precision."""
    man, exp = value.man_exp()
    return mpmath.mp.make_mpf(mpmath.libmp.from_man_exp(int(man), int(exp)))


def _relative_radius(value) -> float:
    size = float(abs(value).mid())
    radius = float(abs(value).rad())
    return radius / size if size else (0.0 if radius == 0 else math.inf)


def _derivative_entry(root, power: int, order: int, t):
    """d^order/dt^order of t^power e^{ρt} at t, as a ball."""
    total = acb(0)
    for j in range(min(order, power) + 1):
        falling = math.perm(power, j)
        term = math.comb(order, j) * falling * t ** (power - j) * root ** (order - j)
        total += term
    return total * (root * t).exp()


def _taylor(poly, root, count: int) -> list:
    """The first ``count`` Taylor coefficients of ``poly`` (fmpq_poly) at ``root`` (acb).

    p^(k)(ρ)/k! with the derivative formed exactly and evaluated in ball arithmetic.
    """
    out, factorial = [], 1
    for k in range(count):
        out.append(acb_poly(poly)(root) / factorial)
        poly = poly.derivative()
        factorial *= k + 1
    return out


def _series_mul(a: list, b: list) -> list:

    return [sum((a[i] * b[k - i] for i in range(k + 1)), acb(0)) for k in range(len(a))]


def _series_inverse(h: list) -> list:

    inverse = [1 / h[0]]
    for k in range(1, len(h)):
        inverse.append(-sum((h[i] * inverse[k - i] for i in range(1, k + 1)), acb(0)) / h[0])
    return inverse


def _poles(data: CertifiedPoles, bits: int) -> list[_Pole]:
    """Roots with Im ≥ 0 and the Laurent coefficients of N_i/D at them, at ``bits``."""
    out = []
    with flint_workprec(bits):
        for q, m in data.factors:
            rest = data.denominator
            for _ in range(m):
                rest = rest / q  # exact: q^m divides D
            orders = [m - _divides(N, q, m) for N in data.numerators]
            for root, _ in q.complex_roots():
                if root.imag < 0:
                    continue
                out.append(_pole(data, q, m, rest, root, orders))
    return out


def _divides(N, q, m: int) -> int:
    """The largest j ≤ m with q^j dividing N (exact)."""
    j = 0
    while j < m and (N == 0 or N % q == 0):
        if N != 0:
            N = N / q
        j += 1
    return j


def _pole(data: CertifiedPoles, q, m: int, rest, root, orders: list[int]) -> _Pole:
    """Residue coefficients at a root ρ of q, D = q^m · rest: N/D = N(ρ+u)/(u^m h(u)).

    ``orders[i]`` is the order of the pole of N_i/D at ρ (m less the power of q dividing
    N_i): the coefficients of t^k, k ≥ orders[i], are exactly zero and kept so, not as
    balls around zero whose midpoints a float64 pole sum would add to x_i (a coordinate
    that does not move with ρ: two uncoupled critically damped masses, x_2 ≈ 3e-53 off by
    6e-59 with a bound of 3e-67)."""
    slope = _taylor(q, root, m + 1)[1:]          # q(ρ+u)/u
    h = [acb(1)] + [acb(0)] * (m - 1)
    for _ in range(m):
        h = _series_mul(h, slope)
    h = _series_mul(h, _taylor(rest, root, m))
    inverse = _series_inverse(h)
    coefficients = [[acb(0)] * data.n for _ in range(m)]
    for i, N in enumerate(data.numerators):
        series = _series_mul(_taylor(N, root, m), inverse)
        for k in range(orders[i]):  # residue of e^{λt} N/D: Σ_k [u^{m-1-k}](N/h) t^k/k!
            coefficients[k][i] = series[m - 1 - k] / math.factorial(k)
    return _Pole(root, coefficients, 1 if root.imag == 0 else 2)


def _pole_sum(n: int, poles: list[_Pole], dps: int) -> PoleSum:
    """The poles (with their conjugates) as a PoleSum of mpmath numbers at ``dps + 10``."""
    nodes: list[Any] = []
    coefficients: list[tuple[tuple[Any, ...], ...]] = []
    mirror: list[int] = []
    # the balls' radii, where one is not within dps digits of its own coefficient (a
    # residue that is tiny beside the others: its ball holds 0), become absolute errors
    radii: list[float] = []
    with workdps(dps + 10):
        for pole in poles:
            z = mpmath.mpc(_mpf(pole.root.real.mid()), _mpf(pole.root.imag.mid()))
            rows = [tuple(mpmath.mpc(_mpf(c.real.mid()), _mpf(c.imag.mid())) for c in row)
                    for row in pole.coefficients]
            radius = max((_loose_radius(c, dps) for row in pole.coefficients for c in row),
                         default=0.0)
            index = len(nodes)
            nodes.append(z)
            coefficients.append(tuple(rows))
            radii.append(radius)
            if pole.weight == 1:
                mirror.append(index)
                continue
            nodes.append(mpmath.conj(z))
            coefficients.append(tuple(tuple(mpmath.conj(c) for c in row) for row in rows))
            radii.append(radius)
            mirror.extend([index + 1, index])
    return PoleSum(n, tuple(nodes), tuple(coefficients), tuple(mirror), dps,
                   tuple(radii) if any(radii) else None)


def _loose_radius(value: Any, dps: int) -> float:
    """The radius of a coefficient's ball (rounded up to float64) where it exceeds
    10^-dps of the coefficient's own size, else 0 (the pole sum's relative precision
    covers it)."""
    size, radius = abs(value).mid(), abs(value).rad()
    if radius <= size * 10.0 ** -dps:
        return 0.0
    return float(radius) * (1 + 2.0**-50)


def certified_poles(scene: Scene) -> CertifiedPoles | None:
    """The exact transform data of a scene with rational entries (None otherwise).

    Also None when the scene has no first-order form (massless nodes not held by
    dashpots) or is forced (the route takes free motions).

    Examples
    --------
    Critical damping, x'' + 2x' + x = 0, x(0) = 1: one double pole at −1, and
    x = (1 + t) e^{−t} to the last bit.

    >>> from laplace_springs.model.scene import Scene
    >>> from laplace_springs.numeric.times import as_times
    >>> data = certified_poles(Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[0]))
    >>> data.factors
    [(x + 1, 2)]
    >>> values, radii = data.evaluate(as_times([1.0]), 0, 128)
    >>> float(values[0, 0]), bool(radii[0, 0] < 1e-30)
    (0.7357588823428847, True)
    """
    if scene.is_forced or not is_rational(scene):
        return None
    try:
        Z, y0, _ = first_order_system(scene)
    except ValueError:
        return None
    size = Z.rows
    Zq = fmpq_mat(size, size, [_fmpq(e) for e in Z])
    y = fmpq_mat(size, 1, [_fmpq(e) for e in y0])
    delta = Zq.charpoly()
    a = delta.coeffs()
    b = [y] * size
    for k in range(size - 1, 0, -1):
        b[k - 1] = Zq * b[k] + y * a[k]
    numerators = [fmpq_poly([b[k][i, 0] for k in range(size)]) for i in range(scene.n)]
    common = delta
    for N in numerators:
        common = common.gcd(N)
    if common.degree() > 0:
        delta = delta / common
        numerators = [N / common for N in numerators]
    _, factors = delta.factor()
    return CertifiedPoles(scene.n, delta, numerators, [(q, int(m)) for q, m in factors])


def _start_bits(poles: CertifiedPoles, times: Times, digits: float) -> int:
    """Bits for ``digits`` decimal digits plus those of the largest phase |ρ| t."""
    reach = poles.spectral_radius() * float(np.max(np.abs(times.hi), initial=0.0))
    # beyond float64 (a pole of 1e300 at t = 1e300): the bits of the largest float64
    return int(digits * 3.33) + 32 + max(0, math.ceil(math.log2(1.0 + min(reach, 1e308))))


def certified_values(poles: CertifiedPoles, times: Times, order: int, target: float,
                     floor: float) -> tuple[np.ndarray, np.ndarray]:
    """float64 values and certified bounds, the precision doubled per time until the
    bound is within ``target``·max(‖x(t)‖∞, ``floor``) (or :attr:`~laplace_springs.limits.Limits.max_bits` is reached).

    The bound is the ball radius plus the rounding of the midpoint to float64.
    """
    n, count = poles.n, len(times)
    values, bounds = np.zeros((n, count)), np.full((n, count), np.inf)
    pending = np.arange(count)
    bits = _start_bits(poles, times, -math.log10(target) + 4)
    while pending.size and bits <= limits().max_bits:
        mids, rads = poles.evaluate(times.subset(pending), order, bits)
        with np.errstate(over="ignore", invalid="ignore"):
            rads = rads + np.abs(mids) * _EPS
            finite = np.all(np.isfinite(mids) & np.isfinite(rads), axis=0)
            scale = np.maximum(np.max(np.abs(mids), axis=0), floor)
            done = np.all(rads <= target * scale[None, :], axis=0) & finite
            better = finite & (np.max(rads, axis=0) <= np.max(bounds[:, pending], axis=0))
        values[:, pending[better]], bounds[:, pending[better]] = mids[:, better], rads[:, better]
        # a midpoint beyond float64 (and no finite value yet): kept as ±inf with an infinite
        # bound, so the caller says the value is beyond float64 (dps= gives it) rather
        # than that no engine could bound it
        beyond = ~finite & np.isinf(mids).any(axis=0) & ~np.isnan(mids).any(axis=0) \
            & np.isinf(bounds[:, pending]).all(axis=0)
        values[:, pending[beyond]] = mids[:, beyond]
        pending = pending[~done]
        bits *= 2
    return values, bounds


def certified_digits(poles: CertifiedPoles, times: Times, order: int, dps: int,
                     floor: float) -> tuple[np.ndarray, np.ndarray]:
    """mpmath values good to ``dps`` digits of max(‖x(t)‖∞, ``floor``), and their bounds.

    Returns object arrays (n, len(times)) of mpf: midpoints at ``dps`` digits and
    certified bounds (radius plus the rounding to ``dps`` digits).
    """
    n, count = poles.n, len(times)
    values = np.empty((n, count), dtype=object)
    bounds = np.empty((n, count), dtype=object)
    pending = list(range(count))
    bits = _start_bits(poles, times, dps + 4)
    while pending:
        mids, rads = poles.evaluate_mp(times.subset(np.array(pending)), order, bits)
        keep = []
        with workdps(dps + 10):
            for k, col in enumerate(pending):
                column = [mids[i][k] for i in range(n)]
                radius = [rads[i][k] + abs(column[i]) * mpmath.mpf(10) ** (-dps) for i in range(n)]
                scale = max([abs(v) for v in column] + [mpmath.mpf(floor)])
                if max(radius) <= mpmath.mpf(10) ** (-dps) * scale * 10 or bits >= limits().max_bits:
                    for i in range(n):
                        with workdps(dps):
                            values[i, col] = +column[i]
                        bounds[i, col] = radius[i]
                else:
                    keep.append(col)
        pending = keep
        bits *= 2
    return values, bounds


def closed_form(poles: CertifiedPoles, digits: int = 15) -> list:
    """x(t) as real terms with Float coefficients: Σ t^k e^{αt}(a cos βt + b sin βt)."""


    rows: list = [sp.Integer(0)] * poles.n
    with workdps(digits + 5):
        for pole in poles.poles(int(digits * 3.33) + 64):
            alpha = sp.Float(_mpf(pole.root.real.mid()), digits)
            beta = sp.Float(_mpf(pole.root.imag.mid()), digits)
            growth = sp.exp(alpha * TIME) if alpha != 0 else sp.Integer(1)
            for k, row in enumerate(pole.coefficients):
                for i, c in enumerate(row):
                    re = sp.Float(_mpf(c.real.mid()), digits) * pole.weight
                    im = sp.Float(_mpf(c.imag.mid()), digits) * pole.weight
                    wave = re if beta == 0 else re * sp.cos(beta * TIME) - im * sp.sin(beta * TIME)
                    rows[i] += TIME**k * growth * wave
    return rows

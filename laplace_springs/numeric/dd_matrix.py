"""Double-double matrices with elementwise error bounds: products, the exponential of an
exact matrix, and its dyadic powers e^{A·2^i δ}.

A double-double matrix is a pair (hi, lo) of float64 arrays of one shape (leading axes are
batches, one per time or per step). Every function returns, beside the result, a float64
array bounding the absolute error of every entry; the arithmetic is the error-free
transformations of :mod:`laplace_springs.kernels.dd`, in a fixed order along the summed
index (no BLAS), so an entry never depends on the other entries of the batch.

Error bounds (u = 2⁻⁵³)
-----------------------
* :func:`matvec`, :func:`matmul`: products of the high parts exact (two-product), their
  sums exact (two-sum), the low parts and the errors summed in float64: at most
  (4q² + 12q + 8)u²·Σ|x||y| for q summed terms (each of the 4q float additions is off by
  u of a partial sum ≤ (q + 3)u·Σ|x||y|; the dropped lo·lo and the rounded cross products
  add 3u²).
* :func:`expm`: e^{Xh} = Σ_{j≤J} h^j P_j with P_j = X^j/j! held in double-double (rounded
  once from exact rationals or 60-digit mpmath values: u²|P_j|), by Horner in h: each step
  a double-double product (7u²) and sum (3u² + 13u³), so at most 10.1(J + 1)u²·Σ_j|P_j||h|^j,
  plus the truncation ‖Σ_{j>J}(Xh)^j/j!‖∞ ≤ (θ|h|)^{J+1}/(J+1)!/(1 − θ|h|/(J + 2)) with
  θ ≥ ‖X‖∞, after s halvings of h (θ|h|/2^s ≤ 1/2; J the least degree with a truncation
  below 2⁻¹¹⁰) and s squarings, whose errors are carried exactly as products of the
  bounds: e' = |Y|e + e|Y| + e∘e + rounding.
* :class:`DyadicPowers`: E_i = e^{A·2^i δ} by squaring E_0 = e^{Aδ}, with the same
  bounds, and the elementwise bound sup_{0≤σ≤2^L δ} |e^{Aσ}| ≤ R·Π_{i<L}(I + |E_i|)
  (σ = Σ b_i 2^i δ + r, so e^{Aσ} = e^{Ar}·Π E_i^{b_i}, R ≥ |e^{Ar}| for r ≤ δ from the
  series of |A|δ): no sampling, a bound.

The bounds of products of nonnegative float matrices are rounded up by a factor
(1 + (q + 4)u) per product; every bound gets a tiny absolute term (10⁻³⁰⁰) for underflow.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import mpmath
import numpy as np
from flint import fmpq, fmpq_mat

from ..kernels.batch import rows_product
from ..kernels.dd import U, dd_add, dd_mul, dd_sum, from_exact, two_prod, two_sum
from ..kernels.precision import workdps

__all__ = ["matvec", "matmul", "taylor_matrices", "TaylorMatrices", "expm", "DyadicPowers",
           "abs_product"]

_TINY = 1e-300
#: Truncation allowed in a Taylor series (relative to ‖X‖-powers): far below u².
_TRUNCATION = 2.0**-110
#: Above this many summed terms, :func:`matvec` sums by error-free extraction (fewer calls).
_WIDE = 6
#: Degree of the stored Taylor matrices: enough for θ|h| ≤ 1/2 at 2⁻¹¹⁰.
DEGREE = 27


def matvec(Xh: np.ndarray, Xl: np.ndarray, vh: np.ndarray, vl: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """y = X v in double-double: X (..., p, q), v (..., q) -> y (..., p), and the bound on
    the rounding of each entry (the inputs' own errors are the caller's).

    >>> X = np.array([[1.0, 1e-20], [3.0, 4.0]])
    >>> yh, yl, err = matvec(X, np.zeros_like(X), np.array([1.0, 1.0]), np.zeros(2))
    >>> yh.tolist(), yl.tolist(), bool(err.max() < 1e-29)
    ([1.0, 7.0], [1e-20, 0.0], True)
    """
    q = Xh.shape[-1]
    if q > _WIDE:
        return _matvec_wide(Xh, Xl, vh, vl)
    shape = np.broadcast_shapes(Xh.shape[:-1], vh.shape[:-1] + (1,))
    acc_h, acc_l, size = np.zeros(shape), np.zeros(shape), np.zeros(shape)
    for j in range(q):
        x_h, x_l = Xh[..., j], Xl[..., j]
        a_h, a_l = vh[..., j, None], vl[..., j, None]
        p, e = two_prod(x_h, a_h)
        acc_h, s = two_sum(acc_h, p)
        acc_l = acc_l + (s + (e + (x_h * a_l + x_l * a_h)))
        size = size + np.abs(x_h) * np.abs(a_h)
    yh, yl = two_sum(acc_h, acc_l)
    return yh, yl, _rounding(q, size)


def _matvec_wide(Xh: np.ndarray, Xl: np.ndarray, vh: np.ndarray, vl: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`matvec` for many summed terms: every product at once, summed by error-free
    extraction (:func:`~laplace_springs.kernels.dd.dd_sum`: within γ_q Σ|lo| + 2u²Σ|hi|)."""
    q = Xh.shape[-1]
    p, e = two_prod(Xh, vh[..., None, :])
    lo = e + (Xh * vl[..., None, :] + Xl * vh[..., None, :])
    yh, yl = dd_sum(np.moveaxis(p, -1, 0), np.moveaxis(lo, -1, 0))
    size = np.sum(np.abs(Xh) * np.abs(vh[..., None, :]), axis=-1) * (1 + (q + 2) * 2 * U)
    return yh, yl, (3 * q + 16) * U * U * size * 1.01 + _TINY


def matmul(Xh: np.ndarray, Xl: np.ndarray, Yh: np.ndarray, Yl: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Z = X Y in double-double: X (..., p, q), Y (..., q, r), and the rounding bound."""
    q = Xh.shape[-1]
    shape = np.broadcast_shapes(Xh.shape[:-1] + (1,), Yh.shape[:-2] + (1, Yh.shape[-1]))
    acc_h, acc_l, size = np.zeros(shape), np.zeros(shape), np.zeros(shape)
    for j in range(q):
        x_h, x_l = Xh[..., :, j, None], Xl[..., :, j, None]
        y_h, y_l = Yh[..., None, j, :], Yl[..., None, j, :]
        p, e = two_prod(x_h, y_h)
        acc_h, s = two_sum(acc_h, p)
        acc_l = acc_l + (s + (e + (x_h * y_l + x_l * y_h)))
        size = size + np.abs(x_h) * np.abs(y_h)
    Zh, Zl = two_sum(acc_h, acc_l)
    return Zh, Zl, _rounding(q, size)


def _rounding(q: int, size: np.ndarray) -> np.ndarray:
    return (4 * q * q + 12 * q + 8) * U * U * size * (1 + (q + 4) * 2 * U) + _TINY


def abs_product(X: np.ndarray, Y: np.ndarray) -> np.ndarray:
    """An upper bound on X @ Y for nonnegative float arrays (batched over leading axes; a
    2-d X is one row per time, multiplied row by row as :func:`rows_product` does)."""
    q = X.shape[-1]
    product = rows_product(X, Y) if X.ndim == 2 and Y.ndim == 2 else X @ Y
    return product * (1 + (q + 4) * 2 * U) + _TINY


# ----------------------------------------------------------------------------- Taylor data


@dataclass(frozen=True, eq=False)
class TaylorMatrices:
    """P_j = X^j/j! (j ≤ :data:`DEGREE`) in double-double, and θ ≥ ‖X‖∞ (float64).

    ``hi``, ``lo`` have shape (DEGREE + 1, m, m); ``absolute`` is |hi|·(1 + 2u) (≥ |P_j|).
    """

    hi: np.ndarray
    lo: np.ndarray
    theta: float
    absolute: np.ndarray = field(repr=False)

    @property
    def size(self) -> int:
        return int(self.hi.shape[-1])


def taylor_matrices(entries: list[list[Any]]) -> TaylorMatrices:
    """The Taylor matrices of an exact square matrix given by its entries (Fractions, ints,
    SymPy numbers, python-flint fmpq, or mpmath numbers at 60+ digits).

    Rational entries are multiplied exactly (python-flint); others in mpmath at 60 digits.

    >>> P = taylor_matrices([[0, 1], [-4, 0]])
    >>> P.hi[2].tolist(), round(P.theta, 12)
    ([[-2.0, 0.0], [0.0, -2.0]], 4.0)
    """
    m = len(entries)
    rational = _as_fmpq(entries)
    hi = np.zeros((DEGREE + 1, m, m))
    lo = np.zeros_like(hi)
    if rational is not None:
        X = fmpq_mat(m, m, [v for row in rational for v in row])
        power = fmpq_mat(m, m, [fmpq(int(i == j)) for i in range(m) for j in range(m)])
        factorial = 1
        for j in range(DEGREE + 1):
            if j:
                power = power * X
                factorial *= j
            for a in range(m):
                for b in range(m):
                    hi[j, a, b], lo[j, a, b] = from_exact(power[a, b] / factorial)
        theta = max((sum(abs(float(v)) for v in row) for row in rational), default=0.0)
    else:
        with workdps(60):
            X = mpmath.matrix([[mpmath.mpf(v) if not isinstance(v, mpmath.mpf) else v
                                for v in row] for row in entries])
            P = mpmath.eye(m)
            for j in range(DEGREE + 1):
                if j:
                    P = P * X / j
                for a in range(m):
                    for b in range(m):
                        hi[j, a, b], lo[j, a, b] = from_exact(P[a, b])
            theta = float(max((mpmath.fsum(abs(v) for v in X[a, :]) for a in range(m)),
                              default=mpmath.mpf(0)))
    theta = theta * (1 + (m + 2) * 2 * U) + _TINY
    return TaylorMatrices(hi, lo, theta, np.abs(hi) * (1 + 2 * U))


def _as_fmpq(entries: list[list[Any]]) -> list[list[Any]] | None:
    """The entries as python-flint fmpq when every one is rational, else None."""
    out = []
    for row in entries:
        converted = []
        for v in row:
            p, q = getattr(v, "p", None), getattr(v, "q", None)
            if isinstance(v, int):
                converted.append(fmpq(v))
            elif hasattr(v, "numerator") and hasattr(v, "denominator") and not isinstance(v, float):
                converted.append(fmpq(int(v.numerator), int(v.denominator)))
            elif p is not None and q is not None and getattr(v, "is_Rational", True):
                converted.append(fmpq(int(p() if callable(p) else p), int(q() if callable(q) else q)))
            else:
                return None
        out.append(converted)
    return out


def _degree(x: np.ndarray) -> np.ndarray:
    """The least J with x^{J+1}/(J+1)!/(1 − x/(J+2)) ≤ 2⁻¹¹⁰, for 0 ≤ x ≤ 1/2."""
    J = np.full(x.shape, DEGREE, dtype=np.int64)
    with np.errstate(divide="ignore"):
        logx = np.log(np.maximum(x, 1e-300))
    for degree in range(DEGREE, -1, -1):
        tail = (degree + 1) * logx - math.lgamma(degree + 2) - np.log1p(-x / (degree + 2))
        J = np.where(tail <= math.log(_TRUNCATION), degree, J)
    return np.where(x == 0, 0, J)


def _truncation(x: np.ndarray, J: int) -> np.ndarray:
    with np.errstate(divide="ignore", under="ignore"):
        log = (J + 1) * np.log(np.maximum(x, 1e-300)) - math.lgamma(J + 2) - np.log1p(-x / (J + 2))
        return np.where(x > 0, np.exp(log) * (1 + 1e-12), 0.0)


def expm(P: TaylorMatrices, hh: np.ndarray, hl: np.ndarray, rows: int | None = None
         ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """e^{X h} for each double-double h = hh + hl ≥ 0 (X the matrix of ``P``): arrays
    (T, rows, m) hi, lo and error bound (the first ``rows`` rows; all by default). Each
    time is done alone (its halvings s and degree J depend on it only), so a batch gives
    the same bits as its times one by one.

    >>> P = taylor_matrices([[0, 1], [-4, 0]])
    >>> Eh, El, err = expm(P, np.array([0.25, 1e3]), np.zeros(2))
    >>> bool(abs(Eh[1, 0, 0] - np.cos(2e3)) < 1e-12), bool(err.max() < 1e-23)
    (True, True)
    """
    hh, hl = np.asarray(hh, dtype=float), np.asarray(hl, dtype=float)
    m = P.size
    rows = m if rows is None else rows
    count = hh.size
    out_h, out_l, out_e = (np.empty((count, rows, m)) for _ in range(3))
    x = P.theta * np.abs(hh + hl) * (1 + 4 * U)
    with np.errstate(divide="ignore"):
        halvings = np.where(x > 0.5, np.ceil(np.log2(np.maximum(x, 0.5) / 0.5)), 0).astype(np.int64)
    scaled = np.ldexp(x, -halvings)
    degree = _degree(scaled)
    for s, J in sorted(set(zip(halvings.tolist(), degree.tolist()))):
        chosen = np.flatnonzero((halvings == s) & (degree == J))
        h1, l1 = np.ldexp(hh[chosen], -s), np.ldexp(hl[chosen], -s)
        Xh, Xl, Xe = _horner(P, h1, l1, J, scaled[chosen], m if s else rows)
        for _ in range(s):
            Xh, Xl, Xe = _square(Xh, Xl, Xe)
        out_h[chosen], out_l[chosen], out_e[chosen] = Xh[:, :rows], Xl[:, :rows], Xe[:, :rows]
    return out_h, out_l, out_e


def _horner(P: TaylorMatrices, hh: np.ndarray, hl: np.ndarray, J: int, x: np.ndarray,
            rows: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Σ_{j≤J} h^j P_j by Horner, first ``rows`` rows, with its error bound."""
    m = P.size
    count = hh.size
    Ph, Pl, Pa = P.hi[:, :rows], P.lo[:, :rows], P.absolute[:, :rows]
    Xh = np.broadcast_to(Ph[J], (count, rows, m)).copy()
    Xl = np.broadcast_to(Pl[J], (count, rows, m)).copy()
    size = np.broadcast_to(Pa[J], (count, rows, m)).copy()
    a = np.abs(hh + hl)[:, None, None] * (1 + 4 * U)
    th, tl = hh[:, None, None], hl[:, None, None]
    for j in range(J - 1, -1, -1):
        Xh, Xl = dd_mul(Xh, Xl, th, tl)
        Xh, Xl = dd_add(Xh, Xl, Ph[j], Pl[j])
        size = size * a + Pa[j]
    size = size * (1 + (J + 2) * 2 * U)
    error = (10.1 * (J + 1) + 1.01) * U * U * size + _truncation(x, J)[:, None, None] + _TINY
    return Xh, Xl, error


def _square(Xh: np.ndarray, Xl: np.ndarray, Xe: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    Yh, Yl, rounding = matmul(Xh, Xl, Xh, Xl)
    A = np.abs(Xh) * (1 + 2 * U)
    return Yh, Yl, abs_product(A, Xe) + abs_product(Xe, A) + abs_product(Xe, Xe) + rounding


# ----------------------------------------------------------------------------- dyadic powers


class DyadicPowers:
    """E_i = e^{A·2^i δ} (i = 0, 1, ...) in double-double with error bounds, built lazily.

    δ is the largest power of two with θ_A δ ≤ 1/2 (θ_A ≥ ‖A‖∞). Used to move a state
    over any time τ = q δ + r (the bits of q pick the E_i) and to bound sup |e^{Aσ}|.

    Parameters
    ----------
    P : TaylorMatrices
        Of A.
    """

    def __init__(self, P: TaylorMatrices) -> None:
        self.P = P
        self.delta = math.ldexp(1.0, -math.ceil(math.log2(2 * P.theta))) if P.theta > 0 else 1.0
        Eh, El, Ee = expm(P, np.array([self.delta]), np.zeros(1))
        self._powers: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = [(Eh[0], El[0], Ee[0])]

    def __getitem__(self, i: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(hi, lo, error) of E_i."""
        while len(self._powers) <= i:
            Xh, Xl, Xe = self._powers[-1]
            self._powers.append(_square(Xh, Xl, Xe))
        return self._powers[i]

    def levels(self, span: float) -> int:
        """L with 2^L δ ≥ span."""
        return max(0, math.ceil(math.log2(max(span, self.delta) / self.delta)))

    def sup(self, span: float) -> np.ndarray:
        """An elementwise bound on |e^{Aσ}| for every 0 ≤ σ ≤ span (m x m).

        Two bounds, the smaller kept entry by entry: G_{i+1} = max(G_i, |E_i| G_i) (for σ in
        [2^i δ, 2^{i+1} δ), e^{Aσ} = E_i e^{A(σ − 2^i δ)}), from G_0 ≥ |e^{Ar}| (r ≤ δ: the
        series of |A|δ); and Π_i max(1, ‖E_i‖₂)·e^{‖A‖₂δ} (the 2-norm, which does not see
        the rotations that the elementwise products add up)."""
        absA = self.P.absolute[1] * self.delta
        m = self.P.size
        G = np.eye(m)
        term = np.eye(m)
        for j in range(1, 40):
            term = abs_product(term, absA) / j
            G = G + term
        G = G * (1 + 80 * U) + 1e-40   # the tail beyond degree 39 of e^{|A|δ}, ‖|A|δ‖ ≤ 1/2
        norm1 = float(np.max(np.sum(absA, axis=0), initial=0.0))
        norm = math.exp(math.sqrt(norm1 * self.P.theta * self.delta)) * (1 + 1e-12)
        for i in range(self.levels(span)):
            Eh, El, Ee = self[i]
            absE = np.abs(Eh) * (1 + 2 * U) + Ee
            G = np.maximum(G, abs_product(absE, G))
            two = float(np.linalg.norm(Eh, 2)) * (1 + 1e-12) + float(np.linalg.norm(np.abs(El) + Ee))
            norm *= max(1.0, two)
        return np.minimum(G, norm)

    def split(self, th: np.ndarray, tl: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """τ = q δ + r with q ≥ 0 an integer (int64) and 0 ≤ r ≤ δ a double-double, exactly
        (τ = th + tl ≥ 0). Times beyond 2^62 δ get q = −1 (not served).

        >>> P = DyadicPowers(taylor_matrices([[0, 1], [-4, 0]]))
        >>> P.delta, [a.tolist() for a in P.split(np.array([1.0, 0.3]), np.array([0.0, 1e-20]))]
        (0.0625, [[16, 4], [0.0, 0.04999999999999999], [0.0, 1e-20]])
        """
        th, tl = np.asarray(th, dtype=float), np.asarray(tl, dtype=float)
        e = round(math.log2(self.delta))
        q1, q2 = np.floor(np.ldexp(th, -e)), np.floor(np.ldexp(tl, -e))
        r1, r2 = th - np.ldexp(q1, e), tl - np.ldexp(q2, e)   # exact: the bits below δ
        rh, rl = two_sum(r1, r2)                               # in [0, 2δ)
        over = (rh > self.delta) | ((rh == self.delta) & (rl >= 0))
        rh = np.where(over, rh - self.delta, rh)               # exact (Sterbenz)
        rh, rl = two_sum(rh, rl)
        big = ~(np.abs(q1) < 2.0**61) | ~np.isfinite(q1)
        q = (np.where(big, 0, q1).astype(np.int64) + np.where(big, 0, q2).astype(np.int64)
             + over.astype(np.int64))
        return np.where(big | (q < 0), -1, q), rh, rl

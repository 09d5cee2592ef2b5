"""The long-horizon engine: classically damped and undamped scenes from eigenpairs refined
in double-double, with the phases ωt formed in double-double.

When M, C and K are symmetric and C M⁻¹K = K M⁻¹C (:func:`classical_damping`), the
motion is a sum of modes x(t) = Σ_j φ_j q_j(t), q_j'' + c_j q_j' + θ_j q_j = 0. The work
is fixed by the number of modes, not by t: the whole difficulty of a long horizon is in
the phase ωt. At t = 10⁶ a frequency known to 1e-16 gives a phase wrong by 1e-10; known
to 1e-30, by 1e-24. This engine therefore

1. takes the float64 eigenpairs of K φ = θ M φ (tridiagonal, banded or dense, as
   :mod:`~laplace_springs.numeric.classical` computes them);
2. refines them (Ogita & Aishima's iteration, generalised to the pencil (K, M)): the
   residuals R = KΦ − MΦΘ are formed in double-double from the exact (rational) entries
   (a sparse K by its rows' few nonzeros; a dense K by error-free slices multiplied by
   float64 BLAS, Ozaki's scheme), rounded to float64 and projected, W = Φᵀ R (a float64
   product: R is tiny, so its relative error costs nothing), and Φ ← Φ(I + E) with
   E_kj = W_kj/(θ_j − θ_k) outside clusters and E_jj = (1 − φ_jᵀMφ_j)/2; θ_j ← the
   Rayleigh quotient. Clusters (frequencies √θ closer than ``Limits.close_poles`` · max √θ,
   the package's rule for close poles: identical sub-chains, rigid modes θ = 0) keep their
   invariant subspace and are diagonalised in it by a Rayleigh–Ritz step at 40 digits
   (mpmath), on K + γC so that damping that differs inside an eigenspace of K is
   diagonalised too. Two or three steps bring the residuals to the double-double level.
   The rigid modes of free parts of a spring network (K·1_c = 0 exactly) are taken as
   the exact null vectors 1_c/√m_c, whose residual is exactly zero;
3. holds θ_j, c_j = φ_jᵀCφ_j/φ_jᵀMφ_j, hence h_j = c_j/2 and the damped frequency
   √(θ_j − h_j²), as double-doubles, and the modal initial data q(0), q'(0) solved from
   Φ q = x0, v0 to double-double accuracy;
4. evaluates each q_j in closed form: e^{−ht}(u cos ωt + w sin(ωt)/ω) with ωt formed in
   double-double (:func:`~laplace_springs.kernels.dd.phase`) when underdamped, the
   stable forms e^{λ_big t}, e^{λ_small t} and −expm1(−2gt)/(2g) when over- or critically
   damped (λ_big = −θ/(h + g): no cancellation), and sums x = Φ q per time in blocks of
   ``Limits.refined_sum_block`` modes with a compensated sum of the blocks.

The error bound
---------------
The computed motion is x̂ = Φ̃ q̂, Φ̃ = Φ_hi + Φ_lo the double-double shapes and q̂ the
float64 values of the exact modal functions q̃_j (the closed forms with the held θ̃_j,
c̃_j, q̃(0), q̃'(0), all exact numbers). The function x̃ = Φ̃ q̃ solves

    M x̃'' + C x̃' + K x̃ = r(t) = Σ_j R_K,j q̃_j(t) + R_C,j q̃_j'(t),

R_K,j = Kφ̃_j − θ̃_jMφ̃_j, R_C,j = Cφ̃_j − c̃_jMφ̃_j (computed in double-double, with the
rounding of computing them bounded, against the exact entries). So e = x̃ − x solves
M e'' + C e' + K e = r with e(0) = Φ̃q̃(0) − x0, e'(0) = Φ̃q̃'(0) − v0 (computed too), and
the shifted energy E = ‖e'‖²_M + eᵀ(K + σM)e obeys d√E/dt ≤ ‖r‖_{M⁻¹} + ρ√E with
ρ = δ_C + σ/(2√s), where −δ_C bounds the least eigenvalue of C from below (0 when C is
proved positive semi-definite by diagonal dominance), and s = θ_low + σ > 0 with θ_low
a lower bound on the least θ (Weyl's theorem with the residuals and the measured loss of
M-orthogonality). Hence

    √E(t) ≤ e^{ρt}(√E(0) + t·sup_{s≤t} ‖r(s)‖_{M⁻¹}),    ‖e(t)‖_M ≤ √E(t)/√s,

and, when K is proved positive semi-definite (rigid modes: θ_low ≤ 0), also
‖e(t)‖_M ≤ ‖e(0)‖_M + ∫₀ᵗ √E (σ = 0); the smallest bound is taken. The sup of each |q̃_j|
over [0, t] is read from its closed form (amplitude √(u² + w²/ω²), growth e^{max(0,Re λ)t}).
A derivative of order k is bounded the same way: e^(k) solves the same equation with
r^(k), its initial data follow from the equation, and ‖e^(k)‖_M ≤ √E of e^(k−1). Added to this: the float64
rounding of each q̂_j (phase, exponentials, products; the phase error is |ωt|·O(u²))
and of the sums (γ_b per block of b modes, the compensated block sum, the dropped Φ_lo).
With residuals at u²‖K‖ ≈ 1e-32 the first part stays below 1e-20 of the data at
t = 10⁶ on a 200-mass chain; the float64 sums (≈ 1e-15) dominate. Where the uniform
rounding bound misses ``Limits.target`` for a time, that time's sum is bounded row by
row, and then formed in double-double (per time: a value does not depend on the other
times of the call).

Precision and conditioning
--------------------------
The refinement needs eigenvectors to converge: pairs closer than ``close_poles`` are a
cluster and are never divided by their gap. A cluster larger than
``Limits.refined_max_cluster`` is diagonalised in pieces; if its eigenvalues differ, its
residuals stay at the float64 level, and the bound says so (it grows like t·residual).
Wide spreads of stiffness (1e-6 … 1e6) refine like any other scene: the residual is
relative to |K||φ| (16 masses, springs 1e-6 … 1e6: bound 2e-15 at t = 10⁶). A rigid
mode that is not an exact null vector found as above keeps a residual of ≈ u²‖K‖ that
its growing amplitude feeds: the bound then grows like t³·u²‖K‖ (still ≤ 1e-13 of a
unit motion to t ≈ 10⁷). Damping that makes C indefinite, and stiffness that makes K
indefinite, give bounds that grow like the motion may (e^{ρt}).

Cost
----
Independent of t. Building: the float64 decomposition, then per refinement step two
float64 products of n x n matrices (W = ΦᵀR and ΦE) and one double-double product with
each of K and M (time ∝ n·nonzeros; 13 float64 n x n products for a dense K), plus a
final certificate (the residuals with C, the loss of orthogonality ΦᵀMΦ, the modal
initial data). Per time: the modal functions (O(n)) and x = Φq (O(n²), in blocks).
See :func:`refined_cost` for the measured model.

References: T. Ogita and K. Aishima, "Iterative refinement for symmetric eigenvalue
decomposition", Japan J. Indust. Appl. Math. 35 (2018) and part II (clustered
eigenvalues, 2019); T. Ogita, S. M. Rump and S. Oishi, "Accurate sum and dot product",
SIAM J. Sci. Comput. 26 (2005); K. Ozaki, T. Ogita, S. Oishi and S. M. Rump, "Error-free
transformations of matrix multiplication by using fast routines of matrix
multiplication", Numer. Algorithms 59 (2012).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from fractions import Fraction
from functools import cached_property
from typing import Any

import mpmath
import numpy as np
import sympy as sp
from flint import fmpq, fmpq_mat

from ..kernels.dd import U, dd_add, dd_div, dd_mul, dd_sqrt, dd_sum, phase, two_prod, two_sum
from ..kernels.poles import clusters
from ..kernels.precision import workdps
from ..limits import limits
from ..model.errors import InternalError
from ..model.scene import Scene
from .classical import (
    NOT_CLASSICAL,
    ModalForm,
    SymmetricScene,
    _eigen,
    _modal_form,
    _ModeData,
    classical_damping,
    mode_poles,
    symmetric_scene,
)
from .first_order import rational_entries, scene_entries
from .times import Times

__all__ = ["refined_refusal", "refined_cost", "refined_motion", "RefinedMotion"]


def _gamma(k: int) -> float:
    """γ_k = ku/(1 − ku), the relative rounding of a k-term float64 sum or dot product."""
    return k * U / (1 - k * U)


def _norms(X: np.ndarray) -> np.ndarray:
    """Upper bounds on the 2-norms of the columns of X (float64 norm, rounded up)."""
    return np.linalg.norm(X, axis=0) * (1 + _gamma(X.shape[0] + 4))


#: Rounding of a double-double product or sum of a few terms, relative to Σ|terms|.
_DD = 16 * U * U
#: Relative margin on float64 sums of non-negative terms and products of bounds.
_UP = 1 + 1e-12


# ----------------------------------------------------------------------------- the interface


def refined_refusal(scene: Scene, *, t_max: float, count: int, order: int) -> str | None:
    """None when the engine can serve the request, else why not (one sentence).

    Cheap: the exact classical-damping check (time ∝ nonzero entries for a diagonal M),
    no decomposition. ``t_max`` and ``count`` do not matter: the cost does not depend on
    t, and every time is served.

    Examples
    --------
    >>> scene = Scene.from_matrices(M=[[1]], K=[[4]], x0=[1], v0=[0])
    >>> refined_refusal(scene, t_max=1e9, count=10, order=0) is None
    True
    >>> refined_refusal(Scene.from_matrices(M=[[1, 0], [0, 1]], C=[[1, 0], [0, 0]],
    ...     K=[[2, -1], [-1, 2]], x0=[1, 0], v0=[0, 0]), t_max=1.0, count=1, order=0)
    'the scene is not classical (needs symmetric M, C, K, no massless node and C M⁻¹K = K M⁻¹C)'
    """
    lim = limits()
    if scene.is_forced:
        return "the scene is forced"
    if any(rational_entries(scene, name) is None for name in ("M", "C", "K")):
        return "needs rational M, C and K (no symbols)"
    if scene.x0.free_symbols or scene.v0.free_symbols:
        return "the initial data have symbols"
    if not 0 <= order <= lim.refined_max_order:
        return f"derivative order {order} is outside 0..Limits.refined_max_order = {lim.refined_max_order}"
    if scene.n > lim.refined_max_coordinates:
        return f"coordinates {scene.n:,} > Limits.refined_max_coordinates = {lim.refined_max_coordinates:,}"
    if not classical_damping(scene):
        return NOT_CLASSICAL
    if _dense_stiffness(scene):
        if scene.n > lim.refined_dense_max_coordinates:
            return (f"a dense K of {scene.n:,} coordinates > Limits.refined_dense_max_coordinates = "
                    f"{lim.refined_dense_max_coordinates:,}")
        return None
    work = scene.n * _stored_entries(scene)
    if work > lim.refined_max_products:
        return (f"its double-double products take n·nonzeros = {work:,} > "
                f"Limits.refined_max_products = {lim.refined_max_products:,}")
    return None


def _stored_entries(scene: Scene) -> int:
    return sum(len(scene_entries(scene, name)) for name in ("M", "C", "K"))


def _row_width(scene: Scene, name: str) -> int:
    """The largest number of nonzero entries in a row of ``scene.<name>``."""
    rows = np.array([i for i, _ in scene_entries(scene, name)], dtype=np.int64)
    return int(np.max(np.bincount(rows), initial=0)) if rows.size else 0


def _dense_stiffness(scene: Scene) -> bool:
    """Whether K is multiplied as a dense matrix (rows wider than a band of
    2·Limits.banded_max_bandwidth + 1)."""
    return _row_width(scene, "K") > 2 * limits().banded_max_bandwidth + 1


def refined_cost(scene: Scene, *, t_max: float, count: int, order: int) -> float:
    """Estimated seconds: the decomposition and its refinement, then ``count`` times. It
    does not depend on ``t_max``.

    The model (seconds on the development machine, OpenBLAS, fitted to uniform chains of
    200, 1,000 and 4,000 masses and dense K of 300 and 1,000 coordinates): reading the
    entries 5e-6 per nonzero; the float64 decomposition 2e-8·n² (banded) or 3e-10·n³
    (dense); double-double products 6e-8 per n² and per unit, units = 3·(w_K + 4) +
    (w_K + w_C + 9) for K's and C's row widths w (three refinement steps and the
    certificate); float64 n x n products 7e-11·n³ each, 5 of them (2 per full step, one for
    ΦᵀMΦ), or 58 for a dense K (13 per product with K); then per time
    1e-4 + 2e-7·n + 6e-10·n² (x = Φq), a third more per derivative order. Clusters
    (repeated frequencies) add ≈ 5 ms each, not counted (unknown before decomposing).

    >>> scene = Scene.from_matrices(M=[[1]], K=[[4]], x0=[1], v0=[0])
    >>> refined_cost(scene, t_max=1e6, count=100, order=0) == refined_cost(scene, t_max=1.0,
    ...                                                                   count=100, order=0)
    True
    """
    n = scene.n
    nnz = _stored_entries(scene)
    if _dense_stiffness(scene):
        decomposition, units, products = 3e-10 * n**3, 20, 58
    else:
        width_K, width_C = _row_width(scene, "K"), _row_width(scene, "C")
        decomposition, units, products = 2e-8 * n * n, 3 * (width_K + 4) + width_K + width_C + 9, 5
    build = 2e-3 + 5e-6 * nnz + decomposition + 6e-8 * units * n * n + 7e-11 * products * n**3
    per_time = (1e-4 + 2e-7 * n + 6e-10 * n * n) * (1 + order / 3)
    return build + count * per_time


def refined_motion(scene: Scene) -> RefinedMotion:
    """The motion of a scene :func:`refined_refusal` accepts (built on first use).

    Examples
    --------
    An undamped mass, x'' + 4x = 0, x(0) = 1, at t = 10⁹: cos(2·10⁹) to the last digit.

    >>> from laplace_springs.numeric.times import as_times
    >>> motion = refined_motion(Scene.from_matrices(M=[[1]], K=[[4]], x0=[1], v0=[0]))
    >>> values, bounds = motion.evaluate(as_times([1e9]), 0)
    >>> abs(float(values[0, 0]) - float(mpmath.cos(2 * mpmath.mpf(10) ** 9))) < 1e-15
    True
    >>> bool(bounds[0, 0] < 1e-15)
    True
    """
    return RefinedMotion(scene)


# ----------------------------------------------------------------------------- exact data


def _pair(entry: Any) -> tuple[float, float]:
    """An exact entry (flint fmpq, SymPy number) as a double-double (error ≤ u²|entry|)."""
    p = getattr(entry, "p", None)
    if p is not None and not isinstance(entry, sp.Basic) or isinstance(entry, sp.Rational):
        num, den = int(entry.p), int(entry.q)
        hi = num / den
        if den == 1 and abs(num) <= 2**53:
            return hi, 0.0
        return hi, float(Fraction(num, den) - Fraction(hi))
    with workdps(40):
        value = mpmath.mpf(sp.N(entry, 40)._mpf_)
        hi = float(value)
        return hi, float(value - hi)


@dataclass(frozen=True, eq=False)
class _Slots:
    """A sparse matrix by slots: row i's s-th nonzero is hi[s, i] + lo[s, i] (the
    double-double rounding of the exact entry) in column cols[s, i]; rows with fewer
    nonzeros are padded with zeros. ``identity[s]``: slot s is the diagonal."""

    cols: np.ndarray
    hi: np.ndarray
    lo: np.ndarray
    identity: tuple[bool, ...]

    @property
    def slots(self) -> int:
        return int(self.hi.shape[0])

    def absolute(self, X: np.ndarray) -> np.ndarray:
        """|A|·X for X ≥ 0 (float64; exact up to the factor 1 + γ_{slots+1})."""
        out = np.zeros_like(X)
        for s in range(self.slots):
            out += np.abs(self.hi[s])[:, None] * (X if self.identity[s] else X[self.cols[s]])
        return out

    def row_sums(self) -> np.ndarray:
        """Σ_j |A_ij| (float64, rounded up)."""
        return np.sum(np.abs(self.hi), axis=0) * _UP


def _slots(n: int, entries: dict[tuple[int, int], Any]) -> _Slots:
    if not entries:
        return _Slots(np.zeros((0, n), dtype=np.int64), np.zeros((0, n)), np.zeros((0, n)), ())
    keys = np.array(list(entries), dtype=np.int64).reshape(-1, 2)
    pairs = np.array([_pair(value) for value in entries.values()], dtype=float).reshape(-1, 2)
    order = np.lexsort((keys[:, 1], keys[:, 0]))
    keys, pairs = keys[order], pairs[order]
    rows = keys[:, 0]
    counts = np.bincount(rows, minlength=n)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    position = np.arange(len(rows)) - starts[rows]
    width = int(counts.max())
    cols = np.tile(np.arange(n, dtype=np.int64), (width, 1))
    hi, lo = np.zeros((width, n)), np.zeros((width, n))
    cols[position, rows] = keys[:, 1]
    hi[position, rows] = pairs[:, 0]
    lo[position, rows] = pairs[:, 1]
    identity = tuple(bool(np.array_equal(c, np.arange(n))) for c in cols)
    return _Slots(cols, hi, lo, identity)


def _extract(A: np.ndarray, axis: int, bits: int, count: int) -> tuple[list[np.ndarray], np.ndarray]:
    """A = Σ slices + rest exactly: each slice holds, per row (axis=1) or column (axis=0),
    multiples of 2^(e − bits) below 2^e(1 + 2^-bits), e the exponent of that row's (column's)
    largest remaining entry (Rump, Ogita & Oishi's extraction with σ = 2^(e + 53 − bits))."""
    rest = np.array(A, dtype=float, copy=True)
    slices = []
    for _ in range(count):
        largest = np.max(np.abs(rest), axis=axis, keepdims=True)
        _, exponent = np.frexp(largest)
        sigma = np.where(largest > 0, np.ldexp(1.0, exponent + 53 - bits), 0.0)
        piece = (rest + sigma) - sigma
        rest -= piece
        slices.append(piece)
    return slices, rest


@dataclass(frozen=True, eq=False)
class _Dense:
    """A dense matrix (hi + lo, the double-double rounding of the exact entries) whose
    products are formed from error-free slices by float64 BLAS (Ozaki et al., "Error-free
    transformations of matrix multiplication by using fast routines of matrix
    multiplication", Numer. Algorithms 59, 2012): slices of ``bits`` bits, 2·bits +
    ⌈log₂ n⌉ + 1 ≤ 53, so every product of two slices is exact whatever BLAS does."""

    hi: np.ndarray
    lo: np.ndarray
    slices: tuple[np.ndarray, ...]
    rest: np.ndarray
    bits: int

    @property
    def slots(self) -> int:
        return int(self.hi.shape[0])

    @property
    def identity(self) -> tuple[bool, ...]:
        return (False,)

    def absolute(self, X: np.ndarray) -> np.ndarray:
        return (np.abs(self.hi) @ X) * _UP

    def row_sums(self) -> np.ndarray:
        return np.sum(np.abs(self.hi), axis=1) * _UP


def _dense(slots: _Slots, n: int) -> _Dense:
    hi, lo = np.zeros((n, n)), np.zeros((n, n))
    rows = np.broadcast_to(np.arange(n), slots.cols.shape)
    np.add.at(hi, (rows, slots.cols), slots.hi)
    np.add.at(lo, (rows, slots.cols), slots.lo)
    bits = (52 - math.ceil(math.log2(max(n, 2)))) // 2
    pieces, rest = _extract(hi, 1, bits, 3)
    return _Dense(hi, lo, tuple(pieces), rest, bits)


def _sliced_product(Ah: np.ndarray, Al: np.ndarray, Bh: np.ndarray, Bl: np.ndarray,
                    a_slices: tuple[list[np.ndarray], np.ndarray] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(Ah + Al)(Bh + Bl) in double-double from 9 exact products of error-free slices
    (rows of A, columns of B) and 4 rounded small ones: |result − AB| ≤ (2γ_k u + 2^-60γ_k
    + 3u²)·|A||B| for an inner dimension k."""
    bits = (52 - math.ceil(math.log2(max(Ah.shape[1], 2)))) // 2
    pieces, rest = a_slices if a_slices is not None else _extract(Ah, 1, bits, 3)
    b_pieces, b_rest = _extract(Bh, 0, bits, 3)
    s = np.zeros((Ah.shape[0], Bh.shape[1]))
    err = (rest @ Bh + (Ah - rest) @ b_rest) + (Al @ Bh + Ah @ Bl)
    for a in pieces:
        for b in b_pieces:
            s, sigma = two_sum(s, a @ b)
            err += sigma
    return two_sum(s, err)


def _dense_apply(A: _Dense, Xh: np.ndarray, Xl: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A·X in double-double by :func:`_sliced_product` (A's slices made once)."""
    return _sliced_product(A.hi, A.lo, Xh, Xl, (list(A.slices), A.rest))


def _apply(A: _Slots | _Dense, Xh: np.ndarray, Xl: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A·X in double-double (Ogita–Rump–Oishi Dot2 over each row's slots, or
    :func:`_dense_apply`).

    |result − A_dd X| ≤ (3u² + 2γ_{2S}u)·|A||X| for S slots (S = n when dense), X = Xh + Xl
    and A_dd the double-double entries (which differ from the exact ones by ≤ u²|A|)."""
    if isinstance(A, _Dense):
        return _dense_apply(A, Xh, Xl)
    s = np.zeros_like(Xh)
    err = np.zeros_like(Xh)
    for k in range(A.slots):
        ah, al = A.hi[k][:, None], A.lo[k][:, None]
        xh, xl = (Xh, Xl) if A.identity[k] else (Xh[A.cols[k]], Xl[A.cols[k]])
        p, e = two_prod(ah, xh)
        s, sigma = two_sum(s, p)
        err += e + sigma + (ah * xl + al * xh)
    return two_sum(s, err)


def _dots(Xh: np.ndarray, Xl: np.ndarray, Yh: np.ndarray, Yl: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Σ_i X[i]·Y[i] over the first axis in double-double (error ≈ γ²_{2n}·Σ|X||Y|)."""
    p, e = two_prod(Xh, Yh)
    e = e + (Xh * Yl + Xl * Yh)
    return dd_sum(p, e)


def _matvec(Ph: np.ndarray, Pl: np.ndarray, qh: np.ndarray, ql: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Φ·q in double-double for q of shape (m,) or (m, r): exact products (two_prod) summed
    by :func:`~laplace_springs.kernels.dd.dd_sum`; error ≤ (3u² + 2γ_{2m}u)·|Φ||q|."""
    rows, m = Ph.shape
    qh2, ql2 = qh.reshape(m, -1), ql.reshape(m, -1)
    hi, lo = np.empty((rows, qh2.shape[1])), np.empty((rows, qh2.shape[1]))
    step = max(1, 2**21 // max(m, 1))
    for r in range(qh2.shape[1]):
        for a in range(0, rows, step):
            part = slice(a, min(a + step, rows))
            p, e = two_prod(Ph[part], qh2[:, r][None, :])
            e += Ph[part] * ql2[:, r][None, :] + Pl[part] * qh2[:, r][None, :]
            hi[part, r], lo[part, r] = dd_sum(p.T, e.T)
    return hi.reshape((rows, *qh.shape[1:])), lo.reshape((rows, *qh.shape[1:]))


@dataclass(frozen=True, eq=False)
class _Exact:
    """The scene's exact entries as double-doubles, and the norms the bound needs."""

    n: int
    M: _Slots
    C: _Slots | _Dense | None
    K: _Slots | _Dense
    x0: tuple[np.ndarray, np.ndarray]
    v0: tuple[np.ndarray, np.ndarray]
    mu: float          # ≤ λ_min(M)
    mass_norm: float   # ≥ ‖M‖₂
    stiffness: float   # ≥ ‖M^{-1/2} K M^{-1/2}‖₂
    damping: float     # ≥ ‖M^{-1/2} C M^{-1/2}‖₂
    K_psd: bool        # K ⪰ 0 proved (diagonal dominance)
    C_psd: bool        # C ⪰ 0 proved
    K_rows: tuple[np.ndarray, np.ndarray]   # K's float64 row sums Σ_j K_ij and Σ_j |K_ij|


def _dominant(entries: dict[tuple[int, int], Any], n: int, slots: _Slots) -> bool:
    """Whether a symmetric exact matrix is diagonally dominant with a non-negative
    diagonal (hence positive semi-definite): decided in float64 where the margin exceeds
    the rounding, exactly otherwise."""
    if not entries:
        return True
    on = slots.cols == np.arange(n)[None, :]
    diagonal_f = np.sum(np.where(on, slots.hi, 0.0), axis=0)
    off_f = np.sum(np.where(on, 0.0, np.abs(slots.hi)), axis=0)
    margin = (slots.slots + 4) * U * (np.abs(diagonal_f) + off_f)
    if np.any(diagonal_f - off_f < -margin):
        return False
    if np.all(diagonal_f - off_f > margin):
        return True
    diagonal = [Fraction(0)] * n
    off = [Fraction(0)] * n
    for (i, j), value in entries.items():
        q = Fraction(int(value.p), int(value.q)) if hasattr(value, "q") else Fraction(str(value))
        if i == j:
            diagonal[i] = q
        else:
            off[i] += abs(q)
    return all(d >= o for d, o in zip(diagonal, off))


def _mass_floor(n: int, entries: dict[tuple[int, int], Any]) -> float:
    """A proved lower bound on λ_min(M) for a dense M (n ≤ Limits.dense_check_max_coordinates):
    half the float64 estimate, checked by the signs of the leading minors of M − σI."""
    dense = np.zeros((n, n))
    for (i, j), value in entries.items():
        dense[i, j] = _pair(value)[0]
    sigma = 0.5 * float(np.linalg.eigvalsh(dense)[0])
    if not sigma > 0:
        return 0.0
    shifted = fmpq_mat(n, n)
    for (i, j), value in entries.items():
        shifted[i, j] = value
    shift = Fraction(sigma)
    for i in range(n):
        shifted[i, i] = shifted[i, i] - fmpq(shift.numerator, shift.denominator)
    for k in range(1, n + 1):
        minor = fmpq_mat(k, k, [shifted[i, j] for i in range(k) for j in range(k)])
        if not minor.det() > 0:
            return 0.0
    return sigma


def _exact_data(scene: Scene) -> _Exact:
    n = scene.n
    entries = {name: rational_entries(scene, name) for name in ("M", "C", "K")}
    if any(e is None for e in entries.values()):
        raise InternalError("the refined engine was given a scene with irrational M, C or K")
    Me, Ce, Ke = (entries[name] or {} for name in ("M", "C", "K"))
    M = _slots(n, Me)
    wide = 2 * limits().banded_max_bandwidth + 1  # beyond: dense, exact slices and BLAS
    K_slots = _slots(n, Ke)
    C_slots = _slots(n, Ce) if Ce else None
    K = _dense(K_slots, n) if K_slots.slots > wide else K_slots
    C = _dense(C_slots, n) if C_slots is not None and C_slots.slots > wide else C_slots
    vectors = []
    for name in ("x0", "v0"):
        hi, lo = np.zeros(n), np.zeros(n)
        for (i, _), value in scene_entries(scene, name).items():
            hi[i], lo[i] = _pair(value)
        vectors.append((hi, lo))
    diagonal = all(i == j for i, j in Me)
    if diagonal:
        mass = M.hi[0]
        mu = float(np.min(mass)) * (1 - 2 * U)
        root = np.sqrt(mass)
        stiffness = float(np.max(K.absolute(np.ones((n, 1)) / root[:, None])[:, 0] / root)) * _UP**2
        damping = float(np.max(C.absolute(np.ones((n, 1)) / root[:, None])[:, 0] / root)) * _UP**2 if C else 0.0
    else:
        mu = _mass_floor(n, Me)
        stiffness = float(np.max(K.row_sums())) / mu if mu > 0 else math.inf
        damping = (float(np.max(C.row_sums())) / mu if mu > 0 else math.inf) if C else 0.0
    K_rows = (np.sum(K_slots.hi, axis=0), np.sum(np.abs(K_slots.hi), axis=0))
    return _Exact(n, M, C, K, vectors[0], vectors[1], mu, float(np.max(M.row_sums())),
                  stiffness, damping, _dominant(Ke, n, K_slots),
                  C_slots is None or _dominant(Ce, n, C_slots), K_rows)


# ----------------------------------------------------------------------------- refinement


def _clusters(theta: np.ndarray) -> list[np.ndarray]:
    """Runs of modes whose frequencies ω = √θ (−√−θ for θ < 0) are closer than
    Limits.close_poles · max|ω|: the package's rule for close poles ±iω (size ≥ 2).

    Outside a cluster θ_k − θ_j ≥ close_poles²·max θ, so a correction W_kj/(θ_j − θ_k)
    of float64 pairs (W ≈ u‖K‖) is at most ≈ 1e-4: the refinement converges."""
    if theta.size < 2:
        return []
    omega = np.sign(theta) * np.sqrt(np.abs(theta))
    return clusters(omega, limits().close_poles * max(float(np.max(np.abs(omega))), 1e-300))


def _column_blocks(n: int, m: int) -> list[slice]:
    width = max(1, min(m, 2**22 // max(n, 1)))
    return [slice(a, min(a + width, m)) for a in range(0, m, width)]


@dataclass
class _Pairs:
    """Eigenpairs as double-doubles: θ = th + tl, Φ = Ph + Pl."""

    th: np.ndarray
    tl: np.ndarray
    Ph: np.ndarray
    Pl: np.ndarray
    clusters: list[np.ndarray] = field(default_factory=list)
    steps: int = 0
    residual: float = math.inf   # the last max relative residual measured
    null: np.ndarray | None = None   # modes that are exact null vectors of K (θ = 0, R_K = 0)


def _mass_apply(ex: _Exact, Xh: np.ndarray, Xl: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return _apply(ex.M, Xh, Xl)


def _newton_step(ex: _Exact, pairs: _Pairs, mask: np.ndarray | None, floor: float) -> float:
    """One refinement step (module notes); returns the max relative residual measured
    before it. At or below ``floor`` the pairs are left as they are."""
    n = ex.n
    Ph, Pl, th, tl = pairs.Ph, pairs.Pl, pairs.th, pairs.tl
    R = np.empty((n, n))
    N = np.empty(n)       # φ_jᵀMφ_j in float64: the normalisation needs no more (module notes)
    scale = np.empty(n)   # ‖|K||φ_j| + |θ_j|·|M||φ_j|‖: the level a residual is measured against
    for B in _column_blocks(n, n):
        KXh, KXl = _apply(ex.K, Ph[:, B], Pl[:, B])
        MXh, MXl = _mass_apply(ex, Ph[:, B], Pl[:, B])
        TXh, TXl = dd_mul(MXh, MXl, th[B][None, :], tl[B][None, :])
        R[:, B] = dd_add(KXh, KXl, -TXh, -TXl)[0]
        N[B] = np.einsum("ij,ij->j", Ph[:, B], MXh)
        absolute = np.abs(Ph[:, B])
        scale[B] = np.linalg.norm(ex.K.absolute(absolute) + np.abs(th[B]) * ex.M.absolute(absolute), axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        relative = float(np.max(np.where(scale > 0, np.linalg.norm(R, axis=0) / scale, 0.0), initial=0.0))
    if relative <= floor:
        return relative
    W = Ph.T @ R
    del R
    # Rayleigh quotients θ + φᵀr/φᵀMφ, then the first-order correction of the shapes
    shift = np.diagonal(W) / N
    pairs.th, pairs.tl = dd_add(th, tl, shift, np.zeros(n))
    defect = 1.0 - N
    with np.errstate(divide="ignore", invalid="ignore"):
        W /= pairs.th[None, :] - pairs.th[:, None]
    if mask is not None:
        W[mask] = 0.0
    W[np.diag_indices(n)] = defect / 2
    W[~np.isfinite(W)] = 0.0
    update = Ph @ W
    del W
    pairs.Ph, pairs.Pl = dd_add(Ph, Pl, update, np.zeros_like(update))
    return relative


def _cluster_mask(n: int, clusters: list[np.ndarray]) -> np.ndarray | None:
    if not clusters:
        return None
    mask = np.zeros((n, n), dtype=bool)
    for group in clusters:
        mask[np.ix_(group, group)] = True
    return mask


def _pieces(clusters: list[np.ndarray]) -> list[np.ndarray]:
    """Clusters cut to at most Limits.refined_max_cluster members (module notes)."""
    cap = max(2, limits().refined_max_cluster)
    return [group[a:a + cap] for group in clusters for a in range(0, len(group), cap)
            if len(group[a:a + cap]) > 1]


def _to_mp(hi: np.ndarray, lo: np.ndarray) -> Any:
    rows, cols = hi.shape
    return mpmath.matrix([[mpmath.mpf(float(hi[i, j])) + mpmath.mpf(float(lo[i, j]))
                           for j in range(cols)] for i in range(rows)])


def _from_mp(value: Any) -> tuple[float, float]:
    hi = float(value)
    return hi, float(value - hi)


def _ritz(SK: tuple[np.ndarray, np.ndarray], SC: tuple[np.ndarray, np.ndarray] | None,
          N: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray, list[tuple[float, float]]]:
    """The generalised eigenvectors Y (hi, lo) of (S_K + γS_C, N) at 40 digits (NᵀY N = I),
    with γ weighting C like K in this cluster, and the Rayleigh quotients of S_K."""
    k = SK[0].shape[0]
    with workdps(40):
        K_mp, N_mp = _to_mp(*SK), _to_mp(*N)
        A = K_mp
        if SC is not None:
            C_mp = _to_mp(*SC)
            c_max = max(abs(C_mp[i, i]) for i in range(k))
            theta_max = max(abs(K_mp[i, i]) for i in range(k))
            if c_max > 0 and theta_max > 0:
                A = K_mp + C_mp * (mpmath.mpf("0.6180339887498949") * theta_max / c_max)
        Li = mpmath.inverse(mpmath.cholesky((N_mp + N_mp.T) / 2))
        B = Li * A * Li.T
        _, V = mpmath.eigsy((B + B.T) / 2)
        Y = Li.T * V
        thetas = [_from_mp((Y[:, a].T * K_mp * Y[:, a])[0] / (Y[:, a].T * N_mp * Y[:, a])[0])
                  for a in range(k)]
        pairs = [[_from_mp(Y[b, a]) for a in range(k)] for b in range(k)]
    Yh = np.array([[v[0] for v in row] for row in pairs])
    Yl = np.array([[v[1] for v in row] for row in pairs])
    return Yh, Yl, thetas


def _diagonal_already(SK: tuple[np.ndarray, np.ndarray], SC: tuple[np.ndarray, np.ndarray] | None,
                      N: tuple[np.ndarray, np.ndarray]) -> bool:
    """Whether a cluster's basis is M-orthonormal and diagonalises K and C to 2^-100."""
    tiny = 2.0**-100
    k = N[0].shape[0]
    off = ~np.eye(k, dtype=bool)
    if np.max(np.abs((N[0] - np.eye(k)) + N[1])) > tiny:
        return False
    for S in (SK, SC):
        if S is not None and np.max(np.abs(S[0][off]), initial=0.0) > tiny * np.max(np.abs(np.diagonal(S[0]))):
            return False
    return True


def _rayleigh_ritz(ex: _Exact, pairs: _Pairs) -> None:
    """Diagonalise K + γC in each cluster's subspace at 40 digits (module notes); clusters
    whose basis already does are left alone."""
    pieces = _pieces(pairs.clusters)
    if not pieces:
        return
    columns = np.concatenate(pieces)
    Xh, Xl = pairs.Ph[:, columns], pairs.Pl[:, columns]
    products = [_apply(ex.K, Xh, Xl), _mass_apply(ex, Xh, Xl)]
    if ex.C is not None:
        products.append(_apply(ex.C, Xh, Xl))
    at = 0
    for group in pieces:
        k = len(group)
        part = slice(at, at + k)
        at += k
        xh, xl = Xh[:, part], Xl[:, part]
        grams = [_dots(xh[:, :, None], xl[:, :, None], Y[0][:, None, part], Y[1][:, None, part])
                 for Y in products]
        SK, N = grams[0], grams[1]
        SC = grams[2] if len(grams) > 2 else None
        if _diagonal_already(SK, SC, N):
            continue
        Yh, Yl, thetas = _ritz(SK, SC, N)
        s = np.zeros((xh.shape[0], k))
        err = np.zeros_like(s)
        for b in range(k):
            p, e = two_prod(xh[:, b:b + 1], Yh[b][None, :])
            s, sigma = two_sum(s, p)
            err += e + sigma + (xh[:, b:b + 1] * Yl[b][None, :] + xl[:, b:b + 1] * Yh[b][None, :])
        pairs.Ph[:, group], pairs.Pl[:, group] = two_sum(s, err)
        pairs.th[group] = [v[0] for v in thetas]
        pairs.tl[group] = [v[1] for v in thetas]


def _refine(ex: _Exact, theta: np.ndarray, phi: np.ndarray) -> _Pairs:
    """Refine float64 eigenpairs of (K, M) until the residuals reach the double-double
    level (or stop decreasing), within Limits.refined_max_steps steps."""
    pairs = _Pairs(theta.astype(float).copy(), np.zeros_like(theta, dtype=float),
                   np.array(phi, dtype=float, copy=True), np.zeros_like(phi, dtype=float))
    pairs.clusters = _clusters(pairs.th)
    mask = _cluster_mask(ex.n, pairs.clusters)
    slots = ex.K.slots + ex.M.slots
    floor = (4 * slots + 64) * U * U
    previous = math.inf
    _rayleigh_ritz(ex, pairs)
    for step in range(limits().refined_max_steps):
        relative = _newton_step(ex, pairs, mask, floor)
        pairs.residual = relative
        if relative <= floor:
            break
        pairs.steps = step + 1
        if step >= 1 and relative > previous / 16:
            break
        previous = relative
    if pairs.steps:  # the steps keep each cluster's subspace; its basis is set here once more
        _rayleigh_ritz(ex, pairs)
    return pairs


def _free_components(scene: Scene, ex: _Exact) -> list[np.ndarray]:
    """The free parts of a spring network: connected components c of K's graph with
    K·1_c = 0 exactly (zero row sums), a diagonal M, and 1_cᵀC1_d = 0 for c ≠ d, so that
    the vectors 1_c are exact, M-orthogonal null vectors of K that C keeps apart (rigid
    modes θ = 0, q = a + b·t). Time ∝ nonzero entries."""
    n = scene.n
    total, size = ex.K_rows
    maybe = np.abs(total) <= (ex.K.slots + 4) * U * size  # the others surely sum to nonzero
    if not np.any(maybe) or not all(ex.M.identity):
        return []
    M, C, K = (rational_entries(scene, name) or {} for name in ("M", "C", "K"))
    parent = list(range(n))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for i, j in K:
        parent[root(i)] = root(j)
    sums: dict[int, Fraction] = {}
    for (i, _), value in K.items():
        if maybe[i]:
            sums[i] = sums.get(i, Fraction(0)) + Fraction(int(value.p), int(value.q))
    labels = np.array([root(i) for i in range(n)])
    fixed = {int(labels[i]) for i in np.flatnonzero(~maybe)}
    fixed |= {int(labels[i]) for i, row_sum in sums.items() if row_sum != 0}
    free = {int(c) for c in np.unique(labels)} - fixed
    for (i, j), value in C.items():
        if labels[i] != labels[j] and labels[i] in free and labels[j] in free and value != 0:
            return []  # a dashpot couples two free parts: their rigid modes are not 1_c
    return [np.flatnonzero(labels == c) for c in sorted(free)]


def _exact_rigid_modes(ex: _Exact, pairs: _Pairs, components: list[np.ndarray]) -> None:
    """Replace the refined rigid modes by the exact null vectors 1_c/√m_c of K when the
    r = len(components) smallest |θ| are separated from the others (module notes)."""
    r = len(components)
    if not r or r >= len(pairs.th) + 1:
        return
    order = np.argsort(np.abs(pairs.th))
    largest = float(np.max(np.abs(pairs.th)))
    tiny = limits().close_poles ** 2 * largest
    if np.abs(pairs.th[order[r - 1]]) > tiny or (r < len(order) and np.abs(pairs.th[order[r]]) <= tiny):
        return
    mass = ex.M.hi[0]
    null = np.zeros(len(pairs.th), dtype=bool)
    for column, members in zip(order[:r], components):
        pairs.Ph[:, column] = 0.0
        pairs.Pl[:, column] = 0.0
        pairs.Ph[members, column] = 1 / math.sqrt(float(np.sum(mass[members])))
        pairs.th[column] = pairs.tl[column] = 0.0
        null[column] = True
    pairs.null = null


# ----------------------------------------------------------------------------- certificate


@dataclass(frozen=True, eq=False)
class _Modes:
    """The refined modes and every constant of the error bound (module notes)."""

    th: np.ndarray         # θ̃ (hi, lo)
    tl: np.ndarray
    ch: np.ndarray         # c̃ (hi, lo)
    cl: np.ndarray
    Ph: np.ndarray         # Φ̃ = Ph + Pl
    Pl: np.ndarray
    q0: tuple[np.ndarray, np.ndarray]     # q̃(0) (hi, lo)
    dq0: tuple[np.ndarray, np.ndarray]    # q̃'(0)
    rho_K: np.ndarray      # ≥ ‖R_K,j‖_{M⁻¹}
    rho_C: np.ndarray      # ≥ ‖R_C,j‖_{M⁻¹}
    e0: float              # ≥ ‖e(0)‖_M
    e1: float              # ≥ ‖e'(0)‖_M
    theta_low: float       # ≤ λ_min(K, M)
    delta_C: float         # ≥ max(0, −λ_min(C, M))
    colmax: np.ndarray     # max_i |Ph_ij|
    steps: int
    residual: float


def _perturbation(values: np.ndarray, residual_norm: float, g: float, mu: float) -> float:
    """Δ with |λ_i(A, M) − λ̃_(i)| ≤ Δ, from the residual ‖AΦ − MΦΛ‖_F ≤ residual_norm and
    ‖ΦᵀMΦ − I‖₂ ≤ g < 1/2 (congruence by Φ, then Weyl; module notes)."""
    if not g < 0.5 or mu <= 0:
        return math.inf
    d = 1 / math.sqrt(1 - g) - 1
    size = float(np.max(np.abs(values), initial=0.0))
    F = g * size + math.sqrt((1 + g) / mu) * residual_norm
    return ((2 * d + d * d) * size + (1 + d) ** 2 * F) * _UP


def _normalise(ex: _Exact, pairs: _Pairs) -> None:
    """Scale each shape to φ_jᵀMφ_j = 1 in double-double (the steps normalise in float64
    only; an exact null vector stays one: all its entries are scaled alike)."""
    for B in _column_blocks(ex.n, ex.n):
        MX = _mass_apply(ex, pairs.Ph[:, B], pairs.Pl[:, B])
        Nh, Nl = _dots(pairs.Ph[:, B], pairs.Pl[:, B], *MX)
        with np.errstate(divide="ignore", invalid="ignore"):
            sh, sl = dd_sqrt(*dd_div(np.ones_like(Nh), np.zeros_like(Nh), Nh, Nl))
        usable = np.isfinite(sh) & (Nh > 0)
        sh, sl = np.where(usable, sh, 1.0), np.where(usable, sl, 0.0)
        pairs.Ph[:, B], pairs.Pl[:, B] = dd_mul(pairs.Ph[:, B], pairs.Pl[:, B], sh[None, :], sl[None, :])


def _certify(ex: _Exact, pairs: _Pairs) -> _Modes:
    n = ex.n
    _normalise(ex, pairs)
    Ph, Pl, th, tl = pairs.Ph, pairs.Pl, pairs.th, pairs.tl
    ch, cl = np.zeros(n), np.zeros(n)
    rK, rC = np.empty(n), np.zeros(n)
    aK, aC = np.empty(n), np.zeros(n)
    absP = np.abs(Ph)
    diagonal = all(ex.M.identity)
    G_frob2 = 0.0
    trace = 0.0
    for B in _column_blocks(n, n):
        KX = _apply(ex.K, Ph[:, B], Pl[:, B])
        MX = _mass_apply(ex, Ph[:, B], Pl[:, B])
        N = _dots(Ph[:, B], Pl[:, B], *MX)
        TX = dd_mul(*MX, th[B][None, :], tl[B][None, :])
        R = dd_add(*KX, -TX[0], -TX[1])
        rK[B] = _norms(R[0]) * (1 + 2 * U)
        MA = ex.M.absolute(absP[:, B])
        aK[B] = _norms(ex.K.absolute(absP[:, B]) + np.abs(th[B]) * MA) * _UP
        if ex.C is not None:
            CX = _apply(ex.C, Ph[:, B], Pl[:, B])
            S = _dots(Ph[:, B], Pl[:, B], *CX)
            ch[B], cl[B] = dd_div(*S, *N)
            CT = dd_mul(*MX, ch[B][None, :], cl[B][None, :])
            RC = dd_add(*CX, -CT[0], -CT[1])
            rC[B] = _norms(RC[0]) * (1 + 2 * U)
            aC[B] = _norms(ex.C.absolute(absP[:, B]) + np.abs(ch[B]) * MA) * _UP
        G = Ph.T @ MX[0]
        G[B.start + np.arange(B.stop - B.start), np.arange(B.stop - B.start)] -= 1.0
        G_frob2 += float(np.sum(G * G))
        trace += float(np.sum(absP[:, B] * MA)) if diagonal else ex.mass_norm * float(np.sum(absP[:, B] ** 2))
    slots = max(ex.K.slots, ex.C.slots if ex.C is not None else 0) + ex.M.slots
    rounding = (6 * slots + 40) * U * U
    rK_true = rK + rounding * aK
    if pairs.null is not None:  # K·1_c = 0 exactly and θ = 0: no residual at all
        rK_true[pairs.null] = 0.0
    rC_true = rC + rounding * aC
    root_mu = math.sqrt(ex.mu) if ex.mu > 0 else 0.0
    with np.errstate(divide="ignore"):
        rho_K = rK_true / root_mu if root_mu else np.full(n, math.inf)
        rho_C = rC_true / root_mu if root_mu else np.full(n, math.inf)
    mass_rounding = ex.M.slots + 2
    g = (math.sqrt(G_frob2) * _UP + (2 * _gamma(n + mass_rounding) + 6 * U) * trace) * _UP
    residual_K = float(_norms(rK_true[:, None])[0])
    theta_low = float(np.min(th + tl)) - _perturbation(th, residual_K, g, ex.mu)
    if theta_low <= 0 < float(np.min(th)) and pairs.null is None:
        # a wide spread of θ: float64's ΦᵀMΦ loses θ_min; form it in double-double
        g = _orthogonality_dd(ex, Ph, Pl, trace)
        theta_low = float(np.min(th + tl)) - _perturbation(th, residual_K, g, ex.mu)
    if ex.C is None or ex.C_psd:
        delta_C = 0.0
    else:
        spread = _perturbation(ch, float(_norms(rC_true[:, None])[0]), g, ex.mu)
        delta_C = max(0.0, spread - float(np.min(ch + cl)))
    q0, dq0, e0, e1 = _initial_data(ex, Ph, Pl)
    return _Modes(th, tl, ch, cl, Ph, Pl, q0, dq0, rho_K, rho_C, e0, e1, theta_low, delta_C,
                  np.max(absP, axis=0) if n else np.zeros(0), pairs.steps, pairs.residual)


def _orthogonality_dd(ex: _Exact, Ph: np.ndarray, Pl: np.ndarray, trace: float) -> float:
    """‖Φ̃ᵀMΦ̃ − I‖₂ bounded from a double-double product (13 float64 n x n products);
    ``trace`` ≥ ‖|Φ|ᵀ|M||Φ|‖₂."""
    n = ex.n
    MXh, MXl = _mass_apply(ex, Ph, Pl)
    Gh, Gl = _sliced_product(np.ascontiguousarray(Ph.T), np.ascontiguousarray(Pl.T), MXh, MXl)
    Gh[np.diag_indices(n)] -= 1.0
    defect = float(np.sqrt(np.sum((np.abs(Gh) + np.abs(Gl)) ** 2))) * _UP
    rounding = (2 * _gamma(n + 2) * U + 2.0**-60 * _gamma(n + 2) + (ex.M.slots + 12) * U * U) * trace
    return (defect + rounding) * _UP


def _initial_data(ex: _Exact, Ph: np.ndarray, Pl: np.ndarray) -> tuple[Any, Any, float, float]:
    """q̃(0), q̃'(0) with Φ̃q̃ = x0, v0 to double-double accuracy (Φᵀ M as the approximate
    inverse, corrections from double-double residuals), and ‖e(0)‖_M, ‖e'(0)‖_M."""
    n = ex.n
    rhs_h = np.stack([ex.x0[0], ex.v0[0]], axis=1)
    rhs_l = np.stack([ex.x0[1], ex.v0[1]], axis=1)
    MR = _mass_apply(ex, rhs_h, rhs_l)
    qh, ql = Ph.T @ MR[0], np.zeros((n, 2))
    for _ in range(limits().refined_max_steps):
        xh, xl = _matvec(Ph, Pl, qh, ql)
        res = dd_add(rhs_h, rhs_l, -xh, -xl)
        if not np.any(res[0]):
            break
        correction = Ph.T @ _mass_apply(ex, res[0], res[1])[0]
        qh, ql = dd_add(qh, ql, correction, np.zeros_like(correction))
        if np.max(np.abs(correction)) <= 1e-3 * U * max(float(np.max(np.abs(qh))), 1e-300):
            break  # the next residual is ≈ ‖ΦᵀMΦ − I‖ times this: below u²
    xh, xl = _matvec(Ph, Pl, qh, ql)
    res = dd_add(xh, xl, -rhs_h, -rhs_l)
    bound = (np.abs(res[0]) * (1 + 2 * U) + (3 * U * U + 2 * _gamma(2 * n) * U) * _UP
             * (np.abs(Ph) @ np.abs(qh)) * (1 + _gamma(n + 1) + 2 * U)
             + 2 * U * U * np.abs(rhs_h))
    energy = _mass_norms(ex, bound)
    return (qh[:, 0], ql[:, 0]), (qh[:, 1], ql[:, 1]), energy[0], energy[1]


def _mass_norms(ex: _Exact, vectors: np.ndarray) -> np.ndarray:
    """Upper bounds on ‖v‖_M = √(vᵀMv) for each column of a non-negative array."""
    if all(ex.M.identity):
        return np.sqrt(np.sum(ex.M.hi[0][:, None] * vectors**2, axis=0)) * _UP
    return math.sqrt(ex.mass_norm) * _norms(vectors) * _UP


# ----------------------------------------------------------------------------- modal functions


@dataclass(frozen=True, eq=False)
class _Scalars:
    """Per mode: h = c/2, δ = θ − h² (double-double), the branch, ω (under) or g (over),
    and the rounding constants of the closed forms."""

    h: np.ndarray
    theta: np.ndarray
    under: np.ndarray
    wh: np.ndarray          # ω = √δ (hi, lo) where under, else 0
    wl: np.ndarray
    eta: np.ndarray         # relative error of ω (where under) or of g (over)
    ddelta: np.ndarray      # ≥ |computed δ − δ̃| (the δ-sensitivity forms)
    g: np.ndarray           # √(−δ) where over, else 0
    big: np.ndarray         # λ_big (over)
    small: np.ndarray       # λ_small (over)
    rate: np.ndarray        # the largest real part of the mode's poles


def _scalars(m: _Modes) -> _Scalars:
    hh, hl = m.ch / 2, m.cl / 2
    sq = dd_mul(hh, hl, hh, hl)
    dh, dl = dd_add(m.th, m.tl, -sq[0], -sq[1])
    size = np.abs(m.th) + sq[0]
    ddelta = 12 * U * U * size + U * U * np.abs(dh)   # dd_mul 7u², dd_add 3u², the low part
    under = dh > 0
    wh, wl = dd_sqrt(np.where(under, dh, 0.0), np.where(under, dl, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        eta_w = np.where(under, ddelta / (2 * np.abs(dh)) + 4 * U * U, 0.0)
        g = np.where(under, 0.0, np.sqrt(np.maximum(-(dh + dl), 0.0)))
        eta_g = np.where(under, 0.0, (U * np.abs(dh) + ddelta) / (2 * np.abs(dh)) + 1.5 * U)
    h, theta = hh, m.th
    with np.errstate(divide="ignore", invalid="ignore"):
        small_pos = -(h + g)
        big_pos = np.where(small_pos < 0, theta / np.where(small_pos < 0, small_pos, 1.0), 0.0)
        big_neg = g - h
        small_neg = np.where(big_neg > 0, theta / np.where(big_neg > 0, big_neg, 1.0), 0.0)
    big = np.where(under, 0.0, np.where(h >= 0, big_pos, big_neg))
    small = np.where(under, 0.0, np.where(h >= 0, small_pos, small_neg))
    rate = np.where(under, -h, big)
    eta = np.where(under, eta_w, np.where(np.isfinite(eta_g), eta_g, math.inf))
    return _Scalars(h, theta, under, wh, wl, eta, ddelta + 4 * U * np.abs(dh) * ~under, g, big, small,
                    rate)


def _coefficients(m: _Modes, order: int) -> tuple[np.ndarray, ...]:
    """(u_k, w_k, err_u, err_w) with q^(k) = u_k·e^{−ht}C + w_k·e^{−ht}S (float64), and
    bounds on their errors against the exact recurrence u_{j+1} = −c̃u_j − θ̃u_{j−1} from
    θ̃, c̃, q̃(0), q̃'(0) (the low parts of the double-doubles are the errors of the highs)."""
    theta, c = m.th, m.ch
    u = [m.q0[0], m.dq0[0]]
    err = [np.abs(m.q0[1]), np.abs(m.dq0[1])]
    for _ in range(order + 1):
        term_c, term_t = c * u[-1], theta * u[-2]
        err.append(np.abs(c) * err[-1] + np.abs(theta) * err[-2] + np.abs(m.cl * u[-1])
                   + np.abs(m.tl * u[-2]) + _gamma(2) * (np.abs(term_c) + np.abs(term_t)))
        u.append(-term_c - term_t)
    h = c / 2
    w = u[order + 1] + h * u[order]
    err_u = err[order] * _UP
    err_w = (err[order + 1] + np.abs(h) * err[order] + np.abs(m.cl / 2 * u[order])
             + _gamma(2) * (np.abs(u[order + 1]) + np.abs(h * u[order]))) * _UP
    return u[order], w, err_u, err_w


def _closed_forms(s: _Scalars, th: np.ndarray, tl: np.ndarray) -> tuple[np.ndarray, ...]:
    """e^{−ht}C(t), e^{−ht}S(t) (modes x times), bounds on their errors, and
    sup_{r≤t}|e^{−hr}C|, sup_{r≤t}|e^{−hr}S| of the exact functions."""
    t = th[None, :]
    tlo = np.abs(tl)[None, :]
    t_up = t * (1 + 2 * U) + tlo
    Cf = np.zeros((len(s.h), len(th)))
    Sf, dC, dS, supC, supS = (np.zeros_like(Cf) for _ in range(5))
    with np.errstate(over="ignore", invalid="ignore", divide="ignore", under="ignore"):
        rate_error = 12 * U + np.where(s.under | ~np.isfinite(s.eta), 0.0, s.eta)
        growth = np.exp(np.maximum(s.rate, 0.0)[:, None] * t_up * (1 + rate_error)[:, None]) * (1 + 4 * U)
        supC[:] = growth
        if s.under.any():
            i = s.under
            h = s.h[i][:, None]
            w = s.wh[i][:, None]
            cos, sin, rel = phase(s.wh[i][:, None], s.wl[i][:, None], t, tl[None, :])
            ht = h * t
            D = np.exp(-ht)
            eps_D = (2 * np.abs(ht) + 2) * U + np.abs(h) * tlo * 1.01
            eta = s.eta[i][:, None]
            S_abs = np.minimum(t_up, 1 / w)
            phi = w * t
            formed = phi * (rel + 4 * U * U) + w * tlo * U   # forming ωt (and t's own rounding)
            shifted = phi * eta                              # ω's error, through the phase
            dd = s.ddelta[i][:, None] + 8 * U * U * w * w    # the same, as an error of δ
            Cf[i] = D * cos
            Sf[i] = D * sin / w
            # through δ: |∂C/∂δ| ≤ t·min(t, 1/ω), |∂S/∂δ| ≤ t²·min(t, 1/ω) ≤ t³ (any ω on the way)
            dC[i] = D * (3 * U * np.abs(cos) + formed + np.minimum(shifted, t_up * t_up * dd)) \
                + np.abs(Cf[i]) * (eps_D + U)
            dS[i] = D * (5 * U * np.abs(sin) / w + formed / w
                         + np.minimum((shifted + np.abs(sin) * eta) / w, t_up**3 * dd)) \
                + np.abs(Sf[i]) * (eps_D + U)
            supS[i] = growth[i] * S_abs
        over = ~s.under
        if over.any():
            i = over
            big, small, g = s.big[i][:, None], s.small[i][:, None], s.g[i][:, None]
            P, Q = np.exp(big * t), np.exp(small * t)
            eps_P = (6 * U) * np.abs(big * t) + np.abs(big) * tlo * 1.01 + 2 * U
            eps_Q = (6 * U) * np.abs(small * t) + np.abs(small) * tlo * 1.01 + 2 * U
            eta = s.eta[i][:, None]
            factor = np.where(g > 0, -np.expm1(-2 * g * t) / (2 * np.where(g > 0, g, 1.0)), t)
            Cf[i] = (P + Q) / 2
            Sf[i] = P * factor
            dd = s.ddelta[i][:, None]
            base_C = (np.abs(P) * eps_P + np.abs(Q) * eps_Q) / 2 + U * np.abs(Cf[i])
            base_S = np.abs(Sf[i]) * (eps_P + 6 * U)
            known = np.isfinite(eta)   # g's relative error (infinite at δ = 0: critical)
            eta = np.where(known, eta, 0.0)
            spread_C = np.where(known, (np.abs(big * t) * np.abs(P) + np.abs(small * t) * np.abs(Q)) / 2
                                * eta, np.inf)
            spread_S = np.where(known, np.abs(Sf[i]) * (np.abs(big * t) + 2) * eta, np.inf)
            # through δ: |∂C/∂δ| ≤ t·S/2, |∂S/∂δ| ≤ t²·S/2 (S nearly constant on the way)
            dC[i] = base_C + np.minimum(spread_C, t_up * np.abs(Sf[i]) * dd)
            dS[i] = base_S + np.minimum(spread_S, t_up * t_up * np.abs(Sf[i]) * dd)
            supS[i] = growth[i] * np.where(g > 0, np.minimum(t_up, 1 / (2 * np.where(g > 0, g, 1.0))), t_up)
    return Cf, Sf, dC, dS, supC, supS


# ----------------------------------------------------------------------------- the motion


class RefinedMotion:
    """x(t) of a classically damped or undamped scene from refined modes (module notes).

    The decomposition and its refinement are made on first use (:attr:`modes`).

    Attributes
    ----------
    n : int
        Coordinates.
    """

    #: The engine's name in the planner's vocabulary (``Solution.method``).
    engine = "refined"

    def __init__(self, scene: Scene) -> None:
        self.scene = scene
        self.n = scene.n
        self._coefficient_cache: dict[int, tuple[np.ndarray, ...]] = {}

    @cached_property
    def _exact(self) -> _Exact:
        return _exact_data(self.scene)

    @cached_property
    def data(self) -> SymmetricScene:
        """The float64 data of the scene (as :mod:`~laplace_springs.numeric.classical` reads it)."""
        return symmetric_scene(self.scene)

    @cached_property
    def refined(self) -> _Modes:
        """The refined modes (double-doubles) and the constants of the bound (built on
        first use)."""
        ex = self._exact
        theta, phi = _eigen(self.data)
        pairs = _refine(ex, np.asarray(theta, dtype=float), np.asarray(phi, dtype=float))
        _exact_rigid_modes(ex, pairs, _free_components(self.scene, ex))
        return _certify(ex, pairs)

    @cached_property
    def _scalars(self) -> _Scalars:
        return _scalars(self.refined)

    @cached_property
    def _blocks(self) -> tuple[np.ndarray, int]:
        """Φ_hi as (blocks, n, b), contiguous, zero columns padding the last block."""
        b = max(1, limits().refined_sum_block)
        P = self.refined.Ph
        m = P.shape[1]
        count = max(1, -(-m // b))
        padded = np.zeros((P.shape[0], count * b))
        padded[:, :m] = P
        return np.ascontiguousarray(padded.reshape(P.shape[0], count, b).transpose(1, 0, 2)), b

    @cached_property
    def _radius(self) -> float:
        """ρ, the largest |pole|."""
        return float(np.max(np.abs(self.poles()), initial=0.0))

    @cached_property
    def _scale(self) -> float:
        """S₀ = ‖x0‖∞ + ‖v0‖∞/ρ (the contract's floor of the scale; S₀ρᵏ for the k-th
        derivative)."""
        ex = self._exact
        x0 = float(np.max(np.abs(ex.x0[0]), initial=0.0))
        v0 = float(np.max(np.abs(ex.v0[0]), initial=0.0))
        return x0 + (v0 / self._radius if self._radius > 0 else 0.0)

    @property
    def modes(self) -> _ModeData:
        """(θ, c, Φ): stiffness and damping of each mode and the M-orthonormal shapes
        (the float64 parts of the refined values)."""
        m = self.refined
        return _ModeData(m.th, m.ch, m.Ph)

    @property
    def has_zero_frequency(self) -> bool:
        """Whether some mode is rigid (θ = 0 to working precision): served here, unlike
        the float64 eigen route."""
        theta = self.refined.th
        return bool(theta.size) and float(np.min(theta)) <= 64 * U * self.n * float(np.max(np.abs(theta)))

    def modal_form(self) -> ModalForm:
        """x(t) as a :class:`~laplace_springs.numeric.classical.ModalForm` (float64 terms)."""
        m = self.refined
        return _modal_form(m.th, m.ch, m.Ph, m.q0[0], m.dq0[0])

    def closed_form(self) -> sp.ImmutableMatrix:
        """x(t) as a SymPy column with Float coefficients."""
        return self.modal_form().as_matrix()

    def poles(self) -> np.ndarray:
        """λ = −h ± i√δ (underdamped), the two real roots otherwise, for every mode."""
        m = self.refined
        return mode_poles(m.th, m.ch)

    def _coefficients(self, order: int) -> tuple[np.ndarray, ...]:
        if order not in self._coefficient_cache:
            self._coefficient_cache[order] = _coefficients(self.refined, order)
        return self._coefficient_cache[order]

    def evaluate(self, times: Times, order: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """d^order x/dt^order at the times (float64, (n, len(times))) and bounds on the
        absolute error of every entry (module notes).

        Each time is computed alone (its modal functions elementwise, its sum Φq by
        itself): a value does not depend on the other times of the call.
        """
        if isinstance(order, bool) or not isinstance(order, (int, np.integer)) or order < 0:
            raise ValueError(f"order must be a non-negative integer, got {order!r}")
        count = len(times)
        values = np.zeros((self.n, count))
        bounds = np.zeros((self.n, count))
        if count == 0:
            return values, bounds
        chunk = max(1, 2**20 // max(self.n, 1))
        for a in range(0, count, chunk):
            b = min(a + chunk, count)
            values[:, a:b], bounds[:, a:b] = self._chunk(times.hi[a:b], times.lo[a:b], int(order))
        bad = ~np.isfinite(values)
        values[bad] = 0.0
        bounds[bad | ~np.isfinite(bounds)] = math.inf
        return values, bounds

    def _chunk(self, th: np.ndarray, tl: np.ndarray, order: int) -> tuple[np.ndarray, np.ndarray]:
        s = self._scalars
        u, w, err_u, err_w = self._coefficients(order)
        Cf, Sf, dC, dS, supC, supS = _closed_forms(s, th, tl)
        with np.errstate(over="ignore", invalid="ignore"):
            q = u[:, None] * Cf + w[:, None] * Sf
            eps = (np.abs(u)[:, None] * dC + np.abs(w)[:, None] * dS + err_u[:, None] * np.abs(Cf)
                   + err_w[:, None] * np.abs(Sf) + 2 * U * (np.abs(u[:, None] * Cf) + np.abs(w[:, None] * Sf)))
        energy = self._energy(th, tl, order, supC, supS)
        values = np.empty((self.n, len(th)))
        bounds = np.empty_like(values)
        target = limits().target
        for k in range(len(th)):
            values[:, k], bounds[:, k] = self._sum(q[:, k], eps[:, k], float(energy[k]), target, order)
        return values, bounds

    def _sum(self, q: np.ndarray, eps: np.ndarray, energy: float, target: float,
             order: int) -> tuple[np.ndarray, np.ndarray]:
        """x = Φ q for one time with its bound: blocked float64 sums with a uniform bound,
        then row-wise bounds, then a double-double sum, while the rounding misses the target."""
        blocks, b = self._blocks
        padded = np.zeros(blocks.shape[0] * b)
        padded[: len(q)] = q
        partial = np.matmul(blocks, padded.reshape(blocks.shape[0], b, 1))[:, :, 0]
        x, err = partial[0].copy(), np.zeros(len(partial[0]))
        for row in partial[1:]:  # Sum2: |x − Σ partial| ≤ u|x| + γ²_{blocks}·Σ|partial|
            x, sigma = two_sum(x, row)
            err += sigma
        x = x + err
        terms = min(b, len(q))
        gamma = _gamma(terms) + U * (1 + _gamma(terms)) + _gamma(2 * blocks.shape[0]) ** 2
        with np.errstate(over="ignore", invalid="ignore"):
            rounding = float(np.dot(self.refined.colmax, gamma * np.abs(q) + eps)) * _UP
            scale = max(float(np.max(np.abs(x), initial=0.0)), self._scale * self._radius**order)
            goal = target * scale / 2
            if rounding <= goal:
                return x, energy + rounding + 2 * U * np.abs(x)
            return self._sharper(q, eps, energy, x, gamma, goal)

    def _sharper(self, q: np.ndarray, eps: np.ndarray, energy: float, x: np.ndarray,
                 gamma: float, goal: float) -> tuple[np.ndarray, np.ndarray]:
        m = self.refined
        P = np.abs(m.Ph)
        widen = 1 + 2 * _gamma(P.shape[1] + 1)
        with np.errstate(over="ignore", invalid="ignore"):
            rows = (P @ (gamma * np.abs(q) + eps)) * widen
            if np.all(rows <= goal) or not np.all(np.isfinite(q)):
                return x, energy + rows + 2 * U * np.abs(x)
            hi, _ = _matvec(m.Ph, m.Pl, q, np.zeros_like(q))
            sums = P @ ((3 * U * U + 2 * _gamma(2 * len(q)) * U) * 1.01 * np.abs(q) + eps) * widen
            return hi, energy + sums + U * np.abs(hi)

    def _energy(self, th: np.ndarray, tl: np.ndarray, order: int, supC: np.ndarray,
                supS: np.ndarray) -> np.ndarray:
        """The bound on ‖e^(order)(t)‖∞ from the residuals and the initial data (module
        notes): the energy of e^(order) (its position), and for a derivative also the
        energy of e^(order−1), which holds ‖e^(order)‖²_M (t·residual instead of t²)."""
        ex = self._exact
        if ex.mu <= 0:
            return np.full(len(th), math.inf)
        t = th * (1 + 2 * U) + np.abs(tl)
        position, _ = self._energy_forms(t, self._forcing(order, supC, supS), *self._initial_errors(order))
        if order >= 1:
            _, velocity = self._energy_forms(t, self._forcing(order - 1, supC, supS),
                                             *self._initial_errors(order - 1))
            position = np.minimum(position, velocity)
        return position / math.sqrt(ex.mu)

    def _forcing(self, order: int, supC: np.ndarray, supS: np.ndarray) -> np.ndarray:
        """sup_{s≤t} ‖r^(order)(s)‖_{M⁻¹} ≤ Σ_j ρK_j sup|q̃_j^(order)| + ρC_j sup|q̃_j^(order+1)|."""
        m, s = self.refined, self._scalars
        forcing = np.zeros(supC.shape[1])
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            frequency = np.where(s.under & (s.wh > 0), s.wh, np.inf)[:, None]
            for k, weights in ((order, m.rho_K), (order + 1, m.rho_C)):
                if not np.any(weights):
                    continue
                u, w, err_u, err_w = self._coefficients(k)
                ua, wa = (np.abs(u) + err_u)[:, None], (np.abs(w) + err_w)[:, None]
                plain = ua * supC + wa * supS
                wave = np.where(np.isfinite(frequency), supC * np.sqrt(ua**2 + (wa / frequency) ** 2), np.inf)
                forcing += (weights[:, None] * np.minimum(plain, wave)).sum(axis=0)
        return forcing * _UP

    def _initial_errors(self, order: int) -> tuple[float, float]:
        """‖e^(order)(0)‖_M and ‖e^(order+1)(0)‖_M: M e^(j+2) = r^(j) − C e^(j+1) − K e^(j)."""
        m, ex = self.refined, self._exact
        errors = [m.e0, m.e1]
        for j in range(order):
            u, _, err_u, _ = self._coefficients(j)
            u1, _, err_u1, _ = self._coefficients(j + 1)
            r0 = float(m.rho_K @ (np.abs(u) + err_u) + m.rho_C @ (np.abs(u1) + err_u1))
            errors.append((r0 + ex.damping * errors[-1] + ex.stiffness * errors[-2]) * _UP)
        return errors[order], errors[order + 1]

    def _energy_forms(self, t: np.ndarray, forcing: np.ndarray, e_k: float,
                      e_k1: float) -> tuple[np.ndarray, np.ndarray]:
        """Bounds on ‖y(t)‖_M and ‖y'(t)‖_M for y = e^(k), M y'' + C y' + K y = r^(k), from
        the applicable forms of its energy (module notes): the smallest of each."""
        m, ex = self.refined, self._exact
        position = np.full(len(t), math.inf)
        velocity = np.full(len(t), math.inf)
        with np.errstate(over="ignore", invalid="ignore"):
            if m.theta_low > 0 or ex.K_psd:  # E = ‖y'‖² + yᵀKy ≥ ‖y'‖²
                root = math.sqrt(e_k1**2 + ex.stiffness * e_k**2) * _UP
                growth = np.exp(m.delta_C * t)
                energy = growth * (root + t * forcing) * _UP
                velocity = np.minimum(velocity, energy)
                # ‖y(t)‖_M ≤ ‖y(0)‖_M + ∫₀ᵗ √E ≤ ‖y(0)‖_M + e^{δ_C t}(t√E(0) + t²·sup‖r‖/2)
                position = np.minimum(position, e_k + t * growth * (root + t * forcing / 2) * _UP)
                if m.theta_low > 0:
                    position = np.minimum(position, energy / math.sqrt(m.theta_low))
            if m.theta_low <= 0 and math.isfinite(m.theta_low):  # E_σ with K + σM ⪰ sM
                s = max(-m.theta_low, U * U * ex.stiffness, 1e-300)
                sigma = s - m.theta_low
                root = math.sqrt(e_k1**2 + (ex.stiffness + sigma) * e_k**2) * _UP
                rate = m.delta_C + sigma / (2 * math.sqrt(s))
                energy = np.exp(rate * t) * (root + t * forcing) * _UP
                velocity = np.minimum(velocity, energy)
                position = np.minimum(position, energy / math.sqrt(s))
        return (np.where(np.isnan(position), math.inf, position),
                np.where(np.isnan(velocity), math.inf, velocity))

"""The tiny engine for two to four coordinates: Z = X B X⁻¹ with B block diagonal, and a
bound on e^{Zt}y₀ − X e^{Bt}X⁻¹y₀ from the residual of the decomposition.

Algorithm
---------
The 2n x 2n first-order matrix Z = [[0, σI], [−M⁻¹K/σ, −M⁻¹C]] (formed exactly, σ a
power of two near the frequency scale, so the scaled state (x, x'/σ) is balanced and the
scaling exact) is decomposed by ``numpy.linalg.eig``. An eigenvalue whose condition
number ‖row of V⁻¹‖ (unit eigenvectors) exceeds ``_CLUSTER_CONDITION`` is paired with its
nearest ill-conditioned neighbour when the two are close (defective and nearly defective
pairs: critical modes, exceptional points, rigid-body drift). The pair is replaced by a
2 x 2 block on an orthonormal basis of its invariant subspace (the null space of
(Z − w₁)(Z − w₂), from an SVD), whose exponential is

    e^{Bt} = e^{μt} [cosh(√d t)·I + sinh(√d t)/√d·N],   μ = tr B/2, N = B − μI, d = −det N:

functions of d that are entire, so nothing cancels when the pair is defective (d = 0
gives I + tN). The conjugate pairs of a real scene are evaluated once (twice the real
part), in real arithmetic for the 1 x 1 blocks.

Precision and conditioning (the bound)
--------------------------------------
With R = Z X − X B (formed in extended precision, ``numpy.longdouble``, from Z exact to
2⁻⁶⁴ as hi + lo, with the rounding of that product bounded), F = X⁻¹R, c = X⁻¹y₀ as
computed and r₀ = X c − y₀ its residual (also in extended precision), the exact motion is
e^{Zt}y₀ = X e^{(B+F)t}(c − X⁻¹r₀) while the engine computes X e^{Bt} c. With
‖e^{Bτ}‖ ≤ e^{μτ}p(τ) (μ the largest real part of B's eigenvalues, p = 1 for diagonal
B and p = 1 + ‖N‖·min(τ, 1/|√d|) with a 2 x 2 block), Gronwall's lemma gives

    ‖e^{(B+F)t} − e^{Bt}‖ ≤ t·φ·p(t)·G(t),   G(t) = e^{μt} p(t) e^{p(t)φt},   φ ≥ ‖F‖,

so coordinate i of the derivative of order k is off by at most
‖(L_k)_i‖·G(t)(φ t p(t)‖c‖ + ‖X⁻¹r₀‖), L_k the rows of X that give x^{(k)}, plus for
k = 2 the term ‖(σX_v)_i‖ (φ + u‖B‖) G(t)(‖c‖ + ‖X⁻¹r₀‖) of F itself (and of B's rounding
in the rows σX_v B that give x''), plus the rounding of the
evaluation (arguments |w|·(2u t + |lo|), the libm, the sums) and of d. ‖X⁻¹‖ is bounded
through the computed inverse Y and θ = ‖I − YX‖ < 1/2. Norms are Frobenius norms (upper
bounds of 2-norms). The bound grows like t·‖F‖ only where the motion does not decay
(undamped scenes: about 1e-14 to 1e-13 of the scale at t = 100); where it misses the
target the planner recomputes the time with its next engine. Scenes whose frequencies
differ by orders of magnitude (one σ cannot balance them) get large bounds and are served
by the other engines. A decomposition that cannot be bounded (θ ≥ 1/2, a singular basis)
serves no time and says why (``failure``).

References: Higham, *Functions of Matrices* (SIAM 2008), §10.1–10.2 (perturbation of
e^{At}); Moler & Van Loan, "Nineteen dubious ways to compute the exponential of a matrix,
twenty-five years later" (SIAM Review 2003), methods 14–17 and the block approach for
defective eigenvalues.
"""

from __future__ import annotations

import cmath
import math
from collections.abc import Callable
from functools import cached_property
from typing import Any

import numpy as np
from flint import fmpq

from ..kernels.dd import U
from ..kernels.peaks import peak
from ..limits import limits
from .tiny_refined import Refined

__all__ = ["BlockMotion", "SWITCH_FRACTION"]

#: Unit roundoff of the extended precision the residuals are formed in (2⁻⁶⁴ where
#: ``numpy.longdouble`` is x87 80-bit; 2⁻⁵³ where it is float64, which only loosens the
#: bound).
_U_LONG = float(np.finfo(np.longdouble).eps) / 2
#: Eigenvalues whose condition number exceeds this are candidates for a 2 x 2 block:
#: unblocked, the coefficients grow like the condition number and the bound like its
#: square times u (30² · 1e-16 ≈ 1e-13 of the scale).
_CLUSTER_CONDITION = 30.0
#: A pair is a block only when it is this much closer together than to any other
#: eigenvalue (its invariant subspace is then well determined) ...
_CLUSTER_SEPARATION = 0.1
#: ... and close relative to its own size max(|w₁|, |w₂|, 1e-3·ρ): a conjugate pair ±iω
#: whose eigenvectors are nearly parallel only because one scaling σ cannot balance
#: every frequency (ω ≪ σ) is not defective, and a block for it would be far from normal.
_CLUSTER_CLOSENESS = 0.01
#: Smallest ratio between the third-smallest and the second-smallest singular value of
#: (Z − w₁)(Z − w₂) for its null space to be taken as the pair's invariant subspace.
_SUBSPACE_GAP = 1e3
#: A classically damped scene whose unit eigenvectors V have ‖V⁻¹‖_F above this takes its
#: modes' basis (numeric/tiny_modes.py). Well-separated modes give 2 to 5 (√(2n) is the
#: least); on 200 random classical scenes every one whose bound only the modes' basis
#: brought under the target had more than 3, and 25 of 32 more than 10. Below it the
#: eigenvectors serve as well and cost less (no n x n eigenproblem besides).
_MODAL_CONDITION = 10.0
#: A decomposition without 2 x 2 blocks evaluates x by its refined eigenvalues and
#: double-double phases (numeric/tiny_refined.py), whose bound does not grow like u·|w|·t,
#: at the times beyond the last one where the float64 evaluation's bound (which grows like
#: t·‖F‖) stays within this fraction of Limits.target·max(‖x0‖∞, ‖v0‖∞/ρ); earlier times
#: keep the float64 eigenvalues (fewer operations; building the refined evaluation costs
#: about 0.6 ms on a first call). At 0.5 (of max|y₀|) the 3- and 4-mass chains of
#: benchmarks/bench_tiny.py switched at t ≈ 5.8 with float64 bounds of 4e-14 of S₀ and
#: took 2.1x control's time instead of 0.9x.
SWITCH_FRACTION = 1.0
#: Largest θ = ‖I − Y X‖ accepted (Y the computed inverse of the basis X).
_MAX_THETA = 0.5
#: Second-order terms the first-order rounding bounds neglect: bounds are multiplied by this.
_SAFETY = 1.02


#: NumPy's LAPACK gufuncs (``numpy.linalg._umath_linalg``), where this NumPy has them: the
#: same routines and numbers as ``numpy.linalg.eig``, ``inv`` and ``svd`` without their
#: 10-25 µs of argument checks (the matrices here are finite and square).
_LINALG = getattr(np.linalg, "_umath_linalg", None)


def _norm(a: np.ndarray) -> float:
    """The Frobenius norm (an upper bound of the 2-norm)."""
    return math.sqrt(np.vdot(a, a).real)


def _row_norms(a: np.ndarray) -> np.ndarray:
    """The 2-norms of the rows (``math.hypot``: no overflow of the squares; in Python, which
    for these few entries costs less than NumPy's reductions)."""
    return np.array([math.hypot(*map(abs, row)) for row in a.tolist()])


def _eig(Z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``numpy.linalg.eig`` of a real matrix (complex eigenvalues and unit eigenvectors),
    by LAPACK's ``dgeev`` directly where NumPy exposes it. A failure shows as non-finite
    eigenvalues."""
    gufunc = getattr(_LINALG, "eig", None)
    if gufunc is None:
        return np.linalg.eig(Z)
    w, V = gufunc(Z, signature="d->DD")
    return w, V


def _inv(X: np.ndarray) -> tuple[np.ndarray, float] | None:
    """X⁻¹ (complex) and its Frobenius norm, or None when X is singular or the norm is not
    finite (an entry that is not, or one beyond 1e154)."""
    gufunc = getattr(_LINALG, "inv", None)
    try:
        Y = np.linalg.inv(X) if gufunc is None else gufunc(X, signature="D->D")
    except np.linalg.LinAlgError:
        return None
    norm = _norm(Y)  # NaN propagates
    return (Y, norm) if math.isfinite(norm) else None


def _svd(P: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``numpy.linalg.svd`` (full matrices)."""
    gufunc = getattr(_LINALG, "svd_f", None)
    if gufunc is None:
        u, s, vh = np.linalg.svd(P)
        return u, s, vh
    signature = "d->ddd" if P.dtype.kind == "f" else "D->DdD"
    u, s, vh = gufunc(P, signature=signature)
    return u, s, vh


def _as_slice(columns: list[int], size: int) -> slice | np.ndarray:
    """``columns`` as a slice when they are range(size) or range(0, size, 2), else an index
    array (either selects the same columns)."""
    for step in (1, 2):
        if columns == list(range(0, size, step)):
            return slice(0, size, step)
    return np.array(columns, dtype=np.intp)


#: Integers up to this size are float64 numbers (beyond it an integer entry, say 10⁴⁰, is
#: rounded and gets a low part like any fraction).
_EXACT_INTEGER = 2**53

_EYES: dict[int, np.ndarray] = {}


def _eye(size: int) -> np.ndarray:
    if size not in _EYES:
        _EYES[size] = np.eye(size)
    return _EYES[size]


def _first_order(n: int, A: dict[tuple[int, int], Any], B: dict[tuple[int, int], Any],
                 floats: tuple[list[float], list[float]] | None = None
                 ) -> tuple[float, np.ndarray, np.ndarray | None, float]:
    """(σ, Z, Z_lo, ‖Z‖_F): σ a power of two near the frequency scale and Z = [[0, σI],
    [−A/σ, −B]] as hi + lo, hi the entries correctly rounded and lo their rounded
    remainders (Z_lo None when every entry is a float64 number); ``floats``: A's and B's
    values in float64 where the caller has them. Scaling by σ (a power of
    two) is exact while the scaled entries stay in float64's normal range, as they do for
    entries within the default Limits.tiny_max_magnitude^{±1} = 1e±100; below it the loss
    is under 2⁻¹⁰⁷⁴, far below u·‖Z‖."""
    size = 2 * n
    exact = [*A.values(), *B.values()]
    high = [float(value) for value in exact] if floats is None else [*floats[0], *floats[1]]
    stiff = len(A)
    largest = max(map(abs, high[:stiff]), default=0.0)
    damping = max(map(abs, high[stiff:]), default=0.0)
    scale = max(math.sqrt(largest), damping / 2)
    sigma = 2.0 ** round(math.log2(scale)) if 0 < scale < math.inf else 1.0
    # row-major entries of Z (and of its low parts where an entry is not a float64 number)
    hi = [0.0] * (size * size)
    for i in range(n):
        hi[i * size + n + i] = sigma
    lo: list[float] | None = None
    squares = n * sigma * sigma
    places = [(n + i) * size + j for i, j in A] + [(n + i) * size + n + j for i, j in B]
    factors = [-1 / sigma] * stiff + [-1.0] * (len(exact) - stiff)
    for place, value, rounded, factor in zip(places, exact, high, factors):
        entry = hi[place] = rounded * factor
        squares += entry * entry
        if value.q != 1 or not -_EXACT_INTEGER <= value.p <= _EXACT_INTEGER:
            low = value - fmpq(*rounded.as_integer_ratio())
            if low:
                lo = lo or [0.0] * (size * size)
                lo[place] = float(low) * factor
    return (sigma, np.array(hi).reshape(size, size),
            None if lo is None else np.array(lo).reshape(size, size), math.sqrt(squares))


class _Block:
    """A 2 x 2 block μI + N of B on ``columns`` of X (d = −det N, ``d_error`` its
    rounding). ``weight`` is 2 for the upper member of a conjugate pair, whose partner is
    not evaluated (``skip``); a ``real`` block has real columns and coefficients. ``nu`` =
    ‖N‖_F, ``root`` = √d (the eigenvalues are μ ± √d) and ``growth`` (their largest real
    part) are computed once."""

    __slots__ = ("columns", "mu", "entries", "d", "d_error", "weight", "skip", "real",
                 "nu", "root", "growth")

    def __init__(self, columns: tuple[int, int], mu: complex,
                 entries: tuple[complex, complex, complex], d: complex, d_error: float, *,
                 weight: int = 1, skip: bool = False, real: bool = False) -> None:
        a, b01, b10 = self.entries = entries  # N = [[a, b01], [b10, −a]]
        self.columns, self.mu, self.d, self.d_error = columns, complex(mu), d, d_error
        self.weight, self.skip, self.real = weight, skip, real
        size = abs(a)
        self.nu = math.hypot(size, size, abs(b01), abs(b10))
        self.root = cmath.sqrt(d)
        self.growth = self.mu.real + abs(self.root.real)

    @classmethod
    def of(cls, columns: tuple[int, int], mu: complex, entries: tuple[complex, complex, complex],
           *, real: bool = False) -> _Block:
        """The block μI + N with N = [[a, b01], [b10, −a]] (``entries`` (a, b01, b10)):
        d = a² + b01·b10 with the bound of its rounding."""
        a, b01, b10 = entries
        d = a * a + b01 * b10
        size = abs(a) ** 2 + abs(b01 * b10)
        # each complex product and the sum: ≤ 2√2u + 2u of the terms; √d's rounding (≤ 2u
        # relative, so root² is d within 4u|d|): 8u of the terms and 4u of |d| in all
        return cls(columns, mu, entries, d, 8 * U * size + 4 * U * abs(d), real=real)

    def conjugate(self, columns: tuple[int, int]) -> _Block:
        """The conjugate block on ``columns`` (a lower twin: skipped in evaluation)."""
        a, b01, b10 = self.entries
        return _Block(columns, self.mu.conjugate(), (a.conjugate(), b01.conjugate(), b10.conjugate()),
                      self.d.conjugate(), self.d_error, skip=True)


class BlockMotion:
    """x(t) of a scene of two to four coordinates (see the module notes).

    Parameters
    ----------
    n : int
        Coordinates.
    A, B : dict
        The nonzero entries of M⁻¹K and M⁻¹C, exact (python-flint fmpq).
    x0, v0 : numpy.ndarray
        The initial data rounded to float64.
    floats : tuple of two lists, optional
        A's and B's values rounded to float64, in their order (read from them otherwise).
    modes : callable, optional
        Returns the scene's classical modes
        (:class:`~laplace_springs.numeric.tiny_modes.ClassicalModes`) or None; called only
        when the eigenvectors of ``numpy.linalg.eig`` are far from orthogonal (‖V⁻¹‖_F >
        ``_MODAL_CONDITION``). Their ``layout(motion)`` then sets the basis: it returns
        (w, X) and sets ``columns``, ``weights``, ``rates``, ``real_columns``, ``mirrors``
        and ``doubles`` as :meth:`_layout` does. The residual bound checks it like any
        basis.

    Attributes
    ----------
    poles : numpy.ndarray
        The eigenvalues of Z (the poles).
    radius : float
        max |pole|.
    failure : str or None
        Why the decomposition serves no time (every bound infinite), or None.
    """

    def __init__(self, n: int, A: dict[tuple[int, int], Any], B: dict[tuple[int, int], Any],
                 x0: np.ndarray, v0: np.ndarray, *,
                 floats: tuple[list[float], list[float]] | None = None,
                 modes: Callable[[], Any] | None = None) -> None:
        self.failure: str | None = None
        self.n = n
        #: what the basis X was built from: "eigenvectors" (``numpy.linalg.eig``) or "modes"
        self.basis = "eigenvectors"
        self._square: np.ndarray | None = None  # Z², for the pairs of 2 x 2 blocks
        self.sigma, self.Z, self.Z_lo, self.Z_norm = _first_order(n, A, B, floats)
        x0_list, v0_list = x0.tolist(), v0.tolist()
        #: max |x0| and max |v0| (the scale of the refined evaluation's switch)
        self.initial_sizes = (max(map(abs, x0_list), default=0.0),
                              max(map(abs, v0_list), default=0.0))
        start = [*x0_list, *[v / self.sigma for v in v0_list]]
        self.y0, self.y0_norm = np.array(start), math.hypot(*start)
        w, V = _eig(self.Z)
        if not self._set_poles(w):
            return
        inverse = _inv(V)
        Y, Y_norm = inverse if inverse is not None else (None, math.inf)
        # eigenvectors far from orthogonal (critical and rigid-body modes, repeated
        # frequencies): a classically damped scene takes its n modes' basis instead
        found = modes() if modes is not None and Y_norm > _MODAL_CONDITION else None
        if found is not None:
            self.basis = "modes"
            w, X = found.layout(self)
            if self._set_poles(w):
                self._finish(w, X, None)
            return
        X = self._layout(w, V, Y, Y_norm)
        self._finish(w, X, (Y, Y_norm) if X is V and Y is not None else None)

    def _set_poles(self, w: np.ndarray) -> bool:
        """Set ``poles``, ``w_norm`` and ``radius`` from the eigenvalues ``w``; False (and
        ``failure``) when one is not finite."""
        self.poles = w
        listed = [abs(pole) for pole in w.tolist()]
        #: ‖diag(w)‖_F (NaN or inf when an eigenvalue is not finite)
        self.w_norm = math.hypot(*listed)
        if not math.isfinite(self.w_norm):
            self.radius = math.nan if any(map(math.isnan, listed)) else max(listed)
            self.failure = "the eigenvalues are not finite (LAPACK did not converge)"
            return False
        self.radius = max(listed)
        return True

    # -- the decomposition -------------------------------------------------------------
    def _layout(self, w: np.ndarray, V: np.ndarray, Y: np.ndarray | None,
                Y_norm: float) -> np.ndarray:
        """1 x 1 blocks for well-conditioned eigenvalues, 2 x 2 blocks for defective pairs;
        the basis X (V itself when there are no 2 x 2 blocks). ``Y_norm`` is ‖Y‖_F
        (Y = V⁻¹, None when V is singular).

        Sets ``columns`` (the evaluated 1 x 1 blocks: a real eigenvalue, the upper member
        of a conjugate pair, or a complex term outside LAPACK's layout), their ``weights``
        (2 for a pair: twice the real part), ``doubles`` (the 2 x 2 blocks, the skipped
        lower twins included), and the coefficients' symmetries of a real motion:
        ``real_columns`` (real coefficients) and ``mirrors`` ((j, i): c_j = conj c_i).
        """
        size = w.size
        pairs: dict[int, tuple[int, int]] = {}
        # ‖row of Y‖₂ ≤ ‖Y‖_F: rows need measuring only beyond that
        if Y is None or Y_norm > _CLUSTER_CONDITION:
            with np.errstate(over="ignore"):  # an infinite condition number is one
                condition = (np.full(size, np.inf) if Y is None
                             else _row_norms(Y))
            pairs = self._pairs(w, condition)
        X = V.copy() if pairs else V
        columns: list[int] = []
        weights: list[float] = []
        self.real_columns: list[int] = []
        self.mirrors: list[tuple[int, int]] = []
        self.doubles: list[_Block] = []
        done: set[int] = set()
        rates: list[complex] = w.tolist()
        for j, rate in enumerate(rates):
            if j in done:
                continue
            if j in pairs:
                found = self._cluster(w, pairs[j], X)
                if found is not None:
                    self._add_doubles(found, done)
                    continue
            done.add(j)
            columns.append(j)
            if rate.imag == 0:
                weights.append(1.0)
                self.real_columns.append(j)
            elif rate.imag > 0 and j + 1 < size and rates[j + 1] == rate.conjugate():
                weights.append(2.0)
                self.mirrors.append((j + 1, j))
                done.add(j + 1)
            else:  # not LAPACK's layout of a conjugate pair: evaluated as a complex term
                weights.append(1.0)
        # a slice where the columns are every eigenvalue or every other one (a real scene's
        # conjugate pairs in LAPACK's layout): a view, where an index array copies
        self.columns = _as_slice(columns, size)
        self.weights = np.array(weights)
        self.rates = w[self.columns]
        return X

    def _add_doubles(self, found: list[_Block], done: set[int]) -> None:
        self.doubles += found
        for block in found:
            done.update(block.columns)
            if block.real:
                self.real_columns += block.columns
            elif block.weight == 2:
                self.mirrors += [(i + 1, i) for i in block.columns]

    @staticmethod
    def _pairs(w: np.ndarray, condition: np.ndarray) -> dict[int, tuple[int, int]]:
        """Ill-conditioned eigenvalues paired with their nearest ill-conditioned neighbour,
        when the two are mutually nearest, much closer to each other than to the rest, and
        close relative to their size."""
        rates: list[complex] = w.tolist()
        flagged = [j for j, size in enumerate(condition.tolist()) if size > _CLUSTER_CONDITION]
        radius = max(abs(rate) for rate in rates)
        nearest: dict[int, int] = {}
        for j in flagged:
            others = [k for k in flagged if k != j]
            if others:
                nearest[j] = min(others, key=lambda k: (abs(rates[j] - rates[k]), k))
        pairs: dict[int, tuple[int, int]] = {}
        for j, k in nearest.items():
            if nearest.get(k) != j or j > k:
                continue
            gap = abs(rates[j] - rates[k])
            middle = (rates[j] + rates[k]) / 2
            rest = [abs(rates[i] - middle) for i in range(w.size) if i not in (j, k)]
            size = max(abs(rates[j]), abs(rates[k]), 1e-3 * radius)
            if gap <= _CLUSTER_SEPARATION * min(rest, default=math.inf) \
                    and gap <= _CLUSTER_CLOSENESS * size:
                pairs[j] = pairs[k] = (j, k)
        return pairs

    def _cluster(self, w: np.ndarray, pair: tuple[int, int],
                 X: np.ndarray) -> list[_Block] | None:
        """The 2 x 2 block of a pair (with its conjugate pair's, for a complex pair); None
        when its invariant subspace is not well determined."""
        j, k = pair
        real = (w[j].imag == 0 and w[k].imag == 0) or w[k] == np.conj(w[j])
        if not real:
            if w[j].imag < 0 or w[k].imag < 0:
                return None  # the lower pair: built with the upper one
            if max(j, k) + 1 >= w.size or w[j + 1] != np.conj(w[j]) or w[k + 1] != np.conj(w[k]):
                return None
        _, singular, Vh = _svd(self._pair_product(w[j], w[k], real))
        if singular.size < 3 or singular[-3] < _SUBSPACE_GAP * singular[-2]:
            return None
        basis = Vh[-2:].conj().T
        block = self._block((j, k), basis)
        X[:, [j, k]] = basis
        if real:
            block.real = True
            return [block]
        mirror = (j + 1, k + 1)
        X[:, list(mirror)] = basis.conj()
        block.weight = 2
        return [block, block.conjugate(mirror)]

    def _pair_product(self, w1: complex, w2: complex, real: bool) -> np.ndarray:
        """(Z − w₁)(Z − w₂), whose null space is the pair's invariant subspace: for a real
        pair (two real eigenvalues or a conjugate pair) Z² − (w₁ + w₂)Z + w₁w₂·I in real
        arithmetic (Z² formed once per decomposition)."""
        Z = self.Z
        if not real:
            eye = _eye(Z.shape[0])
            return (Z - w1 * eye) @ (Z - w2 * eye)
        if self._square is None:
            self._square = Z @ Z
        P = self._square - (w1 + w2).real * Z
        P.flat[::Z.shape[0] + 1] += (w1 * w2).real
        return P

    def _block(self, columns: tuple[int, int], basis: np.ndarray) -> _Block:
        """The block basisᴴ Z basis = [[b₀₀, b₀₁], [b₁₀, b₁₁]] as μI + N with μ = (b₀₀ + b₁₁)/2
        and N = [[a, b₀₁], [b₁₀, −a]], a = (b₀₀ − b₁₁)/2 (the rounding of μ and a, ≤ u of
        them, is counted in φ), and d = −det N = a² + b₀₁b₁₀ with its rounding bound."""
        B = basis.conj().T @ self.Z @ basis
        b00, b01, b10, b11 = B.ravel().tolist()
        return _Block.of(columns, (b00 + b11) / 2, ((b00 - b11) / 2, b01, b10))

    def _block_matrix(self, w: np.ndarray) -> tuple[np.ndarray | None, float]:
        """B as a matrix (None when it is diag(w): no 2 x 2 blocks) and ‖μI + N − B‖, the
        rounding of μ and a on the 2 x 2 blocks."""
        if not self.doubles:
            return None, 0.0
        B = np.diag(w)
        moved = 0.0
        for block in self.doubles:
            (i, j), (a, b01, b10), mu = block.columns, block.entries, block.mu
            B[i, i], B[j, j], B[i, j], B[j, i] = mu + a, mu - a, b01, b10
            moved = max(moved, 2 * U * (abs(mu) + abs(a)))
        return B, moved

    def _times_B(self, P: np.ndarray) -> np.ndarray:
        """P·B (B diagonal: a scaling of P's columns)."""
        return P * self.poles if self.B is None else P @ self.B

    def _finish(self, w: np.ndarray, X: np.ndarray,
                inverse: tuple[np.ndarray, float] | None) -> None:
        """Coefficients, residuals and the constants of the bound (``inverse``: X⁻¹ and its
        Frobenius norm, when known). The rounding of each product is bounded through norms
        (‖|A||B|‖_F ≤ ‖A‖_F‖B‖_F)."""
        size = X.shape[0]
        self.X = X
        self.B, moved = self._block_matrix(w)
        B_norm = self.w_norm if self.B is None else _norm(self.B)
        self.B_rounding = U * B_norm
        if inverse is None:
            inverse = _inv(X)
            if inverse is None:
                self.failure = "the eigenvector basis is singular"
                return
        Y, Y_norm = inverse
        # R = Z X − X B in extended precision (Z exact to 2⁻⁶⁴), then one product with Y
        # gives the coefficients Y y₀, Y X (for θ) and Y R (for φ)
        X_long = X.astype(np.clongdouble)
        Z_long = self.Z.astype(np.longdouble)
        if self.Z_lo is not None:
            Z_long += self.Z_lo
        R = (Z_long @ X_long - self._times_B(X_long)).astype(complex)
        product = Y @ np.concatenate((self.y0[:, None], X, R), axis=1)
        coefficients: list[complex] = product[:, 0].tolist()
        for i in self.real_columns:  # the coefficients of a real motion
            coefficients[i] = complex(coefficients[i].real)
        for j, i in self.mirrors:
            coefficients[j] = coefficients[i].conjugate()
        self.c = c = np.array(coefficients)
        X_norm, R_norm = _norm(X), _norm(R)
        misfit, F_norm = _norm(_eye(size) - product[:, 1:size + 1]), _norm(product[:, size + 1:])
        gamma = (2 * size + 4) * U
        theta = misfit + gamma * Y_norm * X_norm
        if not theta < _MAX_THETA:
            self.failure = f"the basis is too ill-conditioned (‖I − X⁻¹X‖ = {theta:.2g})"
            return
        inverse = Y_norm / (1 - theta)  # ≥ ‖X⁻¹‖₂
        R_error = ((2 * size + 6) * _U_LONG * (self.Z_norm + B_norm) * X_norm
                   + U * R_norm)
        phi = (F_norm + gamma * Y_norm * R_norm + Y_norm * R_error
               + theta * inverse * (R_norm + R_error) + 2 * moved)
        #: Y, θ and ‖X⁻¹‖ ≤ inverse, for the refined evaluation of long horizons
        self._inverse: tuple[np.ndarray, float, float] = (Y, theta, Y_norm / (1 - theta))
        c_norm = math.hypot(*map(abs, coefficients))
        y0_norm = self.y0_norm
        # r₀ = X c − y₀ in extended precision; y₀ holds the exact data rounded once
        r0 = _norm(X_long @ c - self.y0)  # (c is promoted to X_long's precision)
        r0_error = (2 * size + 4) * _U_LONG * (X_norm * c_norm + y0_norm) + U * (y0_norm + r0)
        self.phi = phi * _SAFETY
        self.rho0 = inverse * (r0 + r0_error) * _SAFETY
        self.c_norm = c_norm
        self.X_norm = X_norm
        if self.doubles:
            rates = self.rates.tolist()
            self.growth = max([block.growth for block in self.doubles] + [r.real for r in rates])
            self.speed = max([abs(block.mu) + block.nu for block in self.doubles]
                             + [abs(r) for r in rates])
        else:  # every eigenvalue or its conjugate is evaluated
            self.growth, self.speed = max(rate.real for rate in w.tolist()), self.radius
        self._orders: dict[int, _Order] = {}

    # -- evaluation --------------------------------------------------------------------
    def _order(self, order: int) -> _Order:
        """The weights of derivative ``order``: x^(order) = L e^{Bt} c with L the rows of
        X (order 0), σ times X's velocity rows (1), or those times B (2)."""
        if order not in self._orders:
            n, X, sigma = self.n, self.X, self.sigma
            L = X[:n] if order == 0 else sigma * X[n:] if order == 1 \
                else self._times_B(sigma * X[n:])
            F_rows = sigma * _row_norms(X[n:]) if order == 2 else None
            self._orders[order] = _Order(L, self, F_rows)
        return self._orders[order]

    def evaluate(self, t: np.ndarray, lo: np.ndarray | None,
                 order: int) -> tuple[np.ndarray, np.ndarray]:
        """Values and bounds at times t + lo (lo: the low parts, or None for zero): the
        values are taken at t, the bounds cover the shift (|lo| ≤ u·t); x at the late times
        of a decomposition without 2 x 2 blocks by its refined evaluation, at t + lo."""
        n = self.n
        if self.failure is not None:
            return np.zeros((n, t.size)), np.full((n, t.size), np.inf)
        weights = self._order(order)
        values, bounds = self._values(weights, t), self._bounds(weights, t)
        late = self._late(t)
        if late is not None:
            refined, moved = self._refined, (None if lo is None else lo[late])
            values[:, late] = refined.values(t[late], moved, order)
            bounds[:, late] = refined.bounds(t[late], order)
        return values, bounds

    def values(self, t: np.ndarray, lo: np.ndarray | None, order: int) -> np.ndarray:
        """The values of :meth:`evaluate` alone (zeros for a failed decomposition, whose
        :meth:`bound_until` is infinite)."""
        if self.failure is not None:
            return np.zeros((self.n, t.size))
        values = self._values(self._order(order), t)
        late = self._late(t)
        if late is not None:
            values[:, late] = self._refined.values(t[late], None if lo is None else lo[late],
                                                   order)
        return values

    def _late(self, t: np.ndarray) -> np.ndarray | None:
        """The times (a mask) the refined evaluation takes (for x and its derivatives):
        the times beyond :meth:`_switch_at` of a decomposition without 2 x 2 blocks; None
        when there is none. A time's evaluation depends on that time alone."""
        if not t.size:
            return None
        switch = self._switch_at(float(np.maximum.reduce(t)))
        if switch is None:
            return None
        low, high = switch
        late = t > low
        for i in np.flatnonzero(late & (t < high)).tolist():  # between the bisection's ends
            late[i] = self._plain_value(float(t[i])) > self._tolerance
        return late if late.any() else None

    def _switch_at(self, last: float) -> tuple[float, float] | None:
        """The switch, a constant of the decomposition: a time t is late when the float64
        evaluation's bound over [0, t] exceeds :attr:`_tolerance` (monotone in t).
        Returns the bisection's ends (low, high): times up to low are early, from high on
        late, between them each is asked; None when ``last`` is not late (known without
        the bisection when the bound over [0, last] is within it) or the decomposition has
        2 x 2 blocks."""
        if self.failure is not None or self.doubles or not 0 < self.radius < math.inf:
            return None
        if last <= self._early or not last < math.inf:
            return None
        if self._plain_value(last) <= self._tolerance:
            self._early = last
            return None
        return self._switch

    #: A time known to be no later than the switch.
    _early = 0.0

    @cached_property
    def _tolerance(self) -> float:
        """SWITCH_FRACTION·Limits.target·max(max|x0|, max|v0|/ρ): at most the target times
        the contract's scale S₀ = ‖x0‖∞ + ‖v0‖∞/ρ and at least half of it, so the switch
        comes before the float64 bound misses the target and not much earlier (any
        constant of the scene keeps each time's evaluation independent of the others)."""
        x0_size, v0_size = self.initial_sizes
        return SWITCH_FRACTION * limits().target * max(x0_size, v0_size / self.radius)

    @cached_property
    def _switch(self) -> tuple[float, float]:
        """The ends (low, high) of :meth:`_switch_at`: 1/radius doubled while the bound
        stays within the tolerance, then bisected ten times."""
        within, tolerance = self._plain_value, self._tolerance
        if not within(0.0) <= tolerance:
            return -1.0, 0.0
        low, high = 0.0, 1 / self.radius
        while within(high) <= tolerance:
            low, high = high, 2 * high
            if not high < 1e300:
                return math.inf, math.inf
        for _ in range(10):
            middle = (low + high) / 2
            low, high = (middle, high) if within(middle) <= tolerance else (low, middle)
        return low, high

    def _plain_value(self, T: float) -> float:
        """:meth:`_plain_until` with its rounding (inf for NaN), kept per T."""
        cache = self.__dict__.setdefault("_plain_values", {})
        if T not in cache:
            if len(cache) > 64:  # (the bisection's and the latest requests' horizons)
                cache.clear()
            found = self._plain_until(T)
            cache[T] = math.inf if math.isnan(found) else found * (1 + 1e-12)
        return cache[T]

    @cached_property
    def _refined(self) -> Refined:
        """The refined evaluation (:class:`~laplace_springs.numeric.tiny_refined.Refined`),
        built when a late time is first asked for."""
        return Refined(self, *self._inverse)

    def _values(self, weights: _Order, t: np.ndarray) -> np.ndarray:
        """Re Σ_j g_j e^{λ_j t} over the 1 x 1 blocks plus the 2 x 2 blocks' terms."""
        n = self.n
        if self.rates.size:  # Re Σ_j g_j e^{λ_j t}, summed in the order of j for every time
            terms = (weights.g[:, :, None] * np.exp(self.rates[:, None] * t)).real
            if self.rates.size < 8:  # numpy adds fewer than 8 terms in order
                values = np.add.reduce(terms, axis=1)
            else:  # (and pairs 8 or more)
                values = terms[:, 0].copy()
                for j in range(1, self.rates.size):
                    values += terms[:, j]
        else:
            values = np.zeros((n, t.size))
        for block, g_C, g_S in weights.doubles:
            values += self._double(block, g_C, g_S, t)
        return values

    def bound_until(self, t_max: float) -> float:
        """An upper bound of every bound :meth:`evaluate` gives for x (order 0) at times in
        [0, t_max], from the decomposition's constants alone (no per-time work: a few
        float operations where :meth:`bounds` makes a dozen NumPy calls or more).

        Every term of :meth:`_bounds` is a coordinate's weight times t^k·e^{rt} times
        constants, with the factors that vary otherwise (q(t), the integral's factor) at
        their largest, t_max; each t^k·e^{rt} is replaced by its maximum on [0, t_max]
        (:func:`peak`: inside the interval for a decaying rate), so a decaying motion's
        bound is that of its worst time, not of t_max with the decay left out. Inf for a
        failed decomposition or where an exponential would overflow.
        """
        if self.failure is not None or not t_max < 1e300:
            return math.inf
        if self.doubles:
            found = self._blocks_until(t_max)
            return math.inf if math.isnan(found) else found * (1 + 1e-12)  # the sum's rounding
        switch = self._switch_at(t_max)
        if switch is None:
            return self._plain_value(t_max)
        early = self._plain_value(min(switch[1], t_max)) if switch[1] > 0 else 0.0
        return max(early, self._refined.bound_until(t_max))

    def _plain_until(self, T: float) -> float:
        """:meth:`bound_until` without 2 x 2 blocks: per coordinate i, Σ_k W_ik·(s_k·peak(r_k,
        1) + o_k·peak(r_k, 0)) over :meth:`_plain`'s terms W_ik·e^{r_k t}(s_k t + o_k)."""
        weights = self._order(0)
        rates, slopes, offsets, per_row = weights.plain or self._plain(weights)
        peaks = [s * peak(r, 1, T) + o * peak(r, 0, T) for r, s, o
                 in zip(rates.ravel().tolist(), slopes.ravel().tolist(), offsets.ravel().tolist())]
        if not all(map(math.isfinite, peaks)):
            return math.inf
        return max(sum(w * p for w, p in zip(row, peaks)) for row in per_row[:, :, 0].tolist())

    def _blocks_until(self, T: float) -> float:
        """:meth:`bound_until` with 2 x 2 blocks: :meth:`_bounds`' terms per coordinate with
        e^{q(t)φt} ≤ e^{q(T)φt}, q(t) and the integral bounded by polynomials in t (or by K),
        cosh(st) ≤ (e^{st} + e^{−st})/2, and each t^k·e^{rt} at its maximum on [0, T] (the weights of x, which :meth:`evaluate` uses
        too, read as floats)."""
        K, nu = self._growth_constants
        largest = self._largest_root
        g, top = self.growth, self.growth + min(K, 1 + nu * T) * self.phi
        P = [peak(top, k, T) for k in range(4)]
        # q(t) ≤ 1 + νt and ≤ K; the integral ≤ t(1 + νt + (νt)²/6) and ≤ t·K²
        integral = P[1] + nu * P[2] + nu * nu / 6 * P[3]
        q = P[0] + nu * P[1]
        if math.isfinite(K):
            integral, q = min(integral, K * K * P[1]), min(q, K * P[0])
        main = self.phi * self.c_norm * integral + self.rho0 * q
        # rounding(t) = e^{gt}(a + b·t): the shift, the libm and √d's argument (_bounds)
        a, b = (2 * self.n + 12) * U, (3.03 * self.speed + 2 * largest) * U
        near = a * peak(g, 0, T) + b * peak(g, 1, T)
        far = a * peak(g, 1, T) + b * peak(g, 2, T)
        squared = peak(g, 2, T) / 2
        cubed = (peak(g + largest, 3, T) + peak(g - largest, 3, T)) / 8
        if not all(map(math.isfinite, (main, near, far, squared, cubed))):
            return math.inf
        w = self._order(0)
        columns = zip(w.rows.tolist(), (w.single_size + w.double_C).tolist(),
                      w.double_S.tolist(), w.d_C.tolist(), w.d_S.tolist(), w.size.tolist())
        return max((rows * main + one * near + two * far + d_C * squared + d_S * cubed) * _SAFETY
                   + size * 1e-300 * (1 + T)
                   for rows, one, two, d_C, d_S, size in columns)

    def bounds(self, t: np.ndarray, order: int) -> np.ndarray:
        """The bounds of :meth:`evaluate` at the float64 times ``t`` (no values formed)."""
        bounds = self._bounds(self._order(order), t)
        late = self._late(t)
        if late is not None:
            bounds[:, late] = self._refined.bounds(t[late], order)
        return bounds

    @staticmethod
    def _double(block: _Block, g_C: np.ndarray, g_S: np.ndarray, t: np.ndarray) -> np.ndarray:
        """Re e^{μt}[cosh(√d t)·g_C + sinh(√d t)/√d·g_S]: in real arithmetic for a real
        block (cosh and sinh, or cos and sin of √|d|·t), else complex."""
        if block.real:
            d = block.d.real
            E = np.exp(block.mu.real * t)
            if d == 0:
                value: np.ndarray = E * (g_C.real + t * g_S.real)
                return value
            size = math.sqrt(abs(d))
            phase = size * t
            C, S = (np.cosh(phase), np.sinh(phase) / size) if d > 0 \
                else (np.cos(phase), np.sin(phase) / size)
            value = E * (C * g_C.real + S * g_S.real)
            return value
        E = np.exp(block.mu * t)
        root = block.root
        if root == 0:
            return (E * (g_C + t * g_S)).real
        return (E * (np.cosh(root * t) * g_C + (np.sinh(root * t) / root) * g_S)).real

    def _plain(self, weights: _Order) -> tuple[np.ndarray, ...]:
        """The terms of the bound without 2 x 2 blocks (q = 1), per coordinate i and time t:

        * ‖L_i‖·G(t)(φ‖c‖t + ρ₀), G = e^{(g+φ)t}·_SAFETY (the decomposition's error);
        * Σ_j|g_ij|·e^{gt}·(shift(t)·_SAFETY + 1e-300(1 + t)e^{−gt}) (the evaluation's
          rounding, and e^{wt} below 2⁻¹⁰²², which loses relative accuracy);
        * for x'': F_rows_i·(φ + u‖B‖)(‖c‖ + ρ₀)·G(t) (F itself, and B's rounding);

        as rates r_k, slopes s_k, offsets o_k and per-row weights W_ik of
        W_ik·e^{r_k t}(s_k t + o_k) (columns (k, 1), the weights (n, k, 1)), kept with the
        order's weights. shift(t) = (2n + 8)u + 3.03u·speed·t (see :meth:`_bounds`)."""
        phi, c, rho0, S = self.phi, self.c_norm, self.rho0, _SAFETY
        rates = [self.growth + phi, self.growth, 0.0]
        slopes = [phi * c * S, 3.03 * U * self.speed * S, 1e-300]
        offsets = [rho0 * S, (2 * self.n + 8) * U * S, 1e-300]
        columns = [weights.rows, weights.size, weights.size]
        if weights.F_rows is not None:
            rates.append(self.growth + phi)
            slopes.append(0.0)
            offsets.append((phi + self.B_rounding) * (c + rho0) * S)
            columns.append(weights.F_rows)
        table = np.array([rates, slopes, offsets])[:, :, None]
        weights.plain = (table[0], table[1], table[2], np.array(columns).T[:, :, None])
        return weights.plain

    @cached_property
    def _largest_root(self) -> float:
        """max |√d| over the 2 x 2 blocks (a twin's is its partner's)."""
        return max(abs(block.root) for block in self.doubles)

    @cached_property
    def _growth_constants(self) -> tuple[float, float]:
        """(K, ν) with ‖e^{Bτ}‖ ≤ e^{μτ}·min(K, 1 + ντ) =: e^{μτ}q(τ), q nondecreasing.

        A 2 x 2 block is bounded by e^{gτ}(1 + ν_b·min(τ, 1/|√d|)) (g = Re μ_b + |Re √d|:
        |cosh(√d τ)| ≤ e^{|Re √d|τ} and |sinh(√d τ)/√d| ≤ e^{|Re √d|τ}·min(τ, 1/|√d|)), which
        is at most e^{μτ}(1 + ν_b/√(|d| − δd)) (δd the bound of d's rounding: the cap holds
        for the block as stored, not only for the computed d) and, below the top rate μ
        (g = μ − a), at most
        e^{μτ}·max_τ e^{−aτ}(1 + ν_bτ) = e^{μτ}(ν_b/a)e^{a/ν_b − 1} when ν_b > a (else
        e^{μτ}). K is the largest over the blocks of the smaller of these (inf for a
        defective block, d = 0, at the top rate), ν the largest ν_b; 1 x 1 blocks
        contribute 1.
        """
        K, nu = 1.0, 0.0
        for block in self.doubles:
            if block.skip:
                continue
            nu = max(nu, block.nu)
            gap = self.growth - block.growth
            # the stored block's own |d| is at least |d| − d_error (d is rounded)
            least = abs(block.d) - block.d_error
            cap = 1 + block.nu / math.sqrt(least) if least > 0 else math.inf
            if gap <= 0:
                below = math.inf
            elif block.nu > gap:
                below = block.nu / gap * math.exp(gap / block.nu - 1)
            else:
                below = 1.0
            K = max(K, min(cap, below))
        return K, nu

    def _bounds(self, weights: _Order, t: np.ndarray) -> np.ndarray:
        """The decomposition's error, the rounding of the evaluation and of d (times
        _SAFETY). e^{wt}'s argument is off by |w|·(2u·t + |lo|) with |lo| ≤ u·t: relative
        3.03u·|w|·t (e^δ − 1 ≤ 1.0001δ where e^{wt} neither underflows nor overflows);
        the libm, the product with the weight, the real part and the sum over 2n terms
        add (2n + 8)u. Every term is a per-coordinate constant times a per-time function,
        computed elementwise: each time's bound depends on that time alone."""
        if not weights.doubles:  # q = 1, and the weights are the 1 x 1 blocks' alone
            rates, slopes, offsets, per_row = weights.plain or self._plain(weights)
            # Σ_k per_row_k ⊗ e^{r_k t}(s_k t + o_k), added in the order of k (fewer than 8)
            terms = per_row * (np.exp(rates * t) * (slopes * t + offsets))
            bounds: np.ndarray = np.add.reduce(terms, axis=1)
            return bounds
        phi = self.phi
        shift = (2 * self.n + 8) * U + (3.03 * U * self.speed) * t
        decay = np.exp(self.growth * t)
        # e^{wt} below 2⁻¹⁰²² loses relative accuracy: 1e-300 of the weights, absolute
        tiny = 1e-300 * (1 + t)
        floor = weights.size[:, None] * tiny
        K, nu = self._growth_constants
        nu_t = nu * t
        q = np.minimum(K, 1 + nu_t)
        spread = decay * np.exp(q * phi * t)
        # ∫₀ᵗ q(t − s) q(s) ds ≤ t·q(t)², and ≤ t(1 + νt + (νt)²/6) as q(τ) ≤ 1 + ντ
        integral = t * np.minimum(q * q, 1 + nu_t + nu_t * nu_t / 6)
        bounds = weights.rows[:, None] * (spread * (phi * self.c_norm * integral
                                                    + q * self.rho0))
        if weights.F_rows is not None:
            bounds += weights.F_rows[:, None] * ((phi + self.B_rounding)
                                                  * (self.c_norm + self.rho0) * q * spread)
        # the 2 x 2 blocks, each within e^{μt} ≥ e^{Re μ_b t}·cosh(Re √d·t): cosh and sinh
        # of √d·t, whose argument's rounding moves them by ≤ 2u|√d|t of their envelopes
        # (|C| ≤ 1·, |S| ≤ t·), the libm by 4u; and the rounding δd of d: |∂C/∂d| =
        # t|S|/2 ≤ t²/2·, |∂S/∂d| ≤ t³/4·cosh(√|d|·t) (the series) with s = max |√d|
        largest = self._largest_root
        rounding = decay * (shift + (2 * largest * t + 4) * U)
        bounds += (weights.single_size + weights.double_C)[:, None] * rounding
        bounds += weights.double_S[:, None] * (rounding * t)
        squared = decay * (t * t)
        bounds += weights.d_C[:, None] * (squared / 2)
        bounds += weights.d_S[:, None] * (squared * t * np.cosh(largest * t) / 4)
        return bounds * _SAFETY + floor




class _Order:
    """The weights of one derivative order (see :meth:`BlockMotion._order`).

    ``g``: the weights g_j = weight_j·L_j c_j of the evaluated 1 x 1 blocks (the columns
    of an (n, blocks) array); ``doubles``: per 2 x 2 block (block, L_b c_b, L_b N c_b as
    columns); ``single_size`` Σ_j |g_j| per row; ``double_C`` and ``double_S`` Σ_b of
    |L_b c_b| and |L_b N c_b| per row; ``d_C`` and ``d_S`` Σ_b of the rounding δd of the
    block's d times ‖(L_b)_i‖·‖c_b‖ and ‖(L_b)_i‖·‖N c_b‖; ``rows`` the row norms of L;
    ``F_rows`` σ‖(X's velocity rows)_i‖ for order 2.
    """

    def __init__(self, L: np.ndarray, motion: BlockMotion, F_rows: np.ndarray | None) -> None:
        c = motion.c
        g = L[:, motion.columns] * (motion.weights * c[motion.columns])  # (n, blocks)
        self.g = g
        self.single_size = np.array([sum(map(abs, row)) for row in g.tolist()])
        self.rows = _row_norms(L)
        self.F_rows = F_rows
        #: the bound's terms without 2 x 2 blocks (made by BlockMotion._plain)
        self.plain: tuple[np.ndarray, ...] | None = None
        self.doubles: list[tuple[_Block, np.ndarray, np.ndarray]] = []
        #: Σ of every weight's size per row (the absolute floor of the bound)
        self.size = self.single_size
        if motion.doubles:
            self._add_doubles(L.tolist(), c.tolist(), motion.doubles)

    def _add_doubles(self, L: list[list[complex]], c: list[complex],
                     blocks: list[_Block]) -> None:
        """The 2 x 2 blocks' weights and sizes, in Python: two columns and at most four
        rows per block, fewer operations than the NumPy calls that would make them."""
        n = len(L)
        double_C, double_S, d_C, d_S = [0.0] * n, [0.0] * n, [0.0] * n, [0.0] * n
        for block in blocks:
            if block.skip:
                continue
            i, j = block.columns
            (a, b01, b10), weight = block.entries, block.weight
            ci, cj = c[i], c[j]
            Ni, Nj = a * ci + b01 * cj, b10 * ci - a * cj  # N c_b, N = [[a, b01], [b10, −a]]
            c_error = weight * block.d_error * math.hypot(abs(ci), abs(cj))
            Nc_error = weight * block.d_error * math.hypot(abs(Ni), abs(Nj))
            g_C, g_S = [], []
            for r, row in enumerate(L):
                x, y = row[i], row[j]
                C_r, S_r = weight * (x * ci + y * cj), weight * (x * Ni + y * Nj)
                g_C.append(C_r)
                g_S.append(S_r)
                size = math.hypot(abs(x), abs(y))
                double_C[r] += abs(C_r)
                double_S[r] += abs(S_r)
                d_C[r] += c_error * size
                d_S[r] += Nc_error * size
            self.doubles.append((block, np.array(g_C)[:, None], np.array(g_S)[:, None]))
        self.double_C, self.double_S, self.d_C, self.d_S = (
            np.array(double_C), np.array(double_S), np.array(d_C), np.array(d_S))
        self.size = self.single_size + self.double_C + self.double_S

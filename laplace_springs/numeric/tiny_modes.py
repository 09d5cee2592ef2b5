"""Classically damped tiny scenes: the basis of the first-order matrix from n x n modes.

When M is diagonal and positive, K and C are symmetric and K M⁻¹C = C M⁻¹K exactly
(classical damping: C = αM + βK, no damping at all, or any C the modes of K diagonalize),
x = Φq with Φ = M^{-1/2}Ψ, Ψ the orthonormal eigenvectors of M^{-1/2}(K + ξC)M^{-1/2}
(``numpy.linalg.eigh``), splits the scene into n motions q'' + c_j q' + k_j q = 0. On the
columns e₁ = (φ_j, 0) and e₂ = (0, φ_j) (‖φ_j‖ = 1) of the scaled state (x, x'/σ), the
first-order matrix Z acts as the 2 x 2 matrix [[0, σ], [−k_j/σ, −c_j]]. Each is
diagonalized in closed form, its eigenvalues λ = −c/2 ± √(c²/4 − k) (the stable quadratic
formula for real ones) with eigenvectors σ·e₁ + λ·e₂, or kept as a 2 x 2 block when its
two eigenvalues are close (near-critical modes, rigid-body modes k = c = 0), whose
exponential :class:`~laplace_springs.numeric.tiny_blocks.BlockMotion` evaluates without
cancellation. (Balancing a block by scaling e₂ to a ≈ √k_j, as one might, gave bounds
up to 1e9 times larger on 150 random scenes: the basis's conditioning costs more than
the block's norm saves.)

Why: ``numpy.linalg.eig`` of the 2n x 2n matrix returns nearly parallel eigenvectors at
critical and rigid-body modes and where frequencies repeat or nearly do, which then need
an SVD each or give large bounds; ``eigh`` of the n x n matrix returns an orthonormal
basis whatever the spacing. :class:`~laplace_springs.numeric.tiny_blocks.BlockMotion`
asks for the modes only there (its ``_MODAL_CONDITION``): on well-separated scenes the
eigenvectors serve as well and forming the modes besides costs about 35 µs.

Nothing here is trusted: the basis goes through the same residual bound as any other
(R = ZX − XB in extended precision against the exact Z), and a scene that only looks
classical in float64 is not sent here (the test is exact).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .tiny_blocks import _LINALG, BlockMotion, _as_slice, _Block

__all__ = ["ClassicalModes", "classical_modes"]

Entries = dict[tuple[int, int], Any]

#: A mode is a 2 x 2 block when its eigenvalues' distance is at most this fraction of
#: their size max(|λ₊|, |λ₋|, _RIGID·ρ) (ρ the largest |λ| of the scene): near-critical
#: modes, and rigid-body modes (k = 0 computed as ±1e-16·ρ). A slow mode far from
#: critical is diagonalized: its eigenvectors are nearly parallel in the scaled state only
#: through the scaling σ, which a block would not cure.
_MODE_CLOSENESS = 0.1
_RIGID = 1e-6
#: ξ = this times ‖K̃‖/‖C̃‖ in K̃ + ξC̃ (an irrational-looking number, so an eigenvalue of
#: K̃ split by C̃ does not stay repeated by accident).
_MIX = 0.6180339887498949


class ClassicalModes:
    """The modes of a classically damped scene in float64: the shapes φ_j (unit vectors,
    one list per mode), k_j and c_j.

    Built by :func:`classical_modes`; :meth:`layout` lays out a
    :class:`~laplace_springs.numeric.tiny_blocks.BlockMotion`'s basis from them.
    """

    def __init__(self, shapes: list[list[float]], stiffness: list[float],
                 damping: list[float]) -> None:
        self.shapes, self.stiffness, self.damping = shapes, stiffness, damping

    def layout(self, motion: BlockMotion) -> tuple[np.ndarray, np.ndarray]:
        """(w, X) for ``motion`` (its σ): per mode two columns, a conjugate pair, two real
        eigenvalues or a real 2 x 2 block; sets the motion's ``columns``, ``weights``,
        ``rates``, ``real_columns``, ``mirrors`` and ``doubles``. (In Python: a few dozen
        float operations cost less than the NumPy calls that would do them.)"""
        sigma = motion.sigma
        roots = [_roots(k, c) for k, c in zip(self.stiffness, self.damping)]
        radius = max(max(abs(high), abs(low)) for high, low in roots)
        rates: list[complex] = []
        basis: list[list[complex]] = []  # the columns of X
        columns: list[int] = []
        weights: list[float] = []
        motion.real_columns, motion.mirrors, motion.doubles = [], [], []
        for shape, k, c, (high, low) in zip(self.shapes, self.stiffness, self.damping, roots):
            p = len(rates)
            rates += [high, low]
            size = max(abs(high), abs(low), _RIGID * radius)
            if abs(high - low) <= _MODE_CLOSENESS * size:  # near critical, or rigid
                zeros = [0.0] * len(shape)
                basis += [[*shape, *zeros], [*zeros, *shape]]  # e₁ and e₂
                motion.doubles.append(_Block.of((p, p + 1), -c / 2, (c / 2, sigma, -k / sigma),
                                                real=True))
                motion.real_columns += [p, p + 1]
                continue
            for rate in (high, low) if not high.imag else (high,):  # σ·e₁ + λ·e₂, normalized
                size = math.hypot(sigma, abs(rate))
                top, bottom = sigma / size, rate / size
                basis.append([top * v for v in shape] + [bottom * v for v in shape])
            if high.imag:  # a conjugate pair: the upper one evaluated, twice its real part
                basis.append([v.conjugate() for v in basis[-1]])
                columns.append(p)
                weights.append(2.0)
                motion.mirrors.append((p + 1, p))
            else:
                columns += [p, p + 1]
                weights += [1.0, 1.0]
                motion.real_columns += [p, p + 1]
        w = np.array(rates)
        motion.columns = _as_slice(columns, w.size)
        motion.weights = np.array(weights)
        motion.rates = w[motion.columns]
        return w, np.array(basis, dtype=complex).T.copy()  # X in C order, as eig's


def _roots(k: float, c: float) -> tuple[complex, complex]:
    """The roots of λ² + cλ + k: (−c/2 + i√(k − c²/4), its conjugate), or the real ones
    (larger first) by the stable quadratic formula."""
    half = c / 2
    d = half * half - k
    if d < 0:
        high = complex(-half, math.sqrt(-d))
        return high, high.conjugate()
    root = math.sqrt(d)
    large = -half - root if half >= 0 else -half + root  # no cancellation
    small = k / large if large else 0.0
    return complex(max(large, small)), complex(min(large, small))


def classical_modes(n: int, M: Entries, K: Entries, C: Entries,
                    normalized: tuple[list[float], list[float]],
                    keys: tuple[Entries, Entries]) -> ClassicalModes | None:
    """The modes of a classically damped scene (see the module notes), or None when the
    scene is not one (M not diagonal and positive, K or C not symmetric, K M⁻¹C ≠ C M⁻¹K
    exactly) or a float64 number on the way is not finite.

    ``normalized``: the float64 values of M⁻¹K's and M⁻¹C's entries, in the order of the
    exact dicts ``keys``.

    Examples
    --------
    >>> from flint import fmpq
    >>> one, two = fmpq(1), fmpq(2)
    >>> M = {(0, 0): one, (1, 1): one}
    >>> K = {(0, 0): two, (0, 1): -one, (1, 0): -one, (1, 1): two}
    >>> modes = classical_modes(2, M, K, {}, ([2.0, -1.0, -1.0, 2.0], []), (K, {}))
    >>> [round(k, 12) for k in modes.stiffness]
    [1.0, 3.0]
    >>> classical_modes(2, M, K, {(0, 0): one}, ([2.0, -1.0, -1.0, 2.0], [1.0]),
    ...                 (K, {(0, 0): one})) is None    # a dashpot on one mass: not classical
    True
    """
    if not all(i == j for i, j in M) or not (_symmetric(K) and _symmetric(C)):
        return None
    if any((i, i) not in M or M[i, i] <= 0 for i in range(n)):
        return None
    masses = [M[i, i] for i in range(n)]
    if C and not _commute(n, K, C, masses):
        return None
    try:
        scale = [1 / math.sqrt(float(m)) for m in masses]
        stiff = _symmetrized(n, keys[0], normalized[0], masses)
        damp = _symmetrized(n, keys[1], normalized[1], masses)
    except (OverflowError, ZeroDivisionError):
        return None
    stiff_norm = math.hypot(*(v for row in stiff for v in row))
    damp_norm = math.hypot(*(v for row in damp for v in row))
    if not (all(0 < s < math.inf for s in scale) and stiff_norm < math.inf
            and damp_norm < math.inf):
        return None
    mix = _MIX * stiff_norm / damp_norm if damp_norm and stiff_norm else float(damp_norm > 0)
    vectors = _eigenvectors([[a + mix * b for a, b in zip(*rows)] for rows in zip(stiff, damp)])
    # the Rayleigh quotients give k_j and c_j whatever ξ mixed
    stiffness = [_quadratic(stiff, v) for v in vectors]
    damping = [_quadratic(damp, v) for v in vectors]
    shapes = [[s * x for s, x in zip(scale, v)] for v in vectors]
    return ClassicalModes([[x / math.hypot(*shape) for x in shape] for shape in shapes],
                          stiffness, damping)


def _symmetric(entries: Entries) -> bool:
    return all(entries.get((j, i)) == value for (i, j), value in entries.items())


def _commute(n: int, K: Entries, C: Entries, masses: list[Any]) -> bool:
    """K M⁻¹C = C M⁻¹K exactly; with K and C symmetric, P = K M⁻¹C is then symmetric (its
    transpose is C M⁻¹K). Products of the nonzero entries only, in Python (n ≤ 4)."""
    rows: dict[int, list[tuple[int, Any]]] = {}
    for (middle, j), value in C.items():
        rows.setdefault(middle, []).append((j, value))
    P: dict[tuple[int, int], Any] = {}
    for (i, middle), value in K.items():
        scaled = value / masses[middle]
        for j, damping in rows.get(middle, ()):
            P[i, j] = P.get((i, j), 0) + scaled * damping
    return all(P.get((j, i), 0) == value for (i, j), value in P.items())


def _symmetrized(n: int, exact: Entries, values: list[float],
                 masses: list[Any]) -> list[list[float]]:
    """M^{1/2}(M⁻¹E)M^{-1/2} = M^{-1/2} E M^{-1/2} in float64 (rows), from M⁻¹E's float64
    entries (within the engine's magnitude limits): entry (i, j) times √(m_i/m_j), then
    the mean of it and its transpose (equal up to the roundings)."""
    out = [[0.0] * n for _ in range(n)]
    for (i, j), value in zip(exact, values):
        out[i][j] = value if i == j else value * math.sqrt(float(masses[i] / masses[j]))
    return [[(out[i][j] + out[j][i]) / 2 for j in range(n)] for i in range(n)]


def _quadratic(S: list[list[float]], v: list[float]) -> float:
    """vᵀSv."""
    return sum(x * sum(a * y for a, y in zip(row, v)) for x, row in zip(v, S))


def _eigenvectors(S: list[list[float]]) -> list[list[float]]:
    """Orthonormal eigenvectors of the symmetric S (one list per vector): for 2 x 2 the
    Jacobi rotation that diagonalizes it (Golub & Van Loan, *Matrix Computations*, 4th ed.,
    §8.5.2: t = tan θ the smaller root of t² + 2τt − 1 = 0), else LAPACK's ``dsyevd``
    (directly where NumPy exposes it)."""
    if len(S) == 2:
        (a, b), (_, c) = S
        if b == 0:
            return [[1.0, 0.0], [0.0, 1.0]]
        tau = (c - a) / (2 * b)
        t = math.copysign(1.0, tau) / (abs(tau) + math.hypot(1.0, tau))
        cos = 1 / math.hypot(1.0, t)
        sin = t * cos
        return [[cos, -sin], [sin, cos]]
    matrix = np.array(S)
    gufunc = getattr(_LINALG, "eigh_lo", None)
    vectors = np.linalg.eigh(matrix)[1] if gufunc is None else gufunc(matrix, signature="d->dd")[1]
    return vectors.T.tolist()

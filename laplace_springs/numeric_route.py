"""Numeric route: x(t) from a scaled linearisation of the quadratic eigenvalue problem.

For scenes too large for exact partial fractions (or with non-rational entries) the
motion comes from the eigen-decomposition of the first-order matrix, computed in
float64 and made robust where plain eigen-decompositions fail:

1. **Reduction.** With M = L Lᵀ (Cholesky; ``M⁻¹`` for a non-symmetric M) the system
   becomes q'' + Ĉ q' + K̂ q = 0 with x = L⁻ᵀ q.
2. **Scaling** (Fan, Lin & Van Dooren 2004; Tisseur & Meerbergen 2001, §6). Time is
   measured in units of 1/γ, γ = sqrt(‖K̂‖₂), so that the scaled quadratic
   μ² I + μ Ĉ/γ + K̂/γ² has coefficients of norm ≲ 1 and its companion linearisation
   Z = [[0, I], [-K̂/γ², -Ĉ/γ]] is solved by a backward-stable ``numpy.linalg.eig``.
   λ = γ μ. The determinant Δ(λ) is never expanded (``numpy.roots`` of it loses
   all accuracy beyond a few dozen masses).
3. **Conditioning.** Each eigenvalue's condition number κ = ‖wₖ‖‖vₖ‖ comes from the
   eigenvector matrix and its inverse. Eigenvalues with κ above
   :data:`KAPPA_MAX` (defective or nearly defective: critical damping, rigid-body
   modes, exceptional points) are grouped with their neighbours up to the widest
   relative gap, and each group is replaced by an orthonormal basis of its invariant
   subspace (shift-and-invert subspace iteration) and the small block T it carries.
   Its contribution F e^{Tt} c is evaluated by a scaled Taylor series with squaring,
   which is continuous through coalescing eigenvalues: no eigenvector of a defective
   eigenvalue is ever used, and equal but non-defective eigenvalues (symmetric
   frequencies) give T ≈ μI, hence no secular t-terms.
4. **Refinement.** Well-conditioned eigenvalues get one Newton step on the quadratic
   itself, kept only when its rounding noise is below the eigen-solver's error
   (this restores full relative accuracy of slow poles under heavy damping).

``evaluate(times, dps=...)`` does not use the float64 decomposition at all: it
evaluates exp(Zt)·y₀ in python-flint ball arithmetic from the exact scene data,
raising the precision until the result is certified to the requested digits.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Sequence

import mpmath
import numpy as np
import sympy as sp

from .errors import SceneError
from .numbers import TIME
from .solution import Verification

if TYPE_CHECKING:
    from .scene import Scene

__all__ = ["KAPPA_MAX", "Block", "Modes", "NumericSolution", "solve_numeric", "decompose_numeric"]

#: Eigenvalue condition number above which a mode is treated inside a block.
KAPPA_MAX = 1e3
#: Condition number above which a mode is treated in a block if it is also near another
#: eigenvalue (closer than NEAR times its own modulus): a nearly defective pair.
KAPPA_NEAR, NEAR = 10.0, 0.1
#: Relative error estimate above which float evaluation switches to ball arithmetic.
ESCALATE = 1e-13
#: Largest number of eigenvalues grouped around one ill-conditioned eigenvalue.
MAX_GROUP = 8
_EPS = np.finfo(float).eps
_RNG_SEED = 20011


# ----------------------------------------------------------------------------- scene data


def _symbolic_entries(scene: Scene) -> list[str]:
    found: list[str] = []
    if not scene.free_symbols:
        return found
    for name in ("M", "C", "K", "x0", "v0"):
        matrix = getattr(scene, name)
        for index, entry in enumerate(matrix):
            if entry.free_symbols:
                i, j = divmod(index, matrix.cols)
                label = f"{name}[{i}]" if name in ("x0", "v0") else f"{name}[{i},{j}]"
                found.append(f"{label} = {entry}")
    return found


def _float_matrix(matrix: sp.MatrixBase, name: str) -> np.ndarray:
    out = np.zeros(matrix.shape)
    for (i, j), entry in matrix.todok().items():
        try:
            out[i, j] = float(entry)
        except (TypeError, OverflowError, ValueError):
            raise SceneError(f"{name}[{i},{j}] = {entry} has no float64 value") from None
    if not np.all(np.isfinite(out)):
        raise SceneError(f"{name} has entries beyond the float64 range")
    return out


def scene_arrays(scene: Scene) -> tuple[np.ndarray, ...]:
    """(M, C, K, x0, v0) of a numeric scene as float64 arrays (x0, v0 flat).

    Raises
    ------
    SceneError
        Naming every symbolic entry, if there are any.

    Examples
    --------
    >>> from laplace_springs import Scene
    >>> M, C, K, x0, v0 = scene_arrays(Scene.from_matrices(M=[[2]], K=[[8]], x0=[1], v0=[0]))
    >>> M, K, x0
    (array([[2.]]), array([[8.]]), array([1.]))
    """
    symbolic = _symbolic_entries(scene)
    if symbolic:
        raise SceneError("the numeric route needs numbers, but these entries are symbolic: "
                         + ", ".join(symbolic))
    M, C, K = (_float_matrix(getattr(scene, name), name) for name in ("M", "C", "K"))
    x0, v0 = (_float_matrix(getattr(scene, name), name).ravel() for name in ("x0", "v0"))
    return M, C, K, x0, v0


# ----------------------------------------------------------------------------- reduction


@dataclass(frozen=True)
class _Reduced:
    """q'' + C q' + K q = 0 with x = back @ q; q0 and dq0 its initial data."""

    C: np.ndarray
    K: np.ndarray
    back: np.ndarray
    q0: np.ndarray
    dq0: np.ndarray


def _check_invertible(M: np.ndarray) -> None:
    if np.linalg.cond(M) > 1e14:
        raise SceneError(f"the numeric route needs an invertible mass matrix, but M is singular "
                         f"to working precision (condition number {np.linalg.cond(M):.3g})")


def _reduce(M: np.ndarray, C: np.ndarray, K: np.ndarray, x0: np.ndarray, v0: np.ndarray) -> _Reduced:
    _check_invertible(M)
    if np.array_equal(M, M.T):
        try:
            L = np.linalg.cholesky(M)
        except np.linalg.LinAlgError:
            L = None
        if L is not None:
            Linv = np.linalg.solve(L, np.eye(len(M)))
            return _Reduced(Linv @ C @ Linv.T, Linv @ K @ Linv.T, Linv.T, L.T @ x0, L.T @ v0)
    return _Reduced(np.linalg.solve(M, C), np.linalg.solve(M, K), np.eye(len(M)), x0, v0)


def _norm(A: np.ndarray) -> float:
    """sqrt(‖A‖₁‖A‖∞): an upper bound on ‖A‖₂ within a factor √n, without an SVD."""
    return float(math.sqrt(np.linalg.norm(A, 1) * np.linalg.norm(A, np.inf)))


def massless_nodes(M: np.ndarray) -> list[int]:
    """Indices whose row and column of M are zero (massless nodes)."""
    return [i for i in range(len(M)) if not M[i].any() and not M[:, i].any()]


def _massless_system(M: np.ndarray, C: np.ndarray, K: np.ndarray, x0: np.ndarray, v0: np.ndarray,
                     z: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """y' = Z y with y = [x; x_m'] when the massless nodes z are held by dashpots.

    Their rows give C_zz x_z' = -(K x)_z - C_zm x_m', so x_z' is a function of the state
    and x_z is continuous at t = 0 (an invertible C_zz admits no jump); v0 of the
    massless nodes plays no role, as in the transform X(λ).
    """
    n = len(M)
    m = [i for i in range(n) if i not in z]
    Czz, Mmm = C[np.ix_(z, z)], M[np.ix_(m, m)]
    if np.linalg.cond(Czz) > 1e12:
        raise SceneError(f"the numeric route handles massless nodes held by dashpots (invertible C "
                         f"block on them); nodes {z} are not: use method='exact'")
    if m and np.linalg.cond(Mmm) > 1e14:
        raise SceneError("the numeric route needs an invertible mass matrix on the massive nodes")
    P = -np.linalg.solve(Czz, K[z, :])
    Q = -np.linalg.solve(Czz, C[np.ix_(z, m)])
    Cmz = C[np.ix_(m, z)]
    Z = np.zeros((n + len(m), n + len(m)))
    Z[m, n + np.arange(len(m))] = 1
    Z[z, :n], Z[z, n:] = P, Q
    if m:
        Z[n:, :n] = -np.linalg.solve(Mmm, K[m, :] + Cmz @ P)
        Z[n:, n:] = -np.linalg.solve(Mmm, C[np.ix_(m, m)] + Cmz @ Q)
    return Z, np.concatenate([x0, v0[m]])


def _scaling(reduced: _Reduced) -> float:
    """γ of Fan, Lin & Van Dooren for the monic quadratic: sqrt(‖K‖), else ‖C‖, else 1."""
    stiffness = _norm(reduced.K)
    if stiffness > 0:
        return math.sqrt(stiffness)
    damping = _norm(reduced.C)
    return damping if damping > 0 else 1.0


def _companion(reduced: _Reduced, gamma: float) -> tuple[np.ndarray, np.ndarray]:
    """Z = [[0, I], [-K/γ², -C/γ]] and y₀ = [q₀, q₀'/γ] (time in units of 1/γ)."""
    n = len(reduced.K)
    Z = np.zeros((2 * n, 2 * n))
    Z[:n, n:] = np.eye(n)
    Z[n:, :n] = -reduced.K / gamma**2
    Z[n:, n:] = -reduced.C / gamma
    return Z, np.concatenate([reduced.q0, reduced.dq0 / gamma])


# ----------------------------------------------------------------------------- eigen-structure


def _inverse(V: np.ndarray) -> np.ndarray:
    with np.errstate(all="ignore"):
        try:
            W = np.linalg.inv(V)
            if np.all(np.isfinite(W)):
                return W
        except np.linalg.LinAlgError:
            pass
    return np.linalg.pinv(V)


def _condition_numbers(V: np.ndarray, W: np.ndarray) -> np.ndarray:
    """κₖ = ‖wₖ‖‖vₖ‖, the eigenvalue condition numbers (W = V⁻¹, rows are left vectors)."""
    with np.errstate(all="ignore"):
        kappa = np.linalg.norm(W, axis=1) * np.linalg.norm(V, axis=0)
    return np.where(np.isfinite(kappa), kappa, np.inf)


def _group_around(k: int, mu: np.ndarray, scale: float) -> np.ndarray:
    """k and its nearest neighbours up to the widest relative gap in distance."""
    distance = np.abs(mu - mu[k])
    distance[k] = np.inf
    order = np.argsort(distance)[: min(MAX_GROUP - 1, len(mu) - 1)]
    near = np.maximum(distance[order], 1e-3 * _EPS * scale)
    everything = len(order) == len(mu) - 1  # taking all: as if the next one were at 10·‖Z‖
    beyond = np.append(near[1:], 10 * max(scale, near[-1]) if everything else
                       np.partition(distance, len(order))[len(order)])
    members = int(np.argmax(beyond / near)) + 1
    return np.append(order[:members], k)


def _ill_conditioned(mu: np.ndarray, kappa: np.ndarray) -> np.ndarray:
    """Indices of eigenvalues with κ > KAPPA_MAX, or κ > KAPPA_NEAR and a close neighbour.

    The companion form gives low-frequency modes κ ≈ 1/(2|μ|) without harm (their
    neighbours are about |μ| away); a nearly defective pair has its partner much closer.
    """
    if len(mu) < 2:
        return np.flatnonzero(kappa > KAPPA_MAX)
    distance = np.abs(mu[:, None] - mu[None, :])
    np.fill_diagonal(distance, np.inf)
    near = distance.min(axis=1) < NEAR * np.abs(mu)
    return np.flatnonzero((kappa > KAPPA_MAX) | ((kappa > KAPPA_NEAR) & near))


def _groups(mu: np.ndarray, kappa: np.ndarray, scale: float) -> list[list[int]]:
    """Disjoint groups (size ≥ 2) around the ill-conditioned eigenvalues."""
    parent = list(range(len(mu)))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for k in _ill_conditioned(mu, kappa):
        for j in _group_around(int(k), mu, scale):
            parent[root(int(j))] = root(int(k))
    groups: dict[int, list[int]] = {}
    for i in range(len(mu)):
        groups.setdefault(root(i), []).append(i)
    return [g for g in groups.values() if len(g) > 1]


def _invariant_subspace(Z: np.ndarray, group: np.ndarray, mu: np.ndarray, start: np.ndarray,
                        rng: np.random.Generator) -> tuple[np.ndarray, bool, float]:
    """Orthonormal basis of the invariant subspace of the eigenvalues ``mu[group]``.

    Shift-and-invert subspace iteration from the (possibly rank-deficient) computed
    eigenvectors. The shift sits at 1/20 of the gap g to the other eigenvalues: close
    enough to converge at the rate (radius + g/20)/(g - g/20), far enough that the
    inverse does not drown the generalized eigenvectors of a defective eigenvalue
    (a shift at distance d loses about ε/d of them).

    Returns the basis, whether it converged, and an estimate of its error: the larger
    of ε‖Z‖/d and ‖residual‖/gap (measured: 3e-14 actual against 6e-14 and 8e-14 for a
    free mass beside a damped one).
    """
    N, m = start.shape
    if m == N:
        return np.eye(N, dtype=complex), True, 0.0
    center = mu[group].mean()
    radius = np.max(np.abs(mu[group] - center))
    gap = np.min(np.abs(np.delete(mu, group) - center))
    offset = gap / 20
    rate = (radius + offset) / max(gap - offset, 1e-300)
    if not rate < 0.5:
        return start, False, 1.0
    inverse = np.linalg.inv(Z - (center + offset * np.exp(0.3j)) * np.eye(N))
    noise = rng.standard_normal((N, m)) + 1j * rng.standard_normal((N, m))
    Q = np.linalg.qr(start / np.linalg.norm(start, axis=0) + 1e-3 * noise)[0]
    for _ in range(min(60, int(np.log(_EPS) / np.log(rate)) + 3)):
        Q = np.linalg.qr(inverse @ Q)[0]
    residual = Z @ Q - Q @ (Q.conj().T @ Z @ Q)
    error = max(_EPS * _norm(Z) / offset, np.linalg.norm(residual, 2) / gap)
    return Q, bool(np.linalg.norm(residual, 1) <= 1e-10 * max(1.0, np.linalg.norm(Z, 1))), float(error)


def _newton_step(Z: np.ndarray, mu: np.ndarray, V: np.ndarray, W: np.ndarray,
                 kappa: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One Newton step on μ²I + μC + K for each eigenvalue, where it is trustworthy.

    With W = V⁻¹ the denominator w₂ (2μ + C) v₁ equals w·v = 1. The step is kept only
    when its rounding noise is well below the eigen-solver's own error κ·ε·‖Z‖.

    Returns
    -------
    mu, error : numpy.ndarray
        The eigenvalues and an estimate of their absolute error.
    """
    n = Z.shape[0] // 2
    C, K = -Z[n:, n:], -Z[n:, :n]
    X, W2 = V[:n], W[:, n:]
    with np.errstate(all="ignore"):
        residual = X * mu**2 + (C @ X) * mu + K @ X
        step = -np.einsum("ki,ik->k", W2, residual)
        size = np.linalg.norm(W2, axis=1) * np.linalg.norm(X, axis=0)
        noise = _EPS * size * (np.abs(mu) ** 2 + np.abs(mu) * _norm(C) + _norm(K))
        solver = _EPS * kappa * _norm(Z)
        keep = (kappa <= KAPPA_NEAR) & (noise < 0.1 * solver) & (np.abs(step) < 100 * solver)
    return np.where(keep, mu + step, mu), np.where(keep, noise + _EPS * np.abs(mu), solver)


# ----------------------------------------------------------------------------- modes


@dataclass(frozen=True, eq=False)
class Block:
    """A group of clustered eigenvalues; it contributes F e^{T t} c to x(t).

    Attributes
    ----------
    T : numpy.ndarray
        m x m complex matrix (time in the scene's units) whose eigenvalues are the group's.
    F : numpy.ndarray
        n x m complex map from the block's coordinates to x.
    c : numpy.ndarray
        The block's m initial coordinates.
    kappa : float
        Condition of the block's coordinates within the whole basis.
    y0_norm : float
        ‖y₀‖ of the whole initial state, the scale of the absolute error in ``c``.
    basis_error : float
        Estimated error of the block's basis columns (subspace iteration).
    """

    T: np.ndarray
    F: np.ndarray
    c: np.ndarray
    kappa: float
    y0_norm: float = 0.0
    basis_error: float = 0.0

    @cached_property
    def center(self) -> complex:
        return complex(np.trace(self.T) / len(self.T))

    def poles(self) -> np.ndarray:
        """The eigenvalues of T; a group tighter than √ε relative is reported as one repeated pole."""
        values = np.linalg.eigvals(self.T)
        spread = np.max(np.abs(values - self.center))
        if spread <= 1e-7 * max(abs(self.center), np.linalg.norm(self.T, 2), 1e-300):
            return np.full(len(values), self.center)
        return values

    def perturbed(self, size: float, rng: np.random.Generator) -> Block:
        """The block with T moved by a random complex matrix of 2-norm ``size``."""
        m = len(self.T)
        E = rng.standard_normal((m, m)) + 1j * rng.standard_normal((m, m))
        return Block(self.T + E * (size / np.linalg.norm(E, 2)), self.F, self.c, self.kappa, self.y0_norm,
                     self.basis_error)

    @cached_property
    def shift(self) -> complex:
        """The rightmost real part of T's eigenvalues, with the centre's imaginary part.

        Factoring out e^{shift·t} leaves e^{(T - shift)t} bounded by its non-normality
        alone, so neither factor overflows when the block spans many decades of rates.
        """
        return complex(np.max(np.linalg.eigvals(self.T).real), self.center.imag)

    def exp_matrices(self, times: np.ndarray) -> np.ndarray:
        """e^{T t} for each t, shape (len(times), m, m), as e^{shift·t} e^{(T - shift)t}."""
        times = np.asarray(times, dtype=float)
        N = self.T - self.shift * np.eye(len(self.T))
        norm = np.linalg.norm(N, 1)
        out = np.empty((len(times), len(self.T), len(self.T)), dtype=complex)
        squarings = np.maximum(0, np.ceil(np.log2(np.maximum(norm * np.abs(times), 1e-300)))).astype(int)
        for s in np.unique(squarings):
            cols = np.flatnonzero(squarings == s)
            out[cols] = _exp_batch(N, times[cols], int(s))
        with np.errstate(over="ignore", invalid="ignore"):
            return out * np.exp(self.shift * times)[:, None, None]

    def exp_times(self, times: np.ndarray, vector: np.ndarray) -> np.ndarray:
        """e^{T t}·vector for each t, shape (m, len(times))."""
        return np.einsum("tij,j->it", self.exp_matrices(times), vector)


def _exp_batch(N: np.ndarray, times: np.ndarray, squarings: int) -> np.ndarray:
    """e^{N t} for the given times: Taylor series of degree 20 on N t/2^s, squared s times."""
    A = N[None, :, :] * (times[:, None, None] / 2.0**squarings)
    E = np.broadcast_to(np.eye(len(N), dtype=complex), A.shape).copy()
    term = E.copy()
    for k in range(1, 21):
        term = term @ A / k
        E = E + term
    for _ in range(squarings):
        E = E @ E
    return E


@dataclass(frozen=True, eq=False)
class Modes:
    """x(t) = Re[Σₖ weights[:, k] e^{rates[k] t} + Σ_blocks F e^{Tt} c].

    ``rates`` are the well-conditioned eigenvalues λ (both of each conjugate pair),
    ``kappa`` their condition numbers, ``rate_error`` estimates of their absolute
    errors; ``blocks`` the clustered groups; ``norm`` is γ‖Z‖₂, the size of the
    first-order matrix in the scene's time unit. ``reach`` is ‖F_k‖·‖y₀‖ for each simple
    mode k, repeated down the n rows: a weight F_k c_k computed from eigenvectors and
    c = X⁻¹y₀ carries an absolute error of about u·κ times it in every coordinate, even
    where the weight itself is zero.
    """

    rates: np.ndarray
    weights: np.ndarray
    kappa: np.ndarray
    rate_error: np.ndarray
    blocks: tuple[Block, ...]
    norm: float
    reach: np.ndarray
    warnings: tuple[str, ...] = ()

    def poles(self) -> np.ndarray:
        values = np.concatenate([self.rates, *[b.poles() for b in self.blocks]])
        scale = max(np.max(np.abs(values), initial=0.0), 1e-300)
        return values[np.lexsort((values.imag, np.round(values.real / scale, 12)))]

    def _half(self) -> tuple[np.ndarray, np.ndarray]:
        """The rates with Im ≥ 0 and their weights, doubled for Im > 0, if pairs match."""
        upper, lower = self.rates.imag > 0, self.rates.imag < 0
        if np.sort_complex(self.rates[upper]).tolist() != np.sort_complex(self.rates[lower].conj()).tolist():
            return self.rates, self.weights
        keep = ~lower
        return self.rates[keep], self.weights[:, keep] * np.where(upper[keep], 2.0, 1.0)

    def _half_blocks(self) -> list[tuple[Block, float]]:
        """Blocks with their factor: 2 for one of a conjugate pair (the other is dropped), else 1."""
        upper = [b for b in self.blocks if b.center.imag > 0]
        lower = [b for b in self.blocks if b.center.imag < 0]
        partners = []
        for block in upper:
            match = [b for b in lower if len(b.T) == len(block.T) and b not in partners
                     and abs(b.center - block.center.conjugate()) <= 1e-8 * max(1.0, abs(block.center))]
            partners.extend(match[:1])
        if len(partners) != len(lower) or len(upper) != len(lower):
            return [(b, 1.0) for b in self.blocks]
        return [(b, 2.0 if b.center.imag > 0 else 1.0) for b in self.blocks if b.center.imag >= 0]

    def values(self, times: np.ndarray, order: int = 0) -> np.ndarray:
        """d^order x/dt^order at the times, float64, shape (n, len(times))."""
        rates, weights = self._half()
        with np.errstate(over="ignore", invalid="ignore"):
            total = (weights * rates**order) @ np.exp(np.outer(rates, times))
        for block, factor in self._half_blocks():
            vector = np.linalg.matrix_power(block.T, order) @ block.c
            total = total + factor * (block.F @ block.exp_times(times, vector))
        return total.real

    def values_and_errors(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`values` and :meth:`error_estimate` together."""
        return self.values(times), self.error_estimate(times)

    def error_estimate(self, times: np.ndarray) -> np.ndarray:
        """A first-order estimate of the absolute float64 error of :meth:`values`.

        A simple mode contributes e^{αt} (u·κ·(|w| + ‖F_k‖‖y₀‖) + |w|·δλ·|t|): the
        error u of the basis columns (the eigen-solver's backward error 4ε√(2n), or a
        block's subspace error if larger) amplified by its condition number, in
        amplitude (relative to the weight, and absolute from projecting y₀ on the basis),
        and the error δλ of its rate, in phase. A block contributes u·κ_B·‖F‖ times
        ‖e^{Tt}c‖ + ‖e^{Tt}‖‖y₀‖ (normwise: eigenvector errors are not entrywise), plus
        three times the change of F e^{Tt} c under a random perturbation of T of size
        u·‖Z‖ (its sensitivity, whatever its eigen-structure).
        """
        size = len(self.kappa) + sum(len(b.T) for b in self.blocks)
        unit = max([4 * _EPS * math.sqrt(max(size, 1)), *(b.basis_error for b in self.blocks)])
        with np.errstate(over="ignore", invalid="ignore"):
            growth = np.exp(np.outer(self.rates.real, times))
            total = ((np.abs(self.weights) + self.reach) * self.kappa * unit) @ growth
            total += (np.abs(self.weights) * self.rate_error) @ (growth * np.abs(times))
        rng = np.random.default_rng(_RNG_SEED)
        for block, factor in self._half_blocks():
            exps = block.exp_matrices(times)
            inner = np.einsum("tij,j->it", exps, block.c)
            moved = block.perturbed(unit * self.norm, rng).exp_times(times, block.c)
            # ‖y₀‖‖e^{Tt}‖_F: how far an absolute error in c travels
            spread = np.linalg.norm(inner, axis=0) + np.linalg.norm(exps, axis=(1, 2)) * block.y0_norm
            total = total + factor * unit * block.kappa * np.linalg.norm(block.F, 2) * spread
            total = total + factor * 3 * np.abs(block.F @ (moved - inner))
        return total


#: Largest first-order size for which an unseparable group falls back to one block for all.
WHOLE_BLOCK_MAX = 64


def _basis(Z: np.ndarray, mu: np.ndarray, V: np.ndarray, groups: list[list[int]]):
    """Simple eigenvalues, basis [their eigenvectors | group bases], (block, basis error)s, warnings.

    A group whose invariant subspace does not separate from the rest makes the whole
    matrix one block when it is small (exact, evaluated by scaling and squaring);
    otherwise its eigenvalues stay simple modes, with a warning.
    """
    rng = np.random.default_rng(_RNG_SEED)
    columns, blocks, grouped, warnings = [], [], [], []
    for group in groups:
        Q, converged, error = _invariant_subspace(Z, np.array(group), mu, V[:, group], rng)
        if converged:
            columns.append(Q)
            blocks.append((Q.conj().T @ Z @ Q, error))
            grouped.extend(group)
        elif len(Z) <= WHOLE_BLOCK_MAX:
            return np.arange(0), np.eye(len(Z), dtype=complex), [(Z.astype(complex), 0.0)], []
        else:
            warnings.append(f"{len(group)} clustered poles near {complex(mu[group].mean()):.4g} (scaled) "
                            "could not be separated; kept as simple modes, accuracy may suffer")
    simple = np.setdiff1d(np.arange(len(mu)), grouped)
    return simple, np.hstack([V[:, simple], *columns]), blocks, warnings


def decompose_numeric(scene: Scene) -> Modes:
    """The :class:`Modes` of a numeric scene (see the module documentation).

    Examples
    --------
    A critically damped mass has one defective double pole at -1, kept as a block:

    >>> from laplace_springs import Scene
    >>> modes = decompose_numeric(Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[0]))
    >>> len(modes.rates), len(modes.blocks), modes.poles().round(12)
    (0, 1, array([-1.+0.j, -1.+0.j]))
    """
    M, C, K, x0, v0 = scene_arrays(scene)
    z = massless_nodes(M)
    if z:  # the state is [x; massive velocities]; time scaled by ‖Z‖ only
        Z, y0 = _massless_system(M, C, K, x0, v0, z)
        gamma = _norm(Z) or 1.0
        Z, back = Z / gamma, np.eye(len(M))
    else:
        reduced = _reduce(M, C, K, x0, v0)
        gamma = _scaling(reduced)
        Z, y0 = _companion(reduced, gamma)
        back = reduced.back
    mu, V = np.linalg.eig(Z)
    V = V / np.linalg.norm(V, axis=0)
    W = _inverse(V)
    kappa = _condition_numbers(V, W)
    scale = max(_norm(Z), _EPS)
    groups = _groups(mu, kappa, scale)
    if z:
        error = _EPS * kappa * scale
    else:
        mu, error = _newton_step(Z, mu, V, W, kappa)
    simple, X, blocks, warnings = _basis(Z, mu, V, groups)
    Xinv = W[simple] if len(simple) == len(mu) else _inverse(X)
    return _modes(back, gamma, scale, mu[simple], error[simple], X, Xinv, blocks, y0, warnings)


def _modes(back: np.ndarray, gamma: float, scale: float, mu_simple: np.ndarray, error: np.ndarray,
           X: np.ndarray, Xinv: np.ndarray, blocks: list[tuple[np.ndarray, float]], y0: np.ndarray,
           warnings: list[str]) -> Modes:
    n = len(back)
    c = Xinv @ y0
    kappa = _condition_numbers(X, Xinv)
    k = len(mu_simple)
    F = back @ X[:n]
    out_blocks, start = [], k
    for T, basis_error in blocks:
        m = len(T)
        part = slice(start, start + m)
        block_kappa = float(np.linalg.norm(Xinv[part], 2) * np.linalg.norm(X[:, part], 2))
        out_blocks.append(Block(gamma * T, F[:, part], c[part], block_kappa, float(np.linalg.norm(y0)),
                                basis_error))
        start += m
    reach = np.broadcast_to(np.linalg.norm(F[:, :k], axis=0) * np.linalg.norm(y0), (n, k))
    return Modes(gamma * mu_simple, F[:, :k] * c[:k], kappa[:k], gamma * error,
                 tuple(out_blocks), gamma * scale, reach, tuple(warnings))


# ----------------------------------------------------------------------------- closed form


def _block_terms(block: Block, tol: float = 1e-13):
    """(rate, coefficient vectors by power of t) of a block: polynomial×exp if T-μ is nilpotent."""
    m = len(block.T)
    N = block.T - block.center * np.eye(m)
    scale = max(np.linalg.norm(block.T, 1), 1e-300)
    if np.linalg.norm(np.linalg.matrix_power(N, m), 1) <= tol * scale**m:
        powers, vector = [], block.c.astype(complex)
        for p in range(m):
            powers.append(block.F @ vector / math.factorial(p))
            vector = N @ vector
        return [(block.center, powers)]
    values, vectors = np.linalg.eig(block.T)
    coords = np.linalg.solve(vectors, block.c)
    return [(values[k], [block.F @ vectors[:, k] * coords[k]]) for k in range(m)]


def _collect(modes: Modes) -> dict[tuple[int, float, float], np.ndarray]:
    """Real-form coefficients: (power, α, β ≥ 0) -> 2 x n array of cos and sin weights."""
    table: dict[tuple[int, float, float], np.ndarray] = {}
    poles = modes.poles()
    tiny = 1e-13 * max(np.max(np.abs(poles), initial=0.0), 1e-300)

    def add(power: int, rate: complex, weight: np.ndarray) -> None:
        beta = abs(rate.imag) if abs(rate.imag) > tiny else 0.0
        key = (power, float(rate.real) if abs(rate.real) > tiny else 0.0, float(beta))
        sign = -1.0 if rate.imag >= 0 else 1.0  # Re(g e^{iβt}) = Re g cos βt - Im g sin βt
        entry = table.setdefault(key, np.zeros((2, len(weight))))
        entry[0] += weight.real
        if beta:
            entry[1] += sign * weight.imag

    rates, weights = modes._half()
    for k, rate in enumerate(rates):
        add(0, complex(rate), weights[:, k])
    for block, factor in modes._half_blocks():
        for rate, powers in _block_terms(block):
            for p, weight in enumerate(powers):
                add(p, complex(rate), factor * weight)
    return table


def _closed_form(modes: Modes, n: int, relative: float = 1e-13) -> sp.ImmutableMatrix:
    table = _collect(modes)
    largest = max((np.max(np.abs(v)) for v in table.values()), default=0.0)
    rows: list[sp.Expr] = [sp.Integer(0)] * n
    t = TIME
    for (power, alpha, beta), weights in sorted(table.items()):
        growth = t**power * (sp.exp(sp.Float(alpha, 15) * t) if alpha else 1)
        for i in range(n):
            a, b = (float(w) if abs(w) > relative * largest else 0.0 for w in weights[:, i])
            if beta and (a or b):
                wave = sp.Float(a, 15) * sp.cos(sp.Float(beta, 15) * t) + sp.Float(b, 15) * sp.sin(sp.Float(beta, 15) * t)
            elif a:
                wave = sp.Float(a, 15)
            else:
                continue
            rows[i] += growth * wave
    return sp.ImmutableMatrix(rows)


# ----------------------------------------------------------------------------- certified evaluation


def _arb_entry(value: sp.Expr, digits: int):
    from flint import arb, fmpq

    if isinstance(value, sp.Rational):
        return arb(fmpq(int(value.p), int(value.q)))
    from .algebraic import numeric_value

    mid = arb(str(sp.Float(numeric_value(value, digits + 10), digits + 10)))
    return arb(mid.mid(), abs(mid.mid()) * arb(10) ** (-digits) + mid.rad())


def _arb_matrix(matrix: sp.MatrixBase, digits: int):
    from flint import arb_mat

    return arb_mat(matrix.rows, matrix.cols, [_arb_entry(e, digits) for e in matrix])


def _arb_time(value, digits: int):
    """A time as an arb ball; floats by their shortest decimal (0.1 is 1/10), like the exact route."""
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float):
        value = sp.Rational(repr(value))
    elif isinstance(value, mpmath.mpf):
        sign, man, exp, _ = value._mpf_
        value = sp.Rational(-man if sign else man) * sp.Integer(2) ** exp
    elif isinstance(value, str):
        from .numbers import to_exact

        value = to_exact(value, "time")
    return _arb_entry(sp.sympify(value), digits)


def _arb_sub(A, rows: list[int], cols: list[int]):
    from flint import arb_mat

    return arb_mat(len(rows), len(cols), [A[i, j] for i in rows for j in cols])


def _arb_first_order(scene: Scene, digits: int):
    """y' = Z y, y₀ in arb at the current flint precision: y = [x; x'], or [x; x_m'] with
    massless nodes z (rows and columns of M zero) held by dashpots, as in the float route."""
    from flint import arb_mat

    n = scene.n
    M, C, K = (_arb_matrix(getattr(scene, name), digits) for name in ("M", "C", "K"))
    z = [i for i in range(n) if all(scene.M[i, j] == 0 and scene.M[j, i] == 0 for j in range(n))]
    m = [i for i in range(n) if i not in z]
    every = list(range(n))
    try:
        Mmm_inv = _arb_sub(M, m, m).inv() if m else None
        Czz_inv = _arb_sub(C, z, z).inv() if z else None
    except ZeroDivisionError:
        raise SceneError("the numeric route needs an invertible mass block and, for massless "
                         "nodes, an invertible dashpot block on them") from None
    Z = arb_mat(n + len(m), n + len(m))
    Avel, Bvel = -_arb_sub(K, m, every), -_arb_sub(C, m, m)
    if z:
        P, Q = -(Czz_inv * _arb_sub(K, z, every)), -(Czz_inv * _arb_sub(C, z, m))
        Cmz = _arb_sub(C, m, z)
        Avel, Bvel = Avel - Cmz * P, Bvel - Cmz * Q
        for row, i in enumerate(z):
            for j in range(n):
                Z[i, j] = P[row, j]
            for j in range(len(m)):
                Z[i, n + j] = Q[row, j]
    if m:
        Avel, Bvel = Mmm_inv * Avel, Mmm_inv * Bvel
    for row, i in enumerate(m):
        Z[i, n + row] = 1
        for j in range(n):
            Z[n + row, j] = Avel[row, j]
        for j in range(len(m)):
            Z[n + row, n + j] = Bvel[row, j]
    return Z, _arb_matrix(sp.Matrix([*scene.x0, *[scene.v0[i] for i in m]]), digits)


def certified_motion(scene: Scene, times: Sequence, dps: int, *, max_bits: int = 8192):
    """x(t) to ``dps`` digits (relative to max |x|) from exp(Zt)·y₀ in flint ball arithmetic.

    Returns
    -------
    values, errors : numpy.ndarray
        Object array of mpmath numbers at ``dps`` digits, and float bounds on their error.

    Notes
    -----
    One ball matrix exponential of order 2n per time: milliseconds for a few masses,
    seconds per time for a few hundred.
    """
    from flint import ctx

    n, bits = scene.n, int(dps * 3.33) + 40
    while bits <= max_bits:
        with ctx.workprec(bits):
            Z, y0 = _arb_first_order(scene, dps + 20)
            balls = [(Z * _arb_time(tv, dps + 20)).exp() * y0 for tv in times]
        if all(b[i, 0].is_finite() for b in balls for i in range(n)):
            scale = max((abs(float(b[i, 0].mid())) for b in balls for i in range(n)), default=0.0)
            radius = max((float(b[i, 0].rad()) for b in balls for i in range(n)), default=0.0)
            if radius <= 10.0 ** -(dps + 1) * scale or radius == 0:
                return _to_mpmath(balls, n, dps)
        bits *= 2
    raise ArithmeticError(f"certified_motion: {dps} digits not reached at {max_bits} bits")


def _to_mpmath(balls, n: int, dps: int) -> tuple[np.ndarray, np.ndarray]:
    values = np.empty((n, len(balls)), dtype=object)
    errors = np.empty((n, len(balls)))
    with mpmath.workdps(dps):
        for col, ball in enumerate(balls):
            for i in range(n):
                man, exp = ball[i, 0].mid().man_exp()
                values[i, col] = +mpmath.mpf((int(man), int(exp)))
                errors[i, col] = float(ball[i, 0].rad()) + float(abs(values[i, col])) * 10.0 ** -dps
    return values, errors


# ----------------------------------------------------------------------------- the solution


@dataclass(frozen=True, eq=False)
class NumericSolution:
    """Motion x(t) of a numeric scene from a conditioned eigen-decomposition.

    Build it with :func:`solve_numeric`. The interface follows the exact
    :class:`~laplace_springs.solution.Solution`: :meth:`evaluate`, :attr:`x`,
    :meth:`verify`.

    Attributes
    ----------
    scene : Scene
    modes : Modes
        Well-conditioned modes and blocks of clustered poles.
    reason : str
        Why this route was taken.
    method : str
        ``"numeric"``.
    """

    scene: Scene
    modes: Modes
    reason: str
    method: str = field(default="numeric")

    @property
    def poles(self) -> np.ndarray:
        """The poles λ (roots of Δ), complex, sorted by real then imaginary part."""
        return self.modes.poles()

    def evaluate(self, times, *, dps: int | None = None, return_error: bool = False):
        """Evaluate x(t) at the given times.

        Parameters
        ----------
        times : array_like
            Times (a scalar is one time). With ``dps``, floats are read by their
            shortest decimal form and strings as exact decimals, as in the exact route.
        dps : int, optional
            Without it, float64 from the eigen-decomposition; where that decomposition's
            own error estimate exceeds :data:`ESCALATE` of max |x| over the times asked
            (stiff data, long horizons), the modes are recomputed once in ball
            arithmetic (:mod:`laplace_springs.precise_route`) and used from then on,
            when the scene's eigenvalues allow it. With it, an object array of
            mpmath numbers certified to ``dps`` digits relative to max |x| (ball-arithmetic
            matrix exponential of the exact data; see :func:`certified_motion`).
        return_error : bool
            Also return an array of error estimates (float64: a first-order estimate from
            the eigenvalue condition numbers; with ``dps``: certified bounds).

        Returns
        -------
        numpy.ndarray or (numpy.ndarray, numpy.ndarray)
            Shape (n, len(times)).

        Examples
        --------
        >>> from laplace_springs import Scene
        >>> sol = solve_numeric(Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[0]))
        >>> sol.evaluate([0.0, 1.0]).round(12)   # (1 + t) e^{-t}
        array([[1.        , 0.73575888]])
        >>> value, error = sol.evaluate(1, dps=30, return_error=True)
        >>> mpmath.nstr(value[0, 0], 30), bool(error[0, 0] < 1e-29)
        ('0.735758882342884643191047540323', True)
        """
        if dps is not None:
            values, errors = certified_motion(self.scene, list(np.atleast_1d(times)), dps)
            return (values, errors) if return_error else values
        times = np.atleast_1d(np.asarray(times, dtype=float))
        if not np.all(np.isfinite(times)):
            raise ValueError("times must be finite")
        values, errors = self.modes.values_and_errors(times)
        loose = float(np.max(errors, initial=0.0)) > ESCALATE * float(np.max(np.abs(values), initial=0.0))
        if loose and self._precise is not None:
            values, errors = self._precise.values_and_errors(times)
        return (values, errors) if return_error else values

    @cached_property
    def _precise(self):
        """The ball-arithmetic modes of the scene (None where they do not apply)."""
        from .precise_route import MAX_ORDER, PreciseModes, decompose_precise

        if isinstance(self.modes, PreciseModes) or 2 * self.scene.n > MAX_ORDER:
            return None
        return decompose_precise(self.scene)

    @cached_property
    def x(self) -> sp.ImmutableMatrix:
        """x(t) in the symbol :data:`laplace_springs.t`, Float coefficients, real form.

        Terms t^p e^{αt}(a cos βt + b sin βt); coefficients below 1e-13 of the largest
        are omitted (t^p terms appear only for defective poles).
        """
        return _closed_form(self.modes, self.scene.n)

    def verify(self, *, samples: Sequence = ("0.37", "1.3", "4.1"), tolerance: float = 1e-9) -> Verification:
        """Residuals of M x'' + C x' + K x and of the initial data, in float64.

        x, x', x'' come from the decomposition at t = 0 and the sample times; the ODE
        residual is relative to max(|M||x''| + |C||x'| + |K||x| + |M|(r²|x| + r|x'|)),
        r the size of the first-order matrix, the initial one to max(|x0|, |v0|). The
        velocities of massless nodes are not compared with v0: the constraint sets them.

        Examples
        --------
        >>> from laplace_springs import Scene
        >>> bool(solve_numeric(Scene.from_matrices(M=[[1]], K=[[4]], x0=[1], v0=[0])).verify())
        True
        """
        M, C, K, x0, v0 = scene_arrays(self.scene)
        times = np.array([0.0, *(float(sp.Rational(str(s))) for s in samples)])
        x, v, a = (self.modes.values(times, order) for order in range(3))
        residual = np.max(np.abs(M @ a + C @ v + K @ x))
        rate = self.modes.norm  # floor for the scale, e.g. for a free mass where x'' = 0
        size = np.max(np.abs(M) @ np.abs(a) + np.abs(C) @ np.abs(v) + np.abs(K) @ np.abs(x)
                      + np.abs(M) @ (rate**2 * np.abs(x) + rate * np.abs(v)))
        massive = [i for i in range(len(M)) if i not in massless_nodes(M)]  # others: v0 has no role
        start = np.max(np.abs(np.concatenate([x[:, 0] - x0, v[massive, 0] - v0[massive]])))
        data = np.max(np.abs(np.concatenate([x0, v0])))
        return Verification(float(residual / size) if size else float(residual),
                            float(start / data) if data else float(start), tolerance)

    def __repr__(self) -> str:
        poles = self.poles
        sizes = [len(b.T) for b in self.modes.blocks]
        blocks = f", {len(sizes)} block(s) of clustered poles (sizes {sizes})" if sizes else ""
        slowest = float(-poles.real.max()) if len(poles) else 0.0
        slowest = 0.0 if abs(slowest) <= 1e-12 * max(np.max(np.abs(poles), initial=0.0), 1e-300) else slowest
        warnings = "".join(f"; warning: {w}" for w in self.modes.warnings)
        massless = massless_nodes(scene_arrays(self.scene)[0])
        if massless:
            names = ", ".join(self.scene.names[i] for i in massless)
            blocks += f", massless {names} (velocity set by the constraint at 0+, v0 unused)"
        return (f"NumericSolution({self.scene!r}: {len(poles)} poles{blocks}, slowest decay rate "
                f"{slowest:.3g}; method='numeric': {self.reason}{warnings})")


def solve_numeric(scene: Scene, *, reason: str = "method='numeric' was requested") -> NumericSolution:
    """Solve a numeric scene by the conditioned eigen-decomposition of its linearisation.

    Parameters
    ----------
    scene : Scene
        Entries must be numbers (symbolic entries raise :class:`SceneError`); M invertible.
    reason : str
        Recorded in the result: why the numeric route was chosen.

    Returns
    -------
    NumericSolution

    Raises
    ------
    SceneError
        For symbolic entries (named) or a singular mass matrix.

    Examples
    --------
    Two masses between walls, the lowest mode excited:

    >>> from laplace_springs import Scene
    >>> scene = Scene.from_matrices(M=[[1, 0], [0, 1]], K=[[2, -1], [-1, 2]], x0=[1, 1], v0=[0, 0])
    >>> sol = solve_numeric(scene)
    >>> sol.poles.round(12)
    array([...-1.73205081j, ...-1.j        , ...+1.j        , ...+1.73205081j])
    >>> sol.x
    Matrix([
    [1.0*cos(1.0*t)],
    [1.0*cos(1.0*t)]])
    >>> solve_numeric(Scene.from_matrices(M=[[1]], K=[["k"]], x0=[1], v0=[0]))
    Traceback (most recent call last):
    ...
    laplace_springs.errors.SceneError: the numeric route needs numbers, but these entries are symbolic: K[0,0] = k
    """
    return NumericSolution(scene, decompose_numeric(scene), reason)

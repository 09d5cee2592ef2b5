"""Modal route: x(t) in float64 from a scaled, conditioned eigen-decomposition.

For scenes too large for exact partial fractions the motion comes from the
eigen-decomposition of the first-order matrix, computed in float64 and made robust
where plain eigen-decompositions fail:

1. **Rigid-body motion** (K r = C r = 0) is split off exactly first
   (:func:`~laplace_springs.numeric.first_order.rigid_split`): the drift
   offset + slope·t is exact and the rest of the motion has no zero eigenvalue, so no
   defective block at λ = 0 can drift at long horizons.
2. **Reduction.** With M = L Lᵀ (Cholesky; ``M⁻¹`` for a non-symmetric M) the system
   becomes q'' + Ĉ q' + K̂ q = 0 with x = L⁻ᵀ q. Massless nodes held by dashpots keep
   the reduced state [x; x_m'] instead.
3. **Scaling** (Fan, Lin & Van Dooren 2004; Tisseur & Meerbergen 2001, §6). Time is
   measured in units of 1/γ, γ = sqrt(‖K̂‖), so that the companion linearisation
   Z = [[0, I], [-K̂/γ², -Ĉ/γ]] has norm ≲ 1; the initial state is scaled to unit norm.
   Stiffnesses of 1e300 therefore work as well as 1. Δ(λ) is never expanded.
4. **Conditioning.** Each eigenvalue's condition number κ = ‖wₖ‖‖vₖ‖ comes from the
   eigenvector matrix and its inverse. Ill-conditioned eigenvalues (critical damping,
   exceptional points) and close ones (repeated frequencies) are grouped with their
   neighbours, and each group is replaced by an orthonormal basis of its invariant
   subspace and the small block T it carries, evaluated as F e^{Tt} c by a scaled
   Taylor series: no eigenvector of a defective eigenvalue is ever used.
5. **Refinement.** Well-conditioned eigenvalues get one Newton step on the quadratic
   itself, kept only when its rounding noise is below the eigen-solver's error.
   Undamped scenes with symmetric M and K have exactly imaginary eigenvalues; their
   computed real parts (pure rounding) are set to zero.

Precision and conditioning
--------------------------
:meth:`ModalMotion.bound` is a first-order error bound, inflated by :attr:`~laplace_springs.limits.Limits.modal_safety`:
per simple mode, the eigenvector error (u·κ times the weight and the projection of the
initial state) and the eigenvalue error δλ = κ·‖r‖ (measured residual), entering as
e^{δλ t} − 1 (amplitude and phase; exact in δλ t, so long horizons are not
underestimated); per block, its normwise error and its sensitivity to a perturbation of
T of the solver's size; plus the rounding of the phases λt. Where anything is not finite
the bound is infinite: the caller must escalate those times (see
:mod:`laplace_springs.policy`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from fractions import Fraction
from functools import cached_property
from typing import Any, cast

import numpy as np
import sympy as sp

from ..kernels.batch import columns_product
from ..kernels.first_order import FLOAT, first_order, massless_nodes
from ..kernels.poles import clusters
from ..limits import limits
from ..model.errors import FloatRangeError
from ..model.scene import Scene
from ..model.symbols import TIME
from .classical import ModalForm
from .first_order import RigidSplit, rigid_split, scene_arrays

__all__ = ["Block", "Modes", "ModalMotion", "decompose_modal"]

#: Condition number above which a mode is treated in a block if it is also near another
#: eigenvalue (closer than NEAR times its own modulus): a nearly defective pair.
KAPPA_NEAR, NEAR = 10.0, 0.1
_EPS = float(np.finfo(float).eps)
_RNG_SEED = 20011


# ----------------------------------------------------------------------------- reduction


@dataclass(frozen=True)
class _Reduced:
    """q'' + C q' + K q = 0 with x = back @ q; q0 and dq0 its initial data."""

    C: np.ndarray
    K: np.ndarray
    back: np.ndarray
    q0: np.ndarray
    dq0: np.ndarray
    spread: tuple[float, float] = (0.0, 0.0)  # ‖|L⁻¹||C||L⁻ᵀ|‖, ‖|L⁻¹||K||L⁻ᵀ|‖: rounding scales


def _norm(A: np.ndarray) -> float:
    """sqrt(‖A‖₁)·sqrt(‖A‖∞): an upper bound on ‖A‖₂ within √n, without an SVD or overflow."""
    return float(math.sqrt(np.linalg.norm(A, 1)) * math.sqrt(np.linalg.norm(A, np.inf)))


def _reduce(M: np.ndarray, C: np.ndarray, K: np.ndarray, x0: np.ndarray, v0: np.ndarray) -> _Reduced:
    scale = float(np.max(np.abs(M)))
    Ms = M / scale  # masses of 1e-300 or 1e300: factor their size out first
    if np.linalg.cond(Ms) > limits().max_mass_condition:
        raise FloatRangeError(f"the modal route needs an invertible mass matrix, but M is singular "
                         f"to working precision (condition number {np.linalg.cond(Ms):.3g})")
    Cs, Ks = C / scale, K / scale
    if np.array_equal(M, M.T):
        try:
            L = np.linalg.cholesky(Ms)
        except np.linalg.LinAlgError:
            L = None
        if L is not None:
            Linv = np.linalg.solve(L, np.eye(len(M)))
            A = np.abs(Linv)
            spread = (_norm(A @ np.abs(Cs) @ A.T), _norm(A @ np.abs(Ks) @ A.T))
            return _Reduced(Linv @ Cs @ Linv.T, Linv @ Ks @ Linv.T, Linv.T, L.T @ x0, L.T @ v0, spread)
    inverse = np.abs(np.linalg.inv(Ms))
    spread = (_norm(inverse @ np.abs(Cs)), _norm(inverse @ np.abs(Ks)))
    return _Reduced(np.linalg.solve(Ms, Cs), np.linalg.solve(Ms, Ks), np.eye(len(M)), x0, v0, spread)


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
    if np.linalg.cond(Czz) > limits().max_damping_condition:
        raise FloatRangeError(f"the modal route handles massless nodes held by dashpots (invertible C "
                         f"block on them); nodes {z} are not")
    if m and np.linalg.cond(Mmm) > limits().max_mass_condition:
        raise FloatRangeError("the modal route needs an invertible mass matrix on the massive nodes")
    Z, y0, _ = first_order(M, C, K, cast(Sequence[Any], x0), cast(Sequence[Any], v0), FLOAT,
                           massless=z)
    return Z, y0


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
    Z[n:, :n] = -(reduced.K / gamma) / gamma
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
    order = np.argsort(distance)[: min(limits().max_group - 1, len(mu) - 1)]
    near = np.maximum(distance[order], 1e-3 * _EPS * scale)
    everything = len(order) == len(mu) - 1  # taking all: as if the next one were at 10·‖Z‖
    beyond = np.append(near[1:], 10 * max(scale, near[-1]) if everything else
                       np.partition(distance, len(order))[len(order)])
    members = int(np.argmax(beyond / near)) + 1
    return np.append(order[:members], k)


def _ill_conditioned(mu: np.ndarray, kappa: np.ndarray, scale: float) -> np.ndarray:
    """Indices of eigenvalues to group: κ > Limits.kappa_max, or κ > KAPPA_NEAR and a close
    neighbour, or a neighbour closer than Limits.close_poles·‖Z‖ whatever κ.

    The companion form gives low-frequency modes κ ≈ 1/(2|μ|) without harm (their
    neighbours are about |μ| away); a nearly defective pair has its partner much closer.
    """
    if len(mu) < 2:
        return np.flatnonzero(kappa > limits().kappa_max)
    distance = np.abs(mu[:, None] - mu[None, :])
    np.fill_diagonal(distance, np.inf)
    near = distance.min(axis=1) < NEAR * np.abs(mu)
    close = np.zeros(len(mu), dtype=bool)   # the package's close-poles rule (kernels/poles.py)
    for cluster in clusters(mu, limits().close_poles * scale):
        close[cluster] = True
    return np.flatnonzero((kappa > limits().kappa_max) | ((kappa > KAPPA_NEAR) & near) | close)


def _groups(mu: np.ndarray, kappa: np.ndarray, scale: float) -> list[list[int]]:
    """Disjoint groups (size ≥ 2) around the ill-conditioned eigenvalues."""
    parent = list(range(len(mu)))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for k in _ill_conditioned(mu, kappa, scale):
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
    inverse does not drown the generalized eigenvectors of a defective eigenvalue.

    Returns the basis, whether it converged, and an estimate of its error: the larger
    of ε‖Z‖/d and ‖residual‖/gap.
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
    converged = float(np.linalg.norm(residual, 1)) <= 1e-10 * max(1.0, float(np.linalg.norm(Z, 1)))
    return Q, converged, float(error)


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


# ----------------------------------------------------------------------------- blocks


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
    basis_error : float
        Estimated error of the block's basis columns (subspace iteration).
    """

    T: np.ndarray
    F: np.ndarray
    c: np.ndarray
    kappa: float
    basis_error: float = 0.0

    @cached_property
    def center(self) -> complex:
        return complex(np.trace(self.T) / len(self.T))

    def poles(self) -> np.ndarray:
        """The eigenvalues of T; a group tighter than √ε relative is reported as one repeated pole."""
        values = np.linalg.eigvals(self.T)
        spread = np.max(np.abs(values - self.center))
        if spread <= 1e-7 * max(abs(self.center), float(np.linalg.norm(self.T, 2)), 1e-300):
            return np.full(len(values), self.center)
        return values

    def perturbed(self, size: float, rng: np.random.Generator) -> Block:
        """The block with T moved by a random complex matrix of 2-norm ``size`` (its rows of
        zeros, states held constant, stay exact: see :func:`_decompose_arrays`)."""
        m = len(self.T)
        E = rng.standard_normal((m, m)) + 1j * rng.standard_normal((m, m))
        E *= np.any(self.T, axis=1, keepdims=True)
        return Block(self.T + E * (size / max(float(np.linalg.norm(E, 2)), 1e-300)), self.F,
                     self.c, self.kappa, self.basis_error)

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
        N, squarings = self._shifted(times)
        out = np.empty((len(times), len(self.T), len(self.T)), dtype=complex)
        for s in np.unique(squarings):
            cols = np.flatnonzero(squarings == s)
            out[cols] = _exp_batch(N, times[cols], int(s))
        with np.errstate(over="ignore", invalid="ignore"):
            return out * np.exp(self.shift * times)[:, None, None]

    def _shifted(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """T − shift·I and the squarings that bring its 1-norm times |t| to at most 1."""
        N = self.T - self.shift * np.eye(len(self.T))
        norm = np.linalg.norm(N, 1)
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            squarings = np.maximum(0, np.ceil(np.log2(np.maximum(norm * np.abs(times), 1e-300))))
        return N, np.minimum(squarings, 2000).astype(int)

    def exp_times(self, times: np.ndarray, vector: np.ndarray) -> np.ndarray:
        """e^{T t}·vector for each t, shape (m, len(times))."""
        return _stacked_apply(self.exp_matrices(times), vector)

    def exp_error(self, times: np.ndarray) -> np.ndarray:
        """A bound (∞-norm) on the rounding and truncation of :meth:`exp_matrices` at each
        time: the Taylor sum's, then each squaring's, carried through the later ones with
        the computed powers' norms (err ← (2‖E‖ + err)·err + m·u·‖E‖²), times
        |e^{shift·t}|. The perturbed decompositions of the sampled bound share this
        rounding, so they cannot see it."""
        times = np.abs(np.asarray(times, dtype=float))
        N, squarings = self._shifted(times)
        out = np.empty(len(times))
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            for s in np.unique(squarings):
                cols = np.flatnonzero(squarings == s)
                out[cols] = _exp_batch_error(N, times[cols], int(s))
            out = out * np.abs(np.exp(self.shift * times)) * (1 + 4 * _EPS)
        return np.where(np.isfinite(out), out, np.inf)


def _stacked_apply(E: np.ndarray, vector: np.ndarray) -> np.ndarray:
    """E[t] @ vector for each t, shape (m, len(E)): one matrix-vector product of the same
    shape per t (a stacked matmul), so a time's rounding does not depend on the others."""
    return np.matmul(E, vector).T


def _sum_in_order(rows: np.ndarray) -> np.ndarray:
    """Σᵢ rows[i] for each column, added in index order (NumPy's reductions sum pairwise or
    row by row depending on the shape, so a time alone could round differently)."""
    total = np.zeros(rows.shape[1], dtype=rows.dtype)
    for row in rows:
        total = total + row
    return total


def _exp_batch(N: np.ndarray, times: np.ndarray, squarings: int) -> np.ndarray:
    """e^{N t} for the given times: Taylor series of degree 20 on N t/2^s, squared s times."""
    A = N[None, :, :] * (times[:, None, None] / 2.0**squarings)
    E = np.broadcast_to(np.eye(len(N), dtype=complex), A.shape).copy()
    term = E.copy()
    with np.errstate(over="ignore", invalid="ignore"):
        for k in range(1, 21):
            term = term @ A / k
            E = E + term
        for _ in range(squarings):
            E = E @ E
    return E


def _exp_batch_error(N: np.ndarray, times: np.ndarray, squarings: int) -> np.ndarray:
    """The error bound of :func:`_exp_batch` (∞-norm) at each time, from the norms of the
    powers it forms: Taylor truncation a²¹/21!·e^a and rounding 42·m·u·e^a on A = N t/2^s
    (a = ‖A‖∞), then per squaring err ← (2‖E‖ + err)·err + m·u·‖E‖²."""
    m = len(N)
    A = N[None, :, :] * (times[:, None, None] / 2.0**squarings)
    a = np.max(np.sum(np.abs(A), axis=2), axis=1)
    err = a**21 / math.factorial(21) * np.exp(a) + 42 * m * _EPS * np.exp(a)
    E = _exp_batch(N, times / 2.0**squarings, 0) if squarings else None
    with np.errstate(over="ignore", invalid="ignore"):
        for _ in range(squarings):
            assert E is not None
            size = np.max(np.sum(np.abs(E), axis=2), axis=1)
            err = (2 * size + err) * err + m * _EPS * size * size
            E = E @ E
    return err


# ----------------------------------------------------------------------------- modes


@dataclass(frozen=True, eq=False)
class Modes:
    """x(t) = Re[Σₖ weights[:, k] e^{rates[k] t} + Σ_blocks F e^{Tt} c], for a unit initial state.

    ``rates`` are the well-conditioned eigenvalues λ (both of each conjugate pair),
    ``kappa`` their condition numbers, ``rate_error`` bounds on their absolute errors;
    ``blocks`` the clustered groups; ``norm`` is γ‖Z‖, the size of the first-order
    matrix in the scene's time unit. ``reach`` is ‖F_k‖ for each simple mode k: a weight
    F_k c_k computed from eigenvectors and c = X⁻¹y₀ carries an absolute error of about
    u·κ·‖F_k‖ in every coordinate, even where the weight itself is zero. ``unit`` is the
    backward error of the basis columns.

    ``samples`` are decompositions of perturbed copies of the data (each entry moved by its
    own rounding to float64, the first-order matrix by the solver's backward error), as
    (modes, scale ratio) pairs: :meth:`bound` measures how far their motions are from this
    one. Empty where a perturbed copy could not be decomposed.
    """

    rates: np.ndarray
    weights: np.ndarray
    kappa: np.ndarray
    rate_error: np.ndarray
    blocks: tuple[Block, ...]
    norm: float
    reach: np.ndarray
    unit: float
    warnings: tuple[str, ...] = ()
    samples: tuple[tuple[Modes, float], ...] = ()

    @property
    def n(self) -> int:
        return int(self.weights.shape[0]) if self.weights.size else int(self.blocks[0].F.shape[0])

    def poles(self) -> np.ndarray:
        values = np.concatenate([self.rates, *[b.poles() for b in self.blocks]])
        scale = max(np.max(np.abs(values), initial=0.0), 1e-300)
        return values[np.lexsort((values.imag, np.round(values.real / scale, 12)))]

    def half(self) -> tuple[np.ndarray, np.ndarray]:
        """The rates with Im ≥ 0 and their weights, doubled for Im > 0, if pairs match."""
        upper, lower = self.rates.imag > 0, self.rates.imag < 0
        if np.sort_complex(self.rates[upper]).tolist() != np.sort_complex(self.rates[lower].conj()).tolist():
            return self.rates, self.weights
        keep = ~lower
        return self.rates[keep], self.weights[:, keep] * np.where(upper[keep], 2.0, 1.0)

    def half_blocks(self) -> list[tuple[Block, float]]:
        """Blocks with their factor: 2 for one of a conjugate pair (the other is dropped), else 1."""
        upper = [b for b in self.blocks if b.center.imag > 0]
        lower = [b for b in self.blocks if b.center.imag < 0]
        partners: list[Block] = []
        for block in upper:
            match = [b for b in lower if len(b.T) == len(block.T) and b not in partners
                     and abs(b.center - block.center.conjugate()) <= 1e-8 * max(1.0, abs(block.center))]
            partners.extend(match[:1])
        if len(partners) != len(lower) or len(upper) != len(lower):
            return [(b, 1.0) for b in self.blocks]
        return [(b, 2.0 if b.center.imag > 0 else 1.0) for b in self.blocks if b.center.imag >= 0]

    def values(self, times: np.ndarray, order: int = 0) -> np.ndarray:
        """d^order x/dt^order at the times, float64, shape (n, len(times))."""
        return self.analytic(times, order).real

    def analytic(self, times: np.ndarray, order: int = 0) -> np.ndarray:
        """Σ over modes with Im λ ≥ 0 (conjugate pairs doubled) of their complex terms:
        the values are its real part; its modulus is an envelope without the zeros of
        the oscillations."""
        rates, weights = self.half()
        with np.errstate(over="ignore", invalid="ignore"):
            total = columns_product(weights * rates**order, np.exp(np.outer(rates, times)))
            for block, factor in self.half_blocks():
                total = total + factor * _block_value(block, np.asarray(times, dtype=float), order)
        return total

    def bound(self, times: np.ndarray, order: int = 0) -> np.ndarray:
        """An error bound of :meth:`values` (see the module notes); inf where unreliable."""
        t = np.abs(np.asarray(times, dtype=float))
        with np.errstate(over="ignore", invalid="ignore"):
            total = self._rounding_bound(t, order)
            for block, factor in self.half_blocks():   # e^{Tt}'s own rounding, on every path
                vector = np.linalg.matrix_power(block.T, order) @ block.c
                rows = np.sum(np.abs(block.F), axis=1) * float(np.max(np.abs(vector), initial=0.0))
                total += factor * np.outer(rows, block.exp_error(t))
            if self.samples:
                total += self._sampled_bound(t, order)
            else:
                total += self._first_order_bound(t, order)
                rng = np.random.default_rng(_RNG_SEED)
                for block, factor in self.half_blocks():
                    total += factor * self._block_bound(block, t, order, rng)
        return np.where(np.isfinite(total), total, np.inf)

    def _sampled_bound(self, t: np.ndarray, order: int) -> np.ndarray:
        """Limits.sample_safety × the largest distance of a perturbed motion's analytic signal,
        per coordinate, floored at a tenth of its largest over the coordinates."""
        mine = self.analytic(t, order)
        moved = np.zeros(mine.shape)
        shape = self._structure()
        for other, ratio in self.samples:
            change = other.analytic(t, order) * ratio - mine
            # the imaginary parts of two signals are alike only for alike decompositions (a
            # copy that separates the pairs a 6 x 6 block holds has an envelope of its own)
            moved = np.maximum(moved, np.abs(change if other._structure() == shape
                                             else change.real))
        floor = 0.1 * np.max(moved, axis=0, initial=0.0)
        return limits().sample_safety * np.maximum(moved, floor[None, :])

    def _structure(self) -> tuple[Any, ...]:
        """The number of simple modes and the sizes of the blocks."""
        return (len(self.rates), *(len(block.T) for block in self.blocks))

    def _rounding_bound(self, t: np.ndarray, order: int) -> np.ndarray:
        """The rounding of the float64 sum: of the weights (u·(reach + |w|)), of each term,
        and of the phases λt."""
        size, weight = np.abs(self.rates), np.abs(self.weights)
        growth = np.exp(np.outer(self.rates.real, t))
        power = size**order
        mixing = 2 * _EPS * (self.reach + weight)  # forming F = back·X and c = X⁻¹y0 (sampled too)
        total = columns_product((mixing + weight * _EPS * (4 + order + len(size))) * power, growth)
        total += columns_product(weight * power * 4 * _EPS * size, growth * t)
        return total

    def _first_order_bound(self, t: np.ndarray, order: int) -> np.ndarray:
        """u·κ·(|w| + reach) in amplitude and δλ in rate and phase, times Limits.modal_safety."""
        size, delta, weight = np.abs(self.rates), self.rate_error, np.abs(self.weights)
        growth = np.exp(np.outer(self.rates.real + delta, t))
        drift = np.expm1(np.outer(delta, t))
        moved = (size + delta) ** order
        amplitude = limits().modal_safety * self.unit * self.kappa * (weight + self.reach)
        total = columns_product(amplitude * moved, growth * (1 + drift))
        total += limits().modal_safety * columns_product((weight + self.reach) * moved, growth * drift)
        return total

    def _block_bound(self, block: Block, t: np.ndarray, order: int,
                     rng: np.random.Generator) -> np.ndarray:
        """u·κ_B·‖F‖(‖T^p e^{Tt} c‖ + ‖T^p e^{Tt}‖) plus the change under a perturbation."""
        unit = max(self.unit, block.basis_error)
        exps = block.exp_matrices(t)
        Tp = np.linalg.matrix_power(block.T, order)
        inner = columns_product(Tp, _stacked_apply(exps, block.c))
        moved_block = block.perturbed(unit * self.norm, rng)
        moved = columns_product(np.linalg.matrix_power(moved_block.T, order),
                                moved_block.exp_times(t, block.c))
        TpE = np.matmul(Tp, exps)  # one product of the same shape per time
        spread = (np.sqrt(_sum_in_order(np.abs(inner) ** 2))
                  + np.sqrt(_sum_in_order(np.abs(TpE.reshape(len(t), -1).T) ** 2)))
        out = limits().modal_safety * unit * block.kappa * np.linalg.norm(block.F, 2) * spread
        return out[None, :] + limits().modal_safety * np.abs(columns_product(block.F, moved - inner))


def _block_value(block: Block, t: np.ndarray, order: int) -> np.ndarray:
    """d^order/dt^order of F e^{Tt} c at the times (complex, n x len(t))."""
    vector = np.linalg.matrix_power(block.T, order) @ block.c
    return columns_product(block.F, block.exp_times(t, vector))


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
        elif len(Z) <= limits().whole_block_max:
            return np.arange(0), np.eye(len(Z), dtype=complex), [(Z.astype(complex), 0.0)], []
        else:
            warnings.append(f"{len(group)} clustered poles near {complex(mu[group].mean()):.4g} (scaled) "
                            "could not be separated; kept as simple modes, accuracy may suffer")
    simple = np.setdiff1d(np.arange(len(mu)), grouped)
    return simple, np.hstack([V[:, simple], *columns]), blocks, warnings


def _decompose(Z: np.ndarray, y0: np.ndarray, back: np.ndarray, gamma: float,
               newton: bool, undamped: bool) -> Modes:
    """Modes of y' = Z y (time scaled by γ), y0 of unit norm, x = back @ y[:n]."""
    mu, V = np.linalg.eig(Z)
    if undamped:
        mu = 1j * mu.imag
    V = V / np.linalg.norm(V, axis=0)
    W = _inverse(V)
    kappa = _condition_numbers(V, W)
    scale = max(_norm(Z), _EPS)
    groups = _groups(mu, kappa, scale)
    residual = np.linalg.norm(Z @ V - V * mu, axis=0)
    if newton and not undamped:
        mu, error = _newton_step(Z, mu, V, W, kappa)
    else:
        error = _EPS * kappa * scale
    with np.errstate(invalid="ignore"):  # κ = inf (defective): those modes go into blocks
        error = np.maximum(error, np.where(residual > 0, kappa * residual, 0.0))
    simple, X, blocks, warnings = _basis(Z, mu, V, groups)
    Xinv = W[simple] if len(simple) == len(mu) else _inverse(X)
    unit = max(4 * _EPS * math.sqrt(len(mu)), float(np.max(residual, initial=0.0)) / scale)
    return _modes(back, gamma, scale, mu[simple], error[simple], X, Xinv, blocks, y0, unit, warnings)


def _modes(back: np.ndarray, gamma: float, scale: float, mu_simple: np.ndarray, error: np.ndarray,
           X: np.ndarray, Xinv: np.ndarray, blocks: list[tuple[np.ndarray, float]], y0: np.ndarray,
           unit: float, warnings: list[str]) -> Modes:
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
        out_blocks.append(Block(gamma * T, F[:, part], c[part], block_kappa, basis_error))
        start += m
    reach = np.broadcast_to(np.linalg.norm(F[:, :k], axis=0), (n, k))
    return Modes(gamma * mu_simple, F[:, :k] * c[:k], kappa[:k], gamma * error,
                 tuple(out_blocks), gamma * scale, reach, unit, tuple(warnings))


def _is_undamped_symmetric(M: np.ndarray, C: np.ndarray, K: np.ndarray) -> bool:
    return not C.any() and np.array_equal(M, M.T) and np.array_equal(K, K.T)


def _decompose_arrays(M: np.ndarray, C: np.ndarray, K: np.ndarray, x0: np.ndarray,
                      v0: np.ndarray, noise: np.random.Generator | None = None) -> tuple[Modes, float]:
    """The :class:`Modes` of float data for the initial state scaled to unit norm, and that
    scale (x(t) = scale · modes.values(t)). With ``noise``, the first-order matrix is moved
    by a random matrix of 2-norm ε‖Z‖ first (the backward error of forming and solving it).
    """
    size = max(float(np.max(np.abs(x0), initial=0.0)), float(np.max(np.abs(v0), initial=0.0)))
    z = massless_nodes(zip(*np.nonzero(M)), len(M))
    undamped = _is_undamped_symmetric(M, C, K)
    if z:  # the state is [x; massive velocities]; time scaled by ‖Z‖ only
        Z, y0 = _massless_system(M, C, K, x0, v0, z)
        gamma = _norm(Z) or 1.0
        Z, back = Z / gamma, np.eye(len(M))
        newton = False
    else:
        reduced = _reduce(M, C, K, x0, v0)
        gamma = _scaling(reduced)
        if undamped:
            symmetric = _undamped(reduced, gamma, noise)
            if symmetric is not None:
                return symmetric
        Z, y0 = _companion(reduced, gamma)
        back, newton = reduced.back, True
    norm = float(np.linalg.norm(y0))
    if not np.isfinite(norm) or not np.isfinite(Z).all():
        raise FloatRangeError("the modal route cannot scale this scene into float64 "
                         f"(‖y0‖ = {norm:.3g}); use the certified or exact route")
    if norm == 0 or size == 0:
        norm = 1.0
    if noise is not None:
        # a row of zeros (a state held constant: an exosystem's w' = 0) is exact; moved, it
        # makes LAPACK's balancing scale by 1e16 and the sample's eigenvectors lose 7 digits
        Z = Z + _noise(noise, Z.shape, _EPS * _norm(Z)) * np.any(Z, axis=1, keepdims=True)
        if not z:  # the reduction's own rounding, on the blocks it forms
            n = len(M)
            Z[n:, :n] += _noise(noise, (n, n), _EPS * reduced.spread[1] / gamma / gamma)
            Z[n:, n:] += _noise(noise, (n, n), _EPS * reduced.spread[0] / gamma)
    return _decompose(Z, y0 / norm, back, gamma, newton, undamped), norm


def _noise(rng: np.random.Generator, shape: tuple[int, int], size: float,
           symmetric: bool = False) -> np.ndarray:
    """A random matrix of 2-norm ``size`` (symmetric if asked)."""
    E = rng.standard_normal(shape)
    if symmetric:
        E = (E + E.T) / 2
    return E * (size / max(float(np.linalg.norm(E, 2)), 1e-300))


def _undamped(reduced: _Reduced, gamma: float,
              noise: np.random.Generator | None) -> tuple[Modes, float] | None:
    """Modes of q'' + K q = 0 from the symmetric eigenproblem K = Φ diag(ω²) Φᵀ.

    q(t) = Σ φ_k (a_k cos ω_k t + b_k sin(ω_k t)/ω_k), a = Φᵀq0, b = Φᵀq0': the rates are
    exactly ±iω_k and repeated frequencies are harmless. None when some ω² is not clearly
    positive (a zero frequency needs the companion form's blocks).
    """
    K = (reduced.K + reduced.K.T) / 2 / gamma / gamma  # symmetric up to the reduction's rounding
    if noise is not None:
        size = _EPS * max(_norm(K), reduced.spread[1] / gamma / gamma)
        K = K + _noise(noise, K.shape, size, symmetric=True)
    squares, Phi = np.linalg.eigh(K)
    if squares.size and squares.min() <= 64 * _EPS * max(squares.max(), 0.0) * len(K):
        return None
    omega = np.sqrt(squares)
    q0, dq0 = reduced.q0, reduced.dq0 / gamma
    norm = float(np.hypot(np.linalg.norm(q0), np.linalg.norm(dq0))) or 1.0
    a, b = Phi.T @ q0 / norm, Phi.T @ dq0 / norm
    F = reduced.back @ Phi
    upper = (a - 1j * b / omega) / 2
    weights = np.hstack([F * upper, F * upper.conj()])
    rates = gamma * np.concatenate([1j * omega, -1j * omega])
    scale = float(np.linalg.norm(K, 2))
    error = gamma * _EPS * len(K) * scale / (2 * omega)  # |δω| ≤ |δ(ω²)|/(2ω), δ(ω²) ≤ ε n ‖K‖
    reach = np.broadcast_to(np.concatenate([np.linalg.norm(F, axis=0)] * 2), weights.shape)
    unit = 4 * _EPS * math.sqrt(len(K))
    modes = Modes(rates, weights, np.ones(2 * len(K)), np.concatenate([error, error]), (),
                  gamma * max(math.sqrt(scale), 1.0), reach, unit)
    return modes, norm


def _perturbed(arrays: tuple[np.ndarray, ...], rounding: tuple[np.ndarray, ...],
               rng: np.random.Generator) -> tuple[np.ndarray, ...]:
    """The data moved entrywise by its own rounding error, with random signs (symmetry kept)."""
    out = []
    for a, r in zip(arrays, rounding):
        size = np.maximum(r, np.abs(a) * (_EPS / 2))  # also moves the reduction's rounding
        signs = rng.choice([-1.0, 1.0], size=a.shape)
        if a.ndim == 2 and np.array_equal(a, a.T):
            signs = np.triu(signs) + np.triu(signs, 1).T
        out.append(a + signs * size)
    return tuple(out)


def _sampled(modes: Modes, scale: float, arrays: tuple[np.ndarray, ...],
             rounding: tuple[np.ndarray, ...]) -> Modes:
    """``modes`` with :attr:`~laplace_springs.limits.Limits.samples` decompositions of perturbed copies of the data."""
    rng = np.random.default_rng(_RNG_SEED)
    samples = []
    for _ in range(limits().samples):
        try:
            M, C, K, x0, v0 = _perturbed(arrays, rounding, rng)
            other, other_scale = _decompose_arrays(M, C, K, x0, v0, noise=rng)
        except (FloatRangeError, np.linalg.LinAlgError):
            return modes
        samples.append((other, other_scale / scale))
    return dataclasses.replace(modes, samples=tuple(samples))


def decompose(M: np.ndarray, C: np.ndarray, K: np.ndarray, x0: np.ndarray, v0: np.ndarray,
              rounding: tuple[np.ndarray, ...] | None = None) -> tuple[Modes, float]:
    """The :class:`Modes` of float data (unit initial state) and the scale of that state,
    with the errors measured on perturbed copies of the data (see :class:`Modes`).

    ``rounding`` holds the size of each entry's rounding to float64 (M, C, K, x0, v0);
    by default half an ulp of every entry.
    """
    arrays = (M, C, K, x0, v0)
    if rounding is None:
        rounding = tuple(np.abs(a) * (_EPS / 2) for a in arrays)
    modes, scale = _decompose_arrays(*arrays)
    return _sampled(modes, scale, arrays, rounding), scale


# ----------------------------------------------------------------------------- the motion


@dataclass(frozen=True, eq=False)
class ModalMotion:
    """x(t) = lift·(scale · modes) + offset + slope·t (the rigid part exact, split off first).

    Build it with :func:`decompose_modal`.
    """

    modes: Modes
    scale: float
    split: RigidSplit | None = None

    @cached_property
    def _affine(self) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        if self.split is None:
            return None
        lift = np.array([[float(self.split.lift[i, j]) for j in range(self.split.lift.ncols())]
                         for i in range(self.split.lift.nrows())])
        offset = np.array([float(self.split.offset[i, 0]) for i in range(self.split.offset.nrows())])
        slope = np.array([float(self.split.slope[i, 0]) for i in range(self.split.slope.nrows())])
        return lift, offset, slope

    @property
    def n(self) -> int:
        affine = self._affine
        return self.modes.n if affine is None else len(affine[1])

    def values(self, times: np.ndarray, order: int = 0) -> np.ndarray:
        """d^order x/dt^order at the times, float64, shape (n, len(times))."""
        inner = self.scale * self.modes.values(times, order)
        if self._affine is None:
            return inner
        lift, offset, slope = self._affine
        out = columns_product(lift, inner)
        if order == 0:
            out += offset[:, None] + slope[:, None] * times[None, :]
        elif order == 1:
            out += slope[:, None]
        return out

    def bound(self, times: np.ndarray, order: int = 0) -> np.ndarray:
        """An error bound of :meth:`values`, entry by entry (inf where unreliable)."""
        inner = self.scale * self.modes.bound(times, order)
        if self._affine is None:
            return inner
        lift, offset, slope = self._affine
        out = columns_product(np.abs(lift), inner) * (1 + 4 * _EPS * lift.shape[1])
        if order == 0:
            out += 2 * _EPS * (np.abs(offset)[:, None] + np.abs(slope)[:, None] * np.abs(times)[None, :])
        return out

    def poles(self) -> np.ndarray:
        """The poles λ, complex; a rigid split adds the double pole 0 of its drift."""
        poles = self.modes.poles()
        return np.concatenate([poles, np.zeros(2)]) if self.split is not None else poles

    def modal_form(self) -> ModalForm:
        """x(t) as a :class:`~laplace_springs.numeric.classical.ModalForm`: the terms
        t^p e^{αt}(a cos βt + b sin βt) with their coefficient vectors (the rigid drift,
        if any, as the terms of α = β = 0)."""
        table = _collect(self.modes)
        keys = sorted(table)
        n_inner = self.modes.n
        cos = np.array([table[k][0] for k in keys]).T.reshape(n_inner, len(keys)) * self.scale
        sin = np.array([table[k][1] for k in keys]).T.reshape(n_inner, len(keys)) * self.scale
        powers = [k[0] for k in keys]
        alphas = [k[1] for k in keys]
        betas = [k[2] for k in keys]
        affine = self._affine
        if affine is not None:
            lift, offset, slope = affine
            cos, sin = lift @ cos, lift @ sin
            cos = np.hstack([cos, offset[:, None], slope[:, None]])
            sin = np.hstack([sin, np.zeros((len(offset), 2))])
            powers, alphas, betas = [*powers, 0, 1], [*alphas, 0.0, 0.0], [*betas, 0.0, 0.0]
        ones = np.ones(len(powers))
        return ModalForm(powers, alphas, betas, cos, ones, ones, sin_shapes=sin)

    def closed_form(self, relative: float = 1e-13) -> sp.ImmutableMatrix:
        """x(t) in :data:`~laplace_springs.model.symbols.TIME` with Float coefficients.

        Terms t^p e^{αt}(a cos βt + b sin βt); coefficients below ``relative`` of the
        largest are left out (t^p terms appear only for defective poles).
        """
        rows = _closed_form(self.modes, self.modes.n, relative, self.scale)
        if self.split is None:
            return sp.ImmutableMatrix(rows)
        affine = self._affine
        assert affine is not None
        lift, offset, slope = affine
        out = [sp.Add(*(sp.Float(lift[i, j], 15) * rows[j] for j in range(len(rows)) if lift[i, j]))
               + sp.Float(offset[i], 15) + sp.Float(slope[i], 15) * TIME
               for i in range(len(offset))]
        return sp.ImmutableMatrix(out)


def decompose_modal(scene: Scene) -> ModalMotion:
    """The modal motion of a numeric scene (see the module notes).

    Raises
    ------
    FloatRangeError
        For symbolic entries (named), a singular mass matrix, or massless nodes not held
        by dashpots.

    Examples
    --------
    A critically damped mass has one defective double pole at -1, kept as a block:

    >>> motion = decompose_modal(Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[0]))
    >>> len(motion.modes.rates), len(motion.modes.blocks), motion.poles().round(12)
    (0, 1, array([-1.+0.j, -1.+0.j]))
    >>> motion.values(np.array([0.0, 1.0])).round(12)   # (1 + t) e^{-t}
    array([[1.        , 0.73575888]])
    """
    split = rigid_split(scene) if not scene.is_forced else None
    if split is not None:
        modes, scale = decompose(*split.arrays(), rounding=split.rounding())
    else:
        modes, scale = decompose(*scene_arrays(scene), rounding=_rounding(scene))
    return ModalMotion(modes, scale, split)


def _rounding(scene: Scene) -> tuple[np.ndarray, ...]:
    """|float(a) − a| for every entry of M, C, K, x0, v0 (exact for rational entries)."""
    out = []
    for name in ("M", "C", "K", "x0", "v0"):
        matrix = getattr(scene, name)
        error = np.zeros(matrix.shape)
        for (i, j), entry in matrix.todok().items():
            if entry.is_Rational:
                exact = Fraction(int(entry.p), int(entry.q))
                error[i, j] = abs(float(exact - Fraction(float(exact))))
            else:
                error[i, j] = abs(float(entry)) * _EPS
        out.append(error.ravel() if name in ("x0", "v0") else error)
    return tuple(out)


# ----------------------------------------------------------------------------- closed form


def _block_terms(block: Block, tol: float = 1e-13):
    """(rate, coefficient vectors by power of t) of a block: polynomial×exp if T-μ is nilpotent."""
    m = len(block.T)
    N = block.T - block.center * np.eye(m)
    scale = max(float(np.linalg.norm(block.T, 1)), 1e-300)
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

    rates, weights = modes.half()
    for k, rate in enumerate(rates):
        add(0, complex(rate), weights[:, k])
    for block, factor in modes.half_blocks():
        for rate, powers in _block_terms(block):
            for p, weight in enumerate(powers):
                add(p, complex(rate), factor * weight)
    return table


def _closed_form(modes: Modes, n: int, relative: float, scale: float = 1.0) -> list[sp.Expr]:
    """The rows of x(t) with Float coefficients, each weight times ``scale`` (the
    initial state's size: no bare factor 1.0*(...) in front of the terms)."""
    table = {key: weights * scale for key, weights in _collect(modes).items()}
    largest = max((np.max(np.abs(v)) for v in table.values()), default=0.0)
    rows: list[sp.Expr] = [sp.Integer(0)] * n
    t = TIME
    for (power, alpha, beta), weights in sorted(table.items()):
        growth = t**power * (sp.exp(sp.Float(alpha, 15) * t) if alpha else 1)
        for i in range(n):
            a, b = (float(w) if abs(w) > relative * largest else 0.0 for w in weights[:, i])
            if beta and (a or b):
                wave = (sp.Float(a, 15) * sp.cos(sp.Float(beta, 15) * t)
                        + sp.Float(b, 15) * sp.sin(sp.Float(beta, 15) * t))
            elif a:
                wave = sp.Float(a, 15)
            else:
                continue
            rows[i] += growth * wave
    return rows

"""Long horizons for the tiny engine's diagonal decompositions (no 2 x 2 blocks): the
eigenvalues refined from the residual, their phases in double-double, and a first-order
perturbation bound.

Why
---
:class:`~laplace_springs.numeric.tiny_blocks.BlockMotion` evaluates X e^{Bt} c with the
float64 eigenvalues w of B, so its bound grows like t·‖F‖ (F = X⁻¹(ZX − XB), about
u·|w|) and like u·|w|·t (the rounding of w·t): near 1e-12 of the scale at |w|t = 10⁴,
so an undamped or lightly damped scene's late times went to the certified engine (about
ten times slower). Here, at the times beyond the last one where that bound stays within
the target of max(‖x0‖∞, ‖v0‖∞/ρ) (``tiny_blocks.SWITCH_FRACTION``; a constant of the
scene, so a time's value does not depend on the others):

* **Refined eigenvalues.** R = ZX − XB is formed again with every product exact
  (Dekker) and the sums compensated, so it is good to about u² of its terms; then
  w'_j = w_j + δ_j with δ_j = (YR)_jj as computed: the perturbation left,
  F' = X⁻¹(ZX − XB') with B' = diag(w'), has a diagonal near u²|w|.
* **Phases in double-double.** w'_j·t = p + e with p = fl(w_j t) and e its exact error
  (Dekker's product) plus δ_j t and w_j·t_lo: cos, sin and exp of p are the libm's, good
  to an ulp at any size.
* **A first-order bound.** e^{(B'+F')t} − e^{B't} = E₁ + E₂ with
  E₁ = ∫₀ᵗ e^{B'(t−s)}F'e^{B's}ds, whose entries are F'_jk(e^{w'_j t} − e^{w'_k t})/(w'_j − w'_k):
  at most |F'_jk|·e^{gt}·min(t, 2/|w'_j − w'_k|). Only the diagonal (tiny after the
  refinement) and pairs of close eigenvalues grow with t. E₂ = ∫₀ᵗ e^{B'(t−s)}F'E(s)ds is
  at most ‖F'‖²t²/2·e^{(g+‖F'‖)t} (Gronwall for ‖E(s)‖ ≤ s‖F'‖e^{(g+‖F'‖)s}).

Coordinate i of x is then off by at most (with c* = X⁻¹y₀, |c*_k| ≤ |c_k| + ρ₀)

    e^{gt}·Σ_jk |X_ij|·(|F'_jk|)·(|c_k| + ρ₀)·min(t, h_jk) + ‖X_i‖·φ'²t²/2·e^{(g+φ')t}(‖c‖ + ρ₀)
    + ‖X_i‖·ρ₀·e^{gt} + rounding,

h_jk = 2/|w'_j − w'_k| (inf for j = k), φ' ≥ ‖F'‖_F, g ≥ max Re w'_j, where |F'_jk| is
bounded elementwise by the computed |(YR)_jk| (diagonal: what the refinement left) plus
|Y|·(R's error) + the product's rounding + θ‖X⁻¹‖‖R‖ (Y against X⁻¹).
The rounding of the evaluation: (2n + 20)u of Σ_j|g_j|e^{gt} (libm, products, the sum),
the phase argument's (8u²|w|t + 4u|δ|t), and 1e-300(1 + t) where e^{wt} underflows.

References: Higham, *Functions of Matrices* (SIAM 2008), §10.1 (the Fréchet derivative of
e^{At} as the integral above); Dekker (1971) for the exact product.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..kernels.batch import columns_product
from ..kernels.dd import SPLITTER, U, phase, two_prod, two_sum
from ..kernels.peaks import peak

__all__ = ["Refined"]

#: Second-order terms the first-order rounding bounds neglect (as in tiny_blocks).
_SAFETY = 1.02
#: Largest |t|·(1 + max|w|), and largest entry of Z, X or w, for which Dekker's split
#: cannot overflow.
_SPLIT_SAFE = 2.0**990 / SPLITTER


def _residual(Z: np.ndarray, Z_lo: np.ndarray | None, X: np.ndarray,
              w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """R = Z X − X diag(w) (Z = hi + lo, the exact Z within u² of it) rounded once, and an
    elementwise bound on its error. Every entry is a sum of N ≤ 2s + 2 exact products
    (Dekker), added pairwise by two-sums whose errors are summed in float64: the error is
    at most u|R| + 2γ_{2N}²·Σ|terms| (the errors' sum, at most u·(depth + 1)·Σ|terms|, is
    off by γ_{2N} of it; Ogita, Rump & Oishi, "Accurate sum and dot product", 2005), plus
    the exact Z's distance from hi + lo (≤ u|lo|)."""
    size = X.shape[0]
    shape = (2, size, size)
    parts = np.stack((X.real, X.imag))  # (2, k, j)
    his = (Z,) if Z_lo is None else (Z, Z_lo)  # (i, k)
    # the terms (term, part, i, j): Z_ik·X_kj for every k (and lo), then −X_ij·w_j
    x = np.concatenate([np.broadcast_to(half.T[:, None, :, None], (size, *shape)) for half in his]
                       + [np.array([[-X.real, -X.real], [X.imag, -X.imag]])])
    y = np.concatenate([np.broadcast_to(parts.transpose(1, 0, 2)[:, :, None, :], (size, *shape))]
                       * len(his) + [np.broadcast_to(np.array([[w.real, w.imag], [w.imag, w.real]])
                                                     [:, :, None, :], (2, *shape))])
    products, small = two_prod(x, y)
    count = products.shape[0]
    small = small.sum(axis=0)
    while products.shape[0] > 1:  # pairwise two-sums, their errors kept
        if products.shape[0] % 2:
            products = np.concatenate((products, np.zeros_like(products[:1])))
        products, carry = two_sum(products[0::2], products[1::2])
        small += carry.sum(axis=0)
    R_parts = products[0] + small
    gamma = 2 * count * U / (1 - 2 * count * U)
    x_abs, y_abs = np.abs(x), np.abs(y)
    error = U * np.abs(R_parts) + 2 * gamma * gamma * (x_abs * y_abs).sum(axis=0)
    if Z_lo is not None:
        error += U * (np.abs(Z_lo) @ np.abs(parts))
    largest = max(float(x_abs.max()), float(y_abs.max()))
    if not (largest < _SPLIT_SAFE and np.isfinite(error).all() and np.isfinite(R_parts).all()):
        error = np.full_like(error, np.inf)  # Dekker's split could overflow
    R = R_parts[0] + 1j * R_parts[1]
    return R, (error[0] + error[1]) * (1 + 4 * U)


class Refined:
    """The refined evaluation of a diagonal :class:`BlockMotion` (see the module notes).

    Parameters
    ----------
    motion : BlockMotion
        A finished decomposition without 2 x 2 blocks.
    Y : numpy.ndarray
        The computed inverse of the basis X.
    theta : float
        θ ≥ ‖I − Y X‖ (below 1/2).
    inverse : float
        A bound on ‖X⁻¹‖₂.
    """

    def __init__(self, motion: Any, Y: np.ndarray, theta: float, inverse: float) -> None:
        n, X, size = motion.n, motion.X, motion.X.shape[0]
        w = motion.poles
        R, R_error = _residual(motion.Z, motion.Z_lo, X, w)
        F = Y @ R
        # |X⁻¹R_exact − fl(Y R)| ≤ |Y|·R_error + the product's rounding + |(X⁻¹ − Y)R_exact|
        Y_abs, R_abs = np.abs(Y), np.abs(R)
        R_norm = math.sqrt(float(np.vdot(R_abs + R_error, R_abs + R_error).real))
        error = (Y_abs @ R_error + (4 * size + 8) * U * (Y_abs @ R_abs)) * (1 + 4 * U) \
            + theta * inverse * R_norm
        delta = np.diagonal(F).copy()
        for j in motion.real_columns:  # a real eigenvalue stays real
            delta[j] = delta[j].real
        for m, i in motion.mirrors:  # its conjugate twin moves with it
            delta[m] = delta[i].conjugate()
        left = F.copy()
        left.flat[::size + 1] = np.diagonal(F) - delta
        bounded = np.abs(left) * (1 + 4 * U) + error  # ≥ |F'_jk|
        self.rates, self.shifts = w[motion.columns], delta[motion.columns]
        d_abs = np.abs(delta)
        self.d_max = float(d_abs.max(initial=0.0))
        self.speed = float(np.abs(w).max(initial=0.0)) + self.d_max
        self.growth = float((w.real + d_abs).max()) + 2 * U * self.speed
        gaps = np.abs(w[:, None] - w[None, :]) * (1 - 4 * U) - d_abs[:, None] - d_abs[None, :]
        with np.errstate(divide="ignore"):
            reach = np.where(gaps > 0, 2 / np.where(gaps > 0, gaps, 1.0), np.inf)
        reach.flat[::size + 1] = np.inf
        self.reach = reach.ravel()
        self.phi = math.sqrt(float(np.vdot(bounded, bounded).real))
        self._motion, self._bounded, self._delta_abs = motion, bounded, d_abs
        self.unit = (2 * n + 20) * U
        self.slope = 8 * U * U * self.speed + 4 * U * self.d_max
        self._orders: dict[int, _Rows] = {}

    def _rows(self, order: int) -> _Rows:
        """The constants of derivative ``order``'s bound (built on first use)."""
        if order not in self._orders:
            self._orders[order] = _Rows(self, self._motion, order)
        return self._orders[order]

    def values(self, t: np.ndarray, lo: np.ndarray | None, order: int = 0) -> np.ndarray:
        """Re Σ_j g_j e^{w'_j t} at times t (+ lo), the phases in double-double (g_j the
        weights of x, x' or x'')."""
        a, b = self.rates.real[:, None], self.rates.imag[:, None]
        da, db = self.shifts.real[:, None], self.shifts.imag[:, None]
        t_lo = 0.0 if lo is None else lo
        with np.errstate(over="ignore", invalid="ignore", under="ignore"):
            p, e = two_prod(a, t)
            # the exponent p + e' renormalized to s + r (|r| ≤ u|s|): below −745, e^s is 0
            # and so is the motion's (e^{s+r} ≤ e^{s(1−u)}), whatever e^r would overflow to
            s, r = two_sum(p, e + (da * t + a * t_lo))
            decay = np.exp(s) * np.exp(np.where(s < -745.0, 0.0, r))
            cos, sin, _ = phase(b, db, t, t_lo)
            factor = decay * cos + 1j * (decay * sin)
            terms = (self._rows(order).weights[:, :, None] * factor[None, :, :]).real
        values: np.ndarray = np.add.reduce(terms, axis=1)
        return values

    def bounds(self, t: np.ndarray, order: int = 0) -> np.ndarray:
        """The bounds of :meth:`values` at times t (inf where the split could overflow)."""
        g, rows = self.growth, self._rows(order)
        with np.errstate(over="ignore", invalid="ignore"):
            grow = np.exp(g * t)
            spread = np.exp((g + self.phi) * t)
            first = columns_product(rows.terms, np.minimum(t[None, :], self.reach[:, None]))
            second = rows.second[:, None] * (t * t * spread)
            rounding = rows.size[:, None] * (self.unit + self.slope * t)
            bounds = (grow * (first + rounding + (rows.start + rows.moved)[:, None]) + second
                      + rows.direct[:, None] * spread) * _SAFETY
            bounds += rows.size[:, None] * (1e-300 * (1 + t))
        unsafe = ~(t * (1 + self.speed) < _SPLIT_SAFE)
        if unsafe.any():
            bounds[:, unsafe] = np.inf
        return np.where(np.isnan(bounds), np.inf, bounds)

    def bound_until(self, T: float) -> float:
        """An upper bound of :meth:`bounds` over [0, T] (each t^k e^{rt} at its largest)."""
        if not T * (1 + self.speed) < _SPLIT_SAFE:
            return math.inf
        g = self.growth
        P0, P1 = peak(g, 0, T), peak(g, 1, T)
        second = peak(g + self.phi, 2, T)
        if not all(map(math.isfinite, (P0, P1, second))):
            return math.inf
        rows = self._rows(0)
        first = rows.terms @ np.minimum(P1, self.reach * P0)
        found = (first + rows.size * (self.unit * P0 + self.slope * P1) + rows.start * P0
                 + rows.second * second) * _SAFETY + rows.size * 1e-300 * (1 + T)
        largest = float(found.max(initial=0.0))
        return math.inf if math.isnan(largest) else largest * (1 + 1e-12)


class _Rows:
    """The constants of one derivative order's bound: with L the rows that give x^(k) from
    the exact motion (X's position rows; σ times its velocity rows; those times B' =
    diag(w + δ) for x''), ``terms`` K_i,(jk) = |L_ij|·|F'_jk|·(|c_k| + ρ₀), ``second``
    ‖L_i‖φ'²/2·(‖c‖ + ρ₀), ``start`` ‖L_i‖ρ₀, ``size`` Σ_j|g_ij| of the evaluated weights
    g; for x'' also ``direct`` ‖σX_v,i‖φ'(‖c‖ + ρ₀) (the term σX_v F'e^{(B'+F')t}c*, at
    most that times e^{(g+φ')t}) and ``moved`` Σ_j σ|X_v,ij||δ_j||c_j| (the weights are
    formed with w, the motion's exponents are w + δ)."""

    def __init__(self, refined: Refined, motion: Any, order: int) -> None:
        n, X, sigma = motion.n, motion.X, motion.sigma
        size = X.shape[0]
        L_abs = np.abs(X[:n]) if order == 0 else sigma * np.abs(X[n:])
        zeros = np.zeros(n)
        self.direct, self.moved = zeros, zeros
        c_norm = motion.c_norm + motion.rho0
        if order == 2:
            self.direct = np.sqrt((L_abs * L_abs).sum(axis=1)) * (refined.phi * c_norm) \
                * (1 + 4 * U)
            self.moved = L_abs @ (refined._delta_abs * np.abs(motion.c)) * (1 + 4 * U)
            L_abs = L_abs * (np.abs(motion.poles) + refined._delta_abs)[None, :]
        L_abs = L_abs * (1 + 4 * U)
        c_abs = np.abs(motion.c) + motion.rho0
        terms = L_abs[:, :, None] * (refined._bounded * c_abs[None, :])[None, :, :]
        self.terms = terms.reshape(n, size * size) * (1 + 4 * U)
        rows = np.sqrt((L_abs * L_abs).sum(axis=1)) * (1 + 4 * U)
        self.second = rows * (refined.phi * refined.phi / 2 * c_norm)
        self.start = rows * motion.rho0
        weights = motion._order(order)
        self.weights, self.size = weights.g, weights.single_size

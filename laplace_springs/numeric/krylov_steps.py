"""One Taylor step of the krylov engine: its terms, the next state, values inside it, and
the size of every rounding committed (the arithmetic behind :mod:`.krylov`).

A step from the state ẑ = (x̂, v̂) (double-doubles) forms the terms U_k = H^k (A^k ẑ)_v,
k = 0..m (U_0 = v̂), each one sparse product U_k = D·[U_{k−2}; U_{k−1}] (the first with D'
on [x̂; v̂]; see :mod:`.krylov_data`). The exact Taylor series is then

    x(b + rH) = x̂ + Σ_{k≥1} (r^k H / k!)·U_{k−1},      v(b + rH) = Σ_{k≥0} (r^k / k!)·U_k.

*Extended terms.* While a term is large enough for float64's rounding to matter, it is
formed to about 2^-70 (Ozaki's error-free split: the vector w = [U_{k−2}; U_{k−1}] is cut
at the grid 2^(F − b), 2^F > max|w|, its leading part w₁ multiplied exactly by D₁ and the
rest in one float64 product [D₂ + D_lo | D_hi]·[w₁; w₂ + w_lo]), and kept as a
double-double. Its rounding is at most β₂‖w₁‖ + β(‖w₂ + w_lo‖ + 2u‖w‖) in the energy
norm, β and β₂ the norms of |D| and |D₂ + D_lo| weighted by √m_r·(γ_{2w_r} + 2u) per row.
Once a float64 product's rounding, carried to the end of the series, is below
Limits.krylov_step_error/256 of the scene's energy N(z0) (a test on the terms' computed
norms, so the switch is a function of the state alone), the remaining terms are plain
float64 products, whose rounding N(f_k) ≤ F_x‖U_{k−2}‖_m + F_v‖U_{k−1}‖_m with
‖u‖_m = ‖√m·u‖₂ and F the norms of diag(√m·g)|D|diag(1/√m) (:mod:`.krylov_data`).

*The step's error, exactly.* With Z = HA and s_k = (H·U_{k−1}, U_k) (s_0 = ẑ), the
computed terms obey s_k = Z s_{k−1} + g_k, g_k = (0, f_k) the rounding of term k, and the
step sums S(r) = Σ_{k≤m} r^k s_k/k!. Unrolling, s_k = Z^k ẑ + Σ_{i≤k} Z^{k−i} g_i, and with
φ_k(Z) = Σ_j Z^j/(j + k)! = ∫₀¹ e^{(1−s)Z} s^{k−1}/(k−1)! ds the tails of the perturbations
cancel against the tail of ẑ's series:

    e^{rZ}ẑ − S(r) = r^{m+1}φ_{m+1}(rZ)·Z s_m − Σ_{i=1}^{m} r^i φ_i(rZ)·g_i,

(Σ_{k=i}^{m} r^k Z^{k−i}/k! = r^i(φ_i(rZ) − (rZ)^{m+1−i}φ_{m+1}(rZ)), and Z s_m =
Z^{m+1}ẑ + Σ_{i≤m} Z^{m+1−i}g_i). The
motion never increases N, so N(φ_k(rZ)y) ≤ N(y)/k!, and N(Z y) ≤ θN(y): the error of the
step is at most θ·N(s_m)/(m + 1)! + Σ_i N(g_i)/i! for every r in [0, 1], with N(s_m)
from the computed vectors through xᵀKx ≤ Σ_i s_i x_i², s_i = Σ_j |K_ij| (an a posteriori
truncation: well below the a priori tail(θ, m)·N(ẑ) where the motion's top frequency is
below ν or little excited). On x, the x part of φ_k(rZ)y is y_x/k! + rH·(φ_{k+1}(rZ)y)_v
and |v_i| ≤ N/√m_min: the truncation adds H‖U_m‖∞/(m + 1)! + Hθ·N(s_m)/((m + 2)!√m_min)
and g_i (no x part) H·N(g_i)/((i + 1)!√m_min). m itself is still chosen a priori
(tail(θ, m) ≤ Limits.krylov_step_error/8).

*The next state* is the series at r = 1, Σ_k W_k U_k with the exact weights W_k (H/(k+1)!
for x, 1/k! for v), formed with the same split on the terms scaled by 2^(−s_k) ≈ 1/k!
(exactly): the leading slices' products with the weights' leading slices are exact in one
BLAS product, the rest is a second product off by about 2^-70 of the largest scaled term
(its bound counts only the e + 1 rows summed this way). Of the float64 terms after them,
all but the first two go into one float64 product, then the second and the first are added
in turn: |g| ≤ γ_4|W_{e+1}U_{e+1}| + γ_5|W_{e+2}U_{e+2}| + γ_{m−e+2}Σ_{k>e+2}|W_k||U_k| per
coordinate, dominated by the first terms (one product of all, in any order, would need
γ_{m−e+2} on every term, about ten times more on the spread networks of the tests). The
bounds are formed per coordinate and taken into N with the weights s_i and m_i above (κ
for the float terms' x part, κ² ≥ max_i s_i/m_i), not √‖K‖ and √m_max against Euclidean
norms, which on spread masses cost the factor √(m_max/m_min).

*Values* inside the step are the series in float64 from the leading parts, summed from
the last term down so that the large early terms pass through few additions: the
rounding is at most Σ_k (3k + 4)u·|ω_k|·‖U_{k−1}‖∞ (ω_k the k-th weight: 2k + 1 roundings
of the weight, one of the product, k + 1 of the partial sums it enters, one for the
dropped low part) plus 3u‖x̂‖∞. Every operation on a time's values is elementwise, so a
value does not depend on the other times of the call.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np

from ..kernels.dd import U, dd_add, from_exact, two_sum
from ..limits import limits
from .krylov_data import KrylovData, StepMatrix

__all__ = ["Stepper", "StepTerms", "split_product", "tail"]

#: An absolute bound per entry for underflow in the exact products (values below 1e-300
#: of the scale are far below any target).
_TINY = 1e-300


def tail(theta: float, m: int) -> float:
    """Σ_{k>m} θ^k/k! ≤ θ^(m+1)/(m+1)!/(1 − θ/(m+2)) (for θ < m + 2).

    >>> tail(1.0, 3) > sum(1 / math.factorial(k) for k in range(4, 30))
    True
    """
    if theta <= 0:
        return 0.0
    if theta >= m + 2:
        return math.inf
    return math.exp((m + 1) * math.log(theta) - math.lgamma(m + 2)) / (1 - theta / (m + 2))


@dataclass
class StepTerms:
    """One step's terms (rows of ``hi``/``lo``: 0 is x̂, k + 1 is U_k) and its roundings.

    ``rounding`` is Σ_k φ_k N(f_k) (energy norm) and ``rounding_x`` Σ_k ψ_k N(f_k);
    ``truncation`` and ``truncation_x`` bound the series' tail in N and on max|x|;
    ``sup``, ``norms`` and ``mass_norms`` the max-norm, Euclidean norm and mass-weighted
    norm ‖√m·u‖₂ of every row of ``hi`` (the Euclidean ones of the double-double rows
    only); ``extended`` the number of terms formed in double-double (k = 1..extended)."""

    hi: np.ndarray
    lo: np.ndarray
    extended: int
    rounding: float
    rounding_x: float
    sup: np.ndarray
    norms: np.ndarray
    mass_norms: np.ndarray
    truncation: float
    truncation_x: float


def _csr_kernel() -> Any:
    """SciPy's compiled CSR product y += A x (its public ``@`` allocates and checks on every
    call: a third of a product's time at 1,000 rows), or None where it is not there."""
    try:
        from scipy.sparse import _sparsetools
    except ImportError:  # pragma: no cover - another SciPy layout
        return None
    return getattr(_sparsetools, "csr_matvec", None)


def _csr_into(matrix: Any, vector: np.ndarray, out: np.ndarray, kernel: Any) -> None:
    """out = matrix @ vector (CSR, float64, rows in order) written in place."""
    if kernel is None:  # pragma: no cover - another SciPy layout
        out[...] = matrix @ vector
        return
    out.fill(0.0)
    kernel(matrix.shape[0], matrix.shape[1], matrix.indptr, matrix.indices, matrix.data, vector, out)


def split_product(D: StepMatrix, wh: np.ndarray, wl: np.ndarray, largest: float, norm_w: float,
                  out: tuple[np.ndarray, np.ndarray],
                  buffers: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
                  kernel: Any) -> float:
    """D·(wh + wl) to about 2^-70 (module notes) as the double-double ``out`` = (hi, lo):
    the leading slices of wh (exact at the scale of ``largest`` = max|wh|) times D's sliced
    part, the rest in float64, joined by a two-sum in place. ``buffers`` are (rest, lead,
    low, scratch) of the right sizes. Returns the bound on the product's rounding in N
    (``norm_w`` ≥ N(w)), without the underflow floor."""
    rest, lead, low, scratch = buffers
    _, exponent = math.frexp(largest)
    sigma = math.ldexp(1.5, exponent - D.bits + 52)
    half = wh.size
    w1, c = rest[:half], rest[half:]
    np.add(wh, sigma, out=w1)
    np.subtract(w1, sigma, out=w1)          # the leading slices: exact
    np.subtract(wh, w1, out=c)              # w₂, exact
    np.add(c, wl, out=c)                    # w₂ + w_lo, rounded
    _csr_into(D.sliced, w1, lead, kernel)
    _csr_into(D.rest, rest, low, kernel)
    s, e = out                              # two-sum of lead + low, in place
    np.add(lead, low, out=s)
    np.subtract(s, lead, out=scratch)
    np.subtract(s, scratch, out=e)
    np.subtract(lead, e, out=e)
    np.subtract(low, scratch, out=scratch)
    np.add(e, scratch, out=e)
    norm_1, norm_c = math.sqrt(float(w1 @ w1)), math.sqrt(float(c @ c))
    return (D.rest_lead * norm_1 + D.rest_hi * ((1 + U) * norm_c + 2 * U * norm_w)
            + 2.0**-103 * D.beta * norm_w) * (1 + 1e-12)


class Stepper:
    """The arithmetic of the krylov engine's steps for one scene (see the module notes).

    Parameters
    ----------
    data : KrylovData
    """

    def __init__(self, data: KrylovData) -> None:
        self.data = data
        n, theta = data.n, data.theta
        budget = limits().krylov_step_error
        m = 4
        while tail(theta, m) > budget / 8:
            m += 1
        self.m = m
        self.tail = tail(theta, m)
        # φ_k = 1/k!, ψ_k = 1/(k + 1)! (module notes: the truncation is bounded apart)
        self.phi = np.array([1 / math.factorial(k) for k in range(m + 1)]) * (1 + 1e-12)
        self.psi = np.array([1 / math.factorial(k + 1) for k in range(m + 1)]) * (1 + 1e-12)
        self._cut = (theta * (1 + 1e-12) / math.factorial(m + 1),
                     data.H * (1 + 1e-12) / math.factorial(m + 1),
                     data.H * theta * (1 + 1e-12) / (math.factorial(m + 2) * math.sqrt(data.m_min)))
        self.switch = budget / 256 * data.energy
        self._weights()
        self.hi = np.zeros((m + 2, n))
        self.lo = np.zeros((m + 2, n))
        self._rest = np.zeros(4 * n)
        self._lead = np.zeros(n)
        self._low = np.zeros(n)
        self._scratch = np.zeros(n)
        self._sup = np.zeros(m + 2)
        self._norms = np.zeros(m + 2)
        self._mass_norms = np.zeros(m + 2)
        self._stack = np.zeros((3 * (m + 1), n))
        self._kernel = _csr_kernel()

    # -- the next state's weights ------------------------------------------------------
    def _weights(self) -> None:
        """W'_k = W_k·2^(s_k) (2^(s_k) ≈ k!) as double-doubles, split at their grid."""
        m, H = self.m, Fraction(self.data.H)
        shifts = [round(math.log2(math.factorial(k))) for k in range(m + 1)]
        exact = [[H * 2**s / math.factorial(k + 1) if k < m else Fraction(0),
                  Fraction(2**s, math.factorial(k))] for k, s in enumerate(shifts)]
        pairs = [[from_exact(v) for v in row] for row in exact]
        wh = np.array([[p[0] for p in row] for row in pairs])
        wl = np.array([[p[1] for p in row] for row in pairs])
        self.scale = np.ldexp(1.0, -np.array(shifts))[:, None]
        self.sum_bits = (53 - math.ceil(math.log2(m + 1))) // 2
        largest = np.max(np.abs(wh), axis=0)
        _, exponent = np.frexp(largest)
        sigma = np.ldexp(1.5, exponent - self.sum_bits + 52)
        w1 = (wh + sigma) - sigma
        self.w1 = np.ascontiguousarray(w1)
        self.w_rest = np.ascontiguousarray(np.vstack([(wh - w1) + wl, w1, wh]))
        # omega[e] for the e + 1 terms U_0..U_e summed with the split (R = e + 1 rows,
        # 3R products in the rest): per column (x, v), |g_ic| ≤ omega[e, c]·colmax_i
        q = 2.0**-self.sum_bits
        R = np.arange(1, m + 2, dtype=float)[:, None]
        gamma = 3 * R * U / (1 - 3 * R * U)
        total = np.cumsum(np.abs(wh), axis=0)
        omega = gamma * (R * (q + U) * (1 + U) * largest + (q + U) * total + R * q * q * largest) \
            + U * (q + U) * R * largest + (U * U + 2.0**-104) * total
        self.omega = omega * (1 + 1e-9)
        # the float64 terms' weights W_k (unscaled) and their product's rounding
        self.w_float = np.array([[float(H / math.factorial(k + 1)) if k < m else 0.0,
                                  1 / math.factorial(k)] for k in range(m + 1)])

    # -- the terms ----------------------------------------------------------------------
    def terms(self, zh: np.ndarray, zl: np.ndarray) -> StepTerms:
        """The terms of the step from ẑ = zh + zl and the bound on their rounding."""
        d, m = self.data, self.m
        n = d.n
        hi, lo, sup, norms, mass = self.hi, self.lo, self._sup, self._norms, self._mass_norms
        weight = d.mass
        hi[0], hi[1] = zh[:n], zh[n:]
        lo[0], lo[1] = zl[:n], zl[n:]
        lo[2:] = 0.0
        norms[2:] = 0.0
        for row in (0, 1):
            sup[row] = self._row_sup(row)
            norms[row] = math.sqrt(float(hi[row] @ hi[row]))
            mass[row] = math.sqrt(float(hi[row] @ (weight * hi[row])))
        rounding = np.zeros(m + 1)
        count = m
        L = d.later
        for k in range(1, m + 1):
            rounding[k] = self._extended(d.first if k == 1 else d.later, k)
            sup[k + 1] = self._row_sup(k + 1)
            norms[k + 1] = math.sqrt(float(hi[k + 1] @ hi[k + 1]))
            mass[k + 1] = math.sqrt(float(hi[k + 1] @ (weight * hi[k + 1])))
            if k < m and (L.float_x * mass[k] + L.float_v * mass[k + 1]) * self.phi[k + 1] <= self.switch:
                count = k
                break
        for k in range(count + 1, m + 1):      # the float64 terms
            _csr_into(d.later.hi, hi[k - 1:k + 1].reshape(-1), hi[k + 1], self._kernel)
        if count < m:
            rows = hi[count + 2:]
            mass[count + 2:] = np.sqrt(np.einsum("ij,ij,j->i", rows, rows, weight))
            sup[count + 2:] = np.max(np.abs(rows), axis=1)
            rounding[count + 1:] = (L.float_x * mass[count:m] + L.float_v * mass[count + 1:m + 1]) * (1 + 1e-12)
        # the tail: N(Z s_m)/(m + 1)! with s_m = (H·U_{m−1}, U_m) (module notes);
        # N(s_m)² ≤ H²·Σ s_i U_{m−1,i}² + Σ m_i U_{m,i}², |hi + lo| ≤ (1 + u)|hi|
        last, before = hi[m + 1], hi[m]
        state = math.sqrt(d.H * d.H * float(before @ (d.stiffness * before))
                          + float(last @ (weight * last))) * (1 + 4 * U) * (1 + 1e-12)
        cut, cut_x, cut_v = self._cut
        return StepTerms(hi, lo, count, float(self.phi @ rounding) * (1 + 1e-12),
                         float(self.psi @ rounding) * (1 + 1e-12), sup.copy(),
                         norms * (1 + 1e-12), mass * (1 + 1e-12), cut * state + _TINY,
                         cut_x * sup[m + 1] * (1 + 2 * U) + cut_v * state + _TINY)

    def _row_sup(self, row: int) -> float:
        values = self.hi[row]
        return max(float(values.max(initial=0.0)), -float(values.min(initial=0.0)))

    def _extended(self, D: StepMatrix, k: int) -> float:
        """Term k to about 2^-70 (module notes), into rows k + 1 of hi and lo; returns the
        bound on N(f_k)."""
        n = self.data.n
        wh = self.hi[k - 1:k + 1].reshape(-1)
        wl = self.lo[k - 1:k + 1].reshape(-1)
        largest = max(self._sup[k - 1], self._sup[k])
        norm_w = math.hypot(self._norms[k - 1], self._norms[k])
        return split_product(D, wh, wl, largest, norm_w, (self.hi[k + 1], self.lo[k + 1]),
                             (self._rest, self._lead, self._low, self._scratch), self._kernel) \
            + _TINY * math.sqrt(n * self.data.m_max)

    # -- the next state ----------------------------------------------------------------
    def advance(self, terms: StepTerms) -> tuple[np.ndarray, np.ndarray, float, float]:
        """The state at the end of the step (hi, lo), and bounds on the energy norm and on
        the max-norm of x of the rounding committed in the sum (the terms' own rounding is
        in ``terms``).

        U_0..U_e (e = ``terms.extended``: the double-double terms) are summed with the exact
        split (module notes); the float64 terms after them, whose weighted sizes are small,
        in one float64 product, off by (γ_m + 2u)·Σ_k |W_k||U_k|."""
        d, m = self.data, self.m
        n, e = d.n, terms.extended
        rows = e + 1                       # U_0..U_e: rows 1..e+1 of hi
        stack = self._stack[:3 * rows]
        scaled = stack[:rows]
        np.multiply(terms.hi[1:rows + 1], self.scale[:rows], out=scaled)
        colmax = np.max(np.abs(scaled), axis=0)
        _, exponent = np.frexp(colmax)
        sigma = np.ldexp(1.5, exponent - self.sum_bits + 52)
        lead = (scaled + sigma) - sigma
        np.subtract(scaled, lead, out=stack[rows:2 * rows])
        np.multiply(terms.lo[1:rows + 1], self.scale[:rows], out=stack[2 * rows:])
        exact = lead.T @ self.w1[:rows]
        weights = np.vstack([self.w_rest[k * (m + 1):k * (m + 1) + rows] for k in range(3)])
        rest = stack.T @ weights
        float_energy = float_xinf = 0.0
        if e < m:                          # the float64 terms U_{e+1}..U_m
            # the terms after the first two in one float64 product (any order: γ_{L−2}
            # on each, L = m − e), then the second and the first added in turn, then the
            # whole to rest: with the weights' rounding, |g| ≤ γ_4|W_{e+1}U_{e+1}|
            # + γ_5|W_{e+2}U_{e+2}| + γ_{L+2}Σ_{k>e+2}|W_k U_k| per coordinate (the first
            # terms dominate); in N, κ·‖·‖_m for x and ‖·‖_m for v
            tail_weights = self.w_float[e + 1:]
            count = m - e
            if count > 2:
                total = terms.hi[e + 4:].T @ tail_weights[2:]
            else:
                total = np.zeros((n, 2))
            for k in range(min(count, 2) - 1, -1, -1):
                total += terms.hi[e + 2 + k][:, None] * tail_weights[k][None, :]
            rest += total
            passes = np.full(count, count + 2.0)
            passes[:2] = (4.0, 5.0)[:min(count, 2)]
            sizes = np.abs(tail_weights) * (passes * U / (1 - passes * U))[:, None]
            float_energy = float((d.kappa * sizes[:, 0] + sizes[:, 1]) @ terms.mass_norms[e + 2:]) * (1 + 1e-12)
            float_xinf = float(sizes[:, 0] @ terms.sup[e + 2:]) * (1 + 1e-12)
        sh, sl = two_sum(exact, rest)
        xh, xl = dd_add(terms.hi[0], terms.lo[0], sh[:, 0], sl[:, 0])
        vh, vl = sh[:, 1], sl[:, 1]
        omega_x, omega_v = self.omega[e]
        top = float(colmax.max(initial=0.0)) + _TINY
        # per coordinate bounds on the x and v parts of the sum's rounding, and their
        # N-norm through xᵀKx ≤ Σ s_i x_i², vᵀMv ≤ Σ m_i v_i² (krylov_data)
        g_x = (omega_x * colmax + 2 * U * np.abs(rest[:, 0])
               + 2.0**-104 * (np.abs(terms.hi[0]) + np.abs(sh[:, 0])))
        g_v = omega_v * colmax + 2 * U * np.abs(rest[:, 1])
        g_xinf = (omega_x * top + float_xinf + 2 * U * float(np.max(np.abs(rest[:, 0]), initial=0.0))
                  + 2.0**-104 * (terms.sup[0] + float(np.max(np.abs(sh[:, 0]), initial=0.0))))
        energy = (math.sqrt(float(g_x @ (d.stiffness * g_x))) + math.sqrt(float(g_v @ (d.mass * g_v)))
                  + float_energy + _TINY * math.sqrt(n * (d.m_max + d.norm_K)))
        state_h = np.concatenate([xh, vh])
        state_l = np.concatenate([xl, vl])
        return state_h, state_l, energy * (1 + 1e-12), g_xinf * (1 + 1e-12)

    # -- values inside the step --------------------------------------------------------
    def values(self, terms: StepTerms, r: np.ndarray, order: int) -> tuple[np.ndarray, np.ndarray]:
        """x (order 0) or v (order 1) at b + r·H for each r in [0, 1), shape (len(r), n),
        and a bound per time on the float64 rounding of the sums (module notes)."""
        m, H = self.m, self.data.H
        steps = np.empty((m + 1, r.size))
        steps[0] = 1.0
        steps[1:] = r[None, :] / np.arange(1, m + 1, dtype=float)[:, None]
        weights = np.cumprod(steps, axis=0)     # w_k = w_{k−1}·(r/k), in that order
        if order == 0:            # x̂ + Σ_{k≥1} (r^k H/k!)·U_{k−1}: rows k of hi
            weights[1:] *= H
            rows, first = np.arange(m, 0, -1), 0
        else:                     # Σ_{k≥0} (r^k/k!)·U_k: rows k + 1
            rows, first = np.arange(m, -1, -1), 1
        hi = terms.hi
        top = int(rows[0])
        acc = weights[top][:, None] * hi[top + first][None, :]
        product = np.empty_like(acc)
        for k in rows[1:]:
            np.multiply(weights[k][:, None], hi[k + first][None, :], out=product)
            np.add(acc, product, out=acc)
        # Σ_k (3k + 4)u·w_k·sup_k (non-negative terms: their float sum is within the margin)
        # (elementwise, then summed down the rows in order by cumsum: each time's bound is
        # its own column's sequential sum whatever the other times of the call, where a BLAS
        # product or a pairwise sum of a single column would not be)
        bound = np.cumsum(((3 * rows + 4) * U * terms.sup[rows + first])[:, None] * weights[rows],
                          axis=0)[-1]
        if order == 0:
            np.add(acc, hi[0][None, :], out=acc)
            bound = bound + 3 * U * terms.sup[0]
        return acc, bound * (1 + 2.0**-40) + _TINY

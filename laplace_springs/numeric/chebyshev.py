"""Rayleigh-damped scenes by Chebyshev expansion in the stiffness operator (large sparse scenes).

When M is diagonal and positive and C = a K + b M exactly (Rayleigh damping, a, b ≥ 0
rational; :func:`rayleigh_coefficients`), every mode with stiffness λ (an eigenvalue of
M⁻¹K) has damping c(λ) = a λ + b, and the motion is

    x(t) = F_t(M⁻¹K) x0 + G_t(M⁻¹K) v0,

where F_t(λ), G_t(λ) are the solutions of q'' + c(λ) q' + λ q = 0 with (q, q')(0) = (1, 0)
and (0, 1): entire functions of λ. With the spectrum of M⁻¹K in [lo, hi] (Gershgorin,
exact up to a rounding pad) and B = (M⁻¹K − mid)/rad, whose spectrum is in [−1, 1], each
is replaced by its Chebyshev interpolant p_N of degree N on that interval, and

    p_N(B) x0 = Σ_k c_k T_k(B) x0,   T_{k+1}(B)x0 = 2B T_k(B)x0 − T_{k−1}(B)x0,

so the vectors T_k(B) x0 (N sparse products) serve every time at once and the times cost
one matrix product of the n x (N+1) vectors with the (N+1) x T coefficients (a DCT of F_t
at the Chebyshev points). No eigenvectors: time ∝ nnz(K)·N + n·N·T, memory ∝ n·N. N is
chosen from the largest time (N ≈ t_max √hi / 2 + a few dozen). Derivatives use
F' = −λG, G' = F − cG and q'' = −c q' − λ q.

The error bound (per time, per coordinate; all terms computed)
---------------------------------------------------------------
B is self-adjoint in the M-inner product, so ‖T_k(B)‖_M ≤ 1, ‖U_k(B)‖_M ≤ k + 1. The
error of the value, in ‖·‖_M = ‖M^{1/2}·‖₂ and per coordinate |e_i| ≤ ‖e‖_M/√m_i, is at
most the sum, for (f, w) = (F_t, x0) and (G_t, v0), of

* truncation: ‖f − p_N‖ on [−1, 1] ≤ 4 M_r r^{−N}/(r − 1) (interpolation in Chebyshev
  points, f analytic in the Bernstein ellipse E_r, |f| ≤ M_r there; Trefethen, ATAP
  Thm 8.2), minimised over r. M_r comes from an energy estimate valid for complex λ and
  c: with u = (√|λ| q, q'), ‖u(t)‖ ≤ e^{μt}‖u(0)‖, μ = (−Re c + √((Re c)² + 4β²))/2 and
  β = |Im √λ| (the logarithmic norm of u' = [[0, √|λ|], [−λ/√|λ|, −c]] u); so |F| ≤ e^{μt},
  |G| ≤ t e^{μt}, |F'| ≤ √|λ| e^{μt}, |G'| ≤ e^{μt}, and higher derivatives by
  q'' = −c q' − λ q. μ is bounded on E_r by covering it with boxes (β is largest at a
  box's corner of least real part and largest imaginary part);
* the values of f at the nodes: the nodes, c(λ) and the phases (in turns, reduced modulo
  1) are computed in the working precision (the x87 long double, unit roundoff
  u_w = 2^-64, where numpy has it; else float64), the exponents and the cos, sin and exp
  in float64 (an exponent's rounding costs u per unit of it, a phase's would cost u per
  radian), so the rounding is (16 + 10(|√δ| + h)t) u_w + (24 + 2·rate·t) u of the
  envelope, plus the rounding of the nodes and of a, b (through bounds on ∂f/∂λ, ∂f/∂c from the same
  estimate), mapped to the interpolant by the Lebesgue constant Λ_N ≤ (2/π) log(N+1) + 1;
* the DCT's rounding, in the working precision (the FFT model of Higham, *Accuracy and
  Stability*, Thm 24.2, with a factor 2.5 to spare): Σ_k |Δc_k| ≤ √(N+1)·16 (log₂ 2N + 2)
  u_w ‖ĉ‖₂;
* the recurrence, run in the working precision with P and s rounded from the float64
  data: step j commits δ_j with |δ_j| ≤ γ_{w+5}|P||v_j| + γ_5|s||v_j| + γ_1|v_{j−1}|
  per entry (w the nonzeros of the row; plus 2.01u|P||v_j| when the float64 M or K are
  not the scene's exact entries), which reaches v_k as U_{k−1−j}(B)δ_j; the error of the
  value is Σ_j b_{j+1}(B)δ_j with b_j = Σ_{k≥j} ĉ_k U_{k−j}, and ‖b_j(B)‖_M ≤ S_j, the
  sum of the absolute T-coefficients of b_j (|R_j| + 2Σ_{l>j}|R_l|, R_l = ĉ_l + ĉ_{l+2} + ...,
  within a few per cent of max |b_j|, where Σ_{k≥j}|ĉ_k|(k − j + 1) from ‖U_m‖ ≤ m + 1 is 2
  to 10 times larger);
* the final product Σ_k ĉ_k V_k in float64, in 6 blocks of L = ⌈(N+1)/6⌉ terms
  (γ_L + γ_{blocks}), with the rounding of the coefficients and of the vectors to float64:
  (L + blocks + 2)u Σ_k |ĉ_k| max_i |V_ik|, the same for every entry; and the rounding of
  x0, v0 to float64.

With the working precision the recurrence's rounding, N² u_w, is far below u: the bound
is about 1e-14 to 6e-14 of ‖x0‖ at t_max √hi ≈ 100 to 500 (chains and random meshes with
Rayleigh damping, 1,000 to 10,000 masses), a few times the actual error. Without it
(float64 only) the bound is honest but about a thousand times larger.
"""

from __future__ import annotations

import math
from functools import cached_property
from typing import Any

import numpy as np
from flint import fmpq

from ..kernels.batch import columns_product, rows_product
from ..limits import limits
from ..model.errors import SceneError
from ..model.scene import Scene
from .classical import (
    ClassicalMotion,
    ModalForm,
    SymmetricScene,
    _probe_vector,
    _scipy,
    float_matrices,
    mode_poles,
    symmetric_scene,
)
from .first_order import rational_entries, scene_cache

__all__ = ["rayleigh_coefficients", "ChebyshevMotion", "chebyshev_motion", "chebyshev_refusal",
           "chebyshev_cost", "chebyshev_interval", "chebyshev_degree", "verified_interval"]

_EPS = float(np.finfo(float).eps)
_U = _EPS / 2
#: The working precision of the recurrence, the values at the nodes and the DCT: the x87
#: long double (64-bit significand, unit roundoff 2^-64) where numpy has it, else float64.
_WORK: Any = np.longdouble if float(np.finfo(np.longdouble).eps) < _EPS / 1024 else np.float64
_UW = float(np.finfo(_WORK).eps) / 2
#: Bernstein-ellipse parameters r = 1 + ε tried for the truncation bound.
_RADII = 1 + np.geomspace(1e-4, 8.0, 40)
#: Boxes covering the upper half of each ellipse.
_BOXES = 96
#: The final product Σ_k c_k V_k is summed in this many blocks (its rounding bound is
#: γ_{(N+1)/blocks} + γ_{blocks} instead of γ_{N+1}).
_PRODUCT_BLOCKS = 6
#: Largest number of (node, time) pairs held at once; more times are done in chunks.
_CHUNK = 2_000_000
#: Largest number of floats of Chebyshev vectors kept between calls.
_KEEP = 25_000_000


# ----------------------------------------------------------------------------- exact check


def rayleigh_coefficients(scene: Scene) -> tuple[Any, Any] | None:
    """(a, b) with C = a K + b M exactly, M diagonal and positive, K symmetric, a, b ≥ 0
    (flint fmpq), or None. Time proportional to the nonzero entries.

    Examples
    --------
    >>> K = [[2, -1], [-1, 2]]
    >>> rayleigh_coefficients(Scene.from_matrices(M=[[1, 0], [0, 1]], C=[["2/5", "-1/10"],
    ...     ["-1/10", "2/5"]], K=K, x0=[1, 0], v0=[0, 0]))
    (1/10, 1/5)
    >>> rayleigh_coefficients(Scene.from_matrices(M=[[1, 0], [0, 1]], C=[[1, 0], [0, 0]],
    ...                                           K=K, x0=[1, 0], v0=[0, 0])) is None
    True
    """
    cache = scene_cache(scene)
    if "rayleigh" not in cache:
        cache["rayleigh"] = _rayleigh(scene)
    return cache["rayleigh"]


def _rayleigh(scene: Scene) -> tuple[Any, Any] | None:
    M, C, K = (rational_entries(scene, name) for name in ("M", "C", "K"))
    if M is None or C is None or K is None or len(M) != scene.n:
        return None
    if any(i != j or value <= 0 for (i, j), value in M.items()):
        return None
    off = next((key for key in K if key[0] != key[1]), None)
    zero = fmpq(0)
    a = C.get(off, zero) / K[off] if off is not None else zero
    b = (C.get((0, 0), zero) - a * K.get((0, 0), zero)) / M[0, 0]
    if a < 0 or b < 0:
        return None
    if len(C) + len(K) > 256 and _clearly_not_rayleigh(scene, a, b):
        return None
    if any(K.get((j, i)) != value for (i, j), value in K.items()):
        return None
    for key in C.keys() | K.keys():
        expected = a * K.get(key, zero)
        if key[0] == key[1]:
            expected += b * M[key]
        if C.get(key, zero) != expected:
            return None
    if any(C.get(key, zero) != b * value for key, value in M.items() if key not in K):
        return None
    return a, b


def _clearly_not_rayleigh(scene: Scene, a: Any, b: Any) -> bool:
    """A float64 screen: (C − aK − bM)v, for one fixed positive vector v, has an entry far
    above the rounding of its terms (1e-9 of (|C| + a|K| + bM)v, where float64 errs by
    about 1e-15 of it), so C ≠ aK + bM and the exact pass over every entry need not run (a
    4,000-mass mesh: 0.04 s of fmpq work). A scene it does not reject goes to that pass."""
    found = float_matrices(scene)
    if found is None:
        return False
    M, C, K = found
    a_f, b_f = float(a), float(b)
    v = _probe_vector(scene.n)   # (C − aK − bM)v against its terms' size on one vector
    difference = np.abs(C @ v - a_f * (K @ v) - b_f * (M @ v))
    size = abs(C) @ v + a_f * (abs(K) @ v) + b_f * (M @ v)
    return bool(np.any(difference > 1e-9 * size))


# ----------------------------------------------------------------------------- bounds


def _work_number(value: Any) -> tuple[Any, float]:
    """A rational (flint fmpq, Fraction, int) or float in the working precision and a bound
    on its relative error: one rounding when its numerator and denominator are below 2^63,
    else it goes through float64."""
    if isinstance(value, float):
        return _WORK(value), 0.0
    p: Any = getattr(value, "p", None)
    q: Any = getattr(value, "q", None)
    if p is None:
        p, q = getattr(value, "numerator", None), getattr(value, "denominator", None)
    if p is not None and q is not None and abs(int(p)) < 2**63 and 0 < int(q) < 2**63:
        return _WORK(int(p)) / _WORK(int(q)), _UW
    return _WORK(float(value)), _U + _UW


def _mu(beta: np.ndarray, gamma: np.ndarray) -> np.ndarray:
    """(−γ + √(γ² + 4β²))/2 ≥ 0 without cancellation."""
    root = np.sqrt(gamma * gamma + 4 * beta * beta)
    with np.errstate(divide="ignore", invalid="ignore"):
        stable = np.where(gamma > 0, 2 * beta * beta / np.where(gamma > 0, gamma + root, 1.0),
                          (root - gamma) / 2)
    return stable


def _imag_sqrt(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """|Im √(x + iy)| without cancellation."""
    modulus = np.hypot(x, y)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(x > 0, np.abs(y) / np.sqrt(2 * (modulus + np.where(x > 0, x, 0.0))),
                        np.sqrt((modulus - x) / 2))


def _derivative_bounds(b0: np.ndarray, b1: np.ndarray, lam: np.ndarray, c: np.ndarray,
                       order: int) -> np.ndarray:
    """Bounds on |q^(order)| from |q| ≤ b0, |q'| ≤ b1 and q'' = −c q' − λ q."""
    bounds = [b0, b1]
    for _ in range(order - 1):
        bounds.append(c * bounds[-1] + lam * bounds[-2])
    return bounds[order]


def _log_bound(kind: str, order: int, mu: np.ndarray, lam: np.ndarray, c: np.ndarray,
               t: np.ndarray) -> np.ndarray:
    """log of a bound on |F_t^(order)| ("F") or |G_t^(order)| ("G"), broadcast over
    (..., times), given μ, |λ|max, |c|max on a region."""
    grow = mu * t
    root = np.sqrt(lam)
    if kind == "F":
        b0, b1 = np.ones_like(root * t), root + 0 * t
    else:
        b0, b1 = t + 0 * root, np.ones_like(root * t)
    with np.errstate(divide="ignore", over="ignore"):
        return grow + np.log(_derivative_bounds(b0, b1, lam, c, order))


class _Ellipses:
    """Boxes covering the upper halves of the Bernstein ellipses E_r mapped to λ."""

    def __init__(self, mid: float, rad: float, a: float, b: float) -> None:
        phi = np.linspace(0.0, math.pi, _BOXES + 1)
        A = (_RADII + 1 / _RADII) / 2
        Bm = (_RADII - 1 / _RADII) / 2
        cos, sin = np.cos(phi), np.sin(phi)
        top = np.maximum(sin[:-1], sin[1:])
        top[(phi[:-1] <= math.pi / 2) & (phi[1:] >= math.pi / 2)] = 1.0
        pad = 1e-12
        x_lo = mid + rad * (A[:, None] * cos[None, 1:]) - pad * (abs(mid) + rad * A[:, None])
        x_hi = mid + rad * (A[:, None] * cos[None, :-1]) + pad * (abs(mid) + rad * A[:, None])
        y = rad * Bm[:, None] * top[None, :] * (1 + pad) + pad * rad
        beta = _imag_sqrt(x_lo, y)
        gamma = a * x_lo + b  # a ≥ 0: least Re c at least Re λ
        # per ellipse: the largest μ over its boxes, and the largest |λ| and |c| on it (the
        # bound e^{μt}·P(|λ|, |c|, t) with P increasing in both holds with the maxima)
        self.mu = np.max(_mu(beta, gamma), axis=1)[:, None]          # (radii, 1)
        self.lam = np.max(np.hypot(np.maximum(np.abs(x_lo), np.abs(x_hi)), y), axis=1)[:, None]
        self.c = a * self.lam + b
        self.log_r = np.log(_RADII)[:, None]
        self.log_gap = np.log(_RADII - 1)[:, None]

    def log_max(self, kind: str, order: int, t: np.ndarray) -> np.ndarray:
        """log M_r(t): (radii, times)."""
        return _log_bound(kind, order, self.mu, self.lam, self.c, t[None, :])

    def degrees(self, kind: str, order: int, t: np.ndarray, log_tol: float) -> np.ndarray:
        """For each time, the least N with min_r 4 M_r r^{−N}/(r − 1) ≤ e^{log_tol}."""
        log_m = self.log_max(kind, order, t)
        need = np.min((math.log(4) + log_m - self.log_gap - log_tol) / self.log_r, axis=0)
        return np.where(np.isnan(need), 1e9, np.ceil(np.clip(need, 0, 1e9)))  # f = 0: −inf

    def truncation(self, kind: str, order: int, t: np.ndarray, N: int) -> np.ndarray:
        """min_r 4 M_r(t) r^{−N}/(r − 1) for each time."""
        log = math.log(4) + self.log_max(kind, order, t) - N * self.log_r - self.log_gap
        with np.errstate(over="ignore"):
            return np.exp(np.min(log, axis=0))


# ----------------------------------------------------------------------------- the motion


def _tails(coef: np.ndarray, acoef: np.ndarray) -> np.ndarray:
    """S_j ≥ max_{[−1,1]} |b_j|, b_j = Σ_{k≥j} c_k U_{k−j} (rows j = 0..N, columns the
    times): U_m = 2 Σ T_i over 0 ≤ i ≤ m, i ≡ m (mod 2), with half weight on T_0, so the
    T-coefficients of b_j are R_j, 2R_{j+1}, 2R_{j+2}, ... with R_l = c_l + c_{l+2} + ...,
    and S_j = |R_j| + 2 Σ_{l>j} |R_l| (their sum of absolute values; this is within a few
    per cent of the maximum for the oscillating coefficients here, where the bound
    Σ_{k≥j} |c_k|(k − j + 1) from |U_m| ≤ m + 1 is 2 to 10 times larger). The rounding of
    the sums is covered by γ_{N+2} (each R_l within γ_{N+2} Σ_k |c_k|)."""
    N = coef.shape[0] - 1
    even = -(-(N + 1) // 2) * 2
    padded = np.zeros((even,) + coef.shape[1:])
    padded[: N + 1] = coef
    pairs = padded.reshape((even // 2, 2) + coef.shape[1:])    # rows (c_2i, c_2i+1)
    R = np.cumsum(pairs[::-1], axis=0)[::-1].reshape(padded.shape)[: N + 1]
    gamma = 1.01 * (N + 4) * _U
    aR = np.abs(R) + gamma * np.sum(acoef, axis=0)
    after = np.zeros_like(aR)                        # Σ_{l>j} |R_l|
    after[:-1] = np.cumsum(aR[:0:-1], axis=0)[::-1]
    return (aR + 2 * after) * (1 + gamma)


# ----------------------------------------------------------------------------- the interval


def verified_interval(data: SymmetricScene, *, exact: bool) -> tuple[float, float, int, bool]:
    """[lo, hi] ⊇ the spectrum of M⁻¹K, verified: (lo, hi, K's largest row width, whether
    K was proved positive definite).

    Gershgorin's discs of M⁻¹K and of M^{-1/2}KM^{-1/2} (the intersection of the two
    enclosures: each union of discs holds the whole spectrum, a row's smaller radius need not),
    widened by 8(w + 4)u of the largest disc for the float64 sums (w the row width) and
    for the rounding of the entries: an upper bound hi in any case. Where the discs reach
    below 0 (off-diagonal entries larger than the diagonal, as in a dense K = BBᵀ + cI), K
    is checked positive definite by a Cholesky factorization of K − sI in float64 that
    runs to completion (Rump, "Verification of positive definiteness", BIT 46, 2006:
    the computed factor satisfies R̃ᵀR̃ = K − sI + ΔK with ‖ΔK‖₂ ≤ γ/(1 − γ)·tr K for
    γ = γ_{2(w+2)}, so s = 2γ/(1 − γ)·tr K (+ u‖K‖_F when the float64 K is rounded)
    leaves K ≻ 0); then lo = 0. Banded K up to Limits.banded_max_bandwidth and dense K up
    to Limits.dense_eigenvalues_max_coordinates are checked; otherwise lo stays
    Gershgorin's.

    Examples
    --------
    >>> from laplace_springs.numeric.classical import symmetric_scene
    >>> K = [[10, -9, -9], [-9, 10, 8], [-9, 8, 10]]        # positive definite, not dominant
    >>> data = symmetric_scene(Scene.from_matrices(M=[[1, 0, 0], [0, 1, 0], [0, 0, 1]], K=K,
    ...                                            x0=[1, 0, 0], v0=[0, 0, 0]))
    >>> lo, hi, width, definite = verified_interval(data, exact=True)
    >>> lo, round(hi, 6), definite
    (0.0, 28.0, True)
    """
    K = data.K.tocsr()
    m = data.mass
    diag = K.diagonal()
    absK = abs(K)
    row = np.asarray(absK.sum(axis=1)).ravel() - np.abs(diag)
    root = np.sqrt(m)
    sym = np.asarray(absK @ (1 / root)).ravel() / root - np.abs(diag) / m
    center = diag / m
    if data.n == 0:
        return 0.0, 0.0, 0, True
    # each union of discs holds the whole (real) spectrum, so their intervals' intersection
    # does; a row's smaller radius of the two would not (M = diag(4.58, 1.96): 0.383 left out)
    lo = max(float(np.min(center - row / m)), float(np.min(center - sym)))
    hi = min(float(np.max(center + row / m)), float(np.max(center + sym)))
    width = int(np.max(np.diff(K.indptr), initial=0))
    scale = float(np.max(np.abs(center) + np.maximum(row / m, sym), initial=0.0))
    pad = 4 * (width + 4) * _EPS * scale + 1e-300
    lo, hi = lo - pad, hi + pad
    definite = False
    if lo < 0 and data.n:
        definite = _positive_definite(K, data.bandwidth, exact)
        if definite:
            lo = 0.0
    return lo, hi, width, definite


def _positive_definite(K: Any, bandwidth: int, exact: bool) -> bool:
    """Whether a float64 Cholesky factorization proves the symmetric K positive definite
    (see :func:`verified_interval`); False when it fails or K is too large to try."""
    lapack = _scipy().linalg.lapack
    n = K.shape[0]
    diag = K.diagonal()
    if np.any(~(diag > 0)):
        return False
    lim = limits()
    if bandwidth > lim.banded_max_bandwidth and n > lim.dense_eigenvalues_max_coordinates:
        return False
    terms = 2 * (min(bandwidth, n - 1) + 2)
    gamma = terms * _U / (1 - terms * _U)
    shift = 2 * gamma / (1 - gamma) * float(np.sum(diag)) * (1 + n * _EPS)
    if not exact:
        shift += _U * float(np.sqrt(np.sum(K.data * K.data))) * (1 + n * _EPS)
    shift = shift * 1.01 + n * 1e-290
    if bandwidth <= lim.banded_max_bandwidth:
        bands = np.zeros((bandwidth + 1, n))
        for k in range(bandwidth + 1):
            bands[k, : n - k] = K.diagonal(-k)
        bands[0] -= shift
        _, info = lapack.dpbtrf(bands, lower=1)
    else:
        dense = K.toarray()
        dense[np.diag_indices(n)] -= shift
        _, info = lapack.dpotrf(dense, lower=1)
    return bool(info == 0)


def _mu_at(lo: float, a: float, b: float) -> float:
    """The growth rate of the modes at a stiffness lo < 0 (c = a·lo + b)."""
    if lo >= 0:
        return 0.0
    return float(_mu(np.array([math.sqrt(-lo)]), np.array([a * lo + b]))[0])


def chebyshev_interval(scene: Scene) -> tuple[float, float] | None:
    """The verified interval [lo, hi] ⊇ spectrum of M⁻¹K the engine expands on (cached with
    the scene), or None for a scene the engine does not take (not Rayleigh-damped, M not
    diagonal and positive).

    >>> chebyshev_interval(Scene.from_matrices(M=[[1]], C=[[1]], K=[[4]], x0=[1], v0=[0]))[1] > 4
    True
    """
    cache = scene_cache(scene)
    if "chebyshev_interval" not in cache:
        coefficients = rayleigh_coefficients(scene)
        found = None
        if coefficients is not None:
            data = symmetric_scene(scene, damping=coefficients)
            if data.diagonal and np.all(data.mass > 0):
                lo, hi, _, _ = verified_interval(data, exact=_exact_data(scene))
                found = (lo, hi)
        cache["chebyshev_interval"] = found
    interval: tuple[float, float] | None = cache["chebyshev_interval"]
    return interval


def chebyshev_degree(lo: float, hi: float, a: float, b: float, t_max: float, order: int = 0) -> int:
    """The expansion degree N the engine uses for times up to t_max on [lo, hi] (the
    least N whose truncation bound is below u/64 of the data, in multiples of 16)."""
    rad = max((hi - lo) / 2, 1e-300)
    ellipses = _Ellipses(lo + rad, rad, a, b)
    log_tol = math.log(_U / 64)
    t = np.array([max(float(t_max), 0.0)])
    need = max(float(ellipses.degrees(kind, order, t, log_tol)[0]) for kind in ("F", "G"))
    return int(16 * math.ceil(max(need, 1) / 16))


def chebyshev_refusal(scene: Scene, *, t_max: float, count: int, order: int) -> str | None:
    """None when the Chebyshev engine serves this request, else why not (one sentence,
    naming the Limits field when it is a limit). Reads the scene's entries and the verified
    interval (a Gershgorin pass, and a Cholesky factorization where K is not diagonally
    dominant); no eigenvalues.

    Examples
    --------
    >>> chain = Scene.from_matrices(M=[[1, 0], [0, 1]], K=[[2, -1], [-1, 2]], x0=[1, 0], v0=[0, 0])
    >>> chebyshev_refusal(chain, t_max=10.0, count=5, order=0) is None
    True
    >>> print(chebyshev_refusal(chain, t_max=1e9, count=5, order=0))
    the expansion to t = 1e+09 holds 1 x 369,374,257 vectors of 2 entries, more than Limits.chebyshev_max_vector_floats = 125,000,000 floats (the degree grows like t·√‖M⁻¹K‖)
    >>> indefinite = Scene.from_matrices(M=[[1, 0], [0, 1]], K=[[1, 3], [3, 1]], x0=[1, 0], v0=[0, 0])
    >>> print(chebyshev_refusal(indefinite, t_max=10.0, count=5, order=0))
    the verified interval of M⁻¹K reaches down to -2 (K not proved positive definite): the expansion may grow like e^{14.1} by t = 10, more than Limits.chebyshev_max_growth = 1000
    """
    if scene.is_forced or scene.sampled is not None:
        return "the scene is forced"
    if scene.free_symbols:
        return "the scene has symbols"
    coefficients = rayleigh_coefficients(scene)
    if coefficients is None:
        return "the damping is not Rayleigh's (C = aK + bM, a, b ≥ 0, with a diagonal positive M)"
    interval = chebyshev_interval(scene)
    if interval is None:
        return "the mass matrix is not diagonal and positive"
    lim = limits()
    if scene.n > lim.chebyshev_max_coordinates:
        return (f"coordinates {scene.n:,} > Limits.chebyshev_max_coordinates = "
                f"{lim.chebyshev_max_coordinates:,}")
    lo, hi = interval
    a, b = (float(c) for c in coefficients)
    growth = _mu_at(lo, a, b) * max(t_max, 0.0)
    if growth > math.log(lim.chebyshev_max_growth):
        return (f"the verified interval of M⁻¹K reaches down to {lo:.3g} (K not proved positive "
                f"definite): the expansion may grow like e^{{{growth:.3g}}} by t = {t_max:g}, more "
                f"than Limits.chebyshev_max_growth = {lim.chebyshev_max_growth:g}")
    N = chebyshev_degree(lo, hi, a, b, t_max, order)
    columns = 2 if any(v != 0 for v in scene.v0) else 1
    if (N + 1) * scene.n * columns > lim.chebyshev_max_vector_floats:
        return (f"the expansion to t = {t_max:g} holds {columns} x {N + 1:,} vectors of "
                f"{scene.n:,} entries, more than Limits.chebyshev_max_vector_floats = "
                f"{lim.chebyshev_max_vector_floats:,} floats (the degree grows like t·√‖M⁻¹K‖)")
    return None


def chebyshev_cost(scene: Scene, *, t_max: float, count: int, order: int) -> float:
    """Estimated seconds for a request: reading the scene and the interval, the recurrence
    (N sparse products with K), and for every time the nodes' functions, a DCT and the
    product of the n x (N+1) vectors with the coefficients, N = :func:`chebyshev_degree`.

    The model (the development machine, 2 cores, OpenBLAS; fitted to Rayleigh chains of
    1,000 to 100,000 masses at t = 10 to 1,000 and 1 to 1,000 times): 5e-6 s per nonzero
    read; the recurrence 6e-9 s per (nonzero of K + n) and degree (long-double products),
    at least 9e-6 s per degree (the step's overhead, which dominates below ~500 masses);
    per time 4e-8·N·log N (nodes, DCT) + 2e-9·n·N (the product) + 1e-9·n·N for the bound;
    a third more per derivative order. Memory: the vectors, 8·n·(N + 1) bytes per column.

    >>> chain = Scene.from_matrices(M=[[1, 0], [0, 1]], C=[[1, 0], [0, 1]],
    ...                             K=[[2, -1], [-1, 2]], x0=[1, 0], v0=[0, 0])
    >>> 0 < chebyshev_cost(chain, t_max=10.0, count=100, order=0) < 1
    True
    """
    interval = chebyshev_interval(scene)
    coefficients = rayleigh_coefficients(scene)
    if interval is None or coefficients is None:
        return math.inf
    lo, hi = interval
    a, b = (float(c) for c in coefficients)
    N = chebyshev_degree(lo, hi, a, b, t_max, order)
    n = scene.n
    nnz = sum(len(rational_entries(scene, name) or {}) for name in ("M", "C", "K"))
    columns = 2 if any(v != 0 for v in scene.v0) else 1
    read = 5e-6 * nnz
    # a step costs at least its Python and sparse-call overhead, about 9 µs (6 masses at
    # t = 1e5: N = 412,432 in 3.6 s, where the per-entry model alone said 0.1 s)
    recurrence = max(6e-9 * (nnz + n) * columns, 9e-6) * N
    per_time = (4e-8 * N * math.log2(N + 2) + 3e-9 * n * N * columns) * (1 + order / 3)
    return read + recurrence + count * per_time


class ChebyshevMotion:
    """x(t) of a Rayleigh-damped scene with a diagonal M by Chebyshev expansion in M⁻¹K
    (see the module notes). Built by :func:`chebyshev_motion`.

    ``values`` and ``bound`` follow :class:`~laplace_springs.numeric.classical.ClassicalMotion`;
    ``poles`` computes the eigenvalues only (banded K); ``modes`` and ``modal_form`` build the
    eigen route's shapes on request (up to :attr:`~laplace_springs.limits.Limits.classical_max_coordinates` coordinates).
    """

    def __init__(self, data: SymmetricScene, a: Any, b: Any, *, exact_data: bool = False) -> None:
        if not data.diagonal or not np.all(data.mass > 0):
            raise SceneError("the Chebyshev route needs a diagonal, positive mass matrix")
        self.data = data
        self.a, self.b = float(a), float(b)
        (self._a_work, a_err), (self._b_work, b_err) = _work_number(a), _work_number(b)
        self._ab_error = max(a_err, b_err)  # relative
        #: whether the float64 M and K are the scene's exact entries (else each is off by
        #: up to u relatively, and the operator with them)
        self.exact_data = exact_data
        self._last: tuple[Any, tuple[np.ndarray, np.ndarray]] | None = None
        self._vectors: tuple[int, np.ndarray, np.ndarray, np.ndarray] | None = None

    @property
    def n(self) -> int:
        return self.data.n

    # -- the operator ------------------------------------------------------------------
    @cached_property
    def _operator(self) -> dict[str, Any]:
        d = self.data
        K = d.K.tocsr()
        m = d.mass
        lo, hi, width, _ = verified_interval(d, exact=self.exact_data)
        absK = abs(K)
        root = np.sqrt(m)
        rad = max((hi - lo) / 2 * (1 + 4 * _EPS), 1e-12 * max(abs(lo), abs(hi), 1e-300))
        mid = lo + rad
        while mid - rad > lo or mid + rad < hi:  # rounding: widen a few ulps at a time
            rad += 4 * _EPS * max(abs(mid), rad)
        P = (K.multiply((2 / rad) / m[:, None])).tocsr()
        s = 2 * mid / rad
        alpha = (2 / rad) * float(np.max(np.asarray(absK @ (1 / root)).ravel() / root,
                                         initial=0.0)) * (1 + 16 * _EPS * (width + 2))
        gamma = 1.01 * (width + 10) * _U
        # the working-precision operator 2B = P − s: each entry K_ij·(2/rad)/m_i within 3
        # roundings of the working precision of the one from the float64 data
        two_over = _WORK(2) / _WORK(rad)
        P_work = K.astype(_WORK).multiply((two_over / m.astype(_WORK))[:, None]).tocsr()
        s_work = _WORK(2) * _WORK(mid) / _WORK(rad)
        return {"P": P, "s": s, "mid": mid, "rad": rad, "lo": mid - rad, "alpha": alpha,
                "gamma": gamma, "root": root, "P_work": P_work, "s_work": s_work,
                "absP": abs(P) * (1 + 8 * _EPS), "row_nnz": np.diff(K.indptr)}

    @cached_property
    def _ellipses(self) -> _Ellipses:
        op = self._operator
        return _Ellipses(op["mid"], op["rad"], self.a, self.b)

    @cached_property
    def _norms(self) -> tuple[float, float]:
        root = self._operator["root"]
        grow = 1 + (self.n + 4) * _EPS
        return (float(np.linalg.norm(root * self.data.x0)) * grow,
                float(np.linalg.norm(root * self.data.v0)) * grow)

    # -- spectrum-derived quantities ------------------------------------------------------
    def _pole_size(self, theta: np.ndarray) -> np.ndarray:
        c = self.a * theta + self.b
        h = c / 2
        delta = h * h - theta
        g = np.sqrt(np.abs(delta))
        return np.where(delta > 0, h + g, np.sqrt(np.maximum(theta, 0.0)))

    @cached_property
    def spectral_radius(self) -> float:
        """The largest |pole| (the contract's ρ), for stiffnesses from the Gershgorin lower
        bound of M⁻¹K to its largest eigenvalue estimated by 40 Lanczos steps (no eigenvalues
        are computed; the largest Ritz value is a lower bound, usually to 3 digits or more).
        """
        op = self._operator
        grid = np.linspace(max(op["lo"], 0.0), max(self._largest_stiffness, op["lo"], 0.0), 513)
        return float(np.max(self._pole_size(grid), initial=0.0))

    @cached_property
    def _largest_stiffness(self) -> float:
        """The largest Ritz value of M^{-1/2} K M^{-1/2} after up to 40 Lanczos steps."""
        d = self.data
        scale = 1 / np.sqrt(d.mass)
        rng = np.random.default_rng(14)
        q = rng.standard_normal(d.n)
        q /= np.linalg.norm(q)
        previous = np.zeros(d.n)
        alphas: list[float] = []
        betas: list[float] = []
        beta = 0.0
        for _ in range(min(40, d.n)):
            w = scale * (d.K @ (scale * q)) - beta * previous
            alpha = float(q @ w)
            w -= alpha * q
            alphas.append(alpha)
            beta = float(np.linalg.norm(w))
            if beta <= 1e-12 * max(abs(alpha), 1e-300):
                break
            betas.append(beta)
            previous, q = q, w / beta
        off = np.array(betas[: len(alphas) - 1])
        return float(_scipy().linalg.eigvalsh_tridiagonal(np.array(alphas), off)[-1])

    @cached_property
    def _eigenvalues(self) -> np.ndarray:
        la = _scipy().linalg
        d = self.data
        scale = 1 / np.sqrt(d.mass)
        A = d.K.multiply(scale[:, None]).multiply(scale[None, :]).tocsr()
        if d.bandwidth == 0:
            return np.sort(A.diagonal())
        if d.bandwidth == 1:
            return la.eigvalsh_tridiagonal(A.diagonal(), A.diagonal(1))
        if d.bandwidth <= limits().banded_max_bandwidth:
            bands = np.zeros((d.bandwidth + 1, d.n))
            for k in range(d.bandwidth + 1):
                bands[k, : d.n - k] = A.diagonal(-k)
            return la.eig_banded(bands, lower=True, eigvals_only=True)
        if d.n > limits().dense_eigenvalues_max_coordinates:
            raise SceneError(f"the poles of this scene need the eigenvalues of a dense {d.n:,} x "
                             f"{d.n:,} matrix (K has half-bandwidth {d.bandwidth}), more than "
                             f"{limits().dense_eigenvalues_max_coordinates:,} coordinates")
        return la.eigvalsh(A.toarray())

    def poles(self) -> np.ndarray:
        """λ = −h ± i√δ (underdamped), −s and −f (overdamped), for every mode."""
        theta = self._eigenvalues
        return mode_poles(theta, self.a * theta + self.b)

    @cached_property
    def _shapes(self) -> ClassicalMotion:
        if self.n > limits().classical_max_coordinates:
            raise SceneError(f"this scene's motion comes from a Chebyshev expansion without mode "
                             f"shapes; its {self.n:,} coordinates are more than "
                             f"Limits.classical_max_coordinates = {limits().classical_max_coordinates:,} for the n x n "
                             "shapes (use evaluate() for values)")
        return ClassicalMotion(self.data)

    @property
    def modes(self) -> Any:
        """(θ, c, Φ) from the eigen route (built on request)."""
        return self._shapes.modes

    @property
    def has_zero_frequency(self) -> bool:
        return False  # a zero stiffness is harmless here: F = 1, G = t (undamped)

    def modal_form(self) -> ModalForm:
        return self._shapes.modal_form()

    def closed_form(self) -> Any:
        return self._shapes.closed_form()

    # -- the Chebyshev vectors -------------------------------------------------------------
    def _recurrence(self, N: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """T_k(B)[x0 v0] for k ≤ N, run in the working precision and kept in float64
        (columns x n x (N+1)), the largest |entry| of each (columns x (N+1)) and the bounds
        D_j on the M-norm of the rounding committed by step j (columns x (N+1), D_N = 0)."""
        if self._vectors is not None and self._vectors[0] >= N:
            _, V, vinf, errors = self._vectors
            return V[:, :, : N + 1], vinf[:, : N + 1], errors[:, : N + 1]
        op = self._operator
        P, s = op["P_work"], op["s_work"]
        starts = [self.data.x0] + ([self.data.v0] if np.any(self.data.v0) else [])
        cols = len(starts)
        V = np.empty((cols, self.n, N + 1))
        previous = np.stack(starts, axis=1).astype(_WORK)
        V[:, :, 0] = previous.T
        if N >= 1:
            current = 0.5 * (P @ previous - s * previous)
            V[:, :, 1] = current.T
            for k in range(1, N):
                following = P @ current
                following -= s * current
                following -= previous
                previous, current = current, following
                V[:, :, k + 1] = current.T
        errors = self._recurrence_errors(V)
        vinf = np.max(np.abs(V), axis=1) if self.n else np.zeros((cols, N + 1))
        if V.size <= _KEEP:
            self._vectors = (N, V, vinf, errors)
        return V, vinf, errors

    def _recurrence_errors(self, V: np.ndarray) -> np.ndarray:
        """D_j ≥ ‖δ_j‖_M for the working-precision vectors v_k (their float64 roundings V
        within a relative u): step j, v_{j+1} = (P − s)v_j − v_{j−1}, commits
        per entry, with y = fl(P v_j) (γ_w|P||v_j|, w the nonzeros of the row),
        fl(fl(y − fl(s v_j)) − v_{j−1}) and P, s within 3 and 2 roundings,

            |δ_j| ≤ γ_{w+5}|P||v_j| + γ_5|s||v_j| + γ_1|v_{j−1}|

        (γ of the working precision), plus 2.01u|P||v_j| when the float64 M and K are not
        exact. It reaches v_k as U_{k−1−j}(B)δ_j (see :meth:`_chunk` for the sum over k)."""
        op = self._operator
        cols, n, width = V.shape
        mass = self.data.mass
        # ‖g∘(|P||v_j|)‖_M + 5.05u|s|‖v_j‖_M + 1.01u‖v_{j−1}‖_M (the triangle inequality),
        # 64 vectors at a time
        g = 1.01 * _UW * (op["row_nnz"] + 5)
        if not self.exact_data:
            g = g * (1 + 2.01 * _U / (1.01 * _UW * 6))
        scaled = np.empty((width, cols))
        for column in range(cols):
            for start in range(0, width, 64):
                A = np.asarray(op["absP"] @ np.abs(V[column, :, start:start + 64]))
                A *= g[:, None]
                scaled[start:start + 64, column] = np.sqrt(np.einsum("i,ik,ik->k", mass, A, A))
        norms = np.sqrt(np.einsum("i,cik,cik->kc", mass, V, V))
        delta = scaled + (5.05 * _UW * abs(float(op["s_work"]))) * norms
        delta[1:] += 1.01 * _UW * norms[:-1]
        # float64 evaluation of the bound, and |v_j| ≤ (1 + u)|V_j|
        inflate = (1 + 4 * (int(np.max(op["row_nnz"], initial=0)) + 8) * _EPS) * (1 + (n + 4) * _EPS)
        delta *= inflate
        if not self.exact_data:  # the M-norm of the exact masses
            delta *= 1 + 2 * _U
        delta[-1] = 0.0  # no step from the last vector
        return delta.T

    # -- values and bounds ----------------------------------------------------------------
    def _degrees(self, t: np.ndarray, order: int) -> np.ndarray:
        """The degree for each time, from that time alone (so that a value does not depend
        on the other times of a call), rounded up to a multiple of 16 (fewer groups)."""
        ell = self._ellipses
        log_tol = math.log(_U / 64)
        kinds = ["F"] + (["G"] if np.any(self.data.v0) else [])
        need = np.max([ell.degrees(kind, order, t, log_tol) for kind in kinds], axis=0)
        return (16 * np.ceil(np.maximum(need, 1) / 16)).astype(np.int64)

    def _nodes(self, N: int) -> tuple[np.ndarray, np.ndarray]:
        """The Chebyshev points λ_j = lo + 2 rad cos²(jπ/2N), lo = mid − rad, in the working
        precision and bounds on their errors (the argument within 3 roundings of π/2, cos
        within one, lo within one)."""
        op = self._operator
        pi = 4 * np.arctan(_WORK(1))
        cos = np.cos(np.arange(N + 1).astype(_WORK) * (pi / _WORK(2 * N)))
        # lo from the operator's own centre in the working precision: the float64 mid − rad
        # is off by up to u·|lo|, which on a narrow interval (one mass: rad = 1e-12·|mid|)
        # moves every node by 1e-4 of rad against the B = (M⁻¹K − mid)/rad of the recurrence
        lo = _WORK(op["mid"]) - _WORK(op["rad"])
        lam = lo + _WORK(2 * op["rad"]) * (cos * cos)
        c = np.abs(cos).astype(float)
        error = 1.01 * _UW * (2 * op["rad"] * (10 * c + 5 * c * c)
                              + 2 * (np.abs(lam).astype(float) + abs(op["lo"])))
        return lam, error

    def _scalar_parts(self, lam: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, ...]:
        """e^{−ht}C(t), e^{−ht}S(t) at the nodes and times (float64), their envelopes, h, the
        phase speed |√δ| + h and the rate of the exponentials (h, or h + g overdamped), with
        c(λ), h, δ and the phases (in turns, reduced modulo 1) in the working precision, the
        exponents, cos, sin and exp in float64 (an exponent's rounding is u per unit of it;
        see :func:`~laplace_springs.numeric.classical._scalar_parts` for the forms)."""
        c = self._a_work * lam + self._b_work
        h = c / 2
        omega = np.sqrt(np.maximum(lam, 0))
        delta = np.where(lam >= 0, (omega - h) * (omega + h), lam - h * h)
        under = delta > 0
        root = np.sqrt(np.abs(delta))
        tw = t.astype(_WORK)[None, :]
        tt = t[None, :]
        two_pi = 8 * np.arctan(_WORK(1))
        shape = (len(lam), len(t))
        Cf, Sf, envC, envS = (np.empty(shape) for _ in range(4))
        speed = (root + np.abs(h)).astype(float)
        rate = np.empty(len(lam))
        with np.errstate(over="ignore", invalid="ignore", divide="ignore", under="ignore"):
            if under.any():
                d = root[under][:, None]
                turns = (d / two_pi) * tw
                turns -= np.rint(turns)
                reduced = turns.astype(float) * (2 * math.pi)
                decay = np.exp(-h[under][:, None].astype(float) * tt)
                d64 = d.astype(float)
                Cf[under] = decay * np.cos(reduced)
                Sf[under] = decay * np.sin(reduced) / d64
                envC[under] = decay
                envS[under] = decay * np.minimum(t[None, :], 1 / d64)
                rate[under] = np.abs(h[under]).astype(float)
            over = ~under
            if over.any():
                g = root[over][:, None]
                hh = h[over][:, None]
                slow = np.where(hh + g > 0, lam[over][:, None] / (hh + g), 0)
                P = np.exp(-slow.astype(float) * tt)
                Q = np.exp(-(hh + g).astype(float) * tt)
                g64 = g.astype(float)
                factor = np.where(g64 > 0, -np.expm1(-2 * g64 * tt)
                                  / (2 * np.where(g64 > 0, g64, 1.0)), t[None, :])
                Cf[over] = (P + Q) / 2
                Sf[over] = P * factor
                envC[over] = Cf[over]
                envS[over] = Sf[over]
                rate[over] = np.abs(hh + g)[:, 0].astype(float)
        return Cf, Sf, envC, envS, h, c, speed, rate

    def _functions(self, lam: np.ndarray, dlam: np.ndarray, t: np.ndarray,
                   order: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """F_t^(order), G_t^(order) at the nodes (nodes x times, float64) and bounds on their
        errors: the rounding of the working-precision phases and exponents (rates times t
        in units of its roundoff), of their float64 cos, sin, exp (a few u, and u per unit of
        exponent), of the nodes and of c(λ) (through ∂F/∂λ, ∂F/∂c)."""
        Cf, Sf, envC, envS, h_work, c_work, speed, rate = self._scalar_parts(lam, t)
        a = float(self._a_work)
        lam64, h, c = lam.astype(float), h_work.astype(float), c_work.astype(float)
        tt = t[None, :]
        alam = np.abs(lam64)[:, None]
        ac = np.abs(c)[:, None]
        beta = np.sqrt(np.maximum(-lam64, 0.0))
        mu0 = _mu(beta, c)[:, None]
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            E = np.exp(mu0 * tt) * (1 + 4 * _U)
            m = np.minimum(tt, 1 / np.sqrt(alam))
            bG = E * m                                          # |G| (|F| ≤ E)
            F = Cf + h[:, None] * Sf
            G = Sf
            rel = (16 + 10 * speed[:, None] * tt) * _UW + (24 + 2 * rate[:, None] * tt) * _U
            dc = ((3 * _UW + self._ab_error) * (a * alam + float(self._b_work))
                  * (1 + 4 * _U))                               # rounding of c(λ)
            dl = dlam[:, None]
            dF = E * tt * m * (1 + a * np.sqrt(alam))           # ∂F/∂λ (total, through c)
            dG = E * tt * m * (m + a)
            eF = rel * (envC + np.abs(h)[:, None] * envS) + dl * dF + dc * tt * E
            eG = rel * envS + dl * dG + dc * tt * m * E
            lamc, cc = lam64[:, None], c[:, None]
            # derivatives: F' = −λG, G' = F − cG, then q'' = −c q' − λ q (λ, c rounded to
            # float64: u each, in the 4u terms)
            vals = {"F": [F], "G": [G]}
            errs = {"F": [eF], "G": [eG]}
            if order >= 1:
                vals["F"].append(-lamc * G)
                errs["F"].append(alam * eG + dl * bG + 3 * _U * np.abs(vals["F"][1]))
                vals["G"].append(F - cc * G)
                errs["G"].append(eF + ac * eG + (dc + a * dl) * bG
                                 + 4 * _U * (np.abs(F) + np.abs(cc * G)))
            for k in range(2, order + 1):
                for key in ("F", "G"):
                    v, e = vals[key], errs[key]
                    v.append(-cc * v[k - 1] - lamc * v[k - 2])
                    e.append(ac * e[k - 1] + alam * e[k - 2] + (dc + a * dl) * np.abs(v[k - 1])
                             + dl * np.abs(v[k - 2]) + 4 * _U * (np.abs(cc * v[k - 1])
                                                               + np.abs(lamc * v[k - 2])))
        return vals["F"][order], vals["G"][order], errs["F"][order], errs["G"][order]

    def _compute(self, t: np.ndarray, order: int) -> tuple[np.ndarray, np.ndarray]:
        key = (t.tobytes(), order)
        if self._last is not None and self._last[0] == key:
            return self._last[1]
        n = self.n
        values = np.zeros((n, len(t)))
        errors = np.zeros(len(t))       # in the M-norm
        uniform = np.zeros(len(t))      # the same for every entry
        served = np.ones(len(t), dtype=bool)
        if len(t):
            degrees = self._degrees(t, order)
            columns = 2 if np.any(self.data.v0) else 1
            # a time whose vectors would not fit is not served (an infinite bound: the
            # planner's next engine takes it; chebyshev_refusal declines such requests)
            served = (degrees + 1) * self.n * columns <= limits().chebyshev_max_vector_floats
            top = int(np.max(degrees[served], initial=0))
            V, vinf, vec_err = self._recurrence(top)
            for N in (int(value) for value in np.unique(degrees[served])):
                lam, dlam = self._nodes(N)
                where = np.flatnonzero((degrees == N) & served)
                chunk = max(1, _CHUNK // (N + 1))
                for start in range(0, len(where), chunk):
                    part = where[start:start + chunk]
                    v, e, w = self._chunk(t[part], order, N, V[:, :, : N + 1], vinf[:, : N + 1],
                                          vec_err[:, : N + 1], lam, dlam)
                    values[:, part] = v
                    errors[part] = e
                    uniform[part] = w
        bounds = np.outer(1 / self._operator["root"], errors * (1 + 8 * _EPS))
        bounds += uniform * (1 + 8 * _EPS)
        bounds[:, ~served] = np.inf
        self._last = (key, (values, bounds))
        return values, bounds

    def _chunk(self, t: np.ndarray, order: int, N: int, V: np.ndarray, vinf: np.ndarray,
               vec_err: np.ndarray, lam: np.ndarray,
               dlam: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Values at the times, the M-norm part of their error bound and the part that is
        the same for every entry (the float64 product Σ_k c_k V_k)."""
        fft = _scipy().fft
        F, G, eF, eG = self._functions(lam, dlam, t, order)
        lebesgue = 2 / math.pi * math.log(N + 1) + 1
        dct_factor = math.sqrt(N + 1) * 16 * (math.log2(2 * N) + 2) * _UW
        ell = self._ellipses
        values = np.zeros((self.n, len(t)))
        total = np.zeros(len(t))
        products = np.zeros(len(t))     # Σ_k |c_k| max_i |V_ik|
        block = -(-(N + 1) // _PRODUCT_BLOCKS)   # ⌈(N + 1)/blocks⌉ terms per block
        blocks = 0
        for column, (f, ef, kind, norm) in enumerate(((F, eF, "F", self._norms[0]),
                                                      (G, eG, "G", self._norms[1]))):
            if column >= V.shape[0]:
                break
            coef_work = fft.dct(f.astype(_WORK), type=1, axis=0) / N
            coef_work[0] /= 2
            coef_work[-1] /= 2
            coef = coef_work.astype(float)
            for start in range(0, N + 1, block):  # error γ_block + γ_blocks
                values += columns_product(V[column][:, start:start + block],
                                          coef[start:start + block])
                blocks += 1
            acoef = np.abs(coef)
            with np.errstate(over="ignore", invalid="ignore"):
                trunc = ell.truncation(kind, order, t, N)
                nodal = lebesgue * np.max(ef, axis=0)
                dct = dct_factor * np.sqrt(np.sum(acoef * acoef, axis=0))
                size = np.max(np.abs(f), axis=0) + trunc + nodal + dct  # ≥ max |p̂_N|
                total += (trunc + nodal + dct + 2 * _U * size) * norm
                total += rows_product(_tails(coef, acoef)[1:].T, vec_err[column][:-1, None])[:, 0]
                products += rows_product(acoef.T, vinf[column][:, None])[:, 0]
        # the product in blocks (γ_block + γ_blocks), the rounding of the coefficients and of
        # the vectors to float64 (u each), relative to Σ_k |c_k||V_ik|
        factor = 1.01 * (block + blocks + 2) * _U
        uniform = factor * products * (1 + 1e-9)
        return (values, np.where(np.isfinite(total), total, np.inf),
                np.where(np.isfinite(uniform), uniform, np.inf))

    def values(self, times: np.ndarray, order: int = 0) -> np.ndarray:
        """d^order x/dt^order at the times, float64, shape (n, len(times))."""
        return self._compute(np.asarray(times, dtype=float), order)[0]

    def bound(self, times: np.ndarray, order: int = 0) -> np.ndarray:
        """A bound on the error of :meth:`values` for every entry."""
        return self._compute(np.asarray(times, dtype=float), order)[1].copy()


def chebyshev_motion(scene: Scene) -> ChebyshevMotion:
    """The motion of a Rayleigh-damped scene (:func:`rayleigh_coefficients`) with a diagonal M.

    Examples
    --------
    x'' + x' + x = 0 with x(0) = 1 (C = M: a = 0, b = 1):

    >>> motion = chebyshev_motion(Scene.from_matrices(M=[[1]], C=[[1]], K=[[1]], x0=[1], v0=[0]))
    >>> round(float(motion.values(np.array([1.0]))[0, 0]), 12)   # e^{-1/2}(cos w + sin w/(2w)), w = √3/2
    0.659700153392
    """
    coefficients = rayleigh_coefficients(scene)
    if coefficients is None:
        raise SceneError("the Chebyshev route needs Rayleigh damping C = aK + bM (a, b ≥ 0) "
                         "and a diagonal, positive M")
    return ChebyshevMotion(symmetric_scene(scene, damping=coefficients), *coefficients,
                           exact_data=_exact_data(scene))


def _exact_data(scene: Scene) -> bool:
    """Whether M's and K's entries are exactly float64 numbers."""
    return all((value.q == 1 and -_TWO53 < value.p < _TWO53) or _is_double(value)
               for name in ("M", "K")
               for value in (rational_entries(scene, name) or {}).values())


_TWO53 = 2**53


def _is_double(value: Any) -> bool:
    """Whether a rational (flint fmpq) is exactly a float64 (dyadic, 53 bits, in range)."""
    p, q = int(value.p), int(value.q)
    return q & (q - 1) == 0 and abs(p) < 2**53 and q < 2**1000

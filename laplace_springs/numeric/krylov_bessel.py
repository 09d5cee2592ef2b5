"""Long steps of the krylov engine by the Chebyshev (Bessel) expansion of exp(tA), bounded
through the motion's defect (the ``krylov`` engine's path for scenes held by the ground).

With a shift δ ≥ 0 and a scale ν_c (Y = (A + δI)/ν_c), exp(σA) = e^{−δσ}·exp(ν_cσY) and

    exp(xY) = J_0(x) + 2 Σ_{k≥1} J_k(x) Ť_k(Y),   Ť_0 = I, Ť_1 = Y, Ť_{k+1} = 2YŤ_k + Ť_{k−1}

(the Chebyshev series of e^{ixw} at w = −iy). A step of length H from the state ẑ forms
t_k ≈ Ť_k(Y)ẑ, k = 0..K, one sparse product each (t_{k+1} = [I | S]·[t_{k−1}; t_k] with
S = 2Y; the first is S·ẑ/2), in double-double while a term's rounding matters (the exact
split of :mod:`.krylov_data`) and in float64 after; the values inside the step and the
next state are p(σ) = Σ_k c_k(σ) t_k with c_k(σ) = ε_k e^{−δσ} J_k(ν_cσ) (ε_0 = 1, else 2).
About one product per unit of t·ν_c in long steps, against seven for Taylor's at θ = 5.

*The bound: the defect.* Let f_{k+1} = t_{k+1} − 2Yt_k − t_{k−1} (f_1 = t_1 − Yt_0) be
what the computed terms miss of the recurrence (exact Y). With g_k = e^{−δσ}J_k(ν_cσ) and
the identities J_0' = −J_1, 2J_k' = J_{k−1} − J_{k+1}, the function p(σ) (exact
coefficients, computed terms) obeys p(0) = ẑ and

    p' − Ap = ν_c[g_0 f_1 + Σ_{k=1}^{K−1} g_k f_{k+1} − g_{K+1} t_K − g_K (2Yt_K + t_{K−1})],

so, the motion never increasing the energy seminorm N (:mod:`.krylov`), N(p(s) −
exp(sA)ẑ) ≤ ∫_0^s N(p' − Ap) ≤ Σ_k w_k N(f_{k+1}) + w_{K+1} N(t_K) + w_K(2‖Y‖N(t_K) +
N(t_{K−1})), w_k ≥ ∫_0^X |J_k(x)| dx, X = ν_cH: the smaller of X·κ_k, κ_k ≥
max_{x ≤ X}|J_k(x)| (Kapteyn's |J_k(kz)| ≤ (z e^{√(1−z²)}/(1 + √(1−z²)))^k for X < k),
and Landau's ∫_0^X min(1, 0.7858·x^(−1/3)) dx ≈ 1.18·X^(2/3). No bound on the growth of Ť_k(Y)
is needed: the computed terms' own norms enter. The values add the rounding of their
coefficients (the trapezoidal rule J_k(x) = (1/N)Σ_j e^{i(x sin θ_j − kθ_j)}, an FFT in
the x87 long double, aliased by J_{N−k}) and of their float64 sum; the next state uses
coefficients from python-flint's arb (double-doubles) and an exactly split sum.

Used when the scene is held by the ground (compliance √R finite, so |x_i| ≤ √R·N) and
its damping is light against ν: the terms grow like Ť_k off the segment [−i, i], about
(1 + d/ν_c)^k at worst (d ≥ ‖M^{-1/2}CM^{-1/2}‖; δ = Limits.krylov_bessel_shift·d/2,
0 by default: most modes of a lightly damped network sit near the imaginary axis), so a
step is kept to d·H ≤ Limits.krylov_bessel_growth and the path is left to Taylor's steps
where that makes X = ν_c·H < Limits.krylov_bessel_min_norm.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass
from fractions import Fraction
from functools import lru_cache
from typing import Any

import numpy as np
from flint import arb, fmpq

from ..kernels.batch import columns_product
from ..kernels.dd import U, two_sum
from ..kernels.precision import flint_workprec
from ..limits import limits
from ..model.errors import FloatRangeError, SceneError
from ..model.scene import Scene
from .krylov_data import (
    _MARGIN,
    _RANGE,
    StepMatrix,
    _compliance,
    _energy,
    _pattern,
    _quotients,
    _step_matrix,
    _vector,
)
from .krylov_entries import entries_of, scene_refusal, spectral_bound
from .krylov_march import KrylovMotion
from .krylov_steps import _csr_into, _csr_kernel, split_product

__all__ = ["BesselData", "BesselMotion", "BesselStepper", "bessel_data", "kapteyn"]

_TINY = 1e-300
#: Unit roundoff of the long double the values' coefficients are formed in.
_UL = float(np.finfo(np.longdouble).eps) / 2
#: π in the long double (np.pi is float64's, off by 1.2e-16 of itself).
_PI = np.longdouble("3.14159265358979323846264338327950288")
#: Terms per block of the values' float64 sum.
_BLOCK = 16


def kapteyn(k: int, x: float) -> float:
    """≥ max_{0 ≤ y ≤ x} |J_k(y)| (1 up to k = x; Kapteyn's inequality beyond, which grows
    with y).

    >>> from scipy.special import jv
    >>> all(abs(jv(k, 30.0)) <= kapteyn(k, 30.0) for k in range(0, 80))
    True
    """
    if k <= x or k == 0:
        return 1.0
    z = x / k
    s = math.sqrt(1 - z * z)
    return min(1.0, math.exp(k * (math.log(z) + s - math.log1p(s))) * 1.001) if z > 0 else 0.0


def landau(X: float) -> float:
    """≥ ∫_0^X |J_k(x)| dx for every k ≥ 0: |J_k(x)| ≤ min(1, c·x^(−1/3)), c = 0.7858
    (Landau, J. London Math. Soc. 61, 2000).

    >>> from scipy.integrate import quad
    >>> from scipy.special import jv
    >>> all(quad(lambda x: abs(jv(k, x)), 0, 40, limit=400)[0] <= landau(40.0) for k in (0, 1, 5, 30))
    True
    """
    c = 0.7858
    knee = c**3
    if knee >= X:
        return X
    return (knee + 1.5 * c * (X ** (2 / 3) - knee ** (2 / 3))) * 1.001


def _weights(kappa: list[float], X: float) -> np.ndarray:
    """w_k ≥ ν_c∫_0^H e^{−δσ}|J_k(ν_cσ)|dσ = ∫_0^X e^{−δx/ν_c}|J_k(x)| dx."""
    return np.minimum(landau(X), X * np.array(kappa))


def _short(value: float) -> float:
    """The largest float ≤ value with a 5-bit mantissa."""
    e = math.floor(math.log2(value))
    step = 2.0 ** (e - 4)
    return math.floor(value / step) * step


# ----------------------------------------------------------------------------- the data


@dataclass(frozen=True, eq=False)
class BesselData:
    """What the Bessel path holds for one scene (fields as :class:`.krylov_data.KrylovData`
    where they share a name).

    ``a`` (ν_c = 2/a) and ``c`` (δ = c/a) are floats with 5-bit mantissas; the terms and
    ``z0`` hold (unit·x, v), ``root_K`` ≥ √‖K‖/unit; X = ν_c·H;
    ``step`` is [I | S] (2n x 4n), S = 2Y exactly split; ``terms`` is K and ``extended``
    the number of double-double terms; ``coef`` the next state's coefficients c_k(H)
    (hi, lo) and ``coef_error`` a bound on each one's error; ``norm_Y`` ≥ ‖Y‖ in N."""

    n: int
    H: float
    X: float
    a: float
    c: float
    unit: float
    root_K: float
    step: StepMatrix
    terms: int
    extended: int
    coef: tuple[np.ndarray, np.ndarray]
    coef_error: np.ndarray
    kappa: np.ndarray
    weight: np.ndarray
    norm_Y: float
    matrix: Any
    nu: float
    norm_K: float
    m_min: float
    m_max: float
    energy: float
    compliance: float
    row_K: np.ndarray
    row_C: np.ndarray
    width: int
    z0: tuple[np.ndarray, np.ndarray]


def damping_norm(scene: Scene) -> float:
    """≥ ‖M^{-1/2}CM^{-1/2}‖₂ (Gershgorin: the largest absolute row sum, rounded up)."""
    n = scene.n
    M, C = entries_of(scene, "M"), entries_of(scene, "C")
    assert M is not None and C is not None
    root = np.ones(n)
    root[M.rows] = np.sqrt(M.value)
    size = np.abs(C.value) / root[C.rows] / root[C.cols]
    return float(np.max(np.bincount(C.rows, size, minlength=n), initial=0.0)) * (1 + 8 * U) * _MARGIN


def bessel_data(scene: Scene) -> BesselData | None:
    """The Bessel path's data, or None where it does not apply (a part not held by the
    ground, damping heavy against ν)."""
    why = scene_refusal(scene)
    if why is not None:
        raise SceneError(f"the krylov route cannot take this scene: {why}")
    n = scene.n
    M, C, K = (entries_of(scene, name) for name in ("M", "C", "K"))
    assert M is not None and C is not None and K is not None
    nu = spectral_bound(scene)
    d = damping_norm(scene)
    if n == 0 or not (0 < nu < 1e100):
        return None
    compliance = _compliance(n, K)
    if not math.isfinite(compliance):
        return None
    m, m_num, m_den = np.ones(n), np.ones(n), np.ones(n)
    m[M.rows], m_num[M.rows], m_den[M.rows] = M.value, M.num, M.den
    if max(np.max(np.abs(K.value), initial=0.0), np.max(np.abs(C.value), initial=0.0),
           float(m.max(initial=1.0)), 1 / float(m.min(initial=1.0))) > _RANGE:
        raise FloatRangeError("M, C or K has an entry beyond what the krylov engine holds in "
                              "float64 (1e150)")
    a = _short(2 / nu)
    delta = limits().krylov_bessel_shift * d / 2
    c = _short(a * delta) if delta > 0 else 0.0
    if c < a * 2.0**-30:
        c = 0.0
    # X ≤ Limits.krylov_bessel_norm, and d·H ≤ Limits.krylov_bessel_growth: the terms
    # grow about like e^{d·H} (K ≈ 2X terms, each by 1 + d/(2ν_c) at most)
    X_max = min(limits().krylov_bessel_norm, 2 / a * limits().krylov_bessel_growth / d if d > 0 else math.inf)
    if X_max < limits().krylov_bessel_min_norm:
        return None
    H = _short(X_max * a / 2)
    X = float(Fraction(2) * Fraction(H) / Fraction(a))
    norm_K = float(np.max(np.bincount(K.rows, np.abs(K.value), minlength=n), initial=0.0)) * (1 + 4 * U) * _MARGIN
    # [I | S] on [t_{k−1}; t_k]: identity, then S's x rows (c, a) and v rows
    # (−a M⁻¹K | −a M⁻¹C + c I)
    idx = np.arange(n)
    k_hi, k_lo = _quotients(K, C, m_num, m_den, a, 1, M)
    nk = K.rows.size
    shift = [idx] if c > 0 else []
    rows = np.concatenate([np.arange(2 * n), *shift, idx, n + K.rows, n + C.rows,
                           *[n + idx for _ in shift]])
    cols = np.concatenate([np.arange(2 * n), *[2 * n + idx for _ in shift], 3 * n + idx,
                           2 * n + K.cols, 3 * n + C.cols, *[3 * n + idx for _ in shift]])
    # the terms hold (2^p·x, v), 2^p ≈ √(‖K‖/m_max): both parts weigh alike in N
    p = max(-200, min(200, round(math.log2(math.sqrt(norm_K / float(m.max()))))))
    unit = 2.0**p
    k_scaled = np.ldexp(k_hi[:nk], -p)
    small = np.abs(np.concatenate([k_scaled, k_hi[nk:]]))
    if np.any((small > 0) & (small < 1e-280)):
        return None
    hi = np.concatenate([np.ones(2 * n), *[np.full(n, c) for _ in shift], np.full(n, a * unit),
                         k_scaled, k_hi[nk:], *[np.full(n, c) for _ in shift]])
    lo = np.concatenate([np.zeros(2 * n), *[np.zeros(n) for _ in shift], np.zeros(n),
                         np.ldexp(k_lo[:nk], -p), k_lo[nk:], *[np.zeros(n) for _ in shift]])
    pattern = _pattern(2 * n, rows, cols, 4 * n)
    weight = np.concatenate([np.full(n, math.sqrt(norm_K) / unit), np.sqrt(m)]) * _MARGIN
    step = _step_matrix(2 * n, pattern, hi[pattern.order], lo[pattern.order], weight)
    # K and the double-double terms from Kapteyn's bound (module notes)
    norm_Y = (nu + c / a) * a / 2 * (1 + 4 * U) * _MARGIN
    kappa = [kapteyn(k, X) for k in range(int(3 * X) + 200)]
    terms = next(k for k in range(1, len(kappa) - 1)
                 if X * kappa[k] * (3 + 2 * norm_Y) <= 2.0**-62)
    extended = next(k for k in range(terms + 1) if X * kappa[k] <= 2.0**-12)
    extended = min(extended, terms)
    coef_hi, coef_lo, coef_error = _state_coefficients(H, a, c, terms)
    b_pattern = _pattern(n, np.concatenate([K.rows, C.rows]), np.concatenate([K.cols, C.cols + n]))
    b_hi = _quotients(K, C, m_num, m_den, H, 0, M)[0][b_pattern.order]
    size = np.abs(b_hi)
    x_cols = b_pattern.cols < n
    x0h, x0l = _vector(scene, "x0", n)
    v0h, v0l = _vector(scene, "v0", n)
    energy = _energy(n, K, M, x0h, v0h) + 2.0**-100 * (float(np.linalg.norm(x0h)) + float(np.linalg.norm(v0h)))
    zh, zl = np.concatenate([x0h, v0h]), np.concatenate([x0l, v0l])
    if not math.isfinite(energy) or np.max(np.abs(zh), initial=0.0) > _RANGE:
        raise FloatRangeError("the initial data are beyond what the krylov engine holds in float64")
    x_small = np.abs(np.ldexp(x0l[x0l != 0], p))
    if np.any(x_small < 1e-280) or np.any(np.abs(np.ldexp(x0h, p)) > 1e280):
        return None
    zh[:n], zl[:n] = np.ldexp(x0h, p), np.ldexp(x0l, p)
    return BesselData(
        n=n, H=H, X=X, a=a, c=c, unit=unit, root_K=math.sqrt(norm_K) / unit * (1 + 2 * U), step=step, terms=terms, extended=extended,
        coef=(coef_hi, coef_lo), coef_error=coef_error, kappa=np.array(kappa[:terms + 2]),
        weight=_weights(kappa[:terms + 2], X),
        norm_Y=norm_Y, matrix=b_pattern.csr(b_hi), nu=nu, norm_K=norm_K,
        m_min=float(m.min()) / _MARGIN, m_max=float(m.max()) * _MARGIN, energy=energy,
        compliance=compliance,
        row_K=np.bincount(b_pattern.rows, np.where(x_cols, size, 0.0), minlength=n) * (1 + 4 * U) * _MARGIN,
        row_C=np.bincount(b_pattern.rows, np.where(x_cols, 0.0, size), minlength=n) * (1 + 4 * U) * _MARGIN,
        width=int(b_pattern.counts.max(initial=1)) or 1, z0=(zh, zl))


@lru_cache(maxsize=64)
def _state_coefficients(H: float, a: float, c: float, terms: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """c_k(H) = ε_k e^{−δH} J_k(X), k = 0..K, as double-doubles with a bound on each
    one's error (arb balls: J_{K+2}, J_{K+1} by their power series, the rest by the
    backward recurrence J_{k−1} = (2k/X)J_k − J_{k+1}, stable downwards; the precision
    covers the series' cancellation, about e^X)."""
    with flint_workprec(192 + int(1.5 * float(Fraction(2) * Fraction(H) / Fraction(a)))):
        x = arb(fmpq(2) * _fmpq(H) / _fmpq(a))
        damp = (-arb(_fmpq(c) / _fmpq(a) * _fmpq(H))).exp()
        values = [arb(0)] * (terms + 3)
        values[terms + 2] = _bessel_series(x, terms + 2)
        values[terms + 1] = _bessel_series(x, terms + 1)
        for k in range(terms + 1, 0, -1):
            values[k - 1] = 2 * k / x * values[k] - values[k + 1]
        hi, lo, err = np.zeros(terms + 1), np.zeros(terms + 1), np.zeros(terms + 1)
        for k in range(terms + 1):
            value = values[k] * damp * (1 if k == 0 else 2)
            mid = arb(value.mid())
            hi[k] = float(mid)
            lo[k] = float(mid - hi[k])
            rest = abs(mid - hi[k] - lo[k]) + value.rad()
            err[k] = float(arb(rest).upper()) * 1.01 + 2.0**-1000
    return hi, lo, err


def _bessel_series(x: Any, k: int) -> Any:
    """J_k(x) in arb from Σ_m (−x²/4)^m (x/2)^k/(m!(m + k)!), the tail past the point
    where the ratio of terms is below 1/2 bounded by twice its first term.

    >>> with flint_workprec(128):
    ...     v = _bessel_series(arb(10), 3)
    >>> abs(float(v.mid()) - 0.05837937930518666) < 1e-15
    True
    """
    quarter = x * x / 4
    term = (x / 2) ** k / arb(k).gamma() / k if k > 0 else arb(1)
    total = arb(0)
    m = 0
    while True:
        total += term
        ratio = quarter / ((m + 1) * (m + k + 1))
        if ratio.upper() <= 0.5 and abs(term).upper() < total.rad() + 2.0**-600:
            tail = float(abs(term * ratio).upper()) * 2
            return total + arb(0, tail)
        term = -term * ratio
        m += 1


def _fmpq(value: float) -> Any:
    q = Fraction(value)
    return fmpq(q.numerator, q.denominator)


# ----------------------------------------------------------------------------- the steps


@dataclass
class BesselTerms:
    """One step's terms (rows 1..K+1 of ``hi``/``lo`` hold t_0..t_K; row 0 is zero) and
    their norms: ``energy`` ≥ N(t_k), ``sup_x``/``sup_v`` the max-norms of each part;
    ``local`` bounds ∫_0^H N(p' − Ap) (module notes; inf when only t_0..t_count were
    formed), ``rounding[k]`` ≥ N(f_k)."""

    hi: np.ndarray
    lo: np.ndarray
    energy: np.ndarray
    sup_x: np.ndarray
    sup_v: np.ndarray
    local: float
    rounding: np.ndarray
    count: int


class BesselStepper:
    """The arithmetic of the Bessel path's steps (see the module notes)."""

    def __init__(self, data: BesselData) -> None:
        self.data = data
        n, K = data.n, data.terms
        self.m = K
        self.hi = np.zeros((K + 2, 2 * n))
        self.lo = np.zeros((K + 2, 2 * n))
        self._rest = np.zeros(8 * n)
        self._lead = np.zeros(2 * n)
        self._low = np.zeros(2 * n)
        self._scratch = np.zeros(2 * n)
        self._sup = np.zeros(K + 2)
        self._norm = np.zeros(K + 2)
        self._parts = np.zeros((K + 2, 4))
        e = data.extended
        self._sum_lead = np.zeros((e + 1, 2 * n))
        self._sum_rest = np.zeros((e + 1, 2 * n))
        self._kernel = _csr_kernel()
        ch, cl = data.coef
        R = e + 1
        self.sum_bits = (53 - math.ceil(math.log2(R + 1))) // 2
        largest = float(np.max(np.abs(ch[:R])))
        _, exponent = math.frexp(largest)
        sigma = math.ldexp(1.5, exponent - self.sum_bits + 52)
        c1 = (ch + sigma) - sigma
        self.c1 = c1
        self.c2 = (ch - c1) + cl
        q = 2.0**-self.sum_bits
        L = 3 * R + (K + 1 - R) + 4
        self.gamma = gamma = L * U / (1 - L * U)
        s1, s_max = float(np.sum(np.abs(ch[:R]))), R * largest
        # per coordinate i, times colmax_i = max_{k ≤ e} |t_ki|: |T₂| ≤ q·colmax, |t_lo| ≤
        # u·colmax, |lead| ≤ (1 + q)·colmax, |c − c₁| ≤ q·max|c|: the rest's rounding, the
        # dropped c_lo·(T₂ + t_lo) and the rounding of (c − c₁) + c_lo
        self.sum_error = (gamma * ((q + U) * s1 + q * (1 + U) * (1 + q) * s_max)
                          + (q * U + U * U) * s1 + U * q * (1 + U) * (1 + q) * s_max) * (1 + 1e-9)

    # -- the terms ----------------------------------------------------------------------
    def terms(self, zh: np.ndarray, zl: np.ndarray, count: int | None = None) -> BesselTerms:
        """t_0..t_count (all K by default) from the state ẑ = zh + zl; each t_k is formed
        the same way whatever ``count``."""
        d = self.data
        e = d.extended
        K = d.terms if count is None else min(count, d.terms)
        hi, lo, sup, norm = self.hi, self.lo, self._sup, self._norm
        hi[0], lo[0] = 0.0, 0.0
        hi[1], lo[1] = zh, zl
        sup[0], norm[0] = 0.0, 0.0
        self._measure(1)
        rounding = np.zeros(K + 1)          # rounding[k] ≥ N(f_k)
        if K < 1:
            raise ValueError("a Bessel step needs t_0 and t_1 at least")
        for k in range(K):
            if k < e:
                bound = self._extended(k)
                if k == 0:                 # t_1 = S·t_0/2: halved exactly
                    hi[2] *= 0.5
                    lo[2] *= 0.5
                    bound *= 0.5
            else:
                _csr_into(d.step.hi, hi[k:k + 2].reshape(-1), hi[k + 2], self._kernel)
                if k == 0:
                    hi[2] *= 0.5
                bound = d.step.float_x * norm[k] + d.step.float_v * norm[k + 1]
                if k == 0:
                    bound *= 0.5
            self._measure(k + 2)
            rounding[k + 1] = bound
        parts = self._parts[1:K + 2]
        # N(t) ≤ √‖K‖·‖t_x‖ + √m_max·‖t_v‖ for t = hi + lo (|lo| ≤ u|hi|; sums within MARGIN)
        energy = (d.root_K * parts[:, 0] + math.sqrt(d.m_max) * parts[:, 1]) * (1 + 2 * U) * _MARGIN + _TINY
        local = math.inf
        if d.terms == K:
            w = d.weight
            local = (float(w[:K] @ rounding[1:K + 1])
                     + w[K + 1] * energy[K] + w[K] * (2 * d.norm_Y * energy[K] + energy[K - 1])) * _MARGIN
        return BesselTerms(hi, lo, energy, parts[:, 2].copy(), parts[:, 3].copy(), local,
                           rounding.copy(), K)

    def _measure(self, row: int) -> None:
        """The 2-norms and max-norms of row ``row``'s x and v parts, its 2-norm and sup."""
        n = self.data.n
        x, v = self.hi[row, :n], self.hi[row, n:]
        norm_x, norm_v = math.sqrt(float(x @ x)), math.sqrt(float(v @ v))
        sup_x = max(float(x.max(initial=0.0)), -float(x.min(initial=0.0)))
        sup_v = max(float(v.max(initial=0.0)), -float(v.min(initial=0.0)))
        self._parts[row] = (norm_x, norm_v, sup_x, sup_v)
        self._norm[row] = math.hypot(norm_x, norm_v)
        self._sup[row] = max(sup_x, sup_v)

    def _extended(self, k: int) -> float:
        """t_{k+1} = [I | S]·[t_{k−1}; t_k] to about 2^-70 into row k + 2; returns the
        bound on its rounding in N (the exact split of :mod:`.krylov_steps`)."""
        D = self.data.step
        m = 2 * self.data.n
        wh = self.hi[k:k + 2].reshape(-1)
        wl = self.lo[k:k + 2].reshape(-1)
        largest = max(self._sup[k], self._sup[k + 1])
        norm_w = math.hypot(self._norm[k], self._norm[k + 1])
        if largest == 0:
            self.hi[k + 2] = 0.0
            self.lo[k + 2] = 0.0
            return 0.0
        return split_product(D, wh, wl, largest, norm_w, (self.hi[k + 2], self.lo[k + 2]),
                             (self._rest, self._lead, self._low, self._scratch), self._kernel) \
            + _TINY * math.sqrt(m * self.data.m_max)

    # -- the next state ----------------------------------------------------------------
    def advance(self, terms: BesselTerms) -> tuple[np.ndarray, np.ndarray, float]:
        """Σ_k c_k(H) t_k as a double-double, and a bound in N on its error (the
        coefficients' and the sum's; the terms' own are in ``terms.local``).

        The double-double terms t_0..t_e are cut at a grid per coordinate (their largest
        entry's): the leading slices times c's leading slices sum exactly in one gemv, the
        rest (T₂·c, t_lo·c, lead·(c − c₁ + c_lo)) and the float64 terms' c_k·t_k in four
        more, whose rounding is γ_L of their sizes."""
        d = self.data
        K, e = d.terms, d.extended
        R = e + 1
        T = terms.hi[1:R + 1]
        colmax = np.maximum(T.max(axis=0), -T.min(axis=0))
        _, exponent = np.frexp(colmax)
        sigma = np.ldexp(1.5, exponent - self.sum_bits + 52)
        lead, rest_rows = self._sum_lead[:R], self._sum_rest[:R]
        np.add(T, sigma, out=lead)
        np.subtract(lead, sigma, out=lead)
        np.subtract(T, lead, out=rest_rows)
        exact = self.c1[:R] @ lead
        ch = d.coef[0]
        rest = ch[:R] @ rest_rows
        rest += ch[:R] @ terms.lo[1:R + 1]
        rest += self.c2[:R] @ lead
        if R <= K:
            rest += ch[R:] @ terms.hi[R + 1:K + 2]
        sh, sl = two_sum(exact, rest)
        n = d.n
        top = (d.root_K * math.sqrt(float(colmax[:n] @ colmax[:n]))
               + math.sqrt(d.m_max) * math.sqrt(float(colmax[n:] @ colmax[n:]))) * _MARGIN
        floats = float(np.abs(ch[R:]) @ terms.energy[R:]) if R <= K else 0.0
        error = (float(d.coef_error @ terms.energy) + self.sum_error * top
                 + (self.gamma + U) * floats * (1 + 2 * U))
        return sh, sl, error * _MARGIN + _TINY

    # -- values inside the step --------------------------------------------------------
    def cutoffs(self, s: np.ndarray) -> np.ndarray:
        """K(s): the terms a value at b + s uses (x = ν_c·s), the first k with
        x·κ_k(x)·(3 + 2‖Y‖) ≤ 2^-62, at least 2; a function of s alone."""
        d = self.data
        x = 2 * s / d.a * (1 + 1e-12)
        k = np.arange(d.terms + 1, dtype=float)[:, None]
        fit = (x[None, :] * _kapteyn_table(k, x) * (3 + 2 * d.norm_Y) <= 2.0**-62)
        fit[-1] = True
        return np.maximum(np.argmax(fit, axis=0), 2)

    def values(self, terms: BesselTerms, s: np.ndarray, order: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """x (order 0) or v (order 1) at b + s for each s in [0, H), shape (len(s), n), a
        bound per time on the error of the coefficients and of the float64 sum, and one in N
        on ∫_0^s N(p' − Ap) with the series cut after K(s) terms (module notes)."""
        d = self.data
        n, K = d.n, d.terms
        cut = self.cutoffs(s)
        top = int(cut.max(initial=2))
        if top > terms.count:
            raise ValueError("the step's terms stop before a time's cutoff")
        coef, coef_error = value_coefficients(s, d.a, d.c, d.X, K)
        coef = coef[:top + 1]
        coef[np.arange(top + 1)[:, None] > cut[None, :]] = 0.0
        part = terms.hi[1:top + 2, :n] if order == 0 else terms.hi[1:top + 2, n:]
        sup = (terms.sup_x if order == 0 else terms.sup_v)[:top + 1]
        total = np.zeros((n, s.size))
        for start in range(0, top + 1, _BLOCK):
            stop = min(start + _BLOCK, top + 1)
            total += columns_product(part[start:stop].T, coef[start:stop])
        count = -(-(cut + 1) // _BLOCK)
        L = np.minimum(_BLOCK, cut + 1) + count + 2
        gamma = L * U / (1 - L * U)
        # sums down the terms by cumsum: a time's bound is its own column's sequential sum
        rounding = gamma * np.cumsum(sup[:, None] * np.abs(coef), axis=0)[-1] \
            + coef_error * np.sqrt(np.cumsum(sup * sup)[cut])
        if order == 0:            # (unit·x) back to x: exact
            total *= 1 / d.unit
            rounding = rounding / d.unit
        # the defect up to s, cut after K(s) terms: weights from x = ν_c·s
        x = 2 * s / d.a * (1 + 1e-12)
        k = np.arange(top + 2, dtype=float)[:, None]
        weight = np.minimum(_landau_table(x)[None, :], x[None, :] * _kapteyn_table(k, x))
        rows = np.arange(top + 1)[:, None] < cut[None, :]          # f_{k+1}, k < K(s)
        made = min(top + 1, terms.count)
        rnd = np.zeros(top + 1)
        rnd[:made] = terms.rounding[1:made + 1]
        energy = terms.energy
        w_cut = weight[cut, np.arange(s.size)]
        w_next = weight[cut + 1, np.arange(s.size)]
        local = (np.cumsum(np.where(rows, weight[:top + 1] * rnd[:, None], 0.0), axis=0)[-1]
                 + w_next * energy[cut] + w_cut * (2 * d.norm_Y * energy[cut] + energy[cut - 1])) * _MARGIN
        return total.T, rounding * (1 + 1e-9) + _TINY, local


def _kapteyn_table(k: np.ndarray, x: np.ndarray) -> np.ndarray:
    """kapteyn(k, x) for arrays (k a column, x a row)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        z = np.where(k > 0, x[None, :] / np.maximum(k, 1), 0.0)
        root = np.sqrt(np.maximum(1 - z * z, 0.0))
        bound = np.exp(k * (np.log(z) + root - np.log1p(root))) * 1.001
    return np.where((k <= x[None, :]) | (k == 0), 1.0, np.minimum(np.nan_to_num(bound, nan=0.0), 1.0))


def _landau_table(x: np.ndarray) -> np.ndarray:
    """landau(x) for an array."""
    c = 0.7858
    knee = c**3
    return np.where(x <= knee, x, (knee + 1.5 * c * (np.maximum(x, knee) ** (2 / 3) - knee ** (2 / 3))) * 1.001)


def value_coefficients(s: np.ndarray, a: float, c: float, X: float, K: int) -> tuple[np.ndarray, np.ndarray]:
    """ĉ_k(s) = ε_k e^{−δs} J_k(ν_c s), k = 0..K, in float64 (shape (K + 1, len(s))), and a
    bound per time on ‖ĉ(s) − c(s)‖₂: J_k by the trapezoidal rule on N ≥ 2K + 4 points (an
    FFT in long double; aliasing ≤ 4·κ_{N−K}), the phases x·sin θ_j off by 3u_L·x."""
    N = 1 << max(6, math.ceil(math.log2(2 * K + 4)))
    q = N // 4
    j = np.arange(q + 1)
    theta = 2 * _PI * j.astype(np.longdouble) / N
    x = 2 * s.astype(np.longdouble) / np.longdouble(a)
    phase = x[:, None] * np.sin(theta)[None, :]
    cos, sin = np.cos(phase), np.sin(phase)
    # sin θ_j on the other three quarters by symmetry: the same numbers, signs flipped
    y = np.empty((s.size, N), dtype=np.clongdouble)
    for index, sign in ((j, 1), (N // 2 - j, 1), (N // 2 + j, -1), ((N - j) % N, -1)):
        y[:, index] = cos + 1j * (sign * sin)
    J = np.fft.fft(y, axis=1)[:, :K + 1].real / N
    damp = np.exp(-(np.longdouble(c) / np.longdouble(a)) * s.astype(np.longdouble))
    scaled = J * damp[:, None]
    scaled[:, 1:] *= 2
    coef = scaled.astype(float).T
    levels = math.log2(N)
    eta = 4 * _UL + 4 * _UL / (1 - 4 * _UL) * (math.sqrt(2) + 4 * _UL)
    fft = 2.5 * levels * eta / (1 - levels * eta)
    inputs = (10 * X + 8) * _UL
    alias = 4 * kapteyn(N - K - 1, X) * math.sqrt(K + 1)
    size = np.sqrt(np.cumsum(coef * coef, axis=0)[-1])
    error = 2 * (fft + inputs + alias) + (8 * _UL + U) * size
    return coef, error * 1.01


# ----------------------------------------------------------------------------- the motion


class BesselMotion(KrylovMotion):
    """x(t), x'(t), x''(t) from long Bessel steps (the march, checkpoints and the way the
    error is carried are :class:`.krylov_march.KrylovMotion`'s; X_j = √R·E_j here, the
    scene being held by the ground)."""

    data: BesselData  # type: ignore[assignment]
    stepper: BesselStepper  # type: ignore[assignment]

    def __init__(self, data: BesselData) -> None:
        self.data = data
        self.stepper = BesselStepper(data)
        self.H = data.H
        self.m = data.terms
        zh, zl = data.z0
        n = data.n
        start = 3 * U * U * (math.sqrt(data.m_max) * float(np.linalg.norm(zh[n:]))
                             + data.root_K * float(np.linalg.norm(zh[:n])))
        self._checkpoints = {0: (zh.copy(), zl.copy(), start, data.compliance * start)}
        self._keys = [0]
        self._stride = 1

    def _next(self, j: int, state: Any, terms: Any) -> Any:
        d = self.data
        _, _, E, _ = state
        zh, zl, sum_energy = self.stepper.advance(terms)
        energy = (E + terms.local + sum_energy) * (1 + 1e-12)
        following = (zh, zl, energy, d.compliance * energy * (1 + 1e-12))
        self._store(j + 1, following)
        return following

    def _bound(self, state: Any, terms: Any, s: np.ndarray, rounding: np.ndarray,
               order: int, local: Any = None) -> np.ndarray:
        """The bound of a value at b + s: the carried error and the defect up to s (in N,
        through √R for x and 1/√m_min for x'), and the value's own rounding."""
        d = self.data
        E = state[2] + (terms.local if local is None else local)
        if order == 0:
            carried = d.compliance * E
        else:
            carried = E / math.sqrt(d.m_min)
        return (carried + rounding) * (1 + 1e-12) + _TINY

    def _walk(self, steps: np.ndarray, last_count: int | None = None) -> Any:
        """Yield (j, state, terms) for each step j of ``steps`` (sorted); the last step's
        terms stop at ``last_count`` and the march does not go past it."""
        base = self._keys[bisect.bisect_right(self._keys, int(steps[0])) - 1]
        j, state = base, self._checkpoints[base]
        last = int(steps[-1])
        for wanted in steps:
            while j < wanted:
                state = self._next(j, state, self.stepper.terms(state[0], state[1]))
                j += 1
            count = last_count if wanted == last else None
            terms = self.stepper.terms(state[0], state[1], count)
            yield j, state, terms
            if wanted != last:
                state = self._next(j, state, terms)
                j += 1

    def _last_count(self, hi: np.ndarray, step: np.ndarray, last: int) -> int:
        s = hi[step == last] - last * self.H
        return int(self.stepper.cutoffs(s).max(initial=2))

    def _fill(self, hi: np.ndarray, step: np.ndarray, wanted: np.ndarray, order: int,
              values: np.ndarray, bounds: np.ndarray) -> None:
        last = self._last_count(hi, step, int(wanted[-1]))
        for j, state, terms in self._walk(wanted, last):
            columns = np.flatnonzero(step == j)
            s = hi[columns] - j * self.H          # exact (Sterbenz, or j = 0)
            found, rounding, local = self.stepper.values(terms, s, order)
            values[:, columns] = found.T
            bounds[:, columns] = self._bound(state, terms, s, rounding, order, local)[None, :]

    def _fill_acceleration(self, hi: np.ndarray, step: np.ndarray, wanted: np.ndarray,
                           values: np.ndarray, bounds: np.ndarray) -> None:
        d = self.data
        last = self._last_count(hi, step, int(wanted[-1]))
        for j, state, terms in self._walk(wanted, last):
            columns = np.flatnonzero(step == j)
            s = hi[columns] - j * self.H
            x, round_x, local = self.stepper.values(terms, s, 0)
            v, round_v, _ = self.stepper.values(terms, s, 1)
            bx = self._bound(state, terms, s, round_x, 0, local)
            bv = self._bound(state, terms, s, round_v, 1, local)
            states = np.concatenate([x, v], axis=1).T
            values[:, columns] = -(d.matrix @ states)
            size = abs(d.matrix) @ np.abs(states)
            gamma = (d.width + 3) * U / (1 - (d.width + 3) * U)
            bounds[:, columns] = ((d.row_K[:, None] * bx[None, :] + d.row_C[:, None] * bv[None, :])
                                  * (1 + 1e-12) + gamma * size + _TINY)

"""The krylov engine's data: a scene's sparse first-order system, exactly split for
error-free products, and the norms its error bound reads.

The state z = (x, v) obeys z' = A z with A z = (v, −B z), B = M⁻¹[K | C] (n x 2n). A step
of length H forms the terms U_k = H^k (A^k z)_v of its Taylor series from the two before,
U_k = D·[U_{k−2}; U_{k−1}] with D = [−H²M⁻¹K | −H M⁻¹C] (and D' = [−H M⁻¹K | −H M⁻¹C] on
[x; v] for the first): no vector is scaled, each term is one sparse product. Both
matrices are formed from the scene's exact rationals and held as

* ``hi``: the entries rounded to float64 (the products of the float64 terms);
* ``sliced`` and ``rest``: Ozaki's error-free split of ``hi``. Row r is cut at the grid
  2^(E_r − b) (2^E_r > its largest entry, b = ⌊(53 − ⌈log₂ w⌉)/2⌋ for rows of at most w
  entries): D₁ = fl(hi + σ_r) − σ_r holds the leading b bits, and the product of D₁ with a
  vector cut the same way at its own grid is exact in float64 whatever the order of the
  sums (products and partial sums are integers below 2^53 on the common grid). ``rest`` =
  [D₂ + D_lo | hi] takes the remainder, [w₁; w₂ + w_lo], in one float64 product whose
  rounding is about γ_2w·(‖D₂‖‖w₁‖ + ‖D‖‖w₂‖) with ‖D₂‖ ≈ 2^-b‖D‖ and ‖w₂‖ ≈ 2^-b‖w‖.
  Together they give D·w to about 2^-70 of ‖D‖‖w‖.

The numbers the bound reads (each an upper bound, rounded up by a relative margin that
covers float64 sums of non-negative terms): ν ≥ N(Az)/N(z) in the energy seminorm
N(z)² = vᵀMv + xᵀKx (Gershgorin in the mass-weighted norm), ‖K‖₂, the masses, N(z0), and
a compliance √R with |x_i| ≤ √R·√(xᵀKx) for every x: by Thomson's principle
e_iᵀK⁻¹e_i ≤ Σ_e f_e²/w_e for any unit flow f from i to the ground through the springs
(K = Σ_e w_e b_e b_eᵀ with b_e = e_i ± e_j per off-diagonal entry and e_i per diagonal
excess), so R_i is at most the shortest path, in lengths 1/|K_ij|, from i to a node held
by the ground (Dijkstra); a part of the scene not held by the ground has R = ∞.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np

from ..kernels.dd import U
from ..limits import limits
from ..model.errors import FloatRangeError, SceneError
from ..model.scene import Scene
from .krylov_entries import (
    MARGIN,
    RANGE,
    Entries,
    entries_of,
    exact_quotients,
    perron_bound,
    scene_refusal,
    spectral_bound,
)

__all__ = ["KrylovData", "StepMatrix", "krylov_data", "step_length"]

_MARGIN = MARGIN
#: Largest |entry| the engine holds: products of two such stay far from overflow.
_RANGE = RANGE
#: Significant bits of the step H.
_H_BITS = 5


# ----------------------------------------------------------------------------- matrices


@dataclass(frozen=True, eq=False)
class StepMatrix:
    """D = [−H^a M⁻¹K | −H M⁻¹C] (n x 2n) held for the two kinds of products (module notes).

    Attributes
    ----------
    hi : scipy.sparse.csr_matrix
        The entries rounded to float64 (rows sorted).
    sliced, rest : scipy.sparse.csr_matrix
        D₁ (n x 2n) and [D₂ + D_lo | hi] (n x 4n; the zero entries of D₂ + D_lo left out),
        D₂ = hi − D₁: with w = w₁ + w₂ + w_lo (w₁ the leading slices), D·w = D₁w₁ (exact)
        + [D₂ + D_lo | hi]·[w₁; w₂ + w_lo], up to D_lo·w₂ and the roundings of D₂ + D_lo and
        w₂ + w_lo (u each).
    bits : int
        b: D₁ holds b bits of each row, and so must the vector it multiplies.
    width : int
        The longest row of D.
    beta : float
        ≥ ‖diag(√m)·|hi|‖₂ (√(‖·‖₁‖·‖∞), rounded up).
    float_x, float_v : float
        ≥ ‖diag(√m·g)·|hi[:, :n]|·W‖₂ and the same of hi[:, n:], g_r = γ_{w_r} + 3u: the
        float64 product fl(hi·w_hi) is off from the exact D·(w_hi + w_lo) by at most
        g_r·(|hi||w_hi|)_r in row r (its rounding, hi's own and the dropped low part of a
        normalised double-double, |w_lo| ≤ u|w_hi|). W = diag(1/√m) for the Taylor
        matrices (so the norms multiply the vectors' mass-weighted norms ‖√m·w‖₂), the
        identity for the Bessel steps (Euclidean norms).
    rest_lead, rest_hi : float
        ≥ ‖diag(√m·g')·|D₂ + D_lo|‖₂ and ‖diag(√m·g')·|hi|‖₂, g'_r = (γ_{2w_r} + 2u)(1 + 2u):
        the rounding of the ``rest`` product and of its two small terms.
    """

    hi: Any
    sliced: Any
    rest: Any
    bits: int
    width: int
    beta: float
    float_x: float
    float_v: float
    rest_lead: float
    rest_hi: float


def _gamma(k: Any) -> Any:
    return k * U / (1 - k * U)


@dataclass(frozen=True)
class _Pattern:
    """The sparsity of B = M⁻¹[K | C] with rows in order: the entries' permutation into
    CSR order, the CSR arrays and the row lengths."""

    order: np.ndarray
    rows: np.ndarray
    cols: np.ndarray
    indptr: np.ndarray
    counts: np.ndarray
    shape: tuple[int, int]

    def csr(self, data: np.ndarray, n: int | None = None) -> Any:
        import scipy.sparse as sps

        return sps.csr_matrix((data, self.cols.copy(), self.indptr.copy()), shape=self.shape)


def _pattern(n: int, rows: np.ndarray, cols: np.ndarray, columns: int | None = None) -> _Pattern:
    """The pattern of an n x ``columns`` matrix (2n columns unless given)."""
    width = 2 * n if columns is None else columns
    order = np.argsort(rows * width + cols, kind="stable")
    counts = np.bincount(rows, minlength=n)
    indptr = np.concatenate([[0], np.cumsum(counts)])
    index = np.int32 if width + 1 < 2**31 and rows.size < 2**31 else np.int64
    return _Pattern(order, rows[order], cols[order].astype(index), indptr.astype(index), counts,
                    (n, width))


def _weighted_norm(pattern: _Pattern, size: np.ndarray, weight: np.ndarray, n: int,
                   columns: slice, refine: bool = False,
                   col_weight: np.ndarray | None = None) -> float:
    """≥ ‖G‖₂ for G = diag(weight)·|D[:, columns]|·diag(col_weight) (entries ``size`` in CSR
    order; no column weights unless given): √(‖G‖₁‖G‖∞), or (``refine``) the smaller of
    that and √ρ(GᵀG) by Collatz–Wielandt (15 power steps; irregular graphs, whose largest
    rows overstate the norm)."""
    import scipy.sparse as sps

    lo, hi = columns.start or 0, columns.stop or pattern.shape[1]
    kept = (pattern.cols >= lo) & (pattern.cols < hi)
    rows, cols = pattern.rows[kept], pattern.cols[kept] - lo
    weighted = size[kept] * weight[rows]
    if col_weight is not None:
        weighted = weighted * col_weight[pattern.cols[kept]]
    width = hi - lo
    by_col = np.bincount(cols, weighted, minlength=width)
    by_row = np.bincount(rows, weighted, minlength=n)
    holder = math.sqrt(float(by_col.max(initial=0.0)) * float(by_row.max(initial=0.0))) * _MARGIN
    if not refine or holder == 0:
        return holder
    G = sps.csr_matrix((weighted, (rows, cols)), shape=(n, width))
    Gt = G.T.tocsr()
    return min(holder, math.sqrt(perron_bound(lambda d: Gt @ (G @ d), width, 15)) * _MARGIN)


def _step_matrix(n: int, pattern: _Pattern, hi: np.ndarray, lo: np.ndarray, root: np.ndarray,
                 refine: bool = False, col_weight: np.ndarray | None = None) -> StepMatrix:
    import scipy.sparse as sps

    counts, width = pattern.counts, int(pattern.counts.max(initial=1)) or 1
    bits = (53 - math.ceil(math.log2(max(width, 2)))) // 2
    size = np.abs(hi)
    largest = np.zeros(n)
    np.maximum.at(largest, pattern.rows, size)
    _, exponent = np.frexp(largest)             # largest < 2^exponent ≤ 2·largest
    sigma = np.repeat(np.ldexp(1.5, exponent - bits + 52), counts)
    lead = (hi + sigma) - sigma
    rest_low = (hi - lead) + lo
    low = pattern.csr(rest_low, n)
    low.eliminate_zeros()
    rest = sps.hstack([low, pattern.csr(hi, n)], format="csr")
    g_float = root * (_gamma(counts.astype(float)) + 3 * U + 2.0**-100)
    g_rest = root * (_gamma(2.0 * counts) + 2 * U) * (1 + 2 * U)
    half = pattern.shape[1] // 2
    x_part, v_part, every = slice(0, half), slice(half, 2 * half), slice(0, 2 * half)
    return StepMatrix(
        hi=pattern.csr(hi, n), sliced=pattern.csr(lead, n), rest=rest, bits=bits, width=width,
        beta=_weighted_norm(pattern, size, root, n, every),
        float_x=_weighted_norm(pattern, size, g_float, n, x_part, refine, col_weight),
        float_v=_weighted_norm(pattern, size, g_float, n, v_part, refine, col_weight),
        rest_lead=_weighted_norm(pattern, np.abs(rest_low) * (1 + 2 * U), g_rest, n, every, refine),
        rest_hi=_weighted_norm(pattern, size, g_rest, n, every, refine))


# ----------------------------------------------------------------------------- the data


@dataclass(frozen=True, eq=False)
class KrylovData:
    """What the krylov engine holds for one scene (built by :func:`krylov_data`).

    Attributes
    ----------
    n : int
        Coordinates.
    H : float
        The step (a float with a 5-bit mantissa, so every j·H is exact); θ = H·ν.
    first, later : StepMatrix
        D' (the first term, on [x; v]) and D (every later term, on [U_{k−2}; U_{k−1}]).
    matrix : scipy.sparse.csr_matrix
        B = M⁻¹[K | C] rounded to float64 (x'' = −B z).
    nu, norm_K, m_min, m_max, energy : float
        ν ≥ N(Az)/N(z), ‖K‖₂, the extreme masses, N(z0) (upper bounds; m_min a lower one).
    compliance : float
        √R: |x_i| ≤ √R·√(xᵀKx) for every x and i (inf where a part is not held).
    row_K, row_C : numpy.ndarray
        Absolute row sums of M⁻¹K and M⁻¹C (upper bounds); ``width`` B's longest row.
    mass, stiffness : numpy.ndarray
        Upper bounds on the masses m_i and on the absolute row sums s_i = Σ_j |K_ij|, so
        that vᵀMv ≤ Σ_i mass_i·v_i² and xᵀKx ≤ Σ_i s_i·x_i² (|x_i x_j| ≤ (x_i² + x_j²)/2).
    kappa : float
        ≥ √max_i(s_i/m_i) (from ``row_K``): √(Σ s_i x_i²) ≤ κ·√(Σ m_i x_i²).
    z0 : tuple of numpy.ndarray
        The initial state as double-doubles (hi, lo), length 2n.
    """

    n: int
    H: float
    theta: float
    first: StepMatrix
    later: StepMatrix
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
    mass: np.ndarray
    stiffness: np.ndarray
    kappa: float


def step_length(nu: float) -> float:
    """The largest H ≤ Limits.krylov_step_norm/ν with a 5-bit mantissa (so j·H is exact
    for j < 2^48, and H is at most 1/16 shorter than the limit allows).

    >>> step_length(2.5) * 2.5 <= limits().krylov_step_norm < step_length(2.5) * 2.5 * 17 / 16
    True
    """
    h = limits().krylov_step_norm / nu
    e = math.floor(math.log2(h))
    return math.floor(h / 2.0 ** (e - _H_BITS + 1)) * 2.0 ** (e - _H_BITS + 1)


def _compliance(n: int, K: Entries) -> float:
    """√R (module notes): Dijkstra from the ground over lengths 1/|K_ij|, rounded up."""
    import scipy.sparse as sps
    from scipy.sparse.csgraph import dijkstra

    if n == 0:
        return 0.0
    diagonal = K.rows == K.cols
    off = ~diagonal & (K.rows < K.cols)
    size = np.abs(K.value)
    diag = np.zeros(n)
    diag[K.rows[diagonal]] = K.value[diagonal]
    off_sum = np.bincount(K.rows[~diagonal], size[~diagonal], minlength=n)
    counts = np.bincount(K.rows, minlength=n)
    # K's float entries are off by u each; the sum by γ_w of the magnitudes
    slack = _gamma(counts + 3.0)
    ground = (diag - off_sum) - slack * (np.abs(diag) + off_sum)
    held = np.flatnonzero(ground > 0)
    if held.size == 0:
        return math.inf
    up = 1 + 8 * U
    rows = np.concatenate([K.rows[off], held])
    cols = np.concatenate([K.cols[off], np.full(held.size, n)])
    lengths = np.concatenate([up / size[off], up / ground[held]])
    graph = sps.csr_matrix((lengths, (rows, cols)), shape=(n + 1, n + 1))
    distance = dijkstra(graph, directed=False, indices=n)[:n]
    largest = float(np.max(distance))
    return math.sqrt(largest * (1 + 2 * (n + 2) * U)) if math.isfinite(largest) else math.inf


def _quotients(K: Entries, C: Entries, m_num: np.ndarray, m_den: np.ndarray, H: float,
               power_K: int, masses: Entries) -> tuple[np.ndarray, np.ndarray]:
    """The entries of [sign·H^power_K·M⁻¹K | sign·H^power_C·M⁻¹C] as double-doubles
    (power_C = min(power_K, 1), sign = −1 when power_K > 0): exact quotients of float
    integers where they fit, with H = h·2^e (h < 32) applied as h^power and 2^(power·e)."""
    mantissa, exponent = math.frexp(H)
    h_int, h_exp = int(mantissa * 2**_H_BITS), exponent - _H_BITS   # H = h_int·2^h_exp exactly
    his, los = [], []
    for entries, power in ((K, power_K), (C, min(power_K, 1))):
        sign = -1.0 if power_K else 1.0
        num = sign * entries.num * m_den[entries.rows] * float(h_int**power)
        den = entries.den * m_num[entries.rows]
        ok = entries.exact & (np.abs(num) < 2.0**53) & (den < 2.0**53)
        scale = int(sign) * Fraction(H) ** power

        def fraction(i: int, e: Entries = entries, f: Fraction = scale) -> Fraction:
            return f * e.fraction(i) / masses.fraction(int(np.flatnonzero(masses.rows == e.rows[i])[0]))

        hi, lo = exact_quotients(num, den, ok, fraction)
        his.append(np.where(ok, np.ldexp(hi, power * h_exp), hi))
        los.append(np.where(ok, np.ldexp(lo, power * h_exp), lo))
    return np.concatenate(his), np.concatenate(los)


def _energy(n: int, K: Entries, M: Entries, x0: np.ndarray, v0: np.ndarray) -> float:
    """≥ N(z0) = √(v0ᵀMv0 + x0ᵀKx0), in float64 with the rounding added (the entries'
    values are within 2u)."""
    terms = np.concatenate([M.value * v0[M.rows] ** 2, x0[K.rows] * K.value * x0[K.cols]])
    total = float(np.sum(terms))
    slack = _gamma(terms.size + 8.0) * float(np.sum(np.abs(terms)))
    return math.sqrt(max(total + slack, 0.0)) * _MARGIN


def _vector(scene: Scene, name: str, n: int) -> tuple[np.ndarray, np.ndarray]:
    """x0 or v0 as double-doubles (hi, lo)."""
    entries = entries_of(scene, name)
    assert entries is not None
    hi, lo = np.zeros(n), np.zeros(n)
    h, low = exact_quotients(entries.num, entries.den, entries.exact, entries.fraction)
    hi[entries.rows], lo[entries.rows] = h, low
    return hi, lo


def krylov_data(scene: Scene) -> KrylovData:
    """The data of a scene :func:`scene_refusal` accepts (time ∝ nonzero entries).

    >>> data = krylov_data(Scene.from_matrices(M=[[2]], C=[[1]], K=[[8]], x0=[1], v0=[0]))
    >>> data.matrix.toarray().tolist(), round(data.nu, 6), round(data.energy, 8)
    ([[4.0, 0.5]], 2.265564, 2.82842713)
    """
    why = scene_refusal(scene)
    if why is not None:
        raise SceneError(f"the Taylor (krylov) route cannot take this scene: {why}")
    n = scene.n
    M, C, K = (entries_of(scene, name) for name in ("M", "C", "K"))
    assert M is not None and C is not None and K is not None
    m, m_num, m_den = np.ones(n), np.ones(n), np.ones(n)
    m[M.rows], m_num[M.rows], m_den[M.rows] = M.value, M.num, M.den
    if max(np.max(np.abs(K.value), initial=0.0), np.max(np.abs(C.value), initial=0.0),
           float(m.max(initial=1.0)), 1 / float(m.min(initial=1.0))) > _RANGE:
        raise FloatRangeError("M, C or K has an entry beyond what the krylov engine holds in "
                              "float64 (1e150)")
    root = np.sqrt(m)
    nu = spectral_bound(scene)
    H = step_length(nu)
    pattern = _pattern(n, np.concatenate([K.rows, C.rows]), np.concatenate([K.cols, C.cols + n]))
    parts = [_quotients(K, C, m_num, m_den, H, power, M) for power in (0, 1, 2)]
    (b_hi, _), first, later = ((hi[pattern.order], lo[pattern.order]) for hi, lo in parts)
    size = np.abs(b_hi)
    x_cols = pattern.cols < n
    x0h, x0l = _vector(scene, "x0", n)
    v0h, v0l = _vector(scene, "v0", n)
    energy = _energy(n, K, M, x0h, v0h) + 2.0**-100 * (float(np.linalg.norm(x0h)) + float(np.linalg.norm(v0h)))
    zh, zl = np.concatenate([x0h, v0h]), np.concatenate([x0l, v0l])
    if not math.isfinite(energy) or np.max(np.abs(zh), initial=0.0) > _RANGE:
        raise FloatRangeError("the initial data are beyond what the krylov engine holds in float64")
    inverse_root = np.tile(1 / root, 2)
    row_K = np.bincount(pattern.rows, np.where(x_cols, size, 0.0), minlength=n) * (1 + 4 * U) * _MARGIN
    stiffness = np.bincount(K.rows, np.abs(K.value), minlength=n) * (1 + 4 * U) * _MARGIN
    return KrylovData(
        n=n, H=H, theta=H * nu,
        first=_step_matrix(n, pattern, *first, root, col_weight=inverse_root),
        later=_step_matrix(n, pattern, *later, root, refine=True, col_weight=inverse_root),
        matrix=pattern.csr(b_hi, n), nu=nu,
        norm_K=float(np.max(np.bincount(K.rows, np.abs(K.value), minlength=n), initial=0.0)) * (1 + 4 * U) * _MARGIN,
        m_min=float(m.min()) / _MARGIN if n else 1.0, m_max=float(m.max()) * _MARGIN if n else 1.0,
        energy=energy, compliance=_compliance(n, K),
        row_K=row_K,
        row_C=np.bincount(pattern.rows, np.where(x_cols, 0.0, size), minlength=n) * (1 + 4 * U) * _MARGIN,
        width=int(pattern.counts.max(initial=1)) or 1, z0=(zh, zl),
        mass=m * _MARGIN, stiffness=stiffness,
        kappa=math.sqrt(float(row_K.max(initial=0.0))) * _MARGIN)

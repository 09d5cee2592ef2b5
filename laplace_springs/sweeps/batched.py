"""Numeric sweeps of scenes of any size: batched eigen-decompositions with refined modes and
a rigorous bound per set.

For a stack of parameter sets sharing one sparsity pattern (an unforced scene with a
diagonal positive M, a symmetric K ⪰ 0 and C + Cᵀ ⪰ 0, every spring and dashpot network),
each set's motion is written as

    x̂(t) = Re Σ_j w_j v_j a_j e^{λ_j t},    x̂'(t) = Re Σ_j w_j λ_j v_j a_j e^{λ_j t},

over the eigenvalues λ_j of the quadratic pencil λ²M + λC + K with Im λ_j ≥ 0 (w_j = 2 for
a complex pair, 1 for a real root). The steps, vectorised over the sets:

1. **Modes**: ``numpy.linalg.eig`` of the scaled first-order matrices
   [[0, I], [−M⁻¹K/γ², −M⁻¹C/γ]] (γ² ≥ λ_max(M⁻¹K), one batched LAPACK call).
2. **One Newton step on every mode** (the quadratic eigenvalue problem's Newton step, all
   modes at once): the residuals r_j = (λ_j²M + λ_jC + K)v_j are formed in double-double
   from the exact entries of the set (:mod:`~laplace_springs.sweeps.entries`), then
   G = −W [0; M⁻¹r] with W the inverse of [V; VΛ], δλ_j = G_jj and
   δv_j = Σ_i v_i G_ij/(λ_j − λ_i). The refined pairs v + δv, λ + δλ are kept as
   unevaluated sums of two floats.
3. **Coefficients** a = W z0, refined once with the mismatch z0 − ŷ(0) formed in
   double-double.
4. **The bound.** x̂ solves M x̂'' + C x̂' + K x̂ = g(t), g = −Re Σ w_j a_j r'_j e^{λ_j t},
   with the refined residuals r'_j (computed in double-double, their rounding bounded), and
   starts from ŷ(0) = z0 + d with the refined mismatch d. The energy
   N(e)² = e'ᵀMe' + eᵀKe of the error e = x̂ − x never grows by itself (K ⪰ 0,
   C + Cᵀ ⪰ 0, proved per set by diagonal dominance), so
   N(e(t)) ≤ N(e(0)) + ∫₀ᵗ ‖M^{-1/2}g‖, ‖e'(t)‖₂ ≤ N/√μ (μ the least mass) and
   ‖e(t)‖₂ ≤ ‖e(0)‖₂ + ∫₀ᵗ‖e'‖. After the refinement these are of the order of 10⁻³⁰ of
   the motion.
5. **Evaluation in float64** with the phases λt formed in double-double (no loss at long
   times) and the rounding of the coefficients, exponentials, cosines and of the sum over
   the modes bounded term by term (γ_k of the summation, k the number of terms).

Every value's bound is the sum of the two. A time whose bound misses the target relative
to max(‖x(t)‖∞, S₀) (S₀ = ‖x0‖∞ + ‖v0‖∞/ρ, ρ the largest |λ|) is recomputed by
``ls.solve(scene.subs(set))`` by the caller; so is a set that does not meet the
conditions above (a massless node, K not diagonally dominant) or whose modes are nearly
defective (critical damping of a mode, rigid-body motion: the refined residuals or the
coefficients are then large and so is the bound).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..kernels.dd import UNIT_DD, U, dd_add, dd_mul_float, phase, two_prod, two_sum
from ..model.scene import Scene
from .complex_dd import CDD, RowGroups, cdd, cdd_add, cdd_float, cdd_mul_float, cdd_product, row_groups
from .entries import DD, SceneEntries

__all__ = ["BatchedScene", "BatchBlock", "batched_refusal", "batched_scene", "evaluate_batch"]


@dataclass(frozen=True, eq=False)
class BatchedScene:
    """The structure of a scene for :func:`evaluate_batch` (built once per sweep)."""

    n: int
    entries: SceneEntries
    K: RowGroups
    C: RowGroups
    C_transpose: np.ndarray  # position of (j, i) for each entry (i, j) of C, or -1

    @property
    def width(self) -> int:
        return max(self.K.width, self.C.width)


@dataclass
class BatchBlock:
    """What :func:`evaluate_batch` returns for P sets and T times.

    Attributes
    ----------
    values, bounds : numpy.ndarray
        (P, outputs, T).
    accepted : numpy.ndarray
        (P, T) bool: the bound meets the target at that time (else it is recomputed).
    served : numpy.ndarray
        (P,) bool: the set met the engine's conditions (else every time is recomputed).
    poles : numpy.ndarray
        (P, 2n) complex eigenvalues (NaN for sets not served).
    floor : numpy.ndarray
        (P,) the contract's floor S₀·ρ^order of each set.
    """

    values: np.ndarray
    bounds: np.ndarray
    accepted: np.ndarray
    served: np.ndarray
    poles: np.ndarray
    floor: np.ndarray


def batched_refusal(scene: Scene, entries: SceneEntries) -> str | None:
    """Why the batched engine cannot take the scene (structurally), or None.

    Examples
    --------
    >>> from laplace_springs.sweeps.entries import scene_entries_of
    >>> scene = Scene.from_matrices(M=[[1]], C=[["c"]], K=[["k"]], x0=[1], v0=[0],
    ...                             parameters=["c", "k"])
    >>> batched_refusal(scene, scene_entries_of(scene)) is None
    True
    >>> forced = scene.with_forcing(["cos(t)"])
    >>> batched_refusal(forced, scene_entries_of(forced))
    'the scene is forced'
    """
    if scene.is_forced or scene.sampled is not None:
        return "the scene is forced"
    if not entries.compiled:
        return "some entry is not a polynomial or rational function of the parameters"
    n = scene.n
    masses = entries.pattern["M"]
    if any(i != j for i, j in masses) or len(masses) != n:
        return "M is not diagonal with a mass on every coordinate"
    K = dict(zip(entries.pattern["K"], entries.expressions["K"]))
    for (i, j), value in K.items():
        if i < j and sp.expand(value - K.get((j, i), sp.S.Zero)) != 0:
            return f"K is not symmetric (K[{i},{j}] = {value}, K[{j},{i}] = {K.get((j, i), 0)})"
    return None


def batched_scene(scene: Scene, entries: SceneEntries) -> BatchedScene:
    """The :class:`BatchedScene` of a scene :func:`batched_refusal` accepts."""
    n = scene.n
    C_pattern = entries.pattern["C"]
    where = {key: k for k, key in enumerate(C_pattern)}
    transpose = np.array([where.get((j, i), -1) for i, j in C_pattern], dtype=np.intp)
    return BatchedScene(n, entries, row_groups(entries.pattern["K"], n), row_groups(C_pattern, n),
                        transpose)


# ----------------------------------------------------------------------------- the data


@dataclass
class _Data:
    m: DD             # (P, n) masses
    K: DD             # (P, nnzK)
    C: DD             # (P, nnzC)
    x0: DD            # (P, n)
    v0: DD            # (P, n)


def _vector(entries: SceneEntries, name: str, params: list[DD], P: int, n: int) -> DD:
    hi, lo, err = entries.evaluate(name, params, P)
    out = tuple(np.zeros((P, n)) for _ in range(3))
    for k, (i, _) in enumerate(entries.pattern[name]):
        for part, source in zip(out, (hi, lo, err)):
            part[:, i] = source[:, k]
    return out  # type: ignore[return-value]


def _data(structure: BatchedScene, params: list[DD], P: int) -> _Data:
    e, n = structure.entries, structure.n
    return _Data(_vector(e, "M", params, P, n), e.evaluate("K", params, P), e.evaluate("C", params, P),
                 _vector(e, "x0", params, P, n), _vector(e, "v0", params, P, n))


def _dominant(groups: RowGroups, hi: np.ndarray, lo: np.ndarray, err: np.ndarray,
              transpose: np.ndarray | None = None) -> np.ndarray:
    """(P,) whether the symmetric part of each matrix is diagonally dominant with a
    nonnegative diagonal (in double-double; within its own rounding of 10⁻²⁸)."""
    P = hi.shape[0]
    if transpose is not None:  # the symmetric part (C + Cᵀ)/2 at the positions of C
        other = np.where(transpose >= 0, transpose, 0)
        present = transpose >= 0
        th = np.where(present, hi[:, other], 0.0)
        tl = np.where(present, lo[:, other], 0.0)
        sh, sl = dd_add(hi, lo, th, tl)
        hi, lo = sh / 2, sl / 2
        err = (err + np.where(present, err[:, other], 0.0)) / 2 + UNIT_DD * np.abs(hi)
    rows, cols = groups.rows, groups.cols
    diagonal = rows == cols
    sign = np.where(diagonal, 1.0, -np.sign(hi))  # d_ii − Σ_j |a_ij| term by term
    pad = np.zeros((P, 1))
    th = np.concatenate([sign * hi, pad], axis=1)[:, groups.table]  # (P, n, width)
    tl = np.concatenate([sign * lo, pad], axis=1)[:, groups.table]
    sh, sl = _sum_modes((th, tl))
    slack = np.concatenate([err + 8 * groups.width * UNIT_DD * np.abs(hi), pad], axis=1)
    slack = np.sum(slack[:, groups.table], axis=2)
    diag_ok = np.ones(P, dtype=bool)
    if diagonal.any():
        diag_ok = np.all(hi[:, diagonal] + lo[:, diagonal] >= -err[:, diagonal], axis=1)
    return diag_ok & np.all(sh + sl >= -slack, axis=1)


def _conditions(structure: BatchedScene, d: _Data) -> np.ndarray:
    finite = np.ones(d.m[0].shape[0], dtype=bool)
    for part in (d.m, d.K, d.C, d.x0, d.v0):
        finite &= np.all(np.isfinite(part[0]) & np.isfinite(part[2]), axis=1)
    with np.errstate(invalid="ignore"):
        masses = np.all(d.m[0] > 2 * d.m[2], axis=1)
        finite &= masses & np.all(np.abs(d.K[0]) < 1e150, axis=1) & np.all(np.abs(d.C[0]) < 1e150, axis=1)
    ok = finite.copy()
    if ok.any():
        ok[ok] &= _dominant(structure.K, d.K[0][ok], d.K[1][ok], d.K[2][ok])
        ok[ok] &= _dominant(structure.C, d.C[0][ok], d.C[1][ok], d.C[2][ok], structure.C_transpose)
    return ok


# ----------------------------------------------------------------------------- the modes


def _dense(groups: RowGroups, values: np.ndarray, n: int) -> np.ndarray:
    out = np.zeros((values.shape[0], n, n))
    out[:, groups.rows, groups.cols] = values
    return out


def _inverse(Y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Inverses of a stack of matrices, and which were invertible (a singular one is
    replaced by the identity)."""
    finite = np.all(np.isfinite(Y.reshape(Y.shape[0], -1)), axis=1)
    Y = np.where(finite[:, None, None], Y, np.eye(Y.shape[1]))
    try:
        return np.linalg.inv(Y), finite
    except np.linalg.LinAlgError:  # numpy refuses the whole stack: invert one by one
        out = np.empty_like(Y)
        ok = finite.copy()
        for b in range(Y.shape[0]):
            try:
                out[b] = np.linalg.inv(Y[b])
            except np.linalg.LinAlgError:
                out[b], ok[b] = np.eye(Y.shape[1]), False
        return out, ok


@dataclass
class _Products:
    """K V, C V and M V in double-double (P, n, 2n)."""

    KV: CDD
    CV: CDD
    MV: CDD


def _products(structure: BatchedScene, d: _Data, V: np.ndarray) -> _Products:
    KV = structure.K.product((d.K[0], d.K[1]), V)
    CV = structure.C.product((d.C[0], d.C[1]), V)
    m_hi, m_lo = d.m[0][:, :, None], d.m[1][:, :, None]
    real, imag = dd_mul_float(m_hi, m_lo, V.real), dd_mul_float(m_hi, m_lo, V.imag)
    return _Products(KV, CV, (real[0], real[1], imag[0], imag[1]))


def _pencil(products: _Products, lam: np.ndarray, dlam: np.ndarray | None = None) -> CDD:
    """(λ'²M + λ'C + K)V = λ'(λ'·MV + CV) + KV with λ' = λ + dλ (λ, dλ complex floats):
    the products with λ exact (double-double), those with the small dλ in float64 (their
    rounding, below 3u·|dλ|·(2|λ'||M||V| + |C||V|), is counted by the caller)."""
    inner = cdd_add(cdd_mul_float(products.MV, lam), products.CV)
    if dlam is not None:
        inner = cdd_add(inner, cdd(dlam * cdd_float(products.MV)))
    outer = cdd_add(cdd_mul_float(inner, lam), products.KV)
    if dlam is not None:
        outer = cdd_add(outer, cdd(dlam * cdd_float(inner)))
    return outer


def _pencil_floats(structure: BatchedScene, d: _Data, lam: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(λ²M + λC + K)v in float64 (λ (P, 1, 2n), v (P, n, 2n))."""
    Kv = structure.K.floats(d.K[0], v)
    Cv = structure.C.floats(d.C[0], v)
    return lam * (lam * (d.m[0][:, :, None] * v) + Cv) + Kv


def _pencil_size(structure: BatchedScene, d: _Data, lam: np.ndarray, v: np.ndarray,
                 errors: bool = False) -> np.ndarray:
    """|λ|²|M||v| + |λ||C||v| + |K||v| for moduli ``lam``, ``v`` (or, with ``errors``, the
    same with the entries' error bounds in place of the entries)."""
    part = 2 if errors else 0
    grow = 1.0 if errors else 1 + 1e-15
    Kv = structure.K.magnitude(np.abs(d.K[part]) * grow, v)
    Cv = structure.C.magnitude(np.abs(d.C[part]) * grow, v)
    return lam * (lam * (np.abs(d.m[part]) * grow)[:, :, None] * v + Cv) + Kv


def _sum_modes(part: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Σ over the last axis of a double-double array, pairwise."""
    hi, lo = part
    width = hi.shape[-1]
    while width > 1:
        half = (width + 1) // 2
        if width % 2:
            hi = np.concatenate([hi, np.zeros(hi.shape[:-1] + (1,))], axis=-1)
            lo = np.concatenate([lo, np.zeros(lo.shape[:-1] + (1,))], axis=-1)
        hi, lo = dd_add(hi[..., :half], lo[..., :half], hi[..., half:], lo[..., half:])
        width = half
    return hi[..., 0], lo[..., 0]


def _mismatch(d: _Data, V: np.ndarray, v_lo: np.ndarray, lam: np.ndarray, dlam: np.ndarray,
              a: np.ndarray, a_lo: np.ndarray, weight: np.ndarray) -> tuple[DD, DD]:
    """ŷ(0) − z0 = (Re Σ_j w_j v'_j a'_j − x0, Re Σ_j w_j λ'_j v'_j a'_j − v0) in
    double-double, with error bounds (P, n). ``lam``, ``dlam``, ``a``, ``a_lo`` and
    ``weight`` have shape (P, 1, 2n); the products of the leading parts are exact, the
    small cross terms in float64."""
    wa, wa_lo = weight * a, weight * a_lo
    exact = cdd_product(V, wa)  # V·(w a), exactly
    cross = V * wa_lo + v_lo * (wa + wa_lo)
    velocity = cdd_mul_float(exact, lam)
    cross_v = lam * cross + dlam * (cdd_float(exact) + cross)
    size = np.abs(V) * np.abs(wa)
    small = np.abs(V) * np.abs(wa_lo) + np.abs(v_lo) * (np.abs(wa) + np.abs(wa_lo))
    modulus = np.abs(lam) + np.abs(dlam)
    levels = np.log2(V.shape[-1] + 2) + 4
    out = []
    for term, extra, start, scale, tiny in (
            (exact, cross, d.x0, size, small),
            (velocity, cross_v, d.v0, np.abs(lam) * size, modulus * small + np.abs(dlam) * size)):
        hi, lo = _sum_modes((term[0], term[1] + extra.real))
        hi, lo = dd_add(hi, lo, -start[0], -start[1])
        err = 16 * levels * UNIT_DD * np.sum(scale, axis=-1) + 8 * levels * U * np.sum(tiny, axis=-1)
        out.append((hi, lo, err + start[2] + UNIT_DD * np.abs(start[0])))
    return out[0], out[1]


@dataclass
class _Modes:
    lam: np.ndarray        # (P, 2n) complex, refined (rounded)
    lam_lo: np.ndarray     # its low part
    coeff: np.ndarray      # v'·a' (P, n, 2n), rounded (error ≤ 3u of |v'||a'|)
    weight: np.ndarray     # (P, 2n)
    energy: np.ndarray     # (P, 2n): w_j |a'_j| ‖r'_j‖₂ (bound)
    start: np.ndarray      # (P, 2): ‖e(0)‖₂, ‖e'(0)‖₂
    norms: np.ndarray      # (P, 4): μ, ‖M‖, ‖K‖₂, ‖C‖₂ bounds
    served: np.ndarray     # (P,)
    size: np.ndarray       # (P, n, 2n): |v'||a'| bound


def _modes(structure: BatchedScene, d: _Data, served: np.ndarray) -> _Modes:
    n = structure.n
    P = d.m[0].shape[0]
    m = np.where(served[:, None], d.m[0], 1.0)  # a set not served gets a harmless x'' + x = 0
    K = np.where(served[:, None, None], _dense(structure.K, d.K[0], n), np.eye(n))
    C = np.where(served[:, None, None], _dense(structure.C, d.C[0], n), 0.0)
    row = np.max(np.sum(np.abs(K), axis=2) / m, axis=1)
    gamma = np.sqrt(np.where(row > 0, row, 1.0))
    Z = np.zeros((P, 2 * n, 2 * n))
    Z[:, np.arange(n), n + np.arange(n)] = 1.0
    Z[:, n:, :n] = -K / m[:, :, None] / (gamma**2)[:, None, None]
    Z[:, n:, n:] = -C / m[:, :, None] / gamma[:, None, None]
    mu, vectors = np.linalg.eig(Z)
    lam = (mu * gamma[:, None]).astype(complex)
    V = vectors[:, :n, :].astype(complex)
    norm = np.linalg.norm(V, axis=1, keepdims=True)
    served = served & np.all(norm[:, 0, :] > 0, axis=1) & np.all(np.isfinite(lam), axis=1)
    V = V / np.where(norm > 0, norm, 1.0)
    Y = np.concatenate([V, V * lam[:, None, :]], axis=1)
    W, invertible = _inverse(Y)
    served &= invertible
    # one Newton step on every mode
    products = _products(structure, d, V)
    r = cdd_float(_pencil(products, lam[:, None, :]))
    G = -np.matmul(W[:, :, n:], r / m[:, :, None])
    gaps = lam[:, None, :] - lam[:, :, None]
    off = ~np.eye(2 * n, dtype=bool)[None]
    with np.errstate(divide="ignore", invalid="ignore"):
        E = np.where(off & (gaps != 0), G / np.where(gaps != 0, gaps, 1.0), 0.0)
    dlam = np.einsum("pjj->pj", G)
    v_lo = np.matmul(V, E)
    served &= np.all(np.isfinite(v_lo.reshape(P, -1)), axis=1) & np.all(np.isfinite(dlam), axis=1)
    v_lo = np.where(served[:, None, None], v_lo, 0.0)
    dlam = np.where(served[:, None], dlam, 0.0)
    weight = np.where(lam.imag > 0, 2.0, np.where(lam.imag == 0, 1.0, 0.0))[:, None, :]
    lam3, dlam3 = lam[:, None, :], dlam[:, None, :]
    # coefficients, refined once
    z0 = np.concatenate([d.x0[0], d.v0[0]], axis=1)
    a = np.matmul(W, z0[:, :, None].astype(complex))[:, :, 0]
    zero = np.zeros_like(a[:, None, :])
    ex, ev = _mismatch(d, V, v_lo, lam3, dlam3, a[:, None, :], zero, weight)
    d0 = np.concatenate([ex[0] + ex[1], ev[0] + ev[1]], axis=1)
    a_lo = -np.matmul(W, d0[:, :, None].astype(complex))[:, :, 0]
    a_lo = np.where(np.isfinite(a_lo), a_lo, 0.0)
    ex, ev = _mismatch(d, V, v_lo, lam3, dlam3, a[:, None, :], a_lo[:, None, :], weight)
    start = np.stack([np.linalg.norm(np.abs(ex[0] + ex[1]) + ex[2], axis=1),
                      np.linalg.norm(np.abs(ev[0] + ev[1]) + ev[2], axis=1)], axis=1) * (1 + 1e-10)
    # the refined residuals (λ'²M + λ'C + K)(V + δV): the V part in double-double from the
    # products above, the δV part (of the size u·|V|) in float64; and their bound
    main = _pencil(products, lam3, dlam3)
    rest = _pencil_floats(structure, d, lam3 + dlam3, v_lo)
    computed = np.abs(cdd_float(main) + rest) * (1 + 4 * U)
    modulus_lam = (np.abs(lam) + np.abs(dlam))[:, None, :] * (1 + 4 * U)
    size_V = _pencil_size(structure, d, modulus_lam, np.abs(V))
    size_lo = _pencil_size(structure, d, modulus_lam, np.abs(v_lo))
    entry = _pencil_size(structure, d, modulus_lam, np.abs(V) + np.abs(v_lo), errors=True)
    damping = structure.C.magnitude(np.abs(d.C[0]) * (1 + 1e-15), np.abs(V))
    small = 3 * U * np.abs(dlam3) * (2 * modulus_lam * d.m[0][:, :, None] * np.abs(V) + damping)
    bound = computed + 8 * (structure.width + 8) * UNIT_DD * size_V \
        + (2 * structure.width + 16) * U * size_lo + entry + small
    column = np.sqrt(np.sum(bound**2, axis=1)) * (1 + 1e-10)  # (P, 2n)
    modulus_v = (np.abs(V) + np.abs(v_lo)) * (1 + 4 * U)
    modulus_a = (np.abs(a) + np.abs(a_lo)) * (1 + 4 * U)
    energy = weight[:, 0, :] * modulus_a * column
    norms = np.stack([np.min(d.m[0] - d.m[2], axis=1) * (1 - 1e-15), np.max(d.m[0] + d.m[2], axis=1),
                      _row_norm(structure.K, d.K), _two_norm(structure.C, d.C)], axis=1)
    aa = a[:, None, :]
    coeff = cdd_float(cdd_product(V, aa)) + (V * a_lo[:, None, :] + v_lo * (aa + a_lo[:, None, :]))
    size = modulus_v * modulus_a[:, None, :]
    re_hi, re_lo = two_sum(lam.real, dlam.real)
    im_hi, im_lo = two_sum(lam.imag, dlam.imag)
    return _Modes(re_hi + 1j * im_hi, re_lo + 1j * im_lo, coeff, weight[:, 0, :], energy, start,
                  norms, served, size)


def _row_norm(groups: RowGroups, values: DD) -> np.ndarray:
    """max row sum of |A| (≥ ‖A‖₂ for a symmetric A)."""
    absolute = np.abs(values[0]) + values[2]
    sums = _row_sums(absolute, groups.rows, groups.n)
    return np.max(sums, axis=1, initial=0.0) * (1 + 1e-12)


def _row_sums(values: np.ndarray, index: np.ndarray, n: int) -> np.ndarray:
    """Σ of the entries (P, count) by their row (or column) ``index``: (P, n)."""
    out = np.zeros((values.shape[0], n))
    for k, i in enumerate(index.tolist()):
        out[:, i] += values[:, k]
    return out


def _two_norm(groups: RowGroups, values: DD) -> np.ndarray:
    """√(max row sum · max column sum) of |A| ≥ ‖A‖₂."""
    absolute = np.abs(values[0]) + values[2]
    rows = _row_sums(absolute, groups.rows, groups.n)
    cols = _row_sums(absolute, groups.cols, groups.n)
    return np.sqrt(np.max(rows, axis=1, initial=0.0) * np.max(cols, axis=1, initial=0.0)) * (1 + 1e-12)


# ----------------------------------------------------------------------------- evaluation


def _integral(alpha: np.ndarray, t: np.ndarray) -> np.ndarray:
    """∫₀ᵗ e^{αs} ds (≥ 0), shape alpha.shape + t.shape."""
    at = alpha[..., None] * t
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        value = np.where(alpha[..., None] != 0, np.expm1(at) / np.where(alpha[..., None] != 0,
                                                                         alpha[..., None], 1.0),
                         np.broadcast_to(t, at.shape))
    return np.where(np.isfinite(value), value, np.inf) * (1 + 1e-12)


def _energy_bound(modes: _Modes, t: np.ndarray, order: int) -> np.ndarray:
    """‖x^(order) − x̂^(order)‖₂ bound from the energy (P, T)."""
    mu, _, normK, normC = (modes.norms[:, k] for k in range(4))
    normM = modes.norms[:, 1]
    root = np.sqrt(np.maximum(mu, 1e-300))
    alpha = modes.lam.real + np.abs(modes.lam_lo) + 1e-15 * np.abs(modes.lam)
    with np.errstate(over="ignore", invalid="ignore"):
        flow = np.einsum("pj,pjt->pt", modes.energy, _integral(alpha, t)) / root[:, None]
        N = np.sqrt(normM)[:, None] * modes.start[:, 1:2] + np.sqrt(normK)[:, None] * modes.start[:, 0:1]
        N = N + flow
        x_err = modes.start[:, 0:1] + t * N / root[:, None]
        v_err = N / root[:, None]
        if order == 0:
            out = x_err
        elif order == 1:
            out = v_err
        else:
            force = np.einsum("pj,pjt->pt", modes.energy, np.exp(alpha[..., None] * t))
            out = (normK[:, None] * x_err + normC[:, None] * v_err + force) / mu[:, None]
    return np.where(np.isfinite(out), out * (1 + 1e-10), np.inf)


def _exponentials(lam: np.ndarray, lam_lo: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, ...]:
    """e^{λt} (real and imaginary parts) with the products λt in double-double, and
    |e^{λt}|; each (P, K, T)."""
    p, e = two_prod(lam.real[..., None], t)
    e = e + lam_lo.real[..., None] * t
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        amplitude = np.exp(p) * (1 + e)
    cos, sin, _ = phase(lam.imag[..., None], lam_lo.imag[..., None], t, 0.0)
    return amplitude * cos, amplitude * sin, amplitude


#: Terms summed by one matrix product before the pairwise sums (γ_8 for each block).
_BLOCK = 8


def _mode_sums(c: np.ndarray, magnitude: np.ndarray, modes: _Modes, times: np.ndarray,
               order: int) -> tuple[np.ndarray, np.ndarray]:
    """Re Σ_j w_j c_ij e^{λ_j t} (P, outputs, T) and a bound on its rounding.

    Only the modes with w_j > 0 are kept (one of each conjugate pair). The sum over them
    is taken in blocks of :data:`_BLOCK` terms by one matrix product each, then pairwise
    over the blocks: its rounding is at most γ_k·Σ|terms| with k = 8 + ⌈log₂(blocks)⌉,
    whatever the number of modes. Each term carries the rounding of its coefficient
    (2u), of e^{λt} (double-double phase, libm exp, cos and sin: 12u) and of the product.
    """
    P, n_out, N = c.shape
    order_columns = np.argsort(modes.weight <= 0, axis=1, kind="stable")
    kept = int(np.max(np.sum(modes.weight > 0, axis=1), initial=1))
    columns = order_columns[:, :kept]
    weight = np.take_along_axis(modes.weight, columns, axis=1)
    lam = np.take_along_axis(modes.lam, columns, axis=1)
    lam_lo = np.take_along_axis(modes.lam_lo, columns, axis=1)
    picked = np.take_along_axis(c, columns[:, None, :], axis=2) * weight[:, None, :]
    size = np.take_along_axis(magnitude, columns[:, None, :], axis=2) * weight[:, None, :]
    width = 2 * kept
    blocks = -(-width // _BLOCK)
    flat = np.zeros((P, n_out, blocks * _BLOCK))
    flat[:, :, :kept], flat[:, :, kept:width] = picked.real, -picked.imag
    left = flat.reshape(P, n_out, blocks, _BLOCK).transpose(0, 2, 1, 3)  # (P, B, n_out, 8)
    unit = (20 + 4 * order + 2 * (_BLOCK + int(np.ceil(np.log2(blocks))) + 2)) * U
    values = np.empty((P, n_out, times.size))
    rounding = np.empty((P, n_out, times.size))
    step = max(1, int(4_000_000 // max(P * blocks * n_out, 1)))
    for start in range(0, times.size, step):
        t = times[start:start + step]
        er, ei, amplitude = _exponentials(lam, lam_lo, t)
        right = np.zeros((P, blocks * _BLOCK, t.size))
        right[:, :kept], right[:, kept:width] = er, ei
        partial = np.matmul(left, right.reshape(P, blocks, _BLOCK, t.size))  # (P, B, n_out, t)
        while partial.shape[1] > 1:
            half = partial.shape[1] // 2
            paired = partial[:, :half] + partial[:, half:2 * half]
            partial = np.concatenate([paired, partial[:, 2 * half:]], axis=1)
        values[:, :, start:start + step] = partial[:, 0]
        rounding[:, :, start:start + step] = unit * np.matmul(size, amplitude) * (1 + 1e-12) \
            + 1e-300 * np.sum(size, axis=2, keepdims=True)  # underflow
    return values, rounding


def evaluate_batch(structure: BatchedScene, params: list[DD], times: np.ndarray, *,
                   outputs: list[int], order: int, target: float) -> BatchBlock:
    """Values and bounds of P parameter sets (``params``: each parameter's (hi, lo, err),
    arrays of length P) at ``times`` (see the module notes).

    Examples
    --------
    x'' + c x' + k x = 0, x(0) = 1, against the textbook formula:

    >>> from laplace_springs.sweeps.entries import scene_entries_of, parameter_parts
    >>> scene = Scene.from_matrices(M=[[1]], C=[["c"]], K=[["k"]], x0=[1], v0=[0],
    ...                             parameters=["c", "k"])
    >>> structure = batched_scene(scene, scene_entries_of(scene))
    >>> params = [parameter_parts(np.array([0.5])), parameter_parts(np.array([4.0]))]
    >>> block = evaluate_batch(structure, params, np.array([0.0, 2.0]), outputs=[0], order=0,
    ...                        target=1e-13)
    >>> w = np.sqrt(4 - 0.0625)  # h = c/2 = 1/4
    >>> exact = np.exp(-0.5) * (np.cos(2 * w) + 0.25 / w * np.sin(2 * w))
    >>> bool(abs(block.values[0, 0, 1] - exact) < 1e-15), bool(block.bounds[0, 0, 1] < 1e-14)
    (True, True)
    >>> block.accepted.tolist()
    [[True, True]]
    """
    P = params[0][0].shape[0] if params else 1
    d = _data(structure, params, P)
    served = _conditions(structure, d)
    modes = _modes(structure, d, served.copy())
    served = modes.served
    c = modes.coeff[:, outputs, :]
    size = modes.size[:, outputs, :]
    lam_power = np.ones(modes.lam.shape)
    for _ in range(order):  # c·λ'^order, each product rounded (counted in _mode_sums)
        c = c * modes.lam[:, None, :]
    if order:
        lam_power = (np.abs(modes.lam) + np.abs(modes.lam_lo)) ** order * (1 + 8 * U)
    magnitude = size * lam_power[:, None, :]
    with np.errstate(over="ignore", invalid="ignore"):
        values, rounding = _mode_sums(c, magnitude, modes, times, order)
        bounds = rounding + _energy_bound(modes, times, order)[:, None, :]
    values = np.where(served[:, None, None], values, 0.0)
    bounds = np.where(served[:, None, None] & np.isfinite(values) & np.isfinite(bounds), bounds, np.inf)
    floor = _floor(d, modes.lam, order)
    with np.errstate(invalid="ignore"):
        scale = np.maximum(np.max(np.abs(values), axis=1), floor[:, None])
        accepted = np.all(bounds <= target * scale[:, None, :], axis=1) & served[:, None]
    poles = np.where(served[:, None], modes.lam, np.nan)
    return BatchBlock(values, bounds, accepted, served, poles, floor)


def _floor(d: _Data, lam: np.ndarray, order: int) -> np.ndarray:
    """S₀·ρ^order per set: S₀ = ‖x0‖∞ + ‖v0‖∞/ρ (‖v0‖∞ for ρ = 0), ρ = max |λ|."""
    rho = np.max(np.abs(np.where(np.isfinite(lam), lam, 0)), axis=1)
    x0 = np.max(np.abs(d.x0[0]), axis=1)
    v0 = np.max(np.abs(d.v0[0]), axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        base = x0 + np.where(rho > 0, v0 / np.where(rho > 0, rho, 1.0), v0)
    return base * rho**order


"""Large sparse scenes with non-classical damping: Taylor steps of the first-order system.

The state z = (x, v) obeys z' = A z, A = [[0, I], [−M⁻¹K, −M⁻¹C]], held sparse. Time is
cut into steps of length H (H·ν ≤ 2, ν below). On each step the Taylor powers
y_k = (H/k)·A·y_{k−1}, y_0 = z(b) are formed in double-double arithmetic (about 32
digits) from the exact rational entries of M⁻¹K and M⁻¹C; their sum is the next step's
state, and x, x' at any time b + s of the step is Σ (s/H)^k·y_k summed in float64 from
the powers' leading parts. The cost is about 13·ν·t_max double-double products with
A, independent of the number of output times (each costs one small dense product).

The error bound (:meth:`KrylovMotion.evaluate`)
-----------------------------------------------
It rests on the energy seminorm N(z)² = vᵀMv + xᵀKx, which the exact motion never
increases when M is diagonal positive, K symmetric positive semidefinite and C + Cᵀ
positive semidefinite (dN²/dt = −vᵀ(C + Cᵀ)v). :func:`krylov_refusal` checks this
exactly in rational arithmetic (symmetric, diagonally dominant matrices with a
non-negative diagonal: every spring and dashpot network). In energy coordinates
w = (K^{1/2}x, M^{1/2}v) the matrix is [[0, P], [−Pᵀ, −D]] with ‖P‖₂² = λ_max(M⁻¹K) and
D = M^{−1/2}CM^{−1/2}, so N(A z) ≤ ν N(z) with ν = ‖P‖₂ + ‖D‖₂ bounded by Gershgorin
sums. Hence

* the Taylor remainder after m powers is at most (Hν)^{m+1}/(m+1)!/(1 − Hν/(m+2))·N(z)
  in N (m is chosen so that this is below 2⁻⁶⁴), and its x part at most 1/ν of that;
* a local error δ committed at time b propagates without growth in N, and its x part
  stays within ‖δ_x‖∞ + (t − b)·N(δ)/√m_min (x = δ_x + ∫v, |v_i| ≤ N/√m_i): no
  bound on K⁻¹ is needed, so rigid-body motion is allowed;
* double-double rounding (relative 2⁻¹⁰⁰ per operation, with the row lengths) of every
  product and sum is bounded through ‖|A|‖₂ and the powers' norms;
* the float64 output sum carries γ_{2m+4}·Σ_k (s/H)^k·‖y_k‖∞ (the weights' rounding
  included) plus the dropped low parts.

The bound is the same for every coordinate; x'' comes from the equation
M x'' = −Kx − Cx' with the rounding of that product added.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np
from flint import fmpq

from ..limits import limits
from ..model.errors import FloatRangeError, SceneError
from ..model.scene import Scene
from .first_order import rational_entries

__all__ = ["KrylovData", "KrylovMotion", "krylov_refusal", "krylov_data",
           "krylov_motion"]

_U = 2.0**-53
_DD = 2.0**-100          # relative rounding of one double-double operation (generous)
_SPLIT = 134217729.0     # 2**27 + 1


# ----------------------------------------------------------------------------- double-double


def _two_sum(a: Any, b: Any) -> tuple[Any, Any]:
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


def _fast_two_sum(a: Any, b: Any) -> tuple[Any, Any]:
    s = a + b
    return s, b - (s - a)


def _halves(x: Any) -> tuple[Any, Any]:
    c = _SPLIT * x
    high = c - (c - x)
    return high, x - high


def _two_product(a: Any, b: Any) -> tuple[Any, Any]:
    p = a * b
    ah, al = _halves(a)
    bh, bl = _halves(b)
    return p, ((ah * bh - p) + ah * bl + al * bh) + al * bl


def _dd_add(ah: Any, al: Any, bh: Any, bl: Any) -> tuple[Any, Any]:
    s, e = _two_sum(ah, bh)
    t, f = _two_sum(al, bl)
    s, e = _fast_two_sum(s, e + t)
    return _fast_two_sum(s, e + f)


def _dd_mul(ah: Any, al: Any, bh: Any, bl: Any) -> tuple[Any, Any]:
    p, e = _two_product(ah, bh)
    return _fast_two_sum(p, e + (ah * bl + al * bh))


def _dd(value: Any) -> tuple[float, float]:
    """A rational as a double-double hi + lo (hi correctly rounded, lo of the remainder)."""
    q = Fraction(int(value.p), int(value.q))
    hi = int(value.p) / int(value.q)
    return hi, float(q - Fraction(hi))


# ----------------------------------------------------------------------------- scene data


def _row_sums(rows: dict[int, dict[int, Any]], n: int) -> np.ndarray:
    out = np.zeros(n)
    for i, row in rows.items():
        out[i] = float(sum(abs(v) for v in row.values()))
    return out


def _rows(entries: dict[tuple[int, int], Any]) -> dict[int, dict[int, Any]]:
    rows: dict[int, dict[int, Any]] = {}
    for (i, j), value in entries.items():
        rows.setdefault(i, {})[j] = value
    return rows


def _dominant(entries: dict[tuple[int, int], Any], n: int) -> bool:
    """Symmetric part diagonally dominant with a non-negative diagonal (so it is PSD)."""
    sym: dict[tuple[int, int], Any] = {}
    for (i, j), value in entries.items():
        sym[i, j] = sym.get((i, j), 0) + value / 2
        sym[j, i] = sym.get((j, i), 0) + value / 2
    off = [fmpq(0)] * n
    diag = [fmpq(0)] * n
    for (i, j), value in sym.items():
        if i == j:
            diag[i] = value
        else:
            off[i] += abs(value)
    return all(d >= o for d, o in zip(diag, off))


def krylov_refusal(scene: Scene) -> str | None:
    """Why the Taylor route cannot bound this scene's motion, or None when it can.

    It needs rational entries, no forcing, a diagonal positive M, a symmetric K and K, C
    whose symmetric parts are diagonally dominant with a non-negative diagonal (K ⪰ 0,
    C + Cᵀ ⪰ 0, proved exactly): the energy then never grows.

    Examples
    --------
    >>> ok = Scene.from_matrices(M=[[1, 0], [0, 2]], C=[[1, 0], [0, 0]], K=[[2, -1], [-1, 1]],
    ...                          x0=[1, 0], v0=[0, 0])
    >>> krylov_refusal(ok) is None
    True
    >>> krylov_refusal(Scene.from_matrices(M=[[1]], C=[[-1]], K=[[1]], x0=[1], v0=[0]))
    'C + Cᵀ is not diagonally dominant with a non-negative diagonal (C + Cᵀ ⪰ 0 is not proved)'
    """
    if scene.is_forced or getattr(scene, "sampled", None) is not None:
        return "the scene is forced"
    M, C, K, x0, v0 = (rational_entries(scene, name) for name in ("M", "C", "K", "x0", "v0"))
    if M is None or C is None or K is None or x0 is None or v0 is None:
        return "some entry is not a rational number"
    n = scene.n
    if any(i != j for i, j in M) or len(M) < n or any(v <= 0 for v in M.values()):
        return "M is not diagonal with positive masses"
    if any(K.get((j, i)) != value for (i, j), value in K.items()):
        return "K is not symmetric"
    if not _dominant(K, n):
        return "K is not diagonally dominant with a non-negative diagonal (K ⪰ 0 is not proved)"
    if not _dominant(C, n):
        return ("C + Cᵀ is not diagonally dominant with a non-negative diagonal "
                "(C + Cᵀ ⪰ 0 is not proved)")
    return None


@dataclass(frozen=True, eq=False)
class KrylovData:
    """The float data of the Taylor route (built by :func:`krylov_data`).

    ``groups`` hold B = [M⁻¹K | M⁻¹C] (n x 2n, exact entries as double-doubles): rows of
    similar length, each group as (rows, columns, hi, lo) padded to a power of two;
    ``width`` is the longest row; ``nu`` bounds N(Az)/N(z);
    ``norm_K`` ≥ ‖K‖₂, ``abs_B`` ≥ ‖|B|‖₂; ``row_K``, ``row_C`` the absolute row sums of
    M⁻¹K and M⁻¹C; ``energy`` ≥ N(z0).
    """

    n: int
    groups: list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]
    width: int
    nu: float
    norm_K: float
    abs_B: float
    row_K: np.ndarray
    row_C: np.ndarray
    m_min: float
    m_max: float
    energy: float
    z0: tuple[np.ndarray, np.ndarray]
    matrix: Any          # scipy CSR of B's leading parts (float64)


def _groups(n: int, rows: np.ndarray, cols: np.ndarray, hi: np.ndarray,
            lo: np.ndarray) -> list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
    """Rows grouped by length (padded to a power of two with zero entries), entries in
    row order: a product is a few vectorised double-double operations per group."""
    order = np.argsort(rows, kind="stable")
    rows, cols, hi, lo = rows[order], cols[order], hi[order], lo[order]
    counts = np.bincount(rows, minlength=n)
    starts = np.concatenate([[0], np.cumsum(counts)])
    width = np.where(counts > 0, 2 ** np.ceil(np.log2(np.maximum(counts, 1))).astype(int), 0)
    out = []
    for w in np.unique(width[width > 0]):
        members = np.flatnonzero(width == w)
        position = np.arange(int(w))[None, :]
        take = starts[members][:, None] + position
        inside = position < counts[members][:, None]
        take = np.where(inside, take, 0)
        out.append((members, np.where(inside, cols[take], 0), np.where(inside, hi[take], 0.0),
                    np.where(inside, lo[take], 0.0)))
    return out


def krylov_data(scene: Scene) -> KrylovData:
    """The data of a scene :func:`krylov_refusal` accepts (time ∝ nonzero entries).

    >>> data = krylov_data(Scene.from_matrices(M=[[2]], C=[[1]], K=[[8]], x0=[1], v0=[0]))
    >>> data.matrix.toarray().tolist(), round(data.nu, 6), round(data.energy, 8)
    ([[4.0, 0.5]], 2.5, 2.82842713)
    """
    import scipy.sparse as sps

    why = krylov_refusal(scene)
    if why is not None:
        raise SceneError(f"the Taylor (krylov) route cannot take this scene: {why}")
    n = scene.n
    Me, Ce, Ke, x0e, v0e = (rational_entries(scene, name) for name in ("M", "C", "K", "x0", "v0"))
    assert Me is not None and Ce is not None and Ke is not None and x0e is not None and v0e is not None
    mass = [fmpq(0)] * n
    for (i, _), value in Me.items():
        mass[i] = value
    rows: list[list[tuple[int, Any]]] = [[] for _ in range(n)]
    for (i, j), value in Ke.items():
        rows[i].append((j, value / mass[i]))
    for (i, j), value in Ce.items():
        rows[i].append((n + j, value / mass[i]))
    entries = [(i, j, value) for i, row in enumerate(rows) for j, value in row]
    parts = [_dd(value) for _, _, value in entries]
    r_idx = np.array([e[0] for e in entries], dtype=np.intp)
    c_idx = np.array([e[1] for e in entries], dtype=np.intp)
    hi = np.array([p[0] for p in parts])
    lo = np.array([p[1] for p in parts])
    if not (np.all(np.isfinite(hi)) and np.all(np.isfinite(lo))) or np.max(np.abs(hi), initial=0) > 1e150:
        raise FloatRangeError("M⁻¹K or M⁻¹C has an entry beyond what the Taylor route holds in float64")
    groups = _groups(n, r_idx, c_idx, hi, lo)
    margin = 1 + 1e-10
    m = np.array([float(v) for v in mass])
    root = np.sqrt(m)
    Kr = _rows(Ke)
    # Gershgorin: λ_max(M^{-1/2} K M^{-1/2}) ≤ max_i Σ_j |K_ij|/√(m_i m_j)
    gersh = np.zeros(n)
    d_row, d_col = np.zeros(n), np.zeros(n)
    for (i, j), value in Ke.items():
        gersh[i] += abs(float(value)) / (root[i] * root[j])
    for (i, j), value in Ce.items():
        w = abs(float(value)) / (root[i] * root[j])
        d_row[i] += w
        d_col[j] += w
    nu = (math.sqrt(float(gersh.max(initial=0.0))) + math.sqrt(float(d_row.max(initial=0.0))
                                                                 * float(d_col.max(initial=0.0)))) * margin
    norm_K = float(_row_sums(Kr, n).max(initial=0.0)) * margin
    absB = np.abs(hi)
    row_sum = np.bincount(r_idx, absB, minlength=n)
    col_sum = np.bincount(c_idx, absB, minlength=2 * n)
    abs_B = math.sqrt(float(row_sum.max(initial=0.0)) * float(col_sum.max(initial=0.0))) * margin
    row_K = np.bincount(r_idx, np.where(c_idx < n, absB, 0.0), minlength=n) * margin
    row_C = np.bincount(r_idx, np.where(c_idx >= n, absB, 0.0), minlength=n) * margin
    x0 = {i: v for (i, _), v in x0e.items()}
    v0 = {i: v for (i, _), v in v0e.items()}
    energy_sq = sum((v * v * mass[i] for i, v in v0.items()), fmpq(0))
    energy_sq += sum((x0[i] * value * x0[j] for (i, j), value in Ke.items() if i in x0 and j in x0),
                     fmpq(0))
    energy = math.sqrt(float(energy_sq)) * margin
    zh, zl = np.zeros(2 * n), np.zeros(2 * n)
    for offset, vector in ((0, x0), (n, v0)):
        for i, value in vector.items():
            zh[offset + i], zl[offset + i] = _dd(value)
    if not math.isfinite(energy) or not np.all(np.isfinite(zh)):
        raise FloatRangeError("the initial data are beyond the float64 range")
    matrix = sps.csr_matrix((hi, (r_idx, c_idx)), shape=(n, 2 * n))
    width = max((len(r) for r in rows), default=1)
    return KrylovData(n, groups, max(width, 1), max(nu, 1e-300), norm_K, abs_B, row_K, row_C,
                      float(m.min()) / margin, float(m.max()) * margin, energy, (zh, zl), matrix)


# ----------------------------------------------------------------------------- the motion


def _tail(theta: float, m: int) -> float:
    """Σ_{k>m} θ^k/k! ≤ θ^{m+1}/(m+1)!/(1 − θ/(m+2))."""
    if theta <= 0:
        return 0.0
    return math.exp((m + 1) * math.log(theta) - math.lgamma(m + 2)) / (1 - theta / (m + 2))


def _step_length(nu: float) -> float:
    """The largest H ≤ Limits.krylov_step_norm/ν with a 3-bit mantissa (so j·H is exact)."""
    h = limits().krylov_step_norm / nu
    e = math.floor(math.log2(h))
    return math.floor(h / 2.0 ** (e - 2)) * 2.0 ** (e - 2)


class KrylovMotion:
    """x(t), x'(t), x''(t) of a scene from double-double Taylor steps (see module notes)."""

    def __init__(self, data: KrylovData) -> None:
        self.data = data
        self.H = _step_length(data.nu)
        theta = self.H * data.nu
        m = 4
        while _tail(theta, m) > 2.0**-64:
            m += 1
        self.m = m
        self.tail = _tail(theta, m)
        self.growth = math.exp(theta)
        self._last: tuple[Any, Any] | None = None

    @property
    def n(self) -> int:
        return self.data.n

    def _matvec(self, yh: np.ndarray, yl: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(A y) in double-double: (v, −B y)."""
        d = self.data
        n = d.n
        sh, sl = np.zeros(n), np.zeros(n)
        for members, cols, hi, lo in d.groups:
            ph, pl = _dd_mul(hi, lo, yh[cols], yl[cols])
            w = ph.shape[1]
            while w > 1:  # pairwise: log2(width) vectorised additions
                w //= 2
                ph, pl = _dd_add(ph[:, :w], pl[:, :w], ph[:, w:], pl[:, w:])
            sh[members], sl[members] = ph[:, 0], pl[:, 0]
        return np.concatenate([yh[n:], -sh]), np.concatenate([yl[n:], -sl])

    def _march(self, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """States (T, 2n) at the times and their bounds (T,) on x and on v errors."""
        d = self.data
        n, H, m = d.n, self.H, self.m
        T = hi.size
        states = np.zeros((T, 2 * n))
        bx, bv = np.zeros(T), np.zeros(T)
        if T == 0:
            return states, bx, bv
        step = np.floor(hi / H).astype(np.int64)
        last = int(step.max())
        if last >= limits().krylov_max_steps:
            raise ValueError(f"t = {float(hi.max())!r} needs {last:,} Taylor steps of {H:g}, more "
                             f"than Limits.krylov_max_steps = {limits().krylov_max_steps:,}")
        order = np.argsort(step, kind="stable")
        bounds_at = np.searchsorted(step[order], np.arange(last + 2))
        exact_H = Fraction(H)
        coeffs = [_dd(fmpq(exact_H.numerator, exact_H.denominator * k)) if k else (1.0, 0.0)
                  for k in range(m + 1)]
        c_hi = [c[0] for c in coeffs]
        zh, zl = d.z0[0].copy(), d.z0[1].copy()
        # the initial state's rounding (relative 2^-106 of each entry)
        X = float(np.max(np.abs(zl), initial=0.0))
        V = math.sqrt(d.norm_K) * float(np.linalg.norm(zl[:n])) + math.sqrt(d.m_max) * float(
            np.linalg.norm(zl[n:]))
        gamma = (2 * m + 6) * _U / (1 - (2 * m + 6) * _U)
        eps_dd = (d.width + 8) * _DD
        root_m = math.sqrt(d.m_min)
        weight = math.sqrt(d.m_max) * d.abs_B + math.sqrt(d.norm_K)
        Y = np.empty((m + 1, 2 * n))
        for j in range(last + 1):
            Y[0] = zh
            norms2 = [float(np.linalg.norm(zh)) * 1.01]
            acc_h, acc_l = zh, zl
            yh, yl = zh, zl
            local_n = 0.0   # Σ_k N(f_k): double-double rounding of the powers
            local_2 = 0.0   # Σ_k ‖f_k‖₂
            for k in range(1, m + 1):
                ah, al = self._matvec(yh, yl)
                yh, yl = _dd_mul(ah, al, coeffs[k][0], coeffs[k][1])
                f2 = eps_dd * c_hi[k] * (d.abs_B + 1) * norms2[-1]
                local_2 += f2
                local_n += eps_dd * c_hi[k] * weight * norms2[-1]
                Y[k] = yh
                norms2.append(float(np.linalg.norm(yh)) * 1.01)
                acc_h, acc_l = _dd_add(acc_h, acc_l, yh, yl)
            summed = eps_dd * (m + 1) * sum(norms2)
            local_n += summed * (math.sqrt(d.m_max) + math.sqrt(d.norm_K))
            local_2 += summed
            scale = d.energy + V
            trunc_n = self.tail * scale
            trunc_x = trunc_n / d.nu / root_m
            inner_n = self.growth * local_n
            inner_x = local_2 + H * inner_n / root_m + trunc_x
            inner_v = local_2 + inner_n / root_m + trunc_n / root_m
            lo_, hi_ = bounds_at[j], bounds_at[j + 1]
            if hi_ > lo_:
                idx = order[lo_:hi_]
                s = hi[idx] - j * H          # exact (Sterbenz, or j = 0)
                r = s / H
                W = np.cumprod(np.vstack([np.ones_like(r), np.broadcast_to(r, (m, r.size))]), axis=0)
                states[idx] = W.T @ Y
                size_x = np.max(np.abs(Y[:, :n]), axis=1)
                size_v = np.max(np.abs(Y[:, n:]), axis=1)
                rounding_x = (gamma + 2 * _U) * (size_x @ W)
                rounding_v = (gamma + 2 * _U) * (size_v @ W)
                bx[idx] = X + s * V / root_m + inner_x + rounding_x
                bv[idx] = V / root_m + inner_v + rounding_v
            # the next step's state: its error in N and in the x part
            X = X + H * V / root_m + inner_x
            V = V + inner_n + trunc_n
            zh, zl = acc_h, acc_l
        return states, bx * 1.01, bv * 1.01

    def evaluate(self, times: np.ndarray, order: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """d^order x/dt^order at float times (≥ 0) and a bound on each entry's error, both
        shape (n, len(times)).

        Examples
        --------
        x'' + x' + 4x = 0, x(0) = 1 against its closed form:

        >>> motion = krylov_motion(Scene.from_matrices(M=[[1]], C=[[1]], K=[[4]], x0=[1], v0=[0]))
        >>> values, bounds = motion.evaluate(np.array([0.0, 2.0]))
        >>> w = np.sqrt(15) / 2
        >>> exact = np.exp(-1.0) * (np.cos(2 * w) + np.sin(2 * w) / (2 * w))
        >>> bool(abs(values[0, 1] - exact) <= bounds[0, 1] < 1e-14)
        True
        """
        t = np.asarray(times, dtype=float).ravel()
        key = t.tobytes()
        if self._last is not None and self._last[0] == key:
            states, bx, bv = self._last[1]
        else:
            states, bx, bv = self._march(t)
            self._last = (key, (states, bx, bv))
        n = self.n
        if order == 0:
            return states[:, :n].T.copy(), np.broadcast_to(bx, (n, t.size)).copy()
        if order == 1:
            return states[:, n:].T.copy(), np.broadcast_to(bv, (n, t.size)).copy()
        d = self.data
        values = -(d.matrix @ states.T)
        size = abs(d.matrix) @ np.abs(states.T)
        gamma = (d.width + 3) * _U / (1 - (d.width + 3) * _U)
        bounds = (d.row_K[:, None] * bx[None, :] + d.row_C[:, None] * bv[None, :]) * 1.01 \
            + gamma * size
        return values, bounds

    def slope_bound(self, order: int) -> float:
        """A bound on |x^(order+1)_i(t)| for every i and t ≥ 0 (for decimal times)."""
        d = self.data
        return d.nu ** order * d.energy / math.sqrt(d.m_min) * 1.01

    def poles(self, count: int = 6) -> np.ndarray:
        """Some poles: all of them (dense) up to Limits.dense_poles_max_coordinates, else the ``count`` of
        largest modulus and the ``count`` nearest 0 (ARPACK; empty where it fails)."""
        import scipy.linalg as sla
        import scipy.sparse as sps
        import scipy.sparse.linalg as spla

        d = self.data
        n = d.n
        A = sps.bmat([[None, sps.identity(n)], [-d.matrix[:, :n], -d.matrix[:, n:]]], format="csc")
        if n <= limits().dense_poles_max_coordinates:
            return np.sort_complex(sla.eigvals(A.toarray()))
        found = []
        for kw in ({"which": "LM"}, {"sigma": 0.0, "which": "LM"}):
            try:
                found.append(spla.eigs(A, k=count, return_eigenvectors=False, tol=1e-10, **kw))
            except (RuntimeError, ValueError, spla.ArpackError):
                continue
        return np.sort_complex(np.unique(np.concatenate(found))) if found else np.zeros(0, complex)


def krylov_motion(scene: Scene) -> KrylovMotion:
    """The Taylor-step motion of a scene :func:`krylov_refusal` accepts (SceneError if not).

    >>> krylov_motion(Scene.from_matrices(M=[[1]], C=[[1]], K=[[4]], x0=[1], v0=[0])).m > 4
    True
    """
    return KrylovMotion(krylov_data(scene))

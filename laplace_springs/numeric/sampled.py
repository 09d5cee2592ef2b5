"""The response to sampled force histories, exact for their interpolants, in float64 with
an error bound (and in mpmath to any number of digits).

With z = (x, x') the scene is z' = A z + b u(t), A = [[0, I], [-M⁻¹K, -M⁻¹C]],
b = (0, M⁻¹e_j) for a force on coordinate j. On a segment [t_k, t_{k+1}] the input is
u_k + s_k (t − t_k) (s_k = 0 for zero-order hold), so the augmented state (z, u, s) moves
by the exponential of

    Â = [[A, b, 0], [0, 0, 1], [0, 0, 0]]    ((2n+2) x (2n+2)),

exactly: z(t_k + τ) = [e^{Âτ}(z_k, u_k, s_k)]_z. The output at a time t in segment k is
e^{Âτ}(S_k, u_k, s_k), τ = t − t_k; after the last sample the force is zero and the
motion is free, e^{Aτ}S_N; before the first it is zero.

Algorithm
---------
Everything that accumulates is held in double-double (:mod:`laplace_springs.numeric.dd_matrix`):

* **The segment maps.** The step of every segment, h_k = t_{k+1} − t_k, is formed exactly
  (two-sum of the float sample times) and e^{Âh} is computed once per distinct step from
  the exact Taylor matrices Â^j/j! (python-flint rationals rounded once to double-double),
  by Horner in h with halvings and squarings, to about 10⁻³⁰. The slopes
  (u_{k+1} − u_k)/h_k are double-double quotients of exact differences.
* **The states at the sample times**, S_{k+1} = E_k S_k + c_k, in double-double: on
  small systems (2n ≤ 12) in √N blocks advanced together (each block's own response and
  transfer matrix, then the carries between blocks, then the states inside every block
  from its carry); on larger ones step by step. Either way the rounding does not build
  up to anything float64 can see, whatever the grid (uniform or not) and N.
* **The output.** A time τ after a state moves it by e^{Xτ} (X = Â inside the data, A
  after it) as τ = q·δ + r: the bits of q apply the dyadic powers e^{X·2^i δ} in
  double-double (so the phase of a free motion at t = 10⁶ or 10¹² is right to 10⁻²⁰ and
  beyond), and e^{Xr} (‖X‖r ≤ 1/2) is a float64 Taylor series.

Error bound
-----------
Every operation above has a rigorous elementwise bound (see dd_matrix), and a state's
error reaches later states through the true flow, whose size is bounded with no sampling
by sup_{σ ≤ span} |e^{Aσ}| ≤ R·Π_i(I + |E_i|) (dyadic powers of A). The float64 Taylor
series' rounding is bounded from the same series of |X|, and the rounding of A and b to
float64 from |δX| ≤ u|X|. The bound is therefore an upper bound on the error of the
interpolant's response (of the float64 samples as given), not an estimate; it is about
ε·|x| at the sample times and after the data, whatever N and t, until the dyadic
powers' own error (2^{1.5 i}·10⁻³² after i squarings) shows, near t ≈ 10¹⁵/‖A‖.

Every time is evaluated alone (no product across times), so a value does not depend on
the other times of a call.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import mpmath
import numpy as np
import sympy as sp

from ..kernels.batch import rows_product
from ..kernels.dd import U, dd_add, dd_div, two_sum
from ..kernels.precision import workdps
from ..limits import limits
from ..model.errors import SceneError
from ..model.sampled import Sampled
from ..model.scene import Scene
from .dd_matrix import (
    DyadicPowers,
    TaylorMatrices,
    abs_product,
    expm,
    matmul,
    matvec,
    taylor_matrices,
)
from .first_order import first_order_system, massless_nodes

__all__ = ["SampledInput", "sampled_inputs"]

_EPS = 2 * U
_TINY = 1e-300
#: Largest state size (2n) whose states are advanced in blocks: the blocks' transfer
#: matrices cost (2n)³ per segment, stepping costs about 0.3-0.6 ms of array overhead per
#: segment (measured on 5,000 random steps: 3 masses 0.3 s by blocks against 1.7 s
#: stepwise, 4 masses 0.7 s against 1.5 s, 6 masses about even).
_BLOCK_MAX_STATE = 12
#: Degree of the float64 Taylor series of e^{Xr} for ‖X‖r ≤ 1/2 (truncation 2e-20).
_TAYLOR = 16


@dataclass(frozen=True, eq=False)
class _States:
    """States at the sample times (double-double) and bounds on their errors."""

    hi: np.ndarray      # (N, 2n)
    lo: np.ndarray
    bound: np.ndarray
    slopes_hi: np.ndarray   # (N - 1,)
    slopes_lo: np.ndarray
    slopes_bound: np.ndarray


@dataclass(eq=False)
class SampledInput:
    """The response z(t) = (x, x') to one sampled force on one coordinate, zero initial state.

    Build with :func:`sampled_inputs`. :meth:`states` runs the recurrence once (cached);
    :meth:`values` evaluates at any times.
    """

    A: np.ndarray          # 2n x 2n float64
    b: np.ndarray          # 2n float64
    data: Sampled
    coordinate: int
    A_exact: Any = field(repr=False)   # sympy 2n x 2n
    b_exact: Any = field(repr=False)   # sympy 2n x 1
    _cache: dict = field(default_factory=dict, repr=False)

    # -- the matrices (balanced: z' = D z with D a diagonal of powers of two) ----------
    @property
    def scaling(self) -> np.ndarray:
        """Exponents e_i of the balancing D = diag(2^{e_i}) over the m = 2n + 2 augmented
        coordinates (Parlett and Reinsch's balancing of |Â|): in D Â D⁻¹ a stiff oscillator's map is a
        rotation, so elementwise bounds of products do not grow with ω per squaring.
        Powers of two: every conversion is exact."""
        if "scaling" not in self._cache:
            m2 = self.A.shape[0]
            Aa = np.zeros((m2 + 2,) * 2)
            Aa[:m2, :m2], Aa[:m2, m2], Aa[m2, m2 + 1] = np.abs(self.A), np.abs(self.b), 1.0
            self._cache["scaling"] = _balance(Aa)
        return np.asarray(self._cache["scaling"])

    @property
    def augmented(self) -> np.ndarray:
        """D Â D⁻¹ rounded to float64."""
        m2 = self.A.shape[0]
        Aa = np.zeros((m2 + 2, m2 + 2))
        Aa[:m2, :m2], Aa[:m2, m2], Aa[m2, m2 + 1] = self.A, self.b, 1.0
        e = self.scaling
        return np.ldexp(Aa, e[:, None] - e[None, :])

    @property
    def free(self) -> np.ndarray:
        """D_z A D_z⁻¹ rounded to float64."""
        m2 = self.A.shape[0]
        return self.augmented[:m2, :m2]

    @property
    def norm(self) -> float:
        return self.taylor.theta

    @property
    def taylor(self) -> TaylorMatrices:
        """The Taylor matrices of the exact D Â D⁻¹."""
        if "taylor" not in self._cache:
            m2 = self.A.shape[0]
            e = [int(v) for v in self.scaling]
            entries: list[list[Any]] = [[0] * (m2 + 2) for _ in range(m2 + 2)]
            for i in range(m2):
                for j in range(m2):
                    entries[i][j] = _exact(self.A_exact[i, j], e[i] - e[j])
                entries[i][m2] = _exact(self.b_exact[i], e[i] - e[m2])
            entries[m2][m2 + 1] = _exact(sp.S.One, e[m2] - e[m2 + 1])
            self._cache["taylor"] = taylor_matrices(entries)
        return self._cache["taylor"]

    @property
    def taylor_free(self) -> TaylorMatrices:
        """The Taylor matrices of D_z A D_z⁻¹ (the top-left blocks of the augmented ones)."""
        if "taylor_free" not in self._cache:
            P, m2 = self.taylor, self.A.shape[0]
            theta = float(np.max(np.sum(P.absolute[1][:m2, :m2], axis=1), initial=0.0))
            theta = theta * (1 + (m2 + 2) * _EPS) + _TINY
            self._cache["taylor_free"] = TaylorMatrices(
                P.hi[:, :m2, :m2].copy(), P.lo[:, :m2, :m2].copy(), theta,
                P.absolute[:, :m2, :m2].copy())
        return self._cache["taylor_free"]

    @property
    def powers(self) -> DyadicPowers:
        """The dyadic powers of the augmented matrix (moves inside a segment)."""
        if "powers" not in self._cache:
            self._cache["powers"] = DyadicPowers(self.taylor)
        return self._cache["powers"]

    @property
    def free_powers(self) -> DyadicPowers:
        """The dyadic powers of the free matrix (the motion after the data)."""
        if "free_powers" not in self._cache:
            self._cache["free_powers"] = DyadicPowers(self.taylor_free)
        return self._cache["free_powers"]

    @property
    def rho(self) -> float:
        """The largest |eigenvalue| of A (the fastest rate)."""
        if "rho" not in self._cache:
            self._cache["rho"] = float(np.max(np.abs(np.linalg.eigvals(self.A)), initial=0.0))
        return float(self._cache["rho"])

    def sup(self, span: float) -> np.ndarray:
        """An elementwise bound on |e^{A'σ}| (balanced) for 0 ≤ σ ≤ span (2n x 2n)."""
        key = ("sup", span)
        if key not in self._cache:
            self._cache[key] = self.free_powers.sup(span)
        return np.asarray(self._cache[key])

    # -- the states --------------------------------------------------------------------
    def states(self) -> _States:
        """z' = D_z z at every sample time in double-double, with elementwise error bounds."""
        if "states" not in self._cache:
            self._cache["states"] = self._states()
        return self._cache["states"]

    def _slopes(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The exact steps h_k (double-double) and the slopes (double-double, with bounds)."""
        t, u = self.data.times, self.data.values
        hh, hl = two_sum(t[1:], -t[:-1])
        if self.data.kind == "zoh":
            zero = np.zeros(hh.size)
            return hh, hl, zero, zero, zero
        dh, dl = two_sum(u[1:], -u[:-1])
        with np.errstate(over="ignore", invalid="ignore"):
            sh, sl = dd_div(dh, dl, hh, hl)
        return hh, hl, sh, sl, (16 * U * U) * np.abs(sh) + _TINY

    def _states(self) -> _States:
        m2 = self.A.shape[0]
        e = self.scaling
        t, u = self.data.times, self.data.values
        hh, hl, sh, sl, sb = self._slopes()
        steps = np.stack([hh, hl], axis=1)
        distinct, index = np.unique(steps, axis=0, return_inverse=True)
        index = index.ravel()
        Ph, Pl, Pe = expm(self.taylor, distinct[:, 0], distinct[:, 1], rows=m2)
        # the drives c_k = Ψ_k D_d (u_k, s_k): Ψ the last two columns of the z rows
        du, ds = e[m2], e[m2 + 1]
        dh = np.stack([np.ldexp(u[:-1], du), np.ldexp(sh, ds)], axis=1)
        dl = np.stack([np.zeros(u.size - 1), np.ldexp(sl, ds)], axis=1)
        de = np.stack([np.zeros(u.size - 1), np.ldexp(sb, ds)], axis=1)
        Qh, Ql, Qe = (X[index, :m2, m2:] for X in (Ph, Pl, Pe))
        ch, cl, cr = matvec(Qh, Ql, dh, dl)
        cerr = (cr + abs_product(Qe, np.abs(dh)[..., None])[..., 0]
                + abs_product(np.abs(Qh) * (1 + 2 * U) + Qe, de[..., None])[..., 0])
        maps = (Ph[:, :m2, :m2], Pl[:, :m2, :m2], Pe[:, :m2, :m2])
        span = float(t[-1] - t[0])
        if m2 <= _BLOCK_MAX_STATE:
            Sh, Sl, bound = _blocked(maps, index, ch, cl, cerr, t, self.sup)
        else:
            Sh, Sl, bound = _stepwise(maps, index, ch, cl, cerr, self.sup(span))
        return _States(Sh, Sl, bound, np.ldexp(sh, ds), np.ldexp(sl, ds), np.ldexp(sb, ds))

    # -- values ------------------------------------------------------------------------
    def values(self, hi: np.ndarray, lo: np.ndarray | None = None,
               order: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """x, x' or x'' (order 0, 1, 2) at the times hi + lo: (T, n) values and bounds."""
        hi = np.asarray(hi, dtype=float)
        lo = np.zeros_like(hi) if lo is None else np.asarray(lo, dtype=float)
        t = self.data.times
        m2 = self.A.shape[0]
        n = m2 // 2
        e = self.scaling
        S = self.states()
        k = np.searchsorted(t, hi, side="right") - 1
        k = np.where((k >= 0) & (hi == t[np.maximum(k, 0)]) & (lo < 0), k - 1, k)
        inside = np.flatnonzero((k >= 0) & (k < t.size - 1))
        after = np.flatnonzero(k >= t.size - 1)
        y = np.zeros((hi.size, m2))
        yb = np.zeros((hi.size, m2))
        if inside.size:
            kk = k[inside]
            th, tl = two_sum(hi[inside], -t[kk])
            tl = tl + lo[inside]
            vh = np.zeros((inside.size, m2 + 2))
            vl, ve = np.zeros_like(vh), np.zeros_like(vh)
            vh[:, :m2], vl[:, :m2], ve[:, :m2] = S.hi[kk], S.lo[kk], S.bound[kk]
            vh[:, m2] = np.ldexp(self.data.values[kk], e[m2])
            vh[:, m2 + 1], vl[:, m2 + 1], ve[:, m2 + 1] = S.slopes_hi[kk], S.slopes_lo[kk], \
                S.slopes_bound[kk]
            out, bound = _flow(self.powers, self.augmented, th, tl, vh, vl, ve)
            y[inside], yb[inside] = out[:, :m2], bound[:, :m2]
        if after.size:
            last = t.size - 1
            th, tl = two_sum(hi[after], -t[last])
            tl = tl + lo[after]
            count = after.size
            vh, vl, ve = (np.broadcast_to(X[last], (count, m2)).copy() for X in (S.hi, S.lo, S.bound))
            y[after], yb[after] = _flow(self.free_powers, self.free, th, tl, vh, vl, ve)
        y, yb = np.ldexp(y, -e[None, :m2]), np.ldexp(yb, -e[None, :m2])   # back from D_z
        if order < 2:
            part = slice(0, n) if order == 0 else slice(n, m2)
            return y[:, part], yb[:, part]
        return self._acceleration(hi, lo, y, yb)

    def _acceleration(self, hi: np.ndarray, lo: np.ndarray, y: np.ndarray,
                      yb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """x'' = (A z)_v + (b)_v u(t), with u(t) the interpolant (0 outside the data)."""
        n = self.A.shape[0] // 2
        force, force_bound = self._force(hi, lo)
        rows = self.A[n:]
        accel = rows_product(y, rows.T) + force[:, None] * self.b[n:][None, :]
        size = abs_product(np.abs(y), np.abs(rows).T) + np.abs(force)[:, None] * np.abs(self.b[n:])[None, :]
        bound = (abs_product(yb, np.abs(rows).T) * (1 + _EPS)
                 + (2 * self.A.shape[0] + 4) * _EPS * size
                 + force_bound[:, None] * np.abs(self.b[n:])[None, :] * (1 + 3 * _EPS))
        return accel, bound + _TINY

    def _force(self, hi: np.ndarray, lo: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The interpolant at hi + lo (float64) and a bound on its error (0 outside the
        data, where the force is exactly zero). A time just before a sample time t_j
        (hi = t_j, lo < 0) takes the interpolant from the left (a zero-order hold's previous
        sample; zero before the start), one just after the last (hi = t_end, lo > 0) zero."""
        t, u = self.data.times, self.data.values
        slopes = self.data.slopes()
        value = np.array(self.data(hi), dtype=float)
        k = np.clip(np.searchsorted(t, hi, side="right") - 1, 0, t.size - 2)
        at = np.clip(np.searchsorted(t, hi), 0, t.size - 1)
        left = (lo < 0) & (hi == t[at])
        j = at[left]
        k[left] = np.maximum(j - 1, 0)
        value[left] = np.where(j == 0, 0.0, u[k[left]] + slopes[k[left]] * (t[j] - t[k[left]]))
        right = (lo > 0) & (hi == t[-1])
        value[right] = 0.0
        slope = np.abs(slopes[k])
        tau = np.abs(hi - t[k])
        bound = 6 * _EPS * (np.abs(u[k]) + slope * tau) + slope * (np.abs(lo) + _EPS * tau)
        outside = (hi < t[0]) | (hi > t[-1]) | right
        outside[np.flatnonzero(left)[j == 0]] = True
        return value, np.where(outside, 0.0, bound)

    # -- mpmath ----------------------------------------------------------------------
    def digits(self, times: list[Any], order: int, dps: int) -> list[list[Any]]:
        """x, x' or x'' at exact times (Fractions), to about ``dps`` digits: a row per
        time. Runs the segments in mpmath (at most Limits.mp_max_segments of them)."""
        t = self.data.times
        if t.size - 1 > limits().mp_max_segments or np.unique(np.diff(t)).size > limits().mp_max_steps:
            raise ValueError(f"the mpmath evaluation of a sampled force runs through at most "
                             f"{limits().mp_max_segments} segments with at most {limits().mp_max_steps} distinct steps; "
                             f"this one has {t.size - 1} segments")
        m2 = self.A.shape[0]
        n = m2 // 2
        work = dps + 10 + len(str(t.size))
        with workdps(work):
            Aa = mpmath.zeros(m2 + 2, m2 + 2)
            for i in range(m2):
                for j in range(m2):
                    Aa[i, j] = _mp(self.A_exact[i, j], work)
                Aa[i, m2] = _mp(self.b_exact[i], work)
            Aa[m2, m2 + 1] = 1
            wanted = [mpmath.mpf(x.numerator) / x.denominator for x in times]
            last_needed = max(wanted, default=mpmath.mpf(0))
            ends = [mpmath.mpf(float(x)) for x in t]
            u = [mpmath.mpf(float(x)) for x in self.data.values]
            slope = [(u[k + 1] - u[k]) / (ends[k + 1] - ends[k]) if self.data.kind == "linear"
                     else mpmath.mpf(0) for k in range(t.size - 1)]
            cache: dict[float, Any] = {}
            states = [[mpmath.mpf(0)] * m2]
            for k in range(t.size - 1):
                if ends[k] >= last_needed:
                    break
                h = ends[k + 1] - ends[k]
                if float(h) not in cache:
                    cache[float(h)] = mpmath.expm(Aa * h)
                y = cache[float(h)] * mpmath.matrix([*states[-1], u[k], slope[k]])
                states.append([y[i] for i in range(m2)])
            out = []
            for x in wanted:
                k = int(np.searchsorted(t, float(x), side="right")) - 1
                while k + 1 < t.size and ends[k + 1] <= x:  # the float search may be an ulp off
                    k += 1
                while k >= 0 and ends[k] > x:
                    k -= 1
                if k < 0:
                    out.append([mpmath.mpf(0)] * n)
                    continue
                inside = k < t.size - 1
                drive = [u[k], slope[k]] if inside else [mpmath.mpf(0)] * 2
                y = mpmath.expm(Aa * (x - ends[k])) * mpmath.matrix([*states[k], *drive])
                if order == 0:
                    out.append([y[i] for i in range(n)])
                elif order == 1:
                    out.append([y[i] for i in range(n, m2)])
                else:  # the force at the last sample time is its value for "linear"
                    end = x == ends[-1] and self.data.kind == "linear"
                    force = y[m2] if inside else (u[-1] if end else mpmath.mpf(0))
                    out.append([mpmath.fsum(Aa[i, j] * y[j] for j in range(m2)) + Aa[i, m2] * force
                                for i in range(n, m2)])
        return out


# ----------------------------------------------------------------------------- the recurrence

_Maps = tuple[np.ndarray, np.ndarray, np.ndarray]


def _advance(maps: _Maps, which: np.ndarray, Sh: np.ndarray, Sl: np.ndarray, ch: np.ndarray,
             cl: np.ndarray, cerr: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """S ← E S + c for a batch (E = maps[which]): the new states and the error committed
    (E's own error on S, the product's and the sum's rounding, c's error)."""
    Eh, El, Ee = (X[which] for X in maps)
    yh, yl, rounding = matvec(Eh, El, Sh, Sl)
    Nh, Nl = dd_add(yh, yl, ch, cl)
    committed = (rounding + abs_product(Ee, np.abs(Sh)[..., None] * (1 + 2 * U))[..., 0]
                 + cerr + 3.01 * U * U * np.abs(Nh) * (1 + 2 * U))
    return Nh, Nl, committed


def _stepwise(maps: _Maps, index: np.ndarray, ch: np.ndarray, cl: np.ndarray, cerr: np.ndarray,
              sup: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The states one segment after the other: (N, 2n) hi, lo and bounds (each committed
    error reaches the later states through the flow, at most ``sup`` times itself)."""
    count, m2 = ch.shape
    Sh, Sl, D = np.zeros((count + 1, m2)), np.zeros((count + 1, m2)), np.zeros((count + 1, m2))
    h, lo, total = np.zeros((1, m2)), np.zeros((1, m2)), np.zeros((1, m2))
    for k in range(count):
        h, lo, committed = _advance(maps, index[k:k + 1], h, lo, ch[k:k + 1], cl[k:k + 1],
                                    cerr[k:k + 1])
        total = total + committed
        Sh[k + 1], Sl[k + 1], D[k + 1] = h[0], lo[0], total[0]
    return Sh, Sl, abs_product(D * (1 + (count + 2) * 2 * U), sup.T)


def _blocked(maps: _Maps, index: np.ndarray, ch: np.ndarray, cl: np.ndarray, cerr: np.ndarray,
             times: np.ndarray, sup: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The states in about √N blocks advanced together (results as :func:`_stepwise`).

    1. From rest, every block's own response l_b and transfer matrix T_b (the product of
       its maps), with the errors committed (each reaches the block's end through the
       flow over one block: at most G_block·Σ).
    2. The carries C_{b+1} = T_b C_b + l_b, one block after the other; a carry commits its
       rounding plus |T̃_b − T_b||C_b| + |l̃_b − l_b|, and reaches later states through the
       flow over the data (G_full).
    3. Inside every block, the states from its carry (their errors stay in the block).

    ``sup(span)`` gives the elementwise bound G on |e^{Aσ}|, σ ≤ span.
    """
    count, m2 = ch.shape
    L = max(1, math.isqrt(count))
    B = -(-count // L)
    pad = B * L - count
    starts = times[np.minimum(np.arange(B + 1) * L, count)]
    G_block, G_full = sup(float(np.max(np.diff(starts)))), sup(float(times[-1] - times[0]))
    # the padding steps are the identity (one more map) with no drive
    maps = tuple(np.concatenate([X, Y]) for X, Y in  # type: ignore[assignment]
                 zip(maps, (np.eye(m2)[None], np.zeros((1, m2, m2)), np.zeros((1, m2, m2)))))
    idx = np.concatenate([index, np.full(pad, maps[0].shape[0] - 1)]).reshape(B, L)
    drive = tuple(np.concatenate([X, np.zeros((pad, m2))]).reshape(B, L, m2)
                  for X in (ch, cl, cerr))
    # 1. each block from rest, and its transfer matrix
    lh, ll, l_sum = np.zeros((B, m2)), np.zeros((B, m2)), np.zeros((B, m2))
    Th = np.broadcast_to(np.eye(m2), (B, m2, m2)).copy()
    Tl, T_sum = np.zeros((B, m2, m2)), np.zeros((B, m2, m2))
    for r in range(L):
        which = idx[:, r]
        lh, ll, committed = _advance(maps, which, lh, ll, *(X[:, r] for X in drive))
        l_sum = l_sum + committed
        Eh, El, Ee = (X[which] for X in maps)
        Th, Tl, rounding = matmul(Eh, El, Th, Tl)
        T_sum = T_sum + rounding + abs_product(Ee, np.abs(Th) * (1 + 4 * U))
    grow = 1 + (L + 2) * 2 * U
    # 2. the carries
    Ch, Cl, carry_sum = np.zeros((B, m2)), np.zeros((B, m2)), np.zeros((B, m2))
    h, lo, running = np.zeros((1, m2)), np.zeros((1, m2)), np.zeros(m2)
    for b in range(B):
        Ch[b], Cl[b], carry_sum[b] = h[0], lo[0], running
        if b + 1 == B:
            break
        yh, yl, rounding = matvec(Th[b:b + 1], Tl[b:b + 1], h, lo)
        h, lo = dd_add(yh, yl, lh[b:b + 1], ll[b:b + 1])
        moved = abs_product(T_sum[b] * grow, np.abs(Ch[b])[:, None] * (1 + 2 * U))[:, 0] \
            + l_sum[b] * grow
        running = running + (rounding[0] + 3.01 * U * U * np.abs(h[0])
                             + abs_product(G_block, moved[:, None])[:, 0])
    # 3. inside the blocks
    Sh, Sl, D = np.zeros((B, L + 1, m2)), np.zeros((B, L + 1, m2)), np.zeros((B, L + 1, m2))
    Sh[:, 0], Sl[:, 0] = Ch, Cl
    h2, lo2, total = Ch, Cl, np.zeros((B, m2))
    for r in range(L):
        h2, lo2, committed = _advance(maps, idx[:, r], h2, lo2, *(X[:, r] for X in drive))
        total = total + committed
        Sh[:, r + 1], Sl[:, r + 1], D[:, r + 1] = h2, lo2, total
    bound = (abs_product((D * grow).reshape(B * (L + 1), m2), G_block.T).reshape(B, L + 1, m2)
             + abs_product(carry_sum * (1 + (B + 2) * 2 * U), G_full.T)[:, None, :])
    # state bL + r is [b, r]; the last of block b is the first of block b + 1
    out = [np.concatenate([X[:, :L].reshape(B * L, m2), X[-1:, L]])[: count + 1]
           for X in (Sh, Sl, bound)]
    return out[0], out[1], out[2]


# ----------------------------------------------------------------------------- moving a state


def _flow(powers: DyadicPowers, X: np.ndarray, th: np.ndarray, tl: np.ndarray, vh: np.ndarray,
          vl: np.ndarray, ve: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """e^{Xτ}v per row (τ = th + tl ≥ 0, v = vh + vl with error bound ve): values and
    bounds. τ = qδ + r: the bits of q apply the dyadic powers in double-double, then e^{Xr}
    is a float64 Taylor series (:func:`_taylor`). Times beyond 2^62 δ get an infinite bound."""
    q, rh, rl = powers.split(th, tl)
    served = q >= 0
    q = np.where(served, q, 0)
    wh, wl, we = vh.copy(), vl.copy(), ve.copy()
    top = int(np.max(q, initial=0)).bit_length()
    for i in range(top):
        rows = np.flatnonzero((q >> i) & 1)
        if rows.size == 0:
            continue
        Eh, El, Ee = powers[i]
        yh, yl, rounding = matvec(Eh, El, wh[rows], wl[rows])
        absE = np.abs(Eh) * (1 + 2 * U) + Ee
        we[rows] = (abs_product(we[rows], absE.T) + abs_product(np.abs(wh[rows]) * (1 + 2 * U), Ee.T)
                    + rounding)
        wh[rows], wl[rows] = yh, yl
    y, bound = _taylor(X, powers.P.theta, rh, rl, wh, wl, we)
    return np.where(served[:, None], y, 0.0), np.where(served[:, None], bound, np.inf)


def _taylor(X: np.ndarray, theta: float, rh: np.ndarray, rl: np.ndarray, wh: np.ndarray,
            wl: np.ndarray, we: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Σ_{j≤16} (X r)^j w/j! per row for θr ≤ 1/2 (X the float64 rounding of an exact matrix
    with ‖·‖∞ ≤ θ), and a bound on its error.

    Term j is formed by j products with X (each within (m + 3)u of the same product of
    absolute values: the dot product, r/j and the scaling), and X itself is within u|X|
    of the exact matrix (j more u); the terms are summed from the smallest, each addition
    within u of its result. The truncation, the low parts of r and w, and w's error ``we``
    carried by e^{θr}·max ``we`` (‖e^{Xr}‖∞ ≤ e^{θr}) are added."""
    m = X.shape[0]
    absX = np.abs(X)
    step = rh / np.arange(1, _TAYLOR + 1)[:, None]   # r/j
    terms, sizes = [wh], [np.abs(wh)]
    for j in range(_TAYLOR):
        scale = step[j][:, None]
        terms.append(rows_product(terms[-1], X.T) * scale)
        sizes.append(abs_product(sizes[-1], absX.T) * scale)
    e_total = (np.exp(theta * np.abs(rh) * (1 + 4 * U)) * (1 + 4 * U)
               * np.max(we + np.abs(wl), axis=1))[:, None]
    total = np.zeros_like(wh)
    size = np.zeros_like(wh)
    rounding = np.zeros_like(wh)
    for j in range(_TAYLOR, -1, -1):
        total = total + terms[j]
        size = size + sizes[j]
        rounding = rounding + (j * (m + 4) * U) * sizes[j] + U * np.abs(total)
    J = _TAYLOR
    x = theta * np.abs(rh) * (1 + 4 * U)
    with np.errstate(divide="ignore", under="ignore"):
        tail = np.where(x > 0, np.exp((J + 1) * np.log(np.maximum(x, 1e-300)) - math.lgamma(J + 2)
                                      - np.log1p(-np.minimum(x, 0.9) / (J + 2))), 0.0)
    tail = tail * (1 + 1e-9)
    grow = 1 + 2 * (J + 2) * U
    bound = (rounding * 1.01 + e_total * grow
             + tail[:, None] * (np.max(np.abs(wh) + we, axis=1) * (1 + 2 * U))[:, None]
             + np.abs(rl)[:, None] * abs_product(size * grow, absX.T) * 1.01)
    return total, bound + _TINY


# ----------------------------------------------------------------------------- building


def _balance(X: np.ndarray) -> np.ndarray:
    """Exponents e with diag(2^e) X diag(2^-e) balanced (off-diagonal row and column sums
    within a factor 2 of each other; Parlett & Reinsch, as LAPACK's gebal without
    permutations): every scaling a power of two.

    >>> _balance(np.array([[0.0, 1.0], [1e4, 0.0]])).tolist()
    [7, 0]
    """
    m = X.shape[0]
    e = np.zeros(m, dtype=int)
    Y = np.abs(X).astype(float)
    np.fill_diagonal(Y, 0.0)
    for _ in range(100):
        done = True
        for i in range(m):
            c, r = float(np.sum(Y[:, i])), float(np.sum(Y[i, :]))
            if c == 0 or r == 0:
                continue
            f, total = 0, c + r
            while c < r / 2:
                c, f = c * 4, f + 1
            while c >= r * 2:
                c, f = c / 4, f - 1
            if f and (c + r / 4.0**f) * 2.0**f < 0.95 * total:
                e[i] -= f
                Y[i, :] *= 2.0**-f
                Y[:, i] *= 2.0**f
                done = False
        if done:
            break
    return e


def _exact(value: Any, exponent: int = 0) -> Any:
    """value·2^exponent for :func:`taylor_matrices`: a SymPy Rational (exactly), or a
    60-digit mpmath value for other numbers."""
    value = sp.nsimplify(value) if isinstance(value, sp.Float) else value
    value = sp.sympify(value)
    if isinstance(value, sp.Rational):
        return value * sp.Integer(2) ** exponent
    with workdps(60):
        return mpmath.ldexp(_mp(value, 60), exponent)


def _mp(value: Any, dps: int) -> Any:
    value = sp.nsimplify(value) if isinstance(value, sp.Float) else value
    if isinstance(value, sp.Rational):
        return mpmath.mpf(int(value.p)) / int(value.q)
    return mpmath.mpf(sp.Float(value, dps + 5)._mpf_)


def sampled_inputs(scene: Scene) -> list[SampledInput]:
    """One :class:`SampledInput` per sampled entry of the scene.

    Raises
    ------
    SceneError
        For a scene with symbols or massless nodes (a sampled force needs every
        coordinate to carry mass), or without sampled entries.

    Examples
    --------
    >>> from laplace_springs.model.sampled import sampled
    >>> scene = Scene.from_matrices(M=[[2]], K=[[8]], x0=[0], v0=[0],
    ...                             forcing=[sampled([0, 1], [1, 1], kind="zoh")])
    >>> [response] = sampled_inputs(scene)
    >>> response.A.tolist(), response.b.tolist()
    ([[0.0, 1.0], [-4.0, 0.0]], [0.0, 0.5])
    """
    if scene.sampled is None:
        raise SceneError("the scene has no sampled forcing entries")
    if scene.free_symbols:
        raise SceneError("a sampled force needs numbers; the scene has the parameters "
                         + ", ".join(sorted(str(s) for s in scene.free_symbols)))
    if massless_nodes(scene):
        raise SceneError(f"a sampled force needs every coordinate to carry mass; coordinates "
                         f"{massless_nodes(scene)} are massless")
    Z, _, _ = first_order_system(scene)
    n = scene.n
    A = np.array([[float(e) for e in row] for row in Z.tolist()], dtype=float)
    Mmat = sp.Matrix(scene.M)
    out = []
    for j, data in enumerate(scene.sampled):
        if data is None:
            continue
        column = Mmat.LUsolve(sp.Matrix([1 if i == j else 0 for i in range(n)]))
        b_exact = sp.Matrix([*([0] * n), *column])
        b = np.array([float(e) for e in b_exact])
        out.append(SampledInput(A, b, data, j, Z, b_exact))
    return out

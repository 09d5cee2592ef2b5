"""The response to sampled force histories, exact for their interpolants, in float64 with
an error bound (and in mpmath to any number of digits).

With z = (x, x') the scene is z' = A z + b u(t), A = [[0, I], [-M⁻¹K, -M⁻¹C]],
b = (0, M⁻¹e_j) for a force on coordinate j. On a segment [t_k, t_{k+1}] the input is
u_k + s_k (t − t_k) (s_k = 0 for zero-order hold), so the augmented state
(z, u, s) moves by the matrix exponential of

    Â = [[A, b, 0], [0, 0, 1], [0, 0, 0]]    ((2n+2) x (2n+2)),

exactly: z(t_k + τ) = [e^{Âτ}(z_k, u_k, s_k)]_z (φ-functions of Aτ, evaluated stably
by the exponential of the augmented matrix, as ``scipy.signal.lsim`` does). The states
z_k at the sample times are the sum S_{k+1} = Σ_{j≤k} e^{A(t_{k+1} − t_{j+1})} c_j of the
segments' own responses c_j:

* on a uniform grid (up to a few units in the last place, as ``numpy.linspace`` gives)
  in blocks of B = 32 segments: the states at the block starts (the carries) by a
  log₂(N/B)-pass scan in double-double arithmetic (error-free products and sums, so
  the rounding does not build up with N), the block sums and the states inside a block
  from exact weights (E^r and the segments' responses per sample, 40 digits, rounded
  once) applied to the samples. A grid's deviation from the nominal step is corrected
  to first order, the second order bounded;
* on other grids, a loop over the segments with each step's e^{A h_k}.

The output at a time t in segment k is e^{Âτ}(S_k, u_k, s_k), τ = t − t_k; after the last
sample the force is zero and the motion is free, e^{Aτ}S_{N−1}; before the first it is
zero.

**Error bound.** On a uniform grid the bound of the states is a posteriori: every
rounding of the float64 and double-double operations is bounded elementwise from the
computed values and carried through |E^r| and |E^{B·2^i}| alongside them (a few ε of the
states' size, whatever N). The output off the sample times adds a model of
``scipy.linalg.expm``'s error: per entry ``c·ε·((1 + ‖Â‖τ)·max|e^{Âτ}| + log₂(2 +
‖Â‖τ)·G)``, G ≈ sup ‖e^{Aσ}‖ over the data's span (sampled). The (1 + ‖Â‖τ) term is the
phase error any float64 route makes at time τ (the rounding of A itself); it dominates
long free motions after the data. On other grids the segments' local errors are summed
and carried by that sup (N·ε growth).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import mpmath
import numpy as np
import sympy as sp

from ..limits import limits
from ..model.errors import SceneError
from ..model.sampled import Sampled
from ..model.scene import Scene
from .first_order import first_order_system, massless_nodes

__all__ = ["SampledInput", "sampled_inputs"]

_EPS = float(np.finfo(float).eps)
#: Batched expm of at most this many distinct times; beyond, Taylor series (short τ).
_UNIQUE_EXPM = 256
#: Taylor degree for ‖Â‖τ ≤ 1/2 per substep (remainder 0.5^17/17! ≈ 2e-20).
_TAYLOR_DEGREE = 16
#: Digits of the exact weights of the uniform path (then rounded to float64 hi/lo pairs).
_MP_DPS = 40
#: Segments per block of the uniform path.
_BLOCK = 32
#: Dekker's splitting constant 2^27 + 1.
_SPLIT = 134217729.0
#: Bound on the error of the ``_MP_DPS``-digit weights, relative to their largest entry.
_MP_ERROR = 1e-30


def _expm_error(tau: np.ndarray, size: np.ndarray, absPhi: np.ndarray, sup: np.ndarray,
                pert: np.ndarray) -> np.ndarray:
    """Bound on |fl(e^{Âτ}) v − e^{Âτ} v| per row: the module's model of expm's error.

    ``size`` holds |v| per row (k columns), ``absPhi`` |e^{Âτ}| (one k x k matrix or one
    per row), ``sup`` the elementwise sup of |e^{Aσ}| over the span (the z block, z
    columns), ``pert`` a bound on |δA| (z x z: the rounding of A and of the product Aτ).
    Three terms: the local rounding, 4k·ε·|e^{Âτ}||v|; the perturbation of A, whose effect
    ∫ e^{A(τ−σ)} δA z(σ) dσ is at most τ·sup|δA| max(sup|v_z|, |e^{Âτ}||v|) (a phase
    error that grows with τ); and the
    noise of scipy's squarings (one per doubling of ‖Âτ‖₁ beyond 5.4), k·ε·sup|v_z| each,
    absolute: it does not decay with e^{Aτ}.
    """
    k, z = size.shape[1], sup.shape[0]
    tau = np.abs(np.asarray(tau, dtype=float))
    if absPhi.ndim == 2:
        local = size @ absPhi.T
    else:
        local = np.einsum("kij,kj->ki", absPhi, size)
    spread = size[:, :z] @ sup.T
    reach = np.maximum(spread, local[:, :z])
    norm = float(np.max(np.sum(pert, axis=0), initial=0.0)) / _EPS + 1.0
    squarings = np.maximum(0.0, np.ceil(np.log2(np.maximum(norm * tau / 5.4, 1.0))))
    out = 4 * k * _EPS * local
    out[:, :z] += (tau[:, None] * ((reach @ pert.T) @ sup.T)
                   + _EPS * k * squarings[:, None] * spread)
    return out


def _expm_batch(A: np.ndarray, taus: np.ndarray) -> np.ndarray:
    import scipy.linalg  # a core dependency, imported where used (it takes 0.2 s)

    return scipy.linalg.expm(A[None, :, :] * np.asarray(taus, dtype=float)[:, None, None])


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

    # -- float64 -------------------------------------------------------------------
    @property
    def augmented(self) -> np.ndarray:
        m2 = self.A.shape[0]
        Aa = np.zeros((m2 + 2, m2 + 2))
        Aa[:m2, :m2], Aa[:m2, m2], Aa[m2, m2 + 1] = self.A, self.b, 1.0
        return Aa

    @property
    def norm(self) -> float:
        return float(np.max(np.sum(np.abs(self.augmented), axis=0)))

    @property
    def rounding(self) -> np.ndarray:
        """|A − A_exact| entry by entry (exactly: A is the rounded exact matrix)."""
        if "rounding" not in self._cache:
            self._cache["rounding"] = _rounding(self.A_exact, self.A)
        return np.asarray(self._cache["rounding"])

    def _input_rounding(self, tau: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The effect of b's rounding over τ: τ·sup|δb|(|u| + |s|τ), in the state rows."""
        out = np.zeros_like(v)
        z = self.A.shape[0]
        db = _rounding(self.b_exact, self.b.reshape(-1, 1)).ravel()
        force = np.abs(v[:, z]) + np.abs(v[:, z + 1]) * np.abs(tau)
        out[:, :z] = (np.abs(tau) * force)[:, None] * (self.sup @ db)[None, :]
        return out

    def _mp_augmented(self, dps: int, augmented: bool) -> Any:
        """Â (or A) exactly, as an mpmath matrix at ``dps`` digits."""
        m2 = self.A.shape[0]
        size = m2 + 2 if augmented else m2
        with mpmath.workdps(dps):
            out = mpmath.zeros(size, size)
            for i in range(m2):
                for j in range(m2):
                    out[i, j] = _mp(self.A_exact[i, j], dps)
                if augmented:
                    out[i, m2] = _mp(self.b_exact[i], dps)
            if augmented:
                out[m2, m2 + 1] = 1
        return out

    @property
    def rho(self) -> float:
        """The largest |eigenvalue| of A (the fastest rate)."""
        if "rho" not in self._cache:
            self._cache["rho"] = float(np.max(np.abs(np.linalg.eigvals(self.A)), initial=0.0))
        return float(self._cache["rho"])

    @property
    def sup(self) -> np.ndarray:
        """≈ the elementwise sup of |e^{Aσ}| over σ in [0, span] (sampled at 256 points,
        the dyadic multiples of the shortest step and short times; times 1.25)."""
        if "sup" not in self._cache:
            t = self.data.times
            span = max(t[-1] - t[0], 1e-300)
            sigma = np.concatenate([np.linspace(0, span, 257),
                                    np.min(np.diff(t)) * 2.0 ** np.arange(0, 64),
                                    np.linspace(0, 4 / max(self.rho, 1e-300), 17)])
            sigma = sigma[sigma <= span]
            self._cache["sup"] = 1.25 * np.max(np.abs(_expm_batch(self.A, sigma)), axis=0)
        return np.asarray(self._cache["sup"])

    def _error(self, tau: np.ndarray, size: np.ndarray, matrices: np.ndarray) -> np.ndarray:
        """:func:`_expm_error` of the computed exponentials ``matrices`` (one, or one per row)."""
        sup = self.sup
        if matrices.ndim == 3:  # past the span, |e^{Aτ}| itself joins the sup
            z = sup.shape[0]
            sup = np.maximum(sup, np.max(np.abs(matrices[:, :z, :z]), axis=0))
        return _expm_error(tau, size, np.abs(matrices), sup, self.rounding + 0.5 * _EPS * np.abs(self.A))

    def states(self) -> tuple[np.ndarray, np.ndarray]:
        """z at every sample time (N x 2n) and elementwise bounds on its error."""
        if "states" not in self._cache:
            self._cache["states"] = self._scan() or self._loop()
        return self._cache["states"]

    def _segments(self) -> tuple[np.ndarray, np.ndarray]:
        """c_k (the segments' responses from rest) and bounds, (N−1) x 2n."""
        t, u = self.data.times, self.data.values
        s = self.data.slopes()
        h = np.diff(t)
        m2, Aa, m = self.A.shape[0], self.augmented, self.A.shape[0] + 2
        drive = np.zeros((h.size, m))
        drive[:, m2], drive[:, m2 + 1] = u[:-1], s
        steps, inverse = np.unique(h, return_inverse=True)
        Phi = _expm_batch(Aa, steps)[inverse]                     # (K, m, m)
        c = np.einsum("kij,kj->ki", Phi, drive)[:, :m2]
        bound = (2 * m * _EPS * np.einsum("kij,kj->ki", np.abs(Phi), np.abs(drive))
                 + self._error(h, np.abs(drive), Phi))
        return c, bound[:, :m2]

    def _uniform_weights(self, h: float, B: int) -> dict[str, Any]:
        """The exact (``_MP_DPS`` digits) weights of the uniform path, rounded to float64
        hi/lo pairs: E^r (r ≤ B), the block weights W[r, q] (state after r segments of a
        block from rest, per sample q of the block), E^{B·2^i}, E^{2^i} and the
        derivatives in h."""
        m2 = self.A.shape[0]
        with mpmath.workdps(_MP_DPS):
            Aa = self._mp_augmented(_MP_DPS, True)
            hh = mpmath.mpf(h)
            Phi = mpmath.expm(Aa * hh)
            dPhi = Aa * Phi
            E = Phi[:m2, :m2]
            col = [Phi[i, m2] for i in range(m2)], [Phi[i, m2 + 1] for i in range(m2)]
            dcol = [dPhi[i, m2] for i in range(m2)], [dPhi[i, m2 + 1] for i in range(m2)]
            if self.data.kind == "zoh":
                psi0, psi1 = mpmath.matrix(col[0]), mpmath.zeros(m2, 1)
                dpsi0, dpsi1 = mpmath.matrix(dcol[0]), mpmath.zeros(m2, 1)
            else:
                psi1 = mpmath.matrix(col[1]) / hh
                psi0 = mpmath.matrix(col[0]) - psi1
                dpsi1 = mpmath.matrix(dcol[1]) / hh - mpmath.matrix(col[1]) / hh**2
                dpsi0 = mpmath.matrix(dcol[0]) - dpsi1
            powers = [mpmath.eye(m2)]
            for _ in range(B):
                powers.append(E * powers[-1])
            g = [powers[m] * psi0 for m in range(B)]        # E^m Ψ0
            a = [psi1] + [g[m - 1] + powers[m] * psi1 for m in range(1, B + 1)]
            # W[r, q] = [q < r] E^{r−1−q} Ψ0 + [1 ≤ q ≤ r] E^{r−q} Ψ1: a_{r−q} for q ≥ 1
            # (a_0 = Ψ1, a_m = E^{m−1}Ψ0 + E^mΨ1), and E^{r−1}Ψ0 for q = 0
            first = np.array([_hi_lo(x) for x in g])             # (B, 2, m2)
            toeplitz = np.array([_hi_lo(x) for x in a])          # (B+1, 2, m2)
            r, q = np.meshgrid(np.arange(B + 1), np.arange(B + 1), indexing="ij")
            W = toeplitz[np.clip(r - q, 0, B)].transpose(2, 0, 1, 3)   # (2, B+1, B+1, m2)
            W = np.where((q <= r)[None, :, :, None], W, 0.0)
            W[:, 1:, 0] = first.transpose(1, 0, 2)
            W[:, 0, 0] = 0.0
            blocks, steps = [], []
            P = powers[B]
            for _ in range(max(1, math.ceil(math.log2(max(self.data.times.size, 2))))):
                blocks.append(_hi_lo(P))
                P = P * P
            P = E
            for _ in range(max(1, math.ceil(math.log2(max(self.data.times.size, 2))))):
                steps.append(_hi_lo(P)[0])
                P = P * P
            AE = self._mp_augmented(_MP_DPS, False) * E
            return {"E": np.array([_hi_lo(X)[0] for X in powers]), "W": W,
                    "blocks": blocks, "steps": steps, "AE": _hi_lo(AE)[0],
                    "dpsi": np.array([_hi_lo(dpsi0)[0], _hi_lo(dpsi1)[0]])}

    def _nominal_step(self) -> float | None:
        t = self.data.times
        h = (t[-1] - t[0]) / (t.size - 1)
        deviation = np.max(np.abs(np.diff(t) - h))
        return h if deviation * self.norm <= limits().uniform_grid else None

    def _scan(self) -> tuple[np.ndarray, np.ndarray] | None:
        """The states on a uniform grid; None for other grids.

        Blocks of B segments: the state at t_{bB} (the carry C_b) comes from the block
        sums G_b = Σ_q W[B, q] u_{bB+q} by C_{b+1} = E^B C_b + G_b, both in double-double
        (error-free products and sums: the rounding does not accumulate with N); inside
        block b, S_{bB+r} = E^r C_b + Σ_q W[r, q] u_{bB+q} in float64 (one product and a
        dot product of ≤ B+1 terms per value). Every bound is computed alongside (a
        posteriori, elementwise). A grid off the nominal step by δ_k per segment (the
        ulps of ``numpy.linspace``) is corrected to first order: S¹ solves
        S¹_{k+1} = E S¹_k + δ_k (A E S_k + Ψ0' u_k + Ψ1' u_{k+1}), and the rest is bounded.
        """
        h = self._nominal_step()
        if h is None:
            return None
        t, u, m2 = self.data.times, self.data.values, self.A.shape[0]
        K = t.size - 1
        B = _BLOCK
        wts = self._uniform_weights(h, B)
        nb = K // B
        # the samples of each block (zero padding past the data: W[r, q] = 0 for q > r)
        upad = np.zeros((nb + 1) * B + 1)
        upad[:K + 1] = u
        U = upad[np.arange(nb + 1)[:, None] * B + np.arange(B + 1)[None, :]]   # (nb+1, B+1)
        Whi, Wlo = wts["W"]
        absU = np.abs(U)
        # block sums G_b (b < nb) in double-double, with their bounds
        Gh, Gl, Gb = _dd_dot(U[:nb], Whi[B], Wlo[B])
        # carries C_b = state at t_{bB}, b = 0..nb, in double-double (Hillis–Steele scan)
        Ch = np.zeros((nb + 1, m2))
        Cl, Cb = np.zeros_like(Ch), np.zeros_like(Ch)
        Ch[1:], Cl[1:], Cb[1:] = Gh, Gl, Gb
        d, level = 1, 0
        while d <= nb:
            Ph, Pl = wts["blocks"][level]
            Ch, Cl, Cb = _dd_step(Ch, Cl, Cb, Ph, Pl, d)
            d, level = 2 * d, level + 1
        # every state: S_{bB+r} = E^r C_b + L_{b,r}
        E = wts["E"][:B]                                           # (B, m2, m2)
        ET = E.transpose(2, 0, 1).reshape(m2, B * m2)              # [j, r·m2 + i] = E^r[i, j]
        absET = np.abs(ET)
        Wflat = Whi[:B].transpose(1, 0, 2).reshape(B + 1, B * m2)  # [q, r·m2 + i]
        L = U @ Wflat
        S = (Ch @ ET + L).reshape(-1, m2)[:K + 1]
        bound = ((B + 3) * _EPS * (absU @ np.abs(Wflat))
                 + (m2 + 2) * _EPS * (np.abs(Ch) @ absET)
                 + (np.abs(Cl) + Cb) @ absET * (1 + 4 * _EPS)).reshape(-1, m2)[:K + 1]
        bound += 2 * _EPS * np.abs(S) + 1e-300
        # the grid's deviation from the nominal step, to first order, and the rest bounded
        delta = _deviation(t[1:], t[:-1], h)
        if np.any(delta != 0):
            S, bound = self._deviation_correction(S, bound, delta, h, wts)
        return S, bound

    def _deviation_correction(self, S: np.ndarray, bound: np.ndarray, delta: np.ndarray,
                              h: float, wts: dict[str, Any]) -> tuple[np.ndarray, np.ndarray]:
        """S + S¹ (see :meth:`_scan`) and the bound of S¹'s rounding and of the terms of
        second order in δ (∞-norms, spread over the components)."""
        u, m2 = self.data.values, self.A.shape[0]
        AE, (dpsi0, dpsi1) = wts["AE"], wts["dpsi"]
        leaf = S[:-1] @ AE.T + u[:-1, None] * dpsi0[None, :] + u[1:, None] * dpsi1[None, :]
        dleaf = delta[:, None] * leaf
        S1 = dleaf.copy()
        d, levels = 1, 0
        while d < S1.shape[0]:
            S1[d:] += S1[:-d] @ wts["steps"][levels].T
            d, levels = 2 * d, levels + 1
        S1 = np.vstack([np.zeros((1, m2)), S1])
        G = float(np.max(np.sum(self.sup, axis=1)))                 # sup ‖e^{Aσ}‖∞
        nA = float(np.max(np.sum(np.abs(self.A), axis=1)))
        nE = float(np.max(np.sum(np.abs(wts["E"][1]), axis=1))) * (1 + 1e-12)
        nb_ = float(np.max(np.abs(self.b)))
        ad = np.abs(delta)
        x = ad * nA
        grow = np.exp(x)
        norm = lambda a: np.max(np.abs(a), axis=1)  # noqa: E731
        # the leaves' own error (S's bound, float products) and the scan's rounding
        leaf_err = ad * (nA * nE * (norm(bound[:-1]) + 8 * m2 * _EPS * norm(S[:-1]))
                         + 8 * _EPS * norm(leaf))
        scan = ((levels + 2) * 2 * (m2 + 2) * _EPS * G**3 * np.cumsum(norm(dleaf))
                + G * np.cumsum(leaf_err))
        b1 = np.concatenate([[0.0], scan])
        # second order: (E(h_k) − E) S¹_k, E(h_k) − E − δAE, c(h_k) − c − δc'
        umax = np.maximum(np.abs(u[:-1]), np.abs(u[1:]))
        hmax = h + float(np.max(ad))
        rho = (x * grow * nE * (norm(S1[:-1]) + b1[:-1])
               + x * x / 2 * grow * nE * norm(S[:-1])
               + ad * ad / 2 * grow * (2 * nA + hmax * nA * nA) * G * nb_ * umax)
        rest = b1 + np.concatenate([[0.0], G * np.cumsum(rho)])
        total = S + S1
        return total, bound + rest[:, None] + _EPS * np.abs(total)

    def _loop(self) -> tuple[np.ndarray, np.ndarray]:
        """The states on any grid: one step per segment (each with its e^{A h_k})."""
        t, m2 = self.data.times, self.A.shape[0]
        c, cbound = self._segments()
        h = np.diff(t)
        steps, inverse = np.unique(h, return_inverse=True)
        E = _expm_batch(self.A, steps)
        S = np.zeros((t.size, m2))
        state = np.zeros(m2)
        for k in range(t.size - 1):
            state = E[inverse[k]] @ state + c[k]
            S[k + 1] = state
        absE = np.abs(E)[inverse]
        local = ((m2 + 2) * _EPS * (np.einsum("kij,kj->ki", absE, np.abs(S[:-1])) + np.abs(c))
                 + self._error(h, np.abs(S[:-1]), E[inverse]) + cbound)
        # each local error reaches later states through e^{A(t_k − t_j)}: at most sup·error
        sup = self.sup[:m2, :m2]
        bound = np.zeros_like(S)
        bound[1:] = np.cumsum(local, axis=0) @ sup.T
        return S, bound

    def values(self, times: np.ndarray, order: int) -> tuple[np.ndarray, np.ndarray]:
        """x, x' or x'' (order 0, 1, 2) at ``times``: (T, n) values and bounds."""
        t = self.data.times
        m2 = self.A.shape[0]
        n = m2 // 2
        S, Sb = self.states()
        times = np.asarray(times, dtype=float)
        k = np.searchsorted(t, times, side="right") - 1
        inside = (k >= 0) & (k < t.size - 1)
        after = k >= t.size - 1
        y = np.zeros((times.size, m2 + 2))
        yb = np.zeros((times.size, m2 + 2))
        for rows, last in ((np.flatnonzero(inside), False), (np.flatnonzero(after), True)):
            if rows.size == 0:
                continue
            kk = k[rows]
            v = np.zeros((rows.size, m2 + 2))
            vb = np.zeros((rows.size, m2 + 2))
            v[:, :m2], vb[:, :m2] = S[kk], Sb[kk]
            if not last:
                v[:, m2], v[:, m2 + 1] = self.data.values[kk], self.data.slopes()[kk]
            y[rows], yb[rows] = self._flow(times[rows] - t[kk], v, vb)
        if order < 2:
            part = slice(0, n) if order == 0 else slice(n, m2)
            return y[:, part], yb[:, part]
        force = self.data(times)
        accel = y[:, :m2] @ self.A[n:].T + force[:, None] * self.b[n:][None, :]
        accel_bound = (yb[:, :m2] @ np.abs(self.A[n:]).T
                       + (m2 + 2) * _EPS * (np.abs(y[:, :m2]) @ np.abs(self.A[n:]).T
                                            + np.abs(force)[:, None] * np.abs(self.b[n:])[None, :]))
        return accel, accel_bound

    def _flow(self, tau: np.ndarray, v: np.ndarray, vb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """e^{Âτ} v per row, with bounds (vb: the bounds of v)."""
        at_sample = tau == 0          # e^{Â·0} v = v exactly
        if at_sample.any():
            y, bound, rest = v.copy(), vb.copy(), ~at_sample
            if rest.any():
                y[rest], bound[rest] = self._flow(tau[rest], v[rest], vb[rest])
            return y, bound
        Aa, m = self.augmented, self.A.shape[0] + 2
        unique, inverse = np.unique(tau, return_inverse=True)
        if unique.size > _UNIQUE_EXPM and self.norm * float(np.max(tau)) <= 2.0:
            q = max(1, math.ceil(self.norm * float(np.max(tau)) / 0.5))
            y, size, carried = v.copy(), np.abs(v), vb.copy()
            absAa = np.abs(Aa)
            for _ in range(q):
                y = _taylor(Aa, tau / q, y)
                carried = _taylor(absAa, tau / q, carried)
                size = _taylor(absAa, tau / q, size)
            rounding = (q * (_TAYLOR_DEGREE + m) * _EPS + 1e-19) * size
            return y, carried + rounding + _expm_error(tau, np.abs(v), np.zeros((m, m)), self.sup,
                                                       self.rounding) + self._input_rounding(tau, v)
        Phi = _expm_batch(Aa, unique)[inverse]
        absPhi = np.abs(Phi)
        y = np.einsum("kij,kj->ki", Phi, v)
        bound = (np.einsum("kij,kj->ki", absPhi, vb)
                 + 2 * m * _EPS * np.einsum("kij,kj->ki", absPhi, np.abs(v))
                 + self._error(tau, np.abs(v), Phi))
        return y, bound

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
        with mpmath.workdps(work):
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


def _mp(value: Any, dps: int) -> Any:
    value = sp.nsimplify(value) if isinstance(value, sp.Float) else value
    if isinstance(value, sp.Rational):
        return mpmath.mpf(int(value.p)) / int(value.q)
    return mpmath.mpf(sp.Float(value, dps + 5)._mpf_)


def _to_float(matrix: Any) -> np.ndarray:
    return np.array([[float(matrix[i, j]) for j in range(matrix.cols)] for i in range(matrix.rows)])


def _rounding(exact: Any, rounded: np.ndarray) -> np.ndarray:
    """|rounded − exact| per entry, from 40 digits of the exact entries."""
    out = np.zeros(rounded.shape)
    for i in range(rounded.shape[0]):
        for j in range(rounded.shape[1]):
            value = exact[i, j] if rounded.shape[1] > 1 or getattr(exact, "cols", 1) > 1 else exact[i]
            out[i, j] = abs(float(sp.Float(value, 40) - sp.Float(float(rounded[i, j]), 40)))
    return out + 1e-300


def _deviation(a: np.ndarray, b: np.ndarray, nominal: float) -> np.ndarray:
    """(a − b) − nominal, with a − b exact (TwoSum): the deviation of each span."""
    s = a - b
    bb = s - a
    err = (a - (s - bb)) + (-b - bb)
    return (s - nominal) + err


def _hi_lo(matrix: Any) -> np.ndarray:
    """An mpmath matrix as float64 hi and lo parts, hi + lo = it to ~32 digits:
    shape (2, rows) for a column, else (2, rows, cols)."""
    rows, cols = matrix.rows, matrix.cols
    hi = np.array([[float(matrix[i, j]) for j in range(cols)] for i in range(rows)])
    lo = np.array([[float(matrix[i, j] - hi[i, j]) for j in range(cols)] for i in range(rows)])
    return np.array([hi[:, 0], lo[:, 0]]) if cols == 1 else np.array([hi, lo])


def _split(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Dekker's split: a = hi + lo exactly, each with at most 26 significant bits."""
    c = _SPLIT * a
    hi = c - (c - a)
    return hi, a - hi


def _two_sum(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """s = fl(a + b) and the exact error a + b − s (Knuth)."""
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


def _dd_dot(U: np.ndarray, Wh: np.ndarray, Wl: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Σ_q U[:, q] W[q] in double-double (W = Wh + Wl): hi, lo and a bound on the error.

    Products and sums of the hi parts are error-free (Dekker, Knuth); only the sum of
    the low-order parts is rounded, ≤ 10Q²ε² of Σ|U||W|.
    """
    n, Q = U.shape
    m = Wh.shape[1]
    hi, lo = np.zeros((n, m)), np.zeros((n, m))
    Uh, Ul = _split(U)
    Wh_h, Wh_l = _split(Wh)
    for q in range(Q):
        a, ah, al = U[:, q, None], Uh[:, q, None], Ul[:, q, None]
        p = a * Wh[q]
        e = ((ah * Wh_h[q] - p) + ah * Wh_l[q] + al * Wh_h[q]) + al * Wh_l[q]
        hi, err = _two_sum(hi, p)
        lo += err + e + a * Wl[q]
    hi, lo = _two_sum(hi, lo)
    size = np.abs(U) @ np.abs(Wh)
    bound = ((10 * Q * Q + 8) * _EPS**2 + _MP_ERROR) * size \
        + _MP_ERROR * float(np.max(np.abs(Wh), initial=0.0)) * np.sum(np.abs(U), axis=1)[:, None]
    return hi, lo, bound + 1e-300


def _dd_step(Ch: np.ndarray, Cl: np.ndarray, Cb: np.ndarray, Ph: np.ndarray, Pl: np.ndarray,
             d: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One pass of a double-double scan: C[d:] += P C[:-d] (P = Ph + Pl), with the
    elementwise bound Cb carried along (through |P|) and the pass's own rounding added."""
    xh, xl = Ch[:-d], Cl[:-d]
    Xh, Xl = _split(xh)
    Ph_h, Ph_l = _split(Ph)
    hi, lo = Ch[d:].copy(), Cl[d:].copy()
    m = Ph.shape[0]
    for j in range(m):
        a, ah, al = xh[:, j, None], Xh[:, j, None], Xl[:, j, None]
        p = a * Ph[:, j]
        e = ((ah * Ph_h[:, j] - p) + ah * Ph_l[:, j] + al * Ph_h[:, j]) + al * Ph_l[:, j]
        hi, err = _two_sum(hi, p)
        lo += err + e
    lo += xl @ Ph.T + xh @ Pl.T
    hi, lo = _two_sum(hi, lo)
    represent = _MP_ERROR * (float(np.max(np.abs(Ph))) + 1.0)   # |P − Ph − Pl| per entry
    absP = np.abs(Ph) * (1 + 4 * _EPS) + represent
    size = np.abs(Ch[d:]) + np.abs(xh) @ absP.T
    outh, outl, outb = Ch.copy(), Cl.copy(), Cb.copy()
    outh[d:], outl[d:] = hi, lo
    outb[d:] = (Cb[d:] + Cb[:-d] @ absP.T + (8 * (m + 2) ** 2 * _EPS**2) * size
                + represent * np.sum(np.abs(xh) + np.abs(xl), axis=1)[:, None] + 1e-300)
    return outh, outl, outb


def _taylor(A: np.ndarray, tau: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Σ_{j ≤ degree} (Aτ)^j v / j! per row (‖Aτ‖ ≤ 1/2)."""
    total, term = v.copy(), v
    for j in range(1, _TAYLOR_DEGREE + 1):
        term = (term @ A.T) * (tau / j)[:, None]
        total = total + term
    return total


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
